"""The translating (sliding, wedge) cam driving a translating roller follower.

The program's independent variable is the cam travel B in mm (its period is the cam length).  Cam frame: x
along the cam, y up; the line S = 0 of the profile lies at ``y = base_height_mm`` above the cam's bottom edge
(y = 0).  The roller centre is ``(x₀ + χ·B, h + R_r + S)`` with χ = +1 when the cam slides left (the follower
reads the cam left to right, x₀ = 0) and χ = −1 when it slides right (x₀ = the cam length).
"""
from __future__ import annotations

from typing import Any, ClassVar

import numpy as np

from ..errors import Problem
from ..geom2d import J, cross
from ..records import dataclass
from .kinds import CamKind, Direction
from .mechanism import Mechanism, finite_fields, require_non_negative
from .profile import Contact, MotionLike, ProfileSample, inverse, pressure_angle, xy

__all__ = ["TranslatingCamContact", "TranslatingCamRoller"]


def _roller(C, T, A2, v, rr, sg):
    """Pitch/profile quantities from the cam-frame tangent T and second derivative A2."""
    speed = np.hypot(T[:, 0], T[:, 1])
    t = T / speed[:, None]
    kp = sg * cross(T, A2) / speed**3
    n = -sg * J(t)
    point = C - rr * n
    scale = 1.0 - rr * kp
    with np.errstate(divide="ignore", invalid="ignore"):
        k = kp / scale
    return C, point, T * scale[:, None], n, t, kp, k, pressure_angle(v, n, sg)


class TranslatingCamContact(Contact):
    """Roller on a translating (wedge) cam: pitch (x₀ ± B, h + R_r + S)."""

    closed = False

    def __init__(self, motion: MotionLike, roller_radius: float, base_height: float = 0.0,
                 direction: str = "left"):
        super().__init__(motion, 1 if direction == "right" else -1)
        self.roller_radius, self.base_height = float(roller_radius), float(base_height)

    def _evaluate(self, phi, rotate: bool, S=None) -> ProfileSample:
        # a sliding plate is not turned: one sample serves both frames (the checked quantities and the
        # normal do not depend on where the plate has slid to)
        x, (s0, s1, s2) = self._S(phi, S)
        chi = -self.sense  # +1: x = B (cam slides left)
        x0 = 0.0 if chi > 0 else self.period
        z = np.zeros_like(s0)
        C = xy(x0 + chi * x, self.base_height + self.roller_radius + s0)
        out = _roller(C, xy(chi + z, s1), xy(z, s2), xy(z, 1.0 + z), self.roller_radius, self.sense)
        pitch, point, dpoint, n, t, kp, k, delta = out
        return ProfileSample(x, point, dpoint, n, t, k, inverse(k), pitch, kp, inverse(kp), delta, None, None)


@dataclass(frozen=True)
class TranslatingCamRoller(Mechanism):
    """Translating (sliding, wedge) cam driving a translating roller follower.

    Parameters
    ----------
    roller_radius_mm : float
        R_r (>= 0).
    base_height_mm : float
        Height of the profile's lowest line above the bottom edge (>= 0).
    direction : {"left", "right"}
        Sense in which the cam slides under the follower.  ``"left"`` (default) puts the follower at x = B on
        the cam (the CAM-DAS table reads left to right); ``"right"`` is its mirror image, x = length − B.
        ``"right"`` corresponds to the top of a cw disc cam.
    """

    roller_radius_mm: float
    base_height_mm: float = 0.0
    direction: str = "left"
    cam_kind: ClassVar[CamKind] = CamKind.TRANSLATING
    required: ClassVar[tuple[str, ...]] = ("roller_radius_mm", "cam_length_mm")
    optional: ClassVar[tuple[str, ...]] = ("base_height_mm",)

    @classmethod
    def from_spec(cls, spec: Any) -> TranslatingCamRoller:
        f = spec.follower
        return cls(f.roller_radius_mm or 0.0, f.base_height_mm or 0.0, spec.cam.direction)

    @property
    def sense(self) -> int:
        return 1 if self.direction == "right" else -1

    def validate(self) -> list[Problem]:
        p: list[Problem] = []
        if self.direction not in tuple(Direction):
            p.append(Problem("cam.direction", self.direction, "direction must be 'left' or 'right'",
                             'use direction = "left" (default) or "right"'))
        if finite_fields(self, p):
            require_non_negative(p, "roller_radius_mm", self.roller_radius_mm)
            require_non_negative(p, "base_height_mm", self.base_height_mm)
        return p

    def contacts(self, program: MotionLike) -> tuple[Contact, ...]:
        return (TranslatingCamContact(program, self.roller_radius_mm, self.base_height_mm, self.direction),)
