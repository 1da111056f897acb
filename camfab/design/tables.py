"""Tables of an exact cam geometry at round parameters: the sample grid of reports and the lift table.

The lift table gives, every ``step_deg`` of cam angle (or the same number of equal steps along a translating
cam), the follower lift and the distance of the follower's reference from the cam centre — what a drawing
sheet and the CAM-DAS workbook print and a shop checks a cam against.
"""
from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..errors import Problem, SpecError
from ..records import dataclass
from .kinds import ContactKind

__all__ = ["LiftTable", "lift_table", "sample_params", "intervals"]


def sample_params(geometry, step: float) -> np.ndarray:
    """Sample parameters (radians, or mm for a translating cam) from 0 to the period inclusive.

    ``step`` is in degrees; it must divide 360.  A translating cam is cut into
    the same number of equal intervals (``360/step``) over its length.
    """
    n = intervals(step, "step_deg")
    k = np.arange(n + 1, dtype=float)
    if geometry.closed:
        return np.radians(k * (360.0 / n))
    return k * (geometry.period / n)


def intervals(step: Any, field: str) -> int:
    """360/step as a whole number of intervals; a step that is not positive or does not divide 360 is refused."""
    if isinstance(step, bool) or not isinstance(step, (int, float)) or not math.isfinite(step) or step <= 0:
        raise SpecError(Problem(field, step, "must be a positive number of degrees", "e.g. 1 or 0.5"))
    n = 360.0 / step
    if abs(n - round(n)) > 1e-9 * max(1.0, n):
        raise SpecError(Problem(field, step, "must divide 360", "e.g. 0.25, 0.5, 1, 2, 5, 10"))
    return int(round(n))


@dataclass(frozen=True)
class LiftTable:
    """Follower lift against cam angle.

    Attributes
    ----------
    angle : (n,) float
        Cam angle in degrees (travel in mm for a translating cam), 0 up to, not including, the period.
    lift : (n,) float
        Follower lift S (mm, or degrees for oscillating followers).
    radius : (n,) float
        Distance from the cam centre to the follower's reference: the roller
        centre (pitch radius) for rollers and knife edges, the face's centre of
        curvature for curved faces, the face for flat faces (mm).  For a
        translating cam: the roller-centre height.
    lift_unit : str
    radius_label : str
    """

    angle: np.ndarray
    lift: np.ndarray
    radius: np.ndarray
    lift_unit: str
    radius_label: str


def lift_table(geometry, step_deg: float = 10.0, *, profile: int = 0) -> LiftTable:
    """The lift table of profile ``profile`` at ``step_deg`` (must divide 360)."""
    c = geometry.profiles[profile]
    x = sample_params(geometry, step_deg)[:-1]
    smp = c.evaluate(x)
    lift = c.motion.evaluate(x, (0,))[0]
    if not geometry.closed:
        radius, label = smp.pitch[:, 1], "Roller centre height (mm)"
    elif c.kind is ContactKind.ROLLER:
        label = "Face-centre radius (mm)" if c.curved_face else "Pitch radius (mm)"
        radius = np.hypot(smp.pitch[:, 0], smp.pitch[:, 1])
    else:
        radius, label = np.einsum("ij,ij->i", smp.point, smp.normal), "Face distance (mm)"
    return LiftTable(geometry.to_user(x), lift, radius, str(geometry.axis.lift_unit), label)
