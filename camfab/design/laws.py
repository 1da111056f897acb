"""Normalised motion laws ("leyes de desplazamiento") as objects that evaluate themselves.

Every standard law is a normalised shape ``f(u)`` on ``u = x/β ∈ [0, 1]`` with
``f(0) = 0`` and ``f(1) = 1``.  A segment of signed lift ``L`` starting at
ordinate ``Li`` is ``S = Li + L·f(u)`` and its derivatives with respect to the
cam angle are ``S⁽ᵏ⁾ = L/βᵏ · f⁽ᵏ⁾(u)``, so one formula serves rise (L > 0) and
return (L < 0).

A law holds its formula's data once and provides everything that is computed from it:

* ``law(u, nu)`` — the reference evaluation: the ``nu``-th derivative of ``f``, vectorised
  over ``u``; every faster path must give exactly these values;
* ``law.rows(u, orders)`` — several derivative orders at once, value for value as
  ``law(u, nu)`` (a harmonic law takes one sine call for all of them);
* ``law.breaks`` — internal breakpoints in ``u`` where the formula changes, so that samplers
  and root finders never straddle a kink;
* ``law.cv, law.ca, law.cj`` — peak coefficients ``max|f′|, max|f″|, max|f‴|``
  (so ``max|S′| = cv·|L|/β`` …);
* ``law.extremum_candidates(nu)`` — the points where ``f⁽ᵛ⁾`` can take its extremes.

The kinds of law:

* :class:`Dwell` — ``f = 0``;
* :class:`Polynomial` — ``f = Σ cᵢ uⁱ`` (3-4-5, 4-5-6-7, constant velocity ``f = u``, pieces of
  piecewise laws; a polynomial segment also keeps its S(u) in one);
* :class:`Harmonic` — ``f = Σⱼ aⱼ sin(wⱼ (u + sⱼ) + φⱼ) + b·u + c`` (simple harmonic
  ``(1 − cos πu)/2``, cycloidal ``u − sin(2πu)/2π``, the half-period laws, the double
  harmonic rise, pieces of the modified sine and trapezoid);
* :class:`Piecewise` — pieces between breaks, ``u`` on a break takes the right-hand piece;
* :class:`Mirrored` — ``f(u) = 1 − g(1 − u)``, the double harmonic return shape.

Half-period laws (one end moves): semiharmonic ``sin(πu/2)`` (Vf = 0) and
``1 − cos(πu/2)`` (Vi = 0), end slope ``π/2·L/β``; semicycloidal ``u + sin(πu)/π`` (Vf = 0)
and ``u − sin(πu)/π`` (Vi = 0), end slope ``2·L/β``.

Double harmonic: the rise shape ``g(u) = ½[(1 − cos πu) − ¼(1 − cos 2πu)]`` ends with
non-zero acceleration and the return shape ``1 − g(1 − u)`` starts with it.  camfab picks
the shape **by the sign of the lift** (L > 0 → rise shape, L < 0 → return shape), which
makes both the classical rise-then-return pair and a conjugate cam that starts with the
return continuous through jerk; a segment may override the choice with
``shape = "rise" | "return"``.

Modified sine (K = 4 + π), the standard 1/8-split form: ``πu/K − sin(4πu)/4K`` on
[0, 1/8), ``2/K + πu/K − 9/4K·sin(π/3 + 4πu/3)`` on [1/8, 7/8), ``4/K + πu/K −
sin(4πu)/4K`` on [7/8, 1].  Modified trapezoid (Q = 2 + π), five pieces split at 1/8, 3/8,
5/8, 7/8: sine ramps ``(4πu ∓ sin 4πu + const)/2πQ`` alternating with parabolas; with the
exact closed form its jerk is zero on both sides of every internal break, so it is
continuous inside the segment and jumps only at the segment ends.  Constant acceleration
("parabolic"): ``2u²`` then ``1 − 2(1 − u)²``, the acceleration jumps at the ends and the
middle.
"""
from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from ..brent import brentq
from ..records import dataclass, field

__all__ = [
    "horner",
    "derivative_rows",
    "Law",
    "Dwell",
    "Polynomial",
    "Wave",
    "Harmonic",
    "Piecewise",
    "Mirrored",
    "LAWS",
    "HALF_PERIOD",
    "GENERIC",
    "get_law",
    "law_names",
]

PI = np.pi
#: points of the sign scan that brackets a law's critical points on each piece
_SCAN_POINTS = 129


def horner(c: Sequence[float] | np.ndarray, u: Any) -> Any:
    """``Σ c[j]·uʲ`` by Horner's rule: ``c[-1] + u·0``, then ``c[j] + out·u`` down to j = 0.

    Operation for operation as :func:`numpy.polynomial.polynomial.polyval` (so bit-identical
    to it) without its per-call overhead.  High-order zero coefficients leave the result
    exact, so rows of different degrees may be padded to one width.

    Parameters
    ----------
    c : sequence of float, or (..., m) float array
        Ascending coefficients: one polynomial, or one per sample (the last axis).
    u : float or (n,) float array
        Where to evaluate; a Python float in gives a Python float out.

    Returns
    -------
    float or array of the broadcast shape of ``c[..., 0]`` and ``u``
    """
    cols = c.transpose((c.ndim - 1, *range(c.ndim - 1))) if isinstance(c, np.ndarray) else c
    out = cols[-1] + u * 0.0
    for cj in cols[-2::-1]:
        out = cj + out * u
    return out


def derivative_rows(coeffs: Sequence[float], count: int) -> list[tuple[float, ...]]:
    """Ascending coefficients of the 0th … (count − 1)th derivatives (a constant's
    derivative is ``(0.0,)``)."""
    cur = np.asarray(coeffs, dtype=float)
    rows = [tuple(float(v) for v in cur)]
    while len(rows) < count:
        # numpy.polynomial's polyder, j·c[j] (imported only for this it cost ~5 ms of every start)
        cur = cur[1:] * np.arange(1, cur.size) if cur.size > 1 else np.zeros(1)
        rows.append(tuple(float(v) for v in cur))
    return rows


class Law:
    """A normalised motion law (see the module docstring for what every law provides).

    Attributes
    ----------
    name : str
        Key used in design files (``law = "cycloidal"``); empty for the pieces of a law.
    title : str
        Human-readable name (CAM-DAS English UI name where one exists).
    cv, ca, cj : float
        Peak coefficients ``max|f′|, max|f″|, max|f‴|``.
    """

    #: internal breakpoints in ``u`` (open interval (0, 1)) where the formula changes
    breaks: tuple[float, ...] = ()
    #: True when f does not depend on u at all (its value at any u, NaN included, is f(0))
    constant: bool = False

    def __init__(self, name: str = "", title: str = "", cv: float = 0.0, ca: float = 0.0,
                 cj: float = 0.0) -> None:
        self.name, self.title = name, title
        self.cv, self.ca, self.cj = cv, ca, cj
        self._points: dict[tuple[float, int], float] = {}
        self._critical: dict[tuple[int, float, float], tuple[float, ...]] = {}
        self._candidates: dict[int, tuple[np.ndarray, np.ndarray]] = {}

    def __repr__(self) -> str:
        return f"{type(self).__name__}({self.name!r})"

    def __call__(self, u, nu: int = 0) -> np.ndarray:
        """``f⁽ᵛ⁾(u)``: the reference evaluation, (n,) float array for (n,) ``u``."""
        return self._eval(np.asarray(u, dtype=float), nu)

    def _eval(self, u: np.ndarray, nu: int) -> np.ndarray:
        raise NotImplementedError

    def rows(self, u: np.ndarray, orders: Sequence[int]) -> np.ndarray:
        """``[f⁽ᵛ⁾(u) for ν in orders]`` as one (len(orders), n) array, value for value as
        :meth:`__call__` (``u`` a float array)."""
        out = np.empty((len(orders), u.size))
        for r, nu in enumerate(orders):
            out[r] = self._eval(u, nu)
        return out

    def scalar(self, u: float, nu: int) -> float:
        """``f⁽ᵛ⁾(u)`` at one point as a Python float, bit for bit :meth:`__call__`'s value."""
        return float(self._eval(np.array([u]), nu)[0])

    def point(self, u: float, nu: int) -> float:
        """:meth:`scalar`, memoised: the values at the ends and beside the breaks are
        constants of the law, asked for again and again."""
        key = (u, nu)
        v = self._points.get(key)
        if v is None:
            v = self._points[key] = self.scalar(u, nu)
        return v

    def critical_points(self, nu: int, lo: float, hi: float) -> tuple[float, ...]:
        """Zeros of ``f⁽ᵛ⁺¹⁾`` strictly inside (lo, hi) where it changes sign (memoised).

        ``f⁽ᵛ⁺¹⁾`` is scanned at 129 points and every sign change polished by Brent's
        method to ~1e-15; at a flat end (derivative exactly 0) the sign is taken just inside,
        so an extremum in the first or last cell is still bracketed.  The search runs on f
        itself, so the points do not depend on a segment's lift or span (nor on which
        programs were analysed before).
        """
        key = (nu, float(lo), float(hi))
        hit = self._critical.get(key)
        if hit is None:
            hit = self._critical[key] = tuple(self._scan_roots(nu + 1, lo, hi))
        return hit

    def _scan_roots(self, nu: int, lo: float, hi: float) -> list[float]:
        def d(t: float) -> float:
            return self.scalar(t, nu)

        grid = np.linspace(lo, hi, _SCAN_POINTS)
        vals = self(grid, nu)
        inner = 1e-9 * (hi - lo)
        if vals[0] == 0.0:
            grid[0], vals[0] = lo + inner, d(lo + inner)
        if vals[-1] == 0.0:
            grid[-1], vals[-1] = hi - inner, d(hi - inner)
        sgn = np.sign(vals)
        out = list(grid[1:-1][sgn[1:-1] == 0])
        for i in np.flatnonzero(sgn[:-1] * sgn[1:] < 0):
            out.append(brentq(d, grid[i], grid[i + 1], xtol=1e-15, rtol=4 * np.finfo(float).eps))
        return out

    def extremum_candidates(self, nu: int) -> tuple[np.ndarray, np.ndarray]:
        """Where ``f⁽ᵛ⁾`` can take its extremes, and its values there (memoised, read-only).

        Returns
        -------
        u : (m,) float array
            Every piece's ends (nudged one ulp inside at an internal break, so each side
            counts with its own value) and its critical points.
        f : (m,) float array
            ``f⁽ᵛ⁾(u)``.
        """
        hit = self._candidates.get(nu)
        if hit is None:
            edges = [0.0, *self.breaks, 1.0]
            us: list[float] = []
            for ua, ub in zip(edges[:-1], edges[1:], strict=True):
                lo = np.nextafter(ua, 2.0) if ua > 0 else ua
                hi = np.nextafter(ub, -1.0) if ub < 1 else ub
                us += [lo, hi, *self.critical_points(nu, lo, hi)]
            u = np.asarray(us, dtype=float)
            f = self(u, nu)
            u.setflags(write=False)
            f.setflags(write=False)
            hit = self._candidates[nu] = (u, f)
        return hit


class Dwell(Law):
    """``f = 0``: the follower rests."""

    constant = True

    def _eval(self, u: np.ndarray, nu: int) -> np.ndarray:
        return np.zeros_like(u, dtype=float)

    def rows(self, u: np.ndarray, orders: Sequence[int]) -> np.ndarray:
        return np.zeros((len(orders), u.size))

    def critical_points(self, nu: int, lo: float, hi: float) -> tuple[float, ...]:
        return ()  # constant: the piece's ends already carry its only value


class Polynomial(Law):
    """``f = Σ cᵢ uⁱ``, evaluated by :func:`horner` (its derivatives from their own
    coefficients, computed once).

    Parameters
    ----------
    coeffs : sequence of float
        Ascending coefficients in ``u``.
    """

    def __init__(self, coeffs: Sequence[float], name: str = "", title: str = "", cv: float = 0.0,
                 ca: float = 0.0, cj: float = 0.0) -> None:
        super().__init__(name, title, cv, ca, cj)
        self._rows = derivative_rows(coeffs, 6)

    def coefficients(self, nu: int) -> tuple[float, ...]:
        """Ascending coefficients of ``f⁽ᵛ⁾``."""
        if nu >= len(self._rows):
            self._rows = derivative_rows(self._rows[0], nu + 1)
        return self._rows[nu]

    def coefficient_rows(self, orders: Sequence[int], width: int) -> np.ndarray:
        """(len(orders), width) :meth:`coefficients`, padded with high-order zeros."""
        out = np.zeros((len(orders), width))
        for r, nu in enumerate(orders):
            c = self.coefficients(nu)
            out[r, :len(c)] = c
        return out

    def _eval(self, u: np.ndarray, nu: int) -> np.ndarray:
        return horner(self.coefficients(nu), u)

    def scalar(self, u: float, nu: int) -> float:
        return horner(self.coefficients(nu), u)  # Python floats: the same operations

    def critical_points(self, nu: int, lo: float, hi: float) -> tuple[float, ...]:
        if not any(self.coefficients(nu + 1)):
            return ()  # f⁽ᵛ⁾ constant: the ends carry its value
        return super().critical_points(nu, lo, hi)


@dataclass(frozen=True)
class Wave:
    """One harmonic term ``amp·sin(w·(u + shift) + phase)`` (a cosine has phase π/2)."""

    amp: float
    w: float
    phase: float = 0.0
    shift: float = 0.0
    _factors: dict = field(default_factory=dict, init=False, repr=False, compare=False)

    def derivative(self, u: np.ndarray, nu: int) -> np.ndarray:
        """``amp·wᵛ·sin(w·(u + shift) + phase + νπ/2)``."""
        arg = u + self.shift if self.shift else u
        return self.amp * self.w**nu * np.sin(self.w * arg + (self.phase + nu * PI / 2))

    def rows(self, u: np.ndarray, orders: Sequence[int]) -> np.ndarray:
        """:meth:`derivative` for every order, one sine call (same values)."""
        key = tuple(orders)
        hit = self._factors.get(key)
        if hit is None:  # the amplitudes amp·wᵛ and phases φ + νπ/2 as columns
            hit = self._factors[key] = (np.array([[self.amp * self.w**nu] for nu in orders]),
                                        np.array([[self.phase + nu * PI / 2] for nu in orders]))
        a, ph = hit
        arg = u + self.shift if self.shift else u
        return a * np.sin(self.w * arg + ph)


class Harmonic(Law):
    """``f = Σⱼ wavesⱼ(u) + slope·u + offset``.

    Derivatives: the waves' derivatives, plus ``slope·u + offset`` (ν = 0) or ``slope``
    (ν = 1); terms that are zero are not added.
    """

    def __init__(self, waves: Sequence[Wave], slope: float = 0.0, offset: float = 0.0, name: str = "",
                 title: str = "", cv: float = 0.0, ca: float = 0.0, cj: float = 0.0) -> None:
        super().__init__(name, title, cv, ca, cj)
        self.waves, self.slope, self.offset = tuple(waves), slope, offset

    def _tail(self, out: np.ndarray, u: np.ndarray, nu: int) -> np.ndarray:
        if nu == 0:
            if self.slope:
                out = out + (u if self.slope == 1.0 else self.slope * u)
            if self.offset:
                out = out + self.offset
        elif nu == 1 and self.slope:
            out = out + self.slope
        return out

    def _eval(self, u: np.ndarray, nu: int) -> np.ndarray:
        out = self.waves[0].derivative(u, nu)
        for wave in self.waves[1:]:
            out = out + wave.derivative(u, nu)
        return self._tail(out, u, nu)

    def rows(self, u: np.ndarray, orders: Sequence[int]) -> np.ndarray:
        out = self.waves[0].rows(u, orders)
        for wave in self.waves[1:]:
            out = out + wave.rows(u, orders)
        for r, nu in enumerate(orders):
            if nu < 2:
                out[r] = self._tail(out[r], u, nu)
        return out


class Piecewise(Law):
    """Pieces separated by ``breaks``; ``u`` on a break takes the right-hand piece."""

    def __init__(self, breaks: Sequence[float], pieces: Sequence[Law], name: str = "", title: str = "",
                 cv: float = 0.0, ca: float = 0.0, cj: float = 0.0) -> None:
        super().__init__(name, title, cv, ca, cj)
        self.breaks = tuple(breaks)
        self.pieces = tuple(pieces)
        self._edges = np.asarray(self.breaks)

    def _split(self, u: np.ndarray):
        idx = np.searchsorted(self._edges, u, side="right")
        for k, piece in enumerate(self.pieces):
            sel = idx == k
            if np.any(sel):
                yield piece, sel

    def _eval(self, u: np.ndarray, nu: int) -> np.ndarray:
        out = np.empty_like(u, dtype=float)
        for piece, sel in self._split(u):
            out[sel] = piece(u[sel], nu)
        return out

    def rows(self, u: np.ndarray, orders: Sequence[int]) -> np.ndarray:
        out = np.empty((len(orders), u.size))
        for piece, sel in self._split(u):
            out[:, sel] = piece.rows(u[sel], orders)
        return out


class Mirrored(Law):
    """``f(u) = 1 − g(1 − u)``, so ``f⁽ᵏ⁾(u) = (−1)ᵏ⁺¹ g⁽ᵏ⁾(1 − u)``: the return shape of ``g``."""

    def __init__(self, base: Law, name: str = "", title: str = "", cv: float = 0.0, ca: float = 0.0,
                 cj: float = 0.0) -> None:
        super().__init__(name, title, cv, ca, cj)
        self.base = base

    @staticmethod
    def _flip(g: np.ndarray, nu: int) -> np.ndarray:
        return 1.0 - g if nu == 0 else (-1.0) ** (nu + 1) * g

    def _eval(self, u: np.ndarray, nu: int) -> np.ndarray:
        return self._flip(self.base(1.0 - u, nu), nu)

    def rows(self, u: np.ndarray, orders: Sequence[int]) -> np.ndarray:
        g = self.base.rows(1.0 - u, orders)
        for r, nu in enumerate(orders):
            g[r] = self._flip(g[r], nu)
        return g


# ---- the standard laws
_K = 4.0 + PI  # modified sine
_Q = 2.0 + PI  # modified trapezoid
_DH_RISE = Harmonic((Wave(-0.5, PI, PI / 2), Wave(0.125, 2 * PI, PI / 2)), offset=0.375,
                    name="double_harmonic_rise", title="Double Harmonic (rise shape)",
                    cv=3 * np.sqrt(3) * PI / 8, ca=PI**2, cj=42.41389)

_LAW_LIST: list[Law] = [
    Dwell("dwell", "Dwell"),
    Harmonic((Wave(-0.5, PI, PI / 2),), offset=0.5, name="simple_harmonic", title="Simple Harmonic",
             cv=PI / 2, ca=PI**2 / 2, cj=PI**3 / 2),
    Harmonic((Wave(-1 / (2 * PI), 2 * PI),), slope=1.0, name="cycloidal", title="Cycloidal",
             cv=2.0, ca=2 * PI, cj=4 * PI**2),
    Polynomial((0, 0, 0, 10, -15, 6), "poly345", "3-4-5 Polynomial", 1.875, 10 / np.sqrt(3), 60.0),
    Polynomial((0, 0, 0, 0, 35, -84, 70, -20), "poly4567", "4-5-6-7 Polynomial",
               2.1875, 84 * np.sqrt(5) / 25, 52.5),
    Polynomial((0.0, 1.0), "constant_velocity", "Constant Velocity", 1.0, 0.0, 0.0),
    Harmonic((Wave(1.0, PI / 2),), name="semiharmonic_vf0", title="Semiharmonic Vf=0",
             cv=PI / 2, ca=PI**2 / 4, cj=PI**3 / 8),
    Harmonic((Wave(-1.0, PI / 2, PI / 2),), offset=1.0, name="semiharmonic_vi0", title="Semiharmonic Vi=0",
             cv=PI / 2, ca=PI**2 / 4, cj=PI**3 / 8),
    Harmonic((Wave(1 / PI, PI),), slope=1.0, name="semicycloidal_vf0", title="Semicycloidal Vf=0",
             cv=2.0, ca=PI, cj=PI**2),
    Harmonic((Wave(-1 / PI, PI),), slope=1.0, name="semicycloidal_vi0", title="Semicycloidal Vi=0",
             cv=2.0, ca=PI, cj=PI**2),
    _DH_RISE,
    Mirrored(_DH_RISE, "double_harmonic_return", "Double Harmonic (return shape)",
             3 * np.sqrt(3) * PI / 8, PI**2, 42.41389),
    Piecewise((1 / 8, 7 / 8), (
        Harmonic((Wave(-1 / (4 * _K), 4 * PI),), PI / _K, 0.0),
        Harmonic((Wave(-9 / (4 * _K), 4 * PI / 3, 0.0, 0.25),), PI / _K, 2 / _K),  # sin(π/3 + 4πu/3)
        Harmonic((Wave(-1 / (4 * _K), 4 * PI),), PI / _K, 4 / _K),
    ), "modified_sine", "Modified Sine Curve", 4 * PI / _K, 4 * PI**2 / _K, 16 * PI**3 / _K),
    Piecewise((1 / 8, 3 / 8, 5 / 8, 7 / 8), (
        Harmonic((Wave(-1 / (2 * PI * _Q), 4 * PI),), 2 / _Q, 0.0),
        Polynomial(((-8 + PI**2) / (16 * PI * _Q), (2 - PI) / _Q, 4 * PI / _Q)),
        Harmonic((Wave(1 / (2 * PI * _Q), 4 * PI),), (4 * PI + 4 * PI**2) / (2 * PI * _Q),
                 -(PI**2) / (2 * PI * _Q)),
        Polynomial(((-33 * PI**2 + 8) / (16 * PI * _Q), (2 + 7 * PI) / _Q, -4 * PI / _Q)),
        Harmonic((Wave(-1 / (2 * PI * _Q), 4 * PI),), 2 / _Q, 2 * PI**2 / (2 * PI * _Q)),
    ), "modified_trapezoid", "Modified Trapezoidal Curve", 2.0, 8 * PI / _Q, 32 * PI**2 / _Q),
    Piecewise((0.5,), (Polynomial((0.0, 0.0, 2.0)), Polynomial((-1.0, 4.0, -2.0))),
              "constant_acceleration", "Constant Acceleration (parabolic)", 2.0, 4.0, 0.0),
]

#: every standard law by its design-file key
LAWS: dict[str, Law] = {law.name: law for law in _LAW_LIST}

#: half-period laws: name -> (end with non-zero velocity, end slope in units of L/β)
HALF_PERIOD: dict[str, tuple[str, float]] = {
    "semiharmonic_vf0": ("start", PI / 2),
    "semiharmonic_vi0": ("end", PI / 2),
    "semicycloidal_vf0": ("start", 2.0),
    "semicycloidal_vi0": ("end", 2.0),
}

#: generic polynomials solved from their neighbours: name -> degree
GENERIC: dict[str, int] = {"poly5": 5, "poly7": 7}


def law_names() -> list[str]:
    """Every law key accepted in a design file (``double_harmonic`` included)."""
    names = [n for n in LAWS if not n.startswith("double_harmonic_")]
    return sorted(names + ["double_harmonic", *GENERIC])


def get_law(name: str, lift: float = 1.0, shape: str | None = None) -> Law:
    """Resolve a design-file law key to a :class:`Law`.

    ``double_harmonic`` resolves to the rise or return shape by the sign of
    ``lift`` unless ``shape`` ("rise" or "return") says otherwise.  A zero lift
    is a dwell whatever law is named (CAM-DAS rule).
    """
    if lift == 0.0:
        return LAWS["dwell"]
    if name == "double_harmonic":
        shape = shape or ("rise" if lift > 0 else "return")
        return LAWS[f"double_harmonic_{shape}"]
    return LAWS[name]
