"""What a groove (face-groove) cam's drawing sheet adds to the plate sheet of :mod:`camfab.cad.drawing`.

The plate sheet draws both flanks (inner on ``PROFILE``, outer on ``PROFILE_2``), the bore and the side view of the
plate; a groove plate also needs its rim and its groove depth:

* the plate's rim (radius :func:`camfab.cad.groove.plate_radius`) on ``PLATE``, its diameter dimensioned;
* in the side view (first-angle projection: the view from the left, the front face — where the groove opens — on
  its right), the groove as hidden lines: its floor at the groove depth from the front face, over the outer
  flank's extent, and the walls' extreme heights (outer and inner flank) from the front face to the floor; the
  depth dimensioned across the front face and the floor.
"""
from __future__ import annotations

import math

import numpy as np

from .groove import plate_radius
from .sheet import SheetLayout, load_template, text_width

__all__ = ["groove_views", "groove_dimensions", "flank_heights"]


def flank_heights(geometry, n: int = 7201) -> np.ndarray:
    """The lowest and highest y (mm, cam frame as drawn) of the inner and the outer flank: ``[[lo, hi], [lo, hi]]``
    (sampled at ``n`` cam angles, breakpoints aside: within (2π/n)²·R/8 of the true extremes)."""
    x = np.linspace(0.0, geometry.period, n)
    out = []
    for c in geometry.profiles[:2]:
        y = c.evaluate(x).point[:, 1]
        out.append((float(y.min()), float(y.max())))
    return np.array(out)


def _side_box(spec, layout: SheetLayout) -> tuple[float, float]:
    """Paper x of the side view's back face and front face."""
    assert layout.side is not None
    x0, _, x1, _ = layout.side
    t = spec.manufacturing.thickness_mm * layout.scale
    a = (x0 + x1) / 2 - t / 2
    return a, a + t


def groove_views(msp, spec, geometry, layout: SheetLayout) -> None:
    """The plate's rim in the front view and the groove's hidden lines in the side view (module notes)."""
    s, (cx, cy) = layout.scale, layout.centre
    if "PLATE" not in msp.doc.layers:
        msp.doc.layers.add("PLATE", color=7, linetype="Continuous", lineweight=50)
    msp.add_circle((cx, cy), plate_radius(geometry) * s, dxfattribs={"layer": "PLATE"})
    if layout.side is None:
        return
    _, front = _side_box(spec, layout)
    floor = front - geometry.mechanism.groove_depth_mm * s
    (ilo, ihi), (olo, ohi) = flank_heights(geometry)
    msp.add_line((floor, cy + olo * s), (floor, cy + ohi * s), dxfattribs={"layer": "HIDDEN"})
    for y in (olo, ohi, ilo, ihi):
        msp.add_line((floor, cy + y * s), (front, cy + y * s), dxfattribs={"layer": "HIDDEN"})


def groove_dimensions(msp, spec, geometry, layout: SheetLayout) -> None:
    """The rim's diameter and the groove depth, each at the first of a few positions that keep the layout
    rule (:func:`camfab.cad.drawing.place_dimension`)."""
    from .drawing import dim_value, place_dimension
    from .sheet_check import Occupancy

    s, (cx, cy) = layout.scale, layout.centre
    occ = Occupancy(msp.doc, layout)
    r = plate_radius(geometry)
    text = f"%%c{dim_value(2 * r)}"
    half = text_width(text, load_template()["dimensions"]["text_height_mm"]) / 2
    options = []
    for k in (4.0, 10.0):
        for deg in (135.0, 45.0, 225.0, 315.0, 160.0, 20.0, 200.0, 340.0):
            d = r * s + k + half
            loc = (cx + d * math.cos(math.radians(deg)), cy + d * math.sin(math.radians(deg)))
            options.append(dict(center=(cx, cy), radius=r * s, angle=deg, location=loc))
    place_dimension(msp, occ, s, "diameter", text, options)
    if layout.side is None:
        return
    _, front = _side_box(spec, layout)
    floor = front - geometry.mechanism.groove_depth_mm * s
    top = cy + r * s
    depth = dim_value(geometry.mechanism.groove_depth_mm)
    lead = {"dimtmove": 1}
    options = [dict(base=(front, top + k), p1=(floor, top), p2=(front, top), extra=ex, location=loc)
               for k in (6.0, 12.0) for ex, loc in ((None, None), (lead, (front + 4.0, top + k + 2.0)))]
    place_dimension(msp, occ, s, "linear", depth, options)
