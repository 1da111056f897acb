"""The closed plate outline of a translating (wedge) cam, and its exact offsets.

A translating cam is a plate whose top edge is the cam profile (an open curve
over one cam length) and whose other three sides are straight: two vertical
ends and the bottom edge ``y = 0`` of the cam frame (see
:class:`~camfab.design.mechanisms.TranslatingCamRoller`).  Exporters and tool
paths need a closed curve, so this module chains the exact pieces into one
:class:`~camfab.discretize.ParametricCurve`:

* traversed counter-clockwise (outward normal on the right of the direction of
  travel), starting at the middle of the bottom edge, so a lead-in lands on a
  straight edge;
* parameter = arc length on the straight edges and corner arcs, cam travel B
  (mm) on the profile; every corner and every breakpoint of the motion program
  is a breakpoint of the chain (the tangent jumps at the plate corners).

The offset by ``distance > 0`` (outward, a cutter's centre) is exact too: each
edge moves along its normal, the profile by ``distance·n``, and every convex
corner is rounded by an arc of radius ``distance`` about the corner — what a
cutter rolling around the plate traces.
"""
from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from ..discretize import ParametricCurve
from ..errors import ApiError, GeometryError
from ..records import dataclass
from .corners import cornered_curve, profile_corners

__all__ = ["Piece", "line_piece", "arc_piece", "chain_curve", "translating_outline"]


@dataclass(frozen=True)
class Piece:
    """One smooth piece of a chained curve, parametrised by ``u`` in ``[0, length]``."""

    length: float
    point: Callable[[np.ndarray], np.ndarray]
    derivative: Callable[[np.ndarray], np.ndarray]
    breaks: tuple = ()  # internal breakpoints (local u)


def line_piece(a, b) -> Piece:
    """The segment from ``a`` to ``b``, parametrised by arc length."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    length = float(math.hypot(*(b - a)))
    if length <= 0:
        raise GeometryError("a plate edge has zero length")
    t = (b - a) / length
    return Piece(length, lambda u: a + u[:, None] * t, lambda u: np.broadcast_to(t, (u.size, 2)).copy())


def arc_piece(centre, radius: float, theta0: float, sweep: float) -> Piece:
    """Counter-clockwise arc about ``centre`` from angle ``theta0`` through ``sweep`` (> 0) radians,
    parametrised by arc length."""
    c = np.asarray(centre, dtype=float)

    def point(u):
        th = theta0 + u / radius
        return c + radius * np.column_stack([np.cos(th), np.sin(th)])

    def derivative(u):
        th = theta0 + u / radius
        return np.column_stack([-np.sin(th), np.cos(th)])

    return Piece(radius * sweep, point, derivative)


def chain_curve(pieces) -> ParametricCurve:
    """Chain pieces end to end into one closed :class:`ParametricCurve` (the caller makes them meet)."""
    pieces = [p for p in pieces if p.length > 0]
    lengths = np.array([p.length for p in pieces])
    starts = np.concatenate([[0.0], np.cumsum(lengths)])
    period = float(starts[-1])

    def dispatch(name):
        def f(t):
            t = np.asarray(t, dtype=float)
            idx = np.clip(np.searchsorted(starts, t, side="right") - 1, 0, len(pieces) - 1)
            out = np.empty((t.size, 2))
            for i in np.unique(idx):
                sel = idx == i
                out[sel] = getattr(pieces[i], name)(t[sel] - starts[i])
            return out
        return f

    breaks = list(starts)
    for s, p in zip(starts[:-1], pieces, strict=True):
        breaks += [s + b for b in p.breaks]
    return ParametricCurve(dispatch("point"), np.array(breaks), period, dispatch("derivative"))


def _profile_piece(contact, distance: float, reverse: bool) -> Piece:
    """The (offset) profile over one cam length, traversed right to left.  Where the follower's velocity jumps
    (a design written under ``--force``), the profile it makes there (:mod:`camfab.offset.corners`)."""
    corners = profile_corners(contact)
    if corners:
        return _cornered_piece(cornered_curve(contact, corners, distance), reverse)
    length = contact.period

    def travel(u):
        return length - u if reverse else u

    def point(u):
        s = contact.evaluate(travel(u))
        return s.point + distance * s.normal if distance else s.point

    def derivative(u):
        s = contact.evaluate(travel(u))
        d = s.point_d1 * (1.0 + distance * s.curvature)[:, None] if distance else s.point_d1
        return -d if reverse else d

    bp = np.asarray(contact.breakpoints, dtype=float)
    inner = (length - bp) if reverse else bp
    return Piece(length, point, derivative, tuple(float(b) for b in inner if 0 < b < length))


def _cornered_piece(curve: ParametricCurve, reverse: bool) -> Piece:
    """An open cornered profile as a piece (its own parameter, reversed when asked)."""
    length = curve.period

    def point(u):
        return curve.point(length - u if reverse else u)

    def derivative(u):
        d = curve.derivative(length - u if reverse else u)  # type: ignore[misc]
        return -d if reverse else d

    bp = np.asarray(curve.breakpoints, dtype=float)
    inner = (length - bp) if reverse else bp
    return Piece(length, point, derivative, tuple(float(b) for b in inner if 0 < b < length))


def _ends(contact, limits: bool = False):
    """Profile point and outward normal at travel 0⁺ and length⁻ (the point at the length itself, which the
    motion takes from its start, unless ``limits``: a cornered profile ends on its left limit)."""
    length = contact.period
    s = contact.evaluate(np.array([0.0, np.nextafter(length, 0.0)]))
    s_end = s if limits else contact.evaluate(np.array([length]))
    pts = np.array([s.point[0], s_end.point[-1]])
    return pts, s.normal


def translating_outline(contact, distance: float = 0.0) -> ParametricCurve:
    """The closed plate outline of a translating cam, or its outward offset by ``distance`` mm.

    Raises
    ------
    GeometryError
        When the plate has no height under the profile (``base_height_mm`` = 0) or the
        profile ends are not convex corners of the plate.
    """
    if contact.closed:
        raise ApiError("translating_outline is for translating (open-profile) cams; a disc cam's outline is its "
                       "closed profile")
    if not (math.isfinite(distance) and distance >= 0):
        raise GeometryError(f"the outline offset must be >= 0 mm, got {distance!r}")
    if not contact.base_height > 0:
        raise GeometryError("follower.base_height_mm = 0: the plate of a translating cam needs material "
                            "under the profile; set base_height_mm > 0 (the height of the S = 0 line "
                            "above the bottom edge)")
    (p0, p1), n = _ends(contact, limits=bool(profile_corners(contact)))
    reverse = p1[0] > p0[0]  # travel runs left to right: traverse the top edge backwards
    (left, n_left), (right, n_right) = ((p0, n[0]), (p1, n[1])) if reverse else ((p1, n[1]), (p0, n[0]))
    if not right[0] > left[0]:
        raise GeometryError("the profile of the translating cam does not run from one end of the plate "
                            "to the other")
    th_r = math.atan2(n_right[1], n_right[0])  # outward normal angle at the right top corner
    th_l = math.atan2(n_left[1], n_left[0])
    if not (0.0 < th_r < math.pi and 0.0 < th_l < math.pi):
        raise GeometryError("the profile of the translating cam turns downward at an end of the plate; "
                            "start and end the motion program with a dwell")
    d, (xl, yl), (xr, yr) = float(distance), left, right
    xm = 0.5 * (xl + xr)
    arcs = d > 0
    pieces = [line_piece((xm, -d), (xr, -d))]
    if arcs:
        pieces.append(arc_piece((xr, 0.0), d, -math.pi / 2, math.pi / 2))
    pieces.append(line_piece((xr + d, 0.0), (xr + d, yr)))
    if arcs:
        pieces.append(arc_piece((xr, yr), d, 0.0, th_r))
    pieces.append(_profile_piece(contact, d, reverse))
    if arcs:
        pieces.append(arc_piece((xl, yl), d, th_l, math.pi - th_l))
    pieces.append(line_piece((xl - d, yl), (xl - d, 0.0)))
    if arcs:
        pieces.append(arc_piece((xl, 0.0), d, math.pi, math.pi / 2))
    pieces.append(line_piece((xl, -d), (xm, -d)))
    return chain_curve(pieces)
