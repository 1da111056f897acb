"""The solid of a cylindrical cam with a rib (``[cylinder] feature = "rib"``): STEP and STL.

The body is the cylinder of the rib's root radius (R − h/2, length along +Z from z = 0).  The rib is built as the
groove's tool is (:func:`camfab.cad.cylinder.track_loft`): a loft through sections at the cam angles of
:func:`~camfab.cad.cylinder.loft_sections`, each holding, in the plane normal to the 3D pitch curve, the exact
points of both rib flanks (each developed on its own radius, wrapped) on :data:`~camfab.cad.cylinder.SECTION_RADII`
radii from inside the body to past the rib's top, its closed faces split in two; the loft is then cut to the top
cylinder (R + h/2), so the rib's top is that cylinder, and fused to the body.  Its edges along the track are
iso-curves of the loft's faces: the solid passes OCC's boolean argument analyser (the sweep it replaces had
curve-on-surface faults of up to 4.9e-5 mm).
"""
from __future__ import annotations

import numpy as np

from ..design.cylindrical import CylindricalGeometry
from ..errors import ExportError
from .cylinder import CLEARANCE_MM, SECTION_RADII, exact_edges, loft_sections, solid_stl, track_loft
from .step import cadquery, solid_dumps

__all__ = ["ribbed_cylinder", "rib_solid", "rib_step", "rib_stl"]


def ribbed_cylinder(geometry: CylindricalGeometry, *, n: int, bore_mm: float = 0.0):
    """The cylinder with its rib as a cadquery Solid (see the module notes)."""
    cq = cadquery()
    cyl = geometry.cylinder
    r_root, r_top = cyl.inner_radius_mm, cyl.outer_radius_mm
    radii = np.linspace(max(r_root - CLEARANCE_MM, 0.5 * r_root), r_top + CLEARANCE_MM, SECTION_RADII)
    loft = track_loft(geometry, n, radii)
    top = cq.Solid.makeCylinder(r_top, cyl.length_mm, cq.Vector(0, 0, 0), cq.Vector(0, 0, 1))
    body = cq.Solid.makeCylinder(r_root, cyl.length_mm, cq.Vector(0, 0, 0), cq.Vector(0, 0, 1))
    solid = body.fuse(loft.intersect(top))
    if bore_mm > 0:
        solid = solid.cut(cq.Solid.makeCylinder(bore_mm / 2, cyl.length_mm, cq.Vector(0, 0, 0), cq.Vector(0, 0, 1)))
    solid = exact_edges(solid)
    if not (loft.isValid() and solid.isValid()) or len(solid.Solids()) != 1:
        raise ExportError(f"the ribbed cylinder is not one valid solid (OCC's checker): rib {cyl.rib_width_mm:g} mm "
                          f"wide, {cyl.groove_depth_mm:g} mm high. Check the design for an undercut")
    return solid.Solids()[0] if hasattr(solid, "Solids") else solid


def rib_solid(geometry: CylindricalGeometry, *, tol: float, bore_mm: float = 0.0):
    """The ribbed cylinder (:func:`ribbed_cylinder` with :func:`~camfab.cad.cylinder.loft_sections` sections) and
    the measured deviation of its loft's pitch path (mm): what its STEP and IGES files and assembly are made of
    (its exported STL is meshed from the exact surfaces, :mod:`camfab.cad.cylinder_mesh`)."""
    n, dev = loft_sections(geometry, tol)
    return ribbed_cylinder(geometry, n=n, bore_mm=bore_mm), dev


def rib_step(geometry: CylindricalGeometry, *, tol: float, name: str = "cam",
             bore_mm: float = 0.0) -> tuple[str, float]:
    """STEP text of the ribbed cylinder and the measured deviation of its loft's pitch path (mm)."""
    solid, dev = rib_solid(geometry, tol=tol, bore_mm=bore_mm)
    return solid_dumps(solid, name=name), dev


def rib_stl(geometry: CylindricalGeometry, *, tol: float, name: str = "cam",
            bore_mm: float = 0.0) -> tuple[bytes, float]:
    """Binary STL of the ribbed cylinder (its STEP solid tessellated by OpenCascade within ``tol``) and its loft's
    path deviation; ``camfab export --stl`` meshes the exact surfaces instead (:mod:`camfab.cad.cylinder_mesh`)."""
    solid, dev = rib_solid(geometry, tol=tol, bore_mm=bore_mm)
    return solid_stl(solid, tol=tol, name=name, what="ribbed cylinder"), dev
