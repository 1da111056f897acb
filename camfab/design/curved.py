"""Curved-face followers (valve trains): the translating mushroom and the oscillating finger follower.

The follower touches the cam with a convex circular face of radius R (``face_radius_mm``).  The contact
normal of a circle passes through its centre, so the face touches the cam **exactly as a roller of radius R
centred at the face's centre of curvature C**: the profile is the parallel curve at distance R of the path of
C, and the pitch curve, curvatures and undercut limits are the roller's (tested).  What differs from a roller:
the face slides on the cam (friction applies in the dynamics), the contact runs along the face (its position is
reported and checked like a flat face's), and for the oscillating follower the pressure angle is measured, as
for every sliding face, against the velocity of the follower's material point at the contact.

* **Translating (mushroom)**: stem axis at x = e (``offset_mm``, + = right of the cam centre), C on the axis,
  the face touching the base circle at S = 0: ``C = (e, √((R_b + R)² − e²) + S)``; needs |e| < R_b + R.
  Contact position: the signed horizontal distance of the contact from the stem axis, ``−R·n_x``, + to the
  right.  The pressure angle is the roller's (the stem moves along its axis).
* **Oscillating (finger)**: pivot at (m, 0) right of the cam centre, as the flat-face follower: face angle
  ξ = ξ₀ + S (S in degrees, + = clockwise), face normal n(ξ) = (sin ξ, cos ξ) at its vertex V, the pivot at
  the signed distance f (``face_offset_mm``) from the face's tangent line at V.  The centre of curvature is
  rigid on the arm: ``C = pivot + (f + R)·n(ξ)`` — an arm of length A = f + R (> 0) at the angle ξ + 90° from
  the line to the cam centre.  At S = 0 the face touches the base circle, |C| = R_b + R:
  ``sin ξ₀ = ((R_b + R)² − m² − A²)/(2·m·A)``, which needs |A − m| < R_b + R < A + m.  Contact position:
  the arc length R·ψ from V along the face, ψ the angle from the contact normal to n(ξ) — signed as the flat
  face's ``(P − V)·J·n(ξ)``, which it equals to first order.  The pad is the part of the circle that arc
  spans; a realistic finger places C above the cam (f = √(m² + (R_b + R)²) − R), so the contact runs well
  away from V.

**The flat face is the limit R → ∞** (f, e fixed): C recedes to infinity, the circle near the contact tends
to the face line (sag d²/2R), ξ₀ → arcsin((R_b − f)/m), and the profile, contact position and pressure angle
tend to the flat face's (tested against :mod:`camfab.design.faces`).
"""
from __future__ import annotations

import math
from typing import Any, ClassVar

import numpy as np

from ..errors import Problem
from ..records import dataclass
from .kinds import FollowerMotion, FollowerType
from .mechanism import Mechanism, finite_fields, lift_range, require_positive, require_rotation
from .profile import DEG, Contact, MotionLike
from .rollers import OscillatingRollerContact, TranslatingRollerContact

__all__ = ["TranslatingCurvedContact", "OscillatingCurvedContact", "TranslatingCurved", "OscillatingCurved"]


class TranslatingCurvedContact(TranslatingRollerContact):
    """Mushroom follower: a roller of radius R centred at the face's centre of curvature, sliding."""

    has_face = True

    def _face_position(self, cx, cy, nx, ny, xi) -> np.ndarray:
        return -self.roller_radius * nx


class OscillatingCurvedContact(OscillatingRollerContact):
    """Finger follower: a roller of radius R on an arm A = f + R at ξ + 90°, sliding.

    Parameters
    ----------
    pivot_distance, face_offset, face_radius : float
        m, f and R (mm).
    initial_face_angle : float
        ξ₀ (radians).
    """

    has_face = True

    def __init__(self, motion: MotionLike, pivot_distance: float, face_offset: float, face_radius: float,
                 initial_face_angle: float, sense: int = 1):
        super().__init__(motion, pivot_distance, face_offset + face_radius, initial_face_angle + math.pi / 2,
                         face_radius, sense)
        self.f = float(face_offset)

    def _components(self, S):
        *path, zeta = super()._components(S)
        return (*path, zeta - math.pi / 2)  # the arm angle reported is the face angle ξ, as for flat faces

    def _face_position(self, cx, cy, nx, ny, xi) -> np.ndarray:
        # the arc length R·ψ from the vertex V, ψ the angle from the contact normal n to n(ξ) = (C − pivot)/A:
        # sin ψ = n × n(ξ) = (n_x·C_y − n_y·(C_x − m))/A, cos ψ = n·n(ξ)
        dx = cx - self.m
        return self.roller_radius * np.arctan2(nx * cy - ny * dx, nx * dx + ny * cy)

    def _force_velocity(self, cx, cy, nx, ny, vx, vy):
        # the follower's material point at the contact P = C − R·n turns clockwise about the pivot
        rx = cx - self.roller_radius * nx - self.m
        ry = cy - self.roller_radius * ny
        d = np.hypot(rx, ry)
        return ry / d, -rx / d


# ---------------------------------------------------------------------------
@dataclass(frozen=True)
class TranslatingCurved(Mechanism):
    """Disc cam with a translating curved-face (mushroom) follower.

    Parameters
    ----------
    base_radius_mm : float
        R_b (> 0): the face touches the base circle at S = 0.
    face_radius_mm : float
        R (> 0), the radius of the convex face.
    offset_mm : float
        Stem-axis offset e (> 0 = right); |e| < R_b + R.
    rotation : {"cw", "ccw"}
    """

    base_radius_mm: float
    face_radius_mm: float
    offset_mm: float = 0.0
    rotation: str = "cw"
    follower: ClassVar[FollowerType] = FollowerType.CURVED
    required: ClassVar[tuple[str, ...]] = ("base_radius_mm", "face_radius_mm")
    optional: ClassVar[tuple[str, ...]] = ("offset_mm",)

    @classmethod
    def from_spec(cls, spec: Any) -> TranslatingCurved:
        f = spec.follower
        return cls(f.base_radius_mm, f.face_radius_mm, f.offset_mm or 0.0, spec.cam.rotation)

    @property
    def prime_radius_mm(self) -> float:
        """Distance of the face's centre of curvature from the cam centre at S = 0 when e = 0: R_b + R."""
        return self.base_radius_mm + self.face_radius_mm

    def validate(self) -> list[Problem]:
        p: list[Problem] = []
        require_rotation(p, self.rotation)
        if not finite_fields(self, p):
            return p
        require_positive(p, "base_radius_mm", self.base_radius_mm)
        require_positive(p, "face_radius_mm", self.face_radius_mm)
        rp = self.prime_radius_mm
        if not p and abs(self.offset_mm) >= rp:
            p.append(Problem("follower.offset_mm", self.offset_mm,
                             f"|offset| must be smaller than R_b + face radius = {rp:.6g} mm",
                             f"use |offset_mm| < {rp:.6g}, or enlarge the base circle"))
        return p

    def contacts(self, program: MotionLike) -> tuple[Contact, ...]:
        return (TranslatingCurvedContact(program, self.prime_radius_mm, self.face_radius_mm, self.offset_mm,
                                         self.sense),)


@dataclass(frozen=True)
class OscillatingCurved(Mechanism):
    """Disc cam with an oscillating curved-face (finger) follower.

    Parameters
    ----------
    base_radius_mm : float
        R_b (> 0): the face touches the base circle at S = 0.
    face_radius_mm : float
        R (> 0), the radius of the convex face.
    pivot_distance_mm : float
        Cam centre → pivot distance m (> 0), pivot to the right.
    face_offset_mm : float
        f: the signed distance from the pivot to the face's tangent at its vertex (as for the flat face);
        the centre of curvature lies at f + R (> 0) from the pivot.
    rotation : {"cw", "ccw"}
    """

    base_radius_mm: float
    face_radius_mm: float
    pivot_distance_mm: float
    face_offset_mm: float = 0.0
    rotation: str = "cw"
    follower: ClassVar[FollowerType] = FollowerType.CURVED
    motion: ClassVar[FollowerMotion] = FollowerMotion.OSCILLATING
    required: ClassVar[tuple[str, ...]] = ("base_radius_mm", "face_radius_mm", "pivot_distance_mm")
    optional: ClassVar[tuple[str, ...]] = ("face_offset_mm",)

    @classmethod
    def from_spec(cls, spec: Any) -> OscillatingCurved:
        f = spec.follower
        return cls(f.base_radius_mm, f.face_radius_mm, f.pivot_distance_mm, f.face_offset_mm or 0.0,
                   spec.cam.rotation)

    @property
    def arm_length_mm(self) -> float:
        """A = f + R: pivot → the face's centre of curvature (mm)."""
        return self.face_offset_mm + self.face_radius_mm

    @property
    def initial_arm_angle(self) -> float:
        """ξ₀ (radians), the face angle at S = 0: sin ξ₀ = ((R_b + R)² − m² − A²)/(2·m·A)."""
        rp, m, a = self.base_radius_mm + self.face_radius_mm, self.pivot_distance_mm, self.arm_length_mm
        return math.asin(max(-1.0, min(1.0, (rp * rp - m * m - a * a) / (2 * m * a))))

    def validate(self) -> list[Problem]:
        p: list[Problem] = []
        require_rotation(p, self.rotation)
        if not finite_fields(self, p):
            return p
        for name in ("base_radius_mm", "face_radius_mm", "pivot_distance_mm"):
            require_positive(p, name, getattr(self, name))
        if p:
            return p
        a, m, rp = self.arm_length_mm, self.pivot_distance_mm, self.base_radius_mm + self.face_radius_mm
        if a <= 0:
            p.append(Problem("follower.face_offset_mm", self.face_offset_mm,
                             f"the face's centre of curvature must lie beyond the pivot: face_offset_mm + "
                             f"face_radius_mm = {a:.6g} mm must be > 0",
                             f"use face_offset_mm > {-self.face_radius_mm:.6g}"))
        elif not abs(a - m) < rp < a + m:
            p.append(Problem("follower.pivot_distance_mm", m,
                             f"the face cannot touch the base circle: need |A - m| < R_b + R < A + m with "
                             f"A = face_offset_mm + face_radius_mm = {a:.6g} mm and R_b + R = {rp:.6g} mm",
                             f"choose pivot_distance_mm in ({abs(a - rp):.6g}, {a + rp:.6g})"))
        return p

    def validate_motion(self, program: MotionLike, *, bore_mm: float | None = None) -> list[Problem]:
        p = super().validate_motion(program)
        if p:
            return p
        xi0 = self.initial_arm_angle
        smin, smax = lift_range(program, 0)
        lo, hi = xi0 + DEG * smin, xi0 + DEG * smax
        if lo <= -math.pi / 2 or hi >= math.pi / 2:
            p.append(Problem("motion[*].lift", round(smax, 12),
                             f"the face would turn to {math.degrees(hi):.6g}° (from ξ0 = {math.degrees(xi0):.6g}°), "
                             "past perpendicular to the line of centres",
                             f"keep the total lift below {90.0 - math.degrees(xi0):.6g}°"))
        return p

    def contacts(self, program: MotionLike) -> tuple[Contact, ...]:
        return (OscillatingCurvedContact(program, self.pivot_distance_mm, self.face_offset_mm, self.face_radius_mm,
                                         self.initial_arm_angle, self.sense),)
