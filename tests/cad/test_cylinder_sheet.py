"""A cylindrical cam's drawing sheet read back: the developed flanks and pitch curve against the closed-form
development (ezdxf, through the sheet's scale and origin), the lift table's cells against the motion law, the
dimensions' measured points against their explicit values, the layout rule on several cylinders and papers,
LibreCAD showing the dimension values at their dimensions, and the PDF (its text read by poppler)."""
from __future__ import annotations

import io
import math
import shutil
import subprocess
from functools import cache

import numpy as np
import pytest

from camfab.cad.cylinder_sheet import build_cylinder_drawing, cylinder_drawing_sheet, silhouette_notch
from camfab.cad.drawing import dim_value
from camfab.cad.sheet_check import layout_problems
from camfab.design.assemble import check_design, geometry_from_spec
from camfab.design.spec import design_from_dict
from camfab.formats import load_design
from camfab.pipeline import Output, Request, load, run
from tests.conftest import EXAMPLES
from tests.report.test_cylinder_outputs import Z0, exact

ezdxf = pytest.importorskip("ezdxf")
pytest.importorskip("ezdxf.path")
KDTree = pytest.importorskip("scipy.spatial").cKDTree
TOL = 0.01  # the example's tolerance (mm)


def _variant(name: str, cylinder: dict, follower: dict, motion: list, bore: float = 0.0, rotation: str = "cw"):
    return design_from_dict({"name": name, "cam": {"kind": "cylindrical", "rotation": rotation},
                             "cylinder": cylinder, "follower": {"type": "roller", **follower}, "motion": motion,
                             "manufacturing": {"bore_mm": bore, "tolerance_mm": 0.01}})


RISE = [{"law": "cycloidal", "lift": 1.0, "angle_deg": 180.0}, {"law": "cycloidal", "lift": -1.0, "angle_deg": 180.0}]
#: an oscillating follower with a conical roller and a bore (ccw), a small cylinder at 2:1 or 1:1, a large one
VARIANTS = {
    "oscillating": lambda: _variant(
        "Osc", {"radius_mm": 40.0, "length_mm": 90.0, "groove_depth_mm": 10.0, "backlash_mm": 0.1, "roller": "conical"},
        {"motion": "oscillating", "roller_radius_mm": 6.0, "arm_length_mm": 60.0},
        [{**RISE[0], "lift": 30.0, "law": "poly345"}, {**RISE[1], "lift": -30.0, "law": "poly345"}], 20.0, "ccw"),
    "small": lambda: _variant("Tiny", {"radius_mm": 8.0, "length_mm": 20.0, "groove_depth_mm": 3.0},
                              {"motion": "translating", "roller_radius_mm": 2.0},
                              [{**RISE[0], "lift": 8.0}, {**RISE[1], "lift": -8.0}], 5.0),
    "large": lambda: _variant("Big", {"radius_mm": 300.0, "length_mm": 400.0, "groove_depth_mm": 30.0},
                              {"motion": "translating", "roller_radius_mm": 20.0},
                              [{**RISE[0], "lift": 200.0, "angle_deg": 90.0},
                               {**RISE[1], "lift": -200.0, "angle_deg": 270.0}], 100.0),
}


@cache
def _job(name: str):
    spec = load_design(EXAMPLES / "cylindrical_translating.toml") if name == "example" else VARIANTS[name]()
    return spec, geometry_from_spec(spec), check_design(spec)


def _sheet(name: str = "example", paper: str = "auto"):
    spec, geom, report = _job(name)
    return build_cylinder_drawing(spec, geom, report, tol=spec.manufacturing.tolerance_mm, paper=paper)


def _true(doc, pts: np.ndarray) -> np.ndarray:
    """Paper points of the development → true developed (x, z) through the header's scale and origin."""
    s = float(doc.header.custom_vars.get("CAMFAB_SCALE"))
    c = np.array([float(v) for v in doc.header.custom_vars.get("CAMFAB_CENTRE").split(",")])
    return (pts - c) / s


def test_developed_flanks_and_pitch_curve_are_the_exact_development():
    doc, lay, dev = _sheet()
    assert dev <= TOL
    theta = np.linspace(0.0, 2 * math.pi, 200001)
    want = exact(theta, 40.0)
    x_end = lay.centre[0] + lay.scale * 2 * math.pi * 40.0
    found = {"PROFILE": [], "PRIME_CIRCLE": []}
    for e in doc.modelspace().query("LWPOLYLINE"):
        pts = np.array([p[:2] for p in e.get_points("xy")])
        if e.dxf.layer in found and pts[:, 0].max() <= x_end + 1.0:  # the development (not the side view)
            flat = ezdxf.path.make_path(e).flattening(1e-4)
            found[e.dxf.layer].append(_true(doc, np.array([(v.x, v.y) for v in flat])))
    assert len(found["PROFILE"]) == 2 and len(found["PRIME_CIRCLE"]) == 1
    (pitch,) = found["PRIME_CIRCLE"]
    d, _ = KDTree(want["pitch"]).query(pitch)
    assert d.max() < TOL + 1e-3
    plus, minus = sorted(found["PROFILE"], key=lambda p: p[:, 1].mean(), reverse=True)
    for got, key in ((plus, "plus"), (minus, "minus")):
        d, _ = KDTree(want[key]).query(got)
        assert d.max() < TOL + 1e-3, key
        assert got[:, 0].min() == pytest.approx(0.0, abs=1e-6) and got[:, 0].max() == pytest.approx(80 * math.pi)
    # the groove's width across the flanks: the roller diameter plus the backlash, everywhere
    d, _ = KDTree(minus).query(plus[(plus[:, 0] > 1.0) & (plus[:, 0] < 80 * math.pi - 1.0)])
    assert d == pytest.approx(12.05, abs=2 * TOL + 1e-3)


def test_lift_table_cells_are_the_motion_law():
    doc, _, _ = _sheet()
    cells = [(e.dxf.insert.y, e.dxf.align_point.x, e.dxf.text) for e in doc.modelspace().query("TEXT")
             if e.dxf.layer == "LIFT_TABLE"]
    assert {"ANGLE °", "LIFT mm", "Z mm"} <= {t for *_, t in cells}
    rows: dict[float, list[tuple[float, str]]] = {}
    for y, x, t in cells:
        rows.setdefault(round(y, 3), []).append((x, t))
    table = np.array([[float(t) for _, t in sorted(r)] for r in rows.values()
                      if len(r) == 3 and all(t.replace(".", "").isdigit() for _, t in r)])
    table = table[np.argsort(table[:, 0])]
    np.testing.assert_array_equal(table[:, 0], np.arange(0.0, 360.0, 10.0))
    s = exact(np.radians(table[:, 0]), 40.0)["S"]
    np.testing.assert_allclose(table[:, 1], s, atol=5e-4)
    np.testing.assert_allclose(table[:, 2], Z0 + s, atol=5e-4)


def test_dimensions_measure_what_they_say():
    """Each DIMENSION's explicit text is the true length between its measured points (paper / scale)."""
    spec, geom, _ = _job("oscillating")
    doc, lay, _ = _sheet("oscillating")
    cyl = geom.cylinder
    got = {}
    for d in doc.modelspace().query("DIMENSION"):
        p1, p2 = np.array(d.dxf.defpoint2)[:2], np.array(d.dxf.defpoint3)[:2]
        u = np.array([math.cos(math.radians(d.dxf.angle)), math.sin(math.radians(d.dxf.angle))])
        got.setdefault(d.dxf.text, []).append(abs(float((p2 - p1) @ u)) / lay.scale)
    assert got[dim_value(2 * math.pi * 40.0)] == [pytest.approx(2 * math.pi * 40.0)]
    assert got[dim_value(90.0)] == [pytest.approx(90.0)] * 2  # the length on both views
    assert got["%%c90"] == [pytest.approx(90.0)]
    assert got["%%c20 H7"] == [pytest.approx(20.0)]
    assert got["10"] == [pytest.approx(cyl.groove_depth_mm)]
    # the notch at 0°: the flanks at the groove bottom and the outer radius, the roller's axis between them
    notch = silhouette_notch(geom, 0.0)
    z0 = geom.mechanism.z0_for(geom.program)
    for r, zm, zp in notch:
        assert zm < z0 < zp and zp - zm == pytest.approx(2 * geom.mechanism.half_width(r), rel=1e-6)


@pytest.mark.parametrize("name", ["example", *VARIANTS])
@pytest.mark.parametrize("paper", ["auto", "A4", "A3"])
def test_layout_is_free_of_overlaps(name, paper):
    doc, lay, _ = _sheet(name, paper)
    assert lay.fits
    assert layout_problems(doc, lay) == []


# ---------------------------------------------------------------------------
def test_librecad_shows_the_dimension_values(tmp_path):
    """LibreCAD's rendering of the sheet (its stroke font) shows each dimension's value at its dimension."""
    from tests.cad.test_drawing_librecad import _dense, _dimension_texts, _find, _glyphs, _librecad, _strokes, _to_pdf

    exe = _librecad()
    spec, geom, report = _job("oscillating")
    text, _ = cylinder_drawing_sheet(spec, geom, report, tol=0.01)
    dxf = tmp_path / "osc.dxf"
    dxf.write_text(text)
    segs, verts = _strokes(_to_pdf(exe, dxf))
    lo = segs[:, :2].min(axis=0)
    segs, verts = segs - np.tile(lo, 2), verts - lo
    tree = KDTree(_dense(segs))
    dims = _dimension_texts(ezdxf.read(io.StringIO(text)))
    want = {dim_value(2 * math.pi * 40.0), "90", "%%c90", "10", "%%c20 H7"}
    assert want <= {t for t, *_ in dims}
    glyphs = _glyphs(exe, str(tmp_path), tuple(sorted(want)), 2.5)
    for t, at, deg in dims:
        assert _find(glyphs[t], tree, verts, at, (deg, deg + 180.0)), f"LibreCAD does not show {t!r}"


def test_run_writes_the_sheet_and_its_pdf(tmp_path):
    """`camfab run` on the example: the sheet and its PDF, whose text (poppler) holds the title, the values
    and the lift table's last row."""
    res = run(load("cylindrical_translating"), tmp_path, Request(frozenset({Output.DRAWING, Output.PDF})))
    assert {"drawing", "pdf"}.isdisjoint(res.not_applicable)
    assert (tmp_path / "BarrelCam_drawing.dxf").exists()
    pdf = tmp_path / "BarrelCam_drawing.pdf"
    assert pdf.read_bytes().startswith(b"%PDF")
    if shutil.which("pdftotext") is None:
        pytest.skip("pdftotext (poppler-utils) is not installed")
    words = subprocess.run(["pdftotext", "-layout", str(pdf), "-"], capture_output=True, text=True,
                           check=True).stdout
    for word in ("BarrelCam", "251.33", "Ø90", "DEVELOPED GROOVE", "SIDE VIEW", "Z mm", "350"):
        assert word in words, word
