"""The continuity rule: ``VELOCITY_/ACCELERATION_/JERK_DISCONTINUITY`` at the motion's junctions
(and the internal breaks of piecewise laws), with the motion's peaks for the report
(:func:`camfab.design.motion_report.analyse_motion`)."""
from __future__ import annotations

from collections.abc import Sequence
from typing import Any, cast

from ...results import Finding
from ..motion_report import analyse_motion
from ..profile import CamGeometry
from ..program import MotionProgram
from .common import ContactSample, Limits, RuleResult

__all__ = ["continuity_rule"]


def continuity_rule(geometry: CamGeometry, limits: Limits, samples: Sequence[ContactSample]) -> RuleResult:
    """The continuity findings of every distinct motion program of the cam; the first one's peaks and
    junctions go into the report.  A motion derived from another (a conjugate pair's S₂ = h − S₁) has
    no junctions of its own and is skipped."""
    findings: list[Finding] = []
    fields: dict[str, Any] = {}
    seen: list[Any] = []
    for c in geometry.profiles:
        if any(c.motion is m for m in seen) or not hasattr(c.motion, "junctions"):
            continue
        seen.append(c.motion)
        lift_unit = "deg" if c.oscillating else "mm"
        rep = analyse_motion(cast(MotionProgram, c.motion), speed=limits.speed, lift_unit=lift_unit,
                             allow_acceleration_jump=limits.allow_acceleration_jump)
        fields.setdefault("motion", rep)
        findings += rep.findings
    return RuleResult(tuple(findings), fields)
