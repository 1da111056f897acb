"""Precomputed frames of a cylindrical cam's animation in the HTML report: the cylinder turning, the roller moving
along its axis.

The view (``templates/report/cylinder_animation.js``) looks at the cylinder from the follower's side (fixed-frame
+Y, :mod:`camfab.design.cylindrical`): the cam axis horizontal on the screen (u = z, mm), the fixed-frame X
upwards (v = X).  A point of the cylinder r at cam-frame polar angle a lies, after the cam has turned by θ
with sense σ, at the fixed-frame polar angle ``α = a − σθ`` (the design's ``90° + σθ`` read backwards); it is
drawn at ``(z, r·cos α)`` while it faces the viewer (``sin α > 0``).  The data holds:

* ``edges``: the groove's edges on the outer cylinder (the +z and −z flanks developed on the outer radius and
  wrapped: cam-frame angle a = 90° + σ·x/r and z), which the script turns by each frame's θ;
* ``marks``: the cam-frame angles of generator lines every 30° (the first at the follower's generator at 0°), so
  the turning shows on the surface;
* per frame: the cam angle, θ, the lift S, the pressure angle on the pitch cylinder, and the roller axis's exact
  position ``roller = (z, v)`` — z the developed pitch curve's z on the pitch cylinder (z₀ + S translating,
  z₀ + L·sin φ oscillating) and v = −σ·L·(1 − cos φ) the oscillating arm's sideways shift (0 translating);
* the oscillating follower's pivot ``(z₀, −σ·L)``.

Lengths are rounded to 1 µm, angles to 1e-8 rad, as in :mod:`camfab.report.animation`.
"""
from __future__ import annotations

import math
from typing import Any

import numpy as np

from ._common import sample_grid

__all__ = ["cylinder_animation_data", "is_cylindrical", "CYLINDER_ANIMATION_CAPTION"]

#: the sentence under the animation
CYLINDER_ANIMATION_CAPTION = (
    "The cylinder, seen from the follower's side with its axis across, turns (the orange line is its 0° "
    "generator; the groove's edges on the outer surface show on the front half); the roller sits in the groove at "
    "its exact position along the axis. The strip below shows S over the cycle.")


def _r(a, digits: int = 3) -> list:
    return (np.round(np.asarray(a, dtype=float), digits) + 0.0).tolist()


def is_cylindrical(geometry: Any) -> bool:
    """True for a cylindrical cam's geometry (it has a ``cylinder``)."""
    return getattr(geometry, "cylinder", None) is not None and hasattr(geometry, "at_radius")


def _edges(geometry: Any, points: int) -> list[list[float]]:
    """The +z and −z flanks on the outer cylinder, wrapped: flat [a, z, a, z, …] (cam-frame angle, mm)."""
    ro, sense = geometry.cylinder.outer_radius_mm, geometry.mechanism.sense
    out = []
    for flank in (1, -1):
        c = geometry.at_radius(ro, flank)
        p = c.evaluate(sample_grid(c.period, c.breakpoints, points + 1)).point
        a = 0.5 * math.pi + sense * p[:, 0] / ro
        out.append(np.column_stack([np.round(a, 6), np.round(p[:, 1], 3)]).ravel().tolist())
    return out


def cylinder_animation_data(spec: Any, geometry: Any, report: Any, *, frames: int = 360,
                            edge_points: int = 720) -> dict[str, Any]:
    """Everything the cylinder's canvas animation draws, as a JSON-ready dict (see the module notes)."""
    cyl, mech = geometry.cylinder, geometry.mechanism
    sense = int(mech.sense)
    theta = np.arange(frames) * (2 * math.pi / frames)
    pitch = geometry.at_radius(cyl.radius_mm)
    C, _ = pitch.pitch(theta)
    s = pitch.evaluate(theta)
    S = pitch.motion.evaluate(theta, (0,))[0]
    z0 = mech.z0_for(geometry.program)
    arm = float(getattr(mech, "arm_length_mm", 0.0) or 0.0)
    oscillating = mech.motion.value == "oscillating"
    shift = -sense * arm * (1.0 - np.cos(np.radians(S))) if oscillating else np.zeros_like(S)
    pa_lim = report.pressure_angle.limit if report.pressure_angle is not None else None
    half = max(cyl.outer_radius_mm, arm if oscillating else 0.0)
    return {
        "cylinder": True, "name": spec.name, "sense": sense, "unit": "°", "period": 360.0,
        "lift_unit": spec.follower.lift_unit, "radius": cyl.radius_mm, "outer": cyl.outer_radius_mm,
        "inner": cyl.inner_radius_mm, "length": cyl.length_mm, "bore": spec.manufacturing.bore_mm / 2,
        "roller_radius": mech.half_width(cyl.radius_mm) - 0.5 * cyl.backlash_mm, "z0": round(z0, 3),
        "edges": _edges(geometry, edge_points),
        "marks": _r(0.5 * math.pi + sense * np.radians(np.arange(0.0, 360.0, 30.0)), 8),
        "pivot": [round(z0, 3), round(-sense * arm, 3)] if oscillating else None,
        "frames": {"x": _r(np.degrees(theta)), "angle": _r(theta, 8), "S": _r(S),
                   "pa": [_r(np.degrees(s.pressure_angle))],
                   "roller": _r(np.column_stack([C[:, 1], shift]).ravel())},
        "bounds": _r([-0.12 * cyl.length_mm, 1.12 * cyl.length_mm, -1.25 * half, 1.25 * half]),
        "pa_limit": pa_lim,
    }
