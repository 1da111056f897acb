"""Mechanism geometry of single-follower cams (frozen, unit-named dataclasses).

Conventions (``design.md`` §3, binding):

* Cam frame: origin at the cam centre; at cam angle 0 the follower axis points
  along +Y (follower above the cam).  ``rotation="cw"`` (default, as CAM-DAS)
  or ``"ccw"`` is the physical sense in which the cam turns in that view.
* Translating followers: ``offset_mm > 0`` puts the follower axis to the
  **right** of the cam centre.  Its effect on the pressure angle is derived in
  :mod:`camfab.design.profile` (a right offset *raises* the rise pressure angle
  of a cw cam and *lowers* it for a ccw cam).
* Oscillating followers: the pivot lies to the right of the cam centre at
  ``pivot_distance_mm``; the roller (or face) sits above the line of centres;
  a positive lift turns the arm clockwise.
* The follower geometry is fixed in the view; ``ccw`` changes only the sense
  of rotation.  Hence a ``ccw`` cam is the mirror image of the ``cw`` cam of
  the mirrored mechanism (offset −e, pivot on the left): for a centred
  translating follower, or any translating flat face, it is simply the mirror
  image of the ``cw`` cam.

Every mechanism has ``validate() -> list[Problem]``; an empty list means the
geometry can be built for *some* motion.  ``validate_motion(program)`` adds the
limits that depend on the motion (an arm that swings past the line of centres,
a face turning as fast as the cam, ...); :class:`camfab.design.profile.CamGeometry`
runs both and raises :class:`~camfab.errors.SpecError` with every problem.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, fields

import numpy as np

from ..errors import Problem

__all__ = [
    "ROTATIONS",
    "Mechanism",
    "TranslatingRoller",
    "OscillatingRoller",
    "TranslatingFlat",
    "OscillatingFlat",
    "TranslatingCamRoller",
]

ROTATIONS = ("cw", "ccw")
_DIRECTIONS = ("left", "right")
_K = math.pi / 180.0  # oscillating lifts are in degrees


def _range(prog, order: int) -> tuple[float, float]:
    """min and max of the ``order``-th derivative of S over the cycle."""
    peaks = getattr(prog, "peaks", None)
    if peaks is not None:
        pk = peaks("exact")[order]
        return pk.min, pk.max
    v = prog.evaluate(np.linspace(0.0, prog.period, 20001), (order,))[0]
    return float(v.min()), float(v.max())


def _finite(obj, problems: list[Problem]) -> bool:
    ok = True
    for f in fields(obj):
        v = getattr(obj, f.name)
        if f.name.endswith("_mm") and (not isinstance(v, (int, float)) or not math.isfinite(v)):
            problems.append(Problem(f"follower.{f.name}", v, "must be a finite number (mm)",
                                    f"give {f.name} as a length in mm"))
            ok = False
    return ok


def _positive(problems, name, value, what="a length > 0 mm"):
    if value <= 0:
        problems.append(Problem(f"follower.{name}", value, f"must be {what}", f"give a positive {name}"))


def _non_negative(problems, name, value):
    if value < 0:
        problems.append(Problem(f"follower.{name}", value, "must be >= 0 mm", f"give {name} >= 0"))


def _rotation(problems, rotation):
    if rotation not in ROTATIONS:
        problems.append(Problem("cam.rotation", rotation, "rotation must be 'cw' or 'ccw'",
                                'use rotation = "cw" (default) or "ccw"'))


@dataclass(frozen=True)
class Mechanism:
    """Base class: every mechanism knows its follower kind and motion."""

    #: "roller" (knife edge = roller radius 0) or "flat"
    follower = "roller"
    #: "translating" or "oscillating"
    motion = "translating"
    #: "disc" for rotating cams, "translating" for the sliding (wedge) cam
    cam_kind = "disc"

    def validate(self) -> list[Problem]:  # pragma: no cover - abstract
        raise NotImplementedError

    def validate_motion(self, program) -> list[Problem]:
        """Limits that depend on both this mechanism and the motion program
        (a disc cam's program must span 2π; arm swing limits)."""
        if self.cam_kind == "disc" and abs(program.period - 2 * math.pi) > 1e-9:
            return [Problem("motion", program.period, "a disc cam's motion must span one revolution (2π rad)",
                            "make the segment angles sum to 360°")]
        return []

    @property
    def sense(self) -> int:
        """+1 for cw, −1 for ccw (the σ of :mod:`camfab.design.profile`)."""
        return 1 if getattr(self, "rotation", "cw") == "cw" else -1


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
        Follower-axis offset e; > 0 puts the axis right of the cam centre.
        Requires |e| < R_p.
    rotation : {"cw", "ccw"}
    """

    base_radius_mm: float
    roller_radius_mm: float
    offset_mm: float = 0.0
    rotation: str = "cw"

    @property
    def prime_radius_mm(self) -> float:
        return self.base_radius_mm + self.roller_radius_mm

    def validate(self) -> list[Problem]:
        p: list[Problem] = []
        _rotation(p, self.rotation)
        if not _finite(self, p):
            return p
        _positive(p, "base_radius_mm", self.base_radius_mm)
        _non_negative(p, "roller_radius_mm", self.roller_radius_mm)
        rp = self.prime_radius_mm
        if not p and abs(self.offset_mm) >= rp:
            p.append(Problem("follower.offset_mm", self.offset_mm,
                             f"|offset| must be smaller than the prime radius R_b + R_r = {rp:.6g} mm",
                             f"use |offset_mm| < {rp:.6g}, or enlarge the base circle"))
        return p


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
        Pivot → roller centre A (> R_r).  The roller rests on the prime circle
        at the initial arm angle ξ₀ = arccos((A² + m² − R_p²)/(2Am)), which
        must lie strictly inside (0°, 180°): |A − m| < R_p < A + m.
    rotation : {"cw", "ccw"}
    """

    base_radius_mm: float
    roller_radius_mm: float
    pivot_distance_mm: float
    arm_length_mm: float
    rotation: str = "cw"
    follower = "roller"
    motion = "oscillating"

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
        _rotation(p, self.rotation)
        if not _finite(self, p):
            return p
        _positive(p, "base_radius_mm", self.base_radius_mm)
        _non_negative(p, "roller_radius_mm", self.roller_radius_mm)
        _positive(p, "pivot_distance_mm", self.pivot_distance_mm)
        _positive(p, "arm_length_mm", self.arm_length_mm)
        if p:
            return p
        a, m, rp = self.arm_length_mm, self.pivot_distance_mm, self.prime_radius_mm
        if a <= self.roller_radius_mm:
            p.append(Problem("follower.arm_length_mm", a,
                             f"the arm must be longer than the roller radius ({self.roller_radius_mm:.6g} mm)",
                             "lengthen the arm or use a smaller roller"))
        if not abs(a - m) < rp < a + m:
            p.append(Problem("follower.pivot_distance_mm", m,
                             f"the arm cannot put the roller on the prime circle (R_p = {rp:.6g} mm): "
                             f"need |A - m| < R_p < A + m with A = {a:.6g} mm",
                             f"choose pivot_distance_mm in ({abs(a - rp):.6g}, {a + rp:.6g})"))
        return p

    def validate_motion(self, program) -> list[Problem]:
        p = super().validate_motion(program)
        if p:
            return p
        smin, smax = _range(program, 0)
        xi0 = self.initial_arm_angle
        lo, hi = xi0 + _K * smin, xi0 + _K * smax
        if lo <= 0.0 or hi >= math.pi:
            p.append(Problem("motion[*].lift", round(smax, 12),
                             f"the arm would swing to {math.degrees(hi):.6g}° (from ξ0 = {math.degrees(xi0):.6g}°); "
                             "it must stay strictly between 0° and 180° from the line of centres",
                             f"keep the total lift below {180.0 - math.degrees(xi0):.6g}° or change the arm geometry"))
        return p


@dataclass(frozen=True)
class TranslatingFlat(Mechanism):
    """Disc cam with a translating flat-face follower.

    Parameters
    ----------
    base_radius_mm : float
        R_b (> 0).
    face_offset_mm : float
        Stem offset (> 0 = right).  It does not change the profile, only the
        forces and the face length needed on each side of the stem.
    rotation : {"cw", "ccw"}
    """

    base_radius_mm: float
    face_offset_mm: float = 0.0
    rotation: str = "cw"
    follower = "flat"

    def validate(self) -> list[Problem]:
        p: list[Problem] = []
        _rotation(p, self.rotation)
        if _finite(self, p):
            _positive(p, "base_radius_mm", self.base_radius_mm)
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
        Face eccentricity f: the distance from the pivot to the vertex of the
        right-angled follower (+, − or 0).  The face is tangent to the base
        circle at ξ₀ = arcsin((R_b − f)/m), so |R_b − f| < m is required.
    rotation : {"cw", "ccw"}
    """

    base_radius_mm: float
    pivot_distance_mm: float
    face_offset_mm: float = 0.0
    rotation: str = "cw"
    follower = "flat"
    motion = "oscillating"

    @property
    def initial_arm_angle(self) -> float:
        """ξ₀ in radians (spec D2: arcsin, not arctan)."""
        x = (self.base_radius_mm - self.face_offset_mm) / self.pivot_distance_mm
        return math.asin(max(-1.0, min(1.0, x)))

    def validate(self) -> list[Problem]:
        p: list[Problem] = []
        _rotation(p, self.rotation)
        if not _finite(self, p):
            return p
        _positive(p, "base_radius_mm", self.base_radius_mm)
        _positive(p, "pivot_distance_mm", self.pivot_distance_mm)
        if not p and not abs(self.base_radius_mm - self.face_offset_mm) < self.pivot_distance_mm:
            lo = self.base_radius_mm - self.pivot_distance_mm
            hi = self.base_radius_mm + self.pivot_distance_mm
            p.append(Problem("follower.face_offset_mm", self.face_offset_mm,
                             "the face cannot touch the base circle: need |R_b - f| < pivot distance",
                             f"choose face_offset_mm in ({lo:.6g}, {hi:.6g}) or move the pivot further out"))
        return p

    def validate_motion(self, program) -> list[Problem]:
        p = super().validate_motion(program)
        if p:
            return p
        xi0, smax = self.initial_arm_angle, _range(program, 0)[1]
        hi = xi0 + _K * smax
        if hi >= math.pi / 2:
            p.append(Problem("motion[*].lift", round(smax, 12),
                             f"the face would turn to {math.degrees(hi):.6g}° (from ξ0 = {math.degrees(xi0):.6g}°), "
                             "past perpendicular to the line of centres",
                             f"keep the total lift below {90.0 - math.degrees(xi0):.6g}°"))
        v1min, v1max = _range(program, 1)
        worst = _K * (v1max if self.sense > 0 else -v1min)
        if worst >= 1.0:  # the envelope needs dφ/dφ − dξ/dφ to keep the sign of the rotation
            p.append(Problem("motion[*].angle_deg", round(math.degrees(worst), 9),
                             "the face turns as fast as the cam (|dξ/dφ| reaches 1 rad/rad): no profile envelopes it",
                             "spread the lift over larger angles"))
        return p


@dataclass(frozen=True)
class TranslatingCamRoller(Mechanism):
    """Translating (sliding, wedge) cam driving a translating roller follower.

    The motion program's independent variable is the cam travel B in mm
    (``MotionProgram.from_segments(..., unit="mm")``; its period is the cam
    length).  Cam frame: x along the cam, y up; the line S = 0 of the profile
    lies at ``y = base_height_mm`` (the cam's bottom edge is y = 0).

    Parameters
    ----------
    roller_radius_mm : float
        R_r (>= 0).
    base_height_mm : float
        Height of the profile's lowest line above the bottom edge (>= 0).
    direction : {"left", "right"}
        Sense in which the cam slides under the follower.  ``"left"`` (default)
        puts the follower at x = B on the cam (the CAM-DAS table reads left to
        right); ``"right"`` is its mirror image, x = length − B.  ``"right"``
        corresponds to the top of a cw disc cam.
    """

    roller_radius_mm: float
    base_height_mm: float = 0.0
    direction: str = "left"
    cam_kind = "translating"

    @property
    def sense(self) -> int:
        return 1 if self.direction == "right" else -1

    def validate(self) -> list[Problem]:
        p: list[Problem] = []
        if self.direction not in _DIRECTIONS:
            p.append(Problem("cam.direction", self.direction, "direction must be 'left' or 'right'",
                             'use direction = "left" (default) or "right"'))
        if _finite(self, p):
            _non_negative(p, "roller_radius_mm", self.roller_radius_mm)
            _non_negative(p, "base_height_mm", self.base_height_mm)
        return p
