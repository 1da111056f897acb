"""The report's figures kept and drawn again for the next design (one per kind and size, per thread).

Inside :func:`reusing_figures` (what :func:`camfab.report.html.render_report` does), a figure function asks
:func:`figure_with_axes` for its figure: the first design makes it, the next ones get it back emptied — their
lines, texts, patches and legends removed, the scales, limits, titles, labels and layout as a new figure has
them — so matplotlib keeps the axes and their tick objects, the largest cost of making a plot after its
drawing.  The files are byte-identical to a new figure's (tests/report/test_figpool.py); outside the block
every call makes a new figure, so a figure a caller holds is never redrawn under it (docs/decisions.md, "Report
figures: one draw per save, kept figures").
"""
from __future__ import annotations

import contextlib
import threading
from collections.abc import Callable, Generator
from typing import Any

__all__ = ["reusing_figures", "figure_with_axes"]

_LOCAL = threading.local()


@contextlib.contextmanager
def reusing_figures() -> Generator[None, None, None]:
    """Within, :func:`figure_with_axes` lends kept figures; they are handed back when the block ends (the
    caller renders them inside it)."""
    outer = getattr(_LOCAL, "lent", None)
    _LOCAL.lent = set() if outer is None else outer
    try:
        yield
    finally:
        if outer is None:
            _LOCAL.lent = None


def figure_with_axes(kind: str, width: float, height: float, make_axes: Callable[[Any], Any]) -> tuple[Any, Any]:
    """``(figure, axes)`` of a report plot ``kind``: a new figure of ``width`` × ``height`` inches and its axes
    ``make_axes(figure)``, or, inside :func:`reusing_figures`, the kept one emptied (call inside
    :func:`~camfab.report.plots.plot_style`)."""
    from .plots import new_figure

    lent = getattr(_LOCAL, "lent", None)
    if lent is None:
        fig = new_figure(width, height)
        return fig, make_axes(fig)
    kept: dict = _LOCAL.__dict__.setdefault("kept", {})
    key = (kind, width, height)
    if key in lent:  # the same kind twice in one block: a figure of its own
        fig = new_figure(width, height)
        return fig, make_axes(fig)
    lent.add(key)
    if key in kept:
        fig, axes = kept[key]
        _empty(fig)
        return fig, axes
    fig = new_figure(width, height)
    kept[key] = (fig, make_axes(fig))
    return kept[key]


def _empty(fig) -> None:
    """The figure as :func:`~camfab.report.plots.new_figure` and its ``subplots`` left it, the axes and their
    tick objects kept: every artist a plot adds removed, the default scales (locators, formatters), limits
    from the data, automatic title placement, the subplot grid's default margins and constrained layout
    (:func:`~camfab.report.layout.fixed_layout` measures it again at the save)."""
    import matplotlib

    for ax in fig.axes:
        if ax.get_legend() is not None:
            ax.get_legend().remove()
        for artist in [*ax.lines, *ax.texts, *ax.patches, *ax.collections, *ax.artists, *ax.images, *ax.tables]:
            artist.remove()
        for axis, set_scale in ((ax.xaxis, ax.set_xscale), (ax.yaxis, ax.set_yscale)):
            if not _default_scale(axis):  # matplotlib's default locator and formatter again (set_xticks left a
                set_scale("linear")       # fixed one); for shared axes, the first one's call resets them all
        for loc in ("center", "left", "right"):
            if ax.get_title(loc):  # an empty title is left as it is: the set_title giving it a text sets its font
                ax.set_title("", loc=loc)
        ax.set_xlabel("")
        ax.set_ylabel("")
        ax.set_aspect("auto")
        ax.set_prop_cycle(None)  # the colour cycle from its start
        ax.margins(x=matplotlib.rcParams["axes.xmargin"], y=matplotlib.rcParams["axes.ymargin"])
        ax.relim()
        ax.set_autoscale_on(False)  # the limits below set without an autoscale of the emptied axes first (~25 %)
        ax.set_xlim(0.0, 1.0)  # a new axes' view: an artist placed in points or axes units (an arrow, a
        ax.set_ylim(0.0, 1.0)  # marker) adds to the data limits through the view it meets when added
        ax.set_autoscale_on(True)
        ax._autotitlepos = True  # matplotlib's switch (fixed_layout turned it off)
    if fig.get_suptitle():
        fig.suptitle("")
    grid = fig.axes[0].get_subplotspec().get_gridspec()
    grid.update(left=None, right=None, top=None, bottom=None, hspace=None, wspace=None)
    for ax in fig.axes:
        ax.set_position(ax.get_subplotspec().get_position(fig))
    fig.set_layout_engine("constrained")


def _default_scale(axis) -> bool:
    """Whether ``axis`` has the linear scale with the default locators and formatters it was made with: setting
    the scale again (~0.7 ms an axis, each shared one reset too) would only replace them by equal new ones (the
    default locators keep no state; ``ScalarFormatter`` computes its offset, order of magnitude and format
    afresh from every set of ticks it formats)."""
    return (axis.get_scale() == "linear" and axis.isDefault_majloc and axis.isDefault_majfmt
            and axis.isDefault_minloc and axis.isDefault_minfmt)
