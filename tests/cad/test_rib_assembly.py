"""The ribbed cylinder's assembly STEP read back with cadquery/OCP at three cam angles (rise, dwell, return): the
parts named (two rollers, two pins, one slide), each roller's axis w/2 + R_r + b/2 along the cam axis from the rib's
mid-line (the exact motion), each roller clear of the rib flank it faces by half the backlash
(``BRepExtrema_DistShapeShape``, within 2·(the solid's measured path deviation) + 1 µm, the nearest point of the cam
on the rib's side of the roller), no common volume with the cam; the same roller moved along the axis by b/2 + 10·tol
into the rib interferes (the test can fail).  A conical design's rollers are the cones of its check."""
from __future__ import annotations

import math

import pytest

from camfab import pipeline

cq = pytest.importorskip("cadquery")

from OCP.BRepAlgoAPI import BRepAlgoAPI_Common  # noqa: E402
from OCP.BRepExtrema import BRepExtrema_DistShapeShape  # noqa: E402

from camfab.cad import cylinder_assembly  # noqa: E402
from camfab.cad.kind_exports import cylinder_solid  # noqa: E402
from tests.design.test_cylinder_rib import RIB_TOML  # noqa: E402

from .test_assembly import _bound, _read, _volume  # noqa: E402

pytestmark = pytest.mark.slow  # one ribbed cylinder (~22 s of CPU), three assemblies read back and measured

#: mm around the follower's parts in which the cam is measured (:func:`_near`), above every distance compared
MARGIN = 3.0
PARTS = {"cam", "shaft", "roller_1", "roller_2", "pin_1", "pin_2", "slide"}


@pytest.fixture(scope="module")
def made(tmp_path_factory):
    src = tmp_path_factory.mktemp("rib") / "rib.toml"
    src.write_text(RIB_TOML, encoding="utf-8")
    cam = pipeline.load(src)
    solid, dev = cylinder_solid(cam, pipeline.Request(frozenset({pipeline.Output.ASSEMBLY})))
    return cam, solid, dev


def _near(parts):
    """The cam within ``MARGIN`` of the follower's parts (their bounding box grown by it): any point of the cam
    left out is farther than ``MARGIN`` from every part, so a distance under it, or a common volume, measured to
    this piece is the one to the whole cam (and costs a tenth)."""
    bb = cq.Compound.makeCompound([s for k, s in parts.items() if k not in ("cam", "shaft")]).BoundingBox()
    m = MARGIN
    corner = cq.Vector(bb.xmin - m, bb.ymin - m, bb.zmin - m)
    box = cq.Solid.makeBox(bb.xlen + 2 * m, bb.ylen + 2 * m, bb.zlen + 2 * m, corner)
    return parts["cam"].intersect(box)


def _nearest(a, b) -> tuple[float, float]:
    """The distance between two shapes and the z of the nearest point on ``b``."""
    d = BRepExtrema_DistShapeShape(a, b)
    assert d.IsDone()
    return d.Value(), d.PointOnShape2(1).Z()


@pytest.mark.parametrize("deg", [70.0, 160.0, 250.0])
def test_each_roller_clears_its_rib_flank_by_half_the_backlash(made, deg, tmp_path):
    cam, solid, dev = made
    geom, tol, cyl = cam.geometry, cam.tolerance(), cam.geometry.cylinder
    phi = math.radians(deg)
    path = tmp_path / "assembly.step"
    path.write_text(cylinder_assembly.dumps(cam.spec, geom, solid, phi), encoding="utf-8")
    parts = _read(path)
    assert set(parts) == PARTS
    body, half = _near(parts), cyl.backlash_mm / 2
    zc = float(geom.program.evaluate([phi], (0,))[0][0]) + geom.mechanism.z0_for(geom.program)  # the exact motion
    offset = cyl.rib_width_mm / 2 + geom.mechanism.roller_radius_mm + half
    for name, side in (("roller_1", 1), ("roller_2", -1)):
        roller = parts[name]
        assert roller.Center().z == pytest.approx(zc + side * offset, abs=1e-9)
        gap, z_cam = _nearest(roller.wrapped, body.wrapped)
        assert gap == pytest.approx(half, abs=2 * dev + 1e-3), name
        assert side * (z_cam - roller.Center().z) < 0  # on the flank it faces: between the rollers
        assert _volume(BRepAlgoAPI_Common(roller.wrapped, body.wrapped).Shape()) == pytest.approx(0.0, abs=1e-9)
        pushed = roller.translate(cq.Vector(0, 0, -side * (half + 10 * tol)))  # into the rib
        into = _volume(BRepAlgoAPI_Common(pushed.wrapped, body.wrapped).Shape())
        assert into > _bound(tol, cyl.outer_radius_mm, cyl.groove_depth_mm), name
    for other in ("pin_1", "pin_2", "slide"):
        assert min(_nearest(parts[other].wrapped, body.wrapped)[0], MARGIN) >= half
    for k in (1, 2):  # the slide carries both pins
        assert _nearest(parts[f"pin_{k}"].wrapped, parts["slide"].wrapped)[0] < 1e-6


def test_run_writes_the_rib_assembly(made, tmp_path):
    """``run`` with the assembly no longer skips it for a rib: the file reads back as an assembly of the named parts
    (the cam's solid is the fixture's, kept per cam)."""
    cam, _, _ = made
    res = pipeline.run(cam, tmp_path, pipeline.Request(frozenset({pipeline.Output.ASSEMBLY}), angle=30.0))
    assert "assembly" not in res.not_applicable
    assert set(_read(tmp_path / "Ribbed_assembly.step")) == PARTS


def test_conical_rib_rollers_are_the_cones_of_the_check():
    """A conical rib design: each roller's conical face has its apex on the cam axis at the roller's height and the
    half-angle atan(R_r/R) of the check, the heights the check's offset from the exact motion (built on a plain
    cylinder: the placement, not the rib, is tested here)."""
    import tomllib

    from OCP.BRepAdaptor import BRepAdaptor_Surface
    from OCP.GeomAbs import GeomAbs_Cone

    from camfab.design.spec import design_from_dict

    conical = RIB_TOML.replace("backlash_mm = 0.1", 'backlash_mm = 0.1\nroller = "conical"')
    cam = pipeline.Cam(design_from_dict(tomllib.loads(conical)))
    geom, phi = cam.geometry, math.radians(100.0)
    cyl, rr = geom.cylinder, geom.mechanism.roller_radius_mm
    plain = cq.Solid.makeCylinder(cyl.inner_radius_mm, cyl.length_mm)
    items = {name: shape for name, shape, *_ in cylinder_assembly.parts(cam.spec, geom, plain, phi).items}
    assert set(items) == PARTS
    zc = float(geom.program.evaluate([phi], (0,))[0][0]) + geom.mechanism.z0_for(geom.program)
    for name, side in (("roller_1", 1), ("roller_2", -1)):
        (cone,) = [s for f in items[name].Faces() if (s := BRepAdaptor_Surface(f.wrapped)).GetType() == GeomAbs_Cone]
        apex, axis = cone.Cone().Apex(), cone.Cone().Axis().Direction()
        z = zc + side * (cyl.rib_width_mm / 2 + rr + cyl.backlash_mm / 2)
        assert (apex.X(), apex.Y(), apex.Z()) == pytest.approx((0.0, 0.0, z), abs=1e-9)
        assert abs(axis.Y()) == pytest.approx(1.0, abs=1e-12)
        assert cone.Cone().SemiAngle() == pytest.approx(math.atan2(rr, cyl.radius_mm), abs=1e-12)
