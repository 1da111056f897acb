"""Report figures: deterministic PNG/SVG bytes, the right plots per mechanism, sampling
at breakpoints, violation shading, and no matplotlib import at ``import camfab``."""
from __future__ import annotations

import subprocess
import sys
import xml.etree.ElementTree as ET

import numpy as np
import pytest

from camfab.design.spec import design_from_dict
from camfab.report._common import axis_of, finding_spans, sample_grid
from camfab.report.plots import figure_bytes, pressure_angle_figure, report_figures, svaj_figure
from tests.report.designs import checked_design

from .designs import DESIGNS

pytest.importorskip("jinja2", reason="HTML reports need jinja2")
pytest.importorskip("matplotlib", reason="report plots need matplotlib")

PNG = b"\x89PNG\r\n\x1a\n"


def test_import_camfab_does_not_import_matplotlib_or_jinja2():
    code = ("import sys, camfab, camfab.report, camfab.report.html, camfab.report.plots, camfab.report.compare; "
            "print(sorted(m for m in ('matplotlib', 'jinja2') if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "[]"


def test_figure_bytes_are_deterministic_and_valid(e9):
    spec = e9[0]
    a, b = svaj_figure(spec, spec.program()), svaj_figure(spec, spec.program())
    png1, png2 = figure_bytes(a, "png"), figure_bytes(b, "png")
    svg1, svg2 = figure_bytes(a, "svg"), figure_bytes(b, "svg")
    assert png1 == png2 and svg1 == svg2
    assert png1.startswith(PNG)
    root = ET.fromstring(svg1)
    assert root.tag.endswith("svg")
    assert b"<dc:date>" not in svg1
    with pytest.raises(ValueError, match="png, svg"):
        figure_bytes(a, "gif")


def test_sample_grid_takes_both_sides_of_every_breakpoint(e9):
    prog = e9[0].program()
    x = sample_grid(prog.period, prog.breakpoints, 1441)
    assert np.all(np.diff(x) > 0) and x[0] == 0.0 and x[-1] < prog.period
    for b in prog.junctions_x[1:-1]:
        assert b in x and np.any(np.abs(x - b + 1e-9 * prog.period) < 1e-15)
    J = prog.evaluate(x)[3]
    i = np.searchsorted(x, prog.junctions_x[1])  # 50°: the jerk jump is drawn as a vertical line
    assert abs(J[i] - J[i - 1]) > 0.5 * abs(prog.peaks()[3].max)


@pytest.mark.parametrize("name", sorted(DESIGNS))
def test_every_mechanism_gets_its_plots(name):
    spec, geom, rep = checked_design(design_from_dict(DESIGNS[name]))
    figs = report_figures(spec, geom, rep)
    assert list(figs)[:3] == ["svaj", "profile", "curvature"]
    kinds = {c.kind for c in geom.profiles}
    assert ("face_position" in figs) == ("flat" in kinds or any(c.curved_face for c in geom.profiles))
    assert ("pressure_angle" in figs) == ("roller" in kinds or spec.follower.motion == "oscillating")
    for fig in figs.values():
        assert fig.axes and all(ax.lines for ax in fig.axes)


def test_profile_plot_has_the_circles(e9):
    spec, geom, rep = e9
    ax = report_figures(spec, geom, rep)["profile"].axes[0]
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert "base circle Rb = 35 mm" in labels and "prime circle Rp = 42 mm" in labels
    assert "R min = 35.00 mm (Ø min = 70.00 mm)" in labels and "R max = 45.00 mm (Ø max = 90.00 mm)" in labels
    assert "pitch curve" in labels and "cam centre" in labels


def test_pressure_angle_violations_are_shaded(bad, e9):
    from matplotlib.collections import PolyCollection

    spec, geom, rep = bad
    ax = pressure_angle_figure(spec, geom, rep).axes[0]
    shaded = [c for c in ax.collections if isinstance(c, PolyCollection) and len(c.get_paths())]  # not junctions
    assert len(shaded) >= 2  # fill_between beyond +lim and -lim
    spans = finding_spans(rep.findings, ("PRESSURE_ANGLE_EXCEEDED",), axis_of(spec.program()))
    assert len(spans) == 4
    patches = [p for p in ax.patches]  # axvspan rectangles, one per finding range
    assert len(patches) >= 4
    ok = pressure_angle_figure(*e9).axes[0]
    assert not [c for c in ok.collections if isinstance(c, PolyCollection) and len(c.get_paths())]


def test_finding_spans_split_a_wrapping_range(e9):
    from camfab.results import Finding, IssueCode, Severity

    f = Finding(IssueCode.UNDERCUT, Severity.ERROR, 350.0, 10.0, 1.0, 2.0, "x")
    assert finding_spans([f], (IssueCode.UNDERCUT,), axis_of(e9[0].program())) == [(350.0, 360.0), (0.0, 10.0)]
