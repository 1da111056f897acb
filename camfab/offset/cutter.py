"""Tool-centre paths: exact normal offsets of cam profiles, cross-checked with shapely.

Sign convention: ``distance > 0`` offsets **outward**, along the profile's unit
outward normal ``n`` (away from the cam material), so a cutter of radius ``Rc``
milling the periphery runs on ``P(φ) + Rc·n(φ)``.  The exact offset is the
reference; shapely's ``buffer`` of a coarse polygon of the profile (round joins,
``quad_segs`` given explicitly) is computed beside it as the topology guard: it
detects split or self-intersecting offsets (:func:`shapely_guard`).  The comparison
of the two to the micrometre is a test, not a run-time cost.

Before offsetting, concave stretches whose radius is below the cutter radius
are refused with their angle ranges and the largest cutter that fits.
"""
from __future__ import annotations

import logging
import math

import numpy as np

from ..discretize import (
    Chain,
    ParametricCurve,
    arcs,
    measure_deviation,
    measure_within,
    points_at,
    polyline,
    validate_tol,
)
from ..discretize.tolerance import within
from ..errors import GeometryError, InternalError
from ..geom2d import ArcChain
from ..records import dataclass
from ..tolerances import DEFAULT_EXPORT_TOL_MM
from .corners import corner_note, cornered_curve, profile_corners
from .outline import translating_outline

__all__ = ["profile_curve", "pitch_curve", "offset_curve", "concave_limit", "ToolCentrePath", "offset_loop",
           "tool_centre_path", "shapely_offset", "shapely_guard", "guard_samples", "roller_envelope_deviation",
           "QUAD_SEGS", "JOIN_STYLE", "GUARD_SAMPLES", "GUARD_MIN_MM"]

log = logging.getLogger(__name__)

#: shapely buffer resolution (segments per quarter circle) and join style, always explicit
QUAD_SEGS = 64
JOIN_STYLE = "round"
#: the shapely topology guard buffers a polygon of this many samples of the profile (at least 4 per smooth
#: piece) and measures how far samples of the exact offset lie from the buffer's boundary; the comparison to
#: the micrometre belongs in the tests (docs/decisions.md, "The shapely guard of a tool path")
GUARD_SAMPLES = 2048
#: the guard refuses an offset whose samples lie further than this (mm) from the buffer's boundary, or than
#: twice the guard's own resolution (chords of the polygon plus the buffer's round joins), if that is larger
GUARD_MIN_MM = 1e-3


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

    def both(t):
        s = contact.evaluate_fields(t, ("point", "point_d1"))
        return s["point"], s["point_d1"]

    return ParametricCurve(lambda t: contact.evaluate_fields(t, ("point",))["point"], contact.breakpoints,
                           contact.period, lambda t: contact.evaluate_fields(t, ("point_d1",))["point_d1"],
                           point_and_derivative=both)


def pitch_curve(contact) -> ParametricCurve | None:
    """The exact closed pitch curve (roller-centre path), or None for flat faces and for
    translating cams (whose pitch curve is open)."""
    if not contact.closed:
        return None
    if contact.evaluate(np.array([0.0])).pitch is None:
        return None
    return ParametricCurve(lambda t: contact.evaluate_fields(t, ("pitch",))["pitch"], contact.breakpoints,
                           contact.period)


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
        s = contact.evaluate_fields(t, ("point", "normal"))
        return s["point"] + distance * s["normal"]

    def deriv(t):
        s = contact.evaluate_fields(t, ("point_d1", "curvature"))
        return s["point_d1"] * (1.0 + distance * s["curvature"])[:, None]

    def both(t):
        s = contact.evaluate_fields(t, ("point", "normal", "point_d1", "curvature"))
        return s["point"] + distance * s["normal"], s["point_d1"] * (1.0 + distance * s["curvature"])[:, None]

    return ParametricCurve(point, contact.breakpoints, contact.period, deriv, point_and_derivative=both)


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
    arcs: ArcChain  # max_deviation measured
    tool_radius: float
    shapely_deviation: float  # shapely buffer vs the exact offset (mm)
    tol: float

    @property
    def max_deviation(self) -> float:
        """Measured deviation of the arc chain from the exact tool-centre curve."""
        if self.arcs.max_deviation is None:  # a fit or an offset loop, measured: never None
            raise InternalError("a tool-centre path's arcs carry no measured deviation")
        return float(self.arcs.max_deviation)


def offset_loop(fit: ArcChain, distance: float, exact: ParametricCurve, tol: float) -> ArcChain | None:
    """``fit`` (arcs of a closed curve) offset by ``distance`` (outward > 0), as the arcs of ``exact`` (that
    curve's exact offset): concentric arcs, exact for a tangent-continuous chain
    (:meth:`~camfab.geom2d.ArcChain.offset_g1`), kept with their deviation from ``exact`` measured within
    ``tol`` (:func:`~camfab.discretize.measure_within`); None for a chain with a corner, an arc the offset would
    shrink away, or an offset farther than ``tol`` from ``exact`` (the caller fits ``exact`` itself)."""
    loop = fit.offset_g1(distance)
    if loop is None:
        log.info("offset by %g mm: the arc chain has a corner or an arc below that radius, so it has no exact "
                 "offset; the offset curve is fitted on its own", distance)
        return None
    dev = float(measure_within(loop, exact, tol).max)
    if not within(dev, tol):
        log.info("offset by %g mm: the arcs offset deviate %.3g mm > tol = %g mm from the exact offset; the offset "
                 "curve is fitted on its own", distance, dev, tol)
        return None
    return loop.with_deviation(dev)


def tool_centre_path(contact, tool_radius: float, *, tol: float = DEFAULT_EXPORT_TOL_MM,
                     label: str = "", profile_arcs: ArcChain | None = None) -> ToolCentrePath:
    """Tool-centre path for milling the periphery of one profile with a cutter of ``tool_radius``.

    ``profile_arcs`` (arcs of the profile, e.g. the plate files' fit) make the path when their offset by the
    tool radius lies within ``tol`` of the exact offset, measured (:func:`offset_loop`); otherwise, and without
    them, the exact offset is arc-fitted within ``tol``.

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
    dev = shapely_guard(profile_curve(contact), exact, tool_radius, label)
    fit = offset_loop(profile_arcs, tool_radius, exact, tol) if profile_arcs is not None else None
    return ToolCentrePath(exact, fit if fit is not None else arcs(exact, tol=tol), tool_radius, dev, tol)


def guard_samples(curve: ParametricCurve, n: int = GUARD_SAMPLES) -> tuple[np.ndarray, float]:
    """``n`` (or a few more) points of a closed curve, spread over its smooth pieces by parameter length, at
    least 4 per piece, and the largest gap between a chord's midpoint and the curve's point half-way along it
    (the polygon's resolution, mm)."""
    bp = np.asarray(curve.breakpoints, dtype=float)
    span = np.diff(bp)
    k = np.maximum(4, np.ceil(n * span / curve.period)).astype(int)
    owner = np.repeat(np.arange(span.size), k)
    j = np.arange(owner.size) - np.repeat(np.cumsum(k) - k, k)
    h = span[owner] / k[owner]
    t = bp[owner] + h * j
    pts = points_at(curve, t)
    mid = points_at(curve, t + 0.5 * h)
    chord_mid = 0.5 * (pts + np.roll(pts, -1, axis=0))
    return pts, float(np.hypot(*(mid - chord_mid).T).max())


def shapely_guard(profile: ParametricCurve, exact: ParametricCurve, tool_radius: float, label: str = "") -> float:
    """The topology guard of a tool path: shapely's buffer of a polygon of the profile must be one piece with no
    hole (:func:`shapely_offset`), and every sample of the exact offset must lie on its boundary within the
    guard's resolution, else the exact offset folds or crosses itself (a neck, a loop) where the buffer does not.
    Returns the largest distance found (mm)."""
    base, res = guard_samples(profile)
    buffered = shapely_offset(base, tool_radius)
    q, res_q = guard_samples(exact)
    # each sample's exact distance to the buffer's boundary (its segments: Chain.distance's grids, not an STRtree)
    dev = float(Chain.from_polyline(np.asarray(buffered.exterior.coords), closed=True).distance(q)[0].max())
    joins = tool_radius * (1.0 - math.cos(math.pi / (4 * QUAD_SEGS)))  # a round join's chord vs its arc
    allow = max(GUARD_MIN_MM, 2.0 * (res + res_q + joins))
    if dev > allow:
        raise GeometryError(f"{label}the exact tool-centre path lies {dev:.3g} mm off shapely's offset of the "
                            f"profile (> {allow:.3g} mm): the offset folds or crosses itself at this tool radius "
                            "(a neck narrower than the cutter, or a loop); use a smaller cutter")
    return dev


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
