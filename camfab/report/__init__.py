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

from importlib import import_module
from typing import Any

#: each public name and the submodule that defines it, imported on first access (PEP 562), so that
#: ``camfab check`` (which needs only :mod:`camfab.report.text`) loads no page or figure code
_WHERE = {"render_comparison": "compare", "render_report": "html", "write_files": "html",
          **dict.fromkeys(("curvature_figure", "face_position_figure", "figure_bytes", "pressure_angle_figure",
                           "profile_figure", "report_figures", "svaj_figure"), "plots")}

__all__ = ["render_report", "render_comparison", "write_files", "figure_bytes", "svaj_figure", "profile_figure",
           "curvature_figure", "pressure_angle_figure", "face_position_figure", "report_figures"]


def __getattr__(name: str) -> Any:
    where = _WHERE.get(name)
    if where is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(import_module(f"{__name__}.{where}"), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted([*globals(), *__all__])
