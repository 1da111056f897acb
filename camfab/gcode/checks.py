"""The checks of a back-plotted program against its job and the machine state it runs in (see
:func:`camfab.gcode.verify.verify`): the modal safety block, feeds, spindle, coolant, tool and length offset,
final depth, step-down and milling direction.  Each takes the moves (:class:`~camfab.gcode.parse.Move`) and
returns findings naming the program lines.
"""
from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from camfab.gcode.model import Job
from camfab.gcode.parse import Backplot, Move
from camfab.gcode.posts.base import Post
from camfab.results import Finding, IssueCode

__all__ = ["BORE_LABEL", "EPS_Z", "FEED_ATOL", "FEED_RTOL", "bore_findings", "bore_moves", "depth_findings",
           "descends", "direction_findings", "feed_findings", "line_list",
           "machine_state_findings", "modal_state", "retract_findings", "xy_travel"]

#: heights closer than this (mm) are the same level
EPS_Z = 1e-6
#: a feed matches the job's within the rounding of the written F word (0.1 mm/min, 0.001 in/min)
FEED_ATOL, FEED_RTOL = 0.05 + 1e-9, 1e-9


#: modal groups every program must set before its first move, and what each is for
_REQUIRED_MODAL = {"plane": "G17 (XY plane)", "units": "G20/G21 (units)", "distance": "G90 (absolute coordinates)",
                   "feed_mode": "G94 (feed per minute)", "comp": "G40 (cutter compensation off)",
                   "wcs": "G54-G59 (work offset)"}


def modal_state(bp: Backplot) -> list[Finding]:
    missing = [text for g, text in _REQUIRED_MODAL.items() if g not in bp.modal_before_motion]
    if not missing:
        return []
    first = bp.moves[0].line if bp.moves else None
    return [Finding.at_line(IssueCode.MODAL_STATE, f"the program does not set {', '.join(missing)} before its first "
                            "move: a controller keeps the mode the last program left (a safety block such as "
                            "'G17 G21 G40 G54 G90 G94' at the start sets them)", first)]


def xy_travel(m: Move) -> bool:
    s, e = m.start, m.end
    if not (math.isfinite(s[0]) and math.isfinite(s[1])):
        return True
    return math.hypot(e[0] - s[0], e[1] - s[1]) > EPS_Z


def descends(m: Move) -> bool:
    """The move ends lower than it starts (a plunge, ramp or helix)."""
    return math.isfinite(m.start[2]) and m.end[2] < m.start[2] - EPS_Z


def feed_findings(moves, cutting, job: Job | None) -> list[Finding]:
    """FEED_MISSING for every cutting move without a feed (or F0); with a job FEED_OUT_OF_RANGE for every
    feed other than the job's (plunge feed for Z-only moves and every descending move - helices and ramps -,
    cutting feed for the others)."""
    out = []
    none = [moves[i].line for i in cutting if moves[i].feed is None or moves[i].feed <= 0]
    if none:
        out.append(Finding.at_line(IssueCode.FEED_MISSING, f"{len(none)} cutting move(s) run without a feed (no F "
                                   f"word before them, or F0): lines {line_list(none)}", none[0]))
    if job is None:
        return out
    wrong: dict[tuple[str, float, float], list[int]] = {}
    for i in cutting:
        m = moves[i]
        if m.feed is None or m.feed <= 0:
            continue
        plunge = not xy_travel(m) or descends(m)
        kind, want = ("plunge", job.plunge_feed_mm_min) if plunge else ("cutting", job.feed_mm_min)
        if abs(m.feed - want) > FEED_ATOL + FEED_RTOL * want:
            wrong.setdefault((kind, want, round(m.feed, 6)), []).append(m.line)
    for (kind, want, got), lines in sorted(wrong.items(), key=lambda kv: kv[1][0]):
        what = "Z-only or descending (plunge)" if kind == "plunge" else "cutting"
        out.append(Finding.at_line(IssueCode.FEED_OUT_OF_RANGE, f"{len(lines)} {what} move(s) at F{got:g} mm/min; "
                                   f"the job's {kind} feed is {want:g} mm/min: lines {line_list(lines)}", lines[0]))
    return out


def machine_state_findings(moves, cutting, top_z: float, job: Job | None, post: Post | None) -> list[Finding]:
    """Spindle, coolant and tool of every cutting move below the stock top."""
    out = []
    below = [moves[i] for i in cutting if min(moves[i].start[2], moves[i].end[2]) < top_z - EPS_Z]

    def report(code, bad, text):
        if bad:
            lines = sorted({m.line for m in bad})
            out.append(Finding.at_line(code, f"{text}: lines {line_list(lines)}", lines[0]))

    report(IssueCode.SPINDLE_OFF, [m for m in below if not m.spindle_on], "cutting below the stock top with the "
           "spindle off")
    report(IssueCode.SPINDLE_DIRECTION, [m for m in below if m.spindle_on and m.spindle_dir == "ccw"],
           "cutting with the spindle turning counter-clockwise (M4): the end mill cuts clockwise (M3)")
    if job is None:
        return out
    rpm = job.spindle_rpm
    slow = [m for m in below if m.spindle_on and (m.spindle_rpm is None or abs(m.spindle_rpm - rpm) > 0.5 + 1e-9 * rpm)]
    if slow:
        got = sorted({"none" if m.spindle_rpm is None else f"S{m.spindle_rpm:g}" for m in slow})
        report(IssueCode.SPINDLE_SPEED, slow, f"cutting at spindle speed {', '.join(got)}; the job asks S{rpm:g}")
    want = job.coolant
    if want == "off":
        ok = {"off"}
    elif want == "flood":
        ok = {"flood", "flood+mist"}
    else:
        ok = {"mist", "flood+mist"}
        if post is not None and post.coolant_code("mist", dict(post.defaults)) == "M8":
            ok |= {"flood"}  # this controller writes flood for mist
    codes = {"off": "none (M9)", "flood": "flood (M8)", "mist": "mist (M7)", "flood+mist": "flood and mist"}
    bad = [m for m in below if m.coolant not in ok]
    if bad:
        got = sorted({codes[m.coolant] for m in bad})
        report(IssueCode.COOLANT, bad, f"cutting with coolant {', '.join(got)}; the job asks {codes[want]}")
    T = job.tool_number
    if post is None or post.tool_change:
        if post is not None or any(m.tool is not None for m in below):
            report(IssueCode.TOOL, [m for m in below if m.tool != T],
                   f"cutting without the job's tool T{T} loaded (T{T} M6 before the first cut)")
    else:
        report(IssueCode.TOOL, [m for m in below if m.tool not in (None, T)], f"cutting with another tool than T{T}")
    if post is not None and post.tool_change and post.length_offset:
        report(IssueCode.TOOL_LENGTH_OFFSET, [m for m in below if m.length_offset != T],
               f"cutting without the tool length offset of T{T} (G43 H{T} after the tool change): Z is not "
               "where the program says")
    return out


def depth_findings(moves, cutting, fin_final, zf: float, job: Job, top_z: float, tol: float) -> list[Finding]:
    """FINISH_DEPTH, TOO_DEEP and STEP_DOWN against the job."""
    out = []
    z_final = top_z - job.depth_mm
    if fin_final and abs(zf - z_final) > tol:
        how = "does not reach" if zf > z_final else "goes below"
        out.append(Finding.at_line(
            IssueCode.FINISH_DEPTH, f"the finishing pass runs at Z{zf:.4f}: it {how} the final depth Z{z_final:.4f} "
            f"(the plate and its breakthrough: {job.depth_mm:g} mm)", moves[fin_final[0]].line))
    deep = sorted({moves[i].line for i in cutting if min(moves[i].start[2], moves[i].end[2]) < z_final - tol})
    if deep:
        zmin = min(min(moves[i].start[2], moves[i].end[2]) for i in cutting)
        out.append(Finding.at_line(
            IssueCode.TOO_DEEP, f"cutting down to Z{zmin:.4f}, below the final depth Z{z_final:.4f} (plate and "
            f"breakthrough; deeper is the fixture): lines {line_list(deep)}", deep[0]))
    floor = top_z
    steep = []
    for i in cutting:
        m = moves[i]
        z = min(m.start[2], m.end[2])
        if not (xy_travel(m) and math.isfinite(z)):
            continue
        if z < floor - job.step_down_mm - tol:
            steep.append((m.line, floor - z))
        floor = min(floor, z)
    if steep:
        worst = max(d for _, d in steep)
        lines = [ln for ln, _ in steep]
        out.append(Finding.at_line(
            IssueCode.STEP_DOWN, f"cutting up to {worst:.4f} mm deeper than anything cut before; the job's step-down "
            f"is {job.step_down_mm:g} mm: lines {line_list(lines)}", lines[0]))
    return out


def retract_findings(moves, top_z: float) -> list[Finding]:
    """RETRACT_MISSING: the program ends with the tool below the stock top (in the material)."""
    if not moves:
        return []
    z = moves[-1].end[2]
    if not (math.isfinite(z) and z < top_z - EPS_Z):
        return []
    return [Finding.at_line(IssueCode.RETRACT_MISSING, f"the program ends with the tool at Z{z:.4f}, below the stock "
                            f"top Z{top_z:.4f}: retract it before the spindle stops", moves[-1].line)]


def direction_findings(pts: np.ndarray, job: Job, line: int) -> list[Finding]:
    """DIRECTION: the finishing pass must run clockwise around the part for climb milling (with M3)."""
    x, y = pts[:, 0] - pts[:, 0].mean(), pts[:, 1] - pts[:, 1].mean()
    area = 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))
    if area == 0.0:
        return []
    want_cw = job.direction == "climb"
    if (area < 0) == want_cw:
        return []
    return [Finding.at_line(IssueCode.DIRECTION, f"the finishing pass runs {'counter-' if want_cw else ''}clockwise "
                            f"around the part: {'conventional' if want_cw else 'climb'} milling with M3, but the job "
                            f"asks {job.direction}", line)]


#: the label (comment prefix) of the bore moves camfab writes
BORE_LABEL = "BORE"


def bore_moves(moves, cutting, job: Job | None) -> list[int]:
    """The cutting moves of the bore (labelled ``BORE ...``) when the job mills one, else none: they are checked
    against the bore (:func:`bore_findings`), not the cam contour."""
    if job is None or not job.mill_bore or job.bore_mm <= 0:
        return []
    return [i for i in cutting if (moves[i].label or "").upper().startswith(BORE_LABEL)]


def bore_findings(moves, bore: list[int], job: Job, tol: float, step: float, sample) -> list[Finding]:
    """GOUGE when a bore move takes the tool beyond the bore's wall (Ø ``job.bore_mm`` on the axis), DEVIATION
    when the bore's finishing circle at full depth does not run at ``(bore - D) / 2`` from the axis."""
    if not bore:
        return []
    out = []
    smp = sample([moves[i] for i in bore], step, 256)
    rho = np.hypot(smp.points[:, 0], smp.points[:, 1])
    R = 0.5 * (job.bore_mm - job.tool_diameter_mm)
    over = rho - R
    if (over > tol).any():
        w = int(np.argmax(over))
        lines = sorted({moves[bore[int(k)]].line for k in smp.index[over > tol]})
        out.append(Finding.at_line(IssueCode.GOUGE, f"the bore moves take the tool {over[w]:.4f} mm beyond the wall of "
                                   f"the D{job.bore_mm:g} bore: lines {line_list(lines)}", lines[0]))
    z_final = -job.depth_mm
    fin = (smp.points[:, 2] <= z_final + tol) & np.array(
        [(moves[bore[int(k)]].label or "").upper().startswith(BORE_LABEL + " FINISH") for k in smp.index])
    if not fin.any():
        out.append(Finding.at_line(IssueCode.FINISH_DEPTH, f"no finishing circle of the bore at the final depth "
                                   f"Z{z_final:.4f}", moves[bore[0]].line))
    elif float(np.max(np.abs(rho[fin] - R))) > tol or float(np.ptp(np.arctan2(smp.points[fin, 1],
                                                                                smp.points[fin, 0]))) < 6.0:
        dev = float(np.max(np.abs(rho[fin] - R)))
        out.append(Finding.at_line(IssueCode.DEVIATION, f"the bore's finishing circle deviates {dev:.4f} mm from "
                                   f"radius {R:.4f} mm or does not go round", moves[bore[0]].line))
    return out


def line_list(lines: Sequence[int], limit: int = 8) -> str:
    head = ", ".join(str(v) for v in lines[:limit])
    return head + (f" and {len(lines) - limit} more" if len(lines) > limit else "")
