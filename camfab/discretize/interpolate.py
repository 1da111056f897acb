"""Interpolating discretisations on adaptive node grids: chords or biarcs through exact curve points.

Used by :func:`~camfab.discretize.fit.polyline` (chords) and as the fallback of
:func:`~camfab.discretize.fit.arcs` (interpolating biarcs, when the free arc spline of
:mod:`camfab.discretize.arcspline` does not fit).  Every parameter interval of a node grid gets its
own entities (one chord, or a biarc with the exact one-sided end tangents), whose two-way deviation
from the interval's curve is measured (samples plus a golden-section maximisation in each
direction); intervals above the target are split, a grid equidistributing the measured errors is
tried once, and the finished result is verified globally by the caller's ``verify``.
"""
from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from ..errors import GeometryError
from ..geom2d import cross, dot, unit
from .chain import Chain
from .curve import ParametricCurve, derivatives_at, discontinuities, piece_index, points_at
from .entities import MAX_TURNING_RAD, biarc, entity_distance, entity_point
from .surrogate import HermiteSurrogate, fit_surrogate
from .tolerance import MARGIN, within

__all__ = ["fit_grid", "biarc_chain"]


#: interior curve samples per interval and samples per entity used while fitting
_CURVE_SAMPLES = 24
_ENTITY_SAMPLES = 17
#: golden-section iterations of every local maximisation
_GOLDEN_ITERS = 16
#: Gauss-Newton steps of a projection onto the curve
_PROJECT_ITERS = 4
#: the biarc tangent-length ratio d1/d2 is searched in exp(±this)
_LOG_RATIO_BOUND = 1.5
#: intervals measured per vectorised block (bounds memory)
_BLOCK = 2048
_MAX_ROUNDS = 80
_INV_PHI = (math.sqrt(5.0) - 1.0) / 2.0


def _project(curve: ParametricCurve, x: np.ndarray, t0: np.ndarray, a: np.ndarray,
             b: np.ndarray, lo: np.ndarray, hi: np.ndarray,
             iters: int = _PROJECT_ITERS) -> np.ndarray:
    """Parameter of the point of ``P([a, b])`` closest to ``x`` (Gauss-Newton).

    Starts from ``t0`` (a nearby sample), stays in ``[a, b]`` (inside the
    smooth piece ``[lo, hi]``).  The result is a curve point, so the distance
    to it is always an upper bound of the distance to the curve.
    """
    t = np.clip(t0, a, b)
    for _ in range(iters):
        r = points_at(curve, t) - x
        d = derivatives_at(curve, t, lo, hi)
        dd = np.einsum("...i,...i->...", d, d)
        step = np.einsum("...i,...i->...", r, d) / np.where(dd > 0, dd, 1.0)
        t = np.clip(t - step, a, b)
    return t


def _golden_min(f: Callable[[np.ndarray], np.ndarray], lo: np.ndarray, hi: np.ndarray,
                iters: int = _GOLDEN_ITERS) -> tuple[np.ndarray, np.ndarray]:
    """Vectorised golden-section search on each ``[lo, hi]``: the argument minimising ``f`` and the
    smallest value of ``f`` met on the way."""
    a, b = lo.astype(float), hi.astype(float)
    c = b - _INV_PHI * (b - a)
    d = a + _INV_PHI * (b - a)
    fc, fd = f(c), f(d)
    best = np.minimum(fc, fd)
    for _ in range(iters):
        left = fc < fd
        b = np.where(left, d, b)
        a = np.where(left, a, c)
        x = np.where(left, b - _INV_PHI * (b - a), a + _INV_PHI * (b - a))
        fx = f(x)
        best = np.minimum(best, fx)
        c, d, fc, fd = (np.where(left, x, d), np.where(left, c, x),
                        np.where(left, fx, fd), np.where(left, fc, fx))
    return np.where(fc < fd, c, d), best


def _golden_max(f: Callable[[np.ndarray], np.ndarray], lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """The largest value of ``f`` a golden-section search finds on each ``[lo, hi]``."""
    return -_golden_min(lambda t: -f(t), lo, hi)[1]


def _interval_entities(curve: ParametricCurve, a, b, lo, hi, kind: str, pa=None, pb=None) -> dict:
    """Entities of each interval ``[a, b]``: arrays with a leading ``(n, E)`` shape.

    ``kind`` is ``"line"`` (one chord, E = 1) or ``"biarc"`` (E = 2: a
    biarc through the end points with the exact one-sided end tangents; the
    ratio of its tangent lengths minimises, by golden-section search, the
    largest distance from the curve samples of the interval to the biarc).
    ``pa``, ``pb`` may pass ``P(a)``, ``P(b)`` already evaluated.
    """
    pa = points_at(curve, a) if pa is None else pa
    pb = points_at(curve, b) if pb is None else pb
    if kind == "line":
        w = pb - pa
        length = np.hypot(w[:, 0], w[:, 1])
        return dict(s=pa[:, None], T=unit(w)[:, None], k=np.zeros((a.size, 1)),
                    ell=length[:, None], e=pb[:, None], valid=length > 0)
    ta = unit(derivatives_at(curve, a, lo, hi))
    tb = unit(derivatives_at(curve, b, lo, hi))
    frac = np.arange(1, _CURVE_SAMPLES + 1) / (_CURVE_SAMPLES + 1)
    q = points_at(curve, a[:, None] + (b - a)[:, None] * frac)

    def proxy(log_r):
        ent = biarc(pa, ta, pb, tb, np.exp(log_r))
        d = entity_distance(q[:, :, None], *(ent[key][:, None] for key in ("s", "T", "k", "ell", "e")))
        return np.where(ent["valid"], d.min(axis=-1).max(axis=-1), np.inf)

    bound = np.full(a.size, _LOG_RATIO_BOUND)
    log_r = _golden_min(proxy, -bound, bound)[0]
    log_r = np.where(proxy(log_r) < proxy(np.zeros(a.size)), log_r, 0.0)
    return biarc(pa, ta, pb, tb, np.exp(log_r))


def _measure_block(curve: ParametricCurve, a, b, lo, hi, ent: dict) -> np.ndarray:
    """Two-way maximum deviation of each interval's entities from ``P([a, b])``.

    Curve to entities: interior curve samples, distance to the interval's own
    entities, then a golden-section maximisation around the worst sample.
    Entities to curve: entity samples projected onto ``P([a, b])`` by
    Gauss-Newton from the nearest curve sample, then a golden-section
    maximisation along the worst entity.  Both are upper bounds of the
    distances to the whole chain / curve.
    """
    n = a.size
    rows = np.arange(n)
    s, T, k, ell, e = ent["s"], ent["T"], ent["k"], ent["ell"], ent["e"]
    m = _CURVE_SAMPLES
    frac = np.arange(1, m + 1) / (m + 1)
    tfull = np.concatenate([a[:, None], a[:, None] + (b - a)[:, None] * frac, b[:, None]], axis=1)
    qfull = points_at(curve, tfull)
    d_a = entity_distance(qfull[:, 1:-1, None], s[:, None], T[:, None], k[:, None],
                           ell[:, None], e[:, None]).min(axis=-1)
    j = d_a.argmax(axis=1)

    def g_a(t):
        return entity_distance(points_at(curve, t)[:, None], s, T, k, ell, e).min(axis=-1)

    worst_a = np.maximum(d_a.max(axis=1), _golden_max(g_a, tfull[rows, j], tfull[rows, j + 2]))

    n_ent = k.shape[1]
    me = _ENTITY_SAMPLES
    uf = np.linspace(0.0, 1.0, me)
    x = entity_point(s[:, :, None], T[:, :, None], k[:, :, None], ell[:, :, None] * uf)
    x = x.reshape(n, n_ent * me, 2)
    d2 = ((x[:, :, None, :] - qfull[:, None, :, :]) ** 2).sum(axis=-1)
    t0 = np.take_along_axis(tfull, d2.argmin(axis=-1), axis=1)
    bb = lambda z: np.broadcast_to(z[:, None], t0.shape)  # noqa: E731
    tp = _project(curve, x, t0, bb(a), bb(b), bb(lo), bb(hi))
    diff = x - points_at(curve, tp)
    d_b = np.hypot(diff[..., 0], diff[..., 1])
    jb = d_b.argmax(axis=1)
    ei, ui = jb // me, jb % me
    t_best = tp[rows, jb]
    s_i, T_i, k_i, l_i = s[rows, ei], T[rows, ei], k[rows, ei], ell[rows, ei]

    def g_b(u):
        pts = entity_point(s_i, T_i, k_i, u)
        tt = _project(curve, pts, t_best, a, b, lo, hi, iters=3)
        dd = pts - points_at(curve, tt)
        return np.hypot(dd[:, 0], dd[:, 1])

    u_lo = l_i * uf[np.maximum(ui - 1, 0)]
    u_hi = l_i * uf[np.minimum(ui + 1, me - 1)]
    worst_b = np.maximum(d_b.max(axis=1), _golden_max(g_b, u_lo, u_hi))
    dev = np.maximum(worst_a, worst_b)
    return np.where(ent["valid"], dev, np.inf)


def _measure_intervals(curve: ParametricCurve, a: np.ndarray, b: np.ndarray, kind: str) -> np.ndarray:
    """Measured deviation of every interval ``[a_i, b_i]`` (vectorised in blocks)."""
    out = np.empty(a.size)
    pieces = piece_index(curve, 0.5 * (a + b))
    lo_all, hi_all = curve.breakpoints[pieces], curve.breakpoints[pieces + 1]
    for c in range(0, a.size, _BLOCK):
        sl = slice(c, c + _BLOCK)
        ent = _interval_entities(curve, a[sl], b[sl], lo_all[sl], hi_all[sl], kind)
        with np.errstate(invalid="ignore", divide="ignore"):
            out[sl] = _measure_block(curve, a[sl], b[sl], lo_all[sl], hi_all[sl], ent)
    return out


def _piece_samples(curve: ParametricCurve, lo: float, hi: float, m: int = 129):
    t = np.linspace(lo, hi, m)
    return t, points_at(curve, t)


def _turning(p: np.ndarray) -> float:
    """Total absolute turning of the polygon through ``p`` (radians)."""
    w = np.diff(p, axis=0)
    w = w[np.hypot(w[:, 0], w[:, 1]) > 0]
    if w.shape[0] < 2:
        return 0.0
    return float(np.abs(np.arctan2(cross(w[:-1], w[1:]), dot(w[:-1], w[1:]))).sum())


def _place(lo: float, hi: float, t: np.ndarray, density: np.ndarray, n: int) -> np.ndarray:
    """``n`` intervals on ``[lo, hi]`` equidistributing the piecewise-constant ``density``."""
    cum = np.concatenate([[0.0], np.cumsum(density * np.diff(t))])
    if not (cum[-1] > 0):
        return np.linspace(lo, hi, n + 1)
    nodes = np.interp(np.linspace(0.0, cum[-1], n + 1), cum, t)
    nodes[0], nodes[-1] = lo, hi
    return nodes


def _initial_grid(curve: ParametricCurve, target: float, kind: str) -> np.ndarray:
    """A starting grid per smooth piece (breakpoints always included).

    Lines: the chord-error estimate ``L²κ/8 = target`` sets the local step
    from the curvature of a 129-point sample of the piece.  Biarcs: uniform
    steps turning at most :data:`MAX_TURNING_RAD`.  Both keep at least that
    turning bound.
    """
    grids: list[np.ndarray] = []
    for lo, hi in zip(*curve.pieces, strict=True):
        t, p = _piece_samples(curve, float(lo), float(hi))
        n_min = max(1, math.ceil(_turning(p) / MAX_TURNING_RAD))
        if kind == "line":
            w = np.diff(p, axis=0)
            seg = np.hypot(w[:, 0], w[:, 1])
            turn = np.abs(np.arctan2(cross(w[:-1], w[1:]), dot(w[:-1], w[1:])))
            kappa = turn / np.maximum(0.5 * (seg[:-1] + seg[1:]), 1e-300)
            kappa = np.concatenate([[kappa[0]], np.maximum(kappa[:-1], kappa[1:]), [kappa[-1]]])
            speed = seg / np.diff(t)
            density = speed * np.sqrt(kappa / (8.0 * target))  # intervals per unit parameter
            n = max(n_min, math.ceil(float((density * np.diff(t)).sum())))
            grids.append(_place(float(lo), float(hi), t, density, n)[:-1])
        else:
            grids.append(np.linspace(float(lo), float(hi), n_min + 1)[:-1])
    grids.append(np.array([curve.period]))
    return np.concatenate(grids)


def _refine(curve: ParametricCurve, nodes: np.ndarray, target: float, kind: str,
            dev: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Split intervals whose measured deviation exceeds ``target`` until none does.

    An interval is bisected, or cut into ``k`` equal parts when its measured
    error says one halving cannot suffice (``k ≈ (dev/target)^(1/p)``, p = 2
    for chords, 3 for biarcs).  Measurements of untouched intervals are kept.
    """
    power = 2.0 if kind == "line" else 3.0
    dev = np.full(nodes.size - 1, np.nan) if dev is None else dev.copy()
    for _ in range(_MAX_ROUNDS):
        todo = np.flatnonzero(np.isnan(dev))
        if todo.size:
            dev[todo] = _measure_intervals(curve, nodes[:-1][todo], nodes[1:][todo], kind)
        bad = dev > target
        if not bad.any():
            return nodes, dev
        width = np.diff(nodes)
        if np.any(width[bad] < 1e-12 * curve.period):
            where = nodes[:-1][bad & (width < 1e-12 * curve.period)][0]
            raise GeometryError(f"cannot reach the tolerance near parameter {where:.9g}: "
                               "is the curve continuous there?")
        ratio = np.where(np.isfinite(dev), dev / target, 8.0)
        parts = np.where(bad, np.clip(np.ceil(1.05 * ratio ** (1.0 / power)), 2, 16), 1).astype(int)
        a = np.repeat(nodes[:-1], parts)
        w = np.repeat(width, parts)
        group_start = np.repeat(np.cumsum(parts) - parts, parts)
        j = np.arange(a.size) - group_start
        nodes = np.append(a + w * j / np.repeat(parts, parts), curve.period)
        dev = np.repeat(np.where(bad, np.nan, dev), parts)
    raise GeometryError(f"the discretisation did not converge within {_MAX_ROUNDS} rounds of refinement: a curve "
                        "with a cusp, or one that crosses itself, cannot be followed (camfab check reports such a "
                        "profile as CUSP or UNDERCUT); otherwise try a larger tolerance")


def _equidistribute(curve: ParametricCurve, nodes: np.ndarray, dev: np.ndarray, target: float,
                    kind: str, fill: float) -> np.ndarray:
    """A new grid with the measured error spread evenly (each interval at ``fill·target``).

    Uses the measured deviations of a converged grid as the local error model
    ``dev ∝ h^p``; keeps the turning bound of the initial grid.
    """
    power = 2.0 if kind == "line" else 3.0
    share = np.maximum((np.maximum(dev, 0.0) / (fill * target)) ** (1.0 / power), 1e-6)
    grids: list[np.ndarray] = []
    for lo, hi in zip(*curve.pieces, strict=True):
        sel = (nodes[:-1] >= lo) & (nodes[:-1] < hi)
        t = np.append(nodes[:-1][sel], hi)
        _, p = _piece_samples(curve, float(lo), float(hi))
        n_min = max(1, math.ceil(_turning(p) / MAX_TURNING_RAD))
        n = max(n_min, math.ceil(float(share[sel].sum())))
        grids.append(_place(float(lo), float(hi), t, share[sel] / np.diff(t), n)[:-1])
    grids.append(np.array([curve.period]))
    return np.concatenate(grids)


def fit_grid(curve: ParametricCurve, tol: float, kind: str, verify: Callable[[np.ndarray], float],
             surrogate: tuple[HermiteSurrogate, float] | None = None) -> tuple[np.ndarray, float]:
    """Adaptive grid for ``kind`` within ``tol``: initial grid, refinement, one re-spread.

    ``verify(nodes)`` measures the finished result globally; should it exceed
    ``tol`` the target is tightened and refinement resumes.  Returns the nodes and the measured
    deviation.  ``surrogate``: the curve's Hermite stand-in and its error, when already built.
    """
    sur, sur_err = surrogate or fit_surrogate(curve, tol)
    target = tol * (1.0 - MARGIN) - sur_err
    if not target > 0:  # no stand-in within the tolerance: the curve jumps (or is not finite) somewhere
        gaps = discontinuities(curve, tol)
        where = f": P jumps by {gaps[0][1]:.3g} mm at parameter {gaps[0][0]:.9g}" if gaps else ""
        raise GeometryError(f"the curve cannot be followed within {tol:g} mm{where} (a discretised curve must be "
                            "continuous)")
    curve = sur.as_curve()  # fitting never calls the exact curve; verify() measures on it
    nodes, dev = _refine(curve, _initial_grid(curve, target, kind), target, kind)
    for fill in (0.9,):
        alt, alt_dev = _refine(curve, _equidistribute(curve, nodes, dev, target, kind, fill),
                               target, kind)
        if alt.size < nodes.size:
            nodes, dev = alt, alt_dev
    for _ in range(6):
        measured = verify(nodes)
        if within(measured, tol):
            return nodes, measured
        target *= 0.7
        nodes, dev = _refine(curve, nodes, target, kind, dev)
    raise GeometryError(f"could not verify the tolerance {tol:g} mm (measured {measured:.3g} mm after refining): "
                        "a curve with a cusp, or one that crosses itself, cannot be followed (camfab check reports "
                        "such a profile as CUSP or UNDERCUT); otherwise try a larger tolerance")


def biarc_chain(curve: ParametricCurve, nodes: np.ndarray, fit_curve: ParametricCurve | None = None
                ) -> tuple[Chain, np.ndarray]:
    """The biarc chain of a node grid and the piece index of every entity.

    The nodes are exact points of ``curve``; tangents and biarc ratios may be
    taken from ``fit_curve`` (a surrogate of it).
    """
    a, b = nodes[:-1], nodes[1:]
    pieces = piece_index(curve, 0.5 * (a + b))
    bp = curve.breakpoints
    pts = points_at(curve, nodes)
    if curve.closed:
        pts[-1] = pts[0]  # one evaluation per node: ends[i] == starts[i + 1] bit for bit
    ent = _interval_entities(fit_curve or curve, a, b, bp[pieces], bp[pieces + 1], "biarc", pts[:-1], pts[1:])
    start = ent["s"].reshape(-1, 2)
    end = ent["e"].reshape(-1, 2)
    chain = Chain(start, ent["T"].reshape(-1, 2), ent["k"].ravel(), ent["ell"].ravel(), end)
    return chain, np.repeat(pieces, 2)
