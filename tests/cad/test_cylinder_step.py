"""The grooved cylinder's STEP read back by OpenCascade: a valid solid (``BRepCheck_Analyzer``), the groove as wide
as the roller plus the backlash along the whole track (probe lines across the groove through the exact pitch
curve, intersected with the solid's faces), and the roller placed at several angles clear of both flanks by half
the backlash (rays from its axis, ``IntCurvesFace``).  Also the developed DXF read back with ezdxf: its layers and the
pitch curve's points on the exact law."""
from __future__ import annotations

import io
import math
from pathlib import Path

import numpy as np
import pytest

from camfab.design.cylindrical import pitch_3d
from camfab.design.mechanisms import geometry_from_spec
from camfab.formats import load_design

pytest.importorskip("cadquery", reason="STEP needs cadquery (the step extra)")

from OCP.BRepCheck import BRepCheck_Analyzer  # noqa: E402
from OCP.gp import gp_Dir, gp_Lin, gp_Pnt  # noqa: E402
from OCP.IntCurvesFace import IntCurvesFace_ShapeIntersector  # noqa: E402
from OCP.TopAbs import TopAbs_SOLID  # noqa: E402
from OCP.TopExp import TopExp_Explorer  # noqa: E402

from camfab.cad.cylinder import cylinder_step, developed_dxf  # noqa: E402
from tests.cad.test_step_occ import read_step  # noqa: E402

pytestmark = pytest.mark.slow  # one grooved cylinder swept and cut (~30 s), probed by OCC

EXAMPLE = Path(__file__).parents[2] / "camfab" / "examples" / "cylindrical_translating.toml"


@pytest.fixture(scope="module")
def made(tmp_path_factory):
    geom = geometry_from_spec(load_design(EXAMPLE))
    text, dev = cylinder_step(geom, tol=0.01, name="barrel")
    path = tmp_path_factory.mktemp("cyl") / "barrel.step"
    path.write_text(text, encoding="utf-8")
    return geom, read_step(path), dev


def _across(geom, phi):
    """Pitch points (3D) and the unit directions across the groove there: the developed normal wrapped onto the
    pitch cylinder's tangent plane."""
    R, sigma = geom.cylinder.radius_mm, geom.mechanism.sense
    s = geom.at_radius(R).evaluate(phi)
    a = 0.5 * math.pi + sigma * s.pitch[:, 0] / R
    e_x = sigma * np.stack([-np.sin(a), np.cos(a), 0 * a], axis=1)
    across = s.normal[:, :1] * e_x + s.normal[:, 1:] * np.array([0.0, 0.0, 1.0])
    return pitch_3d(geom, phi), across


def test_step_is_one_valid_solid(made):
    _, shape, dev = made
    assert BRepCheck_Analyzer(shape).IsValid()
    ex, solids = TopExp_Explorer(shape, TopAbs_SOLID), 0
    while ex.More():
        solids += 1
        ex.Next()
    assert solids == 1
    assert dev <= 0.01


def test_groove_width_is_roller_plus_backlash_along_the_track(made):
    """Along the track (rise, dwell, return) the probe line across the groove through the pitch point meets the
    flanks at ± (R_r + backlash/2): the width on the solid is the roller diameter plus the backlash."""
    geom, shape, dev = made
    w = geom.mechanism.half_width(geom.cylinder.radius_mm)
    phi = np.radians(np.r_[np.arange(5.0, 360.0, 15.0), 0.5, 359.5])  # and both sides of the loft's closing
    points, across = _across(geom, phi)
    hits = IntCurvesFace_ShapeIntersector()
    hits.Load(shape, 1e-9)
    widths, sides = [], []
    for p, d in zip(points, across, strict=True):
        hits.Perform(gp_Lin(gp_Pnt(*map(float, p)), gp_Dir(*map(float, d))), -3 * w, 3 * w)
        t = np.array([hits.WParameter(i) for i in range(1, hits.NbPnt() + 1)])
        plus, minus = t[t > 0].min(), -t[t < 0].max()
        widths.append(plus + minus)
        sides += [plus, minus]
    # 12.05 mm: 2 × 6 mm roller + 0.05 mm backlash, within 0.44 µm measured (the loft between its 48 sections),
    # a tenth of the design's 0.01 mm tolerance
    np.testing.assert_allclose(widths, 2 * w, atol=1e-3)
    np.testing.assert_allclose(sides, w, atol=2 * dev + 1e-3)


def test_roller_clears_both_flanks_by_half_the_backlash(made):
    """The roller (radius R_r about the radial line through the pitch point) placed at several angles (rise, dwell,
    return) clears each flank by half the backlash over its whole height in the groove: rays from its axis, normal
    to it (where the shortest distance between a cylinder and a surface lies), every 4° around and at 6 radii
    from just above the groove bottom to the outer surface, meet the solid at R_r + b/2 at the nearest, on the +z
    side and on the −z side alike (IntCurvesFace on the STEP's faces)."""
    geom, shape, dev = made
    cyl, rr = geom.cylinder, geom.mechanism.roller_radius_mm
    half = cyl.backlash_mm / 2
    hits = IntCurvesFace_ShapeIntersector()
    hits.Load(shape, 1e-9)
    phi = np.radians([20.0, 70.0, 160.0, 250.0, 340.0])
    beta = np.radians(np.arange(0.0, 360.0, 4.0))
    for p, d in zip(*_across(geom, phi), strict=True):
        u = np.array([p[0], p[1], 0.0]) / math.hypot(p[0], p[1])
        v = np.cross(u, d)
        clear = {1: np.inf, -1: np.inf}
        for r in np.linspace(cyl.inner_radius_mm + 0.2, cyl.outer_radius_mm - 0.01, 6):
            axis = p + (r - cyl.radius_mm) * u
            for b in beta:
                ray = math.cos(b) * d + math.sin(b) * v
                hits.Perform(gp_Lin(gp_Pnt(*map(float, axis)), gp_Dir(*map(float, ray))), 0.0, 3 * rr)
                if hits.NbPnt():
                    t = min(hits.WParameter(i) for i in range(1, hits.NbPnt() + 1))
                    side = 1 if ray[2] > 0 else -1
                    clear[side] = min(clear[side], t - rr)
        assert clear[1] == pytest.approx(half, abs=2 * dev + 1e-3)
        assert clear[-1] == pytest.approx(half, abs=2 * dev + 1e-3)


def test_developed_dxf_layers_and_law():
    """The DXF read back: the pitch curve, both flanks and the outline on their layers; the pitch curve's
    vertices on the exact law y = z0 + S(x/R), x from 0 to 2πR."""
    ezdxf = pytest.importorskip("ezdxf")
    geom = geometry_from_spec(load_design(EXAMPLE))
    text, dev = developed_dxf(geom, tol=0.01, name="barrel")
    assert dev <= 0.01
    doc = ezdxf.read(io.StringIO(text))
    layers = {e.dxf.layer for e in doc.modelspace()}
    assert {"PITCH_CURVE", "PROFILE", "PROFILE_2", "OUTLINE"} <= layers
    (pitch,) = [e for e in doc.modelspace() if e.dxf.layer == "PITCH_CURVE"]
    pts = np.array([(x, y) for x, y, *_ in pitch.get_points("xyseb")])
    R, z0 = geom.cylinder.radius_mm, geom.mechanism.z0_for(geom.program)
    x = np.linspace(0.0, 2 * math.pi * R, 200001)
    exact = np.stack([x, z0 + geom.program.evaluate(x / R, (0,))[0]], axis=1)
    far = [np.hypot(*(exact - p).T).min() for p in pts]
    assert max(far) <= 0.01  # every vertex within the tolerance of the law (arc ends lie on the fitted chain)
    assert pts[0, 0] == pytest.approx(0.0, abs=1e-12) and pts[-1, 0] == pytest.approx(2 * math.pi * R)
