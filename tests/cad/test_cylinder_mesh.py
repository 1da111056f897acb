"""The grooved (and the ribbed) cylinder's STL meshed from its exact surfaces (:mod:`camfab.cad.cylinder_mesh`):
closed and outward, every vertex on the exact part, the exact surfaces within the tolerance of the mesh and the
mesh's facets within it of them, the STEP solid's volume and surface, no CAD or mesh library imported by
``camfab export --stl``, and bad input refused."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from camfab.cad import cylinder_mesh as cm
from camfab.cad.stl import FACET, is_closed_surface
from camfab.design.cylindrical import wrap
from camfab.errors import ExportError, InputError
from camfab.pipeline import load

ROOT = Path(__file__).resolve().parents[2]
EXAMPLE = ROOT / "camfab" / "examples" / "cylindrical_translating.toml"
TOL = 0.01
BORE = 20.0


@pytest.fixture(scope="module")
def geometry():
    return load(EXAMPLE).geometry


@pytest.fixture(scope="module", params=[0.0, BORE], ids=["solid", "bored"])
def made(request, geometry):
    bore = request.param
    verts, faces, dev = cm.part_mesh(geometry, tol=TOL, bore_mm=bore)
    return bore, verts, faces, dev


def _roller_distance(geometry, p: np.ndarray, shift: float = 0.0) -> np.ndarray:
    """Each point's smallest distance to the roller's axis over the cycle (a translating follower's: the radial
    ray at the pitch point's polar angle, at its height plus ``shift``: a rib's rollers), minimised over the cam
    angle (dense grid, then Newton on the squared distance with numerical derivatives): a flank's points are the
    half width from it."""
    sense = geometry.mechanism.sense
    R = geometry.cylinder.radius_mm

    def dist2(t):
        C, _ = geometry.at_radius(R).pitch(t)
        a = 0.5 * math.pi + sense * C[:, 0] / R
        v = p - np.column_stack([0 * a, 0 * a, C[:, 1] + shift])
        along = np.maximum(v[:, 0] * np.cos(a) + v[:, 1] * np.sin(a), 0.0)  # the ray out from the cam axis
        return np.einsum("ij,ij->i", v, v) - along ** 2

    grid = np.linspace(0.0, geometry.period, 361)
    best = np.full(len(p), np.inf)
    t = np.zeros(len(p))
    for g in grid:
        d = dist2(np.full(len(p), g))
        t, best = np.where(d < best, g, t), np.minimum(d, best)
    h = 1e-5
    for _ in range(30):
        d0, dp, dm = dist2(t), dist2(t + h), dist2(t - h)
        curv = (dp - 2 * d0 + dm) / h ** 2
        t = t - np.where(curv > 0, (dp - dm) / (2 * h) / np.where(curv > 0, curv, 1.0), 0.0)
    return np.sqrt(np.maximum(dist2(t), 0.0))


def _classify(geometry, verts: np.ndarray, bore: float) -> dict[str, np.ndarray]:
    cyl = geometry.cylinder
    rho = np.hypot(verts[:, 0], verts[:, 1])
    low, high = np.abs(verts[:, 2]) < 1e-12, np.abs(verts[:, 2] - cyl.length_mm) < 1e-12
    outer = np.abs(rho - cyl.outer_radius_mm) < 1e-9
    hole = np.abs(rho - bore / 2) < 1e-9 if bore else np.zeros(len(verts), dtype=bool)
    return {"ends": low | high, "low": low, "high": high, "outer": outer, "hole": hole, "rho": rho}


def _point_triangle(p: np.ndarray, tri: np.ndarray) -> np.ndarray:
    """Distances ``(m,)`` from points p ``(m, 3)`` to triangles ``(m, 3, 3)`` (pairwise)."""
    a, b, c = tri[:, 0], tri[:, 1], tri[:, 2]
    n = np.cross(b - a, c - a)
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    h = np.einsum("ij,ij->i", p - a, n)
    foot = p - h[:, None] * n
    inside = np.ones(len(p), dtype=bool)
    for u, v in ((a, b), (b, c), (c, a)):
        inside &= np.einsum("ij,ij->i", np.cross(v - u, foot - u), n) >= 0
    best = np.where(inside, np.abs(h), np.inf)
    for u, v in ((a, b), (b, c), (c, a)):
        e = v - u
        s = np.clip(np.einsum("ij,ij->i", p - u, e) / np.einsum("ij,ij->i", e, e), 0.0, 1.0)
        best = np.minimum(best, np.linalg.norm(p - u - s[:, None] * e, axis=1))
    return best


def _mesh_distance(verts: np.ndarray, faces: np.ndarray, points: np.ndarray, reach: float = 0.1) -> np.ndarray:
    """Each point's distance to the mesh (inf beyond ``reach`` of every facet): exact point-to-triangle distances
    to the facets whose bounding sphere (about the centroid) comes within ``reach`` of it (a KD tree of the
    points, queried with each facet's own radius)."""
    from scipy.spatial import cKDTree

    tri = verts[faces]
    centre = tri.mean(axis=1)
    radius = np.linalg.norm(tri - centre[:, None], axis=2).max(axis=1) + reach
    near = cKDTree(points).query_ball_point(centre, radius)
    fi = np.concatenate([np.full(len(c), k) for k, c in enumerate(near)])
    pi = np.concatenate([np.asarray(c, dtype=np.int64) for c in near])
    d = _point_triangle(points[pi], tri[fi])
    out = np.full(len(points), np.inf)
    np.minimum.at(out, pi, d)
    return out


def test_closed_outward_and_positive(made, geometry):
    trimesh = pytest.importorskip("trimesh")
    bore, verts, faces, dev = made
    tri = verts[faces]
    assert is_closed_surface(tri) and cm.closed(faces)
    mesh = trimesh.Trimesh(verts, faces, process=False)
    assert mesh.is_watertight and mesh.is_winding_consistent and mesh.is_volume and mesh.volume > 0
    cyl = geometry.cylinder
    full = math.pi * (cyl.outer_radius_mm ** 2 - (bore / 2) ** 2) * cyl.length_mm
    assert 0.8 * full < mesh.volume < full  # the groove takes some
    assert 0 < dev <= TOL
    assert len(faces) < 30000  # the example: 13 364 (OpenCascade's tessellation: 14 890)


def test_every_vertex_lies_on_the_exact_part(made, geometry):
    bore, verts, faces, _ = made
    cyl = geometry.cylinder
    kind = _classify(geometry, verts, bore)
    rho = kind["rho"]
    assert np.all(rho <= cyl.outer_radius_mm + 1e-9) and np.all(rho >= bore / 2 - 1e-9)
    assert np.all((verts[:, 2] >= -1e-12) & (verts[:, 2] <= cyl.length_mm + 1e-12))
    rest = ~(kind["ends"] | kind["outer"] | kind["hole"])
    w = geometry.mechanism.half_width(cyl.radius_mm)  # a cylindrical roller: the same on every radius
    d = _roller_distance(geometry, verts[rest])
    on_flank = np.abs(d - w) < 1e-9
    # the rest: the flat bottom's inside, on or under the groove bottom's radius (on it where the segment across
    # is axial: the dwells), inside the roller's sweep
    bottom = ~on_flank
    assert np.all(rho[rest][bottom] <= cyl.inner_radius_mm + 1e-9) and np.all(d[bottom] < w - 1e-6)
    assert on_flank.any() and bottom.any()
    # the outer cylinder's vertices off the ends are the flanks' top edges: on the roller's sweep too
    top = kind["outer"] & ~kind["ends"]
    assert top.any() and np.all(np.abs(_roller_distance(geometry, verts[top]) - w) < 1e-9)


def test_exact_surfaces_lie_within_tol_of_the_mesh(made, geometry):
    """Points of the exact flanks (at cam angles and radii the mesh does not use), of the exact bottom (the
    STEP's own sections, :func:`~camfab.cad.cylinder.groove_sections`, across at random places) and of the outer
    cylinder outside the groove, against the mesh."""
    from camfab.cad.cylinder import groove_sections

    bore, verts, faces, dev = made
    cyl, sense = geometry.cylinder, geometry.mechanism.sense
    rng = np.random.default_rng(5)
    pts = []
    for flank in (1, -1):  # flank_at: the per-radius evaluation bit for bit (tested below)
        t, r = rng.uniform(0, geometry.period, 3000), rng.uniform(cyl.inner_radius_mm, cyl.outer_radius_mm, 3000)
        pts.append(cm.flank_at(geometry, flank, t, r)[1])
    _, sec = groove_sections(geometry, 401, np.array([cyl.inner_radius_mm]))
    s = rng.uniform(0, 1, (401, 1))
    pts.append((1 - s) * sec[:, 0, 0] + s * sec[:, 1, 0])
    u, z = rng.uniform(0, 2 * math.pi, 4000), rng.uniform(0, cyl.length_mm, 4000)
    outer = wrap(sense, cyl.outer_radius_mm, u, z)
    w = geometry.mechanism.half_width(cyl.radius_mm)
    pts.append(outer[_roller_distance(geometry, outer) > w])
    points = np.concatenate(pts)
    far = _mesh_distance(verts, faces, points)
    assert far.max() <= TOL, far.max()
    assert far.max() <= 1.5 * dev + 1e-4  # the measured deviation is about the largest


def test_facets_lie_within_tol_of_the_exact_surfaces(made, geometry):
    """Random points of every flank facet: within tol of the flank (their distance to the roller's sweep, the
    half width off the roller's axis); of the cylinders' facets: within tol of their radius; of the ends: on the
    plane."""
    bore, verts, faces, dev = made
    cyl = geometry.cylinder
    rng = np.random.default_rng(9)
    tri = verts[faces]
    lam = rng.dirichlet([1.0, 1.0, 1.0], len(tri))
    p = np.einsum("fk,fkc->fc", lam, tri)
    kind = _classify(geometry, verts, bore)
    on = {name: kind[name][faces].all(axis=1) for name in ("low", "high", "outer", "hole")}
    on["ends"] = on["low"] | on["high"]
    rho = np.hypot(p[:, 0], p[:, 1])
    assert np.all(cyl.outer_radius_mm - rho[on["outer"]] <= dev + 1e-12)
    if bore:
        assert np.all(bore / 2 - rho[on["hole"]] <= dev + 1e-12) and on["hole"].any()
    z = p[on["ends"], 2]
    assert np.all(np.minimum(np.abs(z), np.abs(z - cyl.length_mm)) < 1e-12)
    w = geometry.mechanism.half_width(cyl.radius_mm)
    swept = ~(kind["ends"] | kind["hole"])
    d = np.full(len(verts), np.inf)
    d[swept] = _roller_distance(geometry, verts[swept])
    flank = (np.abs(d - w) < 1e-9)[faces].all(axis=1) & ~on["outer"]
    assert flank.sum() > len(faces) / 3
    off = np.abs(_roller_distance(geometry, p[flank]) - w)
    assert off.max() <= TOL and off.max() <= dev + 1e-6, off.max()


def test_flank_at_array_radius_is_the_per_radius_evaluation(geometry):
    rng = np.random.default_rng(3)
    t, r = rng.uniform(0, 7, 50), rng.uniform(35, 45, 50)
    u, p, v = cm.flank_at(geometry, -1, t, r)
    for k in range(50):
        e = geometry.at_radius(float(r[k]), -1).evaluate(t[k:k + 1])
        assert u[k] == e.point[0, 0] / r[k]
        np.testing.assert_array_equal(p[k], wrap(geometry.mechanism.sense, float(r[k]), u[k:k + 1],
                                                    e.point[:, 1])[0])


def test_on_radii_is_each_radius_own_evaluation_bit_for_bit(geometry):
    """DevelopedContact.on_radii (one evaluation, a radius per cam angle) gives the points of the per-radius
    contact's evaluate bit for bit and every other field of the sample to 1e-14 relative (numpy's vector loops
    against one-element arrays); a conical roller (its section changes with r) is refused."""
    import dataclasses

    from camfab.design.assemble import geometry_from_spec
    from camfab.design.spec import design_from_dict

    rng = np.random.default_rng(11)
    t, r = rng.uniform(0, 7, 40), rng.uniform(35, 45, 40)
    for flank in (1, -1):
        many = geometry.at_radius(40.0, flank).on_radii(t, r)
        for k in range(40):
            one = geometry.at_radius(float(r[k]), flank).evaluate(t[k:k + 1])
            for f in dataclasses.fields(one):
                a, b = getattr(one, f.name), getattr(many, f.name)
                if a is None:
                    assert b is None, f.name
                    continue
                a, b = np.asarray(a)[0], np.asarray(b)[k]
                if f.name in ("phi", "point"):
                    assert a.tobytes() == b.tobytes(), (f.name, k)
                else:
                    np.testing.assert_allclose(b, a, rtol=1e-14, atol=0, err_msg=f"{f.name} {k}")
    conical = geometry_from_spec(design_from_dict({
        "name": "Cone", "cam": {"kind": "cylindrical"},
        "cylinder": {"radius_mm": 40.0, "length_mm": 90.0, "groove_depth_mm": 10.0, "roller": "conical"},
        "follower": {"type": "roller", "motion": "translating", "roller_radius_mm": 6.0},
        "motion": [{"law": "cycloidal", "lift": 10.0, "angle_deg": 180.0},
                   {"law": "cycloidal", "lift": -10.0, "angle_deg": 180.0}]}))
    with pytest.raises(InputError, match="cylindrical roller"):
        conical.at_radius(40.0, 1).on_radii(t, r)


def test_zipper_walks_both_edges_once():
    ua = np.sort(np.random.default_rng(1).uniform(0.3, 0.3 + 2 * math.pi, 37))
    ub = 2 * math.pi * np.arange(16) / 16
    tri = cm.zipper(ua, ub)
    assert tri.shape == (53, 3)
    edges = {tuple(e) for t in tri for e in ((t[0], t[1]), (t[1], t[2]), (t[2], t[0]))}
    assert all(((i, (i + 1) % 37) in edges) for i in range(37))  # A forwards, B backwards: one band's winding
    assert all(((37 + (j + 1) % 16, 37 + j) in edges) for j in range(16))


def test_refused_beyond_the_triangle_cap_and_for_a_bad_bore(geometry):
    with pytest.raises(ExportError, match=r"exceed the cap of 2000000 triangles.*\[manufacturing\] tolerance_mm"):
        cm.part_mesh(geometry, tol=1e-7)
    with pytest.raises(ExportError, match="bore_mm"):
        cm.part_mesh(geometry, tol=TOL, bore_mm=2 * geometry.cylinder.inner_radius_mm)
    with pytest.raises(ExportError, match="tolerance_mm"):
        cm.part_mesh(geometry, tol=0.0)


def _against_solid(solid, verts: np.ndarray, faces: np.ndarray, n: int, seed: int) -> np.ndarray:
    """The mesh against an OCC solid: the solid's adaptive volume within tol·area of the mesh's (asserted), and the
    distances to the solid's surface of n random mesh vertices, then n random facet centroids."""
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeVertex
    from OCP.BRepExtrema import BRepExtrema_DistShapeShape
    from OCP.BRepGProp import BRepGProp
    from OCP.gp import gp_Pnt
    from OCP.GProp import GProp_GProps

    vol, area = GProp_GProps(), GProp_GProps()
    BRepGProp.VolumeProperties_s(solid.wrapped, vol, 1e-6, True)
    BRepGProp.SurfaceProperties_s(solid.wrapped, area, 1e-6, True)
    tri = verts[faces]
    volume = float(np.einsum("ij,ij->", tri[:, 0], np.cross(tri[:, 1], tri[:, 2]))) / 6.0
    assert abs(volume - vol.Mass()) <= TOL * area.Mass()
    rng = np.random.default_rng(seed)
    sample = np.concatenate([verts[rng.choice(len(verts), n, replace=False)],
                             tri[rng.choice(len(tri), n, replace=False)].mean(axis=1)])
    shell = solid.Shells()[0].wrapped  # the surface: a point inside the solid is not 0 from it
    return np.array([BRepExtrema_DistShapeShape(shell, BRepBuilderAPI_MakeVertex(gp_Pnt(*map(float, p))).Vertex())
                     .Value() for p in sample])


@pytest.mark.slow  # the STEP's solid (~6 s) and 500 distances to its surface
def test_the_step_solid_agrees(made, geometry):
    """OCC's adaptive volume of the STEP's solid within tol·area of the mesh's; a few hundred mesh vertices and
    facet points within tol (plus the loft's own deviation) of the solid's surface."""
    pytest.importorskip("cadquery", reason="the STEP solid needs cadquery (the step extra)")
    from camfab.cad.cylinder import cylinder_solid

    bore, verts, faces, dev = made
    if bore:
        pytest.skip("one solid is enough (the bore's cylinder is checked exactly above)")
    solid, loft_dev = cylinder_solid(geometry, tol=TOL)
    far = _against_solid(solid, verts, faces, 250, 11)
    assert far[:250].max() <= TOL, far[:250].max()  # the vertices: exact points; the loft within its deviation
    assert far.max() <= TOL + loft_dev, far.max()


@pytest.fixture(scope="module")
def rib(tmp_path_factory):
    from tests.design.test_cylinder_rib import RIB_TOML

    src = tmp_path_factory.mktemp("rib") / "rib.toml"
    src.write_text(RIB_TOML, encoding="utf-8")
    geometry = load(src).geometry
    return geometry, *cm.part_mesh(geometry, tol=TOL, bore_mm=BORE)


def test_rib_mesh_is_closed_and_on_the_exact_part(rib):
    """The ribbed cylinder: closed and outward; every vertex off the end faces and the bore on a rib flank (the
    half width from one of its two rollers' axes), the rib's top and root edges on their cylinders; the flank
    facets within tol of the flanks; the STL's header names the ribbed cylinder."""
    trimesh = pytest.importorskip("trimesh")
    geometry, verts, faces, dev = rib
    cyl, mech = geometry.cylinder, geometry.mechanism
    assert cm.closed(faces) and is_closed_surface(verts[faces]) and 0 < dev <= TOL
    mesh = trimesh.Trimesh(verts, faces, process=False)
    assert mesh.is_volume and mesh.volume > math.pi * (cyl.inner_radius_mm ** 2 - (BORE / 2) ** 2) * cyl.length_mm
    kind = _classify(geometry, verts, BORE)
    rho = kind["rho"]
    assert np.all((rho > cyl.inner_radius_mm - 1e-9) | kind["hole"]) and np.all(rho < cyl.outer_radius_mm + 1e-9)
    w, off = mech.half_width(cyl.radius_mm), mech.rib_offset_mm
    flank = ~(kind["ends"] | kind["hole"])
    d = np.minimum(_roller_distance(geometry, verts[flank], off), _roller_distance(geometry, verts[flank], -off))
    assert np.all(np.abs(d - w) < 1e-9)
    tri = verts[faces]
    sides = (np.abs(np.hypot(tri[..., 0], tri[..., 1]) - cyl.inner_radius_mm) < 1e-9).all(axis=1) | \
        (np.abs(np.hypot(tri[..., 0], tri[..., 1]) - cyl.outer_radius_mm) < 1e-9).all(axis=1)
    flank_facets = flank[faces].all(axis=1) & ~sides  # every vertex off the ends and bore is a flank's
    assert flank_facets.sum() > len(faces) / 3
    p = tri[flank_facets].mean(axis=1)
    off_flank = np.abs(np.minimum(_roller_distance(geometry, p, off), _roller_distance(geometry, p, -off)) - w)
    assert off_flank.max() <= dev + 1e-6
    data, _ = cm.part_stl(geometry, tol=TOL, name="Ribbed")
    assert data.startswith(b"camfab Ribbed units=mm tol=0.01 ribbed cylinder")


@pytest.mark.slow  # the STEP's ribbed solid (~6 s)
def test_rib_step_solid_agrees(rib):
    pytest.importorskip("cadquery", reason="the STEP solid needs cadquery (the step extra)")
    from camfab.cad.rib import rib_solid

    geometry, *_ = rib
    verts, faces, _ = cm.part_mesh(geometry, tol=TOL)
    solid, loft_dev = rib_solid(geometry, tol=TOL)
    far = _against_solid(solid, verts, faces, 200, 13)
    assert far[:200].max() <= TOL and far.max() <= TOL + loft_dev, far.max()


def test_export_stl_imports_no_cad_or_mesh_library(tmp_path):
    """``camfab export <cylindrical example> --stl`` writes the STL without cadquery, OCP or trimesh."""
    from tests.test_lazy_imports import _run

    last = _run(tmp_path, "export", str(EXAMPLE), "--stl", "-o", str(tmp_path), "--force")
    assert last["code"] in (0, None), last
    heavy = sorted(m for m in last["modules"] if m.split(".")[0] in ("cadquery", "OCP", "trimesh", "scipy"))
    assert not heavy, heavy
    data = (tmp_path / "BarrelCam.stl").read_bytes()
    assert data.startswith(b"camfab BarrelCam units=mm tol=0.01 grooved cylinder")
    count = int(np.frombuffer(data[80:84], "<u4")[0])
    assert len(data) == 84 + 50 * count
    tri = np.frombuffer(data[84:], dtype=FACET)["vertices"].astype(np.float64)
    assert is_closed_surface(tri)  # float32 vertices: still closed (shared vertices round alike)
