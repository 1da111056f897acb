"""Post-processors: every program reads back, cuts the designed curve, and obeys its controller's syntax.

Syntax is checked by rules on the parsed words, never against a stored snapshot.
"""
from __future__ import annotations

import math
import re

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from camfab.errors import ExportError
from camfab.gcode import POSTS, contour_toolpath, dumps, parse, verify, write_gcode
from tests.gcode.parts import (
    CENTRE_CURVE,
    HALF,
    PART,
    R_TOOL,
    RP,
    SAFE_Z,
    TOL,
    centre_path,
    circle,
    circle_distance,
    job,
    stadium,
    stadium_points,
)

CASES = [("linuxcnc", {}), ("fanuc", {}), ("fanuc", {"arc_format": "r"}), ("grbl", {})]
IDS = ["linuxcnc", "fanuc-ij", "fanuc-r", "grbl"]

WORD = re.compile(r"([A-Z])([+-]?(?:\d+\.?\d*|\.\d+))")


def _code_lines(text):
    """(line, words) of every line with code, comments removed."""
    out = []
    for raw in text.splitlines():
        code = re.sub(r"\([^()]*\)", "", raw).strip()
        if code and code != "%":
            out.append((raw, WORD.findall(code)))
    return out


def _program(**over):
    return contour_toolpath(centre_path(), job(**over))


@pytest.mark.parametrize("units", ["mm", "inch"])
@pytest.mark.parametrize("post,opts", CASES, ids=IDS)
def test_program_reads_back_and_cuts_the_exact_curve(post, opts, units):
    text = dumps(_program(units=units), post, **opts)
    bp = parse(text)
    assert bp.units == units and bp.ended
    rep = verify(bp, exact_curve_distance=CENTRE_CURVE, part_distance=PART, tool_radius=R_TOOL, tol=TOL,
                 safe_z=SAFE_Z, curve_points=stadium_points(HALF, RP + R_TOOL))
    assert rep.ok, rep.to_dict()
    assert rep.max_deviation_mm <= TOL and not rep.gouge and rep.coverage_gap_mm <= TOL
    d = rep.to_dict()
    assert {"max_deviation_mm", "gouge", "gouge_at", "problems", "ok"} <= set(d)
    # feed is set before the first cut, every cut below the top has the spindle on
    cuts = [m for m in bp.moves if m.is_cutting]
    assert cuts[0].feed == pytest.approx(200.0, rel=1e-5) and all(m.spindle_on for m in cuts)
    # the header states units, tool, tolerance, design and achieved deviation
    head = "\n".join(bp.comments[:16]).lower()
    for needle in ("units", "tool", "t1", "tolerance", "0.001000 mm", "design", "stadium test",
                   "achieved deviation", "0.000400 mm"):
        assert needle in head, needle


@pytest.mark.parametrize("post,opts", CASES, ids=IDS)
def test_byte_identical_output(post, opts, tmp_path):
    a = dumps(_program(), post, **opts)
    b = dumps(_program(), post, **opts)
    assert a == b
    p1 = write_gcode(tmp_path / "a.nc", _program(), post, **opts)
    p2 = write_gcode(tmp_path / "b.nc", _program(), post, **opts)
    assert p1.read_bytes() == p2.read_bytes() == a.encode()
    assert sorted(x.name for x in tmp_path.iterdir()) == ["a.nc", "b.nc"]  # no temp files left
    assert "\r" not in a and a.endswith("\n")


def test_unknown_post_lists_the_valid_ones():
    with pytest.raises(ValueError, match="fanuc, grbl, linuxcnc"):
        dumps(_program(), "heidenhain")
    with pytest.raises(ValueError, match="arc_format"):
        dumps(_program(), "fanuc", arc_format="polar")
    with pytest.raises(ValueError, match="unknown option"):
        dumps(_program(), "linuxcnc", arc_format="r")
    assert set(POSTS) == {"linuxcnc", "fanuc", "grbl"}


# ---- controller syntax ---------------------------------------------------------------------------

LINUXCNC_G = {"0", "1", "2", "3", "17", "20", "21", "40", "41", "42", "43", "49", "54", "80", "90", "91.1", "94",
              "97"}
LINUXCNC_M = {"2", "3", "5", "6", "7", "8", "9"}


def test_linuxcnc_syntax():
    text = dumps(_program(), "linuxcnc")
    lines = _code_lines(text)
    for raw, words in lines:
        assert "".join(letter + v for letter, v in words) == re.sub(r"\([^()]*\)|\s", "", raw), raw
        for letter, v in words:
            assert letter in "GMTSFXYZIJHD", raw
            if letter == "G":
                assert f"{float(v):g}" in LINUXCNC_G, raw
            if letter == "M":
                assert f"{float(v):g}" in LINUXCNC_M, raw
            assert letter != "R"
    flat = [" ".join(letter + v for letter, v in w) for _, w in lines]
    assert "T1 M6" in flat and any("G43 H1" in f for f in flat)
    assert flat[-1] == "M2" and "%" not in text
    for raw in text.splitlines():
        assert raw.count("(") == raw.count(")") <= 1
        assert not re.match(r"\(\s*(msg|debug|print|log)", raw, re.I)


def test_fanuc_syntax_ij_and_r():
    for fmt in ("ij", "r"):
        text = dumps(_program(), "fanuc", arc_format=fmt, program_number=1234)
        raw = text.splitlines()
        assert raw[0] == "%" and raw[-1] == "%"
        assert re.fullmatch(r"O1234( \([A-Z0-9 .,\-+/=*#_]*\))?", raw[1])
        numbers = []
        for line in raw[2:-1]:
            if line.startswith("("):
                assert re.fullmatch(r"\([A-Z0-9 .,\-+/=*#_]*\)", line), line
                continue
            m = re.match(r"N(\d+) ", line)
            assert m, line
            numbers.append(int(m.group(1)))
            for letter, v in WORD.findall(line[m.end():]):
                if letter in "XYZIJRF":
                    assert "." in v, f"Fanuc needs a decimal point: {line}"
            if re.search(r"\bG0?[23]\b", line):
                if fmt == "r":
                    assert " R" in line and " I" not in line and " J" not in line, line
                else:
                    assert " I" in line and " R" not in line, line
        assert numbers == sorted(numbers) and len(set(numbers)) == len(numbers)
        assert raw[-2].endswith("M30")
        bp = parse(text)
        assert bp.program_number == 1234
        limit = math.pi / 2 if fmt == "r" else math.pi
        assert all(abs(m.sweep) <= limit + 1e-9 for m in bp.moves if m.kind == "arc")


def test_r_mode_splits_arcs_over_180_degrees():
    prog = contour_toolpath(circle(20.0), job(roughing_passes=0, depth_mm=3, step_down_mm=3))
    ij = parse(dumps(prog, "fanuc"))
    r = parse(dumps(prog, "fanuc", arc_format="r"))
    fin = lambda bp: [m for m in bp.moves if m.kind == "arc" and m.label == "FINISH CONTOUR"]  # noqa: E731
    # Fanuc writes arcs in pieces of at most 30 degrees (its rounding budget), I J and R alike
    for bp in (ij, r):
        assert len(fin(bp)) == 12 and all(abs(m.sweep) <= math.pi / 6 + 1e-5 for m in fin(bp))  # + rounding
        assert sum(abs(m.sweep) for m in fin(bp)) == pytest.approx(2 * math.pi, abs=1e-4)
    radii = [float(m.group(1)) for line in dumps(prog, "fanuc", arc_format="r").splitlines()
             if not line.startswith("(") and (m := re.search(r" R(-?[\d.]+)", line))]
    assert len(radii) == 18 and all(v > 0 for v in radii)  # 12 contour pieces + 2 lead arcs of 3
    for bp in (ij, r):
        rep = verify(bp, exact_curve_distance=circle_distance(20.0), part_distance=circle_distance(17.0),
                     tool_radius=R_TOOL, tol=TOL, safe_z=SAFE_Z)
        assert rep.ok, rep.to_dict()


GRBL_G = {"0", "1", "2", "3", "17", "20", "21", "40", "54", "90", "91.1", "94"}
GRBL_M = {"2", "3", "5", "7", "8", "9", "30"}


@pytest.mark.parametrize("opts", [{}, {"coolant": False}])
def test_grbl_syntax(opts):
    text = dumps(_program(design_name="Cam (v2) – ñ; 100%"), "grbl", **opts)
    assert text.isascii() and "%" not in text
    for raw in text.splitlines():
        assert len(raw) <= 80, raw
        assert raw.count("(") == raw.count(")") <= 1
        if "(" in raw:
            body = raw[raw.index("(") + 1:raw.rindex(")")]
            assert "(" not in body and ")" not in body
            assert re.fullmatch(r"[A-Za-z0-9 .,\-+/=*#_:]*", body), raw
    for raw, words in _code_lines(text):
        for letter, v in words:
            assert letter in "GMSFXYZIJ", raw  # no N, O, T, H, D, R
            if letter == "G":
                assert f"{float(v):g}" in GRBL_G, raw
            if letter == "M":
                assert f"{float(v):g}" in GRBL_M, raw
    flat = [" ".join(letter + v for letter, v in w) for _, w in _code_lines(text)]
    assert not any("M6" in f.split() for f in flat)
    assert any("load T1" in line for line in text.splitlines())
    assert ("M8" in flat) == (opts.get("coolant", True))


def test_grbl_refuses_cutter_compensation():
    prog = contour_toolpath(stadium(HALF, RP), job(), compensation="G41")
    with pytest.raises(ExportError, match="compensation"):
        dumps(prog, "grbl")


def test_sanitised_design_names_still_parse():
    for post, opts in CASES:
        text = dumps(_program(design_name="MSG, (evil) ünïcode\nname"), post, **opts)
        bp = parse(text)
        assert bp.ended


# ---- cutter compensation -------------------------------------------------------------------------

@pytest.mark.parametrize("post", ["linuxcnc", "fanuc"])
@pytest.mark.parametrize("direction,code", [("climb", "G41"), ("conventional", "G42")])
def test_cutter_compensation_program(post, direction, code):
    prog = contour_toolpath(stadium(HALF, RP), job(direction=direction), compensation=code)
    text = dumps(prog, post)
    bp = parse(text)
    entries = [i for i, m in enumerate(bp.moves) if m.comp == code and (i == 0 or bp.moves[i - 1].comp == "G40")]
    assert len(entries) == 4  # 3 rough levels + 1 finishing pass
    for i in entries:
        m = bp.moves[i]
        assert m.kind == "line"  # controllers need a straight entry move
        assert math.dist(m.start[:2], m.end[:2]) > R_TOOL  # ... longer than the tool radius
        assert bp.moves[i - 1].comp == "G40"
    exits = [m for m in bp.moves if m.comp == "G40" and m.kind == "line" and m.label.endswith("LEAD-OUT")]
    assert len(exits) == 4
    rep = verify(bp, exact_curve_distance=PART, part_distance=PART, tool_radius=R_TOOL, tol=TOL,
                 safe_z=SAFE_Z)
    assert rep.ok, rep.to_dict()
    assert f"{code} D1" in text or f"{code} D1".upper() in text


# ---- property: R and I/J describe the same arcs --------------------------------------------------

@settings(max_examples=15, deadline=None)
@given(r=st.floats(8.0, 60.0), cx=st.floats(-50, 50), cy=st.floats(-50, 50),
       units=st.sampled_from(["mm", "inch"]))
def test_r_and_ij_back_plots_agree(r, cx, cy, units):
    prog = contour_toolpath(circle(r, (cx, cy)), job(roughing_passes=0, depth_mm=2, step_down_mm=2,
                                                     units=units))
    exact = circle_distance(r + 0.0, (cx, cy))
    part = circle_distance(r - R_TOOL, (cx, cy))
    for post, opts in CASES:
        rep = verify(parse(dumps(prog, post, **opts)), exact_curve_distance=exact, part_distance=part,
                     tool_radius=R_TOOL, tol=TOL, safe_z=SAFE_Z)
        assert rep.ok, (post, opts, rep.to_dict())


def test_grbl_tool_comment_reads_well():
    """GRBL has no tool changer: the operator's comment is one plain sentence (it read
    ``(load T1 D6.0000 mm by hand no M6 , set Z zero)`` once the post had stripped its parentheses)."""
    text = dumps(_program(), "grbl")
    (c,) = [line for line in text.splitlines() if "by hand" in line]
    assert re.fullmatch(r"\(tool change by hand: load T1 end mill \d+(\.\d+)? mm then set Z zero\)", c), c


@pytest.mark.parametrize("post,words", [("linuxcnc", "G17 G21 G40 G49 G54 G80 G90 G91.1 G94 G97"),
                                        ("grbl", "G17 G21 G40 G54 G90 G91.1 G94"),
                                        ("fanuc", "G17 G21 G40 G49 G80 G54 G90 G94 G97")])
def test_safety_block_states_the_modal_state(post, words):
    """Every post states plane, units, compensation, length offset, canned cycles (where the controller has
    them), work offset, absolute mode, arc-centre mode (LinuxCNC and GRBL: G91.1; Fanuc's I J are always
    incremental) and feed per minute before the first move."""
    blocks = [line.split(" ", 1)[1] if line.startswith("N") else line
              for line in dumps(_program(), post).splitlines() if line and line[0] in "GN"]
    assert blocks[0] == words


def test_fanuc_writes_three_decimals_in_mm_within_the_tolerance():
    """Fanuc IS-B: X/Y/Z/I/J with 3 decimals in mm (4 in inch) when the contour leaves room for their rounding;
    the program read back stays within the tolerance of the exact tool-centre curve (camfab verify)."""
    from camfab.gcode.cam import cam_program, verify_cam_program
    from camfab.pipeline import gcode_job, load

    cam = load("ejemplo1rt")
    tol = cam.tolerance()
    job = gcode_job(cam.spec, tol=tol)
    contact = cam.geometry.profiles[0]
    cp = cam_program(contact, job, tol=tol, post="fanuc")
    text = dumps(cp.program, "fanuc")
    nums = re.findall(r"\b[XYZIJ](-?\d+\.\d+)", "\n".join(ln for ln in text.splitlines() if not ln.startswith("(")))
    assert nums and {len(v.split(".")[1]) for v in nums} == {3}
    rep = verify_cam_program(text, contact, job, tol=tol, post="fanuc")
    assert rep.ok and rep.max_deviation_mm <= tol
    # the same contour as LinuxCNC budgets it leaves no room for 0.001 mm rounding: Fanuc falls back to IS-C
    loose = dumps(cam_program(contact, job, tol=tol).program, "fanuc")
    assert "OUTPUT RESOLUTION 0.0001 MM" in loose
