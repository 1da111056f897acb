"""The two-way maximum distance between lines/arcs and an exact curve, measured (never assumed).

Curve to entities: exact point-to-line / point-to-arc distances of exact curve samples to the chain.
Entities to curve: every entity sample is projected onto the curve (Newton on a Hermite interpolant of
the exact samples and derivatives, on both sample intervals touching the nearest curve sample, never
across a breakpoint) and its distance taken to the exact curve point at the foot, an upper bound; the
feet of the samples that could hold the maximum are then polished by Gauss-Newton steps on the exact
curve (a short, sharp piece has only its few samples in the interpolant).  The worst local maxima of
each direction are then refined by two nested grids around them.  The exact curve is called a fixed,
small number of times (batched).
"""
from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ..errors import GeometryError
from ..geom2d import ArcChain, dot
from .chain import Chain
from .curve import ParametricCurve, derivatives_at, points_at
from .entities import entity_point, local_distance
from .grid import grid_nearest
from .results import ArcDiscretisation, Deviation, Discretisation
from .surrogate import HermiteSurrogate, sample_nodes

__all__ = ["as_chain", "measure_deviation", "measure_fit", "max_deviation"]

#: Gauss-Newton steps on the exact curve that polish a foot found on the surrogate, and the rounds of
#: polishing (each takes the unpolished samples within half the largest distance)
_POLISH_ITERS = 2
_POLISH_ROUNDS = 6
#: points of each nested grid of :func:`measure_fit`'s refinement (two levels: the peak's bracket shrinks to 1/64
#: of the sample spacing, its value within ~10⁻⁸ of tol of the peak's on the examples)
_FIT_ZOOM = 17
#: nested grids of the refinement with the local bound: its samples are about ten times sparser, so one level more
#: brings a peak's bracket to a fraction of the spacing the two levels reached before
_LOCAL_LEVELS = 3
#: how much farther than its nearest point (mm) a curve sample may be from an entity's joint for the local bound to
#: read it against the entity across that joint (:func:`_interval_ends`)
_JOINT_SLACK = 1e-12


def as_chain(entities, closed: bool = True) -> Chain:
    """Any entities :func:`measure_deviation` accepts as a :class:`Chain`; arrays of vertex rows are
    closed or open as ``closed`` says (an arc chain or discretisation knows).

    Raises
    ------
    GeometryError
        For anything else (the accepted forms are named).
    """
    if isinstance(entities, Chain):
        return entities
    if isinstance(entities, (Discretisation, ArcDiscretisation)):
        return entities.chain()
    if isinstance(entities, ArcChain):
        entities, closed = entities.lwpolyline, entities.closed
    arr = np.asarray(entities, dtype=float)
    if arr.ndim == 2 and arr.shape[1] == 2:
        return Chain.from_polyline(arr, closed)
    if arr.ndim == 2 and arr.shape[1] == 3:
        return Chain.from_bulges(arr, closed)
    raise GeometryError("entities must be a Chain, an ArcChain, a discretisation, an (n, 2) polyline or "
                        f"(n, 3) (x, y, bulge) rows; got shape {arr.shape}")


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

    def __init__(self, sur: HermiteSurrogate):
        self.sur = sur
        self.curve = sur.curve
        self.x = sur.x
        self.n = sur.x.size - 1
        self.sites = sur.points[:-1] if self.curve.closed else sur.points
        step = np.diff(sur.points, axis=0)
        # twice the typical spacing: a query near the curve is settled in the finest grid; one far from it (or
        # near a sparse stretch) on a coarser one
        self.cell = 2.0 * float(np.median(np.hypot(step[:, 0], step[:, 1])))
        # contiguous per-interval columns for the Newton iterations (gathered once per query and interval; the
        # same values as gathering the (4, n, 2) coefficients and splitting them, without strided arithmetic):
        # the cubic's coefficients by component, ``2·c₂`` (a power of two: exact), the interval widths, and the
        # sites by component for the distances of the nearest-sample grid
        self._cx = tuple(np.ascontiguousarray(c[:, 0]) for c in sur.coef)
        self._cy = tuple(np.ascontiguousarray(c[:, 1]) for c in sur.coef)
        self._width = sur.x[1:] - sur.x[:-1]
        self._site_x = np.ascontiguousarray(self.sites[:, 0])
        self._site_y = np.ascontiguousarray(self.sites[:, 1])
        self._cells: dict = {}  # the sites' grid buckets, made once for every query (grid_nearest)

    def nearest(self, x: np.ndarray) -> np.ndarray:
        """Index of the curve sample nearest to each ``x`` ``(N, 2)``."""
        sx, sy = self._site_x, self._site_y

        def dist(p: np.ndarray, j: np.ndarray) -> np.ndarray:
            return np.hypot(p[:, 0] - sx[j], p[:, 1] - sy[j])

        return grid_nearest(x, self.sites, self.cell, dist, cells=self._cells)[1]

    def project(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Distance from each ``x`` ``(N, 2)`` to the curve, the foot parameter and its smooth piece.

        Newton's iterations run on the two components as separate ``(N, 2)`` arrays (one column per
        interval), each product and sum the same as on the ``(N, 2, 2)`` points in the same order."""
        j = self.nearest(x)
        if self.curve.closed:
            iv = np.stack([(j - 1) % self.n, j], axis=1)  # (N, 2)
        else:
            iv = np.stack([np.maximum(j - 1, 0), np.minimum(j, self.n - 1)], axis=1)
        a, h = self.x[iv], self._width[iv]
        c0x, c1x, c2x, c3x = (c[iv] for c in self._cx)
        c0y, c1y, c2y, c3y = (c[iv] for c in self._cy)
        c2x2, c2y2 = 2 * c2x, 2 * c2y
        qx, qy = x[:, 0, None], x[:, 1, None]
        u = 0.5 * h
        for _ in range(6):
            # p = c₀ + u(c₁ + u(c₂ + u c₃)), d = c₁ + u(2c₂ + (3u) c₃), dd = 2c₂ + (6u) c₃, r = p − x
            u3, u6 = 3 * u, 6 * u
            rx = c0x + u * (c1x + u * (c2x + u * c3x)) - qx
            ry = c0y + u * (c1y + u * (c2y + u * c3y)) - qy
            dx = c1x + u * (c2x2 + u3 * c3x)
            dy = c1y + u * (c2y2 + u3 * c3y)
            g = rx * dx + ry * dy
            dd = dx * dx + dy * dy
            hess = dd + (rx * (c2x2 + u6 * c3x) + ry * (c2y2 + u6 * c3y))
            step = g / np.where(hess > 0, hess, np.maximum(dd, 1e-300))
            u = np.clip(u - step, 0.0, h)
        t = a + u
        foot = points_at(self.curve, t)
        dist = np.hypot(qx - foot[..., 0], qy - foot[..., 1])
        # argmin over the two intervals (a reduction over an axis of two is slow): argmin takes the first NaN, so
        # the second interval when it is strictly nearer, or when it alone is NaN
        d0, d1 = dist[:, 0], dist[:, 1]
        best = ((d1 < d0) | (np.isnan(d1) & ~np.isnan(d0))).astype(np.intp)
        rows = np.arange(x.shape[0])
        return dist[rows, best], t[rows, best], self.sur.piece[iv[rows, best]]

    def polish(self, x: np.ndarray, t: np.ndarray, piece: np.ndarray, dist: np.ndarray
               ) -> tuple[np.ndarray, np.ndarray]:
        """Feet moved by Gauss-Newton steps on the *exact* curve (inside their smooth piece).

        The surrogate's foot is off along the curve by about the surrogate's own error, which a
        distance to the exact point there adds in quadrature: where the surrogate is coarse (a short,
        sharp piece gets only its few samples) that is more than a fine tolerance.  The result is the
        smaller of the two distances, each to an exact curve point, so still an upper bound.
        """
        lo, hi = self.curve.breakpoints[piece], self.curve.breakpoints[piece + 1]
        tt = t
        for _ in range(_POLISH_ITERS):
            r = points_at(self.curve, tt) - x
            d = derivatives_at(self.curve, tt, lo, hi)
            dd = dot(d, d)
            tt = np.clip(tt - dot(r, d) / np.where(dd > 0, dd, 1.0), lo, hi)
        diff = x - points_at(self.curve, tt)
        new = np.hypot(diff[:, 0], diff[:, 1])
        better = new < dist
        return np.where(better, new, dist), np.where(better, tt, t)


def _zoom_max(f: Callable[[np.ndarray, np.ndarray], np.ndarray], lo: np.ndarray, hi: np.ndarray,
              levels: int = 2, m: int = 33, per_step: float | np.ndarray | None = None) -> np.ndarray:
    """Maximum of ``f`` on each ``[lo, hi]`` by nested sample grids (one batched call of ``f`` per level);
    ``f(points, rows)`` takes the brackets (rows of ``lo``) its points belong to.

    ``per_step``: when given, the maximum of ``f`` between two samples ``Δ`` apart exceeds the larger of them by
    at most ``per_step·Δ²`` (the certificate's bound, :mod:`camfab.discretize.certify`), and a bracket whose
    samples plus that bound stay below the largest value found so far is not zoomed into further.  The overall
    maximum and the bracket holding it are then the same bit for bit: such a bracket holds no value reaching
    the largest, so neither does any sample a further level would take (a 1e-9 relative margin covers the
    rounding of the bound and of the distances); the entry of a bracket left out is its last level's maximum.
    ``per_step`` may also be an array, one value per bracket."""
    best = np.full(lo.size, -np.inf)
    grid = np.linspace(0.0, 1.0, m)
    rows = np.arange(lo.size)
    for level in range(levels):
        u = lo[:, None] + (hi - lo)[:, None] * grid
        v = f(u, rows)
        j = v.argmax(axis=1)
        here = np.arange(rows.size)
        best[rows] = np.maximum(best[rows], v[here, j])
        lo, hi = u[here, np.maximum(j - 1, 0)], u[here, np.minimum(j + 1, m - 1)]
        if per_step is not None and level + 1 < levels:
            step = u[:, 1] - u[:, 0]
            ps = per_step if np.ndim(per_step) == 0 else np.asarray(per_step)[rows]
            keep = (best[rows] + ps * step * step) * (1.0 + 1e-9) >= best.max()
            rows, lo, hi = rows[keep], lo[keep], hi[keep]
            if not rows.size:
                break
    return best


def _curve_to_chain(chain: Chain, curve: ParametricCurve, sur: HermiteSurrogate,
                    refine_top: int) -> tuple[float, float]:
    """Largest distance from the exact curve to the chain and its parameter: exact distances of the
    surrogate's exact samples, the worst local maxima refined by nested grids of exact points."""
    ts = sur.x
    n_t = ts.size - 1
    d_a, _ = chain.distance(sur.points[:-1] if curve.closed else sur.points)

    def g_a(t):
        return chain.distance(points_at(curve, t.ravel()))[0].reshape(t.shape)

    top = _local_maxima(d_a, curve.closed, refine_top)
    if curve.closed:
        lo_t = np.where(top > 0, ts[top - 1], ts[n_t - 1] - curve.period)
        hi_t = ts[top + 1]
    else:
        lo_t, hi_t = ts[np.maximum(top - 1, 0)], ts[np.minimum(top + 1, n_t)]
    best_a = _zoom_max(lambda t, _: g_a(t), lo_t, hi_t) if top.size else np.zeros(0)
    i_a = int(np.argmax(d_a))
    worst_a, at_a = float(d_a[i_a]), float(ts[i_a])
    if best_a.size and best_a.max() > worst_a:
        worst_a = float(best_a.max())
        at_a = float(np.mod(0.5 * (lo_t + hi_t)[best_a.argmax()], curve.period))
    return worst_a, at_a


def _chain_to_curve(chain: Chain, sur: HermiteSurrogate, per_entity: int,
                    refine_top: int) -> tuple[float, float]:
    """Largest distance from the chain to the exact curve and the parameter of its foot: entity samples
    projected onto the curve, the worst local maxima refined by nested grids along their entities."""
    proj = _CurveProjector(sur)
    x, u = chain.sample(per_entity)
    xs = x.reshape(-1, 2)
    d_b, t_b, p_b = proj.project(xs)
    polished = np.zeros(d_b.size, dtype=bool)
    for _ in range(_POLISH_ROUNDS):  # polish every sample that could hold the maximum
        sel = np.flatnonzero(~polished & (d_b >= 0.5 * d_b.max()))
        if sel.size == 0:
            break
        d_b[sel], t_b[sel] = proj.polish(xs[sel], t_b[sel], p_b[sel], d_b[sel])
        polished[sel] = True

    def dist(q):
        d, t, piece = proj.project(q)
        return proj.polish(q, t, piece, d)[0]

    return _refine_along_entities(chain, u, d_b, t_b, refine_top, dist, 33)


def _refine_along_entities(chain: Chain, u: np.ndarray, d_b: np.ndarray, t_b: np.ndarray, refine_top: int,
                           dist: Callable[[np.ndarray], np.ndarray], m: int) -> tuple[float, float]:
    """The largest of the entity samples' distances ``d_b`` (feet ``t_b``; ``u`` their arc lengths, one row per
    entity) with its ``refine_top`` worst local maxima refined by nested grids of ``m`` points along their
    entities (``dist`` of points ``(K, 2)``), and the foot's parameter."""
    per_entity = u.shape[1]
    i_b = int(np.argmax(d_b))
    worst_b, at_b = float(d_b[i_b]), float(t_b[i_b])
    flat = _local_maxima(d_b, False, refine_top)
    if flat.size:
        ent, ui = flat // per_entity, flat % per_entity
        u_lo = u[ent, np.maximum(ui - 1, 0)]
        u_hi = u[ent, np.minimum(ui + 1, per_entity - 1)]

        def g_b(uu, _):
            pts = entity_point(chain.start[ent, None], chain.tangent[ent, None], chain.curvature[ent, None], uu)
            return dist(pts.reshape(-1, 2)).reshape(uu.shape)

        best_b = _zoom_max(g_b, u_lo, u_hi, m=m)
        if best_b.max() > worst_b:
            worst_b = float(best_b.max())
            at_b = float(t_b.reshape(chain.n, per_entity)[ent[best_b.argmax()], ui[best_b.argmax()]])
    return worst_b, at_b


def measure_deviation(entities, curve: ParametricCurve, *, samples: int = 20000,
                      per_entity: int = 17, refine_top: int = 32) -> Deviation:
    """Two-way maximum distance between entities and the exact curve (see the module notes).

    Parameters
    ----------
    entities : Chain, ArcChain, Discretisation or array_like
        An arc chain or discretisation, ``(n, 2)`` polyline vertices or ``(n, 3)`` rows
        ``(x, y, bulge)`` of an LWPOLYLINE, e.g. read back from a file (closed implicitly when the
        curve is closed).
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
        ``max``, both one-way maxima (mm) and where the maximum occurs.
    """
    chain = as_chain(entities, curve.closed)
    if chain.n == 0:
        raise GeometryError("no entities to measure: give at least one line or arc")
    sur = HermiteSurrogate(curve, max(int(samples), 8 * chain.n), min_count=8)
    worst_a, at_a = _curve_to_chain(chain, curve, sur, refine_top)
    worst_b, at_b = _chain_to_curve(chain, sur, per_entity, refine_top)
    return two_way_deviation(curve, worst_a, at_a, worst_b, at_b)


def _near_entities(chain: Chain, q: np.ndarray, ent: np.ndarray, reach: int = 1, cyclic: bool = True,
                   with_entity: bool = False):
    """Distance from each point ``q`` ``(..., 2)`` to the nearest of the entities ``ent - reach … ent + reach``
    (``ent`` of ``q``'s leading shape, or broadcasting to it; cyclic, or clipped to the chain's first and last
    entities when ``cyclic`` is false): an upper bound of its distance to the chain, exact when the nearest entity
    is among them.  ``with_entity``: also which of them is the nearest (the first of ``ent``, ``ent - 1``, ``ent + 1``,
    … among equal distances), as a second array.

    The hot loop of :func:`measure_fit` (~10⁴ points × 3 entities, several times per fit): the chain's entities
    are laid out once as a table of contiguous columns, padded by ``reach`` entities at both ends, so that the
    ``2·reach + 1`` neighbours are plain column gathers with the neighbour axis first (no modulo, no gathers of
    ``(…, 2)`` rows, contiguous rows for the element-wise arithmetic and the running minimum).  The distance to
    ``ent`` is taken first; a neighbour's end distance provably above it is skipped (it cannot be the minimum).
    Every distance that can be the minimum is :func:`~camfab.discretize.entities.entity_distance`'s, operation
    for operation, so the result is the same bit for bit."""
    n = chain.n
    ent = np.broadcast_to(ent, q.shape[:-1]).ravel()
    if ent.size and (ent.min() < 0 or ent.max() >= n):
        ent = ent % n
    slots = np.arange(-reach, n + reach)  # the entity of every padded slot
    slots = slots % n if cyclic else np.clip(slots, 0, n - 1)
    table = np.stack([chain.start[:, 0], chain.start[:, 1], chain.tangent[:, 0], chain.tangent[:, 1],
                      chain.curvature, chain.length, chain.end[:, 0], chain.end[:, 1]])[:, slots]
    # slot of entity ent + off is ent + off + reach; the row of ``ent`` itself first (see below)
    idx = ent + np.concatenate([[reach], np.delete(np.arange(2 * reach + 1), reach)])[:, None]
    s0, s1, t0, t1, k, length, e0, e1 = (np.take(col, idx) for col in table)
    flat = q.reshape(-1, 2)
    q0, q1 = flat[:, 0], flat[:, 1]
    w0, w1 = q0 - s0, q1 - s1
    x = w0 * t0 + w1 * t1  # dot(w, tangent)
    y = t0 * w1 - t1 * w0  # cross(tangent, w)
    f0, f1 = q0 - e0, q1 - e1
    # the distance to ``ent`` first: a neighbour's end distance can only matter when below it, and where the point
    # is far from that end (nearly everywhere) its two hypot are skipped (local_distance's ``above``)
    best = local_distance(x[0], y[0], k[0], length[0], w0[0], w1[0], f0[0], f1[0])
    at = idx[0]
    if reach:
        rest = local_distance(x[1:].ravel(), y[1:].ravel(), k[1:].ravel(), length[1:].ravel(), w0[1:].ravel(),
                              w1[1:].ravel(), f0[1:].ravel(), f1[1:].ravel(), np.tile(best, 2 * reach))
        for r, row in enumerate(rest.reshape(2 * reach, -1)):
            if with_entity:  # (a neighbour's skipped end distance is above ``best``: never taken)
                at = np.where(row < best, idx[r + 1], at)
            # distances are never -0 (nor zeros of mixed signs): the minimum is the same in any order
            best = np.minimum(best, row)
    if with_entity:
        return best.reshape(q.shape[:-1]), slots[at].reshape(q.shape[:-1])
    return best.reshape(q.shape[:-1])


def owners(foot: np.ndarray, period: float) -> Callable[[np.ndarray], np.ndarray]:
    """The entity a curve parameter belongs to: the one whose start's foot ``foot`` (curve parameters, one per
    entity) comes last before it (cyclic)."""
    order = np.argsort(foot, kind="stable")
    sorted_foot = foot[order]
    n = foot.size

    def owner(t):
        return order[(np.searchsorted(sorted_foot, np.mod(t, period), side="right") - 1) % n]

    return owner


def _interval_ends(chain: Chain, q: np.ndarray, d: np.ndarray, nearest: np.ndarray, n_t: int, closed: bool
                   ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """For the ``n_t`` intervals between the curve samples ``q`` (a closed curve's last one back to the first):
    ``(d0, d1, e0, e1)``, the distances at both ends and the entities from ``e0`` to ``e1`` the local bound reads.

    A sample's entity is its nearest; where the sample is as near (to :data:`_JOINT_SLACK`) a point of the entity on
    the interval's side of it (the end of the one before, at the interval's end; the start of the one after, at its
    start), that entity is taken instead, its distance ``_JOINT_SLACK`` more: an interval ending on the joint between
    two arcs of different curvature then reads only the arc it runs along."""
    d0, e0 = d[:n_t], nearest[:n_t]
    qa, qb = q[:n_t], (q[1:] if d.size > n_t else np.roll(q, -1, axis=0))
    d1, e1 = (d[1:], nearest[1:]) if d.size > n_t else (np.roll(d, -1), np.roll(nearest, -1))
    n = chain.n
    span = (e1 - e0) % n if closed else e1 - e0
    e1, d1, before = _toward_joint(qb, d1, e1, chain.end, -1, span >= 1, n)  # the end of the entity before e1
    e0, d0, _ = _toward_joint(qa, d0, e0, chain.start, 1, span - before >= 1, n)  # the start of the one after e0
    return d0, d1, e0, e1


def _toward_joint(p: np.ndarray, dist: np.ndarray, ent: np.ndarray, joints: np.ndarray, step: int, room: np.ndarray,
                  n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The joint rule of :func:`_interval_ends` at one end of the intervals: ``(entity, distance, moved)``, each point
    ``p`` whose joint with the entity ``ent + step`` (``joints``: the chain's ends for ``step`` -1, starts for +1) lies
    no farther than its distance ``dist`` plus :data:`_JOINT_SLACK` read against that entity, its distance that slack
    more, where the interval has ``room`` (spans more than one entity)."""
    j = (ent + step) % n
    joint = joints[j]
    moved = room & (np.hypot(p[:, 0] - joint[:, 0], p[:, 1] - joint[:, 1]) <= dist + _JOINT_SLACK)
    return np.where(moved, j, ent), np.where(moved, dist + _JOINT_SLACK, dist), moved


def _local_brackets(chain: Chain, q: np.ndarray, ts: np.ndarray, d: np.ndarray, nearest: np.ndarray, top: np.ndarray,
                    worst: float, local, closed: bool) -> tuple[float, np.ndarray, np.ndarray, np.ndarray]:
    """With the local bound: ``(certified, top, reach, per_step)``, the largest sample interval's bound and the
    local maxima ``top`` (of the samples' distances ``d``) whose bracket, the two intervals beside each (one at an
    open curve's ends), can hold a distance above ``worst``, with their brackets' bound and ``c_i``."""
    n_t = ts.size - 1
    d0, d1, e0, e1 = _interval_ends(chain, q, d, nearest, n_t, closed)
    c = local.per_step(ts, d0, d1, e0, e1)
    dt = ts[1:] - ts[:-1]
    interval = np.maximum(d0, d1) + c * dt * dt  # each sample interval's bound
    before = (top - 1) % n_t if closed else np.maximum(top - 1, 0)
    after = np.minimum(top, n_t - 1)
    reach = np.maximum(interval[before], interval[after])
    keep = reach * (1.0 + 1e-9) >= worst
    return float(interval.max()), top[keep], reach[keep], np.maximum(c[before], c[after])[keep]


def fit_curve_to_chain(chain: Chain, curve: ParametricCurve, samples: int, gap: float,
                       foot: np.ndarray, bound: tuple[float, float] | None = None, local=None,
                       nodes: np.ndarray | None = None) -> tuple[float, float, float]:
    """Largest distance from the exact curve to the chain, its parameter, and (with ``local``) the certified bound
    of the true maximum, from one call of the curve at the nodes :func:`measure_deviation` takes for ``samples``.

    A sample's distance is taken to the entity whose start's foot ``foot`` (curve parameters, one per entity) comes
    last before it and to that entity's two neighbours: an upper bound, exact for a chain that follows its curve
    (any sample left too far only makes the certificate fail, and the default measurement runs).  Without
    ``local`` every local maximum within ``gap`` of the largest is refined by nested grids of exact points (by the
    bound of :mod:`camfab.discretize.certify` only those can hold the true maximum); with ``bound``, the
    certificate's ``(K, max |P′|)``, only the brackets that can still hold the largest distance are zoomed into a
    second time (:func:`_zoom_max`); the third value is inf.

    ``local`` (a :class:`~camfab.discretize.certify.LocalBound`) gives every sample interval its own bound ``c_i``
    (the distance there is at most the larger sample plus ``c_i·Δt²``): the third value is the largest such bound,
    only the local maxima whose bracket can exceed the largest sample are refined (each with its own ``c_i``), and a
    refined value above its bracket's bound (the bound was wrong) makes the third value inf.  ``nodes``: the sample
    parameters instead (every breakpoint and the period among them, increasing)."""
    ts = sample_nodes(curve, max(int(samples), 8 * chain.n), 8)[0] if nodes is None else nodes
    n_t = ts.size - 1
    owner = owners(foot, curve.period)
    t_a = ts[:-1] if curve.closed else ts
    ent = owner(t_a)
    # (the local bound reads the entities around a sample's own: an open chain's window does not wrap)
    cyclic = curve.closed or local is None
    q = points_at(curve, t_a)
    if local is None:
        d_a = _near_entities(chain, q, ent, 1, cyclic)
    else:
        d_a, nearest = _near_entities(chain, q, ent, 1, cyclic, with_entity=True)
    i_a = int(np.argmax(d_a))
    worst_a, at_a = float(d_a[i_a]), float(ts[i_a])
    top = _local_maxima(d_a, curve.closed, d_a.size)
    certified = np.inf
    per_step: float | np.ndarray | None = None if bound is None else bound[0] * bound[1] ** 2 / 8.0
    if local is not None:
        certified, top, reach, per_step = _local_brackets(chain, q, ts, d_a, nearest, top, worst_a, local,
                                                          curve.closed)
    else:
        top = top[d_a[top] >= worst_a - gap]
    if not top.size:
        return worst_a, at_a, certified
    if curve.closed:
        lo_t = np.where(top > 0, ts[top - 1], ts[n_t - 1] - curve.period)
        hi_t = ts[top + 1]
    else:
        lo_t, hi_t = ts[np.maximum(top - 1, 0)], ts[np.minimum(top + 1, n_t)]
    near = ent[top]
    # (samples Δt apart miss at most K·(max|P′|·Δt)²/8: certify's gap)
    best_a = _zoom_max(lambda t, rows: _near_entities(chain, points_at(curve, t), near[rows, None], 2, cyclic),
                       lo_t, hi_t, levels=2 if local is None else _LOCAL_LEVELS, m=_FIT_ZOOM, per_step=per_step)
    if local is not None and np.any(best_a > reach * (1.0 + 1e-9) + 1e-15):
        certified = np.inf  # a refined distance above its bracket's bound: no certificate
    if best_a.max() > worst_a:
        worst_a = float(best_a.max())
        at_a = float(np.mod(0.5 * (lo_t + hi_t)[best_a.argmax()], curve.period))
    return worst_a, at_a, certified


def fit_chain_to_curve(chain: Chain, sur: HermiteSurrogate, per_entity: int = 17, refine_top: int = 8
                       ) -> tuple[float, float, np.ndarray]:
    """Largest distance from the chain to the exact curve, its foot's parameter, and the foot of every entity's
    start: entity samples projected on the fit's stand-in ``sur`` (Newton on its cubics), each distance taken to
    the exact curve point at the foot (one call: upper bounds); the ``refine_top`` worst local maxima refined by
    nested grids along their entities.  No polishing on the exact curve: the stand-in's measured error ``ε`` is
    at most ``tol/200``, and a foot off by it overstates a distance ``d`` by about ``ε²/(2d)`` (a bound still,
    and a few parts in 10⁵ of tol at most at the largest distances)."""
    proj = _CurveProjector(sur)
    x, u = chain.sample(per_entity)
    d_b, t_b, _ = proj.project(x.reshape(-1, 2))
    worst_b, at_b = _refine_along_entities(chain, u, d_b, t_b, refine_top, lambda q: proj.project(q)[0], _FIT_ZOOM)
    return worst_b, at_b, t_b.reshape(chain.n, per_entity)[:, 0]


def two_way_deviation(curve: ParametricCurve, worst_a: float, at_a: float, worst_b: float, at_b: float) -> Deviation:
    """The :class:`Deviation` of the two directions' maxima and their parameters (curve to chain, chain to curve),
    located at the larger one's parameter (the curve to chain one on a tie)."""
    at = at_a if worst_a >= worst_b else at_b
    return Deviation(max=max(worst_a, worst_b), curve_to_entities=worst_a,
                     entities_to_curve=worst_b, at_param=at, at_point=points_at(curve, np.array([at]))[0])


def measure_fit(chain: Chain, curve: ParametricCurve, sur: HermiteSurrogate, samples: int, gap: float, *,
                per_entity: int = 17, refine_top: int = 8, bound: tuple[float, float] | None = None,
                chain_to_curve: tuple[float, float, np.ndarray] | None = None) -> Deviation:
    """The fit's own two-way measurement of ``chain`` on its stand-in ``sur`` (a :func:`fit_surrogate` result,
    error at most ``tol/200``), for :func:`~camfab.discretize.certify.certified_deviation`.

    Curve to chain as :func:`measure_deviation` with ``samples`` (the same exact sample nodes, one call of the
    curve), refining every sampled local maximum within ``gap`` (the certificate's ``K·h²/8``) of the largest
    instead of a fixed number; chain to curve by projection on ``sur`` instead of a stand-in built from new
    exact samples and derivatives, without polishing (:func:`fit_chain_to_curve`).  About six calls of the exact
    curve instead of ~25.  ``bound``: the certificate's ``(K, max |P′|)`` that gave ``gap``, when known; the
    refinement then zooms only into the brackets that can hold the largest distance (:func:`_zoom_max`: the same
    result).  ``chain_to_curve``: :func:`fit_chain_to_curve`'s result for ``per_entity`` and ``refine_top``, when
    already taken (the local certificate took it)."""
    if chain.n == 0:
        raise GeometryError("no entities to measure: give at least one line or arc")
    worst_b, at_b, foot = fit_chain_to_curve(chain, sur, per_entity, refine_top) if chain_to_curve is None \
        else chain_to_curve
    worst_a, at_a, _ = fit_curve_to_chain(chain, curve, samples, gap, foot, bound)
    return two_way_deviation(curve, worst_a, at_a, worst_b, at_b)


def max_deviation(entities, curve: ParametricCurve, **kwargs) -> float:
    """Two-way maximum distance (mm) between entities and the exact curve.

    A shorthand for ``measure_deviation(entities, curve, **kwargs).max``; see
    :func:`measure_deviation` for the accepted ``entities``.
    """
    return measure_deviation(entities, curve, **kwargs).max
