"""A chain of lines and arcs as fitted and measured: exact point-to-chain distances, constructors from
polylines, bulge rows, G-code style arcs and arc chains, and the merging of co-circular neighbours."""
from __future__ import annotations

import math

import numpy as np

from ..geom2d import TWO_PI, J, cross, dot, rotate, unit
from ..records import dataclass
from .entities import LINE_SWEEP_RAD, MAX_ARC_SWEEP_RAD, arc_from, entity_distance, entity_point
from .grid import grid_nearest

__all__ = ["Chain", "merge_cocircular"]


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
        return rotate(self.tangent, self.sweep)

    def sample(self, n_per_entity: int) -> tuple[np.ndarray, np.ndarray]:
        """``n_per_entity`` points per entity, ends included: ``(points (n, m, 2), u (n, m))``."""
        u = self.length[:, None] * np.linspace(0.0, 1.0, n_per_entity)
        return entity_point(self.start[:, None], self.tangent[:, None], self.curvature[:, None], u), u

    def distance(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Exact distance from each point of ``q`` ``(N, 2)`` to the chain, and the nearest entity.

        The entities are cut into short sub-pieces (each at most ``h`` long) whose midpoints are bucketed
        on a grid (:func:`~camfab.discretize.grid.grid_nearest`); a point is compared with the entities of
        the sub-pieces around it, and the answer is exact because a point is re-checked on coarser grids,
        and finally against every entity, unless every unexamined sub-piece is provably too far.
        """
        q = np.asarray(q, dtype=float).reshape(-1, 2)
        h = max(float(np.median(self.length)), float(self.length.sum()) / (4 * self.n))
        parts = np.maximum(1, np.ceil(self.length / h)).astype(int)
        owner = np.repeat(np.arange(self.n), parts)
        j = np.arange(owner.size) - np.repeat(np.cumsum(parts) - parts, parts)
        u = self.length[owner] * (j + 0.5) / parts[owner]
        mid = entity_point(self.start[owner], self.tangent[owner], self.curvature[owner], u)
        piece = float((self.length / parts).max())
        dist, part = grid_nearest(q, mid, piece, lambda x, p: self._dist_to(x, owner[p]), reach=0.5 * piece)
        return dist, owner[part]

    def _dist_to(self, q: np.ndarray, idx: np.ndarray) -> np.ndarray:
        return entity_distance(q, self.start[idx], self.tangent[idx], self.curvature[idx],
                                self.length[idx], self.end[idx])

    # ---- constructors ------------------------------------------------
    @classmethod
    def from_polyline(cls, points, closed: bool = True) -> Chain:
        """Polyline through ``points`` ``(n, 2)``; a closed one gets its closing segment if needed."""
        p = np.asarray(points, dtype=float).reshape(-1, 2)
        if closed and not np.array_equal(p[0], p[-1]):
            p = np.vstack([p, p[:1]])
        s, e = p[:-1], p[1:]
        w = e - s
        length = np.hypot(w[:, 0], w[:, 1])
        keep = length > 0
        return cls(s[keep], unit(w[keep]), np.zeros(int(keep.sum())), length[keep], e[keep])

    @classmethod
    def from_bulges(cls, rows, closed: bool = True) -> Chain:
        """Chain from ``(x, y, bulge)`` rows, as in a DXF LWPOLYLINE.

        The bulge of row ``i`` (``tan(sweep/4)``, > 0 counter-clockwise)
        belongs to the segment from vertex ``i`` to vertex ``i + 1`` (the last row's to vertex 0
        when ``closed``; an open chain ignores the last bulge).
        """
        r = np.asarray(rows, dtype=float).reshape(-1, 3)
        if closed:
            s, e, bulge = r[:, :2], np.roll(r[:, :2], -1, axis=0), r[:, 2]
        else:  # the last row only ends the last entity
            s, e, bulge = r[:-1, :2], r[1:, :2], r[:-1, 2]
        keep = np.any(s != e, axis=1)
        s, e, bulge = s[keep], e[keep], bulge[keep]
        w = e - s
        chord = np.hypot(w[:, 0], w[:, 1])
        sweep = 4.0 * np.arctan(bulge)
        tangent = rotate(unit(w), -0.5 * sweep)
        length = chord / np.sinc(sweep / TWO_PI)
        k = np.where(sweep != 0, sweep / np.where(length > 0, length, 1.0), 0.0)
        return cls(s, tangent, k, length, e)

    @classmethod
    def from_arcs(cls, starts, ends, centres, ccw) -> Chain:
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
        sweep = np.mod(sign * np.arctan2(cross(a, b), dot(a, b)), TWO_PI)
        sweep = np.where(sweep == 0, TWO_PI, sweep) * sign
        w = e - s
        chord = np.hypot(w[:, 0], w[:, 1])
        rsafe = np.where(radius > 0, radius, 1.0)
        tangent = np.where(line[:, None], unit(w), sign[:, None] * J(a) / rsafe[:, None])
        k = np.where(line, 0.0, sign / np.where(radius > 0, radius, 1.0))
        length = np.where(line, chord, np.abs(sweep) * radius)
        return cls(s, tangent, k, length, e)


def merge_cocircular(chain: Chain, pieces: np.ndarray) -> Chain:
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
    tangent, k_new, l_new, _ = arc_from(s, chain.tangent[first], e)
    return Chain(s,
                 np.where(single[:, None], chain.tangent[first], tangent),
                 np.where(single, chain.curvature[first], k_new),
                 np.where(single, chain.length[first], l_new), e)
