"""A groove cam's files read back: the STEP solid (OpenCascade) has a groove 2·R_r + b wide along the whole track,
a roller placed in it at several angles touches each flank within the backlash, and the plate's volume is the
disc's minus the bore's and the pocket's; the DXF (ezdxf) holds both flanks and the pitch curve on their
layers; the STL (trimesh) is watertight with the solid's volume."""
from __future__ import annotations

import io
import math

import numpy as np
import pytest

from camfab import pipeline

pytest.importorskip("cadquery", reason="STEP needs cadquery (the step extra)")

from OCP.BRepAlgoAPI import BRepAlgoAPI_Section  # noqa: E402
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeVertex  # noqa: E402
from OCP.BRepCheck import BRepCheck_Analyzer  # noqa: E402
from OCP.BRepExtrema import BRepExtrema_DistShapeShape  # noqa: E402
from OCP.BRepGProp import BRepGProp  # noqa: E402
from OCP.BRepPrimAPI import BRepPrimAPI_MakeCylinder  # noqa: E402
from OCP.gp import gp_Ax2, gp_Dir, gp_Pln, gp_Pnt  # noqa: E402
from OCP.GProp import GProp_GProps  # noqa: E402

from .test_step_occ import read_step  # noqa: E402

NAME = "groove_translating"


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    cam = pipeline.load(NAME)
    out = tmp_path_factory.mktemp("groove")
    cam.run(out, ["dxf", "step", "stl"])
    return cam, out


def _dist(a, b) -> float:
    d = BRepExtrema_DistShapeShape(a, b)
    assert d.IsDone()
    return d.Value()


def test_step_groove_width_and_roller_fit(files):
    cam, out = files
    shape = read_step(out / "GrooveTranslating.step")
    assert BRepCheck_Analyzer(shape).IsValid()
    geo, mech = cam.geometry, cam.geometry.mechanism
    w, b, depth = mech.half_width_mm, mech.backlash_mm, mech.groove_depth_mm
    tol = cam.tolerance()
    # the section half-way down the groove: its edges on the flanks
    sec = BRepAlgoAPI_Section(shape, gp_Pln(gp_Pnt(0, 0, depth / 2), gp_Dir(0, 0, 1)))
    sec.Build()
    section = sec.Shape()
    phi = np.radians(np.arange(0.0, 360.0, 7.5))
    inner, outer = geo.evaluate(phi, 0), geo.evaluate(phi, 1)
    for k in range(len(phi)):
        # from the exact inner flank point the section lies 0 away (the flank face) ...
        vi = BRepBuilderAPI_MakeVertex(gp_Pnt(*inner.point[k], depth / 2)).Vertex()
        assert _dist(vi, section) < tol
        # ... and across the groove: the outer flank face is 2w away along the common normal, nothing nearer
        mid = 0.5 * (inner.point[k] + outer.point[k])
        vm = BRepBuilderAPI_MakeVertex(gp_Pnt(*mid, depth / 2)).Vertex()
        assert _dist(vm, section) == pytest.approx(w, abs=tol)
        # a roller of radius R_r at the pitch point, down to just above the floor: b/2 from both flanks;
        # pushed b/2 onto either flank it touches it (distance 0 within the tolerance)
        n = inner.normal[k]
        for shift, gap in ((0.0, b / 2), (-b / 2, 0.0), (b / 2, 0.0)):
            c = inner.pitch[k] + shift * n
            cyl = BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(c[0], c[1], -1.0), gp_Dir(0, 0, 1)),
                                           mech.roller_radius_mm, depth + 1.0 - 0.5).Shape()
            assert _dist(cyl, shape) == pytest.approx(gap, abs=tol), (math.degrees(phi[k]), shift)


def test_step_volume_is_plate_minus_bore_minus_pocket(files):
    cam, out = files
    shape = read_step(out / "GrooveTranslating.step")
    props = GProp_GProps()
    BRepGProp.VolumeProperties_s(shape, props)
    geo, mech, m = cam.geometry, cam.geometry.mechanism, cam.spec.manufacturing
    from shapely.geometry import Polygon

    from camfab.cad.groove import plate_radius
    from camfab.cad.plate import bore_loop

    pocket = (geo.area(1) - geo.area(0)) * mech.groove_depth_mm
    bore = Polygon(bore_loop(m.bore_mm, m.keyway).flatten(1e-4)).area
    expect = (math.pi * plate_radius(geo) ** 2 - bore) * m.thickness_mm - pocket
    assert props.Mass() == pytest.approx(expect, rel=2e-5)
    # the pocket's area is the groove's width times the pitch curve's length (the flanks' mean length)
    length = _pitch_length(geo)
    assert geo.area(1) - geo.area(0) == pytest.approx(2 * mech.half_width_mm * length, rel=1e-6)


def _pitch_length(geo) -> float:
    x = np.linspace(0.0, 2 * math.pi, 200001)
    p = geo.evaluate(x, 0).pitch
    return float(np.hypot(*np.diff(p, axis=0).T).sum())


def test_dxf_layers_and_stl_watertight(files):
    import ezdxf
    import trimesh

    cam, out = files
    doc = ezdxf.readfile(out / "GrooveTranslating.dxf")
    layers = {e.dxf.layer for e in doc.modelspace()}
    assert {"PROFILE", "PROFILE_2", "PITCH_CURVE", "PLATE", "BORE"} <= layers
    assert "PITCH_CURVE_2" not in layers  # one pitch curve: the groove's centre line
    mesh = trimesh.load(io.BytesIO((out / "GrooveTranslating.stl").read_bytes()), file_type="stl")
    assert mesh.is_watertight and mesh.volume > 0
    shape = read_step(out / "GrooveTranslating.step")
    props = GProp_GProps()
    BRepGProp.VolumeProperties_s(shape, props)
    # the mesh's chords are inscribed within tol/2: its volume within (perimeters × tol/2 × thickness)
    assert mesh.volume == pytest.approx(props.Mass(), rel=2e-4)


def test_assembly_roller_sits_in_the_groove_within_the_backlash(tmp_path):
    """The assembly at several cam angles: the roller (radius R_r, centred on the pitch curve) is b/2 from the
    grooved plate (OCC distance between the read-back parts): it touches neither flank nor the floor; its pin and
    the follower's stem stand off the plate."""
    from camfab.cad import assembly

    from .test_assembly import _read

    cam = pipeline.load(NAME)
    mech, tol = cam.geometry.mechanism, cam.tolerance()
    for ang in (0.0, 50.0, 140.0):
        text = assembly.dumps(cam.spec, cam.geometry, list(cam.shapes().profiles), math.radians(ang))
        path = tmp_path / f"{ang:g}.step"
        path.write_text(text, encoding="utf-8")
        parts = _read(path)
        assert {"cam", "shaft", "roller", "pin", "stem"} <= set(parts)
        assert _dist(parts["roller"].wrapped, parts["cam"].wrapped) == pytest.approx(mech.backlash_mm / 2, abs=tol)
        for other in ("pin", "stem"):  # in front of the plate, off its face
            assert _dist(parts[other].wrapped, parts["cam"].wrapped) > mech.backlash_mm / 2
        stem = parts["stem"].BoundingBox()
        assert stem.ymax > parts["cam"].BoundingBox().ymax  # along the follower's axis (+Y) past the rim


def test_iges_of_a_groove_is_the_pocketed_plate(tmp_path):
    """``--outputs iges`` writes the grooved plate as IGES: read back by OpenCascade, one valid solid with the
    STEP's volume (the pocket included)."""
    from camfab.cli import main

    from .test_kind_iges import read_iges, volume
    from .test_step_occ import read_step

    out = tmp_path / "out"
    assert main(["run", "groove_translating", "-o", str(out), "--outputs", "iges,step"]) == 0
    iges, step = read_iges(out / "GrooveTranslating.igs"), read_step(out / "GrooveTranslating.step")
    assert volume(iges) == pytest.approx(volume(step), rel=1e-7)


def test_shop_file_names_of_a_groove_are_its_one_plate_files(files):
    cam, out = files
    names = pipeline.shop_file_names(cam)
    assert {"GrooveTranslating.step", "GrooveTranslating.stl", "GrooveTranslating.nc"} <= names
    assert not any("_cam" in n or "_pair" in n for n in names)
    assert {p.name for p in out.iterdir()} - {"check.json"} <= names
