"""Translating (wedge) cams as plates: the closed outline, its exact offsets, DXF/STL/STEP and G-code."""
from __future__ import annotations

import io
import math

import numpy as np
import pytest

from camfab.cad.export import build_artifacts, cam_shapes
from camfab.cad.plate import PlateSpec, plate_volume
from camfab.cli import main
from camfab.design.assemble import geometry_from_spec
from camfab.design.spec import design_from_dict
from camfab.discretize import Chain, arcs, measure_deviation, polyline
from camfab.errors import GeometryError, SpecError
from camfab.formats import load_design
from camfab.gcode import Job, dumps, parse, verify
from camfab.gcode.cam import cam_program, signed_distance
from camfab.offset.cutter import offset_curve, pitch_curve, profile_curve, tool_centre_path
from camfab.offset.outline import translating_outline
from tests.conftest import EXAMPLES, base_design

ezdxf = pytest.importorskip("ezdxf")
trimesh = pytest.importorskip("trimesh")


def _wedge(direction="left", rows=None, **follower):
    fol = {"type": "roller", "motion": "translating", "roller_radius_mm": 8.0, "cam_length_mm": 300.0,
           "base_height_mm": 20.0}
    fol.update(follower)
    rows = rows or [("cycloidal", 20.0, 100.0), ("dwell", 0.0, 50.0), ("cycloidal", -20.0, 100.0),
                    ("dwell", 0.0, 50.0)]
    d = base_design(cam={"kind": "translating", "speed_mm_s": 50.0, "direction": direction}, follower=fol,
                    motion=[{"law": law, "lift": lift, "length_mm": span} for law, lift, span in rows])
    d["manufacturing"] = {"thickness_mm": 12.0, "tool_diameter_mm": 10.0}
    return design_from_dict(d)


# a rise straight from the left end: the profile meets the plate's end at a slant
SLANTED = [("poly345", 15.0, 120.0), ("poly345", -15.0, 120.0), ("dwell", 0.0, 60.0)]


@pytest.fixture(scope="module", params=[("left", None), ("right", None), ("left", SLANTED)],
            ids=["left", "right", "slanted"])
def wedge(request):
    spec = _wedge(request.param[0], request.param[1])
    return spec, geometry_from_spec(spec)


def _fine(curve):
    return Chain.from_polyline(polyline(curve, tol=1e-6).points)


def test_outline_is_closed_ccw_and_encloses_the_exact_area(wedge):
    spec, geom = wedge
    c = geom.profiles[0]
    out = profile_curve(c)
    fit = arcs(out, tol=1e-5)
    area = 0.5 * float(np.sum(fit.starts[:, 0] * fit.ends[:, 1] - fit.ends[:, 0] * fit.starts[:, 1]))
    loop = cam_shapes(geom, tol=1e-5, with_pitch=False).profiles[0]
    assert loop.area() > 0  # counter-clockwise
    assert area == pytest.approx(loop.area(), rel=1e-3)  # chord polygon vs arcs
    assert loop.area() == pytest.approx(geom.area(), abs=700 * 1e-5)  # exact ∫ y dx, within perimeter × tol
    # the bottom edge is y = 0 and the plate spans one cam length
    pts = polyline(out, tol=1e-4).points
    assert pts[:, 1].min() == pytest.approx(0.0, abs=1e-12)
    assert np.ptp(pts[:, 0]) == pytest.approx(300.0, abs=1e-9)
    # every point of the exact profile lies on the outline
    s = c.evaluate(np.linspace(0, 300, 997))
    assert float(_fine(out).distance(s.point)[0].max()) <= 1e-6


@pytest.mark.parametrize("d", [0.5, 5.0])
def test_offset_is_exactly_at_distance_with_rounded_corners(wedge, d):
    _, geom = wedge
    c = geom.profiles[0]
    outline = _fine(profile_curve(c))
    off = offset_curve(c, d)
    t = np.linspace(0, off.period, 4001)[:-1]
    dist = outline.distance(off.point(t))[0]
    assert np.abs(dist - d).max() <= 2e-6
    # Steiner: area of the outward offset of a simple closed curve = A + d·perimeter + π d²
    fit0, fitd = polyline(profile_curve(c), tol=1e-6), polyline(off, tol=1e-6)

    def area(p):
        return 0.5 * float(np.sum(p[:-1, 0] * p[1:, 1] - p[1:, 0] * p[:-1, 1]))

    per = float(np.sum(np.hypot(*np.diff(fit0.points, axis=0).T)))
    assert area(fitd.points) == pytest.approx(area(fit0.points) + d * per + math.pi * d * d, abs=0.02)
    # the analytic derivative is the tangent of the curve (finite differences away from breakpoints)
    bp = off.breakpoints
    mids = 0.5 * (bp[:-1] + bp[1:])
    h = 1e-5
    fd = (off.point(mids + h) - off.point(mids - h)) / (2 * h)
    assert np.abs(fd - off.derivative(mids)).max() <= 1e-5


@pytest.mark.parametrize("tol", [1e-2, 1e-3, 1e-4])
def test_dxf_stl_read_back_within_tol(wedge, tol):
    spec, geom = wedge
    dxf, stl = build_artifacts(spec, geom, ["dxf", "stl"], tol=tol)
    doc = ezdxf.read(io.StringIO(dxf.data.decode()))
    assert not doc.audit().has_errors and doc.header["$INSUNITS"] == 4
    (pl,) = doc.modelspace().query("LWPOLYLINE[layer=='PROFILE']")
    rows = np.array(list(pl.get_points("xyb")))
    curve = profile_curve(geom.profiles[0])
    assert measure_deviation(rows, curve).max <= tol
    assert not doc.modelspace().query("CIRCLE[layer=='BASE_CIRCLE']")  # a plate has no base circle
    assert pitch_curve(geom.profiles[0]) is None
    mesh = trimesh.load(trimesh.util.wrap_as_stream(stl.data), file_type="stl")
    assert mesh.is_watertight and mesh.is_winding_consistent and mesh.volume > 0
    exact = geom.area() * spec.manufacturing.thickness_mm
    assert abs(mesh.volume - exact) <= 700 * tol * spec.manufacturing.thickness_mm
    top = mesh.vertices[np.isclose(mesh.vertices[:, 2], spec.manufacturing.thickness_mm)][:, :2]
    assert float(_fine(curve).distance(top)[0].max()) <= tol + 1e-6


@pytest.mark.slow
def test_step_plate_volume_and_reimport(tmp_path):
    cq = pytest.importorskip("cadquery")
    spec = _wedge()
    geom = geometry_from_spec(spec)
    (art,) = build_artifacts(spec, geom, ["step"], tol=1e-5)
    path = tmp_path / "w.step"
    path.write_bytes(art.data)
    solid = cq.importers.importStep(str(path)).val()
    assert solid.isValid()
    t = spec.manufacturing.thickness_mm
    loop = cam_shapes(geom, tol=1e-5, with_pitch=False).profiles[0]
    assert solid.Volume() == pytest.approx(plate_volume(loop, PlateSpec(t, 0.0, False)), rel=1e-9)
    assert solid.Volume() == pytest.approx(geom.area() * t, rel=1e-6)
    bb = solid.BoundingBox()
    assert (bb.xlen, bb.zlen) == (pytest.approx(300.0, abs=1e-6), pytest.approx(t, abs=1e-6))


def test_gcode_for_the_plate_verifies_in_every_post(wedge):
    spec, geom = wedge
    c = geom.profiles[0]
    tol, r = 1e-3, 5.0
    job = Job(tool_diameter_mm=2 * r, depth_mm=spec.manufacturing.thickness_mm, tolerance_mm=tol,
              design_name=spec.name)
    cp = cam_program(c, job, tol=tol)
    part = signed_distance(profile_curve(c), tol=tol)
    centre = signed_distance(offset_curve(c, r), tol=tol)
    for post in ("linuxcnc", "fanuc", "grbl"):
        rep = verify(parse(dumps(cp.program, post)), exact_curve_distance=centre, part_distance=part,
                     tool_radius=r, tol=tol, safe_z=job.safe_z_mm,
                     curve_points=offset_curve(c, r).point(np.linspace(0, offset_curve(c, r).period, 2000)))
        assert rep.ok, rep.to_dict()["problems"]
        assert rep.max_deviation_mm <= tol and not rep.gouge
        assert rep.coverage_gap_mm <= tol  # the whole outline, corners included, is cut


def test_tool_path_rounds_the_plate_corners():
    spec = _wedge()
    c = geometry_from_spec(spec).profiles[0]
    path = tool_centre_path(c, 5.0, tol=1e-3)
    assert path.max_deviation <= 1e-3 and path.shapely_deviation <= 1e-3  # the coarse guard agrees too
    # four corner arcs of radius 5 about the plate corners: the fit carries them as arcs
    fit = path.arcs
    radii = np.hypot(*(fit.starts - fit.centres).T)[fit.sweeps != 0]
    assert np.sum(np.isclose(radii, 5.0, atol=1e-9)) >= 4


def test_concave_stretch_tighter_than_the_cutter_is_refused():
    spec = _wedge()
    c = geometry_from_spec(spec).profiles[0]
    with pytest.raises(GeometryError, match="largest cutter") as e:
        tool_centre_path(c, 200.0, tol=1e-3)
    assert " mm–" in str(e.value) and "°" not in str(e.value)  # the stretch is named in mm of travel


def test_plate_without_height_and_bore_are_refused(tmp_path):
    spec = _wedge(base_height_mm=0.0)
    with pytest.raises(GeometryError, match="base_height_mm"):
        translating_outline(geometry_from_spec(spec).profiles[0])
    d = base_design(cam={"kind": "translating", "speed_mm_s": 50.0},
                    follower={"type": "roller", "motion": "translating", "roller_radius_mm": 8.0,
                              "cam_length_mm": 200.0, "base_height_mm": 10.0},
                    motion=[{"law": "cycloidal", "lift": 8.0, "length_mm": 100.0},
                            {"law": "cycloidal", "lift": -8.0, "length_mm": 100.0}])
    d["manufacturing"] = {"bore_mm": 20.0}
    with pytest.raises(SpecError, match="manufacturing.bore_mm"):
        design_from_dict(d)
    # the CLI refuses a zero-height plate with exit 2 and writes nothing
    path = tmp_path / "w.toml"
    path.write_text((EXAMPLES / "wedge_translating.toml").read_text().replace("base_height_mm = 20.0",
                                                                              "base_height_mm = 0.0"))
    out = tmp_path / "out"
    assert main(["export", str(path), "--dxf", "-o", str(out)]) != 0
    assert not out.exists() or not any(out.iterdir())


def test_example_wedge_runs_end_to_end(tmp_path):
    assert main(["run", str(EXAMPLES / "wedge_translating.toml"), "-o", str(tmp_path)]) == 0
    spec = load_design(EXAMPLES / "wedge_translating.toml")
    assert {p.name for p in tmp_path.iterdir()} >= {f"{spec.name}.dxf", f"{spec.name}.stl", f"{spec.name}.nc"}
