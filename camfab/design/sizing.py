"""Design helpers: the smallest base circle for a constraint, the best offset.

Every helper returns the value at which its constraint is exactly active
(so :func:`camfab.design.checks.check` passes just above it and fails just
below), or the geometric lower bound when the constraint never binds.

* :func:`min_base_radius_for_pressure_angle` — translating roller (closed
  form: ``√(R_p² − e²) ≥ max_φ(|S′ + σe|/tan δ_max − S)``) and oscillating
  roller (numerical).
* :func:`min_base_radius_no_undercut` — rollers: min convex ρ_p = R_r.
* :func:`min_base_radius_no_cusp` — flat faces: translating
  ``R_b,min = −min(S + S″)`` (ρ = R_b + S + S″ must stay ≥ 0), oscillating numerical.
* :func:`optimal_offset` — the offset of a translating roller that minimises
  the peak |pressure angle|.
* :func:`min_base_radius_for_cutter` — rollers: the smallest concave profile radius
  (|ρ_p| + R_r) reaches the cutter radius (an outside contour's convex stretches never limit it).
* :func:`best_pivot_and_arm` — oscillating roller: the pivot distance and arm length within bounds
  that minimise the peak |pressure angle|.

The searches are :mod:`camfab.numeric`'s: bracketing root refinement for the radius at which a
constraint becomes active, the global extremum search for the best offset.
"""
from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable

import numpy as np

from ..errors import ApiError, InputError, SpecError
from ..numeric import extremum, root
from .checks import DEFAULT_PRESSURE_LIMIT_DEG
from .mechanisms import Mechanism, OscillatingFlat, OscillatingRoller, TranslatingFlat, TranslatingRoller
from .profile import CamGeometry, Contact, MotionLike

__all__ = [
    "peak_pressure_angle_deg",
    "min_base_radius_for_pressure_angle",
    "min_base_radius_no_undercut",
    "min_base_radius_no_cusp",
    "optimal_offset",
    "min_base_radius_for_cutter",
    "min_base_radius_for_stress",
    "best_pivot_and_arm",
]

_TINY = 1e-9

#: the families these helpers size (each has a ``base_radius_mm``)
_Sized = TranslatingRoller | OscillatingRoller | TranslatingFlat | OscillatingFlat


def _abs_pressure_angle(c: Contact, x) -> np.ndarray:
    """|δ| of contact ``c`` at parameters x (radians)."""
    pa = c.evaluate(x).pressure_angle
    if pa is None:
        raise ApiError(f"{type(c).__name__} has no pressure angle: pressure-angle sizing applies to roller followers")
    return np.abs(pa)


def peak_pressure_angle_deg(mechanism: Mechanism, program: MotionLike) -> float:
    """max |δ| over the cycle in degrees (roller followers)."""
    c = CamGeometry(mechanism, program).profiles[0]
    f = lambda x: _abs_pressure_angle(c, x)  # noqa: E731
    return math.degrees(extremum(f, c.breakpoints, maximize=True)[1])


def _with_rb(mech: _Sized, rb: float) -> _Sized:
    return dataclasses.replace(mech, base_radius_mm=rb)


def _measure(mech: _Sized, program: MotionLike, rb: float, fn: Callable) -> float:
    """fn(contact) at base radius rb; +inf where the geometry cannot be built."""
    try:
        g = CamGeometry(_with_rb(mech, rb), program)
    except SpecError:
        return math.inf
    return fn(g.profiles[0])


def _each(f: Callable[[float], float]) -> Callable[[np.ndarray], np.ndarray]:
    """A scalar function applied to every element of an array."""
    return lambda xs: np.array([f(float(x)) for x in np.ravel(xs)])


def _smallest(f: Callable[[float], float], lo: float, hi: float, n: int = 40) -> float:
    """Smallest r in [lo, hi] with f(r) <= 0 (the first feasible point from below).

    Scans n points, then refines the infeasible→feasible step to its root (f = +inf where the
    geometry cannot be built counts as infeasible, so the step may cross a validity boundary).
    """
    rs = np.geomspace(lo, hi, n) if lo > 0 else np.linspace(lo, hi, n)
    vals = np.array([f(r) for r in rs])
    good = np.flatnonzero(vals <= 0)
    if good.size == 0:
        raise InputError(f"no base radius between {lo:.6g} and {hi:.6g} mm meets the constraint; relax the limit "
                         "or change the follower (offset, pivot, arm)")
    i = int(good[0])
    if i == 0:
        return float(lo)
    return root(_each(f), float(rs[i - 1]), float(rs[i]), fa=vals[i - 1], fb=vals[i])


def _upper(mech: _Sized, program: MotionLike, f: Callable[[float], float], start: float) -> float:
    """A base radius at which f <= 0, found by doubling from ``start``."""
    hi = max(start, 1.0)
    for _ in range(60):
        if f(hi) <= 0:
            return hi
        hi *= 2.0
    raise InputError(f"no base radius up to {hi:.6g} mm meets the constraint; relax the limit or change the "
                     "follower (offset, pivot, arm)")


def _lift(program: MotionLike) -> float:
    x = np.linspace(0.0, program.period, 2001)
    return float(np.max(program.evaluate(x, (0,))[0]))


def _osc_bounds(mech: OscillatingRoller | OscillatingFlat) -> tuple[float, float]:
    if isinstance(mech, OscillatingRoller):
        a, m, rr = mech.arm_length_mm, mech.pivot_distance_mm, mech.roller_radius_mm
        return max(abs(a - m) - rr, 0.0) * (1 + _TINY) + _TINY, (a + m - rr) * (1 - _TINY)
    f, m = mech.face_offset_mm, mech.pivot_distance_mm
    return max(f - m, 0.0) * (1 + _TINY) + _TINY, (f + m) * (1 - _TINY)


def min_base_radius_for_pressure_angle(mechanism: Mechanism, program: MotionLike,
                                       limit_deg: float | None = None) -> float:
    """Smallest R_b (mm) keeping |pressure angle| <= ``limit_deg`` everywhere.

    Parameters
    ----------
    mechanism : TranslatingRoller or OscillatingRoller
        Its roller, offset / pivot and arm are kept; ``base_radius_mm`` is ignored.
    program : MotionProgram
    limit_deg : float, optional
        Default 30° (translating) or 35° (oscillating).
    """
    if isinstance(mechanism, TranslatingRoller):
        lim = math.radians(limit_deg or DEFAULT_PRESSURE_LIMIT_DEG["translating"])
        e, sg = mechanism.offset_mm, mechanism.sense

        def need(x):
            s = program.evaluate(x, (0, 1))
            return np.abs(s[1] + sg * e) / math.tan(lim) - s[0]

        d = extremum(need, np.asarray(program.breakpoints, float), maximize=True)[1]
        rr = mechanism.roller_radius_mm
        if d <= 0:  # never binds: the only bound is |e| < R_p
            return max(abs(e) - rr, 0.0)
        return math.sqrt(d * d + e * e) - rr
    if isinstance(mechanism, OscillatingRoller):
        lim = limit_deg or DEFAULT_PRESSURE_LIMIT_DEG["oscillating"]

        def f(rb):
            def peak(c):
                g = lambda x: _abs_pressure_angle(c, x)  # noqa: E731
                return math.degrees(extremum(g, c.breakpoints, maximize=True)[1]) - lim
            return _measure(mechanism, program, rb, peak)

        return _smallest(f, *_osc_bounds(mechanism))
    raise ApiError("pressure-angle sizing applies to translating and oscillating roller followers, not a "
                   f"{type(mechanism).__name__}")


def min_base_radius_no_undercut(mechanism: Mechanism, program: MotionLike) -> float:
    """Smallest R_b (mm) at which the smallest convex pitch radius equals the roller
    radius (no undercut above it).  Roller followers (translating or oscillating)."""
    if not isinstance(mechanism, (TranslatingRoller, OscillatingRoller)):
        raise ApiError(f"undercut sizing applies to roller followers, not a {type(mechanism).__name__}")
    rr = mechanism.roller_radius_mm
    if rr <= 0:
        raise InputError("roller_radius_mm = 0: a knife edge (roller radius 0) cannot undercut; no sizing needed")

    def f(rb):
        def worst(c):
            return rr * extremum(lambda x: c.evaluate(x).curvature_pitch, c.breakpoints, maximize=True)[1] - 1.0
        return _measure(mechanism, program, rb, worst)

    if isinstance(mechanism, TranslatingRoller):
        lo = max(abs(mechanism.offset_mm) - rr, 0.0) * (1 + _TINY) + _TINY
        return _smallest(f, lo, _upper(mechanism, program, f, 4 * max(rr, _lift(program))))
    return _smallest(f, *_osc_bounds(mechanism))


def min_base_radius_no_cusp(mechanism: Mechanism, program: MotionLike) -> float:
    """Smallest R_b (mm) of a flat-face follower at which the profile's radius of
    curvature reaches 0 (a cusp); above it the profile is free of cusps.

    Translating face: ``R_b,min = −min(S + S″)`` exactly (its radius of curvature is R_b + S + S″).
    """
    if isinstance(mechanism, TranslatingFlat):
        g = lambda x: np.sum(program.evaluate(x, (0, 2)), axis=0)  # noqa: E731
        return max(-extremum(g, np.asarray(program.breakpoints, float))[1], 0.0)
    if isinstance(mechanism, OscillatingFlat):
        def f(rb):
            return _measure(mechanism, program, rb,
                            lambda c: -extremum(lambda x: c.evaluate(x).rho, c.breakpoints)[1])
        return _smallest(f, *_osc_bounds(mechanism))
    raise ApiError(f"cusp sizing applies to flat-face followers, not a {type(mechanism).__name__}")


def optimal_offset(mechanism: TranslatingRoller, program: MotionLike) -> float:
    """Offset e (mm) that minimises the peak |pressure angle| of a translating roller.

    Searched over |e| < 0.99·R_p (a coarse scan, then the best local minima refined to 1e-9 of
    their bracket); the base and roller radii of ``mechanism`` are kept.
    """
    if not isinstance(mechanism, TranslatingRoller):
        raise ApiError(f"optimal_offset applies to translating roller followers, not a {type(mechanism).__name__}")
    rp = mechanism.prime_radius_mm

    def peak(e):
        return peak_pressure_angle_deg(dataclasses.replace(mechanism, offset_mm=e), program)

    span = 0.99 * rp
    return extremum(_each(peak), [-span, span], step=span / 4).at


def min_base_radius_for_cutter(mechanism: Mechanism, program: MotionLike, tool_radius_mm: float) -> float:
    """Smallest R_b (mm) at which every concave stretch of a roller follower's profile is at least as wide
    as the cutter: min over concave stretches of (1/|κ_p| + R_r) >= ``tool_radius_mm``.

    A flat face's profile has no concave stretch (ρ = R_b + S + S″ > 0 where it is valid), so only roller
    followers (translating or oscillating) are sized; a profile with no concave stretch needs no sizing
    (its geometric lower bound is returned).
    """
    if not isinstance(mechanism, (TranslatingRoller, OscillatingRoller)):
        raise ApiError(f"cutter sizing applies to roller followers, not a {type(mechanism).__name__}")
    rr, rt = mechanism.roller_radius_mm, float(tool_radius_mm)
    if not (math.isfinite(rt) and rt > 0):
        raise InputError(f"tool radius {rt!r}: must be a positive length in mm")

    def f(rb):
        def tight(c):
            kmin = extremum(lambda x: c.evaluate(x).curvature_pitch, c.breakpoints)[1]
            # concave radius 1/|κ| + R_r >= R_t  ⟺  (R_t − R_r)·|κ| − 1 <= 0
            return (rt - rr) * max(-kmin, 0.0) - 1.0
        return _measure(mechanism, program, rb, tight)

    if isinstance(mechanism, TranslatingRoller):
        lo = max(abs(mechanism.offset_mm) - rr, 0.0) * (1 + _TINY) + _TINY
        if rt <= rr:  # the concave radius is always > R_r
            return lo
        return _smallest(f, lo, _upper(mechanism, program, f, 4 * max(rt, _lift(program))))
    if rt <= rr:
        return _osc_bounds(mechanism)[0]
    return _smallest(f, *_osc_bounds(mechanism))


def best_pivot_and_arm(mechanism: OscillatingRoller, program: MotionLike,
                       pivot_bounds: tuple[float, float], arm_bounds: tuple[float, float]) -> tuple[float, float]:
    """Pivot distance m and arm length A (mm) within their bounds that minimise the peak |pressure angle| of an
    oscillating roller at its base radius (scipy's bounded Powell search from the mechanism's own m and A,
    deterministic).  A pair whose arm cannot reach the prime circle, or swings past the line of centres,
    counts as infinitely bad."""
    from scipy.optimize import minimize

    if not isinstance(mechanism, OscillatingRoller):
        raise ApiError(f"best_pivot_and_arm applies to oscillating roller followers, not a {type(mechanism).__name__}")

    def peak(z) -> float:
        m, a = float(z[0]), float(z[1])
        mech = dataclasses.replace(mechanism, pivot_distance_mm=m, arm_length_mm=a)
        if mech.validate() or mech.validate_motion(program):
            return 180.0
        try:
            return peak_pressure_angle_deg(mech, program)
        except (SpecError, InputError):
            return 180.0

    x0 = [min(max(mechanism.pivot_distance_mm, pivot_bounds[0]), pivot_bounds[1]),
          min(max(mechanism.arm_length_mm, arm_bounds[0]), arm_bounds[1])]
    res = minimize(peak, x0, method="Powell", bounds=[pivot_bounds, arm_bounds],
                   options={"xtol": 1e-4, "ftol": 1e-8, "maxfev": 200})
    best = (float(res.x[0]), float(res.x[1]))
    return best if peak(best) <= peak(x0) else (float(x0[0]), float(x0[1]))


def min_base_radius_for_stress(mechanism: Mechanism, program: MotionLike,
                               peak_stress_mpa: Callable[[Mechanism], float], allowable_mpa: float) -> float:
    """Smallest R_b (mm) at which the peak Hertz contact stress ``peak_stress_mpa(mechanism at R_b)`` (MPa; +inf
    where it is infinite or the geometry cannot be built) is at most ``allowable_mpa``.

    The stress falls as the base circle grows (the profile's curvature flattens and the pressure angle drops),
    so the first feasible radius of a scan from the follower's geometric lower bound (a flat face: from its
    cusp radius, where the stress is infinite) is refined to the root of p_max/allowable − 1.
    """
    if not (math.isfinite(allowable_mpa) and allowable_mpa > 0):
        raise InputError(f"allowable contact stress {allowable_mpa!r}: must be a positive stress in MPa")

    def f(rb):
        try:
            p = float(peak_stress_mpa(_with_rb(mechanism, rb)))
        except SpecError:
            return math.inf
        return p / allowable_mpa - 1.0 if math.isfinite(p) else math.inf

    if isinstance(mechanism, (OscillatingRoller, OscillatingFlat)):
        return _smallest(f, *_osc_bounds(mechanism), n=24)
    if isinstance(mechanism, TranslatingRoller):
        lo = max(abs(mechanism.offset_mm) - mechanism.roller_radius_mm, 0.0) * (1 + _TINY) + _TINY
        start = 4 * max(mechanism.roller_radius_mm, _lift(program))
    elif isinstance(mechanism, TranslatingFlat):
        lo = min_base_radius_no_cusp(mechanism, program) * (1 + _TINY) + _TINY
        start = 2 * max(lo, _lift(program))
    else:
        raise ApiError(f"contact-stress sizing applies to disc cams with roller or flat-face followers, not a "
                       f"{type(mechanism).__name__}")
    start = max(start, lo)
    far = 1000.0 * start  # a cam this large is flat to the follower: the stress is then the follower's alone
    if f(far) > 0:
        raise InputError(f"no base radius brings the contact stress to the allowable {allowable_mpa:g} MPa: even "
                         f"at {far:.6g} mm it is {(f(far) + 1) * allowable_mpa:.6g} MPa (set by the follower's "
                         "radius and the force, not by the cam): widen the face, use a larger roller or a stronger "
                         "material, or lower the force")
    return _smallest(f, lo, _upper(mechanism, program, f, start), n=24)
