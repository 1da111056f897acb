"""Profile verification: coded findings, the CAM-DAS conclusions and the verdict.

The checks are flat rules, registered in :data:`RULES` and run in that order by :func:`check`:

* :func:`continuity_rule` — velocity/acceleration/jerk jumps of the motion (and its peaks);
* :func:`curvature_rule` — undercut, cusp, concave stretches tighter than the cutter;
* :func:`pressure_angle_rule` — |δ| above its limit (rollers and knife edges);
* :func:`face_rule` — the flat-face length needed;
* :func:`extent_rule` — base and largest radius, area;
* :func:`contact_stress_rule` — Hertz contact stress above the allowable, roller and cam life (with forces).

A rule of the whole cam is a function ``(geometry, limits, samples) -> RuleResult``; a rule of one
contact is ``(contact, limits, sample) -> RuleResult`` and runs for every profile (consecutive
contact rules run profile by profile, so a profile's findings stay together).  A rule decides
from the contact's declared properties (``kind``, ``has_face``, ``oscillating``, ``axis``,
``closed``) whether it applies.  Every contact is evaluated once on its dense grid
(:class:`ContactSample`) and all its rules read that sample.  A new rule is one function plus
one entry in :data:`RULES`.

Verdict: any error → ``unacceptable``; else a jerk (or allowed acceleration) jump →
``not_for_high_speed``; else ``acceptable``.  Angles in findings are degrees of cam angle (mm of
travel for a translating cam); a range through 360° has ``from_deg > to_deg``.
"""
from __future__ import annotations

import dataclasses
import itertools
from collections.abc import Callable
from enum import StrEnum
from typing import Any

from ...records import dataclass
from ...results import CheckReport
from ..profile import CamGeometry
from .common import CUSP_TOL_MM, DEFAULT_PRESSURE_LIMIT_DEG, ContactSample, Limits, RuleResult
from .continuity import continuity_rule
from .curvature import curvature_rule
from .extent import extent_rule
from .face import face_rule
from .pressure import pressure_angle_rule
from .strength import contact_stress_rule

__all__ = ["check", "Limits", "RuleResult", "ContactSample", "Rule", "Scope", "RULES", "CUSP_TOL_MM",
           "DEFAULT_PRESSURE_LIMIT_DEG", "continuity_rule", "curvature_rule", "pressure_angle_rule", "face_rule",
           "extent_rule", "contact_stress_rule"]


class Scope(StrEnum):
    """What a rule is a function of."""

    #: ``(geometry, limits, samples)``: the whole cam
    CAM = "cam"
    #: ``(contact, limits, sample)``: one profile, run for each
    CONTACT = "contact"


@dataclass(frozen=True)
class Rule:
    """A registered check: its name, its scope and the function."""

    name: str
    scope: Scope
    run: Callable[..., RuleResult]


#: the checks, in the order their findings are reported
RULES: tuple[Rule, ...] = (
    Rule("continuity", Scope.CAM, continuity_rule),
    Rule("curvature", Scope.CONTACT, curvature_rule),
    Rule("pressure_angle", Scope.CONTACT, pressure_angle_rule),
    Rule("face", Scope.CONTACT, face_rule),
    Rule("extent", Scope.CAM, extent_rule),
    Rule("contact_stress", Scope.CAM, contact_stress_rule),
)


def check(geometry: CamGeometry, *, pressure_angle_limit_deg: float | None = None,
          allow_acceleration_jump: bool = False, tool_radius_mm: float | None = None,
          face_margin_mm: float = 0.0, name: str = "cam", speed: float = 1.0, strength: Any = None) -> CheckReport:
    """Verify a cam geometry: run every rule of :data:`RULES`.

    Parameters
    ----------
    geometry : CamGeometry
    pressure_angle_limit_deg : float, optional
        Limit on |δ| in degrees; default 30 (translating roller, translating cam) or 35 (oscillating).
    allow_acceleration_jump : bool
        Accept acceleration jumps (constant-width / constant-diameter cams).
    tool_radius_mm : float, optional
        Cutter radius: concave stretches tighter than it are reported.
    face_margin_mm : float
        Safety margin added to each required flat-face length (mm).
    name : str
        Cam name for the report.
    speed : float
        ω in rad/s (mm/s for a translating cam), for the motion peaks.
    strength : camfab.design.strength.StrengthInput, optional
        Contact-stress inputs: the ``contact_stress`` rule runs with them.

    Returns
    -------
    CheckReport
    """
    limits = Limits(pressure_angle_limit_deg, tool_radius_mm, face_margin_mm, allow_acceleration_jump, speed, strength)
    samples = [ContactSample(c) for c in geometry.profiles]
    multi = len(samples) > 1
    findings: list = []
    fields: dict[str, Any] = {}
    for scope, group in itertools.groupby(RULES, key=lambda r: r.scope):
        rules = list(group)
        if scope is Scope.CAM:
            results = [(r.run(geometry, limits, samples), "") for r in rules]
        else:
            results = [(r.run(s.contact, limits, s), _tag(s.contact, k) if multi else "")
                       for k, s in enumerate(samples) for r in rules]
        for res, tag in results:
            findings += [dataclasses.replace(f, message=tag + f.message) for f in res.findings] if tag else \
                res.findings
            _merge(fields, res.fields)
    if "motion" in fields:
        fields["motion"] = dataclasses.replace(fields["motion"], name=name)
    return CheckReport(name, tuple(findings), x_unit=geometry.axis.x_unit,
                       initial_arm_angle_deg=geometry.initial_arm_angle_deg, **fields)


def _tag(contact: Any, k: int) -> str:
    """How a finding names profile k of several: ``"profile 2: "``, or the contact's own ``label``."""
    return f"{contact.label or f'profile {k + 1}'}: "


def _merge(fields: dict[str, Any], new: dict[str, Any]) -> None:
    """File a rule's report fields: the first value of a field, merged with later ones where the
    field knows how (a summary of several profiles)."""
    for key, value in new.items():
        if key not in fields:
            fields[key] = value
        elif hasattr(fields[key], "merged"):
            fields[key] = fields[key].merged(value)
