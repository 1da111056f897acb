"""Precomputed frames of the mechanism animation embedded in the HTML report.

The browser does no kinematics: for ``frames`` cam angles (default 360, one per
degree; a translating cam: evenly over its length) Python evaluates the exact
geometry and stores, in the *fixed* frame (cam centre at the origin, follower
above), every follower's primitives — roller circle, face segment, curved face
(an arc about its centre of curvature), stem or arm line, contact point and line
of action — plus the cam outline in the *cam*
frame.  The script of ``templates/report/animation.js`` rotates the outline by
−σφ (σ = +1 clockwise, as :mod:`camfab.design.profile` maps a fixed point q to
``R(σφ)·q`` in the cam frame) or slides it (translating cam), and draws the
follower of the same frame.  Lengths are rounded to 1 µm (angles to 1e-8 rad) to keep
the page small and the output deterministic.

Constant-width and constant-diameter cams have one profile touched by two
followers: follower 2 is the contact at φ + π, turned by the actual cam angle φ.
"""
from __future__ import annotations

import math
from typing import Any

import numpy as np

from ._common import axis_of, sample_grid

__all__ = ["animation_data"]

_ROUND = 3


def _r(a, digits: int = _ROUND) -> list:
    """Rounded plain list (JSON-ready); -0.0 normalised to 0.0."""
    return (np.round(np.asarray(a, dtype=float), digits) + 0.0).tolist()


def _rotate(p: np.ndarray, ang: np.ndarray) -> np.ndarray:
    c, s = np.cos(ang), np.sin(ang)
    return np.stack([p[:, 0] * c - p[:, 1] * s, p[:, 0] * s + p[:, 1] * c], axis=1)


def animation_data(spec, geometry, report, *, frames: int = 360, outline_points: int = 720) -> dict[str, Any]:
    """Everything the report's canvas animation draws, as a JSON-ready dict.

    Parameters
    ----------
    spec : DesignSpec
    geometry : CamGeometry
    report : Report
        For the pressure-angle limit and R max.
    frames : int
        Number of frames over one cycle.
    outline_points : int
        Even samples of each cam outline (breakpoints are added).

    Returns
    -------
    dict
        ``closed``, ``sense``, ``unit``, ``period``, ``lift_unit``, ``outline`` (flat x, y lists
        per profile, cam frame), ``circles`` (cam-frame circles: base, bore), ``pivot``,
        ``guides``, ``frames`` (``x`` in user units, ``S``, ``pa`` per follower in degrees,
        ``shift`` for a translating cam), ``followers`` (per-frame primitives), ``bounds``,
        ``pa_limit``, ``name``.
    """
    prog = spec.program()
    axis = axis_of(prog)
    period = float(geometry.period)
    x = np.arange(frames) * (period / frames)
    sense = geometry.profiles[0].sense
    closed = geometry.closed
    rot = -sense * x if closed else np.zeros_like(x)

    outline = []
    for c in geometry.profiles:
        xs = sample_grid(c.period, c.breakpoints, outline_points + 1)
        outline.append(_r(c.evaluate(xs).point.ravel()))

    pairs = [(k, 0.0) for k in range(len(geometry.profiles))]
    if spec.cam.kind in ("constant_width", "constant_diameter") and len(geometry.profiles) == 1:
        pairs.append((0, math.pi))
    if closed:
        rmax = report.max_radius_mm or float(np.max(np.hypot(*geometry.evaluate(x).point.T)))
    else:  # a translating cam: its height sets the scale
        rmax = float(np.max(geometry.evaluate(x).point[:, 1])) + geometry.profiles[0].roller_radius
    stem = 0.9 * rmax

    shift = np.zeros_like(x)
    samples = []
    for k, phase in pairs:
        c = geometry.profiles[k]
        s = c.evaluate(x + phase)
        samples.append((c, s))
    if not closed:  # the cam slides so that roller 1 stays on the axis x = 0
        shift = -samples[0][1].pitch[:, 0]

    followers, pas, points = [], [], []
    for c, s in samples:
        f = _follower(c, s, rot, shift, stem, closed)
        followers.append(f)
        pas.append(_r(np.degrees(s.pressure_angle)) if s.pressure_angle is not None else None)
        points.append(f.pop("_pts"))
    if closed:
        pts = np.concatenate(points + [np.array([[rmax, rmax], [-rmax, -rmax]])])
    else:  # a window on the sliding cam, centred on the roller
        half = 0.5 * min(period, 5.0 * rmax)
        ys = np.concatenate(points)[:, 1]
        pts = np.array([[-half, -0.2 * rmax], [half, ys.max()]])
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    pad = 0.06 * float(np.max(hi - lo))
    f0 = spec.follower
    circles = []
    if closed:
        if f0.base_radius_mm:
            circles.append({"r": f0.base_radius_mm, "kind": "base"})
        if spec.manufacturing.bore_mm:
            circles.append({"r": spec.manufacturing.bore_mm / 2, "kind": "bore"})
    pivot = None
    c0 = geometry.profiles[0]
    if c0.oscillating:
        pivot = [float(c0.m), 0.0]
    pa_lim = report.pressure_angle.limit if report.pressure_angle is not None else None
    return {
        "name": spec.name, "closed": closed, "sense": int(sense), "unit": axis.unit,
        "period": axis.user_period, "lift_unit": f0.lift_unit,
        "outline": outline, "circles": circles, "pivot": pivot,
        "guides": [g for f in followers for g in f.pop("guides")],
        "frames": {"x": _r(x * axis.scale), "angle": _r(rot, 8), "shift": _r(shift), "S": _r(prog.evaluate(x)[0]),
                   "pa": pas},
        "followers": followers,
        "bounds": _r([lo[0] - pad, hi[0] + pad, lo[1] - pad, hi[1] + pad]),
        "pa_limit": pa_lim, "rmax": round(float(rmax), _ROUND),
        # a face-groove cam: the groove's half width (the script draws the groove between the flanks in the plate)
        "groove": round(float(geometry.profiles[0].roller_radius), _ROUND) if spec.cam.kind == "groove" else None,
    }


def _curved_face(out: dict[str, Any], pts: list, centre: np.ndarray, normal: np.ndarray, r: float,
                 pivot: np.ndarray | None, stem: float) -> np.ndarray:
    """A curved face: the arc of radius ``r`` about its centre of curvature that the contact runs over (plus
    a margin; from the vertex on for a finger), on a stem rising from the vertex (mushroom) or on the arm
    from the pivot to the vertex (finger).  Fills ``out["centre"]`` and ``out["arc"]`` (per frame the arc's
    start and end angles, radians, counter-clockwise in the fixed frame) and returns the link."""
    if pivot is None:  # the vertex is the face's lowest point, on the stem axis
        up = float(np.sign(np.median(centre[:, 1])) or 1.0)
        vertex_dir = np.broadcast_to(np.array([0.0, -up]), centre.shape)
    else:  # the vertex lies on the line from the pivot to the centre of curvature
        arm = centre - pivot
        vertex_dir = -arm / np.hypot(arm[:, 0], arm[:, 1])[:, None]
    # ψ: the angle at the centre from the vertex to the contact (at −n), counter-clockwise
    psi = np.arctan2(vertex_dir[:, 0] * -normal[:, 1] + vertex_dir[:, 1] * normal[:, 0],
                     -(vertex_dir[:, 0] * normal[:, 0] + vertex_dir[:, 1] * normal[:, 1]))
    lo, hi = float(psi.min()), float(psi.max())
    lo, hi = (min(lo, 0.0), max(hi, 0.0)) if pivot is not None else (-max(-lo, hi), max(-lo, hi))
    pad = 0.08 * (hi - lo) + 0.05 * stem / r
    lo, hi = max(lo - pad, -0.9 * math.pi), min(hi + pad, 0.9 * math.pi)
    base = np.arctan2(vertex_dir[:, 1], vertex_dir[:, 0])
    out["centre"] = _r(centre.ravel())
    out["arc"] = _r(np.stack([base + lo, base + hi], axis=1).ravel(), 8)
    for t in np.linspace(0.0, 1.0, 9):  # the arc's extent, for the view
        a = base + lo + t * (hi - lo)
        pts.append(centre + r * np.stack([np.cos(a), np.sin(a)], axis=1))
    vertex = centre + r * vertex_dir
    if pivot is not None:
        return np.concatenate([np.broadcast_to(pivot, vertex.shape), vertex], axis=1)
    up = -vertex_dir[0, 1]
    xg = float(np.median(vertex[:, 0]))
    y0 = float(np.max(np.abs(vertex[:, 1]))) + 0.25 * stem
    out["guides"] = [[xg + sx * 0.06 * stem, up * y0, xg + sx * 0.06 * stem, up * (y0 + 0.45 * stem)]
                     for sx in (-1, 1)]
    return np.concatenate([vertex, vertex + np.array([0.0, up * stem])], axis=1)


def _follower(c, s, rot: np.ndarray, shift: np.ndarray, stem: float, closed: bool) -> dict[str, Any]:
    """Fixed-frame primitives of one follower over all frames."""
    def fixed(p):
        q = _rotate(p, rot)
        q[:, 0] += shift
        return q

    contact = fixed(s.point)
    normal = _rotate(s.normal, rot)
    tangent = np.stack([-normal[:, 1], normal[:, 0]], axis=1)
    oscillating = c.oscillating
    pivot = np.array([float(getattr(c, "m", 0.0)), 0.0])
    out: dict[str, Any] = {"kind": c.kind, "r": float(c.roller_radius), "guides": []}
    pts = [contact]
    if c.curved_face:
        link = _curved_face(out, pts, fixed(s.pitch), normal, c.roller_radius, pivot if oscillating else None, stem)
    elif c.kind == "roller":
        centre = fixed(s.pitch)
        out["centre"] = _r(centre.ravel())
        pts.append(centre + c.roller_radius)
        pts.append(centre - c.roller_radius)
        if oscillating:
            link = np.concatenate([np.broadcast_to(pivot, centre.shape), centre], axis=1)
        else:
            up = np.sign(np.median(centre[:, 1])) or 1.0
            end = centre + np.array([0.0, up * stem])
            link = np.concatenate([centre, end], axis=1)
            xg = float(np.median(centre[:, 0]))
            y0 = float(np.max(np.abs(centre[:, 1]))) + 0.25 * stem
            w = max(c.roller_radius, 0.04 * stem)
            out["guides"] = [[xg + sx * w, up * y0, xg + sx * w, up * (y0 + 0.45 * stem)] for sx in (-1, 1)]
    else:
        if oscillating:
            foot = pivot + ((contact - pivot) * normal).sum(axis=1)[:, None] * normal
            link = np.concatenate([np.broadcast_to(pivot, foot.shape), foot], axis=1)
        else:
            xa = float(getattr(c, "face_offset", 0.0))
            with np.errstate(divide="ignore", invalid="ignore"):
                t = (xa - contact[:, 0]) / tangent[:, 0]
            foot = contact + np.nan_to_num(t)[:, None] * tangent
            link = np.concatenate([foot, foot + normal * stem], axis=1)
            up = float(np.sign(np.median(normal[:, 1])) or 1.0)
            y0 = float(np.max(np.abs(foot[:, 1]))) + 0.35 * stem
            out["guides"] = [[xa + sx * 0.06 * stem, up * y0, xa + sx * 0.06 * stem, up * (y0 + 0.45 * stem)]
                             for sx in (-1, 1)]
        along = ((contact - foot) * tangent).sum(axis=1)
        smin, smax = float(along.min()), float(along.max())
        if oscillating:
            smin = min(smin, 0.0)
        pad = 0.08 * (smax - smin) + 0.05 * stem
        a = foot + (smin - pad) * tangent
        b = foot + (smax + pad) * tangent
        out["face"] = _r(np.concatenate([a, b], axis=1).ravel())
        pts += [a, b]
    out["link"] = _r(link.ravel())
    pts += [link[:, :2], link[:, 2:]]
    out["contact"] = _r(contact.ravel())
    out["normal"] = _r(normal.ravel())
    if oscillating:
        out["guides"] = []
    pts += [np.array(g).reshape(2, 2) for g in out["guides"]]
    out["_pts"] = np.concatenate(pts)
    return out
