"""The shop sections of a design: ``[manufacturing]`` (stock and tool), ``[machining]`` (how the G-code cuts)
and ``[outputs]`` (what ``camfab run`` writes) — their values and their validation.

Every reader collects its problems in a :class:`~camfab.design.validator.Validator` (field path, value,
rule, fix); nothing here raises.  ``[machining]`` leaves spindle speed and feeds unset by default: the
G-code takes them from the cutting-data table (``camfab.gcode.cutting``); command-line flags override it
(``camfab.pipeline.gcode_job``), so ``gcode``, ``run`` and ``package`` cut the same program for the same
inputs.
"""
from __future__ import annotations

from collections.abc import Mapping
from enum import StrEnum
from typing import Any

from ..limits import MAX_DEPTH_LEVELS
from ..records import dataclass
from ..tolerances import DEFAULT_EXPORT_TOL_MM, MAX_EXPORT_TOL_MM, MIN_EXPORT_TOL_MM
from .validator import Validator

__all__ = ["POSTS", "Post", "ManufacturingSpec", "MachiningSpec", "OutputsSpec", "AssemblySpec", "ASSEMBLY_KEYS",
           "manufacturing_section", "machining_section", "outputs_section", "assembly_section", "depth_problems"]


class Post(StrEnum):
    """The controller dialects camfab writes."""

    LINUXCNC = "linuxcnc"
    FANUC = "fanuc"
    GRBL = "grbl"


POSTS = tuple(p.value for p in Post)

_MFG_KEYS = ("thickness_mm", "bore_mm", "keyway", "hub_diameter_mm", "hub_length_mm",
             "tool_diameter_mm", "tolerance_mm", "material")
_OUTPUT_KEYS = ("dxf", "step", "stl", "gcode", "report", "xlsx", "drawing", "lift_table", "pdf", "assembly",
                "iges")


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
class MachiningSpec:
    """``[machining]``: how the contour-milling program cuts (lengths mm, feeds mm/min, speeds rpm).

    ``compensation`` = ``"G41"`` / ``"G42"`` writes the part contour with the controller's cutter
    compensation instead of tool-centre coordinates (no roughing passes then); ``lines_only`` writes the
    finishing contour as G1 lines.

    ``spindle_rpm``, ``feed_mm_min`` and ``plunge_feed_mm_min`` not given (None) come from the cutting-data
    table (``camfab/gcode/cutting_data.toml``) for ``[manufacturing] material``, the tool diameter,
    ``tool_material`` and ``tool_flutes``, within the machine's ``max_spindle_rpm``.  The final depth is the
    plate thickness plus ``breakthrough_mm``; the stock is a blank ``stock_allowance_mm`` larger than the
    part all round (or a round blank of ``stock_diameter_mm``); ``mill_bore`` mills the bore by a helix of
    at most ``helix_pitch_mm`` per turn and ``ramp_angle_deg`` steep, then a finishing circle.
    """

    tool_number: int = 1
    spindle_rpm: float | None = None
    feed_mm_min: float | None = None
    plunge_feed_mm_min: float | None = None
    tool_material: str = "carbide"
    tool_flutes: int | None = None
    max_spindle_rpm: float = 10000.0
    breakthrough_mm: float = 0.5
    stock_diameter_mm: float | None = None
    stock_allowance_mm: float = 2.0
    mill_bore: bool = False
    helix_pitch_mm: float = 1.0
    ramp_angle_deg: float = 3.0
    step_down_mm: float = 3.0
    safe_z_mm: float = 25.0
    clearance_mm: float = 2.0
    roughing_passes: int = 1
    roughing_allowance_mm: float = 0.2
    roughing_stepover_mm: float | None = None
    lead_radius_mm: float | None = None
    direction: str = "climb"
    coolant: str = "flood"
    units: str = "mm"
    compensation: str | None = None
    lines_only: bool = False


#: [machining] keys: positive numbers (with their upper bounds), then the choices
_MACHINING_NUMBERS = {"spindle_rpm": 1e6, "feed_mm_min": 1e6, "plunge_feed_mm_min": 1e6, "step_down_mm": 1e3,
                      "safe_z_mm": 1e4, "clearance_mm": 1e3, "roughing_allowance_mm": 1e2,
                      "roughing_stepover_mm": 1e3, "lead_radius_mm": 1e3, "max_spindle_rpm": 1e6,
                      "stock_diameter_mm": 1e4, "helix_pitch_mm": 1e2, "ramp_angle_deg": 45.0}
#: [machining] lengths that may be 0 (with their upper bounds)
_MACHINING_ZERO_OK = {"breakthrough_mm": 1e2, "stock_allowance_mm": 1e3}
_MACHINING_CHOICES = {"direction": ("climb", "conventional"), "coolant": ("flood", "mist", "off"),
                      "units": ("mm", "inch"), "compensation": ("G41", "G42"), "tool_material": ("carbide", "hss")}
_MACHINING_KEYS = (*_MACHINING_NUMBERS, *_MACHINING_ZERO_OK, *_MACHINING_CHOICES, "tool_number", "roughing_passes",
                   "lines_only", "tool_flutes", "mill_bore")


@dataclass(frozen=True, slots=True)
class OutputsSpec:
    """``[outputs]``: what ``camfab run`` produces for this design."""

    dxf: bool = True
    step: bool = True
    stl: bool = False
    gcode: str | None = None
    report: bool = True
    xlsx: bool = False
    drawing: bool = False
    lift_table: bool = False
    #: the drawing sheet as PDF too (``<stem>_drawing.pdf``); when the file does not say, as ``drawing``
    pdf: bool = False
    #: the mechanism as a STEP assembly (``<name>_assembly.step``); when the table does not say, as ``step``
    assembly: bool = True
    #: the plate as IGES (``<name>.igs``) for older CAM systems
    iges: bool = False


@dataclass(frozen=True, slots=True)
class AssemblySpec:
    """``[assembly]``: follower dimensions the design does not give, for the assembly STEP (mm).

    None = derived from the design (``camfab.cad.assembly.dimensions``, ``docs/decisions.md``, "Assembly
    STEP"): roller width = plate thickness, pin = 0.4 × roller diameter, stem = 0.8 × roller diameter …
    """

    roller_width_mm: float | None = None
    pin_diameter_mm: float | None = None
    stem_diameter_mm: float | None = None
    arm_width_mm: float | None = None
    arm_thickness_mm: float | None = None
    face_thickness_mm: float | None = None
    pivot_diameter_mm: float | None = None
    clearance_mm: float | None = None


#: [assembly] keys, each a positive length with its upper bound (mm)
ASSEMBLY_KEYS = {"roller_width_mm": 1e4, "pin_diameter_mm": 1e4, "stem_diameter_mm": 1e4, "arm_width_mm": 1e4,
                 "arm_thickness_mm": 1e4, "face_thickness_mm": 1e4, "pivot_diameter_mm": 1e4, "clearance_mm": 1e3}


def manufacturing_section(v: Validator, t: Mapping[str, Any], base_radius_mm: float | None,
                          translating: bool = False) -> ManufacturingSpec:
    """``[manufacturing]``: numbers in range, a bore inside the base circle, no bore on a sliding plate."""
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
    rb = base_radius_mm
    if rb is not None and m.bore_mm >= 2 * rb:
        v.add("manufacturing.bore_mm", m.bore_mm,
              f"the bore does not fit inside the base circle (diameter {2 * rb:g} mm)",
              "use a smaller bore or a larger base_radius_mm")
    if translating:
        for key in ("bore_mm", "hub_diameter_mm", "hub_length_mm"):
            if getattr(m, key):
                v.add(f"manufacturing.{key}", getattr(m, key), "a translating cam is a plate that slides; it has "
                      "no shaft, bore or hub", f"remove {key} (mount the plate with your own holes in CAD)")
    if m.keyway and m.bore_mm == 0:
        v.add("manufacturing.keyway", True, "a keyway needs a bore", "set bore_mm or keyway = false")
    return m


def machining_section(v: Validator, t: Mapping[str, Any]) -> MachiningSpec:
    """``[machining]``: positive feeds, speeds and lengths, whole numbers of tools and passes, the choices."""
    v.keys(t, _MACHINING_KEYS, "machining")
    d = MachiningSpec()
    values: dict[str, Any] = {}
    for key, hi in _MACHINING_NUMBERS.items():
        values[key] = v.number(t, key, "machining", getattr(d, key), lo=0.0, lo_open=True, hi=hi)
    for key, hi in _MACHINING_ZERO_OK.items():
        values[key] = v.number(t, key, "machining", getattr(d, key), lo=0.0, hi=hi)
    for key, options in _MACHINING_CHOICES.items():
        val = t.get(key, getattr(d, key))
        if val is not None and val not in options:
            v.add(f"machining.{key}", val, "is not a valid option", "must be one of: " + ", ".join(options))
            val = getattr(d, key)
        values[key] = val
    values["tool_number"] = _whole(v, t, "tool_number", d.tool_number, 1, 99999)
    values["roughing_passes"] = _whole(v, t, "roughing_passes", d.roughing_passes, 0, 100)
    values["lines_only"] = v.boolean(t, "lines_only", "machining", d.lines_only)
    values["mill_bore"] = v.boolean(t, "mill_bore", "machining", d.mill_bore)
    values["tool_flutes"] = None if "tool_flutes" not in t else _whole(v, t, "tool_flutes", None, 1, 12)
    return MachiningSpec(**values)


def _whole(v: Validator, t: Mapping[str, Any], key: str, default: Any, lo: int, hi: int) -> Any:
    val = t.get(key, default)
    if isinstance(val, bool) or not isinstance(val, int) or not lo <= val <= hi:
        v.add(f"machining.{key}", val, f"must be a whole number in [{lo}, {hi}]", f"give {key} as an integer")
        return default
    return val


def outputs_section(v: Validator, t: Mapping[str, Any]) -> OutputsSpec:
    """``[outputs]``: booleans, and the G-code post (``false``, ``true`` = linuxcnc, or a post's name)."""
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
             for k in ("dxf", "step", "stl", "report", "xlsx", "drawing", "lift_table", "iges")}
    flags["pdf"] = v.boolean(t, "pdf", "outputs", flags["drawing"])
    flags["assembly"] = v.boolean(t, "assembly", "outputs", flags["step"])  # follows step unless given
    return OutputsSpec(gcode=post, **flags)


def assembly_section(v: Validator, t: Mapping[str, Any]) -> AssemblySpec:
    """``[assembly]``: positive lengths within their bounds (mm); what is not given is derived later."""
    v.keys(t, tuple(ASSEMBLY_KEYS), "assembly")
    return AssemblySpec(**{k: v.number(t, k, "assembly", None, lo=0.0, lo_open=True, hi=hi)
                           for k, hi in ASSEMBLY_KEYS.items()})


def depth_problems(v: Validator, mfg: ManufacturingSpec, machining: MachiningSpec,
                   groove_depth_mm: float | None = None) -> None:
    """The depths the plate is cut to: in at most :data:`~camfab.limits.MAX_DEPTH_LEVELS` step-downs
    (``docs/decisions.md``, "Input limits"), and a groove that leaves a floor — its depth below the plate thickness
    (``docs/decisions.md``, "Groove cams")."""
    depth, step = mfg.thickness_mm + machining.breakthrough_mm, machining.step_down_mm
    if depth / step > MAX_DEPTH_LEVELS:
        v.add("machining.step_down_mm", step, f"cuts the {depth:g} mm depth (plate and breakthrough) in more than "
              f"{MAX_DEPTH_LEVELS} depth levels (the input limit)",
              f"give a step-down of at least {depth / MAX_DEPTH_LEVELS:.3g} mm")
    if groove_depth_mm is not None and groove_depth_mm >= mfg.thickness_mm:
        v.add("follower.groove_depth_mm", groove_depth_mm, f"must be smaller than the plate thickness "
              f"([manufacturing] thickness_mm = {mfg.thickness_mm:g} mm): the groove needs a floor",
              f"give groove_depth_mm < {mfg.thickness_mm:g}, or a thicker plate")
