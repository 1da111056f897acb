"""Designs read from xlsx: round trips, errors naming the field and the cell, corrupt files."""
from __future__ import annotations

import dataclasses
import io

import numpy as np
import pytest

from camfab.design.spec import design_from_dict
from camfab.errors import SpecError
from camfab.formats import design_to_xlsx, load_design, load_design_xlsx
from tests.conftest import EXAMPLES, base_design

openpyxl = pytest.importorskip("openpyxl")


def _bare(spec, *, table=True):
    """The spec without its origin (source file), optionally without the motion table."""
    out = dataclasses.replace(spec, source=None)
    return out if table else dataclasses.replace(out, motion_table=None)


def _write(tmp_path, data: bytes, name="design.xlsx"):
    p = tmp_path / name
    p.write_bytes(data)
    return p


def _problems(path):
    with pytest.raises(SpecError) as info:
        load_design_xlsx(path)
    return info.value


def _book(design_rows, motion=None, knots=None):
    wb = openpyxl.Workbook()
    ws = wb.active
    ws.title = "design"
    for r in design_rows:
        ws.append(list(r))
    if motion is not None:
        ms = wb.create_sheet("motion")
        for r in motion:
            ms.append(list(r))
    if knots is not None:
        ks = wb.create_sheet("knots")
        for r in knots:
            ks.append(list(r))
    buf = io.BytesIO()
    wb.save(buf)
    return buf.getvalue()


E9_ROWS = [("key", "value"), ("name", "E9"), ("cam.kind", "disc"), ("cam.omega_rad_s", 1.0),
           ("follower.type", "roller"), ("follower.motion", "translating"), ("follower.base_radius_mm", 35),
           ("follower.roller_radius_mm", 7)]
E9_MOTION = [("law", "lift", "angle_deg"), ("modified_sine", 10, 50), ("dwell", 0, 40), ("cycloidal", -10, 50),
             ("dwell", 0, 40), ("poly345", 10, 50), ("dwell", 0, 40), ("poly4567", -10, 50), ("dwell", 0, 40)]


@pytest.mark.parametrize("name", ["ejemplo9rt", "groove_translating"])
def test_round_trip_toml_example(tmp_path, name):
    spec = load_design(EXAMPLES / f"{name}.toml")
    back = load_design_xlsx(_write(tmp_path, design_to_xlsx(spec)))
    assert _bare(back) == _bare(spec)
    assert back.source == str(tmp_path / "design.xlsx") and back.sources == (back.source,)


@pytest.mark.parametrize("design", [
    base_design(cam={"kind": "disc", "rotation": "ccw", "speed_rpm": 9.5493},
                follower={"type": "roller", "motion": "oscillating", "base_radius_mm": 40.0,
                          "roller_radius_mm": 8.0, "pivot_distance_mm": 110.0, "arm_length_mm": 90.0},
                motion=[{"law": "dwell", "lift": 0.0, "angle_deg": 90.0},
                        {"law": "poly4567", "lift": 25.0, "angle_deg": 90.0},
                        {"law": "poly4567", "lift": -25.0, "angle_deg": 180.0}],
                manufacturing={"thickness_mm": 12.5, "bore_mm": 20.0, "keyway": True, "material": "C45",
                               "tolerance_mm": 0.005, "hub_diameter_mm": 40.0, "hub_length_mm": 8.0},
                outputs={"gcode": "fanuc", "drawing": True, "xlsx": True},
                checks={"pressure_angle_limit_deg": 40.0}, description="oscillating test cam"),
    base_design(follower={"type": "flat", "motion": "oscillating", "base_radius_mm": 60.0,
                          "pivot_distance_mm": 150.0, "face_offset_mm": -5.0}, checks={"face_margin_mm": 2.0},
                cam={"kind": "disc", "omega_rad_s": 0.1 + 0.2}),
    base_design(cam={"kind": "translating", "speed_mm_s": 20.0, "direction": "right"},
                follower={"type": "roller", "motion": "translating", "roller_radius_mm": 5.0,
                          "cam_length_mm": 200.0},
                motion=[{"law": "cycloidal", "lift": 8.0, "length_mm": 100.0},
                        {"law": "cycloidal", "lift": -8.0, "length_mm": 100.0}]),
    base_design(follower={"type": "knife", "motion": "translating", "base_radius_mm": 40.0, "offset_mm": 3.0},
                motion=[{"law": "simple_harmonic", "lift": 10.0, "angle_deg": 180.0},
                        {"law": "simple_harmonic", "lift": -10.0, "angle_deg": 180.0}],
                outputs={"drawing": True, "pdf": False}),  # a PDF that does not follow the drawing
    {k: v for k, v in base_design(cam={"kind": "constant_width", "speed_rpm": 60.0},
                                  follower={"type": "flat", "motion": "translating", "base_radius_mm": 30.0,
                                            "width_mm": 80.0, "rise_deg": 150.0}).items() if k != "motion"},
], ids=["osc-roller", "flat-osc", "translating-cam", "knife", "constant-width-rise"])
def test_round_trip_variants(tmp_path, design):
    spec = design_from_dict(design)
    back = load_design_xlsx(_write(tmp_path, design_to_xlsx(spec)))
    assert _bare(back) == _bare(spec)


def test_round_trip_knot_rows(tmp_path):
    rows = [[0, 0, 0, 0, 0], [90, 5, 0.05, 0, 0], [180, 9.123456789012345, 0, -0.001, 0], [270, 5, -0.05, 0, 0]]
    design = base_design(motion_table={"rows": rows, "units": {"angle": "deg", "s": "mm", "v": "mm/deg",
                                                               "a": "mm/deg2", "j": "mm/deg3"}, "degree": 7})
    del design["motion"]
    spec = design_from_dict(design)
    data = design_to_xlsx(spec)
    wb = openpyxl.load_workbook(io.BytesIO(data))
    assert [c.value for c in wb["knots"][1]] == ["angle", "s", "v", "a", "j"]
    back = load_design_xlsx(_write(tmp_path, data))
    assert _bare(back) == _bare(spec)


def test_knot_file_is_written_inline(tmp_path):
    spec = load_design(EXAMPLES / "valve_exhaust_ej1.toml")
    data = design_to_xlsx(spec)
    wb = openpyxl.load_workbook(io.BytesIO(data))
    keys = {r[0]: r[1] for r in wb["design"].iter_rows(values_only=True)}
    assert keys["motion_table.units.s"] == "m" and keys["motion_table.speed_rpm"] == 1500
    assert "motion_table.file" not in keys and wb["knots"].max_row > 10
    back = load_design_xlsx(_write(tmp_path, data))
    assert _bare(back, table=False) == _bare(spec, table=False)
    x = np.linspace(0, 2 * np.pi, 997)
    assert np.array_equal(back.program().evaluate(x), spec.program().evaluate(x))


def test_written_bytes_are_deterministic():
    spec = load_design(EXAMPLES / "ejemplo9rt.toml")
    assert design_to_xlsx(spec) == design_to_xlsx(spec)


def test_hand_written_workbook(tmp_path):
    rows = [("# a comment row", None), ("name", "Hand"), ("cam.kind", "disc"), ("cam.rotation", "ccw"),
            (None, None), ("cam.speed_rpm", "60"), ("follower.type", "roller"), ("follower.motion", "translating"),
            ("follower.base_radius_mm", "35,5"), ("follower.roller_radius_mm", 7, "a note in column C"),
            ("manufacturing.keyway", "FALSE"), ("manufacturing.material", 1045), ("outputs.xlsx", True)]
    spec = load_design_xlsx(_write(tmp_path, _book(rows, E9_MOTION)))
    assert spec.name == "Hand" and spec.cam.rotation == "ccw"
    assert spec.cam.omega_rad_s == pytest.approx(2 * np.pi)
    assert spec.follower.base_radius_mm == 35.5 and spec.manufacturing.keyway is False
    assert spec.manufacturing.material == "1045" and spec.outputs.xlsx is True
    assert len(spec.motion) == 8 and spec.motion[0].law == "modified_sine"


def test_name_defaults_to_the_file_stem(tmp_path):
    spec = load_design_xlsx(_write(tmp_path, _book(E9_ROWS[2:], E9_MOTION), "cam_42.xlsx"))
    assert spec.name == "cam_42"


def test_knots_sheet_with_design_keys(tmp_path):
    rows = E9_ROWS + [("motion_table.units.angle", "deg"), ("motion_table.degree", 5)]
    knots = [("angle", "s", "v", "a"), (0, 0, 0, 0), (90, 5, 0, 0), (180, 0, 0, 0)]
    spec = load_design_xlsx(_write(tmp_path, _book(rows, knots=knots)))
    assert spec.motion is None and spec.motion_table["rows"] == [[0, 0, 0, 0], [90, 5, 0, 0], [180, 0, 0, 0]]
    assert float(spec.program().evaluate(np.array([np.pi / 2]))[0, 0]) == pytest.approx(5.0)


def test_errors_name_the_field_and_the_cell(tmp_path):
    rows = list(E9_ROWS)
    rows[6] = ("follower.base_radius_mm", -3)          # row 7
    rows[7] = ("follower.roler_radius_mm", 7)          # row 8: misspelt, so the roller radius is missing
    rows.append(("cam.rotation", "clockwise"))         # row 9
    motion = list(E9_MOTION)
    motion[2] = ("dwell", "ten", 40)                   # motion row 3 = segment 1
    motion[3] = ("cycloidall", -10, 50)                # segment 2
    err = _problems(_write(tmp_path, _book(rows, motion)))
    text = str(err)
    assert "follower.base_radius_mm [design!B7]" in text
    assert "follower.roler_radius_mm [design!A8]" in text and "did you mean 'roller_radius_mm'" in text
    assert "follower.roller_radius_mm [design sheet: no such row]" in text
    assert "cam.rotation [design!B9]" in text
    assert "motion[1].lift [motion!B3]" in text
    assert "motion[2].law [motion!A4]" in text and "cycloidal" in text
    assert len(err.problems) == 6 and err.source.endswith("design.xlsx")


def test_knot_errors_name_the_cell(tmp_path):
    knots = [("angle", "s", "v", "a"), (0, 0, 0, 0), (90, "five", 0, 0), (80, 0, 0, 0)]
    err = _problems(_write(tmp_path, _book(E9_ROWS, knots=knots)))
    text = str(err)
    assert "motion_table.rows[1][1] [knots!B3]" in text
    assert "motion_table.rows[2][0] [knots!A4]" in text


def test_sheet_level_errors(tmp_path):
    rows = E9_ROWS + [("follower.base_radius_mm", 40), ("manufacturing.bore_mm", None), ("motion.law", "dwell")]
    err = _problems(_write(tmp_path, _book(rows, [("law", "lift", "angle", "shape")] + E9_MOTION[1:])))
    text = str(err)
    assert "given twice (also design!A7)" in text and "[design!A9]" in text
    assert "manufacturing.bore_mm [design!B10]" in text and "has no value" in text
    assert "motion.law [design!A11]" in text and "'motion' sheet" in text
    assert "[motion!C1]" in text and "unknown column heading" in text


def test_missing_design_sheet(tmp_path):
    wb = openpyxl.Workbook()
    wb.active.title = "Sheet1"
    buf = io.BytesIO()
    wb.save(buf)
    err = _problems(_write(tmp_path, buf.getvalue()))
    assert "no 'design' sheet" in str(err) and "add a sheet named 'design'" in str(err)


@pytest.mark.parametrize("content", [b"", b"PK\x03\x04 not really a zip", b"name = 'toml, not xlsx'\n"])
def test_corrupt_or_foreign_file(tmp_path, content):
    p = _write(tmp_path, content, "broken.xlsx")
    err = _problems(p)
    text = str(err)
    assert str(p) in text and "not a readable xlsx workbook" in text and "save it as an .xlsx" in text


def test_missing_file(tmp_path):
    err = _problems(tmp_path / "nope.xlsx")
    assert "nope.xlsx" in str(err) and "no such design workbook" in str(err)
