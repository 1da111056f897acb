"""`camfab verify` on a cylindrical cam's 4-axis program (camfab.gcode.rotary_verify): the program camfab writes
passes, with the plate verify's JSON keys; programs mutated the ways a program goes wrong (a shifted A word, a
missing block, a wrong depth, a flank pass moved into the flank, a reversed flank pass) fail with the finding
that names it; an unreadable program and the grbl post are refused."""
from __future__ import annotations

import json
import re

import pytest

from camfab import pipeline
from camfab.cli import main
from camfab.gcode.model import design_job
from camfab.gcode.rotary import cylinder_job, rotary_gcode
from camfab.gcode.rotary_verify import verify_rotary_program
from camfab.gcode.verify import VerifyReport

EXAMPLE = "cylindrical_translating"


@pytest.fixture(scope="module")
def setup():
    cam = pipeline.load(EXAMPLE)
    tol = cam.tolerance()
    job = cylinder_job(design_job(cam.spec, tol=tol), cam.geometry)
    data, _, _ = rotary_gcode(cam.geometry, job, tol, "linuxcnc")
    return cam.geometry, job, tol, data.decode()


def _verify(setup, text):
    geometry, job, tol, _ = setup
    return verify_rotary_program(text, geometry, job, tol=tol)


def _line_index(lines, pattern, after=0):
    return next(i for i in range(after, len(lines)) if re.search(pattern, lines[i]))


def test_the_written_program_passes_with_the_plate_verify_keys(tmp_path, capsys):
    prog = tmp_path / "b.ngc"
    for post in ("linuxcnc", "fanuc"):
        assert main(["gcode", EXAMPLE, "-o", str(prog), "--post", post]) in (0, 1)
        capsys.readouterr()
        assert main(["verify", str(prog), "--design", EXAMPLE, "--json"]) == 0
        rep = json.loads(capsys.readouterr().out)
        plate = VerifyReport(None, False, None, (), 0.01).to_dict()
        assert set(plate) <= set(rep) and rep["ok"] and not rep["problems"] and not rep["gouge"]
        assert rep["max_deviation_mm"] <= rep["tolerance_mm"] and rep["coverage_gap_mm"] <= rep["tolerance_mm"]
        r = rep["rotary"]
        assert r["centre_levels"] == [42.5, 40.0, 37.5, 35.0] and r["finishing_passes"] == 2
        assert r["max_penetration_mm"] <= rep["tolerance_mm"] and r["deepest_tip_radius_mm"] == 35.0


def test_a_shifted_a_word_fails(setup):
    lines = setup[3].splitlines()
    i = _line_index(lines, r"^G1 X30\.0000 A-70\.0000")  # mid-rise on the first level: the slope is steep
    lines[i] = lines[i].replace("A-70.0000", "A-70.5000")
    rep = _verify(setup, "\n".join(lines))
    assert not rep.ok and "DEVIATION" in rep.codes() and any(p.line == i + 1 for p in rep.problems)


def test_a_missing_block_fails(setup):
    lines = setup[3].splitlines()
    bottom = _line_index(lines, r"centre pass level 4")
    last = _line_index(lines, r"^G94", bottom) - 1  # the move that closes the turn on the groove bottom
    rep = _verify(setup, "\n".join(lines[:last] + lines[last + 1:]))
    assert not rep.ok and "COVERAGE" in rep.codes()
    fin = _line_index(lines, r"finishing pass \+z")
    mid = _line_index(lines, r"^G1 X\S+ A", _line_index(lines, r"^G93", fin)) + 14  # a block mid-rise
    rep = _verify(setup, "\n".join(lines[:mid] + lines[mid + 1:]))
    assert not rep.ok and {"DEVIATION", "FEED_OUT_OF_RANGE"} & rep.codes()


def test_a_wrong_depth_fails(setup):
    text = setup[3]
    fin = text.index("(finishing pass +z")
    deeper = text[:fin] + text[fin:].replace("G1 Z35.0000", "G1 Z34.9000", 1)
    assert {"TOO_DEEP", "FINISH_DEPTH"} <= _verify(setup, deeper).codes()
    bottom = text.index("(centre pass level 4")
    shallow = text[:bottom] + text[bottom:fin].replace("G1 Z35.0000", "G1 Z35.5000", 1) + text[fin:]
    assert "FINISH_DEPTH" in _verify(setup, shallow).codes()


def test_a_flank_pass_moved_into_the_flank_gouges(setup):
    text = setup[3]
    fin = text.index("(finishing pass +z")
    end = text.index("(finishing pass -z")

    def shift(m):  # the whole +z pass 0.05 mm towards +z (the cylinder's axis)
        return f"X{float(m.group(1)) + 0.05:.4f}"

    moved = text[:fin] + re.sub(r"X([0-9.]+)", shift, text[fin:end]) + text[end:]
    rep = _verify(setup, moved)
    assert rep.gouge and "GOUGE" in rep.codes() and rep.gouge_at["penetration_mm"] > 0.03


def test_a_reversed_flank_pass_is_the_wrong_milling_direction(setup):
    geometry, job, tol, _ = setup
    import dataclasses

    conv = rotary_gcode(geometry, dataclasses.replace(job, direction="conventional"), tol, "linuxcnc")[0]
    assert verify_rotary_program(conv, geometry, job, tol=tol).codes() == {"DIRECTION"}


def test_an_unreadable_program_and_grbl_are_refused(setup, tmp_path, capsys):
    rep = _verify(setup, setup[3].replace("G1 Z35.0000", "G2 Z35.0000", 1))
    assert rep.codes() == {"PARSE_ERROR"} and "G2" in rep.problems[0].message
    prog = tmp_path / "b.ngc"
    prog.write_text(setup[3])
    assert main(["verify", str(prog), "--design", EXAMPLE, "--post", "grbl"]) == 2
    assert "rotary" in capsys.readouterr().err
