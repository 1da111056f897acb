"""A piecewise cubic Hermite stand-in of a curve, built from a few batched exact samples.

Fitting runs on this surrogate so that the exact curve is called only a fixed, small number of
times; every result is measured against the exact curve afterwards.
"""
from __future__ import annotations

import numpy as np

from .curve import ParametricCurve, derivatives_at, points_at

__all__ = ["HermiteSurrogate", "fit_surrogate"]


class HermiteSurrogate:
    """Piecewise cubic Hermite interpolant of a curve from exact samples (never across a breakpoint).

    Built from two calls of the exact curve (points, then one-sided
    derivatives); used to *fit* without calling the exact curve again.
    Results are always measured against the exact curve.
    """

    def __init__(self, curve: ParametricCurve, n: int, min_count: int = 4):
        lo, hi = curve.pieces
        counts = np.maximum(min_count, np.ceil(n * (hi - lo) / curve.period)).astype(int)
        x = np.append(np.concatenate([l_ + (h_ - l_) * np.arange(c) / c
                                      for l_, h_, c in zip(lo, hi, counts, strict=True)]), curve.period)
        piece = np.repeat(np.arange(lo.size), counts)
        a, b = x[:-1], x[1:]
        p = points_at(curve, x)
        if curve.closed:
            p[-1] = p[0]
        d = derivatives_at(curve, np.concatenate([a, b]), np.tile(lo[piece], 2), np.tile(hi[piece], 2))
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
        """The cubic holding each ``t`` (within the cubics of ``piece`` when given)."""
        i = np.searchsorted(self.x, t, side="right") - 1
        if piece is None:
            return np.clip(i, 0, self.x.size - 2)
        return np.clip(i, self.first[piece], self.first[piece + 1] - 1)

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

    def second_derivative(self, t, piece: int) -> np.ndarray:
        """``d²P/dt²`` of the surrogate inside smooth piece ``piece``."""
        t = np.asarray(t, dtype=float)
        i = self._index(t, piece)
        u = (t - self.x[i])[..., None]
        c = self.coef[:, i]
        return 2 * c[2] + 6 * u * c[3]

    def as_curve(self) -> ParametricCurve:
        """The surrogate as a curve (same breakpoints, period and closure)."""
        return ParametricCurve(self.point, self.curve.breakpoints, self.curve.period, self.derivative,
                               self.curve.closed)

    def error(self) -> float:
        """Largest distance between surrogate and exact curve at the interval midpoints (one call)."""
        mid = 0.5 * (self.x[:-1] + self.x[1:])
        d = points_at(self.curve, mid) - self.point(mid)
        return float(np.hypot(d[:, 0], d[:, 1]).max())


def fit_surrogate(curve: ParametricCurve, tol: float, n: int = 4096) -> tuple[HermiteSurrogate, float]:
    """A surrogate whose measured midpoint error is below ``tol / 200`` (grid refined as needed)."""
    for _ in range(4):
        sur = HermiteSurrogate(curve, n)
        err = sur.error()
        if err <= tol / 200 or n >= 2 ** 17:
            return sur, err
        n = int(min(2 ** 17, n * max(2.0, min(8.0, (err / (tol / 400)) ** 0.25))))
    return sur, err
