"""Lines and circular arcs in one form (start, unit tangent, signed curvature, length): points,
exact distances, the arc through a point with a given start tangent, and biarcs.

Every function broadcasts over leading axes of ``(..., 2)`` point arrays; curvature ``k`` is 0 for
a line and > 0 for a counter-clockwise arc, lengths and distances are in mm.
"""
from __future__ import annotations

import math

import numpy as np

from ..geom2d import TWO_PI, J, cross, dot, unit

__all__ = [
    "LINE_SWEEP_RAD",
    "MAX_ARC_SWEEP_RAD",
    "MAX_TURNING_RAD",
    "entity_point",
    "entity_distance",
    "arc_from",
    "biarc",
]


#: an arc whose sweep is below this (radians) is written as a straight line
LINE_SWEEP_RAD = 1e-9
#: largest sweep of one arc entity (radians); merged arcs stay below it
MAX_ARC_SWEEP_RAD = 0.999 * math.pi
#: initial grids keep the tangent turning of one interval below this (radians)
MAX_TURNING_RAD = math.pi / 2


def entity_point(s, tangent, k, u) -> np.ndarray:
    """Point at arc length ``u`` along the entity (start ``s``, tangent, curvature ``k``)."""
    ku = k * u
    x = u * np.sinc(ku / math.pi)
    y = 0.5 * k * u * u * np.sinc(ku / TWO_PI) ** 2
    return s + x[..., None] * tangent + y[..., None] * J(tangent)


def entity_distance(q, s, tangent, k, length, e) -> np.ndarray:
    """Exact distance from ``q`` to the entity (broadcasting over leading axes).

    Works in the entity's local frame; the radial distance is written in a form
    that stays accurate as the curvature tends to 0 (a line).
    """
    w = q - s
    x = dot(w, tangent)
    y = cross(tangent, w)
    f = q - e
    shape = np.broadcast_shapes(x.shape, np.shape(k), np.shape(length), f.shape[:-1])

    def flat(a):
        return np.broadcast_to(a, shape).ravel()

    d = local_distance(flat(x), flat(y), flat(k), flat(length), flat(w[..., 0]), flat(w[..., 1]),
                       flat(f[..., 0]), flat(f[..., 1]))
    return d.reshape(shape)


def local_distance(x, y, k, length, w0, w1, f0, f1, above=None) -> np.ndarray:
    """:func:`entity_distance` from the point's local coordinates ``x`` (along the start tangent) and ``y`` (to
    its left), its offsets ``w`` from the entity's start and ``f`` from its end; every argument 1-D, one
    element per (point, entity) pair.

    A point whose foot lies on the entity is at its radial distance, any other at the nearer end: each of the
    two costly forms (``hypot``, ~20 ns an element) is evaluated only where it is the answer, element by
    element the same operations as on every element (the others' results were discarded).

    ``above`` (optional, one per element) is a distance the caller only needs the result below: an end
    distance provably larger is returned as ``inf`` without its two ``hypot``.  Proof: when the computed
    ``w0² + w1²`` exceeds ``above²·(1 + 10⁻⁹)`` (and ``10⁻²⁸⁰``: no underflow), the true ``|w|`` exceeds ``above``
    by far more than the few rounding errors of those sums and of ``hypot`` (~10⁻¹⁶ relative), so the
    computed ``hypot(w0, w1)`` is larger than ``above`` too; likewise for ``f``.  A NaN compares false and is
    computed as before.
    """
    kx, ky1 = k * x, 1.0 - k * y
    line = np.flatnonzero(k == 0)
    ksafe = k
    if line.size:
        ksafe = k.copy()
        ksafe[line] = 1.0
    along = np.arctan2(kx, ky1)
    along /= ksafe
    wrap = along < 0
    wrap[line] = False
    i = np.flatnonzero(wrap)
    along[i] += TWO_PI / np.abs(ksafe[i])
    along[line] = x[line]
    inside = (along >= 0) & (along <= length)
    ends = ~inside
    if above is None:
        d = np.empty_like(along)
    else:  # (on every element: cheaper than gathering the outside ones first)
        d = np.full_like(along, np.inf)
        sq = np.minimum(w0 * w0 + w1 * w1, f0 * f0 + f1 * f1)
        ends &= ~(sq > np.maximum(above * above * (1.0 + 1e-9), 1e-280))
    i = np.flatnonzero(inside)
    ki, xi, yi = k[i], x[i], y[i]
    d[i] = np.abs(ki * (xi * xi + yi * yi) - 2.0 * yi) / (np.hypot(kx[i], ky1[i]) + 1.0)
    i = np.flatnonzero(ends)
    d[i] = np.minimum(np.hypot(w0[i], w1[i]), np.hypot(f0[i], f1[i]))
    return d


def arc_from(s: np.ndarray, tangent: np.ndarray, e: np.ndarray):
    """The arc leaving ``s`` along ``tangent`` and ending at ``e``.

    Returns ``(tangent, k, length, valid)``; a nearly straight arc becomes a
    line along the chord.  ``valid`` is false for an empty chord or a sweep of
    π or more.
    """
    w = e - s
    chord = np.hypot(w[..., 0], w[..., 1])
    half = np.arctan2(cross(tangent, w), dot(tangent, w))
    safe = np.where(chord > 0, chord, 1.0)
    k = 2.0 * cross(tangent, w) / safe**2
    length = chord / np.sinc(half / math.pi)
    line = np.abs(2.0 * half) < LINE_SWEEP_RAD
    k = np.where(line, 0.0, k)
    length = np.where(line, chord, length)
    tangent = np.where(line[..., None], w / safe[..., None], tangent)
    valid = (chord > 0) & (np.abs(2.0 * half) < math.pi) & np.isfinite(length)
    return tangent, k, length, valid


def biarc(pa, ta, pb, tb, ratio) -> dict:
    """The biarc from ``pa`` (tangent ``ta``) to ``pb`` (tangent ``tb``) with ``d1 = ratio·d2``.

    ``d1, d2`` are the tangent lengths of the two arcs: the control points are
    ``q0 = pa + d1·ta``, ``q1 = pb - d2·tb`` with ``|q1 - q0| = d1 + d2``, and
    the joint lies on ``q0 q1`` at ``d1`` from ``q0``.  Arrays of shape
    ``(n, E)`` with E = 2 are returned (the form of one interval's entities in :mod:`camfab.discretize.interpolate`).
    """
    v = pb - pa
    u = ratio[:, None] * ta + tb
    vu, vv, c = dot(v, u), dot(v, v), dot(ta, tb)
    denom = vu + np.sqrt(np.maximum(vu * vu + 2.0 * ratio * (1.0 - c) * vv, 0.0))
    d2 = vv / np.where(denom > 0, denom, 1.0)
    d1 = ratio * d2
    q0 = pa + d1[:, None] * ta
    q1 = pb - d2[:, None] * tb
    pm = q0 + (d1 / np.where(d1 + d2 > 0, d1 + d2, 1.0))[:, None] * (q1 - q0)
    tm = unit(q1 - q0)
    t1, k1, l1, ok1 = arc_from(pa, ta, pm)
    t2, k2, l2, ok2 = arc_from(pm, tm, pb)
    valid = (denom > 0) & (d2 > 0) & np.isfinite(d2) & ok1 & ok2
    return dict(s=np.stack([pa, pm], 1), T=np.stack([t1, t2], 1), k=np.stack([k1, k2], 1),
                ell=np.stack([l1, l2], 1), e=np.stack([pm, pb], 1), valid=valid)
