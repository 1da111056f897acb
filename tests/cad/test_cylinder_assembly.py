"""The cylindrical cam's assembly STEP read back with cadquery/OCP at several cam angles (rise, dwell, return):
the parts named, the roller — placed from the exact motion — clear of each flank by half the backlash
(``BRepExtrema_DistShapeShape`` from the roller to the cam's +z and −z halves about the roller axis), within
2·(the loft's measured path deviation) + 1 µm, and no common volume with the cam; the same roller pushed by the
backlash along the axis interferes (the test can fail)."""
from __future__ import annotations

import math

import pytest

from camfab import pipeline

cq = pytest.importorskip("cadquery")

from OCP.BRepAlgoAPI import BRepAlgoAPI_Common  # noqa: E402
from OCP.BRepExtrema import BRepExtrema_DistShapeShape  # noqa: E402

from camfab.cad import cylinder_assembly  # noqa: E402
from camfab.cad.kind_exports import cylinder_solid  # noqa: E402

from .test_assembly import _bound, _read, _volume  # noqa: E402

pytestmark = pytest.mark.slow  # grooved cylinders (~6 s each), assemblies and their distances


@pytest.fixture(scope="module")
def cam():
    cam = pipeline.load("cylindrical_translating")
    solid, dev = cylinder_solid(cam, pipeline.Request(frozenset({pipeline.Output.ASSEMBLY})))
    return cam, solid, dev


def _dist(a, b) -> float:
    d = BRepExtrema_DistShapeShape(a, b)
    assert d.IsDone()
    return d.Value()


@pytest.mark.parametrize("deg", [70.0, 160.0, 250.0])
def test_roller_clears_both_flanks_by_half_the_backlash(cam, deg, tmp_path):
    cam, solid, dev = cam
    geom, tol = cam.geometry, cam.tolerance()
    path = tmp_path / "assembly.step"
    path.write_text(cylinder_assembly.dumps(cam.spec, geom, solid, math.radians(deg)), encoding="utf-8")
    parts = _read(path)
    assert set(parts) == {"cam", "shaft", "roller", "pin", "slide"}
    roller, body = parts["roller"], parts["cam"]
    zc, half = cylinder_assembly.roller_axis(geom, math.radians(deg)), geom.cylinder.backlash_mm / 2
    assert roller.Center().z == pytest.approx(zc, abs=1e-9)
    big = 4 * geom.cylinder.outer_radius_mm
    for z0 in (zc, zc - big):  # the cam's half above the roller axis (+z flank), then below it (−z flank)
        side = body.intersect(cq.Solid.makeBox(big, big, big, cq.Vector(-big / 2, -big / 2, z0)))
        assert _dist(roller.wrapped, side.wrapped) == pytest.approx(half, abs=2 * dev + 1e-3)
    for other in ("pin", "slide"):
        assert _dist(parts[other].wrapped, body.wrapped) >= half - 2 * dev - 1e-3
    width, size = geom.cylinder.groove_depth_mm, geom.cylinder.outer_radius_mm
    assert _volume(BRepAlgoAPI_Common(roller.wrapped, body.wrapped).Shape()) <= _bound(tol, size, width)
    pushed = roller.translate(cq.Vector(0, 0, 2 * half + 10 * tol))
    assert _volume(BRepAlgoAPI_Common(pushed.wrapped, body.wrapped).Shape()) > _bound(tol, size, width)


OSCILLATING = {"name": "barrel_arm", "cam": {"kind": "cylindrical"},
               "cylinder": {"radius_mm": 40.0, "length_mm": 70.0, "groove_depth_mm": 10.0, "backlash_mm": 0.05},
               "follower": {"type": "roller", "motion": "oscillating", "roller_radius_mm": 6.0, "arm_length_mm": 60.0},
               "motion": [{"law": "cycloidal", "lift": 20.0, "angle_deg": 160.0}, {"law": "dwell", "angle_deg": 20.0},
                          {"law": "cycloidal", "lift": -20.0, "angle_deg": 160.0}, {"law": "dwell", "angle_deg": 20.0}],
               "manufacturing": {"tolerance_mm": 0.01}}


def test_oscillating_arm_reaches_from_its_pivot_to_the_roller(tmp_path):
    """An oscillating follower at 80° (mid-rise, arm at 10°): the roller's axis at X = −σ·L(1 − cos φ), clear of
    both flanks; the arm touches the pin and the pivot, and stands off the cam."""
    from camfab.design.spec import design_from_dict

    cam = pipeline.Cam(design_from_dict(OSCILLATING))
    solid, dev = cylinder_solid(cam, pipeline.Request(frozenset({pipeline.Output.ASSEMBLY})))
    geom, phi = cam.geometry, math.radians(80.0)
    arm = math.radians(float(geom.program.evaluate([phi], (0,))[0][0]))
    assert cylinder_assembly.axis_x(geom, phi) == pytest.approx(-60.0 * (1 - math.cos(arm)), abs=1e-9)
    path = tmp_path / "arm.step"
    path.write_text(cylinder_assembly.dumps(cam.spec, geom, solid, phi), encoding="utf-8")
    parts = _read(path)
    assert set(parts) == {"cam", "shaft", "roller", "pin", "arm", "pivot"}
    body, half = parts["cam"], geom.cylinder.backlash_mm / 2
    assert _dist(parts["roller"].wrapped, body.wrapped) == pytest.approx(half, abs=2 * dev + 1e-3)
    assert _dist(parts["arm"].wrapped, parts["pin"].wrapped) < 1e-6
    assert _dist(parts["arm"].wrapped, parts["pivot"].wrapped) < 1e-6
    assert _dist(parts["arm"].wrapped, body.wrapped) > half


def test_run_writes_the_assembly(tmp_path):
    res = pipeline.run(pipeline.load("cylindrical_translating"), tmp_path,
                       pipeline.Request(frozenset({pipeline.Output.ASSEMBLY}), angle=30.0))
    assert "assembly" not in res.not_applicable
    assert set(_read(tmp_path / "BarrelCam_assembly.step")) == {"cam", "shaft", "roller", "pin", "slide"}
