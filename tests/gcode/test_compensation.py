"""Cutter compensation (G41/G42) is simulated like a controller and the tool-centre path is verified.

Physics, not snapshots: simulated paths are compared with exact offsets and closed-form lengths, and
broken programs (wrong side, notch or arc smaller than the tool, short entry) must be caught with the
right program line.
"""
from __future__ import annotations

import itertools
import json
import math
import re

import numpy as np
import pytest

from camfab.gcode import ContourDistance, Segment, contour_toolpath, dumps, offset_contour, parse, sample, verify
from camfab.gcode.compensation import move_lengths, simulate_compensation
from tests.gcode.parts import (
    HALF,
    PART,
    R_TOOL,
    RP,
    SAFE_Z,
    TOL,
    job,
    notched_disc,
    stadium,
    stadium_distance,
    stadium_points,
)

FINISH = "FINISH CONTOUR"


# ---- helpers --------------------------------------------------------------------------------------

def polygon(pts) -> list[Segment]:
    pts = [tuple(map(float, p)) for p in pts]
    return [Segment(a, b) for a, b in zip(pts, pts[1:] + pts[:1], strict=True)]


def square(a=40.0):
    return polygon([(-a / 2, -a / 2), (a / 2, -a / 2), (a / 2, a / 2), (-a / 2, a / 2)])


def pentagon():
    """An irregular convex pentagon (not symmetric, corners of different angles)."""
    return polygon([(0, -20), (25, -12), (28, 10), (5, 24), (-22, 6)])


def l_shape():
    """40 x 40 square minus a 20 x 20 quadrant: five convex corners and one concave (90 deg)."""
    return polygon([(-20, -20), (20, -20), (20, 0), (0, 0), (0, 20), (-20, 20)])


def notched_square(width, depth=8.0, a=40.0):
    """A square with a rectangular notch of ``width`` x ``depth`` in the middle of its top edge."""
    h, w = a / 2, width / 2
    return polygon([(-h, -h), (h, -h), (h, h), (w, h), (w, h - depth), (-w, h - depth), (-w, h), (-h, h)])


def comp_text(part, comp="G41", post="linuxcnc", **over):
    direction = "climb" if comp == "G41" else "conventional"
    kw = dict(roughing_passes=0, depth_mm=4.0, step_down_mm=4.0, direction=direction)
    kw.update(over)
    opts = {"arc_format": "r"} if post == "fanuc-r" else {}
    return dumps(contour_toolpath(part, job(**kw), compensation=comp), post.split("-")[0], **opts)


def check(text, part_segments, centre_segments=None, **kw):
    """verify() against exact contour distances (the tool-centre curve: the part offset by r)."""
    part = ContourDistance(part_segments)
    # without centre segments: the part distance less the tool radius (exact for convex parts)
    centre = (lambda p: part(p) - R_TOOL) if centre_segments is None else ContourDistance(centre_segments)
    args = dict(exact_curve_distance=centre, part_distance=part, tool_radius=R_TOOL, tol=TOL, safe_z=SAFE_Z)
    args.update(kw)
    return verify(parse(text), **args)


def finish_moves(path):
    """Simulated moves of the finishing contour at final depth, and their kinds."""
    moves = [(m, k) for m, k in zip(path.moves, path.kind, strict=True) if (m.label or "").startswith(FINISH)]
    zf = min(min(m.start[2], m.end[2]) for m, _ in moves)
    return [(m, k) for m, k in moves if abs(m.start[2] - zf) < 1e-9 and abs(m.end[2] - zf) < 1e-9]


def programmed_finish_length(text):
    moves = [m for m in parse(text).moves if (m.label or "").startswith(FINISH)]
    return float(move_lengths(moves).sum())


def swap_sides(text):
    return re.sub(r"G4[12]", lambda m: "G42" if m.group(0) == "G41" else "G41", text)


def line_of(text, pattern, after=FINISH):
    lines = text.splitlines()
    start = next(i for i, ln in enumerate(lines) if after in ln.upper())
    return next(i for i in range(start, len(lines)) if re.search(pattern, lines[i])) + 1


# ---- camfab's own compensated programs -------------------------------------------------------------

@pytest.mark.parametrize("post", ["linuxcnc", "fanuc", "fanuc-r"])
@pytest.mark.parametrize("comp", ["G41", "G42"])
def test_stadium_compensated_program_is_the_exact_tool_centre_path(post, comp):
    text = comp_text(stadium(HALF, RP), comp, post, roughing_passes=1, depth_mm=10.0)
    assert f"{comp} D1" in text
    centre = stadium_distance(HALF, RP + R_TOOL)
    rep = verify(parse(text), exact_curve_distance=centre, part_distance=PART, tool_radius=R_TOOL, tol=TOL,
                 safe_z=SAFE_Z, curve_points=stadium_points(HALF, RP + R_TOOL))
    assert rep.ok, rep.to_dict()["problems"]
    assert rep.max_deviation_mm <= TOL and rep.coverage_gap_mm <= TOL
    assert any("compensation simulated" in n for n in rep.notes)
    # the simulated finishing pass *is* the exact tool-centre stadium: 2 * 40 + 2 * pi * 18
    path = simulate_compensation(parse(text).moves, R_TOOL)
    fin = finish_moves(path)
    L = sum(move_lengths([m for m, _ in fin]))
    # (Fanuc writes 0.001 mm increments in 30-degree arc pieces: the length agrees within the tolerance)
    assert pytest.approx(4 * HALF + 2 * math.pi * (RP + R_TOOL), abs=1e-6 if post == "linuxcnc" else TOL) == L
    pts = sample([m for m, _ in fin], 0.02).points[:, :2]
    assert np.abs(centre(pts)).max() < (1e-9 if post == "linuxcnc" else TOL / 10)


@pytest.fixture(scope="module")
def cam_case():
    from camfab.design.assemble import geometry_from_spec
    from camfab.gcode import Job
    from camfab.gcode.cam import cam_program, signed_distance
    from camfab.offset.cutter import offset_curve, profile_curve
    from tests.conftest import DESIGNS

    spec = DESIGNS["ejemplo9rt"]()
    contact = geometry_from_spec(spec).profiles[0]
    part = signed_distance(profile_curve(contact), tol=TOL)
    centre_curve = offset_curve(contact, R_TOOL)
    centre = signed_distance(centre_curve, tol=TOL)
    curve_pts = centre_curve.point(np.linspace(0, 2 * np.pi, 3000, endpoint=False))
    j = Job(tool_diameter_mm=2 * R_TOOL, depth_mm=spec.manufacturing.thickness_mm, tolerance_mm=TOL,
            roughing_passes=0, design_name=spec.name)
    texts = {None: dumps(cam_program(contact, j, tol=TOL).program, "linuxcnc")}
    for comp, direction in (("G41", "climb"), ("G42", "conventional")):
        j = Job(tool_diameter_mm=2 * R_TOOL, depth_mm=spec.manufacturing.thickness_mm, tolerance_mm=TOL,
                roughing_passes=0, direction=direction, design_name=spec.name)
        texts[comp] = dumps(cam_program(contact, j, tol=TOL, compensation=comp).program, "linuxcnc")
    return dict(part=part, centre=centre, curve_pts=curve_pts, texts=texts)


def _cam_verify(case, text, **kw):
    return verify(parse(text), exact_curve_distance=case["centre"], part_distance=case["part"],
                  tool_radius=R_TOOL, tol=TOL, safe_z=SAFE_Z, **kw)


@pytest.mark.parametrize("comp", ["G41", "G42"])
def test_cam_program_with_compensation_verifies_against_the_exact_offset(cam_case, comp):
    text = cam_case["texts"][comp]
    rep = _cam_verify(cam_case, text, curve_points=cam_case["curve_pts"])
    assert rep.ok, rep.to_dict()["problems"]
    assert rep.max_deviation_mm <= TOL and rep.coverage_gap_mm <= TOL and not rep.gouge
    # independently of part_distance: the simulated finishing pass lies on the exact offset curve
    # (offset_curve of the cam, not the part distance minus r)
    fin = finish_moves(simulate_compensation(parse(text).moves, R_TOOL))
    pts = sample([m for m, _ in fin], 0.02).points[:, :2]
    assert np.abs(cam_case["centre"](pts)).max() <= TOL
    # and it is as long as the exact tool-centre curve (closed curve, within the fit tolerance)
    c = np.vstack([cam_case["curve_pts"], cam_case["curve_pts"][:1]])
    L_exact = float(np.hypot(*np.diff(c, axis=0).T).sum())
    assert sum(move_lengths([m for m, _ in fin])) == pytest.approx(L_exact, rel=2e-4)


def test_coverage_is_measured_across_move_junctions(cam_case):
    """The coverage gap of a good program is the deviation, not half a sampling step: a curve point next to
    a junction visited twice (the contour's start and end) or next to a tiny move still finds its segment."""
    for comp in (None, "G41"):
        rep = _cam_verify(cam_case, cam_case["texts"][comp], curve_points=cam_case["curve_pts"])
        assert rep.ok and rep.coverage_gap_mm <= rep.max_deviation_mm + 1e-4, rep.to_dict()


@pytest.mark.parametrize("comp", ["G41", "G42"])
def test_cam_program_compensated_to_the_wrong_side_gouges(cam_case, comp):
    text = cam_case["texts"][comp]
    rep = _cam_verify(cam_case, swap_sides(text))
    assert not rep.ok and rep.gouge and {"GOUGE", "COMP_WRONG_SIDE", "DEVIATION"} <= rep.codes()
    # the tool centre runs r inside the part instead of r outside: it cuts 2 r deep
    assert rep.gouge_at["penetration_mm"] == pytest.approx(2 * R_TOOL, abs=2 * TOL)
    lines = text.splitlines()
    start, end = lines.index(f"({FINISH})"), lines.index("(FINISH LEAD-OUT)")
    assert start < rep.gouge_at["line"] <= end
    gouge = next(p for p in rep.problems if p.code == "GOUGE")
    assert str(start + 2) in gouge.message  # the first contour move is named
    wrong = next(p for p in rep.problems if p.code == "COMP_WRONG_SIDE")
    entry = next(i for i, ln in enumerate(lines) if re.search(r"G4[12] D", ln)) + 1
    assert wrong.line == entry and ("G42" if comp == "G41" else "G41") in wrong.message


@pytest.mark.parametrize("delta", [0.01, -0.01])
def test_wrong_radius_in_the_d_register_shows_as_deviation_or_gouge(delta):
    text = comp_text(stadium(HALF, RP))
    centre = stadium_distance(HALF, RP + R_TOOL)
    rep = verify(parse(text), exact_curve_distance=centre, part_distance=PART, tool_radius=R_TOOL, tol=TOL,
                 safe_z=SAFE_Z, comp_radius=R_TOOL + delta)
    assert "DEVIATION" in rep.codes() and rep.max_deviation_mm == pytest.approx(abs(delta), abs=1e-6)
    # a register 10 um too small leaves the tool 10 um inside: a gouge; too large leaves stock
    assert rep.gouge is (delta < 0)
    if delta < 0:
        assert rep.gouge_at["penetration_mm"] == pytest.approx(-delta, abs=1e-6)
        assert "COMP_WRONG_SIDE" not in rep.codes()


# ---- corners: rolling arcs and trimmed concave corners ---------------------------------------------

@pytest.mark.parametrize("shape", [square, pentagon])
@pytest.mark.parametrize("comp", ["G41", "G42"])
def test_convex_polygon_gets_rolling_arcs_perimeter_plus_2_pi_r(shape, comp):
    part = shape()
    text = comp_text(part, comp)
    path = simulate_compensation(parse(text).moves, R_TOOL)
    fin = finish_moves(path)
    corners = [m for m, k in fin if k == "corner"]
    # one rolling arc per vertex; the start is mid-edge, where the rounded split point may leave a kink
    # of a few microradians (rolled, or trimmed when it turns the other way)
    assert len([m for m in corners if abs(m.sweep) > 1e-3]) == len(part)
    assert all(abs(m.sweep) < 1e-4 for m in corners if abs(m.sweep) <= 1e-3)
    for m in corners:
        assert m.kind == "arc" and m.radius_start == pytest.approx(R_TOOL) == m.radius_end
        assert m.clockwise is (comp == "G41")
    perimeter = programmed_finish_length(text)
    L = float(move_lengths([m for m, _ in fin]).sum())
    # exact for the square; the pentagon's written (rounded) vertices leave kinks of ~3 microradians at
    # the lead-in/out junctions, which belong to the leads: r * 3e-6 ~ 1e-5 mm
    assert pytest.approx(perimeter + 2 * math.pi * R_TOOL, abs=1e-9 if shape is square else 1e-4) == L
    assert sum(abs(m.sweep) for m in corners) == pytest.approx(2 * math.pi, abs=1e-4)
    rep = check(text, part, offset_contour(part, R_TOOL))
    assert rep.ok, rep.to_dict()["problems"]
    assert rep.max_deviation_mm <= 1e-6


def test_rounded_rectangle_with_fillets_smaller_than_the_tool_is_fine_on_the_outside():
    # convex fillets of 1 mm with a 3 mm tool: the offset arcs grow to 4 mm
    a, b, f = 20.0, 12.0, 1.0
    segs = [Segment((-a + f, -b), (a - f, -b)), Segment((a - f, -b), (a, -b + f), (a - f, -b + f), False),
            Segment((a, -b + f), (a, b - f)), Segment((a, b - f), (a - f, b), (a - f, b - f), False),
            Segment((a - f, b), (-a + f, b)), Segment((-a + f, b), (-a, b - f), (-a + f, b - f), False),
            Segment((-a, b - f), (-a, -b + f)), Segment((-a, -b + f), (-a + f, -b), (-a + f, -b + f), False)]
    text = comp_text(segs, "G41")
    path = simulate_compensation(parse(text).moves, R_TOOL)
    fin = finish_moves(path)
    assert not [k for _, k in fin if k == "corner"]  # tangent joins: nothing inserted
    L = float(move_lengths([m for m, _ in fin]).sum())
    assert pytest.approx(programmed_finish_length(text) + 2 * math.pi * R_TOOL, abs=1e-6) == L
    assert check(text, segs, offset_contour(segs, R_TOOL)).ok


@pytest.mark.parametrize("comp", ["G41", "G42"])
def test_concave_corner_is_trimmed_to_the_exact_offset(comp):
    part = l_shape()
    text = comp_text(part, comp)
    path = simulate_compensation(parse(text).moves, R_TOOL)
    fin = finish_moves(path)
    assert sum(k == "corner" for _, k in fin) == 5 and path.corners["trimmed"] >= 1
    # closed form: perimeter + r * (5 convex quarter turns) - 2 r tan(45 deg) at the concave corner
    L = float(move_lengths([m for m, _ in fin]).sum())
    assert pytest.approx(160.0 + R_TOOL * 5 * math.pi / 2 - 2 * R_TOOL, abs=1e-9) == L
    # the trimmed corner sits on the bisector, r from both walls
    ends = np.array([m.end[:2] for m, _ in fin])
    assert np.min(np.hypot(*(ends - [R_TOOL, R_TOOL]).T)) < 1e-9
    rep = check(text, part)
    assert rep.ok, rep.to_dict()["problems"]
    assert rep.max_deviation_mm <= 1e-6


def test_notch_narrower_than_the_tool_is_reported():
    part = notched_square(width=4.0)  # 4 mm notch, 6 mm tool
    text = comp_text(part, "G41")
    rep = check(text, part)
    assert not rep.ok and {"COMP_CORNER", "GOUGE"} <= rep.codes()
    # the three notch moves: both ends within |x| <= 2, 12 <= y <= 20
    notch = {m.line for m in parse(text).moves
             if all(abs(p[0]) <= 2 + 1e-9 and 12 - 1e-9 <= p[1] <= 20 + 1e-9 for p in (m.start, m.end))}
    assert len(notch) == 3
    corner = [p for p in rep.problems if p.code == "COMP_CORNER"]
    assert corner and all(p.line in notch for p in corner), (corner, notch)
    assert "too tight" in corner[0].message
    assert rep.gouge_at["line"] in notch


def test_notch_wider_than_the_tool_is_fine():
    part = notched_square(width=8.0)
    rep = check(notched := comp_text(part, "G41"), part)
    assert rep.ok, rep.to_dict()["problems"]
    path = simulate_compensation(parse(notched).moves, R_TOOL)
    assert path.corners["trimmed"] == 2 and path.corners["failed"] == 0


# ---- arcs under compensation -----------------------------------------------------------------------

def _hand_program(segs, comp, entry_from, exit_to, z=-4.0):
    """A minimal compensated program through the closed contour ``segs`` (traversed as given)."""
    out = ["G17 G21 G40 G54 G90 G94", "S3000 M3", "G0 Z25", f"G0 X{entry_from[0]:.4f} Y{entry_from[1]:.4f}", "G0 Z2",
           f"G1 Z{z:.4f} F200", "(FINISH LEAD-IN)",
           f"G1 {comp} D1 X{segs[0].start[0]:.4f} Y{segs[0].start[1]:.4f} F600", f"({FINISH})"]
    for s in segs:
        if s.is_arc:
            i, j = s.center[0] - s.start[0], s.center[1] - s.start[1]
            out.append(f"G{2 if s.clockwise else 3} X{s.end[0]:.4f} Y{s.end[1]:.4f} I{i:.4f} J{j:.4f}")
        else:
            out.append(f"G1 X{s.end[0]:.4f} Y{s.end[1]:.4f}")
    out += ["(FINISH LEAD-OUT)", f"G1 G40 X{exit_to[0]:.4f} Y{exit_to[1]:.4f}", "G0 Z25", "M5", "M2"]
    return "\n".join(out) + "\n"


def _notched_disc_program(r_notch, comp="G41"):
    """Climb (clockwise, tool left = outside) round the notched disc, from the bottom of the disc."""
    big, notch = notched_disc(30.0, r_notch)
    first_half, second_half = big.reversed().split(0.5)  # the long clockwise arc, split at (0, -30)
    segs = [second_half, notch.reversed(), first_half]
    p0 = np.array(segs[0].start)
    out = p0 + 2.5 * R_TOOL * p0 / np.hypot(*p0)
    return _hand_program(segs, comp, out, out), [big, notch]


def test_concave_arc_smaller_than_the_tool_is_reported():
    text, part = _notched_disc_program(2.0)  # a 2 mm concave notch, 3 mm tool radius
    rep = check(text, part)
    assert "COMP_ARC_RADIUS" in rep.codes() and not rep.ok
    p = next(p for p in rep.problems if p.code == "COMP_ARC_RADIUS")
    lines = text.splitlines()
    assert re.search(r"\bG3\b", lines[p.line - 1])  # the notch: a concave G3 in a clockwise contour
    assert "smaller than tool radius under G41" in p.message and "diameter 4.0000" in p.message


def test_concave_arc_larger_than_the_tool_is_offset_exactly():
    text, part = _notched_disc_program(4.0)
    rep = check(text, part, offset_contour(part, R_TOOL))
    assert rep.ok, rep.to_dict()["problems"]
    path = simulate_compensation(parse(text).moves, R_TOOL)
    radii = sorted(round(m.radius_start, 9) for m, k in finish_moves(path) if k == "offset" and m.kind == "arc")
    assert radii == pytest.approx([1.0, 33.0, 33.0], abs=1e-4)  # notch 4 - 3, disc 30 + 3 (4-decimal I J)


# ---- entry and exit --------------------------------------------------------------------------------

def test_entry_move_shorter_than_the_tool_radius_is_reported():
    text = comp_text(stadium(HALF, RP))
    # the pass plunges outside the stock and feeds in to Y27, then turns compensation on over 6 mm
    assert "G1 Y27.0000 F600.0\nG1 G41 D1 Y21.0000\n" in text
    bad = text.replace("G1 Y27.0000 F600.0", "G1 Y23.0000 F600.0")  # 2 mm entry, 3 mm tool radius
    rep = check(bad, stadium(HALF, RP))
    entry = line_of(bad, r"G41 D1", after="FINISH LEAD-IN")
    assert [p.line for p in rep.problems if p.code == "COMP_ENTRY"] == [entry]
    assert "2.0000 mm long" in next(p.message for p in rep.problems if p.code == "COMP_ENTRY")
    assert check(text, stadium(HALF, RP)).ok  # the 6 mm entry camfab writes is fine


def test_entry_by_an_arc_is_reported():
    text = comp_text(stadium(HALF, RP))
    # the straight entry runs without compensation, which is turned on for the lead-in arc
    bad = text.replace("G1 G41 D1 Y21.0000\n", "G1 Y21.0000\nG41 D1\n")
    rep = check(bad, stadium(HALF, RP))
    arc_line = line_of(bad, r"^G3 X0\.0000 Y15", after="FINISH LEAD-IN")
    probs = [p for p in rep.problems if p.code == "COMP_ENTRY"]
    assert [p.line for p in probs if "arc" in p.message] == [arc_line]


@pytest.mark.parametrize("exit_move,what", [("G1 G40 Y24.0000", "3.0000 mm long"),
                                             ("G40\nG2 X6.0000 Y27.0000 I0 J3.0000", "is an arc")])
def test_exit_move_that_controllers_refuse_is_reported(exit_move, what):
    text = comp_text(stadium(HALF, RP))
    bad = text.replace("G1 G40 Y27.0000", exit_move)
    rep = check(bad, stadium(HALF, RP))
    exit_line = line_of(bad, r"G40 Y24|G2 X6\.0000 Y27", after="FINISH LEAD-OUT")
    probs = [p for p in rep.problems if p.code == "COMP_EXIT"]
    assert [p.line for p in probs] == [exit_line] and what in probs[0].message


def test_linuxcnc_entry_is_tangent_to_the_circle_about_the_programmed_point():
    # G41 travelling +X, then a right turn: a convex corner after the entry
    text = "G17 G21 G40 G54 G90 G94\nG0 X0 Y0 Z-1\nG1 G41 D1 X10 Y0 F100\nG1 X10 Y-10\nG1 G40 X0 Y-10\nM2\n"
    path = simulate_compensation(parse(text).moves, 2.0)
    entry = next(m for m, k in zip(path.moves, path.kind, strict=True) if k == "entry")
    E, C, P = np.array(entry.end[:2]), np.array(entry.start[:2]), np.array([10.0, 0.0])
    assert C.tolist() == [0.0, 0.0]
    assert np.hypot(*(E - P)) == pytest.approx(2.0)
    assert float((E - C) @ (E - P)) == pytest.approx(0.0, abs=1e-12)  # tangent: the cutter touches P
    assert E[1] > 0  # G41: left of travel (+X)
    corner = next(m for m, k in zip(path.moves, path.kind, strict=True) if k == "corner")
    assert corner.center == (10.0, 0.0) and corner.clockwise and corner.end[:2] == pytest.approx((12.0, 0.0))
    # the rolling arc turns from the entry's direction to -Y: 90 deg + asin(r / d)
    assert abs(corner.sweep) == pytest.approx(math.pi / 2 + math.asin(2.0 / 10.0))
    ex = next(m for m, k in zip(path.moves, path.kind, strict=True) if k == "exit")
    assert ex.start[:2] == pytest.approx((12.0, -10.0)) and ex.end[:2] == (0.0, -10.0)


def test_entry_into_a_concave_corner_is_trimmed():
    # G41 travelling +X, then a left turn: concave; the entry is cut short where it meets X = 10 - r
    text = "G17 G21 G40 G54 G90 G94\nG0 X0 Y0 Z-1\nG1 G41 D1 X10 Y0 F100\nG1 X10 Y10\nG1 G40 X0 Y10\nM2\n"
    path = simulate_compensation(parse(text).moves, 2.0)
    assert "corner" not in path.kind and path.corners["trimmed"] == 1
    entry = next(m for m, k in zip(path.moves, path.kind, strict=True) if k == "entry")
    off = next(m for m, k in zip(path.moves, path.kind, strict=True) if k == "offset")
    assert entry.end[0] == pytest.approx(8.0) and off.start[:2] == pytest.approx(entry.end[:2])
    assert off.end[:2] == pytest.approx((8.0, 10.0))
    ex = next(m for m, k in zip(path.moves, path.kind, strict=True) if k == "exit")
    assert ex.start[:2] == pytest.approx((8.0, 10.0)) and ex.end[:2] == (0.0, 10.0)


def test_reversal_rolls_half_a_turn_round_the_end():
    text = "G17 G21 G40 G54 G90 G94\nG0 X-20 Y0 Z-1\nG1 G41 D1 X0 Y0 F100\nG1 X20\nG1 X0\nG1 G40 X-20\nM2\n"
    path = simulate_compensation(parse(text).moves, 2.0)
    c = [m for m, k in zip(path.moves, path.kind, strict=True) if k == "corner" and m.line == 5]
    assert len(c) == 1 and c[0].center == (20.0, 0.0) and c[0].sweep == pytest.approx(-math.pi)
    assert c[0].start[:2] == pytest.approx((20.0, 2.0)) and c[0].end[:2] == pytest.approx((20.0, -2.0))


def test_side_change_without_g40_is_reported():
    text = ("G17 G21 G40 G54 G90 G94\nG0 X0 Y0 Z-1\nG1 G41 D1 X10 Y0 F100\nG1 X20\nG1 G42 D1 X30\nG1 X40\n"
            "G1 G40 X50\nM2\n")
    path = simulate_compensation(parse(text).moves, 2.0)
    assert [(p.code, p.line) for p in path.problems] == [("COMP_SIDE_CHANGE", 5)]
    assert len(path.runs) == 2


def test_z_only_moves_keep_the_compensated_position():
    text = ("G17 G21 G40 G54 G90 G94\nG0 X0 Y-10 Z5\nG1 G41 D1 X0 Y0 F100\nG1 Z-1\nG1 X20\nG1 Z5\nG1 G40 X20 Y-10\n"
            "G0 Z25\nM2\n")
    path = simulate_compensation(parse(text).moves, 2.0)
    z = [m for m, k in zip(path.moves, path.kind, strict=True) if k == "z"]
    assert len(z) == 2
    assert z[0].start[:2] == z[0].end[:2] and z[1].start[:2] == z[1].end[:2]
    assert z[1].end[:2] == pytest.approx((20.0, 2.0))  # left of +X travel, before the exit
    # and the sequence is continuous in XY
    for a, b in itertools.pairwise(path.moves[1:]):
        assert np.allclose(a.end[:2], b.start[:2], atol=1e-12), (a, b)


def test_compensated_path_is_continuous_for_a_cam(cam_case):
    path = simulate_compensation(parse(cam_case["texts"]["G41"]).moves, R_TOOL)
    ms = [m for m in path.moves if np.all(np.isfinite(m.start))]
    gaps = [math.dist(a.end, b.start) for a, b in itertools.pairwise(ms)]
    assert max(gaps) < 1e-9
    assert path.corners["failed"] == 0 and not path.problems


# ---- the command line ------------------------------------------------------------------------------

def test_cli_compensated_program_verifies_and_the_swapped_one_fails(tmp_path, capsys):
    from camfab.cli import main

    out = tmp_path / "c.nc"
    assert main(["gcode", "ejemplo9rt", "--compensation", "G41", "-o", str(out)]) == 0
    capsys.readouterr()
    assert main(["verify", str(out), "--design", "ejemplo9rt", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["ok"] and d["max_deviation_mm"] <= d["tolerance_mm"] and d["gouge"] is False
    assert any("compensation simulated" in n for n in d["notes"])
    out.write_text(swap_sides(out.read_text()))
    assert main(["verify", str(out), "--design", "ejemplo9rt", "--json"]) == 1
    d = json.loads(capsys.readouterr().out)
    assert d["gouge"] and {"GOUGE", "COMP_WRONG_SIDE"} <= {p["code"] for p in d["problems"]}
