"""The contact-stress figure of the report: Hertz stress along the cycle against the allowable
(:mod:`camfab.design.strength`), the ``CONTACT_STRESS_ABOVE_LIMIT`` ranges shaded, the exact peak marked."""
from __future__ import annotations

import numpy as np

from ..errors import InputError
from ..results import IssueCode, pair_names
from ..textsafe import mpl_text
from ._common import axis_of, finding_spans, fmt_at, sample_grid
from .plots import boundaries, new_figure, plot_style, shade, x_axis

__all__ = ["contact_stress_figure"]


def contact_stress_figure(spec, geometry, report, *, n: int = 1441):
    """Contact stress p_max (MPa) against the cam angle (travel of a translating cam), with the allowable line.

    Parameters
    ----------
    spec : DesignSpec
        With ``[dynamics]`` (the contact force).
    geometry : CamGeometry
    report : CheckReport
        From :func:`camfab.design.assemble.check_design` (its ``contact_stress`` summary and findings).

    Returns
    -------
    matplotlib.figure.Figure
    """
    from ..design.assemble import strength_input
    from ..design.strength import StressModel, effective_modulus

    inp = strength_input(spec, geometry)
    cs = report.contact_stress
    if inp is None or inp.dynamics is None or cs is None or cs.max_mpa is None:
        raise InputError(f"{spec.name}: no contact stress to plot (it needs a [dynamics] section and a roller or a "
                         "face follower)")
    e = effective_modulus(inp.cam.e_mpa, inp.cam.poisson, inp.follower.e_mpa, inp.follower.poisson)
    prog = spec.program()
    axis = axis_of(prog)
    c = geometry.profiles[0]
    x = sample_grid(c.period, c.breakpoints, n)
    sm = StressModel(inp.dynamics, e, inp.width_mm).evaluate(x)
    with plot_style():
        fig = new_figure(9.0, 3.6)
        ax = fig.subplots()
        pair = sm.stress_2 is not None
        names = pair_names(geometry.flank_pair)
        ax.plot(x * axis.scale, np.where(np.isfinite(sm.stress), sm.stress, np.nan), color="C0",
                label=names[0] if pair else "contact stress")
        if sm.stress_2 is not None:
            ax.plot(x * axis.scale, np.where(np.isfinite(sm.stress_2), sm.stress_2, np.nan), color="C1",
                    label=names[1])
        ax.axhline(inp.allowable_mpa, color="#d62728", lw=1.0, ls="--", label=f"allowable {inp.allowable_mpa:g} MPa")
        shade(ax, finding_spans(report.findings, (IssueCode.CONTACT_STRESS_ABOVE_LIMIT,), axis),
              label="above the allowable")
        ax.plot([cs.at], [cs.max_mpa], "o", color="0.1", ms=3.5)
        sf = "" if cs.safety_factor is None else f", S = {cs.safety_factor:.3g}"
        ax.annotate(f"{cs.max_mpa:.4g} MPa at {fmt_at(cs.at, axis.unit)}{sf}", (cs.at, cs.max_mpa), xytext=(5, 4),
                    textcoords="offset points", fontsize=7, va="bottom", color="0.1")
        ax.set_ylim(0.0, 1.15 * max(cs.max_mpa, inp.allowable_mpa))
        ax.set_ylabel("Hertz contact stress (MPa)")
        boundaries(ax, prog, axis)
        x_axis(ax, axis)
        ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)
        mats = f"{inp.cam.name} on {inp.follower.name}, face width {inp.width_mm:g} mm"
        fig.suptitle(f"{mpl_text(spec.name)}: contact stress ({mpl_text(mats)})", fontsize=11)
    return fig
