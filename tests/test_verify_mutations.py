"""Mutation testing of ``camfab verify``: realistic hand edits of correct generated programs, for every post.

Each mutation is an edit a shop could make by mistake (a deleted line, a truncated file, a changed depth,
feed, spindle or coolant word, a rapid in the material, a moved arc centre, a flipped arc, a 0.05 mm typo, a
missing retract, tool change or length offset, a deeper plunge, inch units, a missing G90, a stray G91, ...).
Every mutated program must fail verification with the named finding(s) - exactly what makes ``camfab verify``
exit 1 - and every unmutated program must pass.  The programs are written once per module (Ejemplo9RT at a
0.01 mm tolerance and two depth levels, so each check takes a fraction of a second) and verified the way
the command does (:func:`camfab.gcode.cam.verify_cam_program`: the design's job, coverage, full depth).
"""
from __future__ import annotations

import math
import re

import pytest

from camfab import pipeline
from camfab.gcode import dumps
from camfab.gcode.cam import cam_program, signed_distance, verify_cam_program
from camfab.offset import profile_curve

TOL = 0.01
POSTS = ("linuxcnc", "fanuc", "grbl")
GEOMETRY = {"DEVIATION", "GOUGE", "COVERAGE", "PARSE_ERROR", "ARC_RADIUS_MISMATCH", "RAPID_BELOW_SAFE",
            "RAPID_THROUGH_PART", "RAPID_INTO_STOCK", "FINISH_DEPTH", "TOO_DEEP", "STEP_DOWN"}


@pytest.fixture(scope="module")
def case():
    cam = pipeline.load("ejemplo9rt")
    # the edits below name the numbers of this job (S3000, F600, F200, Z-5, Z-10): fixed here, not taken from the
    # cutting-data table, and no breakthrough, so the final depth is the 10 mm plate
    job = pipeline.gcode_job(cam.spec, tol=TOL, overrides={"step_down_mm": 5.0, "spindle_rpm": 3000.0,
                                                           "feed_mm_min": 600.0, "plunge_feed_mm_min": 200.0,
                                                           "breakthrough_mm": 0.0})
    contact = cam.geometry.profiles[0]
    prog = cam_program(contact, job, tol=TOL)
    lines_only = cam_program(contact, job, tol=TOL, arcs_allowed=False)
    texts = {post: dumps(prog.program, post) for post in POSTS}
    texts["linuxcnc-lines"] = dumps(lines_only.program, "linuxcnc")
    part = signed_distance(profile_curve(contact), tol=TOL)
    return {"contact": contact, "job": job, "part": part, "texts": texts}


def _check(case, text):
    return verify_cam_program(text, case["contact"], case["job"], tol=TOL, part=case["part"])


# -- editing helpers: fanuc lines carry N numbers (and 3 decimals), grbl comments keep their case --------------
_N = re.compile(r"^(N\d+\s+)?(.*)$")


def _code(line: str) -> str:
    return _N.match(line).group(2)


def _at(lines, pattern, after=None, nth=0):
    """Index of the ``nth`` line whose code matches ``pattern``, after the comment ``(after)`` if given."""
    start = 0
    if after is not None:
        start = next(i for i, t in enumerate(lines) if t.upper() == f"({after})") + 1
    hits = [i for i in range(start, len(lines)) if re.search(pattern, _code(lines[i]))]
    return hits[nth]


def _sub(lines, i, pattern, repl):
    pre = _N.match(lines[i]).group(1) or ""
    new = re.sub(pattern, repl, _code(lines[i]), count=1)
    assert new != _code(lines[i]), (pattern, lines[i])
    lines[i] = pre + new


def _num(pattern_letter, delta):
    return lambda m: f"{pattern_letter}{float(m.group(1)) + delta:.4f}"


def _replacing(find, pattern, repl, after=None):
    """An edit: in the first line matching ``find`` (after the comment ``after``), ``pattern`` -> ``repl``."""
    return lambda L: _sub(L, _at(L, find, after), pattern, repl)


def _deleting(find, after=None):
    """An edit: delete the first line matching ``find`` (after the comment ``after``)."""
    def edit(L):
        del L[_at(L, find, after)]
    return edit


m_finish_depth = _replacing(r"^G1 Z-10\.", r"Z-10\.0+", "Z-5.0000", "FINISH PASS LEVEL 1 OF 1")
m_rough_depth = _replacing(r"^G1 Z-5\.0+\b", r"Z-5\.0+", "Z-10.0000")
m_feed_lower = _replacing(r"F600\.0", r"F600\.0", "F550.0", "FINISH LEAD-IN")
m_plunge_feed = _replacing(r"^G1 Z-10\.", r"F200\.0", "F2000.0", "FINISH PASS LEVEL 1 OF 1")
m_m3_to_m4 = _replacing(r"\bM3\b", r"\bM3\b", "M4")
m_spindle_speed = _replacing(r"\bM3\b", r"S3000", "S30000")
m_m8_to_m7 = _replacing(r"^M8$", r"M8", "M7")
m_rapid_plunge = _replacing(r"^G1 Z-10\.", r"^G1 Z-10\.0+ F200\.0", "G0 Z-10.0000", "FINISH PASS LEVEL 1 OF 1")
m_other_tool = _replacing(r"^T1 M6$", r"^T1", "T2")
m_no_length_offset = _replacing(r"G43 H1", r"G43 H1 ", "")
m_inch = _replacing(r"\bG21\b", r"\bG21\b", "G20")
m_no_g90 = _replacing(r"\bG90\b", r" G90\b", "")
m_drop_m3 = _deleting(r"\bM3\b")
m_drop_m8 = _deleting(r"^M8$")
m_no_retract = _deleting(r"^G0 Z25\.", "ROUGH LEAD-OUT")
m_no_final_retract = _deleting(r"^G0 Z25\.", "FINISH LEAD-OUT")
m_no_tool_change = _deleting(r"^T1 M6$")
m_no_program_end = _deleting(r"^M(2|30)$")


# -- the mutations: (name, posts it applies to, edit(lines) -> None, the finding(s) one of which must appear) --
def m_delete_finish_line(L):
    del L[_at(L, r"^G[0123]\b", "FINISH CONTOUR", 3)]


def m_truncate_in_finish(L):
    i = _at(L, r"^G[0123]\b", "FINISH CONTOUR", 10)
    del L[i:]


def m_truncate_after_roughing(L):
    i = next(k for k, t in enumerate(L) if t.upper() == "(FINISH PASS LEVEL 1 OF 1)")
    del L[i:]


def m_feed_fast(L):
    i = _at(L, r"^G[123]\b", "FINISH CONTOUR")
    L[i] += " F60000.0"


def m_feed_zero(L):
    i = _at(L, r"^G[123]\b", "FINISH CONTOUR")
    L[i] += " F0"


def m_spindle_after_plunge(L):
    i = _at(L, r"\bM3\b")
    line = L.pop(i)
    L.insert(_at(L, r"^G1 Z-5\.") + 1, line)


def m_m9_before_cutting(L):
    i = _at(L, r"^M8$")
    L.insert(i + 1, "M9")


def m_rapid_in_material(L):
    i = _at(L, r"^G[123]\b", "FINISH CONTOUR", 5)
    _sub(L, i, r"^G[123]\b(.*?)( I\S+ J\S+)?( F\S+)?$", r"G0\1")


def _finish_moves(L):
    """Indexes of the finishing-contour move lines."""
    i = next(k for k, t in enumerate(L) if t.upper() == "(FINISH CONTOUR)") + 1
    out = []
    while re.match(r"G[123]\b", _code(L[i])):
        out.append(i)
        i += 1
    return out


def _xy(line):
    return tuple(float(re.search(a + r"(-?[\d.]+)", _code(line)).group(1)) for a in "XY")


def m_arc_centre(L):
    # the finishing arc of moderate radius whose ends differ most in x for their radius: moving the centre of a
    # 2 m radius arc by 0.05 mm hardly moves the arc, and neither does it on a short arc, whose written ends pin
    # the path; I + e changes the two radii by e (x_start - x_end) / r apart
    def word(line, a):
        m = re.search(a + r"(-?[\d.]+)", _code(line))
        return None if m is None else float(m.group(1))

    moves = _finish_moves(L)
    x, y = word(L[moves[0] - 2], "X"), word(L[moves[0] - 2], "Y")  # the lead-in arc ends where the contour starts
    best, chord = None, 0.0
    for k in moves:
        ex, ey = word(L[k], "X"), word(L[k], "Y")
        ex, ey = x if ex is None else ex, y if ey is None else ey
        i, j = word(L[k], "I"), word(L[k], "J")
        if i is not None and j is not None and math.hypot(i, j) < 60 and abs(ex - x) / math.hypot(i, j) > chord:
            best, chord = k, abs(ex - x) / math.hypot(i, j)
        x, y = ex, ey
    assert best is not None
    _sub(L, best, r"I(-?[\d.]+)", _num("I", 0.05))


def m_flip_arc(L):
    i = _at(L, r"^G[23]\b", "FINISH CONTOUR", 4)
    _sub(L, i, r"^G([23])\b", lambda m: "G3" if m.group(1) == "2" else "G2")


def m_coordinate_typo(L):
    # X of the move ending farthest right, where the contour's normal is along X
    i = max(_finish_moves(L), key=lambda k: _xy(L[k])[0])
    _sub(L, i, r"X(-?[\d.]+)", _num("X", 0.05))


def m_safe_z_low(L):
    for i, t in enumerate(L):
        if re.search(r"^G0 .*Z25\.0+\b", _code(t)):
            _sub(L, i, r"Z25\.0+", "Z1.0000")


def m_plunge_deeper(L):
    i = _at(L, r"^G1 Z-10\.", "FINISH PASS LEVEL 1 OF 1")
    L.insert(i + 1, "G1 Z-12.0000")


def m_inject_g91(L):
    i = next(k for k, t in enumerate(L) if t.upper() == "(FINISH CONTOUR)")
    L.insert(i + 1, "G91")


def m_cut_across(L):
    i = _finish_moves(L)[8]
    x, y = _xy(L[i])
    L[i + 1:i + 1] = ["G1 X0.0000 Y0.0000", f"G1 X{x:.4f} Y{y:.4f}"]


def m_lift_over_a_stretch(L):
    # lift the tool after one finishing move, rapid over the next three and plunge again: only coverage sees it
    f = _finish_moves(L)
    k = f[6]
    x, y = _xy(L[f[9]])
    del L[f[7]:f[10]]
    L[k + 1:k + 1] = ["G0 Z25.0000", f"G0 X{x:.4f} Y{y:.4f}", "G0 Z2.0000", "G1 Z-10.0000 F200.0"]
    L[k + 5] += " F600.0"


def m_swap_ij(L):
    i = _at(L, r"^G[23]\b.* I", "FINISH CONTOUR", 1)
    _sub(L, i, r"I(-?[\d.]+) J(-?[\d.]+)", lambda m: f"I{m.group(2)} J{m.group(1)}")


ALL = POSTS
CHANGER = ("linuxcnc", "fanuc")
MUTATIONS = [
    ("delete a finishing-contour line", ALL + ("linuxcnc-lines",), m_delete_finish_line, GEOMETRY),
    ("truncate inside the finishing contour", ALL, m_truncate_in_finish, {"COVERAGE"}),
    ("truncate before the finishing pass", ALL, m_truncate_after_roughing, {"NO_FINISH_PASS", "FINISH_DEPTH",
                                                                            "COVERAGE"}),
    ("finishing pass at Z-5 of Z-10", ALL, m_finish_depth, {"FINISH_DEPTH"}),
    ("first roughing level at full depth", ALL, m_rough_depth, {"STEP_DOWN"}),
    ("F60000 on the finishing pass", ALL, m_feed_fast, {"FEED_OUT_OF_RANGE"}),
    ("F0 on the finishing pass", ALL, m_feed_zero, {"FEED_MISSING"}),
    ("cutting feed 600 -> 550", ALL, m_feed_lower, {"FEED_OUT_OF_RANGE"}),
    ("plunge feed 200 -> 2000", ALL, m_plunge_feed, {"FEED_OUT_OF_RANGE"}),
    ("M3 deleted", ALL, m_drop_m3, {"SPINDLE_OFF"}),
    ("M3 -> M4", ALL, m_m3_to_m4, {"SPINDLE_DIRECTION"}),
    ("S3000 -> S30000", ALL, m_spindle_speed, {"SPINDLE_SPEED"}),
    ("spindle started after the first plunge", ALL, m_spindle_after_plunge, {"SPINDLE_OFF"}),
    ("M8 deleted", ALL, m_drop_m8, {"COOLANT"}),
    ("flood M8 -> mist M7", ALL, m_m8_to_m7, {"COOLANT"}),
    ("M9 before cutting", ALL, m_m9_before_cutting, {"COOLANT"}),
    ("finishing plunge as a rapid", ALL, m_rapid_plunge, {"RAPID_INTO_STOCK"}),
    ("rapid G0 in the material", ALL + ("linuxcnc-lines",), m_rapid_in_material, {"RAPID_BELOW_SAFE"}),
    ("arc centre moved 0.05 mm", ALL, m_arc_centre, {"DEVIATION", "PARSE_ERROR", "ARC_RADIUS_MISMATCH"}),
    ("G2 <-> G3 on a finishing arc", ALL, m_flip_arc, {"DEVIATION", "GOUGE"}),
    ("X +0.05 mm on a finishing move", ALL + ("linuxcnc-lines",), m_coordinate_typo,
     {"DEVIATION", "PARSE_ERROR", "GOUGE"}),
    ("retract before a rapid deleted", ALL, m_no_retract, {"RAPID_BELOW_SAFE"}),
    ("final retract deleted", ALL, m_no_final_retract, {"RETRACT_MISSING"}),
    ("safe height Z25 -> Z1", ALL, m_safe_z_low, {"RAPID_BELOW_SAFE"}),
    ("tool change deleted", CHANGER, m_no_tool_change, {"TOOL"}),
    ("T1 -> T2", CHANGER, m_other_tool, {"TOOL"}),
    ("tool length offset deleted", CHANGER, m_no_length_offset, {"TOOL_LENGTH_OFFSET"}),
    ("plunge duplicated 2 mm deeper", ALL, m_plunge_deeper, {"FINISH_DEPTH", "TOO_DEEP"}),
    ("G21 -> G20", ALL, m_inch, GEOMETRY),
    ("G90 deleted from the safety block", ALL, m_no_g90, {"MODAL_STATE"}),
    ("G91 injected before the finishing contour", ALL, m_inject_g91, GEOMETRY),
    ("program end deleted", ALL, m_no_program_end, {"PARSE_WARNING"}),
    ("a cut across the part", ALL, m_cut_across, {"GOUGE"}),
    ("a stretch skipped by lifting the tool", ALL, m_lift_over_a_stretch, {"COVERAGE"}),
    ("I and J swapped", ALL, m_swap_ij, {"PARSE_ERROR", "DEVIATION", "GOUGE"}),
]
CASES = [pytest.param(post, edit, codes, id=f"{post}: {name}")
         for name, posts, edit, codes in MUTATIONS for post in posts]


def test_the_suite_is_large_enough():
    assert len(MUTATIONS) >= 30 and len(CASES) >= 90
    assert {p for _, posts, _, _ in MUTATIONS for p in posts} >= set(POSTS)


@pytest.mark.parametrize("post", POSTS + ("linuxcnc-lines",))
def test_unmutated_program_passes(case, post):
    rep = _check(case, case["texts"][post])
    assert rep.ok, rep.to_dict()["problems"]
    assert rep.max_deviation_mm <= TOL and rep.coverage_gap_mm <= TOL and not rep.gouge


@pytest.mark.parametrize("post,edit,codes", CASES)
def test_every_mutation_is_caught(case, post, edit, codes):
    lines = case["texts"][post].splitlines()
    edit(lines)
    text = "\n".join(lines) + "\n"
    assert text != case["texts"][post]
    rep = _check(case, text)
    found = {str(p.code) for p in rep.problems}
    assert not rep.ok and found & codes, (sorted(found), sorted(codes))
    assert all(p.message for p in rep.problems)
