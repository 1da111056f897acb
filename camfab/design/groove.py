"""Groove (track) cams on a disc: one roller running in a face groove, driven both ways by its two flanks.

Conventions and derivation
--------------------------
The **pitch curve** C(φ) is the roller-centre path of the ordinary roller follower (translating with offset,
or oscillating on an arm; :mod:`camfab.design.rollers`), with ``n`` its outward unit normal (away from the cam
centre side of the curve).  With the roller radius R_r and the backlash b (the groove is b wider than the
roller) the half-width of the groove is ``w = R_r + b/2`` and the flanks are the exact parallel curves::

    inner flank  P_i = C − w·n          (nearer the cam centre; the usual cam profile)
    outer flank  P_o = C + w·n

so the normal distance between the flanks is ``2w = 2R_r + b`` everywhere (both lie on the same normal line
of the pitch curve).  ``base_radius_mm`` is the smallest radius of the inner flank (as for a plain roller cam):
the pitch curve's prime radius is ``R_b + w``.  The pitch curve is the groove's centre line; a roller of
radius R_r touching one flank has its centre b/2 off it, on the same normal.

**Which flank drives.**  The inner flank pushes the roller outward (the direction S increases: a rise), the
outer flank pushes it back toward the cam centre (a return).  Which one carries the load at a moment is the
sign of the follower force (inertia plus load): with inertia alone the inner flank while S″ > 0 and the outer
while S″ < 0.  The checks judge *both flanks over the whole cycle* (conservative).

**Each flank as a contact.**  The inner flank is the ordinary roller contact with radius w.  The outer flank
is the same formulas with radius −w, seen from the groove: its normal points into the groove (``−n``, away
from its material, as every contact's normal does), and its curvature, pitch curvature and radii change sign
(positive = convex *seen from the roller*).  So where the pitch curve is convex, the outer flank is concave
with radius ρ_p + w; where the pitch curve is concave with radius |ρ_p| < w, the outer flank undercuts (the
ordinary undercut rule with the pitch curvature −κ_p).  The line of force is the common normal through the
roller centre, the same line for both flanks: the outer flank's pressure angle, measured from the return
velocity to its (flipped) normal, equals the inner flank's.  The tangent stays the true direction of travel
(``point_d1`` is the true derivative), as for the second cam of a conjugate pair.

Every check, export and the milling read the two flanks as :class:`~camfab.design.profile.Contact` values
(``label`` "inner flank" / "outer flank"); :class:`GrooveGeometry` adds the groove's own measures.  A
cylindrical cam's groove can reuse :func:`flank_contacts` on its developed pitch curve.
"""
from __future__ import annotations

from typing import Any, ClassVar

import numpy as np

from ..errors import Problem
from ..records import dataclass, replace
from .kinds import CamKind, FollowerMotion
from .mechanism import Mechanism, finite_fields, require_non_negative, require_positive
from .profile import CamGeometry, Contact, MotionLike, ProfileSample
from .rollers import OscillatingRoller, OscillatingRollerContact, TranslatingRoller, TranslatingRollerContact

__all__ = ["GrooveTranslatingRoller", "GrooveOscillatingRoller", "GrooveGeometry", "OuterTranslatingFlank",
           "OuterOscillatingFlank", "outer_sample", "INNER", "OUTER"]

#: the flanks' labels (the checks' findings and the files name them)
INNER, OUTER = "inner flank", "outer flank"


def outer_sample(s: ProfileSample) -> ProfileSample:
    """The outer flank's sample from the formulas evaluated with the radius −w: normal into the groove,
    curvatures and radii seen from the roller (signs flipped); points, derivative, tangent and pressure angle
    unchanged."""
    neg = lambda v: None if v is None else -v  # noqa: E731
    return replace(s, normal=-s.normal, curvature=-s.curvature, rho=-s.rho, curvature_pitch=neg(s.curvature_pitch),
                   rho_pitch=neg(s.rho_pitch))


class _Outer:
    """Mixin: the outer flank of the plain roller contact ``_plain`` built with the same arguments (its
    ``roller_radius`` is the groove half-width w > 0; the formulas run with −w)."""

    _plain: type
    label = OUTER

    def __init__(self, *args: Any, sense: int = 1):
        super().__init__(*args, sense=sense)  # type: ignore[call-arg]
        self._formula = self._plain(*args, sense=sense)
        self._formula.roller_radius = -self.roller_radius  # type: ignore[attr-defined]

    def _evaluate(self, phi, rotate: bool, S=None) -> ProfileSample:
        return outer_sample(self._formula._evaluate(phi, rotate, S))


class InnerTranslatingFlank(TranslatingRollerContact):
    """Inner flank of a groove with a translating roller (the plain contact of radius w)."""

    label = INNER


class OuterTranslatingFlank(_Outer, TranslatingRollerContact):
    """Outer flank of a groove with a translating roller (arguments of :class:`TranslatingRollerContact`)."""

    _plain = TranslatingRollerContact


class InnerOscillatingFlank(OscillatingRollerContact):
    """Inner flank of a groove with an oscillating roller."""

    label = INNER


class OuterOscillatingFlank(_Outer, OscillatingRollerContact):
    """Outer flank of a groove with an oscillating roller (arguments of :class:`OscillatingRollerContact`)."""

    _plain = OscillatingRollerContact


class GrooveGeometry(CamGeometry):
    """A groove cam's geometry: profile 0 the inner flank, profile 1 the outer flank (one pitch curve)."""

    form_closed: ClassVar[bool] = True
    flank_pair: ClassVar[bool] = True

    @property
    def half_width_mm(self) -> float:
        """w = R_r + b/2: the distance of each flank from the pitch curve (mm)."""
        return float(self.mechanism.half_width_mm)

    def flank_distance(self, phi) -> np.ndarray:
        """Distance between the inner and outer flank points at φ (mm; 2·R_r + b by construction)."""
        a, b = self.evaluate(phi, 0), self.evaluate(phi, 1)
        return np.hypot(*(b.point - a.point).T)

    @property
    def outer_radius_mm(self) -> float:
        """Largest radius of the outer flank (mm)."""
        return self.radius_extremes(1).max


class _Groove(Mechanism):
    """Shared validation of the groove families: roller > 0, backlash >= 0, groove depth > 0."""

    cam_kind: ClassVar[CamKind] = CamKind.GROOVE
    geometry_class: ClassVar[type[CamGeometry]] = GrooveGeometry
    roller_radius_mm: float
    backlash_mm: float
    groove_depth_mm: float

    @property
    def half_width_mm(self) -> float:
        """w = R_r + b/2 (mm)."""
        return self.roller_radius_mm + 0.5 * self.backlash_mm

    def groove_problems(self, p: list[Problem]) -> bool:
        if not finite_fields(self, p):
            return False
        require_positive(p, "roller_radius_mm", self.roller_radius_mm, "> 0 mm (a groove needs a roller)")
        require_non_negative(p, "backlash_mm", self.backlash_mm)
        require_positive(p, "groove_depth_mm", self.groove_depth_mm)
        return not p

    def plain(self) -> Mechanism:  # pragma: no cover - abstract
        """The roller mechanism whose profile is the inner flank (roller radius w)."""
        raise NotImplementedError

    def validate(self) -> list[Problem]:
        p: list[Problem] = []
        if self.groove_problems(p):
            p += self.plain().validate()
        return p

    def validate_motion(self, program: MotionLike, *, bore_mm: float | None = None) -> list[Problem]:
        return self.plain().validate_motion(program, bore_mm=bore_mm)


@dataclass(frozen=True)
class GrooveTranslatingRoller(_Groove):
    """Face-groove cam with a translating roller follower.

    Parameters
    ----------
    base_radius_mm : float
        Smallest radius of the inner flank R_b (> 0); the pitch curve's prime radius is R_b + R_r + b/2.
    roller_radius_mm : float
        Roller radius R_r (> 0).
    groove_depth_mm : float
        Depth of the groove in the plate (> 0, < ``[manufacturing] thickness_mm``).
    backlash_mm : float
        b >= 0: the groove is 2·R_r + b wide (default 0).
    offset_mm : float
        Follower-axis offset e, as :class:`~camfab.design.rollers.TranslatingRoller`.
    rotation : {"cw", "ccw"}
    """

    base_radius_mm: float
    roller_radius_mm: float
    groove_depth_mm: float
    backlash_mm: float = 0.0
    offset_mm: float = 0.0
    rotation: str = "cw"
    required: ClassVar[tuple[str, ...]] = ("base_radius_mm", "roller_radius_mm", "groove_depth_mm")
    optional: ClassVar[tuple[str, ...]] = ("backlash_mm", "offset_mm")

    @classmethod
    def from_spec(cls, spec: Any) -> GrooveTranslatingRoller:
        f = spec.follower
        return cls(f.base_radius_mm, f.roller_radius_mm or 0.0, f.groove_depth_mm, f.backlash_mm or 0.0,
                   f.offset_mm or 0.0, spec.cam.rotation)

    def plain(self) -> TranslatingRoller:
        return TranslatingRoller(self.base_radius_mm, self.half_width_mm, self.offset_mm, self.rotation)

    @property
    def prime_radius_mm(self) -> float:
        return self.base_radius_mm + self.half_width_mm

    def contacts(self, program: MotionLike) -> tuple[Contact, ...]:
        args = (program, self.prime_radius_mm, self.half_width_mm, self.offset_mm)
        return InnerTranslatingFlank(*args, sense=self.sense), OuterTranslatingFlank(*args, sense=self.sense)


@dataclass(frozen=True)
class GrooveOscillatingRoller(_Groove):
    """Face-groove cam with an oscillating roller follower (arm as
    :class:`~camfab.design.rollers.OscillatingRoller`, with the prime radius R_b + R_r + b/2).

    Parameters
    ----------
    base_radius_mm, roller_radius_mm, groove_depth_mm, backlash_mm : float
        As :class:`GrooveTranslatingRoller`.
    pivot_distance_mm, arm_length_mm : float
        Cam centre → pivot m, pivot → roller centre A.
    rotation : {"cw", "ccw"}
    """

    base_radius_mm: float
    roller_radius_mm: float
    pivot_distance_mm: float
    arm_length_mm: float
    groove_depth_mm: float
    backlash_mm: float = 0.0
    rotation: str = "cw"
    motion: ClassVar[FollowerMotion] = FollowerMotion.OSCILLATING
    required: ClassVar[tuple[str, ...]] = ("base_radius_mm", "roller_radius_mm", "pivot_distance_mm",
                                           "arm_length_mm", "groove_depth_mm")
    optional: ClassVar[tuple[str, ...]] = ("backlash_mm",)

    @classmethod
    def from_spec(cls, spec: Any) -> GrooveOscillatingRoller:
        f = spec.follower
        return cls(f.base_radius_mm, f.roller_radius_mm or 0.0, f.pivot_distance_mm, f.arm_length_mm,
                   f.groove_depth_mm, f.backlash_mm or 0.0, spec.cam.rotation)

    def plain(self) -> OscillatingRoller:
        return OscillatingRoller(self.base_radius_mm, self.half_width_mm, self.pivot_distance_mm,
                                 self.arm_length_mm, self.rotation)

    @property
    def prime_radius_mm(self) -> float:
        return self.base_radius_mm + self.half_width_mm

    @property
    def initial_arm_angle(self) -> float:
        """ξ₀ (radians), as :attr:`OscillatingRoller.initial_arm_angle` on the prime radius R_b + w."""
        return self.plain().initial_arm_angle

    def contacts(self, program: MotionLike) -> tuple[Contact, ...]:
        args = (program, self.pivot_distance_mm, self.arm_length_mm, self.initial_arm_angle, self.half_width_mm)
        return InnerOscillatingFlank(*args, sense=self.sense), OuterOscillatingFlank(*args, sense=self.sense)
