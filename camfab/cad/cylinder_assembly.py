"""A cylindrical cam's assembly STEP: the grooved cylinder on its shaft, the roller in the groove and the
translating follower's pin and slide, at a cam angle.

Frame (the plate assemblies' convention, ``docs/decisions.md`` "Assembly STEP"): the cam axis is Z, the cylinder
spans z = 0 … length; at cam angle φ the cam is turned by −σ·φ about Z (σ = +1 for a ``cw`` cam), so the pitch
point of angle φ — at the polar angle 90° + σ·φ in the cam frame (:func:`camfab.design.cylindrical.pitch_3d`) — is
on +Y.  The roller's axis is the radial line +Y at z = z₀ + S(φ), the exact motion; it reaches from ``clearance``
above the groove bottom to the outer cylinder (a conical roller: the cone with its apex on the cam axis).  Its pin
carries on up the same line to the slide, a block ``clearance`` above the cylinder that slides parallel to Z.  An
oscillating follower's roller axis stays parallel to +Y at X = −σ·e (``docs/decisions.md``, "Cylindrical cams: the
oscillating follower's exact pitch curve"); its pin carries the arm, in the plane ``clearance`` above the cylinder,
to the pivot at X = −σ·L, z = z₀ (pivot axis parallel to Y).  The shaft goes through the bore, or, without one,
stands on both end faces.

A rib (``[cylinder] feature = "rib"``): two rollers straddle it, ``roller_1`` facing the rib's +z flank and
``roller_2`` its −z flank, each on its own radial axis shifted from the rib's mid-line (the pitch curve) by the
axial offset its flank's check uses (:attr:`~camfab.design.cylindrical.DevelopedContact.shift`, ±(w/2 + R_r + b/2)),
each with its pin, both pins carried by one slide (the rib's follower is translating only).
"""
from __future__ import annotations

import math
import tempfile
from pathlib import Path
from typing import Any, cast

import numpy as np

from ..design.cylindrical import Feature, RollerShape, pitch_3d
from ..records import dataclass, field
from .assembly import canonical_order, to_assembly
from .step import cadquery, canonical_reals
from .stepheader import design_meta, header_dumps

__all__ = ["CylinderParts", "parts", "dumps", "roller_axis", "axis_x", "roller_axes"]


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


def axis_x(geometry, phi: float) -> float:
    """The roller axis's fixed-frame X (mm) at cam angle ``phi``: 0 for a translating follower, −σ·e for an
    oscillating one (the pitch point turned back by −σ·φ)."""
    p = pitch_3d(geometry, np.array([phi]))[0]
    a = -geometry.mechanism.sense * phi
    return float(p[0] * math.cos(a) - p[1] * math.sin(a))


def roller_axes(geometry, phi: float) -> list[float]:
    """Each roller axis's height z (mm) at cam angle ``phi`` (rad): the groove's one on the exact pitch curve; a
    rib's two (the +z flank's roller first) shifted from it along the axis as the design's check of each rib flank
    shifts its roller (:meth:`~camfab.design.cylindrical.CylindricalGeometry.at_radius`, ``shift``)."""
    zc = roller_axis(geometry, phi)
    if geometry.cylinder.feature is not Feature.RIB:
        return [zc]
    return [zc + geometry.at_radius(geometry.cylinder.radius_mm, flank).shift for flank in (1, -1)]


def parts(spec, geometry, solid, phi: float) -> CylinderParts:
    """The assembly's parts at cam angle ``phi`` (rad), the cam being ``solid`` (the grooved or ribbed cylinder)."""
    cq = cadquery()
    mech = geometry.mechanism
    cyl, clear = geometry.cylinder, spec.assembly.clearance_mm or 0.5
    rr, zc, xa = mech.roller_radius_mm, roller_axis(geometry, phi), axis_x(geometry, phi)
    out = CylinderParts()
    out.add("cam", solid, rot=math.degrees(-mech.sense * phi))
    r0, r1 = cyl.inner_radius_mm + clear, cyl.outer_radius_mm
    y0, y1 = math.sqrt(r0**2 - xa**2), math.sqrt(r1**2 - xa**2)  # where the axis (parallel to Y) meets them
    y, top = cq.Vector(0, 1, 0), r1 + clear
    axes = roller_axes(geometry, phi)
    for k, z in enumerate(axes, start=1):
        if cyl.roller is RollerShape.CONICAL:
            roller = cq.Solid.makeCone(rr * r0 / cyl.radius_mm, rr * r1 / cyl.radius_mm, y1 - y0,
                                       cq.Vector(xa, y0, z), y)
        else:
            roller = cq.Solid.makeCylinder(rr, y1 - y0, cq.Vector(xa, y0, z), y)
        tag = f"_{k}" if len(axes) > 1 else ""  # a rib's two rollers: roller_1 (+z flank), roller_2 (−z flank)
        out.add(f"roller{tag}", roller)
        out.add(f"pin{tag}", cq.Solid.makeCylinder(0.4 * rr, top - y1, cq.Vector(xa, y1, z), y))
    if getattr(mech, "arm_length_mm", 0.0):
        _arm(cq, out, geometry, (xa, zc), top, rr)
    else:  # one slide carrying every pin
        slide, lo, hi = max(2 * rr, 4.0), min(axes), max(axes)
        block = cq.Solid.makeBox(2 * slide, slide, hi - lo + 2 * slide, cq.Vector(xa - slide, top, lo - slide))
        out.add("slide", block)
    out.add("shaft", _shaft(cq, spec, cyl))
    return out


def _arm(cq, out: CylinderParts, geometry, roller: tuple[float, float], top: float, rr: float) -> None:
    """An oscillating follower's arm, in the plane tangent to the cylinder ``top`` above the axis, from its pivot
    (X = −σ·L, z = z₀; the pivot axis parallel to Y) to the roller's pin, and the pivot pin."""
    mech = geometry.mechanism
    px, pz = -mech.sense * mech.arm_length_mm, mech.z0_for(geometry.program)
    dx, dz = roller[0] - px, roller[1] - pz
    w, t = 1.2 * rr, max(0.5 * rr, 2.0)
    bar = cq.Solid.makeBox(math.hypot(dx, dz), t, w, cq.Vector(0, 0, -w / 2))
    bar = bar.fuse(cq.Solid.makeCylinder(w / 2, t, cq.Vector(0, 0, 0), cq.Vector(0, 1, 0)))
    bar = bar.fuse(cq.Solid.makeCylinder(w / 2, t, cq.Vector(math.hypot(dx, dz), 0, 0), cq.Vector(0, 1, 0)))
    turn = math.degrees(math.atan2(-dz, dx))  # about +Y: the bar's +X onto the pivot-to-roller direction
    out.add("arm", bar.rotate(cq.Vector(0, 0, 0), cq.Vector(0, 1, 0), turn).translate(cq.Vector(px, top, pz)))
    out.add("pivot", cq.Solid.makeCylinder(0.4 * w, 3 * t, cq.Vector(px, top - t, pz), cq.Vector(0, 1, 0)))


def _shaft(cq, spec, cyl):
    """The shaft through the bore, or, without one, two stubs on the end faces."""
    bore, z = spec.manufacturing.bore_mm, cq.Vector(0, 0, 1)
    if bore > 0:
        return cq.Solid.makeCylinder(bore / 2, 2 * cyl.length_mm, cq.Vector(0, 0, -cyl.length_mm / 2), z)
    stub = 0.25 * cyl.inner_radius_mm
    return cq.Solid.makeCylinder(stub, cyl.length_mm / 2, cq.Vector(0, 0, -cyl.length_mm / 2), z).fuse(
        cq.Solid.makeCylinder(stub, cyl.length_mm / 2, cq.Vector(0, 0, cyl.length_mm), z))


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
