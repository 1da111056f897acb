"""The whole mechanism as a STEP assembly: the cam on its shaft, the follower(s) and the fixed frame.

Mating frame (``docs/decisions.md``, "Assembly STEP"): the fixed frame of the design — the cam axis is Z through
the origin, at cam angle 0 the follower lies along +Y, the cam plate spans z = 0 … thickness (a conjugate
pair's second plate above it), X to the right.  At the chosen cam angle φ the cam is turned by −σ·φ about Z
(σ = +1 for a ``cw`` cam: it turns clockwise seen from +Z); the follower is placed where the exact geometry puts
it at φ: the cam-frame sample of each profile turned back into the fixed frame, ``R(−σφ)·sample(φ)``.  A
translating (wedge) cam slides along X instead, the follower axis on the Y axis.

Every follower part is built in a local frame (a, b) whose b axis points away from the cam (the follower's rise
direction, or the arm for an oscillating follower, origin at its pivot) and is placed with one rotation about Z.
Rollers and faces lie in their cam's plate layer; forks, arms and brackets in layers beside it (``clearance``
apart), so that nothing but the contact touches the cam.
"""
from __future__ import annotations

import math
import re
import tempfile
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from ..design.mechanisms import ConstantDiameterCam, ConstantWidthCam
from ..errors import Problem, SpecError
from ..geom2d import ArcChain
from ..records import dataclass
from .export import plate_of
from .step import cadquery as _cq
from .step import plate_solid
from .stepheader import StepMeta, design_meta, header_dumps

__all__ = ["Dimensions", "FollowerPose", "dimensions", "follower_poses", "build", "dumps", "PART_COLOURS"]

#: RGB of each kind of part (the name without its ``_1``/``_2`` suffix)
PART_COLOURS = {"cam": (0.70, 0.72, 0.75), "shaft": (0.35, 0.35, 0.38), "roller": (0.85, 0.45, 0.10),
                "pin": (0.90, 0.80, 0.20), "stem": (0.20, 0.40, 0.80), "arm": (0.20, 0.40, 0.80),
                "face": (0.20, 0.65, 0.35), "knife": (0.20, 0.65, 0.35), "pivot": (0.90, 0.80, 0.20),
                "frame": (0.45, 0.45, 0.45), "slide": (0.45, 0.45, 0.45)}

#: samples per cycle for the follower's extents (face lengths, stroke)
_SAMPLES = 1441


@dataclass(frozen=True)
class Dimensions:
    """Follower dimensions of the assembly (mm): ``[assembly]`` values or the defaults derived from the design."""

    roller_width: float
    pin_diameter: float
    stem_diameter: float
    arm_width: float
    arm_thickness: float
    face_thickness: float
    pivot_diameter: float
    clearance: float


def dimensions(spec, geometry) -> Dimensions:
    """``[assembly]`` over the defaults derived from the design (``docs/decisions.md``, "Assembly STEP").

    Raises
    ------
    SpecError
        A pin that does not fit in the roller, or an arm narrower than the pin or pivot it carries.
    """
    a = spec.assembly
    t = spec.manufacturing.thickness_mm
    c0 = geometry.profiles[0]
    rr = c0.roller_radius
    size = max(float(geometry.max_radius), 1.0) if geometry.closed else max(4 * rr, 4 * t)
    roller = rr > 0 and not c0.has_face
    rb = spec.follower.base_radius_mm or size / 2
    d_default = 1.6 * rr if roller else 0.3 * rb
    got = {k: getattr(a, f"{k}_mm") for k in ("roller_width", "pin_diameter", "stem_diameter", "arm_width",
                                              "arm_thickness", "face_thickness", "pivot_diameter", "clearance")}
    d = Dimensions(
        roller_width=got["roller_width"] or t,
        pin_diameter=got["pin_diameter"] or (0.8 * rr if rr > 0 else 0.1 * size),
        stem_diameter=got["stem_diameter"] or d_default,
        arm_width=got["arm_width"] or max(d_default, 0.1 * size),
        arm_thickness=got["arm_thickness"] or 0.6 * t,
        face_thickness=got["face_thickness"] or 0.4 * t,
        pivot_diameter=got["pivot_diameter"] or 0.1 * size,
        clearance=got["clearance"] or max(0.5, 0.1 * t),
    )
    problems = []
    if roller and d.pin_diameter >= 2 * rr:
        problems.append(Problem("assembly.pin_diameter_mm", d.pin_diameter,
                                f"the pin must be thinner than the roller (diameter {2 * rr:g} mm)",
                                f"give pin_diameter_mm < {2 * rr:g}"))
    oscillating = any(getattr(c, "oscillating", False) for c in geometry.profiles)
    if oscillating and d.arm_width <= max(d.pivot_diameter, d.pin_diameter if roller else 0.0):
        problems.append(Problem("assembly.arm_width_mm", d.arm_width,
                                "the arm must be wider than the pivot and the pin it carries",
                                f"give arm_width_mm > {max(d.pivot_diameter, d.pin_diameter):g}"))
    if problems:
        raise SpecError(problems, spec.source)
    return d


# ---------------------------------------------------------------------------
# where the followers are (pure numpy, from the exact geometry)
@dataclass(frozen=True)
class FollowerPose:
    """One follower at the chosen angle, in its local frame (a, b) placed at ``origin`` with b along ``up``.

    kind: ``"roller"`` (a circle of ``radius`` about ``centre``; a knife edge has radius 0), ``"curved"`` (a
    curved face: the arc of ``radius`` about ``centre`` between the contact angles ``span`` (radians, measured
    from −b)), ``"flat"`` (a face on the line b = ``face_b`` over a = ``span``).  ``travel``: the range of the
    local origin along b over the cycle relative to now (translating followers), for the guide.
    ``oscillating``: origin = the pivot.  ``layer``: index of the cam plate it runs on.
    """

    kind: str
    oscillating: bool
    origin: tuple[float, float]
    up: tuple[float, float]
    centre: tuple[float, float]
    radius: float
    face_b: float
    span: tuple[float, float]
    travel: tuple[float, float]
    layer: int


def _rot(v: np.ndarray, ang: np.ndarray) -> np.ndarray:
    c, s = np.cos(ang), np.sin(ang)
    return np.stack([c * v[:, 0] - s * v[:, 1], s * v[:, 0] + c * v[:, 1]], axis=1)


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def _slots(geometry) -> list[tuple[Any, float, int, int]]:
    """(contact, parameter shift, flip (−1: the follower turned by π), cam layer) of every follower."""
    mech = getattr(geometry, "mechanism", None)
    if isinstance(mech, (ConstantWidthCam, ConstantDiameterCam)):  # one cam, two followers π apart
        return [(geometry.profiles[0], 0.0, 1, 0), (geometry.profiles[0], math.pi, -1, 0)]
    return [(c, 0.0, 1, i) for i, c in enumerate(geometry.profiles)]


def follower_poses(geometry, x: float) -> tuple[list[FollowerPose], float]:
    """Every follower placed at the cam parameter ``x`` (radians; mm of travel for a translating cam), and the
    cam's placement: the angle (degrees) to turn the cam about Z, or the X shift (mm) of a sliding plate."""
    sigma = geometry.profiles[0].sense
    period = geometry.period
    grid = np.concatenate([[x], np.linspace(0.0, period, _SAMPLES)])
    poses = []
    cam_move = 0.0
    for contact, shift, flip, layer in _slots(geometry):
        s = contact.evaluate((grid + shift) % period if geometry.closed else grid)
        if geometry.closed:
            ang = -sigma * grid
            point, normal = _rot(s.point, ang), _rot(s.normal, ang)
            pitch = _rot(s.pitch, ang) if s.pitch is not None else None
            cam_move = math.degrees(-sigma * x)
        else:  # a sliding plate: the follower's axis is the Y axis
            dx = np.stack([s.pitch[:, 0], np.zeros(len(grid))], axis=1)
            point, normal, pitch = s.point - dx, s.normal, s.pitch - dx
            cam_move = -float(s.pitch[0, 0])
        poses.append(_pose(contact, point, normal, pitch, flip, layer))
    return poses, cam_move


def _pose(contact, point, normal, pitch, flip: int, layer: int) -> FollowerPose:
    oscillating = bool(getattr(contact, "oscillating", False))
    kind = "flat" if pitch is None else "curved" if contact.curved_face else "roller"
    if oscillating:
        pivot = np.array(contact.pivot, float) * flip
        up = normal if kind == "flat" else _unit(pitch - pivot)
        origin = np.broadcast_to(pivot, point.shape)
    elif kind == "flat":
        up = np.broadcast_to(normal[0], point.shape)
        axis = np.array([getattr(contact, "face_offset", 0.0) * flip, 0.0])
        origin = axis + ((point - axis) @ up[0])[:, None] * up[0]
    else:
        up = np.broadcast_to(np.array([0.0, math.copysign(1.0, pitch[0, 1])]), point.shape)
        origin = pitch
    v = np.stack([up[:, 1], -up[:, 0]], axis=1)

    def local(p):
        d = p - origin
        return np.stack([np.einsum("ij,ij->i", d, v), np.einsum("ij,ij->i", d, up)], axis=1)

    pl = local(point)
    travel = ((origin[1:] - origin[0]) @ up[0]) if not oscillating else np.zeros(1)
    if kind == "flat":
        centre, radius, face_b = (0.0, 0.0), 0.0, float(pl[0, 1])
        span = (float(pl[1:, 0].min()), float(pl[1:, 0].max()))
    else:
        cl = local(pitch)
        centre, radius, face_b = (float(cl[0, 0]), float(cl[0, 1])), float(contact.roller_radius), 0.0
        d = pl - cl
        if radius == 0:  # a knife edge: the direction towards the cam is −n
            d = -np.stack([np.einsum("ij,ij->i", normal, v), np.einsum("ij,ij->i", normal, up)], axis=1)
        gam = np.arctan2(d[1:, 0], -d[1:, 1])  # contact direction from the centre, from −b
        span = (float(gam.min()), float(gam.max()))
    return FollowerPose(kind, oscillating, (float(origin[0, 0]), float(origin[0, 1])),
                        (float(up[0, 0]), float(up[0, 1])), centre, radius, face_b, span,
                        (float(travel.min()), float(travel.max())), layer)


# ---------------------------------------------------------------------------
# solids
def _cyl(cq, a: float, b: float, r: float, z0: float, z1: float):
    return cq.Workplane("XY", origin=(0, 0, z0)).center(a, b).circle(r).extrude(z1 - z0)


def _box(cq, a0: float, a1: float, b0: float, b1: float, z0: float, z1: float):
    return (cq.Workplane("XY", origin=(0, 0, z0)).center((a0 + a1) / 2, (b0 + b1) / 2)
            .rect(abs(a1 - a0), abs(b1 - b0)).extrude(z1 - z0))


def _bar(cq, p0, p1, w: float, z0: float, z1: float):
    """A flat bar of width w with round ends from p0 to p1 (local a, b)."""
    (a0, b0), (a1, b1) = p0, p1
    length = math.hypot(a1 - a0, b1 - b0)
    ends = _cyl(cq, a0, b0, w / 2, z0, z1).union(_cyl(cq, a1, b1, w / 2, z0, z1))
    if length < 1e-9:
        return ends
    ang = math.degrees(math.atan2(b1 - b0, a1 - a0))
    body = (cq.Workplane("XY", origin=(0, 0, z0)).center((a0 + a1) / 2, (b0 + b1) / 2)
            .transformed(rotate=(0, 0, ang)).rect(length, w).extrude(z1 - z0))
    return ends.union(body)


@dataclass
class _Parts:
    """Named solids (cadquery Workplanes) with their placement (translation, rotation about Z in degrees)."""

    items: list[tuple[str, Any, tuple[float, float, float], float]]

    def add(self, name: str, wp, at=(0.0, 0.0, 0.0), rot: float = 0.0) -> None:
        self.items.append((name, wp, at, rot))


def _follower(cq, parts: _Parts, p: FollowerPose, d: Dimensions, z0: float, t: float, sfx: str) -> None:
    """The follower's parts (and its frame) in the local frame, placed at the pose."""
    at = (p.origin[0], p.origin[1], 0.0)
    rot = math.degrees(math.atan2(-p.up[0], p.up[1]))
    zc = z0 + t / 2
    w = d.roller_width if p.kind == "roller" else t
    zin = max(w, t) / 2 + d.clearance           # the inner face of the layers beside the plate (from zc)
    lo_z, hi_z = zc - zin - d.arm_thickness, zc + zin + d.arm_thickness
    ca, cb = p.centre
    margin = 0.1 * max(d.stem_diameter, 1.0)
    if p.kind == "roller":
        rr = max(p.radius, 1e-3)
        if p.radius > 0:
            roller = _cyl(cq, ca, cb, rr, zc - w / 2, zc + w / 2).cut(_cyl(cq, ca, cb, d.pin_diameter / 2,
                                                                          zc - w, zc + w))
            parts.add(f"roller{sfx}", roller, at, rot)
            pin_z = (lo_z, zc + w / 2) if p.oscillating else (lo_z, hi_z)
            parts.add(f"pin{sfx}", _cyl(cq, ca, cb, d.pin_diameter / 2, *pin_z), at, rot)
        head_b = cb + rr + d.clearance                  # the follower body starts above the roller
        contact_parts: tuple[Any, ...] = ()
        if p.radius == 0:  # a knife edge: a wedge of half-angle 15° from its edge at the pitch point, pointing
            # along the middle of the contact normals (straight down the stem of a translating knife)
            mid = (p.span[0] + p.span[1]) / 2 if p.oscillating else 0.0
            axis = np.array([math.sin(mid), -math.cos(mid)])
            height = max(d.stem_diameter, 1.0)
            back = np.array([ca, cb]) - axis * height
            side = np.array([-axis[1], axis[0]]) * height * math.tan(math.radians(15.0))
            kz0 = zc - zin if p.oscillating else zc - w / 2  # an arm's knife reaches down to the arm's layer
            knife = (cq.Workplane("XY", origin=(0, 0, kz0))
                     .polyline([(ca, cb), tuple(back + side), tuple(back - side)]).close().extrude(zc + w / 2 - kz0))
            parts.add(f"knife{sfx}", knife, at, rot)
            head_b = cb + height
            contact_parts = (tuple(back),)
    elif p.kind == "curved":
        g0, g1 = p.span
        # a translating face is cut square to its stem (the stem stands on a flat chord); an arm's face
        # about the middle of its contacts
        mid = (g0 + g1) / 2 if p.oscillating else 0.0
        half = max(abs(g0 - mid), abs(g1 - mid)) + 0.05
        axis = np.array([math.sin(mid), -math.cos(mid)])  # from the centre towards the contacts
        depth = p.radius * (1 - math.cos(min(half, math.pi / 2))) + d.face_thickness
        fz0 = zc - zin if p.oscillating else zc - t / 2  # an arm's face reaches down to the arm's layer
        disk = _cyl(cq, ca, cb, p.radius, fz0, zc + t / 2)
        keep_c = np.array([ca, cb]) + axis * (p.radius - depth / 2)
        ang = math.degrees(math.atan2(axis[1], axis[0]))
        cap = (cq.Workplane("XY", origin=(0, 0, fz0)).center(*keep_c).transformed(rotate=(0, 0, ang))
               .rect(depth, 4 * p.radius).extrude(zc + t / 2 - fz0))
        parts.add(f"face{sfx}", disk.intersect(cap), at, rot)
        head_b = cb - p.radius + depth if not p.oscillating else cb
        contact_parts = (keep_c,)
    else:  # flat
        a0, a1 = min(p.span[0], 0.0) - margin, max(p.span[1], 0.0) + margin
        if not p.oscillating:
            a0, a1 = min(a0, -d.stem_diameter / 2), max(a1, d.stem_diameter / 2)
        fz0 = zc - zin if p.oscillating else zc - t / 2
        parts.add(f"face{sfx}", _box(cq, a0, a1, p.face_b, p.face_b + d.face_thickness, fz0, zc + t / 2),
                  at, rot)
        head_b = p.face_b + d.face_thickness
        contact_parts = ((a0, a1),)
    if p.oscillating:
        _arm(cq, parts, p, d, at, rot, zc, zin, sfx, contact_parts)
    else:
        _stem(cq, parts, p, d, at, rot, zc, zin, lo_z, hi_z, head_b, sfx)


def _stem(cq, parts, p: FollowerPose, d: Dimensions, at, rot, zc, zin, lo_z, hi_z, head_b, sfx) -> None:
    """A translating follower: (a fork round the roller,) a yoke and the stem, and the guide block (frame)."""
    ds = d.stem_diameter
    yoke = max(ds, 1.0) * 0.5
    if p.kind == "roller" and p.radius > 0:
        hw = max(d.pin_diameter, 0.6 * ds)
        cheek = [_box(cq, -hw, hw, p.centre[1] - hw, head_b + yoke, lo_z, zc - zin),
                 _box(cq, -hw, hw, p.centre[1] - hw, head_b + yoke, zc + zin, hi_z)]
        fork = _box(cq, -hw, hw, head_b, head_b + yoke, lo_z, hi_z).union(cheek[0]).union(cheek[1])
        fork = fork.cut(_cyl(cq, *p.centre, d.pin_diameter / 2, lo_z - 1, hi_z + 1))
        base = head_b + yoke
    else:
        fork = None
        base = head_b
    guide_len = max(2 * ds, 5.0)
    g0 = base + (p.travel[1] + d.clearance + 0.5 * ds)          # guide bottom above the highest stem base
    length = (g0 - base) - p.travel[0] + guide_len + ds  # the stem stays in the guide at its lowest
    rod = (cq.Workplane("XZ", origin=(0, base, zc)).circle(ds / 2).extrude(-length))
    body = rod if fork is None else fork.union(rod)
    parts.add(f"stem{sfx}", body, at, rot)
    gz = max(ds, 2 * (hi_z - zc) if p.kind == "roller" else ds) * 1.5
    guide = _box(cq, -1.5 * ds, 1.5 * ds, g0, g0 + guide_len, zc - gz / 2, zc + gz / 2)
    guide = guide.cut(cq.Workplane("XZ", origin=(0, g0 - 1.0, zc)).circle(ds / 2).extrude(-(guide_len + 2.0)))
    parts.add(f"frame{sfx}", guide, at, rot)


def _arm(cq, parts, p: FollowerPose, d: Dimensions, at, rot, zc, zin, sfx, contact_parts) -> None:
    """An oscillating follower: the arm in the layer below the plate from the pivot to the roller pin or the
    face, the pivot pin and the bracket (frame) below the arm."""
    z1 = zc - zin
    z0 = z1 - d.arm_thickness
    if p.kind == "roller" and p.radius == 0:  # a knife on the arm: the arm reaches its back
        arm = _bar(cq, (0.0, 0.0), tuple(contact_parts[0]), d.arm_width, z0, z1)
    elif p.kind == "roller":
        arm = _bar(cq, (0.0, 0.0), p.centre, d.arm_width, z0, z1)
        arm = arm.cut(_cyl(cq, *p.centre, d.pin_diameter / 2, z0 - 1, z1 + 1))
    elif p.kind == "curved":
        arm = _bar(cq, (0.0, 0.0), tuple(contact_parts[0]), d.arm_width, z0, z1)
    else:
        a0, a1 = contact_parts[0]
        arm = _bar(cq, (0.0, 0.0), (0.0, p.face_b + d.face_thickness / 2), d.arm_width, z0, z1)
        arm = arm.union(_box(cq, a0, a1, p.face_b, p.face_b + d.face_thickness, z0, z1))
    arm = arm.cut(_cyl(cq, 0.0, 0.0, d.pivot_diameter / 2, z0 - 1, z1 + 1))
    parts.add(f"arm{sfx}", arm, at, rot)
    zb1 = z0 - d.clearance
    zb0 = zb1 - max(d.arm_thickness, d.pivot_diameter)
    parts.add(f"pivot{sfx}", _cyl(cq, 0.0, 0.0, d.pivot_diameter / 2, zb0, z1), at, rot)
    s = 1.5 * max(d.pivot_diameter, d.arm_width)
    bracket = _box(cq, -s, s, -s, s, zb0, zb1).cut(_cyl(cq, 0.0, 0.0, d.pivot_diameter / 2, zb0 - 1, zb1 + 1))
    parts.add(f"frame{sfx}", bracket, at, rot)


def build(spec, geometry, outlines: Sequence[ArcChain], x: float, *, dims: Dimensions | None = None) -> _Parts:
    """Every part of the mechanism at the cam parameter ``x`` (radians, or mm for a translating cam)."""
    cq = _cq()
    d = dims or dimensions(spec, geometry)
    plate = plate_of(spec)
    t = plate.thickness_mm
    hub = plate.hub_length_mm or 0.0
    poses, cam_move = follower_poses(geometry, x)
    layer_gap = 2 * (d.clearance + d.arm_thickness) + 2 * d.clearance + max(d.pivot_diameter, d.arm_thickness)
    pitch = t + hub + layer_gap
    parts = _Parts([])
    if getattr(geometry.mechanism, "cam_kind", None) == "groove":
        return _groove_parts(cq, parts, geometry, outlines, x, cam_move, plate, d, poses[0])
    two = len(outlines) > 1
    for i, outline in enumerate(outlines):
        at = (cam_move, 0.0, i * pitch) if not geometry.closed else (0.0, 0.0, i * pitch)
        parts.add(f"cam_{i + 1}" if two else "cam", plate_solid(outline, plate), at,
                  cam_move if geometry.closed else 0.0)
    if geometry.closed and plate.bore_mm > 0:
        top = (len(outlines) - 1) * pitch + t + hub
        below = layer_gap + t
        parts.add("shaft", _cyl(cq, 0.0, 0.0, plate.bore_mm / 2, -below, top + below))
    if not geometry.closed:
        length = geometry.period
        parts.add("slide", _box(cq, -1.5 * length, 1.5 * length, -0.2 * length / 3 - t, 0.0, -d.clearance,
                                t + d.clearance))
    for k, p in enumerate(poses):
        sfx = f"_{k + 1}" if len(poses) > 1 else ""
        _follower(cq, parts, p, d, p.layer * pitch, t, sfx)
    return parts


def _groove_parts(cq, parts: _Parts, geometry, outlines: Sequence[ArcChain], x: float, cam_move: float, plate,
                  d: Dimensions, pose: FollowerPose) -> _Parts:
    """A groove cam's assembly: the grooved plate turned to ``x``, the shaft, and the roller (radius R_r) centred on
    the pitch curve in the groove, standing ``clearance`` out of the front face (z = 0) and clear of the floor by
    as much; in front of the plate (2·``clearance`` off its face) the follower: the roller's pin and the stem
    along the follower's axis past the plate, or the arm from its pivot."""
    from .groove import plate_radius
    from .plate import circle_loop
    from .step import groove_solid

    mech = geometry.mechanism
    depth = mech.groove_depth_mm
    parts.add("cam", groove_solid(circle_loop(plate_radius(geometry)), outlines[0], outlines[1], plate, depth),
              (0.0, 0.0, 0.0), cam_move)
    if plate.bore_mm > 0:
        t = plate.thickness_mm + (plate.hub_length_mm or 0.0)
        parts.add("shaft", _cyl(cq, 0.0, 0.0, plate.bore_mm / 2, -t, 2 * t))
    c = geometry.profiles[0].evaluate_fixed(np.array([x])).pitch[0]
    parts.add("roller", _cyl(cq, float(c[0]), float(c[1]), mech.roller_radius_mm, -d.clearance, depth - d.clearance))
    _groove_follower(cq, parts, pose, d, plate_radius(geometry))
    return parts


def _groove_follower(cq, parts: _Parts, p: FollowerPose, d: Dimensions, plate_r: float) -> None:
    """The groove cam's follower in front of the plate (:func:`_groove_parts`), in the pose's local frame."""
    at = (p.origin[0], p.origin[1], 0.0)
    rot = math.degrees(math.atan2(-p.up[0], p.up[1]))
    z1 = -2 * d.clearance
    z0 = z1 - d.arm_thickness
    parts.add("pin", _cyl(cq, *p.centre, d.pin_diameter / 2, z0, -d.clearance), at, rot)
    if p.oscillating:
        parts.add("arm", _bar(cq, (0.0, 0.0), p.centre, d.arm_width, z0, z1), at, rot)
        parts.add("pivot", _cyl(cq, 0.0, 0.0, d.pivot_diameter / 2, z0 - d.arm_thickness, z1), at, rot)
    else:  # the stem from the roller's pin out along the follower's axis, past the plate's rim
        reach = plate_r + math.hypot(*p.origin) + d.stem_diameter
        parts.add("stem", _bar(cq, p.centre, (p.centre[0], p.centre[1] + reach), d.stem_diameter, z0, z1), at, rot)


def to_assembly(parts: _Parts, name: str = "mechanism"):
    """The cadquery ``Assembly`` of the parts, each named and coloured."""
    cq = _cq()
    assy = cq.Assembly(name=name)
    for pname, wp, at, rot in parts.items:
        rgb = PART_COLOURS[pname.split("_")[0]]
        loc = cq.Location(cq.Vector(*at), cq.Vector(0, 0, 1), rot)
        assy.add(wp, name=pname, color=cq.Color(*rgb), loc=loc)
    return assy


def dumps(spec, geometry, outlines: Sequence[ArcChain], x: float, *, meta: StepMeta | None = None,
          dims: Dimensions | None = None) -> str:
    """The assembly STEP (AP214) text at the cam parameter ``x``, reproducible; header ``meta`` (default: the
    design's, :func:`.stepheader.design_meta`)."""
    from .step import canonical_reals

    assy = to_assembly(build(spec, geometry, outlines, x, dims=dims))
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "assembly.step"  # never a path built from the name
        assy.export(str(path), "STEP")
        text = path.read_text(encoding="utf-8", errors="replace")
    text = header_dumps(text, spec.name, meta or design_meta(spec))
    return canonical_reals(canonical_order(text))


_ENTITY = re.compile(r"^#(\d+) = (.*?);$", re.S | re.M)
_REF = re.compile(r"#(\d+)")


def canonical_order(text: str) -> str:
    """The assembly STEP made byte-identical from run to run: OpenCascade numbers the usage occurrences from
    a counter of the process, and writes the colour groups (each one MECHANICAL_DESIGN_GEOMETRIC_PRESENTATION_
    REPRESENTATION with its styled item … COLOUR_RGB, referring to the shapes before them and sharing the colours)
    in an order that depends on memory addresses.  The occurrences are numbered 1, 2 … in file order; the
    presentation entities are renumbered from the groups sorted by their content (each entity spelled out with
    what it uses), in pre-order, so a shared colour takes its number at its first use.  Any other layout is left
    as it is."""
    from .step import canonical_occurrences

    text = canonical_occurrences(text)
    head, sep, data = text.partition("DATA;")
    body, end, tail = data.partition("ENDSEC;")
    ents = [(int(m.group(1)), m.group(2)) for m in _ENTITY.finditer(body)]
    first = next((i for i, (_, t) in enumerate(ents) if t.startswith("MECHANICAL_DESIGN_GEOMETRIC_PRESENTATION")),
                 None)
    if first is None:
        return text
    tail_ents = dict(ents[first:])
    if any(int(r) in tail_ents for _, t in ents[:first] for r in _REF.findall(t)):
        return text  # the shapes refer to the presentation: not the layout described above, leave it
    sig: dict[int, str] = {}

    def signature(n: int) -> str:  # the entity's text with every presentation entity it uses spelled out
        if n not in sig:
            sig[n] = ""  # a cycle (none in OpenCascade's output) stops here
            sig[n] = _REF.sub(lambda m: f"<{signature(int(m.group(1)))}>" if int(m.group(1)) in tail_ents
                              else m.group(0), tail_ents[n])
        return sig[n]

    used = {int(r) for t in tail_ents.values() for r in _REF.findall(t)}
    roots = sorted((n for n in tail_ents if n not in used), key=signature)
    renum: dict[int, int] = {}
    nxt = ents[first][0]

    def visit(n: int) -> None:  # numbered in pre-order from the sorted roots: shared colours at first use
        nonlocal nxt
        if n in renum:
            return
        renum[n] = nxt
        nxt += 1
        for r in _REF.findall(tail_ents[n]):
            if int(r) in tail_ents:
                visit(int(r))

    for n in roots:
        visit(n)
    for n in sorted((n for n in tail_ents if n not in renum), key=signature):
        visit(n)
    lines = [f"#{n} = {t};" for n, t in ents[:first]]
    for n in sorted(tail_ents, key=renum.__getitem__):
        lines.append(f"#{renum[n]} = " + _REF.sub(lambda m: f"#{renum.get(int(m.group(1)), int(m.group(1)))}",
                                                  tail_ents[n]) + ";")
    return head + sep + "\n" + "\n".join(lines) + "\n" + end + tail
