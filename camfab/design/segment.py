"""One resolved segment of a motion program, and the Hermite polynomials that join given end states.

A segment maps its local coordinate ``u = (x − start)/span ∈ [0, 1]`` to the follower
coordinate S.  A standard-law segment scales a normalised law: ``S = s0 + lift·f(u)``,
``S⁽ᵛ⁾ = lift·f⁽ᵛ⁾(u)/spanᵛ``.  A polynomial segment (a generic 5th/7th-degree polynomial
solved from its neighbours, or a piece of a knot table) holds S itself as a polynomial in
u: ``S⁽ᵛ⁾ = p⁽ᵛ⁾(u)/spanᵛ``.  :meth:`Segment.values` is the reference evaluation that every
faster path reproduces operation for operation.
"""
from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..errors import InputError
from ..records import dataclass, field
from .laws import LAWS, Law, Polynomial, derivative_rows, horner

__all__ = ["Segment", "hermite_coefficients", "solve_generic"]


@dataclass(frozen=True, slots=True)
class Segment:
    """A resolved segment: its law, span, start and exact polynomial data.

    ``S(u) = s0 + lift·f(u)`` for standard laws, or ``S(u) = Σ coeffs[i]·uⁱ``
    for polynomial segments (generic 5th/7th, knot-table Hermite pieces), with
    ``u = (x − start)/span``.
    """

    law: str
    lift: float
    span: float
    start: float
    s0: float
    coeffs: tuple[float, ...] | None = None
    title: str = ""
    #: the law object: the standard law named ``law``, or S(u) of a polynomial segment
    formula: Law = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        formula = LAWS[self.law] if self.coeffs is None else Polynomial(self.coeffs, self.law, self.title)
        object.__setattr__(self, "formula", formula)

    @property
    def end(self) -> float:
        return self.start + self.span

    @property
    def breaks(self) -> tuple[float, ...]:
        """Internal breakpoints in ``u``."""
        return self.formula.breaks

    def du(self, u: np.ndarray, nu: int) -> np.ndarray:
        """``nu``-th derivative of S with respect to ``u`` (absolute units)."""
        f = self.formula(u, nu)
        if self.coeffs is not None:
            return f
        out = self.lift * f
        return out + self.s0 if nu == 0 else out

    def values(self, u: np.ndarray, nu: int) -> np.ndarray:
        """``nu``-th derivative of S with respect to ``x`` at local ``u``."""
        return self.du(u, nu) / self.span**nu

    def rows(self, u: np.ndarray, orders: Sequence[int]) -> np.ndarray:
        """``[values(u, ν) for ν in orders]`` as one (len(orders), n) array, value for value
        (``u`` a float array)."""
        out = self.formula.rows(u, orders)
        if self.coeffs is None:
            out *= self.lift
            for r, nu in enumerate(orders):
                if nu == 0:
                    out[r] += self.s0
        for r, nu in enumerate(orders):
            if nu != 0:
                out[r] /= self.span**nu
        return out

    def value_at(self, u: float, nu: int) -> float:
        """``values(np.array([u]), nu)[0]``, bit for bit, as a Python float (a standard
        law's f⁽ᵛ⁾(u) is a constant of the law, taken once)."""
        if self.coeffs is not None:
            out = self.formula.scalar(u, nu)
        else:
            out = self.lift * self.formula.point(u, nu)
            if nu == 0:
                out = out + self.s0
        return out / self.span**nu

    def end_values(self, at_end: bool, n: int = 4) -> np.ndarray:
        """S, S′, S″, S‴ (per unit x) at the start (``at_end=False``) or end."""
        u = 1.0 if at_end else 0.0
        return np.array([self.value_at(u, k) for k in range(n)])


def hermite_coefficients(
    start: Sequence[float] | np.ndarray, end: Sequence[float] | np.ndarray, span: float
) -> tuple[float, ...]:
    """Polynomial (in u) through end conditions given per unit x.

    ``start`` and ``end`` hold ``(S, S′, S″)`` for a quintic or
    ``(S, S′, S″, S‴)`` for a 7th-degree polynomial.  The low coefficients follow from the
    start (``Cₖ = S⁽ᵏ⁾(0)·spanᵏ/k!``); the high ones solve, in closed form, the linear system
    that matches the end values ``S⁽ᵏ⁾(1)·spanᵏ`` (CAM-DAS's generic-polynomial system).
    """
    m = len(start)
    if m not in (3, 4) or len(end) != m:
        raise InputError(f"hermite_coefficients needs 3 (quintic) or 4 (7th degree) values per end, got {len(start)} "
                         f"and {len(end)}")
    fact = [1.0, 1.0, 2.0, 6.0]
    a = [start[k] * span**k / fact[k] for k in range(m)]  # C0..C(m-1)
    # Δk = S^(k)(1)·β^k − d^k/du^k of the known low-order part at u=1
    low = _derivatives_at_one(a)
    d = [end[k] * span**k - low[k] for k in range(m)]
    if m == 3:
        c3 = 10 * d[0] - 4 * d[1] + d[2] / 2
        c4 = -15 * d[0] + 7 * d[1] - d[2]
        c5 = 6 * d[0] - 3 * d[1] + d[2] / 2
        return (*a, c3, c4, c5)
    c4 = 35 * d[0] - 15 * d[1] + 2.5 * d[2] - d[3] / 6
    c5 = -84 * d[0] + 39 * d[1] - 7 * d[2] + d[3] / 2
    c6 = 70 * d[0] - 34 * d[1] + 6.5 * d[2] - d[3] / 2
    c7 = -20 * d[0] + 10 * d[1] - 2 * d[2] + d[3] / 6
    return (*a, c4, c5, c6, c7)


def _derivatives_at_one(a: Sequence[float]) -> list[float]:
    """``dᵏ/duᵏ Σ aⱼ uʲ`` at ``u = 1`` for ``k = 0 … len(a) − 1``, rounded as
    ``numpy.polynomial.Polynomial(a).deriv(k)(1.0)`` (polyder's ``j·cⱼ``, then polyval's Horner rule: the laws'
    :func:`~camfab.design.laws.horner` on their derivative rows) without building the polynomials, which cost a
    knot table ~0.17 ms per interval."""
    return [horner(row, 1.0) for row in derivative_rows(a, len(a))]


def solve_generic(degree: int, s0: float, lift: float, span: float,
                  prev_end: np.ndarray, next_start: np.ndarray) -> tuple[float, ...]:
    """Coefficients of a generic 5th/7th-degree segment from its neighbours.

    ``prev_end`` and ``next_start`` are the neighbours' ``S, S′, S″, S‴`` (per
    unit x); S itself is taken from ``s0`` and ``s0 + lift``.
    """
    m = 3 if degree == 5 else 4
    start = [s0, *prev_end[1:m]]
    end = [s0 + lift, *next_start[1:m]]
    return hermite_coefficients(start, end, span)
