"""``camfab size``: the ``[sizing]`` table and the sizing of a whole design.

Each constraint of :data:`SIZERS` gives the smallest base radius at which it holds (the helpers of
:mod:`camfab.design.sizing`); the largest of them governs, rounded up to ``round_up_mm`` so that the sized
design passes the checks rather than sitting on their limit.  A translating roller's best offset and an
oscillating roller's best pivot distance and arm length (least peak pressure angle) are reported and, on
request (``set_offset`` / ``set_pivot``), written into the design before its radius is sized.

A new constraint is one more :class:`Sizer` in :data:`SIZERS` and its name in ``sizing_spec.SIZER_NAMES`` (the
contact-stress limit is one: it reads the design's force model and materials through the ``peak_stress``
function of the limits).
"""
from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Mapping
from typing import Any

from ..errors import InputError, Problem, SpecError
from ..records import dataclass
from .checks import DEFAULT_PRESSURE_LIMIT_DEG
from .kinds import FollowerMotion
from .mechanisms import OscillatingFlat, OscillatingRoller, TranslatingFlat, TranslatingRoller, mechanism_from_spec
from .profile import MotionLike
from .sizing import (
    best_pivot_and_arm,
    min_base_radius_for_cutter,
    min_base_radius_for_pressure_angle,
    min_base_radius_for_stress,
    min_base_radius_no_cusp,
    min_base_radius_no_undercut,
    optimal_offset,
    peak_pressure_angle_deg,
)
from .sizing_spec import SizingSpec, sizing_section

__all__ = ["SizingSpec", "Sizer", "SIZERS", "SizingRow", "SizingResult", "sizing_section", "size_design"]

@dataclass(frozen=True)
class Sizer:
    """One sizing constraint: why it does not apply to a mechanism (None: it applies), and the smallest
    base radius (mm) meeting it, given the mechanism, the motion and the resolved limits."""

    title: str
    not_applicable: Callable[[Any, Mapping[str, Any]], str | None]
    smallest: Callable[[Any, MotionLike, Mapping[str, Any]], float]


_ROLLERS = (TranslatingRoller, OscillatingRoller)
_FLATS = (TranslatingFlat, OscillatingFlat)


def _rollers_only(mech: Any, lim: Mapping[str, Any]) -> str | None:
    return None if isinstance(mech, _ROLLERS) else "roller followers only"


def _undercut_na(mech: Any, lim: Mapping[str, Any]) -> str | None:
    if not isinstance(mech, _ROLLERS):
        return "roller followers only (a flat face: see cusp)"
    return "a knife edge cannot undercut" if mech.roller_radius_mm <= 0 else None


def _cutter_na(mech: Any, lim: Mapping[str, Any]) -> str | None:
    if not isinstance(mech, _ROLLERS):
        return "a flat face's profile has no concave stretch"
    return None if lim.get("tool_radius_mm") else "no cutter: give [manufacturing] tool_diameter_mm"


def _stress_na(mech: Any, lim: Mapping[str, Any]) -> str | None:
    if lim.get("peak_stress") is None:
        return "no contact force: give [dynamics] (the materials: [strength])"
    if isinstance(mech, _ROLLERS) and mech.roller_radius_mm <= 0:
        return "a knife edge's contact stress is infinite: use a roller"
    return None


#: the sizing constraints, by their name in ``[sizing] constraints``
SIZERS: dict[str, Sizer] = {
    "pressure_angle": Sizer(
        "pressure angle ≤ limit", _rollers_only,
        lambda m, p, lim: min_base_radius_for_pressure_angle(m, p, lim["pressure_angle_limit_deg"])),
    "undercut": Sizer("no undercut (pitch radius ≥ roller)", _undercut_na,
                      lambda m, p, lim: min_base_radius_no_undercut(m, p)),
    "cusp": Sizer("no cusp (flat face ρ ≥ 0)",
                  lambda m, lim: None if isinstance(m, _FLATS) else "flat-face followers only",
                  lambda m, p, lim: min_base_radius_no_cusp(m, p)),
    "cutter": Sizer("concave radius ≥ cutter radius", _cutter_na,
                    lambda m, p, lim: min_base_radius_for_cutter(m, p, float(lim["tool_radius_mm"] or 0.0))),
    "contact_stress": Sizer("Hertz contact stress ≤ allowable", _stress_na,
                            lambda m, p, lim: min_base_radius_for_stress(m, p, lim["peak_stress"],
                                                                         float(lim["allowable_contact_stress_mpa"]))),
}


def _peak_stress(spec: Any, program: MotionLike) -> Callable[[Any], float] | None:
    """The peak contact stress (MPa, both followers; +inf where infinite) of the design's mechanism at another
    size: its force model and materials (``[dynamics]``, ``[strength]``); None without them."""
    if spec.dynamics is None or spec.strength is None:
        return None
    from .assemble import strength_input  # the design's force model; assemble imports spec, which imports us
    from .profile import CamGeometry
    from .strength import analyse_strength

    def peak(mech: Any) -> float:
        geom = CamGeometry(mech, program)
        inp = strength_input(spec, geom)
        summary = analyse_strength(geom, inp)[0] if inp is not None else None
        return math.inf if summary is None or summary.max_mpa is None else float(summary.max_mpa)
    return peak


@dataclass(frozen=True)
class SizingRow:
    """A constraint's smallest base radius (None with the reason when it does not apply)."""

    constraint: str
    title: str
    radius_mm: float | None
    note: str = ""
    governing: bool = False


@dataclass(frozen=True)
class SizingResult:
    """What ``camfab size`` found: the rows, the governing constraint and the design changes (design-file
    key paths → new values)."""

    rows: tuple[SizingRow, ...]
    governing: str
    base_radius_mm: float
    changes: Mapping[str, float]
    limits: Mapping[str, float | None]
    best_offset_mm: float | None = None
    best_pivot_mm: tuple[float, float] | None = None
    peak_pressure_angle_deg: float | None = None

    def to_dict(self) -> dict[str, Any]:
        return {"governing": self.governing, "base_radius_mm": self.base_radius_mm,
                "constraints": [{"constraint": r.constraint, "radius_mm": r.radius_mm, "governing": r.governing,
                                 "note": r.note} for r in self.rows],
                "limits": dict(self.limits), "best_offset_mm": self.best_offset_mm,
                "best_pivot_distance_mm": None if self.best_pivot_mm is None else self.best_pivot_mm[0],
                "best_arm_length_mm": None if self.best_pivot_mm is None else self.best_pivot_mm[1],
                "peak_pressure_angle_deg": self.peak_pressure_angle_deg, "changes": dict(self.changes)}


# ---------------------------------------------------------------------------
# ---------------------------------------------------------------------------
def size_design(spec: Any) -> SizingResult:
    """Size a validated design's base radius for its ``[sizing]`` constraints (the mechanism's other
    dimensions kept, or set to their best values on request).

    Raises
    ------
    SpecError
        A constraint named in ``[sizing] constraints`` that does not apply to the follower, or a follower
        family that has no base radius to size (field path and fix).
    InputError
        No base radius meets a constraint.
    """
    sz: SizingSpec = spec.sizing
    mech = mechanism_from_spec(spec)
    if not isinstance(mech, (*_ROLLERS, *_FLATS)):
        raise SpecError(Problem("follower.type", f"{spec.cam.kind} cam, {spec.follower.motion} {spec.follower.type}",
                                "camfab size sizes the base circle of disc cams with roller, knife-edge or flat-face "
                                "followers", "size this design by hand (its base radius is fixed by the "
                                "follower distance or the cam length)"), spec.source)
    program = spec.program()
    osc = spec.follower.motion == FollowerMotion.OSCILLATING
    tool = sz.tool_radius_mm or (spec.manufacturing.tool_diameter_mm / 2 if spec.manufacturing.tool_diameter_mm
                                 else None)
    pa = sz.pressure_angle_limit_deg or spec.pressure_angle_limit_deg or \
        DEFAULT_PRESSURE_LIMIT_DEG["oscillating" if osc else "translating"]
    limits: dict[str, Any] = {"pressure_angle_limit_deg": pa, "tool_radius_mm": tool,
                              "peak_stress": _peak_stress(spec, program),
                              "allowable_contact_stress_mpa": spec.strength.allowable_mpa if spec.strength else None}
    wanted = sz.constraints or tuple(SIZERS)
    for i, name in enumerate(sz.constraints or ()):
        why = SIZERS[name].not_applicable(mech, limits)
        if why:
            raise SpecError(Problem(f"sizing.constraints[{i}]", name, f"does not apply to this follower ({why})",
                                    "remove it from [sizing] constraints"), spec.source)
    rows, gov, rb = _size_rows(mech, program, wanted, limits)
    mech, changes, best_e, best_pa = _follower_changes(mech, program, sz, rb)
    if changes:  # sized again with the better follower
        rows, gov, rb = _size_rows(mech, program, wanted, limits)
    step = sz.round_up_mm
    sized = math.ceil(rb / step * (1 - 1e-12)) * step
    sized = float(f"{sized:.10g}")
    if sized <= rb:
        sized = float(f"{sized + step:.10g}")
    changes["follower.base_radius_mm"] = sized
    mech = dataclasses.replace(mech, base_radius_mm=sized)
    peak = peak_pressure_angle_deg(mech, program) if isinstance(mech, _ROLLERS) else None
    stated = {k: v for k, v in limits.items() if k != "peak_stress"}  # the numbers, not the stress model
    return SizingResult(tuple(rows), gov, sized, changes, stated, best_e, best_pa, peak)


def _follower_changes(mech: Any, program: MotionLike, sz: SizingSpec, rb: float) -> tuple[
        Any, dict[str, float], float | None, tuple[float, float] | None]:
    """The best offset (translating roller) or pivot distance and arm length (oscillating roller) at base radius
    ``rb``; set into the mechanism (and the changes) when ``[sizing]`` asks."""
    changes: dict[str, float] = {}
    best_e = best_pa = None
    if isinstance(mech, TranslatingRoller):
        best_e = optimal_offset(dataclasses.replace(mech, base_radius_mm=rb), program)
        if sz.set_offset:
            changes["follower.offset_mm"] = _round(best_e, 1e-4)
            mech = dataclasses.replace(mech, offset_mm=changes["follower.offset_mm"])
    elif isinstance(mech, OscillatingRoller):
        m0, a0 = mech.pivot_distance_mm, mech.arm_length_mm
        best_pa = best_pivot_and_arm(dataclasses.replace(mech, base_radius_mm=rb), program,
                                     sz.pivot_distance_mm or (0.8 * m0, 1.5 * m0),
                                     sz.arm_length_mm or (0.8 * a0, 1.5 * a0))
        if sz.set_pivot:
            m, a = _round(best_pa[0], 1e-3), _round(best_pa[1], 1e-3)
            changes["follower.pivot_distance_mm"], changes["follower.arm_length_mm"] = m, a
            mech = dataclasses.replace(mech, pivot_distance_mm=m, arm_length_mm=a)
    return mech, changes, best_e, best_pa


def _size_rows(mech: Any, program: MotionLike, wanted: tuple[str, ...],
               limits: Mapping[str, Any]) -> tuple[list[SizingRow], str, float]:
    """Every constraint's row, the governing constraint and its radius."""
    rows: list[SizingRow] = []
    for name in wanted:
        s = SIZERS[name]
        why = s.not_applicable(mech, limits)
        if why:
            rows.append(SizingRow(name, s.title, None, f"does not apply: {why}"))
            continue
        r = float(s.smallest(mech, program, limits))
        rows.append(SizingRow(name, s.title, r, "never binds (the smallest radius the follower allows)"
                              if r <= _least(mech) * (1 + 1e-6) + 1e-6 else ""))
    sized = [r for r in rows if r.radius_mm is not None]
    if not sized:
        raise InputError("no sizing constraint applies to this follower; name one in [sizing] constraints "
                         "(" + ", ".join(SIZERS) + ")")
    top = max(sized, key=lambda r: r.radius_mm or 0.0)
    rows = [dataclasses.replace(r, governing=True) if r is top else r for r in rows]
    return rows, top.constraint, float(top.radius_mm or 0.0)


def _least(mech: Any) -> float:
    """The smallest base radius the follower's geometry allows (an offset or an arm must reach the prime circle)."""
    if isinstance(mech, OscillatingRoller):
        return max(abs(mech.arm_length_mm - mech.pivot_distance_mm) - mech.roller_radius_mm, 0.0)
    if isinstance(mech, TranslatingRoller):
        return max(abs(mech.offset_mm) - mech.roller_radius_mm, 0.0)
    if isinstance(mech, OscillatingFlat):
        return max(mech.face_offset_mm - mech.pivot_distance_mm, 0.0)
    return 0.0


def _round(x: float, step: float) -> float:
    return float(f"{round(x / step) * step:.10g}")
