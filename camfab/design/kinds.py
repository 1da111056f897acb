"""Named kinds of the design model: cam kind, follower type and motion, rotation sense, and the axis.

Every kind is a :class:`enum.StrEnum`, so a member equals its design-file string
(``CamKind.DISC == "disc"``) and JSON writes it as that string.

The :class:`Axis` travels with a motion program and the geometry built on it: it says
whether the independent variable x is a cam angle (radians inside, degrees for the user)
or the travel of a translating cam (mm), and whether the lift S is in mm (translating
followers) or degrees (oscillating followers).  Code asks the axis instead of guessing
from the period or from the attributes a contact happens to have.
"""
from __future__ import annotations

import math
from enum import StrEnum

import numpy as np

from ..records import dataclass

__all__ = [
    "CamKind",
    "FollowerType",
    "FollowerMotion",
    "Rotation",
    "Direction",
    "ContactKind",
    "AxisKind",
    "LiftUnit",
    "Axis",
    "ROTATING_MM",
    "ROTATING_DEG",
    "TRANSLATING_MM",
]


class CamKind(StrEnum):
    """``[cam] kind``."""

    DISC = "disc"
    CONJUGATE = "conjugate"
    CONSTANT_WIDTH = "constant_width"
    CONSTANT_DIAMETER = "constant_diameter"
    TRANSLATING = "translating"
    #: a disc with a face groove: one pitch curve, two flanks, one roller driven both ways
    GROOVE = "groove"
    CYLINDRICAL = "cylindrical"

    @property
    def form_closed(self) -> bool:
        """Conjugate, constant-width, constant-diameter, (disc) groove and cylindrical (groove or rib) cams drive
        their follower both ways (each family's geometry class says the same: ``CamGeometry.form_closed``)."""
        return self in (CamKind.CONJUGATE, CamKind.CONSTANT_WIDTH, CamKind.CONSTANT_DIAMETER, CamKind.GROOVE,
                        CamKind.CYLINDRICAL)

    @property
    def symmetric(self) -> bool:
        """Constant-width and constant-diameter cams: one profile touched by both followers."""
        return self in (CamKind.CONSTANT_WIDTH, CamKind.CONSTANT_DIAMETER)


class FollowerType(StrEnum):
    """``[follower] type``."""

    ROLLER = "roller"
    FLAT = "flat"
    KNIFE = "knife"
    #: a convex circular face (mushroom or finger follower)
    CURVED = "curved"

    # shadows str.title() on purpose (a name in words, not a capitalised value); no compatible override exists
    @property
    def title(self) -> str:  # type: ignore[override]
        """The follower's name in words: "roller", "flat-face", "knife-edge" or "curved-face"."""
        return {"roller": "roller", "flat": "flat-face", "knife": "knife-edge", "curved": "curved-face"}[self.value]


class FollowerMotion(StrEnum):
    """``[follower] motion``."""

    TRANSLATING = "translating"
    OSCILLATING = "oscillating"


class Rotation(StrEnum):
    """``[cam] rotation``: the sense in which the cam turns, seen with the follower above it."""

    CW = "cw"
    CCW = "ccw"

    @property
    def sense(self) -> int:
        """σ: +1 for cw, −1 for ccw."""
        return 1 if self is Rotation.CW else -1


class Direction(StrEnum):
    """``[cam] direction`` of a translating cam: the way it slides under the follower."""

    LEFT = "left"
    RIGHT = "right"


class ContactKind(StrEnum):
    """The shape of the follower surface that envelopes a profile."""

    #: a circle of fixed radius about a point of the follower (roller; knife edge = radius 0; a curved
    #: face, which slides)
    ROLLER = "roller"
    #: a straight face
    FLAT = "flat"


class AxisKind(StrEnum):
    """What the independent variable x of a program is."""

    #: a cam angle: radians inside, degrees for the user; period 2π
    ROTATING = "rotating"
    #: the travel of a translating cam, mm; period the cam length
    TRANSLATING = "translating"


class LiftUnit(StrEnum):
    """Unit of the follower coordinate S."""

    MM = "mm"
    DEG = "deg"


@dataclass(frozen=True, slots=True)
class Axis:
    """The independent variable of a program (and its geometry) and the unit of its lift."""

    kind: AxisKind = AxisKind.ROTATING
    lift_unit: LiftUnit = LiftUnit.MM

    @property
    def rotating(self) -> bool:
        """True for a cam angle, False for a translating cam's travel."""
        return self.kind is AxisKind.ROTATING

    @property
    def x_unit(self) -> str:
        """The user unit of x: ``"deg"`` or ``"mm"``."""
        return "deg" if self.rotating else "mm"

    @property
    def x_symbol(self) -> str:
        """``"°"`` or ``" mm"``, to follow a number in a message."""
        return "°" if self.rotating else " mm"

    @property
    def x_header(self) -> str:
        """Column header of x in tables: ``"angle_deg"`` or ``"position_mm"``."""
        return "angle_deg" if self.rotating else "position_mm"

    @property
    def x_scale(self) -> float:
        """Internal units of x per user unit: radians per degree, or 1 (mm)."""
        return math.pi / 180.0 if self.rotating else 1.0

    @property
    def lift_header(self) -> str:
        """Column header of the lift in tables: ``"lift_mm"`` or ``"lift_deg"``."""
        return f"lift_{self.lift_unit.value}"

    @property
    def lift_to_rad(self) -> float:
        """Radians per unit of lift for an oscillating follower (1 for mm, used as is)."""
        return math.pi / 180.0 if self.lift_unit is LiftUnit.DEG else 1.0

    def to_user(self, x):
        """x in internal units (radians or mm) → user units (degrees or mm); floats or arrays."""
        return np.degrees(x) if self.rotating else x

    def from_user(self, x):
        """x in user units (degrees or mm) → internal units (radians or mm); floats or arrays."""
        return np.radians(x) if self.rotating else x

    def with_lift(self, unit: LiftUnit | str) -> Axis:
        """The same axis with another lift unit."""
        return Axis(self.kind, LiftUnit(unit))


#: a disc cam with a translating follower (lift in mm)
ROTATING_MM = Axis(AxisKind.ROTATING, LiftUnit.MM)
#: a disc cam with an oscillating follower (lift in degrees)
ROTATING_DEG = Axis(AxisKind.ROTATING, LiftUnit.DEG)
#: a translating (wedge) cam
TRANSLATING_MM = Axis(AxisKind.TRANSLATING, LiftUnit.MM)
