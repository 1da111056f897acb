"""A cylindrical cam's assembly STEP: the grooved cylinder on its shaft, the roller in the groove and the
translating follower's pin and slide, at a cam angle.

Frame (the plate assemblies' convention, ``docs/decisions.md`` "Assembly STEP"): the cam axis is Z, the cylinder
spans z = 0 … length; at cam angle φ the cam is turned by −σ·φ about Z (σ = +1 for a ``cw`` cam), so the pitch
point of angle φ — at the polar angle 90° + σ·φ in the cam frame (:func:`camfab.design.cylindrical.pitch_3d`) — is
on +Y.  The roller's axis is the radial line +Y at z = z₀ + S(φ), the exact motion; it reaches from ``clearance``
above the groove bottom to the outer cylinder (a conical roller: the cone with its apex on the cam axis).  Its pin
carries on up the same line to the slide, a block ``clearance`` above the cylinder that slides parallel to Z.  The
shaft goes through the bore, or, without one, stands on both end faces.
"""
from __future__ import annotations

import math
import tempfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, cast

import numpy as np

from ..design.cylindrical import RollerShape, pitch_3d
from ..errors import ExportError
from .assembly import canonical_order, to_assembly
from .step import cadquery, canonical_reals
from .stepheader import design_meta, header_dumps

__all__ = ["CylinderParts", "parts", "dumps", "roller_axis"]


@dataclass
class CylinderParts:
    """Named solids with their placement (translation, rotation about Z in degrees): what
    :func:`camfab.cad.assembly.to_assembly` names and colours."""

    items: list[tuple[str, Any, tuple[float, float, float], float]] = field(default_factory=list)

    def add(self, name: str, shape, at=(0.0, 0.0, 0.0), rot: float = 0.0) -> None:
        self.items.append((name, shape, at, rot))


def roller_axis(geometry, phi: float) -> float:
    """The roller axis's height z (mm) at cam angle ``phi`` (rad): the exact pitch curve's."""
    return float(pitch_3d(geometry, np.array([phi]))[0, 2])


def parts(spec, geometry, solid, phi: float) -> CylinderParts:
    """The assembly's parts at cam angle ``phi`` (rad), the cam being ``solid`` (the grooved cylinder)."""
    cq = cadquery()
    mech = geometry.mechanism
    if getattr(mech, "arm_length_mm", 0.0):
        raise ExportError("the assembly of a cylindrical cam with an oscillating follower is not made yet (its "
                          "arm and pivot); use the STEP of the cam (step = true)")
    cyl, clear = geometry.cylinder, spec.assembly.clearance_mm or 0.5
    rr, zc = mech.roller_radius_mm, roller_axis(geometry, phi)
    out = CylinderParts()
    out.add("cam", solid, rot=math.degrees(-mech.sense * phi))
    r0, r1 = cyl.inner_radius_mm + clear, cyl.outer_radius_mm
    y = cq.Vector(0, 1, 0)
    if cyl.roller is RollerShape.CONICAL:
        roller = cq.Solid.makeCone(rr * r0 / cyl.radius_mm, rr * r1 / cyl.radius_mm, r1 - r0, cq.Vector(0, r0, zc), y)
    else:
        roller = cq.Solid.makeCylinder(rr, r1 - r0, cq.Vector(0, r0, zc), y)
    pin_r = 0.4 * rr
    top = r1 + clear
    slide = max(2 * rr, 4.0)
    out.add("roller", roller)
    out.add("pin", cq.Solid.makeCylinder(pin_r, top - r1, cq.Vector(0, r1, zc), y))
    out.add("slide", cq.Solid.makeBox(2 * slide, slide, 2 * slide, cq.Vector(-slide, top, zc - slide)))
    bore = spec.manufacturing.bore_mm
    z = cq.Vector(0, 0, 1)
    if bore > 0:
        shaft = cq.Solid.makeCylinder(bore / 2, 2 * cyl.length_mm, cq.Vector(0, 0, -cyl.length_mm / 2), z)
    else:
        stub = 0.25 * cyl.inner_radius_mm
        shaft = cq.Solid.makeCylinder(stub, cyl.length_mm / 2, cq.Vector(0, 0, -cyl.length_mm / 2), z).fuse(
            cq.Solid.makeCylinder(stub, cyl.length_mm / 2, cq.Vector(0, 0, cyl.length_mm), z))
    out.add("shaft", shaft)
    return out


def dumps(spec, geometry, solid, phi: float) -> str:
    """The assembly STEP (AP214) text at cam angle ``phi`` (rad), reproducible (the plate assemblies' header
    and canonical order)."""
    assy = to_assembly(cast(Any, parts(spec, geometry, solid, phi)))  # reads its items only
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "assembly.step"  # never a path built from the name
        assy.export(str(path), "STEP")
        text = path.read_text(encoding="utf-8", errors="replace")
    text = header_dumps(text, spec.name, design_meta(spec))
    return canonical_reals(canonical_order(text))
