"""DXF export: units, layers, exact arcs read back, audit, determinism."""
from __future__ import annotations

import io
import math

import numpy as np
import pytest

from camfab.cad.dxf import DxfContent, dumps
from camfab.cad.plate import bore_loop, circle_loop
from camfab.geom2d import ArcChain

ezdxf = pytest.importorskip("ezdxf")


def _stadium():
    pts = np.array([[-15.0, -15.0], [15.0, -15.0], [15.0, 15.0], [-15.0, 15.0]])
    return ArcChain.from_bulges(pts, np.array([0.0, 1.0, 0.0, 1.0]))


def _content():
    return DxfContent((_stadium(),), (circle_loop(20.0),), base_radius=15.0, prime_radius=20.0,
                      bore=bore_loop(12.0, True), tol_mm=0.001, deviation_mm=2e-7, name="t")


def sample_entities(entities, n=200):
    """Points on LWPOLYLINE/LINE/ARC entities, arcs from ezdxf's own bulge_to_arc (no Bezier)."""
    from ezdxf.math import bulge_to_arc

    out = []

    def arc(c, r, a0, a1):
        a1 = a1 if a1 > a0 else a1 + 2 * math.pi
        t = np.linspace(a0, a1, n)
        out.append(np.column_stack([c[0] + r * np.cos(t), c[1] + r * np.sin(t)]))

    for e in entities:
        if e.dxftype() == "LWPOLYLINE":
            v = list(e.get_points("xyb"))
            for i, (x, y, b) in enumerate(v):
                x1, y1, _ = v[(i + 1) % len(v)]
                if b == 0:
                    out.append(np.linspace((x, y), (x1, y1), n))
                else:
                    c, a0, a1, r = bulge_to_arc((x, y), (x1, y1), b)
                    arc((c.x, c.y), r, a0, a1)
        elif e.dxftype() == "LINE":
            out.append(np.linspace(e.dxf.start.vec2, e.dxf.end.vec2, n))
        elif e.dxftype() == "ARC":
            arc(e.dxf.center.vec2, e.dxf.radius, math.radians(e.dxf.start_angle), math.radians(e.dxf.end_angle))
    return np.concatenate(out)


def _read(text):
    return ezdxf.read(io.StringIO(text))


def _stadium_distance(p):
    """Exact distance from points to the stadium boundary."""
    x, y = p[:, 0], p[:, 1]
    inner = np.abs(x) <= 15
    d_line = np.abs(np.abs(y) - 15)
    cx = np.where(x > 0, 15.0, -15.0)
    d_arc = np.abs(np.hypot(x - cx, y) - 15)
    return np.where(inner, np.minimum(d_line, d_arc), d_arc)


@pytest.mark.parametrize("flavour", ["lwpolyline", "r12"])
def test_read_back_units_layers_geometry(flavour):
    doc = _read(dumps(_content(), flavour=flavour))
    if flavour == "lwpolyline":  # R12 has no $INSUNITS; its flavour is documented as mm
        assert doc.header["$INSUNITS"] == 4
    layers = {e.dxf.layer for e in doc.modelspace()}
    assert {"PROFILE", "PITCH_CURVE", "BASE_CIRCLE", "PRIME_CIRCLE", "BORE", "CENTRE_MARKS"} <= layers
    auditor = doc.audit()
    assert not auditor.has_errors
    pts = sample_entities(doc.modelspace().query("*[layer=='PROFILE']"))
    assert _stadium_distance(pts).max() < 1e-12
    if flavour == "lwpolyline":
        assert doc.header.custom_vars.get("CAMFAB_TOL_MM") == "0.001"


def test_deterministic():
    assert dumps(_content()) == dumps(_content())
    assert dumps(_content(), flavour="r12") == dumps(_content(), flavour="r12")


def test_bad_flavour():
    with pytest.raises(ValueError, match="lwpolyline, r12"):
        dumps(_content(), flavour="spline3")


def test_bore_area_preserved_through_dxf():
    doc = _read(dumps(_content()))
    (bore,) = doc.modelspace().query("LWPOLYLINE[layer=='BORE']")
    pts = sample_entities([bore], n=20000)
    area = 0.5 * abs(np.sum(pts[:, 0] * np.roll(pts[:, 1], -1) - np.roll(pts[:, 0], -1) * pts[:, 1]))
    assert area == pytest.approx(bore_loop(12.0, True).area(), rel=1e-6)
