"""Text presenters of the command line: the motion summary and CSV, and the CAM-DAS conclusions table.

Each reads typed results (:mod:`camfab.results`) and the design, and returns text; nothing is printed or
written here.
"""
from __future__ import annotations

import math
import sys

import numpy as np

from ..results import FORCE_CODES, IssueCode, Verdict
from ..textsafe import plain

__all__ = ["motion_csv", "segment_rows", "format_motion", "format_check", "VERDICT_TEXT"]

VERDICT_TEXT = {Verdict.ACCEPTABLE: "Cam OK (acceptable)",
                Verdict.NOT_FOR_HIGH_SPEED: "Not suitable for high speeds",
                Verdict.UNACCEPTABLE: "Cam KO (unacceptable)"}


def motion_csv(prog, speed: float, step: float) -> str:
    """``angle_deg,S,V,A,J`` rows (``position_mm,…`` for a translating cam) from 0 to 360° (or the cam length)
    inclusive, every ``step`` user units, in time units at ``speed``."""
    axis = prog.axis
    k = axis.x_scale
    n = int(math.floor(prog.period / k / step + 1e-9))
    xu = np.arange(n + 1) * step
    vals = prog.evaluate(xu * k) * (speed ** np.arange(4))[:, None]
    body = np.column_stack([xu, vals.T])
    lines = [f"{axis.x_header},S,V,A,J"] + [",".join(f"{v:.10g}" for v in row) for row in body]
    return "\n".join(lines) + "\n"


def segment_rows(prog) -> list[dict]:
    """One row per segment (law, lift, span and S at its ends), x in user units (``motion --json``)."""
    k = prog.axis.x_scale
    return [{"index": i, "law": s.law, "title": s.title, "lift": s.lift, "from": s.start / k, "to": s.end / k,
             "span": s.span / k, "S_start": s.s0, "S_end": s.s0 + s.lift} for i, s in enumerate(prog.segments)]


def format_motion(spec, prog, report) -> str:
    """The human-readable motion summary (``camfab motion``)."""
    lu = spec.follower.lift_unit
    xu = "°" if prog.axis.rotating else "mm"
    speed = (f"ω = {spec.speed:.6g} rad/s ({spec.speed * 60 / (2 * math.pi):.6g} rpm)"
             if xu == "°" else f"v = {spec.speed:.6g} mm/s")
    out = [f"{plain(spec.name)}: {spec.cam.kind} cam, {spec.follower.motion} {spec.follower.type} follower, {speed}"
           + ("" if spec.cam.speed_given else " [default speed]"), ""]
    out.append(f"{'#':>3}  {'law':<34}{'lift(' + lu + ')':>10}{'from(' + xu + ')':>10}{'to(' + xu + ')':>10}"
               f"{'S start':>10}{'S end':>10}")
    for r in segment_rows(prog):
        out.append(f"{r['index'] + 1:>3}  {r['title'][:33]:<34}{r['lift']:>+10.4f}{r['from']:>10.4f}"
                   f"{r['to']:>10.4f}{r['S_start']:>10.4f}{r['S_end']:>10.4f}")
    out += ["", "Junctions: " + ", ".join(f"{j.at:g}{xu} {j.continuity}" for j in report.junctions), ""]
    units = {"S": lu, "V": f"{lu}/s", "A": f"{lu}/s²", "J": f"{lu}/s³"}
    out.append(f"Peaks ({report.peaks_mode}){'':14}{'max':>14}{'at':>10}{'min':>14}{'at':>10}")
    for q, p in report.peaks.items():
        out.append(f"  {q} ({units[q]}){'':<{22 - len(units[q])}}{p.max:>14.6g}{p.at_max:>10.4f}"
                   f"{p.min:>14.6g}{p.at_min:>10.4f}")
    out += ["", f"Verdict: {report.verdict}"]
    out += [f"  [{f.severity}] {f.code}: {f.message}" for f in report.findings]
    return "\n".join(out)


def format_check(spec, report) -> str:
    """The CAM-DAS style conclusions table (``camfab check``)."""
    codes = report.codes()
    rows = _motion_rows(spec, report, codes) + _geometry_rows(report, codes)
    if report.dynamics is not None:
        rows += _dynamics_rows(report.dynamics, codes)
    cs = report.contact_stress
    if cs is not None and cs.max_mpa is not None:
        rows.append(("Contact stress (MPa)", _num(cs.max_mpa), "--",
                     ("above the allowable: see findings" if IssueCode.CONTACT_STRESS_ABOVE_LIMIT in codes else
                      "within the allowable") + f" {cs.allowable_mpa:g} MPa, safety factor {cs.safety_factor:.3g}"))
    width = max(len(r[0]) for r in rows) + 2
    out = [f"{plain(spec.name)}: {VERDICT_TEXT[report.verdict]}", ""]  # no control characters to a terminal
    out.append(f"{'Concept':<{width}}{'Maximum':>13}{'Minimum':>13}  Comments")
    out += [f"{a:<{width}}{b:>13}{c:>13}  {e}" for a, b, c, e in rows]
    extra = [("base_radius_mm", report.base_radius_mm), ("max_radius_mm", report.max_radius_mm),
             ("area_mm2", report.area_mm2), ("initial_arm_angle_deg", report.initial_arm_angle_deg)]
    out += [""] + [f"{k}: {v:.6g}" for k, v in extra if v is not None]
    dyn = report.dynamics
    if dyn is not None and not dyn.form_closed:
        pre, jump = dyn.preload_needed, dyn.jump_speed
        out.append(f"spring preload for the safety force: {pre.value:.6g} {pre.unit} (worst at {pre.at:.2f})")
        out.append("jump speed: " + ("none (the follower never leaves the cam)" if jump.value is None else
                                     f"{jump.value:.6g} {jump.unit} (first at {jump.at:.2f})"))
    out += _vibration_lines(report)
    out += _strength_lines(cs)
    if report.findings:
        out += ["", "Findings:"]
        out += [f"  [{f.severity}] {f.code}: {f.message}" for f in report.findings]
    return "\n".join(out)


def _strength_lines(cs) -> list[str]:
    """Materials, roller life and cam-life estimate, and the notes of a ``contact_stress`` summary."""
    if cs is None:
        return []
    out = []
    if cs.cam_material is not None:
        out.append(f"contact stress: {plain(cs.cam_material)} cam, {plain(str(cs.follower_material))} follower, "
                   f"face width {cs.width_mm:g} mm")
    life = cs.roller_life
    if life is not None:
        out.append("roller life L10 (ISO 281): " + ("unlimited" if life.hours is None else
                   f"{life.hours:.4g} h, {life.cam_cycles:.4g} cam revolutions (equivalent load "
                   f"{life.equivalent_load_n:.4g} N)"))
    if cs.cam_life is not None and cs.cam_life.hours is not None:
        out.append(f"cam track life (estimate): {cs.cam_life.hours:.4g} h, {cs.cam_life.cam_cycles:.4g} revolutions")
    return out + [f"  note: {plain(n)}" for n in cs.notes]


def _motion_rows(spec, report, codes) -> list[tuple[str, str, str, str]]:
    lu = spec.follower.lift_unit
    cont = {"S": "Continuous",
            "V": "Discontinuous" if IssueCode.VELOCITY_DISCONTINUITY in codes else "Continuous",
            "A": "Discontinuous" if IssueCode.ACCELERATION_DISCONTINUITY in codes else "Continuous",
            "J": "Discontinuous" if IssueCode.JERK_DISCONTINUITY in codes else "Continuous"}
    names = {"S": f"Displacement ({lu})", "V": f"Velocity ({lu}/s)", "A": f"Acceleration ({lu}/s²)",
             "J": f"Jerk ({lu}/s³)"}
    return [(names[q], _num(p.max), _num(p.min), cont[q])
            for q, p in (report.motion.peaks.items() if report.motion is not None else ())]


def _geometry_rows(report, codes) -> list[tuple[str, str, str, str]]:
    rows = []
    roc = report.curvature
    if roc is not None:
        bad = codes & {IssueCode.UNDERCUT, IssueCode.CUSP}
        rows.append(("Convex radius of curvature (mm)", "--", _num(roc.min_convex),
                     "undercut or cusp: see findings" if bad else "The profile is free of cusps and undercuts"))
        if roc.min_concave is not None:
            rows.append(("Concave radius of curvature (mm)", "--", _num(roc.min_concave),
                         "smallest concave radius (cutter must be smaller)"))
    pa = report.pressure_angle
    if pa is not None:
        ok = IssueCode.PRESSURE_ANGLE_EXCEEDED not in codes
        rows.append(("Pressure angle (°)", _num(pa.max), _num(pa.min),
                     "Acceptable" if ok else f"High pressure angle (> {pa.limit:g}°)"))
    face = report.face_length
    if face is not None and face.left is not None:
        rows.append(("Face length left / right (mm)", _num(face.left), _num(face.right),
                     "minimum face length on each side to keep contact"))
    elif face is not None:  # an oscillating face: the contact's distance from the vertex
        rows.append(("Contact along the face (mm)", _num(face.max), _num(face.min),
                     "distance of the contact from the face vertex"))
    return rows


def _dynamics_rows(dyn, codes) -> list[tuple[str, str, str, str]]:
    """The contact-force, drive and bearing rows of the conclusions table."""
    cf, rows = dyn.contact_force, []
    if dyn.form_closed:
        cf2, rev = dyn.second_contact_force, len(dyn.load_reversals or ())
        (a, b), other = dyn.contact_names, "flank" if dyn.flanks else "follower"
        rows.append((f"Contact force, {a} (N)", _num(cf.max), _num(cf.min), "form-closed: no jump"))
        rows.append((f"Contact force, {b} (N)", _num(cf2.max), _num(cf2.min),
                     f"the load changes {other} {rev} time{'s' if rev != 1 else ''} per turn"))
    else:
        rows.append(("Contact force (N)", _num(cf.max), _num(cf.min),
                     "below the safety force or jumping: see findings" if codes & set(FORCE_CODES) else
                     f"never below the safety force ({dyn.safety_force_n:g} N)"))
    rows.append(("Drive torque (N·m)" if dyn.torque else "Drive force (N)", _num(dyn.drive.max), _num(dyn.drive.min),
                 f"work per cycle {dyn.work_per_cycle_j:.4g} J, mean power {dyn.mean_power_w:.4g} W"))
    rows.append(("Camshaft bearing force (N)", _num(dyn.bearing_force.max), "--", ""))
    return rows


def _num(v) -> str:
    if v is None:
        return "--"
    if v != 0 and abs(v) < 0.01:
        return f"{v:.3g}"  # small forces and torques keep their digits
    return f"{v:.2f}" if abs(v) < 1e7 else f"{v:.5g}"


def _vibration_lines(report) -> list[str]:
    """The ``camfab check`` text lines of the follower vibration (none without ``[vibration]``)."""
    v = report.vibration
    results = sys.modules.get("camfab.design.vibration_results")  # loaded by a design that has [vibration]
    if results is None or not isinstance(v, results.VibrationSummary):
        return []
    sep = v.separation_speed
    f = v.contact_force
    out = [f"follower vibration: f_n {v.natural_frequency_hz:.6g} Hz (harmonic {v.nearest_resonance_order} of "
           f"{v.cycle_frequency_hz:.6g} Hz), zeta {v.damping_ratio:g}",
           f"  deviation from the kinematic motion: {v.max_deviation.max:.4g} {v.lift_unit} "
           f"(at {v.max_deviation.at_max:.2f})",
           f"  contact force with vibration: {f.min:.6g} N (at {f.at_min:.2f}) to {f.max:.6g} N (at {f.at_max:.2f})",
           "  separation speed: " + ("none up to 10x the design speed" if sep.value is None else
                                     f"{sep.value:.6g} {sep.unit} (first at {sep.at:.2f})")]
    if v.residual_amplitude is not None:
        out.insert(2, f"  residual vibration in dwells: {v.residual_amplitude.max:.4g} {v.lift_unit} "
                      f"(dwell from {v.residual_amplitude.at_max:.2f})")
    return out
