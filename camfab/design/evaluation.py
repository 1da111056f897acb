"""Evaluating a chain of segments at many points: segment by segment, or law by law.

Both paths give exactly the values of :meth:`Segment.values` (the same operations in the
same order): ``(lift·f⁽ᵛ⁾(u) + s0)/βᵛ`` for a standard law (``+ s0`` at ν = 0 only; βᵛ = 1
there), ``p⁽ᵛ⁾(u)/βᵛ`` for a polynomial segment, ``u = (x − start)/β``.

* :func:`by_segment` — the reference path: the samples are grouped by segment and each
  segment evaluates its own (:meth:`Segment.rows`) with scalar parameters.  Fastest with
  many samples per segment.
* :class:`Grouped` — the samples are grouped by *law*: each law evaluates the samples of
  all its segments in one call (the normalised shape does not depend on the segment), then
  lift, S0 and β are applied per sample; the polynomial laws, and the polynomial segments,
  are each evaluated together with per-sample coefficients, and a dwell's values are looked
  up.  Fastest with few samples per segment (a check's searches), where the cost is the
  number of numpy calls, not their length.
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
    for k in np.flatnonzero(bounds[1:] > bounds[:-1]).tolist():
        sel = order[bounds[k]:bounds[k + 1]]
        seg = segments[k]
        if seg.formula.constant:  # the same values at every u: evaluated once
            out[:, sel] = seg.rows(np.zeros(1), orders)
            continue
        u = xr[sel]
        u -= seg.start
        u /= seg.span
        out[:, sel] = seg.rows(u, orders)


#: group keys of :class:`Grouped` besides the laws themselves
_CONSTANT, _POLY_LAW, _POLY_SEGMENT = "constant", "polynomial law", "polynomial segment"


def _group_key(seg: Segment) -> str | Law:
    if seg.formula.constant:
        return _CONSTANT
    if seg.coeffs is not None:
        return _POLY_SEGMENT
    return _POLY_LAW if isinstance(seg.formula, Polynomial) else seg.formula


class Grouped:
    """A program's segments in arrays and grouped by law, for evaluating few samples per segment.

    The groups: the constant (dwell) segments, whose values are looked up; the polynomial
    laws, and the polynomial segments, each evaluated together by Horner's rule with
    per-sample coefficients; every other law on its own, by :meth:`Law.rows`.

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
        #: the key of each group: a law, or one of the shared kinds above
        self.keys: list = []
        gid = []
        for s in segments:
            key = _group_key(s)
            if key not in self.keys:
                self.keys.append(key)
            gid.append(self.keys.index(key))
        self.gid = np.array(gid, dtype=np.intp)
        self._tables: dict[tuple[str, tuple[int, ...]], np.ndarray] = {}

    def _table(self, kind: str, orders: Sequence[int], make) -> np.ndarray:
        key = (kind, tuple(orders))
        hit = self._tables.get(key)
        if hit is None:
            hit = self._tables[key] = make(orders)
        return hit

    def _powers(self, orders: Sequence[int]) -> np.ndarray:
        """(len(orders), n_segments) βᵛ, as :meth:`Segment.values` computes it."""
        return np.array([[s.span**nu for s in self.segments] for nu in orders])

    def _constants(self, orders: Sequence[int]) -> np.ndarray:
        """(len(orders), n_segments) values of the constant segments (zeros elsewhere)."""
        out = np.zeros((len(orders), len(self.segments)))
        for i, s in enumerate(self.segments):
            if s.formula.constant:
                out[:, i] = s.rows(np.zeros(1), orders)[:, 0]
        return out

    def _coefficients(self, orders: Sequence[int]) -> np.ndarray:
        """(len(orders), n_segments, width) ascending coefficients of the polynomial laws'
        f⁽ᵛ⁾ and the polynomial segments' p⁽ᵛ⁾, padded with high-order zeros (which leave
        Horner's rule exact); zero rows for the other segments."""
        polys = [s.formula if isinstance(s.formula, Polynomial) else None for s in self.segments]
        width = max((len(p.coefficients(nu)) for p in polys if p is not None for nu in orders), default=1)
        out = np.zeros((len(orders), len(polys), width))
        for i, p in enumerate(polys):
            if p is not None:
                out[:, i, :] = p.coefficient_rows(orders, width)
        return out

    def _parts(self, idx: np.ndarray):
        """(group, selection of the samples) for every group hit."""
        if len(self.keys) == 1:
            return [(0, slice(None))]
        key = self.gid[idx]
        order = np.argsort(key, kind="stable")
        bounds = np.searchsorted(key[order], np.arange(len(self.keys) + 1))
        return [(g, order[bounds[g]:bounds[g + 1]]) for g in range(len(self.keys)) if bounds[g + 1] > bounds[g]]

    def evaluate(self, xr: np.ndarray, idx: np.ndarray, orders: Sequence[int], out: np.ndarray) -> None:
        """``out[:, i]`` = the orders at ``xr[i]`` (see :func:`by_segment` for the arguments)."""
        for g, sel in self._parts(idx):
            key, si = self.keys[g], idx[sel]
            if key == _CONSTANT:
                out[:, sel] = self._table("constant", orders, self._constants)[:, si]
                continue
            u = (xr[sel] - self.start[si]) / self.span[si]
            if isinstance(key, Law):
                v = key.rows(u, orders)
            else:
                v = horner(self._table("coef", orders, self._coefficients)[:, si, :], u)
            if key != _POLY_SEGMENT:
                v *= self.lift[si]
                for r, nu in enumerate(orders):
                    if nu == 0:
                        v[r] += self.s0[si]
            v /= self._table("pow", orders, self._powers)[:, si]  # βᵛ = 1 for ν = 0: exact
            out[:, sel] = v
