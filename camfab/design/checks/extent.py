"""The extent rule: the smallest and largest radius of a disc cam (R min / R max) and the profile area.

No findings: the numbers go into the report (``base_radius_mm``, ``max_radius_mm``, ``area_mm2``).
"""
from __future__ import annotations

import logging
import math
from collections.abc import Sequence

import numpy as np

from ... import numeric
from ...errors import GeometryError
from ..profile import CamGeometry, Contact, ProfileSample
from .common import ContactSample, Limits, RuleResult, where

#: the area is computed to this relative tolerance (or to the rounding floor of a cancelling integrand) ...
AREA_RTOL = 1e-11
#: ... or, where double precision cannot reach it within the budget, reported rounded to the digits its error
#: estimate supports as long as that is this relative accuracy (six significant digits); else refused
AREA_RTOL_LEAST = 1e-6

log = logging.getLogger(__name__)

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
    profile (disc cams), and the area enclosed by profile 1 (rtol 1e-11 within the quadrature's fixed budget;
    a profile too steep for double precision: :func:`_area`)."""
    fields: dict = {}
    first = samples[0]
    if geometry.closed:
        fields["base_radius_mm"] = first.extremes("radius")[0].value
        fields["max_radius_mm"] = max(s.extremes("radius")[1].value for s in samples)
    c = first.contact
    green = _green_closed if c.closed else _green_open
    fields["area_mm2"] = _area(c, numeric.integral(lambda x: green(c.evaluate_fixed(x)), c.breakpoints,
                                                   rtol=AREA_RTOL))
    return RuleResult((), fields)


def _area(c: Contact, area: numeric.Integral) -> float:
    """|area| to :data:`AREA_RTOL`; past the budget rounded to the decimals its error estimate supports (a
    warning), or refused (GeometryError naming the segment) when that is worse than :data:`AREA_RTOL_LEAST`."""
    if area.converged:
        return abs(area.value)
    if not area.error <= AREA_RTOL_LEAST * abs(area.value):
        raise GeometryError(
            f"{where(c, *area.worst)}: the contact point moves too fast there for double precision, so the profile "
            f"area cannot be computed to {AREA_RTOL_LEAST:g} within the check's fixed budget (error estimate "
            f"{area.error:.3g} mm² of {abs(area.value):.6g} mm²). Spread the motion over a larger angle")
    decimals = -math.ceil(math.log10(area.error))
    log.warning("the profile area is known to %.3g mm² only (not %g relative: %s moves too fast for double "
                "precision); reported to %d decimals", area.error, AREA_RTOL, where(c, *area.worst), decimals)
    return abs(round(area.value, decimals))
