"""The G-code reader: modal state, arcs by I/J and R, units, distance modes, and clear errors."""
from __future__ import annotations

import math

import numpy as np
import pytest

from camfab.gcode import GcodeError, parse, sample

HEAD = "G17 G21 G90\nG0 X0 Y0 Z0\n"


def _arc(text):
    moves = parse(HEAD + text + "\nM2\n").moves
    return moves[-1]


def test_r_sign_chooses_short_or_long_arc():
    short = _arc("G2 X10 Y0 R10 F100")
    assert short.center == pytest.approx((5, -math.sqrt(75)))
    assert short.sweep == pytest.approx(-math.pi / 3)
    long = _arc("G2 X10 Y0 R-10 F100")
    assert long.center == pytest.approx((5, math.sqrt(75)))
    assert long.sweep == pytest.approx(-5 * math.pi / 3)
    ccw = _arc("G3 X10 Y0 R10 F100")
    assert ccw.center == pytest.approx((5, math.sqrt(75))) and ccw.sweep == pytest.approx(math.pi / 3)


def test_ij_incremental_and_absolute_centres():
    m = parse("G21 G90\nG0 X10 Y0 Z0\nG3 X0 Y10 I-10 J0 F50\nM2\n").moves[-1]
    assert m.center == pytest.approx((0, 0)) and m.sweep == pytest.approx(math.pi / 2)
    assert m.feed == 50.0 and m.kind == "arc" and m.clockwise is False
    m = parse("G21 G90 G90.1\nG0 X10 Y0 Z0\nG2 X0 Y-10 I0 J0 F50\nM2\n").moves[-1]
    assert m.center == pytest.approx((0, 0)) and m.sweep == pytest.approx(-math.pi / 2)


def test_full_circle_by_ij():
    m = _arc("G2 X0 Y0 I5 J0 F100")
    assert m.sweep == pytest.approx(-2 * math.pi)


def test_units_and_incremental_distance():
    bp = parse("%\nO0042 (demo)\nN10 G20 G90\nN20 G0 X1 Y2 Z0.5\nN30 G91 G1 X1 F10\nN40 M30\n%\n")
    assert bp.units == "inch" and bp.program_number == 42 and bp.ended
    a, b = bp.moves
    assert a.end == pytest.approx((25.4, 50.8, 12.7)) and a.n == 20 and a.feed is None
    assert b.end == pytest.approx((50.8, 50.8, 12.7)) and b.feed == pytest.approx(254.0)
    assert b.line == 5


def test_labels_come_from_the_last_comment():
    bp = parse("G21 G90\n(FIRST)\nG0 X0 Y0 Z5\nG1 Z0 F10 ; second\nG1 X1\nM2\n")
    assert [m.label for m in bp.moves] == ["FIRST", "second", "second"]
    assert "FIRST" in bp.comments


def test_modal_motion_and_feed():
    bp = parse("G21 G90\nG0 X0 Y0 Z0\nG1 X1 F100\nX2\nY3\nM2\n")
    assert [m.kind for m in bp.moves] == ["rapid", "line", "line", "line"]
    assert bp.moves[-1].end == (2.0, 3.0, 0.0) and bp.moves[-1].feed == 100.0


def test_missing_feed_is_recorded_not_raised():
    bp = parse("G21 G90\nG0 X0 Y0 Z0\nG1 X1\nM2\n")
    assert bp.moves[-1].feed is None


def test_spiral_from_mismatched_radii_is_back_plotted():
    m = _arc("G2 X10 Y0 I5.01 J0 F100")  # centre 0.01 off: radii 5.01 and 4.99
    assert m.radius_start == pytest.approx(5.01) and m.radius_end == pytest.approx(4.99)
    pts = sample([m], 0.01).points
    assert np.allclose(pts[0], m.start) and np.allclose(pts[-1], m.end)


@pytest.mark.parametrize("line,msg", [
    ("G1 X1.2.3 F10", "malformed"),
    ("G1 X1 Q5 F10", "unknown word"),
    ("G5 X1", "unsupported G-code"),
    ("M99", "unsupported M-code"),
    ("G1 X1 X2 F10", "twice"),
    ("G0 G1 X1", "same modal group"),
    ("G2 X1 Y1 F10", "without centre"),
    ("G2 X0 Y0 R5 F10", "full circle"),
    ("G2 X10 Y0 R2 F10", "smaller than half the chord"),
    ("G2 X10 Y0 I5 J0 R5 F10", "R and I/J"),
    ("G2 X10 Y0 I5.5 J0 F10", "radii differ"),
    ("G1 X1 (a (nested) comment) F10", "nested comment"),
    ("G1 X1 (open F10", "not closed"),
    ("G18\nG2 X1 Z1 I1 F10", "G17 only"),
    ("G1 I3 F10", "without a G2/G3"),
    ("o100 sub", "malformed"),
    ("G41 G1 X5 F10", "needs a D word"),
    ("G1 X1 F10 %", "stand alone"),
    ("/G1 X1 F10", "block delete"),
    ("X1 N10", "N word must come first"),
])
def test_errors_name_the_line(line, msg):
    text = HEAD + line + "\nM2\n"
    with pytest.raises(GcodeError) as info:
        parse(text)
    assert msg in str(info.value)
    assert info.value.line >= 3 and f"line {info.value.line}:" in str(info.value)


def test_axis_words_need_a_motion_mode():
    with pytest.raises(GcodeError, match="line 2: axis words without a motion mode"):
        parse("G21\nX1\n")


def test_warnings_for_missing_units_and_end():
    bp = parse("G0 X0 Y0 Z5\n")
    assert any("G20/G21" in w for w in bp.warnings) and any("no end" in w for w in bp.warnings)
    bp = parse("G21\nG0 Z5\nM2\nG0 X10\n")
    assert len(bp.moves) == 1 and any("after the program end" in w for w in bp.warnings)


def test_sample_points_lie_on_the_arc():
    m = _arc("G3 X-10 Y0 I-5 J0 F100")  # from (0,0): centre (-5,0), half circle
    s = sample([m], 0.1)
    r = np.hypot(s.points[:, 0] + 5, s.points[:, 1])
    assert np.allclose(r, 5.0) and len(s.points) >= math.pi * 5 / 0.1
    assert (s.index == 0).all()
    steps = np.linalg.norm(np.diff(s.points, axis=0), axis=1)
    assert steps.max() <= 0.1 + 1e-12


def test_machine_state_is_carried_by_every_move():
    text = ("G17 G21 G40 G54 G90 G94\nT3 M6\nG0 G43 H3 Z25\nS2500 M4\nM8\nG0 X0 Y0\nG1 Z-1 F100\nM7\n"
            "G1 X5\nM9\nM3\nG49\nG1 X6\nG43\nG1 X7\nM2\n")
    m = {mv.line: mv for mv in parse(text).moves}
    assert (m[7].tool, m[7].length_offset, m[7].spindle_dir, m[7].spindle_rpm, m[7].coolant) == (3, 3, "ccw", 2500,
                                                                                                    "flood")
    assert m[9].coolant == "flood+mist"
    assert (m[13].coolant, m[13].spindle_dir, m[13].length_offset) == ("off", "cw", None)
    assert m[15].length_offset == 3  # G43 alone takes the loaded tool


def test_modal_groups_set_before_the_first_move():
    bp = parse("G21 G90\nG0 X0 Y0 Z5\nG17 G94\nM2\n")
    assert bp.modal_before_motion >= {"units", "distance", "motion"}
    assert not bp.modal_before_motion & {"plane", "feed_mode", "comp", "wcs"}
    assert parse("G17 G21 G40 G54 G90 G94\nG0 Z5\nM2\n").modal_before_motion >= {
        "plane", "units", "distance", "feed_mode", "comp", "wcs"}


def test_sampling_is_bounded_per_move_and_keeps_where():
    from camfab.gcode.parse import points_along

    m = _arc("G3 X-10 Y0 I-5 J0 F100")
    s = sample([m], 0.001, max_per_move=40)
    assert len(s.points) == 41 and np.allclose(s.param, np.linspace(0, 1, 41))
    assert np.allclose(points_along(m, s.param), s.points)
    # a line 1 km long: at most 40 intervals
    line = parse("G21 G90\nG0 X0 Y0 Z0\nG1 X1000000 F100\nM2\n").moves[-1]
    assert len(sample([line], 0.05, max_per_move=40).points) == 41
