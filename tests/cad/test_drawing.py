"""The DXF manufacturing drawing: audit, title block, lift table, dimensions, geometry, paper and scale."""
from __future__ import annotations

import datetime
import io
import time

import numpy as np
import pytest

from camfab.cad.drawing import LAYERS, build_drawing, drawing_sheet, load_template, parse_scale, sheet_layout
from camfab.cad.export import cam_shapes
from camfab.design.assemble import check_design, geometry_from_spec
from camfab.design.spec import design_from_dict
from camfab.discretize import measure_deviation
from camfab.errors import SpecError
from camfab.formats import load_design
from camfab.offset.cutter import profile_curve
from tests.conftest import EXAMPLES, base_design

ezdxf = pytest.importorskip("ezdxf")

TOL = 1e-3


def _job(spec, tol=TOL):
    geom = geometry_from_spec(spec)
    return spec, geom, check_design(spec), cam_shapes(geom, tol=tol)


def _e9_with_material():
    d = base_design(manufacturing={"thickness_mm": 10.0, "bore_mm": 12.0, "keyway": True, "material": "C45E",
                                   "tolerance_mm": 0.002})
    d["name"] = "Ejemplo9RT"
    return design_from_dict(d)


@pytest.fixture(scope="module")
def e9():
    job = _job(_e9_with_material())
    text = drawing_sheet(*job)
    return job, text, ezdxf.read(io.StringIO(text))


def _texts(doc, layer):
    return [e.dxf.text for e in doc.modelspace().query(f"TEXT[layer=='{layer}']")]


def _centre_scale(doc):
    cv = doc.header.custom_vars
    cx, cy = map(float, cv.get("CAMFAB_CENTRE").split(","))
    return np.array([cx, cy]), float(cv.get("CAMFAB_SCALE"))


def test_reads_back_and_audits_clean(e9):
    _, _, doc = e9
    auditor = doc.audit()
    assert not auditor.has_errors and not auditor.has_fixes
    assert doc.header["$INSUNITS"] == 4 and doc.dxfversion == "AC1024"
    for name in LAYERS:
        assert name in doc.layers
    assert doc.layers.get("BASE_CIRCLE").dxf.linetype == "PHANTOM"
    assert doc.layers.get("PRIME_CIRCLE").dxf.linetype == "CENTER"


def test_title_block(e9):
    (spec, geom, report, shapes), _, doc = e9
    texts = _texts(doc, "TITLE_BLOCK")
    for label in ("TITLE", "SCALE", "MATERIAL", "UNITS", "CHECK VERDICT", "DRAWN BY", "CHECKED BY", "DATE",
                  "DRAWING NO.", "REV.", "GENERAL TOLERANCES"):
        assert label in texts
    # the CAD approximation tolerance is no shop tolerance: it is not in the title block
    assert "PROFILE TOLERANCE" not in texts and not any("0.002" in t for t in texts)
    assert "Ejemplo9RT" in texts and "C45E" in texts and "ISO 2768-m" in texts and "mm" in texts
    assert report.verdict in texts and "1:1" in texts and "A4" in texts
    assert any(t.startswith("camfab ") for t in texts)
    # the title block sits inside the frame's bottom-right corner
    lay = sheet_layout(geom.max_radius, 36)
    assert lay.title[2] == lay.frame[2] and lay.title[1] == lay.frame[1]


def _table_rows(doc):
    """(angle, lift, radius) rows of the drawn lift table, read from the TEXT positions."""
    ents = [(e.dxf.text, e.dxf.align_point.x, e.dxf.align_point.y) for e in
            doc.modelspace().query("TEXT[layer=='LIFT_TABLE']")]
    widths = load_template()["lift_table"]["column_widths_mm"]
    heads = [t for t in ents if t[0].startswith("ANGLE")]
    rows = []
    for _, hx, hy in heads:
        cells = [t for t in ents if t[2] < hy - 0.1 and hx - 1 < t[1] < hx - widths[0] / 2 + sum(widths)]
        for y in sorted({round(t[2], 6) for t in cells}, reverse=True):
            line = sorted((t for t in cells if abs(t[2] - y) < 1e-6), key=lambda t: t[1])
            rows.append(tuple(float(t[0]) for t in line))
    return np.array(rows)


def test_lift_table_values_equal_the_engine(e9):
    (spec, geom, report, shapes), _, doc = e9
    texts = _texts(doc, "LIFT_TABLE")
    assert "LIFT TABLE (step 10°)" in texts and "LIFT mm" in texts and "RADIUS mm" in texts
    rows = _table_rows(doc)
    assert rows.shape == (36, 3)
    assert rows[:, 0] == pytest.approx(np.arange(0, 360, 10))
    S = spec.program().evaluate(np.radians(rows[:, 0]))[0]
    assert rows[:, 1] == pytest.approx(S, abs=5e-4 + 1e-12)
    assert rows[:, 2] == pytest.approx(42.0 + S, abs=5e-4 + 1e-12)


def test_lift_table_step_splits_into_groups():
    job = _job(_e9_with_material())
    doc, lay = build_drawing(*job, lift_step_deg=2.0)
    assert lay.table_groups >= 2 and lay.table_groups * lay.table_rows >= 180
    rows = _table_rows(doc)
    assert rows.shape == (180, 3)
    assert sorted(rows[:, 0]) == pytest.approx(np.arange(0, 360, 2))
    with pytest.raises(SpecError, match="divide 360"):
        build_drawing(*job, lift_step_deg=7.0)


def _dims(doc):
    out = {}
    for d in doc.modelspace().query("DIMENSION"):
        lfac = d.override().get("dimlfac", 1.0)
        out.setdefault(d.dimtype, []).append(d.get_measurement() * lfac)
    return out


def test_dimensions_are_real_dimension_entities(e9):
    (spec, geom, report, shapes), _, doc = e9
    dims = _dims(doc)
    assert all(d.dxf.layer == "DIMENSIONS" for d in doc.modelspace().query("DIMENSION"))
    assert sorted(dims[3]) == pytest.approx([12.0, 70.0])  # bore and base-circle diameters (true size)
    assert dims[4] == pytest.approx([geom.max_radius], abs=1e-9)  # R max
    # keyway width b, the plate thickness (side view) and d + t2 (DIN 6885: 12 mm bore)
    assert sorted(dims[0]) == pytest.approx([4.0, 10.0, 13.8])
    # rendered: each dimension has its block with the measurement text
    for d in doc.modelspace().query("DIMENSION"):
        block = doc.blocks.get(d.dxf.geometry)
        assert any(e.dxftype() == "MTEXT" for e in block)


def test_profile_scaled_back_lies_within_tol(e9):
    (spec, geom, report, shapes), _, doc = e9
    centre, scale = _centre_scale(doc)
    (pl,) = doc.modelspace().query("LWPOLYLINE[layer=='PROFILE']")
    rows = np.array(list(pl.get_points("xyb")))
    true = np.column_stack([(rows[:, :2] - centre) / scale, rows[:, 2]])
    dev = measure_deviation(true, profile_curve(geom.profiles[0]))
    assert dev.max <= TOL + 1e-9
    circles = {c.dxf.layer: c for c in doc.modelspace().query("CIRCLE")}
    assert circles["BASE_CIRCLE"].dxf.radius == pytest.approx(35.0 * scale)
    assert circles["PRIME_CIRCLE"].dxf.radius == pytest.approx(42.0 * scale)
    assert np.allclose(tuple(circles["BASE_CIRCLE"].dxf.center)[:2], centre)
    (bore,) = doc.modelspace().query("LWPOLYLINE[layer=='BORE']")
    bpts = (np.array(list(bore.get_points("xy"))) - centre) / scale
    assert bpts[:, 1].max() == pytest.approx(6.0 + 1.8)  # keyseat top at r + t2 on +Y


def test_notes(e9):
    _, _, doc = e9
    (mt,) = doc.modelspace().query("MTEXT[layer=='NOTES']")
    text = mt.plain_text()
    text = " ".join(line.strip() for line in text.splitlines())  # the notes are wrapped to the column
    for word in ("Material: C45E", "tolerance 0.002 mm, not a manufacturing tolerance", "All dimensions in mm",
                 "CLOCKWISE", "Zero-angle reference", "0°", "not_for_high_speed", "Plate thickness 10 mm",
                 "bore Ø12 H7", "keyway DIN 6885-1", "width 4 JS9", "d + t2 = 13.8 +0.1/0 mm", "ISO 2768-m",
                 "Ra 1.6 µm", "±0.02 mm of the true profile", "R max = 45.000 mm", "Ø max = 2 × R max = 90.000 mm"):
        assert word in text
    assert "NOTES" in _texts(doc, "NOTES")


def test_paper_and_scale_for_small_and_large_cams():
    small = drawing_sheet(*_job(load_design(EXAMPLES / "ejemplo9rt.toml")))
    doc = ezdxf.read(io.StringIO(small))
    assert doc.header.custom_vars.get("CAMFAB_PAPER") == "A4" and _centre_scale(doc)[1] == 1.0
    tiny = design_from_dict(base_design(follower={"type": "roller", "motion": "translating",
                                                  "base_radius_mm": 12.0, "roller_radius_mm": 3.0}))
    doc = ezdxf.read(io.StringIO(drawing_sheet(*_job(tiny))))
    # a tiny cam is enlarged (the side view takes room beside it: 1:1 on A4 rather than 2:1)
    assert doc.header.custom_vars.get("CAMFAB_PAPER") == "A4" and _centre_scale(doc)[1] >= 1.0
    big = design_from_dict(base_design(follower={"type": "roller", "motion": "translating",
                                                 "base_radius_mm": 150.0, "roller_radius_mm": 10.0},
                                       manufacturing={"bore_mm": 40.0, "keyway": True}))
    job = _job(big)
    doc = ezdxf.read(io.StringIO(drawing_sheet(*job)))
    assert doc.header.custom_vars.get("CAMFAB_PAPER") == "A3" and _centre_scale(doc)[1] == 0.5
    assert "1:2" in _texts(doc, "TITLE_BLOCK") and not doc.audit().has_errors
    # forced A4: the same cam is reduced further
    doc4, lay = build_drawing(*job, paper="A4")
    assert lay.paper == "A4" and lay.scale_label == "1:5"
    # the cam plus its dimension clearance fits inside the view area
    r = geometry_from_spec(big).max_radius * lay.scale + load_template()["view"]["clearance_mm"]
    x0, y0, x1, y1 = lay.view
    assert x0 <= lay.centre[0] - r and lay.centre[0] + r <= x1 and y0 <= lay.centre[1] - r <= lay.centre[1] + r <= y1
    with pytest.raises(ValueError, match="must be one of"):
        drawing_sheet(*job, paper="A0")


def test_sheet_layout_rules():
    assert parse_scale("1:2") == 0.5 and parse_scale("5:1") == 5.0
    assert sheet_layout(45.0, 36).paper == "A4"
    assert sheet_layout(45.0, 36, "A3").scale > 1.0
    lay = sheet_layout(5000.0, 36)
    assert (lay.paper, lay.scale_label, lay.fits) == ("A3", "1:50", True)
    lay = sheet_layout(20000.0, 36)  # too large even at 1:100: drawn at 1:100 and flagged
    assert (lay.scale_label, lay.fits) == ("1:100", False)


def test_oscillating_and_flat_followers_draw():
    osc = design_from_dict(base_design(
        follower={"type": "roller", "motion": "oscillating", "base_radius_mm": 40.0, "roller_radius_mm": 8.0,
                  "pivot_distance_mm": 110.0, "arm_length_mm": 90.0},
        cam={"kind": "disc", "rotation": "ccw", "omega_rad_s": 1.0},
        motion=[{"law": "dwell", "lift": 0.0, "angle_deg": 90.0}, {"law": "poly4567", "lift": 15.0, "angle_deg": 90.0},
                {"law": "poly4567", "lift": -15.0, "angle_deg": 180.0}]))
    doc = ezdxf.read(io.StringIO(drawing_sheet(*_job(osc))))
    assert not doc.audit().has_errors
    assert "LIFT °" in _texts(doc, "LIFT_TABLE") and "CCW" in _texts(doc, "ANNOTATION")
    assert "COUNTER-CLOCKWISE" in doc.modelspace().query("MTEXT")[0].plain_text()
    rows = _table_rows(doc)
    S = osc.program().evaluate(np.radians(rows[:, 0]))[0]
    assert rows[:, 1] == pytest.approx(S, abs=5e-5 + 1e-12)
    flat = design_from_dict(base_design(follower={"type": "flat", "motion": "translating", "base_radius_mm": 100.0}))
    doc = ezdxf.read(io.StringIO(drawing_sheet(*_job(flat))))
    assert not doc.audit().has_errors and not doc.modelspace().query("CIRCLE[layer=='PRIME_CIRCLE']")
    rows = _table_rows(doc)
    assert rows[:, 2] == pytest.approx(100.0 + rows[:, 1], abs=1e-3)
    dims = _dims(doc)
    # no bore: only the base circle, R max and the plate thickness (side view)
    assert dims[3] == pytest.approx([200.0]) and dims[0] == pytest.approx([10.0])


def test_translating_cam_is_drawn_as_a_plate():
    spec = load_design(EXAMPLES / "wedge_translating.toml")
    job = _job(spec)
    geom = job[1]
    doc, lay = build_drawing(*job)
    assert not doc.audit().has_errors
    doc = ezdxf.read(io.StringIO(drawing_sheet(*job)))
    centre, scale = _centre_scale(doc)
    assert scale == lay.scale
    # the plate outline, scaled back, is within tol of the exact outline
    (pl,) = doc.modelspace().query("LWPOLYLINE[layer=='PROFILE']")
    rows = np.array(list(pl.get_points("xyb")))
    true = np.column_stack([(rows[:, :2] - centre) / scale, rows[:, 2]])
    assert measure_deviation(true, profile_curve(geom.profiles[0])).max <= TOL + 1e-9
    # the plate fits the view
    x0, y0, x1, y1 = lay.view
    assert x0 <= rows[:, 0].min() and rows[:, 0].max() <= x1 and y0 <= rows[:, 1].min() and rows[:, 1].max() <= y1
    # overall length, the S = 0 line's height and the highest point, true size
    # (and the plate thickness in the side view)
    assert sorted(_dims(doc)[0]) == pytest.approx(sorted([300.0, 20.0, 20.0 + 20.0, 12.0]), abs=1e-9)
    texts = _texts(doc, "LIFT_TABLE")
    assert "LIFT TABLE (step 10 mm)" in texts and "TRAVEL mm" in texts and "HEIGHT mm" in texts
    ents = [(e.dxf.text, e.dxf.align_point.x, e.dxf.align_point.y) for e in
            doc.modelspace().query("TEXT[layer=='LIFT_TABLE']")]
    travel = sorted(float(t) for t, *_ in ents if t.replace(".", "").isdigit() and float(t) % 10 == 0
                    and len(t.split(".")) == 1)
    assert travel == pytest.approx(np.arange(0, 310, 10))  # the whole plate, 0 … 300 mm
    assert "CAM SLIDES LEFT" in _texts(doc, "ANNOTATION")
    text = doc.modelspace().query("MTEXT")[0].plain_text()
    assert "slides LEFT" in text and "no bore" in text and "length 300 mm" in text


def test_deterministic(e9):
    job, text, _ = e9
    time.sleep(1.1)
    assert drawing_sheet(*job) == text
    assert datetime.date.today().isoformat() not in text
