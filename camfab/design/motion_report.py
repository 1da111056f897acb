"""Motion analysis: peaks in time units, junction continuity, findings and verdict.

The verdict rules are CAM-DAS's, restricted to what the motion alone decides:

* a velocity or acceleration discontinuity → ``unacceptable`` (constant-width and
  constant-diameter cams are allowed an acceleration jump: a warning);
* otherwise a jerk discontinuity → ``not_for_high_speed``;
* otherwise ``acceptable``.

Continuity is judged on the per-radian derivatives (independent of ω) at every segment junction,
360°→0° included, and at the internal breakpoints of piecewise laws (constant acceleration jumps
inside its segment).
"""
from __future__ import annotations

import math

from ..results import Extreme, Finding, IssueCode, Junction, MotionPeaks, MotionReport, Severity
from .kinds import Axis
from .program import MotionProgram, Peak

__all__ = ["analyse_motion"]

#: the quantity whose jump a junction of order k (0, 1, 2) is, and its name
_JUMP = {0: (IssueCode.VELOCITY_DISCONTINUITY, "velocity"), 1: (IssueCode.ACCELERATION_DISCONTINUITY, "acceleration"),
         2: (IssueCode.JERK_DISCONTINUITY, "jerk")}


def _user(x: float, axis: Axis) -> float:
    """A program parameter in user units: degrees of cam angle, or mm of travel."""
    return math.degrees(x) if axis.rotating else x


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
    axis = prog.axis
    peaks = MotionPeaks(*(_peak(p, speed**k, axis) for k, p in enumerate(prog.peaks(peaks_mode))))
    wrap = 360.0 if axis.rotating else prog.period
    junctions, findings = [], []
    for j in prog.junctions(internal=True):
        at = round(_user(j.at, axis), 12) % wrap
        if j.segment is not None:
            junctions.append(Junction(at, j.continuity, j.segment))
        if j.order < 3:
            findings.append(_jump_finding(j.order, at, j.jumps, speed, lift_unit, allow_acceleration_jump,
                                          j.segment is None))
    return MotionReport(name, lift_unit, axis.x_unit, speed, peaks_mode, peaks, tuple(junctions), tuple(findings))


def _peak(p: Peak, scale: float, axis: Axis) -> Extreme:
    return Extreme(p.min * scale, _user(p.at_min, axis), p.max * scale, _user(p.at_max, axis))


def _jump_finding(order: int, at: float, jumps, speed: float, unit: str, allow_acc: bool,
                  internal: bool) -> Finding:
    code, word = _JUMP[max(order, 0)]
    k = max(order + 1, 1)
    size = jumps[k] * speed**k
    where = "inside a segment" if internal else "at a segment junction"
    if code is IssueCode.JERK_DISCONTINUITY:
        sev, effect = Severity.WARNING, "the cam is not suitable for high speeds"
    elif code is IssueCode.ACCELERATION_DISCONTINUITY and allow_acc:
        sev, effect = Severity.WARNING, "accepted for constant-width/diameter cams (low speed only)"
    else:
        word2 = "acceleration" if code is IssueCode.VELOCITY_DISCONTINUITY else "jerk"
        sev, effect = Severity.ERROR, f"infinite {word2} in theory: the cam is unacceptable"
    units = {1: f"{unit}/s", 2: f"{unit}/s2", 3: f"{unit}/s3"}[k]
    msg = f"{word} jumps by {size:.6g} {units} at {at:.6g} ({where}); {effect}"
    return Finding(code, sev, at, at, size, 0.0, msg)
