"""The command line: exit codes, CSV contract, JSON contract, nothing written on error."""
from __future__ import annotations

import csv
import json
import math

import numpy as np
import pytest

from camfab.cli import main
from camfab.formats import load_design
from tests.conftest import EXAMPLES


def test_version(capsys):
    assert main(["--version"]) == 0
    assert "camfab" in capsys.readouterr().out


def test_no_command_is_usage_error():
    assert main([]) == 2


def test_motion_table_and_verdict(capsys):
    assert main(["motion", "ejemplo9rt"]) == 0
    out = capsys.readouterr().out
    assert "Modified Sine Curve" in out and "Verdict: not_for_high_speed" in out
    assert "Junctions:" in out


def test_motion_json_contract(capsys):
    assert main(["motion", str(EXAMPLES / "ejemplo9rt.toml"), "--json", "--peaks", "camdas"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["verdict"] in ("acceptable", "not_for_high_speed", "unacceptable")
    for q in "SVAJ":
        assert set(data["peaks"][q]) >= {"max", "min", "at_max_deg", "at_min_deg"}
    # the 9RT reference row derived from the thesis' inputs (§7.4.9), 1° sampling, ω = 1
    assert round(data["peaks"]["V"]["max"], 2) == 21.49
    assert round(data["peaks"]["V"]["min"], 2) == -25.07
    assert round(data["peaks"]["J"]["max"], 2) == 1045.28
    assert [j["at_deg"] for j in data["junctions"]] == [0, 50, 90, 140, 180, 230, 270, 320]
    assert all(j["continuity"] in ("C2", "C3") for j in data["junctions"])
    assert len(data["segments"]) == 8


def test_motion_csv_matches_engine_in_time_units(tmp_path):
    out = tmp_path / "m.csv"
    d = tmp_path / "fast.toml"
    d.write_text((EXAMPLES / "ejemplo9rt.toml").read_text().replace("omega_rad_s = 1.0", "speed_rpm = 300.0"))
    assert main(["motion", str(d), "--csv", str(out), "--step-deg", "0.5"]) == 0
    rows = list(csv.reader(out.open()))
    assert rows[0] == ["angle_deg", "S", "V", "A", "J"]
    data = np.array(rows[1:], dtype=float)
    assert data.shape == (721, 5) and data[-1, 0] == 360.0
    prog = load_design(d).program()
    w = 300 * 2 * math.pi / 60
    ref = prog.evaluate(np.radians(data[:, 0])) * (w ** np.arange(4))[:, None]
    np.testing.assert_allclose(data[:, 1:], ref.T, rtol=1e-9, atol=1e-9)


def test_invalid_design_exit_2_and_no_output(tmp_path, capsys):
    bad = tmp_path / "bad.toml"
    bad.write_text((EXAMPLES / "ejemplo9rt.toml").read_text().replace("angle_deg = 40.0", "angle_deg = 41.0", 1))
    out = tmp_path / "m.csv"
    assert main(["motion", str(bad), "--csv", str(out)]) == 2
    err = capsys.readouterr().err
    assert "motion[*].angle_deg" in err and "360" in err
    assert not out.exists()


def test_unacceptable_motion_exit_1(tmp_path, capsys):
    p = tmp_path / "cv.toml"
    p.write_text("""name = "cv"
[follower]
type = "roller"
motion = "translating"
base_radius_mm = 40.0
roller_radius_mm = 5.0
[[motion]]
law = "constant_velocity"
lift = 10.0
angle_deg = 90.0
[[motion]]
law = "dwell"
angle_deg = 90.0
[[motion]]
law = "cycloidal"
lift = -10.0
angle_deg = 180.0
""")
    assert main(["motion", str(p), "--json"]) == 1
    data = json.loads(capsys.readouterr().out)
    assert data["verdict"] == "unacceptable"
    codes = {f["code"] for f in data["findings"]}
    assert "VELOCITY_DISCONTINUITY" in codes


@pytest.mark.parametrize("step", ["0", "-1", "nan"])
def test_bad_step_is_usage_error(step, tmp_path):
    out = tmp_path / "m.csv"
    assert main(["motion", "ejemplo9rt", "--step-deg", step, "--csv", str(out)]) == 2
    assert not out.exists()


def test_unwritable_csv_is_io_error(tmp_path):
    target = tmp_path / "file"
    target.write_text("x")
    assert main(["motion", "ejemplo9rt", "--csv", str(target / "sub" / "m.csv")]) == 3


def test_knot_table_inconsistency_is_reported(tmp_path, capsys):
    # a 2° knot segment asked to rise 1 mm with zero velocity and tiny accelerations at its knots
    p = tmp_path / "k.toml"
    p.write_text("""name = "k"
[follower]
type = "flat"
motion = "translating"
base_radius_mm = 20.0
[motion_table]
rows = [[0, 0, 0, 0], [90, 1, 0, 0.001], [92, 2, 0, 0.001], [180, 0, 0, 0]]
units = { angle = "deg", s = "mm", v = "mm/deg", a = "mm/deg2" }
""")
    assert main(["motion", str(p), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    codes = [f["code"] for f in data["findings"]]
    assert "KNOT_INCONSISTENT" in codes


@pytest.mark.parametrize("argv", [["--help"], ["-v", "--help"], ["chek", "x"], ["check", "ejemplo9rt", "--bogus"],
                                  ["check"], ["-v", "export", "--help"], ["gcode", "--post", "nope", "x"]])
def test_the_parser_of_one_command_answers_as_the_full_parser(argv, capsys):
    """``main`` builds only the parser of the command being run: help, usage and errors are the same text as
    with every command's parser."""
    from camfab.cli import COMMANDS, build_parser

    def answer(parser):
        with pytest.raises(SystemExit) as exc:
            parser.parse_args(argv)
        out = capsys.readouterr()
        return exc.value.code, out.out, out.err

    full, one = answer(build_parser()), answer(build_parser(argv))
    assert one == full
    assert full[0] in (0, 2) and (full[1] or full[2])
    if argv[-1] == "--help" and len(argv) > 1 and argv[-2] in COMMANDS:
        assert f"usage: camfab {argv[-2]}" in full[1]
