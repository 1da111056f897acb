"""The solid of a cylindrical cam with a rib (``[cylinder] feature = "rib"``): STEP and STL.

The body is the cylinder of the rib's root radius (R − h/2, length along +Z from z = 0).  The rib is swept as the
groove is (:mod:`camfab.cad.cylinder`): along the exact 3D mid-line (a periodic B-spline, sweep points doubled
until it lies within the tolerance), the follower's roller axis as auxiliary spine, through sections holding, in
each plane normal to the path, the exact points of both rib flanks (each developed on its own radius, wrapped) on
:data:`~camfab.cad.cylinder.SECTION_RADII` radii from inside the body to past the rib's top; the sweep is then
cut to the top cylinder (R + h/2), so the rib's top is that cylinder, and fused to the body.
"""
from __future__ import annotations

import numpy as np

from ..design.cylindrical import CylindricalGeometry, pitch_3d
from ..errors import ExportError
from ..textsafe import plain
from .cylinder import CLEARANCE_MM, SECTION_RADII, groove_sections, solid_mesh, sweep_points
from .step import cadquery, solid_dumps

__all__ = ["ribbed_cylinder", "rib_solid", "rib_step", "rib_stl"]


def _spline(cq, points: np.ndarray):
    return cq.Wire.assembleEdges([cq.Edge.makeSpline([cq.Vector(*map(float, p)) for p in points], periodic=True)])


def ribbed_cylinder(geometry: CylindricalGeometry, *, n: int, bore_mm: float = 0.0):
    """The cylinder with its rib as a cadquery Solid (see the module notes)."""
    cq = cadquery()
    cyl = geometry.cylinder
    r_root, r_top = cyl.inner_radius_mm, cyl.outer_radius_mm
    radii = np.linspace(max(r_root - CLEARANCE_MM, 0.5 * r_root), r_top + CLEARANCE_MM, SECTION_RADII)
    theta, sections = groove_sections(geometry, n, radii)
    wires = [cq.Wire.makePolygon([cq.Vector(*map(float, p)) for p in (*sec[0], *sec[1][::-1])], close=True)
             for sec in sections]
    sweep = cq.Solid.sweep_multi([*wires, wires[0]], _spline(cq, pitch_3d(geometry, theta)), makeSolid=True,
                                 mode=_spline(cq, pitch_3d(geometry, theta, float(radii[-1]))))
    top = cq.Solid.makeCylinder(r_top, cyl.length_mm, cq.Vector(0, 0, 0), cq.Vector(0, 0, 1))
    body = cq.Solid.makeCylinder(r_root, cyl.length_mm, cq.Vector(0, 0, 0), cq.Vector(0, 0, 1))
    solid = body.fuse(sweep.intersect(top)).clean()
    if bore_mm > 0:
        solid = solid.cut(cq.Solid.makeCylinder(bore_mm / 2, cyl.length_mm, cq.Vector(0, 0, 0), cq.Vector(0, 0, 1)))
    if not (sweep.isValid() and solid.isValid()) or len(solid.Solids()) != 1:
        raise ExportError(f"the ribbed cylinder is not one valid solid (OCC's checker): rib {cyl.rib_width_mm:g} mm "
                          f"wide, {cyl.groove_depth_mm:g} mm high. Check the design for an undercut")
    return solid.Solids()[0] if hasattr(solid, "Solids") else solid


def rib_solid(geometry: CylindricalGeometry, *, tol: float, bore_mm: float = 0.0):
    """The ribbed cylinder (:func:`ribbed_cylinder` with :func:`~camfab.cad.cylinder.sweep_points` sections) and
    the measured deviation of its path (mm): what its STEP, STL and IGES files are made of."""
    n, dev = sweep_points(geometry, tol)
    return ribbed_cylinder(geometry, n=n, bore_mm=bore_mm), dev


def rib_step(geometry: CylindricalGeometry, *, tol: float, name: str = "cam",
             bore_mm: float = 0.0) -> tuple[str, float]:
    """STEP text of the ribbed cylinder and the measured deviation of its sweep path (mm)."""
    n, dev = sweep_points(geometry, tol)
    return solid_dumps(ribbed_cylinder(geometry, n=n, bore_mm=bore_mm), name=name), dev


def rib_stl(geometry: CylindricalGeometry, *, tol: float, name: str = "cam",
            bore_mm: float = 0.0) -> tuple[bytes, float]:
    """Binary STL of the ribbed cylinder (its STEP solid tessellated within ``tol``) and the path's deviation."""
    n, dev = sweep_points(geometry, tol)
    data = solid_mesh(ribbed_cylinder(geometry, n=n, bore_mm=bore_mm), tol).export(file_type="stl")
    head = f"camfab {plain(name)} units=mm tol={tol:g} ribbed cylinder".encode("ascii", "replace")[:80]
    return head.ljust(80, b" ") + data[80:], dev
