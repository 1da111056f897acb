"""Typed results: finding codes, severities and verdicts, the one finding record, and the frozen
summaries of the motion analysis, the profile checks and the follower dynamics.

Presenters read attributes; ``to_dict()`` is the one JSON seam (the ``check --json`` and
``motion --json`` objects, whose keys and key order are fixed).  Angles and positions in a
summary are in user units: degrees of cam angle, or mm of travel for a translating cam (the
JSON keys say ``_deg`` either way).
"""
from __future__ import annotations

from collections.abc import Iterable, Iterator
from enum import StrEnum
from typing import Any, Protocol

import numpy as np

from .records import dataclass

__all__ = [
    "Severity",
    "Verdict",
    "IssueCode",
    "Finding",
    "Extreme",
    "Maximum",
    "MotionPeaks",
    "Junction",
    "MotionReport",
    "Curvature",
    "PressureAngle",
    "FaceLength",
    "pair_names",
    "Preload",
    "JumpSpeed",
    "DynamicsSummary",
    "DynamicsReport",
    "CheckReport",
    "JsonPart",
    "CURVATURE_CODES",
    "JUMP_CODES",
    "FORCE_CODES",
]


class Severity(StrEnum):
    """How much a finding matters: an error makes the cam unacceptable."""

    ERROR = "error"
    WARNING = "warning"
    INFO = "info"


class Verdict(StrEnum):
    """The CAM-DAS verdict, from best to worst."""

    ACCEPTABLE = "acceptable"
    NOT_FOR_HIGH_SPEED = "not_for_high_speed"
    UNACCEPTABLE = "unacceptable"

    @classmethod
    def of(cls, findings: Iterable[Finding]) -> Verdict:
        """Any error → unacceptable; else a jerk or (allowed) acceleration jump → not for high
        speed; else acceptable."""
        findings = list(findings)
        if any(f.severity is Severity.ERROR for f in findings):
            return cls.UNACCEPTABLE
        if any(f.code in (IssueCode.JERK_DISCONTINUITY, IssueCode.ACCELERATION_DISCONTINUITY) for f in findings):
            return cls.NOT_FOR_HIGH_SPEED
        return cls.ACCEPTABLE

    @classmethod
    def worst(cls, *verdicts: Verdict | str) -> Verdict:
        """The worst of several verdicts."""
        order = list(cls)
        return max((cls(v) for v in verdicts), key=order.index)


class IssueCode(StrEnum):
    """Every finding code (stable strings: they are written to JSON and printed)."""

    # motion: continuity at the junctions and the internal breaks of piecewise laws
    VELOCITY_DISCONTINUITY = "VELOCITY_DISCONTINUITY"
    ACCELERATION_DISCONTINUITY = "ACCELERATION_DISCONTINUITY"
    JERK_DISCONTINUITY = "JERK_DISCONTINUITY"
    # knot tables
    KNOT_INCONSISTENT = "KNOT_INCONSISTENT"
    # profile geometry
    UNDERCUT = "UNDERCUT"
    CUSP = "CUSP"
    CONCAVE_RADIUS_BELOW_ROLLER = "CONCAVE_RADIUS_BELOW_ROLLER"
    PRESSURE_ANGLE_EXCEEDED = "PRESSURE_ANGLE_EXCEEDED"
    FACE_LENGTH = "FACE_LENGTH"
    # follower dynamics
    FOLLOWER_JUMP = "FOLLOWER_JUMP"
    CONTACT_FORCE_BELOW_SAFETY = "CONTACT_FORCE_BELOW_SAFETY"
    SELF_LOCKING = "SELF_LOCKING"
    LOAD_REVERSAL = "LOAD_REVERSAL"
    # follower vibration (the elastic follower train, [vibration])
    FOLLOWER_SEPARATES_VIBRATION = "FOLLOWER_SEPARATES_VIBRATION"
    VIBRATION_RESONANCE = "VIBRATION_RESONANCE"
    # contact stress (Hertz)
    CONTACT_STRESS_ABOVE_LIMIT = "CONTACT_STRESS_ABOVE_LIMIT"
    # G-code verification
    PARSE_WARNING = "PARSE_WARNING"
    NO_CUTTING_MOVES = "NO_CUTTING_MOVES"
    NO_FINISH_PASS = "NO_FINISH_PASS"
    FEED_MISSING = "FEED_MISSING"
    SPINDLE_OFF = "SPINDLE_OFF"
    ARC_RADIUS_MISMATCH = "ARC_RADIUS_MISMATCH"
    DEVIATION = "DEVIATION"
    GOUGE = "GOUGE"
    RAPID_BELOW_SAFE = "RAPID_BELOW_SAFE"
    RAPID_INTO_STOCK = "RAPID_INTO_STOCK"
    RAPID_THROUGH_PART = "RAPID_THROUGH_PART"
    COVERAGE = "COVERAGE"
    PARSE_ERROR = "PARSE_ERROR"
    MODAL_STATE = "MODAL_STATE"
    FEED_OUT_OF_RANGE = "FEED_OUT_OF_RANGE"
    SPINDLE_DIRECTION = "SPINDLE_DIRECTION"
    SPINDLE_SPEED = "SPINDLE_SPEED"
    COOLANT = "COOLANT"
    TOOL = "TOOL"
    TOOL_LENGTH_OFFSET = "TOOL_LENGTH_OFFSET"
    FINISH_DEPTH = "FINISH_DEPTH"
    TOO_DEEP = "TOO_DEEP"
    STEP_DOWN = "STEP_DOWN"
    DIRECTION = "DIRECTION"
    RETRACT_MISSING = "RETRACT_MISSING"
    # cutter-radius compensation (simulated as the controller runs it)
    COMP_ENTRY = "COMP_ENTRY"
    COMP_EXIT = "COMP_EXIT"
    COMP_ARC_RADIUS = "COMP_ARC_RADIUS"
    COMP_CORNER = "COMP_CORNER"
    COMP_SIDE_CHANGE = "COMP_SIDE_CHANGE"
    COMP_WRONG_SIDE = "COMP_WRONG_SIDE"


#: the findings about the profile's curvature (undercut, cusp, too tight for the cutter)
CURVATURE_CODES = (IssueCode.UNDERCUT, IssueCode.CUSP, IssueCode.CONCAVE_RADIUS_BELOW_ROLLER)
#: the motion's continuity findings, by the quantity that jumps
JUMP_CODES = {"V": IssueCode.VELOCITY_DISCONTINUITY, "A": IssueCode.ACCELERATION_DISCONTINUITY,
              "J": IssueCode.JERK_DISCONTINUITY}
#: the findings of a spring-loaded follower's contact force
FORCE_CODES = (IssueCode.FOLLOWER_JUMP, IssueCode.CONTACT_FORCE_BELOW_SAFETY, IssueCode.SELF_LOCKING)


def _plain(v: Any) -> Any:
    """numpy scalars → Python numbers, enums → their strings (JSON-ready)."""
    if isinstance(v, StrEnum):
        return v.value
    if isinstance(v, (np.floating, np.integer)):
        return v.item()
    return v


@dataclass(frozen=True)
class Finding:
    """One coded result of a check, an analysis or a verification.

    Attributes
    ----------
    code : IssueCode
    severity : Severity
    from_deg, to_deg : float or None
        Where: cam angle in degrees (mm of travel for a translating cam); a range through 360° has
        ``from_deg > to_deg``; one point has them equal.
    value, limit : float or None
        The worst value found and the limit it is judged against (units of the finding).
    message : str
        The finding in words, with its fix.
    line : int or None
        G-code findings: the program line (1-based) when known.
    """

    code: IssueCode
    severity: Severity
    from_deg: float | None
    to_deg: float | None
    value: float | None
    limit: float | None
    message: str
    line: int | None = None

    @classmethod
    def at_line(cls, code: IssueCode, message: str, line: int | None = None,
                severity: Severity = Severity.ERROR) -> Finding:
        """A G-code finding: a code, a sentence and the program line (1-based) when known."""
        return cls(code, severity, None, None, None, None, message, line)

    def to_dict(self) -> dict[str, Any]:
        """The ``findings`` item of ``check --json``."""
        return {"code": self.code.value, "severity": self.severity.value, "from_deg": _plain(self.from_deg),
                "to_deg": _plain(self.to_deg), "value": _plain(self.value), "limit": _plain(self.limit),
                "message": self.message}


@dataclass(frozen=True)
class Extreme:
    """Smallest and largest value of a quantity and where they are (user units)."""

    min: float
    at_min: float | None
    max: float
    at_max: float | None

    def to_dict(self) -> dict[str, Any]:
        return {"min": _plain(self.min), "max": _plain(self.max), "at_min_deg": _plain(self.at_min),
                "at_max_deg": _plain(self.at_max)}

    def scaled(self, k: float) -> Extreme:
        """The extreme of k·quantity for k > 0."""
        return Extreme(self.min * k, self.at_min, self.max * k, self.at_max)


@dataclass(frozen=True)
class Maximum:
    """Largest value of a quantity and where it is."""

    max: float
    at_max: float | None

    def to_dict(self) -> dict[str, Any]:
        return {"max": _plain(self.max), "at_max_deg": _plain(self.at_max)}


# ---------------------------------------------------------------------------
# motion
@dataclass(frozen=True)
class MotionPeaks:
    """Peaks of S, V, A, J in time units (lift unit, /s, /s², /s³)."""

    S: Extreme
    V: Extreme
    A: Extreme
    J: Extreme

    def items(self) -> Iterator[tuple[str, Extreme]]:
        """``("S", extreme), ("V", …), ("A", …), ("J", …)``."""
        return iter((("S", self.S), ("V", self.V), ("A", self.A), ("J", self.J)))

    def to_dict(self) -> dict[str, dict[str, Any]]:
        return {q: {"max": _plain(e.max), "min": _plain(e.min), "at_max_deg": _plain(e.at_max),
                    "at_min_deg": _plain(e.at_min)} for q, e in self.items()}


@dataclass(frozen=True)
class Junction:
    """A segment junction: where (user units), its continuity (``"C2"`` …), the segment it starts."""

    at: float
    continuity: str
    segment: int

    def to_dict(self) -> dict[str, Any]:
        return {"at_deg": _plain(self.at), "continuity": self.continuity, "segment": self.segment}


@dataclass(frozen=True)
class MotionReport:
    """Everything ``camfab motion`` prints, in user units (deg, mm or deg, seconds)."""

    name: str
    lift_unit: str
    x_unit: str  # "deg" for rotating cams, "mm" for translating cams
    speed: float  # rad/s or mm/s
    peaks_mode: str
    peaks: MotionPeaks
    junctions: tuple[Junction, ...]
    findings: tuple[Finding, ...] = ()

    @property
    def verdict(self) -> Verdict:
        return Verdict.of(self.findings)

    @property
    def has_errors(self) -> bool:
        return any(f.severity is Severity.ERROR for f in self.findings)

    def to_dict(self) -> dict[str, Any]:
        """The ``motion --json`` object (without the segment table)."""
        return {"name": self.name, "verdict": self.verdict.value, "peaks": self.peaks.to_dict(),
                "peaks_mode": self.peaks_mode, "junctions": [j.to_dict() for j in self.junctions],
                "findings": [f.to_dict() for f in self.findings],
                "units": {"x": self.x_unit, "S": self.lift_unit, "V": f"{self.lift_unit}/s",
                          "A": f"{self.lift_unit}/s2", "J": f"{self.lift_unit}/s3"},
                "speed": self.speed}


# ---------------------------------------------------------------------------
# profile checks
@dataclass(frozen=True)
class Curvature:
    """Radius-of-curvature summary (mm; positive = convex).

    ``min_convex`` is the smallest convex profile radius and ``min_concave`` the smallest concave
    one (as a positive radius), with where they are; ``pitch_min_convex`` the smallest convex
    pitch-curve radius (rollers); ``max`` the largest profile radius (flat faces).  None where a
    quantity does not apply or does not occur.
    """

    min_convex: float | None
    at_min_convex: float | None
    min_concave: float | None
    at_min_concave: float | None
    pitch_min_convex: float | None
    max: float | None

    def merged(self, other: Curvature) -> Curvature:
        """The summary of two profiles: the smaller minima (with their places), the larger maximum."""
        def low(a, at_a, b, at_b):
            return (b, at_b) if b is not None and (a is None or b < a) else (a, at_a)

        convex, at_convex = low(self.min_convex, self.at_min_convex, other.min_convex, other.at_min_convex)
        concave, at_concave = low(self.min_concave, self.at_min_concave, other.min_concave, other.at_min_concave)
        pitch, _ = low(self.pitch_min_convex, None, other.pitch_min_convex, None)
        big = other.max if other.max is not None and (self.max is None or other.max > self.max) else self.max
        return Curvature(convex, at_convex, concave, at_concave, pitch, big)

    def to_dict(self) -> dict[str, Any]:
        return {"min_convex": _plain(self.min_convex), "min_concave": _plain(self.min_concave),
                "at_deg": _plain(self.at_min_convex), "at_min_concave_deg": _plain(self.at_min_concave),
                "pitch_min_convex": _plain(self.pitch_min_convex), "max": _plain(self.max)}


@dataclass(frozen=True)
class PressureAngle(Extreme):
    """Signed pressure-angle extremes (degrees) and the limit on |δ| they are judged against."""

    limit: float = 0.0

    def merged(self, other: PressureAngle) -> PressureAngle:
        """Two profiles: the larger maximum and the smaller minimum (the first profile's limit)."""
        mx, at_mx = (other.max, other.at_max) if other.max > self.max else (self.max, self.at_max)
        mn, at_mn = (other.min, other.at_min) if other.min < self.min else (self.min, self.at_min)
        return PressureAngle(mn, at_mn, mx, at_mx, self.limit)

    def to_dict(self) -> dict[str, Any]:
        return {"max": _plain(self.max), "min": _plain(self.min), "at_max_deg": _plain(self.at_max),
                "at_min_deg": _plain(self.at_min), "limit": _plain(self.limit)}


@dataclass(frozen=True)
class FaceLength:
    """Faces (flat or curved): where the contact runs along the face (mm, ``min``/``max``) and, for a translating
    face, the length needed each side of the stem (``left``/``right``, margin included; None for an
    oscillating face, whose position is measured from the vertex)."""

    left: float | None
    right: float | None
    min: float
    max: float

    def merged(self, other: FaceLength) -> FaceLength:
        """Two profiles: the longer lengths and the wider contact range."""
        def big(a, b):
            return b if a is None else (a if b is None else max(a, b))

        return FaceLength(big(self.left, other.left), big(self.right, other.right), min(self.min, other.min),
                          max(self.max, other.max))

    def to_dict(self) -> dict[str, Any]:
        return {"left": _plain(self.left), "right": _plain(self.right), "min": _plain(self.min),
                "max": _plain(self.max)}


# ---------------------------------------------------------------------------
# follower dynamics
@dataclass(frozen=True)
class Preload:
    """The spring preload (N, or N·m for an arm) that keeps the contact force at the safety force
    everywhere, and the angle where it binds."""

    value: float
    unit: str
    at: float

    def to_dict(self) -> dict[str, Any]:
        return {"value": _plain(self.value), "unit": self.unit, "at_deg": _plain(self.at)}


@dataclass(frozen=True)
class JumpSpeed:
    """The speed (rpm, or mm/s for a translating cam) at which the contact force first falls to the
    safety force, and where; ``value`` None when it never does."""

    value: float | None
    unit: str
    at: float | None

    def to_dict(self) -> dict[str, Any]:
        return {"value": _plain(self.value), "unit": self.unit, "at_deg": _plain(self.at)}


def pair_names(flanks: bool) -> tuple[str, str]:
    """The two contacts of a form-closed follower as tables and plots label them: a groove's one roller between its
    inner and outer flank (``flanks``), else follower 1 and follower 2 (a conjugate pair, a constant-width or
    -diameter cam)."""
    return ("inner flank", "outer flank") if flanks else ("follower 1", "follower 2")


@dataclass(frozen=True)
class DynamicsSummary:
    """Follower forces at the design speed (N, N·m, J, W).

    Attributes
    ----------
    form_closed : bool
        The cam drives its follower both ways (conjugate, constant width/diameter).
    contact_force : Extreme
        Contact force N (follower 1's for a form-closed follower).
    safety_force_n : float or None
        Smallest acceptable contact force (None for a form-closed follower).
    bearing_force : Maximum
        Load on the camshaft bearings.
    drive : Extreme
        Drive torque (N·m), or drive force along the travel (N) of a translating cam (``torque``).
    torque : bool
        ``drive`` is a torque.
    work_per_cycle_j, mean_power_w : float
        Energy lost to damping and friction per cycle, and its mean power.
    preload_needed : Preload or None
        Spring-loaded followers only.
    jump_speed : JumpSpeed or None
        Spring-loaded followers only.
    second_contact_force : Extreme or None
        Form-closed followers: follower 2's contact force.
    load_reversals : tuple of (from, to) or None
        Form-closed followers: where the load passes to the other follower.
    flanks : bool
        A groove cam: the two contacts are its inner and outer flank (:attr:`contact_names`), not two followers.
    """

    form_closed: bool
    contact_force: Extreme
    safety_force_n: float | None
    bearing_force: Maximum
    drive: Extreme
    torque: bool
    work_per_cycle_j: float
    mean_power_w: float
    preload_needed: Preload | None = None
    jump_speed: JumpSpeed | None = None
    second_contact_force: Extreme | None = None
    load_reversals: tuple[tuple[float, float], ...] | None = None
    flanks: bool = False

    @property
    def contact_names(self) -> tuple[str, str]:
        """The labels of a form-closed follower's two contacts (:func:`pair_names`)."""
        return pair_names(self.flanks)

    def to_dict(self) -> dict[str, Any]:
        """The ``dynamics`` object of ``check --json``."""
        out: dict[str, Any] = {
            "form_closed": self.form_closed, "contact_force_n": self.contact_force.to_dict(),
            "safety_force_n": _plain(self.safety_force_n), "bearing_force_n": self.bearing_force.to_dict(),
            ("drive_torque_nm" if self.torque else "drive_force_n"): self.drive.to_dict(),
            "work_per_cycle_j": _plain(self.work_per_cycle_j), "mean_power_w": _plain(self.mean_power_w)}
        if self.form_closed:
            out["second_contact_force_n"] = None if self.second_contact_force is None else \
                self.second_contact_force.to_dict()
        out["preload_needed"] = None if self.preload_needed is None else self.preload_needed.to_dict()
        out["jump_speed"] = None if self.jump_speed is None else self.jump_speed.to_dict()
        if self.form_closed:
            out["load_reversals_deg"] = [[_plain(a), _plain(b)] for a, b in self.load_reversals or ()]
        return out


@dataclass(frozen=True)
class DynamicsReport:
    """Summary and findings of the follower dynamics."""

    summary: DynamicsSummary
    findings: tuple[Finding, ...]


# ---------------------------------------------------------------------------
# the check report
class JsonPart(Protocol):
    """A summary kept outside this module that writes its own part of ``check --json``."""

    def to_dict(self) -> dict[str, Any]: ...



@dataclass(frozen=True)
class CheckReport:
    """The profile checks of a cam (the ``camfab check`` report): findings, verdict, conclusions.

    Attributes
    ----------
    name : str
    findings : tuple of Finding
        In order: motion, per profile (curvature, pressure angle or face), dynamics, knot table.
    motion : MotionReport or None
        The motion's peaks and junctions.
    x_unit : str
        ``"deg"`` (disc cams) or ``"mm"`` (translating cam).
    curvature, pressure_angle, face_length : summaries or None
        None where they do not apply (no pressure angle for flat faces, no face for rollers).
    base_radius_mm, max_radius_mm : float or None
        Smallest and largest distance of the profile(s) from the cam centre (disc cams).
    area_mm2 : float or None
        Area enclosed by the profile (translating cam: between the profile and the bottom edge).
    dynamics : DynamicsSummary or None
        With a ``[dynamics]`` section.
    initial_arm_angle_deg : float or None
        Oscillating followers.
    vibration : JsonPart or None
        With a ``[vibration]`` section: a :class:`camfab.design.vibration_results.VibrationSummary`.
    contact_stress : camfab.design.strength.ContactStressSummary or None
        With a ``[dynamics]`` or ``[strength]`` section (its ``to_dict`` is the ``contact_stress`` object).
    """

    name: str
    findings: tuple[Finding, ...]
    motion: MotionReport | None = None
    x_unit: str = "deg"
    curvature: Curvature | None = None
    pressure_angle: PressureAngle | None = None
    face_length: FaceLength | None = None
    base_radius_mm: float | None = None
    max_radius_mm: float | None = None
    area_mm2: float | None = None
    dynamics: DynamicsSummary | None = None
    initial_arm_angle_deg: float | None = None
    vibration: JsonPart | None = None
    contact_stress: JsonPart | None = None
    #: cylindrical cams: the radii checked, the roller and its slip (``camfab.design.cylindrical``), JSON-ready
    cylinder: dict[str, Any] | None = None

    @property
    def verdict(self) -> Verdict:
        return Verdict.of(self.findings)

    def codes(self) -> set[IssueCode]:
        """The codes of the findings."""
        return {f.code for f in self.findings}

    def by_code(self, code: IssueCode | str) -> list[Finding]:
        """The findings with one code."""
        return [f for f in self.findings if f.code == code]

    def to_dict(self) -> dict[str, Any]:
        """The ``check --json`` object (JSON-ready: floats, str, None, lists, dicts)."""
        out: dict[str, Any] = {"name": self.name, "verdict": self.verdict.value}
        if self.motion is not None:
            out["peaks"] = self.motion.peaks.to_dict()
            out["junctions"] = [j.to_dict() for j in self.motion.junctions]

        def part(v):
            return None if v is None else v.to_dict()

        out.update({"pressure_angle_deg": part(self.pressure_angle), "radius_of_curvature_mm": part(self.curvature),
                    "face_length_mm": part(self.face_length), "base_radius_mm": _plain(self.base_radius_mm),
                    "max_radius_mm": _plain(self.max_radius_mm), "area_mm2": _plain(self.area_mm2),
                    "dynamics": part(self.dynamics), "initial_arm_angle_deg": _plain(self.initial_arm_angle_deg),
                    "x_unit": self.x_unit, "findings": [f.to_dict() for f in self.findings]})
        out["vibration"] = part(self.vibration)
        out["contact_stress"] = part(self.contact_stress)
        out["cylinder"] = self.cylinder
        return out
