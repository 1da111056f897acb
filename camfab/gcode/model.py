"""The common toolpath model: program items (moves, comments, tool, spindle, coolant, compensation),
the milling :class:`Job` and the :class:`Program` a post-processor writes.

All coordinates, lengths and feeds are millimetres (feeds mm/min), whatever units the program is
finally written in: the post-processor converts (``Job.units``).
"""
from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

from camfab.design.shop import MachiningSpec
from camfab.errors import Problem, SpecError
from camfab.gcode.cutting import cutting_data
from camfab.limits import MAX_DEPTH_LEVELS
from camfab.records import dataclass, field, replace
from camfab.tolerances import MAX_EXPORT_TOL_MM, MIN_EXPORT_TOL_MM

__all__ = ["Rapid", "Feed", "Arc", "Comment", "ToolChange", "Spindle", "Coolant", "CutterComp", "Item", "Job",
           "Program", "job_from_machining", "design_job", "machining_of"]


@dataclass(frozen=True)
class Rapid:
    """Rapid move (G0) to absolute ``(x, y, z)`` in mm; ``None`` leaves an axis where it is."""

    x: float | None
    y: float | None
    z: float | None

    def __post_init__(self):
        for k in ("x", "y", "z"):
            v = getattr(self, k)
            object.__setattr__(self, k, None if v is None else float(v))


@dataclass(frozen=True)
class Feed:
    """Straight cutting move (G1) to ``(x, y, z)`` mm at ``feed`` mm/min."""

    x: float
    y: float
    z: float
    feed: float

    def __post_init__(self):
        for k in ("x", "y", "z", "feed"):
            object.__setattr__(self, k, float(getattr(self, k)))


@dataclass(frozen=True)
class Arc:
    """Circular cutting move (G2 clockwise / G3) in the XY plane.

    The arc starts where the previous move ended and ends at ``(x, y)``; ``(cx, cy)`` is the absolute
    centre in mm, ``z`` the end height (equal to the start height except for helices) and ``feed`` mm/min.
    """

    x: float
    y: float
    cx: float
    cy: float
    clockwise: bool
    z: float
    feed: float

    def __post_init__(self):
        for k in ("x", "y", "cx", "cy", "z", "feed"):
            object.__setattr__(self, k, float(getattr(self, k)))
        object.__setattr__(self, "clockwise", bool(self.clockwise))


@dataclass(frozen=True)
class Comment:
    """A comment line; the post sanitises it for its controller."""

    text: str


@dataclass(frozen=True)
class ToolChange:
    """Load tool ``tool`` (diameter in mm); posts without a tool changer write a comment."""

    tool: int
    diameter_mm: float


@dataclass(frozen=True)
class Spindle:
    """Spindle on at ``rpm`` (clockwise, M3), or off (M5) when ``rpm == 0``."""

    rpm: float


@dataclass(frozen=True)
class Coolant:
    """Coolant ``"flood"`` (M8), ``"mist"`` (M7) or ``"off"`` (M9)."""

    mode: str


@dataclass(frozen=True)
class CutterComp:
    """Cutter radius compensation ``"G41"``, ``"G42"`` (with D ``register``) or ``"G40"`` (off).

    Posts put it on the next motion block, which must be a straight line.
    """

    mode: str
    register: int = 0


Item = Rapid | Feed | Arc | Comment | ToolChange | Spindle | Coolant | CutterComp

_DIRECTIONS = ("climb", "conventional")
_STOCKS = ("round", "plate")
#: the defaults of a job are those of the design's [machining] table (one place)
_M = MachiningSpec()
_COOLANTS = ("flood", "mist", "off")
_UNITS = ("mm", "inch")


@dataclass(frozen=True)
class Job:
    """Everything a milling program needs besides the contour.  Lengths mm, feeds mm/min.

    Parameters
    ----------
    tool_diameter_mm : float
        Flat end mill diameter.
    depth_mm : float
        The final cutting depth below the stock top (``Z = -depth_mm``): the plate thickness plus the
        breakthrough.
    tool_number : int
        T word and length-offset register H (and D register for G41/G42).
    spindle_rpm : float
        Spindle speed (M3, clockwise).  Designs get it from the cutting-data table
        (:func:`job_from_machining`); 3000 is only the default of a job built by hand.
    feed_mm_min, plunge_feed_mm_min : float
        Cutting feed, and the feed of every descending move (plunges, helices).
    step_down_mm : float
        Largest depth per level; levels are equal, ``ceil(depth / step_down)`` of them.
    safe_z_mm : float
        Safe height: every horizontal rapid runs at this Z.
    clearance_mm : float
        Height above the stock top where the rapid descent stops and the plunge feed begins.
    roughing_allowance_mm : float
        Radial stock left by the roughing passes for the finishing pass.
    roughing_passes : int
        Number of roughing passes per level (0 = finishing pass only, cut in step-downs).
    roughing_stepover_mm : float or None
        Radial distance between roughing passes; default half the tool diameter.
    direction : {"climb", "conventional"}
        Milling direction (with M3: climb = clockwise around the part).
    coolant : {"flood", "mist", "off"}
    units : {"mm", "inch"}
        Units of the written program (G21 / G20).  The model itself is always mm.
    tolerance_mm : float
        Discretisation tolerance the contour was built to (stated in the header, sets the output
        resolution).
    design_name : str
    achieved_deviation_mm : float or None
        Worst deviation of the contour from the exact curve, as reported by the offset module.
    lead_radius_mm : float or None
        Radius of the tangent lead-in/lead-out arcs; default the tool diameter.
    finish_full_depth : bool
        With roughing passes, cut the finishing pass at full depth in one level (default) instead of in
        step-downs.
    breakthrough_mm : float
        How much of ``depth_mm`` lies below the plate (stated in the header).
    stock_shape : {"round", "plate"}
        The blank: a round blank centred on the cam axis (rotating cams) or a rectangular plate.
    stock_diameter_mm : float or None
        Diameter of the round blank; default the part's largest diameter plus twice the allowance,
        rounded up to a whole mm.
    stock_allowance_mm : float
        Stock left around the part by the derived blank (each side).
    bore_mm : float
        Bore diameter, centred on the cam axis (0: none).
    mill_bore : bool
        Mill the bore by helical interpolation (before the contour) and a finishing circle at full depth.
    helix_pitch_mm, ramp_angle_deg : float
        The bore helix descends at most this much per turn, and at most this steeply.
    notes : tuple of str
        Header lines stating where the cutting data came from.
    """

    tool_diameter_mm: float
    depth_mm: float
    tool_number: int = _M.tool_number
    spindle_rpm: float = 3000.0
    feed_mm_min: float = 600.0
    plunge_feed_mm_min: float = 200.0
    step_down_mm: float = _M.step_down_mm
    safe_z_mm: float = _M.safe_z_mm
    clearance_mm: float = _M.clearance_mm
    roughing_allowance_mm: float = _M.roughing_allowance_mm
    roughing_passes: int = _M.roughing_passes
    roughing_stepover_mm: float | None = _M.roughing_stepover_mm
    direction: str = _M.direction
    coolant: str = _M.coolant
    units: str = _M.units
    tolerance_mm: float = 0.001
    design_name: str = "cam"
    achieved_deviation_mm: float | None = None
    lead_radius_mm: float | None = _M.lead_radius_mm
    finish_full_depth: bool = True
    breakthrough_mm: float = 0.0
    stock_shape: str = "round"
    stock_diameter_mm: float | None = _M.stock_diameter_mm
    stock_allowance_mm: float = _M.stock_allowance_mm
    bore_mm: float = 0.0
    mill_bore: bool = _M.mill_bore
    helix_pitch_mm: float = _M.helix_pitch_mm
    ramp_angle_deg: float = _M.ramp_angle_deg
    notes: tuple[str, ...] = ()

    def __post_init__(self):
        problems = self._problems()
        if problems:
            raise SpecError(problems, source="job")

    def _problems(self) -> list[Problem]:
        P: list[Problem] = []

        def num(name, positive=True, allow_none=False):
            v = getattr(self, name)
            if v is None and allow_none:
                return None
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
                P.append(Problem(f"job.{name}", v, "must be a finite number", "give a number in mm"))
                return None
            if positive and v <= 0:
                P.append(Problem(f"job.{name}", v, "must be > 0", "give a positive value"))
                return None
            return float(v)

        def integer(name, minimum):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, int) or v < minimum:
                P.append(Problem(f"job.{name}", v, f"must be an integer >= {minimum}",
                                 f"give a whole number >= {minimum}"))

        D = num("tool_diameter_mm")
        depth = num("depth_mm")
        integer("tool_number", 1)
        if isinstance(self.tool_number, int) and self.tool_number > 99:
            P.append(Problem("job.tool_number", self.tool_number, "must be <= 99", "use a tool pocket 1..99"))
        num("spindle_rpm")
        num("feed_mm_min")
        num("plunge_feed_mm_min")
        step = num("step_down_mm")
        if depth is not None and step is not None and depth / step > MAX_DEPTH_LEVELS:
            P.append(Problem("job.step_down_mm", step, f"cuts {depth:g} mm in more than {MAX_DEPTH_LEVELS} depth "
                             "levels (the input limit)",
                             f"give a step-down of at least {depth / MAX_DEPTH_LEVELS:.3g} mm"))
        safe = num("safe_z_mm")
        clear = num("clearance_mm")
        if safe is not None and clear is not None and clear >= safe:
            P.append(Problem("job.clearance_mm", self.clearance_mm,
                             f"must be below the safe height ({self.safe_z_mm} mm)",
                             "raise safe_z_mm or lower clearance_mm"))
        allow = num("roughing_allowance_mm", positive=False)
        if allow is not None and allow < 0:
            P.append(Problem("job.roughing_allowance_mm", allow, "must be >= 0", "give 0 or more"))
        integer("roughing_passes", 0)
        if (isinstance(self.roughing_passes, int) and not isinstance(self.roughing_passes, bool)
                and self.roughing_passes > 0 and allow is not None and allow <= 0):
            P.append(Problem("job.roughing_allowance_mm", self.roughing_allowance_mm,
                             "must be > 0 when there are roughing passes",
                             "leave a finishing allowance (e.g. 0.2 mm) or set roughing_passes = 0"))
        num("roughing_stepover_mm", allow_none=True)
        if D is not None and self.roughing_stepover_mm is not None and isinstance(
                self.roughing_stepover_mm, (int, float)) and self.roughing_stepover_mm > D:
            P.append(Problem("job.roughing_stepover_mm", self.roughing_stepover_mm,
                             f"must not exceed the tool diameter ({D} mm)", "use at most the tool diameter"))
        if self.direction not in _DIRECTIONS:
            P.append(Problem("job.direction", self.direction, f"must be one of {', '.join(_DIRECTIONS)}",
                             "climb is the usual choice"))
        if self.coolant not in _COOLANTS:
            P.append(Problem("job.coolant", self.coolant, f"must be one of {', '.join(_COOLANTS)}", ""))
        if self.units not in _UNITS:
            P.append(Problem("job.units", self.units, f"must be one of {', '.join(_UNITS)}", ""))
        tol = num("tolerance_mm")
        if tol is not None and not (MIN_EXPORT_TOL_MM <= tol <= MAX_EXPORT_TOL_MM):
            P.append(Problem("job.tolerance_mm", tol,
                             f"must lie in [{MIN_EXPORT_TOL_MM:g}, {MAX_EXPORT_TOL_MM:g}] mm", ""))
        if not isinstance(self.design_name, str) or not self.design_name.strip():
            P.append(Problem("job.design_name", self.design_name, "must be a non-empty string", ""))
        dev = num("achieved_deviation_mm", positive=False, allow_none=True)
        if dev is not None and dev < 0:
            P.append(Problem("job.achieved_deviation_mm", dev, "must be >= 0", ""))
        num("lead_radius_mm", allow_none=True)
        if not isinstance(self.finish_full_depth, bool):
            P.append(Problem("job.finish_full_depth", self.finish_full_depth, "must be true or false", ""))
        brk = num("breakthrough_mm", positive=False)
        if brk is not None and depth is not None and not 0.0 <= brk < depth:
            P.append(Problem("job.breakthrough_mm", brk, "must be >= 0 and less than the depth", ""))
        if self.stock_shape not in _STOCKS:
            P.append(Problem("job.stock_shape", self.stock_shape, f"must be one of {', '.join(_STOCKS)}", ""))
        num("stock_diameter_mm", allow_none=True)
        sa = num("stock_allowance_mm", positive=False)
        if sa is not None and sa < 0:
            P.append(Problem("job.stock_allowance_mm", sa, "must be >= 0", "give 0 or more"))
        bore = num("bore_mm", positive=False)
        if bore is not None and bore < 0:
            P.append(Problem("job.bore_mm", bore, "must be >= 0", ""))
        num("helix_pitch_mm")
        ang = num("ramp_angle_deg")
        if ang is not None and ang > 45.0:
            P.append(Problem("job.ramp_angle_deg", ang, "must be at most 45 degrees", ""))
        if not isinstance(self.mill_bore, bool):
            P.append(Problem("job.mill_bore", self.mill_bore, "must be true or false", ""))
        elif self.mill_bore and bore is not None and D is not None:
            P += bore_problems(bore, D, "job")
        return P

    @property
    def tool_radius_mm(self) -> float:
        """Half the tool diameter."""
        return 0.5 * self.tool_diameter_mm

    @property
    def lead_radius(self) -> float:
        """Lead-in/out arc radius in mm (``lead_radius_mm`` or the tool diameter)."""
        return float(self.lead_radius_mm) if self.lead_radius_mm is not None else float(self.tool_diameter_mm)

    @property
    def stepover(self) -> float:
        """Radial step between roughing passes in mm."""
        if self.roughing_stepover_mm is not None:
            return float(self.roughing_stepover_mm)
        return 0.5 * self.tool_diameter_mm

    @property
    def levels(self) -> tuple[float, ...]:
        """Z of each depth level, top down, equal steps no larger than ``step_down_mm``."""
        n = max(1, math.ceil(self.depth_mm / self.step_down_mm - 1e-9))
        return tuple(-self.depth_mm * k / n for k in range(1, n + 1))


def bore_problems(bore_mm: float, tool_diameter_mm: float, where: str = "machining") -> list[Problem]:
    """Why a bore of ``bore_mm`` cannot be milled with the tool (empty when it can)."""
    if bore_mm <= 0:
        return [Problem(f"{where}.mill_bore", True, "there is no bore to mill (manufacturing.bore_mm = 0)",
                        "set manufacturing.bore_mm or mill_bore = false")]
    if tool_diameter_mm >= bore_mm:
        return [Problem(f"{where}.mill_bore", True, f"the tool (manufacturing.tool_diameter_mm = "
                        f"{tool_diameter_mm:g} mm) does not fit the bore (manufacturing.bore_mm = {bore_mm:g} mm): "
                        "helical bore milling needs a tool smaller than the bore",
                        "use a smaller tool, or mill_bore = false and bore the hole another way")]
    return []


def job_from_machining(m: MachiningSpec, *, tool_diameter_mm: float, thickness_mm: float, material: str = "",
                       bore_mm: float = 0.0, stock_shape: str = "round", tolerance_mm: float = 0.001,
                       design_name: str = "cam", source: str | None = None) -> Job:
    """The :class:`Job` of a design's ``[machining]`` table ``m`` and its ``[manufacturing]`` values: the
    cutting data from :func:`camfab.gcode.cutting.cutting_data` where ``m`` does not give them, the final
    depth ``thickness_mm + m.breakthrough_mm``.

    Raises
    ------
    SpecError
        A material or tool the cutting-data table does not know, a bore the tool does not fit, a job value
        out of range (field named).
    """
    cd = cutting_data(tool_diameter_mm=tool_diameter_mm, material=material, tool_material=m.tool_material,
                      flutes=m.tool_flutes, spindle_rpm=m.spindle_rpm, feed_mm_min=m.feed_mm_min,
                      plunge_feed_mm_min=m.plunge_feed_mm_min, max_spindle_rpm=m.max_spindle_rpm, source=source)
    if m.mill_bore:
        bad = bore_problems(bore_mm, tool_diameter_mm)
        if bad:
            raise SpecError(bad, source)
    return Job(tool_diameter_mm=tool_diameter_mm, depth_mm=thickness_mm + m.breakthrough_mm,
               tool_number=m.tool_number, spindle_rpm=cd.spindle_rpm, feed_mm_min=cd.feed_mm_min,
               plunge_feed_mm_min=cd.plunge_feed_mm_min, step_down_mm=m.step_down_mm, safe_z_mm=m.safe_z_mm,
               clearance_mm=m.clearance_mm, roughing_allowance_mm=m.roughing_allowance_mm,
               roughing_passes=0 if m.compensation else m.roughing_passes,
               roughing_stepover_mm=m.roughing_stepover_mm, direction=m.direction, coolant=m.coolant,
               units=m.units, tolerance_mm=tolerance_mm, design_name=design_name, lead_radius_mm=m.lead_radius_mm,
               breakthrough_mm=m.breakthrough_mm, stock_shape=stock_shape, stock_diameter_mm=m.stock_diameter_mm,
               stock_allowance_mm=m.stock_allowance_mm, bore_mm=bore_mm, mill_bore=m.mill_bore,
               helix_pitch_mm=m.helix_pitch_mm, ramp_angle_deg=m.ramp_angle_deg, notes=cd.notes)


@dataclass(frozen=True)
class Program:
    """A complete milling program in the common model, ready for a post-processor.

    Attributes
    ----------
    job : Job
    items : tuple of Item
        The blocks in order (mm, absolute).
    compensation : {None, "G41", "G42"}
        ``None``: coordinates are tool-centre; otherwise the part contour with cutter compensation.
    contour : tuple of Segment
        The finishing contour as traversed (tool-centre path, or the part profile when compensated).
    roughing : tuple of tuple of Segment
        The roughing contours, outermost first.
    notes : tuple of str
        Header lines: the job's cutting-data notes, the stock, the depth, the entry and the bore.
    milled : str
        What is milled, for the header (``"outside contour"``, or a groove's slot); only an outside contour has
        roughing passes in the header.
    """

    job: Job
    items: tuple
    compensation: str | None = None
    contour: tuple = ()
    roughing: tuple = field(default=())
    notes: tuple = ()
    #: what is milled, for the header: the periphery, or a groove's slot (camfab.gcode.groove)
    milled: str = "outside contour"


#: the overrides of :func:`design_job` that are [manufacturing] values, not [machining] ones
_MFG_OVERRIDES = ("tool_diameter_mm", "material")


def machining_of(spec: Any, overrides: Mapping[str, Any] | None = None) -> MachiningSpec:
    """A design's ``[machining]`` with the given overrides applied (None values ignored)."""
    over = {k: v for k, v in (overrides or {}).items() if v is not None and k not in _MFG_OVERRIDES}
    return replace(spec.machining, **over)


def design_job(spec: Any, *, tol: float, overrides: Mapping[str, Any] | None = None) -> Job:
    """The :class:`Job` of a validated design: ``[manufacturing]`` tool, thickness, material and bore and
    ``[machining]``, each value replaced by ``overrides[key]`` when given (not None); ``tool_diameter_mm``
    and ``material`` may be overridden too.  Cutting data the design does not give come from the cutting-data table
    (:func:`job_from_machining`).  A groove cam's job mills a slot: to the groove depth, no breakthrough, no bore.

    Raises
    ------
    SpecError
        No tool diameter, or a job value out of range.
    """
    over = {k: v for k, v in (overrides or {}).items() if v is not None}
    m = machining_of(spec, over)
    tool = over.get("tool_diameter_mm", spec.manufacturing.tool_diameter_mm)
    if not tool:
        raise SpecError(Problem("manufacturing.tool_diameter_mm", None, "G-code needs a tool",
                                "add tool_diameter_mm to [manufacturing] (or give --tool-diameter)"), spec.source)
    mfg = spec.manufacturing
    m = replace(m, breakthrough_mm=0.0, mill_bore=False) if spec.cam.kind == "groove" else m  # a slot (README)
    return job_from_machining(m, tool_diameter_mm=tool, thickness_mm=spec.follower.groove_depth_mm or mfg.thickness_mm,
                              material=over.get("material", mfg.material),
                              bore_mm=mfg.bore_mm, stock_shape="plate" if spec.is_translating_cam else "round",
                              tolerance_mm=tol, design_name=spec.name, source=spec.source)
