"""The cam plate as plane geometry: an outline loop, a bore with keyway, a hub.

Loops are closed :class:`~camfab.geom2d.ArcChain` values (the DXF LWPOLYLINE model:
vertices and the bulge ``tan(sweep/4)`` of the line or arc leaving each).  They carry
arcs exactly, so the STEP solid holds true circles, and they flatten to polylines
within a chordal tolerance for meshes.

Keyway: hub keyseat of DIN 6885-1 / ISO R773 proportions for the bore, centred
on the +Y axis (the follower direction at cam angle 0).
"""
from __future__ import annotations

import math

import numpy as np

from ..errors import GeometryError, InternalError
from ..geom2d import ArcChain
from ..records import dataclass

__all__ = ["PlateSpec", "keyway_size", "bore_loop", "circle_loop", "plate_volume"]

# DIN 6885-1: (bore diameter upper limit mm, key width b mm, hub keyseat depth t2 mm)
_KEYWAYS = [(8, 2, 1.0), (10, 3, 1.4), (12, 4, 1.8), (17, 5, 2.3), (22, 6, 2.8), (30, 8, 3.3),
            (38, 10, 3.3), (44, 12, 3.3), (50, 14, 3.8), (58, 16, 4.3), (65, 18, 4.4), (75, 20, 4.9),
            (85, 22, 5.4), (95, 25, 5.4), (110, 28, 6.4), (130, 32, 7.4), (150, 36, 8.4),
            (170, 40, 9.4), (200, 45, 10.4), (230, 50, 11.4)]


def keyway_size(bore_mm: float) -> tuple[float, float]:
    """Key width b and hub keyseat depth t2 (mm) for a bore diameter (DIN 6885-1).

    Raises
    ------
    GeometryError
        For bores outside 6 … 230 mm, where the standard gives no key.
    """
    if not 6.0 <= bore_mm <= 230.0:
        raise GeometryError(f"manufacturing.bore_mm = {bore_mm:g}: DIN 6885 keys cover bores of 6 to 230 mm; "
                            "set keyway = false or change the bore")
    for dmax, b, t2 in _KEYWAYS:
        if bore_mm <= dmax:
            return float(b), float(t2)
    raise InternalError(f"DIN 6885 table has no key for bore {bore_mm:g} mm inside 6 … 230 mm")


def circle_loop(radius: float, centre=(0.0, 0.0)) -> ArcChain:
    """A full circle (mm) as two half-circle arcs (counter-clockwise)."""
    cx, cy = centre
    pts = np.array([[cx + radius, cy], [cx - radius, cy]])
    return ArcChain.from_bulges(pts, np.array([1.0, 1.0]))


def bore_loop(bore_mm: float, keyway: bool) -> ArcChain:
    """The bore (with a DIN 6885 keyseat towards +Y when asked), counter-clockwise."""
    r = bore_mm / 2
    if not keyway:
        return circle_loop(r)
    b, t2 = keyway_size(bore_mm)
    y0 = math.sqrt(r * r - (b / 2) ** 2)
    top = r + t2
    pts = np.array([[b / 2, y0], [b / 2, top], [-b / 2, top], [-b / 2, y0]])
    sweep = 2 * math.pi - 2 * math.asin(b / (2 * r))
    return ArcChain.from_bulges(pts, np.array([0.0, 0.0, 0.0, math.tan(sweep / 4)]))


@dataclass(frozen=True)
class PlateSpec:
    """Plate thickness, bore, keyway and optional hub (mm).  The plate spans z = 0 … thickness."""

    thickness_mm: float
    bore_mm: float = 0.0
    keyway: bool = False
    hub_diameter_mm: float | None = None
    hub_length_mm: float | None = None

    def hole(self) -> ArcChain | None:
        """The bore loop, or None without a bore."""
        return bore_loop(self.bore_mm, self.keyway) if self.bore_mm > 0 else None


def plate_volume(outline: ArcChain, plate: PlateSpec) -> float:
    """Exact volume (mm³): outline area × thickness − bore, plus the hub ring if any."""
    hole = plate.hole()
    hole_area = abs(hole.area()) if hole is not None else 0.0
    vol = abs(outline.area()) * plate.thickness_mm - hole_area * plate.thickness_mm
    if plate.hub_diameter_mm and plate.hub_length_mm:
        vol += (math.pi * plate.hub_diameter_mm**2 / 4 - hole_area) * plate.hub_length_mm
    return vol
