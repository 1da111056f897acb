"""Synthetic parts with exact signed distances for the G-code tests."""
from __future__ import annotations

import math

import numpy as np

from camfab.gcode import Job, Segment

TOL = 0.001
TOOL_D = 6.0
R_TOOL = TOOL_D / 2
SAFE_Z = 25.0


def stadium(half_len: float, radius: float, ccw: bool = True) -> list[Segment]:
    """Stadium: semicircles of ``radius`` about (+-half_len, 0) joined by lines (counter-clockwise)."""
    a, r = half_len, radius
    segs = [Segment((-a, -r), (a, -r)), Segment((a, -r), (a, r), (a, 0), False),
            Segment((a, r), (-a, r)), Segment((-a, r), (-a, -r), (-a, 0), False)]
    if not ccw:
        segs = [s.reversed() for s in reversed(segs)]
    return segs


def stadium_distance(half_len: float, radius: float):
    """Exact signed distance to the stadium (negative inside)."""
    def f(p):
        p = np.asarray(p, float).reshape(-1, 2)
        x = np.clip(p[:, 0], -half_len, half_len)
        return np.hypot(p[:, 0] - x, p[:, 1]) - radius
    return f


def stadium_points(half_len: float, radius: float, n: int = 2000) -> np.ndarray:
    """Points spread along the stadium outline (for the coverage check)."""
    t = np.linspace(0, 2 * np.pi, n, endpoint=False)
    right = np.column_stack([half_len + radius * np.cos(t), radius * np.sin(t)])
    right = right[np.cos(t) >= 0]
    left = np.column_stack([-half_len + radius * np.cos(t), radius * np.sin(t)])
    left = left[np.cos(t) <= 0]
    xs = np.linspace(-half_len, half_len, n // 4)
    return np.concatenate([right, left, np.column_stack([xs, np.full_like(xs, radius)]),
                           np.column_stack([xs, np.full_like(xs, -radius)])])


def circle(radius: float, centre=(0.0, 0.0)) -> list[Segment]:
    cx, cy = centre
    return [Segment((cx + radius, cy), (cx + radius, cy), (cx, cy), False)]


def circle_distance(radius: float, centre=(0.0, 0.0)):
    def f(p):
        p = np.asarray(p, float).reshape(-1, 2)
        return np.hypot(p[:, 0] - centre[0], p[:, 1] - centre[1]) - radius
    return f


def notched_disc(R: float = 30.0, r: float = 4.0) -> list[Segment]:
    """Disc of radius R with a circular notch of radius r centred at (0, R) (concave radius r)."""
    ym = (R * R - r * r + R * R) / (2 * R)
    xm = math.sqrt(R * R - ym * ym)
    return [Segment((-xm, ym), (xm, ym), (0, 0), False),      # the long way round, ccw
            Segment((xm, ym), (-xm, ym), (0, R), True)]       # the notch, concave (cw)


def notched_disc_distance(R: float = 30.0, r: float = 4.0):
    """Exact signed distance to the notched disc (distance to its two arcs, negative inside)."""
    from camfab.gcode import ContourDistance
    return ContourDistance(notched_disc(R, r))


def job(**over) -> Job:
    kw = dict(tool_diameter_mm=TOOL_D, depth_mm=10.0, step_down_mm=4.0, safe_z_mm=SAFE_Z, clearance_mm=2.0,
              roughing_passes=1, roughing_allowance_mm=0.2, tolerance_mm=TOL, design_name="stadium test",
              achieved_deviation_mm=0.0004, feed_mm_min=600.0, plunge_feed_mm_min=200.0, spindle_rpm=4000)
    kw.update(over)
    return Job(**kw)


# the standard synthetic part: stadium 40 x 30, tool-centre path offset by the tool radius
HALF, RP = 20.0, 15.0
PART = stadium_distance(HALF, RP)
CENTRE_CURVE = stadium_distance(HALF, RP + R_TOOL)


def centre_path():
    return stadium(HALF, RP + R_TOOL)
