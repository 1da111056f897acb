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
* Entry: every pass plunges (at the plunge feed) **outside the stock**, its tool clear of the blank by
  :data:`ENTRY_CLEARANCE_MM`, and feeds in horizontally at its depth along the outward normal at the
  lead-in, in line with the lead-in of every other pass and level (the roughing contours start next to
  the finishing contour's start), so no pass plunges into material and the finishing pass at full depth
  runs in along the slot the roughing levels cut.  The stock is a round blank centred on the cam axis
  (``Job.stock_shape = "round"``) or a rectangular plate, stated in the header.
* With ``Job.mill_bore`` the bore (centred on the axis) is milled first: a helix of radius
  ``(bore - D) / 2`` descending at most ``helix_pitch_mm`` per turn and ``ramp_angle_deg`` steep, at the
  plunge feed, then a finishing circle at full depth at the cutting feed; labelled ``BORE ...``.
* Structural comments label every pass: ``ROUGH PASS k OF N LEVEL i OF m``, ``FINISH PASS LEVEL i OF m``,
  then ``<KIND> LEAD-IN``, ``<KIND> CONTOUR``, ``<KIND> LEAD-OUT`` with ``KIND`` = ``ROUGH``/``FINISH``.
  :func:`camfab.gcode.verify.verify` uses the ``FINISH CONTOUR`` label to measure the deviation.
"""
from __future__ import annotations

import math

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

__all__ = ["ENTRY_CLEARANCE_MM", "contour_toolpath", "stock_outline", "contour_items", "start_near"]

#: the plunge point of every pass keeps the tool this far outside the stock (mm)
ENTRY_CLEARANCE_MM = 1.0


def _points(segs) -> np.ndarray:
    """Dense points along a contour (arcs every 0.5 degree at most)."""
    return np.concatenate([s.polyline(max(2, int(math.ceil(abs(s.sweep) / TWO_PI * 720)))) if s.is_arc
                           else np.array([s.start, s.end]) for s in segs])


def stock_outline(segs, job: Job, part_offset: float) -> tuple[dict, list[str]]:
    """The blank around the part: ``{"shape": "round", "radius": R}`` centred on the axis, or ``{"shape":
    "plate", "box": (xmin, ymin, xmax, ymax)}``, and its header lines.

    ``segs`` is the contour the program follows, ``part_offset`` its distance from the part (the tool radius
    for a tool-centre path, 0 for a compensated part contour).  A derived blank is the part plus
    ``job.stock_allowance_mm`` all round, rounded up to whole mm.

    Raises
    ------
    SpecError
        A given ``stock_diameter_mm`` smaller than the part.
    """
    pts = _points(segs)
    t = job.depth_mm - job.breakthrough_mm
    a = job.stock_allowance_mm
    if job.stock_shape == "round":
        r_part = float(np.max(np.hypot(pts[:, 0], pts[:, 1]))) - part_offset
        if job.stock_diameter_mm is not None:
            D = float(job.stock_diameter_mm)
            if 2 * r_part > D:
                raise SpecError(Problem("machining.stock_diameter_mm", D, f"is smaller than the part "
                                        f"(largest diameter {2 * r_part:.3f} mm)",
                                        f"give at least {math.ceil(2 * r_part):g} mm, or leave it out"))
            how = "stock: diameter given in the design"
        else:
            D = float(math.ceil(2 * (r_part + a) - 1e-9))
            how = f"stock: part D{2 * r_part:.3f} + 2 x {a:g} mm, rounded up"
        return {"shape": "round", "radius": 0.5 * D}, [f"stock: round blank D{D:g} x {t:g} mm on the axis X0 Y0", how]
    lo = pts.min(axis=0) + part_offset
    hi = pts.max(axis=0) - part_offset
    c = 0.5 * (lo + hi)
    size = np.ceil(hi - lo + 2 * a - 1e-9)
    box = (float(c[0] - size[0] / 2), float(c[1] - size[1] / 2), float(c[0] + size[0] / 2), float(c[1] + size[1] / 2))
    return {"shape": "plate", "box": box}, [f"stock: plate blank {size[0]:g} x {size[1]:g} x {t:g} mm, part + {a:g} mm",
                                            f"stock: X{box[0]:.3f} to X{box[2]:.3f}, Y{box[1]:.3f} to Y{box[3]:.3f}"]


def _exit_distance(stock: dict, q: np.ndarray, n: np.ndarray, margin: float) -> float:
    """How far from ``q`` along the unit vector ``n`` the point lies ``margin`` outside the stock (0 if ``q``
    already does)."""
    if stock["shape"] == "round":
        R = stock["radius"] + margin
        b = float(q @ n)
        c = float(q @ q) - R * R
        disc = b * b - c
        return max(0.0, -b + math.sqrt(disc)) if disc > 0 else 0.0
    x0, y0, x1, y1 = stock["box"]
    lo, hi = np.array([x0 - margin, y0 - margin]), np.array([x1 + margin, y1 + margin])
    if np.any(q < lo) or np.any(q > hi):
        return 0.0
    s = [((hi[k] if n[k] > 0 else lo[k]) - q[k]) / n[k] for k in range(2) if abs(n[k]) > 1e-12]
    return max(0.0, min(s))


def _start_near(segs: tuple[Segment, ...], target: np.ndarray) -> tuple[Segment, ...]:
    """Rotate the closed contour to start at its point nearest ``target`` (splitting the entity there)."""
    best = (math.inf, 0, 0.0)
    for i, s in enumerate(segs):
        if s.is_arc:
            c = np.array(s.center)
            a0 = math.atan2(s.start[1] - c[1], s.start[0] - c[0])
            a = math.atan2(target[1] - c[1], target[0] - c[0])
            rel = (a - a0) % TWO_PI if s.sweep > 0 else (a0 - a) % TWO_PI
            u = rel / abs(s.sweep) if rel <= abs(s.sweep) else (0.0 if TWO_PI - rel < rel - abs(s.sweep) else 1.0)
        else:
            p0, p1 = np.array(s.start), np.array(s.end)
            d = p1 - p0
            u = float(np.clip((target - p0) @ d / max(float(d @ d), 1e-300), 0.0, 1.0))
        u = min(max(u, 0.0), 1.0)
        dist = float(np.hypot(*(s.point(u) - target)))
        if dist < best[0]:
            best = (dist, i, u)
    _, i, u = best
    L = segs[i].length
    if u * L < 1e-6:
        return segs[i:] + segs[:i]
    if (1 - u) * L < 1e-6:
        return segs[i + 1:] + segs[:i + 1]
    head, tail = segs[i].split(u)
    return (tail,) + segs[i + 1:] + segs[:i] + (head,)


def _bore_items(job: Job) -> tuple[list[Item], list[str]]:
    """The bore by helical interpolation from the stock top to full depth, and a finishing circle there."""
    R = 0.5 * (job.bore_mm - job.tool_diameter_mm)
    ccw = job.direction == "climb"  # climb milling inside a hole runs counter-clockwise with M3
    depth = job.depth_mm
    pitch = min(job.helix_pitch_mm, TWO_PI * R * math.tan(math.radians(job.ramp_angle_deg)))
    turns = max(1, math.ceil(depth / pitch - 1e-9))
    p = depth / turns
    items: list[Item] = [Comment(f"BORE HELIX D{job.bore_mm:g} RADIUS {R:.4f} PITCH {p:.4f} TURNS {turns}"),
                         Rapid(R, 0.0, job.safe_z_mm), Rapid(R, 0.0, job.clearance_mm),
                         Feed(R, 0.0, 0.0, job.plunge_feed_mm_min)]
    for k in range(2 * turns):
        x = -R if k % 2 == 0 else R
        items.append(Arc(x, 0.0, 0.0, 0.0, not ccw, -p * (k + 1) / 2, job.plunge_feed_mm_min))
    items.append(Comment("BORE FINISH CIRCLE"))
    items += [Arc(-R, 0.0, 0.0, 0.0, not ccw, -depth, job.feed_mm_min),
              Arc(R, 0.0, 0.0, 0.0, not ccw, -depth, job.feed_mm_min)]
    items.append(Comment("BORE RETRACT"))
    items += [Feed(R, 0.0, job.clearance_mm, job.plunge_feed_mm_min), Rapid(R, 0.0, job.safe_z_mm)]
    angle = math.degrees(math.atan2(p, TWO_PI * R))
    notes = [f"bore: D{job.bore_mm:g} first, {'ccw' if ccw else 'cw'} helix radius {R:.4f} mm",
             f"bore: pitch {p:.4f} mm, {angle:.2f} deg, {turns} turns, finish circle"]
    core = job.bore_mm - 2 * job.tool_diameter_mm
    if core > 0:
        notes.append(f"bore: leaves a free core D{core:.3f} mm, falls at breakthrough")
    return items, notes


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
        rough = [orient_contour(c, cw) for c in rough_in]
    else:
        rough = [offset_contour(oriented, job.roughing_allowance_mm + (N - 1 - k) * job.stepover) for k in range(N)]
    # every roughing pass starts next to the finishing start, so all passes enter along one line
    rough = [_start_near(c, np.array(finish[0].start)) for c in rough]

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

    bore_items, bore_notes = _bore_items(job) if job.mill_bore else ([], [])
    moves = sum(len(segs) + 9 for _, _, segs, _ in passes) + len(bore_items)
    if moves > MAX_PROGRAM_MOVES:  # docs/decisions.md, "Input limits"
        raise SpecError(Problem("job", f"{moves} moves", f"the program would exceed {MAX_PROGRAM_MOVES:,} moves "
                                f"({len(levels)} depth levels × {N + 1} passes × {len(finish)} contour entities)",
                                "raise step_down_mm, use fewer roughing_passes, or a coarser tolerance"))
    items: list = [ToolChange(job.tool_number, job.tool_diameter_mm), Rapid(None, None, job.safe_z_mm),
                   Spindle(job.spindle_rpm)]
    if job.coolant != "off":
        items.append(Coolant(job.coolant))
    part_offset = 0.0 if compensation else r_tool
    stock, stock_lines = stock_outline(finish, job, part_offset)
    notes = [*job.notes, *stock_lines,
             f"depth: plate {job.depth_mm - job.breakthrough_mm:g} + breakthrough {job.breakthrough_mm:g} = "
             f"{job.depth_mm:g} mm",
             "entry: plunge outside the stock, feed in horizontally"]
    items += bore_items
    notes += bore_notes
    z_clear = job.clearance_mm
    entries = _entries(passes, outside, stock, cw, rho, comp_len, r_tool, compensation)
    for kind, label, segs, z in passes:
        P, C, q_in, q_out, lead_cw, a, b, first, last, E = entries[id(segs)]
        items.append(Comment(label))
        items += [Rapid(E[0], E[1], job.safe_z_mm), Rapid(E[0], E[1], z_clear),
                  Feed(E[0], E[1], z, job.plunge_feed_mm_min)]
        items.append(Comment(f"{kind} LEAD-IN"))
        if float(np.hypot(*(E - first))) > 1e-9:
            items.append(Feed(first[0], first[1], z, job.feed_mm_min))
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
                   roughing=tuple(rough), notes=tuple(notes))


def _entries(passes, outside, stock, cw: bool, rho: float, comp_len: float, r_tool: float, compensation
             ) -> dict[int, tuple]:
    """Every distinct contour's lead geometry and entry point (by ``id``; a contour repeated at each depth level
    has the same ones), its lead points and entry line checked outside the part in one call of ``outside`` for
    all contours (each point's distance is its own: the same values as one call per pass).

    Raises
    ------
    GeometryError
        For the first pass whose lead-in/lead-out falls inside the contour, or whose entry along the normal
        would cut into the part.
    """
    geo: dict[int, tuple] = {}
    checks = []
    for _, label, segs, _ in passes:
        if id(segs) in geo:
            continue
        P, C, q_in, q_out, lead_cw, a, b = _lead_geometry(segs, cw, rho, comp_len)
        first = a if compensation else q_in
        last = b if compensation else q_out
        n = outward_normal(segs[0].tangent(0.0), cw)
        E = first + _exit_distance(stock, first, n, r_tool + ENTRY_CLEARANCE_MM) * n
        line = first[None, :] + np.linspace(0.0, 1.0, 65)[:, None] * (E - first)[None, :]
        geo[id(segs)] = (P, C, q_in, q_out, lead_cw, a, b, first, last, E)
        checks.append((label, P, np.array([q_in, q_out, first, last]), line))
    if not checks:
        return geo
    d = outside(np.concatenate([x for _, _, pts, line in checks for x in (pts, line)]))
    at = 0
    for label, P, pts, line in checks:
        d_pts, d_line = d[at:at + len(pts)], d[at + len(pts):at + len(pts) + len(line)]
        at += len(pts) + len(line)
        if np.any(d_pts <= 0.0):
            raise GeometryError(f"{label}: the lead-in/lead-out near {tuple(P)} falls inside the contour; "
                                "reduce job.lead_radius_mm")
        if np.any(d_line <= (r_tool if compensation else 0.0)):
            raise GeometryError(f"{label}: the entry from outside the stock along the normal at {tuple(P)} would cut "
                                "into the part; reduce job.lead_radius_mm")
    return geo


#: the feed moves along a contour at one height, and a closed contour restarted at its point nearest a target
#: (public: the groove slot's passes use them)
contour_items, start_near = _contour_items, _start_near
