"""`camfab export`: every artifact read back independently and compared with the exact profile."""
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
from camfab.discretize import Chain, measure_deviation, polyline
from camfab.offset.cutter import profile_curve
from tests.conftest import DESIGNS, EXAMPLES, base_design

ezdxf = pytest.importorskip("ezdxf")
trimesh = pytest.importorskip("trimesh")



def _by_angle(points):
    """Unordered outline points (star-shaped about the cam centre) as a closed polyline."""
    pts = np.unique(np.round(points, 12), axis=0)
    return pts[np.argsort(np.arctan2(pts[:, 1], pts[:, 0]))]


def _points_to_curve(points, curve):
    """Upper bound of the largest distance from points to the exact curve (via a 1e-6 mm polyline)."""
    fine = Chain.from_polyline(polyline(curve, tol=1e-6).points)
    return float(fine.distance(points)[0].max()) + 1e-6


def _profile_rows(text):
    doc = ezdxf.read(io.StringIO(text))
    assert doc.header["$INSUNITS"] == 4
    assert not doc.audit().has_errors
    (pl,) = doc.modelspace().query("LWPOLYLINE[layer=='PROFILE']")
    return np.array(list(pl.get_points("xyb")))


@pytest.mark.parametrize("name", sorted(DESIGNS))
@pytest.mark.parametrize("tol", [1e-2, 1e-3, 1e-4])
def test_dxf_read_back_within_tol(name, tol):
    spec = DESIGNS[name]()
    geom = geometry_from_spec(spec)
    (art,) = build_artifacts(spec, geom, ["dxf"], tol=tol)
    rows = _profile_rows(art.data.decode())
    dev = measure_deviation(rows, profile_curve(geom.profiles[0]))
    assert dev.max <= tol
    assert art.deviation_mm <= tol


def test_arc_count_far_below_polyline_at_1um():
    spec = DESIGNS["ejemplo9rt"]()
    shapes = cam_shapes(geometry_from_spec(spec), tol=1e-3, with_pitch=False)
    assert len(shapes.profiles[0].points) < 120  # a uniform 1° polyline needs 360 vertices and is not within 1 µm


def test_stl_watertight_volume_and_deviation():
    spec = DESIGNS["ejemplo9rt"]()
    geom = geometry_from_spec(spec)
    (art,) = build_artifacts(spec, geom, ["stl"], tol=1e-3)
    mesh = trimesh.load(trimesh.util.wrap_as_stream(art.data), file_type="stl")
    assert mesh.is_watertight and mesh.is_winding_consistent
    m = spec.manufacturing
    hole = PlateSpec(m.thickness_mm, m.bore_mm, m.keyway).hole().area()
    exact = (geom.area() - hole) * m.thickness_mm
    perimeter = 2 * math.pi * 45 + 2 * math.pi * 6 + 10
    assert abs(mesh.volume - exact) <= perimeter * 1e-3 * m.thickness_mm
    assert art.deviation_mm <= 1e-3
    # the mesh's top-face outline is within tol of the exact profile
    top = mesh.vertices[np.isclose(mesh.vertices[:, 2], m.thickness_mm)][:, :2]
    d = measure_deviation(_by_angle(top[np.hypot(*top.T) > 20]), profile_curve(geom.profiles[0]))
    assert d.max <= 1e-3


@pytest.mark.parametrize("name", ["ejemplo9rt", "constant_width", "groove_translating", "valve_exhaust_ej1"])
def test_the_stl_deviation_bounds_the_measured_one(name):
    """The STL's deviation is the plate fit's plus the flattening's largest sagitta (triangle inequality, no
    measurement of the polyline): never below the deviation of the flattened polyline measured on the exact
    curve, and within tol; a fit that carries no deviation is measured instead (docs/decisions.md, "The STL's
    deviation is the fit's plus the sagitta")."""
    from camfab.cad.export import flattened_deviation, stl_facet_tolerance
    from camfab.formats import load_design

    spec = load_design(EXAMPLES / f"{name}.toml")
    geom = geometry_from_spec(spec)
    tol = spec.manufacturing.tolerance_mm
    shapes = cam_shapes(geom, tol=tol, with_pitch=False)
    rest = stl_facet_tolerance(tol)
    (art,) = build_artifacts(spec, geom, ["stl"], tol=tol, shapes=shapes)
    devs = []
    for fit, curve in zip(shapes.profiles, shapes.curves, strict=True):
        measured = measure_deviation(fit.flatten(rest), curve).max
        bound = flattened_deviation(fit, curve, tol, rest)
        assert measured <= bound <= tol
        assert bound - measured <= 0.2 * tol  # a bound, not a blind tol
        unmeasured = fit.with_deviation(None)
        assert flattened_deviation(unmeasured, curve, tol, rest) == pytest.approx(measured, rel=1e-6)
        devs.append(bound)
    assert art.deviation_mm == max(devs)


def test_same_export_twice_is_byte_identical():
    spec = DESIGNS["ejemplo9rt"]()
    geom = geometry_from_spec(spec)
    a = build_artifacts(spec, geom, ["dxf", "stl"], tol=1e-3)
    b = build_artifacts(spec, geom, ["dxf", "stl"], tol=1e-3)
    assert [x.data for x in a] == [x.data for x in b]


@pytest.mark.slow
def test_step_valid_volume_reimport(tmp_path):
    cq = pytest.importorskip("cadquery")
    spec = DESIGNS["ejemplo9rt"]()
    geom = geometry_from_spec(spec)
    (art,) = build_artifacts(spec, geom, ["step"], tol=1e-5)
    path = tmp_path / "c.step"
    path.write_bytes(art.data)
    solid = cq.importers.importStep(str(path)).val()
    assert solid.isValid()
    m = spec.manufacturing
    plate = PlateSpec(m.thickness_mm, m.bore_mm, m.keyway)
    loop = cam_shapes(geom, tol=1e-5, with_pitch=False).profiles[0]
    assert solid.Volume() == pytest.approx(plate_volume(loop, plate), rel=1e-9)
    exact = (geom.area() - plate.hole().area()) * m.thickness_mm
    assert solid.Volume() == pytest.approx(exact, rel=1e-6)
    # the solid's outline edges lie on the exact profile (a 1e-4 mm export, read back)
    (art,) = build_artifacts(spec, geom, ["step"], tol=1e-4)
    path.write_bytes(art.data)
    solid = cq.importers.importStep(str(path)).val()
    edges = cq.Workplane().add(solid).faces(">Z").edges().vals()
    pts = np.array([(p.x, p.y) for e in edges for p in [e.positionAt(t) for t in np.linspace(0, 1, 400)]])
    outer = pts[np.hypot(*pts.T) > 20]
    assert _points_to_curve(outer, profile_curve(geom.profiles[0])) <= 1e-4


def test_cli_export_writes_summary(tmp_path, capsys):
    assert main(["export", "ejemplo9rt", "--dxf", "--stl", "--tol", "0.01", "-o", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "Ejemplo9RT.dxf" in out and "max deviation" in out
    assert (tmp_path / "Ejemplo9RT.dxf").exists() and (tmp_path / "Ejemplo9RT.stl").exists()


def test_cli_export_refuses_unacceptable_unless_forced(tmp_path, capsys):
    d = tmp_path / "bad.toml"
    d.write_text((EXAMPLES / "ejemplo9rt.toml").read_text().replace("base_radius_mm = 35.0", "base_radius_mm = 12.0"))
    out = tmp_path / "out"
    assert main(["export", str(d), "--dxf", "-o", str(out)]) == 1
    assert "nothing written" in capsys.readouterr().err
    assert not out.exists()
    assert main(["export", str(d), "--dxf", "--force", "-o", str(out)]) == 1  # written, still unacceptable
    assert (out / "Ejemplo9RT.dxf").exists()


def test_cli_export_tool_too_big_is_refused(tmp_path, capsys):
    d = tmp_path / "t.toml"
    d.write_text((EXAMPLES / "ejemplo9rt.toml").read_text().replace("tool_diameter_mm = 6.0",
                                                                      "tool_diameter_mm = 100.0"))
    out = tmp_path / "out"
    assert main(["export", str(d), "--dxf", "--tool-path", "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert "largest cutter" in err and "47.5" in err and "°" in err
    assert not out.exists()


@pytest.mark.parametrize("tol", ["0", "1", "nan"])
def test_cli_export_bad_tol(tmp_path, tol):
    assert main(["export", "ejemplo9rt", "--dxf", "--tol", tol, "-o", str(tmp_path / "o")]) == 2
    assert not (tmp_path / "o").exists()


CONJ = base_design(cam={"kind": "conjugate"},
                   follower={"type": "flat", "motion": "translating", "base_radius_mm": 45.0,
                             "follower_distance_mm": 225.0},
                   motion=[{"law": "double_harmonic", "lift": 100.0, "angle_deg": 180.0},
                           {"law": "double_harmonic", "lift": -100.0, "angle_deg": 180.0}],
                   manufacturing={"thickness_mm": 12.0, "bore_mm": 20.0, "keyway": True})
CWIDTH = base_design(cam={"kind": "constant_width"},
                     follower={"type": "flat", "motion": "translating", "base_radius_mm": 40.0, "width_mm": 100.0})
del CWIDTH["motion"]


@pytest.mark.parametrize("data", [CONJ, CWIDTH], ids=["conjugate_8DA", "constant_width"])
@pytest.mark.parametrize("tol", [1e-2, 1e-3, 1e-4])
def test_desmodromic_dxf_within_tol(data, tol):
    spec = design_from_dict(data)
    geom = geometry_from_spec(spec)
    (art,) = build_artifacts(spec, geom, ["dxf"], tol=tol)
    doc = ezdxf.read(io.StringIO(art.data.decode()))
    assert not doc.audit().has_errors
    for i, contact in enumerate(geom.profiles):
        layer = "PROFILE" if i == 0 else f"PROFILE_{i + 1}"
        (pl,) = doc.modelspace().query(f"LWPOLYLINE[layer=='{layer}']")
        rows = np.array(list(pl.get_points("xyb")))
        assert measure_deviation(rows, profile_curve(contact)).max <= tol


@pytest.mark.slow
def test_conjugate_step_pair(tmp_path):
    cq = pytest.importorskip("cadquery")
    spec = design_from_dict(CONJ)
    geom = geometry_from_spec(spec)
    arts = build_artifacts(spec, geom, ["step"], tol=1e-4)
    assert [a.filename for a in arts] == ["T_cam1.step", "T_cam2.step", "T_pair.step"]
    (tmp_path / "p.step").write_bytes(arts[-1].data)
    pair = cq.importers.importStep(str(tmp_path / "p.step")).val()
    assert pair.isValid() and len(pair.Solids()) == 2
    bb = pair.BoundingBox()
    assert bb.zmax == pytest.approx(12.0 + 2.0 + 12.0)
    vol = sum(s.Volume() for s in pair.Solids())
    loops = cam_shapes(geom, tol=1e-4, with_pitch=False).profiles
    plate = PlateSpec(12.0, 20.0, True)
    assert vol == pytest.approx(sum(plate_volume(lp, plate) for lp in loops), rel=1e-9)


@pytest.mark.parametrize("tol", [1e-2, 1e-3, 1e-4])
def test_dxf_spline_flavour_is_exact_nurbs_of_the_arcs(tol):
    spec = DESIGNS["ejemplo9rt"]()
    geom = geometry_from_spec(spec)
    (art,) = build_artifacts(spec, geom, ["dxf"], tol=tol, dxf_flavour="spline")
    doc = ezdxf.read(io.StringIO(art.data.decode()))
    assert not doc.audit().has_errors
    (sp,) = doc.modelspace().query("SPLINE[layer=='PROFILE']")
    bs = sp.construction_tool()
    assert bs.degree == 2
    t = np.linspace(0, bs.max_t, 40001)
    pts = np.array([(p.x, p.y) for p in bs.points(t)])
    # every spline point is on one of the fitted arcs (to round-off) and the whole is within tol
    loop = cam_shapes(geom, tol=tol, with_pitch=False).profiles[0]
    rows = np.column_stack([loop.points, loop.bulges])
    assert Chain.from_bulges(rows).distance(pts)[0].max() < 1e-9
    assert measure_deviation(pts, profile_curve(geom.profiles[0])).max <= tol


@pytest.mark.parametrize("name", ["ejemplo9rt", "oscillating"])  # the roller designs (flat faces have no pitch)
@pytest.mark.parametrize("tol", [1e-2, 1e-3, 1e-4])
def test_dxf_pitch_curve_read_back_within_tol(name, tol):
    from camfab.offset.cutter import pitch_curve

    spec = DESIGNS[name]()
    geom = geometry_from_spec(spec)
    pc = pitch_curve(geom.profiles[0])
    (art,) = build_artifacts(spec, geom, ["dxf"], tol=tol)
    doc = ezdxf.read(io.StringIO(art.data.decode()))
    (pl,) = doc.modelspace().query("LWPOLYLINE[layer=='PITCH_CURVE']")
    rows = np.array(list(pl.get_points("xyb")))
    assert measure_deviation(rows, pc).max <= tol
    pts = Chain.from_bulges(rows).sample(40)[0]  # an independent check: dense points on the drawn arcs
    assert _points_to_curve(pts, pc) <= tol + 1e-6
