"""The ribbed cylinder's STEP read back by OpenCascade: one valid solid, the rib ``rib_width_mm`` wide where it runs
round (probe lines along the axis through the mid-line, intersected with the solid's faces), its top on the top
radius, and each of the two rollers, placed at several angles, clear of the rib by half the backlash (rays from its
axis, ``IntCurvesFace``)."""
from __future__ import annotations

import math

import numpy as np
import pytest

from camfab.design.cylindrical import pitch_3d
from camfab.pipeline import load

pytest.importorskip("cadquery", reason="STEP needs cadquery (the step extra)")

from OCP.BRepCheck import BRepCheck_Analyzer  # noqa: E402
from OCP.gp import gp_Dir, gp_Lin, gp_Pnt  # noqa: E402
from OCP.IntCurvesFace import IntCurvesFace_ShapeIntersector  # noqa: E402
from OCP.TopAbs import TopAbs_SOLID  # noqa: E402
from OCP.TopExp import TopExp_Explorer  # noqa: E402

from camfab.cad.rib import rib_solid  # noqa: E402
from camfab.cad.step import solid_dumps  # noqa: E402
from tests.cad.test_step_occ import bop_faults, read_step  # noqa: E402
from tests.design.test_cylinder_rib import RIB_TOML  # noqa: E402

pytestmark = pytest.mark.slow  # one rib lofted, cut to its top and fused to the body (~5 s), probed by OCC


@pytest.fixture(scope="module")
def made(tmp_path_factory):
    folder = tmp_path_factory.mktemp("rib")
    (folder / "rib.toml").write_text(RIB_TOML, encoding="utf-8")
    geom = load(folder / "rib.toml").geometry
    solid, dev = rib_solid(geom, tol=0.01)
    (folder / "ribbed.step").write_text(solid_dumps(solid, name="ribbed"), encoding="utf-8")
    hits = IntCurvesFace_ShapeIntersector()
    shape = read_step(folder / "ribbed.step")
    hits.Load(shape, 1e-9)
    return geom, shape, dev, hits, solid


def test_rib_solid_passes_the_boolean_argument_analyser(made):
    """The ribbed cylinder as built (the rib a loft through its exact sections, as the groove's tool, cut to the
    top cylinder and fused to the body, its top and root edges rebuilt exactly) and read back from its STEP passes
    BOPAlgo_ArgumentAnalyzer with every check on; the sweep it replaces had curve-on-surface faults of up to
    4.9e-5 mm, and the boolean's top and root edges, read back, of up to 8e-7 mm."""
    _, shape, _, _, solid = made
    assert bop_faults(solid.wrapped) == []
    assert bop_faults(shape) == []


def _ray(hits, p, d, lo, hi) -> np.ndarray:
    hits.Perform(gp_Lin(gp_Pnt(*map(float, p)), gp_Dir(*map(float, d))), lo, hi)
    return np.array([hits.WParameter(i) for i in range(1, hits.NbPnt() + 1)])


def test_rib_step_is_one_valid_solid(made):
    _, shape, dev, *_ = made
    assert BRepCheck_Analyzer(shape).IsValid()
    ex, solids = TopExp_Explorer(shape, TopAbs_SOLID), 0
    while ex.More():
        solids += 1
        ex.Next()
    assert solids == 1 and dev <= 0.01


def test_rib_width_and_top_on_the_solid(made):
    """Where the rib runs round (140° to 180°), a line along the axis through the mid-line point on the pitch
    radius leaves the rib at ± w/2; a radial line through it leaves the solid on the top radius."""
    geom, _, dev, hits, _ = made
    w, top = geom.cylinder.rib_width_mm, geom.cylinder.outer_radius_mm
    for p in pitch_3d(geom, np.radians([145.0, 160.0, 175.0])):
        t = _ray(hits, p, (0.0, 0.0, 1.0), -w, w)
        assert t[t > 0].min() == pytest.approx(w / 2, abs=2 * dev + 1e-3)
        assert -t[t < 0].max() == pytest.approx(w / 2, abs=2 * dev + 1e-3)
        u = np.array([p[0], p[1], 0.0]) / math.hypot(p[0], p[1])
        t = _ray(hits, p, u, 0.0, 20.0)
        assert t.min() == pytest.approx(top - geom.cylinder.radius_mm, abs=1e-6)


def test_rollers_clear_the_rib_by_half_the_backlash_on_the_solid(made):
    """Each roller (radius R_r about the radial line ±d along the axis from the mid-line point) at several angles
    (rise, dwell, return): rays from its axis in its plane, every 4° (then 0.125° about the nearest) and at 5 radii
    from just above the root to just below the top, meet the solid at R_r + b/2 at the nearest."""
    geom, _, dev, hits, _ = made
    cyl, mech = geom.cylinder, geom.mechanism
    rr, d = mech.roller_radius_mm, mech.rib_offset_mm
    z = np.array([0.0, 0.0, 1.0])
    for theta in np.radians([30.0, 100.0, 160.0, 250.0]):
        p = pitch_3d(geom, np.array([theta]))[0]
        u = np.array([p[0], p[1], 0.0]) / math.hypot(p[0], p[1])
        e_x = np.cross(z, u)
        for side in (1, -1):
            clear = np.inf
            for r in np.linspace(cyl.inner_radius_mm + 0.3, cyl.outer_radius_mm - 0.05, 5):
                axis = p + (r - cyl.radius_mm) * u + side * d * z

                def nearest(b, axis=axis, e_x=e_x):
                    t = _ray(hits, axis, math.cos(b) * e_x + math.sin(b) * z, 0.0, 3 * rr)
                    return t.min() if t.size else np.inf
                coarse = np.radians(np.arange(0.0, 360.0, 4.0))
                best = coarse[int(np.argmin([nearest(b) for b in coarse]))]
                fine = best + np.radians(np.linspace(-2.0, 2.0, 33))  # 0.125° steps: under 0.02 µm of cosine error
                clear = min(clear, min(nearest(b) for b in fine) - rr)
            assert clear == pytest.approx(cyl.backlash_mm / 2, abs=2 * dev + 1e-3)


def test_rib_mesh_is_watertight_and_holds_the_volume(made):
    """The STL's mesh of the solid (:func:`~camfab.cad.cylinder.solid_mesh`, as ``rib_stl`` makes it): watertight,
    its volume within tol·area of OCC's adaptive volume of the solid, its bounds the top radius and the length."""
    import cadquery as cq
    from OCP.BRepGProp import BRepGProp
    from OCP.GProp import GProp_GProps

    from camfab.cad.cylinder import solid_mesh

    geom, shape, *_ = made
    mesh = solid_mesh(cq.Shape.cast(shape), 0.01)
    props = GProp_GProps()
    BRepGProp.VolumeProperties_s(shape, props, 1e-6, False, False)
    assert mesh.is_watertight
    assert abs(mesh.volume - props.Mass()) <= 0.01 * mesh.area
    top = geom.cylinder.outer_radius_mm
    np.testing.assert_allclose(mesh.bounds, [[-top, -top, 0.0], [top, top, geom.cylinder.length_mm]], atol=0.02)
