"""The common toolpath model and the 2.5D contour-milling program builder.

Conventions
-----------
* All coordinates, lengths and feeds in the model are **millimetres** (feeds mm/min), whatever units the
  program is finally written in: the post-processor converts (``Job.units``).
* The top of the stock is ``Z = 0``; cutting depths are negative, the final depth is ``-Job.depth_mm``.
* Outside milling of a plate cam: the part lies inside the closed contour.  With the spindle turning
  clockwise (M3) *climb* milling runs clockwise around the part (G41 side), *conventional* runs
  counter-clockwise (G42 side).
* The program carries **tool-centre** coordinates (the contour given is the tool-centre path from the
  offset module) unless ``compensation="G41"|"G42"`` is asked for; then the contour given is the finished
  part profile and the controller offsets it.
* Structural comments label every pass: ``ROUGH PASS k OF N LEVEL i OF m``, ``FINISH PASS LEVEL i OF m``,
  then ``<KIND> LEAD-IN``, ``<KIND> CONTOUR``, ``<KIND> LEAD-OUT`` with ``KIND`` = ``ROUGH``/``FINISH``.
  :func:`camfab.gcode.verify.verify` uses the ``FINISH CONTOUR`` label to measure the deviation.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Sequence, Union

import numpy as np

from camfab.errors import GeometryError, Problem, SpecError
from camfab.gcode.geom import TWO_PI, ContourDistance, arc_sweep
from camfab.tolerances import MAX_EXPORT_TOL_MM, MIN_EXPORT_TOL_MM

__all__ = [
    "CLOSE_TOL_MM",
    "Segment",
    "Rapid",
    "Feed",
    "Arc",
    "Comment",
    "ToolChange",
    "Spindle",
    "Coolant",
    "CutterComp",
    "Item",
    "Job",
    "Program",
    "as_contour",
    "contour_is_clockwise",
    "orient_contour",
    "offset_contour",
    "contour_toolpath",
]

#: consecutive contour entities must meet within this distance (mm)
CLOSE_TOL_MM = 1e-6
#: an arc's start and end radii must agree within this (mm, plus 1e-9 relative)
ARC_RADIUS_TOL_MM = 1e-6


def _pt(p) -> tuple[float, float]:
    x, y = (float(v) for v in p)
    return (x, y)


def _rot(v):
    """Rotate a 2-vector by +90 degrees."""
    return np.array([-v[1], v[0]])


# --------------------------------------------------------------------------------------------------
# contour entities


@dataclass(frozen=True)
class Segment:
    """One entity of a closed planar contour: a line, or an arc when ``center`` is given.

    Parameters
    ----------
    start, end : tuple of float
        End points ``(x, y)`` in mm.  An arc whose start equals its end is a full circle.
    center : tuple of float or None
        Arc centre; ``None`` for a straight line.
    clockwise : bool
        Arc direction (ignored for lines).
    """

    start: tuple[float, float]
    end: tuple[float, float]
    center: tuple[float, float] | None = None
    clockwise: bool = False

    def __post_init__(self):
        object.__setattr__(self, "start", _pt(self.start))
        object.__setattr__(self, "end", _pt(self.end))
        if self.center is not None:
            object.__setattr__(self, "center", _pt(self.center))
        object.__setattr__(self, "clockwise", bool(self.clockwise))

    @property
    def is_arc(self) -> bool:
        """True for an arc."""
        return self.center is not None

    @property
    def radius(self) -> float:
        """Arc radius (distance from the centre to the start), mm; ``inf`` for a line."""
        if self.center is None:
            return math.inf
        return math.hypot(self.start[0] - self.center[0], self.start[1] - self.center[1])

    @property
    def sweep(self) -> float:
        """Signed sweep in radians (negative clockwise); 0 for a line."""
        if self.center is None:
            return 0.0
        return arc_sweep(self.start, self.end, self.center, self.clockwise)

    @property
    def length(self) -> float:
        """Length in mm."""
        if self.center is None:
            return math.hypot(self.end[0] - self.start[0], self.end[1] - self.start[1])
        return abs(self.sweep) * self.radius

    def reversed(self) -> "Segment":
        """The same entity traversed the other way."""
        return Segment(self.end, self.start, self.center, not self.clockwise)

    def point(self, u: float) -> np.ndarray:
        """Point at parameter ``u`` in [0, 1] (by length)."""
        if u >= 1.0:
            return np.array(self.end)
        if self.center is None:
            s, e = np.array(self.start), np.array(self.end)
            return s + u * (e - s)
        cx, cy = self.center
        a = math.atan2(self.start[1] - cy, self.start[0] - cx) + u * self.sweep
        return np.array([cx + self.radius * math.cos(a), cy + self.radius * math.sin(a)])

    def tangent(self, u: float) -> np.ndarray:
        """Unit tangent in the direction of travel at parameter ``u``."""
        if self.center is None:
            d = np.array(self.end) - np.array(self.start)
            return d / np.hypot(*d)
        p = self.point(u)
        r = (p - np.array(self.center)) / self.radius
        return -_rot(r) if self.clockwise else _rot(r)

    def split(self, u: float) -> tuple["Segment", "Segment"]:
        """Split at parameter ``u`` into two entities."""
        m = tuple(self.point(u))
        return Segment(self.start, m, self.center, self.clockwise), Segment(m, self.end, self.center,
                                                                            self.clockwise)

    def polyline(self, n: int) -> np.ndarray:
        """``n + 1`` points along the entity, both ends included (array ``(n+1, 2)``)."""
        u = np.linspace(0.0, 1.0, n + 1)
        if self.center is None:
            s, e = np.array(self.start), np.array(self.end)
            return s + u[:, None] * (e - s)
        cx, cy = self.center
        a = math.atan2(self.start[1] - cy, self.start[0] - cx) + u * self.sweep
        pts = np.column_stack([cx + self.radius * np.cos(a), cy + self.radius * np.sin(a)])
        pts[-1] = self.end
        return pts


def _as_segment(e, i: int) -> Segment:
    if isinstance(e, Segment):
        return e
    if isinstance(e, dict):
        c = e.get("center", e.get("centre"))
        return Segment(e["start"], e["end"], c, bool(e.get("clockwise", False)))
    if hasattr(e, "start") and hasattr(e, "end"):
        c = getattr(e, "center", getattr(e, "centre", None))
        return Segment(e.start, e.end, c, bool(getattr(e, "clockwise", False)))
    try:
        t = tuple(e)
    except TypeError:
        raise GeometryError(f"contour entity {i}: {e!r} is not a line or an arc") from None
    if len(t) == 2:
        return Segment(t[0], t[1])
    if len(t) == 4:
        return Segment(t[0], t[1], t[2], bool(t[3]))
    raise GeometryError(f"contour entity {i}: expected (start, end) or (start, end, centre, clockwise), "
                        f"got {len(t)} items")


def as_contour(entities) -> tuple[Segment, ...]:
    """Normalise and check a closed contour.

    Parameters
    ----------
    entities : iterable
        Lines and arcs: :class:`Segment` objects, tuples ``(start, end)`` / ``(start, end, centre,
        clockwise)``, dicts with keys ``start``, ``end``, ``center`` (or ``centre``), ``clockwise``, or
        objects with those attributes.

    Returns
    -------
    tuple of Segment

    Raises
    ------
    GeometryError
        Empty, open (consecutive entities more than :data:`CLOSE_TOL_MM` apart), degenerate, or an arc
        whose end is not on its circle.
    """
    if isinstance(entities, Segment):
        entities = [entities]
    segs = tuple(_as_segment(e, i) for i, e in enumerate(entities))
    if not segs:
        raise GeometryError("the contour has no entities")
    for i, s in enumerate(segs):
        if not all(math.isfinite(v) for v in s.start + s.end + (s.center or ())):
            raise GeometryError(f"contour entity {i}: non-finite coordinates")
        if s.is_arc:
            r0 = s.radius
            r1 = math.hypot(s.end[0] - s.center[0], s.end[1] - s.center[1])
            if r0 <= CLOSE_TOL_MM:
                raise GeometryError(f"contour entity {i}: arc of zero radius")
            if abs(r1 - r0) > ARC_RADIUS_TOL_MM + 1e-9 * r0:
                raise GeometryError(f"contour entity {i}: arc end is {abs(r1 - r0):.3g} mm off its circle "
                                    f"(start radius {r0:.6f} mm, end radius {r1:.6f} mm)")
        elif s.length <= CLOSE_TOL_MM:
            raise GeometryError(f"contour entity {i}: zero-length line at {s.start}")
    for i, s in enumerate(segs):
        nxt = segs[(i + 1) % len(segs)]
        gap = math.hypot(nxt.start[0] - s.end[0], nxt.start[1] - s.end[1])
        if gap > CLOSE_TOL_MM:
            j = (i + 1) % len(segs)
            raise GeometryError(f"the contour is not closed: entity {i} ends at {s.end} but entity {j} "
                                f"starts at {nxt.start} ({gap:.3g} mm apart)")
    return segs


def _signed_area(segs: Sequence[Segment]) -> float:
    pts = np.concatenate([s.polyline(max(4, int(math.ceil(abs(s.sweep) / TWO_PI * 64))))[:-1]
                          if s.is_arc else np.array([s.start]) for s in segs])
    x, y = pts[:, 0], pts[:, 1]
    return 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))


def contour_is_clockwise(entities) -> bool:
    """True when the closed contour runs clockwise (negative signed area)."""
    return _signed_area(as_contour(entities)) < 0.0


def orient_contour(entities, clockwise: bool) -> tuple[Segment, ...]:
    """Return the contour traversed clockwise (``clockwise=True``) or counter-clockwise."""
    segs = as_contour(entities)
    if contour_is_clockwise(segs) == clockwise:
        return segs
    return tuple(s.reversed() for s in reversed(segs))


def _outward(t: np.ndarray, cw: bool) -> np.ndarray:
    """Outward normal for a tangent on a contour around the part (part inside)."""
    return _rot(t) if cw else -_rot(t)


def offset_contour(entities, distance: float) -> tuple[Segment, ...]:
    """Offset a closed line/arc contour outward (``distance > 0``) or inward.

    Lines shift along their normal, arcs change radius, and convex corners (tangent discontinuities)
    get a round arc about the corner.  Meant for the roughing passes around a tool-centre contour, which
    is usually tangent-continuous; the cam offset module is the general tool.

    Parameters
    ----------
    entities : sequence
        Closed contour (see :func:`as_contour`); its orientation is kept.
    distance : float
        Offset in mm, positive away from the inside of the contour.

    Returns
    -------
    tuple of Segment

    Raises
    ------
    GeometryError
        A concave arc smaller than the offset, or a corner that would need trimming.
    """
    segs = as_contour(entities)
    d = float(distance)
    if d == 0.0:
        return segs
    cw = contour_is_clockwise(segs)
    out: list[Segment] = []
    for i, s in enumerate(segs):
        if not s.is_arc:
            n = _outward(s.tangent(0.0), cw)
            out.append(Segment(tuple(np.array(s.start) + d * n), tuple(np.array(s.end) + d * n)))
            continue
        convex = s.clockwise == cw
        R = s.radius
        newR = R + d if convex else R - d
        if newR <= CLOSE_TOL_MM:
            kind = "concave" if convex is False else "convex"
            raise GeometryError(f"contour entity {i}: {kind} arc of radius {R:.4f} mm cannot be offset by "
                                f"{d:.4f} mm (it vanishes); pass the offset contour explicitly")
        c = np.array(s.center)
        us = (np.array(s.start) - c) / R
        ue = np.array(s.end) - c
        ue = ue / np.hypot(*ue)
        full = math.hypot(s.end[0] - s.start[0], s.end[1] - s.start[1]) <= 1e-12
        start = tuple(c + newR * us)
        end = start if full else tuple(c + newR * ue)
        out.append(Segment(start, end, s.center, s.clockwise))
    result: list[Segment] = []
    sigma = -1.0 if cw else 1.0
    for i, o in enumerate(out):
        result.append(o)
        nxt = out[(i + 1) % len(out)]
        gap = math.hypot(nxt.start[0] - o.end[0], nxt.start[1] - o.end[1])
        if gap <= 1e-9 * max(1.0, abs(d)):
            continue
        ta = segs[i].tangent(1.0)
        tb = segs[(i + 1) % len(segs)].tangent(0.0)
        turn = float(ta[0] * tb[1] - ta[1] * tb[0])
        if sigma * turn * d > 0:
            result.append(Segment(o.end, nxt.start, segs[i].end, cw))
        else:
            raise GeometryError(f"offsetting by {d:.4f} mm: the corner at {segs[i].end} would need trimming; "
                                "pass the offset contour explicitly (roughing_contours=...)")
    return as_contour(_snap(result))


def _snap(segs: list[Segment]) -> list[Segment]:
    """Make each entity start exactly where the previous one ends (lines only move)."""
    out = list(segs)
    for i in range(len(out)):
        prev = out[i - 1]
        s = out[i]
        if s.start != prev.end and not s.is_arc:
            out[i] = Segment(prev.end, s.end)
    return out


# --------------------------------------------------------------------------------------------------
# program items


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


Item = Union[Rapid, Feed, Arc, Comment, ToolChange, Spindle, Coolant, CutterComp]

_DIRECTIONS = ("climb", "conventional")
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
        Plate thickness: the final cutting depth below the stock top (``Z = -depth_mm``).
    tool_number : int
        T word and length-offset register H (and D register for G41/G42).
    spindle_rpm : float
        Spindle speed (M3, clockwise).
    feed_mm_min, plunge_feed_mm_min : float
        Cutting feed and the vertical plunge feed.
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
    """

    tool_diameter_mm: float
    depth_mm: float
    tool_number: int = 1
    spindle_rpm: float = 3000.0
    feed_mm_min: float = 600.0
    plunge_feed_mm_min: float = 200.0
    step_down_mm: float = 3.0
    safe_z_mm: float = 25.0
    clearance_mm: float = 2.0
    roughing_allowance_mm: float = 0.2
    roughing_passes: int = 1
    roughing_stepover_mm: float | None = None
    direction: str = "climb"
    coolant: str = "flood"
    units: str = "mm"
    tolerance_mm: float = 0.001
    design_name: str = "cam"
    achieved_deviation_mm: float | None = None
    lead_radius_mm: float | None = None
    finish_full_depth: bool = True

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
        num("depth_mm")
        integer("tool_number", 1)
        if isinstance(self.tool_number, int) and self.tool_number > 99:
            P.append(Problem("job.tool_number", self.tool_number, "must be <= 99", "use a tool pocket 1..99"))
        num("spindle_rpm")
        num("feed_mm_min")
        num("plunge_feed_mm_min")
        num("step_down_mm")
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
    """

    job: Job
    items: tuple
    compensation: str | None = None
    contour: tuple = ()
    roughing: tuple = field(default=())


# --------------------------------------------------------------------------------------------------
# builder


def _choose_start(segs: tuple[Segment, ...], cw: bool) -> tuple[Segment, ...]:
    """Rotate the contour to start mid-way along its longest line, else its largest convex arc."""
    lines = [(s.length, -i) for i, s in enumerate(segs) if not s.is_arc]
    if lines:
        i = -max(lines)[1]
    else:
        convex = [(s.radius, abs(s.sweep), -i) for i, s in enumerate(segs) if s.clockwise == cw]
        if not convex:
            return segs
        i = -max(convex)[2]
    a, b = segs[i].split(0.5)
    return (b,) + segs[i + 1:] + segs[:i] + (a,)


def _contour_items(segs, z, feed) -> list:
    items = []
    for s in segs:
        if not s.is_arc:
            items.append(Feed(s.end[0], s.end[1], z, feed))
            continue
        pieces = [s]
        if abs(s.sweep) >= TWO_PI - 1e-12:  # a full circle always goes out as two halves
            pieces = list(s.split(0.5))
        for p in pieces:
            items.append(Arc(p.end[0], p.end[1], p.center[0], p.center[1], p.clockwise, z, feed))
    return items


def _lead_geometry(segs, cw, rho, comp_len):
    P = np.array(segs[0].start)
    t = segs[0].tangent(0.0)
    n = _outward(t, cw)
    C = P + rho * n
    q_in = C - rho * t
    q_out = C + rho * t
    lead_cw = float((-n[0]) * t[1] - (-n[1]) * t[0]) < 0
    a = q_in + comp_len * n
    b = q_out + comp_len * n
    return P, C, q_in, q_out, lead_cw, a, b


def contour_toolpath(path_entities, job: Job, *, roughing_contours=None,
                     compensation: str | None = None) -> Program:
    """Build the contour-milling program of a closed contour.

    Roughing passes (outermost first) at every depth level, then the finishing pass (at full depth in one
    level when there are roughing passes and ``job.finish_full_depth``; otherwise in the same
    step-downs).  Every pass: rapid at safe height to the lead-in point outside the part, rapid down to
    the clearance height, plunge at the plunge feed, a tangent lead-in arc (radius ``job.lead_radius``,
    centre outside the part), the contour, a tangent lead-out arc, and a rapid retract to the safe height.

    Parameters
    ----------
    path_entities : sequence
        Closed contour of lines and arcs (see :func:`as_contour`) around the part: the **tool-centre**
        path, or the finished **part** profile when ``compensation`` is given.  Its orientation is
        irrelevant: it is traversed as ``job.direction`` requires.
    job : Job
    roughing_contours : sequence of contours, optional
        The roughing paths, outermost first, e.g. from the offset module (one per roughing pass).
        Default: :func:`offset_contour` of the finishing contour by ``allowance + k * stepover``.
    compensation : {None, "G41", "G42"}
        Emit the part contour with cutter radius compensation.  With M3, G41 is climb and G42
        conventional; it must agree with ``job.direction``.  The compensated lead-in is a straight line
        of twice the tool radius followed by the lead-in arc (radius must exceed the tool radius).

    Returns
    -------
    Program

    Raises
    ------
    SpecError
        Options that contradict each other (field named).
    GeometryError
        Open or degenerate contour; with compensation, a concave arc smaller than the tool radius; a
        lead-in point that falls inside the contour.
    """
    if not isinstance(job, Job):
        raise SpecError(Problem("job", type(job).__name__, "must be a camfab.gcode.toolpath.Job", ""))
    cw = job.direction == "climb"
    r_tool = job.tool_radius_mm
    rho = job.lead_radius
    if compensation not in (None, "G41", "G42"):
        raise SpecError(Problem("compensation", compensation, "must be None, 'G41' or 'G42'",
                                "G41 for climb, G42 for conventional milling"))
    if compensation is not None:
        want = "G41" if cw else "G42"
        if compensation != want:
            raise SpecError(Problem("compensation", compensation,
                                    f"{compensation} with M3 on an outside contour is "
                                    f"{'climb' if compensation == 'G41' else 'conventional'} milling, "
                                    f"but job.direction is {job.direction!r}",
                                    f"use {want} or change job.direction"))
        if rho <= r_tool:
            raise SpecError(Problem("job.lead_radius_mm", rho,
                                    f"must exceed the tool radius ({r_tool} mm) with cutter compensation",
                                    "leave it unset (default: the tool diameter)"))

    oriented = orient_contour(path_entities, cw)
    finish = oriented
    if compensation is not None:
        for i, s in enumerate(finish):
            if s.is_arc and s.clockwise != cw and s.radius < r_tool:
                raise GeometryError(
                    f"part contour entity {i}: concave arc of radius {s.radius:.4f} mm from {s.start} to "
                    f"{s.end} is smaller than the tool radius {r_tool:.4f} mm; the largest tool that fits "
                    f"has diameter {2 * s.radius:.4f} mm")
    finish = _choose_start(finish, cw)

    N = job.roughing_passes
    if roughing_contours is not None:
        rough_in = list(roughing_contours)
        if len(rough_in) != N:
            raise SpecError(Problem("roughing_contours", len(rough_in),
                                    f"must hold job.roughing_passes = {N} contours",
                                    "pass one contour per roughing pass, outermost first"))
        rough = [_choose_start(orient_contour(c, cw), cw) for c in rough_in]
    else:
        rough = [_choose_start(offset_contour(oriented, job.roughing_allowance_mm + (N - 1 - k) * job.stepover),
                               cw) for k in range(N)]

    comp_len = 2.0 * r_tool if compensation else 0.0
    outside = ContourDistance(finish)
    levels = job.levels
    passes = []
    for li, z in enumerate(levels):
        for k, c in enumerate(rough):
            passes.append(("ROUGH", f"ROUGH PASS {k + 1} OF {N} LEVEL {li + 1} OF {len(levels)}", c, z))
    fin_levels = [levels[-1]] if (N > 0 and job.finish_full_depth) else list(levels)
    for li, z in enumerate(fin_levels):
        passes.append(("FINISH", f"FINISH PASS LEVEL {li + 1} OF {len(fin_levels)}", finish, z))

    items: list = [ToolChange(job.tool_number, job.tool_diameter_mm), Rapid(None, None, job.safe_z_mm),
                   Spindle(job.spindle_rpm)]
    if job.coolant != "off":
        items.append(Coolant(job.coolant))
    z_clear = job.clearance_mm
    for kind, label, segs, z in passes:
        P, C, q_in, q_out, lead_cw, a, b = _lead_geometry(segs, cw, rho, comp_len)
        first = a if compensation else q_in
        last = b if compensation else q_out
        pts = np.array([q_in, q_out, first, last])
        if np.any(outside(pts) <= 0.0):
            raise GeometryError(f"{label}: the lead-in/lead-out near {tuple(P)} falls inside the contour; "
                                "reduce job.lead_radius_mm")
        items.append(Comment(label))
        items += [Rapid(first[0], first[1], job.safe_z_mm), Rapid(first[0], first[1], z_clear),
                  Feed(first[0], first[1], z, job.plunge_feed_mm_min)]
        items.append(Comment(f"{kind} LEAD-IN"))
        if compensation:
            items += [CutterComp(compensation, job.tool_number), Feed(q_in[0], q_in[1], z, job.feed_mm_min)]
        items.append(Arc(P[0], P[1], C[0], C[1], lead_cw, z, job.feed_mm_min))
        items.append(Comment(f"{kind} CONTOUR"))
        items += _contour_items(segs, z, job.feed_mm_min)
        items.append(Comment(f"{kind} LEAD-OUT"))
        items.append(Arc(q_out[0], q_out[1], C[0], C[1], lead_cw, z, job.feed_mm_min))
        if compensation:
            items += [CutterComp("G40"), Feed(b[0], b[1], z, job.feed_mm_min)]
        items.append(Rapid(last[0], last[1], job.safe_z_mm))
    if job.coolant != "off":
        items.append(Coolant("off"))
    items.append(Spindle(0.0))
    return Program(job=job, items=tuple(items), compensation=compensation, contour=finish,
                   roughing=tuple(rough))
