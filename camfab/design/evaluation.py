"""Evaluating a chain of segments at many points: segment by segment, or law by law.

Both paths give exactly the values of :meth:`Segment.values` (the same operations in the
same order): ``(lift·f⁽ᵛ⁾(u) + s0)/βᵛ`` for a standard law (``+ s0`` at ν = 0 only; βᵛ = 1
there), ``p⁽ᵛ⁾(u)/βᵛ`` for a polynomial segment, ``u = (x − start)/β``.

* :func:`by_segment` — the reference path: the samples are grouped by segment and each
  segment evaluates its own with scalar parameters.  Fastest with many samples per segment.
* :class:`Grouped` — the samples are grouped by *law*: each law evaluates the samples of
  all its segments in one call (the normalised shape does not depend on the segment), then
  lift, S0 and β are applied per sample; the polynomial segments are evaluated together
  with per-sample coefficients.  Fastest with few samples per segment (a check's searches),
  where the cost is the number of numpy calls, not their length.
"""
from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from .laws import Law, Polynomial, horner
from .segment import Segment

__all__ = ["by_segment", "Grouped"]


def by_segment(segments: Sequence[Segment], xr: np.ndarray, idx: np.ndarray, orders: Sequence[int],
               out: np.ndarray) -> None:
    """``out[:, i]`` = the orders at ``xr[i]``, segment by segment.

    Parameters
    ----------
    segments : sequence of Segment
    xr : (n,) float array
        Points already reduced to one period.
    idx : (n,) int array
        Index of the segment holding each point.
    orders : sequence of int
    out : (len(orders), n) float array
        Filled in place.
    """
    # group the samples by segment (stable counting sort) and visit only the segments hit
    order = np.argsort(idx.astype(np.int16 if len(segments) < 2**15 else np.int32), kind="stable")
    bounds = np.searchsorted(idx[order], np.arange(len(segments) + 1))
    for k in np.flatnonzero(bounds[1:] > bounds[:-1]):
        sel = order[bounds[k]:bounds[k + 1]]
        seg = segments[k]
        u = xr[sel]
        u -= seg.start
        u /= seg.span
        out[:, sel] = seg.rows(u, orders)


class Grouped:
    """A program's segments in arrays and grouped by law, for evaluating few samples per segment.

    Parameters
    ----------
    segments : sequence of Segment
    """

    def __init__(self, segments: Sequence[Segment]) -> None:
        self.segments = segments
        self.start = np.array([s.start for s in segments], dtype=float)
        self.span = np.array([s.span for s in segments], dtype=float)
        self.lift = np.array([s.lift for s in segments], dtype=float)
        self.s0 = np.array([s.s0 for s in segments], dtype=float)
        #: the law of each group; None for the group of the polynomial segments
        self.laws: list[Law | None] = []
        gid = []
        for s in segments:
            key = None if s.coeffs is not None else s.formula
            if key not in self.laws:
                self.laws.append(key)
            gid.append(self.laws.index(key))
        self.gid = np.array(gid, dtype=np.intp)
        self._tables: dict[tuple[str, tuple[int, ...]], np.ndarray] = {}

    def powers(self, orders: Sequence[int]) -> np.ndarray:
        """(len(orders), n_segments) βᵛ, as :meth:`Segment.values` computes it."""
        key = ("pow", tuple(orders))
        hit = self._tables.get(key)
        if hit is None:
            hit = self._tables[key] = np.array([[s.span**nu for s in self.segments] for nu in orders])
        return hit

    def coefficients(self, orders: Sequence[int]) -> np.ndarray:
        """(len(orders), n_segments, width) ascending coefficients of p⁽ᵛ⁾ of the polynomial
        segments, padded with high-order zeros (which leave Horner's rule exact); zero rows
        for the other segments."""
        key = ("coef", tuple(orders))
        hit = self._tables.get(key)
        if hit is None:
            polys = [s.formula if s.coeffs is not None else None for s in self.segments]
            width = max(len(p.coefficients(nu)) for p in polys if isinstance(p, Polynomial) for nu in orders)
            hit = np.zeros((len(orders), len(polys), width))
            for i, p in enumerate(polys):
                if isinstance(p, Polynomial):
                    hit[:, i, :] = p.coefficient_rows(orders, width)
            self._tables[key] = hit
        return hit

    def _parts(self, idx: np.ndarray):
        """(group, selection of the samples) for every group hit."""
        if len(self.laws) == 1:
            return [(0, slice(None))]
        key = self.gid[idx]
        order = np.argsort(key, kind="stable")
        bounds = np.searchsorted(key[order], np.arange(len(self.laws) + 1))
        return [(g, order[bounds[g]:bounds[g + 1]]) for g in range(len(self.laws)) if bounds[g + 1] > bounds[g]]

    def evaluate(self, xr: np.ndarray, idx: np.ndarray, orders: Sequence[int], out: np.ndarray) -> None:
        """``out[:, i]`` = the orders at ``xr[i]`` (see :func:`by_segment` for the arguments)."""
        for g, sel in self._parts(idx):
            si = idx[sel]
            u = (xr[sel] - self.start[si]) / self.span[si]
            law = self.laws[g]
            if law is None:
                v = horner(self.coefficients(orders)[:, si, :], u)
            else:
                v = law.rows(u, orders)
                v *= self.lift[si]
                for r, nu in enumerate(orders):
                    if nu == 0:
                        v[r] += self.s0[si]
            v /= self.powers(orders)[:, si]  # βᵛ = 1 for ν = 0: exact
            out[:, sel] = v
