"""The 2.5D contour-milling program builder: a closed contour and a Job -> a Program.

Conventions
-----------
* All coordinates, lengths and feeds in the model (:mod:`camfab.gcode.model`) are **millimetres**
  (feeds mm/min), whatever units the program is finally written in: the post-processor converts
  (``Job.units``).
* The top of the stock is ``Z = 0``; cutting depths are negative, the final depth is ``-Job.depth_mm``.
* Outside milling of a plate cam: the part lies inside the closed contour.  With the spindle turning
  clockwise (M3) *climb* milling runs clockwise around the part (G41 side), *conventional* runs
  counter-clockwise (G42 side).
* The program carries **tool-centre** coordinates (the contour given is the tool-centre path from the
  offset module) unless ``compensation="G41"|"G42"`` is asked for; then the contour given is the finished
  part profile and the controller offsets it.
* Structural comments label every pass: ``ROUGH PASS k OF N LEVEL i OF m``, ``FINISH PASS LEVEL i OF m``,
  then ``<KIND> LEAD-IN``, ``<KIND> CONTOUR``, ``<KIND> LEAD-OUT`` with ``KIND`` = ``ROUGH``/``FINISH``.
  :func:`camfab.gcode.verify.verify` uses the ``FINISH CONTOUR`` label to measure the deviation.
"""
from __future__ import annotations

import numpy as np

from camfab.errors import GeometryError, Problem, SpecError
from camfab.gcode.contour import (
    ContourDistance,
    Segment,
    offset_contour,
    orient_contour,
    outward_normal,
)
from camfab.gcode.model import (
    Arc,
    Comment,
    Coolant,
    CutterComp,
    Feed,
    Item,
    Job,
    Program,
    Rapid,
    Spindle,
    ToolChange,
)
from camfab.geom2d import TWO_PI
from camfab.limits import MAX_PROGRAM_MOVES

__all__ = ["contour_toolpath"]


def _choose_start(segs: tuple[Segment, ...], cw: bool) -> tuple[Segment, ...]:
    """Rotate the contour to start mid-way along its longest line, else its largest convex arc."""
    lines = [(s.length, -i) for i, s in enumerate(segs) if not s.is_arc]
    if lines:
        i = -max(lines)[1]
    else:
        convex = [(s.radius, abs(s.sweep), -i) for i, s in enumerate(segs) if s.clockwise == cw]
        if not convex:
            return segs
        i = -max(convex)[2]
    a, b = segs[i].split(0.5)
    return (b,) + segs[i + 1:] + segs[:i] + (a,)


def _contour_items(segs, z, feed) -> list[Item]:
    """The feed moves along a contour at height ``z``: G1 lines and G2/G3 arcs (a full circle as two)."""
    items: list[Item] = []
    for s in segs:
        if not s.is_arc:
            items.append(Feed(s.end[0], s.end[1], z, feed))
            continue
        pieces = [s]
        if abs(s.sweep) >= TWO_PI - 1e-12:  # a full circle always goes out as two halves
            pieces = list(s.split(0.5))
        for p in pieces:
            items.append(Arc(p.end[0], p.end[1], p.center[0], p.center[1], p.clockwise, z, feed))
    return items


def _lead_geometry(segs, cw, rho, comp_len):
    P = np.array(segs[0].start)
    t = segs[0].tangent(0.0)
    n = outward_normal(t, cw)
    C = P + rho * n
    q_in = C - rho * t
    q_out = C + rho * t
    lead_cw = float((-n[0]) * t[1] - (-n[1]) * t[0]) < 0
    a = q_in + comp_len * n
    b = q_out + comp_len * n
    return P, C, q_in, q_out, lead_cw, a, b


def contour_toolpath(path_entities, job: Job, *, roughing_contours=None,
                     compensation: str | None = None) -> Program:
    """Build the contour-milling program of a closed contour.

    Roughing passes (outermost first) at every depth level, then the finishing pass (at full depth in one
    level when there are roughing passes and ``job.finish_full_depth``; otherwise in the same
    step-downs).  Every pass: rapid at safe height to the lead-in point outside the part, rapid down to
    the clearance height, plunge at the plunge feed, a tangent lead-in arc (radius ``job.lead_radius``,
    centre outside the part), the contour, a tangent lead-out arc, and a rapid retract to the safe height.

    Parameters
    ----------
    path_entities : sequence
        Closed contour of lines and arcs (an :class:`~camfab.geom2d.ArcChain`, or anything
        :func:`~camfab.gcode.contour.as_contour` accepts) around the part: the **tool-centre** path, or the
        finished **part** profile when ``compensation`` is given.  Its orientation is
        irrelevant: it is traversed as ``job.direction`` requires.
    job : Job
    roughing_contours : sequence of contours, optional
        The roughing paths, outermost first, e.g. from the offset module (one per roughing pass).
        Default: :func:`offset_contour` of the finishing contour by ``allowance + k * stepover``.
    compensation : {None, "G41", "G42"}
        Emit the part contour with cutter radius compensation.  With M3, G41 is climb and G42
        conventional; it must agree with ``job.direction``.  The compensated lead-in is a straight line
        of twice the tool radius followed by the lead-in arc (radius must exceed the tool radius).

    Returns
    -------
    Program

    Raises
    ------
    SpecError
        Options that contradict each other (field named).
    GeometryError
        Open or degenerate contour; with compensation, a concave arc smaller than the tool radius; a
        lead-in point that falls inside the contour.
    """
    if not isinstance(job, Job):
        raise SpecError(Problem("job", type(job).__name__, "must be a camfab.gcode.Job", ""))
    cw = job.direction == "climb"
    r_tool = job.tool_radius_mm
    rho = job.lead_radius
    if compensation not in (None, "G41", "G42"):
        raise SpecError(Problem("compensation", compensation, "must be None, 'G41' or 'G42'",
                                "G41 for climb, G42 for conventional milling"))
    if compensation is not None:
        want = "G41" if cw else "G42"
        if compensation != want:
            raise SpecError(Problem("compensation", compensation,
                                    f"{compensation} with M3 on an outside contour is "
                                    f"{'climb' if compensation == 'G41' else 'conventional'} milling, "
                                    f"but job.direction is {job.direction!r}",
                                    f"use {want} or change job.direction"))
        if rho <= r_tool:
            raise SpecError(Problem("job.lead_radius_mm", rho,
                                    f"must exceed the tool radius ({r_tool} mm) with cutter compensation",
                                    "leave it unset (default: the tool diameter)"))

    oriented = orient_contour(path_entities, cw)
    finish = oriented
    if compensation is not None:
        for i, s in enumerate(finish):
            if s.is_arc and s.clockwise != cw and s.radius < r_tool:
                raise GeometryError(
                    f"part contour entity {i}: concave arc of radius {s.radius:.4f} mm from {s.start} to "
                    f"{s.end} is smaller than the tool radius {r_tool:.4f} mm; the largest tool that fits "
                    f"has diameter {2 * s.radius:.4f} mm")
    finish = _choose_start(finish, cw)

    N = job.roughing_passes
    if roughing_contours is not None:
        rough_in = list(roughing_contours)
        if len(rough_in) != N:
            raise SpecError(Problem("roughing_contours", len(rough_in),
                                    f"must hold job.roughing_passes = {N} contours",
                                    "pass one contour per roughing pass, outermost first"))
        rough = [_choose_start(orient_contour(c, cw), cw) for c in rough_in]
    else:
        rough = [_choose_start(offset_contour(oriented, job.roughing_allowance_mm + (N - 1 - k) * job.stepover),
                               cw) for k in range(N)]

    comp_len = 2.0 * r_tool if compensation else 0.0
    outside = ContourDistance(finish)
    levels = job.levels
    passes = []
    for li, z in enumerate(levels):
        for k, c in enumerate(rough):
            passes.append(("ROUGH", f"ROUGH PASS {k + 1} OF {N} LEVEL {li + 1} OF {len(levels)}", c, z))
    fin_levels = [levels[-1]] if (N > 0 and job.finish_full_depth) else list(levels)
    for li, z in enumerate(fin_levels):
        passes.append(("FINISH", f"FINISH PASS LEVEL {li + 1} OF {len(fin_levels)}", finish, z))

    moves = sum(len(segs) + 8 for _, _, segs, _ in passes)
    if moves > MAX_PROGRAM_MOVES:  # docs/decisions.md, "Input limits"
        raise SpecError(Problem("job", f"{moves} moves", f"the program would exceed {MAX_PROGRAM_MOVES:,} moves "
                                f"({len(levels)} depth levels × {N + 1} passes × {len(finish)} contour entities)",
                                "raise step_down_mm, use fewer roughing_passes, or a coarser tolerance"))
    items: list = [ToolChange(job.tool_number, job.tool_diameter_mm), Rapid(None, None, job.safe_z_mm),
                   Spindle(job.spindle_rpm)]
    if job.coolant != "off":
        items.append(Coolant(job.coolant))
    z_clear = job.clearance_mm
    for kind, label, segs, z in passes:
        P, C, q_in, q_out, lead_cw, a, b = _lead_geometry(segs, cw, rho, comp_len)
        first = a if compensation else q_in
        last = b if compensation else q_out
        pts = np.array([q_in, q_out, first, last])
        if np.any(outside(pts) <= 0.0):
            raise GeometryError(f"{label}: the lead-in/lead-out near {tuple(P)} falls inside the contour; "
                                "reduce job.lead_radius_mm")
        items.append(Comment(label))
        items += [Rapid(first[0], first[1], job.safe_z_mm), Rapid(first[0], first[1], z_clear),
                  Feed(first[0], first[1], z, job.plunge_feed_mm_min)]
        items.append(Comment(f"{kind} LEAD-IN"))
        if compensation:
            items += [CutterComp(compensation, job.tool_number), Feed(q_in[0], q_in[1], z, job.feed_mm_min)]
        items.append(Arc(P[0], P[1], C[0], C[1], lead_cw, z, job.feed_mm_min))
        items.append(Comment(f"{kind} CONTOUR"))
        items += _contour_items(segs, z, job.feed_mm_min)
        items.append(Comment(f"{kind} LEAD-OUT"))
        items.append(Arc(q_out[0], q_out[1], C[0], C[1], lead_cw, z, job.feed_mm_min))
        if compensation:
            items += [CutterComp("G40"), Feed(b[0], b[1], z, job.feed_mm_min)]
        items.append(Rapid(last[0], last[1], job.safe_z_mm))
    if job.coolant != "off":
        items.append(Coolant("off"))
    items.append(Spindle(0.0))
    return Program(job=job, items=tuple(items), compensation=compensation, contour=finish,
                   roughing=tuple(rough))
