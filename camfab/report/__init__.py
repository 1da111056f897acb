"""Reports: HTML report with plots and a mechanism animation, and design comparisons.

``import camfab.report`` is light: matplotlib and jinja2 are imported only when a
figure or a page is made.

Examples
--------
>>> from camfab.formats import load_design
>>> from camfab.design.assemble import geometry_from_spec, check_design
>>> from camfab.report import render_report, write_files
>>> spec = load_design("camfab/examples/ejemplo9rt.toml")          # doctest: +SKIP
>>> files = render_report(spec, geometry_from_spec(spec), check_design(spec))  # doctest: +SKIP
>>> write_files(files, "out/report")                                         # doctest: +SKIP
"""
from __future__ import annotations

from .compare import render_comparison
from .html import render_report, write_files
from .plots import (
    curvature_figure,
    face_position_figure,
    figure_bytes,
    pressure_angle_figure,
    profile_figure,
    report_figures,
    svaj_figure,
)

__all__ = ["render_report", "render_comparison", "write_files", "figure_bytes", "svaj_figure", "profile_figure",
           "curvature_figure", "pressure_angle_figure", "face_position_figure", "report_figures"]
