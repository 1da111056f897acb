"""Jobs: which artifacts a design asks for, and the stages that make exactly those.

A job ("scene") names the artifacts wanted; only the stages they need run:
no cadquery import without STEP, no tool-centre offsets without G-code, no arc
fitting without a CAD artifact, no plots without a report.  Every artifact is
built in memory and the files are written only once all of them succeeded.

A design whose verdict is *unacceptable* gets its check, report and
spreadsheet (so the user can see why) but no shop artifacts (DXF, STEP, STL,
G-code, drawing, lift table) unless the job is forced.
"""
from __future__ import annotations

import json
import time
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Callable

from .io import atomic_write
from .results import Verdict

__all__ = ["JobRequest", "RunResult", "request_from_outputs", "run_design", "SHOP_ARTIFACTS"]

#: artifacts withheld for an unacceptable design unless forced
SHOP_ARTIFACTS = ("dxf", "step", "stl", "gcode", "drawing", "lift_table")


@dataclass(frozen=True)
class JobRequest:
    """What to produce for one design."""

    dxf: bool = False
    step: bool = False
    stl: bool = False
    gcode: str | None = None  # post-processor name
    lift_table: bool = False
    xlsx: bool = False
    report: bool = False
    drawing: bool = False
    tol: float | None = None  # None: the design's tolerance
    force: bool = False
    dxf_flavour: str = "lwpolyline"
    lift_step_deg: float = 1.0
    xlsx_step_deg: float = 1.0

    def key(self) -> dict:
        """The options that change the output (for incremental builds)."""
        return {k: getattr(self, k) for k in self.__dataclass_fields__}


@dataclass
class RunResult:
    """Files written for one design, with the verdict, measured deviations and stage timings."""

    name: str
    verdict: str
    files: dict[str, Path] = field(default_factory=dict)
    deviations: dict[str, float | None] = field(default_factory=dict)
    timings: dict[str, float] = field(default_factory=dict)
    withheld: list[str] = field(default_factory=list)
    tol: float = 0.0


def request_from_outputs(spec, **over) -> JobRequest:
    """The job a design's ``[outputs]`` section asks for, with overrides.

    An override of ``None`` keeps the design's value; ``gcode=False`` switches G-code off.
    """
    o = spec.outputs
    req = JobRequest(dxf=o.dxf, step=o.step, stl=o.stl, gcode=o.gcode, lift_table=o.lift_table, xlsx=o.xlsx,
                     report=o.report, drawing=o.drawing)
    over = {k: v for k, v in over.items() if v is not None}
    if over.get("gcode") is False:
        over["gcode"] = None
    return replace(req, **over)


class _Timer:
    def __init__(self, timings: dict[str, float], say: Callable[[str], None]):
        self.timings, self.say = timings, say

    def __call__(self, stage: str, fn, *a, **kw):
        self.say(stage)
        t = time.perf_counter()
        out = fn(*a, **kw)
        self.timings[stage] = self.timings.get(stage, 0.0) + time.perf_counter() - t
        return out


def run_design(spec, outdir: str | Path, req: JobRequest, *,
               progress: Callable[[str], None] | None = None) -> RunResult:
    """Run one design's job and write its files into ``outdir``.

    Returns the :class:`RunResult`; raises the usual camfab errors (SpecError,
    GeometryError, MissingDependencyError) before anything is written.
    """
    from .design.assemble import check_design, geometry_from_spec
    from .discretize import validate_tol

    say = progress or (lambda m: None)
    res = RunResult(spec.name, "")
    timed = _Timer(res.timings, say)
    tol = validate_tol(spec.manufacturing.tolerance_mm if req.tol is None else req.tol)
    res.tol = tol
    tool = spec.manufacturing.tool_diameter_mm
    report = timed("check", check_design, spec, tool_radius_mm=tool / 2 if tool else None)
    res.verdict = report.verdict
    if report.verdict == Verdict.UNACCEPTABLE and not req.force:
        res.withheld = [a for a in SHOP_ARTIFACTS if _wants(req, a)]
        req = replace(req, dxf=False, step=False, stl=False, gcode=None, drawing=False, lift_table=False)
    geom = timed("geometry", geometry_from_spec, spec)
    files: dict[str, bytes] = {"check.json": (json.dumps(report.to_dict(), indent=2) + "\n").encode()}
    shapes = None
    cad = [f for f in ("dxf", "step", "stl") if getattr(req, f)]
    if cad:
        from .cad.export import build_artifacts

        for a in timed("cad", build_artifacts, spec, geom, cad, tol=tol, dxf_flavour=req.dxf_flavour,
                       tool_paths=bool(req.gcode)):
            files[a.filename] = a.data
            res.deviations[a.filename] = a.deviation_mm
    if req.drawing:
        from .cad.drawing import drawing_sheet
        from .cad.export import cam_shapes

        shapes = timed("arcs", cam_shapes, geom, tol=tol, with_pitch=False)
        files[f"{spec.name}_drawing.dxf"] = timed("drawing", drawing_sheet, spec, geom, report, shapes).encode()
        res.deviations[f"{spec.name}_drawing.dxf"] = max(shapes.profile_deviation)
    if req.gcode:
        for name, text, dev in timed("gcode", _gcode, spec, geom, req.gcode, tol):
            files[name] = text.encode()
            res.deviations[name] = dev
    if req.lift_table:
        files[f"{spec.name}_lift.csv"] = timed("lift_table", _lift_csv, spec, req.lift_step_deg).encode()
    if req.xlsx:
        from .report.xlsx import camdas_workbook

        files[f"{spec.name}.xlsx"] = timed("xlsx", camdas_workbook, spec, geom, report, step_deg=req.xlsx_step_deg)
    if req.report:
        from .report.commands import require_report_dependencies
        from .report.html import render_report

        require_report_dependencies()
        files.update(timed("report", render_report, spec, geom, report))
    out = Path(outdir)
    for name, data in sorted(files.items()):
        res.files[name] = atomic_write(out / name, data)
    return res


def _wants(req: JobRequest, artifact: str) -> bool:
    return bool(getattr(req, artifact))


def _gcode(spec, geom, post: str, tol: float):
    from .errors import SpecError, Problem
    from .gcode import Job, dumps
    from .gcode.cam import cam_program

    tool = spec.manufacturing.tool_diameter_mm
    if not tool:
        raise SpecError(Problem("manufacturing.tool_diameter_mm", None, "G-code needs a tool",
                                "add tool_diameter_mm to [manufacturing]"), spec.source)
    job = Job(tool_diameter_mm=tool, depth_mm=spec.manufacturing.thickness_mm, tolerance_mm=tol,
              design_name=spec.name)
    out = []
    n = len(geom.profiles)
    for i, contact in enumerate(geom.profiles):
        cp = cam_program(contact, job, tol=tol)
        suffix = f"_cam{i + 1}" if n > 1 else ""
        out.append((f"{spec.name}{suffix}.nc", dumps(cp.program, post), cp.deviation_mm))
    return out


def _lift_csv(spec, step_deg: float) -> str:
    import numpy as np

    from .errors import GeometryError
    from .gcode import lift_angles, lift_table_csv

    prog = spec.program()
    if spec.is_translating_cam:
        raise GeometryError("a polar lift table needs a rotating cam")
    ang = lift_angles(step_deg)
    return lift_table_csv(ang, prog(np.radians(ang)), lift_unit=prog.axis.lift_unit)
