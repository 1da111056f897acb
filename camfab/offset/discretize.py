"""Discretisation of exact closed plane curves with a measured tolerance guarantee.

The curves handled here are closed parametric curves ``P(t)``, ``t`` in
``[0, period)``, smooth between known *breakpoints* (where higher derivatives,
and possibly the tangent, may jump; ``P`` itself is continuous).  The module
knows nothing about cams: a cam profile is just one such curve.

Two discretisations are offered, both driven by a tolerance ``tol`` (mm):

* :func:`polyline` -- straight chords between curve points;
* :func:`arcs` -- a tangent-continuous (G1) chain of circular arcs (biarcs),
  which needs far fewer entities for the same tolerance.

Both guarantee that the Hausdorff distance between the entities and the exact
curve is at most ``tol``.  The guarantee is *measured*, never assumed from an
error model: every parameter interval is checked in both directions (curve
samples to the entities and entity samples to the curve, with a local
maximisation of each distance) and refined until the measured worst deviation is
below ``tol * (1 - margin)``; the result is then verified once more by the
independent, global :func:`measure_deviation`.

Every breakpoint where the tangent jumps (a kink) is a vertex of the result, so no entity
straddles a kink; polylines keep every breakpoint, arc chains may run across breakpoints where
the curve is tangent continuous (the deviation is measured all the same).

The geometry of a discretisation is a :class:`Chain`: entities given by start
point, unit start tangent, signed curvature (0 for a line, > 0 for a
counter-clockwise arc) and arc length.  :func:`measure_deviation` accepts a
chain, a discretisation, a polyline ``(n, 2)`` or ``(x, y, bulge)`` rows read
back from a DXF LWPOLYLINE, so exporters and tests can verify read-back
geometry against the exact curve.

This module holds the public API and the core shared by the fitting modules
(the curve and its Hermite surrogate, entity geometry, chains, results,
validation, measurement); the fitting itself lives in
:mod:`camfab.offset.interpolate` (adaptive grids of chords or interpolating
biarcs) and :mod:`camfab.offset.arcspline` (the free G1 arc spline tried first
by :func:`arcs`).  Both import from here, so they are imported inside
:func:`polyline` and :func:`arcs`.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable, Optional

import numpy as np
from scipy.spatial import cKDTree

from ..tolerances import DEFAULT_EXPORT_TOL_MM, MAX_EXPORT_TOL_MM, MIN_EXPORT_TOL_MM

__all__ = [
    "ParametricCurve",
    "Chain",
    "Discretisation",
    "ArcDiscretisation",
    "Deviation",
    "validate_tol",
    "polyline",
    "arcs",
    "measure_deviation",
    "max_deviation",
]

TWO_PI = 2.0 * math.pi
#: refinement stops when the measured deviation is below ``tol * (1 - MARGIN)``
MARGIN = 0.05
#: an arc whose sweep is below this (radians) is written as a straight line
LINE_SWEEP_RAD = 1e-9
#: largest sweep of one arc entity (radians); merged arcs stay below it
MAX_ARC_SWEEP_RAD = 0.999 * math.pi
#: initial grids keep the tangent turning of one interval below this (radians)
MAX_TURNING_RAD = math.pi / 2


# --------------------------------------------------------------------------------------
# the curve
# --------------------------------------------------------------------------------------
@dataclass(frozen=True)
class ParametricCurve:
    """An exact closed plane curve ``P(t)``, periodic with period :attr:`period`.

    Parameters
    ----------
    point : callable
        ``point(t)`` with ``t`` a ``(n,)`` float array returns the ``(n, 2)``
        points.  It is called with ``t`` in ``[0, period]``; ``P(period)`` must
        equal ``P(0)``.
    breakpoints : (m,) array_like
        Parameters in ``[0, period]`` where the curve's formula changes (higher
        derivatives or the tangent may jump there).  0 and ``period`` are added
        when missing; the values are sorted and de-duplicated.
    period : float, optional
        The parameter period (default 2π).
    derivative : callable, optional
        ``derivative(t)`` returns ``dP/dt`` as ``(n, 2)``.  Without it the
        derivative is taken by finite differences that never cross a breakpoint.
    """

    point: Callable[[np.ndarray], np.ndarray]
    breakpoints: np.ndarray = field(default_factory=lambda: np.array([0.0, TWO_PI]))
    period: float = TWO_PI
    derivative: Optional[Callable[[np.ndarray], np.ndarray]] = None

    def __post_init__(self) -> None:
        period = float(self.period)
        if not (math.isfinite(period) and period > 0.0):
            raise ValueError(f"period must be a positive finite number, got {self.period!r}")
        bp = np.asarray(self.breakpoints, dtype=float).ravel()
        if not np.all(np.isfinite(bp)):
            raise ValueError("breakpoints must be finite")
        if bp.size and (bp.min() < -1e-12 * period or bp.max() > period * (1 + 1e-12)):
            raise ValueError(f"breakpoints must lie in [0, period={period}]")
        bp = np.unique(np.concatenate([[0.0], np.clip(bp, 0.0, period), [period]]))
        keep = np.concatenate([[True], np.diff(bp) > 1e-12 * period])
        bp = bp[keep]
        bp[-1] = period
        object.__setattr__(self, "period", period)
        object.__setattr__(self, "breakpoints", bp)

    @property
    def pieces(self) -> tuple[np.ndarray, np.ndarray]:
        """``(lo, hi)`` parameter bounds of the smooth pieces between breakpoints."""
        return self.breakpoints[:-1], self.breakpoints[1:]


def _points(curve: ParametricCurve, t) -> np.ndarray:
    """``P(t)`` for any array shape of ``t``; returns ``t.shape + (2,)``."""
    t = np.asarray(t, dtype=float)
    flat = t.ravel()
    outside = (flat < 0.0) | (flat > curve.period)
    if outside.any():
        flat = np.where(outside, np.mod(flat, curve.period), flat)
    p = np.asarray(curve.point(flat), dtype=float)
    if p.shape != (flat.size, 2):
        raise ValueError(f"curve.point must return an (n, 2) array, got shape {p.shape}")
    return p.reshape(t.shape + (2,))


def _derivatives(curve: ParametricCurve, t, lo, hi) -> np.ndarray:
    """``dP/dt`` at ``t`` taken from inside the smooth piece ``[lo, hi]`` containing it.

    With an analytic derivative, values within ``2δ`` of a piece end
    (``δ = 1e-7`` of the piece) are extrapolated linearly from inside the
    piece, so a breakpoint's one-sided tangent is used whatever side the
    curve's own formula picks there.  Without one, second-order finite
    differences whose stencils stay inside ``[lo, hi]`` are used.
    """
    t, lo, hi = np.broadcast_arrays(*(np.asarray(x, dtype=float) for x in (t, lo, hi)))
    shape = t.shape
    t, lo, hi = t.ravel(), lo.ravel(), hi.ravel()
    width = hi - lo
    if curve.derivative is not None:
        def der(x):
            d = np.asarray(curve.derivative(x), dtype=float)
            if d.shape != (x.size, 2):
                raise ValueError(f"curve.derivative must return an (n, 2) array, got shape {d.shape}")
            return d

        delta = 1e-7 * width
        near_lo = t - lo < 2 * delta
        near_hi = (hi - t < 2 * delta) & ~near_lo
        near = near_lo | near_hi
        base = np.where(near_lo, lo, hi)[near]
        side = np.where(near_lo, 1.0, -1.0)[near]
        t1 = base + side * 2 * delta[near]
        t2 = base + side * 4 * delta[near]
        vals = der(np.concatenate([t, t1, t2]))  # one call: user functions may be costly
        out = vals[:t.size]
        if near.any():
            d1, d2 = vals[t.size:t.size + t1.size], vals[t.size + t1.size:]
            frac = ((t[near] - t1) / (t2 - t1))[:, None]
            out[near] = d1 + frac * (d2 - d1)
        return out.reshape(shape + (2,))
    h = np.minimum(1e-6 * curve.period, width / 8.0)
    fwd = t - h < lo
    bwd = (t + h > hi) & ~fwd
    sgn = np.where(bwd, -1.0, 1.0)
    hs = sgn * h
    cen = ~(fwd | bwd)
    # one call for every stencil: central (t - h, t + h) or one-sided (t, t ± h, t ± 2h)
    p = _points(curve, np.concatenate([np.where(cen, t - h, t), t + hs, t + 2 * hs]))
    p0, p1, p2 = p[:t.size], p[t.size:2 * t.size], p[2 * t.size:]
    out = np.where(cen[:, None], (p1 - p0) / (2 * h[:, None]), (-3 * p0 + 4 * p1 - p2) / (2 * hs[:, None]))
    return out.reshape(shape + (2,))


class _Surrogate:
    """Piecewise cubic Hermite interpolant of a curve from exact samples (never across a breakpoint).

    Built from two calls of the exact curve (points, then one-sided
    derivatives); used to *fit* without calling the exact curve again.
    Results are always measured against the exact curve.
    """

    def __init__(self, curve: ParametricCurve, n: int, min_count: int = 4):
        lo, hi = curve.pieces
        counts = np.maximum(min_count, np.ceil(n * (hi - lo) / curve.period)).astype(int)
        x = np.append(np.concatenate([l_ + (h_ - l_) * np.arange(c) / c for l_, h_, c in zip(lo, hi, counts)]),
                      curve.period)
        piece = np.repeat(np.arange(lo.size), counts)
        a, b = x[:-1], x[1:]
        p = _points(curve, x)
        p[-1] = p[0]
        d = _derivatives(curve, np.concatenate([a, b]), np.tile(lo[piece], 2), np.tile(hi[piece], 2))
        d0, d1 = d[:a.size], d[a.size:]
        h = (b - a)[:, None]
        p0, p1 = p[:-1], p[1:]
        self.curve = curve
        self.x = x
        self.first = np.concatenate([[0], np.cumsum(counts)])  # interval range of each piece
        self.piece = piece
        self.coef = np.stack([p0, d0, (3 * (p1 - p0) / h - 2 * d0 - d1) / h,
                              (2 * (p0 - p1) / h + d0 + d1) / h ** 2])
        self.points = p

    def _index(self, t, piece=None):
        i = np.searchsorted(self.x, t, side="right") - 1
        if piece is None:
            return np.clip(i, 0, self.x.size - 2)
        return np.clip(i, self.first[piece], self.first[piece + 1] - 1)

    def _local(self, t, piece):
        """Offset ``u`` of ``t`` in its cubic and that cubic's coefficients (``t`` wrapped into the
        period unless a ``piece`` is given)."""
        t = np.asarray(t, dtype=float)
        if piece is None:
            t = np.where((t < 0) | (t > self.curve.period), np.mod(t, self.curve.period), t)
        i = self._index(t, piece)
        return (t - self.x[i])[..., None], self.coef[:, i]

    def point(self, t, piece=None) -> np.ndarray:
        u, c = self._local(t, piece)
        return c[0] + u * (c[1] + u * (c[2] + u * c[3]))

    def derivative(self, t, piece=None) -> np.ndarray:
        u, c = self._local(t, piece)
        return c[1] + u * (2 * c[2] + 3 * u * c[3])

    def second_derivative(self, t, piece: int) -> np.ndarray:
        """``d²P/dt²`` of the surrogate inside smooth piece ``piece``."""
        t = np.asarray(t, dtype=float)
        i = self._index(t, piece)
        u = (t - self.x[i])[..., None]
        c = self.coef[:, i]
        return 2 * c[2] + 6 * u * c[3]

    def as_curve(self) -> ParametricCurve:
        return ParametricCurve(self.point, self.curve.breakpoints, self.curve.period, self.derivative)

    def error(self) -> float:
        """Largest distance between surrogate and exact curve at the interval midpoints (one call)."""
        mid = 0.5 * (self.x[:-1] + self.x[1:])
        d = _points(self.curve, mid) - self.point(mid)
        return float(np.hypot(d[:, 0], d[:, 1]).max())


def _surrogate(curve: ParametricCurve, tol: float, n: int = 4096) -> tuple[_Surrogate, float]:
    """A surrogate whose measured midpoint error is below ``tol / 200`` (grid refined as needed)."""
    for _ in range(4):
        sur = _Surrogate(curve, n)
        err = sur.error()
        if err <= tol / 200 or n >= 2 ** 17:
            return sur, err
        n = int(min(2 ** 17, n * max(2.0, min(8.0, (err / (tol / 400)) ** 0.25))))
    return sur, err


def _piece_index(curve: ParametricCurve, t: np.ndarray) -> np.ndarray:
    """Index of the piece containing each ``t`` (a value on a breakpoint goes right)."""
    bp = curve.breakpoints
    return np.clip(np.searchsorted(bp, t, side="right") - 1, 0, bp.size - 2)


# --------------------------------------------------------------------------------------
# entity geometry (lines and arcs in one form)
# --------------------------------------------------------------------------------------
def _dot(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    return u[..., 0] * v[..., 0] + u[..., 1] * v[..., 1]


def _cross(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    return u[..., 0] * v[..., 1] - u[..., 1] * v[..., 0]


def _perp(u: np.ndarray) -> np.ndarray:
    """``u`` turned +90°."""
    return np.stack([-u[..., 1], u[..., 0]], axis=-1)


def _rotate(u: np.ndarray, angle) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    return np.stack([c * u[..., 0] - s * u[..., 1], s * u[..., 0] + c * u[..., 1]], axis=-1)


def _unit(v: np.ndarray) -> np.ndarray:
    n = np.hypot(v[..., 0], v[..., 1])
    return v / np.where(n > 0, n, 1.0)[..., None]


def _entity_point(s, tangent, k, u) -> np.ndarray:
    """Point at arc length ``u`` along the entity (start ``s``, tangent, curvature ``k``)."""
    ku = k * u
    x = u * np.sinc(ku / math.pi)
    y = 0.5 * k * u * u * np.sinc(ku / TWO_PI) ** 2
    return s + x[..., None] * tangent + y[..., None] * _perp(tangent)


def _entity_distance(q, s, tangent, k, length, e) -> np.ndarray:
    """Exact distance from ``q`` to the entity (broadcasting over leading axes).

    Works in the entity's local frame; the radial distance is written in a form
    that stays accurate as the curvature tends to 0 (a line).
    """
    w = q - s
    x = _dot(w, tangent)
    y = _cross(tangent, w)
    kx, ky1 = k * x, 1.0 - k * y
    curved = k != 0
    ksafe = np.where(curved, k, 1.0)
    along = np.where(curved, np.arctan2(kx, ky1) / ksafe, x)
    along = np.where(curved & (along < 0), along + TWO_PI / np.abs(ksafe), along)
    inside = (along >= 0) & (along <= length)
    radial = np.abs(k * (x * x + y * y) - 2.0 * y) / (np.hypot(kx, ky1) + 1.0)
    ends = np.minimum(np.hypot(w[..., 0], w[..., 1]), np.hypot(*np.moveaxis(q - e, -1, 0)))
    return np.where(inside, radial, ends)


def _arc_from(s: np.ndarray, tangent: np.ndarray, e: np.ndarray):
    """The arc leaving ``s`` along ``tangent`` and ending at ``e``.

    Returns ``(tangent, k, length, valid)``; a nearly straight arc becomes a
    line along the chord.  ``valid`` is false for an empty chord or a sweep of
    π or more.
    """
    w = e - s
    chord = np.hypot(w[..., 0], w[..., 1])
    half = np.arctan2(_cross(tangent, w), _dot(tangent, w))
    safe = np.where(chord > 0, chord, 1.0)
    k = 2.0 * _cross(tangent, w) / safe**2
    length = chord / np.sinc(half / math.pi)
    line = np.abs(2.0 * half) < LINE_SWEEP_RAD
    k = np.where(line, 0.0, k)
    length = np.where(line, chord, length)
    tangent = np.where(line[..., None], w / safe[..., None], tangent)
    valid = (chord > 0) & (np.abs(2.0 * half) < math.pi) & np.isfinite(length)
    return tangent, k, length, valid


def _biarc(pa, ta, pb, tb, ratio) -> dict:
    """The biarc from ``pa`` (tangent ``ta``) to ``pb`` (tangent ``tb``) with ``d1 = ratio·d2``.

    ``d1, d2`` are the tangent lengths of the two arcs: the control points are
    ``q0 = pa + d1·ta``, ``q1 = pb - d2·tb`` with ``|q1 - q0| = d1 + d2``, and
    the joint lies on ``q0 q1`` at ``d1`` from ``q0``.  Arrays of shape
    ``(n, E)`` with E = 2 are returned (see :func:`~camfab.offset.interpolate._interval_entities`).
    """
    v = pb - pa
    u = ratio[:, None] * ta + tb
    vu, vv, c = _dot(v, u), _dot(v, v), _dot(ta, tb)
    denom = vu + np.sqrt(np.maximum(vu * vu + 2.0 * ratio * (1.0 - c) * vv, 0.0))
    d2 = vv / np.where(denom > 0, denom, 1.0)
    d1 = ratio * d2
    q0 = pa + d1[:, None] * ta
    q1 = pb - d2[:, None] * tb
    pm = q0 + (d1 / np.where(d1 + d2 > 0, d1 + d2, 1.0))[:, None] * (q1 - q0)
    tm = _unit(q1 - q0)
    t1, k1, l1, ok1 = _arc_from(pa, ta, pm)
    t2, k2, l2, ok2 = _arc_from(pm, tm, pb)
    valid = (denom > 0) & (d2 > 0) & np.isfinite(d2) & ok1 & ok2
    return dict(s=np.stack([pa, pm], 1), T=np.stack([t1, t2], 1), k=np.stack([k1, k2], 1),
                ell=np.stack([l1, l2], 1), e=np.stack([pm, pb], 1), valid=valid)


@dataclass(frozen=True)
class Chain:
    """A closed chain of lines and circular arcs.

    Entity ``i`` starts at ``start[i]`` with unit tangent ``tangent[i]``, has
    signed curvature ``curvature[i]`` (0 = line, > 0 = counter-clockwise arc)
    and arc length ``length[i]``, and ends at ``end[i]``.
    """

    start: np.ndarray
    tangent: np.ndarray
    curvature: np.ndarray
    length: np.ndarray
    end: np.ndarray

    @property
    def n(self) -> int:
        """Number of entities."""
        return int(self.curvature.size)

    @property
    def sweep(self) -> np.ndarray:
        """Signed sweep of every entity (radians; 0 for lines)."""
        return self.curvature * self.length

    @property
    def end_tangent(self) -> np.ndarray:
        """Unit tangent at the end of every entity."""
        return _rotate(self.tangent, self.sweep)

    def sample(self, n_per_entity: int) -> tuple[np.ndarray, np.ndarray]:
        """``n_per_entity`` points per entity, ends included: ``(points (n, m, 2), u (n, m))``."""
        u = self.length[:, None] * np.linspace(0.0, 1.0, n_per_entity)
        return _entity_point(self.start[:, None], self.tangent[:, None], self.curvature[:, None], u), u

    def distance(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Exact distance from each point of ``q`` ``(N, 2)`` to the chain, and the nearest entity.

        A k-d tree on the midpoints of short sub-pieces of the entities (each
        at most ``h`` long) proposes candidates; the answer is exact because a
        point is re-checked with more candidates, and finally against every
        entity, unless the nearest unexamined sub-piece is provably too far.
        """
        q = np.asarray(q, dtype=float).reshape(-1, 2)
        h = max(float(np.median(self.length)), float(self.length.sum()) / (4 * self.n))
        parts = np.maximum(1, np.ceil(self.length / h)).astype(int)
        owner = np.repeat(np.arange(self.n), parts)
        j = np.arange(owner.size) - np.repeat(np.cumsum(parts) - parts, parts)
        u = self.length[owner] * (j + 0.5) / parts[owner]
        mid = _entity_point(self.start[owner], self.tangent[owner], self.curvature[owner], u)
        reach = 0.5 * float((self.length / parts).max())
        tree = cKDTree(mid)
        dist = np.full(q.shape[0], np.inf)
        which = np.zeros(q.shape[0], dtype=int)
        todo = np.arange(q.shape[0])
        for k in (4, 64):
            k = min(k, owner.size)
            dm, idx = tree.query(q[todo], k=k)
            dm, idx = dm.reshape(todo.size, k), owner[idx.reshape(todo.size, k)]
            d = self._dist_to(q[todo, None], idx)
            best = d.argmin(axis=1)
            dist[todo] = d[np.arange(todo.size), best]
            which[todo] = idx[np.arange(todo.size), best]
            if k == owner.size:
                return dist, which
            todo = todo[dm[:, -1] - reach < dist[todo]]
            if todo.size == 0:
                return dist, which
        step = max(1, 2_000_000 // self.n)
        allidx = np.arange(self.n)[None, :]
        for c in range(0, todo.size, step):
            sel = todo[c:c + step]
            dd = self._dist_to(q[sel, None], allidx)
            b = dd.argmin(axis=1)
            dist[sel] = dd[np.arange(sel.size), b]
            which[sel] = b
        return dist, which

    def _dist_to(self, q: np.ndarray, idx: np.ndarray) -> np.ndarray:
        return _entity_distance(q, self.start[idx], self.tangent[idx], self.curvature[idx],
                                self.length[idx], self.end[idx])

    # ---- constructors ------------------------------------------------
    @classmethod
    def from_polyline(cls, points) -> "Chain":
        """Closed polyline through ``points`` ``(n, 2)`` (closing segment added if needed)."""
        p = np.asarray(points, dtype=float).reshape(-1, 2)
        if not np.array_equal(p[0], p[-1]):
            p = np.vstack([p, p[:1]])
        s, e = p[:-1], p[1:]
        w = e - s
        length = np.hypot(w[:, 0], w[:, 1])
        keep = length > 0
        return cls(s[keep], _unit(w[keep]), np.zeros(int(keep.sum())), length[keep], e[keep])

    @classmethod
    def from_bulges(cls, rows) -> "Chain":
        """Closed chain from ``(x, y, bulge)`` rows, as in a DXF LWPOLYLINE.

        The bulge of row ``i`` (``tan(sweep/4)``, > 0 counter-clockwise)
        belongs to the segment from vertex ``i`` to vertex ``i + 1``.
        """
        r = np.asarray(rows, dtype=float).reshape(-1, 3)
        s = r[:, :2]
        e = np.roll(s, -1, axis=0)
        keep = np.any(s != e, axis=1)
        s, e, bulge = s[keep], e[keep], r[keep, 2]
        w = e - s
        chord = np.hypot(w[:, 0], w[:, 1])
        sweep = 4.0 * np.arctan(bulge)
        tangent = _rotate(_unit(w), -0.5 * sweep)
        length = chord / np.sinc(sweep / TWO_PI)
        k = np.where(sweep != 0, sweep / np.where(length > 0, length, 1.0), 0.0)
        return cls(s, tangent, k, length, e)

    @classmethod
    def from_arcs(cls, starts, ends, centres, ccw) -> "Chain":
        """Chain from G-code style entities.

        Parameters
        ----------
        starts, ends : (n, 2) array_like
        centres : (n, 2) array_like
            Arc centres; a row of NaN makes that entity a straight line.
        ccw : (n,) array_like of bool
            True for counter-clockwise (G3) arcs.  An arc whose start equals its
            end is a full circle.
        """
        s = np.asarray(starts, dtype=float).reshape(-1, 2)
        e = np.asarray(ends, dtype=float).reshape(-1, 2)
        c = np.asarray(centres, dtype=float).reshape(-1, 2)
        ccw = np.broadcast_to(np.asarray(ccw, dtype=bool), (s.shape[0],))
        line = np.isnan(c).any(axis=1)
        cs = np.where(line[:, None], 0.0, c)
        a = s - cs
        b = e - cs
        radius = np.hypot(a[:, 0], a[:, 1])
        sign = np.where(ccw, 1.0, -1.0)
        sweep = np.mod(sign * np.arctan2(_cross(a, b), _dot(a, b)), TWO_PI)
        sweep = np.where(sweep == 0, TWO_PI, sweep) * sign
        w = e - s
        chord = np.hypot(w[:, 0], w[:, 1])
        rsafe = np.where(radius > 0, radius, 1.0)
        tangent = np.where(line[:, None], _unit(w), sign[:, None] * _perp(a) / rsafe[:, None])
        k = np.where(line, 0.0, sign / np.where(radius > 0, radius, 1.0))
        length = np.where(line, chord, np.abs(sweep) * radius)
        return cls(s, tangent, k, length, e)


# --------------------------------------------------------------------------------------
# results
# --------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Deviation:
    """Measured two-way deviation between entities and an exact curve (mm).

    Attributes
    ----------
    max : float
        The Hausdorff-type maximum of the two directions.
    curve_to_entities : float
        Largest distance from a point of the exact curve to the entities.
    entities_to_curve : float
        Largest distance from a point of the entities to the exact curve.
    at_param : float
        Curve parameter where the maximum occurs (for the entity direction: the
        parameter of the closest curve point).
    at_point : (2,) ndarray
        The curve point at ``at_param``.
    """

    max: float
    curve_to_entities: float
    entities_to_curve: float
    at_param: float
    at_point: np.ndarray

    def __float__(self) -> float:
        return float(self.max)


@dataclass(frozen=True)
class Discretisation:
    """A closed polyline within ``tol`` of an exact curve.

    Attributes
    ----------
    params : (n,) ndarray
        Curve parameters of the vertices, from 0 to ``period`` inclusive; every
        breakpoint is among them.
    points : (n, 2) ndarray
        The vertices ``P(params)``; ``points[-1] == points[0]`` (closed).
    max_deviation : float
        Measured two-way maximum distance between the segments and the curve.
    tol : float
        The requested tolerance; ``max_deviation <= tol``.
    """

    params: np.ndarray
    points: np.ndarray
    max_deviation: float
    tol: float

    @property
    def n_entities(self) -> int:
        """Number of line segments."""
        return int(self.params.size - 1)

    def chain(self) -> Chain:
        """The segments as a :class:`Chain`."""
        return Chain.from_polyline(self.points)


@dataclass(frozen=True)
class ArcDiscretisation:
    """A closed, tangent-continuous chain of arcs (and lines) within ``tol`` of a curve.

    Attributes
    ----------
    params : (m,) ndarray
        Curve parameters (0 … ``period``) where the chain passes through
        ``P(params)`` with the curve's tangent (exactly at breakpoints, to the
        surrogate's accuracy elsewhere).  For a free arc spline (see
        :func:`arcs`) they are its span ends (every kink among them; G1
        breakpoints may be crossed by arcs); for interpolating biarcs every
        fitting node (every breakpoint).
    starts, ends : (n, 2) ndarray
        Entity end points; ``ends[i] == starts[i + 1]``.
    centres : (n, 2) ndarray
        Arc centres (NaN for lines).
    radii : (n,) ndarray
        Arc radii (``inf`` for lines).
    sweeps : (n,) ndarray
        Signed sweep angles in radians, > 0 counter-clockwise (0 for lines).
    bulges : (n,) ndarray
        DXF LWPOLYLINE bulge of every entity, ``tan(sweep / 4)``.
    tangents : (n, 2) ndarray
        Unit tangents at the entity starts.
    max_deviation : float
        Measured two-way maximum distance between the chain and the curve.
    tol : float
        The requested tolerance; ``max_deviation <= tol``.
    """

    params: np.ndarray
    starts: np.ndarray
    ends: np.ndarray
    centres: np.ndarray
    radii: np.ndarray
    sweeps: np.ndarray
    bulges: np.ndarray
    tangents: np.ndarray
    max_deviation: float
    tol: float

    @property
    def n_entities(self) -> int:
        """Number of entities (arcs and lines)."""
        return int(self.sweeps.size)

    @property
    def is_line(self) -> np.ndarray:
        """Boolean mask of the entities that are straight lines."""
        return self.sweeps == 0

    @property
    def end_tangents(self) -> np.ndarray:
        """Unit tangents at the entity ends."""
        return _rotate(self.tangents, self.sweeps)

    @property
    def lwpolyline(self) -> np.ndarray:
        """``(n, 3)`` rows ``(x, y, bulge)`` of a closed DXF LWPOLYLINE."""
        return np.column_stack([self.starts, self.bulges])

    def chain(self) -> Chain:
        """The entities as a :class:`Chain`."""
        k = np.where(self.is_line, 0.0, np.sign(self.sweeps) / self.radii)
        length = np.where(self.is_line, np.hypot(*(self.ends - self.starts).T),
                          np.abs(self.sweeps) * self.radii)
        return Chain(self.starts, self.tangents, k, length, self.ends)


# --------------------------------------------------------------------------------------
# validation
# --------------------------------------------------------------------------------------
def validate_tol(tol) -> float:
    """Return ``tol`` as a float, or raise ``ValueError`` unless it is in the accepted range.

    The accepted range is ``[MIN_EXPORT_TOL_MM, MAX_EXPORT_TOL_MM]``
    (1e-6 … 0.1 mm).
    """
    try:
        value = float(tol)
    except (TypeError, ValueError):
        value = math.nan
    if not (MIN_EXPORT_TOL_MM <= value <= MAX_EXPORT_TOL_MM):
        raise ValueError(f"tol must be in [{MIN_EXPORT_TOL_MM:g}, {MAX_EXPORT_TOL_MM:g}] mm, "
                         f"got {tol!r}")
    return value


def _check_closed(curve: ParametricCurve, tol: float) -> None:
    gap = _points(curve, np.array([0.0, curve.period]))
    if np.hypot(*(gap[1] - gap[0])) > 0.01 * tol:
        raise ValueError(f"the curve is not closed: |P(period) - P(0)| = "
                         f"{np.hypot(*(gap[1] - gap[0])):.3g} mm")


# --------------------------------------------------------------------------------------
# public API
# --------------------------------------------------------------------------------------
def polyline(curve: ParametricCurve, *, tol: float = DEFAULT_EXPORT_TOL_MM) -> Discretisation:
    """Closed polyline whose segments lie within ``tol`` of the exact curve.

    Parameters
    ----------
    curve : ParametricCurve
        The exact closed curve.
    tol : float, keyword-only
        Maximum distance (mm) between the segments and the curve, in
        ``[1e-6, 0.1]``.

    Returns
    -------
    Discretisation
        Vertices on the curve (every breakpoint is one) and the measured
        two-way maximum deviation, which is ``<= tol``.

    Raises
    ------
    ValueError
        If ``tol`` is outside the accepted range or the curve is not closed.

    Notes
    -----
    The initial grid follows the chord-error estimate ``L²κ/8``; intervals
    whose *measured* deviation exceeds ``tol·(1 - MARGIN)`` are bisected; a
    second grid equidistributing the measured errors is tried and the smaller
    result kept; :func:`measure_deviation` verifies the result globally.
    """
    from .interpolate import _fit  # (imported here: it builds on this module)

    tol = validate_tol(tol)
    _check_closed(curve, tol)

    def build(nodes):
        pts = _points(curve, nodes)
        pts[-1] = pts[0]
        return pts

    nodes, measured = _fit(curve, tol, "line",
                           lambda nodes: measure_deviation(build(nodes), curve).max)
    return Discretisation(params=nodes, points=build(nodes), max_deviation=float(measured), tol=tol)


def _merge_cocircular(chain: Chain, pieces: np.ndarray) -> Chain:
    """Merge runs of consecutive entities on the same circle (or line) within one piece.

    Two neighbours merge when their curvatures agree so closely that the
    tangent of the merged entity differs from the original ones by less than
    :data:`LINE_SWEEP_RAD`; a merged arc sweeps less than :data:`MAX_ARC_SWEEP_RAD`.
    """
    k, ell = chain.curvature, chain.length
    same = (pieces[1:] == pieces[:-1]) & (np.abs(k[1:] - k[:-1]) * (ell[1:] + ell[:-1]) <= LINE_SWEEP_RAD)
    if not same.any():
        return chain
    first = np.flatnonzero(np.concatenate([[True], ~same]))
    last = np.append(first[1:] - 1, chain.n - 1)
    sweep = np.abs(chain.sweep)
    long_runs = np.flatnonzero(last > first)
    extra_first, extra_last = [], []
    for r in long_runs:  # loops over runs of co-circular entities only (few: dwells, flats)
        members = np.arange(first[r], last[r] + 1)
        n_chunks = max(1, math.ceil(float(sweep[members].sum()) / MAX_ARC_SWEEP_RAD))
        while True:
            chunks = np.array_split(members, n_chunks)
            if all(sweep[c].sum() <= MAX_ARC_SWEEP_RAD for c in chunks) or n_chunks >= members.size:
                break
            n_chunks += 1
        extra_first += [c[0] for c in chunks]
        extra_last += [c[-1] for c in chunks]
    single = last == first
    first = np.concatenate([first[single], np.array(extra_first, dtype=int)])
    last = np.concatenate([last[single], np.array(extra_last, dtype=int)])
    order = np.argsort(first)
    first, last = first[order], last[order]
    s, e = chain.start[first], chain.end[last]
    single = first == last
    tangent, k_new, l_new, _ = _arc_from(s, chain.tangent[first], e)
    return Chain(s,
                 np.where(single[:, None], chain.tangent[first], tangent),
                 np.where(single, chain.curvature[first], k_new),
                 np.where(single, chain.length[first], l_new), e)


def arcs(curve: ParametricCurve, *, tol: float = DEFAULT_EXPORT_TOL_MM) -> ArcDiscretisation:
    """Closed G1 chain of circular arcs within ``tol`` of the exact curve (biarcs).

    Parameters
    ----------
    curve : ParametricCurve
        The exact closed curve.
    tol : float, keyword-only
        Maximum distance (mm) between the chain and the curve, in ``[1e-6, 0.1]``.

    Returns
    -------
    ArcDiscretisation
        The arcs (nearly straight ones as lines) and the measured two-way
        maximum deviation, which is ``<= tol``.

    Raises
    ------
    ValueError
        If ``tol`` is outside the accepted range or the curve is not closed.

    Notes
    -----
    Each parameter interval ``[a, b]`` of a smooth piece gets a biarc through
    ``P(a)`` and ``P(b)`` with the exact one-sided tangents there (the ratio
    of its two tangent lengths chosen by a golden-section search to minimise
    the deviation at curve samples), so neighbouring intervals share their end
    tangent and the chain is G1 everywhere except at true kinks of the curve.
    The initial grid turns at most :data:`MAX_TURNING_RAD` per interval;
    intervals whose measured deviation exceeds ``tol·(1 - MARGIN)`` are
    split; a second grid equidistributing the measured errors is tried and the
    smaller kept.
    Consecutive co-circular arcs in one piece are merged, and the final chain
    is verified with :func:`measure_deviation`.

    First, a *free* (non-interpolating) G1 arc spline is tried, by spans
    clamped to the exact point and one-sided tangent at their ends.  Spans
    end at kinks and at circular pieces (dwells), whose exact arcs the
    neighbouring spans continue: their arcs next to a dwell keep its
    curvature and merge with it; G1 breakpoints in between are crossed by
    arcs (without kinks or circular pieces every breakpoint ends a span).
    Long spans are cut into spans of about :data:`~camfab.offset.arcspline._SPLINE_SPAN` arcs, joined
    G1 on the curve with its tangent.  Per span
    knots and curvatures are optimised together on a linear model of the
    normal deviation (its prefix integrals exact for cubic Hermite data, so
    the model matches the built chain to a fraction of a percent) and the
    fewest arcs kept; two arcs of a span (the last two, or the two before a
    fixed-curvature last arc) are the biarc closing it exactly.  The chain is
    measured on the exact curve; should it exceed ``tol``, only the offending
    spans are refitted to a lower target.  It is used when it measures within
    ``tol`` (else the same spline clamped at every breakpoint, else the
    interpolating biarcs above).  All fitting runs on a Hermite surrogate of a few batched exact
    samples; only the verification calls the exact curve again.
    """
    from .arcspline import _fit_spline  # (imported here: both build on this module)
    from .interpolate import _arc_chain, _fit

    tol = validate_tol(tol)
    _check_closed(curve, tol)

    cache: dict = {}

    def build(nodes):
        key = nodes.tobytes()
        if key not in cache:
            chain, pieces = _arc_chain(curve, nodes, fit_curve)
            merged = _merge_cocircular(chain, pieces)
            result = (chain, measure_deviation(chain, curve).max) if merged is chain else None
            if result is None:
                measured = measure_deviation(merged, curve).max
                result = (merged, measured) if measured <= tol else \
                    (chain, measure_deviation(chain, curve).max)
            cache.clear()
            cache[key] = result
        return cache[key]

    sur = _surrogate(curve, tol)
    fit_curve = sur[0].as_curve()
    spline = _fit_spline(curve, sur, tol)
    if spline is None:
        spline = _fit_spline(curve, sur, tol, anchored=False)
    if spline is not None:
        chain, measured, nodes = spline
    else:
        nodes, _ = _fit(curve, tol, "biarc", lambda nodes: build(nodes)[1], sur)
        chain, measured = build(nodes)
    line = chain.curvature == 0
    ksafe = np.where(line, 1.0, chain.curvature)
    centres = np.where(line[:, None], np.nan, chain.start + _perp(chain.tangent) / ksafe[:, None])
    sweeps = chain.sweep
    return ArcDiscretisation(
        params=nodes, starts=chain.start, ends=chain.end, centres=centres,
        radii=np.where(line, np.inf, 1.0 / np.abs(ksafe)), sweeps=sweeps,
        bulges=np.tan(sweeps / 4.0), tangents=chain.tangent,
        max_deviation=float(measured), tol=tol)


# --------------------------------------------------------------------------------------
# global two-way measurement
# --------------------------------------------------------------------------------------
def _as_chain(entities) -> Chain:
    if isinstance(entities, Chain):
        return entities
    if isinstance(entities, (Discretisation, ArcDiscretisation)):
        return entities.chain()
    arr = np.asarray(entities, dtype=float)
    if arr.ndim == 2 and arr.shape[1] == 2:
        return Chain.from_polyline(arr)
    if arr.ndim == 2 and arr.shape[1] == 3:
        return Chain.from_bulges(arr)
    raise ValueError("entities must be a Chain, a discretisation, an (n, 2) polyline or "
                     f"(n, 3) (x, y, bulge) rows; got shape {arr.shape}")


def _curve_grid(curve: ParametricCurve, samples: int) -> np.ndarray:
    """About ``samples`` parameters, uniform per piece, every breakpoint included."""
    lo, hi = curve.pieces
    counts = np.maximum(8, np.ceil(samples * (hi - lo) / curve.period)).astype(int)
    parts = [lo_ + (hi_ - lo_) * np.arange(c) / c for lo_, hi_, c in zip(lo, hi, counts)]
    return np.append(np.concatenate(parts), curve.period)


def _local_maxima(values: np.ndarray, cyclic: bool, top: int) -> np.ndarray:
    """Indices of the ``top`` largest local maxima of ``values`` (largest first)."""
    left = np.roll(values, 1) if cyclic else np.concatenate([[-np.inf], values[:-1]])
    right = np.roll(values, -1) if cyclic else np.concatenate([values[1:], [-np.inf]])
    cand = np.flatnonzero((values >= left) & (values >= right))
    return cand[np.argsort(-values[cand], kind="stable")[:top]]


class _CurveProjector:
    """Closest-point queries on the exact curve.

    The foot of every query point is found by Newton iterations on a cubic
    Hermite surrogate of the dense exact samples (on both sample intervals
    touching the nearest sample, never across a breakpoint); the distance is
    then taken to the *exact* curve point at that foot, one batched call, so
    it is always an upper bound of the true distance.
    """

    def __init__(self, sur: _Surrogate):
        self.sur = sur
        self.curve = sur.curve
        self.x = sur.x
        self.n = sur.x.size - 1
        self.tree = cKDTree(sur.points[:-1])

    def __call__(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Distance from each ``x`` ``(N, 2)`` to the curve and the foot parameter."""
        _, j = self.tree.query(x)
        iv = np.stack([(j - 1) % self.n, j], axis=1)  # (N, 2)
        a, h = self.x[iv], self.x[iv + 1] - self.x[iv]
        c = self.sur.coef[:, iv]
        xx = x[:, None, :]
        u = 0.5 * h
        for _ in range(6):
            uu = u[..., None]
            p = c[0] + uu * (c[1] + uu * (c[2] + uu * c[3]))
            d = c[1] + uu * (2 * c[2] + 3 * uu * c[3])
            dd = 2 * c[2] + 6 * uu * c[3]
            r = p - xx
            g = _dot(r, d)
            hess = _dot(d, d) + _dot(r, dd)
            step = g / np.where(hess > 0, hess, np.maximum(_dot(d, d), 1e-300))
            u = np.clip(u - step, 0.0, h)
        t = a + u
        diff = xx - _points(self.curve, t)
        dist = np.hypot(diff[..., 0], diff[..., 1])
        best = dist.argmin(axis=1)
        rows = np.arange(x.shape[0])
        return dist[rows, best], t[rows, best]


def _zoom_max(f: Callable[[np.ndarray], np.ndarray], lo: np.ndarray, hi: np.ndarray,
              levels: int = 2, m: int = 33) -> np.ndarray:
    """Maximum of ``f`` on each ``[lo, hi]`` by nested sample grids (one batched call of ``f`` per level)."""
    best = np.full(lo.size, -np.inf)
    grid = np.linspace(0.0, 1.0, m)
    rows = np.arange(lo.size)
    for _ in range(levels):
        u = lo[:, None] + (hi - lo)[:, None] * grid
        v = f(u)
        j = v.argmax(axis=1)
        best = np.maximum(best, v[rows, j])
        lo, hi = u[rows, np.maximum(j - 1, 0)], u[rows, np.minimum(j + 1, m - 1)]
    return best


def measure_deviation(entities, curve: ParametricCurve, *, samples: int = 20000,
                      per_entity: int = 17, refine_top: int = 32) -> Deviation:
    """Two-way maximum distance between entities and the exact curve.

    Parameters
    ----------
    entities : Chain, Discretisation, ArcDiscretisation or array_like
        ``(n, 2)`` polyline vertices (closed implicitly) or ``(n, 3)`` rows
        ``(x, y, bulge)`` of a closed LWPOLYLINE, e.g. read back from a file.
    curve : ParametricCurve
        The exact curve.
    samples : int, optional
        Curve samples (at least 8 per entity and per piece are used).
    per_entity : int, optional
        Samples per entity, ends included.
    refine_top : int, optional
        How many of the worst local maxima of each direction are refined by
        nested sample grids.

    Returns
    -------
    Deviation
        ``max``, both one-way maxima and where the maximum occurs.

    Notes
    -----
    Curve to entities: exact point-to-line / point-to-arc distances of exact
    curve samples to the chain.  Entities to curve: every entity sample is
    projected onto the curve (Newton on a Hermite interpolant of the exact
    samples and derivatives, on both sample intervals touching the nearest
    curve sample, never across a breakpoint) and its distance taken to the
    exact curve point at the foot, an upper bound.  The worst local maxima of
    each direction are then refined by two nested grids around them.  The
    exact curve is called a fixed, small number of times (batched).
    """
    chain = _as_chain(entities)
    if chain.n == 0:
        raise ValueError("no entities to measure")
    sur = _Surrogate(curve, max(int(samples), 8 * chain.n), min_count=8)
    ts = sur.x
    q = sur.points[:-1]
    d_a, _ = chain.distance(q)
    n_t = ts.size - 1

    def g_a(t):
        return chain.distance(_points(curve, t.ravel()))[0].reshape(t.shape)

    top = _local_maxima(d_a, True, refine_top)
    lo_t = np.where(top > 0, ts[top - 1], ts[n_t - 1] - curve.period)
    hi_t = ts[top + 1]
    best_a = _zoom_max(g_a, lo_t, hi_t) if top.size else np.zeros(0)
    i_a = int(np.argmax(d_a))
    worst_a, at_a = float(d_a[i_a]), float(ts[i_a])
    if best_a.size and best_a.max() > worst_a:
        worst_a = float(best_a.max())
        at_a = float(np.mod(0.5 * (lo_t + hi_t)[best_a.argmax()], curve.period))

    proj = _CurveProjector(sur)
    x, u = chain.sample(per_entity)
    d_b, t_b = proj(x.reshape(-1, 2))
    i_b = int(np.argmax(d_b))
    worst_b, at_b = float(d_b[i_b]), float(t_b[i_b])
    d_b2 = d_b.reshape(chain.n, per_entity)
    flat = _local_maxima(d_b, False, refine_top)
    if flat.size:
        ent, ui = flat // per_entity, flat % per_entity
        u_lo = u[ent, np.maximum(ui - 1, 0)]
        u_hi = u[ent, np.minimum(ui + 1, per_entity - 1)]

        def g_b(uu):
            pts = _entity_point(chain.start[ent, None], chain.tangent[ent, None], chain.curvature[ent, None], uu)
            return proj(pts.reshape(-1, 2))[0].reshape(uu.shape)

        best_b = _zoom_max(g_b, u_lo, u_hi)
        if best_b.max() > worst_b:
            worst_b = float(best_b.max())
            at_b = float(t_b.reshape(d_b2.shape)[ent[best_b.argmax()], ui[best_b.argmax()]])
    at = at_a if worst_a >= worst_b else at_b
    return Deviation(max=max(worst_a, worst_b), curve_to_entities=worst_a,
                     entities_to_curve=worst_b, at_param=at, at_point=_points(curve, np.array([at]))[0])


def max_deviation(entities, curve: ParametricCurve, **kwargs) -> float:
    """Two-way maximum distance (mm) between entities and the exact curve.

    A shorthand for ``measure_deviation(entities, curve, **kwargs).max``; see
    :func:`measure_deviation` for the accepted ``entities``.
    """
    return measure_deviation(entities, curve, **kwargs).max
