"""``[sizing]`` of a design (what ``camfab size`` sizes): its values and their validation, without the sizing
itself (:mod:`camfab.design.sizing_plan`, which re-exports these names and is imported only by the commands that
size)."""
from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

from ..records import dataclass
from .validator import Validator

__all__ = ["SizingSpec", "sizing_section", "SIZER_NAMES"]

#: the sizing constraints' names in ``[sizing] constraints`` (the keys of ``sizing_plan.SIZERS``, in order)
SIZER_NAMES = ("pressure_angle", "undercut", "cusp", "cutter", "contact_stress")

_KEYS = ("constraints", "pressure_angle_limit_deg", "tool_radius_mm", "set_offset", "set_pivot",
         "pivot_distance_mm", "arm_length_mm", "round_up_mm")


@dataclass(frozen=True, slots=True)
class SizingSpec:
    """``[sizing]``: which constraints size the base radius, their limits and the follower changes allowed.

    ``constraints`` None: every constraint that applies to the follower.  ``pressure_angle_limit_deg`` None:
    ``[checks]``'s (else 30° translating, 35° oscillating); ``tool_radius_mm`` None: half ``[manufacturing]
    tool_diameter_mm``.  ``pivot_distance_mm`` / ``arm_length_mm``: the (lo, hi) ranges searched for an
    oscillating roller (None: 0.8 to 1.5 times the design's)."""

    constraints: tuple[str, ...] | None = None
    pressure_angle_limit_deg: float | None = None
    tool_radius_mm: float | None = None
    set_offset: bool = False
    set_pivot: bool = False
    pivot_distance_mm: tuple[float, float] | None = None
    arm_length_mm: tuple[float, float] | None = None
    round_up_mm: float = 0.01


def sizing_section(v: Validator, t: Mapping[str, Any]) -> SizingSpec:
    """Read ``[sizing]`` (problems collected in ``v``)."""
    v.keys(t, _KEYS, "sizing")
    cons = t.get("constraints")
    if cons is not None:
        if not isinstance(cons, list) or not cons or not all(isinstance(c, str) for c in cons):
            v.add("sizing.constraints", cons, "must be a non-empty list of names",
                  "e.g. constraints = [\"pressure_angle\", \"undercut\"]; names: " + ", ".join(SIZER_NAMES))
            cons = None
        else:
            for i, c in enumerate(cons):
                if c not in SIZER_NAMES:
                    v.add(f"sizing.constraints[{i}]", c, "unknown sizing constraint",
                          "use one of: " + ", ".join(SIZER_NAMES))
            cons = tuple(dict.fromkeys(c for c in cons if c in SIZER_NAMES)) or None
    pa = v.number(t, "pressure_angle_limit_deg", "sizing", None, lo=0.0, hi=90.0, lo_open=True, hi_open=True)
    tool = v.number(t, "tool_radius_mm", "sizing", None, lo=0.0, hi=1e4, lo_open=True,
                    fix="give the cutter radius in mm (> 0), or leave it out to use [manufacturing] tool_diameter_mm")
    rnd = v.number(t, "round_up_mm", "sizing", 0.01, lo=0.0, hi=10.0, lo_open=True,
                   fix="give the step the radius is rounded up to, in mm (0 < step <= 10)")
    return SizingSpec(cons, pa, tool, v.boolean(t, "set_offset", "sizing", False),
                      v.boolean(t, "set_pivot", "sizing", False), _range(v, t, "pivot_distance_mm"),
                      _range(v, t, "arm_length_mm"), rnd)


def _range(v: Validator, t: Mapping[str, Any], key: str) -> tuple[float, float] | None:
    if key not in t:
        return None
    r = t[key]
    ok = isinstance(r, list) and len(r) == 2 and all(
        isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x) for x in r)
    if not ok or not 0 < r[0] < r[1] <= 1e6:
        v.add(f"sizing.{key}", r, "must be a range [lo, hi] of lengths with 0 < lo < hi <= 1e6",
              f"e.g. {key} = [40.0, 80.0]")
        return None
    return float(r[0]), float(r[1])
