"""Cam designs → G-code through every post, back-plotted against the exact design (camfab gcode/verify)."""
from __future__ import annotations

import json
import re

import numpy as np
import pytest

from camfab.cli import main
from camfab.design.assemble import geometry_from_spec
from camfab.formats import load_design
from camfab.gcode import Job, dumps, parse, verify
from camfab.gcode.cam import cam_program, signed_distance
from camfab.offset.cutter import offset_curve, profile_curve
from tests.conftest import DESIGNS, EXAMPLES

TOL, R_TOOL = 1e-3, 3.0


_DIST: dict = {}


def _distances(contact, r_tool):
    key = (id(contact), r_tool)
    if key not in _DIST:
        _DIST[key] = (signed_distance(profile_curve(contact), tol=TOL),
                      signed_distance(offset_curve(contact, r_tool), tol=TOL))
    return _DIST[key]


def _verify(text, contact, r_tool=R_TOOL, centre=None):
    if centre is None:
        part, centre = _distances(contact, r_tool)
    else:
        part = _distances(contact, R_TOOL)[0]
    return verify(parse(text), exact_curve_distance=centre, part_distance=part, tool_radius=r_tool, tol=TOL,
                  safe_z=25.0)


@pytest.fixture(scope="module")
def programs():
    out = {}
    for name, make in DESIGNS.items():
        spec = make()
        contact = geometry_from_spec(spec).profiles[0]
        job = Job(tool_diameter_mm=2 * R_TOOL, depth_mm=spec.manufacturing.thickness_mm, tolerance_mm=TOL,
                  design_name=spec.name)
        out[name] = (contact, cam_program(contact, job, tol=TOL))
    return out


@pytest.mark.parametrize("name", sorted(DESIGNS))
@pytest.mark.parametrize("post", ["linuxcnc", "fanuc", "grbl"])
def test_every_example_and_post_verifies(programs, name, post):
    contact, cp = programs[name]
    text = dumps(cp.program, post)
    rep = _verify(text, contact)
    assert rep.ok, rep.to_dict()["problems"]
    assert rep.max_deviation_mm <= TOL and not rep.gouge
    assert text == dumps(cp.program, post)  # byte-identical


def test_moved_arc_centre_and_missing_retract_are_caught(programs):
    contact, cp = programs["ejemplo9rt"]
    lines = dumps(cp.program, "linuxcnc").splitlines()
    # the tightest finishing arc, its centre moved 0.01 mm along the radius through the chord midpoint
    start = lines.index("(FINISH CONTOUR)")
    arcs = [i for i in range(start, len(lines)) if re.search(r"\bG0?[23]\b.* I", lines[i])]
    ij = {i: np.array([float(v) for v in re.findall(r"[IJ](-?[\d.]+)", lines[i])]) for i in arcs}
    k = min(arcs, key=lambda i: np.hypot(*ij[i]))
    moved = list(lines)
    shift = -0.01 * ij[k] / np.hypot(*ij[k])
    moved[k] = re.sub(r"I(-?[\d.]+) J(-?[\d.]+)",
                      f"I{ij[k][0] + shift[0]:.4f} J{ij[k][1] + shift[1]:.4f}", moved[k])
    rep = _verify("\n".join(moved) + "\n", contact)
    assert not rep.ok
    assert {p.code for p in rep.problems} & {"DEVIATION", "ARC_RADIUS_MISMATCH"}
    # drop the retract after the roughing pass: the next rapid runs at cutting depth through the part
    k = next(i for i, ln in enumerate(lines) if "ROUGH LEAD-OUT" in ln)
    r = next(i for i in range(k, len(lines)) if re.search(r"G0 Z25", lines[i]))
    broken = lines[:r] + lines[r + 1:]
    rep = _verify("\n".join(broken) + "\n", contact)
    assert not rep.ok
    assert any("RAPID" in p.code for p in rep.problems)


def test_cutter_larger_than_concave_radius_gouges(programs):
    """A tool-centre path for a 50 mm cutter (concave radius 47.5 mm) must be flagged as a gouge."""
    contact, _ = programs["ejemplo9rt"]
    r = 50.0
    pts = offset_curve(contact, r).point(np.linspace(0, 2 * np.pi, 3601))
    body = [f"G1 X{x:.4f} Y{y:.4f}" for x, y in pts]
    text = "\n".join(["G17 G21 G40 G54 G90 G94", "S3000 M3", "G0 Z25", f"G0 X{pts[0, 0]:.4f} Y{pts[0, 1]:.4f}",
                      "G1 Z-10 F200", "(FINISH CONTOUR)", "F600", *body, "G0 Z25", "M5", "M2"]) + "\n"
    # the offset by 50 mm folds over itself; measure the centre path against the part distance - r
    part = _distances(contact, R_TOOL)[0]
    rep = _verify(text, contact, r_tool=r, centre=lambda p: part(p) - r)
    assert rep.gouge and not rep.ok
    assert rep.gouge_at["penetration_mm"] > TOL


def test_cli_gcode_verify_roundtrip(tmp_path, capsys):
    out = tmp_path / "c.nc"
    lift = tmp_path / "lift.csv"
    assert main(["gcode", "ejemplo9rt", "--post", "grbl", "-o", str(out), "--lift-table", str(lift),
                 "--lift-step", "0.5"]) == 0
    capsys.readouterr()
    assert main(["verify", str(out), "--design", "ejemplo9rt", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["ok"]
    rows = [r for r in lift.read_text().splitlines() if not r.startswith("#")]
    assert rows[0] == "angle_deg,lift_mm,radius_mm" and len(rows) == 721
    prog = load_design(EXAMPLES / "ejemplo9rt.toml").program()
    a, s = map(float, rows[101].split(",")[:2])
    assert s == pytest.approx(float(prog(np.radians(a))[0]), abs=5e-7)


def test_cli_compensated_program_is_simulated(tmp_path, capsys):
    out = tmp_path / "c.nc"
    assert main(["gcode", "ejemplo9rt", "--compensation", "G41", "-o", str(out)]) == 0
    capsys.readouterr()
    assert main(["verify", str(out), "--design", "ejemplo9rt", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["ok"]
    # the controller holding a radius 0.01 mm too large leaves the part 0.01 mm oversize
    assert main(["verify", str(out), "--design", "ejemplo9rt", "--json", "--comp-radius", "3.01"]) == 1
    data = json.loads(capsys.readouterr().out)
    assert data["max_deviation_mm"] == pytest.approx(0.01, abs=2e-3)
    # the wrong side cuts into the part
    out.write_text(out.read_text().replace("G41", "G42"))
    assert main(["verify", str(out), "--design", "ejemplo9rt", "--json"]) == 1
    codes = {p["code"] for p in json.loads(capsys.readouterr().out)["problems"]}
    assert {"GOUGE", "COMP_WRONG_SIDE"} <= codes
    assert main(["verify", str(out), "--design", "ejemplo9rt", "--comp-radius", "-1"]) == 2


def test_cli_verify_json_and_failure_exit(tmp_path, capsys):
    out = tmp_path / "c.nc"
    assert main(["gcode", "ejemplo9rt", "-o", str(out)]) == 0
    capsys.readouterr()
    assert main(["verify", str(out), "--design", "ejemplo9rt", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["ok"] and d["max_deviation_mm"] <= 1e-3 and d["gouge"] is False
    text = out.read_text().replace("G0 Z25.0000", "G0 Z5.0000")
    out.write_text(text)
    assert main(["verify", str(out), "--design", "ejemplo9rt", "--json"]) == 1
    assert json.loads(capsys.readouterr().out)["problems"]


def test_cli_gcode_refuses_big_tool_and_unacceptable(tmp_path, capsys):
    out = tmp_path / "c.nc"
    # (the cutting data given: a 100 mm tool is beyond the cutting-data table, refused by that first otherwise)
    assert main(["gcode", "ejemplo9rt", "--tool-diameter", "100", "--rpm", "300", "--feed", "200", "--plunge-feed",
                 "100", "-o", str(out)]) == 2
    assert "largest cutter" in capsys.readouterr().err and not out.exists()
    d = tmp_path / "bad.toml"
    d.write_text((EXAMPLES / "ejemplo9rt.toml").read_text().replace("base_radius_mm = 35.0", "base_radius_mm = 12.0"))
    assert main(["gcode", str(d), "-o", str(out)]) == 1
    assert "nothing written" in capsys.readouterr().err and not out.exists()


def test_lines_only_program_verifies_and_has_no_arcs_in_the_finish(programs):
    contact, _ = programs["ejemplo9rt"]
    job = Job(tool_diameter_mm=2 * R_TOOL, depth_mm=10.0, tolerance_mm=TOL)
    cp = cam_program(contact, job, tol=TOL, arcs_allowed=False)
    text = dumps(cp.program, "linuxcnc")
    lines = text.splitlines()
    start = lines.index("(FINISH CONTOUR)")
    end = next(i for i in range(start + 1, len(lines)) if lines[i].startswith("(") and "LEAD-OUT" in lines[i])
    assert not any(re.search(r"\bG0?[23]\b", ln) for ln in lines[start + 1:end])
    rep = _verify(text, contact)
    assert rep.ok and rep.max_deviation_mm <= TOL
    assert cp.entities > 300  # a polyline needs far more moves than the ~90 arcs


def _millable_examples():
    out = []
    for p in sorted(EXAMPLES.glob("*.toml")):
        spec = load_design(p)
        if spec.manufacturing.tool_diameter_mm and spec.cam.kind != "cylindrical":  # its 4-axis program: test_rotary
            out.append(p.stem)
    return out


@pytest.mark.slow
@pytest.mark.parametrize("name", _millable_examples())
def test_every_example_design_verifies_with_every_post(name):
    spec = load_design(EXAMPLES / f"{name}.toml")
    geom = geometry_from_spec(spec)
    tol = spec.manufacturing.tolerance_mm
    tool = spec.manufacturing.tool_diameter_mm
    job = Job(tool_diameter_mm=tool, depth_mm=spec.follower.groove_depth_mm or spec.manufacturing.thickness_mm,
              tolerance_mm=tol, design_name=spec.name)
    if spec.cam.kind == "groove":  # one program mills the slot; both flanks are its targets
        from camfab.gcode.groove import groove_program, verify_groove_program

        cp = groove_program(*geom.profiles, job, tol=tol)
        for post in ("linuxcnc", "fanuc", "grbl"):
            rep = verify_groove_program(dumps(cp.program, post), *geom.profiles, job, tol=tol, post=post)
            assert rep.ok, (name, post, rep.to_dict()["problems"])
        return
    for contact in geom.profiles:
        cp = cam_program(contact, job, tol=tol)
        part = signed_distance(profile_curve(contact), tol=tol)
        centre = signed_distance(offset_curve(contact, tool / 2), tol=tol)
        for post in ("linuxcnc", "fanuc", "grbl"):
            rep = verify(parse(dumps(cp.program, post)), exact_curve_distance=centre, part_distance=part,
                         tool_radius=tool / 2, tol=tol, safe_z=job.safe_z_mm)
            assert rep.ok, (name, post, rep.to_dict()["problems"])
            assert rep.max_deviation_mm <= tol and not rep.gouge
