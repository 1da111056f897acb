"""The extent rule: the smallest and largest radius of a disc cam (DMIN/DMAX) and the profile area.

No findings: the numbers go into the report (``base_radius_mm``, ``max_radius_mm``, ``area_mm2``).
"""
from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ... import numeric
from ..profile import CamGeometry, ProfileSample
from .common import ContactSample, Limits, RuleResult

__all__ = ["extent_rule"]


def _green_closed(s: ProfileSample) -> np.ndarray:
    """½·(P × P′): the integrand of the enclosed area (Green's theorem, mm² per unit parameter)."""
    p, d = s.point, s.point_d1
    return 0.5 * (p[:, 0] * d[:, 1] - p[:, 1] * d[:, 0])


def _green_open(s: ProfileSample) -> np.ndarray:
    """y·x′: the integrand of the area between a translating cam's profile and its bottom edge."""
    return s.point[:, 1] * s.point_d1[:, 0]


def extent_rule(geometry: CamGeometry, limits: Limits, samples: Sequence[ContactSample]) -> RuleResult:
    """Base radius (the smallest distance of profile 1 from the centre), the largest distance of any
    profile (disc cams), and the area enclosed by profile 1 (rtol 1e-11)."""
    fields: dict = {}
    first = samples[0]
    if geometry.closed:
        fields["base_radius_mm"] = first.extremes("radius")[0].value
        fields["max_radius_mm"] = max(s.extremes("radius")[1].value for s in samples)
    c = first.contact
    green = _green_closed if c.closed else _green_open
    fields["area_mm2"] = abs(numeric.integrate(lambda x: green(c.evaluate_fixed(x)), c.breakpoints, rtol=1e-11))
    return RuleResult((), fields)
