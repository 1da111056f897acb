"""Plane geometry shared by the G-code layer: arc sweeps and exact contour distances.

Everything here works in millimetres in the XY plane.  Angles are radians, counter-clockwise positive;
a *signed sweep* is negative for a clockwise arc.
"""
from __future__ import annotations

import math
from typing import Sequence

import numpy as np

__all__ = ["TWO_PI", "arc_sweep", "ContourDistance"]

#: a full turn in radians
TWO_PI = 2.0 * math.pi
#: start and end closer than this (mm) make an arc a full circle
FULL_CIRCLE_TOL_MM = 1e-9


def arc_sweep(start: Sequence[float], end: Sequence[float], center: Sequence[float],
              clockwise: bool) -> float:
    """Signed sweep of an arc from ``start`` to ``end`` about ``center``.

    Parameters
    ----------
    start, end, center : sequence of float
        Points ``(x, y)`` in mm.
    clockwise : bool
        Direction of travel (G2 when true).

    Returns
    -------
    float
        Sweep in radians, in ``(0, 2*pi]`` for counter-clockwise arcs and ``[-2*pi, 0)`` for clockwise
        ones.  Coincident start and end points give a full circle.
    """
    sx, sy = float(start[0]), float(start[1])
    ex, ey = float(end[0]), float(end[1])
    cx, cy = float(center[0]), float(center[1])
    if math.hypot(ex - sx, ey - sy) <= FULL_CIRCLE_TOL_MM:
        return -TWO_PI if clockwise else TWO_PI
    a0 = math.atan2(sy - cy, sx - cx)
    a1 = math.atan2(ey - cy, ex - cx)
    if clockwise:
        return -((a0 - a1) % TWO_PI)
    return (a1 - a0) % TWO_PI


class ContourDistance:
    """Exact signed distance from points to a closed contour of lines and arcs.

    Negative inside the contour, positive outside, exact to rounding for every point (the distance is the
    minimum over the entities of the distance to that line segment or circular arc, not to a polyline).
    The sign comes from the side of the nearest entity; where the nearest point is a sharp vertex the sign
    comes from a dense polygon of the contour.

    Parameters
    ----------
    entities : sequence
        The closed contour; anything :func:`camfab.gcode.toolpath.as_contour` accepts.

    Examples
    --------
    >>> from camfab.gcode.toolpath import Segment
    >>> circle = [Segment((10, 0), (10, 0), center=(0, 0), clockwise=False)]
    >>> float(ContourDistance(circle)(np.array([[12.0, 0.0]]))[0])
    2.0
    """

    def __init__(self, entities):
        from camfab.gcode.toolpath import as_contour, contour_is_clockwise  # local: avoid a cycle

        self.segments = as_contour(entities)
        self.clockwise = contour_is_clockwise(self.segments)
        poly = np.concatenate([s.polyline(max(8, int(math.ceil(abs(s.sweep) / TWO_PI * 720))))[:-1]
                               if s.is_arc else np.array([s.start]) for s in self.segments])
        import shapely

        self._polygon = shapely.Polygon(poly)
        shapely.prepare(self._polygon)

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
            inside[idx] = shapely.contains_xy(self._polygon, p[idx, 0], p[idx, 1])
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
