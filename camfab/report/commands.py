"""Command-line glue for reports: ``camfab compare`` and ``camfab report``.

The functions follow :mod:`camfab.cli`'s convention (``fn(args) -> exit code`` with
``fn.add_arguments(parser)``) but do not register themselves; ``camfab/cli.py``
registers them::

    from .report.commands import cmd_compare, cmd_report
    register("compare", "overlaid plots and a side-by-side table of several designs")(cmd_compare)
    register("report", "HTML report with plots and an animation of the mechanism")(cmd_report)

:func:`design_report_files` is what ``camfab run`` calls for the ``report`` output.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from ..errors import MissingDependencyError
from ..formats import load_design, resolve_design_path

__all__ = ["checked_design", "design_report_files", "cmd_compare", "cmd_report", "require_report_dependencies"]


def require_report_dependencies() -> None:
    """Raise :class:`MissingDependencyError` (exit code 3) without jinja2 or matplotlib."""
    for mod in ("jinja2", "matplotlib"):
        try:
            __import__(mod)
        except ImportError as exc:
            raise MissingDependencyError(f"HTML reports need {mod}: pip install {mod}") from exc


def checked_design(spec):
    """``(spec, geometry, report)`` of a design: the ``camfab check`` report (tool radius
    from ``[manufacturing]``, knot-table warnings included)."""
    from ..design.assemble import check_design, geometry_from_spec

    tool = spec.manufacturing.tool_diameter_mm
    geometry = geometry_from_spec(spec)
    report = check_design(spec, tool_radius_mm=tool / 2 if tool else None)
    return spec, geometry, report


def design_report_files(spec, *, standalone: bool = False) -> dict[str, bytes]:
    """The report files of one design (``report.html`` and ``plots/…``), see
    :func:`camfab.report.html.render_report`."""
    from .html import render_report

    require_report_dependencies()
    return render_report(*checked_design(spec), standalone=standalone)


def _out_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("-o", "--out", required=True, metavar="DIR", help="output directory")
    p.add_argument("--standalone", action="store_true",
                   help="embed the plots in the HTML page (one self-contained file; plots/ is written too)")


def _compare_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("files", nargs="+", metavar="FILE", help="design files (TOML) or built-in example names")
    _out_args(p)


def cmd_compare(args: argparse.Namespace) -> int:
    """``camfab compare FILE FILE… -o DIR``: writes ``compare.html`` and ``plots/``; exit 0."""
    from .compare import render_comparison
    from .html import write_files

    require_report_dependencies()
    items = [checked_design(load_design(resolve_design_path(f))) for f in args.files]
    paths = write_files(render_comparison(items, standalone=args.standalone), args.out)
    for spec, _, rep in items:
        print(f"{spec.name}: {rep.verdict}")
    print(f"wrote {paths[0]} (+{len(paths) - 1} plot files)", file=sys.stderr)
    return 0


cmd_compare.add_arguments = _compare_args  # type: ignore[attr-defined]


def _report_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("file", metavar="FILE", help="design file (TOML) or built-in example name")
    _out_args(p)


def cmd_report(args: argparse.Namespace) -> int:
    """``camfab report FILE -o DIR``: writes ``report.html`` and ``plots/``; exit 1 if unacceptable."""
    from .html import render_report, write_files

    require_report_dependencies()
    spec, geometry, report = checked_design(load_design(resolve_design_path(args.file)))
    paths = write_files(render_report(spec, geometry, report, standalone=args.standalone), args.out)
    print(f"{spec.name}: {report.verdict}")
    print(f"wrote {Path(paths[0])} (+{len(paths) - 1} plot files)", file=sys.stderr)
    return 1 if report.verdict == "unacceptable" else 0


cmd_report.add_arguments = _report_args  # type: ignore[attr-defined]
