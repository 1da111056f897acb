"""Brent's bracketing root finder for one scalar function, step for step the algorithm of
``scipy.optimize.brentq`` (Brent 1973, ch. 4, in Charles Harris's formulation that scipy compiles):
the same trial points, so the same root to the last bit.

It lives here so that a command that needs a handful of roots (a law's critical points, a
conjugate cam's admissible follower range) does not import :mod:`scipy.optimize`, which alone
cost more than half of ``camfab check``'s start (docs/decisions.md "Lazy imports").
"""
from __future__ import annotations

import math
from collections.abc import Callable

from .errors import InputError, InternalError

__all__ = ["brentq"]

_EPS = 2.220446049250313e-16
#: scipy.optimize.brentq's defaults
XTOL, RTOL, MAXITER = 2e-12, 4 * _EPS, 100


def _value(f: Callable[[float], float], x: float) -> float:
    v = float(f(x))
    if math.isnan(v):
        raise InputError(f"The function value at x={x} is NaN; solver cannot continue.")
    return v


def brentq(f: Callable[[float], float], a: float, b: float, *, xtol: float = XTOL, rtol: float = RTOL,
           maxiter: int = MAXITER) -> float:
    """A root of ``f`` in ``[a, b]`` (``f(a)`` and ``f(b)`` of opposite signs), to within
    ``xtol + rtol·|x|``, as ``scipy.optimize.brentq(f, a, b, xtol=, rtol=, maxiter=)`` returns it.

    Raises :class:`~camfab.errors.InputError` (a ``ValueError``, as scipy raises) when the ends do not bracket a
    sign change or ``f`` gives NaN, and :class:`~camfab.errors.InternalError` (a ``RuntimeError``) when
    ``maxiter`` steps do not converge.
    """
    if xtol <= 0:
        raise InputError(f"xtol too small ({xtol:g} <= 0)")
    if rtol < RTOL:
        raise InputError(f"rtol too small ({rtol:g} < {RTOL:g})")
    x_prev, x_cur = float(a), float(b)
    f_prev, f_cur = _value(f, x_prev), _value(f, x_cur)
    if f_prev * f_cur > 0:
        raise InputError("f(a) and f(b) must have different signs")
    if f_prev == 0:
        return x_prev
    if f_cur == 0:
        return x_cur
    x_blk = f_blk = s_prev = s_cur = 0.0
    for _ in range(maxiter):
        if f_prev != 0 and f_cur != 0 and math.copysign(1.0, f_prev) != math.copysign(1.0, f_cur):
            x_blk, f_blk = x_prev, f_prev
            s_prev = s_cur = x_cur - x_prev
        if abs(f_blk) < abs(f_cur):  # keep the best estimate in x_cur
            x_prev, x_cur, x_blk = x_cur, x_blk, x_cur
            f_prev, f_cur, f_blk = f_cur, f_blk, f_cur
        delta = (xtol + rtol * abs(x_cur)) / 2
        s_bis = (x_blk - x_cur) / 2
        if f_cur == 0 or abs(s_bis) < delta:
            return x_cur
        s_prev, s_cur = _step(x_prev, x_cur, x_blk, f_prev, f_cur, f_blk, s_prev, s_cur, s_bis, delta)
        x_prev, f_prev = x_cur, f_cur
        x_cur += s_cur if abs(s_cur) > delta else (delta if s_bis > 0 else -delta)
        f_cur = _value(f, x_cur)
    raise InternalError(f"brentq: failed to converge after {maxiter} iterations, value is {x_cur}")


def _step(x_prev: float, x_cur: float, x_blk: float, f_prev: float, f_cur: float, f_blk: float,
          s_prev: float, s_cur: float, s_bis: float, delta: float) -> tuple[float, float]:
    """The next (previous step, step): the interpolated one when it is short enough, else bisection."""
    if abs(s_prev) > delta and abs(f_cur) < abs(f_prev):
        if x_prev == x_blk:  # secant
            s_try = -f_cur * (x_cur - x_prev) / (f_cur - f_prev)
        else:  # inverse quadratic
            d_prev = (f_prev - f_cur) / (x_prev - x_cur)
            d_blk = (f_blk - f_cur) / (x_blk - x_cur)
            s_try = -f_cur * (f_blk * d_blk - f_prev * d_prev) / (d_blk * d_prev * (f_blk - f_prev))
        if 2 * abs(s_try) < min(abs(s_prev), 3 * abs(s_bis) - delta):
            return s_cur, s_try
    return s_bis, s_bis
