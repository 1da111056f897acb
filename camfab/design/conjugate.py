"""Conjugate cams: two cams on one shaft driving one rigid double follower, both ways (form closure).

A rigid double follower is driven positively in both directions: follower 1 touches cam 1, follower 2 touches
cam 2 in a second plane.  The constant-width and constant-diameter cams (:mod:`camfab.design.symmetric`) are
the special case where both followers touch the same profile; they share :class:`DesmodromicGeometry`.

Conventions and derivation
--------------------------
camfab's single convention applies (:mod:`camfab.design.mechanism`): cam centre at the origin, follower 1
above the cam along +Y at cam angle 0, ``rotation="cw"`` by default.  (The Cardona & Clos rotation matrix
``[S_θ] = R(−θ)`` of the source's conjugate-cam chapter is camfab's ``rotation="ccw"``; the tests check the
source's formulas against the ``ccw`` cams.)

Follower 2 sits on the far side of the line through the cam centre perpendicular to follower 1 (translating:
below the cam centre on the same axis x = ε; oscillating: arm 2 on the same pivot, β clockwise-*before*
arm 1, i.e. below the line of centres).  Mirroring the mechanism in that line (y → −y) turns follower 2 into
an ordinary single follower above the cam on a cam that turns the *other* way; hence (M = diag(1, −1) in the
cam frame)::

    profile 2(φ) = M · profile(mirrored follower 2, sense −σ, law S₂)(φ)

and the rigid follower gives the complementary law ``S₂(φ) = h − S₁(φ)`` (h = max S₁), measured from cam 2's
own base/prime circle: it starts with a descent (CAM-DAS Ejemplo7CRT/8DA).  Curvature and pressure angle are
invariant under the mirror; normals and points are mirrored.  Second-cam geometry:

* translating flat: ``R_b2 = d − R_b1 − h`` (d = face-to-face distance);
* translating roller: roller centres at distance d on the axis x = ε, ``a₂ = d − √(R_p1² − ε²) − h``,
  ``R_p2 = √(a₂² + ε²)``, ``R_b2 = R_p2 − R_r2``;
* oscillating (β = angle at the pivot between arm/face 1 and arm/face 2): mirrored arm angle
  ``ξ₂′ = β − ξ₁ = ξ₂₀′ + S₂`` with ``ξ₂₀′ = β − ξ₁₀ − h``; flat ``R_b2 = f + m sin ξ₂₀′``, roller
  ``R_p2² = A² + m² − 2Am cos ξ₂₀′`` (derived here by the law of cosines in the pivot triangle; the source's
  formula for this case is unusable).

The *minimum admissible follower distance* (oscillating: follower angle) is the value below which the second
cam cannot be made: its base radius reaches 0 (or the bore radius), its profile cusps/undercuts (flat ρ₂ ≤ 0,
roller convex pitch radius ≤ R_r2), or the second follower cannot exist (a₂ ≤ 0, arm 2 not below the line of
centres).  It is computed by root finding on that margin and enforced with a
:class:`~camfab.errors.Problem` naming the field.
"""
from __future__ import annotations

import math
from typing import Any, ClassVar

import numpy as np

from ..brent import brentq
from ..errors import ApiError, Problem
from ..numeric import extremum
from ..records import dataclass, replace
from ..sets import sorted_unique
from .faces import OscillatingFlat, OscillatingFlatContact, TranslatingFlat, TranslatingFlatContact
from .kinds import CamKind, FollowerMotion, FollowerType
from .mechanism import Mechanism, finite_fields, require_rotation
from .profile import CamGeometry, Contact, MotionLike, ProfileSample
from .rollers import OscillatingRoller, OscillatingRollerContact, TranslatingRoller, TranslatingRollerContact

__all__ = [
    "ConjugateTranslatingFlat", "ConjugateTranslatingRoller", "ConjugateOscillatingFlat", "ConjugateOscillatingRoller",
    "ComplementMotion", "SecondTranslatingFlatContact", "SecondTranslatingRollerContact",
    "SecondOscillatingFlatContact", "SecondOscillatingRollerContact", "DesmodromicGeometry", "FormClosed",
    "follower_limits", "minimum_follower_distance", "lift_of",
]

_K = math.pi / 180.0
_MX = np.array([1.0, -1.0])



# ---------------------------------------------------------------------------
class ComplementMotion:
    """The second follower's law ``S₂(x) = lift − S₁(x)`` (same breakpoints, period).

    Parameters
    ----------
    base : MotionLike
        The first follower's program (mm, or degrees for oscillating followers).
    lift : float
        h = max S₁ (same unit).
    """

    def __init__(self, base, lift: float):
        self.base, self.lift, self.period = base, float(lift), float(base.period)
        self.breakpoints = np.asarray(base.breakpoints, dtype=float)
        self.axis = base.axis

    def evaluate(self, x, orders=(0, 1, 2, 3)) -> np.ndarray:
        out = -np.asarray(self.base.evaluate(x, orders), dtype=float)
        out[[i for i, nu in enumerate(orders) if nu == 0]] += self.lift
        return out

    def __call__(self, x, nu: int = 0) -> np.ndarray:
        return self.evaluate(x, (nu,))[0]


def lift_of(program) -> float:
    """h = max S of a program (exact peaks when available), in its lift unit."""
    peaks = getattr(program, "peaks", None)
    if peaks is not None:
        return float(peaks("exact")[0].max)
    return extremum(lambda x: program.evaluate(x, (0,))[0], program.breakpoints, maximize=True)[1]


def _mirror(s: ProfileSample) -> ProfileSample:
    m = lambda v: None if v is None else v * _MX  # noqa: E731
    return replace(s, point=s.point * _MX, point_d1=s.point_d1 * _MX, normal=s.normal * _MX,
                   tangent=s.tangent * _MX, pitch=m(s.pitch), arm_angle=None if s.arm_angle is None else -s.arm_angle)


class _Second:
    """Mixin: the contact of follower 2 = mirror (y → −y) of the plain contact of the
    mirrored follower on a cam turning the other way.  ``sense`` is the true σ;
    ``arm_angle`` is the true (negative, below the line of centres) arm angle."""

    _plain: type

    def __init__(self, *args, sense: int = 1):
        super().__init__(*args, sense=sense)  # type: ignore[call-arg]
        self._inner = self._plain(*args, sense=-sense)

    def _evaluate(self, phi, rotate: bool, S=None) -> ProfileSample:
        return _mirror(self._inner._evaluate(phi, rotate, S))


class SecondTranslatingFlatContact(_Second, TranslatingFlatContact):
    """Lower face of a double translating flat follower (args of :class:`TranslatingFlatContact`)."""
    _plain = TranslatingFlatContact


class SecondTranslatingRollerContact(_Second, TranslatingRollerContact):
    """Lower roller of a double translating roller follower."""
    _plain = TranslatingRollerContact


class SecondOscillatingFlatContact(_Second, OscillatingFlatContact):
    """Second face of a double oscillating flat follower (below the line of centres)."""
    _plain = OscillatingFlatContact


class SecondOscillatingRollerContact(_Second, OscillatingRollerContact):
    """Second roller of a double oscillating roller follower (below the line of centres)."""
    _plain = OscillatingRollerContact


# ---------------------------------------------------------------------------
class DesmodromicGeometry(CamGeometry):
    """A :class:`CamGeometry` of a desmodromic cam with the double follower's checks.

    Profiles: conjugate pairs have two (cam 1, cam 2, one cam frame);
    constant-width/diameter cams have one, touched by follower 2 at φ + π.
    """

    form_closed: ClassVar[bool] = True

    @property
    def second_program(self):
        """Follower 2's law S₂ = h − S₁ of a conjugate pair (None for one profile)."""
        return self.profiles[1].motion if len(self.profiles) > 1 else None

    def _pair(self, phi) -> tuple[ProfileSample, ProfileSample]:
        phi = np.atleast_1d(np.asarray(phi, dtype=float))
        if len(self.profiles) == 1:
            return self.evaluate(phi), self.evaluate(phi + math.pi)
        return self.evaluate(phi, 0), self.evaluate(phi, 1)

    def follower_distance(self, phi) -> np.ndarray:
        """Distance kept by the translating double follower, measured on the geometry (mm):
        face gap (distance between the tangents at both contacts) or roller-centre distance."""
        a, b = self._pair(phi)
        if a.pitch is not None:
            return np.hypot(*(a.pitch - b.pitch).T)
        return ((a.point - b.point) * a.normal).sum(axis=1)

    def width(self, phi) -> np.ndarray:
        """Constant-width cam: distance between the parallel tangents at φ and φ + π;
        constant-diameter cam: roller-centre distance (pitch chord through the centre)."""
        if len(self.profiles) != 1:
            raise ApiError("width() applies to constant-width and constant-diameter cams (one profile), this pair has "
                           f"{len(self.profiles)}; use follower_distance()")
        return self.follower_distance(phi)

    def contact_distance(self, phi) -> np.ndarray:
        """Distance between the two contact points (mm; not constant for rollers where S′ ≠ 0)."""
        a, b = self._pair(phi)
        return np.hypot(*(a.point - b.point).T)

    def follower_angle(self, phi) -> np.ndarray:
        """Oscillating pairs: angle β (degrees) at the pivot between arm/face 1 and 2, from the geometry."""
        a, b = self._pair(phi)
        sx = self.profiles[0].sense * np.atleast_1d(np.asarray(phi, dtype=float))
        if a.pitch is not None:  # arms: pivot → roller centres (pivot turned into the cam frame)
            pv = self.mechanism.pivot_distance_mm * np.stack([np.cos(sx), np.sin(sx)], axis=1)
            u, v, turn = a.pitch - pv, b.pitch - pv, 0.0
        else:  # faces: their normals are π − β apart
            u, v, turn = a.normal, b.normal, math.pi
        ang = np.arctan2(u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0], (u * v).sum(1))
        return np.degrees(np.mod(turn + ang, 2 * math.pi))


# ---------------------------------------------------------------------------
class FormClosed(Mechanism):
    """Base of the form-closed families (conjugate pairs, constant width/diameter): one rigid double
    follower driven both ways, measured by :class:`DesmodromicGeometry`."""

    geometry_class: ClassVar[type[CamGeometry]] = DesmodromicGeometry


class _Desmodromic(FormClosed):
    """Base of the conjugate pairs.  Subclasses give ``first_mechanism()`` (follower 1
    as a single-follower mechanism), ``_span(h)`` (open interval of the free
    parameter q in which follower 2 exists) and ``_second(program, h, q)`` →
    (contact 2 or None, R_b2, existence margin > 0)."""

    cam_kind: ClassVar[CamKind] = CamKind.CONJUGATE
    #: the free parameter bounded by the minimum follower distance (angle)
    _free_field = "follower_distance_mm"

    # fields every conjugate pair has (declared by each subclass's dataclass; annotations only here:
    # this base is not a dataclass, so they add no fields)
    base_radius_mm: float
    rotation: str

    @property
    def second_roller_mm(self) -> float:
        r = getattr(self, "second_roller_radius_mm", None)
        return getattr(self, "roller_radius_mm", 0.0) if r is None else r

    def _free(self) -> float:
        return float(getattr(self, self._free_field))

    @property
    def initial_arm_angle(self) -> float | None:
        """ξ₁₀ (radians) of arm/face 1 of an oscillating pair, else None."""
        return getattr(self.first_mechanism(), "initial_arm_angle", None)

    def validate(self) -> list[Problem]:
        p: list[Problem] = []
        if self._static(p) and self._free() <= 0:
            p.append(Problem(f"follower.{self._free_field}", self._free(), f"must be > 0 {self._unit}",
                             f"give a positive {self._free_field}"))
        return p

    @property
    def _unit(self) -> str:
        return self._free_field.rsplit("_", 1)[1]

    def _static(self, p: list[Problem]) -> bool:
        require_rotation(p, self.rotation)
        if not finite_fields(self, p, ("_mm", "_deg")) or p:
            return False
        p += [q for q in self.first_mechanism().validate() if q.path != "cam.rotation"]
        return not p

    def second_base_radius_mm(self, program) -> float:
        """Base radius R_b2 (mm) of the second cam for this follower distance/angle."""
        return self._second(program, lift_of(program), self._free())[1]

    def first_mechanism(self) -> Mechanism:  # pragma: no cover - abstract
        """Follower 1 as a single-follower mechanism."""
        raise NotImplementedError

    def _span(self, h: float) -> tuple[float, float]:  # pragma: no cover - abstract
        raise NotImplementedError

    def _second(self, program, h: float, q: float) -> tuple[Any, float, float]:  # pragma: no cover - abstract
        raise NotImplementedError

    def contacts(self, program: MotionLike) -> tuple[Contact, ...]:
        """(contact 1, contact 2) (no validation)."""
        return (self.first_mechanism().contacts(program)[0], self._second(program, lift_of(program), self._free())[0])

    def validate_motion(self, program, *, bore_mm: float | None = None) -> list[Problem]:
        """Follower 1's limits plus the enforced follower distance (angle) window."""
        p = self.first_mechanism().validate_motion(program)
        if p:
            return p
        h, q = lift_of(program), self._free()
        rmin = 0.5 * bore_mm if bore_mm else 0.0
        why = _margin(self, program, h, q, rmin, explain=True)
        if why is None:
            return p
        lo, hi = follower_limits(self, program, bore_mm=bore_mm)
        u, f = self._unit, self._free_field
        if not math.isfinite(lo):
            p.append(Problem(f"follower.{f}", q, f"no {f} gives a valid second cam ({why})",
                             "enlarge the base circle, reduce the lift or change the follower geometry"))
        else:
            rng = f"use {f} > {lo:.9g}" + (f" and < {hi:.9g}" if math.isfinite(hi) else "")
            rule = (f"below the minimum admissible value {lo:.9g} {u}" if q <= lo else
                    f"above the maximum admissible value {hi:.9g} {u}" if q >= hi else "not admissible")
            p.append(Problem(f"follower.{f}", q, f"{rule}: {why}", rng))
        return p


def _margin(mech: _Desmodromic, program, h: float, q: float, rmin: float, explain: bool = False,
            coarse: bool = False):
    """> 0 (mm) when the second cam is valid; with ``explain`` the reason it is not (or None).

    ``coarse`` takes the curvature extreme over dense samples only (an upper
    bound of the exact margin, for scanning)."""
    c, rb2, exist = mech._second(program, h, q)
    if exist <= 0:
        return ("the second follower cannot be placed opposite the first (it would reach or cross the line "
                "through the cam centre)") if explain else exist - 1.0  # strictly < 0: inadmissible
    out = [(rb2 - rmin, f"the second cam's base radius would be {rb2:.6g} mm"
            + (f", not above the bore radius {rmin:.6g} mm" if rmin else ", not > 0"))]
    edges = c.breakpoints
    flat = c.kind == "flat"
    f = (lambda t: c._inner.evaluate(t).rho) if flat else (lambda t: -c._inner.evaluate(t).curvature_pitch)
    if flat or c.roller_radius > 0:
        if coarse:
            xs = sorted_unique(np.r_[np.linspace(edges[0], edges[-1], 1441), edges])
            v = f(xs)
            i = int(np.argmin(v))
            x, val = xs[i], v[i]
        else:
            x, val = extremum(f, edges)
        if flat:
            out.append((val, f"the second profile would cusp or undercut (radius of curvature {val:.6g} mm at "
                             f"{math.degrees(x):.6g}°)"))
        elif val < 0:
            out.append((-1.0 / val - c.roller_radius,
                        f"the second pitch curve's convex radius {-1 / val:.6g} mm (at {math.degrees(x):.6g}°) would "
                        f"not exceed the roller radius {c.roller_radius:.6g} mm (cusp or undercut)"))
    if explain:
        bad = [w for v, w in out if not v > 0]
        return "; ".join(bad) if bad else None
    return min(v for v, _ in out)


def follower_limits(mechanism: _Desmodromic, program, *, bore_mm: float | None = None) -> tuple[float, float]:
    """Open interval of admissible follower distances (mm) or follower angles (degrees).

    The lower end is the minimum admissible follower distance (angle): below it
    the second cam's base radius reaches 0 (or ``bore_mm / 2``), its profile
    cusps or undercuts, or the second follower cannot exist.  The upper end is
    ``inf`` for translating followers.  ``(nan, nan)`` when none is admissible.
    Found by a scan and Brent's method on the margin (to ~1e-12 relative).
    """
    h = lift_of(program)
    rmin = 0.5 * bore_mm if bore_mm else 0.0
    g = lambda q: _margin(mechanism, program, h, q, rmin)  # noqa: E731
    gc = lambda q: _margin(mechanism, program, h, q, rmin, coarse=True)  # noqa: E731
    lo0, top = mechanism._span(h)
    if math.isinf(top):
        width = max(h, mechanism.base_radius_mm, 1.0)
        k = 0
        while g(lo0 + width) <= 0 and k < 60:
            width, k = 2 * width, k + 1
        grid = np.linspace(lo0, lo0 + width, 25)[1:]
    else:
        grid = np.linspace(lo0, top, 49)[1:-1]
    vals = np.array([gc(q) for q in grid])  # coarse >= exact: a coarse "bad" is bad
    i = next((j for j in np.flatnonzero(vals > 0) if g(grid[j]) > 0), None)
    if i is None:
        return math.nan, math.nan
    xt = 1e-12 * max(1.0, abs(grid[-1]))
    a = grid[i - 1] if i else lo0
    lo = brentq(g, a, grid[i], xtol=xt) if g(a) < 0 else a
    bad = np.flatnonzero(vals[i:] <= 0)
    hi = top
    if bad.size:
        j = i + int(bad[0])
        hi = brentq(g, grid[j - 1], grid[j], xtol=xt) if g(grid[j - 1]) > 0 else grid[j - 1]
    return float(lo), float(hi)


def minimum_follower_distance(mechanism: _Desmodromic, program, *, bore_mm: float | None = None) -> float:
    """Minimum admissible follower distance (mm) or follower angle (degrees); see :func:`follower_limits`."""
    return follower_limits(mechanism, program, bore_mm=bore_mm)[0]


def _second_roller_ok(mech, p: list[Problem]) -> bool:
    r = mech.second_roller_radius_mm
    if r is not None and (not isinstance(r, (int, float)) or not r >= 0 or not math.isfinite(r)):
        p.append(Problem("follower.second_roller_radius_mm", r, "must be a finite length >= 0 mm",
                         "give second_roller_radius_mm >= 0 (or omit it: same roller as follower 1)"))
        return False
    return True


# ---------------------------------------------------------------------------
@dataclass(frozen=True)
class ConjugateTranslatingFlat(_Desmodromic):
    """Conjugate pair, double translating flat follower.

    Parameters
    ----------
    base_radius_mm : float
        R_b1 of cam 1 (face 1 above the cam), > 0.
    follower_distance_mm : float
        Constant distance d between the two parallel faces (mm).  Cam 2's base
        radius is ``R_b2 = d − R_b1 − h``; ``d`` must exceed the minimum of
        :func:`minimum_follower_distance`.
    rotation : {"cw", "ccw"}
    """

    base_radius_mm: float
    follower_distance_mm: float
    rotation: str = "cw"
    follower: ClassVar[FollowerType] = FollowerType.FLAT
    required: ClassVar[tuple[str, ...]] = ("base_radius_mm", "follower_distance_mm")

    @classmethod
    def from_spec(cls, spec: Any) -> ConjugateTranslatingFlat:
        f = spec.follower
        return cls(f.base_radius_mm, f.follower_distance_mm, spec.cam.rotation)

    def first_mechanism(self) -> Mechanism:
        return TranslatingFlat(self.base_radius_mm, 0.0, self.rotation)

    def _span(self, h):
        return self.base_radius_mm + h, math.inf

    def _second(self, program, h, q):
        rb2 = q - self.base_radius_mm - h
        return SecondTranslatingFlatContact(ComplementMotion(program, h), rb2, 0.0, sense=self.sense), rb2, 1.0


@dataclass(frozen=True)
class ConjugateTranslatingRoller(_Desmodromic):
    """Conjugate pair, double translating roller follower.

    Parameters
    ----------
    base_radius_mm, roller_radius_mm : float
        R_b1 (> 0) and R_r1 (>= 0) of follower 1 (above the cam).
    follower_distance_mm : float
        Constant roller-centre distance d (mm; CAM-DAS "distance between
        followers", ``d_c = 2R_p + S_max`` for equal cams).
    second_roller_radius_mm : float, optional
        R_r2 (default R_r1).
    offset_mm : float
        Common follower-axis offset ε (> 0 = right), |ε| < R_p1.
    rotation : {"cw", "ccw"}
    """

    base_radius_mm: float
    roller_radius_mm: float
    follower_distance_mm: float
    second_roller_radius_mm: float | None = None
    offset_mm: float = 0.0
    rotation: str = "cw"
    required: ClassVar[tuple[str, ...]] = ("base_radius_mm", "roller_radius_mm", "follower_distance_mm")
    optional: ClassVar[tuple[str, ...]] = ("second_roller_radius_mm", "offset_mm")

    @classmethod
    def from_spec(cls, spec: Any) -> ConjugateTranslatingRoller:
        f = spec.follower
        return cls(f.base_radius_mm, f.roller_radius_mm or 0.0, f.follower_distance_mm, f.second_roller_radius_mm,
                   f.offset_mm or 0.0, spec.cam.rotation)

    def first_mechanism(self) -> Mechanism:
        return TranslatingRoller(self.base_radius_mm, self.roller_radius_mm, self.offset_mm, self.rotation)

    def _d0(self):
        rp = self.base_radius_mm + self.roller_radius_mm
        return math.sqrt(max(rp * rp - self.offset_mm**2, 0.0))

    def _span(self, h):
        return self._d0() + h, math.inf

    def _static(self, p):
        return _second_roller_ok(self, p) and super()._static(p)

    def _second(self, program, h, q):
        a2 = q - self._d0() - h
        rp2 = math.hypot(a2, self.offset_mm)
        c = SecondTranslatingRollerContact(ComplementMotion(program, h), rp2, self.second_roller_mm, self.offset_mm,
                                           sense=self.sense) if a2 > 0 else None
        return c, rp2 - self.second_roller_mm, a2


@dataclass(frozen=True)
class ConjugateOscillatingFlat(_Desmodromic):
    """Conjugate pair, double oscillating flat follower.

    Parameters
    ----------
    base_radius_mm : float
        R_b1 (> 0); face 1 touches it at ξ₁₀ = arcsin((R_b1 − f)/m).
    pivot_distance_mm : float
        Cam centre → pivot m (> 0), pivot to the right.
    face_offset_mm : float
        Eccentricity f of both faces (distance from the pivot, CAM-DAS uses 0).
    follower_angle_deg : float
        Fixed angle β (degrees) at the pivot between face 1 and face 2 (face 2
        below the line of centres); bounded by :func:`follower_limits`.
    rotation : {"cw", "ccw"}
    """

    base_radius_mm: float
    pivot_distance_mm: float
    face_offset_mm: float
    follower_angle_deg: float
    rotation: str = "cw"
    follower: ClassVar[FollowerType] = FollowerType.FLAT
    motion: ClassVar[FollowerMotion] = FollowerMotion.OSCILLATING
    required: ClassVar[tuple[str, ...]] = ("base_radius_mm", "pivot_distance_mm", "follower_angle_deg")
    optional: ClassVar[tuple[str, ...]] = ("face_offset_mm",)
    _free_field = "follower_angle_deg"

    @classmethod
    def from_spec(cls, spec: Any) -> ConjugateOscillatingFlat:
        f = spec.follower
        return cls(f.base_radius_mm, f.pivot_distance_mm, f.face_offset_mm or 0.0, f.follower_angle_deg,
                   spec.cam.rotation)

    def first_mechanism(self) -> Mechanism:
        return OscillatingFlat(self.base_radius_mm, self.pivot_distance_mm, self.face_offset_mm, self.rotation)

    def _span(self, h):
        x = self.initial_arm_angle
        return math.degrees(x - math.pi / 2) + h, math.degrees(x + math.pi / 2)

    def _second(self, program, h, q):
        xi = _K * q - self.initial_arm_angle - _K * h
        exist = min(xi + math.pi / 2, math.pi / 2 - xi - _K * h)
        c = SecondOscillatingFlatContact(ComplementMotion(program, h), self.pivot_distance_mm, self.face_offset_mm,
                                         xi, sense=self.sense)
        return c, self.face_offset_mm + self.pivot_distance_mm * math.sin(xi), exist


@dataclass(frozen=True)
class ConjugateOscillatingRoller(_Desmodromic):
    """Conjugate pair, double oscillating roller follower (the second cam derived in the module notes).

    Two arms of length A on one pivot at a fixed angle β; arm 2 below the line
    of centres; cam 2 is the envelope of roller 2.

    Parameters
    ----------
    base_radius_mm, roller_radius_mm : float
        R_b1 (> 0), R_r1 (>= 0) of follower 1.
    pivot_distance_mm, arm_length_mm : float
        m and A, as :class:`~camfab.design.rollers.OscillatingRoller`.
    follower_angle_deg : float
        β (degrees) between the two arms; bounded by :func:`follower_limits`.
    second_roller_radius_mm : float, optional
        R_r2 (default R_r1), < A.
    rotation : {"cw", "ccw"}
    """

    base_radius_mm: float
    roller_radius_mm: float
    pivot_distance_mm: float
    arm_length_mm: float
    follower_angle_deg: float
    second_roller_radius_mm: float | None = None
    rotation: str = "cw"
    motion: ClassVar[FollowerMotion] = FollowerMotion.OSCILLATING
    required: ClassVar[tuple[str, ...]] = ("base_radius_mm", "roller_radius_mm", "pivot_distance_mm",
                                           "arm_length_mm", "follower_angle_deg")
    optional: ClassVar[tuple[str, ...]] = ("second_roller_radius_mm",)
    _free_field = "follower_angle_deg"

    @classmethod
    def from_spec(cls, spec: Any) -> ConjugateOscillatingRoller:
        f = spec.follower
        return cls(f.base_radius_mm, f.roller_radius_mm or 0.0, f.pivot_distance_mm, f.arm_length_mm,
                   f.follower_angle_deg, f.second_roller_radius_mm, spec.cam.rotation)

    def first_mechanism(self) -> Mechanism:
        return OscillatingRoller(self.base_radius_mm, self.roller_radius_mm, self.pivot_distance_mm,
                                 self.arm_length_mm, self.rotation)

    def _static(self, p):
        if not (_second_roller_ok(self, p) and super()._static(p)):
            return False
        if self.second_roller_mm >= self.arm_length_mm:
            p.append(Problem("follower.second_roller_radius_mm", self.second_roller_mm,
                             f"the arm must be longer than the second roller ({self.arm_length_mm:.6g} mm)",
                             "use a smaller second roller"))
        return not p

    def _span(self, h):
        x = self.initial_arm_angle
        return math.degrees(x) + h, math.degrees(x + math.pi)

    def _second(self, program, h, q):
        xi = _K * q - self.initial_arm_angle - _K * h
        a, m = self.arm_length_mm, self.pivot_distance_mm
        exist = min(xi, math.pi - xi - _K * h)
        rp2 = math.sqrt(max(a * a + m * m - 2 * a * m * math.cos(xi), 0.0))
        c = SecondOscillatingRollerContact(ComplementMotion(program, h), m, a, xi, self.second_roller_mm,
                                           sense=self.sense) if exist > 0 else None
        return c, rp2 - self.second_roller_mm, exist
