"""The report's follower-vibration figure (``[vibration]``): the elastic follower against the kinematic one,
and the contact force with the vibration against the rigid follower's (docs/decisions.md, "Follower vibration").
"""
from __future__ import annotations

import math
from typing import Any

from ..design.assemble import loads_from_spec
from ..design.vibration import FollowerTrain
from ..design.vibration_results import VibrationSummary
from ..design.vibration_spec import train_of
from ..results import IssueCode
from ..textsafe import mpl_text
from ._common import axis_of, finding_spans
from .plots import boundaries, new_figure, plot_style, shade, x_axis

__all__ = ["vibration_figure", "vibration_figures", "VIBRATION_PLOT_TEXT"]

#: file stem → (title, caption) of the vibration plot (merged into the report's plot texts)
VIBRATION_PLOT_TEXT = {
    "vibration": ("Follower vibration",
                  "The elastic follower train (one mass on the train's spring and damper, in its periodic steady "
                  "state at the design speed) against the kinematic motion: top, the follower displacement; middle, "
                  "their difference (the train's deflection and ringing); bottom, the contact force with the "
                  "vibration against the rigid follower's. Red bands: the follower leaves the cam."),
}


def vibration_figure(spec, geometry, report):
    """Three panels against the cam angle: the dynamic and kinematic follower displacement, their
    difference, and the contact force with and without the vibration (``FOLLOWER_SEPARATES_VIBRATION``
    ranges shaded, the minimum marked).

    Parameters
    ----------
    spec : DesignSpec
        With ``[dynamics]`` and ``[vibration]`` sections.
    geometry : CamGeometry
    report : CheckReport
        From :func:`camfab.design.assemble.check_design` (its ``vibration`` summary and findings).

    Returns
    -------
    matplotlib.figure.Figure
    """
    model = FollowerTrain(geometry.profiles[0], loads_from_spec(spec.dynamics), train_of(spec.vibration))
    r = model.response(spec.speed)
    prog = spec.program()
    axis = axis_of(prog)
    c = geometry.profiles[0]
    lift = 180.0 / math.pi if c.oscillating else 1e3
    lu = "°" if c.oscillating else "mm"
    x = r.x * axis.scale
    summary = report.vibration if isinstance(report.vibration, VibrationSummary) else None
    with plot_style():
        fig = new_figure(9.0, 7.6)
        ax, ax2, ax3 = fig.subplots(3, 1, sharex=True, height_ratios=(3, 2, 3))
        ax.plot(x, r.s * lift, color="0.45", lw=1.0, ls="--", label="kinematic s")
        ax.plot(x, r.w * lift, color="C0", label="elastic follower y")
        ax.set_ylabel(f"follower ({lu})")
        ax.set_title("Follower displacement", loc="left", fontsize=9)
        ax2.plot(x, (r.w - r.s) * lift, color="C4", label="y − s")
        ax2.axhline(0.0, color="0.2", lw=0.6)
        ax2.set_ylabel(f"y − s ({lu})")
        ax2.set_title("Deviation from the kinematic motion", loc="left", fontsize=9)
        ax3.plot(x, r.kinematic_force, color="0.45", lw=1.0, ls="--", label="rigid follower")
        ax3.plot(x, r.contact_force, color="C0", label="with vibration")
        ax3.axhline(0.0, color="0.1", lw=0.9, label="N = 0 (separation)")
        shade(ax3, finding_spans(report.findings, (IssueCode.FOLLOWER_SEPARATES_VIBRATION,), axis),
              label="follower leaves the cam")
        if summary is not None and summary.contact_force.at_min is not None:
            v, at = summary.contact_force.min, summary.contact_force.at_min
            ax3.plot([at], [v], "o", color="0.1", ms=3.5)
            ax3.annotate(f"{v:.4g} N", (at, v), xytext=(5, -4), textcoords="offset points", fontsize=7, va="top")
        ax3.set_ylabel("contact force N (N)")
        ax3.set_title("Contact force", loc="left", fontsize=9)
        for a in (ax, ax2, ax3):
            boundaries(a, prog, axis)
            a.margins(y=0.12)
            a.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)
        x_axis(ax3, axis)
        speed = f"{spec.speed * 30 / math.pi:.4g} rpm" if axis.closed else f"{spec.speed:.4g} mm/s"
        fn = f", f_n = {model.natural_frequency_hz:.4g} Hz"
        fig.suptitle(f"{mpl_text(spec.name)}: follower vibration at {speed}{fn}", fontsize=11)
    return fig


def vibration_figures(spec, geometry, report) -> dict[str, Any]:
    """``{"vibration": figure}`` for a design with ``[vibration]`` (and ``[dynamics]``), else ``{}``."""
    if spec.vibration is None or spec.dynamics is None:
        return {}
    return {"vibration": vibration_figure(spec, geometry, report)}
