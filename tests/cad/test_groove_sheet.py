"""A groove cam's drawing sheet read back with ezdxf: both flanks, the plate's rim at its radius (the layout sized
for it), the groove in the side view at its depth and both dimensioned with their measured lengths; the layout
rule on every paper; LibreCAD showing the two new values."""
from __future__ import annotations

import io
import math

import numpy as np
import pytest

from camfab.cad.drawing import build_drawing, dim_value, drawing_sheet
from camfab.cad.export import cam_shapes
from camfab.cad.groove import plate_radius
from camfab.cad.groove_sheet import flank_heights
from camfab.cad.sheet_check import layout_problems
from camfab.design.assemble import check_design, geometry_from_spec
from camfab.formats import load_design
from tests.conftest import EXAMPLES

ezdxf = pytest.importorskip("ezdxf")


def _job():
    spec = load_design(EXAMPLES / "groove_translating.toml")
    geom = geometry_from_spec(spec)
    return spec, geom, check_design(spec), cam_shapes(geom, tol=1e-3)


JOB = _job()


def _measured(doc) -> dict[str, list[float]]:
    """Each DIMENSION's text and the paper length between its measured points (along the dimension for a linear
    one; the diameter for a diameter dimension)."""
    out: dict[str, list[float]] = {}
    for d in doc.modelspace().query("DIMENSION"):
        p1, p2 = np.array(d.dxf.defpoint)[:2], np.array(d.dxf.defpoint4 if d.dimtype == 3 else d.dxf.defpoint3)[:2]
        if d.dimtype == 0:
            p1 = np.array(d.dxf.defpoint2)[:2]
            u = np.array([math.cos(math.radians(d.dxf.angle)), math.sin(math.radians(d.dxf.angle))])
            length = abs(float((p2 - p1) @ u))
        else:
            length = float(np.hypot(*(p2 - p1)))
        out.setdefault(d.dxf.text, []).append(length)
    return out


def test_sheet_shows_both_flanks_the_rim_and_the_groove_depth():
    spec, geom, report, shapes = JOB
    doc, lay = build_drawing(spec, geom, report, shapes)
    s, (cx, cy) = lay.scale, lay.centre
    msp = doc.modelspace()
    assert len(msp.query('LWPOLYLINE[layer=="PROFILE"]')) == 1 and len(msp.query('LWPOLYLINE[layer=="PROFILE_2"]')) == 1
    (rim,) = msp.query('CIRCLE[layer=="PLATE"]')
    r = plate_radius(geom)
    assert rim.dxf.radius == pytest.approx(r * s) and (rim.dxf.center.x, rim.dxf.center.y) == pytest.approx((cx, cy))
    dims = _measured(doc)
    assert dims[f"%%c{dim_value(2 * r)}"] == [pytest.approx(2 * r * s)]
    depth = spec.follower.groove_depth_mm
    assert dims[dim_value(depth)] == [pytest.approx(depth * s)]
    assert dims[dim_value(spec.manufacturing.thickness_mm)] == [pytest.approx(spec.manufacturing.thickness_mm * s)]
    # the side view: the plate's full height, the groove floor a depth from the front face over the outer flank
    side = [e for e in msp.query('LWPOLYLINE[layer=="SIDE_VIEW"]')]
    (outline,) = side
    xs, ys = np.array(outline.get_points("xy")).T
    assert ys.max() - ys.min() == pytest.approx(2 * r * s) and xs.max() - xs.min() == pytest.approx(12.0 * s)
    hidden = [(e.dxf.start, e.dxf.end) for e in msp.query('LINE[layer=="HIDDEN"]') if e.dxf.start.x > lay.side[0]]
    floor = [(a, b) for a, b in hidden if a.x == pytest.approx(xs.max() - depth * s) and abs(a.y - b.y) > 1.0]
    (olo, ohi) = flank_heights(geom)[1]
    assert len(floor) == 1
    assert sorted((floor[0][0].y, floor[0][1].y)) == pytest.approx([cy + olo * s, cy + ohi * s])
    exact = geom.profiles[1].evaluate(np.linspace(0.0, 2 * math.pi, 200001)).point[:, 1]
    assert (olo, ohi) == pytest.approx((exact.min(), exact.max()), abs=1e-4)


@pytest.mark.parametrize("paper", ["auto", "A4", "A3"])
def test_layout_is_free_of_overlaps(paper):
    doc, lay = build_drawing(*JOB, paper=paper)
    assert layout_problems(doc, lay) == []


def test_librecad_shows_the_rim_and_the_depth(tmp_path):
    from tests.cad.test_drawing_librecad import _dense, _dimension_texts, _find, _glyphs, _librecad, _strokes, _to_pdf

    KDTree = pytest.importorskip("scipy.spatial").cKDTree
    exe = _librecad()
    spec, geom, *_ = JOB
    text = drawing_sheet(*JOB)
    dxf = tmp_path / "groove.dxf"
    dxf.write_text(text)
    segs, verts = _strokes(_to_pdf(exe, dxf))
    lo = segs[:, :2].min(axis=0)
    segs, verts = segs - np.tile(lo, 2), verts - lo
    tree = KDTree(_dense(segs))
    want = (f"%%c{dim_value(2 * plate_radius(geom))}", dim_value(spec.follower.groove_depth_mm))
    dims = {t: (at, deg) for t, at, deg in _dimension_texts(ezdxf.read(io.StringIO(text)))}
    glyphs = _glyphs(exe, str(tmp_path), want, 2.5)
    for t in want:
        at, deg = dims[t]
        assert _find(glyphs[t], tree, verts, at, (deg, deg + 180.0)), f"LibreCAD does not show {t!r}"
