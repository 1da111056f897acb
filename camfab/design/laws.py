"""Normalised motion laws ("leyes de desplazamiento").

Every standard law is a normalised shape ``f(u)`` on ``u = x/β ∈ [0, 1]`` with
``f(0) = 0`` and ``f(1) = 1``.  A segment of signed lift ``L`` starting at
ordinate ``Li`` is ``S = Li + L·f(u)`` and its derivatives with respect to the
cam angle are ``S⁽ᵏ⁾ = L/βᵏ · f⁽ᵏ⁾(u)``, so one formula serves rise (L > 0) and
return (L < 0).  Formulas: ``../shared/spec/motion-laws.md`` §5; peak
coefficients §7; boundary values §6.

Each shape function has the signature ``f(u, nu)`` and returns the ``nu``-th
derivative (``nu`` = 0…4) of the normalised shape, vectorised over the numpy
array ``u``.  Piecewise laws also list their internal breakpoints in ``u`` so
that samplers and root finders never straddle a kink.

Double harmonic (spec doubt D3): the rise shape ``g(u)`` ends with non-zero
acceleration and the return shape ``1 − g(1 − u)`` starts with it.  camfab picks
the shape **by the sign of the lift** (L > 0 → rise shape, L < 0 → return
shape), which makes both the classical rise-then-return pair and the Ejemplo8DA
conjugate (return first, then rise) continuous through jerk; a segment may
override the choice with ``shape = "rise" | "return"``.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

__all__ = ["Law", "LAWS", "HALF_PERIOD", "GENERIC", "get_law", "law_names"]

PI = np.pi
ShapeFn = Callable[[np.ndarray, int], np.ndarray]


@dataclass(frozen=True, slots=True)
class Law:
    """A normalised motion law.

    Attributes
    ----------
    name : str
        Key used in design files (``law = "cycloidal"``).
    title : str
        Human-readable name (CAM-DAS English UI name where one exists).
    shape : callable
        ``shape(u, nu) -> ndarray``: ``nu``-th derivative of ``f`` at ``u``.
    breaks : tuple of float
        Internal breakpoints in ``u`` (open interval (0, 1)) where the shape
        changes formula.
    cv, ca, cj : float
        Peak coefficients ``max|f'|, max|f''|, max|f'''|`` (spec §7).
    """

    name: str
    title: str
    shape: ShapeFn
    breaks: tuple[float, ...] = ()
    cv: float = 0.0
    ca: float = 0.0
    cj: float = 0.0

    def __call__(self, u: np.ndarray, nu: int = 0) -> np.ndarray:
        return self.shape(np.asarray(u, dtype=float), nu)


def _zeros(u: np.ndarray) -> np.ndarray:
    return np.zeros_like(u, dtype=float)


def _dwell(u, nu):
    return _zeros(u)


def _constant_velocity(u, nu):
    if nu == 0:
        return u.astype(float, copy=True)
    if nu == 1:
        return np.ones_like(u, dtype=float)
    return _zeros(u)


def _trig(kind: str, w: float, amp: float, nu: int, u: np.ndarray) -> np.ndarray:
    """``nu``-th derivative of ``amp·sin(w u)`` (kind 's') or ``amp·cos(w u)`` ('c')."""
    phase = {"s": 0.0, "c": PI / 2}[kind] + nu * PI / 2
    return amp * w**nu * np.sin(w * u + phase)


def _poly(coeffs: tuple[float, ...]) -> ShapeFn:
    """Shape from ascending polynomial coefficients in ``u``."""
    base = np.polynomial.Polynomial(coeffs)
    derivs = [tuple(float(c) for c in (base.deriv(k) if k else base).coef) for k in range(6)]

    def shape(u, nu):
        return horner(derivs[nu], u)

    shape.coeffs = derivs  # type: ignore[attr-defined]
    return shape


def horner(c: tuple[float, ...], u: np.ndarray) -> np.ndarray:
    """``Σ c[i]·uⁱ`` by Horner's rule, operation for operation as
    :func:`numpy.polynomial.polynomial.polyval` (so bit-identical to it), without its
    per-call overhead."""
    out = c[-1] + u * 0.0
    for ci in c[-2::-1]:
        out = ci + out * u
    return out


def _simple_harmonic(u, nu):
    # f = (1 - cos πu)/2
    out = _trig("c", PI, -0.5, nu, u)
    return out + 0.5 if nu == 0 else out


def _cycloidal(u, nu):
    # f = u - sin(2πu)/(2π)
    out = _trig("s", 2 * PI, -1 / (2 * PI), nu, u)
    if nu == 0:
        out += u
    elif nu == 1:
        out += 1.0
    return out


def _semiharmonic_vf0(u, nu):
    # f = sin(πu/2): velocity zero at the end
    return _trig("s", PI / 2, 1.0, nu, u)


def _semiharmonic_vi0(u, nu):
    # f = 1 - cos(πu/2): velocity zero at the start
    out = _trig("c", PI / 2, -1.0, nu, u)
    return out + 1.0 if nu == 0 else out


def _semicycloidal_vf0(u, nu):
    # f = u + sin(πu)/π
    out = _trig("s", PI, 1 / PI, nu, u)
    if nu == 0:
        out += u
    elif nu == 1:
        out += 1.0
    return out


def _semicycloidal_vi0(u, nu):
    # f = u - sin(πu)/π
    out = _trig("s", PI, -1 / PI, nu, u)
    if nu == 0:
        out += u
    elif nu == 1:
        out += 1.0
    return out


def _dh_rise(u, nu):
    # g = ½[(1 - cos πu) - ¼(1 - cos 2πu)] = 3/8 - ½cos πu + ⅛cos 2πu
    out = _trig("c", PI, -0.5, nu, u) + _trig("c", 2 * PI, 0.125, nu, u)
    return out + 0.375 if nu == 0 else out


def _dh_return(u, nu):
    # f = 1 - g(1 - u);  f^(k)(u) = (-1)^(k+1) g^(k)(1 - u)
    g = _dh_rise(1.0 - u, nu)
    return 1.0 - g if nu == 0 else (-1.0) ** (nu + 1) * g


def _piecewise(breaks: tuple[float, ...], pieces: tuple[ShapeFn, ...]) -> ShapeFn:
    """Shape made of pieces separated by ``breaks``; u on a break takes the right piece."""
    edges = np.asarray(breaks)

    def shape(u, nu):
        idx = np.searchsorted(edges, u, side="right")
        out = np.empty_like(u, dtype=float)
        for k, piece in enumerate(pieces):
            sel = idx == k
            if np.any(sel):
                out[sel] = piece(u[sel], nu)
        return out

    return shape


def _with_linear(fn: ShapeFn, slope: float, offset: float) -> ShapeFn:
    """``fn(u) + slope·u + offset`` with the derivatives to match."""

    def shape(u, nu):
        out = fn(u, nu)
        if nu == 0:
            return out + slope * u + offset
        if nu == 1:
            return out + slope
        return out

    return shape


# ---- modified sine (Norton form, K = 4 + π), spec §5.11
_K = 4.0 + PI
_ms_end = _with_linear(lambda u, nu: _trig("s", 4 * PI, -1 / (4 * _K), nu, u), PI / _K, 0.0)
_ms_mid = _with_linear(
    lambda u, nu: _trig("s", 4 * PI / 3, -9 / (4 * _K), nu, u + 0.25),  # sin(π/3 + 4πu/3)
    PI / _K,
    2 / _K,
)
_ms_last = _with_linear(lambda u, nu: _trig("s", 4 * PI, -1 / (4 * _K), nu, u), PI / _K, 4 / _K)
_modified_sine = _piecewise((1 / 8, 7 / 8), (_ms_end, _ms_mid, _ms_last))

# ---- modified trapezoid (Q = 2 + π), spec §5.12
_Q = 2.0 + PI
_mt_1 = _with_linear(lambda u, nu: _trig("s", 4 * PI, -1 / (2 * PI * _Q), nu, u), 2 / _Q, 0.0)
_mt_2 = _poly(((-8 + PI**2) / (16 * PI * _Q), (2 - PI) / _Q, 4 * PI / _Q))
_mt_3 = _with_linear(
    lambda u, nu: _trig("s", 4 * PI, 1 / (2 * PI * _Q), nu, u),
    (4 * PI + 4 * PI**2) / (2 * PI * _Q),
    -(PI**2) / (2 * PI * _Q),
)
_mt_4 = _poly(((-33 * PI**2 + 8) / (16 * PI * _Q), (2 + 7 * PI) / _Q, -4 * PI / _Q))
_mt_5 = _with_linear(
    lambda u, nu: _trig("s", 4 * PI, -1 / (2 * PI * _Q), nu, u),
    2 / _Q,
    2 * PI**2 / (2 * PI * _Q),
)
_modified_trapezoid = _piecewise((1 / 8, 3 / 8, 5 / 8, 7 / 8), (_mt_1, _mt_2, _mt_3, _mt_4, _mt_5))

# ---- constant acceleration ("parabolic", textbook 003): f = 2u², then 1 - 2(1-u)²
_constant_acceleration = _piecewise(
    (0.5,), (_poly((0.0, 0.0, 2.0)), _poly((-1.0, 4.0, -2.0)))
)

_LAW_LIST = [
    Law("dwell", "Dwell", _dwell),
    Law("simple_harmonic", "Simple Harmonic", _simple_harmonic, (), PI / 2, PI**2 / 2, PI**3 / 2),
    Law("cycloidal", "Cycloidal", _cycloidal, (), 2.0, 2 * PI, 4 * PI**2),
    Law("poly345", "3-4-5 Polynomial", _poly((0, 0, 0, 10, -15, 6)), (), 1.875, 10 / np.sqrt(3), 60.0),
    Law("poly4567", "4-5-6-7 Polynomial", _poly((0, 0, 0, 0, 35, -84, 70, -20)), (),
        2.1875, 84 * np.sqrt(5) / 25, 52.5),
    Law("constant_velocity", "Constant Velocity", _constant_velocity, (), 1.0, 0.0, 0.0),
    Law("semiharmonic_vf0", "Semiharmonic Vf=0", _semiharmonic_vf0, (), PI / 2, PI**2 / 4, PI**3 / 8),
    Law("semiharmonic_vi0", "Semiharmonic Vi=0", _semiharmonic_vi0, (), PI / 2, PI**2 / 4, PI**3 / 8),
    Law("semicycloidal_vf0", "Semicycloidal Vf=0", _semicycloidal_vf0, (), 2.0, PI, PI**2),
    Law("semicycloidal_vi0", "Semicycloidal Vi=0", _semicycloidal_vi0, (), 2.0, PI, PI**2),
    Law("double_harmonic_rise", "Double Harmonic (rise shape)", _dh_rise, (),
        3 * np.sqrt(3) * PI / 8, PI**2, 42.41389),
    Law("double_harmonic_return", "Double Harmonic (return shape)", _dh_return, (),
        3 * np.sqrt(3) * PI / 8, PI**2, 42.41389),
    Law("modified_sine", "Modified Sine Curve", _modified_sine, (1 / 8, 7 / 8),
        4 * PI / _K, 4 * PI**2 / _K, 16 * PI**3 / _K),
    Law("modified_trapezoid", "Modified Trapezoidal Curve", _modified_trapezoid,
        (1 / 8, 3 / 8, 5 / 8, 7 / 8), 2.0, 8 * PI / _Q, 32 * PI**2 / _Q),
    Law("constant_acceleration", "Constant Acceleration (parabolic)", _constant_acceleration,
        (0.5,), 2.0, 4.0, 0.0),
]

#: every standard law by its design-file key
LAWS: dict[str, Law] = {law.name: law for law in _LAW_LIST}

#: single-term trigonometric laws, for evaluating several derivative orders at once:
#: ``f⁽ᵛ⁾ = _trig(kind, w, amp, ν, u)``, plus ``add0`` at ν = 0 ("u" adds u) and ``add1`` at
#: ν = 1 (None: nothing), exactly as the shape functions above compute them
TRIG1: dict[str, tuple] = {
    "simple_harmonic": ("c", PI, -0.5, 0.5, None),
    "cycloidal": ("s", 2 * PI, -1 / (2 * PI), "u", 1.0),
    "semiharmonic_vf0": ("s", PI / 2, 1.0, None, None),
    "semiharmonic_vi0": ("c", PI / 2, -1.0, 1.0, None),
    "semicycloidal_vf0": ("s", PI, 1 / PI, "u", 1.0),
    "semicycloidal_vi0": ("s", PI, -1 / PI, "u", 1.0),
}


def trig_rows(name: str, orders, u: np.ndarray) -> np.ndarray:
    """``[f⁽ᵛ⁾(u) for ν in orders]`` of a :data:`TRIG1` law as one (len(orders), n) array, value
    for value as its shape function (one sine call for all orders)."""
    kind, w, amp, add0, add1 = TRIG1[name]
    base = {"s": 0.0, "c": PI / 2}[kind]
    a = np.array([amp * w**nu for nu in orders])
    ph = np.array([base + nu * PI / 2 for nu in orders])
    out = a[:, None] * np.sin(w * u + ph[:, None])
    for r, nu in enumerate(orders):
        if nu == 0 and add0 is not None:
            out[r] += u if add0 == "u" else add0
        elif nu == 1 and add1 is not None:
            out[r] += add1
    return out

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
