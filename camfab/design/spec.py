"""The design as data (the TOML structure, a dict) → one immutable, validated :class:`DesignSpec`.

The keys are the user-facing contract of the design file (see the README).  Every
problem in a design is collected and reported together in one
:class:`~camfab.errors.SpecError`; each names the field path, the value, the rule
and a fix.  This module reads no files: :mod:`camfab.formats` reads TOML and xlsx
designs, and the knot file a ``[motion_table]`` names, and hands the data over.
Nothing here computes geometry: :meth:`DesignSpec.program` builds the (validated)
motion program, and mechanism geometry is checked by :mod:`camfab.design.mechanisms`.
"""
from __future__ import annotations

import functools
import math
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

from ..errors import Problem, SpecError
from ..limits import MAX_LENGTH_MM, MAX_LIFT_MM, MAX_SEGMENTS, data_problems
from ..records import dataclass, field
from ..units import DEG, RPM
from .drawing import DrawingSpec, drawing_section
from .kinds import CamKind, Direction, FollowerMotion, FollowerType, LiftUnit, Rotation
from .knots import KnotFile, KnotTable, build_knot_table
from .laws import law_names
from .mechanisms import MECHANISMS, mechanism_class, mechanism_from_spec
from .optional_sections import optional_sections
from .program import TWO_PI, MotionProgram, SegmentInput, build_program
from .resolve import END_KEYS
from .shop import (
    POSTS,
    AssemblySpec,
    MachiningSpec,
    ManufacturingSpec,
    OutputsSpec,
    assembly_section,
    depth_problems,
    machining_section,
    manufacturing_section,
    outputs_section,
)
from .sizing_spec import SizingSpec
from .validator import Validator

if TYPE_CHECKING:  # the readers of these sections are imported only by designs that have them
    from .cylinder_spec import CylinderSpec
    from .optimise_spec import OptimiseSpec
    from .strength_spec import StrengthSpec
    from .vibration_spec import VibrationSpec

__all__ = [
    "CamSpec",
    "FollowerSpec",
    "SegmentSpec",
    "ManufacturingSpec",
    "MachiningSpec",
    "OutputsSpec",
    "AssemblySpec",
    "DynamicsSpec",
    "DesignSpec",
    "DrawingSpec",
    "design_from_dict",
    "dynamics_items",
    "POSTS",
]


_TOP_KEYS = ("name", "description", "cam", "follower", "motion", "motion_table", "manufacturing", "machining",
             "outputs", "checks", "dynamics", "assembly", "drawing",
             "vibration", "strength", "materials", "cylinder",
             "sizing", "optimise")  # camfab size / camfab optimise: design/sizing_plan.py, design/optimise_spec.py
_CAM_KEYS = ("kind", "rotation", "direction", "speed_rpm", "omega_rad_s", "speed_mm_s")
_FOLLOWER_FLOATS = ("base_radius_mm", "roller_radius_mm", "offset_mm", "pivot_distance_mm",
                    "arm_length_mm", "face_offset_mm", "follower_distance_mm",
                    "second_roller_radius_mm", "follower_angle_deg", "cam_length_mm",
                    "base_height_mm", "width_mm", "rise_deg", "face_radius_mm", "backlash_mm", "groove_depth_mm")
_FOLLOWER_KEYS = ("type", "motion", *_FOLLOWER_FLOATS)
#: [follower] lengths that must be > 0, and those that may be 0 (the others lie in ±1e6)
_POSITIVE = ("base_radius_mm", "arm_length_mm", "cam_length_mm", "follower_distance_mm", "width_mm",
             "face_radius_mm", "groove_depth_mm")
_NON_NEGATIVE = ("roller_radius_mm", "pivot_distance_mm", "second_roller_radius_mm", "base_height_mm", "backlash_mm")
_SEGMENT_KEYS = ("law", "lift", "angle_deg", "length_mm", "shape", *END_KEYS)
_CHECK_KEYS = ("pressure_angle_limit_deg", "face_margin_mm")
#: [dynamics] keys by follower motion (the units are in the names) and for both
_DYN_TRANSLATING = ("mass_kg", "spring_rate_n_per_mm", "spring_preload_n", "damping_n_s_per_m", "external_force_n")
_DYN_OSCILLATING = ("inertia_kg_m2", "spring_rate_nm_per_deg", "spring_preload_nm", "damping_nm_s_per_deg",
                    "external_torque_nm")
_DYN_COMMON = ("friction_coefficient", "safety_force_n")


@dataclass(frozen=True, slots=True)
class CamSpec:
    """``[cam]``: kind, rotation sense and speed.

    ``omega_rad_s`` is the cam speed (rad/s) for rotating cams; when the file
    gives neither ``speed_rpm`` nor ``omega_rad_s`` it is 1 rad/s (the CAM-DAS
    default) and ``speed_given`` is False.  ``speed_mm_s`` is the travel speed
    of a translating cam.
    """

    kind: CamKind = CamKind.DISC
    rotation: Rotation = Rotation.CW
    omega_rad_s: float = 1.0
    speed_mm_s: float | None = None
    speed_given: bool = False
    direction: Direction = Direction.LEFT


@dataclass(frozen=True, slots=True)
class FollowerSpec:
    """``[follower]``: type, motion and geometry (mm, degrees).  Unused fields are None."""

    type: FollowerType = FollowerType.ROLLER
    motion: FollowerMotion = FollowerMotion.TRANSLATING
    base_radius_mm: float | None = None
    roller_radius_mm: float | None = None
    offset_mm: float | None = None
    pivot_distance_mm: float | None = None
    arm_length_mm: float | None = None
    face_offset_mm: float | None = None
    follower_distance_mm: float | None = None
    second_roller_radius_mm: float | None = None
    follower_angle_deg: float | None = None
    cam_length_mm: float | None = None
    base_height_mm: float | None = None
    width_mm: float | None = None
    rise_deg: float | None = None
    face_radius_mm: float | None = None
    #: groove cams: the groove's extra width over the roller diameter, and its depth in the plate
    backlash_mm: float | None = None
    groove_depth_mm: float | None = None

    @property
    def lift_unit(self) -> LiftUnit:
        """Degrees for oscillating followers, mm otherwise."""
        return LiftUnit.DEG if self.motion == FollowerMotion.OSCILLATING else LiftUnit.MM


@dataclass(frozen=True, slots=True)
class SegmentSpec:
    """One ``[[motion]]`` segment as written: law, signed lift, span (None = solve)."""

    law: str
    lift: float
    span: float | None  # degrees, or mm for translating cams
    shape: str | None = None
    ends: tuple[float | None, float | None, float | None] = (None, None, None)  # end_v, end_a, end_j per rad (mm)


@dataclass(frozen=True, slots=True)
class DynamicsSpec:
    """``[dynamics]``: the spring-loaded follower's mass, spring, damper and loads.

    Translating followers (and translating cams): ``mass_kg`` (required), ``spring_rate_n_per_mm``,
    ``spring_preload_n`` (the spring force at S = 0), ``damping_n_s_per_m``, ``external_force_n``
    (a constant load pressing the follower onto the cam, e.g. its weight).  Oscillating followers:
    ``inertia_kg_m2`` (about the pivot, required), ``spring_rate_nm_per_deg``, ``spring_preload_nm``,
    ``damping_nm_s_per_deg``, ``external_torque_nm``.  Both: ``friction_coefficient`` (sliding
    contacts: knife edges and faces, flat or curved) and ``safety_force_n`` (the smallest acceptable
    contact force).  Form-closed cams (conjugate, constant width/diameter) take no spring and no safety force.
    The fields of the other motion are None."""

    motion: FollowerMotion
    inertia: float
    spring_rate: float = 0.0
    spring_preload: float = 0.0
    damping: float = 0.0
    external: float = 0.0
    friction_coefficient: float = 0.0
    safety_force_n: float = 0.0

    @property
    def preload_unit(self) -> str:
        return "N·m" if self.motion == FollowerMotion.OSCILLATING else "N"


@dataclass(frozen=True)
class DesignSpec:
    """A validated design (immutable).  Build it with :func:`design_from_dict`, or read a file with
    :func:`camfab.formats.load_design`.

    ``motion_table`` is the ``[motion_table]`` section as written, its rows at hand: given inline
    (``rows``) or read from its ``file`` by the formats layer (a :class:`~camfab.design.knots.KnotFile`).
    ``source`` names the design file (None for a dict).
    """

    name: str
    cam: CamSpec
    follower: FollowerSpec
    motion: tuple[SegmentSpec, ...] | None
    motion_table: Mapping[str, Any] | None = None
    manufacturing: ManufacturingSpec = field(default_factory=ManufacturingSpec)
    outputs: OutputsSpec = field(default_factory=OutputsSpec)
    pressure_angle_limit_deg: float | None = None
    description: str = ""
    source: str | None = None
    face_margin_mm: float = 0.0
    dynamics: DynamicsSpec | None = None
    machining: MachiningSpec = field(default_factory=MachiningSpec)
    assembly: AssemblySpec = field(default_factory=AssemblySpec)
    drawing: DrawingSpec = field(default_factory=DrawingSpec)
    vibration: VibrationSpec | None = None
    #: ``[strength]`` / ``[materials.*]`` resolved (``camfab.design.strength_spec``); None when the contact-stress
    #: check does not apply (no ``[dynamics]``, no ``[strength]``)
    strength: StrengthSpec | None = None
    sizing: SizingSpec = field(default_factory=SizingSpec)
    optimise: OptimiseSpec | None = None
    #: ``[cylinder]`` of a cylindrical cam (:class:`~camfab.design.cylindrical.CylinderSpec`), else None
    cylinder: CylinderSpec | None = None

    @property
    def is_translating_cam(self) -> bool:
        return self.cam.kind == CamKind.TRANSLATING

    @property
    def speed(self) -> float:
        """Rate of the independent variable: ω (rad/s), or v (mm/s) for translating cams."""
        if self.is_translating_cam:
            return self.cam.speed_mm_s if self.cam.speed_mm_s is not None else 1.0
        return self.cam.omega_rad_s

    @property
    def sources(self) -> tuple[str, ...]:
        """The files this design was read from: the design file, then the knot file it names."""
        out = [self.source] if self.source else []
        file = self.motion_table.get("file") if self.motion_table is not None else None
        if isinstance(file, KnotFile):
            out.append(file.path)
        return tuple(out)

    @functools.cached_property
    def knot_table(self) -> KnotTable | None:
        """The validated :class:`~camfab.design.knots.KnotTable` of a ``[motion_table]`` (built once)."""
        return None if self.motion_table is None else build_knot_table(self.motion_table)

    @functools.cached_property
    def motion_program(self) -> MotionProgram:
        """The validated :class:`~camfab.design.program.MotionProgram` (built once)."""
        return _build_motion(self)

    def program(self) -> MotionProgram:
        """The validated :class:`~camfab.design.program.MotionProgram` of this design."""
        return self.motion_program


def dynamics_items(d: DynamicsSpec) -> list[tuple[str, float]]:
    """The ``[dynamics]`` keys (as in the design file, units in the names) and values of a spec."""
    own = _DYN_OSCILLATING if d.motion == FollowerMotion.OSCILLATING else _DYN_TRANSLATING
    vals = (d.inertia, d.spring_rate, d.spring_preload, d.damping, d.external)
    return [*zip(own, vals, strict=True), ("friction_coefficient", d.friction_coefficient),
            ("safety_force_n", d.safety_force_n)]


# ---------------------------------------------------------------------------
def design_from_dict(data: Mapping[str, Any], *, source: str | None = None) -> DesignSpec:
    """Validate a design given as a dict (the TOML structure) into a :class:`DesignSpec`.

    Parameters
    ----------
    data : Mapping
        The design; a ``[motion_table]`` gives its ``rows`` inline or a ``file`` already read by
        :mod:`camfab.formats` (a :class:`~camfab.design.knots.KnotFile`).
    source : str, optional
        The design file, named in messages.

    Raises
    ------
    SpecError
        Every problem found, each with its field path, value, rule and fix.
    """
    over = data_problems(data) if isinstance(data, Mapping) else []
    if over:  # nothing more is read from a design beyond the input limits
        raise SpecError(over, source)
    v = Validator()
    spec = _validate(v, data, source)
    problems = list(v.problems)
    program = _program_problems(spec, problems)
    _mechanism_problems(spec, program, problems)
    if problems:
        raise SpecError(problems, source)
    return spec


def _merge(problems: list[Problem], more: Sequence[Problem]) -> None:
    """Add the problems of a later rule, leaving out a field already reported (its first report stands)."""
    seen = {p.path for p in problems}
    problems.extend(p for p in more if p.path not in seen)


def _program_problems(spec: DesignSpec, problems: list[Problem]) -> MotionProgram | None:
    """The motion program, built whatever the other sections hold, its problems merged into ``problems``;
    None when it cannot be built, or when the sections it reads are broken ([[motion]] / [motion_table] as
    a whole, the cam kind, or the follower of a constant-width/diameter cam, whose law it sets)."""
    paths = {p.path for p in problems}
    if paths & {"motion", "motion_table", "cam.kind"} or (
            spec.cam.kind.symmetric and any(p.startswith("follower.") for p in paths)):
        return None
    try:
        return spec.program()
    except SpecError as exc:
        _merge(problems, exc.problems)
        return None


def _mechanism_problems(spec: DesignSpec, program: MotionProgram | None, problems: list[Problem]) -> None:
    """The mechanism's rules (``docs/decisions.md``: every family's dimensions, then those that need the
    motion), judged once [cam] and [follower] are valid; merged into ``problems``."""
    if any(p.path.startswith(("cam.", "follower.")) for p in problems):
        return
    if mechanism_class(spec.cam.kind, spec.follower.type, spec.follower.motion) is None:
        return
    mech = mechanism_from_spec(spec)
    found = mech.validate()
    if not found and program is not None:
        found = mech.validate_motion(program, bore_mm=spec.manufacturing.bore_mm or None)
    _merge(problems, found)


def _validate(v: Validator, data: Mapping[str, Any], source: str | None) -> DesignSpec:
    """Every section read into the spec, problems collected in ``v``."""
    v.keys(data, _TOP_KEYS, "")
    name = data.get("name", "cam")
    if not isinstance(name, str) or not name.strip():
        v.add("name", name, "must be a non-empty string", 'e.g. name = "Ejemplo9RT"')
        name = "cam"
    cam = _cam(v, v.table(data, "cam"))
    fol = _follower(v, v.table(data, "follower"), cam)
    motion, table = _motion(v, data, cam)
    mfg = manufacturing_section(v, v.table(data, "manufacturing"), fol.base_radius_mm,
                                cam.kind == CamKind.TRANSLATING)
    out = outputs_section(v, v.table(data, "outputs"))
    machining = machining_section(v, v.table(data, "machining"))
    assembly = assembly_section(v, v.table(data, "assembly"))
    depth_problems(v, mfg, machining, fol.groove_depth_mm)
    drawing = drawing_section(v, v.table(data, "drawing"), mfg.tolerance_mm)
    checks = v.table(data, "checks")
    v.keys(checks, _CHECK_KEYS, "checks")
    pa = v.number(checks, "pressure_angle_limit_deg", "checks", None, lo=0.0, hi=90.0, lo_open=True, hi_open=True)
    margin = v.number(checks, "face_margin_mm", "checks", 0.0, lo=0.0, hi=1e4)
    dyn = _dynamics(v, data, cam, fol)
    groove = fol.groove_depth_mm if cam.kind == CamKind.GROOVE else None  # the flanks: as high as the groove
    strength = None  # without these sections there is nothing to read or check: materials not imported
    if not {"strength", "materials", "dynamics"}.isdisjoint(data):
        from .strength_spec import strength_section

        strength = strength_section(v, data, thickness_mm=groove or mfg.thickness_mm, applies="dynamics" in data,
                                    manufacturing_material=mfg.material,
                                    assembly_roller_width_mm=assembly.roller_width_mm,
                                    face="the groove depth" if groove else "the plate thickness")
    return DesignSpec(name.strip(), cam, fol, motion, table, mfg, out, pressure_angle_limit_deg=pa,
                      description=str(data.get("description", "")), source=source, face_margin_mm=margin,
                      dynamics=dyn, machining=machining, assembly=assembly, drawing=drawing, strength=strength,
                      **optional_sections(v, data, cam.kind, fol.motion))


# ---------------------------------------------------------------------------
def _cam(v: Validator, t: Mapping[str, Any]) -> CamSpec:
    v.keys(t, _CAM_KEYS, "cam")
    kind = v.choice(t, "kind", "cam", CamKind, CamKind.DISC)
    rotation = v.choice(t, "rotation", "cam", Rotation, Rotation.CW)
    rpm = v.number(t, "speed_rpm", "cam", None, lo=0.0, lo_open=True, hi=1e6)
    omega = v.number(t, "omega_rad_s", "cam", None, lo=0.0, lo_open=True, hi=1e6)
    vmm = v.number(t, "speed_mm_s", "cam", None, lo=0.0, lo_open=True, hi=1e7)
    translating = kind == CamKind.TRANSLATING
    if rpm is not None and omega is not None:
        v.add("cam.speed_rpm", rpm, "give either speed_rpm or omega_rad_s, not both", "remove one of them")
    if translating and (rpm is not None or omega is not None):
        v.add("cam.speed_rpm" if rpm is not None else "cam.omega_rad_s", rpm or omega,
              "a translating cam has a linear speed", "use speed_mm_s")
    if not translating and vmm is not None:
        v.add("cam.speed_mm_s", vmm, "only translating cams have a linear speed", "use speed_rpm or omega_rad_s")
    direction = v.choice(t, "direction", "cam", Direction, Direction.LEFT)
    if "direction" in t and not translating:
        v.add("cam.direction", t["direction"], "only translating cams slide left or right",
              "use rotation = \"cw\" | \"ccw\" for rotating cams")
    given = rpm is not None or omega is not None or vmm is not None
    w = omega if omega is not None else (rpm * RPM if rpm is not None else 1.0)
    return CamSpec(kind, rotation, w, vmm, given, direction)


# ---------------------------------------------------------------------------
# [follower]: numbers, then the rules of the cam kind, then the keys that kind requires
def _follower(v: Validator, t: Mapping[str, Any], cam: CamSpec) -> FollowerSpec:
    v.keys(t, _FOLLOWER_KEYS, "follower")
    ftype = v.choice(t, "type", "follower", FollowerType, FollowerType.ROLLER)
    motion = v.choice(t, "motion", "follower", FollowerMotion, FollowerMotion.TRANSLATING)
    vals = _follower_numbers(v, t)
    if ftype == FollowerType.KNIFE:
        if vals["roller_radius_mm"] not in (None, 0.0):
            v.add("follower.roller_radius_mm", vals["roller_radius_mm"], "a knife-edge follower has no roller",
                  'remove roller_radius_mm or use type = "roller"')
        vals["roller_radius_mm"] = 0.0
    family = mechanism_class(cam.kind, ftype, motion)
    if family is None:
        v.add("follower.type", f"{motion} {ftype}", f"a {cam.kind.replace('_', '-')} cam has no {motion} {ftype} "
              "follower", "use one of: " + ", ".join(_followers_of(cam.kind)))
        return FollowerSpec(ftype, motion, **vals)
    if cam.kind.symmetric:
        _width_once(v, t, cam.kind, vals)
    for key in family.required:
        if key not in t and not (key == "roller_radius_mm" and ftype == FollowerType.KNIFE) and not (
                key == "width_mm" and vals["width_mm"] is not None):
            v.add(f"follower.{key}", None, f"is required for a {cam.kind.replace('_', '-')} cam with a {motion} "
                  f"{ftype} follower", f"add {key} = <{'degrees' if key.endswith('_deg') else 'mm'}> to [follower]")
    used = set(family.required) | set(family.optional) | {"type", "motion"}
    if cam.kind.symmetric:
        used.add("follower_distance_mm")  # the constant width's other name
    for key in t:
        if key in _FOLLOWER_KEYS and key not in used and not (key == "roller_radius_mm" and vals[key] == 0.0):
            v.add(f"follower.{key}", t[key], f"is not used by a {cam.kind.replace('_', '-')} cam with a {motion} "
                  f"{ftype} follower", "remove it (it would be ignored), or check the follower type and motion")
    return FollowerSpec(ftype, motion, **vals)


def _followers_of(kind: CamKind) -> list[str]:
    """The follower types and motions a cam kind has families for ("translating roller", …)."""
    return sorted(f"{m.value} {t.value}" for k, t, m in MECHANISMS if k == kind)


def _follower_numbers(v: Validator, t: Mapping[str, Any]) -> dict[str, float | None]:
    """Every ``[follower]`` number (None when absent), each checked against its range."""
    vals: dict[str, float | None] = {}
    for key in _FOLLOWER_FLOATS:
        if key in _POSITIVE:
            vals[key] = v.number(t, key, "follower", None, lo=0.0, lo_open=True, hi=MAX_LENGTH_MM,
                                 fix=f"{key} must be a positive length in mm")
        elif key in _NON_NEGATIVE:
            vals[key] = v.number(t, key, "follower", None, lo=0.0, hi=MAX_LENGTH_MM,
                                 fix=f"{key} must be a length >= 0 in mm")
        else:
            vals[key] = v.number(t, key, "follower", None, lo=-MAX_LENGTH_MM, hi=MAX_LENGTH_MM)
    return vals


def _width_once(v: Validator, t: Mapping[str, Any], kind: CamKind, vals: dict[str, float | None]) -> None:
    """Constant-width/diameter cams: the width, given once (``width_mm`` or ``follower_distance_mm``)."""
    if "width_mm" in t and "follower_distance_mm" in t:
        v.add("follower.follower_distance_mm", t["follower_distance_mm"],
              "give the constant width once", "keep width_mm and remove follower_distance_mm")
    elif vals["width_mm"] is None:
        vals["width_mm"] = vals["follower_distance_mm"]
    if vals["width_mm"] is None and "width_mm" not in t and "follower_distance_mm" not in t:
        v.add("follower.width_mm", None, f"is required for a {kind} cam",
              "add width_mm = <mm> (the constant width, > 2·base_radius_mm)")


# ---------------------------------------------------------------------------
# [[motion]] segments or a [motion_table]
def _motion(v: Validator, data: Mapping[str, Any],
            cam: CamSpec) -> tuple[tuple[SegmentSpec, ...] | None, dict[str, Any] | None]:
    has_seg, has_table = "motion" in data, "motion_table" in data
    if has_seg and has_table:
        v.add("motion_table", "...", "give either [[motion]] segments or a [motion_table], not both",
              "remove one of them")
        return None, None
    if has_table:
        table = data["motion_table"]
        if not isinstance(table, Mapping):
            v.add("motion_table", table, "must be a table", "write it as a [motion_table] section")
            return None, None
        return None, dict(table)
    if not has_seg:
        if not cam.kind.symmetric:  # a constant-width/diameter law follows from the width
            v.add("motion", None, "the design has no motion", "add [[motion]] segments or a [motion_table]")
        return None, None
    rows = data["motion"]
    if not isinstance(rows, list) or not all(isinstance(r, Mapping) for r in rows):
        v.add("motion", rows, "must be an array of tables", "write each segment as a [[motion]] block")
        return None, None
    if len(rows) > MAX_SEGMENTS:  # not read further (docs/decisions.md, "Input limits")
        v.add("motion", f"{len(rows)} segments", f"more than the limit of {MAX_SEGMENTS} segments",
              "join consecutive segments, or give the motion as a knot table ([motion_table])")
        return None, None
    span_key = "length_mm" if cam.kind == CamKind.TRANSLATING else "angle_deg"
    return tuple(_segment(v, r, f"motion[{i}]", span_key) for i, r in enumerate(rows)), None


def _segment(v: Validator, r: Mapping[str, Any], p: str, span_key: str) -> SegmentSpec:
    """One ``[[motion]]`` segment; its span is in ``span_key`` (degrees, or mm on a translating cam).

    A value reported here is kept as written (a law) or as NaN (a number), so that the program's own rules
    skip it (and do not report it again) while judging the rest."""
    v.keys(r, _SEGMENT_KEYS, p)
    law = r.get("law", "dwell" if r.get("lift", 0) == 0 else None)
    laws = law_names()
    if law not in laws:
        import difflib  # only for a misspelt name

        close = difflib.get_close_matches(str(law), laws, n=1)
        v.add(f"{p}.law", law, "unknown motion law" if law is not None else "is required",
              f"did you mean '{close[0]}'?" if close else "use one of: " + ", ".join(laws))
    n = len(v.problems)
    lift = v.number(r, "lift", p, 0.0, lo=-MAX_LIFT_MM, hi=MAX_LIFT_MM)
    if len(v.problems) > n:
        lift = math.nan
    other = "angle_deg" if span_key == "length_mm" else "length_mm"
    if other in r:
        v.add(f"{p}.{other}", r[other], f"this cam measures segments in {span_key}", f"rename it to {span_key}")
    span_raw = r.get(span_key)
    span = None
    if span_raw is None:
        v.add(f"{p}.{span_key}", None, "is required", f"give {span_key} (or \"auto\" for a half-period law)")
        span = math.nan
    elif span_raw != "auto":
        span = v.number(r, span_key, p, None, lo=0.0, lo_open=True,
                        hi=360.0 if span_key == "angle_deg" else MAX_LENGTH_MM)
        if span is None:
            span = math.nan  # already reported
    ends = tuple(v.number(r, k, p, math.nan) if k in r else None for k in END_KEYS)  # NaN: reported
    return SegmentSpec("" if law is None else str(law), lift, span, r.get("shape"), ends)  # type: ignore[arg-type]


# ---------------------------------------------------------------------------
# [dynamics]: the keys of the follower's motion, form closure, the speed, then the numbers
def _dynamics(v: Validator, data: Mapping[str, Any], cam: CamSpec, fol: FollowerSpec) -> DynamicsSpec | None:
    if "dynamics" not in data:
        return None
    t = v.table(data, "dynamics")
    if cam.kind == CamKind.CYLINDRICAL:  # six developed contacts, no force model yet
        v.add("dynamics", "...", "a cylindrical cam has no force model yet",
              "remove [dynamics] (and [vibration]); the geometry checks do not need it")
        return None
    osc = fol.motion == FollowerMotion.OSCILLATING and cam.kind != CamKind.TRANSLATING
    own = _DYN_OSCILLATING if osc else _DYN_TRANSLATING
    _dynamics_keys(v, t, osc)
    if cam.kind.form_closed:
        for k in (own[1], own[2], "safety_force_n"):
            if k in t:
                v.add(f"dynamics.{k}", t[k], f"a {cam.kind.replace('_', '-')} cam drives its follower both ways "
                      "(form closure): it has no return spring and cannot jump", f"remove {k}")
    if not cam.speed_given:
        key = "speed_mm_s" if cam.kind == CamKind.TRANSLATING else "speed_rpm"
        v.add(f"cam.{key}", None, "dynamics needs the cam speed", f"add {key} = ... to [cam]")
    m = v.number(t, own[0], "dynamics", None, lo=0.0, lo_open=True, hi=1e9,
                 fix=f"give the {'arm inertia about its pivot' if osc else 'moving mass'} (> 0)")
    if own[0] not in t:
        v.add(f"dynamics.{own[0]}", None, "is required", f"add {own[0]} = ... ("
              f"{'the arm and roller about the pivot' if osc else 'follower, spring share and attached parts'})")
    values = _dynamics_values(v, t, own)
    if values[4] and fol.type == FollowerType.ROLLER and (fol.roller_radius_mm or 0.0) > 0:
        v.add("dynamics.friction_coefficient", values[4], "a roller rolls on the cam (no sliding friction is "
              "modelled)", "remove friction_coefficient, or model a knife edge, flat or curved face")
    if m is None:
        return None
    motion = FollowerMotion.OSCILLATING if osc else FollowerMotion.TRANSLATING
    return DynamicsSpec(motion, m, *values)


def _dynamics_keys(v: Validator, t: Mapping[str, Any], osc: bool) -> None:
    """Unknown keys, and the keys of the other follower motion named as such."""
    own, other = (_DYN_OSCILLATING, _DYN_TRANSLATING) if osc else (_DYN_TRANSLATING, _DYN_OSCILLATING)
    kind = "an oscillating" if osc else "a translating"
    for k in t:
        if k in other:
            v.add(f"dynamics.{k}", t[k], f"is for {'translating' if osc else 'oscillating'} followers",
                  f"{kind} follower takes: " + ", ".join(own))
    v.keys({k: t[k] for k in t if k not in other}, own + _DYN_COMMON, "dynamics")


def _dynamics_values(v: Validator, t: Mapping[str, Any], own: tuple[str, ...]) -> tuple[float, ...]:
    """Spring rate, preload, damping, external load, friction coefficient and safety force."""
    big = 1e9
    return (v.number(t, own[1], "dynamics", 0.0, lo=0.0, hi=big),
            v.number(t, own[2], "dynamics", 0.0, lo=-big, hi=big),
            v.number(t, own[3], "dynamics", 0.0, lo=0.0, hi=big),
            v.number(t, own[4], "dynamics", 0.0, lo=-big, hi=big),
            v.number(t, "friction_coefficient", "dynamics", 0.0, lo=0.0, hi=2.0),
            v.number(t, "safety_force_n", "dynamics", 0.0, lo=0.0, hi=big))


# ---------------------------------------------------------------------------
# the motion program
def _symmetric_law(spec: DesignSpec) -> MotionProgram:
    """The fixed constant-width/diameter law: SHM rise, dwell, SHM return, dwell; h = width − 2·Rb."""
    f = spec.follower
    h = (f.width_mm or 0.0) - (f.base_radius_mm or 0.0) * 2
    r = f.rise_deg or 120.0
    if h <= 0 or not 0 < r <= 180:
        raise SpecError(Problem("follower.width_mm", f.width_mm,
                                f"the width must exceed the base diameter {2 * (f.base_radius_mm or 0):g} mm and "
                                "rise_deg lie in (0, 180]", "increase width_mm or fix rise_deg"), spec.source)
    dwell = [("dwell", 0.0, 180.0 - r)] if r < 180.0 else []
    return MotionProgram.from_segments([("simple_harmonic", h, r), *dwell, ("simple_harmonic", -h, r), *dwell])


def _build_motion(spec: DesignSpec) -> MotionProgram:
    if spec.knot_table is not None:
        return spec.knot_table.program()
    if spec.motion is None:
        if spec.cam.kind.symmetric:
            return _symmetric_law(spec)
        raise SpecError(Problem("motion", None, f"no motion law for a {spec.cam.kind} cam",
                                "add [[motion]] segments"), spec.source)
    if spec.is_translating_cam:
        length = spec.follower.cam_length_mm or sum(s.span or 0.0 for s in spec.motion)
        inputs = [SegmentInput(s.law, s.lift, s.span, s.shape, s.ends) for s in spec.motion]
        return build_program(inputs, period=length, unit="mm", source=spec.source)
    inputs = [SegmentInput(s.law, s.lift, None if s.span is None else s.span * DEG, s.shape, s.ends)
              for s in spec.motion]
    return build_program(inputs, period=TWO_PI, unit="rad", source=spec.source, lift_unit=spec.follower.lift_unit)
