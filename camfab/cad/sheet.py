"""The drawing sheet's frame: paper and scale, layers, the title block, the lift table and the notes column.

Sizes come from the title-block template ``templates/drawing/title_block.toml`` (shipped in the wheel, found
by :mod:`camfab.assets`).  Everything is in paper millimetres, origin at the sheet's lower-left corner;
:mod:`camfab.cad.drawing` places the cam's views and notes in the boxes of a :class:`SheetLayout`.
"""
from __future__ import annotations

import functools
import math
import tomllib
from dataclasses import dataclass
from typing import Any, cast

import numpy as np

from ..assets import read_template
from ..errors import ExportError, InputError
from ..geom2d import ArcChain
from ..textsafe import dxf_mtext, dxf_string, dxf_text
from .dxf import ezdxf_module

__all__ = ["PAPERS", "LAYERS", "SheetLayout", "load_template", "parse_scale", "sheet_layout", "put_text", "rect",
           "place", "fmt", "title_block", "lift_table_block", "notes_column", "clipped_circle", "new_document",
           "text_width", "wrap", "NOTE_PITCH", "SheetItems", "sheet_items", "layout_problems", "Occupancy",
           "dimension_parts", "REFERENCE_LAYERS"]

PAPERS = ("A4", "A3")


#: layer -> (ACI colour, linetype, lineweight in 1/100 mm)
LAYERS = {
    "FRAME": (7, "Continuous", 70), "TITLE_BLOCK": (7, "Continuous", 35), "PROFILE": (7, "Continuous", 50),
    "BORE": (7, "Continuous", 50), "BASE_CIRCLE": (3, "PHANTOM", 18), "PRIME_CIRCLE": (1, "CENTER", 18),
    "CENTRE_LINES": (8, "CENTER", 18), "CENTRE_MARKS": (8, "Continuous", 18), "DIMENSIONS": (4, "Continuous", 18),
    "LIFT_TABLE": (7, "Continuous", 25), "NOTES": (7, "Continuous", 25), "ANNOTATION": (6, "Continuous", 25),
    "PROFILE_2": (5, "DASHED", 50), "HIDDEN": (7, "DASHED2", 25), "SIDE_VIEW": (7, "Continuous", 50),
}


@functools.lru_cache(maxsize=1)
def load_template() -> dict[str, Any]:
    """The title-block template (``templates/drawing/title_block.toml``) as a dict."""
    text = read_template("drawing", "title_block.toml")
    return tomllib.loads(text)


def parse_scale(label: str) -> float:
    """``"1:2"`` → 0.5, ``"2:1"`` → 2.0 (drawing length per true length)."""
    a, b = label.split(":")
    return float(a) / float(b)


@dataclass(frozen=True)
class SheetLayout:
    """Where everything goes on the sheet (paper mm, origin at the sheet's lower-left corner).

    Boxes are ``(x0, y0, x1, y1)``.  ``fits`` is False when even the smallest
    scale does not fit the view (the cam is then drawn at that scale anyway).  ``side`` is the box of
    the side view (the plate's thickness), to the right of ``view``, when one was asked for.
    """

    paper: str
    size: tuple[float, float]
    scale: float
    scale_label: str
    centre: tuple[float, float]
    frame: tuple[float, float, float, float]
    title: tuple[float, float, float, float]
    table: tuple[float, float, float, float]
    table_groups: int
    table_rows: int
    notes: tuple[float, float, float, float]
    view: tuple[float, float, float, float]
    fits: bool
    side: tuple[float, float, float, float] | None = None


def _layout_on(paper: str, extent_mm: float | tuple[float, float], n_rows: int, tpl: dict[str, Any],
               thickness_mm: float | None = None) -> SheetLayout:
    w, h = tpl["paper"][paper]["width_mm"], tpl["paper"][paper]["height_mm"]
    fr, gap = tpl["frame"], tpl["frame"]["gap_mm"]
    fx0, fy0, fx1, fy1 = fr["left_mm"], fr["bottom_mm"], w - fr["right_mm"], h - fr["top_mm"]
    tb = tpl["title_block"]
    title = (fx1 - tb["width_mm"], fy0, fx1, fy0 + tb["height_mm"])
    lt = tpl["lift_table"]
    rh, colw = lt["row_height_mm"], sum(lt["column_widths_mm"])
    avail = fy1 - title[3] - gap
    per_group = max(1, int(math.floor(avail / rh - 2.5)))
    groups = max(1, math.ceil(n_rows / per_group))
    rows = math.ceil(n_rows / groups)
    table = (fx1 - groups * colw, fy1 - (rows + 2.5) * rh, fx1, fy1)
    notes = (fx0, fy0, fx0 + tpl["notes"]["width_mm"], fy1)
    area = (notes[2] + gap, title[3] + gap, table[0] - gap, fy1)
    clear, side_gap, side_pad = tpl["view"]["clearance_mm"], tpl["view"]["side_gap_mm"], tpl["view"]["side_pad_mm"]
    half_w, half_h = (cast(float, extent_mm),) * 2 if np.isscalar(extent_mm) else cast(tuple[float, float], extent_mm)
    labels = tpl["view"]["scales"]

    def boxes(scale: float):
        """The cam view and the side view in the area at ``scale``."""
        if thickness_mm is None:
            return area, None
        sw = thickness_mm * scale + 2 * side_pad
        split = area[2] - sw
        return (area[0], area[1], split - side_gap, area[3]), (split, area[1], area[2], area[3])

    def fits(scale: float) -> bool:
        view, _ = boxes(scale)
        room_w, room_h = (view[2] - view[0]) / 2 - clear, (view[3] - view[1]) / 2 - clear
        if np.isscalar(extent_mm):  # a disc cam: a circle of radius extent in the square part of the view
            room_w = room_h = min(room_w, room_h)
        return half_w * scale <= room_w and half_h * scale <= room_h

    good = [s for s in labels if fits(parse_scale(s))]
    label = good[0] if good else labels[-1]
    view, side = boxes(parse_scale(label))
    centre = ((view[0] + view[2]) / 2, (view[1] + view[3]) / 2)
    return SheetLayout(paper, (w, h), parse_scale(label), label, centre, (fx0, fy0, fx1, fy1), title, table,
                       groups, rows, notes, view, bool(good), side)


def sheet_layout(extent_mm: float | tuple[float, float], n_rows: int, paper: str = "auto",
                 thickness_mm: float | None = None) -> SheetLayout:
    """Choose paper and scale for a cam of outer radius ``extent_mm`` and a lift table of ``n_rows`` rows.

    Parameters
    ----------
    extent_mm : float or (float, float)
        Largest distance of the cam outline from its centre (true mm), or the half width and
        half height of a translating cam's plate.
    n_rows : int
        Data rows of the lift table.
    paper : {"auto", "A4", "A3"}
    thickness_mm : float, optional
        The plate thickness (true mm): a side view this wide (at the sheet's scale) is kept to the
        right of the cam view.

    Raises
    ------
    InputError
        An unknown paper name (a ``ValueError``).
    """
    if paper != "auto" and paper not in PAPERS:
        raise InputError(f"'{paper}' is not a valid paper, must be one of: auto, {', '.join(PAPERS)}")
    tpl = load_template()
    if paper != "auto":
        return _layout_on(paper, extent_mm, n_rows, tpl, thickness_mm)
    options = [_layout_on(p, extent_mm, n_rows, tpl, thickness_mm) for p in PAPERS]
    return max(options, key=lambda lay: (lay.fits, min(lay.scale, 1.0), -PAPERS.index(lay.paper)))


def put_text(msp, text: str, at, height: float, layer: str, align: str = "BOTTOM_LEFT", width: float | None = None):
    """A TEXT entity at ``at`` (paper mm), shrunk to fit ``width`` when one is given (never below 1 mm)."""
    from ezdxf.enums import TextEntityAlignment

    if width is not None and text:
        height = max(1.0, min(height, width / text_width(text, 1.0)))
    t = msp.add_text(text, height=height, dxfattribs={"layer": layer})
    t.set_placement((float(at[0]), float(at[1])), align=TextEntityAlignment[align])
    return t


def text_width(text: str, height: float) -> float:
    """A conservative width (paper mm) of ``text`` at ``height``: at least what LibreCAD's ISO 3098 stroke
    font takes (lower case and digits ``width_factor`` × height, capitals 1.0, W M % Ø 1.25, a space 0.75),
    wider than the TrueType fonts of other viewers.  DXF special codes count as the character they show."""
    lower = load_template()["text"]["width_factor"]
    text = text.replace("%%c", "Ø").replace("%%C", "Ø").replace("%%d", "°").replace("%%p", "±")
    total = 0.0
    for c in text:
        if c in "WM%Ø@":
            total += 1.25
        elif c == " ":
            total += 0.75
        elif c.isupper():
            total += 1.0
        else:
            total += lower
    return total * height


def wrap(text: str, width: float, height: float, indent: str = "") -> list[str]:
    """``text`` broken at spaces into lines no wider than ``width`` (paper mm, by :func:`text_width` at
    ``height``); continuation lines start with ``indent``; a word longer than a line is cut."""
    lines: list[str] = []
    line = ""
    for word in text.split(" "):
        trial = f"{line} {word}" if line else (indent if lines else "") + word
        if text_width(trial, height) <= width:
            line = trial
            continue
        if line:
            lines.append(line)
        line = (indent if lines else "") + word
        while text_width(line, height) > width and len(line) > len(indent) + 1:  # a very long word: cut it
            cut = len(line) - 1
            while cut > len(indent) + 1 and text_width(line[:cut], height) > width:
                cut -= 1
            lines.append(line[:cut])
            line = indent + line[cut:]
    if line:
        lines.append(line)
    return lines


def rect(msp, box, layer: str) -> None:
    """A closed rectangle over the box ``(x0, y0, x1, y1)``."""
    x0, y0, x1, y1 = box
    msp.add_lwpolyline([(x0, y0), (x1, y0), (x1, y1), (x0, y1)], close=True, dxfattribs={"layer": layer})


def place(loop: ArcChain, scale: float, centre) -> list[tuple[float, float, float, float, float]]:
    """An arc chain scaled about the origin and moved to ``centre``, as LWPOLYLINE ``xyseb`` vertices."""
    pts = loop.points * scale + np.asarray(centre)
    return [(float(x), float(y), 0.0, 0.0, float(b)) for (x, y), b in zip(pts, loop.bulges, strict=True)]


def fmt(v: float, dec: int = 3) -> str:
    """``v`` with ``dec`` decimals, without a minus sign on a value that rounds to zero."""
    s = f"{v:.{dec}f}"
    return s[1:] if s.startswith("-") and float(s) == 0 else s


def title_block(msp, layout: SheetLayout, fields: dict[str, str]) -> None:
    """The title block's cells from the template, filled with ``fields`` (an unknown template field is an
    :class:`~camfab.errors.ExportError`)."""
    tpl = load_template()
    x0, y0, x1, y1 = layout.title
    rect(msp, layout.title, "TITLE_BLOCK")
    th = tpl["text"]
    for cell in tpl["title_block"]["cells"]:
        if cell["field"] not in fields:
            raise ExportError(f"title-block template field '{cell['field']}' is unknown; "
                              f"use one of: {', '.join(fields)}")
        cx, cy = x0 + cell["x_mm"], y0 + cell["y_mm"]
        cw, ch = cell["width_mm"], cell["height_mm"]
        rect(msp, (cx, cy, cx + cw, cy + ch), "TITLE_BLOCK")
        put_text(msp, cell["label"], (cx + 1.0, cy + ch - 1.0), th["label_height_mm"], "TITLE_BLOCK", "TOP_LEFT",
                 width=cw - 2.0)
        value = fields[cell["field"]]
        if value:
            h = th["title_height_mm"] if cell.get("large") else th["value_height_mm"]
            put_text(msp, dxf_text(value), (cx + 1.5, cy + 1.5), h, "TITLE_BLOCK", "BOTTOM_LEFT", width=cw - 3.0)


def lift_table_block(msp, layout: SheetLayout, table, closed: bool) -> None:
    """The lift table in ``layout.table``, split into side-by-side column groups when it is tall."""
    tpl = load_template()["lift_table"]
    rh, widths, h = tpl["row_height_mm"], tpl["column_widths_mm"], tpl["text_height_mm"]
    x0, y0, x1, y1 = layout.table
    rect(msp, layout.table, "LIFT_TABLE")
    step = float(table.angle[1] - table.angle[0]) if len(table.angle) > 1 else 360.0
    unit = "°" if table.lift_unit == "deg" else "mm"
    put_text(msp, f"LIFT TABLE (step {step:g}{'°' if closed else ' mm'})", ((x0 + x1) / 2, y1 - 0.75 * rh),
          h, "LIFT_TABLE", "MIDDLE_CENTER", width=x1 - x0 - 2)
    msp.add_line((x0, y1 - 1.5 * rh), (x1, y1 - 1.5 * rh), dxfattribs={"layer": "LIFT_TABLE"})
    heads = ("ANGLE °" if closed else "TRAVEL mm", f"LIFT {unit}", "RADIUS mm" if closed else "HEIGHT mm")
    gw = sum(widths)
    lift_dec = 4 if table.lift_unit == "deg" else 3
    for g in range(layout.table_groups):
        gx = x0 + g * gw
        if g:
            msp.add_line((gx, y0), (gx, y1 - 1.5 * rh), dxfattribs={"layer": "LIFT_TABLE"})
        xs = np.cumsum([gx] + list(widths))
        for k in range(1, 3):
            msp.add_line((xs[k], y0), (xs[k], y1 - 1.5 * rh), dxfattribs={"layer": "LIFT_TABLE"})
        ytop = y1 - 1.5 * rh
        for k, text in enumerate(heads):
            put_text(msp, text, ((xs[k] + xs[k + 1]) / 2, ytop - rh / 2), h, "LIFT_TABLE", "MIDDLE_CENTER",
                  width=widths[k] - 1)
        msp.add_line((gx, ytop - rh), (gx + gw, ytop - rh), dxfattribs={"layer": "LIFT_TABLE"})
        rows = range(g * layout.table_rows, min(len(table.angle), (g + 1) * layout.table_rows))
        for j, i in enumerate(rows):
            yc = ytop - rh * (j + 1.5)
            vals = (f"{table.angle[i]:g}", fmt(table.lift[i], lift_dec), fmt(table.radius[i]))
            for k, text in enumerate(vals):
                put_text(msp, text, ((xs[k] + xs[k + 1]) / 2, yc), h, "LIFT_TABLE", "MIDDLE_CENTER",
                      width=widths[k] - 1)


#: MTEXT line spacing: the factor written, and the pitch (× text height) a box of the notes assumes (AutoCAD
#: draws 5/3 × height × factor; LibreCAD less)
NOTE_SPACING = 1.0
NOTE_PITCH = 5.0 / 3.0 * NOTE_SPACING


def notes_column(msp, layout: SheetLayout, notes: list[str]) -> tuple[float, float, float, float]:
    """The numbered notes in the left column, each wrapped to the column by :func:`wrap` and written with
    explicit ``\\P`` line breaks (a viewer that does not wrap MTEXT shows the same lines); returns the box of
    the text."""
    tpl = load_template()["notes"]
    x0, y0, x1, y1 = layout.notes
    h = tpl["text_height_mm"]
    put_text(msp, "NOTES", (x0 + 2, y1 - 2), 3.5, "NOTES", "TOP_LEFT")
    width = x1 - x0 - 4
    lines: list[str] = []
    for i, n in enumerate(notes, 1):
        lines += wrap(f"{i}. {n}", width, h, indent="    ")
    body = "\\P".join(dxf_mtext(line) for line in lines)  # a note is text, never codes
    mt = msp.add_mtext(body, dxfattribs={"layer": "NOTES", "char_height": h, "width": width,
                                         "insert": (x0 + 2, y1 - 8), "attachment_point": 1})
    mt.dxf.line_spacing_factor = NOTE_SPACING
    return (x0 + 2, y1 - 8 - len(lines) * h * NOTE_PITCH, x0 + 2 + width, y1 - 8)


def _dimstyle(doc, tpl) -> None:
    d = tpl["dimensions"]
    doc.dimstyles.new("CAMFAB", dxfattribs={
        "dimtxt": d["text_height_mm"], "dimasz": d["arrow_size_mm"], "dimexe": 1.25, "dimexo": 0.625,
        "dimgap": 0.625, "dimdec": d["decimals"], "dimtxsty": "Standard", "dimzin": 8, "dimdsep": ord("."),
        "dimtad": 1, "dimtih": 0, "dimtoh": 0, "dimtofl": 1, "dimclrd": 4, "dimclre": 4, "dimclrt": 4})


def clipped_circle(msp, centre, r: float, box, layer: str) -> None:
    """A circle of radius ``r`` (paper mm) about ``centre``, drawn whole when it fits the box (x0, y0, x1, y1)
    and otherwise as the arcs of it inside the box."""
    cx, cy = centre
    x0, y0, x1, y1 = box
    hw, hh = min(cx - x0, x1 - cx), min(cy - y0, y1 - cy)
    if r <= min(hw, hh):
        msp.add_circle((cx, cy), r, dxfattribs={"layer": layer})
        return
    # inside where |cos t| ≤ hw/r and |sin t| ≤ hh/r: four arcs symmetric about the axes
    a, b = math.degrees(math.acos(min(1.0, hw / r))), math.degrees(math.asin(min(1.0, hh / r)))
    if a >= b:
        return
    for start, end in ((a, b), (180.0 - b, 180.0 - a), (180.0 + a, 180.0 + b), (360.0 - b, 360.0 - a)):
        msp.add_arc((cx, cy), r, start, end, dxfattribs={"layer": layer})


def new_document(spec, layout: SheetLayout, shapes, tpl):
    """A new R2010 document with the header values, layers, dimension style and frame of the sheet; returns
    ``(doc, modelspace)``."""
    ezdxf = ezdxf_module()
    doc = ezdxf.new("R2010", setup=["linetypes"], units=4)
    doc.header["$INSUNITS"] = 4
    doc.header["$MEASUREMENT"] = 1
    doc.header["$LTSCALE"] = 1.0
    doc.header["$LWDISPLAY"] = 1
    # ezdxf writes the header's extents and limits from the model space's layout record: set them there
    msp = doc.modelspace()
    msp.dxf.extmin = (0.0, 0.0, 0.0)
    msp.dxf.extmax = (layout.size[0], layout.size[1], 0.0)
    msp.dxf.limmin = (0.0, 0.0)
    msp.dxf.limmax = layout.size
    doc.header["$EXTMIN"] = (0.0, 0.0, 0.0)  # (ezdxf keeps these when the layout's extents start at 0, 0, 0)
    doc.header["$EXTMAX"] = (layout.size[0], layout.size[1], 0.0)
    doc.header.custom_vars.append("CAMFAB_NAME", dxf_string(spec.name))
    doc.header.custom_vars.append("CAMFAB_PAPER", layout.paper)
    doc.header.custom_vars.append("CAMFAB_SCALE", f"{layout.scale!r}")
    doc.header.custom_vars.append("CAMFAB_CENTRE", f"{layout.centre[0]!r},{layout.centre[1]!r}")
    doc.header.custom_vars.append("CAMFAB_TOL_MM", f"{shapes.tol:g}")
    for name, (colour, ltype, lw) in LAYERS.items():
        doc.layers.add(name, color=colour, linetype=ltype, lineweight=lw)
    _dimstyle(doc, tpl)
    msp = doc.modelspace()
    rect(msp, (0.0, 0.0, *layout.size), "FRAME")
    rect(msp, layout.frame, "FRAME")
    return doc, msp


# ---------------------------------------------------------------------------
# the layout rule, checked on the written sheet: boxes of every text, table, view and title block
_GROUP_OF_LAYER = {"TITLE_BLOCK": "title", "LIFT_TABLE": "table", "NOTES": "notes"}
#: thin reference circles (base circle, prime or face-centre circle) that may pass behind a text; a face-centre
#: circle can be larger than the cam, and a small base circle runs close round the bore's texts
REFERENCE_LAYERS = ("BASE_CIRCLE", "PRIME_CIRCLE")
_HALIGN = {"LEFT": 0.0, "CENTER": 0.5, "MIDDLE": 0.5, "RIGHT": 1.0, "ALIGNED": 0.0, "FIT": 0.0}


@dataclass(frozen=True)
class SheetItems:
    """What lies on a sheet, in paper mm: the text boxes and line segments with their group (``title``,
    ``table``, ``notes``, ``view``, ``side``) and owner (the handle of the DIMENSION they belong to, else
    ``""``)."""

    texts: list[tuple[str, str, str, np.ndarray]]  # (text, group, owner, corners (4, 2) of its box)
    segments: np.ndarray  # (n, 4) x0, y0, x1, y1
    seg_group: list[str]
    seg_owner: list[str]
    seg_reference: np.ndarray  # (n,) bool: on a layer of REFERENCE_LAYERS


def _rotated_box(x: float, y: float, local: tuple[float, float, float, float], deg: float) -> np.ndarray:
    """The corners (4, 2) of the box ``local`` = (u0, v0, u1, v1) turned by ``deg`` about (0, 0) and moved to
    (x, y)."""
    a = math.radians(deg)
    c, s = math.cos(a), math.sin(a)
    u0, v0, u1, v1 = local
    uv = np.array([(u0, v0), (u1, v0), (u1, v1), (u0, v1)])
    return np.column_stack([x + uv[:, 0] * c - uv[:, 1] * s, y + uv[:, 0] * s + uv[:, 1] * c])


def _text_box(e) -> tuple[str, np.ndarray]:
    """A TEXT's or MTEXT's text and its conservative box (:func:`text_width`; TEXT from the baseline less a
    quarter height for descenders to the cap height; MTEXT lines at :data:`NOTE_PITCH`)."""
    if e.dxftype() == "TEXT":
        align, p1, p2 = e.get_placement()
        h = e.dxf.height
        w = text_width(e.dxf.text, h)
        name = align.name  # e.g. MIDDLE_CENTER, BOTTOM_LEFT, LEFT
        v, _, hname = name.partition("_") if "_" in name else ("BASELINE", "", name)
        at = p1 if name in ("LEFT",) else (p2 if p2 is not None else p1)
        u0 = -_HALIGN.get(hname, 0.0) * w
        v0 = {"TOP": -h, "MIDDLE": -h / 2, "BOTTOM": -0.25 * h}.get(v, -0.25 * h)
        v1 = {"TOP": 0.0, "MIDDLE": h / 2}.get(v, h)
        return e.dxf.text, _rotated_box(at[0], at[1], (u0, v0, u0 + w, v1), e.dxf.rotation)
    lines = e.text.split("\\P")
    h = e.dxf.char_height
    w, tall = max(text_width(line, h) for line in lines), h + (len(lines) - 1) * h * NOTE_PITCH
    ap = e.dxf.attachment_point
    u0 = -w * ((ap - 1) % 3) / 2
    v1 = {0: 0.0, 1: tall / 2, 2: tall}[(ap - 1) // 3]
    direction = e.dxf.get("rotation", 0.0)
    if e.dxf.hasattr("text_direction"):
        d = e.dxf.text_direction
        direction = math.degrees(math.atan2(d[1], d[0]))
    x, y = e.dxf.insert[0], e.dxf.insert[1]
    return e.text, _rotated_box(x, y, (u0, v1 - tall, u0 + w, v1), direction)


def _segments(e, flat: float = 0.05) -> list[tuple[float, float, float, float]]:
    from ezdxf import path as ezpath

    kind = e.dxftype()
    if kind == "INSERT":
        return [s for v in e.virtual_entities() for s in _segments(v, flat)]
    if kind not in ("LINE", "LWPOLYLINE", "ARC", "CIRCLE", "SOLID"):
        return []
    pts = [(p.x, p.y) for p in ezpath.make_path(e).flattening(flat)]
    return [(a[0], a[1], b[0], b[1]) for a, b in zip(pts[:-1], pts[1:], strict=True)]


def sheet_items(doc, layout: SheetLayout) -> SheetItems:
    """Every text box and line segment of a sheet (the frame excepted), grouped: by layer for the title
    block, lift table and notes, by position for the side view (right of ``layout.side``'s left edge),
    the rest is the cam view; a DIMENSION's lines and text are owned by it."""
    texts, segs, groups, owners, refs = [], [], [], [], []

    def group_of(e, x: float) -> str:
        g = _GROUP_OF_LAYER.get(e.dxf.layer)
        if g:
            return g
        return "side" if layout.side is not None and x >= layout.side[0] else "view"

    for e in doc.modelspace():
        if e.dxf.layer == "FRAME" or e.dxftype() == "POINT":
            continue
        if e.dxftype() == "DIMENSION":
            block = doc.blocks.get(e.dxf.geometry)
            lines = [s for t in block for s in _segments(t)]
            x = min(s[0] for s in lines)
            g = group_of(e, x)
            for text, box in _dimension_quads(doc, e):
                texts.append((text, g, e.dxf.handle, box))
            segs += lines
            groups += [g] * len(lines)
            owners += [e.dxf.handle] * len(lines)
            refs += [False] * len(lines)
        elif e.dxftype() in ("TEXT", "MTEXT"):
            text, box = _text_box(e)
            texts.append((text, group_of(e, float(box[:, 0].min())), "", box))
        else:
            lines = _segments(e)
            if lines:
                g = group_of(e, min(min(s[0], s[2]) for s in lines))
                segs += lines
                groups += [g] * len(lines)
                owners += [""] * len(lines)
                refs += [e.dxf.layer in REFERENCE_LAYERS] * len(lines)
    return SheetItems(texts, np.array(segs, dtype=float).reshape(-1, 4), groups, owners, np.array(refs, dtype=bool))


def _axes(quad: np.ndarray) -> np.ndarray:
    """The two edge normals of a box given by its corners (4, 2)."""
    e = np.array([quad[1] - quad[0], quad[3] - quad[0]])
    return np.column_stack([-e[:, 1], e[:, 0]])


def _crosses(quad: np.ndarray, seg: np.ndarray, eps: float = 0.05) -> np.ndarray:
    """Which segments pass through the inside of the box ``quad`` (corners (4, 2)) shrunk by ``eps``
    (separating axes: the box's two edge normals and each segment's normal)."""
    hit = np.ones(len(seg), dtype=bool)
    for n in _axes(quad):
        n = n / np.hypot(*n)
        q = quad @ n
        lo, hi = q.min() + eps, q.max() - eps
        a, b = seg[:, :2] @ n, seg[:, 2:] @ n
        hit &= (np.maximum(a, b) > lo) & (np.minimum(a, b) < hi)
    nx, ny = seg[:, 1] - seg[:, 3], seg[:, 2] - seg[:, 0]
    d = nx * (quad[:, :1] - seg[:, 0]) + ny * (quad[:, 1:] - seg[:, 1])  # (4, n): the corners' sides
    return hit & (d.max(axis=0) > 0) & (d.min(axis=0) < 0)


def _overlap(a: np.ndarray, b: np.ndarray, eps: float = 0.05) -> bool:
    """Whether two boxes (corners (4, 2)) share more than a rim of ``eps``."""
    for n in np.vstack([_axes(a), _axes(b)]):
        n = n / np.hypot(*n)
        pa, pb = a @ n, b @ n
        if pa.max() - eps <= pb.min() or pb.max() - eps <= pa.min():
            return False
    return True


def _quad(b) -> np.ndarray:
    return np.array([(b[0], b[1]), (b[2], b[1]), (b[2], b[3]), (b[0], b[3])], dtype=float)


def layout_problems(doc, layout: SheetLayout) -> list[str]:
    """The layout rule (docs/decisions.md, "Drawing layout rule") checked on a sheet: everything inside the
    frame; the title block, lift table, notes, cam view and side view (each the box of all it holds) apart;
    no two texts overlapping; no line through a text except its own dimension's and the thin reference
    circles (:data:`REFERENCE_LAYERS`).  Returns the
    violations (empty when the sheet keeps the rule)."""
    it = sheet_items(doc, layout)
    out: list[str] = []
    fx0, fy0, fx1, fy1 = layout.frame
    for text, _, _, q in it.texts:
        if q[:, 0].min() < fx0 or q[:, 1].min() < fy0 or q[:, 0].max() > fx1 or q[:, 1].max() > fy1:
            out.append(f"text {text!r} {_fmt_box(q)} leaves the frame")
    s = it.segments
    if len(s):
        outside = ((np.minimum(s[:, 0], s[:, 2]) < fx0 - 1e-6) | (np.maximum(s[:, 0], s[:, 2]) > fx1 + 1e-6)
                   | (np.minimum(s[:, 1], s[:, 3]) < fy0 - 1e-6) | (np.maximum(s[:, 1], s[:, 3]) > fy1 + 1e-6))
        for i in np.flatnonzero(outside)[:5]:
            out.append(f"a {it.seg_group[i]} line {s[i].round(2).tolist()} leaves the frame")
    boxes: dict[str, list[float]] = {}
    for _, g, _, q in it.texts:
        b = [q[:, 0].min(), q[:, 1].min(), q[:, 0].max(), q[:, 1].max()]
        boxes.setdefault(g, list(b))
        boxes[g] = [min(boxes[g][0], b[0]), min(boxes[g][1], b[1]), max(boxes[g][2], b[2]), max(boxes[g][3], b[3])]
    for g in set(it.seg_group):
        m = np.array([x == g for x in it.seg_group])
        sg = s[m]
        b = [float(np.minimum(sg[:, 0], sg[:, 2]).min()), float(np.minimum(sg[:, 1], sg[:, 3]).min()),
             float(np.maximum(sg[:, 0], sg[:, 2]).max()), float(np.maximum(sg[:, 1], sg[:, 3]).max())]
        old = boxes.get(g, b)
        boxes[g] = [min(old[0], b[0]), min(old[1], b[1]), max(old[2], b[2]), max(old[3], b[3])]
    seg_group = np.array(it.seg_group)
    # nothing of one group inside the box of another; the cam view's items scatter round the cam (a leader, a
    # label below it), so its box is no container: its items are kept apart item by item (texts and lines)
    for g, box in sorted((g, b) for g, b in boxes.items() if g != "view"):
        quad = _quad(box)
        for text, tg, _, q in it.texts:
            if tg != g and _overlap(q, quad):
                out.append(f"text {text!r} of the {tg} {_fmt_box(q)} enters the {g} {_fmt_box(box)}")
        if len(s):
            inside = _crosses(quad, s) & (seg_group != g)
            for k in np.flatnonzero(inside)[:2]:
                out.append(f"a {seg_group[k]} line {s[k].round(2).tolist()} enters the {g} {_fmt_box(box)}")
    for i, (ta, _, _, ba) in enumerate(it.texts):
        for tb, _, _, bb in it.texts[i + 1:]:
            if _overlap(ba, bb):
                out.append(f"texts {ta!r} {_fmt_box(ba)} and {tb!r} {_fmt_box(bb)} overlap")
        owner = it.texts[i][2]
        hit = (_crosses(ba, s) & np.array([o != owner or not owner for o in it.seg_owner], dtype=bool)
               & ~it.seg_reference)
        for k in np.flatnonzero(hit)[:2]:
            out.append(f"a {it.seg_group[k]} line {s[k].round(2).tolist()} runs through text {ta!r} {_fmt_box(ba)}")
    return out


def _fmt_box(b) -> str:
    b = np.asarray(b, dtype=float)
    if b.ndim == 2:
        b = np.array([b[:, 0].min(), b[:, 1].min(), b[:, 0].max(), b[:, 1].max()])
    return "(" + ", ".join(f"{v:.1f}" for v in b) + ")"


def _dimension_quads(doc, dim) -> list[tuple[str, np.ndarray]]:
    """A DIMENSION's texts and their boxes as ezdxf renders them (centred on the text position) — and, for a
    linear dimension whose text is longer than its dimension line, also where LibreCAD puts it: starting at
    the text position (it shifts a text that does not fit by half its length along the reading direction)."""
    out = []
    for t in doc.blocks.get(dim.dxf.geometry):
        if t.dxftype() != "MTEXT":
            continue
        text, q = _text_box(t)
        if dim.dimtype == 0:  # linear: the measured length on paper, along the dimension line
            a = math.radians(dim.dxf.angle)
            u = np.array([math.cos(a), math.sin(a)])
            p2, p3 = dim.dxf.defpoint2, dim.dxf.defpoint3
            span = abs(float(np.dot((p3.x - p2.x, p3.y - p2.y), u)))
            length = float(np.hypot(*(q[1] - q[0])))
            if length > span:
                d = (q[1] - q[0]) / length * (length / 2)
                q = np.array([q[0], q[1] + d, q[2] + d, q[3]])
        out.append((text, q))
    return out


def dimension_parts(doc, dim) -> tuple[list[np.ndarray], np.ndarray]:
    """A rendered DIMENSION's text boxes (corners, see :func:`_dimension_quads`) and line segments (n, 4)."""
    block = doc.blocks.get(dim.dxf.geometry)
    quads = [q for _, q in _dimension_quads(doc, dim)]
    return quads, np.array([s for t in block for s in _segments(t)], dtype=float).reshape(-1, 4)


class Occupancy:
    """The text boxes and line segments already on a sheet, to place a new dimension where its text crosses
    no line and no text, and its lines cross no text (the layout rule, applied while drawing)."""

    def __init__(self, doc, layout: SheetLayout) -> None:
        it = sheet_items(doc, layout)
        self.quads = [q for *_, q in it.texts]
        self.segments = it.segments[~it.seg_reference]
        self.frame = layout.frame
        for g in ("title", "table", "notes", "side"):  # the other groups' boxes: no view text may enter them
            pts = [q for _, grp, _, q in it.texts if grp == g]
            segs = it.segments[np.array([x == g for x in it.seg_group], dtype=bool)] if len(it.segments) else []
            pts += [seg.reshape(2, 2) for seg in segs]
            if pts:
                allp = np.vstack(pts)
                self.quads.append(_quad((allp[:, 0].min(), allp[:, 1].min(), allp[:, 0].max(), allp[:, 1].max())))

    def free(self, quads: list[np.ndarray], segments: np.ndarray) -> bool:
        x0, y0, x1, y1 = self.frame
        for q in quads:
            if q[:, 0].min() < x0 or q[:, 1].min() < y0 or q[:, 0].max() > x1 or q[:, 1].max() > y1:
                return False
            if len(self.segments) and _crosses(q, self.segments).any():
                return False
            if any(_overlap(q, other) for other in self.quads):
                return False
        return not (len(segments) and any(_crosses(q, segments).any() for q in self.quads))

    def add(self, quads: list[np.ndarray], segments: np.ndarray) -> None:
        self.quads += quads
        self.segments = np.vstack([self.segments.reshape(-1, 4), segments.reshape(-1, 4)])
