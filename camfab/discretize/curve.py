"""The parametric-curve protocol: a plane curve ``P(t)`` smooth between breakpoints, closed or open.

A :class:`ParametricCurve` holds ``point(t)`` (and optionally ``derivative(t)``) on the parameter
interval ``[0, period]``, the *breakpoints* where its formula changes (higher derivatives, and
possibly the tangent, may jump there; ``P`` itself is continuous) and whether it is closed
(``P(period) == P(0)``, parameters wrap around).  The functions here evaluate it for the
discretisation: points for any array of parameters, one-sided derivatives at breakpoints, the smooth
piece holding a parameter, the curvature, and the closure check.
"""
from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from ..errors import CamfabError
from ..geom2d import TWO_PI, cross
from ..records import dataclass, field

__all__ = [
    "CurveError",
    "ParametricCurve",
    "points_at",
    "derivatives_at",
    "points_and_derivatives_at",
    "piece_index",
    "check_closed",
    "discontinuities",
    "curvature_at",
]


class CurveError(CamfabError, ValueError):
    """A curve that cannot be discretised: bad period or breakpoints, wrong array shapes, not closed."""



@dataclass(frozen=True)
class ParametricCurve:
    """An exact plane curve ``P(t)``, ``t`` in ``[0, period]``, smooth between breakpoints.

    Parameters
    ----------
    point : callable
        ``point(t)`` with ``t`` a ``(n,)`` float array returns the ``(n, 2)``
        points (mm).  It is called with ``t`` in ``[0, period]``.
    breakpoints : (m,) array_like
        Parameters in ``[0, period]`` where the curve's formula changes (higher
        derivatives or the tangent may jump there).  0 and ``period`` are added
        when missing; the values are sorted and de-duplicated.
    period : float, optional
        Length of the parameter interval (default 2π); for a closed curve its period.
    derivative : callable, optional
        ``derivative(t)`` returns ``dP/dt`` as ``(n, 2)``.  Without it the
        derivative is taken by finite differences that never cross a breakpoint.
    closed : bool, optional
        True (default) for a closed curve: ``P(period)`` equals ``P(0)`` and
        parameters outside ``[0, period]`` wrap around.
    point_and_derivative : callable, optional
        ``point_and_derivative(t)`` returns ``(point(t), derivative(t))`` from one evaluation, for a curve whose
        two share their work (a cam profile: one motion evaluation instead of two).  Its values must be those of
        ``point`` and ``derivative`` exactly; used only together with ``derivative``
        (:func:`points_and_derivatives_at`).

    Raises
    ------
    CurveError
        A period that is not a positive finite number, or breakpoints outside ``[0, period]``.
    """

    point: Callable[[np.ndarray], np.ndarray]
    breakpoints: np.ndarray = field(default_factory=lambda: np.array([0.0, TWO_PI]))
    period: float = TWO_PI
    derivative: Callable[[np.ndarray], np.ndarray] | None = None
    closed: bool = True
    point_and_derivative: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]] | None = None

    def __post_init__(self) -> None:
        period = float(self.period)
        if not (math.isfinite(period) and period > 0.0):
            raise CurveError(f"period must be a positive finite number, got {self.period!r}")
        bp = np.asarray(self.breakpoints, dtype=float).ravel()
        if not np.all(np.isfinite(bp)):
            raise CurveError(f"breakpoints must be finite, got {bp!r}")
        if bp.size and (bp.min() < -1e-12 * period or bp.max() > period * (1 + 1e-12)):
            raise CurveError(f"breakpoints must lie in [0, period={period}], got {bp.min():g} … {bp.max():g}")
        bp = np.unique(np.concatenate([[0.0], np.clip(bp, 0.0, period), [period]]))
        keep = np.concatenate([[True], np.diff(bp) > 1e-12 * period])
        bp = bp[keep]
        bp[-1] = period
        object.__setattr__(self, "period", period)
        object.__setattr__(self, "breakpoints", bp)
        object.__setattr__(self, "closed", bool(self.closed))

    @property
    def pieces(self) -> tuple[np.ndarray, np.ndarray]:
        """``(lo, hi)`` parameter bounds ``(m - 1,)`` of the smooth pieces between breakpoints."""
        return self.breakpoints[:-1], self.breakpoints[1:]


def _inside(curve: ParametricCurve, flat: np.ndarray) -> np.ndarray:
    """Parameters outside ``[0, period]`` wrapped around (closed curve) or clamped to the ends (open)."""
    outside = (flat < 0.0) | (flat > curve.period)
    if outside.any():
        inside = np.mod(flat, curve.period) if curve.closed else np.clip(flat, 0.0, curve.period)
        flat = np.where(outside, inside, flat)
    return flat


def _checked(values, n: int, what: str, fix: str) -> np.ndarray:
    """A user function's ``(n, 2)`` result as floats (a :class:`CurveError` for any other shape)."""
    v = np.asarray(values, dtype=float)
    if v.shape != (n, 2):
        raise CurveError(f"curve.{what} must return an (n, 2) array, got shape {v.shape}; return {fix}")
    return v


def points_at(curve: ParametricCurve, t) -> np.ndarray:
    """``P(t)`` (mm) for any array shape of ``t``: ``t.shape + (2,)``.

    Parameters outside ``[0, period]`` wrap around on a closed curve and are clamped to the ends of
    an open one.

    Raises
    ------
    CurveError
        If ``curve.point`` does not return an ``(n, 2)`` array.
    """
    t = np.asarray(t, dtype=float)
    flat = _inside(curve, t.ravel())
    return _checked(curve.point(flat), flat.size, "point", "np.column_stack([x, y])").reshape(t.shape + (2,))


def _near_ends(t, lo, hi):
    """Where :func:`derivatives_at` extrapolates: the parameters within ``2δ`` of their piece's ends, and the two
    inner parameters ``t1``, ``t2`` it extrapolates from."""
    width = hi - lo
    # δ = 1e-7 of the piece, but at least a few ulps of the parameter (a piece 1e-9° wide would
    # otherwise put t1 and t2 on the same float) and at most an eighth of the piece
    ulps = 8 * np.spacing(np.maximum(np.abs(lo), np.abs(hi)))
    delta = np.minimum(np.maximum(1e-7 * width, ulps), width / 8)
    near_lo = t - lo < 2 * delta
    near_hi = (hi - t < 2 * delta) & ~near_lo
    near = near_lo | near_hi
    base = np.where(near_lo, lo, hi)[near]
    side = np.where(near_lo, 1.0, -1.0)[near]
    return near, base + side * 2 * delta[near], base + side * 4 * delta[near]


def _one_sided(t, near, t1, t2, vals) -> np.ndarray:
    """The derivatives at ``t`` from ``vals`` (the curve's derivative at ``t``, ``t1``, ``t2`` in a row): those
    near a piece end extrapolated linearly from ``t1``, ``t2`` inside it."""
    out = vals[:t.size]
    if near.any():
        d1, d2 = vals[t.size:t.size + t1.size], vals[t.size + t1.size:]
        step = t2 - t1
        frac = np.where(step != 0, (t[near] - t1) / np.where(step != 0, step, 1.0), 0.0)[:, None]
        out[near] = d1 + frac * (d2 - d1)
    return out


def points_and_derivatives_at(curve: ParametricCurve, x, t, lo, hi) -> tuple[np.ndarray, np.ndarray]:
    """``(points_at(curve, x), derivatives_at(curve, t, lo, hi))`` (``x`` and ``t`` 1-D; ``x`` None: at ``t``, whose
    points then come from the same parameters as its derivatives), from one evaluation when the curve has
    ``point_and_derivative`` (the same values: its contract), else from the two."""
    if curve.point_and_derivative is None or curve.derivative is None:
        return points_at(curve, t if x is None else x), derivatives_at(curve, t, lo, hi)
    t, lo, hi = (np.asarray(v, dtype=float).ravel() for v in np.broadcast_arrays(t, lo, hi))
    at_t = x is None
    x = np.empty(0) if at_t else _inside(curve, np.asarray(x, dtype=float).ravel())
    near, t1, t2 = _near_ends(t, lo, hi)
    p, d = curve.point_and_derivative(np.concatenate([x, _inside(curve, t), t1, t2]))
    n = x.size + t.size + t1.size + t2.size
    p = _checked(p, n, "point_and_derivative", "(points, derivatives), each np.column_stack([x, y])")
    d = _checked(d, n, "point_and_derivative", "(points, derivatives), each np.column_stack([x, y])")
    return p[:t.size] if at_t else p[:x.size], _one_sided(t, near, t1, t2, d[x.size:])


def derivatives_at(curve: ParametricCurve, t, lo, hi) -> np.ndarray:
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
        near, t1, t2 = _near_ends(t, lo, hi)
        vals = _checked(curve.derivative(np.concatenate([t, t1, t2])), t.size + t1.size + t2.size, "derivative",
                        "np.column_stack([dx, dy])")  # one call: user functions may be costly
        return _one_sided(t, near, t1, t2, vals).reshape(shape + (2,))
    h = np.minimum(1e-6 * curve.period, width / 8.0)
    fwd = t - h < lo
    bwd = (t + h > hi) & ~fwd
    sgn = np.where(bwd, -1.0, 1.0)
    hs = sgn * h
    cen = ~(fwd | bwd)
    # one call for every stencil: central (t - h, t + h) or one-sided (t, t ± h, t ± 2h)
    p = points_at(curve, np.concatenate([np.where(cen, t - h, t), t + hs, t + 2 * hs]))
    p0, p1, p2 = p[:t.size], p[t.size:2 * t.size], p[2 * t.size:]
    out = np.where(cen[:, None], (p1 - p0) / (2 * h[:, None]), (-3 * p0 + 4 * p1 - p2) / (2 * hs[:, None]))
    return out.reshape(shape + (2,))


def piece_index(curve: ParametricCurve, t: np.ndarray) -> np.ndarray:
    """Index of the piece containing each ``t`` (a value on a breakpoint goes right); shape of ``t``."""
    bp = curve.breakpoints
    return np.clip(np.searchsorted(bp, t, side="right") - 1, 0, bp.size - 2)


def check_closed(curve: ParametricCurve, tol: float) -> None:
    """Raise :class:`CurveError` unless a closed curve's ends meet within ``tol / 100`` mm."""
    if not curve.closed:
        return
    gap = points_at(curve, np.array([0.0, curve.period]))
    if np.hypot(*(gap[1] - gap[0])) > 0.01 * tol:
        raise CurveError(f"the curve is not closed: |P(period) - P(0)| = {np.hypot(*(gap[1] - gap[0])):.3g} mm; "
                         "make P(period) equal P(0), or pass closed=False")


def curvature_at(curve: ParametricCurve, t) -> np.ndarray:
    """Signed curvature (1/mm, > 0 turning counter-clockwise) at parameters ``t`` ``(n,)``.

    ``κ = (P′ × P″) / |P′|³`` with ``P′`` from :func:`derivatives_at` and ``P″`` its central
    difference inside the smooth piece holding ``t`` (one-sided at a breakpoint, whose curvature is
    the one of the piece to its right).
    """
    t = np.asarray(t, dtype=float).ravel()
    piece = piece_index(curve, t)
    lo, hi = curve.breakpoints[piece], curve.breakpoints[piece + 1]
    h = 1e-4 * (hi - lo)
    a, b = np.maximum(t - h, lo), np.minimum(t + h, hi)
    d = derivatives_at(curve, np.concatenate([t, a, b]), np.tile(lo, 3), np.tile(hi, 3))
    d1, da, db = d[:t.size], d[t.size:2 * t.size], d[2 * t.size:]
    d2 = (db - da) / (b - a)[:, None]
    speed = np.hypot(d1[:, 0], d1[:, 1])
    return cross(d1, d2) / speed ** 3


def discontinuities(curve: ParametricCurve, tol: float) -> list[tuple[float, float]]:
    """The breakpoints where ``P`` itself jumps by more than ``tol / 100`` mm (the protocol wants it
    continuous): ``(parameter, gap in mm)`` each, the closure of a closed curve included.

    Both one-sided limits are extrapolated from inside their pieces (a curve may give either side's value at
    the breakpoint itself), each from two samples at most a quarter of its piece away."""
    bp = np.asarray(curve.breakpoints, dtype=float)
    inner = np.flatnonzero((bp > 0) & (bp < curve.period))
    ends = [bp.size - 1] if curve.closed else []
    k = np.concatenate([inner, ends]).astype(int)
    if k.size == 0:
        return []
    at = bp[k]
    width = np.diff(bp)
    w_left = width[k - 1]
    w_right = width[np.where(k == bp.size - 1, 0, k)]  # the closure: the first piece is to the right
    floor = 4 * np.spacing(np.maximum(at, 1.0))
    h_l = np.maximum(np.minimum(1e-9 * curve.period, w_left / 4), floor)
    h_r = np.maximum(np.minimum(1e-9 * curve.period, w_right / 4), floor)
    right_at = np.where(k == bp.size - 1, 0.0, at)
    left = 2.0 * points_at(curve, at - h_l) - points_at(curve, at - 2.0 * h_l)  # O(h²)
    right = 2.0 * points_at(curve, right_at + h_r) - points_at(curve, right_at + 2.0 * h_r)
    gap = np.hypot(*(right - left).T)
    return [(float(t), float(g)) for t, g in zip(at, gap, strict=True) if g > 0.01 * tol]
