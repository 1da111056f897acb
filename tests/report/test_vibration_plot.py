"""The follower-vibration figure and text lines (``[vibration]``): what they draw is the check's vibration
summary and an independent :class:`~camfab.design.vibration.FollowerTrain` solution; no figure without the
section."""
from __future__ import annotations

import numpy as np
import pytest

from camfab.design.assemble import check_design, loads_from_spec
from camfab.design.mechanisms import geometry_from_spec
from camfab.design.spec import design_from_dict
from camfab.design.vibration import FollowerTrain, Train
from camfab.report.text import format_check
from camfab.report.vibration_plot import vibration_figure, vibration_figures
from camfab.results import IssueCode

pytest.importorskip("matplotlib")

DESIGN = {"name": "vib", "cam": {"kind": "disc", "speed_rpm": 3000.0},
          "follower": {"type": "roller", "motion": "translating", "base_radius_mm": 30.0, "roller_radius_mm": 8.0},
          "motion": [{"law": "dwell", "angle_deg": 90.0}, {"law": "cycloidal", "lift": 8.0, "angle_deg": 90.0},
                     {"law": "cycloidal", "lift": -8.0, "angle_deg": 90.0}, {"law": "dwell", "angle_deg": 90.0}],
          "dynamics": {"mass_kg": 0.2, "spring_rate_n_per_mm": 20.0, "spring_preload_n": 300.0},
          "vibration": {"stiffness_n_per_mm": 2000.0, "damping_ratio": 0.05}}


def test_vibration_figure_draws_the_steady_state():
    spec = design_from_dict(DESIGN)
    geom = geometry_from_spec(spec)
    report = check_design(spec)
    fig = vibration_figure(spec, geom, report)
    ax, ax2, ax3 = fig.axes[:3]
    train = FollowerTrain(geom.profiles[0], loads_from_spec(spec.dynamics), Train(2e6, 0.05))
    r = train.response(spec.speed)
    lines = {ln.get_label(): ln for a in (ax, ax3) for ln in a.get_lines()}
    np.testing.assert_allclose(lines["elastic follower y"].get_ydata(), r.w * 1e3, rtol=1e-12)
    force = lines["with vibration"].get_ydata()
    np.testing.assert_allclose(force, r.contact_force, rtol=1e-12)
    summary = report.vibration
    assert force.min() == pytest.approx(summary.contact_force.min, rel=1e-3)
    seps = report.by_code(IssueCode.FOLLOWER_SEPARATES_VIBRATION)
    assert seps and len(ax3.patches) == len(seps)  # one red band per separation range
    text = format_check(spec, report)
    assert f"separation speed: {summary.separation_speed.value:.6g} rpm" in text


def test_no_vibration_section_no_figure():
    d = {k: v for k, v in DESIGN.items() if k != "vibration"}
    spec = design_from_dict(d)
    report = check_design(spec)
    assert vibration_figures(spec, geometry_from_spec(spec), report) == {}
    assert report.vibration is None and "follower vibration" not in format_check(spec, report)


def test_html_report_shows_the_vibration_plot():
    from camfab.report.html import render_report

    spec = design_from_dict(DESIGN)
    files = render_report(spec, geometry_from_spec(spec), check_design(spec), frames=12)
    assert files["plots/vibration.svg"].startswith(b"<?xml")
    html = files["report.html"].decode("utf-8")
    assert 'src="plots/vibration.svg"' in html and "Follower vibration" in html
    assert "FOLLOWER_SEPARATES_VIBRATION" in html
