"""The common toolpath model and the contour program builder."""
from __future__ import annotations

import math

import numpy as np
import pytest

from camfab.errors import GeometryError, SpecError
from camfab.gcode import (
    Arc,
    Comment,
    Feed,
    Job,
    Rapid,
    Segment,
    ToolChange,
    as_contour,
    contour_toolpath,
    offset_contour,
)
from tests.gcode.parts import (
    CENTRE_CURVE,
    HALF,
    PART,
    R_TOOL,
    RP,
    SAFE_Z,
    centre_path,
    circle,
    job,
    stadium,
    stadium_distance,
)


def test_job_collects_every_problem_with_field_paths():
    with pytest.raises(SpecError) as info:
        Job(tool_diameter_mm=-1, depth_mm=0, feed_mm_min=float("nan"), direction="sideways",
            units="furlong", tolerance_mm=1.0, clearance_mm=30.0, safe_z_mm=25.0, roughing_passes=-1,
            tool_number=0, coolant="beer")
    paths = {p.path for p in info.value.problems}
    assert {"job.tool_diameter_mm", "job.depth_mm", "job.feed_mm_min", "job.direction", "job.units",
            "job.tolerance_mm", "job.clearance_mm", "job.roughing_passes", "job.tool_number",
            "job.coolant"} <= paths
    assert all(p.rule for p in info.value.problems)


def test_roughing_needs_an_allowance():
    with pytest.raises(SpecError) as info:
        job(roughing_passes=2, roughing_allowance_mm=0.0)
    assert info.value.problems[0].path == "job.roughing_allowance_mm"


def test_levels_are_equal_and_reach_the_thickness():
    j = job(depth_mm=10.0, step_down_mm=4.0)
    assert j.levels == pytest.approx((-10 / 3, -20 / 3, -10.0))
    assert job(depth_mm=8.0, step_down_mm=4.0).levels == pytest.approx((-4.0, -8.0))


def test_contour_checks():
    with pytest.raises(GeometryError, match="not closed"):
        as_contour([Segment((0, 0), (10, 0)), Segment((10, 0), (10, 10)), Segment((10, 10), (0, 1))])
    with pytest.raises(GeometryError, match="off its circle"):
        as_contour([Segment((10, 0), (0, 10.1), (0, 0), False), Segment((0, 10.1), (10, 0))])
    segs = as_contour([((0, 0), (10, 0)), {"start": (10, 0), "end": (0, 0), "centre": (5, 0),
                                            "clockwise": False}])
    assert segs[1].is_arc and segs[1].sweep == pytest.approx(math.pi)


def test_orientation_does_not_matter():
    a = contour_toolpath(stadium(HALF, RP + R_TOOL, ccw=True), job())
    b = contour_toolpath(stadium(HALF, RP + R_TOOL, ccw=False), job())
    assert a.items == b.items


def test_offset_contour_of_stadium_is_exact():
    off = offset_contour(centre_path(), 0.5)
    exact = stadium_distance(HALF, RP + R_TOOL + 0.5)
    pts = np.concatenate([s.polyline(50) for s in off])
    assert np.abs(exact(pts)).max() < 1e-9


def test_offset_contour_rounds_convex_corners():
    square = [Segment((0, 0), (10, 0)), Segment((10, 0), (10, 10)), Segment((10, 10), (0, 10)),
              Segment((0, 10), (0, 0))]
    off = offset_contour(square, 1.0)
    assert len(off) == 8 and sum(s.is_arc for s in off) == 4
    assert sum(s.length for s in off) == pytest.approx(40 + 2 * math.pi)


def test_offset_contour_refuses_a_vanishing_concave_arc():
    from tests.gcode.parts import notched_disc
    with pytest.raises(GeometryError, match="concave arc of radius 4"):
        offset_contour(notched_disc(30, 4), 5.0)  # outward by 5 closes the notch


def _moves(prog):
    return [it for it in prog.items if isinstance(it, (Rapid, Feed, Arc))]


def test_program_structure_climb():
    prog = contour_toolpath(centre_path(), job())
    items = prog.items
    assert isinstance(items[0], ToolChange)
    labels = [it.text for it in items if isinstance(it, Comment)]
    assert labels.count("FINISH CONTOUR") == 1 and labels.count("ROUGH CONTOUR") == 3
    # climb with M3 = clockwise round the part: every contour arc runs clockwise
    assert all(s.clockwise for s in prog.contour if s.is_arc)
    # every rapid that moves in XY is at the safe height
    prev = None
    for it in _moves(prog):
        if isinstance(it, Rapid) and prev is not None and it.x is not None and (it.x, it.y) != prev[:2]:
            assert it.z == SAFE_Z
        prev = (it.x, it.y, it.z)


def test_conventional_runs_counter_clockwise():
    prog = contour_toolpath(centre_path(), job(direction="conventional"))
    assert not any(s.clockwise for s in prog.contour if s.is_arc)


def test_roughing_leaves_the_allowance():
    prog = contour_toolpath(centre_path(), job(roughing_passes=2, roughing_allowance_mm=0.3,
                                               roughing_stepover_mm=2.0))
    assert len(prog.roughing) == 2
    outer = np.concatenate([s.polyline(20) for s in prog.roughing[0]])
    inner = np.concatenate([s.polyline(20) for s in prog.roughing[1]])
    assert CENTRE_CURVE(inner) == pytest.approx(0.3, abs=1e-9)
    assert CENTRE_CURVE(outer) == pytest.approx(2.3, abs=1e-9)
    assert PART(inner).min() >= R_TOOL + 0.3 - 1e-9


def test_explicit_roughing_contours():
    given = [stadium(HALF, RP + R_TOOL + 0.25)]
    prog = contour_toolpath(centre_path(), job(), roughing_contours=given)
    pts = np.concatenate([s.polyline(20) for s in prog.roughing[0]])
    assert CENTRE_CURVE(pts) == pytest.approx(0.25, abs=1e-9)
    with pytest.raises(SpecError) as info:
        contour_toolpath(centre_path(), job(), roughing_contours=given * 2)
    assert info.value.problems[0].path == "roughing_contours"


def test_finish_in_step_downs_without_roughing():
    prog = contour_toolpath(centre_path(), job(roughing_passes=0))
    labels = [it.text for it in prog.items if isinstance(it, Comment)]
    assert labels.count("FINISH CONTOUR") == 3 and "ROUGH CONTOUR" not in labels


def test_full_circle_is_split_in_two():
    prog = contour_toolpath(circle(20.0), job(roughing_passes=0))
    i = [k for k, it in enumerate(prog.items) if it == Comment("FINISH CONTOUR")][0]
    arcs = []
    for it in prog.items[i + 1:]:
        if isinstance(it, Comment):
            break
        arcs.append(it)
    assert len(arcs) == 2 and all(isinstance(a, Arc) for a in arcs)


def test_lead_arcs_are_tangent_and_outside():
    prog = contour_toolpath(centre_path(), job(roughing_passes=0, depth_mm=3.0, step_down_mm=3.0))
    moves = _moves(prog)
    arcs = [m for m in moves if isinstance(m, Arc)]
    lead_in, lead_out = arcs[0], arcs[-1]
    # lead arcs' centres lie outside the tool-centre path by the lead radius
    c = np.array([[lead_in.cx, lead_in.cy], [lead_out.cx, lead_out.cy]])
    assert CENTRE_CURVE(c) == pytest.approx(job().lead_radius)


def test_compensation_must_match_direction():
    with pytest.raises(SpecError) as info:
        contour_toolpath(stadium(HALF, RP), job(), compensation="G42")
    assert info.value.problems[0].path == "compensation"
    with pytest.raises(SpecError):
        contour_toolpath(stadium(HALF, RP), job(), compensation="G43")


def test_compensation_refuses_a_tool_bigger_than_a_concave_arc():
    from tests.gcode.parts import notched_disc
    with pytest.raises(GeometryError, match="largest tool that fits has diameter 8.0000"):
        contour_toolpath(notched_disc(30, 4), job(tool_diameter_mm=10.0, roughing_passes=0),
                         compensation="G41")


def test_items_are_plain_floats():
    prog = contour_toolpath(centre_path(), job())
    for it in _moves(prog):
        for v in vars(it).values():
            assert v is None or type(v) in (float, bool)
