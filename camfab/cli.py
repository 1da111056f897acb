"""The ``camfab`` command line: argument parsing and presentation only; the work is :mod:`camfab.pipeline`'s.

Exit codes (the user-facing contract, ``docs/decisions.md``, "The user-facing contract"): 0 success; 1 computed
but fails its checks; 2 invalid input (design file, options); 3 I/O error or a missing optional dependency.
``-v`` / ``--verbose`` shows the ``camfab`` logger's INFO records (the fallbacks taken) on stderr; its warnings
are shown always.
"""
from __future__ import annotations

import argparse
import contextlib
import contextvars
import dataclasses
import json
import math
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

from . import pipeline
from .cad.kind_exports import applicable, kind_exporter
from .errors import ApiError, CamfabError, InternalError, MissingDependencyError, SpecError, UnreachableError
from .exitcodes import EXIT_BROKEN_PIPE, EXIT_CHECKS, EXIT_INPUT, EXIT_INTERRUPTED, EXIT_IO, EXIT_OK
from .io import atomic_write, inside, output_folder, write_all
from .pipeline import Cam, Output, Request
from .results import Severity, Verdict
from .terminal import first_interrupt_only, log_to_stderr, raise_if_interrupted, stdout_to_devnull
from .textsafe import plain
from .version import __version__

__all__ = ["main", "register", "COMMANDS", "UsageError"]

#: every subcommand: name → (run(args) -> exit code, add_arguments(parser), help)
COMMANDS: dict[str, tuple[Callable[[argparse.Namespace], int], Callable[[argparse.ArgumentParser], None], str]] = {}


class UsageError(CamfabError):
    """A command-line option that cannot be honoured (exit code 2)."""


def register(name: str, help: str, arguments: Callable[[argparse.ArgumentParser], None]):
    """Register ``fn(args) -> int`` as the subcommand ``name`` with its options."""

    def deco(fn: Callable[[argparse.Namespace], int]) -> Callable[[argparse.Namespace], int]:
        COMMANDS[name] = (fn, arguments, help)
        return fn

    return deco


#: ``--allow-outside-files`` of the command being run (set by :func:`_guarded`)
_ALLOW_OUTSIDE: contextvars.ContextVar[bool] = contextvars.ContextVar("allow_outside_files", default=False)


def _cam(name: str) -> Cam:
    """The design ``name`` (a TOML or xlsx file, or a built-in example) as a :class:`~camfab.pipeline.Cam`;
    its knot file may lie outside its folder only with ``--allow-outside-files``."""
    return pipeline.load(name, allow_outside_files=_ALLOW_OUTSIDE.get())


def _tol(cam: Cam, value: float | None) -> float:
    try:
        return cam.tolerance(value)
    except SpecError:  # the design's own tolerance_mm: its field path, not the option
        raise
    except ValueError as exc:
        raise UsageError(f"--tol {value}: {exc}") from None


def _exit(verdict: Verdict) -> int:
    return EXIT_CHECKS if verdict == Verdict.UNACCEPTABLE else EXIT_OK


# ---------------------------------------------------------------------------
def _motion_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("file", help="design file (TOML) or built-in example name")
    p.add_argument("--step-deg", type=float, default=1.0,
                   help="sampling step of the CSV (degrees; mm for translating cams), default 1")
    p.add_argument("--csv", metavar="OUT", help="write angle_deg,S,V,A,J to this CSV file")
    p.add_argument("--json", action="store_true", help="print one JSON object instead of the tables")
    p.add_argument("--peaks", choices=("exact", "camdas"), default="exact",
                   help="analytic extremes (default) or CAM-DAS 1-degree sampling")


@register("motion", "follower motion: segment table, continuity, peaks, verdict, CSV", _motion_args)
def cmd_motion(args: argparse.Namespace) -> int:
    from .design.assemble import knot_findings
    from .design.motion_report import analyse_motion
    from .report.text import format_motion, motion_csv, segment_rows

    spec = _cam(args.file).spec
    prog = spec.program()
    step = args.step_deg
    if not (math.isfinite(step) and step > 0 and prog.period / prog.axis.x_scale / step <= 1e7):
        raise UsageError(f"--step-deg {step}: must be > 0 and give at most 1e7 rows")
    report = analyse_motion(prog, name=spec.name, speed=spec.speed, lift_unit=spec.follower.lift_unit,
                            peaks_mode=args.peaks, allow_acceleration_jump=spec.cam.kind.symmetric)
    report = dataclasses.replace(report, findings=report.findings + tuple(knot_findings(spec)))
    if args.csv:
        atomic_write(args.csv, motion_csv(prog, spec.speed, step))
    if args.json:
        print(json.dumps({**report.to_dict(), "segments": segment_rows(prog)}, indent=2))
    else:
        print(format_motion(spec, prog, report))
        if args.csv:
            print(f"wrote {args.csv}")
    return _exit(report.verdict)


def _check_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("file", help="design file (TOML) or built-in example name")
    p.add_argument("--json", action="store_true", help="print one JSON object instead of the table")


@register("check", "profile checks: CAM-DAS conclusions table, findings and verdict", _check_args)
def cmd_check(args: argparse.Namespace) -> int:
    from .report.text import format_check

    cam = _cam(args.file)
    report = cam.check()
    print(json.dumps(report.to_dict(), indent=2) if args.json else format_check(cam.spec, report))
    return _exit(report.verdict)


def _refuse_unacceptable(cam: Cam, command: str, force: bool) -> bool:
    """True (and why, on stderr) when the design is unacceptable and the command is not forced."""
    report = cam.check()
    if report.verdict != Verdict.UNACCEPTABLE or force:
        return False
    errs = sorted({str(f.code) for f in report.findings if f.severity == Severity.ERROR})
    print(f"camfab {command}: {plain(cam.name)} is unacceptable ({', '.join(errs) or report.verdict}): nothing written "
          "(use --force to write anyway)", file=sys.stderr)
    return True


# ---------------------------------------------------------------------------
def _export_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("file", help="design file (TOML) or built-in example name")
    p.add_argument("--dxf", action="store_true", help="write the DXF drawing of the profile")
    p.add_argument("--step", action="store_true", help="write the STEP solid (needs cadquery)")
    p.add_argument("--stl", action="store_true", help="write the STL mesh")
    p.add_argument("--assembly", action="store_true",
                   help="write the mechanism as a STEP assembly: cam, shaft, follower, frame (needs cadquery)")
    p.add_argument("--iges", action="store_true", help="write the plate as IGES for older CAM systems (needs cadquery)")
    _assembly_args(p)
    p.add_argument("--tol", type=float, default=None,
                   help="max distance of every entity from the exact profile, mm (default: the design's, 0.001)")
    p.add_argument("--dxf-flavour", choices=("lwpolyline", "r12", "spline"), default="lwpolyline",
                   help="LWPOLYLINE with bulges (default), R12 LINE/ARC entities, or one exact rational SPLINE")
    p.add_argument("--tool-path", action="store_true",
                   help="add the tool-centre path of [manufacturing] tool_diameter_mm to the DXF (TOOL_PATH layer)")
    p.add_argument("--force", action="store_true", help="export even if the design's verdict is unacceptable")
    p.add_argument("-o", "--output", required=True, metavar="DIR", help="output folder")


@register("export", "DXF, STEP and STL files within a measured tolerance of the exact profile", _export_args)
def cmd_export(args: argparse.Namespace) -> int:
    _check_assembly_args(args)
    cam = _cam(args.file)
    kinds = ("dxf", "step", "stl", "assembly", "iges")
    formats = [f for f in kinds if getattr(args, f)] or [f for f in kinds if getattr(cam.spec.outputs, f)]
    if not formats:
        raise UsageError("nothing to export: give --dxf, --step, --stl or --assembly, or enable them in [outputs]")
    tol = _tol(cam, args.tol)
    with output_folder(args.output) as folder:  # created, writable and locked before computing (else exit 3)
        if _refuse_unacceptable(cam, "export", args.force):
            return EXIT_CHECKS
        req = Request(frozenset(Output(f) for f in formats), tol=tol, dxf_flavour=args.dxf_flavour,
                      tool_paths=args.tool_path, angle=args.angle, poses=args.poses)
        found, skip = applicable(cam, [out for out in pipeline.EXPORTERS if out in req.outputs])
        arts = [a for out in found for a in kind_exporter(cam.spec.cam.kind, out, pipeline.EXPORTERS[out])(cam, req)]
        targets = [inside(folder, a.filename) for a in arts]  # all proved inside -o before any write
        paths = write_all({t: a.data for t, a in zip(targets, arts, strict=True)})  # all files or none
    print(f"{plain(cam.name)}: verdict {cam.verdict}, tolerance {tol:g} mm")
    print(f"  {'file':<32}{'entities':>10}{'max deviation (mm)':>22}")
    for a, p in zip(arts, paths, strict=True):
        ents = "-" if a.entities is None else str(a.entities)
        dev = "-" if a.deviation_mm is None else f"{a.deviation_mm:.3g}"
        print(f"  {str(p):<32}{ents:>10}{dev:>22}")
    for out, why in skip.items():
        print(f"  skipped {out}: {why}")
    return _exit(cam.verdict)  # forced files of an unacceptable design: written, and still exit 1


# ---------------------------------------------------------------------------
#: the job flags of ``camfab gcode`` and ``camfab verify`` (flag dest → [machining] key, or [manufacturing]
#: tool_diameter_mm / material), added to both parsers by :func:`_job_flags`
_JOB_FLAGS = {"tool_diameter": "tool_diameter_mm", "material": "material", "tool_material": "tool_material",
              "flutes": "tool_flutes", "max_rpm": "max_spindle_rpm", "tool_number": "tool_number",
              "rpm": "spindle_rpm", "feed": "feed_mm_min", "plunge_feed": "plunge_feed_mm_min",
              "step_down": "step_down_mm", "breakthrough": "breakthrough_mm", "roughing_passes": "roughing_passes",
              "allowance": "roughing_allowance_mm", "direction": "direction", "coolant": "coolant", "units": "units",
              "safe_z": "safe_z_mm", "stock_diameter": "stock_diameter_mm", "mill_bore": "mill_bore",
              "compensation": "compensation", "lines_only": "lines_only"}
#: what verify may not be told: how the program is written, not what it must do
_GCODE_ONLY = ("units", "compensation", "lines_only")


def _job_flags(g: argparse._ArgumentGroup, *, verify: bool = False) -> None:
    """The job flags (each overrides the design's value, its default in brackets) of ``gcode`` and ``verify``."""
    g.add_argument("--tool-diameter", type=float, metavar="MM",
                   help="end mill diameter ([manufacturing] tool_diameter_mm)")
    g.add_argument("--material", help="work material of the cutting-data table ([manufacturing] material)")
    g.add_argument("--tool-material", choices=("carbide", "hss"), help="[carbide]")
    g.add_argument("--flutes", type=int, help="flutes of the end mill [the table's for the material]")
    g.add_argument("--max-rpm", type=float, help="the machine's highest spindle speed [10000]")
    g.add_argument("--tool-number", type=int, help="T word and H/D register [1]")
    g.add_argument("--rpm", type=float, help="spindle speed [from the cutting-data table]")
    g.add_argument("--feed", type=float, help="cutting feed, mm/min [from the cutting-data table]")
    g.add_argument("--plunge-feed", type=float, help="feed of descending moves, mm/min [half the feed]")
    g.add_argument("--step-down", type=float, help="largest depth per level, mm [3]")
    g.add_argument("--breakthrough", type=float, help="depth below the plate, mm [0.5]")
    g.add_argument("--roughing-passes", type=int, help="roughing passes per level [1]")
    g.add_argument("--allowance", type=float, help="radial finishing allowance, mm [0.2]")
    g.add_argument("--direction", choices=("climb", "conventional"), help="[climb]")
    g.add_argument("--coolant", choices=("flood", "mist", "off"), help="[flood]")
    g.add_argument("--safe-z", type=float, help="safe height for rapids, mm [25]")
    g.add_argument("--stock-diameter", type=float, help="round blank diameter, mm [part + 2 x 2 mm]")
    g.add_argument("--mill-bore", action="store_const", const=True,
                   help="mill the bore by helical interpolation ([machining] mill_bore)")
    if verify:
        return
    g.add_argument("--units", choices=("mm", "inch"), help="[mm]")
    g.add_argument("--compensation", choices=("G41", "G42"),
                   help="emit the part contour with cutter compensation instead of tool-centre coordinates")
    g.add_argument("--lines-only", action="store_const", const=True,
                   help="write the finishing contour as G1 lines (no G2/G3)")


def _job_overrides(args: argparse.Namespace) -> dict[str, Any]:
    """The job flags given on the command line, by design key (None: not given)."""
    return {key: getattr(args, flag, None) for flag, key in _JOB_FLAGS.items()}


def _gcode_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("file", help="design file (TOML) or built-in example name")
    p.add_argument("--post", choices=("linuxcnc", "fanuc", "grbl"), default=None,
                   help="controller dialect (default: [outputs] gcode, else linuxcnc)")
    p.add_argument("--tol", type=float, default=None, help="tool-path tolerance, mm (default: the design's)")
    _job_flags(p.add_argument_group("machining", "override the design's [machining] table (its defaults in "
                                               "brackets)"))
    p.add_argument("--lift-table", metavar="CSV", help="also write the polar lift table for cam grinders")
    p.add_argument("--lift-step", type=float, default=1.0, help="lift-table step in degrees (divides 360)")
    p.add_argument("--force", action="store_true", help="write even if the design's verdict is unacceptable")
    p.add_argument("-o", "--output", required=True, metavar="OUT.nc")


@register("gcode", "contour-milling G-code (LinuxCNC, Fanuc, GRBL) of the cam periphery", _gcode_args)
def cmd_gcode(args: argparse.Namespace) -> int:
    cam = _cam(args.file)
    tol = _tol(cam, args.tol)
    machining = _job_overrides(args)
    req = Request(frozenset({Output.GCODE}), args.post or cam.spec.outputs.gcode or "linuxcnc", tol=tol,
                  machining=machining, lift_step_deg=args.lift_step)
    pipeline.gcode_job(cam.spec, tol=tol, overrides=machining)  # a bad job is refused before the check
    _refuse_compensation(req.post, pipeline.machining_of(cam.spec, machining).compensation, args.compensation)
    out = Path(args.output)
    # the folders of the program and the lift table: created and proved writable before computing (else exit 3);
    # not locked (gcode writes single named files, often beside others' files)
    with contextlib.ExitStack() as stack:
        for folder in dict.fromkeys(p.parent for p in (out, *([Path(args.lift_table)] if args.lift_table else []))):
            stack.enter_context(output_folder(folder, lock=False))
        if _refuse_unacceptable(cam, "gcode", args.force):
            return EXIT_CHECKS
        arts = kind_exporter(cam.spec.cam.kind, "gcode", pipeline.EXPORTERS[Output.GCODE])(cam, req)
        names = [out if len(arts) == 1 else out.with_name(f"{out.stem}_cam{i + 1}{out.suffix}")
                 for i in range(len(arts))]
        files: dict[Path, bytes | str] = {n: a.data for n, a in zip(names, arts, strict=True)}
        if args.lift_table:
            files[Path(args.lift_table)] = pipeline.EXPORTERS[Output.LIFT_TABLE](cam, req)[0].data
        write_all(files)  # the programs and the lift table: all or none
    for name, a in zip(names, arts, strict=True):
        print(f"wrote {name}: {req.post}, {a.entities} contour entities, max deviation {a.deviation_mm:.3g} mm "
              f"(tol {tol:g} mm)")
    if args.lift_table:
        print(f"wrote {args.lift_table}")
    return _exit(cam.verdict)  # forced files of an unacceptable design: written, and still exit 1


def _refuse_compensation(post: str, compensation: str | None, flag: str | None) -> None:
    """A controller without cutter radius compensation cannot run a G41/G42 program: refused before any work."""
    from .gcode import get_post

    if compensation and not get_post(post).compensation:
        where = f"--compensation {flag}" if flag else f"[machining] compensation = {compensation!r}"
        raise UsageError(f"{where}: the {post} post has no cutter radius compensation ({post} rejects G41/G42), so "
                         "it cannot run a program of the part contour; leave compensation out to write the tool-centre "
                         "program (what the controller needs), or choose --post linuxcnc or fanuc")


def _verify_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("program", help="G-code file to verify")
    p.add_argument("--design", required=True, help="the design the program should cut")
    p.add_argument("--tol", type=float, default=None, help="tolerance, mm (default: the design's)")
    p.add_argument("--profile", type=int, default=1, help="which profile of a conjugate pair (1 or 2)")
    p.add_argument("--comp-radius", type=float, default=None, metavar="MM",
                   help="radius in the controller's D register for G41/G42 programs (default: the tool radius)")
    p.add_argument("--post", choices=("linuxcnc", "fanuc", "grbl"), default=None,
                   help="controller the program is for (default: the one its header names, else [outputs] gcode, "
                        "else linuxcnc): whether T.. M6 and G43 H.. are expected")
    _job_flags(p.add_argument_group("job", "what the program must do, when the gcode command was given other "
                                           "values than the design's"), verify=True)
    p.add_argument("--json", action="store_true")


@register("verify", "back-plot a G-code program and check it against the exact design and its job", _verify_args)
def cmd_verify(args: argparse.Namespace) -> int:
    from .gcode.cam import verify_cam_program
    from .gcode.verify import VerifyReport

    cam = _cam(args.design)
    if cam.spec.cam.kind == "cylindrical" and args.post == "grbl":  # a 4-axis program (README)
        raise UsageError("--post grbl: the grbl controller has no rotary (A) axis, so it cannot run a cylindrical "
                         "cam's 4-axis program; choose --post linuxcnc or --post fanuc")
    tol = _tol(cam, args.tol)
    if args.comp_radius is not None and not (math.isfinite(args.comp_radius) and args.comp_radius > 0):
        raise UsageError(f"--comp-radius {args.comp_radius:g}: must be a positive radius in mm")
    profiles = cam.geometry.profiles
    if not 1 <= args.profile <= len(profiles):
        raise UsageError(f"--profile {args.profile}: the design has {len(profiles)} profile(s)")
    job = pipeline.gcode_job(cam.spec, tol=tol, overrides=_job_overrides(args))
    data = Path(args.program).read_bytes()  # a missing file is an I/O error (3); an unreadable one a finding
    rep: VerifyReport
    if cam.spec.cam.kind == "cylindrical":  # the 4-axis program of the groove or rib (camfab.gcode.cylinder)
        from .gcode.cylinder import verify_cylinder_program

        rep = verify_cylinder_program(data, cam.geometry, job, tol=tol)
    elif cam.spec.cam.kind == "groove":  # both flanks are the targets (camfab.gcode.groove)
        from .gcode.groove import verify_groove_program

        rep = verify_groove_program(data, profiles[0], profiles[1], job, tol=tol, post=args.post,
                                    default_post=cam.spec.outputs.gcode or "linuxcnc", comp_radius=args.comp_radius)
    else:
        rep = verify_cam_program(data, profiles[args.profile - 1], job, tol=tol, post=args.post,
                                 default_post=cam.spec.outputs.gcode or "linuxcnc", comp_radius=args.comp_radius)
    if args.json:
        print(json.dumps(rep.to_dict(), indent=2))
    else:
        dev = rep.max_deviation_mm
        print(f"{args.program}: {'OK' if rep.ok else 'FAILED'}; max deviation "
              f"{'-' if dev is None else f'{dev:.3g}'} mm (tol {tol:g}); gouge: {'yes' if rep.gouge else 'no'}")
        for pr in rep.problems:
            print(f"  [{pr.code}] line {pr.line}: {pr.message}")
    return EXIT_OK if rep.ok else EXIT_CHECKS


# ---------------------------------------------------------------------------
def outputs_list(text: str | None) -> list[str] | None:
    """``--outputs dxf,report`` → the outputs named (None when the option is not given)."""
    if text is None:
        return None
    wanted = [w.strip() for w in text.split(",") if w.strip()]
    names = [o.value for o in Output]
    bad = [w for w in wanted if w not in names]
    if bad:
        raise UsageError(f"--outputs: '{bad[0]}' is not a valid option, must be one of: {', '.join(names)}")
    return wanted


def _assembly_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("--angle", type=float, default=0.0, metavar="DEG",
                   help="cam angle of the assembly STEP, degrees (mm of travel for a translating cam; default 0)")
    p.add_argument("--poses", type=int, default=0, metavar="N",
                   help="also write N assembly STEPs at equally spaced cam angles from --angle (a motion check "
                        "in CAD; default 0)")


def _check_assembly_args(args: argparse.Namespace) -> None:
    """--angle and --poses refused at once when out of range (before any computing)."""
    if not math.isfinite(args.angle) or abs(args.angle) > 1e6:
        raise UsageError(f"--angle {args.angle}: must be a finite number of at most 1e6 (degrees; mm of travel "
                         "for a translating cam)")
    if not 0 <= args.poses <= pipeline.MAX_POSES:
        raise UsageError(f"--poses {args.poses}: must be a whole number from 0 to {pipeline.MAX_POSES}")


def _run_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("file", nargs="?", default=None,
                   help="design file (TOML or xlsx) or example name; default: the built-in example ejemplo9rt")
    p.add_argument("-o", "--output", required=True, metavar="DIR")
    p.add_argument("--outputs", metavar="LIST", help="comma list overriding [outputs]: " +
                   ",".join(o.value for o in Output))
    p.add_argument("--tol", type=float, default=None, help="export tolerance, mm (default: the design's)")
    p.add_argument("--force", action="store_true", help="write shop artifacts even for an unacceptable design")
    _assembly_args(p)


@register("run", "the main job: every artifact the design's [outputs] asks for", _run_args)
def cmd_run(args: argparse.Namespace) -> int:
    _check_assembly_args(args)
    cam = _cam(args.file or "ejemplo9rt")
    outputs = outputs_list(args.outputs)
    _tol(cam, args.tol)
    req = Request.from_design(cam.spec, outputs, tol=args.tol, force=args.force,
                              post="linuxcnc" if outputs is not None else None, angle=args.angle, poses=args.poses)
    res = pipeline.run(cam, args.output, req, progress=lambda m: print(f"  ... {m}", file=sys.stderr))
    print(f"{plain(cam.name)}: verdict {res.verdict}; tolerance {res.tol:g} mm; {len(res.files)} file(s) in "
          f"{args.output}")
    for name in res.files:
        dev = res.deviations.get(name)
        print(f"  {name:<36}" + ("" if dev is None else f" max deviation {dev:.3g} mm"))
    if res.withheld:
        print(f"  withheld (verdict unacceptable, use --force): {', '.join(res.withheld)}")
    if res.skipped:
        print(f"  skipped (cadquery is missing: pip install cadquery): {', '.join(res.skipped)}")
    for out, why in res.not_applicable.items():
        print(f"  skipped {out}: {why}")
    if res.removed:
        print(f"  removed (an earlier run's shop files; verdict unacceptable): {', '.join(res.removed)}")
    return _exit(Verdict(res.verdict))


def _package_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("paths", nargs="+", metavar="PATH", help="design files or folders (searched recursively)")
    p.add_argument("-o", "--output", required=True, metavar="DIR")
    p.add_argument("--jobs", type=int, default=1, help="designs built in parallel (processes)")
    p.add_argument("--outputs", metavar="LIST", help="comma list overriding every design's [outputs]")
    p.add_argument("--force", action="store_true", help="write shop artifacts even for unacceptable designs")
    p.add_argument("--executor", choices=("builtin", "dask", "dask-local"), default="builtin",
                   help="where the cams are built: camfab's process pool (default), a Dask cluster (--scheduler), "
                        "or a local Dask cluster (--dask-workers); Dask needs pip install camfab[dask]")
    p.add_argument("--scheduler", metavar="ADDRESS", help="the Dask scheduler's address (with --executor dask)")
    p.add_argument("--dask-workers", type=int, metavar="N", help="worker processes of --executor dask-local "
                   "(default: one per CPU)")
    p.add_argument("--dask-config", action="append", metavar="KEY=VALUE",
                   help="a Dask setting over camfab's (repeatable), e.g. distributed.worker.profile.enabled=true")


@register("package", "many designs in parallel: per-cam folders, index.html, manifest.json, incremental",
          _package_args)
def cmd_package(args: argparse.Namespace) -> int:
    from .package import exit_status, package

    if args.jobs < 1:
        raise UsageError(f"--jobs {args.jobs}: must be at least 1")
    missing = [p for p in args.paths if not Path(p).exists()]
    if missing:
        raise UsageError(f"no such file or folder: {missing[0]}")
    from .package_dask import executor_options

    dask = executor_options(args.executor, args.scheduler, args.dask_workers, args.dask_config, args.jobs)
    manifest = package(args.paths, args.output, jobs=args.jobs, outputs=outputs_list(args.outputs),
                       force=args.force, progress=lambda m: print(m, file=sys.stderr),
                       allow_outside_files=args.allow_outside_files, **dask)
    cams = manifest["cams"]
    rebuilt = sum(1 for c in cams if c.get("rebuilt"))
    bad = [c for c in cams if c.get("status") == "error"]
    print(f"{len(cams)} design(s), {rebuilt} rebuilt, {len(bad)} failed; index: {Path(args.output) / 'index.html'}")
    for c in bad:
        print(f"  {c['source']}: {c['error']}", file=sys.stderr)
    return exit_status(manifest)


# ---------------------------------------------------------------------------
def _report_out_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("-o", "--out", required=True, metavar="DIR", help="output directory")
    p.add_argument("--standalone", action="store_true",
                   help="embed the plots in the HTML page (one self-contained file; plots/ is written too)")
    p.add_argument("--png", action="store_true", help="also write every plot as PNG (the page shows the SVG)")


def _report_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("file", metavar="FILE", help="design file (TOML) or built-in example name")
    _report_out_args(p)


@register("report", "HTML report with plots and an animation of the mechanism", _report_args)
def cmd_report(args: argparse.Namespace) -> int:
    """``camfab report FILE -o DIR``: writes ``report.html`` and ``plots/``; exit 1 if unacceptable."""
    from .report.html import render_report, require_report_dependencies, write_files

    require_report_dependencies()
    cam = _cam(args.file)
    with output_folder(args.out) as folder:  # created, writable and locked before computing (else exit 3)
        paths = write_files(render_report(cam.spec, cam.geometry, cam.check(), standalone=args.standalone,
                                                  png=args.png), folder)
    print(f"{plain(cam.name)}: {cam.verdict}")
    print(f"wrote {Path(paths[0])} (+{len(paths) - 1} plot files)", file=sys.stderr)
    return _exit(cam.verdict)


def _compare_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("files", nargs="+", metavar="FILE", help="design files (TOML) or built-in example names")
    _report_out_args(p)


@register("compare", "overlaid S-V-A-J, curvature and pressure-angle plots and a side-by-side table", _compare_args)
def cmd_compare(args: argparse.Namespace) -> int:
    """``camfab compare FILE FILE… -o DIR``: writes ``compare.html`` and ``plots/``; exit 0."""
    from .report.compare import render_comparison
    from .report.html import require_report_dependencies, write_files

    require_report_dependencies()
    cams = [_cam(f) for f in args.files]
    with output_folder(args.out) as folder:  # created, writable and locked before computing (else exit 3)
        items = [(c.spec, c.geometry, c.check()) for c in cams]
        paths = write_files(render_comparison(items, standalone=args.standalone, png=args.png), folder)
    for c in cams:
        print(f"{plain(c.name)}: {c.verdict}")
    print(f"wrote {paths[0]} (+{len(paths) - 1} plot files)", file=sys.stderr)
    return EXIT_OK


def _examples_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("--json", action="store_true", help="print one JSON list instead of one name per line")


@register("examples", "the names of the built-in example designs (usable wherever a FILE is asked)", _examples_args)
def cmd_examples(args: argparse.Namespace) -> int:
    names = pipeline.examples()
    print(json.dumps(names) if args.json else "\n".join(names))
    return EXIT_OK


# ---------------------------------------------------------------------------
def build_parser(argv: list[str] | None = None) -> argparse.ArgumentParser:
    """The parser; given ``argv``, of the command it runs alone (its first argument that is not an option: the
    top-level ones take no value), same help and errors without building every command's (~10 ms of a start)."""
    only = next((a for a in argv or () if not a.startswith("-")), None)
    parser = argparse.ArgumentParser(prog="camfab", description="Cam design, checks and manufacturing files.")
    parser.add_argument("--version", action="version", version=f"camfab {__version__}")
    parser.add_argument("-v", "--verbose", action="store_true", help=_VERBOSE_HELP)
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name, (_, arguments, help_text) in COMMANDS.items():
        if only in COMMANDS and name != only:
            continue
        p = sub.add_parser(name, help=help_text, description=help_text)
        arguments(p)
        p.add_argument("-v", "--verbose", action="store_true", default=argparse.SUPPRESS, help=_VERBOSE_HELP)
        if name in _READS_DESIGNS:
            p.add_argument("--allow-outside-files", action="store_true", help=_OUTSIDE_HELP)
    return parser


_VERBOSE_HELP = "also log the fallbacks camfab takes (logger 'camfab', INFO) on stderr"
#: the commands that read design files, and so take --allow-outside-files
_READS_DESIGNS = ("motion", "check", "export", "gcode", "verify", "run", "package", "report", "compare")
_OUTSIDE_HELP = ("let a design read a knot file ([motion_table] file) outside its own folder (only for designs "
                 "you trust)")


def main(argv: list[str] | None = None) -> int:
    """Run the command line; returns the exit code (testable in-process)."""
    parser = build_parser(sys.argv[1:] if argv is None else argv)
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:  # argparse: 0 for --help/--version, 2 for bad options
        return int(exc.code or 0)
    if not args.command:
        parser.print_help(sys.stderr)
        return EXIT_INPUT
    try:
        with log_to_stderr(args.verbose), first_interrupt_only():
            code = _guarded(args)
    except KeyboardInterrupt:  # Ctrl-C: one line, no traceback; what was being written has been removed
        print(f"camfab {args.command}: interrupted", file=sys.stderr)
        code = EXIT_INTERRUPTED
    try:
        sys.stdout.flush()  # a pipe closed by the reader shows here when the output fitted in its buffer
    except BrokenPipeError:
        stdout_to_devnull()
    return code


def _guarded(args: argparse.Namespace) -> int:
    """Run the command; the deliberate errors become their exit codes and a one-line message: a missing
    optional dependency 3; every other :class:`~camfab.errors.CamfabError` (SpecError, UsageError,
    GeometryError, InputError, ExportError, ...) is invalid input, 2.  ApiError and InternalError are bugs
    of camfab, not of the input: they keep their traceback.  Any error after a Ctrl-C is the interrupt
    (:func:`~camfab.terminal.interrupt_came`): exit 130, "interrupted", not the error's message."""
    fn: Any = COMMANDS[args.command][0]
    token = _ALLOW_OUTSIDE.set(bool(getattr(args, "allow_outside_files", False)))
    try:
        try:
            return int(fn(args))
        except Exception:
            raise_if_interrupted()  # the interrupt, turned into this error (terminal.interrupt_came)
            raise
    except (MissingDependencyError, UnreachableError) as exc:  # the environment lacks something: exit 3
        print(f"camfab {args.command}: error: {exc}", file=sys.stderr)
        return EXIT_IO
    except BrokenPipeError:  # stdout closed by its reader: stop quietly, as a command killed by SIGPIPE does
        stdout_to_devnull()
        return EXIT_BROKEN_PIPE
    except (ApiError, InternalError):
        raise
    except CamfabError as exc:
        print(f"camfab {args.command}: error: {exc}", file=sys.stderr)
        if isinstance(exc, SpecError) and getattr(args, "json", False):  # every problem, machine-readable
            print(json.dumps(exc.to_dict(), indent=2))
        return EXIT_INPUT
    except OSError as exc:
        print(f"camfab {args.command}: I/O error: {exc}", file=sys.stderr)
        return EXIT_IO
    finally:
        _ALLOW_OUTSIDE.reset(token)
from . import cli_design  # noqa: E402,F401  (registers the size and optimise commands)
