"""Closed contours of lines and arcs for milling: the entity, normalisation, orientation, offsets, distance.

A contour is a tuple of :class:`Segment` (mm, XY plane).  :func:`as_contour` accepts an
:class:`~camfab.geom2d.ArcChain` (what the discretisation produces), :class:`Segment` objects, tuples,
dicts or objects with ``start``/``end``/``center``/``clockwise``, and checks that they close up.
"""
from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from camfab.errors import GeometryError
from camfab.geom2d import TWO_PI, ArcChain, J, arc_sweep
from camfab.records import dataclass

__all__ = [
    "CLOSE_TOL_MM",
    "ARC_RADIUS_TOL_MM",
    "Segment",
    "as_contour",
    "contour_is_clockwise",
    "orient_contour",
    "outward_normal",
    "offset_contour",
    "ContourDistance",
]

#: consecutive contour entities must meet within this distance (mm)
CLOSE_TOL_MM = 1e-6
#: an arc's start and end radii must agree within this (mm, plus 1e-9 relative)
ARC_RADIUS_TOL_MM = 1e-6


def _pt(p) -> tuple[float, float]:
    x, y = (float(v) for v in p)
    return (x, y)


# --------------------------------------------------------------------------------------------------
# contour entities


@dataclass(frozen=True)
class Segment:
    """One entity of a closed planar contour: a line, or an arc when ``center`` is given.

    Parameters
    ----------
    start, end : tuple of float
        End points ``(x, y)`` in mm.  An arc whose start equals its end is a full circle.
    center : tuple of float or None
        Arc centre; ``None`` for a straight line.
    clockwise : bool
        Arc direction (ignored for lines).
    """

    start: tuple[float, float]
    end: tuple[float, float]
    center: tuple[float, float] | None = None
    clockwise: bool = False

    def __post_init__(self):
        object.__setattr__(self, "start", _pt(self.start))
        object.__setattr__(self, "end", _pt(self.end))
        if self.center is not None:
            object.__setattr__(self, "center", _pt(self.center))
        object.__setattr__(self, "clockwise", bool(self.clockwise))

    @property
    def is_arc(self) -> bool:
        """True for an arc."""
        return self.center is not None

    @property
    def radius(self) -> float:
        """Arc radius (distance from the centre to the start), mm; ``inf`` for a line."""
        if self.center is None:
            return math.inf
        return math.hypot(self.start[0] - self.center[0], self.start[1] - self.center[1])

    @property
    def sweep(self) -> float:
        """Signed sweep in radians (negative clockwise); 0 for a line."""
        if self.center is None:
            return 0.0
        return arc_sweep(self.start, self.end, self.center, self.clockwise)

    @property
    def length(self) -> float:
        """Length in mm."""
        if self.center is None:
            return math.hypot(self.end[0] - self.start[0], self.end[1] - self.start[1])
        return abs(self.sweep) * self.radius

    def reversed(self) -> Segment:
        """The same entity traversed the other way."""
        return Segment(self.end, self.start, self.center, not self.clockwise)

    def point(self, u: float) -> np.ndarray:
        """Point at parameter ``u`` in [0, 1] (by length)."""
        if u >= 1.0:
            return np.array(self.end)
        if self.center is None:
            s, e = np.array(self.start), np.array(self.end)
            return s + u * (e - s)
        cx, cy = self.center
        a = math.atan2(self.start[1] - cy, self.start[0] - cx) + u * self.sweep
        return np.array([cx + self.radius * math.cos(a), cy + self.radius * math.sin(a)])

    def tangent(self, u: float) -> np.ndarray:
        """Unit tangent in the direction of travel at parameter ``u``."""
        if self.center is None:
            d = np.array(self.end) - np.array(self.start)
            return d / np.hypot(*d)
        p = self.point(u)
        r = (p - np.array(self.center)) / self.radius
        return -J(r) if self.clockwise else J(r)

    def split(self, u: float) -> tuple[Segment, Segment]:
        """Split at parameter ``u`` into two entities."""
        m = tuple(self.point(u))
        return Segment(self.start, m, self.center, self.clockwise), Segment(m, self.end, self.center,
                                                                            self.clockwise)

    def polyline(self, n: int) -> np.ndarray:
        """``n + 1`` points along the entity, both ends included (array ``(n+1, 2)``)."""
        u = np.linspace(0.0, 1.0, n + 1)
        if self.center is None:
            s, e = np.array(self.start), np.array(self.end)
            return s + u[:, None] * (e - s)
        cx, cy = self.center
        a = math.atan2(self.start[1] - cy, self.start[0] - cx) + u * self.sweep
        pts = np.column_stack([cx + self.radius * np.cos(a), cy + self.radius * np.sin(a)])
        pts[-1] = self.end
        return pts


def _as_segment(e, i: int) -> Segment:
    if isinstance(e, Segment):
        return e
    if isinstance(e, dict):
        c = e.get("center", e.get("centre"))
        return Segment(e["start"], e["end"], c, bool(e.get("clockwise", False)))
    if hasattr(e, "start") and hasattr(e, "end"):
        c = getattr(e, "center", getattr(e, "centre", None))
        return Segment(e.start, e.end, c, bool(getattr(e, "clockwise", False)))
    try:
        t = tuple(e)
    except TypeError:
        raise GeometryError(f"contour entity {i}: {e!r} is not a line or an arc") from None
    if len(t) == 2:
        return Segment(t[0], t[1])
    if len(t) == 4:
        return Segment(t[0], t[1], t[2], bool(t[3]))
    raise GeometryError(f"contour entity {i}: expected (start, end) or (start, end, centre, clockwise), "
                        f"got {len(t)} items")


def _chain_segments(chain: ArcChain) -> list[Segment]:
    """The entities of a closed :class:`~camfab.geom2d.ArcChain`: its lines, and its arcs with their
    centres, clockwise where the sweep is negative."""
    if not chain.closed:
        raise GeometryError("an open arc chain is not a contour; close it (the part must lie inside)")
    return [Segment(tuple(s), tuple(e)) if sw == 0 else Segment(tuple(s), tuple(e), tuple(c), bool(sw < 0))
            for s, e, c, sw in zip(chain.starts, chain.ends, chain.centres, chain.sweeps, strict=True)]


def as_contour(entities) -> tuple[Segment, ...]:
    """Normalise and check a closed contour.

    Parameters
    ----------
    entities : ArcChain or iterable
        A closed :class:`~camfab.geom2d.ArcChain`, or lines and arcs: :class:`Segment` objects, tuples
        ``(start, end)`` / ``(start, end, centre, clockwise)``, dicts with keys ``start``, ``end``,
        ``center`` (or ``centre``), ``clockwise``, or objects with those attributes.

    Returns
    -------
    tuple of Segment

    Raises
    ------
    GeometryError
        Empty, open (consecutive entities more than :data:`CLOSE_TOL_MM` apart), degenerate, or an arc
        whose end is not on its circle.
    """
    if isinstance(entities, ArcChain):
        entities = _chain_segments(entities)
    elif isinstance(entities, Segment):
        entities = [entities]
    segs = tuple(_as_segment(e, i) for i, e in enumerate(entities))
    if not segs:
        raise GeometryError("the contour has no entities")
    for i, s in enumerate(segs):
        if not all(math.isfinite(v) for v in s.start + s.end + (s.center or ())):
            raise GeometryError(f"contour entity {i}: non-finite coordinates")
        if s.center is not None:
            r0 = s.radius
            r1 = math.hypot(s.end[0] - s.center[0], s.end[1] - s.center[1])
            if r0 <= CLOSE_TOL_MM:
                raise GeometryError(f"contour entity {i}: arc of zero radius")
            if abs(r1 - r0) > ARC_RADIUS_TOL_MM + 1e-9 * r0:
                raise GeometryError(f"contour entity {i}: arc end is {abs(r1 - r0):.3g} mm off its circle "
                                    f"(start radius {r0:.6f} mm, end radius {r1:.6f} mm)")
        elif s.length <= CLOSE_TOL_MM:
            raise GeometryError(f"contour entity {i}: zero-length line at {s.start}")
    for i, s in enumerate(segs):
        nxt = segs[(i + 1) % len(segs)]
        gap = math.hypot(nxt.start[0] - s.end[0], nxt.start[1] - s.end[1])
        if gap > CLOSE_TOL_MM:
            j = (i + 1) % len(segs)
            raise GeometryError(f"the contour is not closed: entity {i} ends at {s.end} but entity {j} "
                                f"starts at {nxt.start} ({gap:.3g} mm apart)")
    return segs


def _signed_area(segs: Sequence[Segment]) -> float:
    """The exact signed area of a closed contour (> 0 counter-clockwise), by Green's theorem: every entity's chord
    ``(a × b)/2``, and an arc's circular segment between chord and arc ``r²(θ - sin θ)/2`` (``θ`` its signed
    sweep; a full circle's ``πr²``; docs/decisions.md, "Contours: exact signed area")."""
    total = 0.0
    for s in segs:
        (ax, ay), (bx, by) = s.start, s.end
        total += 0.5 * (ax * by - bx * ay)
        if s.is_arc:
            theta, r = s.sweep, s.radius
            total += 0.5 * r * r * (theta - math.sin(theta))
    return total


def contour_is_clockwise(entities) -> bool:
    """True when the closed contour runs clockwise (negative signed area)."""
    return _signed_area(as_contour(entities)) < 0.0


def orient_contour(entities, clockwise: bool) -> tuple[Segment, ...]:
    """Return the contour traversed clockwise (``clockwise=True``) or counter-clockwise."""
    segs = as_contour(entities)
    if contour_is_clockwise(segs) == clockwise:
        return segs
    return tuple(s.reversed() for s in reversed(segs))


def outward_normal(t: np.ndarray, cw: bool) -> np.ndarray:
    """Outward unit normal ``(2,)`` for the unit tangent ``t`` of a contour around the part (part inside)
    traversed clockwise (``cw``) or counter-clockwise."""
    return J(t) if cw else -J(t)


def offset_contour(entities, distance: float) -> tuple[Segment, ...]:
    """Offset a closed line/arc contour outward (``distance > 0``) or inward.

    Lines shift along their normal, arcs change radius, and convex corners (tangent discontinuities)
    get a round arc about the corner.  Meant for the roughing passes around a tool-centre contour, which
    is usually tangent-continuous; the cam offset module is the general tool.

    Parameters
    ----------
    entities : sequence
        Closed contour (see :func:`as_contour`); its orientation is kept.
    distance : float
        Offset in mm, positive away from the inside of the contour.

    Returns
    -------
    tuple of Segment

    Raises
    ------
    GeometryError
        A concave arc smaller than the offset, or a corner that would need trimming.
    """
    segs = as_contour(entities)
    d = float(distance)
    if d == 0.0:
        return segs
    cw = contour_is_clockwise(segs)
    out: list[Segment] = []
    for i, s in enumerate(segs):
        if not s.is_arc:
            n = outward_normal(s.tangent(0.0), cw)
            out.append(Segment(tuple(np.array(s.start) + d * n), tuple(np.array(s.end) + d * n)))
            continue
        convex = s.clockwise == cw
        R = s.radius
        newR = R + d if convex else R - d
        if newR <= CLOSE_TOL_MM:
            kind = "concave" if convex is False else "convex"
            raise GeometryError(f"contour entity {i}: {kind} arc of radius {R:.4f} mm cannot be offset by "
                                f"{d:.4f} mm (it vanishes); pass the offset contour explicitly")
        c = np.array(s.center)
        us = (np.array(s.start) - c) / R
        ue = np.array(s.end) - c
        ue = ue / np.hypot(*ue)
        full = math.hypot(s.end[0] - s.start[0], s.end[1] - s.start[1]) <= 1e-12
        start = tuple(c + newR * us)
        end = start if full else tuple(c + newR * ue)
        out.append(Segment(start, end, s.center, s.clockwise))
    result: list[Segment] = []
    sigma = -1.0 if cw else 1.0
    for i, o in enumerate(out):
        result.append(o)
        nxt = out[(i + 1) % len(out)]
        gap = math.hypot(nxt.start[0] - o.end[0], nxt.start[1] - o.end[1])
        if gap <= 1e-9 * max(1.0, abs(d)):
            continue
        ta = segs[i].tangent(1.0)
        tb = segs[(i + 1) % len(segs)].tangent(0.0)
        turn = float(ta[0] * tb[1] - ta[1] * tb[0])
        if sigma * turn * d > 0:
            result.append(Segment(o.end, nxt.start, segs[i].end, cw))
        else:
            raise GeometryError(f"offsetting by {d:.4f} mm: the corner at {segs[i].end} would need trimming; "
                                "pass the offset contour explicitly (roughing_contours=...)")
    return as_contour(_snap(result))


def _snap(segs: list[Segment]) -> list[Segment]:
    """Make each entity start exactly where the previous one ends (lines only move)."""
    out = list(segs)
    for i in range(len(out)):
        prev = out[i - 1]
        s = out[i]
        if s.start != prev.end and not s.is_arc:
            out[i] = Segment(prev.end, s.end)
    return out




class ContourDistance:
    """Exact signed distance from points to a closed contour of lines and arcs.

    Negative inside the contour, positive outside, exact to rounding for every point (the distance is the
    minimum over the entities of the distance to that line segment or circular arc, not to a polyline).
    The sign comes from the side of the nearest entity; where the nearest point is a sharp vertex the sign
    comes from a dense polygon of the contour.

    Parameters
    ----------
    entities : sequence
        The closed contour; anything :func:`as_contour` accepts.

    Examples
    --------
    >>> circle = [Segment((10, 0), (10, 0), center=(0, 0), clockwise=False)]
    >>> float(ContourDistance(circle)(np.array([[12.0, 0.0]]))[0])
    2.0
    """

    def __init__(self, entities):
        self.segments = as_contour(entities)
        self.clockwise = contour_is_clockwise(self.segments)
        self._polygon = None  # the dense polygon of the sign at sharp vertices, made when a query first needs it

    def _dense_polygon(self):
        if self._polygon is None:
            import shapely

            poly = np.concatenate([s.polyline(max(8, int(math.ceil(abs(s.sweep) / TWO_PI * 720))))[:-1]
                                   if s.is_arc else np.array([s.start]) for s in self.segments])
            self._polygon = shapely.Polygon(poly)
            shapely.prepare(self._polygon)
        return self._polygon

    def __call__(self, points) -> np.ndarray:
        """Signed distance of ``points`` (array ``(n, 2)``) in mm; negative inside."""
        import shapely

        p = np.asarray(points, dtype=float).reshape(-1, 2)
        n = len(p)
        best = np.full(n, np.inf)
        inside = np.zeros(n, dtype=bool)
        at_vertex = np.zeros(n, dtype=bool)
        contour_ccw = not self.clockwise
        for s in self.segments:
            if s.is_arc:
                d, interior, ins = self._arc(p, s, contour_ccw)
            else:
                d, interior, ins = self._line(p, s, contour_ccw)
            closer = d < best
            best = np.where(closer, d, best)
            inside = np.where(closer, ins, inside)
            at_vertex = np.where(closer, ~interior, at_vertex)
        if at_vertex.any():
            idx = np.nonzero(at_vertex)[0]
            inside[idx] = shapely.contains_xy(self._dense_polygon(), p[idx, 0], p[idx, 1])
        return np.where(inside, -best, best)

    @staticmethod
    def _line(p, s, contour_ccw):
        a = np.array(s.start)
        b = np.array(s.end)
        ab = b - a
        L2 = float(ab @ ab)
        if L2 == 0.0:
            d = np.hypot(p[:, 0] - a[0], p[:, 1] - a[1])
            return d, np.zeros(len(p), bool), np.zeros(len(p), bool)
        t = ((p - a) @ ab) / L2
        interior = (t > 0.0) & (t < 1.0)
        tc = np.clip(t, 0.0, 1.0)
        q = a + tc[:, None] * ab
        d = np.hypot(p[:, 0] - q[:, 0], p[:, 1] - q[:, 1])
        cross = ab[0] * (p[:, 1] - a[1]) - ab[1] * (p[:, 0] - a[0])
        ins = cross > 0 if contour_ccw else cross < 0
        return d, interior, ins

    @staticmethod
    def _arc(p, s, contour_ccw):
        cx, cy = s.center
        R = s.radius
        sweep = s.sweep
        a0 = math.atan2(s.start[1] - cy, s.start[0] - cx)
        dx = p[:, 0] - cx
        dy = p[:, 1] - cy
        rho = np.hypot(dx, dy)
        phi = np.arctan2(dy, dx)
        if abs(sweep) >= TWO_PI - 1e-15:
            interior = np.ones(len(p), dtype=bool)
        else:
            rel = (phi - a0) % TWO_PI if sweep > 0 else (a0 - phi) % TWO_PI
            interior = rel < abs(sweep)
        d_circle = np.abs(rho - R)
        d_ends = np.minimum(np.hypot(p[:, 0] - s.start[0], p[:, 1] - s.start[1]),
                            np.hypot(p[:, 0] - s.end[0], p[:, 1] - s.end[1]))
        d = np.where(interior, d_circle, d_ends)
        arc_ccw = sweep > 0
        ins = (rho < R) if arc_ccw == contour_ccw else (rho > R)
        return d, interior, ins

