"""The trade-off (Pareto) plot of ``camfab optimise``: two objectives of the optimum for a sweep of weights.

Drawn with the report's conventions (:func:`camfab.report.plots.new_figure`, ``figure_bytes``: deterministic
SVG); the design's name only through :func:`camfab.textsafe.mpl_text`.
"""
from __future__ import annotations

from collections.abc import Sequence

from ..textsafe import mpl_text
from .plots import figure_bytes, new_figure, plot_style

__all__ = ["pareto_figure", "pareto_svg"]


def pareto_figure(rows: Sequence[tuple[float, float, float]], labels: tuple[str, str], *, name: str = "",
                  start: tuple[float, float] | None = None):
    """The optimum's two objectives for each weight t of the second (rows ``(t, first, second)``), joined in
    the order of t, each point labelled with its weight; the start design as a cross."""
    with plot_style():
        fig = new_figure(6.4, 4.6)
        ax = fig.add_subplot()
        xs = [r[1] for r in rows]
        ys = [r[2] for r in rows]
        second = labels[1].split(" (", 1)[0]
        ax.plot(xs, ys, "-o", color="#1f77b4", label=f"optimum with weight t on the {second}, 1 − t on the other")
        for t, x, y in rows:
            ax.annotate(f"t = {t:.2g}", (x, y), textcoords="offset points", xytext=(5, 4), fontsize=7)
        if start is not None:
            ax.plot([start[0]], [start[1]], "x", color="#d62728", markersize=8, label="start design")
        ax.set_xlabel(labels[0])
        ax.set_ylabel(labels[1])
        ax.set_title(mpl_text(f"Trade-off: {name}" if name else "Trade-off"))
        ax.legend(loc="best")
    return fig


def pareto_svg(rows: Sequence[tuple[float, float, float]], labels: tuple[str, str], *, name: str = "",
               start: tuple[float, float] | None = None) -> bytes:
    """:func:`pareto_figure` as SVG bytes."""
    return figure_bytes(pareto_figure(rows, labels, name=name, start=start), "svg")
