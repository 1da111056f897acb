"""A piecewise cubic Hermite stand-in of a curve, built from a few batched exact samples.

Fitting runs on this surrogate so that the exact curve is called only a fixed, small number of
times; every result is measured against the exact curve afterwards.
"""
from __future__ import annotations

import numpy as np

from .curve import ParametricCurve, points_and_derivatives_at, points_at

__all__ = ["HermiteSurrogate", "sample_nodes", "fit_surrogate", "SURROGATE_FRACTION", "SURROGATE_MAX_NODES"]


def sample_nodes(curve: ParametricCurve, n: int, min_count: int = 4) -> tuple[np.ndarray, np.ndarray]:
    """``(x, counts)``: about ``n`` parameters shared out by parameter length, at least ``min_count`` equal
    intervals per smooth piece (``counts`` of them), every breakpoint and ``period`` among them."""
    lo, hi = curve.pieces
    counts = np.maximum(min_count, np.ceil(n * (hi - lo) / curve.period)).astype(int)
    x = np.append(np.concatenate([l_ + (h_ - l_) * np.arange(c) / c
                                  for l_, h_, c in zip(lo, hi, counts, strict=True)]), curve.period)
    return x, counts


class HermiteSurrogate:
    """Piecewise cubic Hermite interpolant of a curve from exact samples (never across a breakpoint).

    Built from two calls of the exact curve (points, then one-sided
    derivatives); used to *fit* without calling the exact curve again.
    Results are always measured against the exact curve.
    """

    def __init__(self, curve: ParametricCurve, n: int = 4096, min_count: int = 4, *, x: np.ndarray | None = None):
        lo, hi = curve.pieces
        if x is None:
            x, counts = sample_nodes(curve, n, min_count)
        else:  # explicit nodes (every breakpoint among them, increasing)
            x = np.asarray(x, dtype=float)
            counts = np.diff(np.searchsorted(x, curve.breakpoints))
        piece = np.repeat(np.arange(lo.size), counts)
        a, b = x[:-1], x[1:]
        # one derivative per node and smooth piece: an interval's end is the next one's start (same piece) except
        # at each piece's end, whose one-sided derivative comes from that piece (points and derivatives from one
        # evaluation when the curve offers it)
        ends = np.cumsum(counts) - 1  # the last interval of every piece (each piece has one at least)
        # (the nodes are the interval starts and the last end, the period, which is the last piece's end: every
        # point comes from the parameters the derivatives are taken at, one evaluation of each)
        p, d = points_and_derivatives_at(curve, None, np.concatenate([a, b[ends]]),
                                         np.concatenate([lo[piece], lo]), np.concatenate([hi[piece], hi]))
        p = np.concatenate([p[:a.size], p[-1:]])
        if curve.closed:
            p[-1] = p[0]
        d0 = d[:a.size]
        d1 = np.empty_like(d0)
        d1[:-1] = d0[1:]
        d1[ends] = d[a.size:]
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
        """The cubic holding each ``t`` (within the cubics of ``piece`` when given)."""
        i = np.searchsorted(self.x, t, side="right") - 1
        if piece is None:
            return np.minimum(np.maximum(i, 0), self.x.size - 2)  # (np.clip: 10× the call)
        return np.minimum(np.maximum(i, self.first[piece]), self.first[piece + 1] - 1)

    def _local(self, t, piece):
        """Offset ``u`` of ``t`` in its cubic and that cubic's coefficients (``t`` wrapped into the
        period of a closed curve unless a ``piece`` is given)."""
        t = np.asarray(t, dtype=float)
        if piece is None and self.curve.closed:
            t = np.where((t < 0) | (t > self.curve.period), np.mod(t, self.curve.period), t)
        i = self._index(t, piece)
        return (t - self.x[i])[..., None], self.coef[:, i]

    def point(self, t, piece=None) -> np.ndarray:
        """``P(t)`` of the surrogate, ``t.shape + (2,)`` (inside smooth piece ``piece`` when given)."""
        u, c = self._local(t, piece)
        return c[0] + u * (c[1] + u * (c[2] + u * c[3]))

    def derivative(self, t, piece=None) -> np.ndarray:
        """``dP/dt`` of the surrogate, ``t.shape + (2,)`` (inside smooth piece ``piece`` when given)."""
        u, c = self._local(t, piece)
        return c[1] + u * (2 * c[2] + 3 * u * c[3])

    def second_derivative(self, t, piece: int | np.ndarray) -> np.ndarray:
        """``d²P/dt²`` of the surrogate inside smooth piece ``piece`` (one per ``t``, or one for all)."""
        t = np.asarray(t, dtype=float)
        i = self._index(t, piece)
        u = (t - self.x[i])[..., None]
        c = self.coef[:, i]
        return 2 * c[2] + 6 * u * c[3]

    def as_curve(self) -> ParametricCurve:
        """The surrogate as a curve (same breakpoints, period and closure)."""
        return ParametricCurve(self.point, self.curve.breakpoints, self.curve.period, self.derivative,
                               self.curve.closed)

    def interval_errors(self) -> np.ndarray:
        """Distance between surrogate and exact curve at every interval's midpoint (one call), where a
        cubic Hermite interpolant's error peaks (``h⁴·|P⁗|/384``); NaN/inf count as infinitely wrong."""
        mid = 0.5 * (self.x[:-1] + self.x[1:])
        d = points_at(self.curve, mid) - self.point(mid, self.piece)
        err = np.hypot(d[:, 0], d[:, 1])
        return np.where(np.isfinite(err), err, np.inf)

    def error(self) -> float:
        """Largest distance between surrogate and exact curve at the interval midpoints (one call)."""
        return float(self.interval_errors().max())


#: the stand-in's error goal (midpoint error ≤ ``tol / SURROGATE_FRACTION``): every fit keeps its target
#: ``tol·(1 - MARGIN) - error``, so the stand-in costs at most half a percent of the tolerance
SURROGATE_FRACTION = 200
#: most nodes of a stand-in (bounds memory and exact-curve calls whatever the curve)
SURROGATE_MAX_NODES = 2 ** 18
#: refinement rounds of a stand-in (one batched exact call each)
_SURROGATE_ROUNDS = 10


def _split(x: np.ndarray, parts: np.ndarray) -> np.ndarray:
    """The nodes ``x`` with interval ``i`` cut into ``parts[i]`` equal parts."""
    w = np.diff(x)
    a = np.repeat(x[:-1], parts)
    j = np.arange(a.size) - np.repeat(np.cumsum(parts) - parts, parts)
    return np.append(a + np.repeat(w, parts) * j / np.repeat(parts, parts), x[-1])


def fit_surrogate(curve: ParametricCurve, tol: float, n: int = 4096) -> tuple[HermiteSurrogate, float]:
    """A stand-in whose measured midpoint error is below ``tol / SURROGATE_FRACTION``, and that error.

    Starts from ``n`` nodes shared out by parameter length (at least 4 per smooth piece), then cuts only
    the intervals whose midpoint error exceeds the goal, each into ``≈ (err/goal)^(1/4)`` parts (the
    error of a cubic Hermite interval falls as ``h⁴``): a short, sharp piece (a rise over 0.01°) gets the
    nodes it needs however small its share of the period.  Bounded: at most
    :data:`SURROGATE_MAX_NODES` nodes and a few rounds, never an interval below a few ulps of the
    parameter; the error returned is what was measured (the caller's target subtracts it).
    """
    goal = tol / SURROGATE_FRACTION
    sur = HermiteSurrogate(curve, n)
    floor = 64 * np.finfo(float).eps * max(curve.period, 1.0)
    for _ in range(_SURROGATE_ROUNDS):
        err = sur.interval_errors()
        bad = (err > goal) & (np.diff(sur.x) > floor)
        if not bad.any():
            return sur, float(err.max())
        ratio = np.where(np.isfinite(err), err / goal, 1e4)
        parts = np.where(bad, np.clip(np.ceil(1.25 * ratio ** 0.25), 2, 16), 1).astype(int)
        room = SURROGATE_MAX_NODES - sur.x.size
        extra = int((parts - 1).sum())
        if room <= 0:
            break
        if extra > room:  # spend what is left on the worst intervals first
            order = np.argsort(-err)
            keep = np.cumsum((parts - 1)[order]) <= room
            cut = np.zeros(parts.size, dtype=bool)
            cut[order[keep]] = True
            parts = np.where(cut, parts, 1)
            if not (parts > 1).any():
                break
        sur = HermiteSurrogate(curve, x=_split(sur.x, parts))
    return sur, sur.error()
