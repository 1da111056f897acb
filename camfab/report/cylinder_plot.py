"""The unrolled-profile figure of a cylindrical cam's report: the groove developed on the pitch cylinder.

The development is :mod:`camfab.design.cylindrical`'s (docs/decisions.md, "Cylindrical cams"): x = R·θ along the
circumference (0 to 2πR, one turn), z along the cylinder's axis.  The figure draws the developed pitch curve
(the roller axis's track) and both flanks on the pitch radius R, exact (sampled, not fitted), the developed
cylinder (its ends z = 0 and z = length) and the cam angle on a second axis along the top.
"""
from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..textsafe import mpl_text
from ._common import sample_grid
from .plots import new_figure, plot_style

__all__ = ["unrolled_figure", "unrolled_curves", "UNROLLED_PLOT_TEXT"]

#: (title, caption) of the unrolled-profile plot, by file stem (merged into the report's plot text)
UNROLLED_PLOT_TEXT = {
    "unrolled": ("Unrolled groove",
                 "The groove developed on the pitch cylinder (x = R·θ along the circumference, z along the axis; "
                 "top axis: cam angle): the pitch curve the roller's axis follows and both flanks, half the groove "
                 "width (roller radius plus half the backlash) either side along the developed normal. The grey "
                 "lines are the cylinder's ends; the workbook's Cylinder sheet has the same curves on the groove "
                 "bottom and the outer cylinder."),
}


def unrolled_curves(geometry: Any, *, n: int = 1441) -> dict[str, np.ndarray]:
    """The developed pitch curve and flanks on the pitch radius, each (m, 2) mm (x = R·θ, z), at the cam angles of
    the report's grid (``theta``, radians; breakpoints included)."""
    R = geometry.cylinder.radius_mm
    plus, minus = geometry.at_radius(R, 1), geometry.at_radius(R, -1)
    theta = sample_grid(plus.period, plus.breakpoints, n)
    sp, sm = plus.evaluate(theta), minus.evaluate(theta)
    return {"theta": theta, "pitch": sp.pitch, "plus": sp.point, "minus": sm.point}


def unrolled_figure(spec: Any, geometry: Any, report: Any = None, *, n: int = 1441) -> Any:
    """The unrolled groove (see the module notes); lines labelled ``pitch curve``, ``+z flank``, ``-z flank``."""
    del report  # the same signature as the other report figures
    cyl = geometry.cylinder
    R, L = cyl.radius_mm, cyl.length_mm
    cur = unrolled_curves(geometry, n=n)
    width = 2 * math.pi * R
    with plot_style():
        fig = new_figure(9.0, max(2.6, 9.0 * L / width + 1.3))
        ax = fig.subplots()
        for z in (0.0, L):
            ax.axhline(z, color="0.55", lw=0.9)
        ax.plot(*cur["pitch"].T, color="C0", lw=1.0, ls="--", label="pitch curve")
        ax.plot(*cur["plus"].T, color="C3", label="+z flank")
        ax.plot(*cur["minus"].T, color="C2", label="-z flank")
        ax.set_xlim(0.0, width)
        ax.set_ylim(-0.05 * L, 1.05 * L)
        ax.set_aspect("equal")
        ax.set_xlabel(f"developed x = R·θ (mm), pitch radius R = {R:g} mm")
        ax.set_ylabel("z along the axis (mm)")
        top = ax.secondary_xaxis("top", functions=(lambda x: np.degrees(x / R), lambda d: np.radians(d) * R))
        top.set_xticks(np.arange(0.0, 361.0, 45.0))
        top.set_xlabel("cam angle (°)")
        ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)
        rib = cyl.rib_width_mm
        what = (f"rib unrolled on the pitch cylinder (width {rib:g} mm where it runs round)" if rib is not None
                else f"groove unrolled on the pitch cylinder (width {2 * geometry.mechanism.half_width(R):g} mm)")
        fig.suptitle(f"{mpl_text(spec.name)}: {what}", fontsize=11)
    return fig
