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
``manufacturing.tool_diameter_mm``.  Then, like the face-groove cam, **a finishing pass per flank at full depth**
(:mod:`camfab.gcode.rotary_finish`): plunge on the pitch curve at cam angle 0, straight along its normal to the
flank's cutter path (the flank's exact offset by the cutter radius on the developed bottom cylinder), once round
it, back to the pitch curve; the +z and −z flanks run in opposite senses so that both are milled in the job's
``[machining] direction``.  The cutter check runs on each flank (concave radius, and the twist of the flank
across the depth, which a radial cutter narrower than the roller cannot follow exactly).

Feeds: the moves mix mm (X) and degrees (A), so the cutting moves are written in **inverse time** (``G93``,
``F`` = 1/minutes of the move, from the move's length on the tool tip's cylinder and the cutting feed); the
plunges and rapids return to ``G94`` (mm/min).  Sampling: the points are the exact pitch curve at cam angles
chosen adaptively so that every chord, on the developed cylinder of the level's radius, stays within the
tolerance less the rounding of the written numbers (measured at the chord's quarter, half and three-quarter
points and refined by bisection).  GRBL has no rotary axis: refused (:class:`~camfab.errors.ExportError`).
"""
from __future__ import annotations

import dataclasses
import functools
import math
from collections.abc import Callable
from typing import Any

import numpy as np

from ..errors import ExportError, Problem, SpecError
from .model import Job
from .posts.base import MM_PER_INCH, Post
from .rotary_finish import check_finishing_tool, finishing_direction, flank_path, require_groove

__all__ = ["ROTARY_POSTS", "rotary_samples", "rotary_levels", "rotary_gcode", "check_rotary_tool", "RotaryWriter",
           "to_machine", "chord_error", "rotary_post"]

#: the posts whose controllers have a rotary A axis and inverse-time feed (G93)
ROTARY_POSTS = ("linuxcnc", "fanuc")
#: samples per turn before refinement, and the largest number after it
_START = 72
_MAX_POINTS = 200_000


def _developed(geometry: Any, r: float, phi: np.ndarray) -> np.ndarray:
    """The exact developed pitch curve on radius r at cam angles ``phi``: (n, 2) of (x, z), mm."""
    return geometry.at_radius(r).pitch(np.asarray(phi, dtype=float))[0]


def chord_error(curve: Callable[[np.ndarray], np.ndarray], phi: np.ndarray) -> np.ndarray:
    """Largest distance of the exact ``curve(phi)`` from each chord between consecutive ``phi`` (at 1/4, 1/2,
    3/4)."""
    P = curve(phi)
    a, b = P[:-1], P[1:]
    d = b - a
    ln = np.maximum(np.hypot(d[:, 0], d[:, 1]), 1e-300)
    worst = np.zeros(len(a))
    for t in (0.25, 0.5, 0.75):
        w = curve(phi[:-1] + t * np.diff(phi)) - a
        worst = np.maximum(worst, np.abs(w[:, 0] * d[:, 1] - w[:, 1] * d[:, 0]) / ln)
    return worst


def rotary_samples(geometry: Any, r: float, tol: float,
                   curve: Callable[[np.ndarray], np.ndarray] | None = None) -> np.ndarray:
    """Cam angles (rad, 0 to the period, increasing) whose chords on the developed cylinder of radius r lie
    within ``tol`` of the exact pitch curve, or of ``curve`` when given (bisection of every chord that does
    not)."""
    f = curve or (lambda t: _developed(geometry, r, t))
    period = float(geometry.period)
    phi = np.linspace(0.0, period, _START + 1)
    while True:
        bad = chord_error(f, phi) > tol
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


def rotary_post(post: str | Post) -> Post:
    from .post import get_post

    p = get_post(post)
    if p.name not in ROTARY_POSTS:
        raise ExportError(f"--post {p.name}: the {p.name} controller has no rotary (A) axis, so it cannot run the "
                          "4-axis program of a cylindrical cam; choose --post linuxcnc or --post fanuc")
    return p


class RotaryWriter:
    """The program's lines in the post's dialect: number formats, comments, numbered blocks."""

    def __init__(self, p: Post, job: Job, tol: float):
        self.p, self.job = p, job
        self.k = 1.0 / MM_PER_INCH if job.units == "inch" else 1.0
        self.d = p.decimals(job.units, tol)
        self.fd = 3 if job.units == "inch" else 1
        self.lines: list[str] = []
        self.n = 0

    def fmt(self, v: float) -> str:
        s = f"{v:.{self.d}f}"
        return s[1:] if s.startswith("-") and float(s) == 0.0 else s

    def L(self, v_mm: float) -> str:
        return self.fmt(v_mm * self.k)

    def comment(self, text: str) -> None:
        t = self.p.sanitize_comment(text)
        if t:
            self.lines.append(f"({t})")

    def block(self, words: list[str]) -> None:
        if self.p.line_numbers:
            self.n += 1
            words = [f"N{(self.n * 10 - 1) % 99999 + 1}"] + words
        self.lines.append(" ".join(words))

    def feed(self, v_mm_min: float) -> str:
        return f"F{v_mm_min * self.k:.{self.fd}f}"

    def inverse_time(self, X: np.ndarray, A: np.ndarray, r: float) -> int:
        """``G93``, the moves from the first point (where the tool is) through the others at the cutting feed on
        the tool tip's cylinder of radius r, ``G94``; returns the number of moves."""
        seg = np.hypot(np.diff(X), r * np.radians(np.diff(A)))
        minutes = np.maximum(seg / self.job.feed_mm_min, 1e-9)
        self.block(["G93"])
        for x, a, t in zip(X[1:], A[1:], minutes, strict=True):
            self.block(["G1", f"X{self.L(x)}", f"A{self.fmt(a)}", f"F{1.0 / t:.3f}"])
        self.block(["G94"])
        return len(minutes)

    def enter(self, x: float, a: float, z: float, safe: float, clear: float, lenoff: list[str]) -> None:
        """Rapid over (x, a) at the safe radius, down to the clearance, plunge to z at the plunge feed."""
        self.block(["G0", *lenoff, f"Z{self.L(safe)}"])
        self.block(["G0", f"X{self.L(x)}", f"A{self.fmt(a)}"])
        self.block(["G0", f"Z{self.L(clear)}"])
        self.block(["G1", f"Z{self.L(z)}", self.feed(self.job.plunge_feed_mm_min)])

    def header(self, title: str, mid: list[str], flanks: str, levels: list[float], safe: float, tol: float,
               sense: int, rotation: str) -> None:
        """The program's head (``%``, the O number) and its comment block: ``title``, the set-up, the tool, the
        feature's own lines ``mid``, the tolerance, the ``flanks`` line, the levels, spindle, feeds and the job's
        notes; then :meth:`start`."""
        p, job = self.p, self.job
        inch = job.units == "inch"
        u = "in" if inch else "mm"
        if p.percent:
            self.lines.append("%")
        if p.program_number:
            self.lines.append(f"O1000 ({p.sanitize_comment(job.design_name)[:16]})")
        for text in (title, f"design: {job.design_name}", f"post: {p.name}", f"units: {'inch' if inch else 'mm'}, "
                     "A in degrees", "work offset G54: X0 at the cylinder z = 0 end, Z0 on the rotary axis (Z = tool "
                     "tip radius), A0 = cam angle 0 under the tool",
                     f"rotary axis: A about X, A = {'-' if sense > 0 else '+'}cam angle ({rotation})",
                     f"tool: T{job.tool_number} flat end mill D{self.L(job.tool_diameter_mm)} {u}, axis radial "
                     "(along Z)", *mid,
                     f"tolerance: {tol:.6f} mm, output resolution {10.0 ** -self.d:.{self.d}f} {u} and "
                     f"{10.0 ** -self.d:.{self.d}f} deg", flanks,
                     f"depth levels: {len(levels)}, safe Z{self.L(safe)}", f"spindle: {round(job.spindle_rpm)} rpm cw",
                     f"feed: {job.feed_mm_min * self.k:.{self.fd}f} {u}/min at the tool tip as inverse time G93, "
                     f"plunge {job.plunge_feed_mm_min * self.k:.{self.fd}f} {u}/min", *job.notes):
            self.comment(text)
        self.start()

    def start(self) -> None:
        """The post's preamble, the tool, the spindle (M3) and the coolant, after the header's comments."""
        p, job = self.p, self.job
        self.block(p.preamble(job.units))
        if p.tool_change:
            self.block([f"T{job.tool_number}", "M6"])
        else:
            self.comment(f"load T{job.tool_number}")
        self.block([f"S{round(job.spindle_rpm)}", "M3"])
        self.block([p.coolant_code(job.coolant, {})])

    def leave(self, safe: float) -> None:
        """Retract to the safe radius and unwind the table (the next pass starts at A0: no 360° jump)."""
        self.block(["G0", f"Z{self.L(safe)}"])
        self.block(["G0", "A0"])


def to_machine(P: np.ndarray, r: float, sigma: float) -> tuple[np.ndarray, np.ndarray]:
    """Developed (x, z) on radius r → machine X (mm along the axis) and A (degrees, A = −σ·x/r)."""
    return P[:, 1], np.degrees(-sigma * P[:, 0] / r)


def _header(w: RotaryWriter, geometry: Any, levels: list[float], safe: float, tol: float, over: float) -> None:
    cyl, mech, u = geometry.cylinder, geometry.mechanism, "in" if w.job.units == "inch" else "mm"
    w.header("camfab 4-axis program: cylindrical cam groove, centre pass and a finishing pass per flank",
             [f"groove: bottom Z{w.L(cyl.inner_radius_mm)}, outer Z{w.L(cyl.outer_radius_mm)}, "
              f"width {w.L(2 * mech.half_width(cyl.inner_radius_mm))} {u} at the bottom"],
             f"flanks: one finishing pass each at full depth, tangent on the bottom radius, "
             f"twist overcut above it at most {max(over, 0.0) * w.k:.4f} {u}", levels, safe, tol, mech.sense,
             mech.rotation)


def _finishing(w: RotaryWriter, geometry: Any, tol_fin: float, safe: float, clear: float) -> tuple[int, float]:
    """One finishing pass per flank at full depth (:mod:`camfab.gcode.rotary_finish`): plunge on the pitch
    curve at cam angle 0, straight along its normal to the flank's cutter path, once round it in the job's
    milling direction, back to the pitch curve.  Returns the moves and the largest chord error."""
    r_b, r_c = geometry.cylinder.inner_radius_mm, w.job.tool_radius_mm
    sigma, period = float(geometry.mechanism.sense), float(geometry.period)
    moves, worst = 0, 0.0
    for flank, name in ((1, "+z"), (-1, "-z")):
        way = finishing_direction(flank, int(sigma), w.job.direction == "climb")

        def curve(t: np.ndarray, flank: int = flank, way: int = way) -> np.ndarray:
            return flank_path(geometry, r_b, flank, r_c, way * t)

        phi = rotary_samples(geometry, r_b, tol_fin, curve)
        worst = max(worst, float(np.max(chord_error(curve, phi))))
        ends = _developed(geometry, r_b, np.array([0.0, way * period]))
        X, A = to_machine(np.concatenate([ends[:1], curve(phi), ends[1:]]), r_b, sigma)
        w.comment(f"finishing pass {name} flank Z{w.L(r_b)} ({'forwards' if way > 0 else 'backwards'}, "
                  f"{w.job.direction})")
        w.enter(X[0], A[0], r_b, safe, clear, [])
        moves += w.inverse_time(X, A, r_b)
        w.leave(safe)
    return moves, worst


def rotary_gcode(geometry: Any, job: Job, tol: float, post: str | Post = "linuxcnc") -> tuple[bytes, int, float]:
    """The groove's 4-axis program (module notes) as bytes, its number of cutting ``G1 X.. A..`` moves and the
    largest chord error (mm) of the written path on the developed cylinder of each level's radius (before
    rounding).  A rib's program is :func:`~camfab.gcode.rib_program.rib_gcode` (a rib here: ApiError)."""
    require_groove(geometry, "rotary_gcode", "camfab.gcode.rib_program.rib_gcode")
    p = rotary_post(post)
    check_rotary_tool(geometry, job.tool_diameter_mm)
    cyl = geometry.cylinder
    over = check_finishing_tool(geometry, job.tool_radius_mm, tol, np.linspace(0.0, geometry.period, 1441))
    sigma = float(geometry.mechanism.sense)
    w = RotaryWriter(p, job, tol)
    # rounding: X and Z by half an increment (mm), A by half an increment (degrees) on the outer radius
    h_lin = 0.5 * 10.0 ** -w.d / w.k
    h_ang = 0.5 * 10.0 ** -w.d * math.pi / 180.0 * cyl.outer_radius_mm
    tol_fit = max(tol - math.hypot(h_lin, h_ang), 0.5 * tol)
    levels = rotary_levels(cyl.outer_radius_mm, cyl.inner_radius_mm, job.step_down_mm)
    safe = cyl.outer_radius_mm + job.safe_z_mm
    clear = cyl.outer_radius_mm + job.clearance_mm
    _header(w, geometry, levels, safe, tol, over)
    lenoff = ["G43", f"H{job.tool_number}"] if p.tool_change and p.length_offset else []
    worst, moves = 0.0, 0
    for i, z in enumerate(levels):
        phi = rotary_samples(geometry, z, tol_fit)
        worst = max(worst, float(np.max(chord_error(functools.partial(_developed, geometry, z), phi))))
        X, A = to_machine(_developed(geometry, z, phi), z, sigma)
        w.comment(f"centre pass level {i + 1} of {len(levels)} Z{w.L(z)}")
        w.enter(X[0], A[0], z, safe, clear, lenoff)
        lenoff = []
        moves += w.inverse_time(X, A, z)
        w.leave(safe)
    m, e = _finishing(w, geometry, max(tol_fit - max(over, 0.0), 0.25 * tol_fit), safe, clear)
    w.block(["M9"])
    w.block(["M5"])
    w.block([p.end_code])
    if p.percent:
        w.lines.append("%")
    return ("\n".join(w.lines) + "\n").encode("ascii"), moves + m, max(worst, e)


def cylinder_job(job: Job, geometry: Any) -> Job:
    """The job cut to the groove's depth: no breakthrough, no bore, a round stock."""
    return dataclasses.replace(job, depth_mm=geometry.cylinder.groove_depth_mm, breakthrough_mm=0.0,
                               mill_bore=False, stock_shape="round")
