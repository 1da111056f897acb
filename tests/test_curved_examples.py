"""The curved-face examples (``valve_mushroom``, ``finger_follower``) through ``camfab run`` with every output:
each artifact read back independently and compared with the exact geometry, and the words that name the
curved face in the workbook, the drawing and the report."""
from __future__ import annotations

import json
import math
import re

import numpy as np
import pytest

from camfab.cad.plate import PlateSpec
from camfab.cli import main
from camfab.design.assemble import check_design, geometry_from_spec
from camfab.discretize import Chain, measure_deviation
from camfab.formats import load_design
from camfab.offset.cutter import pitch_curve, profile_curve
from tests.conftest import EXAMPLES

ezdxf = pytest.importorskip("ezdxf")
trimesh = pytest.importorskip("trimesh")
openpyxl = pytest.importorskip("openpyxl")

CURVED = ("valve_mushroom", "finger_follower")
ALL = "dxf,step,stl,gcode,lift_table,xlsx,report,drawing"


@pytest.fixture(scope="module", params=CURVED)
def run(request, tmp_path_factory):
    """(name, spec, geometry, output directory) of one example after ``camfab run`` with every output."""
    name = request.param
    out = tmp_path_factory.mktemp(name)
    assert main(["run", name, "-o", str(out), "--outputs", ALL]) == 0  # acceptable: nothing withheld
    spec = load_design(EXAMPLES / f"{name}.toml")
    return name, spec, geometry_from_spec(spec), out


def _one(out, pattern):
    (path,) = out.glob(pattern)
    return path


def test_examples_are_acceptable_curved_faces(run):
    name, spec, geom, out = run
    c = geom.profiles[0]
    assert spec.follower.type == "curved" and c.curved_face and c.sliding
    assert c.oscillating is (name == "finger_follower")
    rep = json.loads((out / "check.json").read_text())
    assert rep["verdict"] == "acceptable" and rep["dynamics"]["contact_force_n"]["min"] >= 100.0
    assert not [f for f in rep["findings"] if f["severity"] != "info"]
    assert {f["code"] for f in rep["findings"]} == {"FACE_LENGTH"}
    names = {p.name for p in out.rglob("*") if p.is_file()}
    for suffix in (".dxf", ".step", ".stl", ".nc", ".xlsx", "_drawing.dxf", "_lift.csv"):
        assert f"{spec.name}{suffix}" in names
    assert {"report.html", "check.json", "face_position.svg", "dynamics.svg"} <= names


def test_dxf_profile_and_face_centre_path_read_back_within_tol(run):
    name, spec, geom, out = run
    tol = spec.manufacturing.tolerance_mm
    c = geom.profiles[0]
    doc = ezdxf.readfile(_one(out, f"{spec.name}.dxf"))
    assert doc.header["$INSUNITS"] == 4 and not doc.audit().has_errors
    (pl,) = doc.modelspace().query("LWPOLYLINE[layer=='PROFILE']")
    rows = np.array(list(pl.get_points("xyb")))
    assert measure_deviation(rows, profile_curve(c)).max <= tol
    # the pitch curve of a curved face is the path of its centre of curvature, R outside the profile
    (pc,) = doc.modelspace().query("LWPOLYLINE[layer=='PITCH_CURVE']")
    prow = np.array(list(pc.get_points("xyb")))
    assert measure_deviation(prow, pitch_curve(c)).max <= tol
    pts = Chain.from_bulges(prow).sample(40)[0]
    far = c.evaluate(np.linspace(0, 2 * np.pi, 3601)).pitch
    assert np.abs(np.hypot(*pts.T).max() - np.hypot(*far.T).max()) < 10 * tol
    circles = {e.dxf.layer: e.dxf.radius for e in doc.modelspace().query("CIRCLE")}
    assert circles["BASE_CIRCLE"] == spec.follower.base_radius_mm
    assert circles["PRIME_CIRCLE"] == spec.follower.base_radius_mm + spec.follower.face_radius_mm


def test_stl_is_closed_and_on_the_profile(run):
    name, spec, geom, out = run
    m = spec.manufacturing
    mesh = trimesh.load(_one(out, "*.stl"))
    assert mesh.is_watertight and mesh.is_winding_consistent and mesh.volume > 0
    assert mesh.bounds[1][2] == pytest.approx(m.thickness_mm) and mesh.bounds[0][2] == pytest.approx(0.0)
    top = mesh.vertices[np.isclose(mesh.vertices[:, 2], m.thickness_mm)][:, :2]
    outer = top[np.hypot(*top.T) > m.bore_mm]
    assert measure_deviation(outer[np.argsort(np.arctan2(outer[:, 1], outer[:, 0]))],
                             profile_curve(geom.profiles[0])).max <= m.tolerance_mm
    hole = PlateSpec(m.thickness_mm, m.bore_mm, m.keyway).hole().area()  # bore and keyseat
    perimeter = 2 * math.pi * (geom.max_radius + m.bore_mm)
    assert abs(mesh.volume - (geom.area() - hole) * m.thickness_mm) <= perimeter * m.tolerance_mm * m.thickness_mm


@pytest.mark.slow
def test_step_is_a_valid_solid_of_the_plate(run):
    cq = pytest.importorskip("cadquery")
    name, spec, geom, out = run
    solid = cq.importers.importStep(str(_one(out, "*.step"))).val()
    assert solid.isValid()
    m = spec.manufacturing
    mesh = trimesh.load(_one(out, "*.stl"))
    assert solid.Volume() == pytest.approx(mesh.volume, rel=1e-4)
    assert solid.BoundingBox().zlen == pytest.approx(m.thickness_mm)


def test_gcode_verifies_against_the_exact_profile(run, capsys):
    name, spec, geom, out = run
    nc = _one(out, "*.nc")
    capsys.readouterr()
    assert main(["verify", str(nc), "--design", name, "--json"]) == 0
    rep = json.loads(capsys.readouterr().out)
    assert rep["ok"] and not rep["gouge"] and rep["problems"] == []
    assert rep["max_deviation_mm"] <= spec.manufacturing.tolerance_mm


def test_lift_table_csv(run):
    name, spec, geom, out = run
    lines = [ln for ln in _one(out, "*_lift.csv").read_text().splitlines() if not ln.startswith("#")]
    unit = "deg" if name == "finger_follower" else "mm"
    assert lines[0] == f"angle_deg,lift_{unit},radius_mm"
    table = np.array([[float(v) for v in ln.split(",")] for ln in lines[1:]])
    S = spec.program().evaluate(np.radians(table[:, 0]))[0]
    assert table[:, 2].min() >= (spec.follower.base_radius_mm or 0.0) - 1e-6  # the contact never inside the base circle
    np.testing.assert_allclose(table[:, 1], S, atol=6e-7)


def test_workbook_names_the_curved_face(run):
    name, spec, geom, out = run
    c = geom.profiles[0]
    wb = openpyxl.load_workbook(_one(out, "*.xlsx"))
    ws = wb["CAM-DAS"]
    motion = "oscillating" if c.oscillating else "translating"
    assert ws["A1"].value == f"Rotating disc cam (clockwise) with curved-face follower, {motion} motion"
    rows = {ws.cell(r, 1).value.split(" = ")[0]: ws.cell(r, 2).value for r in range(4, 8) if ws.cell(r, 1).value}
    f = spec.follower
    assert rows["Base radius R_b"] == f.base_radius_mm and rows["Face radius R"] == f.face_radius_mm
    if c.oscillating:
        assert rows["Pivot distance PivCen"] == f.pivot_distance_mm
        assert rows["Face offset (Excentricidad)"] == f.face_offset_mm
        assert ws["H9"].value == "Contact arc length from the face vertex (mm)"
    else:
        assert rows["Offset e"] == f.offset_mm
        assert rows["Face-centre circle R_b + R"] == f.base_radius_mm + f.face_radius_mm
        assert ws["H9"].value == "Contact position from the stem axis, + right (mm)"
    assert ws["G9"].value == "Pressure angle (deg)" and ws["O9"].value == "Face centre radius (mm)"
    x = np.radians(np.arange(0.0, 361.0))
    smp = c.evaluate(x)
    got = np.array([[ws.cell(10 + i, col).value for col in (7, 8, 15)] for i in range(361)], dtype=float)
    np.testing.assert_allclose(got[:, 0], np.degrees(smp.pressure_angle), atol=1e-9)
    np.testing.assert_allclose(got[:, 1], smp.face_position, atol=1e-9)
    np.testing.assert_allclose(got[:, 2], np.hypot(*smp.pitch.T), atol=1e-9)
    assert wb["Lift table"]["C1"].value == "Face-centre radius (mm)"
    assert "Dynamics" in wb.sheetnames and wb["Dynamics"]["C1"].value == "Friction force (N)"
    friction = [r[2] for r in wb["Dynamics"].iter_rows(min_row=2, values_only=True)]
    assert min(friction) > 0  # the face slides: μN everywhere


def test_drawing_names_the_curved_face_and_draws_its_centre_circle(run):
    name, spec, geom, out = run
    f, c = spec.follower, geom.profiles[0]
    doc = ezdxf.readfile(_one(out, "*_drawing.dxf"))
    assert not doc.audit().has_errors
    text = doc.modelspace().query("MTEXT[layer=='NOTES']")[0].plain_text()
    text = " ".join(line.strip() for line in text.splitlines())  # the notes are wrapped to their column
    assert f"{f.motion} curved-face follower, face radius R{f.face_radius_mm:g} mm" in text
    assert "roller" not in text
    assert f"Face-centre circle (chain line) R{f.base_radius_mm + f.face_radius_mm:g} mm" in text
    assert "RADIUS = distance of the face's centre of curvature from the cam centre" in text
    cv = doc.header.custom_vars
    scale = float(cv.get("CAMFAB_SCALE"))
    centre = np.array([float(v) for v in cv.get("CAMFAB_CENTRE").split(",")])
    prime = list(doc.modelspace().query("CIRCLE ARC").filter(lambda e: e.dxf.layer == "PRIME_CIRCLE"))
    assert prime
    for e in prime:
        assert e.dxf.radius == pytest.approx((f.base_radius_mm + f.face_radius_mm) * scale)
        assert np.allclose(tuple(e.dxf.center)[:2], centre)
    (pl,) = doc.modelspace().query("LWPOLYLINE[layer=='PROFILE']")
    rows = np.array(list(pl.get_points("xyb")))
    true = np.column_stack([(rows[:, :2] - centre) / scale, rows[:, 2]])
    assert measure_deviation(true, profile_curve(c)).max <= spec.manufacturing.tolerance_mm + 1e-9
    # the lift table's RADIUS column is the face centre's distance from the cam centre
    radius = [float(e.dxf.text) for e in doc.modelspace().query("TEXT[layer=='LIFT_TABLE']")
              if re.fullmatch(r"\d+\.\d{3}", e.dxf.text) and float(e.dxf.text) >= f.base_radius_mm + f.face_radius_mm]
    assert min(radius) == pytest.approx(f.base_radius_mm + f.face_radius_mm, abs=5e-4)


def test_report_has_the_face_position_plot_and_draws_the_face_as_an_arc(run):
    name, spec, geom, out = run
    html = (out / "report.html").read_text()
    assert "curved-face follower" in html and "roller follower" not in html
    assert 'data-plot="face_position"' in html and "Curved-face contact position" in html
    assert (out / "plots" / "face_position.svg").stat().st_size > 10_000
    data = json.loads(re.search(r'<script type="application/json" id="anim-data">(.*?)</script>', html, re.S)[1])
    (f,) = data["followers"]
    n = len(data["frames"]["x"])
    R = spec.follower.face_radius_mm
    centre, contact = np.reshape(f["centre"], (n, 2)), np.reshape(f["contact"], (n, 2))
    arc = np.reshape(f["arc"], (n, 2))
    assert f["r"] == R and np.all(arc[:, 1] > arc[:, 0])
    # the contact lies on the drawn arc: at R from the face's centre, within the arc's angles
    np.testing.assert_allclose(np.hypot(*(contact - centre).T), R, atol=2e-3)
    at = np.arctan2(*(contact - centre).T[::-1])
    inside = (at - arc[:, 0]) % (2 * np.pi) <= (arc[:, 1] - arc[:, 0]) + 1e-9
    assert inside.all()
    # the arm (finger) or stem (mushroom) meets the face at its vertex, on the circle
    link = np.reshape(f["link"], (n, 4))
    vertex = link[:, 2:] if name == "finger_follower" else link[:, :2]
    np.testing.assert_allclose(np.hypot(*(vertex - centre).T), R, atol=2e-3)
    if name == "finger_follower":
        np.testing.assert_allclose(link[:, :2], [[spec.follower.pivot_distance_mm, 0.0]] * n)
    else:
        np.testing.assert_allclose(link[:, 0], link[:, 2])  # a vertical stem
    assert "animation.js" not in html and "f.arc" in html  # the script that draws it is inlined


def test_check_messages_speak_of_the_face():
    rep = check_design(load_design(EXAMPLES / "finger_follower.toml"))
    (face,) = rep.findings
    assert "measured along its arc" in face.message and "roller" not in face.message
