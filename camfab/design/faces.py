"""Flat-face followers on disc cams: translating (a stem with a face) and oscillating (a face on an arm).

A flat face with unit normal angle β(φ) and distance p(φ) from the cam centre (fixed frame) envelopes the
profile ``P = p·n + s·J·n`` with ``s = p′/(σ + β′)`` and radius of curvature
``ρ = p + p″/(σ+β′)² − p′β″/(σ+β′)³`` (see :mod:`camfab.design.profile` for σ and J).

* Translating face: normal +Y, p = R_b + S, so ρ = R_b + S + S″; the stem offset changes only the forces and
  the face length needed each side of the stem.  Contact position: the signed distance from the stem axis
  along the face, + to the right (a cw cam touches the left side, −S′, while rising).
* Oscillating face: pivot at (m, 0); face angle ξ = ξ₀ + S (S in degrees, + = clockwise), normal
  (sin ξ, cos ξ), distance from the cam centre p = f + m·sin ξ, where f is the signed distance from the pivot
  to the face line (the face offset).  At S = 0 the face touches the base circle: ξ₀ = arcsin((R_b − f)/m)
  (an arcsine: the face is tangent to the circle, not aimed at its centre), which needs |R_b − f| < m.
  Contact position: the distance along the face from its vertex (the pivot's foot on the face),
  ``m·cos ξ + s``.
"""
from __future__ import annotations

import math
from typing import Any, ClassVar

import numpy as np

from ..errors import Problem
from ..records import dataclass
from .kinds import ContactKind, FollowerMotion, FollowerType
from .mechanism import Mechanism, finite_fields, lift_range, require_positive, require_rotation
from .profile import CHUNK, DEG, Contact, MotionLike, ProfileSample, block, rot_into
from .trig import cos_sin

__all__ = ["DiscFlatContact", "TranslatingFlatContact", "OscillatingFlatContact", "TranslatingFlat",
           "OscillatingFlat"]


class DiscFlatContact(Contact):
    """Generic flat face on a rotating cam.  Subclasses give, from S, S′, S″, the fixed-frame face normal
    angle β, β′, β″ and its distance p, p′, p″ from the cam centre (:meth:`_face`), and the follower's
    velocity direction, face position and arm angle (:meth:`_extras`)."""

    kind = ContactKind.FLAT
    has_face = True

    def _face(self, S: np.ndarray) -> tuple[Any, ...]:  # pragma: no cover - abstract
        raise NotImplementedError

    def _extras(self, px, py, s, S) -> tuple[Any, ...]:  # pragma: no cover - abstract
        """``(vx, vy, face position, arm angle)``: the follower's unit rise velocity at the contact point
        (px, py) (fixed frame), and the optional outputs (or None)."""
        raise NotImplementedError

    def _evaluate(self, phi, rotate: bool, S=None) -> ProfileSample:
        x, S = self._S(phi, S)
        n = x.size
        out = block(13, n)  # the last two rows are the face position and the arm angle, when given
        extra: dict[str, bool] = {}
        for a in range(0, max(n, 1), CHUNK):  # chunked as the rollers are
            b = min(a + CHUNK, n)
            self._fill(out, a, b, x[a:b], S[:, a:b], rotate, extra)
        point, point_d1, normal, tangent = out[0:2], out[2:4], out[4:6], out[6:8]
        k, rho, delta = out[8:11]
        pos = out[11] if extra.get("face") else None
        arm = out[12] if extra.get("arm") else None
        return ProfileSample(x, point.T, point_d1.T, normal.T, tangent.T, k, rho, None, None, None, delta, pos, arm)

    def _fill(self, out: np.ndarray, a: int, b: int, x: np.ndarray, Sc: np.ndarray, rotate: bool,
              extra: dict[str, bool]) -> None:
        """Rows of ``out[:, a:b]`` for one chunk of samples (see :meth:`_evaluate`)."""
        sg = self.sense
        point, point_d1, normal, tangent = out[0:2], out[2:4], out[4:6], out[6:8]
        beta, b1, b2, p, p1, p2 = self._face(Sc)
        w = sg + b1
        s = p1 / w
        rc = np.subtract(p + p2 / w**2, p1 * b2 / w**3, out=out[9, a:b])
        nx, ny = cos_sin(beta)                             # face normal; J·n = (−ny, nx)
        px, py = p * nx - s * ny, p * ny + s * nx
        vx, vy, pc, xi = self._extras(px, py, s, Sc)
        if pc is not None:
            out[11, a:b] = pc
            extra["face"] = True
        if xi is not None:
            out[12, a:b] = xi
            extra["arm"] = True
        np.arctan2(-sg * (vx * ny - vy * nx), vx * nx + vy * ny, out=out[10, a:b])
        with np.errstate(divide="ignore"):
            np.divide(1.0, rc, out=out[8, a:b])
        wr = w * rc
        if rotate:
            c, sn = cos_sin(sg * x)
            rot_into(point, a, b, px, py, c, sn)
            rot_into(point_d1, a, b, -ny * wr, nx * wr, c, sn)
            rot_into(normal, a, b, nx, ny, c, sn)
            rot_into(tangent, a, b, -sg * ny, sg * nx, c, sn)
        else:
            point[0, a:b], point[1, a:b], point_d1[0, a:b], point_d1[1, a:b] = px, py, -ny * wr, nx * wr
            normal[0, a:b], normal[1, a:b], tangent[0, a:b], tangent[1, a:b] = nx, ny, -sg * ny, sg * nx


class TranslatingFlatContact(DiscFlatContact):
    """Translating flat face at distance R_b + S; ρ = R_b + S + S″."""

    def __init__(self, motion: MotionLike, base_radius: float, face_offset: float = 0.0, sense: int = 1):
        super().__init__(motion, sense)
        self.rb, self.face_offset = float(base_radius), float(face_offset)

    def _face(self, S):
        # the face normal angle is the constant π/2: given as a scalar (its cos/sin are then
        # taken once, not per sample), β′ = β″ = 0 likewise
        return math.pi / 2, 0.0, 0.0, self.rb + S[0], S[1], S[2]

    def _extras(self, px, py, s, S):
        return 0.0, 1.0, px - self.face_offset, None


class OscillatingFlatContact(DiscFlatContact):
    """Oscillating flat face: normal (sin ξ, cos ξ), distance f + m sin ξ from the cam centre."""

    oscillating = True

    def __init__(self, motion: MotionLike, pivot_distance: float, face_offset: float,
                 initial_arm_angle: float, sense: int = 1):
        super().__init__(motion, sense)
        self.m, self.f, self.xi0 = float(pivot_distance), float(face_offset), float(initial_arm_angle)

    @property
    def pivot(self) -> tuple[float, float]:
        """The face's pivot in the fixed frame (mm)."""
        return self.m, 0.0

    def _xi(self, S):
        return self.xi0 + DEG * S[0], DEG * S[1], DEG * S[2]

    def _face(self, S):
        xi, x1, x2 = self._xi(S)
        (cx, sx), m = cos_sin(xi), self.m
        return (math.pi / 2 - xi, -x1, -x2, self.f + m * sx, m * cx * x1, m * (cx * x2 - sx * x1**2))

    def _extras(self, px, py, s, S):
        xi = self._xi(S)[0]
        rx, ry = px - self.m, py - 0.0
        d = np.hypot(rx, ry)
        return ry / d, -rx / d, s + self.m * cos_sin(xi)[0], xi  # clockwise about the pivot


# ---------------------------------------------------------------------------
@dataclass(frozen=True)
class TranslatingFlat(Mechanism):
    """Disc cam with a translating flat-face follower.

    Parameters
    ----------
    base_radius_mm : float
        R_b (> 0).
    face_offset_mm : float
        Stem offset (> 0 = right).  It does not change the profile, only the forces and the face length
        needed on each side of the stem.
    rotation : {"cw", "ccw"}
    """

    base_radius_mm: float
    face_offset_mm: float = 0.0
    rotation: str = "cw"
    follower: ClassVar[FollowerType] = FollowerType.FLAT
    required: ClassVar[tuple[str, ...]] = ("base_radius_mm",)
    optional: ClassVar[tuple[str, ...]] = ("face_offset_mm",)

    @classmethod
    def from_spec(cls, spec: Any) -> TranslatingFlat:
        return cls(spec.follower.base_radius_mm, spec.follower.face_offset_mm or 0.0, spec.cam.rotation)

    def validate(self) -> list[Problem]:
        p: list[Problem] = []
        require_rotation(p, self.rotation)
        if finite_fields(self, p):
            require_positive(p, "base_radius_mm", self.base_radius_mm)
        return p

    def contacts(self, program: MotionLike) -> tuple[Contact, ...]:
        return (TranslatingFlatContact(program, self.base_radius_mm, self.face_offset_mm, self.sense),)


def face_swing_problems(xi0: float, program: MotionLike, sense: int) -> list[Problem]:
    """An oscillating face must stay short of perpendicular to the line of centres, and turn slower than
    the cam (the envelope needs σ + dξ/dφ to keep its sign)."""
    p: list[Problem] = []
    smax = lift_range(program, 0)[1]
    hi = xi0 + DEG * smax
    if hi >= math.pi / 2:
        p.append(Problem("motion[*].lift", round(smax, 12),
                         f"the face would turn to {math.degrees(hi):.6g}° (from ξ0 = {math.degrees(xi0):.6g}°), "
                         "past perpendicular to the line of centres",
                         f"keep the total lift below {90.0 - math.degrees(xi0):.6g}°"))
    v1min, v1max = lift_range(program, 1)
    worst = DEG * (v1max if sense > 0 else -v1min)
    if worst >= 1.0:
        p.append(Problem("motion[*].angle_deg", round(math.degrees(worst), 9),
                         "the face turns as fast as the cam (|dξ/dφ| reaches 1 rad/rad): no profile envelopes it",
                         "spread the lift over larger angles"))
    return p


@dataclass(frozen=True)
class OscillatingFlat(Mechanism):
    """Disc cam with an oscillating flat-face follower.

    Parameters
    ----------
    base_radius_mm : float
        R_b (> 0).
    pivot_distance_mm : float
        Cam centre → pivot distance m (> 0), pivot to the right.
    face_offset_mm : float
        Face eccentricity f: the distance from the pivot to the vertex of the right-angled follower (+, − or
        0).  The face is tangent to the base circle at ξ₀ = arcsin((R_b − f)/m), so |R_b − f| < m is required.
    rotation : {"cw", "ccw"}
    """

    base_radius_mm: float
    pivot_distance_mm: float
    face_offset_mm: float = 0.0
    rotation: str = "cw"
    follower: ClassVar[FollowerType] = FollowerType.FLAT
    motion: ClassVar[FollowerMotion] = FollowerMotion.OSCILLATING
    required: ClassVar[tuple[str, ...]] = ("base_radius_mm", "pivot_distance_mm")
    optional: ClassVar[tuple[str, ...]] = ("face_offset_mm",)

    @classmethod
    def from_spec(cls, spec: Any) -> OscillatingFlat:
        f = spec.follower
        return cls(f.base_radius_mm, f.pivot_distance_mm, f.face_offset_mm or 0.0, spec.cam.rotation)

    @property
    def initial_arm_angle(self) -> float:
        """ξ₀ in radians: arcsin((R_b − f)/m)."""
        x = (self.base_radius_mm - self.face_offset_mm) / self.pivot_distance_mm
        return math.asin(max(-1.0, min(1.0, x)))

    def validate(self) -> list[Problem]:
        p: list[Problem] = []
        require_rotation(p, self.rotation)
        if not finite_fields(self, p):
            return p
        require_positive(p, "base_radius_mm", self.base_radius_mm)
        require_positive(p, "pivot_distance_mm", self.pivot_distance_mm)
        if not p and not abs(self.base_radius_mm - self.face_offset_mm) < self.pivot_distance_mm:
            lo = self.base_radius_mm - self.pivot_distance_mm
            hi = self.base_radius_mm + self.pivot_distance_mm
            p.append(Problem("follower.face_offset_mm", self.face_offset_mm,
                             "the face cannot touch the base circle: need |R_b - f| < pivot distance",
                             f"choose face_offset_mm in ({lo:.6g}, {hi:.6g}) or move the pivot further out"))
        return p

    def validate_motion(self, program: MotionLike, *, bore_mm: float | None = None) -> list[Problem]:
        return super().validate_motion(program) or face_swing_problems(self.initial_arm_angle, program, self.sense)

    def contacts(self, program: MotionLike) -> tuple[Contact, ...]:
        return (OscillatingFlatContact(program, self.pivot_distance_mm, self.face_offset_mm,
                                       self.initial_arm_angle, self.sense),)
