"""The report's fixed plot layout (camfab/report/layout.py) keeps every label readable: after a figure is
saved, every visible text — tick labels, axis labels, titles, the suptitle, legend entries, annotations — lies
inside the figure, and the stacked axes of one figure do not overlap (docs/decisions.md "Plot layout")."""
from __future__ import annotations

import pytest

import camfab

pytest.importorskip("matplotlib")

from matplotlib.text import Text  # noqa: E402

from camfab.report.plots import figure_bytes, report_figures  # noqa: E402

#: cams of every figure kind: roller, flat face, oscillating, curved face, conjugate, dynamics, translating
EXAMPLES = ["ejemplo9rt", "valve_mushroom", "finger_follower", "ejemplo8da_conjugate", "press_feed_oscillating",
            "wedge_translating", "constant_width"]


def _drawn_texts(fig) -> list[Text]:
    """Every visible, non-empty text the figure draws: tick labels only of the ticks inside the view (matplotlib
    keeps, undrawn, the labels of ticks it placed for an earlier view)."""
    ticks, kept = set(), []
    for ax in fig.axes:
        for axis in (ax.xaxis, ax.yaxis):
            lo, hi = sorted(axis.get_view_interval())
            tol = 1e-9 * ((hi - lo) or 1.0)
            for tick in axis.get_major_ticks() + axis.get_minor_ticks():
                ticks.update({id(tick.label1), id(tick.label2)})
                if lo - tol <= tick.get_loc() <= hi + tol:
                    kept += [lab for lab in (tick.label1, tick.label2) if lab.get_visible()]
    kept += [t for t in fig.findobj(Text) if id(t) not in ticks and t.get_visible()]
    return [t for t in kept if t.get_text().strip()]


@pytest.mark.slow
@pytest.mark.parametrize("example", EXAMPLES)
def test_every_text_inside_the_figure(example):
    cam = camfab.load(example)
    figs = report_figures(cam.spec, cam.geometry, cam.check())
    for name, fig in figs.items():
        assert figure_bytes(fig, "png")[:4] == b"\x89PNG"
        fig.canvas.draw()  # at the figure's own dpi (the save's renderer had savefig.dpi); the layout is fixed
        renderer = fig.canvas.get_renderer()
        box = fig.bbox
        outside = []
        for t in _drawn_texts(fig):
            e = t.get_window_extent(renderer)
            if e.x0 < box.x0 - 0.5 or e.y0 < box.y0 - 0.5 or e.x1 > box.x1 + 0.5 or e.y1 > box.y1 + 0.5:
                outside.append((t.get_text(), tuple(round(v) for v in e.extents)))
        assert not outside, f"{example} {name}: texts outside the figure {tuple(box.extents)}: {outside}"
        boxes = [ax.get_window_extent(renderer) for ax in fig.axes]
        for a, b in zip(boxes, boxes[1:], strict=False):
            assert not a.overlaps(b), f"{example} {name}: axes overlap"
        for ax, own in zip(fig.axes, boxes, strict=True):  # a title clears the other axes (the one above it)
            names = {ax.get_title(loc) for loc in ("center", "left", "right")} - {""}
            for t in (c for c in ax.get_children() if isinstance(c, Text) and c.get_text() in names):
                hit = [o for o in boxes if o is not own and t.get_window_extent(renderer).overlaps(o)]
                assert not hit, f"{example} {name}: title {t.get_text()!r} overlaps other axes"


def test_legend_extent_is_matplotlibs_after_the_axes_move():
    """The legend's packed box measured once (layout.legend_extent) gives matplotlib's own window extent, before
    the layout and after it moved the axes (the SVG writer's call)."""
    from camfab.report.layout import fixed_layout, legend_extent
    from camfab.report.plots import new_figure

    fig = new_figure(6.0, 4.0)  # the report's figures: an Agg canvas, constrained layout until fixed_layout
    ax = fig.subplots()
    ax.plot([0, 1], [0, 2], label="a line")
    ax.axhline(1.0, color="r", label="a limit, longer")
    leg = ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)
    r = fig.canvas.get_renderer()
    assert tuple(legend_extent(leg, r).bounds) == pytest.approx(tuple(leg.get_window_extent(r).bounds), abs=1e-9)
    fixed_layout(fig)  # the axes move; the legend with them
    assert tuple(legend_extent(leg, r).bounds) == pytest.approx(tuple(leg.get_window_extent(r).bounds), abs=1e-9)
