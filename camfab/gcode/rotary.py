"""The 4-axis program of a cylindrical cam's groove: a rotary table (A) and a radial end mill.

Machine set-up and work offset (README, "Cylindrical cams"; docs/decisions.md, "Cylindrical cams: the 4-axis
program")
--------------------------------------------------------------------------------------------------------------
The cylinder lies on a rotary table whose axis is the machine X axis; the end mill's axis is radial, along the
machine Z axis, the tool above the cylinder.  Work offset (G54):

* **X0** at the cylinder's z = 0 end; machine X = the design's axial position z;
* **Z0** on the rotary axis; Z is the radius of the tool tip (the outer surface at Z = R + depth/2, the groove
  bottom at Z = R − depth/2);
* **A0** with the follower's position at cam angle 0 under the tool (the cam frame's +Y up); A turns the part
  about +X by the right-hand rule (degrees).  The cam frame (X_c, Y_c, Z_c) maps to the machine (Y, Z, X), so a
  point at cam polar angle α is under the tool when α + A = 90°: the developed x on radius r sits there at
  ``A = −σ·x/r`` (σ = +1 cw, −1 ccw).  For a translating follower A = −σ·θ: the table turns the cylinder as
  the cam turns.

The program mills the **centre pass** along the pitch curve: at each depth level (equal steps no larger than
``[machining] step_down_mm``, the last on the groove bottom) it plunges at the plunge feed at cam angle 0 and runs
once round (A from 0 to ∓360°) with ``G1 X.. A..``.  The tool must be narrower than the groove on its bottom
(``2·w(r_bottom)``, w = R_r + backlash/2), else :class:`~camfab.errors.SpecError` naming
``manufacturing.tool_diameter_mm``.  Finishing passes per flank are not written yet (the tool leaves w − r_c on
each flank).

Feeds: the moves mix mm (X) and degrees (A), so the cutting moves are written in **inverse time** (``G93``,
``F`` = 1/minutes of the move, from the move's length on the tool tip's cylinder and the cutting feed); the
plunges and rapids return to ``G94`` (mm/min).  Sampling: the points are the exact pitch curve at cam angles
chosen adaptively so that every chord, on the developed cylinder of the level's radius, stays within the
tolerance less the rounding of the written numbers (measured at the chord's quarter, half and three-quarter
points and refined by bisection).  GRBL has no rotary axis: refused (:class:`~camfab.errors.ExportError`).
"""
from __future__ import annotations

import dataclasses
import math
from typing import Any

import numpy as np

from ..errors import ExportError, Problem, SpecError
from .model import Job
from .posts.base import MM_PER_INCH, Post

__all__ = ["ROTARY_POSTS", "rotary_samples", "rotary_levels", "rotary_gcode", "check_rotary_tool"]

#: the posts whose controllers have a rotary A axis and inverse-time feed (G93)
ROTARY_POSTS = ("linuxcnc", "fanuc")
#: samples per turn before refinement, and the largest number after it
_START = 72
_MAX_POINTS = 200_000


def _developed(geometry: Any, r: float, phi: np.ndarray) -> np.ndarray:
    """The exact developed pitch curve on radius r at cam angles ``phi``: (n, 2) of (x, z), mm."""
    return geometry.at_radius(r).pitch(np.asarray(phi, dtype=float))[0]


def _chord_error(geometry: Any, r: float, phi: np.ndarray) -> np.ndarray:
    """Largest distance of the exact curve from each chord between consecutive ``phi`` (at 1/4, 1/2, 3/4)."""
    P = _developed(geometry, r, phi)
    a, b = P[:-1], P[1:]
    d = b - a
    ln = np.maximum(np.hypot(d[:, 0], d[:, 1]), 1e-300)
    worst = np.zeros(len(a))
    for t in (0.25, 0.5, 0.75):
        Q = _developed(geometry, r, phi[:-1] + t * np.diff(phi))
        w = Q - a
        worst = np.maximum(worst, np.abs(w[:, 0] * d[:, 1] - w[:, 1] * d[:, 0]) / ln)
    return worst


def rotary_samples(geometry: Any, r: float, tol: float) -> np.ndarray:
    """Cam angles (rad, 0 to the period, increasing) whose chords on the developed cylinder of radius r lie
    within ``tol`` of the exact pitch curve (bisection of every chord that does not)."""
    period = float(geometry.period)
    phi = np.linspace(0.0, period, _START + 1)
    while True:
        bad = _chord_error(geometry, r, phi) > tol
        if not bad.any():
            return phi
        if len(phi) + int(bad.sum()) > _MAX_POINTS:
            raise ExportError(f"the 4-axis program needs more than {_MAX_POINTS} points for the tolerance "
                              f"{tol:g} mm; give a coarser --tol")
        mids = 0.5 * (phi[:-1] + phi[1:])[bad]
        phi = np.sort(np.concatenate([phi, mids]))


def rotary_levels(r_outer: float, r_bottom: float, step_down_mm: float) -> list[float]:
    """Z (tool-tip radius) of each depth level, top down: equal steps no larger than ``step_down_mm``, the last
    on the groove bottom."""
    depth = r_outer - r_bottom
    n = max(1, math.ceil(depth / step_down_mm - 1e-9))
    return [r_outer - depth * k / n for k in range(1, n + 1)]


def check_rotary_tool(geometry: Any, tool_diameter_mm: float) -> None:
    """Refuse a tool that is not narrower than the groove on its bottom (SpecError naming the field)."""
    r_b = geometry.cylinder.inner_radius_mm
    width = 2.0 * geometry.mechanism.half_width(r_b)
    if tool_diameter_mm >= width:
        raise SpecError(Problem("manufacturing.tool_diameter_mm", tool_diameter_mm,
                                f"the end mill is not narrower than the groove on its bottom ({width:.6g} mm = the "
                                "roller diameter plus the backlash): the centre pass would cut the flanks",
                                f"use a tool smaller than {width:.6g} mm (e.g. {math.floor(width * 0.8):g} mm)"))


def _rotary_post(post: str | Post) -> Post:
    from .post import get_post

    p = get_post(post)
    if p.name not in ROTARY_POSTS:
        raise ExportError(f"--post {p.name}: the {p.name} controller has no rotary (A) axis, so it cannot run the "
                          "4-axis program of a cylindrical cam; choose --post linuxcnc or --post fanuc")
    return p


def rotary_gcode(geometry: Any, job: Job, tol: float, post: str | Post = "linuxcnc") -> tuple[bytes, int, float]:
    """The 4-axis program (module notes) as bytes, its number of cutting ``G1 X.. A..`` moves and the largest
    chord error (mm) of the written path on the developed cylinder of each level's radius (before rounding)."""
    p = _rotary_post(post)
    check_rotary_tool(geometry, job.tool_diameter_mm)
    cyl = geometry.cylinder
    sigma = float(geometry.mechanism.sense)
    inch = job.units == "inch"
    k = 1.0 / MM_PER_INCH if inch else 1.0
    d = p.decimals(job.units, tol)
    # rounding: X and Z by half an increment (mm), A by half an increment (degrees) on the outer radius
    h_lin = 0.5 * 10.0 ** -d / k
    h_ang = 0.5 * 10.0 ** -d * math.pi / 180.0 * cyl.outer_radius_mm
    tol_fit = max(tol - math.hypot(h_lin, h_ang), 0.5 * tol)
    levels = rotary_levels(cyl.outer_radius_mm, cyl.inner_radius_mm, job.step_down_mm)
    safe = cyl.outer_radius_mm + job.safe_z_mm
    clear = cyl.outer_radius_mm + job.clearance_mm
    lines: list[str] = []
    n = [0]
    step = 10

    def fmt(v: float, dec: int = d) -> str:
        s = f"{v:.{dec}f}"
        return s[1:] if s.startswith("-") and float(s) == 0.0 else s

    def L(v_mm: float) -> str:
        return fmt(v_mm * k)

    def comment(text: str) -> None:
        t = p.sanitize_comment(text)
        if t:
            lines.append(f"({t})")

    def block(words: list[str]) -> None:
        if p.line_numbers:
            n[0] += 1
            words = [f"N{(n[0] * step - 1) % 99999 + 1}"] + words
        lines.append(" ".join(words))

    u = "in" if inch else "mm"
    fd = 3 if inch else 1
    if p.percent:
        lines.append("%")
    if p.program_number:
        lines.append(f"O1000 ({p.sanitize_comment(job.design_name)[:16]})")
    for text in ("camfab 4-axis program: cylindrical cam groove, centre pass",
                 f"design: {job.design_name}", f"post: {p.name}", f"units: {'inch' if inch else 'mm'}, A in degrees",
                 "work offset G54: X0 at the cylinder z = 0 end, Z0 on the rotary axis (Z = tool tip radius), "
                 "A0 = cam angle 0 under the tool",
                 f"rotary axis: A about X, A = {'-' if sigma > 0 else '+'}cam angle ({geometry.mechanism.rotation})",
                 f"tool: T{job.tool_number} flat end mill D{L(job.tool_diameter_mm)} {u}, axis radial (along Z)",
                 f"groove: bottom Z{L(cyl.inner_radius_mm)}, outer Z{L(cyl.outer_radius_mm)}, "
                 f"width {L(2 * geometry.mechanism.half_width(cyl.inner_radius_mm))} {u} at the bottom",
                 f"tolerance: {tol:.6f} mm, output resolution {10.0 ** -d:.{d}f} {u} and {10.0 ** -d:.{d}f} deg",
                 f"flanks: centre pass only, "
                 f"{L(geometry.mechanism.half_width(cyl.inner_radius_mm) - job.tool_radius_mm)} {u} left on each",
                 f"depth levels: {len(levels)}, safe Z{L(safe)}",
                 f"spindle: {round(job.spindle_rpm)} rpm cw",
                 f"feed: {job.feed_mm_min * k:.{fd}f} {u}/min at the tool tip as inverse time G93, "
                 f"plunge {job.plunge_feed_mm_min * k:.{fd}f} {u}/min", *job.notes):
        comment(text)
    block(p.preamble(job.units))
    if p.tool_change:
        block([f"T{job.tool_number}", "M6"])
    else:
        comment(f"load T{job.tool_number}")
    block([f"S{round(job.spindle_rpm)}", "M3"])
    block([p.coolant_code(job.coolant, {})])
    lenoff = ["G43", f"H{job.tool_number}"] if p.tool_change and p.length_offset else []
    worst, moves = 0.0, 0
    for i, z in enumerate(levels):
        phi = rotary_samples(geometry, z, tol_fit)
        worst = max(worst, float(np.max(_chord_error(geometry, z, phi))))
        P = _developed(geometry, z, phi)
        X = P[:, 1]
        A = np.degrees(-sigma * P[:, 0] / z)
        comment(f"centre pass level {i + 1} of {len(levels)} Z{L(z)}")
        block(["G0", *lenoff, f"Z{L(safe)}"])
        lenoff = []
        block(["G0", f"X{L(X[0])}", f"A{fmt(A[0])}"])
        block(["G0", f"Z{L(clear)}"])
        block(["G1", f"Z{L(z)}", f"F{job.plunge_feed_mm_min * k:.{fd}f}"])
        seg = np.hypot(np.diff(X), z * np.radians(np.diff(A)))
        minutes = np.maximum(seg / job.feed_mm_min, 1e-9)
        block(["G93"])
        moves += len(minutes)
        for x, a, t in zip(X[1:], A[1:], minutes, strict=True):
            block(["G1", f"X{L(x)}", f"A{fmt(a)}", f"F{1.0 / t:.3f}"])
        block(["G94"])
        block(["G0", f"Z{L(safe)}"])
        block(["G0", "A0"])  # unwind the table: the next level starts at A0 again (no 360° jump per level)
    block(["M9"])
    block(["M5"])
    block([p.end_code])
    if p.percent:
        lines.append("%")
    return ("\n".join(lines) + "\n").encode("ascii"), moves, worst


def cylinder_job(job: Job, geometry: Any) -> Job:
    """The job cut to the groove's depth: no breakthrough, no bore, a round stock."""
    return dataclasses.replace(job, depth_mm=geometry.cylinder.groove_depth_mm, breakthrough_mm=0.0,
                               mill_bore=False, stock_shape="round")
