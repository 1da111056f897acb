"""Exact distances from points to chains of lines and arcs, indexed so that their cost follows the number of
points and entities, never the size of the part.

:class:`Entities` holds lines, arcs and the near-arc spirals a back-plot can contain (an ``I J`` arc whose
start and end radii differ a little: the radius changes linearly with the angle) as flat arrays.  Its
:meth:`Entities.nearest` finds, for every query point, the nearest entity and the distance to it: the
candidates are the entities of the ``k`` nearest of a few thousand samples spread along the chain (a
k-d tree); the answer is *proved* exact where the ``k``-th sample is farther than the best distance found
plus half the sample spacing (every entity has a sample within half a spacing of each of its points, so no
entity left out can be nearer); for the other points (16, then 128 nearest samples, then) a ball query of
that radius gathers every entity that can be nearer.  The spacing is at most the chain's length over a
fixed number of samples, so a cam ten metres across costs what a small one does.

:class:`IndexedContourDistance` is the signed distance to a closed contour (negative inside, the side taken
from the nearest entity, or from the polygon at a sharp vertex), with the values of
:class:`camfab.gcode.contour.ContourDistance`: for a polyline (what :func:`camfab.gcode.cam.signed_distance`
measures against) the nearest segment comes from GEOS's R-tree (``shapely.STRtree.query_nearest``, exact),
for a chain with arcs from :meth:`Entities.nearest`.

The distance to a spiral is measured along the radius from its centre (to the spiral's radius at that
angle), larger than the true distance by a factor ``sqrt(1 + slope**2)`` where ``slope`` is the radius
change per unit arc length: 1e-6 relative for the 0.02 mm a back-plot accepts over a 20 mm arc.
"""
from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from camfab.discretize import polyline
from camfab.discretize.curve import derivatives_at, piece_index, points_at
from camfab.errors import ApiError, GeometryError
from camfab.gcode.contour import Segment, as_contour
from camfab.geom2d import TWO_PI, ArcChain

__all__ = ["CurveDistance", "Entities", "IndexedContourDistance", "SAMPLES_PER_CHAIN"]

#: samples spread along a chain for the candidate search (the spacing is the chain's length over this)
SAMPLES_PER_CHAIN = 4096
#: nearest samples whose entities are the candidates of a query point
_K = 16
#: the most nearest samples tried (16, 128) before a ball query gathers every candidate of a point
_K_MAX = 128
#: sub-intervals of a coarse segment where the nearest point of the curve is looked for
_SUB = 4
#: the most Illinois steps (it converges with order 1.44: ~12 from a grid bracket to 1e-13)
_ILLINOIS_STEPS = 60
#: point-entity pairs measured at once (bounds the memory)
_PAIRS = 1 << 18
#: points per ball query (bounds the memory of the candidate lists)
_BALL_BLOCK = 256


class Entities:
    """Lines, arcs and spirals as arrays, with exact nearest-entity queries.

    Parameters
    ----------
    starts, ends : (n, 2) array
        End points, mm.
    centres : (n, 2) array
        Arc centres; NaN rows for lines.
    sweeps : (n,) array
        Signed sweeps in radians (> 0 counter-clockwise), 0 for lines.
    radii_end : (n,) array, optional
        Radius at the end of each arc (default: the start radius; a different value makes a spiral).
    """

    def __init__(self, starts, ends, centres, sweeps, radii_end=None):
        self.a = np.asarray(starts, dtype=float).reshape(-1, 2)
        self.b = np.asarray(ends, dtype=float).reshape(-1, 2)
        self.c = np.asarray(centres, dtype=float).reshape(-1, 2)
        self.sw = np.asarray(sweeps, dtype=float).reshape(-1)
        n = len(self.a)
        if not (len(self.b) == len(self.c) == len(self.sw) == n):
            raise ApiError("Entities: starts, ends, centres and sweeps need one row per entity")
        self.arc = self.sw != 0.0
        with np.errstate(invalid="ignore"):
            self.rs = np.where(self.arc, np.hypot(*(self.a - self.c).T), np.nan)
            self.a0 = np.where(self.arc, np.arctan2(self.a[:, 1] - self.c[:, 1], self.a[:, 0] - self.c[:, 0]), 0.0)
        re_ = self.rs if radii_end is None else np.asarray(radii_end, dtype=float).reshape(-1)
        self.re = np.where(self.arc, re_, np.nan)
        self.length = np.where(self.arc, np.abs(self.sw) * np.fmax(self.rs, self.re),
                               np.hypot(*(self.b - self.a).T))
        self._tree = None

    @classmethod
    def from_segments(cls, segs: Sequence[Segment]) -> Entities:
        """From :class:`~camfab.gcode.contour.Segment` objects."""
        nan = (math.nan, math.nan)
        return cls([s.start for s in segs], [s.end for s in segs], [s.center or nan for s in segs],
                   [s.sweep for s in segs])

    @classmethod
    def from_moves(cls, moves) -> Entities:
        """The XY paths of back-plotted moves (:class:`~camfab.gcode.parse.Move`; spirals included)."""
        nan = (math.nan, math.nan)
        return cls([m.start[:2] for m in moves], [m.end[:2] for m in moves],
                   [m.center if m.kind == "arc" else nan for m in moves],
                   [m.sweep if m.kind == "arc" else 0.0 for m in moves],
                   [m.radius_end if m.kind == "arc" else math.nan for m in moves])

    def __len__(self) -> int:
        return len(self.a)

    # -- samples and the candidate index ---------------------------------------------------------------
    def points(self, spacing: float, max_per_entity: int | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Points along every entity at most ``spacing`` apart (arc length), each entity's two ends included,
        at most ``max_per_entity + 1`` per entity; returns ``(points (m, 2), entity index (m,))``."""
        k = np.maximum(1, np.ceil(self.length / spacing - 1e-9)).astype(np.int64)
        if max_per_entity is not None:
            k = np.minimum(k, max_per_entity)
        k = np.where(self.arc, np.maximum(k, np.ceil(np.abs(self.sw) / (math.pi / 8)).astype(np.int64)), k)
        ent = np.repeat(np.arange(len(self)), k + 1)
        start = np.repeat(np.cumsum(k + 1) - (k + 1), k + 1)
        u = (np.arange(len(ent)) - start) / k[ent]
        return self.at(ent, u), ent

    def at(self, ent: np.ndarray, u: np.ndarray) -> np.ndarray:
        """Points at fraction ``u`` (0..1) along entities ``ent``."""
        a, b = self.a[ent], self.b[ent]
        line = a + u[:, None] * (b - a)
        arc = self.arc[ent]
        if not arc.any():
            return line
        ang = self.a0[ent] + self.sw[ent] * u
        r = self.rs[ent] + (self.re[ent] - self.rs[ent]) * u
        with np.errstate(invalid="ignore"):
            pa = self.c[ent] + r[:, None] * np.column_stack([np.cos(ang), np.sin(ang)])
        out = np.where(arc[:, None], pa, line)
        ends = u >= 1.0
        out[ends] = b[ends]
        return out

    def _index(self):
        if self._tree is None:
            from scipy.spatial import cKDTree

            spacing = max(float(self.length.sum()) / SAMPLES_PER_CHAIN, 1e-9)
            pts, ent = self.points(spacing)
            # the largest arc-length gap between neighbouring samples of one entity
            k = np.bincount(ent, minlength=len(self)) - 1
            self._h = float(np.max(self.length / np.maximum(k, 1)))
            self._tree = (cKDTree(pts), ent, len(pts))
        return self._tree

    @property
    def spacing(self) -> float:
        """The largest arc-length gap between neighbouring samples of one entity in the candidate index, mm."""
        self._index()
        return self._h

    # -- distances ---------------------------------------------------------------------------------------
    def fraction(self, p: np.ndarray, j: np.ndarray) -> np.ndarray:
        """Where along entity ``j[i]`` (0 at its start, 1 at its end) the point nearest ``p[i]`` lies."""
        a, b = self.a[j], self.b[j]
        ab = b - a
        L2 = np.einsum("ij,ij->i", ab, ab)
        u_line = np.clip(np.where(L2 > 0, np.einsum("ij,ij->i", p - a, ab) / np.where(L2 > 0, L2, 1.0), 0.0), 0, 1)
        arc = self.arc[j]
        if not arc.any():
            return u_line
        sw = np.abs(self.sw[j])
        with np.errstate(invalid="ignore"):
            phi = np.arctan2(p[:, 1] - self.c[j, 1], p[:, 0] - self.c[j, 0])
            rel = np.where(self.sw[j] > 0, (phi - self.a0[j]) % TWO_PI, (self.a0[j] - phi) % TWO_PI)
            end = np.hypot(*(p - b).T) < np.hypot(*(p - a).T)
            u_arc = np.where(rel < sw, rel / np.where(sw > 0, sw, 1.0), np.where(end, 1.0, 0.0))
        return np.where(arc, u_arc, u_line)

    def pair(self, p: np.ndarray, j: np.ndarray, ccw: bool = True):
        """Distance from each point ``p[i]`` to entity ``j[i]``: ``(d, interior, inside)`` where ``interior``
        says the nearest point is inside the entity (not an end) and ``inside`` is the side that lies inside
        a contour of orientation ``ccw``."""
        a, b = self.a[j], self.b[j]
        arc = self.arc[j]
        # lines
        ab = b - a
        L2 = np.einsum("ij,ij->i", ab, ab)
        ap = p - a
        t = np.where(L2 > 0, np.einsum("ij,ij->i", ap, ab) / np.where(L2 > 0, L2, 1.0), 0.0)
        tc = np.clip(t, 0.0, 1.0)
        q = a + tc[:, None] * ab
        d_line = np.hypot(*(p - q).T)
        int_line = (t > 0.0) & (t < 1.0) & (L2 > 0)
        cross = ab[:, 0] * ap[:, 1] - ab[:, 1] * ap[:, 0]
        ins_line = cross > 0 if ccw else cross < 0
        if not arc.any():
            return d_line, int_line, ins_line
        # arcs and spirals
        sw = self.sw[j]
        with np.errstate(invalid="ignore"):
            dx = p - self.c[j]
            rho = np.hypot(*dx.T)
            phi = np.arctan2(dx[:, 1], dx[:, 0])
            rel = np.where(sw > 0, (phi - self.a0[j]) % TWO_PI, (self.a0[j] - phi) % TWO_PI)
            full = np.abs(sw) >= TWO_PI - 1e-15
            int_arc = full | (rel < np.abs(sw))
            u = np.clip(np.where(np.abs(sw) > 0, rel / np.where(np.abs(sw) > 0, np.abs(sw), 1.0), 0.0), 0.0, 1.0)
            r = self.rs[j] + (self.re[j] - self.rs[j]) * u
            d_ends = np.minimum(np.hypot(*(p - a).T), np.hypot(*(p - b).T))
            d_arc = np.where(int_arc, np.abs(rho - r), d_ends)
            ins_arc = np.where((sw > 0) == ccw, rho < r, rho > r)
        return (np.where(arc, d_arc, d_line), np.where(arc, int_arc, int_line), np.where(arc, ins_arc, ins_line))

    def nearest(self, points, ccw: bool = True) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Exact nearest entity of every point: ``(distance, entity, interior, inside)`` (see :meth:`pair`)."""
        p = np.asarray(points, dtype=float).reshape(-1, 2)
        m = len(p)
        best = np.full(m, np.inf)
        j_best = np.zeros(m, dtype=np.int64)
        interior = np.zeros(m, dtype=bool)
        inside = np.zeros(m, dtype=bool)
        if m == 0 or len(self) == 0:
            return best, j_best, interior, inside
        tree, ent, n_samples = self._index()
        rows, done, k = np.arange(m), 0, _K
        while len(rows):
            k = min(k, n_samples)
            pr = p[rows]
            dk, ik = tree.query(pr, k=k)
            dk, ik = dk.reshape(len(rows), k), ik.reshape(len(rows), k)
            # the candidates not measured yet, a block of points at a time
            nc = k - done
            blk = max(1, _PAIRS // nc)
            for lo in range(0, len(rows), blk):
                rb, pb = rows[lo:lo + blk], pr[lo:lo + blk]
                j = ent[ik[lo:lo + blk, done:]]
                d, it, ins = (v.reshape(len(rb), nc) for v in self.pair(np.repeat(pb, nc, axis=0), j.reshape(-1), ccw))
                at = (np.arange(len(rb)), np.argmin(d, axis=1))  # the first of equal ones: the nearest sample's
                _keep_nearer((best, j_best, interior, inside), rb, (d[at], j[at], it[at], ins[at]))
            if k == n_samples:
                return best, j_best, interior, inside  # every sample (so every entity) was a candidate
            # proved where no sample left out lies within best + h/2 (every entity has one that close to
            # each of its points)
            rows = rows[~(dk[:, -1] > best[rows] + 0.5 * self._h * (1 + 1e-9) + 1e-12)]
            if k >= _K_MAX:
                break
            done, k = k, k * 8
        # the rest (points nearly as far from a long stretch of the chain as from its nearest point): every
        # entity with a sample within best + h/2, found by a ball query, a block of points at a time
        pts_tree = tree
        for lo in range(0, len(rows), _BALL_BLOCK):
            blk = rows[lo:lo + _BALL_BLOCK]
            balls = pts_tree.query_ball_point(p[blk], best[blk] + 0.5 * self._h * (1 + 1e-9) + 1e-12)
            sizes = np.fromiter((len(b) for b in balls), dtype=np.int64, count=len(blk))
            if not sizes.sum():
                continue
            ri = np.repeat(np.arange(len(blk)), sizes)
            ei = ent[np.concatenate([np.asarray(b, dtype=np.int64) for b in balls])]
            key = np.unique(ri * len(self) + ei)
            ri, ei = key // len(self), key % len(self)
            d, it, ins = self.pair(p[blk][ri], ei, ccw)
            order = np.lexsort((ei, d, ri))  # per point: the smallest distance, then the first entity
            ri, ei, d, it, ins = ri[order], ei[order], d[order], it[order], ins[order]
            first = np.ones(len(ri), dtype=bool)
            first[1:] = ri[1:] != ri[:-1]
            _keep_nearer((best, j_best, interior, inside), blk[ri[first]], (d[first], ei[first], it[first], ins[first]))
        return best, j_best, interior, inside

    def distance(self, points) -> np.ndarray:
        """Unsigned distance from each point to the nearest entity, mm."""
        return self.nearest(points)[0]


def _keep_nearer(state: tuple, rows: np.ndarray, found: tuple) -> None:
    """Where ``found`` (distance, entity, interior, inside of ``rows``) is nearer than ``state``, take it."""
    closer = found[0] < state[0][rows]
    r = rows[closer]
    for have, new in zip(state, found, strict=True):
        have[r] = new[closer]


class IndexedContourDistance:
    """Exact signed distance to a closed contour of lines and arcs (negative inside), indexed.

    The same values as :class:`camfab.gcode.contour.ContourDistance` at a cost that grows with the number of
    points and entities only.

    Parameters
    ----------
    entities : sequence
        The closed contour: an :class:`~camfab.geom2d.ArcChain` or anything
        :func:`~camfab.gcode.contour.as_contour` accepts.
    """

    def __init__(self, entities):
        import shapely

        if isinstance(entities, ArcChain):
            if not entities.closed:
                raise GeometryError("an open arc chain is not a contour; close it (the part must lie inside)")
            self.entities = Entities(entities.starts, entities.ends, entities.centres, entities.sweeps)
        else:
            self.entities = Entities.from_segments(as_contour(entities))
        e = self.entities
        k = np.where(e.arc, np.maximum(8, np.ceil(np.abs(e.sw) / TWO_PI * 720)), 1).astype(np.int64)
        ent = np.repeat(np.arange(len(e)), k)
        u = (np.arange(len(ent)) - np.repeat(np.cumsum(k) - k, k)) / k[ent]
        poly = e.at(ent, u)
        x, y = poly[:, 0], poly[:, 1]
        self.clockwise = bool(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y) < 0)
        self.polygon = shapely.Polygon(poly)
        shapely.prepare(self.polygon)
        #: an R-tree of the segments when the contour is a polyline (None with arcs)
        self.segments_tree = None if e.arc.any() else shapely.STRtree(
            shapely.linestrings(np.stack([e.a, e.b], axis=1)))
        self._cum = np.concatenate([[0.0], np.cumsum(e.length)])

    def __call__(self, points) -> np.ndarray:
        """Signed distance of ``points`` (array ``(n, 2)``) in mm; negative inside."""
        import shapely

        p = np.asarray(points, dtype=float).reshape(-1, 2)
        ok = np.all(np.isfinite(p), axis=1)
        if not ok.all():
            out = np.full(len(p), np.nan)
            out[ok] = self(p[ok])
            return out
        if self.segments_tree is not None and len(p):  # a polyline: GEOS's R-tree finds the nearest segment exactly
            (i, j), _ = self.segments_tree.query_nearest(shapely.points(p), return_distance=True, all_matches=False)
            d, interior, inside = self.entities.pair(p, j[np.argsort(i, kind="stable")], not self.clockwise)
        else:
            d, _, interior, inside = self.entities.nearest(p, ccw=not self.clockwise)
        vertex = np.nonzero(~interior)[0]
        if len(vertex):
            inside[vertex] = shapely.contains_xy(self.polygon, p[vertex, 0], p[vertex, 1])
        return np.where(inside, -d, d)

    def points(self, spacing: float, max_per_entity: int | None = None) -> np.ndarray:
        """Points along the contour at most ``spacing`` apart, at most ``max_per_entity + 1`` per entity."""
        return self.entities.points(spacing, max_per_entity)[0]

    @property
    def length(self) -> float:
        """Length of the contour, mm."""
        return float(self._cum[-1])

    def project(self, points) -> tuple[np.ndarray, np.ndarray]:
        """The nearest point of the contour to each point: ``(distance, position)``, the position as arc length
        from the contour's first point in ``[0, length]``."""
        import shapely

        p = np.asarray(points, dtype=float).reshape(-1, 2)
        if self.segments_tree is not None and len(p):
            (i, j), _ = self.segments_tree.query_nearest(shapely.points(p), return_distance=True, all_matches=False)
            j = j[np.argsort(i, kind="stable")]
            d = self.entities.pair(p, j)[0]
        else:
            d, j, _, _ = self.entities.nearest(p)
        return d, self._cum[j] + self.entities.fraction(p, j) * self.entities.length[j]

    def locate(self, s) -> tuple[np.ndarray, np.ndarray]:
        """Entity and fraction along it of the arc-length positions ``s`` (wrapped into ``[0, length)``)."""
        s = np.mod(np.asarray(s, dtype=float).reshape(-1), self.length)
        j = np.clip(np.searchsorted(self._cum, s, side="right") - 1, 0, len(self.entities) - 1)
        L = self.entities.length[j]
        return j, np.clip((s - self._cum[j]) / np.where(L > 0, L, 1.0), 0.0, 1.0)

    def at_position(self, s) -> np.ndarray:
        """Points of the contour at arc-length positions ``s`` (wrapped into ``[0, length)``)."""
        return self.entities.at(*self.locate(s))


class CurveDistance:
    """Exact signed distance to a closed exact curve (negative inside), at a cost that follows the points.

    A coarse polyline of the curve (within ``coarse_tol``; its vertices include every breakpoint) only
    brackets the answer: for each point, every coarse segment within ``2 * coarse_tol`` of the nearest one
    (an R-tree query) is a candidate, and on each candidate's parameter interval - one smooth piece of the
    curve - the nearest point of the curve itself is found from the distance and its slope at ``_SUB + 1``
    points of the segment's interval and Illinois regula falsi on ``(P(t) - p) . P'(t)`` where it
    brackets a minimum (to ``1e-13`` of the bracket).  The exact curve's nearest point
    lies on a candidate (every piece lies within ``coarse_tol`` of its segment), so the distance is the
    curve's, to rounding: no stand-in polyline of ``tol / 50`` whose size grows with the part.  The side
    comes from the curve's normal at the nearest point, or from the coarse polygon where that point is a
    piece's end (a kink), which can only be wrong within ``coarse_tol`` of the curve.

    Points whose distance exceeds ``exact_within`` by more than ``coarse_tol`` get the distance to the
    coarse polyline instead (off by at most ``coarse_tol``, with the right sign): a caller that only needs
    exact values near a threshold saves the refinement elsewhere.

    Parameters
    ----------
    curve : ParametricCurve
        Closed.
    coarse_tol : float
        Tolerance of the bracketing polyline, mm (default 0.01).
    exact_within : float
        Distances up to this are exact (default: all).
    """

    def __init__(self, curve, coarse_tol: float = 0.01, exact_within: float = math.inf):
        self.curve = curve
        self.exact_within = float(exact_within)
        disc = polyline(curve, tol=coarse_tol)
        self.coarse_tol = float(disc.max_deviation if disc.max_deviation > 0 else coarse_tol)
        self.params = np.asarray(disc.params, dtype=float)
        # the smooth piece of the curve each coarse segment lies in (its vertices include every breakpoint)
        piece = piece_index(curve, 0.5 * (self.params[:-1] + self.params[1:]))
        self.piece_lo, self.piece_hi = curve.breakpoints[piece], curve.breakpoints[piece + 1]
        self.coarse = IndexedContourDistance(disc.arc_chain())
        self._ccw = not self.coarse.clockwise

    @property
    def length(self) -> float:
        """Length of the coarse polyline, mm (within ``coarse_tol`` of the curve's)."""
        return self.coarse.length

    def _nearest(self, p: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Exact distance, curve parameter and 'at a piece end' of the nearest point of the curve."""
        import shapely

        geoms = shapely.points(p)
        tree = self.coarse.segments_tree
        (i0, j0), d0 = tree.query_nearest(geoms, return_distance=True, all_matches=False)
        reach = np.empty(len(p))
        reach[i0] = d0 + 2.0 * self.coarse_tol * (1 + 1e-9) + 1e-12
        qi, qj = tree.query(geoms, predicate="dwithin", distance=reach)
        qi, qj = np.concatenate([qi, i0]), np.concatenate([qj, j0])  # the nearest always, whatever the rounding
        d, t, end = self._refine(p[qi], self.params[qj], self.params[qj + 1], self.piece_lo[qj], self.piece_hi[qj])
        order = np.lexsort((t, d, qi))  # per point: the smallest distance
        qi, d, t, end = qi[order], d[order], t[order], end[order]
        first = np.ones(len(qi), dtype=bool)
        first[1:] = qi[1:] != qi[:-1]
        return d[first], t[first], end[first]

    def _refine(self, p: np.ndarray, a: np.ndarray, b: np.ndarray, lo: np.ndarray, hi: np.ndarray
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Nearest point of the curve on ``[a, b]`` (inside the smooth piece ``[lo, hi]``) to each ``p``:
        ``(distance, t, at an end)``.

        The distance and ``g(t) = (P(t) - p) . P'(t)`` at ``_SUB + 1`` points across the interval; every change
        of sign of ``g`` from - to + between two of them (a local minimum) that could beat the nearest of
        those points (the distance is 1-Lipschitz along the arc) is refined by Illinois regula falsi.  A
        point near a centre of curvature sees a nearly flat distance with several extrema: all are looked at.
        """
        curve = self.curve
        n = len(p)
        grid = a[:, None] + (b - a)[:, None] * (np.arange(_SUB + 1) / _SUB)[None, :]  # (n, SUB+1)
        rep = np.repeat(np.arange(n), _SUB + 1)
        tg = grid.reshape(-1)
        q = points_at(curve, tg)
        g = _slope(curve, p[rep], tg, lo[rep], hi[rep], q).reshape(n, _SUB + 1)
        q = q.reshape(n, _SUB + 1, 2)
        dg = np.hypot(q[..., 0] - p[:, None, 0], q[..., 1] - p[:, None, 1])
        rows = np.arange(n)
        k = np.argmin(dg, axis=1)
        d, t = dg[rows, k], grid[rows, k]
        chord = np.hypot(*np.moveaxis(np.diff(q, axis=1), -1, 0))
        lower = np.minimum(dg[:, :-1], dg[:, 1:]) - 0.51 * chord - 1e-12
        pi, si = np.nonzero((g[:, :-1] < 0.0) & (g[:, 1:] > 0.0) & (lower < d[:, None]))
        if len(pi):
            tk = self._illinois(p[pi], grid[pi, si], grid[pi, si + 1], g[pi, si], g[pi, si + 1], lo[pi], hi[pi])
            dk = np.hypot(*(p[pi] - points_at(curve, tk)).T)
            better = np.full(n, np.inf)
            np.minimum.at(better, pi, dk)
            hit = dk <= better[pi]
            closer = better[pi[hit]] < d[pi[hit]]
            d[pi[hit][closer]], t[pi[hit][closer]] = dk[hit][closer], tk[hit][closer]
        return d, t, (t <= a) | (t >= b)

    def _illinois(self, p, x0, x1, g0, g1, lo, hi) -> np.ndarray:
        """The root of ``g`` in each bracket ``[x0, x1]`` (``g0 < 0 < g1``): Illinois regula falsi until a step
        is below 1e-13 of the first bracket."""
        x0, x1, g0, g1 = x0.copy(), x1.copy(), g0.copy(), g1.copy()
        tol = 1e-13 * np.abs(x1 - x0) + 1e-300
        t = x1.copy()
        live = np.ones(len(p), dtype=bool)
        for _ in range(_ILLINOIS_STEPS):
            k = np.nonzero(live)[0]
            if not len(k):
                break
            tk = np.clip(x1[k] - g1[k] * (x1[k] - x0[k]) / (g1[k] - g0[k]), np.minimum(x0[k], x1[k]),
                         np.maximum(x0[k], x1[k]))
            gk = _slope(self.curve, p[k], tk, lo[k], hi[k])
            flip = np.sign(gk) != np.sign(g1[k])
            # the bracket [x0, x1] keeps opposite signs: on a flip the old x1 becomes x0, else x0 stays with
            # its value halved (Illinois)
            g0[k] = np.where(flip, g1[k], 0.5 * g0[k])
            x0[k] = np.where(flip, x1[k], x0[k])
            step = np.abs(tk - t[k])
            x1[k], g1[k], t[k] = tk, gk, tk
            live[k[(step <= tol[k]) | (gk == 0.0)]] = False
        return t

    def __call__(self, points) -> np.ndarray:
        """Signed distance of ``points`` (array ``(n, 2)``) in mm; negative inside."""
        import shapely

        p = np.asarray(points, dtype=float).reshape(-1, 2)
        ok = np.all(np.isfinite(p), axis=1)
        out = np.full(len(p), np.nan)
        if not ok.any():
            return out
        coarse = self.coarse(p[ok])
        near = np.abs(coarse) <= self.exact_within + self.coarse_tol
        out[np.nonzero(ok)[0][~near]] = coarse[~near]
        if not near.any():
            return out
        pk = p[ok][near]
        d, t, end = self._nearest(pk)
        piece = piece_index(self.curve, t)
        bp = self.curve.breakpoints
        tangent = derivatives_at(self.curve, t, bp[piece], bp[piece + 1])
        q = points_at(self.curve, t)
        cross = tangent[:, 0] * (pk[:, 1] - q[:, 1]) - tangent[:, 1] * (pk[:, 0] - q[:, 0])
        inside = cross > 0 if self._ccw else cross < 0
        if end.any():
            e = np.nonzero(end)[0]
            inside[e] = shapely.contains_xy(self.coarse.polygon, pk[e, 0], pk[e, 1])
        out[np.nonzero(ok)[0][near]] = np.where(inside, -d, d)
        return out

    def project(self, points) -> tuple[np.ndarray, np.ndarray]:
        """Distance to the coarse polyline and the arc-length position along it of each point's nearest point."""
        return self.coarse.project(points)

    def at_position(self, s) -> np.ndarray:
        """Points of the exact curve at arc-length positions ``s`` of the coarse polyline (wrapped)."""
        j, u = self.coarse.locate(s)
        return points_at(self.curve, self.params[j] + u * (self.params[j + 1] - self.params[j]))


def _slope(curve, p: np.ndarray, t: np.ndarray, lo: np.ndarray, hi: np.ndarray, q: np.ndarray | None = None
           ) -> np.ndarray:
    """``(P(t) - p) . P'(t)``: half the derivative of the squared distance along the curve (``q = P(t)`` if known)."""
    if q is None:
        q = points_at(curve, t)
    return np.einsum("ij,ij->i", q - p, derivatives_at(curve, t, lo, hi))
