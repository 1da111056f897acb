"""Motion analysis: peaks in time units, junction continuity, findings and verdict.

The verdict rules are CAM-DAS's (``spec/camdas-reference.md`` §1.6), restricted
to what the motion alone decides:

* a velocity or acceleration discontinuity → ``unacceptable`` (constant-width
  and constant-diameter cams are allowed an acceleration jump);
* otherwise a jerk discontinuity → ``not_for_high_speed``;
* otherwise ``acceptable``.

Continuity is judged on the per-radian derivatives (independent of ω) at every
segment junction, 360°→0° included, and at the internal breakpoints of
piecewise laws (constant acceleration jumps inside its segment).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

from .program import MotionProgram, Peak

__all__ = ["Finding", "MotionReport", "analyse_motion", "VERDICTS", "combine_verdicts"]

VERDICTS = ("acceptable", "not_for_high_speed", "unacceptable")
_QUANTITIES = ("S", "V", "A", "J")
_JUMP = {0: ("VELOCITY_DISCONTINUITY", "velocity"), 1: ("ACCELERATION_DISCONTINUITY", "acceleration"),
         2: ("JERK_DISCONTINUITY", "jerk")}


@dataclass(frozen=True)
class Finding:
    """One coded check result (the ``findings`` items of ``check --json``)."""

    code: str
    severity: str  # "error" | "warning" | "info"
    from_deg: float | None
    to_deg: float | None
    value: float | None
    limit: float | None
    message: str

    def to_dict(self) -> dict[str, Any]:
        return {"code": self.code, "severity": self.severity, "from_deg": self.from_deg,
                "to_deg": self.to_deg, "value": self.value, "limit": self.limit, "message": self.message}


@dataclass(frozen=True)
class MotionReport:
    """Everything ``camfab motion`` prints, in user units (deg, mm or deg, seconds)."""

    name: str
    lift_unit: str
    x_unit: str  # "deg" for rotating cams, "mm" for translating cams
    speed: float  # rad/s or mm/s
    peaks_mode: str
    peaks: dict[str, dict[str, float]]
    junctions: list[dict[str, Any]]
    findings: list[Finding] = field(default_factory=list)

    @property
    def verdict(self) -> str:
        return verdict_of(self.findings)

    @property
    def has_errors(self) -> bool:
        return any(f.severity == "error" for f in self.findings)

    def to_dict(self) -> dict[str, Any]:
        return {"name": self.name, "verdict": self.verdict, "peaks": self.peaks, "peaks_mode": self.peaks_mode,
                "junctions": self.junctions, "findings": [f.to_dict() for f in self.findings],
                "units": {"x": self.x_unit, "S": self.lift_unit, "V": f"{self.lift_unit}/s",
                          "A": f"{self.lift_unit}/s2", "J": f"{self.lift_unit}/s3"},
                "speed": self.speed}


def verdict_of(findings: list[Finding]) -> str:
    """CAM-DAS verdict from coded findings."""
    if any(f.severity == "error" for f in findings):
        return "unacceptable"
    if any(f.code in ("JERK_DISCONTINUITY", "ACCELERATION_DISCONTINUITY") for f in findings):
        return "not_for_high_speed"
    return "acceptable"


def combine_verdicts(*verdicts: str) -> str:
    """The worst of several verdicts."""
    return max(verdicts, key=VERDICTS.index)


def _x_to_user(x: float, period: float) -> float:
    return math.degrees(x) if abs(period - 2 * math.pi) < 1e-12 else x


def analyse_motion(prog: MotionProgram, *, name: str = "cam", speed: float = 1.0,
                   lift_unit: str = "mm", peaks_mode: str = "exact",
                   allow_acceleration_jump: bool = False) -> MotionReport:
    """Analyse a motion program.

    Parameters
    ----------
    prog : MotionProgram
    speed : float
        ω in rad/s (or mm/s for a translating cam); time quantities are
        V = S′ω, A = S″ω², J = S‴ω³.
    lift_unit : str
        "mm" or "deg" (oscillating followers), used in labels only.
    peaks_mode : {"exact", "camdas"}
    allow_acceleration_jump : bool
        True for constant-width / constant-diameter cams.
    """
    per = prog.period
    raw = prog.peaks(peaks_mode)
    peaks = {q: _peak_dict(p, speed**k, per) for k, (q, p) in enumerate(zip(_QUANTITIES, raw))}
    junctions, findings = [], []
    for j in prog.junctions(internal=True):
        at = round(_x_to_user(j.at, per), 12) % (360.0 if abs(per - 2 * math.pi) < 1e-12 else per)
        if j.segment is not None:
            junctions.append({"at_deg": at, "continuity": j.continuity, "segment": j.segment})
        if j.order < 3:
            findings.append(_jump_finding(j.order, at, j.jumps, speed, lift_unit, allow_acceleration_jump,
                                          j.segment is None))
    return MotionReport(name, lift_unit, "deg" if abs(per - 2 * math.pi) < 1e-12 else "mm", speed,
                        peaks_mode, peaks, junctions, findings)


def _peak_dict(p: Peak, scale: float, period: float) -> dict[str, float]:
    return {"max": p.max * scale, "min": p.min * scale,
            "at_max_deg": _x_to_user(p.at_max, period), "at_min_deg": _x_to_user(p.at_min, period)}


def _jump_finding(order: int, at: float, jumps, speed: float, unit: str, allow_acc: bool,
                  internal: bool) -> Finding:
    code, word = _JUMP[max(order, 0)]
    k = max(order + 1, 1)
    size = jumps[k] * speed**k
    where = "inside a segment" if internal else "at a segment junction"
    if code == "JERK_DISCONTINUITY":
        sev, effect = "warning", "the cam is not suitable for high speeds"
    elif code == "ACCELERATION_DISCONTINUITY" and allow_acc:
        sev, effect = "warning", "accepted for constant-width/diameter cams (low speed only)"
    else:
        sev, effect = "error", "infinite " + ("acceleration" if code == "VELOCITY_DISCONTINUITY" else "jerk") + \
            " in theory: the cam is unacceptable"
    units = {1: f"{unit}/s", 2: f"{unit}/s2", 3: f"{unit}/s3"}[k]
    msg = f"{word} jumps by {size:.6g} {units} at {at:.6g} ({where}); {effect}"
    return Finding(code, sev, at, at, size, 0.0, msg)
