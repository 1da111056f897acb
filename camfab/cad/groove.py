"""Files of a groove (face-groove) cam: one plate, its two flanks and the pitch curve.

The plate is a disc of radius ``outer flank's largest radius + rim`` with the rim
``max(w, RIM_MIN_MM)`` (w = R_r + b/2, the groove half-width: the outer wall is at least as thick as half the
groove), bored as ``[manufacturing]`` says; the groove is pocketed from the face z = 0 (the face opposite a
hub) to ``groove_depth_mm``.

* DXF: the inner flank on ``PROFILE``, the outer flank on ``PROFILE_2``, the pitch curve (the groove's centre
  line, the roller-centre path) on ``PITCH_CURVE``, the plate's rim circle on ``PLATE``; with tool paths, the
  centre pass and both flank finishing passes on ``TOOL_PATH``.
* STEP: the plate solid with the groove pocket (exact lines and arcs).
* IGES: the STEP's solid (:func:`groove_iges`).
* STL: the same solid as a watertight mesh, every loop flattened by chords inscribed in its arcs within tol/2.
"""
from __future__ import annotations

import numpy as np

from ..design.kinds import CamKind
from ..discretize import arcs
from ..errors import GeometryError
from ..geom2d import ArcChain
from ..io import safe_stem
from ..offset.groove import groove_tool_paths
from ..textsafe import plain
from ..tolerances import profile_fit_tolerance
from . import dxf as dxf_mod
from . import step
from .export import Artifact, CamShapes, flattened_deviation, plate_of, solid_outlines, stl_facet_tolerance
from .plate import PlateSpec, bore_loop, circle_loop
from .stepheader import design_meta

__all__ = ["RIM_MIN_MM", "is_groove", "plate_radius", "groove_artifacts", "groove_mesh", "groove_iges"]

#: the thinnest outer wall of a groove plate (mm)
RIM_MIN_MM = 3.0


def is_groove(geometry) -> bool:
    """True for the geometry of a groove cam (``[cam] kind = "groove"``)."""
    return getattr(getattr(geometry, "mechanism", None), "cam_kind", None) == CamKind.GROOVE


def plate_radius(geometry) -> float:
    """The groove plate's radius (mm): the outer flank's largest radius plus the rim (module notes)."""
    w = float(geometry.mechanism.half_width_mm)
    return float(geometry.radius_extremes(1).max) + max(w, RIM_MIN_MM)


def groove_artifacts(spec, geometry, formats: list[str], *, shapes: CamShapes, tol: float, dxf_flavour: str,
                     tool_paths: bool) -> list[Artifact]:
    """The DXF, STL and STEP artifacts of a groove cam (in that order, those asked for)."""
    plate, stem = plate_of(spec), safe_stem(spec.name)
    outline = circle_loop(plate_radius(geometry))
    depth = float(geometry.mechanism.groove_depth_mm)
    out: list[Artifact] = []
    if "dxf" in formats:
        out.append(_dxf(spec, geometry, shapes, plate, outline, tol, dxf_flavour, tool_paths))
    if "stl" in formats:
        # the flanks' plate fit (within PROFILE_FIT_SHARE·tol) when built, else the same fit here; flattened within
        # the rest of tol
        rest = stl_facet_tolerance(tol)
        fine = list(shapes.profiles) or [arcs(c, tol=profile_fit_tolerance(tol)) for c in shapes.curves]
        dev = max(flattened_deviation(f, c, tol, rest) for f, c in zip(fine, shapes.curves, strict=True))
        data = _stl_bytes(groove_mesh(outline, fine[0], fine[1], plate, depth, tol=rest), spec.name, rest)
        out.append(Artifact(f"{stem}.stl", data, "stl", None, dev))
    if "step" in formats:
        (inner, outer), devs = solid_outlines(shapes, tol)
        text = step.groove_dumps(outline, inner, outer, plate, depth, name=spec.name, meta=design_meta(spec))
        out.append(Artifact(f"{stem}.step", text.encode("utf-8"), "step", inner.n_entities + outer.n_entities,
                            max(devs), f"groove {depth:g} mm deep from the face z = 0"))
    return out


def groove_iges(spec, geometry, *, shapes: CamShapes, tol: float) -> Artifact:
    """``<stem>.igs``: the groove cam's plate with the groove pocketed (the STEP's solid), as IGES."""
    from .iges import shape_dumps

    (inner, outer), devs = solid_outlines(shapes, tol)
    solid = step.groove_solid(circle_loop(plate_radius(geometry)), inner, outer, plate_of(spec),
                              float(geometry.mechanism.groove_depth_mm))
    text = shape_dumps(solid.val(), name=spec.name)
    return Artifact(f"{safe_stem(spec.name)}.igs", text.encode("ascii"), "iges", inner.n_entities + outer.n_entities,
                    max(devs))


def _dxf(spec, geometry, shapes: CamShapes, plate: PlateSpec, outline: ArcChain, tol: float, flavour: str,
         tool_paths: bool) -> Artifact:
    tools: tuple[ArcChain, ...] = ()
    tool_d = spec.manufacturing.tool_diameter_mm
    if tool_paths and tool_d:
        g = groove_tool_paths(geometry.profiles[0], geometry.profiles[1], tool_d / 2, tol=tol)
        tools = (g.centre_arcs, g.inner.arcs, g.outer.arcs)
    mech = geometry.mechanism
    content = dxf_mod.DxfContent(
        profiles=shapes.profiles, pitch_curves=shapes.pitch[:1], base_radius=mech.base_radius_mm,
        prime_radius=mech.base_radius_mm + mech.half_width_mm,
        bore=bore_loop(plate.bore_mm, plate.keyway) if plate.bore_mm > 0 else None, tool_paths=tools, tol_mm=tol,
        deviation_mm=max(shapes.profile_deviation), name=spec.name, plate_outline=outline)
    text = dxf_mod.dumps(content, flavour=flavour)
    ents = sum(lp.n_entities for lp in shapes.profiles)
    return Artifact(f"{safe_stem(spec.name)}.dxf", text.encode("utf-8"), "dxf", ents, max(shapes.profile_deviation),
                    f"{flavour}; groove: inner flank PROFILE, outer flank PROFILE_2"
                    + (f"; {len(tools)} tool path(s)" if tools else ""))


# ---------------------------------------------------------------------------
def _ring(loop: ArcChain, tol: float) -> np.ndarray:
    """A loop's polyline (inscribed chords within ``tol``), counter-clockwise, without the closing point."""
    pts = np.asarray(loop.flatten(tol), dtype=float)
    if np.allclose(pts[0], pts[-1]):
        pts = pts[:-1]
    x, y = pts.T
    area = 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))
    return pts if area > 0 else pts[::-1]


def groove_mesh(outline: ArcChain, inner: ArcChain, outer: ArcChain, plate: PlateSpec, depth_mm: float, *,
                tol: float) -> np.ndarray:
    """The triangles ``(m, 3, 3)`` of a watertight mesh of the groove plate (:mod:`camfab.cad.stl`): caps at
    z = 0 (around the groove), at the groove's floor z = depth and at z = thickness, and the walls of the rim,
    the bore and both flanks."""
    from .stl import cap_triangles, is_closed_surface, wall_triangles

    if plate.hub_diameter_mm and plate.hub_length_mm:
        raise GeometryError("STL export of a plate with a hub is not supported yet; "
                            "remove manufacturing.hub_diameter_mm for the STL or use STEP")
    rim, fin, fout = _ring(outline, tol), _ring(inner, tol), _ring(outer, tol)
    hole = plate.hole()
    bore = _ring(hole, tol) if hole is not None else None
    holes = [bore[::-1]] if bore is not None else []
    t = plate.thickness_mm
    parts = [
        cap_triangles([rim, *holes], t, up=True),                # the back face
        cap_triangles([rim, fout[::-1]], 0.0, up=False),         # the front face outside the groove
        cap_triangles([fin, *holes], 0.0, up=False),             # the front face inside the groove
        cap_triangles([fout, fin[::-1]], depth_mm, up=False),    # the groove's floor, facing the opening
        wall_triangles(rim, 0.0, t),                             # rings counter-clockwise: a wall faces out
        wall_triangles(fout[::-1], 0.0, depth_mm),               # the outer flank faces the groove (inward)
        wall_triangles(fin, 0.0, depth_mm),                      # the inner flank faces the groove (outward)
    ]
    if bore is not None:
        parts.append(wall_triangles(bore[::-1], 0.0, t))
    tri = np.concatenate(parts)
    if not is_closed_surface(tri):
        raise GeometryError("the groove plate's mesh is not watertight (a flank too close to the rim or the bore?)")
    return tri


def _stl_bytes(triangles: np.ndarray, name: str, tol: float) -> bytes:
    from .stl import stl_bytes

    return stl_bytes(triangles, f"camfab {plain(name)} units=mm tol={tol:g} groove")


def groove_width_note(geometry) -> str:
    """``"groove 16.1 mm wide (roller 16 mm + backlash 0.1 mm), 6 mm deep"`` for reports."""
    m = geometry.mechanism
    return (f"groove {2 * m.half_width_mm:g} mm wide (roller {2 * m.roller_radius_mm:g} mm + backlash "
            f"{m.backlash_mm:g} mm), {m.groove_depth_mm:g} mm deep")


