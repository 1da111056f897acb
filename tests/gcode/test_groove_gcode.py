"""The slot program of a groove cam: `camfab verify` accepts it and refuses it mutated (a flank pass pushed into
the flank gouges; a flank pass run the other way is not climb milling); the cutter must be narrower than the
groove and fit each flank's concave stretches."""
from __future__ import annotations

import re

import pytest

from camfab import pipeline
from camfab.errors import GeometryError, SpecError
from camfab.gcode.groove import verify_groove_program
from camfab.offset.groove import flank_cutter_problem, groove_tool_paths
from camfab.results import IssueCode


@pytest.fixture(scope="module")
def made():
    cam = pipeline.load("groove_translating")
    tol = cam.tolerance()
    job = pipeline.gcode_job(cam.spec, tol=tol)
    return cam, tol, job, cam.to_gcode()


def _verify(cam, tol, job, text):
    return verify_groove_program(text, *cam.geometry.profiles, job, tol=tol)


def test_program_verifies_and_cuts_to_the_groove_depth(made):
    cam, tol, job, text = made
    rep = _verify(cam, tol, job, text)
    assert rep.ok, [p.message for p in rep.problems]
    assert rep.max_deviation_mm <= tol and rep.coverage_gap_mm is not None and rep.coverage_gap_mm <= tol
    assert job.depth_mm == cam.spec.follower.groove_depth_mm  # no breakthrough: the groove has a floor
    assert text.count("(FINISH CONTOUR)") == 2 and "(FINISH PASS OUTER FLANK)" in text


def _finish_block(text: str, flank: str) -> tuple[int, int]:
    lines = text.splitlines()
    a = lines.index(f"(FINISH PASS {flank} FLANK)")
    b = next(i for i in range(a, len(lines)) if lines[i] == "(FINISH LEAD-OUT)")
    return a, b


def test_mutated_program_fails(made):
    cam, tol, job, text = made
    lines = text.splitlines()
    a, b = _finish_block(text, "OUTER")
    # the outer flank's pass moved 0.05 mm (10 tolerances) in +Y (arc centres are incremental: still arcs): into
    # the flank at the top, away from it at the bottom
    move = lambda ln: re.sub(r"Y(-?\d+\.\d+)", lambda m: f"Y{float(m.group(1)) + 0.05:.4f}", ln)  # noqa: E731
    shifted = [move(ln) if a < i < b else ln for i, ln in enumerate(lines)]
    rep = _verify(cam, tol, job, "\n".join(shifted) + "\n")
    assert not rep.ok and rep.codes() & {IssueCode.DEVIATION, IssueCode.GOUGE}
    # the inner flank's pass run backwards (G2 <-> G3 on its arcs, ends kept) is neither on the curve nor climb
    a, b = _finish_block(text, "INNER")
    flip = [ln.replace("G2", "G3") if a < i < b else ln for i, ln in enumerate(lines)]
    rep = _verify(cam, tol, job, "\n".join(flip) + "\n")
    assert IssueCode.GOUGE in rep.codes()
    # a conventional program judged against the climb job: both flank passes run the wrong way, each named
    conv = cam.to_gcode(direction="conventional")
    assert _verify(cam, tol, pipeline.gcode_job(cam.spec, tol=tol, overrides={"direction": "conventional"}), conv).ok
    wrong = [p.message for p in _verify(cam, tol, job, conv).problems if p.code is IssueCode.DIRECTION]
    assert len(wrong) == 2 and wrong[0].startswith("the inner flank") and wrong[1].startswith("the outer flank")


def test_cutter_must_be_narrower_than_the_groove(made):
    cam, tol, *_ = made
    inner, outer = cam.geometry.profiles
    w = inner.roller_radius
    with pytest.raises(GeometryError, match="narrower than the groove"):
        groove_tool_paths(inner, outer, w, tol=tol)
    # each flank's concave radius is |ρ_p| + w > w: a cutter that fits the groove fits the flanks, and one that
    # is larger than a flank's concave radius is named with that flank
    assert flank_cutter_problem(inner, 0.99 * w) is None and flank_cutter_problem(outer, 0.99 * w) is None
    msg = flank_cutter_problem(outer, 80.0)
    assert msg is not None and msg.startswith("outer flank: the cutter radius 80 mm")


def test_compensation_is_refused_for_a_groove(made):
    cam, *_ = made
    with pytest.raises(SpecError) as e:
        cam.to_gcode(compensation="G41")
    assert "machining.compensation" in {p.path for p in e.value.problems}


def test_oscillating_groove_program_verifies(tmp_path):
    """An oscillating roller in a groove, ccw: the program from `camfab run` passes `camfab verify` (CLI)."""
    import tomllib

    from camfab.cli import main
    from camfab.formats import EXAMPLES_DIR

    text = (EXAMPLES_DIR / "groove_translating.toml").read_text()
    data = tomllib.loads(text)
    assert data["follower"]["motion"] == "translating"
    text = text.replace('motion = "translating"', 'motion = "oscillating"\npivot_distance_mm = 90.0\n'
                        'arm_length_mm = 70.0').replace('rotation = "cw"', 'rotation = "ccw"')
    text = text.replace("lift = 12.0", "lift = 15.0").replace("lift = -12.0", "lift = -15.0")
    design = tmp_path / "osc.toml"
    design.write_text(text)
    assert main(["run", str(design), "-o", str(tmp_path / "out"), "--outputs", "gcode"]) == 0
    assert main(["verify", str(tmp_path / "out" / "GrooveTranslating.nc"), "--design", str(design)]) == 0
