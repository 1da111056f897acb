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
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable, Optional

import numpy as np
from scipy.spatial import cKDTree

from ..errors import GeometryError
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

    def point(self, t, piece=None) -> np.ndarray:
        t = np.asarray(t, dtype=float)
        if piece is None:
            t = np.where((t < 0) | (t > self.curve.period), np.mod(t, self.curve.period), t)
        i = self._index(t, piece)
        u = (t - self.x[i])[..., None]
        c = self.coef[:, i]
        return c[0] + u * (c[1] + u * (c[2] + u * c[3]))

    def derivative(self, t, piece=None) -> np.ndarray:
        t = np.asarray(t, dtype=float)
        if piece is None:
            t = np.where((t < 0) | (t > self.curve.period), np.mod(t, self.curve.period), t)
        i = self._index(t, piece)
        u = (t - self.x[i])[..., None]
        c = self.coef[:, i]
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
        r = _points(curve, t) - x
        d = _derivatives(curve, t, lo, hi)
        dd = np.einsum("...i,...i->...", d, d)
        step = np.einsum("...i,...i->...", r, d) / np.where(dd > 0, dd, 1.0)
        t = np.clip(t - step, a, b)
    return t


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
# per-interval measurement
# --------------------------------------------------------------------------------------
def _golden_max(f: Callable[[np.ndarray], np.ndarray], lo: np.ndarray, hi: np.ndarray,
                iters: int = _GOLDEN_ITERS) -> np.ndarray:
    """Vectorised golden-section search for the maximum of ``f`` on each ``[lo, hi]``."""
    a, b = lo.astype(float), hi.astype(float)
    c = b - _INV_PHI * (b - a)
    d = a + _INV_PHI * (b - a)
    fc, fd = f(c), f(d)
    best = np.maximum(fc, fd)
    for _ in range(iters):
        left = fc > fd
        b = np.where(left, d, b)
        a = np.where(left, a, c)
        x = np.where(left, b - _INV_PHI * (b - a), a + _INV_PHI * (b - a))
        fx = f(x)
        best = np.maximum(best, fx)
        c, d, fc, fd = (np.where(left, x, d), np.where(left, c, x),
                        np.where(left, fx, fd), np.where(left, fc, fx))
    return best


def _golden_min(f: Callable[[np.ndarray], np.ndarray], lo: np.ndarray, hi: np.ndarray,
                iters: int = _GOLDEN_ITERS) -> np.ndarray:
    """Vectorised golden-section search: the argument minimising ``f`` on each ``[lo, hi]``."""
    a, b = lo.astype(float), hi.astype(float)
    c = b - _INV_PHI * (b - a)
    d = a + _INV_PHI * (b - a)
    fc, fd = f(c), f(d)
    for _ in range(iters):
        left = fc < fd
        b = np.where(left, d, b)
        a = np.where(left, a, c)
        x = np.where(left, b - _INV_PHI * (b - a), a + _INV_PHI * (b - a))
        fx = f(x)
        c, d, fc, fd = (np.where(left, x, d), np.where(left, c, x),
                        np.where(left, fx, fd), np.where(left, fc, fx))
    return np.where(fc < fd, c, d)


def _interval_entities(curve: ParametricCurve, a, b, lo, hi, kind: str, pa=None, pb=None) -> dict:
    """Entities of each interval ``[a, b]``: arrays with a leading ``(n, E)`` shape.

    ``kind`` is ``"line"`` (one chord, E = 1) or ``"biarc"`` (E = 2: a
    biarc through the end points with the exact one-sided end tangents; the
    ratio of its tangent lengths minimises, by golden-section search, the
    largest distance from the curve samples of the interval to the biarc).
    ``pa``, ``pb`` may pass ``P(a)``, ``P(b)`` already evaluated.
    """
    pa = _points(curve, a) if pa is None else pa
    pb = _points(curve, b) if pb is None else pb
    if kind == "line":
        w = pb - pa
        length = np.hypot(w[:, 0], w[:, 1])
        return dict(s=pa[:, None], T=_unit(w)[:, None], k=np.zeros((a.size, 1)),
                    ell=length[:, None], e=pb[:, None], valid=length > 0)
    ta = _unit(_derivatives(curve, a, lo, hi))
    tb = _unit(_derivatives(curve, b, lo, hi))
    frac = np.arange(1, _CURVE_SAMPLES + 1) / (_CURVE_SAMPLES + 1)
    q = _points(curve, a[:, None] + (b - a)[:, None] * frac)

    def proxy(log_r):
        ent = _biarc(pa, ta, pb, tb, np.exp(log_r))
        d = _entity_distance(q[:, :, None], *(ent[key][:, None] for key in ("s", "T", "k", "ell", "e")))
        return np.where(ent["valid"], d.min(axis=-1).max(axis=-1), np.inf)

    bound = np.full(a.size, _LOG_RATIO_BOUND)
    log_r = _golden_min(proxy, -bound, bound)
    log_r = np.where(proxy(log_r) < proxy(np.zeros(a.size)), log_r, 0.0)
    return _biarc(pa, ta, pb, tb, np.exp(log_r))


def _biarc(pa, ta, pb, tb, ratio) -> dict:
    """The biarc from ``pa`` (tangent ``ta``) to ``pb`` (tangent ``tb``) with ``d1 = ratio·d2``.

    ``d1, d2`` are the tangent lengths of the two arcs: the control points are
    ``q0 = pa + d1·ta``, ``q1 = pb - d2·tb`` with ``|q1 - q0| = d1 + d2``, and
    the joint lies on ``q0 q1`` at ``d1`` from ``q0``.  Arrays of shape
    ``(n, E)`` with E = 2 are returned (see :func:`_interval_entities`).
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
    qfull = _points(curve, tfull)
    d_a = _entity_distance(qfull[:, 1:-1, None], s[:, None], T[:, None], k[:, None],
                           ell[:, None], e[:, None]).min(axis=-1)
    j = d_a.argmax(axis=1)

    def g_a(t):
        return _entity_distance(_points(curve, t)[:, None], s, T, k, ell, e).min(axis=-1)

    worst_a = np.maximum(d_a.max(axis=1), _golden_max(g_a, tfull[rows, j], tfull[rows, j + 2]))

    n_ent = k.shape[1]
    me = _ENTITY_SAMPLES
    uf = np.linspace(0.0, 1.0, me)
    x = _entity_point(s[:, :, None], T[:, :, None], k[:, :, None], ell[:, :, None] * uf)
    x = x.reshape(n, n_ent * me, 2)
    d2 = ((x[:, :, None, :] - qfull[:, None, :, :]) ** 2).sum(axis=-1)
    t0 = np.take_along_axis(tfull, d2.argmin(axis=-1), axis=1)
    bb = lambda z: np.broadcast_to(z[:, None], t0.shape)  # noqa: E731
    tp = _project(curve, x, t0, bb(a), bb(b), bb(lo), bb(hi))
    diff = x - _points(curve, tp)
    d_b = np.hypot(diff[..., 0], diff[..., 1])
    jb = d_b.argmax(axis=1)
    ei, ui = jb // me, jb % me
    t_best = tp[rows, jb]
    s_i, T_i, k_i, l_i = s[rows, ei], T[rows, ei], k[rows, ei], ell[rows, ei]

    def g_b(u):
        pts = _entity_point(s_i, T_i, k_i, u)
        tt = _project(curve, pts, t_best, a, b, lo, hi, iters=3)
        dd = pts - _points(curve, tt)
        return np.hypot(dd[:, 0], dd[:, 1])

    u_lo = l_i * uf[np.maximum(ui - 1, 0)]
    u_hi = l_i * uf[np.minimum(ui + 1, me - 1)]
    worst_b = np.maximum(d_b.max(axis=1), _golden_max(g_b, u_lo, u_hi))
    dev = np.maximum(worst_a, worst_b)
    return np.where(ent["valid"], dev, np.inf)


def _measure_intervals(curve: ParametricCurve, a: np.ndarray, b: np.ndarray, kind: str) -> np.ndarray:
    """Measured deviation of every interval ``[a_i, b_i]`` (vectorised in blocks)."""
    out = np.empty(a.size)
    pieces = _piece_index(curve, 0.5 * (a + b))
    lo_all, hi_all = curve.breakpoints[pieces], curve.breakpoints[pieces + 1]
    for c in range(0, a.size, _BLOCK):
        sl = slice(c, c + _BLOCK)
        ent = _interval_entities(curve, a[sl], b[sl], lo_all[sl], hi_all[sl], kind)
        with np.errstate(invalid="ignore", divide="ignore"):
            out[sl] = _measure_block(curve, a[sl], b[sl], lo_all[sl], hi_all[sl], ent)
    return out


# --------------------------------------------------------------------------------------
# grids and refinement
# --------------------------------------------------------------------------------------
def _piece_samples(curve: ParametricCurve, lo: float, hi: float, m: int = 129):
    t = np.linspace(lo, hi, m)
    return t, _points(curve, t)


def _turning(p: np.ndarray) -> float:
    """Total absolute turning of the polygon through ``p`` (radians)."""
    w = np.diff(p, axis=0)
    w = w[np.hypot(w[:, 0], w[:, 1]) > 0]
    if w.shape[0] < 2:
        return 0.0
    return float(np.abs(np.arctan2(_cross(w[:-1], w[1:]), _dot(w[:-1], w[1:]))).sum())


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
    grids = []
    for lo, hi in zip(*curve.pieces):
        t, p = _piece_samples(curve, float(lo), float(hi))
        n_min = max(1, math.ceil(_turning(p) / MAX_TURNING_RAD))
        if kind == "line":
            w = np.diff(p, axis=0)
            seg = np.hypot(w[:, 0], w[:, 1])
            turn = np.abs(np.arctan2(_cross(w[:-1], w[1:]), _dot(w[:-1], w[1:])))
            kappa = turn / np.maximum(0.5 * (seg[:-1] + seg[1:]), 1e-300)
            kappa = np.concatenate([[kappa[0]], np.maximum(kappa[:-1], kappa[1:]), [kappa[-1]]])
            speed = seg / np.diff(t)
            density = speed * np.sqrt(kappa / (8.0 * target))  # intervals per unit parameter
            n = max(n_min, math.ceil(float((density * np.diff(t)).sum())))
            grids.append(_place(float(lo), float(hi), t, density, n)[:-1])
        else:
            grids.append(np.linspace(float(lo), float(hi), n_min + 1)[:-1])
    grids.append([curve.period])
    return np.concatenate(grids)


def _refine(curve: ParametricCurve, nodes: np.ndarray, target: float, kind: str,
            dev: Optional[np.ndarray] = None) -> tuple[np.ndarray, np.ndarray]:
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
    raise GeometryError("the discretisation did not converge: the curve may have a cusp or cross itself "
                        "(an undercut profile cannot be exported)")


def _equidistribute(curve: ParametricCurve, nodes: np.ndarray, dev: np.ndarray, target: float,
                    kind: str, fill: float) -> np.ndarray:
    """A new grid with the measured error spread evenly (each interval at ``fill·target``).

    Uses the measured deviations of a converged grid as the local error model
    ``dev ∝ h^p``; keeps the turning bound of the initial grid.
    """
    power = 2.0 if kind == "line" else 3.0
    share = np.maximum((np.maximum(dev, 0.0) / (fill * target)) ** (1.0 / power), 1e-6)
    grids = []
    for lo, hi in zip(*curve.pieces):
        sel = (nodes[:-1] >= lo) & (nodes[:-1] < hi)
        t = np.append(nodes[:-1][sel], hi)
        _, p = _piece_samples(curve, float(lo), float(hi))
        n_min = max(1, math.ceil(_turning(p) / MAX_TURNING_RAD))
        n = max(n_min, math.ceil(float(share[sel].sum())))
        grids.append(_place(float(lo), float(hi), t, share[sel] / np.diff(t), n)[:-1])
    grids.append([curve.period])
    return np.concatenate(grids)


def _fit(curve: ParametricCurve, tol: float, kind: str, verify: Callable[[np.ndarray], float],
         sur: Optional[tuple] = None):
    """Adaptive grid for ``kind`` within ``tol``: initial grid, refinement, one re-spread.

    ``verify(nodes)`` measures the finished result globally; should it exceed
    ``tol`` the target is tightened and refinement resumes.
    """
    sur, sur_err = sur or _surrogate(curve, tol)
    curve = sur.as_curve()  # fitting never calls the exact curve; verify() measures on it
    target = tol * (1.0 - MARGIN) - sur_err
    nodes, dev = _refine(curve, _initial_grid(curve, target, kind), target, kind)
    for fill in (0.9,):
        alt, alt_dev = _refine(curve, _equidistribute(curve, nodes, dev, target, kind, fill),
                               target, kind)
        if alt.size < nodes.size:
            nodes, dev = alt, alt_dev
    for _ in range(6):
        measured = verify(nodes)
        if measured <= tol:
            return nodes, measured
        target *= 0.7
        nodes, dev = _refine(curve, nodes, target, kind, dev)
    raise GeometryError(f"could not verify the tolerance {tol:g} mm (measured {measured:.3g} mm): the curve "
                        "may have a cusp or cross itself (an undercut profile cannot be exported)")


# --------------------------------------------------------------------------------------
# free G1 arc splines (non-interpolating): the arcs stay inside the ±tol band
# --------------------------------------------------------------------------------------
#: model samples per arc of the free arc spline, and Lawson (minimax) iterations of its start
_SPLINE_SAMPLES = 16
#: the free spline's model deviation aims at this fraction of tol (less the surrogate error)
_SPLINE_FILL = 0.97
#: fewest model samples of one span
_SPLINE_MIN_GRID = 129
#: the first arc count tried is this multiple of the asymptotic estimate
_EST_FACTOR = 1.0
#: one arc fewer is tried while the predicted error (∝ 1/m³) stays below this multiple of the target
_DOWN_SLACK = 1.2
_LAWSON_ITERS = 8
#: Gauss-Newton rounds equalising the arc errors (knots and curvatures together)
_EQUI_ITERS = 8
#: most arcs of one free span: a longer smooth piece is cut into spans joined G1 at (surrogate)
#: curve points with the curve's tangent, which keeps every linear system small
_SPLINE_SPAN = 40
#: a span is only fitted up to this many arcs (else interpolating biarcs are used)
_SPAN_MAX_ARCS = 64
#: relative lengths of the two end arcs at each clamped end of a piece (an LP over C¹ patterns:
#: a clamped end then costs about half an arc instead of tripling the error of uniform arcs)
_END_ARCS = (0.6, 1.0)
#: further end-arc ratios tried at the smallest failing arc count (the optimum is not monotone in it)
_END_ARCS_ALT = ((0.7, 1.1),)
#: refits of the spans where the measured chain exceeds tol
_SPAN_REFITS = 4
#: relative lengths of the two end arcs at an end whose arc curvature is fixed (next to a dwell: the
#: arc matches the curve to second order there, so it is kept shorter)
_FIXED_END_ARCS = (0.35, 0.9)
#: further fixed-end ratios tried at the smallest failing count (none: they rarely paid for their time)
_FIXED_END_ARCS_ALT: tuple = ()
#: a breakpoint whose one-sided tangents differ by less than this (radians) is G1 (arcs may run across it)
_G1_RAD = 1e-6


def _span_model(sur: _Surrogate, segs, n_grid: int, curvature: bool = False):
    """Arc length, tangent angle (and curvature) of the surrogate along a span.

    ``segs`` lists ``(piece, lo, hi)`` parameter ranges of consecutive smooth pieces joined G1; the
    grid points are shared out by parameter length, every junction appearing twice (its one-sided
    values: the curvature may jump there)."""
    total = sum(hi - lo for _, lo, hi in segs)
    ts, ss, ths, ks = [], [], [], []
    s_off, th_off = 0.0, None
    for piece, lo, hi in segs:
        n = max(5, int(round(n_grid * (hi - lo) / total)) + 1) if len(segs) > 1 else n_grid
        t = np.linspace(lo, hi, n)
        tm = 0.5 * (t[:-1] + t[1:])
        d = sur.derivative(t, piece)
        dm = sur.derivative(tm, piece)
        sp, spm = np.hypot(d[:, 0], d[:, 1]), np.hypot(dm[:, 0], dm[:, 1])
        sv = s_off + np.concatenate([[0.0], np.cumsum(np.diff(t) / 6.0 * (sp[:-1] + 4 * spm + sp[1:]))])
        theta = np.unwrap(np.arctan2(d[:, 1], d[:, 0]))
        if th_off is not None:
            theta = theta + TWO_PI * round((th_off - theta[0]) / TWO_PI)
        ts.append(t)
        ss.append(sv)
        ths.append(theta)
        if curvature:
            ks.append(_cross(d, sur.second_derivative(t, piece)) / np.maximum(sp, 1e-300) ** 3)
        s_off, th_off = float(sv[-1]), float(theta[-1])
    out = (np.concatenate(ts), np.concatenate(ss), np.concatenate(ths))
    return out + (np.concatenate(ks),) if curvature else out


def _cumtrapz(f: np.ndarray, s: np.ndarray) -> np.ndarray:
    ds = np.diff(s).reshape((-1,) + (1,) * (f.ndim - 1))
    return np.concatenate([np.zeros((1,) + f.shape[1:]), np.cumsum(0.5 * ds * (f[1:] + f[:-1]), axis=0)])


def _cumhermite(f: np.ndarray, fp: np.ndarray, s: np.ndarray) -> np.ndarray:
    """Cumulative integral of ``f`` (derivative ``fp``) on the grid ``s``: exact for piecewise cubics."""
    ds = np.diff(s).reshape((-1,) + (1,) * (f.ndim - 1))
    inc = 0.5 * ds * (f[1:] + f[:-1]) + ds * ds / 12.0 * (fp[:-1] - fp[1:])
    return np.concatenate([np.zeros((1,) + f.shape[1:]), np.cumsum(inc, axis=0)])


def _hermite_at(x: np.ndarray, s: np.ndarray, F: np.ndarray, f: np.ndarray, fp: np.ndarray) -> np.ndarray:
    """``F(x) = ∫₀ˣ f`` between grid points: integral of the cubic Hermite interpolant of ``f``."""
    i = np.clip(np.searchsorted(s, x, side="right") - 1, 0, s.size - 2)
    h = s[i + 1] - s[i]
    tau = np.clip((x - s[i]) / np.where(h > 0, h, 1.0), 0.0, 1.0)
    t2, t3, t4 = tau * tau, tau ** 3, tau ** 4
    w = (h * (tau - t3 + 0.5 * t4), h * h * (0.25 * t4 - 2.0 * t3 / 3.0 + 0.5 * t2),
         h * (t3 - 0.5 * t4), h * h * (0.25 * t4 - t3 / 3.0))
    return (F[i] + w[0][:, None] * f[i] + w[1][:, None] * fp[i] + w[2][:, None] * f[i + 1]
            + w[3][:, None] * fp[i + 1])


def _lawson(A: np.ndarray, b: np.ndarray, C: np.ndarray, dvec: np.ndarray, iters: int = _LAWSON_ITERS):
    """Approximately minimise ``max |A k + b|`` subject to ``C k = d`` (Lawson's reweighting)."""
    kp, *_ = np.linalg.lstsq(C, dvec, rcond=None)
    _, sv, vt = np.linalg.svd(C)
    rank = int((sv > sv[0] * 1e-12).sum()) if sv.size else 0
    Z = vt[rank:].T
    if Z.shape[1] == 0:
        return kp, A @ kp + b
    AZ = A @ Z
    r0 = A @ kp + b
    w = np.full(A.shape[0], 1.0 / A.shape[0])
    best_k, best_e = None, np.inf
    for _ in range(iters):
        M = AZ * w[:, None]
        H = AZ.T @ M
        H[np.diag_indices_from(H)] += 1e-14 * np.trace(H) + 1e-300
        y = np.linalg.solve(H, -(M.T @ r0))
        k = kp + Z @ y
        e = r0 + AZ @ y
        emax = np.abs(e).max()
        if emax < best_e:
            best_k, best_e, best_res = k, emax, e
        w = w * np.abs(e)
        total = w.sum()
        if not (total > 0):
            break
        w = np.maximum(w / total, 1e-12)
    return best_k, best_res


class _SpanModel:
    """Linear model of the normal deviation of a G1 arc spline from one smooth piece.

    The arcs are parametrised by the arc length ``s`` of the piece: with knots
    ``x`` (arc ends) and curvatures ``k`` the spline's tangent angle is
    ``φ(s) = θ(0) + Σ k_j·clip(s - x_j, 0, ℓ_j)``; to first order its point at
    ``s`` is ``P(s) + V(s)`` with ``V(s) = ∫₀ˢ (φ - θ)·n ds'``, and the normal
    deviation is ``e(s) = n(s)·V(s) = A k + b``.  The spline starts at the
    piece's first point with its tangent; ``C k = d`` closes it on the last
    point with its tangent (first order; the last two arcs are re-fitted exactly).
    """

    def __init__(self, sur: _Surrogate, segs, n_grid: int, fixed=(None, None)):
        _, s, theta, kappa = _span_model(sur, segs, n_grid, curvature=True)
        self.fixed = fixed  # curvatures imposed on the first / last arc (None: free)
        self.s, self.theta, self.L = s, theta, float(s[-1])
        # every prefix integral is the exact integral of the cubic Hermite interpolant of its
        # integrand (values and derivatives at the grid): knots fall between grid points, and
        # linear interpolation there would cost O(h²·κ) -- of the order of tol at fine tolerances
        tng = np.stack([np.cos(theta), np.sin(theta)], axis=-1)
        nrm = np.stack([-np.sin(theta), np.cos(theta)], axis=-1)
        dn = -kappa[:, None] * tng                                       # d n / ds
        dth = (theta[0] - theta)[:, None]
        self.nrm = nrm
        self.n_fp = (nrm, dn)
        self.m_fp = (s[:, None] * nrm, nrm + s[:, None] * dn)
        self.N = _cumhermite(nrm, dn, s)                                 # ∫ n ds
        self.Dt = _cumhermite(dth * nrm, -kappa[:, None] * nrm + dth * dn, s)
        self.b = _dot(self.Dt, nrm)
        self.M = _cumhermite(*self.m_fp, s)                              # ∫ s·n ds
        self.nN, self.nM = _dot(nrm, self.N), _dot(nrm, self.M)
        self._nm = (np.hstack([self.N, self.M]), np.hstack([nrm, self.m_fp[0]]), np.hstack([dn, self.m_fp[1]]))
        self._last = (None, None)

    def NM_at(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(N(x), M(x))`` between grid points (the last query is cached)."""
        key = x.tobytes()
        if self._last[0] != key:
            v = _hermite_at(x, self.s, *self._nm)
            self._last = (key, (v[:, :2], v[:, 2:]))
        return self._last[1]

    def system(self, knots: np.ndarray):
        """``(A, C, d)`` of the knots: ``e = A k + b`` on the grid, ``C k = d`` closes the span."""
        ell = np.diff(knots)
        s, nrm = self.s, self.nrm
        # V_j(s) = ∫ clip(s' - x_j, 0, ℓ_j)·n ds' from the prefix integrals N = ∫ n, M = ∫ s'·n:
        # after arc j (s > x_{j+1}) n·V_j = n·W_j + ℓ_j·n·N(s), W_j = [M - x·N] from x_j to x_{j+1};
        # inside it n·V_j = n·M(s) - x_j·n·N(s) - n·(M(x_j) - x_j·N(x_j)); before it 0
        Nx, Mx = self.NM_at(knots)
        G = Mx - knots[:, None] * Nx                                        # (m + 1, 2)
        m = ell.size
        A = nrm @ (G[1:] - G[:-1]).T + self.nN[:, None] * ell[None, :]
        jj = np.clip(np.searchsorted(knots, s, side="right") - 1, 0, m - 1)
        A[np.arange(m)[None, :] >= jj[:, None]] = 0.0
        A[np.arange(s.size), jj] = self.nM - knots[jj] * self.nN - _dot(nrm, G[jj])
        Dk_end = (Mx[1:] - Mx[:-1]) - knots[:-1, None] * (Nx[1:] - Nx[:-1]) + ell[:, None] * (self.N[-1] - Nx[1:])
        scale = self.L / ell.size
        C = np.vstack([ell * scale, Dk_end.T])
        d = np.concatenate([[(self.theta[-1] - self.theta[0]) * scale], -self.Dt[-1]])
        rows, vals = self._fixed_rows(m)
        if rows.shape[0]:
            C, d = np.vstack([C, rows]), np.concatenate([d, vals])
        return A, C, d

    def _fixed_rows(self, m: int):
        rows, vals = [], []
        for j, kf in ((0, self.fixed[0]), (m - 1, self.fixed[1])):
            if kf is not None:
                r = np.zeros(m)
                r[j] = self.L
                rows.append(r)
                vals.append(kf * self.L)
        return np.array(rows).reshape(-1, m), np.array(vals)

    def knot_jacobian(self, knots: np.ndarray, k: np.ndarray):
        """Derivatives of ``e`` (grid) and of ``C k - d`` with respect to the interior knots.

        Moving knot ``x_j`` by ``δ`` turns every later tangent by ``(k_{j-1} - k_j)·δ``.
        """
        xi = knots[1:-1]
        Nx = self.NM_at(knots)[0][1:-1]
        jump = k[:-1] - k[1:]
        B = (self.nN[:, None] - self.nrm @ Nx.T) * jump
        B[self.s[:, None] <= xi[None, :]] = 0.0
        Bc = np.vstack([jump * (self.L / k.size), ((self.N[-1][None] - Nx) * jump[:, None]).T])
        n_fixed = self._fixed_rows(k.size)[0].shape[0]
        if n_fixed:
            Bc = np.vstack([Bc, np.zeros((n_fixed, xi.size))])
        return B, Bc


def _local_extrema(e: np.ndarray) -> np.ndarray:
    """Grid indices where ``|e|`` has a local maximum."""
    ae = np.abs(e)
    left = np.concatenate([[-np.inf], ae[:-1]])
    right = np.concatenate([ae[1:], [-np.inf]])
    return np.flatnonzero((ae >= left) & (ae >= right) & (ae > 0))


def _equioscillate(model: _SpanModel, knots: np.ndarray, iters: int = _EQUI_ITERS):
    """Jointly optimise knots and curvatures of a clamped span: ``(max |e|, knots, k)``.

    Starts from the (approximate) minimax curvatures of the given knots, then
    Gauss-Newton steps on knots and curvatures together drive every local
    extremum of the deviation to one common level (a Remez-like exchange: the
    extrema are re-located after every step), the knot moves damped
    (Levenberg) and each step accepted only if the largest deviation drops.
    """
    A, C, d = model.system(knots)
    k, e = _lawson(A, model.b, C, d, iters=4)
    best = (float(np.abs(e).max()), knots, k, e)
    m = k.size
    if m < 3:
        return _peak(e), knots, k
    lam = 1e-2
    hmean = model.L / m
    for _ in range(iters):
        E, knots, k, e = best
        p = _local_extrema(e)
        B, Bc = model.knot_jacobian(knots, k)
        J = np.hstack([A[p], B[p], -np.sign(e[p])[:, None]])
        Cj = np.hstack([C, Bc, np.zeros((C.shape[0], 1))])
        wc = 1e3 / max(float(np.abs(Cj).max()), 1e-300)
        damp = np.zeros((m - 1, 2 * m))
        damp[:, m:2 * m - 1] = np.eye(m - 1) * (lam * E / hmean)
        y, *_ = np.linalg.lstsq(np.vstack([J, wc * Cj, damp]),
                                np.concatenate([-e[p], wc * (d - C @ k), np.zeros(m - 1)]), rcond=None)
        dk, dx = y[:m], y[m:2 * m - 1]
        improved = False
        for alpha in (1.0, 0.5, 0.25):
            xn = knots.copy()
            xn[1:-1] += alpha * dx
            if not np.all(np.diff(xn) >= 0.3 * np.diff(knots)):
                continue
            A2, C2, d2 = model.system(xn)
            k2 = k + alpha * dk
            try:  # restore the closure exactly (least-norm change of the curvatures)
                k2 = k2 + C2.T @ np.linalg.solve(C2 @ C2.T, d2 - C2 @ k2)
            except np.linalg.LinAlgError:
                continue
            e2 = A2 @ k2 + model.b
            E2 = float(np.abs(e2).max())
            if E2 < best[0]:
                best = (E2, xn, k2, e2)
                A, C, d = A2, C2, d2
                improved = True
                break
        if not improved:
            lam *= 4.0
            if lam > 10.0:
                break
        elif E - best[0] < 1e-3 * E:
            break
    return _peak(best[3]), best[1], best[2]


def _peak(e: np.ndarray) -> float:
    """Largest ``|e|`` with every interior local extremum refined by a parabola through its neighbours."""
    ae = np.abs(e)
    j = np.clip(_local_extrema(e), 1, e.size - 2)
    a, b, c = ae[j - 1], ae[j], ae[j + 1]
    curv = a - 2 * b + c
    lift = np.where(curv < 0, -(c - a) ** 2 / (8 * np.where(curv < 0, curv, -1.0)), 0.0)
    return float(max(ae.max(), (b + np.minimum(lift, b)).max() if j.size else 0.0))


def _place_knots(s, density, m, ends=_END_ARCS, ends_hi=None):
    """``m`` arcs equidistributing ``density``, the two end arcs at each end scaled (``ends``, ``ends_hi``)."""
    ends_hi = ends if ends_hi is None else ends_hi
    w = np.ones(m)
    if m >= 4:
        w[0], w[1] = ends[0], ends[1]
        w[-1], w[-2] = ends_hi[0], ends_hi[1]
    elif m >= 2:
        if m == 3:
            w[0], w[-1] = ends[0], ends_hi[0]
    q = np.concatenate([[0.0], np.cumsum(w)]) / w.sum()
    cum = _cumtrapz(density, s)
    if not (cum[-1] > 0):
        knots = q * s[-1]
    else:
        knots = np.interp(q * cum[-1], cum, s)
    knots[0], knots[-1] = 0.0, s[-1]
    return knots


def _span_density(sur: _Surrogate, segs, target: float, n: int = 257):
    """``(t, s, density)``: arcs per unit length, ``(|κ'| / (124.7·target))^(1/3)`` (+ a turning bound).

    ``t`` holds the parameters of the grid and ``piece`` (4th value) their pieces."""
    total = sum(hi - lo for _, lo, hi in segs)
    ts, ss, ds, ps = [], [], [], []
    s_off = 0.0
    for seg in segs:
        k = max(33, int(round(n * (seg[2] - seg[1]) / total))) if len(segs) > 1 else n
        t, s0, theta = _span_model(sur, [seg], k)
        kappa = np.gradient(theta, s0)
        dk = np.abs(np.gradient(kappa, s0))
        ts.append(t)
        ss.append(s0 + s_off)
        ds.append((dk / (124.7 * target)) ** (1.0 / 3.0) + np.abs(kappa) / MAX_TURNING_RAD)
        ps.append(np.full(t.size, seg[0]))
        s_off += float(s0[-1])
    return np.concatenate(ts), np.concatenate(ss), np.concatenate(ds), np.concatenate(ps)


@dataclass
class _Span:
    """A free span: consecutive smooth pieces joined G1, ``segs`` = ``[(piece, lo, hi), ...]``.

    Its ends are clamped (point and tangent of the curve); ``fixed`` imposes the curvature of the
    first / last arc (the span ends on a circular piece joined G1, e.g. a dwell: that arc continues
    the circle and merges with its exact arcs).  ``exact`` holds the exact arcs of a span that is
    one circular piece."""

    segs: list
    fixed: tuple = (None, None)
    exact: Optional[tuple] = None
    label: int = 0

    def sample(self, n: int) -> np.ndarray:
        total = sum(hi - lo for _, lo, hi in self.segs)
        return np.concatenate([np.linspace(lo, hi, max(2, int(n * (hi - lo) / total)) + 1)[:-1]
                               for _, lo, hi in self.segs])

    def contains(self, t: float) -> bool:
        return any(lo <= t <= hi for _, lo, hi in self.segs)


def _fit_span(sur: _Surrogate, span: _Span, target: float):
    """Fewest arcs (model) for a clamped span: ``(knots, k, error)`` or None.

    The arc count starts from the asymptotic estimate ``∫ (|κ'| / (124.7·target))^(1/3) ds``;
    every count gets knots equidistributing that density (end arcs shortened at clamped ends),
    then knots and curvatures are optimised together (:func:`_equioscillate`);
    the count goes down while the span still fits ``target`` and up until it does.
    The optimum is not monotone in the count: at the smallest failing count a warm start
    and other end-arc ratios (:data:`_END_ARCS_ALT`) are tried when it failed narrowly.
    """
    _, s0, density, _ = _span_density(sur, span.segs, target)
    est = float(_cumtrapz(density, s0)[-1])
    n_fixed = sum(f is not None for f in span.fixed)
    m_min = 2 + n_fixed
    m = max(m_min, math.ceil(_EST_FACTOR * est))
    best = None
    tried: dict = {}
    models: dict = {}

    def attempt(m, ends=_END_ARCS, knots=None, fixed_ends=_FIXED_END_ARCS):
        if m not in models:
            models[m] = _SpanModel(sur, span.segs, max(_SPLINE_MIN_GRID, _SPLINE_SAMPLES * m + 1), span.fixed)
        model = models[m]
        if knots is None:
            knots = _place_knots(model.s, np.interp(model.s, s0, density), m,
                                 fixed_ends if span.fixed[0] is not None else ends,
                                 fixed_ends if span.fixed[1] is not None else ends)
        err, knots, k = _equioscillate(model, knots)
        free = np.ones(m, bool)
        free[0] = span.fixed[0] is None
        free[-1] = span.fixed[1] is None
        ok = err <= target and np.all(np.abs(k * np.diff(knots))[free] < MAX_TURNING_RAD * 1.5)
        return err, ok, (knots, k, err)

    for _ in range(12):
        if m in tried:
            break
        if m > _SPAN_MAX_ARCS:
            return None
        err, ok, fit = attempt(m)
        tried[m] = err
        if ok and (best is None or m < best[0].size - 1):
            best = fit
        if ok:
            # one arc fewer raises the error by about (m / (m - 1))³: not worth trying beyond the target
            if (m - 1) in tried or m <= m_min or err * (m / (m - 1)) ** 3 > _DOWN_SLACK * target:
                break
            m -= 1
        else:
            if best is not None and best[0].size - 1 == m + 1:
                break
            jump = math.ceil(m * (err / target) ** (1.0 / 3.0)) - m  # (a single count may fail badly)
            m = m + 1 if err < 1.6 * target else m + max(1, min(jump, math.ceil(0.1 * m) + 1))
    if best is not None:
        m = best[0].size - 2
        if m >= max(4, m_min) and m in tried and tried[m] <= 1.3 * target:
            # warm start: the optimised knots of the fitting count less the joint of the smallest
            # curvature jump (not an end arc), then other end-arc ratios
            kb, kk = best[0], best[1]
            jump = np.abs(np.diff(kk))[1:-1]
            if jump.size:
                j = 2 + int(np.argmin(jump))
                err, ok, fit = attempt(m, knots=np.delete(kb, j))
                if ok:
                    return fit
            alts = [(ends, _FIXED_END_ARCS) for ends in _END_ARCS_ALT] if n_fixed < 2 else []
            alts += [(_END_ARCS, fe) for fe in _FIXED_END_ARCS_ALT] if n_fixed else []
            for ends, fixed_ends in alts:
                err, ok, fit = attempt(m, ends, fixed_ends=fixed_ends)
                if ok:
                    return fit
    return best


def _tanlen(kk, ll):
    x = 0.5 * kk * ll
    return ll / 2 if abs(x) < 1e-12 else math.tan(x) / kk


def _span_chain(p0, t0, p1, t1, knots, k, fixed=(None, None)):
    """Exact G1 arcs of a span from ``(p0, t0)`` to ``(p1, t1)``: the planned arcs, closed by a biarc.

    The arcs before the closing biarc are laid forward from ``p0``; with a fixed last curvature the
    last arc is laid backward from ``p1`` (the biarc closes the arcs before it).  Arcs turning more
    than π/2 are cut into equal parts (co-circular parts merge again later)."""
    ell = np.diff(knots)
    k = np.array(k, dtype=float)
    if fixed[0] is not None:
        k[0] = fixed[0]
    if fixed[1] is not None:
        k[-1] = fixed[1]
    m = ell.size
    j = m - 3 if fixed[1] is not None else m - 2  # the closing biarc is arcs j, j + 1
    if j < (1 if fixed[0] is not None else 0):
        return None
    starts, tans, ks, ls = [p0], [t0], [], []
    base = math.atan2(t0[1], t0[0])
    ang = base + np.concatenate([[0.0], np.cumsum(k * ell)])
    for i in range(j):
        e = _entity_point(starts[-1], tans[-1], k[i], ell[i])
        ks.append(k[i])
        ls.append(ell[i])
        starts.append(e)
        tans.append(np.array([math.cos(ang[i + 1]), math.sin(ang[i + 1])]))
    # backward from p1: arcs j + 2 … m - 1
    b_starts, b_tans = [], []
    end_p, end_ang = p1, math.atan2(t1[1], t1[0])
    for i in range(m - 1, j + 1, -1):
        ang_s = end_ang - k[i] * ell[i]
        tb = np.array([math.cos(end_ang), math.sin(end_ang)])
        sp = _entity_point(end_p, -tb, -k[i], ell[i])
        b_starts.insert(0, sp)
        b_tans.insert(0, np.array([math.cos(ang_s), math.sin(ang_s)]))
        end_p, end_ang = sp, ang_s
    d1, d2 = _tanlen(k[j], ell[j]), _tanlen(k[j + 1], ell[j + 1])
    ratio = d1 / d2 if d1 > 0 and d2 > 0 else 1.0
    tgt_t = np.array([math.cos(end_ang), math.sin(end_ang)])
    bi = _biarc(starts[-1][None], tans[-1][None], end_p[None], tgt_t[None], np.array([ratio]))
    if not bi["valid"][0]:
        bi = _biarc(starts[-1][None], tans[-1][None], end_p[None], tgt_t[None], np.array([1.0]))
        if not bi["valid"][0]:
            return None
    S = np.concatenate([np.array(starts[:j]).reshape(-1, 2), bi["s"][0], np.array(b_starts).reshape(-1, 2)])
    TT = np.concatenate([np.array(tans[:j]).reshape(-1, 2), bi["T"][0], np.array(b_tans).reshape(-1, 2)])
    K = np.concatenate([np.array(ks), bi["k"][0], k[j + 2:]])
    L = np.concatenate([np.array(ls), bi["ell"][0], ell[j + 2:]])
    parts = np.maximum(1, np.ceil(np.abs(K * L) / (0.5 * math.pi))).astype(int)
    if parts.max() > 1:  # cut long arcs (fixed dwell arcs) into parts
        idx = np.repeat(np.arange(K.size), parts)
        sub = np.arange(idx.size) - np.repeat(np.cumsum(parts) - parts, parts)
        u = L[idx] * sub / parts[idx]
        S = _entity_point(S[idx], TT[idx], K[idx], u)
        TT = _rotate(TT[idx], K[idx] * u)
        K = K[idx]
    # make every arc consistent with both its end points (ends[i] == starts[i + 1] exactly)
    S_next = np.concatenate([S[1:], [p1]])
    TT2, K2, L2, ok = _arc_from(S, TT, S_next)
    if not ok.all():
        return None
    return S, TT2, K2, L2, S_next


def _circle_pieces(curve: ParametricCurve, sur: _Surrogate, tol: float):
    """``(g1, circ, k)``: tangent continuity at every piece start, circular pieces and their curvatures.

    A piece is circular (or straight) when 17 exact samples lie within ``tol/1000`` (and 1e-10 of
    its chord) of the circle through its samples 0, 4 and 8."""
    bp = curve.breakpoints
    n = bp.size - 1
    lo, hi = bp[:-1], bp[1:]
    idx = np.arange(n)
    t_in = _unit(sur.derivative(lo, idx))
    t_out = _unit(sur.derivative(hi, idx))
    prev = np.roll(t_out, 1, axis=0)
    g1 = np.abs(np.arctan2(_cross(prev, t_in), _dot(prev, t_in))) < _G1_RAD
    tt = lo[:, None] + (hi - lo)[:, None] * np.linspace(0.0, 1.0, 17)
    pts = _points(curve, tt)
    # the tangent at the start of the circle through samples 0, 4, 8 (parallel to the line through
    # their images under inversion about sample 0): independent of derivative errors
    wb, wc = pts[:, 4] - pts[:, 0], pts[:, 8] - pts[:, 0]
    d = wc / np.maximum(_dot(wc, wc), 1e-300)[:, None] - wb / np.maximum(_dot(wb, wb), 1e-300)[:, None]
    t_in = _unit(np.where((_dot(d, wb) < 0)[:, None], -d, d))
    _, k, _, valid = _arc_from(pts[:, 0], t_in, pts[:, 4])
    w = pts - pts[:, :1]
    x, y = _dot(w, t_in[:, None]), _cross(t_in[:, None], w)
    kk = k[:, None]
    radial = np.abs(kk * (x * x + y * y) - 2.0 * y) / (np.hypot(kk * x, 1.0 - kk * y) + 1.0)
    chord = np.hypot(*(pts[:, -1] - pts[:, 0]).T)
    circ = valid & (radial.max(axis=1) <= np.minimum(1e-3 * tol, 1e-10 * chord))
    return g1, circ, k


def _segments(curve: ParametricCurve, a: float, b: float, wrap: bool) -> list:
    """``[(piece, lo, hi), ...]`` from parameter ``a`` forward to ``b`` (across the period when ``wrap``)."""
    bp = curve.breakpoints
    n = bp.size - 1
    p = int(_piece_index(curve, np.array([a]))[0])
    out, lo, laps = [], a, 0
    for _ in range(2 * n + 2):
        if laps == int(wrap) and b <= bp[p + 1] and not (laps == 0 and b < lo):
            out.append((p, lo, b))
            break
        out.append((p, lo, float(bp[p + 1])))
        p += 1
        if p == n:
            p, laps = 0, laps + 1
        lo = float(bp[p])
    return [sg for sg in out if sg[2] > sg[1]]


def _spans(curve: ParametricCurve, sur: _Surrogate, target: float, tol: float, anchored: bool = True) -> list:
    """The free spans (:class:`_Span`) in chain order.

    Spans run between *anchors*: true corners (kept as vertices) and the middles of circular
    pieces (dwells) between G1 junctions, so arcs run across the G1 breakpoints in between.
    Without anchors (or with ``anchored`` false) every breakpoint is a span end.  Long stretches
    are cut into equal shares of about :data:`_SPLINE_SPAN` arcs, joined G1 at (surrogate) curve
    points with the curve's tangent.
    """
    bp = curve.breakpoints
    n = bp.size - 1
    g1, circ, _ = _circle_pieces(curve, sur, tol)
    anchors: dict = {}   # t -> [k of the arc ending there, k of the arc leaving it, corner]
    exact = {}
    if anchored and n > 1:
        for p in range(n):
            if not g1[p]:
                anchors[float(bp[p])] = [None, None, True]
        for p in np.flatnonzero(circ):
            arcs_p = _exact_arcs(curve, sur, int(p))
            if arcs_p is None:
                continue
            exact[int(p)] = arcs_p
            a0 = anchors.setdefault(float(bp[p]), [None, None, False])
            a1 = anchors.setdefault(float(bp[p + 1]) % curve.period, [None, None, False])
            if g1[p]:
                a0[0] = float(arcs_p[2][0])
            if g1[(p + 1) % n]:
                a1[1] = float(arcs_p[2][-1])
    if not anchors:
        anchors = {float(t): [None, None, False] for t in bp[:-1]}
    ts = sorted(anchors)
    corners = [i for i, t in enumerate(ts) if anchors[t][2]]
    if corners:
        ts = ts[corners[0]:] + ts[:corners[0]]
    out, label = [], -1
    for i, a in enumerate(ts):
        b = ts[(i + 1) % len(ts)]
        if anchors[a][2] or label < 0:
            label += 1
        segs = _segments(curve, a, b, wrap=len(ts) == 1 or b <= a)
        fixed = (anchors[a][1], anchors[b][0])
        if len(segs) == 1 and segs[0][0] in exact and segs[0][1] == bp[segs[0][0]]:
            out.append(_Span(segs, (None, None), exact[segs[0][0]], label))
            continue
        if not segs:
            continue
        t, s0, density, piece = _span_density(sur, segs, target)
        cum = _cumtrapz(density, s0)
        m = max(1, math.ceil(1.08 * float(cum[-1]) / _SPLINE_SPAN))
        if m == 1:
            out.append(_Span(segs, fixed, None, label))
            continue
        # cut at equal shares of the density (never on a junction)
        goal = cum[-1] * np.arange(1, m) / m
        j = np.clip(np.searchsorted(cum, goal) - 1, 0, cum.size - 2)
        j = np.where(piece[j] == piece[j + 1], j, j + 1)
        j = np.clip(j, 0, cum.size - 2)
        frac = np.clip((goal - cum[j]) / np.maximum(cum[j + 1] - cum[j], 1e-300), 0.0, 1.0)
        cut_t, cut_p = t[j] + frac * (t[j + 1] - t[j]), piece[j]
        pieces_segs, cur, ci = [], [], 0
        for seg in segs:
            lo = seg[1]
            while ci < cut_t.size and cut_p[ci] == seg[0] and lo < cut_t[ci] < seg[2]:
                cur.append((seg[0], lo, float(cut_t[ci])))
                pieces_segs.append(cur)
                cur, lo, ci = [], float(cut_t[ci]), ci + 1
            cur.append((seg[0], lo, seg[2]))
        pieces_segs.append(cur)
        for q, sg in enumerate(pieces_segs):
            f = (fixed[0] if q == 0 else None, fixed[1] if q == len(pieces_segs) - 1 else None)
            out.append(_Span(sg, f, None, label))
    return out


def _span_ends(sur: _Surrogate, span: _Span):
    """Points and unit tangents at both ends of a span: the exact samples at breakpoints."""
    ends = []
    for piece, t in ((span.segs[0][0], span.segs[0][1]), (span.segs[-1][0], span.segs[-1][2])):
        pt = None
        for i in (sur.first[piece], sur.first[piece + 1]):
            if t == sur.x[i]:
                pt = sur.points[i] if i < sur.x.size - 1 else sur.points[0]
        if pt is None:
            pt = sur.point(np.array([t]), piece)[0]
        ends.append((pt, _unit(sur.derivative(np.array([t]), piece)[0])))
    return ends[0][0], ends[0][1], ends[1][0], ends[1][1]


def _exact_arcs(curve: ParametricCurve, sur: _Surrogate, p: int):
    """Exact arcs (each turning ≤ π/2) of the circular piece ``p``: ``(S, T, K, L, E)`` or None."""
    lo, hi = float(curve.breakpoints[p]), float(curve.breakpoints[p + 1])
    span = _Span([(p, lo, hi)])
    _, _, theta = _span_model(sur, span.segs, 33)
    n = max(1, math.ceil(abs(theta[-1] - theta[0]) / (0.5 * math.pi)))
    p0, t0, p1, _ = _span_ends(sur, span)
    pts = np.concatenate([[p0], _points(curve, lo + (hi - lo) * np.arange(1, n) / n).reshape(-1, 2), [p1]])
    S, TT, K, L = [], [], [], []
    tan = t0
    for i in range(n):
        T, k, ell, ok = _arc_from(pts[i], tan, pts[i + 1])
        if not ok:
            return None
        S.append(pts[i])
        TT.append(T)
        K.append(float(k))
        L.append(float(ell))
        tan = _rotate(T, k * ell)
    return np.array(S), np.array(TT), np.array(K), np.array(L), pts[1:]


def _fit_span_chain(curve: ParametricCurve, sur: _Surrogate, span: _Span, target: float):
    """The exact G1 arcs of one span fitted to ``target`` and the model error, or None."""
    if span.exact is not None:
        return span.exact, 0.0
    fit = _fit_span(sur, span, target)
    if fit is None:
        return None
    knots, k, err = fit
    p0, t0, p1, t1 = _span_ends(sur, span)
    chain = _span_chain(p0, t0, p1, t1, knots, k, span.fixed)
    return None if chain is None else (chain, err)


def _merge_wrap(chain: Chain, labels: np.ndarray) -> tuple[Chain, np.ndarray]:
    """Roll the chain by one entity when its last and first entities lie on one circle (G1 joint)."""
    if chain.n < 2 or labels[0] != labels[-1]:
        return chain, labels
    k, ell = chain.curvature, chain.length
    tj = chain.end_tangent[-1]
    g1 = abs(math.atan2(_cross(tj, chain.tangent[0]), _dot(tj, chain.tangent[0]))) < 1e-12
    if not (g1 and abs(k[0] - k[-1]) * (ell[0] + ell[-1]) <= LINE_SWEEP_RAD):
        return chain, labels
    roll = lambda a: np.roll(a, 1, axis=0)  # noqa: E731
    return Chain(*(roll(a) for a in (chain.start, chain.tangent, chain.curvature, chain.length, chain.end))), \
        roll(labels)


def _fit_spline(curve: ParametricCurve, sur: tuple, tol: float, anchored: bool = True):
    """The free arc spline within ``tol`` (measured on the exact curve) and its span-end parameters, or None.

    Spans are independent (their ends are fixed points with fixed tangents), so
    when the measured chain exceeds ``tol`` only the span where the maximum
    occurs is refitted, to a target lowered by the measured excess.
    """
    sur, sur_err = sur
    target = _SPLINE_FILL * tol - sur_err
    if not (target > 0):
        return None
    spans = _spans(curve, sur, target, tol, anchored)
    targets = [target] * len(spans)
    with np.errstate(invalid="ignore", divide="ignore"):
        fits = [_fit_span_chain(curve, sur, sp, target) for sp in spans]
    if any(f is None for f in fits):
        return None
    parts, errs = [f[0] for f in fits], [f[1] for f in fits]
    params = np.unique(np.append([sp.segs[0][1] for sp in spans], curve.period))
    for _ in range(_SPAN_REFITS + 1):
        cat = [np.concatenate([c[i] for c in parts]) for i in range(5)]
        labels = np.concatenate([np.full(c[0].shape[0], spans[j].label) for j, c in enumerate(parts)])
        chain, labels = _merge_wrap(Chain(*cat), labels)
        merged = _merge_cocircular(chain, labels)
        dev = measure_deviation(merged, curve)
        if dev.max <= tol:
            return merged, dev.max, params
        # refit only the offending spans: the one holding the worst deviation and every span
        # whose exact curve samples (16 per arc) lie farther than tol from the chain
        counts = [c[0].shape[0] for c in parts]
        t = [sp.sample(16 * n) for sp, n in zip(spans, counts)]
        d, _ = merged.distance(_points(curve, np.concatenate(t)))
        worst = np.maximum.reduceat(d, np.concatenate([[0], np.cumsum([x.size for x in t])[:-1]]))
        at = float(dev.at_param)
        j = next((i for i, sp in enumerate(spans) if sp.contains(at)), None)
        if j is not None:
            worst[j] = max(worst[j], dev.max)
        for j in np.flatnonzero(worst > 0.99 * tol):
            if spans[j].exact is not None:
                return None
            # the measured / model ratio of this span scales its next target
            targets[j] = min(0.98 * targets[j], 0.97 * tol * errs[j] / worst[j])
            with np.errstate(invalid="ignore", divide="ignore"):
                fit = _fit_span_chain(curve, sur, spans[j], targets[j])
            if fit is None:
                return None
            parts[j], errs[j] = fit
    return None


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
    tol = validate_tol(tol)
    _check_closed(curve, tol)

    def build(nodes):
        pts = _points(curve, nodes)
        pts[-1] = pts[0]
        return pts

    nodes, measured = _fit(curve, tol, "line",
                           lambda nodes: measure_deviation(build(nodes), curve).max)
    return Discretisation(params=nodes, points=build(nodes), max_deviation=float(measured), tol=tol)


def _arc_chain(curve: ParametricCurve, nodes: np.ndarray, fit_curve: ParametricCurve = None
               ) -> tuple[Chain, np.ndarray]:
    """The biarc chain of a node grid and the piece index of every entity.

    The nodes are exact points of ``curve``; tangents and biarc ratios may be
    taken from ``fit_curve`` (a surrogate of it).
    """
    a, b = nodes[:-1], nodes[1:]
    pieces = _piece_index(curve, 0.5 * (a + b))
    bp = curve.breakpoints
    pts = _points(curve, nodes)
    pts[-1] = pts[0]  # one evaluation per node: ends[i] == starts[i + 1] bit for bit
    ent = _interval_entities(fit_curve or curve, a, b, bp[pieces], bp[pieces + 1], "biarc", pts[:-1], pts[1:])
    start = ent["s"].reshape(-1, 2)
    end = ent["e"].reshape(-1, 2)
    chain = Chain(start, ent["T"].reshape(-1, 2), ent["k"].ravel(), ent["ell"].ravel(), end)
    return chain, np.repeat(pieces, 2)


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
    Long spans are cut into spans of about :data:`_SPLINE_SPAN` arcs, joined
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
