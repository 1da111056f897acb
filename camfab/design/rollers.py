"""Roller (and knife-edge) followers on disc cams: translating with offset, and oscillating on an arm.

The roller centre C follows the pitch curve; the profile is its parallel curve at the roller radius R_r
(:mod:`camfab.design.profile` gives the scheme).  A knife edge is a roller of radius 0.

* Translating roller, offset e (> 0 = axis right of the cam centre): ``C = (e, √(R_p² − e²) + S)`` in the
  fixed frame, R_p = R_b + R_r the prime radius; requires |e| < R_p.
* Oscillating roller: pivot at (m, 0) right of the cam centre, arm A from the pivot to the roller centre,
  ``C = (m − A cos ξ, A sin ξ)`` with the arm angle ξ = ξ₀ + S (S in degrees, + = clockwise) measured at the
  pivot from the line to the cam centre; at S = 0 the roller rests on the prime circle:
  ``ξ₀ = arccos((A² + m² − R_p²)/(2Am))``, which needs |A − m| < R_p < A + m.
"""
from __future__ import annotations

import math
from typing import Any, ClassVar

import numpy as np

from ..errors import Problem
from ..records import dataclass
from .kinds import FollowerMotion, FollowerType
from .mechanism import Mechanism, finite_fields, lift_range, require_non_negative, require_positive, require_rotation
from .profile import CHUNK, DEG, Contact, MotionLike, ProfileSample, block, rot_into
from .trig import cos_sin

__all__ = ["DiscRollerContact", "TranslatingRollerContact", "OscillatingRollerContact", "TranslatingRoller",
           "OscillatingRoller"]


class DiscRollerContact(Contact):
    """Generic roller on a rotating cam.  Subclasses give, from ``S, S′, S″``, the fixed-frame roller
    centre path ``C, C′, C″``, the unit velocity of the follower's point of force while rising, and the
    arm angle (or None) — :meth:`_components`."""

    def __init__(self, motion: MotionLike, roller_radius: float, sense: int = 1):
        super().__init__(motion, sense)
        self.roller_radius = float(roller_radius)

    def _components(self, S: np.ndarray) -> tuple[Any, ...]:  # pragma: no cover - abstract
        """``(cx, cy, c1x, c1y, c2x, c2y, vx, vy, arm)``: C, C′, C″, the unit rise velocity of the roller
        centre (arrays, or scalars where constant) and the arm angle (or None)."""
        raise NotImplementedError

    def _face_position(self, cx, cy, nx, ny, xi) -> np.ndarray | None:
        """The contact's position along a follower face (fixed frame), for faces; None for a roller."""
        return None

    def _force_velocity(self, cx, cy, nx, ny, vx, vy):
        """The unit velocity whose angle to the normal is the pressure angle: the roller centre's."""
        return vx, vy

    def _evaluate(self, phi, rotate: bool, S=None) -> ProfileSample:
        x, S = self._S(phi, S)
        n = x.size
        # outputs filled chunk by chunk: the long chain of elementwise temporaries then
        # stays in cache (and off fresh pages), which is most of the cost at large n
        out = block(17, n)  # rows 15, 16: the arm angle and the face position, when there are any
        extra: dict[str, bool] = {}
        for a in range(0, max(n, 1), CHUNK):
            b = min(a + CHUNK, n)
            self._fill(out, a, b, x[a:b], S[:, a:b], rotate, extra)
        pitch, point, point_d1, normal, tangent = out[0:2], out[2:4], out[4:6], out[6:8], out[8:10]
        kp, k, rho_p, rho, delta = out[10:15]
        arm = out[15] if extra.get("arm") else None
        face = out[16] if extra.get("face") else None
        return ProfileSample(x, point.T, point_d1.T, normal.T, tangent.T, k, rho, pitch.T, kp, rho_p, delta, face,
                             arm)

    def _fill(self, out: np.ndarray, a: int, b: int, x: np.ndarray, S: np.ndarray, rotate: bool,
              extra: dict[str, bool]) -> None:
        """Rows of ``out[:, a:b]`` for one chunk of samples (see :meth:`_evaluate`)."""
        sg, rr = self.sense, self.roller_radius
        comp = self._components(S)
        xi = comp[-1]
        if xi is not None:
            out[15, a:b] = xi
            extra["arm"] = True
        cx, cy, vx, vy, tx, ty, speed, inv, nx, ny = self._frame(comp)
        kpc = self._pitch_curvature(comp, cx, cy, tx, ty, inv, out[10, a:b])
        scale = 1.0 - rr * kpc
        with np.errstate(divide="ignore", invalid="ignore"):
            kc = np.divide(kpc, scale, out=out[11, a:b])
            np.divide(1.0, kc, out=out[13, a:b])
            np.divide(1.0, kpc, out=out[12, a:b])
        # δ = atan2(−σ·(v × n), v·n)
        vx, vy = self._force_velocity(cx, cy, nx, ny, vx, vy)
        cr = vy * nx - vx * ny if sg > 0 else vx * ny - vy * nx
        np.arctan2(cr, vx * nx + vy * ny, out=out[14, a:b])
        face = self._face_position(cx, cy, nx, ny, xi)
        if face is not None:
            out[16, a:b] = face
            extra["face"] = True
        self._place(out, a, b, x, cx, cy, nx, ny, speed * scale, rotate)

    def _frame(self, comp: tuple[Any, ...]) -> tuple[Any, ...]:
        """``(cx, cy, vx, vy, tx, ty, |T|, σ/|T|, nx, ny)`` of the :meth:`_components` ``comp``: C, the rise
        velocity, T = σ·J·C + C′, its length and inverse, and the fixed-frame normal."""
        sg = self.sense
        cx, cy, c1x, c1y, _, _, vx, vy, _ = comp
        # component arrays instead of (n, 2) column slices: this is the hot path
        if not (isinstance(cx, np.ndarray) and cx.shape == cy.shape):
            cx = cx + 0.0 * cy  # broadcast a scalar coordinate to the sample count
        # (σ = ±1 is applied by choosing the operation or the sign of one factor: exact, and
        # no extra pass over the arrays)
        tx, ty = (c1x - cy, c1y + cx) if sg > 0 else (c1x + cy, c1y - cx)  # T = σ·J·C + C′
        speed = np.sqrt(tx * tx + ty * ty)  # |T| is far from overflow: no need for hypot's care
        inv = np.divide(sg, speed)  # σ/|T|
        # n = −σ·J·t = σ·(ty, −tx)/|T|
        nx = ty * inv
        ny = np.negative(tx * inv)
        return cx, cy, vx, vy, tx, ty, speed, inv, nx, ny

    def _pitch_curvature(self, comp: tuple[Any, ...], cx, cy, tx, ty, inv, out: np.ndarray) -> np.ndarray:
        """κp = σ·(T × A2)/|T|³ into ``out``, A2 = −C + 2σ·J·C′ + C″."""
        sg = self.sense
        _, _, c1x, c1y, c2x, c2y, _, _, _ = comp
        ax = c2x - cx - 2 * sg * c1y
        ay = c2y - cy + 2 * sg * c1x
        inv3 = inv * inv
        inv3 *= inv  # σ³/|T|³ = σ/|T|³
        return np.multiply(tx * ay - ty * ax, inv3, out=out)

    def evaluate_fields(self, phi, fields):
        """:meth:`Contact.evaluate_fields`; the profile point and P′ alone (what the exporters and the arc fit
        use) skip the curvatures' inverses, the pressure angle and the arm and face outputs (bit for bit the
        same values: the same operations)."""
        names = tuple(fields)
        if type(self)._evaluate is not DiscRollerContact._evaluate or not names or \
                not set(names) <= {"point", "point_d1"}:
            return super().evaluate_fields(phi, names)
        x = np.atleast_1d(np.asarray(phi, dtype=float))
        n = x.size
        want_d1 = "point_d1" in names
        out = np.empty((4 if want_d1 else 2, n))  # point (and P′): (2, n) rows handed out transposed
        tmp = np.empty((5, min(n, CHUNK)))  # one chunk's pitch point, normal and κp
        sg, rr = self.sense, self.roller_radius
        for a in range(0, n, CHUNK):
            b = min(a + CHUNK, n)
            xc, w = x[a:b], b - a
            comp = self._components(self.motion.evaluate(xc, (0, 1, 2)))
            cx, cy, _, _, tx, ty, speed, inv, nx, ny = self._frame(comp)
            c, s = cos_sin(sg * xc)
            rot_into(tmp[0:2], 0, w, cx, cy, c, s)
            rot_into(tmp[2:4], 0, w, nx, ny, c, s)
            nrx, nry = tmp[2, :w], tmp[3, :w]
            np.subtract(tmp[0, :w], rr * nrx, out=out[0, a:b])
            np.subtract(tmp[1, :w], rr * nry, out=out[1, a:b])
            if want_d1:
                kpc = self._pitch_curvature(comp, cx, cy, tx, ty, inv, tmp[4, :w])
                f = speed * (1.0 - rr * kpc)
                np.multiply(np.multiply(nry, -sg), f, out=out[2, a:b])
                np.multiply(np.multiply(nrx, sg), f, out=out[3, a:b])
        got = {"point": out[0:2].T, "point_d1": out[2:4].T if want_d1 else None}
        return {f: got[f] for f in names}

    def _place(self, out: np.ndarray, a: int, b: int, x: np.ndarray, cx, cy, nx, ny, f, rotate: bool) -> None:
        """Pitch point, normal, tangent, profile point and P′ of one chunk, in the cam frame (``rotate``)
        or the fixed frame; ``f`` = |T|·(1 − Rr·κp)."""
        sg, rr = self.sense, self.roller_radius
        pitch, point, point_d1, normal, tangent = out[0:2], out[2:4], out[4:6], out[6:8], out[8:10]
        if rotate:
            c, s = cos_sin(sg * x)
            rot_into(pitch, a, b, cx, cy, c, s)
            rot_into(normal, a, b, nx, ny, c, s)
        else:
            pitch[0, a:b], pitch[1, a:b], normal[0, a:b], normal[1, a:b] = cx, cy, nx, ny
        # rotation commutes with J: the rotated tangent is σ·J·(rotated normal), the profile point is
        # the rotated pitch point − Rr·(rotated normal), and P′ = T·(1 − Rr·κp) = t·|T|·(1 − Rr·κp)
        nrx, nry = normal[0, a:b], normal[1, a:b]
        np.multiply(nry, -sg, out=tangent[0, a:b])
        np.multiply(nrx, sg, out=tangent[1, a:b])
        np.subtract(pitch[0, a:b], rr * nrx, out=point[0, a:b])
        np.subtract(pitch[1, a:b], rr * nry, out=point[1, a:b])
        np.multiply(tangent[0, a:b], f, out=point_d1[0, a:b])
        np.multiply(tangent[1, a:b], f, out=point_d1[1, a:b])


class TranslatingRollerContact(DiscRollerContact):
    """Translating roller with offset e: C = (e, √(R_p² − e²) + S) in the fixed frame."""

    def __init__(self, motion: MotionLike, prime_radius: float, roller_radius: float,
                 offset: float = 0.0, sense: int = 1):
        super().__init__(motion, roller_radius, sense)
        self.offset = float(offset)
        self.axial_base = math.sqrt(prime_radius**2 - offset**2)

    def _components(self, S):
        s0, s1, s2 = S
        return self.offset, self.axial_base + s0, 0.0, s1, 0.0, s2, 0.0, 1.0, None


class OscillatingRollerContact(DiscRollerContact):
    """Oscillating roller: pivot (m, 0), C = (m − A cos ξ, A sin ξ), ξ = ξ₀ + S (S in degrees)."""

    oscillating = True

    def __init__(self, motion: MotionLike, pivot_distance: float, arm_length: float,
                 initial_arm_angle: float, roller_radius: float, sense: int = 1):
        super().__init__(motion, roller_radius, sense)
        self.m, self.a, self.xi0 = float(pivot_distance), float(arm_length), float(initial_arm_angle)

    @property
    def pivot(self) -> tuple[float, float]:
        """The arm's pivot in the fixed frame (mm)."""
        return self.m, 0.0

    def _components(self, S):
        xi, x1, x2 = self.xi0 + DEG * S[0], DEG * S[1], DEG * S[2]
        (cx, sx), a = cos_sin(xi), self.a
        ax1, ax1sq = a * x1, a * x1 * x1
        return (self.m - a * cx, a * sx, ax1 * sx, ax1 * cx, a * x2 * sx + ax1sq * cx, a * x2 * cx - ax1sq * sx,
                sx, cx, xi)


# ---------------------------------------------------------------------------
def _prime_offset_problems(p: list[Problem], rp: float, offset: float) -> None:
    if not p and abs(offset) >= rp:
        p.append(Problem("follower.offset_mm", offset,
                         f"|offset| must be smaller than the prime radius R_b + R_r = {rp:.6g} mm",
                         f"use |offset_mm| < {rp:.6g}, or enlarge the base circle"))


@dataclass(frozen=True)
class TranslatingRoller(Mechanism):
    """Disc cam with a translating roller (or knife-edge) follower.

    Parameters
    ----------
    base_radius_mm : float
        Base circle radius R_b (> 0); the prime circle is R_p = R_b + R_r.
    roller_radius_mm : float
        Roller radius R_r (>= 0; 0 is a knife edge).
    offset_mm : float
        Follower-axis offset e; > 0 puts the axis right of the cam centre.  Requires |e| < R_p.
    rotation : {"cw", "ccw"}
    """

    base_radius_mm: float
    roller_radius_mm: float
    offset_mm: float = 0.0
    rotation: str = "cw"
    required: ClassVar[tuple[str, ...]] = ("base_radius_mm", "roller_radius_mm")
    optional: ClassVar[tuple[str, ...]] = ("offset_mm",)

    @classmethod
    def from_spec(cls, spec: Any) -> TranslatingRoller:
        f = spec.follower
        rr = 0.0 if f.type == FollowerType.KNIFE else (f.roller_radius_mm or 0.0)
        return cls(f.base_radius_mm, rr, f.offset_mm or 0.0, spec.cam.rotation)

    @property
    def prime_radius_mm(self) -> float:
        return self.base_radius_mm + self.roller_radius_mm

    def validate(self) -> list[Problem]:
        p: list[Problem] = []
        require_rotation(p, self.rotation)
        if not finite_fields(self, p):
            return p
        require_positive(p, "base_radius_mm", self.base_radius_mm)
        require_non_negative(p, "roller_radius_mm", self.roller_radius_mm)
        _prime_offset_problems(p, self.prime_radius_mm, self.offset_mm)
        return p

    def contacts(self, program: MotionLike) -> tuple[Contact, ...]:
        return (TranslatingRollerContact(program, self.prime_radius_mm, self.roller_radius_mm, self.offset_mm,
                                         self.sense),)


def arm_reach_problems(p: list[Problem], a: float, m: float, rp: float, field: str = "pivot_distance_mm") -> None:
    """The arm must put the roller (centre) on the prime circle: |A − m| < R_p < A + m."""
    if not abs(a - m) < rp < a + m:
        p.append(Problem(f"follower.{field}", m,
                         f"the arm cannot put the roller on the prime circle (R_p = {rp:.6g} mm): "
                         f"need |A - m| < R_p < A + m with A = {a:.6g} mm",
                         f"choose pivot_distance_mm in ({abs(a - rp):.6g}, {a + rp:.6g})"))


def arm_swing_problems(xi0: float, program: MotionLike, *, hi_limit: float = math.pi,
                       lo_limit: float = 0.0, what: str = "arm") -> list[Problem]:
    """The arm angle ξ₀ + S must stay strictly inside (``lo_limit``, ``hi_limit``) over the cycle."""
    smin, smax = lift_range(program, 0)
    lo, hi = xi0 + DEG * smin, xi0 + DEG * smax
    if lo > lo_limit and hi < hi_limit:
        return []
    return [Problem("motion[*].lift", round(smax, 12),
                    f"the {what} would swing to {math.degrees(hi):.6g}° (from ξ0 = {math.degrees(xi0):.6g}°); "
                    f"it must stay strictly between {math.degrees(lo_limit):g}° and {math.degrees(hi_limit):g}° "
                    "from the line of centres",
                    f"keep the total lift below {math.degrees(hi_limit) - math.degrees(xi0):.6g}° "
                    "or change the arm geometry")]


@dataclass(frozen=True)
class OscillatingRoller(Mechanism):
    """Disc cam with an oscillating roller follower.

    Parameters
    ----------
    base_radius_mm, roller_radius_mm : float
        R_b (> 0) and R_r (>= 0, < arm length).
    pivot_distance_mm : float
        Cam centre → arm pivot distance m (> 0); the pivot is to the right.
    arm_length_mm : float
        Pivot → roller centre A (> R_r).  The roller rests on the prime circle at the initial arm angle
        ξ₀ = arccos((A² + m² − R_p²)/(2Am)), which must lie strictly inside (0°, 180°): |A − m| < R_p < A + m.
    rotation : {"cw", "ccw"}
    """

    base_radius_mm: float
    roller_radius_mm: float
    pivot_distance_mm: float
    arm_length_mm: float
    rotation: str = "cw"
    motion: ClassVar[FollowerMotion] = FollowerMotion.OSCILLATING
    required: ClassVar[tuple[str, ...]] = ("base_radius_mm", "roller_radius_mm", "pivot_distance_mm",
                                           "arm_length_mm")

    @classmethod
    def from_spec(cls, spec: Any) -> OscillatingRoller:
        f = spec.follower
        rr = 0.0 if f.type == FollowerType.KNIFE else (f.roller_radius_mm or 0.0)
        return cls(f.base_radius_mm, rr, f.pivot_distance_mm, f.arm_length_mm, spec.cam.rotation)

    @property
    def prime_radius_mm(self) -> float:
        return self.base_radius_mm + self.roller_radius_mm

    @property
    def initial_arm_angle(self) -> float:
        """ξ₀ in radians: angle at the pivot between pivot→cam centre and the arm."""
        a, m, rp = self.arm_length_mm, self.pivot_distance_mm, self.prime_radius_mm
        return math.acos(max(-1.0, min(1.0, (a * a + m * m - rp * rp) / (2 * a * m))))

    def validate(self) -> list[Problem]:
        p: list[Problem] = []
        require_rotation(p, self.rotation)
        if not finite_fields(self, p):
            return p
        require_positive(p, "base_radius_mm", self.base_radius_mm)
        require_non_negative(p, "roller_radius_mm", self.roller_radius_mm)
        require_positive(p, "pivot_distance_mm", self.pivot_distance_mm)
        require_positive(p, "arm_length_mm", self.arm_length_mm)
        if p:
            return p
        if self.arm_length_mm <= self.roller_radius_mm:
            p.append(Problem("follower.arm_length_mm", self.arm_length_mm,
                             f"the arm must be longer than the roller radius ({self.roller_radius_mm:.6g} mm)",
                             "lengthen the arm or use a smaller roller"))
        arm_reach_problems(p, self.arm_length_mm, self.pivot_distance_mm, self.prime_radius_mm)
        return p

    def validate_motion(self, program: MotionLike, *, bore_mm: float | None = None) -> list[Problem]:
        return super().validate_motion(program) or arm_swing_problems(self.initial_arm_angle, program)

    def contacts(self, program: MotionLike) -> tuple[Contact, ...]:
        return (OscillatingRollerContact(program, self.pivot_distance_mm, self.arm_length_mm,
                                         self.initial_arm_angle, self.roller_radius_mm, self.sense),)
