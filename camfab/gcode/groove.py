"""Milling the slot of a groove (face-groove) cam, and verifying such a program.

The program (tool-centre coordinates, Z = 0 the plate's front face, the groove ``groove_depth_mm`` deep)::

    GROOVE CENTRE PASS   at every depth level: plunge at the plunge feed on the pitch curve's start (a
                         centre-cutting end mill, the only way into a closed slot besides a ramp) and run the
                         pitch curve: a slot of the tool's width, w − r_c left on each flank
    FINISH PASS INNER FLANK / OUTER FLANK
                         at full depth: from the pitch curve's start straight along its normal to the flank's
                         tool-centre path (the exact offset by r_c into the groove), once round it, back

The three paths start on one normal line of the pitch curve (both flank paths are its offsets by ∓(w − r_c)), so
every lead-in and lead-out runs inside the slot already cut.  Climb milling with M3 (``[machining] direction``)
runs clockwise round the inner flank (its material inside the path) and counter-clockwise along the outer flank
(its material outside); conventional the other way round.

:func:`verify_groove_program` is ``camfab verify`` for a groove design: the finished part is the plate minus the
groove, so the signed part distance is ``min(d_inner, −d_outer)`` (positive in the groove), both flank
tool-centre curves are the finishing targets (their samples the coverage probes), and the milling direction is
judged per flank pass.
"""
from __future__ import annotations

import dataclasses

import numpy as np

from ..discretize import arcs_within_radius, points_at, polyline
from ..geom2d import ArcChain
from ..offset.cutter import offset_curve, profile_curve
from ..offset.groove import groove_tool_paths
from ..results import Finding, IssueCode
from ..tolerances import arc_radius_limit
from .cam import CamProgram, contour_fit_tolerance, contour_tolerance
from .contour import orient_contour
from .distance import CurveDistance
from .model import Comment, Coolant, Feed, Job, Program, Rapid, Spindle, ToolChange
from .parse import parse
from .toolpath import contour_items, start_near
from .verify import VerifyReport, verify_program

__all__ = ["groove_program", "groove_gcode", "verify_groove_program"]

#: the label of both finishing contours (what verify measures); the comment before names the flank
_FINISH = "FINISH CONTOUR"
#: exact points per flank tool-centre curve the coverage check probes
_PROBES = 4096


def groove_program(inner, outer, job: Job, *, tol: float, arcs_allowed: bool = True, post=None) -> CamProgram:
    """The slot-milling program of a groove cam's flanks ``inner`` and ``outer`` (module notes); ``job`` cuts to
    the groove's depth (no breakthrough)."""
    from .post import get_post

    cap = get_post(post or "linuxcnc").max_arc_radius_mm
    r = job.tool_radius_mm
    share = contour_tolerance(tol, post, job.units)
    tol_fit = contour_fit_tolerance(tol, post, job.units)
    paths = groove_tool_paths(inner, outer, r, tol=tol_fit)
    size = float(np.hypot(*np.asarray(paths.outer.arcs.starts, dtype=float).T).max())
    max_r = arc_radius_limit(size, cap)

    def fit(curve, chain) -> ArcChain:
        if arcs_allowed:
            return arcs_within_radius(chain, curve, tol=share, max_radius_mm=max_r)
        line = polyline(curve, tol=tol_fit)
        return line.arc_chain().with_deviation(line.max_deviation)

    climb = job.direction == "climb"
    centre = orient_contour(fit(paths.centre, paths.centre_arcs), climb)
    fin_in_chain, fin_out_chain = fit(paths.inner.curve, paths.inner.arcs), fit(paths.outer.curve, paths.outer.arcs)
    s = np.asarray(centre[0].start, dtype=float)
    # each flank pass starts at its point nearest the centre pass's start: the foot of the pitch normal there
    fin_in = start_near(orient_contour(fin_in_chain, climb), s)
    fin_out = start_near(orient_contour(fin_out_chain, not climb), s)
    dev = max(float(fin_in_chain.max_deviation or 0.0), float(fin_out_chain.max_deviation or 0.0))
    job = dataclasses.replace(job, achieved_deviation_mm=dev)
    items: list = [ToolChange(job.tool_number, job.tool_diameter_mm), Rapid(None, None, job.safe_z_mm),
                   Spindle(job.spindle_rpm)]
    if job.coolant != "off":
        items.append(Coolant(job.coolant))
    items += [Comment("GROOVE CENTRE PASS"), Rapid(s[0], s[1], job.safe_z_mm), Rapid(s[0], s[1], job.clearance_mm)]
    levels = job.levels
    for i, z in enumerate(levels):
        items += [Comment(f"ROUGH PASS 1 OF 1 LEVEL {i + 1} OF {len(levels)}"), Feed(s[0], s[1], z,
                                                                                    job.plunge_feed_mm_min),
                  Comment("ROUGH CONTOUR")]
        items += contour_items(centre, z, job.feed_mm_min)
    z = levels[-1]
    for name, segs in (("INNER", fin_in), ("OUTER", fin_out)):
        q = np.asarray(segs[0].start, dtype=float)
        items += [Comment(f"FINISH PASS {name} FLANK"), Comment("FINISH LEAD-IN"), Feed(q[0], q[1], z, job.feed_mm_min),
                  Comment(_FINISH)]
        items += contour_items(segs, z, job.feed_mm_min)
        items += [Comment("FINISH LEAD-OUT"), Feed(s[0], s[1], z, job.feed_mm_min)]
    items.append(Rapid(s[0], s[1], job.safe_z_mm))
    if job.coolant != "off":
        items.append(Coolant("off"))
    items.append(Spindle(0.0))
    notes = (*job.notes, f"groove: {job.depth_mm:g} mm deep, cut from the front face Z0",
             "entry: plunge on the pitch curve (centre-cutting end mill), then a centre pass and a finishing pass "
             "per flank")
    prog = Program(job=job, items=tuple(items), contour=fin_in, roughing=(centre,), notes=notes,
                   milled="groove slot (a centre pass, then a finishing pass per flank)")
    shapely_dev = max(paths.inner.shapely_deviation, paths.outer.shapely_deviation)
    return CamProgram(prog, dev, shapely_dev, len(centre) + len(fin_in) + len(fin_out))


def verify_groove_program(program: str | bytes, inner, outer, job: Job, *, tol: float, post: str | None = None,
                          default_post: str | None = None, comp_radius: float | None = None) -> VerifyReport:
    """``camfab verify`` of a groove cam's program (module notes)."""
    r = job.tool_radius_mm
    near = r + tol + 0.05
    d_in = CurveDistance(profile_curve(inner), exact_within=near)
    d_out = CurveDistance(profile_curve(outer), exact_within=near)

    def part(p: np.ndarray) -> np.ndarray:
        return np.minimum(np.asarray(d_in(p), dtype=float), -np.asarray(d_out(p), dtype=float))

    probes = np.concatenate([points_at(offset_curve(c, r), np.linspace(0.0, c.period, _PROBES, endpoint=False))
                             for c in (inner, outer)])
    rep = verify_program(program, post=post, default_post=default_post, exact_curve_distance=None,
                         part_distance=part, curve_points=probes, tool_radius=r, tol=tol, safe_z=job.safe_z_mm,
                         top_z=0.0, comp_radius=comp_radius, job=job)
    if any(p.code is IssueCode.PARSE_ERROR for p in rep.problems):
        return rep
    kept = tuple(p for p in rep.problems if p.code is not IssueCode.DIRECTION)
    return dataclasses.replace(rep, problems=kept + tuple(_directions(program, job)),
                               notes=rep.notes + ("groove: the part is the plate minus the groove; both flanks are "
                                                  "finishing targets; the direction is judged per flank",))


def _directions(program: str | bytes, job: Job) -> list[Finding]:
    """DIRECTION per flank pass: climb (M3) runs clockwise round the inner flank, counter-clockwise along the
    outer; conventional the reverse.  The finishing runs (consecutive moves labelled FINISH CONTOUR) are told
    apart by the area they enclose: the inner flank's is the smaller."""
    text = program.decode("utf-8") if isinstance(program, bytes) else program
    runs: list[list] = []
    last = None
    for m in parse(text).moves:
        label = (m.label or "").upper()
        if label == _FINISH and m.kind != "rapid":
            if last != _FINISH:
                runs.append([])
            runs[-1].append(m)
        last = label
    areas = []
    for run in runs:
        pts = np.array([m.end[:2] for m in run], dtype=float)
        x, y = pts[:, 0] - pts[:, 0].mean(), pts[:, 1] - pts[:, 1].mean()
        areas.append(0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y)))
    out = []
    smallest = int(np.argmin(np.abs(areas))) if areas else -1
    for k, (run, area) in enumerate(zip(runs, areas, strict=True)):
        inner = k == smallest
        want_cw = (job.direction == "climb") == inner
        if area != 0.0 and (area < 0) != want_cw:
            out.append(Finding.at_line(IssueCode.DIRECTION, f"the {'inner' if inner else 'outer'} flank's finishing "
                                       f"pass runs {'counter-' if want_cw else ''}clockwise: not {job.direction} "
                                       "milling with M3", run[0].line))
    return out


def groove_gcode(geometry, job: Job, tol: float, machining, post) -> tuple[bytes, str, int, float]:
    """The groove's program as the pipeline's G-code artifact needs it: (bytes, kind, entities, deviation mm).
    Cutter radius compensation is refused (the slot's passes are tool-centre paths)."""
    from ..errors import Problem, SpecError
    from .post import dumps

    if machining.compensation:
        raise SpecError(Problem("machining.compensation", machining.compensation, "a groove's slot is milled on "
                                "tool-centre paths (the centre pass has no part contour to compensate)",
                                "remove compensation from [machining] for a groove cam"))
    cp = groove_program(geometry.profiles[0], geometry.profiles[1], job, tol=tol,
                        arcs_allowed=not machining.lines_only, post=post)
    return dumps(cp.program, post).encode(), "gcode", cp.entities, cp.deviation_mm
