"""The report plots written as SVG by hand (camfab/report/svgfig.py): read back with xml.etree, a curve's points
mapped to data through the axes' box and its tick labels are the motion law's closed forms; a figure the writer
does not draw is saved by matplotlib."""
from __future__ import annotations

import re
import xml.etree.ElementTree as ET

import numpy as np
import pytest

pytest.importorskip("matplotlib", reason="report plots need matplotlib")

from camfab.report.plots import figure_bytes, new_figure, plot_style, svaj_figure  # noqa: E402
from camfab.report.svgfig import figure_svg  # noqa: E402

NS = {"s": "http://www.w3.org/2000/svg"}


def _points(d: str) -> np.ndarray:
    """The vertices of an ``M…L…`` path (several subpaths joined)."""
    return np.array([float(v) for v in re.findall(r"-?\d+(?:\.\d+)?", d)]).reshape(-1, 2)


def _number(text: str) -> float:
    return float(text.replace("\u2212", "-"))


def test_the_displacement_curve_read_back_is_the_motion_law(e9):
    spec = e9[0]
    svg = figure_bytes(svaj_figure(spec, spec.program()), "svg")
    assert b"<!DOCTYPE" not in svg  # written by svgfig, not matplotlib
    root = ET.fromstring(svg)
    ax = root.find(".//s:g[@id='axes0']", NS)  # the displacement axes
    box = ax.find("s:clipPath/s:rect", NS)
    x0, x1 = float(box.get("x")), float(box.get("x")) + float(box.get("width"))
    ticks = [(float(t.get("y")), _number("".join(t.itertext()))) for t in ax.findall("s:text[@class='ytick']", NS)]
    assert len(ticks) >= 3
    py, val = np.array(ticks).T
    a, b = np.polyfit(py, val, 1)  # data = a·y + b: the SVG's y runs down, so a < 0
    assert a < 0 and np.allclose(a * py + b, val, atol=1e-3 * np.ptp(val))  # positions to 0.01 px
    lines = ax.findall("s:path[@class='line']", NS)
    pts = max((_points(p.get("d")) for p in lines), key=len)  # the curve: the line with the most points
    deg = (pts[:, 0] - x0) / (x1 - x0) * 360.0
    s = a * pts[:, 1] + b
    assert len(pts) > 1400 and deg.min() < 0.01 and deg.max() > 359.7
    # Ejemplo9RT: a 3-4-5 polynomial rise of 10 mm over 180-230°, a cycloidal return of 10 mm over 90-140°
    u = (deg - 180.0) / 50.0
    rise = (u > 0) & (u < 1)
    assert rise.sum() > 150
    want = 10.0 * (10 * u**3 - 15 * u**4 + 6 * u**5)
    assert np.abs(s[rise] - want[rise]).max() < 0.01
    u = (deg - 90.0) / 50.0
    ret = (u > 0) & (u < 1)
    want = 10.0 * (1.0 - (u - np.sin(2 * np.pi * u) / (2 * np.pi)))
    assert np.abs(s[ret] - want[ret]).max() < 0.01
    dwell = (deg > 232.0) & (deg < 268.0)
    assert np.abs(s[dwell] - 10.0).max() < 0.01
    assert root.find(".//s:text[@class='suptitle']", NS) is not None


def test_a_figure_it_does_not_draw_goes_to_matplotlib():
    with plot_style():
        fig = new_figure(4.0, 3.0)
        ax = fig.subplots()
        ax.plot([1.0, 10.0, 100.0], [1.0, 2.0, 3.0])
        ax.set_xscale("log")
        fig.set_layout_engine(None)
        assert figure_svg(fig) is None
        svg = figure_bytes(fig, "svg")
    assert b"<!DOCTYPE svg" in svg and ET.fromstring(svg).tag.endswith("svg")
