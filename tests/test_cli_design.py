"""``camfab size`` and ``camfab optimise`` from the command line: exit codes, JSON, the files written (and none on
bad input), determinism."""
from __future__ import annotations

import json
import tomllib

import pytest

from camfab.cli import main
from camfab.formats.toml_write import dumps_design

from .conftest import EJEMPLO9RT


def _design(tmp_path, name="e9.toml", **over):
    data = {"name": "E9 \"sized\"\n[cam]", "cam": {"kind": "disc", "speed_rpm": 100},
            "follower": {"type": "roller", "motion": "translating", "base_radius_mm": 35.0, "roller_radius_mm": 7.0},
            "motion": [{"law": law, "lift": float(h), "angle_deg": float(a)} for law, h, a in EJEMPLO9RT],
            "manufacturing": {"tool_diameter_mm": 6.0}}
    data.update(over)
    p = tmp_path / name
    p.write_text(dumps_design(data), encoding="utf-8")
    return p


def test_size_json_and_written_design_meets_the_constraints(tmp_path, capsys):
    src = _design(tmp_path)
    out = tmp_path / "sized.toml"
    assert main(["size", str(src), "-o", str(out), "--json"]) == 0
    res = json.loads(capsys.readouterr().out)
    assert res["governing"] == "pressure_angle" and res["written"] == str(out)
    gov = [c for c in res["constraints"] if c["governing"]]
    assert len(gov) == 1 and gov[0]["constraint"] == "pressure_angle"
    data = tomllib.loads(out.read_text(encoding="utf-8"))
    assert data["follower"]["base_radius_mm"] == res["base_radius_mm"]
    assert data["name"] == "E9 \"sized\"\n[cam]" and set(data) == set(tomllib.loads(src.read_text()))
    assert main(["check", str(out), "--json"]) == 0
    chk = json.loads(capsys.readouterr().out)
    assert chk["pressure_angle_deg"]["max"] <= 30.0 and abs(chk["pressure_angle_deg"]["min"]) <= 30.0
    assert not {f["code"] for f in chk["findings"]} & {"PRESSURE_ANGLE_EXCEEDED", "UNDERCUT", "CUSP"}


def test_size_writes_the_same_bytes_twice(tmp_path, capsys):
    src = _design(tmp_path, sizing={"set_offset": True})
    a, b = tmp_path / "a.toml", tmp_path / "b.toml"
    assert main(["size", str(src), "-o", str(a)]) == 0 and main(["size", str(src), "-o", str(b)]) == 0
    assert a.read_bytes() == b.read_bytes()
    assert tomllib.loads(a.read_text(encoding="utf-8"))["follower"]["offset_mm"] != 0.0


def test_size_table_text(capsys):
    assert main(["size", "valve_exhaust_ej1"]) == 0
    out = capsys.readouterr().out
    # the cusp radius leaves a point of infinite Hertz stress: the contact stress governs, just above it
    assert "governing: contact_stress" in out and "← governs" in out and "cusp" in out


@pytest.mark.parametrize("over,path", [
    ({"sizing": {"constraints": ["bogus"]}}, "sizing.constraints[0]"),
    ({"sizing": {"constraints": ["cusp"]}}, "sizing.constraints[0]"),
    ({"sizing": {"pressure_angle_limit_deg": 95}}, "sizing.pressure_angle_limit_deg"),
])
def test_size_bad_input_exit_2_nothing_written(tmp_path, capsys, over, path):
    src = _design(tmp_path, **over)
    out = tmp_path / "sized.toml"
    assert main(["size", str(src), "-o", str(out), "--json"]) == 2
    cap = capsys.readouterr()
    assert path in cap.err and not out.exists()
    assert main(["size", str(src), "-o", str(tmp_path / "x.txt")]) == 2


def test_size_refuses_to_overwrite_its_input(tmp_path, capsys):
    src = _design(tmp_path)
    before = src.read_bytes()
    assert main(["size", str(src), "-o", str(src)]) == 2
    assert src.read_bytes() == before and "new file name" in capsys.readouterr().err


OPT = {"variables": [{"name": f"motion[{i}].angle_deg", "lo": 30.0, "hi": 70.0} for i in range(4)]
       + [{"name": "follower.base_radius_mm", "lo": 32.0, "hi": 40.0}],
       "objectives": {"peak_pressure_angle_deg": 1.0, "peak_acceleration": 0.5},
       "pareto": ["peak_pressure_angle_deg", "peak_acceleration"], "pareto_points": 3}


def test_optimise_writes_design_report_and_pareto(tmp_path, capsys):
    src = _design(tmp_path, optimise=OPT)
    out = tmp_path / "out"
    assert main(["optimise", str(src), "-o", str(out), "--json"]) == 0
    res = json.loads(capsys.readouterr().out)
    assert res["improved"] and res["score"] < res["score_start"]
    names = sorted(p.relative_to(out).as_posix() for p in out.rglob("*") if p.is_file())
    design = [n for n in names if n.endswith("_optimised.toml")]
    assert len(design) == 1 and "compare.html" in names and "plots/pareto.svg" in names and "optimise.json" in names
    assert len(res["pareto"]["points"]) == 3
    assert main(["check", str(out / design[0])]) in (0, 1)  # the written design re-loads
    capsys.readouterr()
    html = (out / "compare.html").read_text(encoding="utf-8")
    assert "E9 &#34;sized&#34;" in html and 'E9 "sized"' not in html  # the hostile name autoescaped


def test_optimise_is_deterministic(tmp_path, capsys):
    src = _design(tmp_path, optimise={**OPT, "pareto_points": 2})
    a, b = tmp_path / "a", tmp_path / "b"
    assert main(["optimise", str(src), "-o", str(a)]) == 0
    assert main(["optimise", str(src), "-o", str(b)]) == 0
    files = sorted(p.relative_to(a) for p in a.rglob("*") if p.is_file())
    assert files and all((a / f).read_bytes() == (b / f).read_bytes() for f in files)


@pytest.mark.parametrize("opt,path", [
    ({"variables": [{"name": "motion[0].angel_deg", "lo": 30, "hi": 70}]}, "optimise.variables[0].name"),
    ({"variables": [{"name": "follower.base_radius_mm", "lo": 36, "hi": 40}]}, "optimise.variables[0].lo"),
    ({"variables": OPT["variables"], "constraints": {"min_radius_mm": 500.0}}, "optimise.constraints.min_radius_mm"),
])
def test_optimise_bad_input_exit_2_nothing_written(tmp_path, capsys, opt, path):
    src = _design(tmp_path, optimise=opt)
    out = tmp_path / "out"
    assert main(["optimise", str(src), "-o", str(out), "--json"]) == 2
    cap = capsys.readouterr()
    assert path in cap.err and not out.exists()
    assert any(p["path"] == path for p in json.loads(cap.out)["problems"])


def test_optimise_without_table_exit_2(tmp_path, capsys):
    assert main(["optimise", str(_design(tmp_path)), "-o", str(tmp_path / "o")]) == 2
    assert "[optimise]" in capsys.readouterr().err and not (tmp_path / "o").exists()
