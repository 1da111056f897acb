"""The drawing sheet's frame: paper and scale, layers, the title block, the lift table and the notes column.

Sizes come from the title-block template ``templates/drawing/title_block.toml`` (shipped in the wheel, found
by :mod:`camfab.assets`).  Everything is in paper millimetres, origin at the sheet's lower-left corner;
:mod:`camfab.cad.drawing` places the cam's views and notes in the boxes of a :class:`SheetLayout`.
"""
from __future__ import annotations

import functools
import math
import tomllib
from typing import Any, cast

import numpy as np

from ..assets import read_template
from ..errors import ExportError, InputError
from ..geom2d import ArcChain
from ..records import dataclass
from ..textsafe import dxf_mtext, dxf_string, dxf_text
from .dxf import ezdxf_module

__all__ = ["PAPERS", "LAYERS", "SheetLayout", "load_template", "parse_scale", "sheet_layout", "put_text", "rect",
           "place", "fmt", "title_block", "lift_table_block", "notes_column", "clipped_circle", "new_document",
           "text_width", "wrap", "NOTE_PITCH"]

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
    from ezdxf.enums import MAP_TEXT_ENUM_TO_ALIGN_FLAGS, TextEntityAlignment

    if width is not None and text:
        height = max(1.0, min(height, width / text_width(text, 1.0)))
    p = (float(at[0]), float(at[1]))
    if align in ("ALIGNED", "FIT"):  # two-point alignments: set_placement asks for the second point
        t = msp.add_text(text, height=height, dxfattribs={"layer": layer})
        return t.set_placement(p, align=TextEntityAlignment[align])
    # the attributes Text.set_placement would set afterwards (alignment flags, the point as insert and align
    # point), given at creation: the same entity, set up in one pass (a sheet has ~140 texts)
    halign, valign = MAP_TEXT_ENUM_TO_ALIGN_FLAGS[TextEntityAlignment[align]]
    return msp.add_text(text, height=height, dxfattribs={"layer": layer, "halign": halign, "valign": valign,
                                                         "insert": p, "align_point": p})


def text_width(text: str, height: float) -> float:
    """A conservative width (paper mm) of ``text`` at ``height``: at least what LibreCAD's ISO 3098 stroke
    font takes (lower case and digits ``width_factor`` × height, capitals 1.0, W M % Ø 1.25, a space 0.75),
    wider than the TrueType fonts of other viewers.  DXF special codes count as the character they show."""
    return _unit_width(text, load_template()["text"]["width_factor"]) * height


@functools.lru_cache(maxsize=4096)
def _unit_width(text: str, lower: float) -> float:
    """:func:`text_width` at height 1, summed character by character as there (the same float); cached, since a
    sheet measures the same few strings (lift-table values, labels) many times, once when writing each text and
    again when checking the layout."""
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
    return total


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


def lift_table_block(msp, layout: SheetLayout, table, closed: bool, third: str | None = None) -> None:
    """The lift table in ``layout.table``, split into side-by-side column groups when it is tall; ``third``
    replaces the third column's heading (RADIUS mm / HEIGHT mm)."""
    tpl = load_template()["lift_table"]
    rh, widths, h = tpl["row_height_mm"], tpl["column_widths_mm"], tpl["text_height_mm"]
    x0, y0, x1, y1 = layout.table
    rect(msp, layout.table, "LIFT_TABLE")
    step = float(table.angle[1] - table.angle[0]) if len(table.angle) > 1 else 360.0
    unit = "°" if table.lift_unit == "deg" else "mm"
    put_text(msp, f"LIFT TABLE (step {step:g}{'°' if closed else ' mm'})", ((x0 + x1) / 2, y1 - 0.75 * rh),
          h, "LIFT_TABLE", "MIDDLE_CENTER", width=x1 - x0 - 2)
    msp.add_line((x0, y1 - 1.5 * rh), (x1, y1 - 1.5 * rh), dxfattribs={"layer": "LIFT_TABLE"})
    heads = ("ANGLE °" if closed else "TRAVEL mm", f"LIFT {unit}", third or ("RADIUS mm" if closed else "HEIGHT mm"))
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
