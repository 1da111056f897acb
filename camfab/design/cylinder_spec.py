"""``[cylinder]`` of a cylindrical cam: its values and their validation (re-exported by
:mod:`camfab.design.cylindrical`, whose geometry a design of another kind never imports)."""
from __future__ import annotations

from collections.abc import Mapping
from enum import StrEnum
from typing import Any

from ..records import dataclass
from .kinds import CamKind

__all__ = ["CYLINDER_KEYS", "Feature", "RollerShape", "CylinderSpec", "cylinder_section"]

#: ``[cylinder]`` keys
CYLINDER_KEYS = ("radius_mm", "length_mm", "groove_depth_mm", "backlash_mm", "roller", "zero_position_mm", "feature",
                 "rib_width_mm", "rib_height_mm")


class Feature(StrEnum):
    """``[cylinder] feature``: what the follower runs on (``docs/decisions.md``, "Cylindrical cams: the rib")."""

    #: a groove cut into the cylinder, one roller in it
    GROOVE = "groove"
    #: a rib standing on the cylinder, straddled by two rollers on one follower
    RIB = "rib"


class RollerShape(StrEnum):
    """``[cylinder] roller``: the follower roller's shape."""

    CYLINDRICAL = "cylindrical"
    #: a cone whose apex lies on the cam axis (half-angle atan(R_r/R))
    CONICAL = "conical"


@dataclass(frozen=True, slots=True)
class CylinderSpec:
    """``[cylinder]``: the grooved cylinder (mm).

    Attributes
    ----------
    radius_mm : float
        Pitch radius R: the middle of the groove depth, where the roller's section is R_r.
    length_mm : float
        Length of the cylinder along its axis; z = 0 at one end.
    groove_depth_mm : float
        Depth of the groove; it spans the radii R ± depth/2 (outer surface R + depth/2).  A rib's height
        (``rib_height_mm``): it spans the same radii, from its root on the cylinder to its top.
    backlash_mm : float
        Groove width minus the roller diameter; for a rib, the clearance between each roller and the rib, twice.
    roller : RollerShape
        Cylindrical or conical roller.
    zero_position_mm : float or None
        Axial position z₀ of the roller at S = 0; default: the travel centred on the length.
    feature : Feature
        A groove (default) or a rib.
    rib_width_mm : float or None
        A rib's width where it runs round without lead (dwells); None for a groove.
    """

    radius_mm: float
    length_mm: float
    groove_depth_mm: float
    backlash_mm: float = 0.0
    roller: RollerShape = RollerShape.CYLINDRICAL
    zero_position_mm: float | None = None
    feature: Feature = Feature.GROOVE
    rib_width_mm: float | None = None

    @property
    def inner_radius_mm(self) -> float:
        """Radius of the groove bottom."""
        return self.radius_mm - 0.5 * self.groove_depth_mm

    @property
    def outer_radius_mm(self) -> float:
        """Outer radius of the cylinder (the groove's top edge)."""
        return self.radius_mm + 0.5 * self.groove_depth_mm


def cylinder_section(v: Any, t: Mapping[str, Any], kind: CamKind) -> CylinderSpec | None:
    """``[cylinder]`` read with the validator ``v``: required for a cylindrical cam, refused for any other."""
    if kind != CamKind.CYLINDRICAL:
        if t:
            v.add("cylinder", dict(t), f"a {kind} cam has no cylinder", 'remove [cylinder] or set kind = "cylindrical"')
        return None
    v.keys(t, CYLINDER_KEYS, "cylinder")
    feature = v.choice(t, "feature", "cylinder", Feature, Feature.GROOVE)
    rib = feature is Feature.RIB
    need = ("radius_mm", "length_mm", *(("rib_height_mm", "rib_width_mm") if rib else ("groove_depth_mm",)))
    for k in {"groove_depth_mm", "rib_height_mm", "rib_width_mm"} - set(need):
        if k in t:
            v.add(f"cylinder.{k}", t[k], f'is not a key of a {feature.value} (feature = "{feature.value}")',
                  f"remove {k}, or set feature = \"{'groove' if rib else 'rib'}\"")
    vals = {k: v.number(t, k, "cylinder", None, lo=0.0, lo_open=True, hi=1e5, fix=f"give {k} as a length > 0 in mm")
            for k in need}
    for k, val in vals.items():
        if val is None and k not in t:
            v.add(f"cylinder.{k}", None, f"is required for a {feature.value}", f"add {k} = <mm> to [cylinder]")
    backlash = v.number(t, "backlash_mm", "cylinder", 0.0, lo=0.0, hi=1e3)
    zero = v.number(t, "zero_position_mm", "cylinder", None, lo=-1e5, hi=1e5)
    roller = v.choice(t, "roller", "cylinder", RollerShape, RollerShape.CYLINDRICAL)
    if any(val is None for val in vals.values()):
        return None
    depth = vals["rib_height_mm"] if rib else vals["groove_depth_mm"]
    return CylinderSpec(vals["radius_mm"], vals["length_mm"], depth, backlash, roller, zero, feature,
                        vals.get("rib_width_mm"))
