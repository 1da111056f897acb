"""Tool-centre paths of a groove cam's slot: the centre pass on the pitch curve and a finishing pass per flank.

A cutter of radius r_c < w (the groove half-width R_r + b/2) milling the slot runs on the pitch curve first (it
leaves w − r_c on each flank), then on each flank's exact offset by r_c into the groove: the inner flank's
``P + r_c·n`` (its normal points into the groove, away from its material) and the outer flank's, whose normal
points into the groove too (:mod:`camfab.design.groove`).  The cutter check runs on each flank: r_c must not
exceed the smallest concave radius of either flank (seen from the groove), else the finishing pass gouges.
The shapely guard buffers the inner flank's polygon outward and the outer flank's inward.
"""
from __future__ import annotations

import math

from ..discretize import ArcDiscretisation, ParametricCurve, arcs, validate_tol
from ..errors import GeometryError
from ..numeric import positive_ranges
from ..records import dataclass
from .cutter import ToolCentrePath, concave_limit, offset_curve, pitch_curve, profile_curve, shapely_guard

__all__ = ["GroovePaths", "groove_tool_paths", "flank_cutter_problem"]


@dataclass(frozen=True)
class GroovePaths:
    """The slot's tool-centre paths (mm): the centre pass (the pitch curve) and the two flank finishing passes."""

    centre: ParametricCurve
    centre_arcs: ArcDiscretisation
    inner: ToolCentrePath
    outer: ToolCentrePath


def flank_cutter_problem(contact, tool_radius: float) -> str | None:
    """Why a cutter of ``tool_radius`` cannot finish this flank (a concave stretch tighter than it), or None."""
    fits, _ = concave_limit(contact)
    if tool_radius < fits:
        return None
    g = lambda t: -tool_radius * contact.evaluate(t).curvature - 1.0  # noqa: E731  > 0 where too tight
    where = positive_ranges(g, contact.breakpoints, closed=True)
    spans = ", ".join(f"{math.degrees(lo):.4g}°–{math.degrees(hi):.4g}°" for lo, hi, *_ in where)
    return (f"{contact.label}: the cutter radius {tool_radius:g} mm is larger than its concave radius (down to "
            f"{fits:.6g} mm) in {spans}: it would gouge the flank. The largest cutter that fits has radius "
            f"{fits:.6g} mm")


def groove_tool_paths(inner, outer, tool_radius: float, *, tol: float) -> GroovePaths:
    """The centre pass and the flank finishing passes of a cutter of ``tool_radius`` (see the module notes).

    Raises
    ------
    GeometryError
        A cutter not narrower than the groove, or too large for a concave stretch of a flank, or an offset that
        folds (the shapely guard).
    """
    tol = validate_tol(tol)
    w = float(inner.roller_radius)
    if not (math.isfinite(tool_radius) and 0 < tool_radius < w):
        raise GeometryError(f"the cutter (radius {tool_radius:g} mm) must be narrower than the groove (half-width "
                            f"{w:g} mm = roller radius + backlash/2): it mills the slot along the pitch curve and then "
                            f"finishes each flank; choose a tool diameter below {2 * w:g} mm")
    why = [m for m in (flank_cutter_problem(c, tool_radius) for c in (inner, outer)) if m]
    if why:
        raise GeometryError("; ".join(why) + "; choose a smaller tool")
    centre = pitch_curve(inner)
    if centre is None:  # pragma: no cover - a groove's flanks are roller contacts on a disc
        raise GeometryError("a groove needs a closed pitch curve")
    paths = []
    for contact, side in ((inner, 1.0), (outer, -1.0)):
        exact = offset_curve(contact, tool_radius)
        dev = shapely_guard(profile_curve(contact), exact, side * tool_radius, f"{contact.label}: ")
        paths.append(ToolCentrePath(exact, arcs(exact, tol=tol), tool_radius, dev, tol))
    return GroovePaths(centre, arcs(centre, tol=tol), paths[0], paths[1])
