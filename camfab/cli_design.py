"""``camfab size`` and ``camfab optimise``: the design commands (argument parsing and presentation only; the work
is :mod:`camfab.design.sizing_plan`'s and :mod:`camfab.design.optimise`'s, the files :mod:`camfab.formats`').

Registered on :data:`camfab.cli.COMMANDS` when :mod:`camfab.cli` imports this module; the exit codes and error
conventions are ``cli``'s (its ``_guarded``): 0 done, 1 the written design fails its checks, 2 invalid input
(nothing written), 3 I/O.
"""
from __future__ import annotations

import argparse
import copy
import dataclasses
import json
import sys
from pathlib import Path
from typing import Any

from .cli import UsageError, register
from .design.assemble import check_design
from .design.mechanisms import geometry_from_spec
from .design.spec import DesignSpec, design_from_dict
from .exitcodes import EXIT_CHECKS, EXIT_OK
from .formats.toml_write import design_data, dumps_design
from .io import atomic_write, output_folder, safe_stem
from .results import Verdict
from .textsafe import plain

__all__ = ["cmd_size", "cmd_optimise"]

_OUTSIDE_HELP = ("let a design read a knot file ([motion_table] file) outside its own folder (only for designs "
                 "you trust)")


def _tool_radius(spec: DesignSpec) -> float | None:
    d = spec.manufacturing.tool_diameter_mm
    return d / 2 if d else None


def _with(data: dict[str, Any], changes: dict[str, float]) -> dict[str, Any]:
    """A copy of the design dict with ``changes`` (``"table.key"`` → value) set."""
    new = copy.deepcopy(data)
    for path, value in changes.items():
        table, key = path.split(".", 1)
        new.setdefault(table, {})[key] = value
    return new


def _size_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("file", help="design file (TOML) or built-in example name")
    p.add_argument("-o", "--output", metavar="NEW.toml", help="write the sized design to this new TOML file")
    p.add_argument("--json", action="store_true", help="print one JSON object instead of the table")
    p.add_argument("--allow-outside-files", action="store_true", help=_OUTSIDE_HELP)


@register("size", "smallest base radius for each [sizing] constraint, the governing one, the best offset or pivot; "
          "-o writes the sized design", _size_args)
def cmd_size(args: argparse.Namespace) -> int:
    from .design.sizing_plan import size_design

    out = Path(args.output) if args.output else None
    if out is not None and out.suffix.lower() != ".toml":
        raise UsageError(f"-o {args.output}: the sized design is written as TOML; give a name ending in .toml")
    data, spec = design_data(args.file, allow_outside_files=args.allow_outside_files)
    if out is not None and spec.source and out.resolve() == Path(spec.source).resolve():
        raise UsageError(f"-o {args.output}: that is the design being sized; give a new file name")
    res = size_design(spec)
    new = _with(data, dict(res.changes))
    sized = design_from_dict(new, source=str(out) if out else spec.source)
    report = check_design(sized, tool_radius_mm=_tool_radius(sized))
    if out is not None:
        atomic_write(out, dumps_design(new, header=f"{plain(spec.name)}: sized by camfab size "
                                                   f"(governing constraint: {res.governing})"))
    if args.json:
        print(json.dumps({"name": spec.name, **res.to_dict(), "verdict": str(report.verdict),
                          "written": str(out) if out else None}, indent=2))
    else:
        print(f"{plain(spec.name)}: base radius {spec.follower.base_radius_mm:g} mm → {res.base_radius_mm:g} mm "
              f"(governing: {res.governing})")
        print(f"  {'constraint':<16}{'smallest base radius (mm)':>28}  ")
        for r in res.rows:
            val = f"{r.radius_mm:.6g}" if r.radius_mm is not None else "-"
            print(f"  {r.constraint:<16}{val:>28}  {'← governs' if r.governing else r.note}")
        if res.best_offset_mm is not None:
            print(f"  best offset (least peak pressure angle): {res.best_offset_mm:.6g} mm")
        if res.best_pivot_mm is not None:
            print(f"  best pivot distance and arm length: {res.best_pivot_mm[0]:.6g} mm, {res.best_pivot_mm[1]:.6g} mm")
        for k, v in res.changes.items():
            print(f"  set {k} = {v:g}")
        print(f"  verdict of the sized design: {report.verdict}")
        if out is not None:
            print(f"wrote {out}")
    return EXIT_CHECKS if report.verdict == Verdict.UNACCEPTABLE else EXIT_OK


def _optimise_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("file", help="design file (TOML) or built-in example name, with an [optimise] table")
    p.add_argument("-o", "--output", required=True, metavar="DIR",
                   help="output folder: the optimised design, optimise.json, compare.html and plots/")
    p.add_argument("--json", action="store_true", help="print one JSON object instead of the table")
    p.add_argument("--standalone", action="store_true", help="embed the plots in compare.html")
    p.add_argument("--allow-outside-files", action="store_true", help=_OUTSIDE_HELP)


@register("optimise", "optimise the [optimise] variables of a design for its objectives and constraints; writes the "
          "optimised design, a comparison report and the trade-off plot", _optimise_args)
def cmd_optimise(args: argparse.Namespace) -> int:
    from .design.optimise import OBJECTIVES, build_problem, pareto_sweep, solve
    from .report.compare import render_comparison
    from .report.html import require_report_dependencies, write_files
    from .report.pareto import pareto_svg

    require_report_dependencies()
    data, spec = design_data(args.file, allow_outside_files=args.allow_outside_files)
    prob = build_problem(data, spec)  # every input problem (exit 2) before the folder is touched
    stem = safe_stem(spec.name)
    with output_folder(args.output) as folder:  # created, writable and locked before computing (else exit 3)
        res = solve(prob)
        opt = spec.optimise
        assert opt is not None  # build_problem refused a design without [optimise]
        sweep = pareto_sweep(prob, opt.pareto, opt.pareto_points) if opt.pareto else None
        new_spec = design_from_dict(res.data, source=f"{stem}_optimised.toml")
        new_spec = dataclasses.replace(new_spec, name=f"{spec.name} (optimised)")  # the report's label only
        items = [(s, geometry_from_spec(s), check_design(s, tool_radius_mm=_tool_radius(s))) for s in (spec, new_spec)]
        files = render_comparison(items, standalone=args.standalone)
        summary: dict[str, Any] = {"name": spec.name, **res.to_dict(), "verdict_start": str(items[0][2].verdict),
                                   "verdict": str(items[1][2].verdict), "pareto": None}
        if sweep is not None and opt.pareto is not None:
            a, b = (OBJECTIVES[k] for k in opt.pareto)
            files["plots/pareto.svg"] = pareto_svg(sweep, (f"{a.title} ({a.unit})", f"{b.title} ({b.unit})"),
                                                   name=spec.name, start=(prob.start[a.measure], prob.start[b.measure]))
            summary["pareto"] = {"objectives": list(opt.pareto),
                                 "points": [{"weight": t, opt.pareto[0]: x, opt.pareto[1]: y} for t, x, y in sweep]}
        files[f"{stem}_optimised.toml"] = dumps_design(
            res.data, header=f"{plain(spec.name)}: optimised by camfab optimise").encode("utf-8")
        files["optimise.json"] = (json.dumps(summary, indent=2) + "\n").encode("utf-8")
        paths = write_files(files, folder)
    if args.json:
        print(json.dumps(summary, indent=2))
    else:
        print(f"{plain(spec.name)}: {'improved' if res.improved else 'the start is kept'}; score "
              f"{res.score_start:.6g} → {res.score:.6g} ({res.evaluations} evaluations)")
        for k, v in res.values.items():
            print(f"  {plain(k):<32}{res.start_values[k]:>14.6g} → {v:.6g}")
        for k in sorted(res.best):
            print(f"  {k:<32}{res.start[k]:>14.6g} → {res.best[k]:.6g}")
        print(f"  verdict: {items[0][2].verdict} → {items[1][2].verdict}")
    print(f"wrote {paths[0].parent} ({len(paths)} files)", file=sys.stderr)
    return EXIT_CHECKS if items[1][2].verdict == Verdict.UNACCEPTABLE else EXIT_OK
