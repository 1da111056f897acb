"""The cam plate as plane geometry: an outline loop, a bore with keyway, a hub.

Loops are **bulge loops** (the DXF LWPOLYLINE model): closed chains of vertices
where the segment from vertex i to vertex i+1 is a straight line (bulge 0) or a
circular arc with ``bulge = tan(sweep/4)``, positive for a counter-clockwise
arc.  They carry arcs exactly, so the STEP solid holds true circles, and they
flatten to polylines within a chordal tolerance for meshes.

Keyway: hub keyseat of DIN 6885-1 / ISO R773 proportions for the bore, centred
on the +Y axis (the follower direction at cam angle 0).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import GeometryError

__all__ = ["BulgeLoop", "PlateSpec", "keyway_size", "bore_loop", "circle_loop", "plate_volume"]

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
    raise AssertionError("unreachable")


@dataclass(frozen=True)
class BulgeLoop:
    """A closed chain of lines and arcs.

    Attributes
    ----------
    points : (n, 2) float array, mm
        Vertices; the loop closes from the last back to the first.
    bulges : (n,) float array
        ``tan(sweep/4)`` of the segment leaving each vertex (0 = line).
    """

    points: np.ndarray
    bulges: np.ndarray

    def segments(self):
        """Yield ``(p0, p1, bulge)`` for every segment."""
        n = len(self.points)
        for i in range(n):
            yield self.points[i], self.points[(i + 1) % n], float(self.bulges[i])

    @staticmethod
    def arc_midpoint(p0: np.ndarray, p1: np.ndarray, bulge: float) -> np.ndarray:
        """The point halfway along the arc from p0 to p1 with this bulge."""
        d = p1 - p0
        c = math.hypot(*d)
        right = np.array([d[1], -d[0]]) / c
        return (p0 + p1) / 2 + right * bulge * c / 2

    def area(self) -> float:
        """Exact signed area (positive for a counter-clockwise loop), arcs included."""
        p, q = self.points, np.roll(self.points, -1, axis=0)
        poly = 0.5 * float(np.sum(p[:, 0] * q[:, 1] - q[:, 0] * p[:, 1]))
        c = np.hypot(*(q - p).T)
        th = 4 * np.arctan(np.abs(self.bulges))
        with np.errstate(divide="ignore", invalid="ignore"):
            r = np.where(th > 0, c / (2 * np.sin(th / 2)), 0.0)
        return poly + float(np.sum(np.sign(self.bulges) * r**2 / 2 * (th - np.sin(th))))

    def flatten(self, tol: float) -> np.ndarray:
        """Vertices of a polyline within ``tol`` (sagitta) of every arc; (m, 2), not closed."""
        out = []
        for p0, p1, b in self.segments():
            out.append(p0[None, :])
            if abs(b) < 1e-15:
                continue
            th = 4 * math.atan(b)
            c = math.hypot(*(p1 - p0))
            r = c / (2 * math.sin(abs(th) / 2))
            n = max(1, math.ceil(abs(th) / (2 * math.acos(max(-1.0, 1 - tol / r)))))
            centre = self._centre(p0, p1, b)
            a0 = math.atan2(*(p0 - centre)[::-1])
            ang = a0 + th * np.arange(1, n) / n
            out.append(centre + r * np.column_stack([np.cos(ang), np.sin(ang)]))
        return np.concatenate(out)

    def offset_g1(self, distance: float, *, angle_tol: float = 1e-9) -> "BulgeLoop | None":
        """The loop offset outward by ``distance`` (inward if negative), exactly, or None.

        For a tangent-continuous chain the offset of every arc is the concentric arc with the
        same sweep and of every line the parallel line, so the offset loop is the vertices moved
        along their common normal with the bulges unchanged.  Returns None when the loop has a
        corner (tangent jump above ``angle_tol`` rad) or an arc would shrink to radius ≤ 0.
        """
        p, q = self.points, np.roll(self.points, -1, axis=0)
        d = q - p
        chord = np.hypot(d[:, 0], d[:, 1])
        th = 4 * np.arctan(self.bulges)
        u = d / chord[:, None]
        c, s = np.cos(-th / 2), np.sin(-th / 2)  # start tangent = chord turned back by half the sweep
        t0 = np.column_stack([u[:, 0] * c - u[:, 1] * s, u[:, 0] * s + u[:, 1] * c])
        c, s = np.cos(th / 2), np.sin(th / 2)  # end tangent = chord turned on by half the sweep
        t1 = np.column_stack([u[:, 0] * c - u[:, 1] * s, u[:, 0] * s + u[:, 1] * c])
        t_in = np.roll(t1, 1, axis=0)  # tangent arriving at each vertex
        if np.any(np.abs(t_in[:, 0] * t0[:, 1] - t_in[:, 1] * t0[:, 0]) > angle_tol) or np.any(
                (t_in * t0).sum(1) <= 0):
            return None
        ccw = self.area() > 0
        sign = 1.0 if ccw else -1.0  # outward = right of the direction of travel on a ccw loop
        normal = sign * np.column_stack([t0[:, 1], -t0[:, 0]])
        with np.errstate(divide="ignore", invalid="ignore"):
            radius = np.where(th != 0, chord / (2 * np.abs(np.sin(th / 2))), np.inf)
        # an arc turning the loop's way (convex) grows by the distance, the other way shrinks
        grow = np.where(np.sign(th) == sign, 1.0, -1.0)
        if np.any((th != 0) & (radius + grow * distance <= 0)):
            return None
        return BulgeLoop(p + distance * normal, self.bulges.copy())

    @staticmethod
    def _centre(p0, p1, bulge):
        th = 4 * math.atan(bulge)
        d = p1 - p0
        c = math.hypot(*d)
        left = np.array([-d[1], d[0]]) / c
        # distance from chord midpoint to centre, signed towards the left for CCW arcs < 180°
        h = c / 2 / math.tan(th / 2)
        return (p0 + p1) / 2 + left * h


def circle_loop(radius: float, centre=(0.0, 0.0)) -> BulgeLoop:
    """A full circle as two half-circle arcs (counter-clockwise)."""
    cx, cy = centre
    pts = np.array([[cx + radius, cy], [cx - radius, cy]])
    return BulgeLoop(pts, np.array([1.0, 1.0]))


def bore_loop(bore_mm: float, keyway: bool) -> BulgeLoop:
    """The bore (with a DIN 6885 keyseat towards +Y when asked), counter-clockwise."""
    r = bore_mm / 2
    if not keyway:
        return circle_loop(r)
    b, t2 = keyway_size(bore_mm)
    y0 = math.sqrt(r * r - (b / 2) ** 2)
    top = r + t2
    pts = np.array([[b / 2, y0], [b / 2, top], [-b / 2, top], [-b / 2, y0]])
    sweep = 2 * math.pi - 2 * math.asin(b / (2 * r))
    return BulgeLoop(pts, np.array([0.0, 0.0, 0.0, math.tan(sweep / 4)]))


@dataclass(frozen=True)
class PlateSpec:
    """Plate thickness, bore, keyway and optional hub (mm).  The plate spans z = 0 … thickness."""

    thickness_mm: float
    bore_mm: float = 0.0
    keyway: bool = False
    hub_diameter_mm: float | None = None
    hub_length_mm: float | None = None

    def hole(self) -> BulgeLoop | None:
        return bore_loop(self.bore_mm, self.keyway) if self.bore_mm > 0 else None


def plate_volume(outline: BulgeLoop, plate: PlateSpec) -> float:
    """Exact volume (mm³): outline area × thickness − bore, plus the hub ring if any."""
    hole = plate.hole()
    hole_area = abs(hole.area()) if hole is not None else 0.0
    vol = abs(outline.area()) * plate.thickness_mm - hole_area * plate.thickness_mm
    if plate.hub_diameter_mm and plate.hub_length_mm:
        vol += (math.pi * plate.hub_diameter_mm**2 / 4 - hole_area) * plate.hub_length_mm
    return vol
