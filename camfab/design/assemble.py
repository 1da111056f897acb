"""From a validated :class:`DesignSpec` to mechanism, exact geometry and check report.

The one place that maps design-file sections onto the geometry classes, so the
CLI and the exporters never repeat the mapping.
"""
from __future__ import annotations

from ..errors import Problem, SpecError
from .checks import Report, check
from .mechanisms import OscillatingFlat, OscillatingRoller, TranslatingCamRoller, TranslatingFlat, TranslatingRoller
from .profile import CamGeometry
from .spec import DesignSpec

__all__ = ["mechanism_from_spec", "geometry_from_spec", "check_design"]


def mechanism_from_spec(spec: DesignSpec):
    """The mechanism dataclass described by ``[cam]`` and ``[follower]``."""
    f, rot = spec.follower, spec.cam.rotation
    kind = spec.cam.kind
    if kind == "translating":
        return TranslatingCamRoller(f.roller_radius_mm or 0.0, f.base_height_mm or 0.0, spec.cam.direction)
    if kind != "disc":
        raise SpecError(Problem("cam.kind", kind, "this cam kind is not available yet in this build",
                                'use kind = "disc" or "translating"'), spec.source)
    rr = 0.0 if f.type == "knife" else (f.roller_radius_mm or 0.0)
    if f.type in ("roller", "knife"):
        if f.motion == "translating":
            return TranslatingRoller(f.base_radius_mm, rr, f.offset_mm or 0.0, rot)
        return OscillatingRoller(f.base_radius_mm, rr, f.pivot_distance_mm, f.arm_length_mm, rot)
    if f.motion == "translating":
        return TranslatingFlat(f.base_radius_mm, f.face_offset_mm or 0.0, rot)
    return OscillatingFlat(f.base_radius_mm, f.pivot_distance_mm, f.face_offset_mm or 0.0, rot)


def geometry_from_spec(spec: DesignSpec) -> CamGeometry:
    """The exact :class:`CamGeometry`; every geometry problem raised as one :class:`SpecError`."""
    mech = mechanism_from_spec(spec)
    try:
        return CamGeometry(mech, spec.program())
    except SpecError as exc:
        raise SpecError(exc.problems, spec.source) from None


def check_design(spec: DesignSpec, *, tool_radius_mm: float | None = None) -> Report:
    """Geometry + checks + verdict for a design (the ``camfab check`` report)."""
    geom = geometry_from_spec(spec)
    return check(geom, pressure_angle_limit_deg=spec.pressure_angle_limit_deg,
                 allow_acceleration_jump=spec.cam.kind in ("constant_width", "constant_diameter"),
                 tool_radius_mm=tool_radius_mm, face_margin_mm=spec.face_margin_mm,
                 name=spec.name, speed=spec.speed)
