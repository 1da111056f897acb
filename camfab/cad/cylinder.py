"""Files of a cylindrical cam: the developed (unrolled) groove as DXF, the grooved cylinder as STEP.

DXF: the development of the pitch cylinder (x = R·θ, y = z, :mod:`camfab.design.cylindrical`), one turn
(x from 0 to 2πR): the pitch curve on layer ``PITCH_CURVE``, the groove's +z flank on ``PROFILE`` and its −z
flank on ``PROFILE_2`` (the disc cams' layers), each an arc chain within the tolerance of the exact curve
(measured), and the developed outline of the cylinder (its ends z = 0 and z = length, the seam x = 0 and
x = 2πR) on ``OUTLINE``.  The file is written by :func:`camfab.cad.dxfwrite.developed` without importing ezdxf,
byte-identical to the ezdxf document :func:`developed_document` (tests/cad/test_dxf_write.py).

STEP: the cylinder (outer radius R + depth/2, length along +Z from z = 0) minus the groove, a loft
(``BRepOffsetAPI_ThruSections``) through sections at the interpolated cam angles (:func:`loft_sections`: as many
as the periodic B-spline through the exact 3D pitch curve needs to lie within the tolerance, measured), closed by
its first section: each section, in the plane normal to the pitch curve, holds the exact flank points of
:data:`SECTION_RADII` radii from the groove bottom to past the outer surface (each flank developed on its own
radius, wrapped, and cut by that plane), so the flanks follow the developed offsets on every radius — not a
rectangle swept along the pitch curve, whose flanks are right on the pitch cylinder only and pinch a full-depth
roller by up to w·(1 − (rR + S′²)/(|C_r′||C_R′|)) off it (5 µm in the example).  The groove bottom is the
straight segment across the two flank points on the bottom radius (flat across, as an end mill's end).  The
loft's edges along the track are iso-curves of its faces (exact pcurves: OCC's boolean argument analyser finds
nothing; the sweep it replaces had curve-on-surface faults), its faces split in two so none crosses its own seam
(docs/decisions.md, "Cylindrical cams: the loft, one build, IGES, assembly").  The groove's opening edges (the
loft ∩ the outer cylinder) are rebuilt from exact intersection points (:func:`exact_edges`), so the STEP read
back passes the analyser too.
"""
from __future__ import annotations

import math

import numpy as np

from ..design.cylindrical import CylindricalGeometry, pitch_3d, wrap
from ..discretize import ParametricCurve, arcs
from ..errors import ExportError
from ..textsafe import dxf_string, plain
from .dxf import LAYERS, ezdxf_module, write_deterministic
from .dxfwrite import developed, same_ezdxf
from .step import cadquery, solid_dumps

__all__ = ["developed_curves", "developed_dxf", "developed_document", "grooved_cylinder", "cylinder_solid",
           "cylinder_step", "cylinder_stl", "solid_mesh", "solid_stl", "loft_sections", "track_loft", "LOFT_SECTIONS"]

#: sections of the groove's (and the rib's) loft per turn to begin with: the points the periodic B-spline through
#: the 3D pitch curve passes through, doubled (at most 4 times) until it lies within the tolerance (the sections of
#: the example at 48: 0.6 s CPU, docs/decisions.md, "Cylinder sections: all planes' secant steps at once")
LOFT_SECTIONS = 48
#: how far past the outer surface the groove tool reaches (mm), so the cut leaves no skin
CLEARANCE_MM = 1.0
#: how far (rad) from a section plane's cam angle its flank crossing is looked for
NEAR_RAD = 0.6
#: radii (groove bottom to past the outer surface) at which each section holds the exact flank points
SECTION_RADII = 6


def developed_curves(geometry: CylindricalGeometry, tol: float):
    """The pitch curve and both flanks developed on the pitch cylinder, each as an arc chain within ``tol``:
    ``(pitch, plus_flank, minus_flank)``."""
    R = geometry.cylinder.radius_mm
    out = []
    for flank, take in ((1, "pitch"), (1, "point"), (-1, "point")):
        c = geometry.at_radius(R, flank)

        def point(t, c=c, take=take):
            return getattr(c.evaluate(t), take)
        curve = ParametricCurve(point, c.breakpoints, c.period, closed=False)
        out.append(arcs(curve, tol=tol))
    return tuple(out)


def developed_dxf(geometry: CylindricalGeometry, *, tol: float, name: str = "cam") -> tuple[str, float]:
    """DXF text of the developed groove and its measured largest deviation (mm): written by
    :func:`camfab.cad.dxfwrite.developed` without ezdxf, the bytes of :func:`developed_document` (which writes it
    when the installed ezdxf is not the writer's version, :func:`camfab.cad.dxfwrite.same_ezdxf`)."""
    curves = developed_curves(geometry, tol)
    dev = max(float(c.max_deviation) for c in curves)
    cyl = geometry.cylinder
    args = (name, tol, dev, curves, 2 * math.pi * cyl.radius_mm, cyl.length_mm)
    if not same_ezdxf():  # another ezdxf than the writer's: its own bytes, as before
        return write_deterministic(developed_document(*args)), dev
    return developed(*args), dev


def developed_document(name: str, tol: float, dev: float, curves, width: float, length: float):
    """The developed DXF as an ezdxf document (write it with :func:`~camfab.cad.dxf.write_deterministic`): the
    pitch curve and flanks ``curves`` (:func:`developed_curves`) and the ``width`` × ``length`` outline."""
    ezdxf = ezdxf_module()
    doc = ezdxf.new("R2010", setup=False)
    doc.header["$INSUNITS"] = 4
    doc.header["$MEASUREMENT"] = 1
    doc.header.custom_vars.append("CAMFAB_NAME", dxf_string(name))
    doc.header.custom_vars.append("CAMFAB_TOL_MM", f"{tol:g}")
    doc.header.custom_vars.append("CAMFAB_DEVIATION_MM", f"{dev:.3e}")
    for layer, colour in {**LAYERS, "OUTLINE": 8}.items():
        doc.layers.add(layer, color=colour)
    msp = doc.modelspace()
    for layer, chain in zip(("PITCH_CURVE", "PROFILE", "PROFILE_2"), curves, strict=True):
        pts = [(float(p[0]), float(p[1]), 0.0, 0.0, float(b)) for p, b in zip(chain.starts, chain.bulges, strict=True)]
        end = chain.ends[-1]
        pts.append((float(end[0]), float(end[1]), 0.0, 0.0, 0.0))
        msp.add_lwpolyline(pts, format="xyseb", dxfattribs={"layer": layer})
    msp.add_lwpolyline([(0.0, 0.0), (width, 0.0), (width, length), (0.0, length)], close=True,
                       dxfattribs={"layer": "OUTLINE"})
    return doc


def _vec(cq, p):
    return cq.Vector(float(p[0]), float(p[1]), float(p[2]))


def _wrap(geometry: CylindricalGeometry, r: float, xz: np.ndarray) -> np.ndarray:
    """Developed points (x, z) of the cylinder r → cam-frame 3D points (polar angle 90° + σ·x/r)."""
    return wrap(geometry.mechanism.sense, r, xz[:, 0] / r, xz[:, 1])


def _crossings(geometry: CylindricalGeometry, r: float, contact, grid: tuple, planes: tuple) -> np.ndarray:
    """The points ``(n, 3)`` of the exact flank ``contact`` (its contact curve on the cylinder r) where it crosses
    each of the n planes (points, unit normals, cam angles), near the plane's cam angle: bracketed on ``grid``
    (cam angles and the flank's wrapped points there), then refined by up to four secant steps, all planes'
    steps in one evaluation of the flank each (a plane whose step would divide by zero keeps its point)."""
    p0, normal, theta = planes
    angles, on_grid = grid
    m, n = angles.size, len(theta)
    h = float(angles[1] - angles[0])
    half = int(math.ceil(NEAR_RAD / h)) + 2  # grid points on either side of a plane's angle that can be near it
    brackets = np.empty((4, n))
    for k in range(n):
        if 2 * half + 2 < m:  # the window around the plane's angle (wrapped), one point past its end
            idx = np.arange(int(round(theta[k] / h)) - half, int(round(theta[k] / h)) + half + 2) % m
        else:
            idx = np.arange(m + 1) % m
        d = (on_grid[idx] - p0[k]) @ normal[k]
        near = np.abs((angles[idx[:-1]] - theta[k] + math.pi) % (2 * math.pi) - math.pi) < NEAR_RAD
        cross = np.nonzero(near & (np.sign(d[:-1]) != np.sign(d[1:])))[0]
        if cross.size == 0:
            raise ExportError(f"a flank of the groove does not cross the section plane at "
                              f"{math.degrees(theta[k]):.6g}° on the radius {r:g} mm: check the design for an undercut")
        q = int(cross[np.argmin(idx[cross])])  # the crossing first on the grid, as over the whole grid
        i = int(idx[q])
        brackets[:, k] = angles[i], angles[(i + 1) % m] + (2 * math.pi if i + 1 == m else 0.0), d[q], d[q + 1]
    g0, g1, d0, d1 = brackets
    going = np.ones(len(theta), dtype=bool)
    for _ in range(4):
        going &= d1 != d0
        if not going.any():
            break
        a = going
        g0[a], g1[a], d0[a] = g1[a], g1[a] - d1[a] * (g1[a] - g0[a]) / (d1[a] - d0[a]), d1[a]
        d1[a] = np.einsum("ij,ij->i", _wrap(geometry, r, contact.evaluate(g1[a]).point) - p0[a], normal[a])
    return _wrap(geometry, r, contact.evaluate(g1).point)


def groove_sections(geometry: CylindricalGeometry, n: int, radii: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The groove's sections in the planes normal to the 3D pitch curve at n equally spaced cam angles: the exact
    flank points (developed flanks on each of ``radii``, wrapped) that lie in each plane; (n,) angles and
    (n, 2, len(radii), 3) points (+z flank, −z flank)."""
    R, sense = geometry.cylinder.radius_mm, geometry.mechanism.sense
    theta = np.linspace(0.0, geometry.period, n, endpoint=False)
    C, T = geometry.at_radius(R).pitch(theta)
    a = 0.5 * math.pi + sense * C[:, 0] / R
    along = sense * np.stack([-np.sin(a), np.cos(a), 0 * a], axis=1) * T[:, :1] + np.array([0.0, 0.0, 1.0]) * T[:, 1:]
    along /= np.linalg.norm(along, axis=1)[:, None]
    points = pitch_3d(geometry, theta)
    grid = np.linspace(0.0, geometry.period, 20000, endpoint=False)
    out = np.empty((n, 2, len(radii), 3))
    for f, flank in enumerate((1, -1)):
        for j, r in enumerate(map(float, radii)):
            contact = geometry.at_radius(r, flank)
            on_grid = (grid, _wrap(geometry, r, contact.evaluate(grid).point))  # evaluated once for all sections
            out[:, f, j] = _crossings(geometry, r, contact, on_grid, (points, along, theta))
    return theta, out


def grooved_cylinder(geometry: CylindricalGeometry, *, n: int = LOFT_SECTIONS, bore_mm: float = 0.0):
    """The grooved cylinder as a cadquery Solid (see the module notes)."""
    cq = cadquery()
    cyl = geometry.cylinder
    r_far = cyl.outer_radius_mm + CLEARANCE_MM
    groove = track_loft(geometry, n, np.linspace(cyl.inner_radius_mm, r_far, SECTION_RADII))
    body = cq.Solid.makeCylinder(cyl.outer_radius_mm, cyl.length_mm, cq.Vector(0, 0, 0), cq.Vector(0, 0, 1))
    solid = body.cut(groove)
    if bore_mm > 0:
        solid = solid.cut(cq.Solid.makeCylinder(bore_mm / 2, cyl.length_mm, cq.Vector(0, 0, 0), cq.Vector(0, 0, 1)))
    solid = exact_edges(solid)
    if not (groove.isValid() and solid.isValid()):
        raise ExportError(f"the grooved cylinder is not a valid solid (OCC's checker): groove {cyl.groove_depth_mm:g} "
                          "mm deep swept around the pitch curve. Check the design for an undercut")
    return solid


def track_loft(geometry: CylindricalGeometry, n: int, radii: np.ndarray):
    """The loft (``BRepOffsetAPI_ThruSections``, smooth) through the track's n sections (:func:`groove_sections`
    on ``radii``, each the polygon up the +z flank and down the −z flank), closed by its first section, its closed
    faces split in two: the groove's tool and the rib's body (:mod:`camfab.cad.rib`)."""
    cq = cadquery()
    _, sections = groove_sections(geometry, n, radii)
    wires = [cq.Wire.makePolygon([_vec(cq, p) for p in (*sec[0], *sec[1][::-1])], close=True) for sec in sections]
    return _split_closed(cq, cq.Solid.makeLoft([*wires, wires[0]], False))  # the first section closes the loop


def _split_closed(cq, solid):
    """``solid`` with each of its closed faces (the loft's, closed around the track) split in two along an
    iso-line: no face's boundary crosses its own seam, which OCC's STEP reader rebuilt 2.5 µm off (measured)."""
    from OCP.ShapeUpgrade import ShapeUpgrade_ShapeDivideClosed

    divide = ShapeUpgrade_ShapeDivideClosed(solid.wrapped)
    divide.SetNbSplitPoints(1)
    divide.Perform()
    return cq.Shape.cast(divide.Result())


#: interpolation nodes per knot span (along the track) of the loft face on an edge rebuilt by :func:`exact_edges`:
#: its 3D curve and pcurves then agree within 7.3 nm (the example, measured at 5001 points; 8 nodes: 118 nm)
EDGE_NODES_PER_SPAN = 16


def exact_edges(solid):
    """``solid`` (changed in place and returned) with each edge where a loft face meets a cylinder face (the
    groove's opening, the rib's top and root) rebuilt from exact intersection points: the boolean approximates the
    intersection curve within 2.5e-6 mm, which OCC's STEP reader, setting each edge's tolerance from a few samples,
    read as a curve-on-surface fault (docs/decisions.md, "Cylindrical cams: the rib's loft and exact edges on the
    cylinders")."""
    from OCP.BRep import BRep_Builder
    from OCP.BRepAdaptor import BRepAdaptor_Surface
    from OCP.GeomAbs import GeomAbs_BSplineSurface, GeomAbs_Cylinder
    from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE
    from OCP.TopExp import TopExp
    from OCP.TopoDS import TopoDS
    from OCP.TopTools import TopTools_IndexedDataMapOfShapeListOfShape

    faces = TopTools_IndexedDataMapOfShapeListOfShape()
    TopExp.MapShapesAndAncestors_s(solid.wrapped, TopAbs_EDGE, TopAbs_FACE, faces)
    builder = BRep_Builder()
    for i in range(1, faces.Extent() + 1):
        pair = {BRepAdaptor_Surface(TopoDS.Face_s(f)).GetType(): TopoDS.Face_s(f) for f in faces.FindFromIndex(i)}
        if set(pair) == {GeomAbs_Cylinder, GeomAbs_BSplineSurface}:
            _exact_edge(builder, TopoDS.Edge_s(faces.FindKey(i)), pair[GeomAbs_Cylinder], pair[GeomAbs_BSplineSurface])
    return solid


def _exact_edge(builder, edge, cyl_face, loft_face) -> None:
    """Replace the 3D curve and both pcurves of ``edge`` (a loft face ∩ a cylinder about Z) by cubic interpolants,
    at the same parameters, of points on both surfaces: on each iso-line of the loft's along-track parameter v
    (linear in the edge's parameter; :data:`EDGE_NODES_PER_SPAN` per knot span, the knots among them), the u
    where the loft's (straight) iso-line meets the cylinder (Newton); the ends stay the edge's vertices, with the
    tangents of the exact intersection (a free end would leave the interpolants apart by O(h²) there)."""
    from OCP.BRep import BRep_Tool
    from OCP.BRepAdaptor import BRepAdaptor_Curve, BRepAdaptor_Surface
    from OCP.ElSLib import ElSLib
    from OCP.Geom2dAPI import Geom2dAPI_Interpolate
    from OCP.GeomAPI import GeomAPI_Interpolate, GeomAPI_ProjectPointOnSurf
    from OCP.gp import gp_Pnt, gp_Pnt2d, gp_Vec, gp_Vec2d
    from OCP.TColgp import TColgp_HArray1OfPnt, TColgp_HArray1OfPnt2d
    from OCP.TColStd import TColStd_HArray1OfReal

    cylinder = BRepAdaptor_Surface(cyl_face).Cylinder()
    placed = not all(s.Location().IsIdentity() for s in (edge, cyl_face, loft_face))
    if placed or abs(cylinder.Axis().Direction().Z() - 1.0) > 1e-12 or not cylinder.Direct() \
            or cylinder.Axis().Location().Distance(gp_Pnt()) > 1e-12:
        return  # not the booleans' edge on a cylinder about +Z: leave it as the boolean made it
    radius, surf = cylinder.Radius(), BRep_Tool.Surface_s(loft_face)
    curve = BRepAdaptor_Curve(edge)
    t0, t1 = curve.FirstParameter(), curve.LastParameter()
    old_uv = BRep_Tool.CurveOnSurface_s(edge, loft_face, 0.0, 0.0)
    period = surf.Bounds()[3] - surf.Bounds()[2]
    ends = []
    for t in (t0, t1):
        u, v = GeomAPI_ProjectPointOnSurf(curve.Value(t), surf).LowerDistanceParameters()
        ends.append((u, v + period * round((old_uv.Value(t).Y() - v) / period)))  # the branch of a closed face
    (ua, va), (ub, vb) = ends
    if abs(vb - va) < 1e-9:
        return  # not along the track
    knots = np.array([surf.VKnot(k) for k in range(1, surf.NbVKnots() + 1)])
    lo, hi = sorted((va, vb))
    cuts = np.concatenate([[lo], knots[(knots > lo + 1e-9) & (knots < hi - 1e-9)], [hi]])
    v = np.concatenate([np.linspace(a, b, EDGE_NODES_PER_SPAN, endpoint=False)
                        for a, b in zip(cuts[:-1], cuts[1:], strict=True)] + [[hi]])
    v = v if vb >= va else v[::-1]
    v[0], v[-1] = va, vb
    t = t0 + (t1 - t0) * (v - va) / (vb - va)

    def on_cylinder(u: float, v: float) -> tuple[float, gp_Pnt, gp_Vec, gp_Vec]:
        for _ in range(30):
            p, du, dv = gp_Pnt(), gp_Vec(), gp_Vec()
            surf.D1(u, v, p, du, dv)
            rho = math.hypot(p.X(), p.Y())
            step = (rho - radius) * rho / (p.X() * du.X() + p.Y() * du.Y())
            u -= step
            if abs(step) < 1e-14:
                break
        surf.D1(u, v, p, du, dv)
        return u, p, du, dv

    uv, pts = [], []
    u = ua
    for k, vk in enumerate(v):
        u, p, _, _ = on_cylinder(u, float(vk))
        if k in (0, v.size - 1):  # the vertex itself (on both surfaces within 1e-14 mm, measured)
            u, p = (ua, curve.Value(t0)) if k == 0 else (ub, curve.Value(t1))
        uv.append((u, float(vk)))
        pts.append(p)
    phi = np.unwrap([ElSLib.Parameters_s(cylinder, p)[0] for p in pts])
    old = BRep_Tool.CurveOnSurface_s(edge, cyl_face, 0.0, 0.0).Value(float(t[v.size // 2])).X()
    phi += 2 * math.pi * round((old - phi[v.size // 2]) / (2 * math.pi))  # the pcurve's branch of the angle
    params = TColStd_HArray1OfReal(1, v.size)
    xyz, on_loft, on_cyl = (TColgp_HArray1OfPnt(1, v.size), TColgp_HArray1OfPnt2d(1, v.size),
                            TColgp_HArray1OfPnt2d(1, v.size))
    for k in range(v.size):
        params.SetValue(k + 1, float(t[k]))
        xyz.SetValue(k + 1, pts[k])
        on_loft.SetValue(k + 1, gp_Pnt2d(*uv[k]))
        on_cyl.SetValue(k + 1, gp_Pnt2d(float(phi[k]), pts[k].Z()))
    fits = (GeomAPI_Interpolate(xyz, params, False, 1e-12), Geom2dAPI_Interpolate(on_loft, params, False, 1e-12),
            Geom2dAPI_Interpolate(on_cyl, params, False, 1e-12))
    tangents = []
    for u, vk in (uv[0], uv[-1]):  # d/dt of the exact intersection: v' fixed, u' from |S_xy(u, v)| = R
        _, p, du, dv = on_cylinder(u, vk)
        dv_dt = (vb - va) / (t1 - t0)
        du_dt = -(p.X() * dv.X() + p.Y() * dv.Y()) / (p.X() * du.X() + p.Y() * du.Y()) * dv_dt
        d3 = du.Multiplied(du_dt).Added(dv.Multiplied(dv_dt))
        tangents.append((d3, gp_Vec2d(du_dt, dv_dt), gp_Vec2d((p.X() * d3.Y() - p.Y() * d3.X()) / radius ** 2, d3.Z())))
    for j, fit in enumerate(fits):
        fit.Load(tangents[0][j], tangents[1][j], False)
        fit.Perform()
    tol = BRep_Tool.Tolerance_s(edge)
    builder.UpdateEdge(edge, fits[0].Curve(), tol)
    builder.UpdateEdge(edge, fits[1].Curve(), loft_face, tol)
    builder.UpdateEdge(edge, fits[2].Curve(), cyl_face, tol)
    builder.Range(edge, t0, t1)


def path_deviation(geometry: CylindricalGeometry, n: int = LOFT_SECTIONS, samples: int = 500) -> float:
    """Largest distance (mm) from the exact 3D pitch curve to the periodic B-spline through its points at the n
    sections' cam angles (the loft's pitch path), measured at ``samples`` points between the interpolated ones."""
    cq = cadquery()
    from OCP.BRep import BRep_Tool
    from OCP.GeomAPI import GeomAPI_ProjectPointOnCurve
    from OCP.gp import gp_Pnt

    phi = np.linspace(0.0, geometry.period, n, endpoint=False)
    edge = cq.Edge.makeSpline([_vec(cq, p) for p in pitch_3d(geometry, phi)], periodic=True)
    curve = BRep_Tool.Curve_s(edge.wrapped, 0.0, 1.0)
    test = pitch_3d(geometry, (np.arange(samples) + 0.5) * geometry.period / samples)
    worst = 0.0
    for p in test:
        proj = GeomAPI_ProjectPointOnCurve(gp_Pnt(*map(float, p)), curve)
        worst = max(worst, proj.LowerDistance())
    return worst


def cylinder_solid(geometry: CylindricalGeometry, *, tol: float, bore_mm: float = 0.0):
    """The grooved cylinder (:func:`grooved_cylinder` with :func:`loft_sections` sections) and the measured
    deviation of its pitch path (mm): what the STEP and IGES files and the assembly are made of (the exported STL
    is meshed from the exact surfaces, :mod:`camfab.cad.cylinder_mesh`)."""
    n, dev = loft_sections(geometry, tol)
    return grooved_cylinder(geometry, n=n, bore_mm=bore_mm), dev


def cylinder_step(geometry: CylindricalGeometry, *, tol: float, name: str = "cam",
                  bore_mm: float = 0.0) -> tuple[str, float]:
    """STEP text of the grooved cylinder and the measured deviation of its loft's pitch path (mm); more sections
    when the default ones leave the path farther than ``tol`` from the exact curve."""
    solid, dev = cylinder_solid(geometry, tol=tol, bore_mm=bore_mm)
    return solid_dumps(solid, name=name), dev


def loft_sections(geometry: CylindricalGeometry, tol: float) -> tuple[int, float]:
    """The number of the loft's sections (:data:`LOFT_SECTIONS`, doubled while the pitch path through their cam
    angles lies farther than ``tol`` from the exact pitch curve, :func:`path_deviation`) and the path's measured
    deviation (mm)."""
    n = LOFT_SECTIONS
    dev = path_deviation(geometry, n)
    while dev > tol and n < 16 * LOFT_SECTIONS:
        n *= 2
        dev = path_deviation(geometry, n)
    if dev > tol:
        raise ExportError(f"the STEP loft's pitch path stays {dev:.3g} mm from the exact pitch curve with {n} "
                          f"sections, more than the {tol:g} mm tolerance. Give a larger [manufacturing] tolerance_mm")
    return n, dev


def solid_mesh(solid, tol: float):
    """The cadquery solid tessellated by OpenCascade (linear deflection ``tol`` mm, 0.2 rad angular), as a
    trimesh with the faces' shared edge points merged; refused unless watertight."""
    import trimesh
    from OCP.BRepMesh import BRepMesh_IncrementalMesh

    BRepMesh_IncrementalMesh(solid.wrapped, tol, False, 0.2, True)  # absolute deflection (cadquery's is relative)
    verts, tris = solid.tessellate(tol, 0.2)  # reads that triangulation (fine enough: not meshed again)
    mesh = trimesh.Trimesh(np.array([v.toTuple() for v in verts]), np.array(tris, dtype=np.int64), process=False)
    mesh.merge_vertices()
    if not mesh.is_watertight:
        raise ExportError("the grooved cylinder's mesh is not watertight (OpenCascade's tessellation left a gap). "
                          "Give another [manufacturing] tolerance_mm")
    return mesh


def cylinder_stl(geometry: CylindricalGeometry, *, tol: float, name: str = "cam",
                 bore_mm: float = 0.0) -> tuple[bytes, float]:
    """Binary STL of the grooved cylinder (the STEP's solid, :func:`solid_mesh` within ``tol``) and the loft's
    pitch path's measured deviation (mm; the mesh adds at most ``tol``, OCC's linear deflection); ``camfab export
    --stl`` meshes the exact surfaces instead (:mod:`camfab.cad.cylinder_mesh`)."""
    solid, dev = cylinder_solid(geometry, tol=tol, bore_mm=bore_mm)
    return solid_stl(solid, tol=tol, name=name), dev


def solid_stl(solid, *, tol: float, name: str = "cam", what: str = "grooved cylinder") -> bytes:
    """Binary STL of the cylinder ``solid`` (:func:`solid_mesh` within ``tol``), camfab's header naming ``what``."""
    data = solid_mesh(solid, tol).export(file_type="stl")
    head = f"camfab {plain(name)} units=mm tol={tol:g} {what}".encode("ascii", "replace")[:80]
    return head.ljust(80, b" ") + data[80:]
