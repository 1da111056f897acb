"""The design file: TOML (or a dict) → one immutable, validated :class:`DesignSpec`.

The keys are the user-facing contract of ``../shared/design.md`` §6.  Every
problem in a file is collected and reported together in one
:class:`~camfab.errors.SpecError`; each names the field path, the value, the
rule and a fix.  Nothing here computes geometry: :meth:`DesignSpec.program`
builds the (validated) motion program, and mechanism geometry is checked by
:mod:`camfab.design.mechanisms`.
"""
from __future__ import annotations

import difflib
import functools
import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Mapping

from ..errors import Problem, SpecError
from ..tolerances import MAX_EXPORT_TOL_MM, MIN_EXPORT_TOL_MM, DEFAULT_EXPORT_TOL_MM
from ..units import DEG, RPM
from .laws import law_names

__all__ = [
    "CamSpec",
    "FollowerSpec",
    "SegmentSpec",
    "ManufacturingSpec",
    "OutputsSpec",
    "DynamicsSpec",
    "DesignSpec",
    "load_design",
    "design_from_dict",
    "CAM_KINDS",
    "POSTS",
]

CAM_KINDS = ("disc", "conjugate", "constant_width", "constant_diameter", "translating")
FOLLOWER_TYPES = ("roller", "flat", "knife", "curved")
FOLLOWER_MOTIONS = ("translating", "oscillating")
ROTATIONS = ("cw", "ccw")
POSTS = ("linuxcnc", "fanuc", "grbl")

_TOP_KEYS = ("name", "description", "cam", "follower", "motion", "motion_table", "manufacturing",
             "outputs", "checks", "dynamics")
_CAM_KEYS = ("kind", "rotation", "direction", "speed_rpm", "omega_rad_s", "speed_mm_s")
_FOLLOWER_FLOATS = ("base_radius_mm", "roller_radius_mm", "offset_mm", "pivot_distance_mm",
                    "arm_length_mm", "face_offset_mm", "follower_distance_mm",
                    "second_roller_radius_mm", "follower_angle_deg", "cam_length_mm",
                    "base_height_mm", "width_mm", "rise_deg", "face_radius_mm")
_FOLLOWER_KEYS = ("type", "motion", *_FOLLOWER_FLOATS)
_SEGMENT_KEYS = ("law", "lift", "angle_deg", "length_mm", "shape")
_MFG_KEYS = ("thickness_mm", "bore_mm", "keyway", "hub_diameter_mm", "hub_length_mm",
             "tool_diameter_mm", "tolerance_mm", "material")
_OUTPUT_KEYS = ("dxf", "step", "stl", "gcode", "report", "xlsx", "drawing", "lift_table")
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

    kind: str = "disc"
    rotation: str = "cw"
    omega_rad_s: float = 1.0
    speed_mm_s: float | None = None
    speed_given: bool = False
    direction: str = "left"


@dataclass(frozen=True, slots=True)
class FollowerSpec:
    """``[follower]``: type, motion and geometry (mm, degrees).  Unused fields are None."""

    type: str = "roller"
    motion: str = "translating"
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

    @property
    def lift_unit(self) -> str:
        """'deg' for oscillating followers, 'mm' otherwise."""
        return "deg" if self.motion == "oscillating" else "mm"


@dataclass(frozen=True, slots=True)
class SegmentSpec:
    """One ``[[motion]]`` segment as written: law, signed lift, span (None = solve)."""

    law: str
    lift: float
    span: float | None  # degrees, or mm for translating cams
    shape: str | None = None


@dataclass(frozen=True, slots=True)
class ManufacturingSpec:
    """``[manufacturing]``: stock and tool (mm)."""

    thickness_mm: float = 10.0
    bore_mm: float = 0.0
    keyway: bool = False
    hub_diameter_mm: float | None = None
    hub_length_mm: float | None = None
    tool_diameter_mm: float | None = None
    tolerance_mm: float = DEFAULT_EXPORT_TOL_MM
    material: str = ""


@dataclass(frozen=True, slots=True)
class OutputsSpec:
    """``[outputs]``: what ``camfab run`` produces for this design."""

    dxf: bool = True
    step: bool = False
    stl: bool = False
    gcode: str | None = None
    report: bool = True
    xlsx: bool = False
    drawing: bool = False
    lift_table: bool = False


@dataclass(frozen=True, slots=True)
class DynamicsSpec:
    """``[dynamics]``: the spring-loaded follower's mass, spring, damper and loads.

    Translating followers (and translating cams): ``mass_kg`` (required), ``spring_rate_n_per_mm``,
    ``spring_preload_n`` (the spring force at S = 0), ``damping_n_s_per_m``, ``external_force_n``
    (a constant load pressing the follower onto the cam, e.g. its weight).  Oscillating followers:
    ``inertia_kg_m2`` (about the pivot, required), ``spring_rate_nm_per_deg``, ``spring_preload_nm``,
    ``damping_nm_s_per_deg``, ``external_torque_nm``.  Both: ``friction_coefficient`` (sliding
    contacts: knife edges and flat faces) and ``safety_force_n`` (the smallest acceptable contact
    force).  Form-closed cams (conjugate, constant width/diameter) take no spring and no safety force.
    The fields of the other motion are None."""

    motion: str
    inertia: float
    spring_rate: float = 0.0
    spring_preload: float = 0.0
    damping: float = 0.0
    external: float = 0.0
    friction_coefficient: float = 0.0
    safety_force_n: float = 0.0

    @property
    def preload_unit(self) -> str:
        return "N·m" if self.motion == "oscillating" else "N"


@dataclass(frozen=True)
class DesignSpec:
    """A validated design (immutable).  Build with :func:`load_design` or :func:`design_from_dict`."""

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
    base_dir: str | None = None
    face_margin_mm: float = 0.0
    dynamics: DynamicsSpec | None = None

    @property
    def is_translating_cam(self) -> bool:
        return self.cam.kind == "translating"

    @property
    def speed(self) -> float:
        """Rate of the independent variable: ω (rad/s), or v (mm/s) for translating cams."""
        if self.is_translating_cam:
            return self.cam.speed_mm_s if self.cam.speed_mm_s is not None else 1.0
        return self.cam.omega_rad_s

    @functools.cached_property
    def motion_program(self):
        """The validated :class:`~camfab.design.program.MotionProgram` (built once)."""
        return _build_motion(self)

    def program(self):
        """The validated :class:`~camfab.design.program.MotionProgram` of this design."""
        return self.motion_program


# ---------------------------------------------------------------------------
def load_design(path: str | Path) -> DesignSpec:
    """Read and validate a design file: TOML, or an xlsx workbook (``*.xlsx``, see
    :mod:`camfab.design.xlsx_design`).

    Raises
    ------
    SpecError
        On unreadable or invalid files; every problem found is listed.
    """
    p = Path(path)
    if p.suffix.lower() == ".xlsx":
        from .xlsx_design import load_design_xlsx

        return load_design_xlsx(p)
    try:
        text = p.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise SpecError(Problem("file", str(p), "no such design file", "check the path"), str(p)) from None
    except (OSError, UnicodeDecodeError) as exc:
        raise SpecError(Problem("file", str(p), f"cannot be read ({exc})",
                                "give a UTF-8 TOML design file"), str(p)) from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise SpecError(Problem("file", p.name, f"is not valid TOML: {exc}",
                                "fix the TOML syntax at the line named"), str(p)) from None
    data.setdefault("name", p.stem)
    return design_from_dict(data, source=str(p), base_dir=p.parent)


def design_from_dict(data: Mapping[str, Any], *, source: str | None = None,
                     base_dir: str | Path | None = None) -> DesignSpec:
    """Validate a design given as a dict (the TOML structure) into a :class:`DesignSpec`."""
    v = _Validator()
    v.keys(data, _TOP_KEYS, "")
    name = data.get("name", "cam")
    if not isinstance(name, str) or not name.strip():
        v.add("name", name, "must be a non-empty string", 'e.g. name = "Ejemplo9RT"')
        name = "cam"
    cam = _cam(v, _table(v, data, "cam"))
    fol = _follower(v, _table(v, data, "follower"), cam)
    motion, table = _motion(v, data, cam)
    mfg = _manufacturing(v, _table(v, data, "manufacturing"), fol, cam.kind == "translating")
    out = _outputs(v, _table(v, data, "outputs"))
    checks = _table(v, data, "checks")
    v.keys(checks, _CHECK_KEYS, "checks")
    pa = v.number(checks, "pressure_angle_limit_deg", "checks", None, lo=0.0, hi=90.0, lo_open=True, hi_open=True)
    margin = v.number(checks, "face_margin_mm", "checks", 0.0, lo=0.0, hi=1e4)
    dyn = _dynamics(v, data, cam, fol)
    spec = DesignSpec(name.strip() if isinstance(name, str) else "cam", cam, fol, motion, table, mfg, out,
                      pa, str(data.get("description", "")), source,
                      str(base_dir) if base_dir is not None else None, margin, dyn)
    if not v.problems:
        try:
            spec.program()
        except SpecError as exc:
            v.problems.extend(exc.problems)
    if v.problems:
        raise SpecError(v.problems, source)
    return spec


# ---------------------------------------------------------------------------
class _Validator:
    """Collects problems while reading typed values out of nested dicts."""

    def __init__(self) -> None:
        self.problems: list[Problem] = []

    def add(self, path: str, value: Any, rule: str, fix: str = "") -> None:
        self.problems.append(Problem(path, value, rule, fix))

    def keys(self, table: Mapping[str, Any], allowed: tuple[str, ...], path: str) -> None:
        for k in table:
            if k not in allowed:
                close = difflib.get_close_matches(k, allowed, n=1)
                fix = f"did you mean '{close[0]}'?" if close else "allowed keys: " + ", ".join(allowed)
                self.add(f"{path}.{k}" if path else k, table[k], "unknown key", fix)

    def choice(self, table, key, path, options, default):
        val = table.get(key, default)
        if val not in options:
            self.add(f"{path}.{key}", val, "is not a valid option",
                     "must be one of: " + ", ".join(map(str, options)))
            return default
        return val

    def number(self, table, key, path, default, *, lo=None, hi=None, lo_open=False, hi_open=False,
               fix: str = ""):
        """A finite float in [lo, hi] (open ends optional); None/default when absent."""
        if key not in table:
            return default
        val = table[key]
        where = f"{path}.{key}"
        if isinstance(val, bool) or not isinstance(val, (int, float)):
            self.add(where, val, "must be a number", fix or "write a plain number (no units, no quotes)")
            return default
        val = float(val)
        if not math.isfinite(val):
            self.add(where, val, "must be finite", fix or "give a finite number")
            return default
        bad_lo = lo is not None and (val <= lo if lo_open else val < lo)
        bad_hi = hi is not None and (val >= hi if hi_open else val > hi)
        if bad_lo or bad_hi:
            rng = f"{'(' if lo_open else '['}{'-inf' if lo is None else lo}, {'inf' if hi is None else hi}{')' if hi_open else ']'}"
            self.add(where, val, f"must be in {rng}", fix or "change the value into that range")
            return default
        return val

    def boolean(self, table, key, path, default):
        val = table.get(key, default)
        if not isinstance(val, bool):
            self.add(f"{path}.{key}", val, "must be true or false", "write true or false (no quotes)")
            return default
        return val


def _table(v: _Validator, data: Mapping[str, Any], key: str) -> Mapping[str, Any]:
    t = data.get(key, {})
    if not isinstance(t, Mapping):
        v.add(key, t, "must be a table", f"write it as a [{key}] section")
        return {}
    return t


def _cam(v: _Validator, t: Mapping[str, Any]) -> CamSpec:
    v.keys(t, _CAM_KEYS, "cam")
    kind = v.choice(t, "kind", "cam", CAM_KINDS, "disc")
    rotation = v.choice(t, "rotation", "cam", ROTATIONS, "cw")
    rpm = v.number(t, "speed_rpm", "cam", None, lo=0.0, lo_open=True, hi=1e6)
    omega = v.number(t, "omega_rad_s", "cam", None, lo=0.0, lo_open=True, hi=1e6)
    vmm = v.number(t, "speed_mm_s", "cam", None, lo=0.0, lo_open=True, hi=1e7)
    if rpm is not None and omega is not None:
        v.add("cam.speed_rpm", rpm, "give either speed_rpm or omega_rad_s, not both", "remove one of them")
    if kind == "translating" and (rpm is not None or omega is not None):
        v.add("cam.speed_rpm" if rpm is not None else "cam.omega_rad_s", rpm or omega,
              "a translating cam has a linear speed", "use speed_mm_s")
    if kind != "translating" and vmm is not None:
        v.add("cam.speed_mm_s", vmm, "only translating cams have a linear speed", "use speed_rpm or omega_rad_s")
    direction = v.choice(t, "direction", "cam", ("left", "right"), "left")
    if "direction" in t and kind != "translating":
        v.add("cam.direction", t["direction"], "only translating cams slide left or right",
              "use rotation = \"cw\" | \"ccw\" for rotating cams")
    given = rpm is not None or omega is not None or vmm is not None
    w = omega if omega is not None else (rpm * RPM if rpm is not None else 1.0)
    return CamSpec(kind, rotation, w, vmm, given, direction)


_REQUIRED = {
    ("roller", "translating"): ("base_radius_mm", "roller_radius_mm"),
    ("knife", "translating"): ("base_radius_mm",),
    ("roller", "oscillating"): ("base_radius_mm", "roller_radius_mm", "pivot_distance_mm", "arm_length_mm"),
    ("knife", "oscillating"): ("base_radius_mm", "pivot_distance_mm", "arm_length_mm"),
    ("flat", "translating"): ("base_radius_mm",),
    ("flat", "oscillating"): ("base_radius_mm", "pivot_distance_mm"),
    ("curved", "translating"): ("base_radius_mm", "face_radius_mm"),
    ("curved", "oscillating"): ("base_radius_mm", "face_radius_mm", "pivot_distance_mm"),
}


def _follower(v: _Validator, t: Mapping[str, Any], cam: CamSpec) -> FollowerSpec:
    v.keys(t, _FOLLOWER_KEYS, "follower")
    ftype = v.choice(t, "type", "follower", FOLLOWER_TYPES, "roller")
    motion = v.choice(t, "motion", "follower", FOLLOWER_MOTIONS, "translating")
    vals: dict[str, float | None] = {}
    positive = ("base_radius_mm", "arm_length_mm", "cam_length_mm", "follower_distance_mm", "width_mm",
                "face_radius_mm")
    non_negative = ("roller_radius_mm", "pivot_distance_mm", "second_roller_radius_mm", "base_height_mm")
    for key in _FOLLOWER_FLOATS:
        if key in positive:
            vals[key] = v.number(t, key, "follower", None, lo=0.0, lo_open=True, hi=1e6,
                                 fix=f"{key} must be a positive length in mm")
        elif key in non_negative:
            vals[key] = v.number(t, key, "follower", None, lo=0.0, hi=1e6,
                                 fix=f"{key} must be a length >= 0 in mm")
        else:
            vals[key] = v.number(t, key, "follower", None, lo=-1e6, hi=1e6)
    if ftype == "knife":
        if vals["roller_radius_mm"] not in (None, 0.0):
            v.add("follower.roller_radius_mm", vals["roller_radius_mm"], "a knife-edge follower has no roller",
                  'remove roller_radius_mm or use type = "roller"')
        vals["roller_radius_mm"] = 0.0
    if cam.kind == "translating":
        need: tuple[str, ...] = ("roller_radius_mm", "cam_length_mm")
        if ftype in ("flat", "curved") or motion == "oscillating":
            v.add("follower.type", ftype, "a translating cam drives a translating roller follower",
                  'use type = "roller", motion = "translating"')
    elif cam.kind in ("constant_width", "constant_diameter"):
        want = "flat" if cam.kind == "constant_width" else "roller"
        if ftype != want or motion != "translating":
            v.add("follower.type", ftype, f"a {cam.kind.replace('_', '-')} cam has a double translating {want} "
                  "follower", f'use type = "{want}", motion = "translating"')
        need = ("base_radius_mm",) + (("roller_radius_mm",) if want == "roller" else ())
        if "width_mm" in t and "follower_distance_mm" in t:
            v.add("follower.follower_distance_mm", t["follower_distance_mm"],
                  "give the constant width once", "keep width_mm and remove follower_distance_mm")
        elif vals["width_mm"] is None:
            vals["width_mm"] = vals["follower_distance_mm"]
        if vals["width_mm"] is None and "width_mm" not in t and "follower_distance_mm" not in t:
            v.add("follower.width_mm", None, f"is required for a {cam.kind} cam",
                  "add width_mm = <mm> (the constant width, > 2·base_radius_mm)")
    else:
        need = _REQUIRED[(ftype, motion)]
        if cam.kind == "conjugate":
            if ftype in ("knife", "curved"):
                v.add("follower.type", ftype, "conjugate cams have roller or flat followers",
                      'use type = "roller" or "flat"')
                need = ()
            need = need + (("follower_distance_mm",) if motion == "translating" else ("follower_angle_deg",))
    for key in need:
        if key not in t and not (key == "roller_radius_mm" and ftype == "knife"):
            v.add(f"follower.{key}", None, f"is required for a {motion} {ftype} follower",
                  f"add {key} = <mm> to [follower]")
    if ftype in ("flat", "curved") and "roller_radius_mm" in t:
        v.add("follower.roller_radius_mm", t["roller_radius_mm"], f"a {ftype}-face follower has no roller",
              'remove it or use type = "roller"')
    if ftype != "curved" and "face_radius_mm" in t:
        v.add("follower.face_radius_mm", t["face_radius_mm"], "only a curved-face follower has a face radius",
              'remove it or use type = "curved"')
    return FollowerSpec(ftype, motion, **vals)


def _motion(v: _Validator, data: Mapping[str, Any], cam: CamSpec):
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
        if cam.kind in ("constant_width", "constant_diameter"):
            return None, None  # the law follows from the width (see the geometry module)
        v.add("motion", None, "the design has no motion", "add [[motion]] segments or a [motion_table]")
        return None, None
    rows = data["motion"]
    if not isinstance(rows, list) or not all(isinstance(r, Mapping) for r in rows):
        v.add("motion", rows, "must be an array of tables", "write each segment as a [[motion]] block")
        return None, None
    span_key = "length_mm" if cam.kind == "translating" else "angle_deg"
    other = "angle_deg" if span_key == "length_mm" else "length_mm"
    laws = law_names()
    segs = []
    for i, r in enumerate(rows):
        p = f"motion[{i}]"
        v.keys(r, _SEGMENT_KEYS, p)
        law = r.get("law", "dwell" if r.get("lift", 0) == 0 else None)
        if law not in laws:
            close = difflib.get_close_matches(str(law), laws, n=1)
            v.add(f"{p}.law", law, "unknown motion law" if law is not None else "is required",
                  f"did you mean '{close[0]}'?" if close else "use one of: " + ", ".join(laws))
            law = "dwell"
        lift = v.number(r, "lift", p, 0.0, lo=-1e5, hi=1e5)
        if other in r:
            v.add(f"{p}.{other}", r[other], f"this cam measures segments in {span_key}",
                  f"rename it to {span_key}")
        span_raw = r.get(span_key)
        if span_raw == "auto":
            span = None
        elif span_raw is None:
            v.add(f"{p}.{span_key}", None, "is required", f"give {span_key} (or \"auto\" for a half-period law)")
            span = None
        else:
            span = v.number(r, span_key, p, None, lo=0.0, lo_open=True,
                            hi=360.0 if span_key == "angle_deg" else 1e6)
            if span is None:
                span = 1.0  # already reported; keep going to collect the other problems
        shape = r.get("shape")
        segs.append(SegmentSpec(str(law), lift, span, shape))
    return tuple(segs), None


def _manufacturing(v: _Validator, t: Mapping[str, Any], fol: FollowerSpec,
                   translating: bool = False) -> ManufacturingSpec:
    v.keys(t, _MFG_KEYS, "manufacturing")
    m = ManufacturingSpec(
        thickness_mm=v.number(t, "thickness_mm", "manufacturing", 10.0, lo=0.0, lo_open=True, hi=1e4),
        bore_mm=v.number(t, "bore_mm", "manufacturing", 0.0, lo=0.0, hi=1e4),
        keyway=v.boolean(t, "keyway", "manufacturing", False),
        hub_diameter_mm=v.number(t, "hub_diameter_mm", "manufacturing", None, lo=0.0, lo_open=True, hi=1e4),
        hub_length_mm=v.number(t, "hub_length_mm", "manufacturing", None, lo=0.0, lo_open=True, hi=1e4),
        tool_diameter_mm=v.number(t, "tool_diameter_mm", "manufacturing", None, lo=0.0, lo_open=True, hi=1e3),
        tolerance_mm=v.number(t, "tolerance_mm", "manufacturing", DEFAULT_EXPORT_TOL_MM,
                              lo=MIN_EXPORT_TOL_MM, hi=MAX_EXPORT_TOL_MM),
        material=str(t.get("material", "")),
    )
    rb = fol.base_radius_mm
    if rb is not None and m.bore_mm >= 2 * rb:
        v.add("manufacturing.bore_mm", m.bore_mm, f"the bore does not fit inside the base circle (diameter {2 * rb:g} mm)",
              "use a smaller bore or a larger base_radius_mm")
    if translating:
        for key in ("bore_mm", "hub_diameter_mm", "hub_length_mm"):
            if getattr(m, key):
                v.add(f"manufacturing.{key}", getattr(m, key), "a translating cam is a plate that slides; it has "
                      "no shaft, bore or hub", f"remove {key} (mount the plate with your own holes in CAD)")
    if m.keyway and m.bore_mm == 0:
        v.add("manufacturing.keyway", True, "a keyway needs a bore", "set bore_mm or keyway = false")
    return m


def _dynamics(v: _Validator, data: Mapping[str, Any], cam: CamSpec, fol: FollowerSpec) -> DynamicsSpec | None:
    if "dynamics" not in data:
        return None
    t = _table(v, data, "dynamics")
    osc = fol.motion == "oscillating" and cam.kind != "translating"
    own, other = (_DYN_OSCILLATING, _DYN_TRANSLATING) if osc else (_DYN_TRANSLATING, _DYN_OSCILLATING)
    kind = "an oscillating" if osc else "a translating"
    for k in t:
        if k in other:
            v.add(f"dynamics.{k}", t[k], f"is for {'translating' if osc else 'oscillating'} followers",
                  f"{kind} follower takes: " + ", ".join(own))
    v.keys({k: t[k] for k in t if k not in other}, own + _DYN_COMMON, "dynamics")
    if cam.kind in ("conjugate", "constant_width", "constant_diameter"):
        for k in (own[1], own[2], "safety_force_n"):
            if k in t:
                v.add(f"dynamics.{k}", t[k], f"a {cam.kind.replace('_', '-')} cam drives its follower both ways "
                      "(form closure): it has no return spring and cannot jump", f"remove {k}")
    if not cam.speed_given:
        key = "speed_mm_s" if cam.kind == "translating" else "speed_rpm"
        v.add(f"cam.{key}", None, "dynamics needs the cam speed", f"add {key} = ... to [cam]")
    big = 1e9
    m = v.number(t, own[0], "dynamics", None, lo=0.0, lo_open=True, hi=big,
                 fix=f"give the {'arm inertia about its pivot' if osc else 'moving mass'} (> 0)")
    if own[0] not in t:
        v.add(f"dynamics.{own[0]}", None, "is required",
              f"add {own[0]} = ... ({'the arm and roller about the pivot' if osc else 'follower, spring share and attached parts'})")
    rate = v.number(t, own[1], "dynamics", 0.0, lo=0.0, hi=big)
    pre = v.number(t, own[2], "dynamics", 0.0, lo=-big, hi=big)
    damp = v.number(t, own[3], "dynamics", 0.0, lo=0.0, hi=big)
    ext = v.number(t, own[4], "dynamics", 0.0, lo=-big, hi=big)
    mu = v.number(t, "friction_coefficient", "dynamics", 0.0, lo=0.0, hi=2.0)
    fs = v.number(t, "safety_force_n", "dynamics", 0.0, lo=0.0, hi=big)
    if mu and fol.type == "roller" and (fol.roller_radius_mm or 0.0) > 0:
        v.add("dynamics.friction_coefficient", mu, "a roller rolls on the cam (no sliding friction is modelled)",
              "remove friction_coefficient, or model a knife edge or flat face")
    if m is None:
        return None
    return DynamicsSpec("oscillating" if osc else "translating", m, rate, pre, damp, ext, mu, fs)


def _outputs(v: _Validator, t: Mapping[str, Any]) -> OutputsSpec:
    v.keys(t, _OUTPUT_KEYS, "outputs")
    gcode = t.get("gcode", False)
    if gcode is False:
        post = None
    elif gcode is True:
        post = "linuxcnc"
    elif gcode in POSTS:
        post = gcode
    else:
        v.add("outputs.gcode", gcode, "is not a valid option", "must be false or one of: " + ", ".join(POSTS))
        post = None
    defaults = OutputsSpec()
    flags = {k: v.boolean(t, k, "outputs", getattr(defaults, k))
             for k in ("dxf", "step", "stl", "report", "xlsx", "drawing", "lift_table")}
    return OutputsSpec(gcode=post, **flags)


def _symmetric_law(spec: DesignSpec):
    """The fixed constant-width/diameter law: SHM rise, dwell, SHM return, dwell; h = width − 2·Rb."""
    from .program import MotionProgram

    f = spec.follower
    h = (f.width_mm or 0.0) - (f.base_radius_mm or 0.0) * 2
    r = f.rise_deg or 120.0
    if h <= 0 or not 0 < r <= 180:
        raise SpecError(Problem("follower.width_mm", f.width_mm,
                                f"the width must exceed the base diameter {2 * (f.base_radius_mm or 0):g} mm and "
                                "rise_deg lie in (0, 180]", "increase width_mm or fix rise_deg"), spec.source)
    dwell = [("dwell", 0.0, 180.0 - r)] if r < 180.0 else []
    return MotionProgram.from_segments([("simple_harmonic", h, r), *dwell, ("simple_harmonic", -h, r), *dwell])


def _build_motion(spec: DesignSpec):
    from .program import SegmentInput, TWO_PI, build_program

    if spec.motion_table is not None:
        from .knots import load_motion_table

        base = Path(spec.base_dir) if spec.base_dir else None
        return load_motion_table(spec.motion_table, base_dir=base).program()
    if spec.motion is None:
        if spec.cam.kind in ("constant_width", "constant_diameter"):
            return _symmetric_law(spec)
        raise SpecError(Problem("motion", None, f"no motion law for a {spec.cam.kind} cam",
                                "add [[motion]] segments"), spec.source)
    if spec.is_translating_cam:
        length = spec.follower.cam_length_mm or sum(s.span or 0.0 for s in spec.motion)
        inputs = [SegmentInput(s.law, s.lift, s.span, s.shape) for s in spec.motion]
        return build_program(inputs, period=length, unit="mm", source=spec.source)
    inputs = [SegmentInput(s.law, s.lift, None if s.span is None else s.span * DEG, s.shape) for s in spec.motion]
    return build_program(inputs, period=TWO_PI, unit="rad", source=spec.source, lift_unit=spec.follower.lift_unit)
