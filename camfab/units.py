"""Unit conversions at the edges.  Internally camfab works in mm and radians."""
from __future__ import annotations

import math

__all__ = ["DEG", "RPM", "deg2rad", "rad2deg", "rpm_to_rad_s"]

#: one degree in radians
DEG = math.pi / 180.0
#: one rpm in rad/s
RPM = 2.0 * math.pi / 60.0


def deg2rad(x):
    """Degrees to radians (works on floats and numpy arrays)."""
    return x * DEG


def rad2deg(x):
    """Radians to degrees (works on floats and numpy arrays)."""
    return x / DEG


def rpm_to_rad_s(rpm: float) -> float:
    """Revolutions per minute to rad/s."""
    return rpm * RPM
