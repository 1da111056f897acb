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

Checks (all vectorised over densely sampled moves):

* **deviation** - the largest ``|exact_curve_distance|`` over the finishing-pass cutting moves at final
  depth (moves labelled ``FINISH CONTOUR`` by camfab's posts; without such labels, every horizontal
  cutting move at the deepest Z, which then includes any lead-in arcs); for simulated compensated moves
  the exact tool-centre curve is the set of points ``tool_radius`` from the part, so their deviation is
  ``|part_distance - tool_radius|``;
* **gouge** - a cutting move below the stock top whose tool centre comes closer to the finished part
  than ``tool_radius - tol`` (``part_distance < tool_radius - tol``), compensated or not, with the
  program lines involved;
* **rapids** - a rapid with horizontal travel below ``safe_z - tol`` (or before Z is known), a rapid that
  descends below the stock top, or a rapid below the stock top whose tool overlaps the part;
* **feed** - a cutting move before any feed was set (or at F0); cutting below the top with the spindle off;
* **arcs** - an arc whose start and end radius differ by more than ``tol`` (as programmed);
* **coverage** (optional, ``curve_points``) - the largest distance from points of the exact tool-centre
  curve to the finishing back-plot (simulated for compensated programs), so a program that skips part of
  the contour fails too.

Every problem names the program line (1-based); moves the simulation inserts (corner arcs, bridges) carry
the line of the programmed move they lead into.
"""
from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

from camfab.gcode.compensation import CompensatedPath, simulate_compensation
from camfab.gcode.parse import Backplot, sample
from camfab.results import Finding, IssueCode, Severity

__all__ = ["VerifyReport", "verify"]

_EPS_Z = 1e-6


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


def _r(v: float) -> float:
    return float(f"{v:.6g}")


def verify(moves, *, exact_curve_distance: Callable[[np.ndarray], np.ndarray],
           part_distance: Callable[[np.ndarray], np.ndarray], tool_radius: float, tol: float,
           safe_z: float, top_z: float = 0.0, step: float | None = None,
           finish_label: str = "FINISH CONTOUR", curve_points: np.ndarray | None = None,
           comp_radius: float | None = None) -> VerifyReport:
    """Check a back-plotted program.

    Parameters
    ----------
    moves : Backplot or sequence of Move
        From :func:`camfab.gcode.parse.parse`; a Backplot's warnings become problems.
    exact_curve_distance : callable
        ``f(points (n, 2)) -> (n,)`` signed distance in mm from the exact tool-centre curve (positive
        outside).
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
        Points on the exact tool-centre curve; enables the coverage check.
    comp_radius : float, optional
        Radius the controller compensates G41/G42 moves by (what the D register holds); default
        ``tool_radius``.  Gouge and deviation are always measured for ``tool_radius``.

    Returns
    -------
    VerifyReport
    """
    problems: list[Finding] = []
    notes: list[str] = []
    if isinstance(moves, Backplot):
        for w in moves.warnings:
            problems.append(Finding.at_line(IssueCode.PARSE_WARNING, w, severity=Severity.WARNING))
        moves = moves.moves
    moves = list(moves)
    if step is None:
        step = max(1e-3, min(0.05, 0.05 * tool_radius))
    r_tool = float(tool_radius)

    cutting = [i for i, m in enumerate(moves) if m.is_cutting]
    if not cutting:
        problems.append(Finding.at_line(IssueCode.NO_CUTTING_MOVES, "the program has no cutting moves"))

    # -- feed and spindle --------------------------------------------------------------------------
    if cutting:
        m0 = moves[cutting[0]]
        if m0.feed is None or m0.feed <= 0:
            problems.append(Finding.at_line(IssueCode.FEED_MISSING, "the first cutting move runs without a feed "
                                          "(no F word before it, or F0)", m0.line))
    for i in cutting:
        m = moves[i]
        if not m.spindle_on and min(m.start[2], m.end[2]) < top_z - _EPS_Z:
            problems.append(Finding.at_line(IssueCode.SPINDLE_OFF, "cutting below the stock top with the spindle off",
                                          m.line))
            break

    # -- arcs ----------------------------------------------------------------------------------------
    for m in moves:
        if m.kind == "arc" and abs(m.radius_start - m.radius_end) > tol:
            problems.append(Finding.at_line(
                IssueCode.ARC_RADIUS_MISMATCH, f"arc start and end radii differ by "
                f"{abs(m.radius_start - m.radius_end):.4f} mm (> tol {tol} mm)", m.line))

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

    # -- gouge ---------------------------------------------------------------------------------------
    gouge_at = None
    if cutting:
        smp = sample([moves[i] for i in cutting], step)
        pts, idx = smp.points, np.asarray(cutting)[smp.index]
        below = pts[:, 2] < top_z - _EPS_Z
        if below.any():
            p = pts[below]
            ii = idx[below]
            d = np.asarray(part_distance(p[:, :2]), dtype=float)
            pen = r_tool - d
            bad = pen > tol
            if bad.any():
                w = int(np.argmax(np.where(bad, pen, -np.inf)))
                gouge_at = {"x": _r(p[w, 0]), "y": _r(p[w, 1]), "z": _r(p[w, 2]),
                            "line": moves[int(ii[w])].line, "penetration_mm": _r(pen[w])}
                lines = sorted({moves[int(i)].line for i in ii[bad]})
                problems.append(Finding.at_line(
                    IssueCode.GOUGE, f"the tool enters the finished profile by up to {pen[w]:.4f} mm "
                    f"(> tol {tol} mm) at X{p[w, 0]:.4f} Y{p[w, 1]:.4f} Z{p[w, 2]:.4f}; "
                    f"lines {_line_list(lines)}", moves[int(ii[w])].line))
                if comp_path is not None:
                    runs = comp_path.run[ii[bad]]
                    worst = {int(k): float(pen[bad][runs == k].max()) for k in np.unique(runs) if k >= 0}
                    problems.extend(_wrong_side(comp_path, programmed, worst, part_distance, r_tool, r_comp,
                                                tol, top_z, step, join_tol))

    # -- deviation -----------------------------------------------------------------------------------
    lab = finish_label.upper()
    fin = [i for i in cutting if (moves[i].label or "").upper().startswith(lab)]
    if not fin and cutting:
        notes.append(f"no moves labelled {finish_label!r}: deviation measured over every horizontal "
                     "cutting move at the deepest Z")
        fin = cutting
    max_dev = None
    gap = None
    fin_final: list[int] = []
    if fin:
        zf = min(min(moves[i].start[2], moves[i].end[2]) for i in fin)
        fin_final = [i for i in fin
                     if abs(moves[i].start[2] - zf) <= _EPS_Z and abs(moves[i].end[2] - zf) <= _EPS_Z]
    if fin_final:
        smp = sample([moves[i] for i in fin_final], step)
        pts, idx = smp.points, np.asarray(fin_final)[smp.index]
        # simulated compensated moves: the exact tool-centre curve is where the part is tool_radius away
        comp = np.array([moves[i].comp != "G40" for i in idx])
        dev = np.empty(len(pts))
        if (~comp).any():
            dev[~comp] = np.abs(np.asarray(exact_curve_distance(pts[~comp, :2]), dtype=float))
        if comp.any():
            dev[comp] = np.abs(np.asarray(part_distance(pts[comp, :2]), dtype=float) - r_tool)
        w = int(np.argmax(dev))
        max_dev = _r(dev[w])
        if dev[w] > tol:
            problems.append(Finding.at_line(
                IssueCode.DEVIATION, f"the finishing pass deviates {dev[w]:.4f} mm from the exact curve "
                f"(> tol {tol} mm) at X{pts[w, 0]:.4f} Y{pts[w, 1]:.4f}", moves[int(idx[w])].line))
        if curve_points is not None:
            gap = _r(_coverage_gap(np.asarray(curve_points, float).reshape(-1, 2), pts[:, :2], idx, step))
            if gap > tol:
                problems.append(Finding.at_line(
                    IssueCode.COVERAGE, f"part of the exact curve is {gap:.4f} mm from the finishing pass "
                    f"(> tol {tol} mm): the program does not cut the whole contour"))
    elif cutting:
        problems.append(Finding.at_line(IssueCode.NO_FINISH_PASS, "no horizontal cutting moves at final depth"))

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
        smp = sample([moves[i] for i in rapids], step)
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


def _wrong_side(comp_path: CompensatedPath, programmed, worst: dict, part_distance, r_tool: float,
                r_comp: float, tol: float, top_z: float, step: float, join_tol: float) -> list[Finding]:
    """``COMP_WRONG_SIDE`` for each gouging G41/G42 stretch that would not gouge on the other side."""
    swapped = simulate_compensation(programmed, r_comp, swap_side=True, join_tol=join_tol)
    out = []
    for run, pen_now in sorted(worst.items()):
        info = comp_path.runs[run]
        sel = [i for i, m in enumerate(swapped.moves) if swapped.run[i] == run and m.is_cutting]
        if not sel:
            continue
        smp = sample([swapped.moves[i] for i in sel], step)
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


def _line_list(lines: Sequence[int], limit: int = 8) -> str:
    head = ", ".join(str(v) for v in lines[:limit])
    return head + (f" and {len(lines) - limit} more" if len(lines) > limit else "")


def _coverage_gap(curve: np.ndarray, pts: np.ndarray, idx: np.ndarray, step: float) -> float:
    """Largest distance from curve points to the polyline through the back-plot samples.

    Consecutive samples are joined when they belong to one move, or to consecutive moves that meet (at
    most ``step`` apart once repeated junction points are dropped).  Each curve point is measured to the
    polyline segments at its few nearest samples, so a junction visited twice (the start and end of a
    closed contour) or a very short move between two long ones (a corner arc of a compensated path) does
    not hide the segment it lies on.
    """
    from scipy.spatial import cKDTree

    if len(pts) == 0 or len(curve) == 0:
        return math.inf
    keep = np.ones(len(pts), dtype=bool)
    keep[1:] = np.hypot(*np.diff(pts, axis=0).T) > 1e-9
    pts, idx = pts[keep], idx[keep]
    n = len(pts)
    best = np.full(len(curve), np.inf)
    if n == 1:
        return float(np.hypot(*(curve - pts[0]).T).max())
    seg = np.hypot(*np.diff(pts, axis=0).T)
    link = (idx[1:] == idx[:-1]) | ((idx[1:] > idx[:-1]) & (seg <= step * (1 + 1e-9) + 1e-9))
    k = min(8, n)
    _, near = cKDTree(pts).query(curve, k=k)
    near = near.reshape(len(curve), k)
    for j in range(k):
        a = near[:, j]
        best = np.minimum(best, np.hypot(*(curve - pts[a]).T))
        for off in (-1, 0):  # the segments (a-1, a) and (a, a+1)
            s0 = a + off
            ok = (s0 >= 0) & (s0 < n - 1)
            s0 = np.clip(s0, 0, n - 2)
            ok &= link[s0]
            pa, pb = pts[s0], pts[s0 + 1]
            ab = pb - pa
            L2 = np.einsum("ij,ij->i", ab, ab)
            t = np.where(L2 > 0, np.einsum("ij,ij->i", curve - pa, ab) / np.where(L2 > 0, L2, 1), 0)
            q = pa + np.clip(t, 0, 1)[:, None] * ab
            d = np.hypot(*(curve - q).T)
            best = np.where(ok, np.minimum(best, d), best)
    return float(best.max())
