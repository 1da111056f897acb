"""Plate geometry, STL and STEP solids: exact areas/volumes, validity, read-back, determinism."""
from __future__ import annotations

import math

import numpy as np
import pytest

from camfab.cad.plate import PlateSpec, bore_loop, circle_loop, keyway_size, plate_volume
from camfab.errors import GeometryError
from camfab.geom2d import ArcChain


def _regular_arc_loop(r=40.0, n=4):
    ang = np.linspace(0, 2 * math.pi, n, endpoint=False)
    return ArcChain.from_bulges(r * np.column_stack([np.cos(ang), np.sin(ang)]),
                                np.full(n, math.tan(2 * math.pi / n / 4)))


def _stadium():
    # 60 x 30 stadium: two lines and two half circles (clockwise arcs negative bulge test below)
    pts = np.array([[-15.0, -15.0], [15.0, -15.0], [15.0, 15.0], [-15.0, 15.0]])
    return ArcChain.from_bulges(pts, np.array([0.0, 1.0, 0.0, 1.0]))


def test_areas_are_exact():
    assert _regular_arc_loop().area() == pytest.approx(math.pi * 1600, rel=1e-14)
    assert circle_loop(7.0).area() == pytest.approx(math.pi * 49, rel=1e-14)
    assert _stadium().area() == pytest.approx(30 * 30 + math.pi * 15**2, rel=1e-14)
    cw = ArcChain.from_bulges(_stadium().points[::-1].copy(), -np.roll(_stadium().bulges[::-1], -1))
    assert cw.area() == pytest.approx(-_stadium().area(), rel=1e-14)


def test_keyway_proportions_and_bore_area():
    assert keyway_size(12.0) == (4.0, 1.8)
    assert keyway_size(20.0) == (6.0, 2.8)
    with pytest.raises(GeometryError, match="bore_mm"):
        keyway_size(3.0)
    r, (b, t2) = 6.0, keyway_size(12.0)
    # circle + rectangle above the chord y0 .. r + t2, minus the circular cap above y0
    y0 = math.sqrt(r * r - b * b / 4)
    half = math.asin(b / (2 * r))
    cap = r * r * (2 * half - math.sin(2 * half)) / 2
    expect = math.pi * r * r - cap + b * (r + t2 - y0)
    assert bore_loop(12.0, True).area() == pytest.approx(expect, rel=1e-13)


def test_flatten_within_sagitta():
    loop = circle_loop(25.0)
    for tol in (1e-2, 1e-3, 1e-4):
        pts = loop.flatten(tol)
        mids = (pts + np.roll(pts, -1, axis=0)) / 2
        sag = 25.0 - np.hypot(*mids.T)
        assert np.all(np.abs(np.hypot(*pts.T) - 25.0) < 1e-12)
        assert sag.max() <= tol


def test_flatten_sagitta_is_the_largest_distance_of_a_chord_from_its_arc():
    """``flatten_sagitta`` gives ``flatten``'s vertices and its largest sagitta, which equals the largest distance of
    a chord's midpoint from the circle (all arcs of these loops centred on the origin), and is within ``tol``."""
    for loop, r in ((circle_loop(25.0), 25.0), (_regular_arc_loop(40.0, 4), 40.0), (_regular_arc_loop(7.5, 3), 7.5)):
        for tol in (1e-2, 1e-3, 1e-4, 1e-6):
            pts, sagitta = loop.flatten_sagitta(tol)
            assert np.array_equal(pts, loop.flatten(tol))
            mids = (pts + np.roll(pts, -1, axis=0)) / 2
            assert sagitta == pytest.approx(float((r - np.hypot(*mids.T)).max()), rel=1e-9, abs=1e-12)
            assert 0 < sagitta <= tol
    lines = ArcChain.from_polyline(np.array([[0.0, 0.0], [10.0, 0.0], [10.0, 5.0]]))
    assert lines.flatten_sagitta(1e-3)[1] == 0.0


def test_stl_watertight_volume_within_chordal_bound():
    trimesh = pytest.importorskip("trimesh")
    from camfab.cad import stl

    outline, plate = _regular_arc_loop(), PlateSpec(10.0, 12.0, True)
    for tol in (1e-2, 1e-3):
        data = stl.dumps(outline, plate, tol=tol, name="x")
        assert data == stl.dumps(outline, plate, tol=tol, name="x")
        assert data[:80].startswith(b"camfab x units=mm")
        assert len(data) == 84 + 50 * int.from_bytes(data[80:84], "little")  # binary STL, one facet per 50 B
        mesh = trimesh.load(trimesh.util.wrap_as_stream(data), file_type="stl")  # trimesh reads the file back
        assert mesh.is_watertight and mesh.is_winding_consistent and mesh.volume > 0
        exact = plate_volume(outline, plate)
        perimeter = 2 * math.pi * 40 + 2 * math.pi * 6 + 20
        # float32 vertices: the volume to within the chordal bound, and a rounding of ~1e-7 relative
        assert exact - perimeter * tol * plate.thickness_mm <= mesh.volume <= exact * (1 + 1e-6)
        # the written normals are the faces' outward unit normals
        assert np.allclose(mesh.face_normals, np.frombuffer(data[84:], stl.FACET)["normal"], atol=1e-6)
        assert mesh.bounds[0][2] == 0.0 and mesh.bounds[1][2] == pytest.approx(plate.thickness_mm)


def test_stl_refuses_a_bore_through_the_rim():
    pytest.importorskip("shapely")
    from camfab.cad import stl

    with pytest.raises(GeometryError, match=r"bore_mm = 32\) leaves several pieces"):
        stl.plate_triangles(_stadium(), PlateSpec(5.0, 32.0, False), tol=1e-3)  # 30 mm wide: cut in two
    with pytest.raises(GeometryError, match="leaves nothing"):
        stl.plate_triangles(circle_loop(10.0), PlateSpec(5.0, 30.0, False), tol=1e-3)


@pytest.mark.slow
def test_step_solid_valid_volume_and_reimport(tmp_path):
    cq = pytest.importorskip("cadquery")
    from camfab.cad import step

    outline = _stadium()
    for plate in (PlateSpec(8.0, 12.0, True), PlateSpec(8.0, 10.0, False, 20.0, 5.0)):
        exact = plate_volume(outline, plate)
        text = step.dumps(outline, plate, name="t")
        assert text == step.dumps(outline, plate, name="t")
        path = tmp_path / "t.step"
        path.write_text(text)
        back = cq.importers.importStep(str(path)).val()
        assert back.isValid()
        assert back.Volume() == pytest.approx(exact, rel=1e-6)
        bb = back.BoundingBox()
        assert (bb.xmin, bb.xmax) == (pytest.approx(-30.0), pytest.approx(30.0))


# ---------------------------------------------------------------------------
# exact offsets of G1 bulge loops (the pitch curve drawn from the profile's arcs)
@pytest.mark.parametrize("reverse", [False, True], ids=["ccw", "cw"])
@pytest.mark.parametrize("d", [-5.0, 2.5])
def test_offset_of_a_g1_loop_is_exact(reverse, d):
    st = _stadium()
    loop = ArcChain.from_bulges(st.points[::-1].copy(), -np.roll(st.bulges[::-1], -1)) if reverse else st
    off = loop.offset_g1(d)
    # every vertex of the offset stadium lies at distance d outside the original (radius 15 + d)
    pts = off.flatten(1e-6)
    x, y = pts[:, 0], pts[:, 1]
    cx = np.where(x > 0, 15.0, -15.0)
    dist = np.where(np.abs(x) <= 15 + 1e-9, np.abs(y), np.hypot(x - cx, y))
    assert np.allclose(dist, 15 + d, atol=1e-9)
    # Steiner: area grows by d·perimeter + π d² (signed by orientation)
    per = 60 + 2 * math.pi * 15
    assert abs(off.area()) == pytest.approx(abs(loop.area()) + d * per + math.pi * d * d, rel=1e-12)


def test_offset_refuses_corners_and_vanishing_arcs():
    square = ArcChain.from_bulges(np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]), np.zeros(4))
    assert square.offset_g1(0.1) is None  # corners need rounding arcs
    assert _stadium().offset_g1(-15.0) is None  # the half circles would shrink to radius 0
    assert _regular_arc_loop(10.0).offset_g1(-9.0).area() == pytest.approx(math.pi, rel=1e-12)


def test_closed_surface_test_finds_a_hole_and_a_flipped_triangle():
    """The watertightness test the groove plate's mesh must pass agrees with trimesh on a good mesh, a mesh with
    a triangle missing and one with a triangle flipped."""
    trimesh = pytest.importorskip("trimesh")
    from camfab.cad import stl

    tri = stl.plate_triangles(_stadium(), PlateSpec(6.0, 10.0, True), tol=1e-2)
    flipped = tri.copy()
    flipped[5] = flipped[5][::-1]
    for t, closed in ((tri, True), (tri[1:], False), (flipped, False)):
        assert stl.is_closed_surface(t) is closed
        mesh = trimesh.Trimesh(t.reshape(-1, 3), np.arange(3 * len(t)).reshape(-1, 3))  # merges equal vertices
        assert (mesh.is_watertight and mesh.is_winding_consistent) is closed
