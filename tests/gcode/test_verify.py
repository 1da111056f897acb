"""The verifier catches deliberately broken programs (and passes the good ones)."""
from __future__ import annotations

import re

import numpy as np
import pytest

from camfab.gcode import ContourDistance, Segment, contour_toolpath, dumps, parse, verify
from tests.gcode.parts import (
    CENTRE_CURVE,
    HALF,
    PART,
    R_TOOL,
    RP,
    SAFE_Z,
    TOL,
    centre_path,
    job,
    notched_disc,
    notched_disc_distance,
    stadium_points,
)

POSTS = [("linuxcnc", {}), ("fanuc", {}), ("grbl", {})]


def _text(post="linuxcnc", opts=None, **over):
    return dumps(contour_toolpath(centre_path(), job(**over)), post, **(opts or {}))


def _verify(text, **kw):
    args = dict(exact_curve_distance=CENTRE_CURVE, part_distance=PART, tool_radius=R_TOOL, tol=TOL,
                safe_z=SAFE_Z)
    args.update(kw)
    return verify(parse(text), **args)


def _lines(text):
    return text.splitlines()


def _first_after(lines, label, pattern):
    i = lines.index(f"({label})") if f"({label})" in lines else lines.index(f"({label.upper()})")
    for k in range(i + 1, len(lines)):
        if re.search(pattern, lines[k]):
            return k
    raise AssertionError(f"no {pattern} after {label}")


@pytest.mark.parametrize("post,opts", POSTS)
def test_good_program_passes(post, opts):
    rep = _verify(_text(post, opts))
    assert rep.ok and rep.max_deviation_mm <= TOL and rep.finish_moves >= 5


@pytest.mark.parametrize("post,opts", POSTS)
def test_arc_centre_moved_by_10_um_is_caught(post, opts):
    lines = _lines(_text(post, opts))
    k = _first_after(lines, "FINISH CONTOUR", r"\bG0?2\b.* I")
    lines[k] = re.sub(r"I(-?[\d.]+)", lambda m: f"I{float(m.group(1)) + 0.01:.4f}", lines[k])
    rep = _verify("\n".join(lines) + "\n")
    if post == "fanuc":
        # Fanuc's arcs come in pieces of at most 30 degrees, whose written ends pin the path: the moved centre
        # shows as two radii 10 um apart at that line (the path itself moves by ~0.3 um only)
        assert any(p.line == k + 1 for p in rep.problems if p.code == "ARC_RADIUS_MISMATCH")
        return
    assert not rep.ok and "DEVIATION" in rep.codes()
    assert 0.005 < rep.max_deviation_mm < 0.02
    assert any(p.line == k + 1 for p in rep.problems if p.code == "DEVIATION")


def test_arc_centre_moved_in_r_mode_is_caught():
    lines = _lines(_text("fanuc", {"arc_format": "r"}))
    k = _first_after(lines, "FINISH CONTOUR", r" R")
    # R + 5 %: on a piece of at most 30 degrees the ends stay and the bulge changes by 5 % of its sagitta
    lines[k] = re.sub(r"R([\d.]+)", lambda m: f"R{float(m.group(1)) * 1.05:.4f}", lines[k])
    rep = _verify("\n".join(lines) + "\n")
    assert "DEVIATION" in rep.codes() and rep.max_deviation_mm > TOL


@pytest.mark.parametrize("post,opts", POSTS)
def test_missing_retract_is_caught(post, opts):
    lines = _lines(_text(post, opts))
    k = _first_after(lines, "ROUGH LEAD-OUT", r"G0 .*Z25\.")
    del lines[k]
    rep = _verify("\n".join(lines) + "\n")
    assert "RAPID_BELOW_SAFE" in rep.codes()
    # the next horizontal rapid (two lines on, after the pass comment) now runs at cutting depth
    assert [p.line for p in rep.problems if p.code == "RAPID_BELOW_SAFE"] == [k + 2]


def test_rapid_through_the_part_at_cutting_depth_is_caught():
    lines = _lines(_text())
    k = _first_after(lines, "ROUGH LEAD-OUT", r"G0 .*Z25\.")
    # no retract: straight across the part at cutting depth and back
    lines[k:k + 1] = ["G0 X0.0000 Y-30.0000", "G0 X6.0000 Y24.2000"]
    rep = _verify("\n".join(lines) + "\n")
    assert {"RAPID_BELOW_SAFE", "RAPID_THROUGH_PART"} <= rep.codes()
    assert [p.line for p in rep.problems if p.code == "RAPID_THROUGH_PART"] == [k + 1, k + 2]


def test_rapid_plunge_into_stock_is_caught():
    text = _text().replace("G0 Z2.0000\nG1 Z-3.3333 F200.0", "G0 Z-3.3333\nG1 Z-3.3333 F200.0", 1)
    rep = _verify(text)
    assert "RAPID_INTO_STOCK" in rep.codes()


@pytest.mark.parametrize("post,opts", POSTS)
def test_missing_feed_before_first_cut_is_caught(post, opts):
    lines = _lines(_text(post, opts))
    k = next(i for i, line in enumerate(lines) if re.search(r"\bG0?1\b", line))
    assert " F" in lines[k]
    lines[k] = re.sub(r" F[\d.]+", "", lines[k])
    rep = _verify("\n".join(lines) + "\n")
    assert "FEED_MISSING" in rep.codes()
    assert [p.line for p in rep.problems if p.code == "FEED_MISSING"] == [k + 1]


def test_cutter_larger_than_smallest_concave_radius_gouges():
    R, r_notch, r_tool = 30.0, 4.0, 6.0
    # a tool-centre path for a 12 mm cutter that dips into the 4 mm notch until it touches its bottom
    a = np.radians(15)
    p1 = (-(R + r_tool) * np.sin(a), (R + r_tool) * np.cos(a))
    p2 = (-p1[0], p1[1])
    path = [Segment(p1, p2, (0, 0), False), Segment(p2, (0, R - r_notch + r_tool)),
            Segment((0, R - r_notch + r_tool), p1)]
    prog = contour_toolpath(path, job(tool_diameter_mm=2 * r_tool, roughing_passes=0))
    text = dumps(prog, "linuxcnc")
    rep = verify(parse(text), exact_curve_distance=ContourDistance(path),
                 part_distance=notched_disc_distance(R, r_notch), tool_radius=r_tool, tol=TOL, safe_z=SAFE_Z)
    assert rep.gouge and "GOUGE" in rep.codes() and not rep.ok
    g = rep.gouge_at
    assert g["penetration_mm"] > 1.0 and abs(g["x"]) < 10 and g["y"] > 25
    assert rep.max_deviation_mm <= TOL  # it follows its own path exactly: only the gouge check sees it
    d = rep.to_dict()
    assert d["gouge"] is True and d["gouge_at"] == g and d["ok"] is False


def test_cutter_that_fits_the_notch_does_not_gouge():
    R, r_notch, r_tool = 30.0, 4.0, 3.0
    part = notched_disc(R, r_notch)
    # exact tool-centre path for a 6 mm cutter: offset outward by 3 (the notch arc shrinks to radius 1)
    from camfab.gcode import offset_contour
    path = offset_contour(part, r_tool)
    prog = contour_toolpath(path, job(roughing_passes=0))
    rep = verify(parse(dumps(prog, "fanuc")), exact_curve_distance=ContourDistance(path),
                 part_distance=ContourDistance(part), tool_radius=r_tool, tol=TOL, safe_z=SAFE_Z)
    assert rep.ok, rep.to_dict()


def test_skipped_contour_fails_coverage():
    lines = _lines(_text())
    k = _first_after(lines, "FINISH CONTOUR", r"\bG0?2\b")
    # replace the right-hand half circle by a straight chord
    lines[k] = re.sub(r"\bG0?2\b", "G1", re.sub(r" I\S+ J\S+", "", lines[k]))
    rep = _verify("\n".join(lines) + "\n", curve_points=stadium_points(HALF, RP + R_TOOL))
    assert {"DEVIATION", "COVERAGE", "GOUGE"} <= rep.codes()


def test_rapid_before_z_is_known():
    text = "G17 G21 G40 G54 G90 G94\nG0 X10 Y10\nG0 Z25\nM2\n"
    rep = _verify(text)
    assert "RAPID_BELOW_SAFE" in rep.codes() and "NO_CUTTING_MOVES" in rep.codes()


def test_spindle_off_while_cutting():
    text = _text().replace("S4000 M3\n", "")
    assert "SPINDLE_OFF" in _verify(text).codes()


def test_unlabelled_program_falls_back_to_all_final_depth_moves():
    text = re.sub(r"\((FINISH|ROUGH) (CONTOUR|LEAD-IN|LEAD-OUT)\)\n", "", _text(roughing_passes=0))
    rep = _verify(text)
    assert rep.notes and "DEVIATION" in rep.codes()  # the lead arcs now count


def test_report_is_json_ready():
    import json
    rep = _verify(_text())
    d = json.loads(json.dumps(rep.to_dict()))
    assert d["ok"] is True and d["problems"] == [] and d["gouge_at"] is None


def test_bounded_sampling_still_finds_the_worst_deviation():
    """Each move sampled at most 256 (or 32) times, its worst sample resolved 16 times finer: the reported
    deviation is the one a 2 um sampling of the whole finishing pass measures."""
    from camfab import pipeline
    from camfab.gcode.cam import cam_program, signed_distance
    from camfab.gcode.parse import sample
    from camfab.offset import profile_curve

    cam = pipeline.load("ejemplo9rt")
    contact = cam.geometry.profiles[0]
    job = pipeline.gcode_job(cam.spec, tol=0.01, overrides={"step_down_mm": 5.0})
    bp = parse(dumps(cam_program(contact, job, tol=0.01).program, "linuxcnc"))
    part = signed_distance(profile_curve(contact), tol=0.01)
    fin = [m for m in bp.moves if (m.label or "").startswith("FINISH CONTOUR")]
    dense = float(np.abs(part(sample(fin, 0.002).points[:, :2]) - R_TOOL).max())
    for k, rel in ((256, 1e-5), (32, 1e-3)):
        rep = verify(bp, exact_curve_distance=None, part_distance=part, tool_radius=R_TOOL, tol=0.01, safe_z=SAFE_Z,
                     job=job, max_samples_per_move=k)
        assert rep.ok and rep.max_deviation_mm == pytest.approx(dense, rel=rel)


def test_declared_post_reads_every_posts_header():
    from camfab.gcode.verify import declared_post

    for post, opts in POSTS:
        assert declared_post(parse(_text(post, opts)).comments) == post
    assert declared_post(("post: heidenhain",)) is None and declared_post(()) is None


def test_without_a_job_the_job_checks_are_left_out_and_said_so():
    rep = _verify(_text())
    assert rep.ok and any("no job given" in n for n in rep.notes) and any("coverage" in n for n in rep.notes)
