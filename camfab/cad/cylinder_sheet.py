"""The drawing sheet of a cylindrical (barrel) cam: the developed groove, a side view and the lift table.

The sheet keeps the plate sheet's frame (:mod:`camfab.cad.sheet`: paper, title block from ``[drawing]``, notes
column, lift table, explicit-text DIMENSIONs with ``dimlfac = 1/scale``) and its layout rule
(:func:`camfab.cad.sheet_check.layout_problems`).  Its views, in paper mm at one standard scale:

* **Developed groove** (left): the pitch cylinder unrolled (:mod:`camfab.design.cylindrical`, x = R·θ along the
  circumference from cam angle 0° to 360°, z along the axis upwards): the cylinder's development (x from 0 to
  2πR, z from 0 to the length) on ``CYLINDER``, both flanks on ``PROFILE`` and the pitch curve (the roller
  axis's track) on ``PRIME_CIRCLE`` — the arc chains of the developed DXF (:func:`camfab.cad.cylinder.
  developed_curves`, within the tolerance, measured) — the cam angle marked every 90° above it, the developed
  length and the cylinder's length dimensioned.
* **Side view** (right, the axis upright at the same z as the development): the cylinder seen from +X at cam
  angle 0 (the follower on +Y, to the right), its groove cut at both silhouettes (at 0° on the right, 180° on
  the left: the flanks' exact crossings of those generators on the groove bottom and the outer surface), the
  groove's edges on the front half (outer radius, projected), the bore as hidden lines; the outer diameter, the
  length, the groove depth and the bore dimensioned.

The header's ``CAMFAB_CENTRE`` is the paper point of the development's origin (x = 0, z = 0): true developed
coordinates are ``(paper − centre) / scale`` there, as on the plate sheets.
"""
from __future__ import annotations

import math
from dataclasses import replace
from types import SimpleNamespace

import numpy as np

from ..design.tables import LiftTable, sample_params
from .dxf import write_deterministic
from .sheet import (
    PAPERS,
    SheetLayout,
    lift_table_block,
    load_template,
    new_document,
    notes_column,
    parse_scale,
    put_text,
    sheet_layout,
    text_width,
    title_block,
)

__all__ = ["cylinder_lift_table", "cylinder_layout", "build_cylinder_drawing", "cylinder_drawing_sheet",
           "silhouette_notch", "cylinder_notes", "MARGINS_MM"]

#: paper mm kept round the two views for the dimensions and labels: left, bottom, right, top, and between them
MARGINS_MM = (13.0, 18.0, 13.0, 19.0, 16.0)


def cylinder_lift_table(geometry, step_deg: float = 10.0) -> LiftTable:
    """The lift table of a cylindrical cam at ``step_deg`` (the plate's steps): cam angle (degrees), the lift
    S (mm, or degrees of arm rotation) and the roller axis's axial position z on the pitch cylinder (mm)."""
    x = sample_params(geometry, step_deg)[:-1]
    c = geometry.at_radius(geometry.cylinder.radius_mm)
    lift = c.motion.evaluate(x, (0,))[0]
    return LiftTable(np.degrees(x), lift, c.pitch(x)[0][:, 1], str(geometry.axis.lift_unit), "Roller axis z (mm)")


def _views_size(geometry) -> tuple[float, float, float]:
    """True sizes (mm): the development's width, the side view's width, the common height."""
    cyl = geometry.cylinder
    return 2 * math.pi * cyl.radius_mm, 2 * cyl.outer_radius_mm, cyl.length_mm


def _fits(geometry, area, scale: float) -> bool:
    wd, ws, h = _views_size(geometry)
    left, bottom, right, top, gap = MARGINS_MM
    return (scale * (wd + ws) + left + right + gap <= area[2] - area[0]
            and scale * h + bottom + top <= area[3] - area[1])


def cylinder_layout(geometry, n_rows: int, paper: str = "auto") -> SheetLayout:
    """The sheet's layout: the paper (``auto``: as the plate sheets, the larger scale counting any enlargement
    as 1:1, ties to A4) and the largest standard scale at which both views and their margins fit the view area;
    ``centre`` is the paper point of the development's origin."""
    labels = load_template()["view"]["scales"]
    options = []
    for p in (PAPERS if paper == "auto" else (paper,)):
        lay = sheet_layout(1.0, n_rows, p)  # the frame, title block, table and notes; the view area
        good = [s for s in labels if _fits(geometry, lay.view, parse_scale(s))]
        label = good[0] if good else labels[-1]
        options.append((lay, label, bool(good)))
    lay, label, fits = max(options, key=lambda o: (o[2], min(parse_scale(o[1]), 1.0), -PAPERS.index(o[0].paper)))
    s = parse_scale(label)
    wd, ws, h = _views_size(geometry)
    left, bottom, right, top, gap = MARGINS_MM
    x0, y0, x1, y1 = lay.view
    spare_x = (x1 - x0) - (s * (wd + ws) + left + right + gap)
    spare_y = (y1 - y0) - (s * h + bottom + top)
    centre = (x0 + left + max(spare_x, 0.0) / 2, y0 + bottom + max(spare_y, 0.0) / 2)
    return replace(lay, scale=s, scale_label=label, centre=centre, fits=fits)


def _side_origin(geometry, layout: SheetLayout) -> tuple[float, float]:
    """Paper point of the side view's axis at z = 0."""
    wd, ws, _ = _views_size(geometry)
    s, (cx, cy) = layout.scale, layout.centre
    return cx + s * wd + MARGINS_MM[4] + s * ws / 2, cy


def _polyline(msp, chain, s: float, origin, layer: str) -> None:
    pts = [(float(x), float(y), 0.0, 0.0, float(b))
           for (x, y), b in zip(chain.starts * s + np.asarray(origin), chain.bulges, strict=True)]
    end = chain.ends[-1] * s + np.asarray(origin)
    pts.append((float(end[0]), float(end[1]), 0.0, 0.0, 0.0))
    msp.add_lwpolyline(pts, format="xyseb", dxfattribs={"layer": layer})


def _developed_view(msp, geometry, layout: SheetLayout, tol: float) -> float:
    """The development (module notes); returns the curves' measured deviation (mm)."""
    from .cylinder import developed_curves

    s, (cx, cy) = layout.scale, layout.centre
    wd, _, h = _views_size(geometry)
    curves = developed_curves(geometry, tol)
    for chain, layer in zip(curves, ("PRIME_CIRCLE", "PROFILE", "PROFILE"), strict=True):
        _polyline(msp, chain, s, (cx, cy), layer)
    msp.add_lwpolyline([(cx, cy), (cx + s * wd, cy), (cx + s * wd, cy + s * h), (cx, cy + s * h)], close=True,
                       dxfattribs={"layer": "CYLINDER"})
    for k in range(5):  # the cam angle every 90°: a tick above the development and its value
        x = cx + s * wd * k / 4
        msp.add_line((x, cy + s * h), (x, cy + s * h + 2.0), dxfattribs={"layer": "CENTRE_MARKS"})
        put_text(msp, f"{90 * k}°", (x, cy + s * h + 3.0), 2.5, "ANNOTATION", "BOTTOM_CENTER")
    put_text(msp, f"DEVELOPED GROOVE ON THE PITCH CYLINDER R{geometry.cylinder.radius_mm:g} (x = R·θ)",
             (cx, cy + s * h + 9.0), 2.5, "ANNOTATION", "BOTTOM_LEFT", width=s * wd)
    return max(float(c.max_deviation) for c in curves)


def silhouette_notch(geometry, theta: float, n: int = 8001) -> np.ndarray:
    """Where the groove cuts the generator met by the follower at cam angle ``theta`` (radians): the axial
    positions (mm) of the −z and +z flanks on the groove bottom and on the outer cylinder, rows
    ``(r, z_minus, z_plus)`` — each flank's developed curve on that radius crossing x = r·θ round the
    circumference (bracketed on ``n`` samples, then linear; a groove crosses each generator once)."""
    cyl = geometry.cylinder
    grid = np.linspace(0.0, geometry.period, n)
    rows = []
    for r in (cyl.inner_radius_mm, cyl.outer_radius_mm):
        z = []
        for flank in (-1, 1):
            p = geometry.at_radius(r, flank).evaluate(grid).point
            d = (p[:, 0] - r * theta + math.pi * r) % (2 * math.pi * r) - math.pi * r  # along the circumference
            cross = np.flatnonzero((np.sign(d[:-1]) != np.sign(d[1:])) & (np.abs(d[1:] - d[:-1]) < math.pi * r))
            i = int(cross[0]) if cross.size else int(np.argmin(np.abs(d[:-1])))
            t = d[i] / (d[i] - d[i + 1]) if d[i] != d[i + 1] else 0.0
            z.append(float(p[i, 1] + t * (p[i + 1, 1] - p[i, 1])))
        rows.append((r, *z))
    return np.array(rows)


def _side_outline(geometry, layout: SheetLayout):
    """The side view's outline with the groove's notches at both silhouettes, and the notch on the right."""
    s = layout.scale
    ax, ay = _side_origin(geometry, layout)
    cyl = geometry.cylinder
    ro, h = cyl.outer_radius_mm, cyl.length_mm
    right = silhouette_notch(geometry, 0.0)
    left = silhouette_notch(geometry, math.pi)
    (ri, rzm, rzp), (_, ozm, ozp) = right
    (_, lzm_i, lzp_i), (_, lzm_o, lzp_o) = left

    def at(y, z):
        return (ax + s * y, ay + s * z)
    pts = [at(-ro, 0.0), at(ro, 0.0), at(ro, ozm), at(ri, rzm), at(ri, rzp), at(ro, ozp), at(ro, h), at(-ro, h),
           at(-ro, lzp_o), at(-ri, lzp_i), at(-ri, lzm_i), at(-ro, lzm_o)]
    return pts, right


def _side_view(msp, spec, geometry, layout: SheetLayout) -> None:
    """The cylinder seen from +X at cam angle 0 (module notes)."""
    s = layout.scale
    ax, ay = _side_origin(geometry, layout)
    cyl, sense = geometry.cylinder, geometry.mechanism.sense
    ro, h = cyl.outer_radius_mm, cyl.length_mm
    pts, _ = _side_outline(geometry, layout)
    msp.add_lwpolyline(pts, close=True, dxfattribs={"layer": "CYLINDER"})
    theta = np.linspace(0.0, geometry.period, 1441)
    for flank in (-1, 1):  # the groove's edges on the front half (cam-frame polar angle 90° + σx/r, x > 0)
        p = geometry.at_radius(ro, flank).evaluate(theta).point
        a = 0.5 * math.pi + sense * p[:, 0] / ro
        front = np.cos(a) > 0.02
        y = ro * np.sin(a)
        for run in np.split(np.arange(theta.size), np.flatnonzero(np.diff(front.astype(int))) + 1):
            run = run[front[run]]
            if run.size > 1:
                msp.add_lwpolyline([(ax + s * y[i], ay + s * p[i, 1]) for i in run], dxfattribs={"layer": "PROFILE"})
    msp.add_line((ax, ay - 3.0), (ax, ay + s * h + 3.0), dxfattribs={"layer": "CENTRE_LINES"})
    bore = spec.manufacturing.bore_mm
    if bore > 0:
        for y in (-bore / 2, bore / 2):
            msp.add_line((ax + s * y, ay), (ax + s * y, ay + s * h), dxfattribs={"layer": "HIDDEN"})
    put_text(msp, "SIDE VIEW AT 0°", (ax - s * ro, ay + s * h + 15.0), 2.5, "ANNOTATION",
             "BOTTOM_LEFT", width=s * 2 * ro + MARGINS_MM[2] - 1.0)


def _place(msp, occ, s: float, text: str, options: list[dict]) -> None:
    """A linear dimension at the first of ``options`` where it keeps the layout rule against what ``occ``
    holds (:class:`~camfab.cad.sheet_check.Occupancy`), else at the first (the layout test then names it)."""
    from .drawing import dimension
    from .sheet_check import dimension_parts

    doc = msp.doc
    for kw in options:
        d = dimension(msp, "linear", text, s, **kw)
        quads, segs = dimension_parts(doc, d.dimension)
        if occ.free(quads, segs):
            occ.add(quads, segs)
            return
        block = d.dimension.dxf.geometry
        msp.delete_entity(d.dimension)
        doc.blocks.delete_block(block, safe=False)
    d = dimension(msp, "linear", text, s, **options[0])
    occ.add(*dimension_parts(doc, d.dimension))


def _dimensions(msp, spec, geometry, layout: SheetLayout) -> None:
    """The developed length and the length on the development; the outer Ø, the length, the groove depth and the
    bore on the side view — each with its value as explicit text (:func:`camfab.cad.drawing.dimension`), at the
    first of a few positions where it keeps the layout rule."""
    from .drawing import dim_value
    from .sheet_check import Occupancy

    s, (cx, cy) = layout.scale, layout.centre
    wd, _, h = _views_size(geometry)
    cyl, bore = geometry.cylinder, spec.manufacturing.bore_mm
    ro = cyl.outer_radius_mm
    ax, ay = _side_origin(geometry, layout)
    _, right = _side_outline(geometry, layout)
    (ri, rzm, rzp), (_, _, ozp) = right
    top = ay + s * h
    occ = Occupancy(msp.doc, layout)
    _place(msp, occ, s, dim_value(wd), [dict(base=(cx, cy - 8.0), p1=(cx, cy), p2=(cx + s * wd, cy))])
    _place(msp, occ, s, dim_value(h), [dict(base=(cx - 8.0, cy), p1=(cx, cy), p2=(cx, cy + s * h), angle=90.0)])
    _place(msp, occ, s, dim_value(h), [dict(base=(ax + s * ro + 8.0, ay), p1=(ax + s * ro, ay),
                                            p2=(ax + s * ro, top), angle=90.0)])
    depth = [dict(base=(ax + s * ro, top + k), p1=(ax + s * ri, ay + s * 0.5 * (rzm + rzp)),
                  p2=(ax + s * ro, ay + s * ozp), extra=ex, location=loc)
             for k in (8.0, 5.0) for ex, loc in ((None, None), ({"dimtmove": 1}, (ax + s * ro + 6.0, top + k + 2.0)))]
    _place(msp, occ, s, dim_value(cyl.groove_depth_mm), depth)
    below = (-15.0, -8.0) if bore > 0 else (-8.0,)
    _place(msp, occ, s, f"%%c{dim_value(2 * ro)}", [dict(base=(ax, ay + below[0]), p1=(ax - s * ro, ay),
                                                         p2=(ax + s * ro, ay))])
    if bore > 0:
        text = f"%%c{dim_value(bore)} {spec.drawing.bore_fit}"
        w = text_width(text, load_template()["dimensions"]["text_height_mm"])
        p1, p2 = (ax - s * bore / 2, top), (ax + s * bore / 2, top)
        _place(msp, occ, s, text, [dict(base=(ax, ay - 8.0), p1=(p1[0], ay), p2=(p2[0], ay)),
                                   dict(base=(ax, top + 8.0), p1=p1, p2=p2),
                                   *(dict(base=(ax, ay - 8.0), p1=(p1[0], ay), p2=(p2[0], ay), extra={"dimtmove": 1},
                                          location=loc)
                                     for loc in ((ax + s * ro + 2.0 + w / 2, ay - 4.0), (ax, ay - 21.0)))])


def cylinder_notes(spec, geometry, report, layout: SheetLayout, deviation: float) -> list[str]:
    """The numbered notes of a cylindrical cam's sheet."""
    from .drawing import tolerance_notes, verdict_note

    cyl, mech, f = geometry.cylinder, geometry.mechanism, spec.follower
    m = spec.manufacturing
    sense = "CLOCKWISE" if spec.cam.rotation == "cw" else "COUNTER-CLOCKWISE"
    bore = f"bore Ø{m.bore_mm:g} {spec.drawing.bore_fit}" if m.bore_mm > 0 else "no bore"
    roller = f"roller Ø{2 * mech.roller_radius_mm:g} mm"
    if mech.cone_half_angle_deg is not None:
        roller = f"conical {roller} at the pitch radius (half-angle {mech.cone_half_angle_deg:.4g}°, apex on the axis)"
    if mech.motion.value == "oscillating":
        fol = (f"oscillating {roller}, arm {f.arm_length_mm:g} mm, pivot perpendicular to the axis; lift = arm "
               "angle from the perpendicular to the axis (positive towards +z)")
    else:
        fol = f"{roller} translating parallel to the axis"
    width = 2 * mech.half_width(cyl.radius_mm)
    material = spec.drawing.material or m.material or "to be specified"
    return [
        f"Material: {material}.",
        f"Cylinder Ø{2 * cyl.outer_radius_mm:g} mm, length {cyl.length_mm:g} mm; {bore}.",
        f"Groove {width:g} mm wide (roller Ø + backlash {cyl.backlash_mm:g} mm), {cyl.groove_depth_mm:g} mm deep: "
        f"bottom Ø{2 * cyl.inner_radius_mm:g} mm; pitch radius R = {cyl.radius_mm:g} mm (middle of the depth).",
        *(n.replace("RADIUS column", "Z column") for n in tolerance_notes(spec, SimpleNamespace(
            profile_deviation=[deviation]))),
        f"All dimensions in mm (true size); scale {layout.scale_label}.",
        f"The cam rotates {sense} seen from +z (the end z = {cyl.length_mm:g}).",
        "Development: x = R·θ on the pitch cylinder (cam angle θ from the follower's generator at 0°), z along "
        "the axis from the end z = 0; flanks at half the groove width either side of the pitch curve (chain "
        "line), which the roller's axis follows.",
        f"Follower: {fol}.",
        "Lift table: lift in " + ("degrees of arm rotation" if str(geometry.axis.lift_unit) == "deg" else "mm")
        + "; Z = the roller axis's position along the cylinder's axis on the pitch cylinder (mm).",
        verdict_note(report) + ".",
    ]


def build_cylinder_drawing(spec, geometry, report, *, tol: float, paper: str = "auto",
                           lift_step_deg: float = 10.0):
    """The ezdxf document of :func:`cylinder_drawing_sheet`, its :class:`SheetLayout` and the developed curves'
    measured deviation (mm)."""
    from .drawing import title_fields

    tpl = load_template()
    table = cylinder_lift_table(geometry, lift_step_deg)
    layout = cylinder_layout(geometry, len(table.angle), paper)
    doc, msp = new_document(spec, layout, SimpleNamespace(tol=tol), tpl)
    doc.layers.add("CYLINDER", color=7, linetype="Continuous", lineweight=50)
    title_block(msp, layout, title_fields(spec, report, layout))
    lift_table_block(msp, layout, table, True, third="Z mm")
    dev = _developed_view(msp, geometry, layout, tol)
    notes_column(msp, layout, cylinder_notes(spec, geometry, report, layout, dev))
    _side_view(msp, spec, geometry, layout)
    _dimensions(msp, spec, geometry, layout)
    return doc, layout, dev


def cylinder_drawing_sheet(spec, geometry, report, *, tol: float, paper: str = "auto",
                           lift_step_deg: float = 10.0) -> tuple[str, float]:
    """The drawing sheet of a cylindrical cam as DXF text (deterministic) and the developed curves' measured
    deviation (mm); see the module notes."""
    doc, _, dev = build_cylinder_drawing(spec, geometry, report, tol=tol, paper=paper, lift_step_deg=lift_step_deg)
    return write_deterministic(doc), dev
