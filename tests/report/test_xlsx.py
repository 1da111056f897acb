"""CAM-DAS spreadsheet export: the thesis' Exportar-Excel cell map (§7.3.7), engine values, checks and
lift-table sheets."""
from __future__ import annotations

import io
import math
import time
import zipfile

import numpy as np
import pytest

from camfab.design.assemble import check_design, geometry_from_spec
from camfab.design.spec import design_from_dict
from camfab.errors import SpecError
from camfab.formats import load_design
from camfab.formats.camdas_workbook import camdas_workbook
from tests.conftest import EJEMPLO11RO, EXAMPLES, base_design

openpyxl = pytest.importorskip("openpyxl")

OSC_ROLLER = base_design(
    follower={"type": "roller", "motion": "oscillating", "base_radius_mm": 40.0, "roller_radius_mm": 8.0,
              "pivot_distance_mm": 110.0, "arm_length_mm": 90.0},
    motion=[{"law": law, "lift": float(h), "angle_deg": float(b)} for law, h, b in EJEMPLO11RO])
FLAT_TR = base_design(follower={"type": "flat", "motion": "translating", "base_radius_mm": 100.0},
                      cam={"kind": "disc", "rotation": "cw", "speed_rpm": 60.0})
FLAT_OSC = base_design(
    follower={"type": "flat", "motion": "oscillating", "base_radius_mm": 60.0, "pivot_distance_mm": 150.0,
              "face_offset_mm": 5.0},
    motion=[{"law": "dwell", "lift": 0.0, "angle_deg": 90.0}, {"law": "cycloidal", "lift": 8.0, "angle_deg": 90.0},
            {"law": "dwell", "lift": 0.0, "angle_deg": 90.0}, {"law": "cycloidal", "lift": -8.0, "angle_deg": 90.0}])
TRANSLATING_CAM = base_design(
    cam={"kind": "translating", "speed_mm_s": 20.0},
    follower={"type": "roller", "motion": "translating", "roller_radius_mm": 5.0, "cam_length_mm": 200.0,
              "base_height_mm": 10.0},
    motion=[{"law": "cycloidal", "lift": 8.0, "length_mm": 100.0},
            {"law": "cycloidal", "lift": -8.0, "length_mm": 100.0}])
DESIGNS = {"ejemplo9rt": lambda: load_design(EXAMPLES / "ejemplo9rt.toml"),
           "osc_roller": lambda: design_from_dict(OSC_ROLLER), "flat_tr": lambda: design_from_dict(FLAT_TR),
           "flat_osc": lambda: design_from_dict(FLAT_OSC)}
LETTERS = ("A", "B", "C", "D", "E", "F", "G", "H", "I", "J", "K", "L", "M", "N", "O", "P", "Q", "R", "S")


@pytest.fixture(scope="module", params=sorted(DESIGNS))
def case(request):
    spec = DESIGNS[request.param]()
    geom = geometry_from_spec(spec)
    report = check_design(spec)
    return request.param, spec, geom, report


@pytest.fixture(scope="module")
def e9_book():
    spec = DESIGNS["ejemplo9rt"]()
    geom, report = geometry_from_spec(spec), check_design(spec)
    data = camdas_workbook(spec, geom, report)
    return spec, geom, report, data, openpyxl.load_workbook(io.BytesIO(data))


def _column(ws, letter, n):
    return [ws[f"{letter}{10 + i}"].value for i in range(n)]


def _arr(values):
    return np.array([np.nan if v is None else v for v in values], dtype=float)


def test_sheets_and_header_cells(e9_book):
    spec, geom, report, _, wb = e9_book
    assert wb.sheetnames == ["CAM-DAS", "Checks", "Lift table"]
    ws = wb["CAM-DAS"]
    a1 = ws["A1"].value
    assert "roller" in a1 and "translating" in a1 and "clockwise" in a1
    assert ws["A2"].value == "Ejemplo9RT"
    assert report.verdict == "not_for_high_speed" and "not_for_high_speed" in ws["A3"].value
    assert "not suitable for high speeds" in ws["A3"].value
    # A4:A8 geometry and ω (values also as numbers in B, units in C)
    assert ws["A4"].value == "Base radius R_b = 35 mm" and ws["B4"].value == 35 and ws["C4"].value == "mm"
    assert ws["A5"].value.startswith("Roller radius") and ws["B5"].value == 7
    assert ws["A6"].value.startswith("Offset") and ws["B6"].value == 0
    assert ws["A7"].value.startswith("Prime radius") and ws["B7"].value == 42
    assert "ω" in ws["A8"].value and ws["B8"].value == 1.0 and ws["C8"].value == "rad/s"


def test_column_letters_match_the_camdas_map(e9_book):
    ws = e9_book[4]["CAM-DAS"]
    heads = {c: ws[f"{c}9"].value for c in LETTERS}
    expect = {"A": "Cam angle (deg)", "B": "S (mm)", "C": "V (mm/s)", "D": "A (mm/s2)", "E": "J (mm/s3)",
              "F": "Radius of curvature", "G": "Pressure angle (deg)", "I": "Profile radius",
              "J": "Profile polar angle", "L": "Profile x", "M": "Profile y", "O": "Pitch radius",
              "P": "Pitch polar angle", "R": "Pitch x", "S": "Pitch y"}
    for letter, text in expect.items():
        assert heads[letter].startswith(text), letter
    for letter in ("H", "K", "N", "Q"):  # columns CAM-DAS leaves empty for a roller
        assert heads[letter] is None and ws[f"{letter}10"].value is None


def test_rows_run_from_0_to_360_inclusive(e9_book):
    ws = openpyxl.load_workbook(io.BytesIO(e9_book[3]))["CAM-DAS"]
    assert ws.max_row == 370  # 361 points in rows 10…370; row 371 of the thesis map stays empty
    assert ws["A10"].value == 0 and ws["A370"].value == 360
    assert _column(ws, "A", 361) == pytest.approx(list(range(361)), abs=1e-12)


def test_other_step():
    spec = DESIGNS["ejemplo9rt"]()
    geom, report = geometry_from_spec(spec), check_design(spec)
    ws = openpyxl.load_workbook(io.BytesIO(camdas_workbook(spec, geom, report, step_deg=2.5)))["CAM-DAS"]
    assert ws.max_row == 10 + 144 and ws["A154"].value == 360 and ws["A11"].value == 2.5
    with pytest.raises(SpecError, match="step_deg"):
        camdas_workbook(spec, geom, report, step_deg=7.0)
    with pytest.raises(SpecError, match="lift_step_deg"):
        camdas_workbook(spec, geom, report, lift_step_deg=0.0)


def test_values_equal_the_engine(case):
    name, spec, geom, report = case
    ws = openpyxl.load_workbook(io.BytesIO(camdas_workbook(spec, geom, report)))["CAM-DAS"]
    n = 361
    ang = _arr(_column(ws, "A", n))
    x = np.radians(ang)
    prog, w = spec.program(), spec.speed
    S = prog.evaluate(x)
    for k, letter in enumerate("BCDE"):
        assert _arr(_column(ws, letter, n)) == pytest.approx(S[k] * w**k, rel=1e-9, abs=1e-9), letter
    smp = geom.evaluate(x)
    rho = _arr(_column(ws, "F", n))
    fin = np.isfinite(smp.rho)
    assert rho[fin] == pytest.approx(smp.rho[fin], rel=1e-9, abs=1e-9)
    assert np.all(np.isnan(rho[~fin]))
    assert _arr(_column(ws, "L", n)) == pytest.approx(smp.point[:, 0], abs=1e-9)
    assert _arr(_column(ws, "M", n)) == pytest.approx(smp.point[:, 1], abs=1e-9)
    r, th = _arr(_column(ws, "I", n)), np.radians(_arr(_column(ws, "J", n)))
    assert r == pytest.approx(np.hypot(*smp.point.T), rel=1e-9)
    assert np.column_stack([r * np.cos(th), r * np.sin(th)]) == pytest.approx(smp.point, abs=1e-8)
    g, h = _arr(_column(ws, "G", n)), _arr(_column(ws, "H", n))
    if name in ("ejemplo9rt", "osc_roller"):
        assert g == pytest.approx(np.degrees(smp.pressure_angle), abs=1e-9)
        assert np.all(np.isnan(h))
        assert _arr(_column(ws, "R", n)) == pytest.approx(smp.pitch[:, 0], abs=1e-9)
        assert _arr(_column(ws, "S", n)) == pytest.approx(smp.pitch[:, 1], abs=1e-9)
        assert _arr(_column(ws, "O", n)) == pytest.approx(np.hypot(*smp.pitch.T), rel=1e-9)
    elif name == "flat_tr":
        assert g == pytest.approx(np.maximum(-smp.face_position, 0), abs=1e-9)
        assert h == pytest.approx(np.maximum(smp.face_position, 0), abs=1e-9)
        assert g.max() > 1 and h.max() > 1 and np.all(g * h == 0)
        assert np.all(np.isnan(_arr(_column(ws, "R", n))))
    else:
        assert g == pytest.approx(smp.face_position, abs=1e-9) and np.all(np.isnan(h))
        assert ws["G9"].value.startswith("Contact distance along the face")


def test_oscillating_follower_in_degrees():
    spec = design_from_dict(OSC_ROLLER)
    geom, report = geometry_from_spec(spec), check_design(spec)
    ws = openpyxl.load_workbook(io.BytesIO(camdas_workbook(spec, geom, report)))["CAM-DAS"]
    assert [ws[f"{c}9"].value for c in "BCDE"] == ["S (deg)", "V (deg/s)", "A (deg/s2)", "J (deg/s3)"]
    s = _arr(_column(ws, "B", 361))
    assert s.max() == pytest.approx(25.0, abs=1e-9)  # EJEMPLO11RO lifts 25° at 180°
    assert "oscillating" in ws["A1"].value
    assert ws["A6"].value.startswith("Pivot distance") and ws["B6"].value == 110
    assert ws["A7"].value.startswith("Arm length") and ws["B7"].value == 90


def test_flat_face_geometry_rows_and_speed():
    spec = design_from_dict(FLAT_TR)
    geom, report = geometry_from_spec(spec), check_design(spec)
    ws = openpyxl.load_workbook(io.BytesIO(camdas_workbook(spec, geom, report)))["CAM-DAS"]
    assert "flat-face" in ws["A1"].value
    assert ws["B8"].value == pytest.approx(2 * math.pi)  # 60 rpm
    assert ws["G9"].value.startswith("Left") and ws["H9"].value.startswith("Right")
    assert ws["V10"].value is None and ws["O9"].value is None


def test_translating_cam_travel_in_mm():
    spec = design_from_dict(TRANSLATING_CAM)
    geom, report = geometry_from_spec(spec), check_design(spec)
    wb = openpyxl.load_workbook(io.BytesIO(camdas_workbook(spec, geom, report, step_deg=5.0)))
    ws = wb["CAM-DAS"]
    assert ws["A9"].value == "Cam travel (mm)" and ws["A10"].value == 0 and ws["A82"].value == pytest.approx(200)
    x = _arr(_column(ws, "A", 73))
    S = spec.program().evaluate(x)
    assert _arr(_column(ws, "C", 73)) == pytest.approx(S[1] * 20.0, abs=1e-9)
    assert ws["I10"].value is None and ws["O10"].value is None  # no polar coordinates
    assert _arr(_column(ws, "S", 73)) == pytest.approx(geom.evaluate(x).pitch[:, 1], abs=1e-9)
    assert wb["Lift table"]["A1"].value == "Cam travel (mm)"


def test_checks_sheet(e9_book):
    spec, geom, report, _, wb = e9_book
    ws = wb["Checks"]
    assert ws["A1"].value == "Verdict" and ws["B1"].value == report.verdict
    rows = list(ws.iter_rows(values_only=True))
    head = rows.index(("Concept", "Maximum", "Minimum", "Comments", None, None, None))
    table = {r[0]: r[1:4] for r in rows[head + 1:head + 7]}
    peaks = report.to_dict()["peaks"]
    assert table["Displacement (mm)"] == (pytest.approx(peaks["S"]["max"]), pytest.approx(0.0, abs=1e-12),
                                          "Continuous")
    assert table["Velocity (mm/s)"][0] == pytest.approx(peaks["V"]["max"], rel=1e-12)
    assert table["Jerk (mm/s3)"][2] == "Discontinuous" and table["Acceleration (mm/s2)"][2] == "Continuous"
    pa = report.pressure_angle
    assert table["Pressure angle (deg)"] == (pytest.approx(pa.max), pytest.approx(pa.min), "Acceptable")
    assert table["Convex radius of curvature (mm)"][1] == pytest.approx(report.curvature.min_convex)
    fhead = [i for i, r in enumerate(rows) if r[0] == "Code"][0]
    assert rows[fhead][:4] == ("Code", "Severity", "From (deg)", "To (deg)")
    found = [r for r in rows[fhead + 1:] if r[0]]
    assert len(found) == len(report.findings)
    for r, f in zip(found, report.findings, strict=True):
        assert r[:4] == (f.code, f.severity, pytest.approx(f.from_deg), pytest.approx(f.to_deg))
        assert r[6] == f.message


def test_checks_sheet_of_an_unacceptable_flat_face():
    spec = design_from_dict(base_design(follower={"type": "flat", "motion": "translating", "base_radius_mm": 20.0}))
    geom, report = geometry_from_spec(spec), check_design(spec)
    assert report.verdict == "unacceptable"
    wb = openpyxl.load_workbook(io.BytesIO(camdas_workbook(spec, geom, report)))
    assert "undercut" in wb["CAM-DAS"]["A3"].value.lower()
    rows = list(wb["Checks"].iter_rows(values_only=True))
    codes = [r[0] for r in rows]
    assert "UNDERCUT" in codes and "Left contact distance (mm)" in codes
    (und,) = [r for r in rows if r[0] == "UNDERCUT"][:1]
    f = report.by_code("UNDERCUT")[0]
    assert und[2] == pytest.approx(f.from_deg) and und[3] == pytest.approx(f.to_deg)


def test_lift_table_sheet(e9_book):
    spec, geom, report, _, wb = e9_book
    rows = list(wb["Lift table"].iter_rows(values_only=True))
    assert rows[0] == ("Cam angle (deg)", "Lift S (mm)", "Pitch radius (mm)")
    data = np.array(rows[1:], dtype=float)
    assert data[:, 0] == pytest.approx(np.arange(0, 360, 10))
    S = spec.program().evaluate(np.radians(data[:, 0]))[0]
    assert data[:, 1] == pytest.approx(S, abs=1e-9)
    assert data[:, 2] == pytest.approx(42.0 + S, abs=1e-9)  # centred roller: R_p + S


def test_lift_table_step_and_flat_face_radius():
    spec = design_from_dict(FLAT_TR)
    geom, report = geometry_from_spec(spec), check_design(spec)
    wb = openpyxl.load_workbook(io.BytesIO(camdas_workbook(spec, geom, report, lift_step_deg=5.0)))
    rows = list(wb["Lift table"].iter_rows(values_only=True))
    assert rows[0][2] == "Face distance (mm)" and len(rows) == 1 + 72
    data = np.array(rows[1:], dtype=float)
    assert data[:, 2] == pytest.approx(100.0 + data[:, 1], abs=1e-9)


def test_deterministic_bytes_and_fixed_properties(e9_book):
    spec, geom, report, data, wb = e9_book
    time.sleep(1.1)  # openpyxl stamps the save time (1 s resolution) unless camfab pins it
    assert camdas_workbook(spec, geom, report) == data
    assert wb.properties.created.year == 2000 and wb.properties.modified.year == 2000
    with zipfile.ZipFile(io.BytesIO(data)) as z:
        assert {i.date_time for i in z.infolist()} == {(1980, 1, 1, 0, 0, 0)}
