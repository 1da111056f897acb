"""Manufacturing drawing sheet (DXF): the cam plate dimensioned on an A4/A3 frame with a title block.

The sheet is drawn in **paper millimetres** in model space: the cam is placed
at a standard scale (ISO 5455: 10:1 … 1:100) with its centre in the middle of
the view area, and every DIMENSION carries ``dimlfac = 1/scale`` so CAD shows
true sizes.  The frame, title block, notes column and lift-table sizes come
from ``templates/drawing/title_block.toml`` (data shipped in the wheel, found by
:mod:`camfab.assets`); the sheet's frame — paper, scale, title block, lift table and notes column —
is drawn by :mod:`camfab.cad.sheet`, the views and notes of the cam here.

Layout (landscape)
------------------
* frame with a 20 mm filing margin; title block in the bottom-right corner;
* a notes column on the left (material, thickness, bore/keyway, tolerance,
  units and scale, rotation sense, zero-angle reference, follower, verdict);
* the lift table on the right above the title block, split into side-by-side
  column groups when it is taller than the space;
* the cam view between them: profile(s) (arc-fitted bulge loops, layer
  ``PROFILE``), bore and keyway (``BORE``), base circle and — for rollers —
  prime circle (for curved faces the face-centre circle R_b + R, clipped to
  the view when the face radius makes it larger; thin phantom/centre lines),
  centre lines and centre mark, a
  0° mark on +Y, a rotation arrow, and DIMENSION entities: base-circle
  diameter, DMAX radius, bore diameter and, with a keyway, its width and the
  ``d + t2`` depth.

A translating (wedge) cam is drawn as its plate in side view instead: the
outline, the S = 0 line, a 0 mark at the travel-0 end, an arrow for the sense
of sliding, and the overall length, the height of the S = 0 line and the
height of the highest point dimensioned; its lift table gives the travel,
the lift and the roller-centre height.

Paper and scale
---------------
``paper="auto"`` tries A4 then A3 and keeps the sheet giving the larger
scale, counting any enlargement beyond 1:1 as 1:1 (so a cam that fits A4 at
1:1 stays on A4, and a large cam moves to A3 rather than shrinking further);
ties go to A4.  On the chosen paper the largest standard scale at which the
cam (plus a dimension clearance) fits the view is used.

The output is deterministic (ezdxf's fixed-metadata mode, as in
:mod:`camfab.cad.dxf`).  The scale and the cam-centre position are recorded
as header custom properties ``CAMFAB_SCALE`` and ``CAMFAB_CENTRE`` so the
true-size geometry can be recovered: ``true = (paper − centre) / scale``.
"""
from __future__ import annotations

import math

import numpy as np

from ..design.drawing import keyway_depth_tolerance
from ..design.kinds import ContactKind, FollowerType
from ..results import Severity, Verdict
from .dxf import write_deterministic
from .groove import is_groove, plate_radius
from .groove_sheet import groove_dimensions, groove_views
from .plate import bore_loop, keyway_size
from .sheet import (
    LAYERS,
    PAPERS,
    SheetLayout,
    clipped_circle,
    lift_table_block,
    load_template,
    new_document,
    notes_column,
    parse_scale,
    place,
    put_text,
    sheet_layout,
    text_width,
    title_block,
)
from .sheet_check import Occupancy, dimension_parts

__all__ = ["PAPERS", "LAYERS", "SheetLayout", "load_template", "sheet_layout", "parse_scale", "drawing_sheet",
           "build_drawing", "title_fields", "notes_text", "dimension", "verdict_note", "tolerance_notes",
           "place_dimension"]


def title_fields(spec, report, layout: SheetLayout) -> dict[str, str]:
    """The values written into the title block, keyed by template field (the texts of ``[drawing]``, made
    safe by :func:`~camfab.cad.sheet.title_block`)."""
    from ..version import __version__

    d = spec.drawing
    return {"name": spec.name, "material": _material(spec), "scale": layout.scale_label, "units": "mm",
            "verdict": report.verdict.value, "date": d.date, "drawn_by": d.drawn_by or f"camfab {__version__}",
            "checked": d.checked_by, "paper": layout.paper, "sheet": "1 / 1", "number": d.number,
            "revision": d.revision, "organisation": d.organisation, "part_number": d.part_number,
            "general_tolerance": f"ISO 2768-{d.general_tolerance}"}


def _material(spec) -> str:
    return spec.drawing.material or spec.manufacturing.material or "to be specified"


def dim_value(v: float) -> str:
    """A dimension's value as written: at most 2 decimals, trailing zeros dropped (``45``, ``13.8``)."""
    t = f"{v:.2f}".rstrip("0").rstrip(".")
    return "0" if t in ("-0", "") else t


def _tolerance_notes(spec, shapes) -> list[str]:
    """The manufacturing notes of ``[drawing]``: general tolerance, profile tolerance, surface finish, and the
    CAD approximation tolerance of the drawn arcs (a property of the file, not a shop tolerance)."""
    d, m = spec.drawing, spec.manufacturing
    dev = max(shapes.profile_deviation) if shapes.profile_deviation else 0.0
    return [
        f"General tolerances ISO 2768-{d.general_tolerance} unless stated.",
        f"Cam profile: every point within ±{d.profile_tolerance_mm:g} mm of the true profile "
        "(lift table, RADIUS column).",
        f"Surface finish of the profile Ra {d.surface_finish_ra_um:g} µm; elsewhere as machined.",
        f"Drawing accuracy: the drawn arcs lie within {dev:.2g} mm of the exact profile "
        f"(CAD approximation tolerance {m.tolerance_mm:g} mm, not a manufacturing tolerance).",
    ]


def _verdict_note(report) -> str:
    errors = [x for x in report.findings if x.severity == Severity.ERROR]
    verdict = f"Check verdict: {report.verdict.value}"
    if errors:
        verdict += " — " + "; ".join(sorted({x.code for x in errors}))
    elif report.verdict == Verdict.NOT_FOR_HIGH_SPEED:
        verdict += " — jerk discontinuity, not for high speeds"
    return verdict


def notes_text(spec, geometry, report, shapes, layout: SheetLayout) -> list[str]:
    """The numbered notes (one string per note)."""
    m, f = spec.manufacturing, spec.follower
    sense = "CLOCKWISE" if spec.cam.rotation == "cw" else "COUNTER-CLOCKWISE"
    d = spec.drawing
    bore = "no bore"
    if m.bore_mm > 0:
        bore = f"bore Ø{m.bore_mm:g} {d.bore_fit}"
        if m.keyway:
            b, t2 = keyway_size(m.bore_mm)
            bore += (f" with hub keyway DIN 6885-1 on +Y: width {b:g} {d.keyway_width_fit}, "
                     f"d + t2 = {m.bore_mm + t2:g} +{keyway_depth_tolerance(m.bore_mm):g}/0 mm")
    c = geometry.profiles[0]
    fol = f"{f.motion} {FollowerType(f.type).title} follower"
    if c.curved_face:
        fol += f", face radius R{c.roller_radius:g} mm"
    elif f.type == FollowerType.ROLLER:
        fol += f", roller Ø{2 * (f.roller_radius_mm or 0.0):g} mm"
    if c.oscillating:
        fol += f", pivot at {f.pivot_distance_mm:g} mm on +X"
        if f.arm_length_mm:
            fol += f", arm {f.arm_length_mm:g} mm"
        if c.curved_face:
            fol += f", face offset {f.face_offset_mm or 0.0:g} mm (pivot to the face's tangent at its vertex)"
    elif c.kind is ContactKind.ROLLER and f.offset_mm:
        fol += f", offset {f.offset_mm:g} mm"
    if c.kind is not ContactKind.ROLLER:
        radius_word = "face distance"
    elif c.curved_face:
        radius_word = "distance of the face's centre of curvature"
    else:
        radius_word = "roller-centre distance (pitch radius)"
    verdict = _verdict_note(report)
    centre = ([f"Face-centre circle (chain line) R{f.base_radius_mm + c.roller_radius:g} mm = base radius + face "
               "radius: the face's centre of curvature lies on it while the follower rests on the base circle."]
              if c.curved_face else [])
    rmax = geometry.max_radius
    plates = (f"{len(geometry.profiles)} cams, CAM 1 drives the first follower, CAM 2 the second; each"
              if len(shapes.profiles) > 1 else "")
    groove = []
    if spec.cam.kind == "groove":  # one plate: the flanks of one groove (camfab.cad.groove)
        from .groove import groove_width_note

        rmax, plates = plate_radius(geometry), "One plate with a face groove (inner flank solid, outer dashed);"
        groove = [f"Groove: {groove_width_note(geometry)} from the front face; outer flank up to R "
                  f"{geometry.radius_extremes(1).max:.3f} mm; R max below is the plate's radius; "
                  "the side view (first-angle) has the front face on its right, the groove hidden."]
    return [
        f"Material: {_material(spec)}.",
        f"{plates or 'Plate'} thickness {m.thickness_mm:g} mm (side view); {bore}.",
        *_tolerance_notes(spec, shapes),
        f"All dimensions in mm (true size); scale {layout.scale_label}.",
        f"The cam rotates {sense} as drawn.",
        "Zero-angle reference: at cam angle 0° the follower axis is +Y (up on this sheet, marked 0°); "
        "the lift table gives the follower lift after the cam has turned by the angle in its sense of rotation.",
        f"Follower: {fol}.",
        f"Base radius R_b = {f.base_radius_mm:g} mm; largest radius R max = {rmax:.3f} mm; "
        f"blank diameter at least Ø max = 2 × R max = {2 * rmax:.3f} mm.",
        *centre,
        *groove,
        f"Lift table: lift in {'degrees of arm rotation' if f.motion == 'oscillating' else 'mm'}; "
        f"RADIUS = {radius_word} from the cam centre (mm).",
        verdict + ".",
    ]


def _dim(msp, kind: str, text: str, s: float, extra: dict | None = None, **kw):
    """A rendered DIMENSION with its value as explicit text (no ``<>``: LibreCAD ignores the per-entity
    ``dimlfac`` and would show the paper length); ``dimlfac = 1/scale`` is still set so that a CAD program
    that re-measures it gets the true size."""
    add = {"linear": msp.add_linear_dim, "diameter": msp.add_diameter_dim, "radius": msp.add_radius_dim}[kind]
    d = add(dimstyle="CAMFAB", override={"dimlfac": 1.0 / s, **(extra or {})}, dxfattribs={"layer": "DIMENSIONS"},
            text=text, **kw)
    d.render()
    return d


def _place(msp, occ: Occupancy, s: float, kind: str, text: str, options: list[dict], force: bool = True) -> bool:
    """The dimension at the first of ``options`` (keyword sets) where it keeps the layout rule against what
    ``occ`` holds; when none does, at the first (``force``: the layout test then names it) or nowhere.
    Returns whether a free position was found."""
    doc = msp.doc
    for kw in options:
        d = _dim(msp, kind, text, s, **kw)
        quads, segs = dimension_parts(doc, d.dimension)
        if occ.free(quads, segs):
            occ.add(quads, segs)
            return True
        block = d.dimension.dxf.geometry
        msp.delete_entity(d.dimension)
        doc.blocks.delete_block(block, safe=False)
    if force:
        d = _dim(msp, kind, text, s, **options[0])
        occ.add(*dimension_parts(doc, d.dimension))
    return False


def _radial_at(centre, deg: float, inner: float, text: str) -> tuple[float, float]:
    """Where a radial dimension's text (written along the radius) goes so that it starts ``inner`` paper mm
    from ``centre`` in the direction ``deg``."""
    d = inner + text_width(text, load_template()["dimensions"]["text_height_mm"]) / 2
    return (centre[0] + d * math.cos(math.radians(deg)), centre[1] + d * math.sin(math.radians(deg)))


def _dimensions(msp, spec, geometry, shapes, layout: SheetLayout, occ: Occupancy) -> None:
    """R max, base circle Ø, bore Ø with its fit, keyway width and depth with their DIN 6885 tolerances, each
    at the first of a few positions where its text crosses no line and no text (``occ``)."""
    s, c = layout.scale, layout.centre
    cx, cy = c
    rb, rmax = spec.follower.base_radius_mm, geometry.max_radius
    reach = _extent(geometry, shapes) * s
    h = load_template()["dimensions"]["text_height_mm"]
    theta, r_at = _rmax_point(geometry)
    text = f"R{dim_value(rmax)}"
    _place(msp, occ, s, "radius", text, [dict(center=c, radius=r_at * s, location=_radial_at(c, theta, reach + k, text))
                                         for k in (2.0, 8.0, 14.0)])
    text = f"%%c{dim_value(2 * rb)}"
    _place(msp, occ, s, "diameter", text, [dict(center=c, radius=rb * s, angle=a,
                                                location=_radial_at(c, a, reach + k, text))
                                           for k in (2.0, 8.0)
                                           for a in (210.0, 330.0, 150.0, 30.0, 240.0, 300.0, 120.0, 60.0)])
    m, d = spec.manufacturing, spec.drawing
    if m.bore_mm <= 0:
        return
    r = m.bore_mm / 2
    text = f"%%c{dim_value(m.bore_mm)} {d.bore_fit}"
    angles = (300.0, 240.0, 330.0, 210.0, 270.0, 285.0, 255.0)
    _place(msp, occ, s, "diameter", text, [dict(center=c, radius=r * s, angle=a, location=_radial_at(c, a, inner, text))
                                           for inner in (r * s + 2.0, reach + 2.0, reach + 8.0) for a in angles])
    if not m.keyway:
        return
    b, t2 = keyway_size(m.bore_mm)
    top = cy + (r + t2) * s
    lead = {"dimtmove": 1}  # a text moved off its dimension line gets a leader
    # the keyseat depth d + t2 and the width b with their DIN 6885 tolerances; where no position is free for
    # that text (a small hub at a reduced scale), the bare value — note 2 gives the tolerances
    tol = f"{dim_value(m.bore_mm + t2)} +{keyway_depth_tolerance(m.bore_mm):g}/0"
    for text in (tol, dim_value(m.bore_mm + t2)):
        w = text_width(text, h)
        options = []
        for side in (-1.0, 1.0):
            xd = cx + side * (r * s + 5.0)
            base = dict(base=(xd, cy), p1=(cx, cy - r * s), p2=(cx + side * b / 2 * s, top), angle=90.0)
            tx = xd - 0.625 - h / 2
            for loc, ex in (((tx, (cy - r * s + top) / 2), None), ((tx, top + 1.5 + w / 2), None),
                            ((tx, cy - r * s - 1.5 - w), None), ((tx, cy + reach + 2.0 + w / 2), lead),
                            ((tx, cy - reach - 2.0 - w), lead)):
                options.append(dict(base, location=loc, extra=ex))
        if _place(msp, occ, s, "linear", text, options, force=text != tol):
            break
    fit = f"{dim_value(b)} {d.keyway_width_fit}"
    up = top + 5.0 + 0.625 + h / 2
    for text in (fit, dim_value(b)):
        w = text_width(text, h)
        options = [dict(base=(cx, top + 5.0), p1=(cx - b / 2 * s, top), p2=(cx + b / 2 * s, top), location=loc,
                        extra=ex)
                   for loc, ex in (((cx + b / 2 * s + 1.5 + w / 2, up), None),
                                   ((cx - b / 2 * s - 1.5 - w, up), None),
                                   *(((cx + sign * (2.0 + w / 2), cy + reach + k), lead) for k in (3.0, 9.0)
                                     for sign in (1.0, -1.0)))]
        if _place(msp, occ, s, "linear", text, options, force=text != fit):
            break


#: public names of the helpers the cylindrical cam's sheet (:mod:`camfab.cad.cylinder_sheet`) shares
dimension, verdict_note, tolerance_notes, place_dimension = _dim, _verdict_note, _tolerance_notes, _place


def _rmax_point(geometry) -> tuple[float, float]:
    """The angle (degrees, sheet frame) and distance of the profile point at R max."""
    ext = geometry.radius_extremes()
    p = geometry.evaluate(np.array([ext.at_max])).point[0]
    return math.degrees(math.atan2(p[1], p[0])), float(np.hypot(*p))


def _rmax_angle(geometry) -> float:
    return _rmax_point(geometry)[0]


def _cam_labels(msp, spec, geometry, shapes, layout: SheetLayout) -> None:
    """Which line is which cam: a legend in the view's top-left corner on conjugate sheets (two plates,
    CAM 2 dashed on its own layer) and on constant-width / constant-diameter sheets (one cam, two
    followers)."""
    x0, _, _, y1 = layout.view
    kind = str(spec.cam.kind)
    if kind == "groove":
        rows = [("PROFILE", "INNER FLANK (groove)"), ("PROFILE_2", "OUTER FLANK (groove)")]
    elif len(shapes.profiles) > 1:
        rows = [("PROFILE", "CAM 1 (first follower)"), ("PROFILE_2", "CAM 2 (second follower)")]
    elif kind in ("constant_width", "constant_diameter"):
        width = spec.follower.width_mm or 0.0
        word = "width" if kind == "constant_width" else "diameter"
        rows = [("PROFILE", "CAM (one profile, two followers"), ("", f"at 0° and 180°, constant {word} {width:g})")]
    else:
        return
    for i, (layer, label) in enumerate(rows):
        y = y1 - 3.0 - 4.5 * i
        if layer:
            msp.add_line((x0, y), (x0 + 8.0, y), dxfattribs={"layer": layer})
        put_text(msp, label, (x0 + 10.0, y), 2.5, "ANNOTATION", "MIDDLE_LEFT", width=layout.view[2] - x0 - 10.0)


def _view(msp, spec, geometry, shapes, layout: SheetLayout) -> None:
    s, (cx, cy) = layout.scale, layout.centre
    f, m = spec.follower, spec.manufacturing
    for i, loop in enumerate(shapes.profiles):
        msp.add_lwpolyline(place(loop, s, (cx, cy)), format="xyseb", close=True,
                           dxfattribs={"layer": "PROFILE" if i == 0 else "PROFILE_2"})
    if m.bore_mm > 0:
        msp.add_lwpolyline(place(bore_loop(m.bore_mm, m.keyway), s, (cx, cy)), format="xyseb", close=True,
                           dxfattribs={"layer": "BORE"})
    msp.add_circle((cx, cy), f.base_radius_mm * s, dxfattribs={"layer": "BASE_CIRCLE"})
    c = geometry.profiles[0]
    if c.curved_face:  # the face-centre circle, as large as the face radius makes it: clipped to the view
        clipped_circle(msp, (cx, cy), (f.base_radius_mm + c.roller_radius) * s, layout.view, "PRIME_CIRCLE")
    elif f.type == FollowerType.ROLLER and f.roller_radius_mm:
        msp.add_circle((cx, cy), (f.base_radius_mm + f.roller_radius_mm) * s, dxfattribs={"layer": "PRIME_CIRCLE"})
    rmax = _extent(geometry, shapes)
    reach = rmax * s + 4.0
    msp.add_line((cx - reach, cy), (cx + reach, cy), dxfattribs={"layer": "CENTRE_LINES"})
    msp.add_line((cx, cy - reach), (cx, cy + reach), dxfattribs={"layer": "CENTRE_LINES"})
    mark = 2.0
    msp.add_line((cx - mark, cy), (cx + mark, cy), dxfattribs={"layer": "CENTRE_MARKS"})
    msp.add_line((cx, cy - mark), (cx, cy + mark), dxfattribs={"layer": "CENTRE_MARKS"})
    put_text(msp, "0°", (cx + 1.0, cy + reach), 2.5, "ANNOTATION", "BOTTOM_LEFT")
    # rotation arrow: an arc at 40°…70° (110°…140° when R max is on the right) with an arrowhead in the sense
    # of rotation
    ra = rmax * s + 6.0
    if c.curved_face and abs((f.base_radius_mm + c.roller_radius) * s - ra) < 6.0:  # clear of the chain line
        ra = (f.base_radius_mm + c.roller_radius) * s + 6.0
    a0 = 110.0 if math.cos(math.radians(_rmax_angle(geometry))) >= -1e-9 else 40.0
    msp.add_arc((cx, cy), ra, a0, a0 + 30.0, dxfattribs={"layer": "ANNOTATION"})
    cw = spec.cam.rotation == "cw"
    tip_deg = a0 if cw else a0 + 30.0
    t = math.radians(tip_deg)
    tip = np.array([cx + ra * math.cos(t), cy + ra * math.sin(t)])
    fwd = np.array([math.sin(t), -math.cos(t)]) * (1 if cw else -1)
    side = np.array([-fwd[1], fwd[0]])
    back = tip - 3.0 * fwd
    msp.add_solid([tuple(tip), tuple(back + 1.0 * side), tuple(back - 1.0 * side)],
                  dxfattribs={"layer": "ANNOTATION"})
    mid = math.radians(a0 + 15.0)
    put_text(msp, "CW" if cw else "CCW", (cx + (ra + 2) * math.cos(mid), cy + (ra + 2) * math.sin(mid)), 2.5,
             "ANNOTATION", "BOTTOM_LEFT" if a0 < 90 else "BOTTOM_RIGHT")


def _extent(geometry, shapes) -> float:
    rim = [plate_radius(geometry)] if is_groove(geometry) else []  # a groove plate's rim lies past its flanks
    return max([float(np.max(np.hypot(*lp.points.T))) for lp in shapes.profiles] + [geometry.max_radius, *rim])


def _side_view(msp, spec, layout: SheetLayout, y_lo: float, y_hi: float, bore: bool) -> None:
    """The plate seen from the side, in ``layout.side`` at the height of the main view (true ``y_lo`` …
    ``y_hi`` about the view's reference ``layout.centre``): its outline, the thickness dimensioned, the bore
    and keyseat as hidden lines and the axis as a centre line."""
    if layout.side is None:
        return
    s, (_, cy) = layout.scale, layout.centre
    m = spec.manufacturing
    x0, _, x1, _ = layout.side
    t = m.thickness_mm * s
    a = (x0 + x1) / 2 - t / 2
    b = a + t
    lo, hi = cy + y_lo * s, cy + y_hi * s
    msp.add_lwpolyline([(a, lo), (b, lo), (b, hi), (a, hi)], close=True, dxfattribs={"layer": "SIDE_VIEW"})
    if bore and m.bore_mm > 0:
        r = m.bore_mm / 2
        ys = [-r, r] + ([r + keyway_size(m.bore_mm)[1]] if m.keyway else [])
        for y in ys:
            msp.add_line((a, cy + y * s), (b, cy + y * s), dxfattribs={"layer": "HIDDEN"})
        msp.add_line((a - 3.0, cy), (b + 3.0, cy), dxfattribs={"layer": "CENTRE_LINES"})
    _dim(msp, "linear", dim_value(m.thickness_mm), s, base=((a + b) / 2, lo - 8.0), p1=(a, lo), p2=(b, lo))


def build_drawing(spec, geometry, report, shapes, *, paper: str = "auto", lift_step_deg: float = 10.0):
    """The ezdxf document of :func:`drawing_sheet` and its :class:`SheetLayout`."""
    from ..design.tables import lift_table

    tpl = load_template()
    if not geometry.closed:
        return _build_plate_drawing(spec, geometry, report, shapes, _plate_table(geometry), paper, tpl)
    table = lift_table(geometry, lift_step_deg)
    extent = _extent(geometry, shapes)
    layout = sheet_layout(extent, len(table.angle), paper, spec.manufacturing.thickness_mm)
    doc, msp = new_document(spec, layout, shapes, tpl)
    title_block(msp, layout, title_fields(spec, report, layout))
    lift_table_block(msp, layout, table, geometry.closed)
    notes_column(msp, layout, notes_text(spec, geometry, report, shapes, layout))
    _view(msp, spec, geometry, shapes, layout)
    _cam_labels(msp, spec, geometry, shapes, layout)
    _, y_lo, _, y_hi = _plate_box(shapes)  # the outline's extent (its arcs bulge past their end points)
    if is_groove(geometry):  # the plate's rim, the groove in the side view (camfab.cad.groove_sheet)
        y_lo, y_hi = -plate_radius(geometry), plate_radius(geometry)
        groove_views(msp, spec, geometry, layout)
    _side_view(msp, spec, layout, y_lo, y_hi, True)
    _dimensions(msp, spec, geometry, shapes, layout, Occupancy(doc, layout))
    if is_groove(geometry):
        groove_dimensions(msp, spec, geometry, layout)
    return doc, layout


# ---------------------------------------------------------------------------
# translating (wedge) cams: the plate in side view
def _plate_table_intervals(length: float, most: int = 40) -> int:
    """Rows of a translating cam's lift table: the finest round step (1, 2, 2.5, 5 × 10^k mm) that divides
    the cam length into at most ``most`` intervals (36 equal intervals when none does)."""
    for k in range(-2, 6):
        for m in (1.0, 2.0, 2.5, 5.0):
            n = length / (m * 10.0**k)
            if n <= most and abs(n - round(n)) < 1e-9 * n:
                return int(round(n))
    return 36


def _plate_table(geometry):
    """A translating cam's lift table over its whole length: the rows of
    :func:`~camfab.design.tables.lift_table` and the end of the plate (travel = length)."""
    from ..design.tables import LiftTable, lift_table

    t = lift_table(geometry, 360.0 / _plate_table_intervals(geometry.period))
    c = geometry.profiles[0]
    x = np.array([geometry.period])
    lift = c.motion.evaluate(x, (0,))[0]
    height = c.evaluate(x).pitch[:, 1]
    return LiftTable(np.append(t.angle, geometry.to_user(x)), np.append(t.lift, lift), np.append(t.radius, height),
                     t.lift_unit, t.radius_label)


def _plate_box(shapes) -> tuple[float, float, float, float]:
    pts = np.concatenate([lp.flatten(1e-3) for lp in shapes.profiles])
    return float(pts[:, 0].min()), float(pts[:, 1].min()), float(pts[:, 0].max()), float(pts[:, 1].max())


def _build_plate_drawing(spec, geometry, report, shapes, table, paper, tpl):
    from dataclasses import replace

    x0, y0, x1, y1 = _plate_box(shapes)
    layout = sheet_layout(((x1 - x0) / 2, (y1 - y0) / 2), len(table.angle), paper, spec.manufacturing.thickness_mm)
    vx0, vy0, vx1, vy1 = layout.view
    s = layout.scale
    # the true origin (bottom edge, travel 0 end) lands so that the plate's box is centred in the view
    layout = replace(layout, centre=((vx0 + vx1) / 2 - s * (x0 + x1) / 2, (vy0 + vy1) / 2 - s * (y0 + y1) / 2))
    doc, msp = new_document(spec, layout, shapes, tpl)
    title_block(msp, layout, title_fields(spec, report, layout))
    lift_table_block(msp, layout, table, geometry.closed)
    notes_column(msp, layout, plate_notes(spec, geometry, report, shapes, layout))
    _plate_view(msp, spec, geometry, shapes, layout, (x0, y0, x1, y1))
    _side_view(msp, spec, layout, y0, y1, False)
    return doc, layout


def plate_notes(spec, geometry, report, shapes, layout: SheetLayout) -> list[str]:
    """The numbered notes of a translating cam's sheet."""
    m, f = spec.manufacturing, spec.follower
    c = geometry.profiles[0]
    top = geometry.radius_extremes().max
    slide = "LEFT" if spec.cam.direction == "left" else "RIGHT"
    start = "left" if spec.cam.direction == "left" else "right"
    verdict = _verdict_note(report)
    return [
        f"Material: {_material(spec)}.",
        f"Plate thickness {m.thickness_mm:g} mm (side view); length {c.period:g} mm; no bore (sliding plate).",
        *_tolerance_notes(spec, shapes),
        f"All dimensions in mm (true size); scale {layout.scale_label}.",
        f"The cam slides {slide} as drawn; travel 0 is at its {start} end (marked 0), where the follower "
        "starts; the lift table gives the follower lift after the cam has travelled the given distance.",
        f"Follower: translating roller Ø{2 * (f.roller_radius_mm or 0.0):g} mm, moving perpendicular to the "
        "bottom edge.",
        f"The S = 0 line lies {f.base_height_mm:g} mm above the bottom edge; highest point of the profile "
        f"{top:.3f} mm.",
        "Lift table: lift in mm; HEIGHT = roller-centre height above the bottom edge (mm).",
        verdict + ".",
    ]


def _plate_view(msp, spec, geometry, shapes, layout: SheetLayout, box) -> None:
    s, (cx, cy) = layout.scale, layout.centre
    x0, y0, x1, y1 = box
    f = spec.follower
    c = geometry.profiles[0]

    def at(x, y):
        return (cx + s * x, cy + s * y)

    for loop in shapes.profiles:
        msp.add_lwpolyline(place(loop, s, (cx, cy)), format="xyseb", close=True, dxfattribs={"layer": "PROFILE"})
    h = f.base_height_mm
    msp.add_line(at(x0, h), at(x1, h), dxfattribs={"layer": "BASE_CIRCLE"})  # the S = 0 line
    # the label sits on the S = 0 line's extension, between the plate and the dimension of its height
    put_text(msp, "S=0", (at(x0, h)[0] - 0.5, at(x0, h)[1] + 0.5), 1.8, "ANNOTATION", "BOTTOM_RIGHT")
    left = spec.cam.direction == "left"
    zero = x0 if left else x1
    put_text(msp, "0", (at(zero, y1)[0], at(zero, y1)[1] + 2.0), 2.5, "ANNOTATION", "BOTTOM_CENTER")
    # direction of travel: an arrow above the plate
    ya = at(0.0, y1)[1] + 8.0
    xa0, xa1 = at(x0 + 0.35 * (x1 - x0), 0)[0], at(x0 + 0.65 * (x1 - x0), 0)[0]
    tip, tail = (xa0, xa1) if left else (xa1, xa0)
    msp.add_line((tail, ya), (tip, ya), dxfattribs={"layer": "ANNOTATION"})
    d = 3.0 if tip < tail else -3.0
    msp.add_solid([(tip, ya), (tip + d, ya + 1.0), (tip + d, ya - 1.0)], dxfattribs={"layer": "ANNOTATION"})
    put_text(msp, f"CAM SLIDES {'LEFT' if left else 'RIGHT'}", ((xa0 + xa1) / 2, ya + 2.0), 2.5, "ANNOTATION",
          "BOTTOM_CENTER")
    dims = [  # overall length under the plate; S = 0 height at the left end; highest point at the right end
        (c.period, dict(base=(at(x0, y0)[0], at(x0, y0)[1] - 8.0), p1=at(x0, y0), p2=at(x1, y0))),
        (h - y0, dict(base=(at(x0, 0)[0] - 8.0, at(x0, 0)[1]), p1=at(x0, y0), p2=at(x0, h), angle=90.0)),
        (y1 - y0, dict(base=(at(x1, 0)[0] + 8.0, at(x1, 0)[1]), p1=at(x1, y0), p2=at(_x_of_top(geometry), y1),
                       angle=90.0)),
    ]
    for value, kw in dims:
        _dim(msp, "linear", dim_value(value), s, **kw)


def _x_of_top(geometry) -> float:
    ext = geometry.radius_extremes()
    return float(geometry.evaluate(np.array([ext.at_max])).point[0, 0])


def drawing_sheet(spec, geometry, report, shapes, *, paper: str = "auto", lift_step_deg: float = 10.0) -> str:
    """A dimensioned manufacturing drawing of the cam plate as DXF text (deterministic).

    Parameters
    ----------
    spec : DesignSpec
    geometry : CamGeometry
        A disc cam, or a translating cam (drawn as its plate in side view, with the overall
        length, the height of the S = 0 line and of the highest point dimensioned).
    report : Report
        From :func:`camfab.design.assemble.check_design` (its verdict goes into the title block).
    shapes : CamShapes
        From :func:`camfab.cad.export.cam_shapes`; its arc-fitted ``profiles`` are drawn.
    paper : {"auto", "A4", "A3"}
    lift_step_deg : float
        Step of the lift table (degrees, must divide 360).  A translating cam's table uses the
        finest round step in mm (1, 2, 2.5, 5 × 10^k) giving at most 40 rows.

    Returns
    -------
    str
        DXF R2010 text, millimetre units, byte-identical for the same input.

    Raises
    ------
    GeometryError
        A translating cam whose plate cannot be built (e.g. no height under the profile).
    ValueError
        An unknown paper.
    SpecError
        A lift step that does not divide 360.
    """
    doc, _ = build_drawing(spec, geometry, report, shapes, paper=paper, lift_step_deg=lift_step_deg)
    return write_deterministic(doc)
