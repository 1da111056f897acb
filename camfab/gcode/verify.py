"""Verify a back-plotted program against the exact geometry it is meant to cut.

Programs with cutter compensation (G41/G42) carry the part contour, not the tool centre.  They are first
turned into the tool-centre path the controller would run, by
:func:`camfab.gcode.compensation.simulate_compensation` (moves offset by the compensation radius, rolling
arcs at convex corners, trimmed concave corners, LinuxCNC-style ramp-on and ramp-off), and every check
below then sees that simulated path, exactly as for a tool-centre program.  The simulation itself reports
what a controller would refuse or what would cut into the part: ``COMP_ENTRY`` (compensation turned on by
an arc, or by an entry move not longer than the tool radius), ``COMP_EXIT`` (turned off by an arc, or by a
move shorter than the tool diameter), ``COMP_ARC_RADIUS`` (an arc whose radius is smaller than the tool
radius with the tool on its centre's side), ``COMP_CORNER`` (a concave corner or notch too tight for the
tool: the offset moves do not meet), ``COMP_SIDE_CHANGE`` (G41 <-> G42 without G40); and
``COMP_WRONG_SIDE`` when a gouging G41/G42 stretch would not gouge compensated to the other side.

Checks (vectorised over the moves' sample points; each move is sampled every ``step`` mm but at most
``max_samples_per_move`` times, so the cost follows the number of moves, not the size of the part):

* **readable** - a program that cannot be parsed is one ``PARSE_ERROR`` finding (:func:`verify_program`),
  a parse warning (no program end, no units) a ``PARSE_WARNING``; ``MODAL_STATE`` when the program does not
  set the plane (G17), units (G20/G21), distance mode (G90/G91), feed mode (G94), cutter compensation
  (G40/G41/G42) and work offset (G54-G59) before its first move (a controller keeps what the last program
  left);
* **deviation** - the largest ``|exact_curve_distance|`` over the finishing-pass cutting moves at final
  depth (moves labelled ``FINISH CONTOUR`` by camfab's posts; without such labels, every horizontal
  cutting move at the deepest Z, which then includes any lead-in arcs); for simulated compensated moves,
  and for all when ``exact_curve_distance`` is None, the exact tool-centre curve is the set of points
  ``tool_radius`` from the part, so the deviation is ``|part_distance - tool_radius|``;
* **gouge** - a cutting move below the stock top whose tool centre comes closer to the finished part
  than ``tool_radius - tol`` (``part_distance < tool_radius - tol``), compensated or not, with the
  program lines involved;
* **rapids** - a rapid with horizontal travel below ``safe_z - tol`` (or before Z is known), a rapid that
  descends below the stock top, or a rapid below the stock top whose tool overlaps the part;
* **feed** - every cutting move: none set or F0 (``FEED_MISSING``); with a ``job``, a feed other than the
  job's (``FEED_OUT_OF_RANGE``: a Z-only or descending move - plunge, ramp, helix - at the plunge feed,
  every other cutting move at the cutting feed, within the rounding of the written F word);
* **bore** (with a ``job`` that mills the bore) - the moves labelled ``BORE ...`` stay inside the bore's
  wall (``GOUGE``) and its finishing circle runs round at full depth at ``(bore - D) / 2`` (``DEVIATION``,
  ``FINISH_DEPTH``); they are then left out of the contour's gouge, deviation and coverage checks;
* **spindle** - cutting below the top with the spindle off (``SPINDLE_OFF``) or turning counter-clockwise
  (``M4``, ``SPINDLE_DIRECTION``: camfab's end mills cut with M3); with a ``job``, at another speed
  (``SPINDLE_SPEED``);
* **coolant** (with a ``job``) - every cut below the top runs with the coolant the job asks
  (``COOLANT``: flood M8, mist M7 - or M8 where the post writes M8 for mist - or none);
* **tool** (with a ``job``) - the job's tool loaded by ``T.. M6`` (where the post has a tool changer) and
  its length offset ``G43 H..`` active (where the post writes one) while cutting (``TOOL``,
  ``TOOL_LENGTH_OFFSET``);
* **depth** (with a ``job``) - the finishing pass at the final depth ``Z = -depth_mm`` (plate and
  breakthrough, ``FINISH_DEPTH``),
  nothing cut below it (``TOO_DEEP``), no cut deeper than one step-down below what was cut before
  (``STEP_DOWN``), and the finishing pass in the job's milling direction (``DIRECTION``: climb is
  clockwise around the part);
* **end** - the program ends with the tool below the stock top (``RETRACT_MISSING``);
* **arcs** - an arc whose start and end radius differ by more than ``tol`` (as programmed; plus ``√2`` output
  increments of the post's rounding when the post is known);
* **coverage** (``part_curve`` or ``curve_points``) - the thickest material the finishing moves at final
  depth leave on the part (the finishing samples projected onto the part, the part measured where no
  continuous cut covers it and at 4096 points along it), or the largest distance from the given points of
  the exact tool-centre curve to those moves (exact distances to the lines and arcs, simulated for
  compensated programs), so a program that skips part of the contour fails too.

The maximum deviation and penetration of each move are resolved 16 times finer around its worst sample,
so the bounded sampling still finds them (see ``docs/decisions.md``, "What verify checks").

Every problem names the program line (1-based); moves the simulation inserts (corner arcs, bridges) carry
the line of the programmed move they lead into.
"""
from __future__ import annotations

import math
import re
from collections.abc import Callable, Sequence

import numpy as np

from camfab.gcode.checks import (
    EPS_Z,
    bore_findings,
    bore_moves,
    depth_findings,
    direction_findings,
    feed_findings,
    line_list,
    machine_state_findings,
    modal_state,
    retract_findings,
)
from camfab.gcode.compensation import CompensatedPath, simulate_compensation
from camfab.gcode.distance import CurveDistance, Entities, IndexedContourDistance
from camfab.gcode.model import Job
from camfab.gcode.parse import Backplot, GcodeError, Move, Samples, parse, points_along, sample
from camfab.gcode.post import POSTS, get_post
from camfab.gcode.posts.base import Post
from camfab.records import dataclass, field, replace
from camfab.results import Finding, IssueCode, Severity

__all__ = ["MAX_SAMPLES_PER_MOVE", "VerifyReport", "declared_post", "default_step", "verify", "verify_program"]

_EPS_Z = EPS_Z
#: at most this many sample intervals per move: the cost follows the number of moves, not their length
MAX_SAMPLES_PER_MOVE = 256
#: how much finer the intervals around each move's worst sample are resolved
_REFINE = 16


@dataclass(frozen=True)
class VerifyReport:
    """Outcome of :func:`verify`.

    Attributes
    ----------
    max_deviation_mm : float or None
        Worst distance of the finishing back-plot from the exact tool-centre curve (None if no finishing
        moves were found).
    gouge : bool
    gouge_at : dict or None
        Worst gouge: ``x``, ``y``, ``z``, ``line``, ``penetration_mm`` (how far the tool enters the part).
    problems : tuple of Finding
        Each with its code, sentence and program line (1-based) when known.
    tolerance_mm : float
    coverage_gap_mm : float or None
    finish_moves : int
        Number of moves the deviation was measured over.
    notes : tuple of str
    """

    max_deviation_mm: float | None
    gouge: bool
    gouge_at: dict | None
    problems: tuple
    tolerance_mm: float
    coverage_gap_mm: float | None = None
    finish_moves: int = 0
    notes: tuple = field(default=())

    @property
    def ok(self) -> bool:
        """True when there are no problems."""
        return not self.problems

    def codes(self) -> set[IssueCode]:
        """The set of problem codes."""
        return {p.code for p in self.problems}

    def to_dict(self) -> dict:
        """JSON-ready mapping with keys ``max_deviation_mm``, ``gouge``, ``gouge_at``, ``problems``,
        ``ok`` (plus ``tolerance_mm``, ``coverage_gap_mm``, ``finish_moves``, ``notes``)."""
        return {
            "max_deviation_mm": self.max_deviation_mm,
            "gouge": self.gouge,
            "gouge_at": self.gouge_at,
            "problems": [{"code": p.code.value, "message": p.message, "line": p.line} for p in self.problems],
            "ok": self.ok,
            "tolerance_mm": self.tolerance_mm,
            "coverage_gap_mm": self.coverage_gap_mm,
            "finish_moves": self.finish_moves,
            "notes": list(self.notes),
        }


def default_step(tool_radius: float) -> float:
    """The sampling step of :func:`verify` in mm: ``tool_radius / 20`` within [0.001, 0.05]."""
    return max(1e-3, min(0.05, 0.05 * float(tool_radius)))


def _r(v: float) -> float:
    return float(f"{v:.6g}")


def verify(moves, *, exact_curve_distance: Callable[[np.ndarray], np.ndarray] | None,
           part_distance: Callable[[np.ndarray], np.ndarray], tool_radius: float, tol: float,
           safe_z: float, top_z: float = 0.0, step: float | None = None,
           finish_label: str = "FINISH CONTOUR", curve_points: np.ndarray | None = None,
           comp_radius: float | None = None, job: Job | None = None, post: str | Post | None = None,
           part_curve: IndexedContourDistance | CurveDistance | None = None,
           max_samples_per_move: int = MAX_SAMPLES_PER_MOVE) -> VerifyReport:
    """Check a back-plotted program.

    Parameters
    ----------
    moves : Backplot or sequence of Move
        From :func:`camfab.gcode.parse.parse`; a Backplot's warnings become problems and its modal state
        is checked.
    exact_curve_distance : callable or None
        ``f(points (n, 2)) -> (n,)`` signed distance in mm from the exact tool-centre curve (positive
        outside); None: the tool-centre curve is the set of points ``tool_radius`` from the part, whose
        distance is ``|part_distance - tool_radius|`` (what ``camfab verify`` uses; the finishing moves then
        reuse the part distances the gouge check measured).
    part_distance : callable
        ``f(points (n, 2)) -> (n,)`` signed distance in mm from the finished part profile (negative inside
        the material).
    tool_radius : float
        mm.
    tol : float
        Tolerance in mm for deviation and gouge.
    safe_z : float
        Safe height every horizontal rapid must run at, mm.
    top_z : float
        Stock top, mm.
    step : float, optional
        Sampling step in mm (default ``min(0.05, 5 * tool_radius / 100)``, at least 1e-3).
    finish_label : str
        Comment label (prefix, case-insensitive) of the finishing contour moves.
    curve_points : ndarray (m, 2), optional
        Points on the exact tool-centre curve; enables the coverage check (measured at these points).
    comp_radius : float, optional
        Radius the controller compensates G41/G42 moves by (what the D register holds); default
        ``tool_radius``.  Gouge and deviation are always measured for ``tool_radius``.
    job : Job, optional
        What the program must do: final depth, step-down, feeds, spindle speed, coolant, tool, milling
        direction.  Without it those checks are left out (and a note says so).
    post : str or Post, optional
        The controller the program is for (``"linuxcnc"``, ``"fanuc"``, ``"grbl"``): whether a tool change
        and a length offset are expected, and which code means mist coolant.
    part_curve : IndexedContourDistance or CurveDistance, optional
        The finished part's contour (e.g. :func:`camfab.gcode.cam.signed_distance` of it, which may serve as
        ``part_distance`` too); enables the coverage check at a cost that follows the program: the
        finishing samples are projected onto the part, the stretches between consecutive ones marked
        covered, and the material left measured (distance to the pass minus ``tool_radius``) where
        nothing covers the part, and at 4096 points spread along it.
    max_samples_per_move : int
        At most this many sample intervals per move.

    Returns
    -------
    VerifyReport
    """
    problems: list[Finding] = []
    notes: list[str] = []
    if isinstance(moves, Backplot):
        for w in moves.warnings:
            problems.append(Finding.at_line(IssueCode.PARSE_WARNING, w, severity=Severity.WARNING))
        if moves.moves:
            problems.extend(modal_state(moves))
        moves = moves.moves
    moves = list(moves)
    if step is None:
        step = default_step(tool_radius)
    K = int(max_samples_per_move)
    r_tool = float(tool_radius)
    the_post = get_post(post) if post is not None else None

    cutting = [i for i, m in enumerate(moves) if m.is_cutting]
    if not cutting:
        problems.append(Finding.at_line(IssueCode.NO_CUTTING_MOVES, "the program has no cutting moves"))

    # -- feed, spindle, coolant, tool: every cutting move --------------------------------------------
    problems.extend(feed_findings(moves, cutting, job))
    problems.extend(machine_state_findings(moves, cutting, top_z, job, the_post))
    problems.extend(retract_findings(moves, top_z))
    if job is None:
        notes.append("no job given: depth, step-down, feeds, spindle speed, coolant, tool and milling direction "
                     "were not checked against one")

    # -- arcs ----------------------------------------------------------------------------------------
    # rounding the two ends to the post's increment h moves each radius by up to h/√2 (docs/decisions.md, "Fanuc
    # decimals and the rounding budget"): a known post's programs get that room on top of tol
    units = job.units if job is not None else "mm"
    slack = 0.0 if the_post is None else (
        math.sqrt(2.0) * 10.0 ** -the_post.decimals(units, tol) * (25.4 if units == "inch" else 1.0))
    for m in moves:
        if m.kind == "arc" and abs(m.radius_start - m.radius_end) > tol + slack:
            problems.append(Finding.at_line(
                IssueCode.ARC_RADIUS_MISMATCH, f"arc start and end radii differ by "
                f"{abs(m.radius_start - m.radius_end):.4f} mm (> tol {tol} mm"
                f"{f' + rounding {slack:.4f} mm' if slack else ''})", m.line))

    # -- cutter compensation: simulate it, then check the tool-centre path ------------------------------
    programmed = moves
    comp_path: CompensatedPath | None = None
    r_comp = r_tool if comp_radius is None else float(comp_radius)
    join_tol = max(0.1 * tol, 1e-6)
    if any(m.comp != "G40" for m in moves):
        comp_path = simulate_compensation(moves, r_comp, join_tol=join_tol)
        problems.extend(comp_path.problems)
        c = comp_path.corners
        notes.append(f"cutter compensation simulated with radius {r_comp:g} mm over {len(comp_path.runs)} "
                     f"G41/G42 stretch(es): {c['rolling']} rolling corner arc(s), {c['trimmed']} trimmed "
                     "concave corner(s); the checks below see the simulated tool-centre path")
        moves = list(comp_path.moves)
        cutting = [i for i, m in enumerate(moves) if m.is_cutting]

    # -- the bore (when the job mills one): checked against its wall, then left out of the contour checks ------
    bore = bore_moves(moves, cutting, job)
    all_cutting = cutting
    if bore and job is not None:
        problems.extend(bore_findings(moves, bore, job, tol, step, sample))
        cutting = [i for i in cutting if i not in set(bore)]

    # -- gouge ---------------------------------------------------------------------------------------
    gouge_at = None
    if cutting:
        sub = [moves[i] for i in cutting]
        smp = sample(sub, step, K)
        below = smp.points[:, 2] < top_z - _EPS_Z
        d_base = np.full(len(smp.points), np.nan)
        if below.any():
            d_base[below] = np.asarray(part_distance(smp.points[below, :2]), dtype=float)
        # kept per move: the finishing moves' deviation reuses them
        part_at = dict(zip(cutting, np.split(d_base, np.cumsum(np.bincount(smp.index, minlength=len(sub)))[:-1]),
                           strict=True))
        if below.any():
            pen = r_tool - d_base[below]
            smp = _subset(smp, below)
            extra = _around_peaks(sub, smp, pen)  # each move's deepest sample, resolved 16 times finer
            keep = extra.points[:, 2] < top_z - _EPS_Z
            extra = _subset(extra, keep)
            pen = np.concatenate([pen, r_tool - np.asarray(part_distance(extra.points[:, :2]), dtype=float)])
            p = np.concatenate([smp.points, extra.points])
            ii = np.asarray(cutting)[np.concatenate([smp.index, extra.index])]
            bad = pen > tol
            if bad.any():
                w = int(np.argmax(np.where(bad, pen, -np.inf)))
                gouge_at = {"x": _r(p[w, 0]), "y": _r(p[w, 1]), "z": _r(p[w, 2]),
                            "line": moves[int(ii[w])].line, "penetration_mm": _r(pen[w])}
                lines = sorted({moves[int(i)].line for i in ii[bad]})
                problems.append(Finding.at_line(
                    IssueCode.GOUGE, f"the tool enters the finished profile by up to {pen[w]:.4f} mm "
                    f"(> tol {tol} mm) at X{p[w, 0]:.4f} Y{p[w, 1]:.4f} Z{p[w, 2]:.4f}; "
                    f"lines {line_list(lines)}", moves[int(ii[w])].line))
                if comp_path is not None:
                    runs = comp_path.run[ii[bad]]
                    worst = {int(k): float(pen[bad][runs == k].max()) for k in np.unique(runs) if k >= 0}
                    problems.extend(_wrong_side(comp_path, programmed, worst, part_distance, r_tool, r_comp,
                                                tol, top_z, step, join_tol, K))

    # -- deviation, coverage, final depth and direction of the finishing pass ---------------------------
    lab = finish_label.upper()
    fin = [i for i in cutting if (moves[i].label or "").upper().startswith(lab)]
    if not fin and cutting:
        notes.append(f"no moves labelled {finish_label!r}: deviation measured over every horizontal "
                     "cutting move at the deepest Z")
        fin = cutting
    max_dev = None
    gap = None
    fin_final: list[int] = []
    zf = math.nan
    if fin:
        zf = min(min(moves[i].start[2], moves[i].end[2]) for i in fin)
        fin_final = [i for i in fin
                     if abs(moves[i].start[2] - zf) <= _EPS_Z and abs(moves[i].end[2] - zf) <= _EPS_Z]
    if fin_final:
        sub = [moves[i] for i in fin_final]

        def deviation(pts: np.ndarray, idx: np.ndarray, known: np.ndarray | None = None) -> np.ndarray:
            # the exact tool-centre curve is where the part is tool_radius away: |part distance - r| for the
            # simulated compensated moves, and for all when no exact_curve_distance is given
            by_part = np.array([moves[i].comp != "G40" or exact_curve_distance is None for i in idx], dtype=bool)
            dev = np.empty(len(pts))
            if (~by_part).any():
                assert exact_curve_distance is not None
                dev[~by_part] = np.abs(np.asarray(exact_curve_distance(pts[~by_part, :2]), dtype=float))
            if by_part.any():
                d = known[by_part] if known is not None else np.full(int(by_part.sum()), np.nan)
                todo = np.isnan(d)
                if todo.any():
                    d[todo] = np.asarray(part_distance(pts[by_part][todo, :2]), dtype=float)
                dev[by_part] = np.abs(d - r_tool)
            return dev

        smp = sample(sub, step, K)
        known = np.concatenate([part_at.get(i, np.full(int(c), np.nan)) if len(part_at.get(i, ())) == c
                                else np.full(int(c), np.nan)
                                for i, c in zip(fin_final, np.bincount(smp.index, minlength=len(sub)), strict=True)])
        dev = deviation(smp.points, np.asarray(fin_final)[smp.index], known)
        extra = _around_peaks(sub, smp, dev)  # each move's worst sample, resolved 16 times finer
        dev_x = deviation(extra.points, np.asarray(fin_final)[extra.index])
        pts, idx = smp.points, np.asarray(fin_final)[smp.index]  # (coverage: the evenly spaced samples)
        dev_all = np.concatenate([dev, dev_x])
        pts_all = np.concatenate([pts, extra.points])
        idx_all = np.concatenate([idx, np.asarray(fin_final)[extra.index]])
        w = int(np.argmax(dev_all))
        max_dev = _r(dev_all[w])
        if dev_all[w] > tol:
            problems.append(Finding.at_line(
                IssueCode.DEVIATION, f"the finishing pass deviates {dev_all[w]:.4f} mm from the exact curve "
                f"(> tol {tol} mm) at X{pts_all[w, 0]:.4f} Y{pts_all[w, 1]:.4f}", moves[int(idx_all[w])].line))
        # coverage: the largest distance from the exact tool-centre curve to the finishing pass (points of it
        # given), or the thickest material the pass leaves on the part (the part's curve given)
        fin_ent = Entities.from_moves([moves[i] for i in fin_final]) if (
            curve_points is not None or part_curve is not None) else None
        probes = []
        if curve_points is not None and fin_ent is not None:
            on_centre = np.asarray(curve_points, float).reshape(-1, 2)
            probes.append((on_centre, fin_ent.distance(on_centre)))
        if part_curve is not None and fin_ent is not None:
            on_part = _uncovered_probe(part_curve, pts[:, :2], idx, r_tool, tol)
            probes.append((on_part, fin_ent.distance(on_part) - r_tool))
        if probes:
            curve = np.concatenate([q for q, _ in probes])
            d_cov = np.concatenate([d for _, d in probes])
            wc = int(np.argmax(d_cov)) if len(d_cov) else 0
            gap = _r(max(float(d_cov[wc]), 0.0)) if len(d_cov) else None
            if gap is not None and gap > tol:
                problems.append(Finding.at_line(
                    IssueCode.COVERAGE, f"the finishing pass at Z{zf:.4f} leaves up to {gap:.4f} mm (> tol {tol} mm) "
                    f"of the contour uncut, e.g. at X{curve[wc, 0]:.4f} Y{curve[wc, 1]:.4f}: the program does not "
                    "cut the whole contour"))
        if job is not None:
            problems.extend(direction_findings(pts[:, :2], job, moves[fin_final[0]].line))
    elif cutting:
        problems.append(Finding.at_line(IssueCode.NO_FINISH_PASS, "no horizontal cutting moves at final depth"))
    if curve_points is None and part_curve is None:
        notes.append("no exact curve given: coverage of the whole contour not checked")
    if job is not None:
        problems.extend(depth_findings(moves, all_cutting, fin_final, zf, job, top_z, tol))

    # -- rapids --------------------------------------------------------------------------------------
    rapids = [i for i, m in enumerate(moves) if m.kind == "rapid"]
    for i in rapids:
        m = moves[i]
        s, e = np.array(m.start, float), np.array(m.end, float)
        if not np.all(np.isfinite(e[:2])):
            xy_travel = False  # X and Y never set: the rapid moved Z only
        elif not np.all(np.isfinite(s[:2])):
            xy_travel = True  # from an unknown position
        else:
            xy_travel = float(np.hypot(*(e[:2] - s[:2]))) > _EPS_Z
        if xy_travel:
            zs = [v for v in (s[2], e[2])]
            if any(math.isnan(v) for v in zs):
                problems.append(Finding.at_line(IssueCode.RAPID_BELOW_SAFE, "horizontal rapid before the height is "
                                              "known (retract Z first)", m.line))
            elif min(zs) < safe_z - tol:
                problems.append(Finding.at_line(IssueCode.RAPID_BELOW_SAFE, f"horizontal rapid at Z{min(zs):.4f}, "
                                              f"below the safe height Z{safe_z:.4f}", m.line))
        if math.isfinite(e[2]) and e[2] < top_z - _EPS_Z and (not math.isfinite(s[2]) or e[2] < s[2] - _EPS_Z):
            problems.append(Finding.at_line(IssueCode.RAPID_INTO_STOCK, f"rapid descends to Z{e[2]:.4f}, below the "
                                          f"stock top Z{top_z:.4f}", m.line))
    if rapids:
        smp = sample([moves[i] for i in rapids], step, K)
        pts, idx = smp.points, np.asarray(rapids)[smp.index]
        below = pts[:, 2] < top_z - _EPS_Z
        if below.any():
            d = np.asarray(part_distance(pts[below, :2]), dtype=float)
            hit = d < r_tool - tol
            for i in sorted(set(idx[below][hit].tolist())):
                problems.append(Finding.at_line(IssueCode.RAPID_THROUGH_PART, "rapid below the stock top runs the "
                                              "tool through the part", moves[i].line))

    problems.sort(key=lambda p: (p.line if p.line is not None else -1, p.code))
    return VerifyReport(max_deviation_mm=max_dev, gouge=gouge_at is not None, gouge_at=gouge_at,
                        problems=tuple(problems), tolerance_mm=float(tol), coverage_gap_mm=gap,
                        finish_moves=len(fin_final), notes=tuple(notes))


def _subset(smp: Samples, keep: np.ndarray) -> Samples:
    return Samples(smp.points[keep], smp.index[keep], None if smp.param is None else smp.param[keep])


def _around_peaks(moves: Sequence[Move], smp: Samples, value: np.ndarray, n: int = _REFINE) -> Samples:
    """``n + 1`` points across the two sample intervals around each move's largest ``value``.

    Sampled at most ``max_samples_per_move`` times, a long move's worst point lies between two samples;
    the quantities measured (deviation, penetration) are smooth along a line or an arc, so resolving the
    intervals around each move's worst sample ``n`` times finer brings the maximum to its true value.
    """
    if not len(value) or smp.param is None:
        return Samples(np.zeros((0, 3)), np.zeros(0, dtype=np.int64), np.zeros(0))
    order = np.lexsort((-value, smp.index))
    first = np.ones(len(order), dtype=bool)
    first[1:] = smp.index[order][1:] != smp.index[order][:-1]
    pts, ind, par = [], [], []
    for j in order[first]:
        i, u = int(smp.index[j]), smp.param
        lo = u[j - 1] if j > 0 and smp.index[j - 1] == i else u[j]
        hi = u[j + 1] if j + 1 < len(u) and smp.index[j + 1] == i else u[j]
        if hi <= lo:
            continue
        uu = np.linspace(lo, hi, n + 1)
        pts.append(points_along(moves[i], uu))
        ind.append(np.full(n + 1, i, dtype=np.int64))
        par.append(uu)
    if not pts:
        return Samples(np.zeros((0, 3)), np.zeros(0, dtype=np.int64), np.zeros(0))
    return Samples(np.concatenate(pts), np.concatenate(ind), np.concatenate(par))


def _uncovered_probe(part: IndexedContourDistance | CurveDistance, pts: np.ndarray, idx: np.ndarray, r_tool: float,
                     tol: float) -> np.ndarray:
    """Points of the ``part`` contour to measure the coverage at: 4096 spread evenly, and up to 64 in every
    stretch that no part of the finishing pass projects onto.

    Consecutive samples ``pts`` (xy, of moves ``idx``, in program order) belong to one continuous cut when
    they come from one move or coincide (where one move ends and the next begins); the stretch of the part
    between their nearest points is covered unless it is much longer than the cut between them (a cut
    near two branches of the contour does not cover what lies between them).
    """
    L = part.length
    even = np.linspace(0.0, L, 4096, endpoint=False)
    if len(pts) < 2 or L <= 0:
        return part.at_position(even)
    d, s = part.project(pts)
    chord = np.hypot(*np.diff(pts, axis=0).T)
    ds = np.mod(np.diff(s) + 0.5 * L, L) - 0.5 * L  # the short way round
    reach = 2.0 * chord + 4.0 * (d[1:] + d[:-1] + r_tool) + 1e-9
    ok = ((idx[1:] == idx[:-1]) | (chord <= 1e-9)) & (np.abs(ds) <= reach)
    lo = np.mod(np.where(ds >= 0, s[:-1], s[1:]), L)[ok]
    hi = lo + np.abs(ds)[ok]
    # the circle [0, L): split the stretches that pass L, then merge
    wrap = hi > L
    lo, hi = np.concatenate([lo, np.zeros(int(wrap.sum()))]), np.concatenate([np.minimum(hi, L), hi[wrap] - L])
    order = np.argsort(lo, kind="stable")
    lo, hi = lo[order], np.maximum.accumulate(hi[order]) if len(hi) else hi
    gaps_lo, gaps_hi = np.concatenate([[0.0], hi]), np.concatenate([lo, [L]])
    probe = [even]
    for a, b in zip(gaps_lo, gaps_hi, strict=True):
        if b - a > 1e-9:
            probe.append(np.linspace(a, b, int(min(64, max(3, math.ceil((b - a) / max(tol, 1e-9)))))))
    return part.at_position(np.concatenate(probe))


def verify_program(text: str | bytes, *, post: str | Post | None = None, default_post: str | None = None,
                   **kw) -> VerifyReport:
    """Read and :func:`verify` a program; one that cannot be read is a ``PARSE_ERROR`` finding, not an error.

    Parameters
    ----------
    text : str or bytes
        The program (bytes are decoded as UTF-8; undecodable bytes are a parse error at their line).
    post : str or Post, optional
        The controller the program is for; default: the one its header comment declares
        (``(post: grbl, ...)``, as camfab's posts write), else ``default_post``.
    default_post : str, optional
        The controller assumed when neither ``post`` nor the program names one.
    **kw
        The keywords of :func:`verify` (``tol`` required).

    Returns
    -------
    VerifyReport
    """
    tol = float(kw["tol"])
    try:
        if isinstance(text, bytes):
            raw = text
            try:
                text = raw.decode("utf-8")
            except UnicodeDecodeError as exc:
                line = raw[:exc.start].count(b"\n") + 1
                raise GcodeError(line, f"not UTF-8 text (byte 0x{raw[exc.start]:02x})") from None
        backplot = parse(text)
    except GcodeError as exc:
        return VerifyReport(max_deviation_mm=None, gouge=False, gouge_at=None, tolerance_mm=tol,
                            problems=(Finding.at_line(IssueCode.PARSE_ERROR, f"the program cannot be read: {exc}",
                                                      exc.line),),
                            notes=("nothing else was checked: a controller stops at (or misreads) this line",))
    how = "given"
    if post is None:
        post, how = declared_post(backplot.comments), "declared by the program"
    if post is None:
        post, how = default_post, "assumed"
    rep = verify(backplot, post=post, **kw)
    if post is None:
        return rep
    name = post if isinstance(post, str) else post.name
    return replace(rep, notes=rep.notes + (f"checked as a {name} program ({how})",))


def declared_post(comments) -> str | None:
    """The post-processor a program's header comment names (``post: NAME``), if it is a known one."""
    for c in comments[:40]:
        m = _POST_COMMENT.match(c)
        if m and m.group(1).lower() in POSTS:
            return m.group(1).lower()
    return None


_POST_COMMENT = re.compile(r"^\s*post:?\s+([A-Za-z]+)", re.IGNORECASE)
def _wrong_side(comp_path: CompensatedPath, programmed, worst: dict, part_distance, r_tool: float,
                r_comp: float, tol: float, top_z: float, step: float, join_tol: float, K: int) -> list[Finding]:
    """``COMP_WRONG_SIDE`` for each gouging G41/G42 stretch that would not gouge on the other side."""
    swapped = simulate_compensation(programmed, r_comp, swap_side=True, join_tol=join_tol)
    out = []
    for run, pen_now in sorted(worst.items()):
        info = comp_path.runs[run]
        sel = [i for i, m in enumerate(swapped.moves) if swapped.run[i] == run and m.is_cutting]
        if not sel:
            continue
        smp = sample([swapped.moves[i] for i in sel], step, K)
        below = smp.points[:, 2] < top_z - _EPS_Z
        if not below.any():
            continue
        pen = r_tool - np.asarray(part_distance(smp.points[below, :2]), dtype=float)
        if float(pen.max()) > tol:
            continue
        other = "G42" if info.side == "G41" else "G41"
        out.append(Finding.at_line(
            IssueCode.COMP_WRONG_SIDE, f"{info.side} (lines {info.first_line}-{info.last_line}) compensates to the "
            f"wrong side of the contour: the tool cuts up to {pen_now:.4f} mm into the part; with {other} "
            "it would not gouge", info.entry_line if info.entry_line is not None else info.first_line))
    return out
