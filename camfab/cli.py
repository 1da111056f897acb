"""The ``camfab`` command line: registered subcommands and exit codes.

Exit codes (``../shared/design.md`` §6): 0 success; 1 computed but fails its
checks; 2 invalid input (design file, options); 3 I/O error or a missing
optional dependency.  Only core modules are imported at the top: exporters with
heavy dependencies are imported inside the commands that need them.
"""
from __future__ import annotations

import argparse
import dataclasses
import json
import math
import sys
from pathlib import Path
from typing import Callable

import numpy as np

from . import __version__
from .errors import CamfabError, GeometryError, MissingDependencyError, SpecError
from .formats import load_design, resolve_design_path
from .io import atomic_write
from .results import FORCE_CODES, IssueCode, Severity, Verdict

__all__ = ["main", "register", "COMMANDS"]

EXIT_OK, EXIT_CHECKS, EXIT_INPUT, EXIT_IO = 0, 1, 2, 3
COMMANDS: dict[str, Callable] = {}


class UsageError(CamfabError):
    """A command-line option that cannot be honoured (exit code 2)."""


def register(name: str, help: str):
    """Register ``fn(args) -> int`` as a subcommand; ``fn.add_arguments(parser)`` adds its options."""

    def deco(fn):
        fn.command_name, fn.help = name, help
        COMMANDS[name] = fn
        return fn

    return deco


def _load(name: str):
    """The design ``name``: a TOML or xlsx file, or a built-in example."""
    return load_design(resolve_design_path(name))


# ---------------------------------------------------------------------------
def _motion_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("file", help="design file (TOML) or built-in example name")
    p.add_argument("--step-deg", type=float, default=1.0,
                   help="sampling step of the CSV (degrees; mm for translating cams), default 1")
    p.add_argument("--csv", metavar="OUT", help="write angle_deg,S,V,A,J to this CSV file")
    p.add_argument("--json", action="store_true", help="print one JSON object instead of the tables")
    p.add_argument("--peaks", choices=("exact", "camdas"), default="exact",
                   help="analytic extremes (default) or CAM-DAS 1-degree sampling")


@register("motion", "follower motion: segment table, continuity, peaks, verdict, CSV")
def cmd_motion(args: argparse.Namespace) -> int:
    from .design.motion_report import analyse_motion

    spec = _load(args.file)
    prog = spec.program()
    step = args.step_deg
    if not (math.isfinite(step) and step > 0 and prog.period / _x_scale(prog) / step <= 1e7):
        raise UsageError(f"--step-deg {step}: must be > 0 and give at most 1e7 rows")
    report = analyse_motion(prog, name=spec.name, speed=spec.speed, lift_unit=spec.follower.lift_unit,
                            peaks_mode=args.peaks,
                            allow_acceleration_jump=spec.cam.kind in ("constant_width", "constant_diameter"))
    report = dataclasses.replace(report, findings=report.findings + tuple(knot_findings(spec)))
    if args.csv:
        atomic_write(args.csv, motion_csv(prog, spec.speed, step))
    if args.json:
        data = report.to_dict()
        data["segments"] = _segment_rows(prog)
        print(json.dumps(data, indent=2))
    else:
        print(format_motion(spec, prog, report))
        if args.csv:
            print(f"wrote {args.csv}")
    return EXIT_CHECKS if report.verdict == Verdict.UNACCEPTABLE else EXIT_OK


cmd_motion.add_arguments = _motion_args


def knot_findings(spec) -> list:
    """KNOT_INCONSISTENT warnings (see :func:`camfab.design.assemble.knot_findings`)."""
    from .design.assemble import knot_findings as findings

    return findings(spec)


def _x_scale(prog) -> float:
    """Program units per user unit: radians per degree, or 1 (mm) for translating cams."""
    return math.pi / 180.0 if abs(prog.period - 2 * math.pi) < 1e-12 else 1.0


def motion_csv(prog, speed: float, step: float) -> str:
    """``angle_deg,S,V,A,J`` rows from 0 to 360 (or the cam length) inclusive, time units."""
    k = _x_scale(prog)
    n = int(math.floor(prog.period / k / step + 1e-9))
    xu = np.arange(n + 1) * step
    vals = prog.evaluate(xu * k) * (speed ** np.arange(4))[:, None]
    head = "angle_deg,S,V,A,J" if k != 1.0 else "position_mm,S,V,A,J"
    body = np.column_stack([xu, vals.T])
    lines = [head] + [",".join(f"{v:.10g}" for v in row) for row in body]
    return "\n".join(lines) + "\n"


def _segment_rows(prog) -> list[dict]:
    k = _x_scale(prog)
    rows = []
    for i, s in enumerate(prog.segments):
        rows.append({"index": i, "law": s.law, "title": s.title, "lift": s.lift,
                     "from": s.start / k, "to": s.end / k, "span": s.span / k,
                     "S_start": s.s0, "S_end": s.s0 + s.lift})
    return rows


def format_motion(spec, prog, report) -> str:
    """The human-readable motion summary."""
    lu = spec.follower.lift_unit
    xu = "°" if _x_scale(prog) != 1.0 else "mm"
    speed = (f"ω = {spec.speed:.6g} rad/s ({spec.speed * 60 / (2 * math.pi):.6g} rpm)"
             if xu == "°" else f"v = {spec.speed:.6g} mm/s")
    out = [f"{spec.name}: {spec.cam.kind} cam, {spec.follower.motion} {spec.follower.type} follower, {speed}"
           + ("" if spec.cam.speed_given else " [default speed]"), ""]
    out.append(f"{'#':>3}  {'law':<34}{'lift(' + lu + ')':>10}{'from(' + xu + ')':>10}{'to(' + xu + ')':>10}"
               f"{'S start':>10}{'S end':>10}")
    for r in _segment_rows(prog):
        out.append(f"{r['index'] + 1:>3}  {r['title'][:33]:<34}{r['lift']:>+10.4f}{r['from']:>10.4f}"
                   f"{r['to']:>10.4f}{r['S_start']:>10.4f}{r['S_end']:>10.4f}")
    out += ["", "Junctions: " + ", ".join(f"{j.at:g}{xu} {j.continuity}" for j in report.junctions), ""]
    units = {"S": lu, "V": f"{lu}/s", "A": f"{lu}/s²", "J": f"{lu}/s³"}
    out.append(f"Peaks ({report.peaks_mode}){'':14}{'max':>14}{'at':>10}{'min':>14}{'at':>10}")
    for q, p in report.peaks.items():
        out.append(f"  {q} ({units[q]}){'':<{22 - len(units[q])}}{p.max:>14.6g}{p.at_max:>10.4f}"
                   f"{p.min:>14.6g}{p.at_min:>10.4f}")
    out += ["", f"Verdict: {report.verdict}"]
    out += [f"  [{f.severity}] {f.code}: {f.message}" for f in report.findings]
    return "\n".join(out)


def _check_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("file", help="design file (TOML) or built-in example name")
    p.add_argument("--json", action="store_true", help="print one JSON object (design.md §6) instead of the table")


@register("check", "profile checks: CAM-DAS conclusions table, findings and verdict")
def cmd_check(args: argparse.Namespace) -> int:
    from .design.assemble import check_design

    spec = _load(args.file)
    tool = spec.manufacturing.tool_diameter_mm
    report = check_design(spec, tool_radius_mm=tool / 2 if tool else None)
    if args.json:
        print(json.dumps(report.to_dict(), indent=2))
    else:
        print(format_check(spec, report))
    return EXIT_CHECKS if report.verdict == Verdict.UNACCEPTABLE else EXIT_OK


cmd_check.add_arguments = _check_args

_VERDICT_TEXT = {Verdict.ACCEPTABLE: "Cam OK (acceptable)",
                 Verdict.NOT_FOR_HIGH_SPEED: "Not suitable for high speeds",
                 Verdict.UNACCEPTABLE: "Cam KO (unacceptable)"}


def format_check(spec, report) -> str:
    """The CAM-DAS style conclusions table."""
    lu = spec.follower.lift_unit
    codes = report.codes()
    cont = {"S": "Continuous",
            "V": "Discontinuous" if IssueCode.VELOCITY_DISCONTINUITY in codes else "Continuous",
            "A": "Discontinuous" if IssueCode.ACCELERATION_DISCONTINUITY in codes else "Continuous",
            "J": "Discontinuous" if IssueCode.JERK_DISCONTINUITY in codes else "Continuous"}
    names = {"S": f"Displacement ({lu})", "V": f"Velocity ({lu}/s)", "A": f"Acceleration ({lu}/s²)",
             "J": f"Jerk ({lu}/s³)"}
    rows = [(names[q], _num(p.max), _num(p.min), cont[q])
            for q, p in (report.motion.peaks.items() if report.motion is not None else ())]
    roc = report.curvature
    if roc is not None:
        bad = codes & {IssueCode.UNDERCUT, IssueCode.CUSP}
        rows.append(("Convex radius of curvature (mm)", "--", _num(roc.min_convex),
                     "undercut or cusp: see findings" if bad else "The profile is free of cusps and undercuts"))
        if roc.min_concave is not None:
            rows.append(("Concave radius of curvature (mm)", "--", _num(roc.min_concave),
                         "smallest concave radius (cutter must be smaller)"))
    pa = report.pressure_angle
    if pa is not None:
        ok = IssueCode.PRESSURE_ANGLE_EXCEEDED not in codes
        rows.append(("Pressure angle (°)", _num(pa.max), _num(pa.min),
                     "Acceptable" if ok else f"High pressure angle (> {pa.limit:g}°)"))
    face = report.face_length
    if face is not None:
        rows.append(("Face length left / right (mm)", _num(face.left), _num(face.right),
                     "minimum face length on each side to keep contact"))
    dyn = report.dynamics
    if dyn is not None:
        rows += _dynamics_rows(dyn, codes)
    width = max(len(r[0]) for r in rows) + 2
    out = [f"{spec.name}: {_VERDICT_TEXT[report.verdict]}", ""]
    out.append(f"{'Concept':<{width}}{'Maximum':>13}{'Minimum':>13}  Comments")
    out += [f"{a:<{width}}{b:>13}{c:>13}  {e}" for a, b, c, e in rows]
    extra = [("base_radius_mm", report.base_radius_mm), ("max_radius_mm", report.max_radius_mm),
             ("area_mm2", report.area_mm2), ("initial_arm_angle_deg", report.initial_arm_angle_deg)]
    out += [""] + [f"{k}: {v:.6g}" for k, v in extra if v is not None]
    if dyn is not None and not dyn.form_closed:
        pre, jump = dyn.preload_needed, dyn.jump_speed
        out.append(f"spring preload for the safety force: {pre.value:.6g} {pre.unit} (worst at {pre.at:.2f})")
        out.append("jump speed: " + ("none (the follower never leaves the cam)" if jump.value is None else
                                     f"{jump.value:.6g} {jump.unit} (first at {jump.at:.2f})"))
    if report.findings:
        out += ["", "Findings:"]
        out += [f"  [{f.severity}] {f.code}: {f.message}" for f in report.findings]
    return "\n".join(out)


def _dynamics_rows(dyn, codes) -> list[tuple[str, str, str, str]]:
    """The contact-force, drive and bearing rows of the conclusions table."""
    cf, rows = dyn.contact_force, []
    if dyn.form_closed:
        cf2, rev = dyn.second_contact_force, len(dyn.load_reversals or ())
        rows.append(("Contact force, follower 1 (N)", _num(cf.max), _num(cf.min), "form-closed: no jump"))
        rows.append(("Contact force, follower 2 (N)", _num(cf2.max), _num(cf2.min),
                     f"the load changes follower {rev} time{'s' if rev != 1 else ''} per turn"))
    else:
        rows.append(("Contact force (N)", _num(cf.max), _num(cf.min),
                     "below the safety force or jumping: see findings" if codes & set(FORCE_CODES) else
                     f"never below the safety force ({dyn.safety_force_n:g} N)"))
    rows.append(("Drive torque (N·m)" if dyn.torque else "Drive force (N)", _num(dyn.drive.max), _num(dyn.drive.min),
                 f"work per cycle {dyn.work_per_cycle_j:.4g} J, mean power {dyn.mean_power_w:.4g} W"))
    rows.append(("Camshaft bearing force (N)", _num(dyn.bearing_force.max), "--", ""))
    return rows


def _num(v) -> str:
    if v is None:
        return "--"
    if v != 0 and abs(v) < 0.01:
        return f"{v:.3g}"  # small forces and torques keep their digits
    return f"{v:.2f}" if abs(v) < 1e7 else f"{v:.5g}"


def _export_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("file", help="design file (TOML) or built-in example name")
    p.add_argument("--dxf", action="store_true", help="write the DXF drawing of the profile")
    p.add_argument("--step", action="store_true", help="write the STEP solid (needs cadquery)")
    p.add_argument("--stl", action="store_true", help="write the STL mesh")
    p.add_argument("--tol", type=float, default=None,
                   help="max distance of every entity from the exact profile, mm (default: the design's, 0.001)")
    p.add_argument("--dxf-flavour", choices=("lwpolyline", "r12", "spline"), default="lwpolyline",
                   help="LWPOLYLINE with bulges (default), R12 LINE/ARC entities, or one exact rational SPLINE")
    p.add_argument("--tool-path", action="store_true",
                   help="add the tool-centre path of [manufacturing] tool_diameter_mm to the DXF (TOOL_PATH layer)")
    p.add_argument("--force", action="store_true", help="export even if the design's verdict is unacceptable")
    p.add_argument("-o", "--output", required=True, metavar="DIR", help="output folder")


@register("export", "DXF, STEP and STL files within a measured tolerance of the exact profile")
def cmd_export(args: argparse.Namespace) -> int:
    from .cad.export import build_artifacts, write_artifacts
    from .design.assemble import check_design, geometry_from_spec
    from .discretize import validate_tol

    spec = _load(args.file)
    formats = [f for f in ("dxf", "step", "stl") if getattr(args, f)]
    if not formats:
        formats = [f for f in ("dxf", "step", "stl") if getattr(spec.outputs, f)]
    if not formats:
        raise UsageError("nothing to export: give --dxf, --step or --stl, or enable them in [outputs]")
    tol = spec.manufacturing.tolerance_mm if args.tol is None else args.tol
    try:
        tol = validate_tol(tol)
    except ValueError as exc:
        raise UsageError(f"--tol {args.tol}: {exc}") from None
    report = check_design(spec)
    if report.verdict == Verdict.UNACCEPTABLE and not args.force:
        print(format_check(spec, report), file=sys.stderr)
        print(f"camfab export: {spec.name} is unacceptable: nothing written (use --force to export anyway)",
              file=sys.stderr)
        return EXIT_CHECKS
    geom = geometry_from_spec(spec)
    arts = build_artifacts(spec, geom, formats, tol=tol, dxf_flavour=args.dxf_flavour, tool_paths=args.tool_path,
                           progress=lambda m: print(f"  ... {m}", file=sys.stderr))
    paths = write_artifacts(arts, args.output)
    print(f"{spec.name}: verdict {report.verdict}, tolerance {tol:g} mm")
    print(f"  {'file':<32}{'entities':>10}{'max deviation (mm)':>22}")
    for a, p in zip(arts, paths):
        ents = "-" if a.entities is None else str(a.entities)
        dev = "-" if a.deviation_mm is None else f"{a.deviation_mm:.3g}"
        print(f"  {str(p):<32}{ents:>10}{dev:>22}")
    return EXIT_OK


cmd_export.add_arguments = _export_args


def _gcode_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("file", help="design file (TOML) or built-in example name")
    p.add_argument("--post", choices=("linuxcnc", "fanuc", "grbl"), default=None,
                   help="controller dialect (default: [outputs] gcode, else linuxcnc)")
    p.add_argument("--tool-diameter", type=float, default=None, metavar="MM",
                   help="end mill diameter (default: [manufacturing] tool_diameter_mm)")
    p.add_argument("--tol", type=float, default=None, help="tool-path tolerance, mm (default: the design's)")
    p.add_argument("--tool-number", type=int, default=1)
    p.add_argument("--rpm", type=float, default=3000.0, help="spindle speed")
    p.add_argument("--feed", type=float, default=600.0, help="cutting feed, mm/min")
    p.add_argument("--plunge-feed", type=float, default=200.0, help="plunge feed, mm/min")
    p.add_argument("--step-down", type=float, default=3.0, help="largest depth per level, mm")
    p.add_argument("--roughing-passes", type=int, default=1)
    p.add_argument("--allowance", type=float, default=0.2, help="radial finishing allowance, mm")
    p.add_argument("--direction", choices=("climb", "conventional"), default="climb")
    p.add_argument("--coolant", choices=("flood", "mist", "off"), default="flood")
    p.add_argument("--units", choices=("mm", "inch"), default="mm")
    p.add_argument("--safe-z", type=float, default=25.0, help="safe height for rapids, mm")
    p.add_argument("--compensation", choices=("G41", "G42"), default=None,
                   help="emit the part contour with cutter compensation instead of tool-centre coordinates")
    p.add_argument("--lines-only", action="store_true", help="write the finishing contour as G1 lines (no G2/G3)")
    p.add_argument("--lift-table", metavar="CSV", help="also write the polar lift table for cam grinders")
    p.add_argument("--lift-step", type=float, default=1.0, help="lift-table step in degrees (divides 360)")
    p.add_argument("--force", action="store_true", help="write even if the design's verdict is unacceptable")
    p.add_argument("-o", "--output", required=True, metavar="OUT.nc")


def _job(spec, args, tol):
    from .gcode import Job

    tool = args.tool_diameter if args.tool_diameter is not None else spec.manufacturing.tool_diameter_mm
    if tool is None:
        raise UsageError("no tool: give --tool-diameter or [manufacturing] tool_diameter_mm")
    return Job(tool_diameter_mm=tool, depth_mm=spec.manufacturing.thickness_mm, tool_number=args.tool_number,
               spindle_rpm=args.rpm, feed_mm_min=args.feed, plunge_feed_mm_min=args.plunge_feed,
               step_down_mm=args.step_down, safe_z_mm=args.safe_z, roughing_allowance_mm=args.allowance,
               roughing_passes=0 if args.compensation else args.roughing_passes, direction=args.direction,
               coolant=args.coolant, units=args.units, tolerance_mm=tol, design_name=spec.name)


def _tol(spec, value):
    from .discretize import validate_tol

    try:
        return validate_tol(spec.manufacturing.tolerance_mm if value is None else value)
    except ValueError as exc:
        raise UsageError(f"--tol {value}: {exc}") from None


@register("gcode", "contour-milling G-code (LinuxCNC, Fanuc, GRBL) of the cam periphery")
def cmd_gcode(args: argparse.Namespace) -> int:
    from .design.assemble import check_design, geometry_from_spec
    from .gcode import dumps
    from .gcode.cam import cam_program

    spec = _load(args.file)
    tol = _tol(spec, args.tol)
    job = _job(spec, args, tol)
    post = args.post or spec.outputs.gcode or "linuxcnc"
    report = check_design(spec)
    if report.verdict == Verdict.UNACCEPTABLE and not args.force:
        print(f"camfab gcode: {spec.name} is unacceptable ({_worst(report)}): nothing written "
              "(use --force to write anyway)", file=sys.stderr)
        return EXIT_CHECKS
    geom = geometry_from_spec(spec)
    out = Path(args.output)
    texts = []
    for i, contact in enumerate(geom.profiles):
        cp = cam_program(contact, job, tol=tol, compensation=args.compensation, arcs_allowed=not args.lines_only)
        name = out if len(geom.profiles) == 1 else out.with_name(f"{out.stem}_cam{i + 1}{out.suffix}")
        texts.append((name, dumps(cp.program, post), cp))
    lift = None
    if args.lift_table:
        lift = _lift_table(spec, args.lift_step)
    for name, text, cp in texts:
        atomic_write(name, text)
        print(f"wrote {name}: {post}, {cp.entities} contour entities, max deviation {cp.deviation_mm:.3g} mm "
              f"(tol {tol:g} mm)")
    if lift is not None:
        atomic_write(args.lift_table, lift)
        print(f"wrote {args.lift_table}")
    return EXIT_OK


cmd_gcode.add_arguments = _gcode_args


def _worst(report) -> str:
    errs = [f.code for f in report.findings if f.severity == Severity.ERROR]
    return ", ".join(sorted(set(errs))) or report.verdict


def _lift_table(spec, step: float) -> str:
    from .gcode import lift_angles, lift_table_csv

    prog = spec.program()
    if _x_scale(prog) == 1.0:
        raise UsageError("a lift table needs a rotating cam")
    ang = lift_angles(step)
    return lift_table_csv(ang, prog(np.radians(ang)), lift_unit=prog.axis.lift_unit)


def _verify_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("program", help="G-code file to verify")
    p.add_argument("--design", required=True, help="the design the program should cut")
    p.add_argument("--tool-diameter", type=float, default=None, metavar="MM",
                   help="end mill diameter (default: [manufacturing] tool_diameter_mm)")
    p.add_argument("--tol", type=float, default=None, help="tolerance, mm (default: the design's)")
    p.add_argument("--safe-z", type=float, default=25.0)
    p.add_argument("--profile", type=int, default=1, help="which profile of a conjugate pair (1 or 2)")
    p.add_argument("--comp-radius", type=float, default=None, metavar="MM",
                   help="radius in the controller's D register for G41/G42 programs (default: the tool radius)")
    p.add_argument("--json", action="store_true")


@register("verify", "back-plot a G-code program and check it against the exact design")
def cmd_verify(args: argparse.Namespace) -> int:
    from .design.assemble import geometry_from_spec
    from .gcode import GcodeError, parse, verify
    from .gcode.cam import signed_distance
    from .offset.cutter import offset_curve, profile_curve

    spec = _load(args.design)
    tol = _tol(spec, args.tol)
    tool = args.tool_diameter if args.tool_diameter is not None else spec.manufacturing.tool_diameter_mm
    if tool is None:
        raise UsageError("no tool: give --tool-diameter or [manufacturing] tool_diameter_mm")
    if args.comp_radius is not None and not (math.isfinite(args.comp_radius) and args.comp_radius > 0):
        raise UsageError(f"--comp-radius {args.comp_radius:g}: must be a positive radius in mm")
    geom = geometry_from_spec(spec)
    if not 1 <= args.profile <= len(geom.profiles):
        raise UsageError(f"--profile {args.profile}: the design has {len(geom.profiles)} profile(s)")
    contact = geom.profiles[args.profile - 1]
    try:
        text = Path(args.program).read_text(encoding="utf-8")
    except UnicodeDecodeError:
        raise UsageError(f"{args.program}: not a text G-code file") from None
    try:
        moves = parse(text)
    except GcodeError as exc:
        raise UsageError(f"{args.program}: {exc}") from None
    rep = verify(moves, exact_curve_distance=signed_distance(offset_curve(contact, tool / 2), tol=tol),
                 part_distance=signed_distance(profile_curve(contact), tol=tol), tool_radius=tool / 2, tol=tol,
                 safe_z=args.safe_z, top_z=0.0, comp_radius=args.comp_radius)
    if args.json:
        print(json.dumps(rep.to_dict(), indent=2))
    else:
        dev = rep.max_deviation_mm
        print(f"{args.program}: {'OK' if rep.ok else 'FAILED'}; max deviation "
              f"{'-' if dev is None else f'{dev:.3g}'} mm (tol {tol:g}); gouge: {'yes' if rep.gouge else 'no'}")
        for pr in rep.problems:
            print(f"  [{pr.code}] line {pr.line}: {pr.message}")
    return EXIT_OK if rep.ok else EXIT_CHECKS


cmd_verify.add_arguments = _verify_args


_ARTIFACTS = ("dxf", "step", "stl", "gcode", "lift_table", "xlsx", "report", "drawing")


def _outputs_override(text: str | None) -> dict:
    """``--outputs dxf,report`` → every artifact switched on or off explicitly."""
    if text is None:
        return {}
    wanted = [w.strip() for w in text.split(",") if w.strip()]
    bad = [w for w in wanted if w not in _ARTIFACTS]
    if bad:
        raise UsageError(f"--outputs: '{bad[0]}' is not a valid option, must be one of: {', '.join(_ARTIFACTS)}")
    over = {a: (a in wanted) for a in _ARTIFACTS}
    over["gcode"] = "linuxcnc" if "gcode" in wanted else False  # False: off (None means "keep the design's")
    return over


def _run_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("file", nargs="?", default=None,
                   help="design file (TOML or xlsx) or example name; default: the built-in example ejemplo9rt")
    p.add_argument("-o", "--output", required=True, metavar="DIR")
    p.add_argument("--outputs", metavar="LIST", help="comma list overriding [outputs]: " + ",".join(_ARTIFACTS))
    p.add_argument("--tol", type=float, default=None, help="export tolerance, mm (default: the design's)")
    p.add_argument("--force", action="store_true", help="write shop artifacts even for an unacceptable design")


@register("run", "the main job: every artifact the design's [outputs] asks for")
def cmd_run(args: argparse.Namespace) -> int:
    from .jobs import request_from_outputs, run_design

    spec = _load(args.file or "ejemplo9rt")
    over = _outputs_override(args.outputs)
    req = request_from_outputs(spec, tol=args.tol, force=args.force or None, **over)
    if req.tol is not None:
        _tol(spec, req.tol)
    res = run_design(spec, args.output, req, progress=lambda m: print(f"  ... {m}", file=sys.stderr))
    print(f"{spec.name}: verdict {res.verdict}; tolerance {res.tol:g} mm; {len(res.files)} file(s) in {args.output}")
    for name, p in res.files.items():
        dev = res.deviations.get(name)
        print(f"  {name:<36}" + ("" if dev is None else f" max deviation {dev:.3g} mm"))
    if res.withheld:
        print(f"  withheld (verdict unacceptable, use --force): {', '.join(res.withheld)}")
    return EXIT_CHECKS if res.verdict == Verdict.UNACCEPTABLE else EXIT_OK


cmd_run.add_arguments = _run_args


def _package_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("paths", nargs="+", metavar="PATH", help="design files or folders (searched recursively)")
    p.add_argument("-o", "--output", required=True, metavar="DIR")
    p.add_argument("--jobs", type=int, default=1, help="designs built in parallel (processes)")
    p.add_argument("--outputs", metavar="LIST", help="comma list overriding every design's [outputs]")
    p.add_argument("--force", action="store_true", help="write shop artifacts even for unacceptable designs")


@register("package", "many designs in parallel: per-cam folders, index.html, manifest.json, incremental")
def cmd_package(args: argparse.Namespace) -> int:
    from .package import exit_status, package

    if args.jobs < 1:
        raise UsageError(f"--jobs {args.jobs}: must be at least 1")
    missing = [p for p in args.paths if not Path(p).exists()]
    if missing:
        raise UsageError(f"no such file or folder: {missing[0]}")
    over = _outputs_override(args.outputs)
    if args.force:
        over["force"] = True
    manifest = package(args.paths, args.output, jobs=args.jobs, overrides=over,
                       progress=lambda m: print(m, file=sys.stderr))
    cams = manifest["cams"]
    rebuilt = sum(1 for c in cams if c.get("rebuilt"))
    bad = [c for c in cams if c.get("status") == "error"]
    print(f"{len(cams)} design(s), {rebuilt} rebuilt, {len(bad)} failed; index: {Path(args.output) / 'index.html'}")
    for c in bad:
        print(f"  {c['source']}: {c['error']}", file=sys.stderr)
    return exit_status(manifest)


cmd_package.add_arguments = _package_args


def _register_report_commands() -> None:
    """``compare`` and ``report`` live in camfab.report (jinja2/matplotlib are imported only when they run)."""
    from .report.commands import cmd_compare, cmd_report

    register("compare", "overlaid S-V-A-J, curvature and pressure-angle plots and a side-by-side table")(cmd_compare)
    register("report", "HTML report with plots and an animation of the mechanism")(cmd_report)


_register_report_commands()


# ---------------------------------------------------------------------------
def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="camfab", description="Cam design, checks and manufacturing files.")
    parser.add_argument("--version", action="version", version=f"camfab {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name, fn in COMMANDS.items():
        p = sub.add_parser(name, help=fn.help, description=fn.help)
        fn.add_arguments(p)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Run the command line; returns the exit code (testable in-process)."""
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:  # argparse: 0 for --help/--version, 2 for bad options
        return int(exc.code or 0)
    if not args.command:
        parser.print_help(sys.stderr)
        return EXIT_INPUT
    try:
        return COMMANDS[args.command](args)
    except (SpecError, UsageError, GeometryError) as exc:
        print(f"camfab {args.command}: error: {exc}", file=sys.stderr)
        return EXIT_INPUT
    except MissingDependencyError as exc:
        print(f"camfab {args.command}: error: {exc}", file=sys.stderr)
        return EXIT_IO
    except OSError as exc:
        print(f"camfab {args.command}: I/O error: {exc}", file=sys.stderr)
        return EXIT_IO
