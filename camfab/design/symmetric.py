"""Constant-width and constant-diameter cams: one profile touched by both followers of a rigid yoke.

Both followers touch the same profile, at φ and φ + π, so the law must satisfy ``S(θ) + S(θ + π) = h``: camfab
uses an SHM rise over ``rise_deg``, a dwell, an SHM return over ``rise_deg`` and a dwell (default 120°).

* Constant width (double flat yoke): ``width_mm`` is the distance between the parallel faces, exactly
  constant; lift ``h = W − 2R_b``.
* Constant diameter (double roller, offset 0): the user gives CAM-DAS's width ``W = 2R_b + h`` (the
  contact-point distance at the dwells); the *exactly* constant distance is the roller-centre distance
  ``W + 2R_r = 2R_p + h`` — the contact-point distance varies where S′ ≠ 0 (``docs/decisions.md``,
  "constant diameter").
"""
from __future__ import annotations

import math
from typing import Any, ClassVar

import numpy as np

from ..errors import Problem
from ..records import dataclass
from .conjugate import FormClosed
from .faces import TranslatingFlatContact
from .kinds import CamKind, FollowerType
from .mechanism import finite_fields, require_positive, require_rotation
from .profile import Contact, MotionLike
from .program import MotionProgram
from .rollers import TranslatingRollerContact

__all__ = ["ConstantWidthCam", "ConstantDiameterCam"]


# ---------------------------------------------------------------------------
class _Symmetric(FormClosed):
    """Constant-width / constant-diameter cam: one profile, S(θ) + S(θ + π) = h."""

    # fields of both families (declared by each subclass's dataclass; annotations only here: this base is
    # not a dataclass, so they add no fields)
    base_radius_mm: float
    width_mm: float
    rise_deg: float
    rotation: str

    def validate(self) -> list[Problem]:
        p: list[Problem] = []
        require_rotation(p, self.rotation)
        if not finite_fields(self, p):
            return p
        require_positive(p, "base_radius_mm", self.base_radius_mm)
        rb2 = 2 * self.base_radius_mm
        if self.width_mm <= rb2:
            p.append(Problem("follower.width_mm", self.width_mm,
                             f"the width must exceed the base diameter 2·R_b = {rb2:.6g} mm (lift = width − 2·R_b)",
                             f"use width_mm > {rb2:.6g}, or a smaller base circle"))
        r = self.rise_deg
        if not isinstance(r, (int, float)) or not 0.0 < r <= 180.0:
            p.append(Problem("follower.rise_deg", r, "the rise (and return) must span more than 0° and at most 180°",
                             "use rise_deg in (0, 180]; 120 is the CAM-DAS law"))
        if not p and (rr := getattr(self, "roller_radius_mm", 0.0)) < 0:
            p.append(Problem("follower.roller_radius_mm", rr, "must be >= 0 mm",
                             "give roller_radius_mm >= 0"))
        if not p and (offset := getattr(self, "offset_mm", 0.0)) != 0:
            p.append(Problem("follower.offset_mm", offset,
                             "a constant-diameter cam needs offset 0: with an offset the lower roller would need a "
                             "second, different profile", "set offset_mm = 0, or use ConjugateTranslatingRoller"))
        return p

    @property
    def lift_mm(self) -> float:
        """h = width − 2·R_b (mm)."""
        return self.width_mm - 2 * self.base_radius_mm

    def default_program(self) -> MotionProgram:
        """The fixed law: SHM rise h over rise_deg, dwell, SHM return over rise_deg, dwell."""
        h, r = self.lift_mm, float(self.rise_deg)
        dwell = [("dwell", 0.0, 180.0 - r)] if r < 180.0 else []
        return MotionProgram.from_segments([("simple_harmonic", h, r), *dwell, ("simple_harmonic", -h, r), *dwell])

    def validate_motion(self, program: MotionLike, *, bore_mm: float | None = None) -> list[Problem]:
        """Enforce S(θ) + S(θ + π) = h with min S = 0 and h = width − 2·R_b (to 1e-9 mm)."""
        p = super().validate_motion(program)
        if p:
            return p
        x = np.linspace(0.0, math.pi, 20001)
        s = program.evaluate(np.r_[x, x + math.pi], (0,))[0]
        tol = 1e-9 * max(1.0, self.lift_mm)
        err = np.abs(s[: x.size] + s[x.size:] - self.lift_mm).max()
        if err > tol or abs(s.min()) > tol:
            p.append(Problem("motion", round(float(err), 12),
                             f"a constant-width/diameter cam needs S(θ) + S(θ+180°) = h = width − 2·R_b = "
                             f"{self.lift_mm:.6g} mm with min S = 0",
                             "use the built-in law (omit the program) or make the return the mirror of the rise"))
        return p


@dataclass(frozen=True)
class ConstantWidthCam(_Symmetric):
    """Constant-width cam with a double translating flat follower.

    Parameters
    ----------
    base_radius_mm : float
        R_b (> 0).
    width_mm : float
        Distance W between the two parallel faces (> 2·R_b), exactly constant:
        the cam's width between parallel tangents.  Lift h = W − 2·R_b.
    rise_deg : float
        SHM rise (and return) span in degrees, in (0, 180] (dwells of 180 − rise).
    rotation : {"cw", "ccw"}
    """

    base_radius_mm: float
    width_mm: float
    rise_deg: float = 120.0
    rotation: str = "cw"
    cam_kind: ClassVar[CamKind] = CamKind.CONSTANT_WIDTH
    follower: ClassVar[FollowerType] = FollowerType.FLAT
    required: ClassVar[tuple[str, ...]] = ("base_radius_mm", "width_mm")
    optional: ClassVar[tuple[str, ...]] = ("rise_deg",)

    @classmethod
    def from_spec(cls, spec: Any) -> ConstantWidthCam:
        f = spec.follower
        return cls(f.base_radius_mm, f.width_mm, f.rise_deg or 120.0, spec.cam.rotation)

    @property
    def constant_distance_mm(self) -> float:
        """The exactly constant distance: face gap W (mm)."""
        return self.width_mm

    def contacts(self, program: MotionLike) -> tuple[Contact, ...]:
        return (TranslatingFlatContact(program, self.base_radius_mm, 0.0, self.sense),)


@dataclass(frozen=True)
class ConstantDiameterCam(_Symmetric):
    """Constant-diameter cam with a double translating roller follower.

    Parameters
    ----------
    base_radius_mm, roller_radius_mm : float
        R_b (> 0) and R_r (>= 0).
    width_mm : float
        CAM-DAS "constant width" W = 2·R_b + h (> 2·R_b): the contact-point
        distance at the dwells.  The exactly constant distance is the
        roller-centre distance ``W + 2·R_r`` (:attr:`constant_distance_mm`).
    rise_deg : float
        As :class:`ConstantWidthCam`.
    offset_mm : float
        Must be 0: with an offset the lower roller meets a different curve.
    rotation : {"cw", "ccw"}
    """

    base_radius_mm: float
    roller_radius_mm: float
    width_mm: float
    rise_deg: float = 120.0
    offset_mm: float = 0.0
    rotation: str = "cw"
    cam_kind: ClassVar[CamKind] = CamKind.CONSTANT_DIAMETER
    required: ClassVar[tuple[str, ...]] = ("base_radius_mm", "roller_radius_mm", "width_mm")
    optional: ClassVar[tuple[str, ...]] = ("rise_deg", "offset_mm")

    @classmethod
    def from_spec(cls, spec: Any) -> ConstantDiameterCam:
        f = spec.follower
        return cls(f.base_radius_mm, f.roller_radius_mm or 0.0, f.width_mm, f.rise_deg or 120.0, f.offset_mm or 0.0,
                   spec.cam.rotation)

    @property
    def constant_distance_mm(self) -> float:
        """Roller-centre distance 2·R_p + h = W + 2·R_r (mm), exactly constant."""
        return self.width_mm + 2 * self.roller_radius_mm

    def contacts(self, program: MotionLike) -> tuple[Contact, ...]:
        rp = self.base_radius_mm + self.roller_radius_mm
        return (TranslatingRollerContact(program, rp, self.roller_radius_mm, 0.0, self.sense),)
