"""A report figure written as SVG by hand from its matplotlib artists: one pass over the lines, patches, fills,
texts, ticks and legends, without matplotlib's draw.

matplotlib's SVG save was ~70 % of the report stage of ``camfab package`` (profiled: tick machinery, text
layout and every glyph as a path; docs/decisions.md "Report plots written as SVG by hand").  The report's
figures are simple: x–y curves (:class:`~matplotlib.lines.Line2D`), spans and fills (rectangles, polygons,
``fill_between``), texts and annotations, one arrow, legends outside the axes, linear axes with ticks and grids.
:func:`figure_svg` writes exactly those, at the positions the figure's fixed layout
(:func:`camfab.report.layout.fixed_layout`) gave its axes; curves are polylines of every sample, in the
figure's own display units (pixels at ``figure.dpi``, y down).  Texts are SVG ``<text>`` in DejaVu Sans
(matplotlib's font; a browser falls back to its sans-serif).  A figure with anything else (an image, a log
axis, a twin axes, an arrow annotation, an unknown marker) gets ``None``: the caller saves it with matplotlib.

The file is deterministic (no date, no random ids).  Each axes is a ``<g class="axes">``; its curves are
``<path class="line">``, its tick labels ``<text class="xtick">`` / ``<text class="ytick">`` at their tick, so a
reader (tests/report/test_svgfig.py) can map a curve back to data.
"""
from __future__ import annotations

import functools
import math
from typing import Any
from xml.sax.saxutils import escape

import numpy as np

from ..errors import InternalError

__all__ = ["figure_svg"]

_FONT = "DejaVu Sans, Bitstream Vera Sans, Arial, Helvetica, sans-serif"
#: baseline shift of a text line (em) for matplotlib's vertical alignments (DejaVu Sans' ascent and descent)
_VA = {"top": 0.76, "center": 0.36, "center_baseline": 0.0, "baseline": 0.0, "bottom": -0.24}
_ANCHOR = {"left": "start", "center": "middle", "right": "end"}
#: markers drawn: matplotlib's name → (shape)
_MARKERS = frozenset({"o", "v", "^", "+", "x", "s", "D", "None", "none", "", " "})


class _Unsupported(InternalError):
    """The figure has an artist this writer does not draw (caught here: the figure goes to matplotlib's save)."""


def figure_svg(fig) -> bytes | None:
    """The figure as SVG bytes, or ``None`` when it holds an artist :mod:`camfab.report.svgfig` does not draw.

    Call after :func:`~camfab.report.layout.fixed_layout` (no layout engine left: the axes' positions are final).
    """
    if fig.get_layout_engine() is not None or fig.images or fig.patches or fig.lines or fig.legends:
        return None
    try:
        return _Writer(fig).write()
    except _Unsupported:
        return None


def _num(v: float) -> str:
    s = f"{v:.2f}".rstrip("0").rstrip(".")
    return "0" if s == "-0" else s


def _color(c: Any, alpha: float | None = None) -> tuple[str, float]:
    """``fill="…"``-style colour and opacity attributes for a matplotlib colour."""
    from matplotlib.colors import to_rgba

    r, g, b, a = to_rgba(c, alpha)
    return f"#{round(r * 255):02x}{round(g * 255):02x}{round(b * 255):02x}", a


#: ``_paint`` attributes by (kind, colour, alpha): a figure paints with a handful of colours, hundreds of times
_PAINTS: dict[tuple, str] = {}


def _paint(kind: str, c: Any, alpha: float | None = None) -> str:
    try:
        key = (kind, c, alpha)
        got = _PAINTS.get(key)
    except TypeError:  # an unhashable colour (an RGBA array): not kept
        return _new_paint(kind, c, alpha)
    if got is None:
        if len(_PAINTS) > 4096:
            _PAINTS.clear()
        got = _PAINTS[key] = _new_paint(kind, c, alpha)
    return got


def _new_paint(kind: str, c: Any, alpha: float | None) -> str:
    hexa, a = _color(c, alpha)
    if a <= 0:
        return f'{kind}="none"'
    return f'{kind}="{hexa}"' + (f' {kind}-opacity="{_num(a) if a >= 0.01 else f"{a:.4f}"}"' if a < 1 else "")


def _polyline(xy: np.ndarray) -> str:
    """``d`` of a polyline in display coordinates (already y down), broken at non-finite points; 0.01 px."""
    ok = np.isfinite(xy).all(axis=1)
    parts = []
    if len(xy) and ok.all():  # the common case: one run
        start, stop = np.array([0]), np.array([len(xy) - 1])
    else:
        start = np.flatnonzero(ok & ~np.r_[False, ok[:-1]])
        stop = np.flatnonzero(ok & ~np.r_[ok[1:], False])
    for a, b in zip(start, stop, strict=True):
        pts = xy[a:b + 1] + 0.0  # no "-0.00"
        # one C-level %-format of the whole array: ~10x faster than a format call per number (of Python floats:
        # tolist() makes them ~10x faster than numpy's scalars)
        parts.append(("M%.2f,%.2f" + "L%.2f,%.2f" * (len(pts) - 1)) % tuple(pts.ravel().tolist()))  # noqa: UP031
    return "".join(parts)


def _path_d(path, trans, height: float) -> str:
    """``d`` of a matplotlib path through ``trans`` (to display), y flipped."""
    from matplotlib.path import Path

    out = []
    for verts, code in path.iter_segments(trans, simplify=False, curves=True):
        pts = verts.reshape(-1, 2).copy()
        pts[:, 1] = height - pts[:, 1]
        flat = " ".join(f"{_num(x)},{_num(y)}" for x, y in pts)
        if code == Path.MOVETO:
            out.append(f"M{flat}")
        elif code == Path.LINETO:
            out.append(f"L{flat}")
        elif code == Path.CURVE3:
            out.append(f"Q{flat}")
        elif code == Path.CURVE4:
            out.append(f"C{flat}")
        elif code == Path.CLOSEPOLY:
            out.append("Z")
    return "".join(out)


@functools.lru_cache(maxsize=4096)  # tick labels and legend texts recur in every figure
def _shown(text: str) -> str:
    """The characters matplotlib shows for a text without mathtext: ``\\$`` is a dollar sign
    (:func:`camfab.textsafe.mpl_text` escapes them); control characters, which XML cannot hold, become spaces.
    A text matplotlib would parse as mathtext is not drawn here."""
    from matplotlib import cbook

    from ..textsafe import plain

    if cbook.is_math_text(text):
        raise _Unsupported("mathtext")
    return "\n".join(plain(line) for line in text.split("\n")).replace("\\$", "$")


class _Writer:
    def __init__(self, fig):
        self.fig = fig
        self.dpi = float(fig.dpi)
        self.w, self.h = (float(v) * self.dpi for v in fig.get_size_inches())
        self.pt = self.dpi / 72.0
        self.out: list[str] = []
        self.renderer = fig.canvas.get_renderer()
        self.tick_cache: dict[int, tuple[np.ndarray, list[str]]] = {}

    # -- helpers -------------------------------------------------------------------------------------------
    def y(self, v):
        return self.h - v

    def text(self, s: str, x: float, y: float, *, size: float, color: Any = "black", ha: str = "left",
             va: str = "baseline", rotation: float = 0.0, cls: str = "", halo: bool = False, alpha=None,
             weight: str = "normal") -> None:
        """A text at display ``(x, y)`` (y up), ``size`` in points."""
        if not s:
            return
        if ha not in _ANCHOR or va not in _VA:
            raise _Unsupported(f"alignment {ha}/{va}")
        s = _shown(s)
        px = size * self.pt
        lines = s.split("\n")
        attrs = [f'x="{_num(x)}"', f'y="{_num(self.y(y))}"', f'font-size="{_num(px)}"',
                 f'text-anchor="{_ANCHOR[ha]}"', _paint("fill", color, alpha)]
        if weight != "normal":
            attrs.append(f'font-weight="{weight}"')
        if cls:
            attrs.append(f'class="{cls}"')
        if rotation:
            attrs.append(f'transform="rotate({_num(-rotation)} {_num(x)} {_num(self.y(y))})"')
        if halo:
            attrs.append('stroke="#ffffff" stroke-width="3" stroke-opacity="0.75" paint-order="stroke"')
        n = len(lines)
        # the block of lines is aligned as a whole: its first baseline moved by the alignment and the line count
        first = {"top": _VA["top"], "center": _VA["center"] - 0.6 * (n - 1), "bottom": _VA["bottom"] - 1.2 * (n - 1),
                 "baseline": 0.0, "center_baseline": -0.6 * (n - 1)}[va]
        spans = "".join(f'<tspan x="{_num(x)}" dy="{_num((first if i == 0 else 1.2) * px)}">{escape(t)}</tspan>'
                        for i, t in enumerate(lines))
        self.out.append(f'<text {" ".join(attrs)}>{spans}</text>')

    def line_attrs(self, color, lw: float, style: str, dashes, alpha=None, cap: str = "butt") -> str:
        if style in ("None", "none", "", " ") or lw <= 0:
            return ""
        a = f'{_paint("stroke", color, alpha)} stroke-width="{_num(lw * self.pt)}"'
        if cap != "butt":
            a += f' stroke-linecap="{cap}"'
        if dashes is not None and dashes[1]:
            a += f' stroke-dasharray="{",".join(_num(d * self.pt) for d in dashes[1])}"'
            if dashes[0]:
                a += f' stroke-dashoffset="{_num(dashes[0] * self.pt)}"'
        return a

    def marker(self, m: str, xy: np.ndarray, size: float, face, edge, ew: float, alpha=None) -> None:
        if m in ("None", "none", "", " ") or not len(xy):
            return
        r = size * self.pt / 2
        ewp = ew * self.pt
        stroke = f'{_paint("stroke", edge, alpha)} stroke-width="{_num(ewp)}"'
        fill = _paint("fill", face, alpha) if m in ("o", "v", "^", "s", "D") else 'fill="none"'
        for x, y in xy:
            if not (math.isfinite(x) and math.isfinite(y)):
                continue
            y = self.y(y)
            if m == "o":
                self.out.append(f'<circle cx="{_num(x)}" cy="{_num(y)}" r="{_num(r)}" {fill} {stroke}/>')
                continue
            if m == "v":
                pts = [(x - r, y - r), (x + r, y - r), (x, y + r)]
            elif m == "^":
                pts = [(x - r, y + r), (x + r, y + r), (x, y - r)]
            elif m == "s":
                pts = [(x - r, y - r), (x + r, y - r), (x + r, y + r), (x - r, y + r)]
            elif m == "D":
                pts = [(x, y - r), (x + r, y), (x, y + r), (x - r, y)]
            else:
                d = (f"M{_num(x - r)},{_num(y)}L{_num(x + r)},{_num(y)}M{_num(x)},{_num(y - r)}L{_num(x)},{_num(y + r)}"
                     if m == "+" else
                     f"M{_num(x - r)},{_num(y - r)}L{_num(x + r)},{_num(y + r)}M{_num(x - r)},{_num(y + r)}"
                     f"L{_num(x + r)},{_num(y - r)}")
                self.out.append(f'<path d="{d}" {stroke}/>')
                continue
            d = "M" + "L".join(f"{_num(a)},{_num(b)}" for a, b in pts) + "Z"
            self.out.append(f'<path d="{d}" {fill} {stroke}/>')

    def text_width(self, s: str, size: float) -> float:
        """Display width of ``s`` at ``size`` points (matplotlib's measure of its font)."""
        from .layout import text_size

        return text_size(self.renderer, s, size)[0] * self.pt

    # -- the figure ----------------------------------------------------------------------------------------
    def write(self) -> bytes:
        fig = self.fig
        w_pt, h_pt = (float(v) * 72.0 for v in fig.get_size_inches())
        self.out.append(f'<rect width="{_num(self.w)}" height="{_num(self.h)}" {_paint("fill", fig.get_facecolor())}/>')
        for k, ax in enumerate(fig.axes):
            if ax.get_visible():
                self.axes(ax, k)
        sup = getattr(fig, "_suptitle", None)  # matplotlib keeps the suptitle's Text there
        if sup is not None and sup.get_text():
            x, y = sup.get_transform().transform(sup.get_position())
            self.text(sup.get_text(), x, y, size=sup.get_fontsize(), color=sup.get_color(), ha=sup.get_ha(),
                      va=sup.get_va(), cls="suptitle")
        head = (f'<?xml version="1.0" encoding="utf-8" standalone="no"?>\n'
                f'<svg xmlns="http://www.w3.org/2000/svg" width="{_num(w_pt)}pt" height="{_num(h_pt)}pt" '
                f'viewBox="0 0 {_num(self.w)} {_num(self.h)}" version="1.1" font-family="{_FONT}">\n')
        return (head + "\n".join(self.out) + "\n</svg>\n").encode("utf-8")

    def axes(self, ax, k: int) -> None:
        if ax.get_xscale() != "linear" or ax.get_yscale() != "linear" or ax.images or ax.child_axes or ax.tables:
            raise _Unsupported("axes")
        twins = getattr(ax, "_twinned_axes", None)
        if twins is not None and len(twins.get_siblings(ax)) > 1:
            raise _Unsupported("twin axes")
        ax.apply_aspect()
        ax.get_xlim(), ax.get_ylim()  # the view from the data, as a draw computes it
        box = ax.bbox
        x0, y0, x1, y1 = box.x0, box.y0, box.x1, box.y1
        clip = f"clip{k}"
        self.out.append(f'<g class="axes" id="axes{k}">')
        self.out.append(f'<clipPath id="{clip}"><rect x="{_num(x0)}" y="{_num(self.y(y1))}" width="{_num(x1 - x0)}" '
                        f'height="{_num(y1 - y0)}"/></clipPath>')
        patch = ax.patch
        if patch.get_visible():
            self.out.append(f'<rect x="{_num(x0)}" y="{_num(self.y(y1))}" width="{_num(x1 - x0)}" '
                            f'height="{_num(y1 - y0)}" {_paint("fill", patch.get_facecolor())}/>')
        artists = [*ax.collections, *ax.patches, *ax.lines, *ax.texts, *ax.artists]
        artists = [a for a in artists if a.get_visible()]
        below = ax.get_axisbelow()
        grid_z = 0.5 if below is True else 1.5 if below == "line" else 2.5
        layers = [(a.get_zorder(), i, a) for i, a in enumerate(artists)] + [(grid_z, -1, None)]
        for _, _, a in sorted(layers, key=lambda t: (t[0], t[1] >= 0, t[1])):
            if a is None:
                self.grid(ax)
            else:
                self.artist(a, ax, clip)
        self.spines(ax)
        self.ticks(ax)
        self.labels(ax)
        legend = ax.get_legend()
        if legend is not None and legend.get_visible():
            self.legend(legend)
        self.out.append("</g>")

    def artist(self, a, ax, clip: str) -> None:
        from matplotlib.collections import LineCollection, PolyCollection
        from matplotlib.lines import Line2D
        from matplotlib.patches import FancyArrowPatch, Patch
        from matplotlib.text import Annotation, Text

        clipped = f' clip-path="url(#{clip})"' if a.get_clip_on() else ""
        if isinstance(a, Line2D):
            self.line(a, clipped)
        elif isinstance(a, FancyArrowPatch):
            self.arrow(a, clipped)
        elif isinstance(a, Patch) and type(a).__name__ in ("Rectangle", "Polygon", "Circle", "Ellipse", "Wedge"):
            self.patch(a, clipped)
        elif isinstance(a, PolyCollection):
            self.polys(a, clipped)
        elif type(a) is LineCollection:
            self.segments(a, clipped)
        elif isinstance(a, Annotation):
            self.annotation(a, ax)
        elif isinstance(a, Text):
            self.plain_text(a, clipped)
        else:
            raise _Unsupported(type(a).__name__)

    def arrow(self, a: Any, clipped: str) -> None:
        a._dpi_cor = self.pt  # what a draw sets (pixels per point) before it asks for the path
        paths, fillables = a._get_path_in_displaycoord()
        from matplotlib.transforms import IdentityTransform

        for p, fillable in zip(paths, fillables, strict=True):
            d = _path_d(p, IdentityTransform(), self.h)
            fill = _paint("fill", a.get_facecolor()) if fillable else 'fill="none"'
            stroke = self.line_attrs(a.get_edgecolor(), a.get_linewidth(), "-", None)
            self.out.append(f'<path d="{d}" {fill} {stroke}{clipped}/>')

    def patch(self, a: Any, clipped: str) -> None:
        d = _path_d(a.get_path(), a.get_transform(), self.h)
        stroke = self.line_attrs(a.get_edgecolor(), a.get_linewidth(), a.get_linestyle(), None)
        fill = _paint("fill", a.get_facecolor()) if a.get_fill() else 'fill="none"'
        self.out.append(f'<path d="{d}" {fill} {stroke}{clipped}/>')

    def segments(self, a: Any, clipped: str) -> None:
        """A line collection (the segment junctions): one path per segment, each with its colour and style."""
        colors, widths, styles = a.get_color(), a.get_linewidth(), a.get_linestyle()
        segs = [(i, np.asarray(seg, dtype=float)) for i, seg in enumerate(a.get_segments()) if len(seg) >= 2]
        if not segs:
            return
        # one transform of every segment's points (each point's arithmetic is that of a transform of it alone)
        xy_all = a.get_transform().transform(np.concatenate([seg for _, seg in segs]))
        xy_all[:, 1] = self.h - xy_all[:, 1]
        at = 0
        for i, seg in segs:
            xy, at = xy_all[at:at + len(seg)], at + len(seg)
            colour = colors[i % len(colors)]
            attrs = self.line_attrs(tuple(colour) if isinstance(colour, np.ndarray) else colour,  # kept by _paint
                                    widths[i % len(widths)], "-", styles[i % len(styles)])
            if attrs:
                self.out.append(f'<path d="{_polyline(xy)}" fill="none" {attrs}{clipped}/>')

    def polys(self, a: Any, clipped: str) -> None:
        faces, edges = a.get_facecolor(), a.get_edgecolor()
        lws = a.get_linewidth()
        for i, p in enumerate(a.get_paths()):
            if not len(p.vertices):
                continue
            d = _path_d(p, a.get_transform(), self.h)
            fc = faces[i % len(faces)] if len(faces) else "none"
            stroke = ""
            if len(edges) and len(lws) and lws[i % len(lws)] > 0:
                stroke = self.line_attrs(edges[i % len(edges)], lws[i % len(lws)], "-", None)
            fill = _paint("fill", fc) if len(faces) else 'fill="none"'
            self.out.append(f'<path d="{d}" {fill} {stroke}{clipped}/>')

    def line(self, a, clipped: str) -> None:
        if a.get_drawstyle() != "default" or a.get_marker() not in _MARKERS:
            raise _Unsupported("line style")
        xy = a.get_transform().transform(a.get_xydata())
        xy[:, 1] = self.h - xy[:, 1]
        style = a.get_linestyle()
        attrs = self.line_attrs(a.get_color(), a.get_linewidth(), style, getattr(a, "_dash_pattern", None),
                                a.get_alpha(), a.get_solid_capstyle() if style == "-" else a.get_dash_capstyle())
        if attrs and len(xy) > 1:
            self.out.append(f'<path class="line" d="{_polyline(xy)}" fill="none" {attrs} stroke-linejoin="round"'
                            f'{clipped}/>')
        m = a.get_marker()
        if m not in ("None", "none", "", " "):
            pts = a.get_transform().transform(a.get_xydata())
            if clipped:
                b = a.axes.bbox
                inside = (pts[:, 0] >= b.x0 - 1) & (pts[:, 0] <= b.x1 + 1) & (pts[:, 1] >= b.y0 - 1) & (
                    pts[:, 1] <= b.y1 + 1)
                pts = pts[inside]
            self.marker(m, pts, a.get_markersize(), a.get_markerfacecolor(), a.get_markeredgecolor(),
                        a.get_markeredgewidth(), a.get_alpha())

    def plain_text(self, t, clipped: str) -> None:
        x, y = t.get_transform().transform(t.get_position())
        if clipped:
            b = t.axes.bbox
            if not (b.x0 - 1 <= x <= b.x1 + 1 and b.y0 - 1 <= y <= b.y1 + 1):
                return
        self.text(t.get_text(), x, y, size=t.get_fontsize(), color=t.get_color(), ha=t.get_ha(), va=t.get_va(),
                  rotation=t.get_rotation(), halo=t.get_bbox_patch() is not None, alpha=t.get_alpha())

    def annotation(self, t, ax) -> None:
        if t.arrow_patch is not None or t.xycoords != "data" or t.anncoords not in ("data", "offset points"):
            raise _Unsupported("annotation")
        x, y = ax.transData.transform(t.xy)
        if t.anncoords == "offset points":
            dx, dy = t.xyann
            tx, ty = x + dx * self.pt, y + dy * self.pt
        else:
            tx, ty = ax.transData.transform(t.xyann)
        b = ax.bbox
        if t.get_annotation_clip() is not False and not (b.x0 - 1 <= x <= b.x1 + 1 and b.y0 - 1 <= y <= b.y1 + 1):
            return  # matplotlib leaves out an annotation whose point is outside the axes
        self.text(t.get_text(), tx, ty, size=t.get_fontsize(), color=t.get_color(), ha=t.get_ha(), va=t.get_va(),
                  rotation=t.get_rotation(), halo=t.get_bbox_patch() is not None, alpha=t.get_alpha())

    # -- axes furniture --------------------------------------------------------------------------------------
    def _ticks(self, axis) -> tuple[np.ndarray, list[str]]:
        """The major ticks inside the view and their labels (computed once per axis and save)."""
        got = self.tick_cache.get(id(axis))
        if got is None:
            got = self.tick_cache[id(axis)] = self._new_ticks(axis)
        return got

    def _new_ticks(self, axis) -> tuple[np.ndarray, list[str]]:
        lo, hi = sorted(axis.get_view_interval())
        span = (hi - lo) or 1.0
        locs = np.asarray(axis.get_majorticklocs(), dtype=float)
        locs = locs[(locs >= lo - 1e-9 * span) & (locs <= hi + 1e-9 * span)]
        return locs, list(axis.get_major_formatter().format_ticks(list(locs)))

    def _tick_pixels(self, ax, axis, vertical: bool) -> list[float]:
        """Display x (or y, ``vertical``) of the axis's major ticks: one transform of them all (each point's
        arithmetic is the same as a transform of it alone)."""
        locs, _ = self._ticks(axis)
        pts = np.zeros((len(locs), 2))
        pts[:, 1 if vertical else 0] = locs
        return ax.transData.transform(pts)[:, 1 if vertical else 0].tolist()

    def grid(self, ax) -> None:
        b = ax.bbox
        for axis, horizontal in ((ax.xaxis, False), (ax.yaxis, True)):
            tick = axis.get_major_ticks(numticks=1)[0]
            g = tick.gridline
            if not g.get_visible():
                continue
            attrs = self.line_attrs(g.get_color(), g.get_linewidth(), g.get_linestyle(),
                                    getattr(g, "_dash_pattern", None), g.get_alpha(), "projecting")
            if not attrs:
                continue
            d = []
            for p in self._tick_pixels(ax, axis, horizontal):
                if horizontal:
                    d.append(f"M{_num(b.x0)},{_num(self.y(p))}H{_num(b.x1)}")
                else:
                    d.append(f"M{_num(p)},{_num(self.y(b.y0))}V{_num(self.y(b.y1))}")
            if d:
                self.out.append(f'<path class="grid" d="{"".join(d)}" fill="none" {attrs}/>')

    def spines(self, ax) -> None:
        b = ax.bbox
        ends = {"left": (b.x0, b.y0, b.x0, b.y1), "right": (b.x1, b.y0, b.x1, b.y1),
                "bottom": (b.x0, b.y0, b.x1, b.y0), "top": (b.x0, b.y1, b.x1, b.y1)}
        for name, sp in ax.spines.items():
            if not sp.get_visible():
                continue
            if name not in ends or sp.get_position() != ("outward", 0.0) or sp.get_bounds() is not None:
                raise _Unsupported("spine")
            xa, ya, xb, yb = ends[name]
            attrs = self.line_attrs(sp.get_edgecolor(), sp.get_linewidth(), sp.get_linestyle(), None, None,
                                    "projecting")
            self.out.append(f'<path d="M{_num(xa)},{_num(self.y(ya))}L{_num(xb)},{_num(self.y(yb))}" {attrs}/>')

    def ticks(self, ax) -> None:
        b = ax.bbox
        for axis, vertical, cls in ((ax.xaxis, False, "xtick"), (ax.yaxis, True, "ytick")):
            tick = axis.get_major_ticks(numticks=1)[0]
            if tick.tick2line.get_visible() or tick.label2.get_visible() or tick.get_tickdir() != "out":
                raise _Unsupported("ticks")
            _, labels = self._ticks(axis)
            size = tick.get_tick_padding()  # the tick length (points) for outward ticks
            mark = tick.tick1line
            pad = (tick.get_pad() + size) * self.pt
            lab = tick.label1
            d = []
            for p, s in zip(self._tick_pixels(ax, axis, vertical), labels, strict=True):
                if vertical:
                    if mark.get_visible():
                        d.append(f"M{_num(b.x0)},{_num(self.y(p))}h{_num(-size * self.pt)}")
                    if lab.get_visible():
                        self.text(s, b.x0 - pad, p, size=lab.get_fontsize(), color=lab.get_color(), ha="right",
                                  va="center", cls=cls)
                else:
                    if mark.get_visible():
                        d.append(f"M{_num(p)},{_num(self.y(b.y0))}v{_num(size * self.pt)}")
                    if lab.get_visible():
                        self.text(s, p, b.y0 - pad, size=lab.get_fontsize(), color=lab.get_color(), ha="center",
                                  va="top", cls=cls)
            if d:
                attrs = self.line_attrs(mark.get_color(), mark.get_markeredgewidth(), "-", None)
                self.out.append(f'<path d="{"".join(d)}" {attrs}/>')

    def _tick_room(self, axis, vertical: bool) -> float:
        """Display units beside the axes taken by the axis's tick marks and labels (as the layout measured)."""
        tick = axis.get_major_ticks(numticks=1)[0]
        if not tick.label1.get_visible():
            return 0.0
        _, labels = self._ticks(axis)
        size = tick.label1.get_fontsize()
        if vertical:
            text = max((self.text_width(s, size) for s in labels), default=0.0)
        else:
            text = size * self.pt if labels else 0.0
        return text + (tick.get_tick_padding() + tick.get_pad()) * self.pt

    def labels(self, ax) -> None:
        b = ax.bbox
        xl, yl = ax.xaxis.label, ax.yaxis.label
        if xl.get_text() and xl.get_visible():
            y = b.y0 - self._tick_room(ax.xaxis, False) - ax.xaxis.labelpad * self.pt
            self.text(xl.get_text(), (b.x0 + b.x1) / 2, y, size=xl.get_fontsize(), color=xl.get_color(),
                      ha="center", va="top", cls="xlabel")
        if yl.get_text() and yl.get_visible():
            x = b.x0 - self._tick_room(ax.yaxis, True) - ax.yaxis.labelpad * self.pt
            self.text(yl.get_text(), x, (b.y0 + b.y1) / 2, size=yl.get_fontsize(), color=yl.get_color(),
                      ha="center", va="bottom", rotation=90.0, cls="ylabel")
        import matplotlib

        pad = float(matplotlib.rcParams["axes.titlepad"])  # the titles' distance above the axes (points)
        for loc, t in (("center", ax.title), ("left", ax._left_title), ("right", ax._right_title)):
            if t.get_text() and t.get_visible():
                x = {"center": (b.x0 + b.x1) / 2, "left": b.x0, "right": b.x1}[loc]
                self.text(t.get_text(), x, b.y1 + pad * self.pt, size=t.get_fontsize(), color=t.get_color(),
                          ha={"center": "center", "left": "left", "right": "right"}[loc], va="baseline",
                          cls="title")

    def legend(self, leg) -> None:
        from matplotlib.collections import PolyCollection
        from matplotlib.lines import Line2D
        from matplotlib.patches import Patch

        from .layout import legend_extent

        box = legend_extent(leg, self.renderer)  # the packed size measured by the layout, the offset anew
        k = self.dpi / self.renderer.dpi
        x0, y0, x1, y1 = box.x0 * k, box.y0 * k, box.x1 * k, box.y1 * k
        frame = leg.get_frame()
        if leg.get_frame_on():
            r = 0.2 * leg._fontsize * self.pt if getattr(leg, "_fancybox", True) else 0
            self.out.append(f'<rect x="{_num(x0)}" y="{_num(self.y(y1))}" width="{_num(x1 - x0)}" '
                            f'height="{_num(y1 - y0)}" rx="{_num(r)}" {_paint("fill", frame.get_facecolor())} '
                            f'{_paint("stroke", frame.get_edgecolor())} '
                            f'stroke-width="{_num(frame.get_linewidth() * self.pt)}"/>')
        texts = leg.get_texts()
        handles = leg.legend_handles
        n = len(texts)
        if not n:
            return
        fs = leg._fontsize * self.pt
        inner_top, inner_bottom = y1 - leg.borderpad * fs, y0 + leg.borderpad * fs
        if leg.get_title().get_text():
            raise _Unsupported("legend title")
        step = (inner_top - inner_bottom) / n
        hx0 = x0 + leg.borderpad * fs
        hx1 = hx0 + leg.handlelength * fs
        tx = hx1 + leg.handletextpad * fs
        for i, (t, h) in enumerate(zip(texts, handles, strict=True)):
            yc = inner_top - (i + 0.5) * step
            if isinstance(h, Line2D):
                if h.get_marker() not in _MARKERS:
                    raise _Unsupported("legend marker")
                attrs = self.line_attrs(h.get_color(), h.get_linewidth(), str(h.get_linestyle()),
                                        getattr(h, "_dash_pattern", None), h.get_alpha())
                if attrs:
                    self.out.append(f'<path d="M{_num(hx0)},{_num(self.y(yc))}H{_num(hx1)}" fill="none" {attrs}/>')
                self.marker(str(h.get_marker()), np.array([[(hx0 + hx1) / 2, yc]]), h.get_markersize(),
                            h.get_markerfacecolor(), h.get_markeredgecolor(), h.get_markeredgewidth(), h.get_alpha())
            elif isinstance(h, Patch | PolyCollection):
                fc: Any = h.get_facecolor()
                fc = fc[0] if getattr(fc, "ndim", 1) == 2 and len(fc) else fc
                hh = 0.7 * fs
                self.out.append(f'<rect x="{_num(hx0)}" y="{_num(self.y(yc + hh / 2))}" width="{_num(hx1 - hx0)}" '
                                f'height="{_num(hh)}" {_paint("fill", fc)}/>')
            elif h is not None:
                raise _Unsupported("legend handle")
            self.text(t.get_text(), tx, yc, size=t.get_fontsize(), color=t.get_color(), ha="left", va="center",
                      cls="legend")
