"""Tool-centre paths: exact normal offsets of cam profiles, cross-checked with shapely.

Sign convention: ``distance > 0`` offsets **outward**, along the profile's unit
outward normal ``n`` (away from the cam material), so a cutter of radius ``Rc``
milling the periphery runs on ``P(φ) + Rc·n(φ)``.  The exact offset is the
reference; shapely's ``buffer`` of the profile (round joins, ``quad_segs`` given
explicitly) is computed beside it to detect split or self-intersecting offsets
and to cross-check the exact one.

Before offsetting, concave stretches whose radius is below the cutter radius
are refused with their angle ranges and the largest cutter that fits.
"""
from __future__ import annotations

import logging
import math
from dataclasses import dataclass

import numpy as np

from ..discretize import ArcDiscretisation, ParametricCurve, arcs, measure_deviation, polyline, validate_tol
from ..errors import GeometryError
from ..tolerances import DEFAULT_EXPORT_TOL_MM
from .corners import corner_note, cornered_curve, profile_corners
from .outline import translating_outline

__all__ = ["profile_curve", "pitch_curve", "offset_curve", "concave_limit", "ToolCentrePath",
           "tool_centre_path", "shapely_offset", "roller_envelope_deviation", "QUAD_SEGS", "JOIN_STYLE"]

log = logging.getLogger(__name__)

#: shapely buffer resolution (segments per quarter circle) and join style, always explicit
QUAD_SEGS = 64
JOIN_STYLE = "round"
#: the shapely cross-check buffers a polyline of the profile (GEOS simplifies its input slightly), so
#: below this tolerance (mm) it checks
#: at this resolution (the exact offset itself is still fitted to the requested tolerance)
SHAPELY_CHECK_MIN_MM = 1e-4


def _user(contact, x) -> float:
    """A profile parameter in the user's unit: degrees of cam angle, or mm of a translating cam's travel."""
    return float(contact.axis.to_user(x))


def profile_curve(contact) -> ParametricCurve:
    """The exact profile of one contact as a closed :class:`ParametricCurve`.

    For a translating (wedge) cam this is the whole plate outline: the profile
    closed by the plate's ends and bottom edge (:mod:`camfab.offset.outline`).
    """
    if not contact.closed:
        return translating_outline(contact)
    corners = profile_corners(contact)
    if corners:  # a velocity jump (only under --force): the profile the follower really makes there
        log.info("profile: the follower's velocity jumps at %s; the profile is the one the follower makes there",
                 corner_note(contact, corners))
        return cornered_curve(contact, corners)
    return ParametricCurve(lambda t: contact.evaluate(t).point, contact.breakpoints, contact.period,
                           lambda t: contact.evaluate(t).point_d1)


def pitch_curve(contact) -> ParametricCurve | None:
    """The exact closed pitch curve (roller-centre path), or None for flat faces and for
    translating cams (whose pitch curve is open)."""
    if not contact.closed:
        return None
    if contact.evaluate(np.array([0.0])).pitch is None:
        return None
    return ParametricCurve(lambda t: contact.evaluate(t).pitch, contact.breakpoints, contact.period)


def offset_curve(contact, distance: float) -> ParametricCurve:
    """``P + distance·n``: the exact offset of a profile (outward for distance > 0).

    Its derivative is ``P′·(1 + distance·κ)`` (κ > 0 convex), so it is given
    analytically too.  For a translating cam it is the offset of the whole plate outline,
    convex corners rounded by arcs of radius ``distance``.
    """
    if not contact.closed:
        return translating_outline(contact, distance)
    corners = profile_corners(contact)
    if corners:  # a velocity jump (only under --force): the offset of the profile the follower really makes
        return cornered_curve(contact, corners, distance)

    def point(t):
        s = contact.evaluate(t)
        return s.point + distance * s.normal

    def deriv(t):
        s = contact.evaluate(t)
        return s.point_d1 * (1.0 + distance * s.curvature)[:, None]

    return ParametricCurve(point, contact.breakpoints, contact.period, deriv)


def concave_limit(contact) -> tuple[float, list[tuple[float, float]]]:
    """The largest cutter radius that fits every concave stretch, and the concave ranges.

    Returns ``(radius, ranges)``: ``radius`` is ``inf`` for a convex profile;
    ``ranges`` lists ``(from, to)`` of the concave stretches in degrees (mm for
    a translating cam).
    """
    from ..numeric import extremum, positive_ranges

    edges = contact.breakpoints
    x, kmin = extremum(lambda t: contact.evaluate(t).curvature, edges)
    if kmin >= 0:
        return math.inf, []
    ranges = positive_ranges(lambda t: -contact.evaluate(t).curvature, edges, closed=contact.closed)
    return 1.0 / -kmin, [(_user(contact, lo), _user(contact, hi)) for lo, hi, *_ in ranges]


def _refuse_if_too_big(contact, tool_radius: float, label: str) -> None:
    from ..numeric import positive_ranges

    fits, _ = concave_limit(contact)
    if tool_radius < fits:
        return
    g = lambda t: -tool_radius * contact.evaluate(t).curvature - 1.0  # noqa: E731  > 0 where too tight
    where = positive_ranges(g, contact.breakpoints, closed=contact.closed)
    unit = contact.axis.x_symbol
    spans = ", ".join(f"{_user(contact, lo):.4g}{unit}–{_user(contact, hi):.4g}{unit}" for lo, hi, *_ in where)
    raise GeometryError(
        f"{label}the cutter radius {tool_radius:g} mm is larger than the concave radius of the profile "
        f"(down to {fits:.6g} mm) in {spans}: it would gouge the part. The largest cutter that fits has "
        f"radius {fits:.6g} mm (diameter {2 * fits:.6g} mm); choose a smaller tool")


def shapely_offset(points: np.ndarray, distance: float):
    """shapely buffer of the closed polygon ``points`` by ``distance`` (round joins, QUAD_SEGS).

    Raises
    ------
    GeometryError
        When the polygon is invalid (self-intersecting profile) or the offset splits
        into several pieces or has holes.
    """
    from shapely.geometry import Polygon

    poly = Polygon(points)
    if not poly.is_valid:
        from shapely.validation import explain_validity

        raise GeometryError(f"the profile is not a simple closed curve ({explain_validity(poly)}); "
                            "it crosses itself: check the design for undercuts")
    out = poly.buffer(distance, quad_segs=QUAD_SEGS, join_style=JOIN_STYLE)
    if out.geom_type != "Polygon":
        raise GeometryError(f"the offset by {distance:g} mm splits into {len(out.geoms)} pieces: "
                            "the cam has a neck narrower than twice the offset")
    if len(out.interiors):
        raise GeometryError(f"the offset by {distance:g} mm encloses {len(out.interiors)} hole(s): "
                            "the profile folds over itself at that distance")
    return out


@dataclass(frozen=True)
class ToolCentrePath:
    """An exact tool-centre curve and its arc discretisation (mm)."""

    curve: ParametricCurve
    arcs: ArcDiscretisation
    tool_radius: float
    shapely_deviation: float  # shapely buffer vs the exact offset (mm)
    tol: float

    @property
    def max_deviation(self) -> float:
        """Measured deviation of the arc chain from the exact tool-centre curve."""
        return self.arcs.max_deviation


def tool_centre_path(contact, tool_radius: float, *, tol: float = DEFAULT_EXPORT_TOL_MM,
                     label: str = "") -> ToolCentrePath:
    """Tool-centre path for milling the periphery of one profile with a cutter of ``tool_radius``.

    Raises
    ------
    GeometryError
        A concave stretch tighter than the cutter (with the angle ranges and the largest
        cutter that fits), or an offset that splits or folds (shapely), or a shapely offset
        that disagrees with the exact one by more than ``tol``.
    """
    tol = validate_tol(tol)
    if not (math.isfinite(tool_radius) and tool_radius > 0):
        raise GeometryError(f"tool radius must be > 0 mm, got {tool_radius!r}")
    _refuse_if_too_big(contact, tool_radius, label)
    exact = offset_curve(contact, tool_radius)
    fit = arcs(exact, tol=tol)
    check_tol = max(tol, SHAPELY_CHECK_MIN_MM)
    base = polyline(profile_curve(contact), tol=check_tol / 4)
    buffered = shapely_offset(base.points[:-1], tool_radius)
    ring = np.asarray(buffered.exterior.coords)
    dev = float(measure_deviation(ring, exact).max)
    if dev > check_tol:
        raise GeometryError(f"{label}the shapely offset differs from the exact offset by {dev:.3g} mm (> "
                            f"{check_tol:g} mm); the offset is ill-conditioned at this tool radius")
    return ToolCentrePath(exact, fit, tool_radius, dev, tol)


def roller_envelope_deviation(contact, *, tol: float = DEFAULT_EXPORT_TOL_MM) -> float:
    """Cross-check: the pitch curve offset inward by the roller radius (shapely) vs the exact profile.

    Returns the measured maximum distance (mm); a correct envelope gives at most ``tol``.
    """
    pitch = pitch_curve(contact)
    if pitch is None or contact.roller_radius == 0:
        raise GeometryError("the roller-envelope cross-check needs a roller follower on a disc cam")
    pts = polyline(pitch, tol=tol / 4).points[:-1]
    inner = shapely_offset(pts, -contact.roller_radius)
    return float(measure_deviation(np.asarray(inner.exterior.coords), profile_curve(contact)).max)
