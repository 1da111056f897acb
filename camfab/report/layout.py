"""A report figure's layout measured once from its own texts, then fixed: one draw per saved file.

matplotlib's constrained layout draws a figure once without output and measures every artist's
tight box before each save — the largest cost of a report plot.  Here the margins come from the
texts that need room — tick labels (their strings from each axis's locator and formatter), axis
labels, titles, the suptitle and a legend outside the axes — measured with the canvas's renderer;
the axes are placed by their grid's parameters (as ``subplots_adjust`` would) and the layout engine is
turned off (docs/decisions.md "Plot layout").  Figures are one column of axes (the report's shapes).
"""
from __future__ import annotations

import weakref

import numpy as np

__all__ = ["fixed_layout", "legend_extent", "text_size"]

#: breathing room at each figure edge and between stacked axes (points)
_EDGE_PT = 5.0


#: measured text sizes by (text, font, dpi): the tick labels and axis labels of one report's plots recur in the
#: next design's (matplotlib measures with FreeType on every call)
_SIZES: dict[tuple, tuple[float, float]] = {}


def _size(renderer, text: str, prop) -> tuple[float, float]:
    """(width, height) of ``text`` in points."""
    if not text:
        return 0.0, 0.0
    key = (text, tuple(prop.get_family()), prop.get_style(), prop.get_variant(), prop.get_weight(),
           prop.get_stretch(), prop.get_size_in_points(), prop.get_file(), renderer.dpi)
    got = _SIZES.get(key)
    if got is None:
        w, h, _ = renderer.get_text_width_height_descent(text, prop, ismath=False)
        k = 72.0 / renderer.dpi
        if len(_SIZES) > 20000:
            _SIZES.clear()
        got = _SIZES[key] = (w * k, h * k)
    return got


def text_size(renderer, text: str, size: float) -> tuple[float, float]:
    """(width, height) in points of ``text`` in the current default font at ``size`` points."""
    from matplotlib.font_manager import FontProperties

    return _size(renderer, text, FontProperties(size=size))


def _tick_labels(axis) -> list[str]:
    """The major tick labels the axis will draw (its locator's ticks inside the view, formatted)."""
    lo, hi = sorted(axis.get_view_interval())
    locs = np.asarray(axis.get_majorticklocs(), dtype=float)
    span = (hi - lo) or 1.0
    locs = locs[(locs >= lo - 1e-9 * span) & (locs <= hi + 1e-9 * span)]
    return [s for s in axis.get_major_formatter().format_ticks(list(locs)) if s]


def _labelled(axis) -> bool:
    """Whether the axis draws its major tick labels (below or left of the axes)."""
    return axis.get_major_ticks(numticks=1)[0].label1.get_visible()


def _tick_room(renderer, axis, vertical: bool, labels: list[str] | None = None) -> float:
    """Points taken beside the axes by an axis's tick marks and labels (0 when its labels are hidden);
    ``labels``: its :func:`_tick_labels` when the caller has them."""
    tick = axis.get_major_ticks(numticks=1)[0]
    if not tick.label1.get_visible():
        return 0.0
    labels = _tick_labels(axis) if labels is None else labels
    sizes = [_size(renderer, s, tick.label1.get_fontproperties()) for s in labels]
    text = max((w if vertical else h for w, h in sizes), default=0.0)
    return text + tick.get_tick_padding() + tick.get_pad()


def _overhang(renderer, axis, labels: list[str]) -> float:
    """Points an x axis's end tick labels (``labels``) reach past the axes' sides (half the widest label)."""
    tick = axis.get_major_ticks(numticks=1)[0]
    if not tick.label1.get_visible():
        return 0.0
    prop = tick.label1.get_fontproperties()
    return max((_size(renderer, s, prop)[0] for s in labels), default=0.0) / 2


def _label_room(renderer, label) -> float:
    """Points taken by an axis label (its height: y labels are turned)."""
    text = label.get_text()
    return _size(renderer, text, label.get_fontproperties())[1] + 4.0 if text else 0.0


def _offset_room(renderer, axis) -> float:
    """Points above the axes taken by a y axis's offset text ("1e6"; the titles go above it), after
    :func:`_tick_labels` of the axis (the formatter's offset follows its last ticks)."""
    text = axis.get_major_formatter().get_offset()
    return _size(renderer, text, axis.get_offset_text().get_fontproperties())[1] + 2.0 if text else 0.0


def _title_room(renderer, ax) -> float:
    """Points above the axes taken by its titles (centre, left, right) and their pad."""
    height = 0.0
    for loc in ("center", "left", "right"):
        text = ax.get_title(loc)
        if text:
            height = max(height, _size(renderer, text, _title_prop(ax, loc, text))[1])
    return height + 6.0 if height else 0.0


def _title_prop(ax, loc: str, text: str):
    """The font of a title (the left and right ones found among the axes' children by their text)."""
    if loc != "center":
        for child in ax.get_children():
            if child is not ax.title and getattr(child, "get_text", None) and child.get_text() == text:
                return child.get_fontproperties()
    return ax.title.get_fontproperties()


def fixed_layout(fig) -> None:
    """Place the figure's axes (one column) with margins measured from its texts; layout engine off."""
    axes = [ax for ax in fig.axes if ax.get_visible()]
    if not axes:
        _no_engine(fig)
        return
    renderer = fig.canvas.get_renderer()
    w_in, h_in = fig.get_size_inches()
    left = right = 0.0
    tops, bottoms = [], []
    for ax in axes:  # each axis's ticks located and formatted once (its formatter's offset set by that call)
        ylabels = _tick_labels(ax.yaxis)
        xlabels = _tick_labels(ax.xaxis) if _labelled(ax.xaxis) else []  # not for a shared axis' hidden labels
        left = max(left, _tick_room(renderer, ax.yaxis, True, ylabels) + _label_room(renderer, ax.yaxis.label))
        legend = ax.get_legend()
        if legend is not None and legend.get_visible():
            right = max(right, legend_extent(legend, renderer).width * 72.0 / fig.dpi + 0.01 * 72.0 * w_in)
        right = max(right, _overhang(renderer, ax.xaxis, xlabels))
        tops.append(_title_room(renderer, ax) + _offset_room(renderer, ax.yaxis))
        bottoms.append(_tick_room(renderer, ax.xaxis, False, xlabels) + _label_room(renderer, ax.xaxis.label))
    suptitle = fig.get_suptitle()
    artist = getattr(fig, "_suptitle", None)  # matplotlib keeps the suptitle's Text there (no public getter)
    sup = _size(renderer, suptitle, artist.get_fontproperties())[1] + 4.0 if suptitle and artist else 0.0
    n = len(axes)
    gap = max((bottoms[i] + tops[i + 1] for i in range(n - 1)), default=0.0) + _EDGE_PT
    top_pt, bottom_pt = _EDGE_PT + sup + tops[0], _EDGE_PT + bottoms[-1]
    usable = h_in * 72.0 - top_pt - bottom_pt
    mean_h = (usable - gap * (n - 1)) / n
    _no_engine(fig)
    grid = axes[0].get_subplotspec().get_gridspec()
    grid.update(left=(left + _EDGE_PT) / (72.0 * w_in), right=1.0 - (right + _EDGE_PT) / (72.0 * w_in),
                top=1.0 - top_pt / (72.0 * h_in), bottom=bottom_pt / (72.0 * h_in),
                hspace=gap / mean_h if n > 1 else 0.0)
    for ax in axes:
        ax.set_position(ax.get_subplotspec().get_position(fig))
        _fix_titles(ax)


#: each legend's packed box and the resolution it was measured at, kept as long as the legend lives (beside the
#: legend, not on it: no attribute of camfab's on matplotlib's objects)
_PACKED: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def legend_extent(legend, renderer):
    """``legend.get_window_extent(renderer)``, the legend's packed box (its texts and handles, which do not change
    once it is made, nor with where its axes are) measured once per legend and renderer resolution: the layout
    and the SVG writer each need the extent, the SVG writer after the axes moved (the offset is computed again).
    A legend spread over its anchor's width (``mode="expand"``) is measured every time."""
    packer = legend._legend_box  # matplotlib's packer of the legend's entries (Legend.get_window_extent uses it)
    if getattr(legend, "_mode", None) is not None:
        return legend.get_window_extent(renderer)
    kept = _PACKED.get(legend)
    if kept is None or kept[0] != renderer.dpi:
        kept = (renderer.dpi, packer.get_bbox(renderer))
        _PACKED[legend] = kept
    bbox = kept[1]
    return bbox.translated(*packer.get_offset(bbox, renderer))


def _no_engine(fig) -> None:
    """Turn the layout engine off altogether: ``set_layout_engine("none")`` leaves a placeholder engine, and
    with any engine set ``savefig`` draws the whole figure once more (without output) before the real draw."""
    import matplotlib

    rc = matplotlib.rcParams
    if not rc["figure.autolayout"] and not rc["figure.constrained_layout.use"]:  # as they are (no rc_context to pay)
        fig.set_layout_engine(None)  # with both rc settings off this sets no engine (matplotlib's documented rule)
        return
    with matplotlib.rc_context({"figure.autolayout": False, "figure.constrained_layout.use": False}):
        fig.set_layout_engine(None)


def _fix_titles(ax) -> None:
    """Keep the axes' titles where matplotlib's automatic placement would leave them (just above the axes), and
    turn that placement off when nothing can push them up: no tick marks or labels on top, no x label on top, no
    y offset text ("1e6") and no twin or child axes.  The automatic placement measures the x and y axes' tight
    boxes (every tick label) at every draw: ~40 % of a report plot's save, profiled (docs/decisions.md "Report
    figures: one draw per save, kept figures")."""
    xaxis = ax.xaxis
    ticks = xaxis.get_major_ticks(numticks=1) + xaxis.get_minor_ticks(numticks=1)
    on_top = any(t.tick2line.get_visible() or t.label2.get_visible() for t in ticks)
    twins = getattr(ax, "_twinned_axes", None)  # matplotlib's grouper of twinx/twiny axes
    if on_top or xaxis.get_label_position() != "bottom" or ax.child_axes \
            or (twins is not None and len(twins.get_siblings(ax)) > 1):
        return
    _tick_labels(ax.yaxis)  # the formatter's offset follows the ticks of the placed axes
    if ax.yaxis.get_major_formatter().get_offset():
        return
    ax._autotitlepos = False  # matplotlib's switch of the automatic placement (set_title(y=...) sets it too)
