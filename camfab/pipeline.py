"""One pipeline: a cam built once, and one stage function per artifact.

A :class:`Cam` holds a validated design and computes each stage on first use and keeps it — the mechanism,
the exact geometry, the check report, the arc fits per tolerance — so that every command (``check``,
``export``, ``gcode``, ``report``, ``run``, ``package``) and the Python API build each thing once and agree.

Every artifact is an :class:`Output`; :data:`EXPORTERS` maps each one to a stage function with one signature,
``stage(cam, request) -> list[Artifact]``, that builds the files in memory.  :func:`run` checks the design,
withholds the shop outputs of an unacceptable design unless forced, builds what the :class:`Request` asks for
and writes the files atomically at the end, so a failure leaves nothing half-written.

The G-code job comes from one place, :func:`gcode_job`: the design's ``[machining]`` table, overridden by
command-line flags.
"""
from __future__ import annotations

import contextlib
import json
import logging
import math
import time
from collections.abc import Callable, Iterable, Mapping
from enum import StrEnum
from pathlib import Path
from typing import Any

import numpy as np

from .cad.artifact import Artifact, CamShapes, build_artifacts, cam_shapes, validate_tol
from .cad.kind_exports import KIND_CAD_OUTPUTS, applicable, kind_exporter
from .design.assemble import check_design, mechanism_from_spec
from .design.mechanisms import geometry_from_spec
from .design.profile import CamGeometry, ProfileSample
from .design.spec import DesignSpec
from .errors import GeometryError, InputError, MissingDependencyError, Problem, SpecError
from .formats import EXAMPLES_DIR, load_design, resolve_design_path
from .io import atomic_write, inside, output_folder, safe_stem, write_all
from .limits import MAX_POSES, MAX_SIZE_OVER_TOL
from .records import dataclass, field
from .results import CheckReport, IssueCode, Severity, Verdict

__all__ = ["Output", "SHOP_OUTPUTS", "Request", "RunResult", "Cam", "EXPORTERS", "gcode_job", "run", "build_files",
           "load", "examples", "shop_file_names"]


class Output(StrEnum):
    """Every artifact ``camfab run`` can write (the ``[outputs]`` keys)."""

    DXF = "dxf"
    STEP = "step"
    STL = "stl"
    GCODE = "gcode"
    LIFT_TABLE = "lift_table"
    XLSX = "xlsx"
    REPORT = "report"
    DRAWING = "drawing"
    PDF = "pdf"
    ASSEMBLY = "assembly"
    IGES = "iges"


#: artifacts withheld for an unacceptable design unless the job is forced (in the order they are named)
SHOP_OUTPUTS = (Output.DXF, Output.STEP, Output.STL, Output.GCODE, Output.DRAWING, Output.PDF, Output.LIFT_TABLE,
                Output.ASSEMBLY, Output.IGES)

#: outputs a run skips, with a warning, when cadquery is missing (the rest is written)
CAD_OUTPUTS = (Output.STEP, Output.ASSEMBLY, Output.IGES)

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class Request:
    """What to produce for one design, and how.

    Parameters
    ----------
    outputs : frozenset of Output
    post : str
        The G-code dialect (``linuxcnc``, ``fanuc``, ``grbl``).
    tol : float or None
        Export tolerance (mm); None = the design's ``[manufacturing] tolerance_mm``.
    force : bool
        Write the shop outputs even for an unacceptable design.
    dxf_flavour : str
        ``lwpolyline`` (bulges), ``r12`` (LINE/ARC) or ``spline``.
    tool_paths : bool or None
        Put the tool-centre paths on the DXF's TOOL_PATH layer; None = when G-code is asked for.
    machining : Mapping
        ``[machining]`` values given on the command line (None values are not given).
    angle : float
        The cam angle (degrees; mm of travel for a translating cam) of the assembly STEP.
    poses : int
        Also write this many assembly poses at equally spaced angles from ``angle`` (0: none).
    """

    outputs: frozenset[Output] = frozenset()
    post: str = "linuxcnc"
    tol: float | None = None
    force: bool = False
    dxf_flavour: str = "lwpolyline"
    tool_paths: bool | None = None
    lift_step_deg: float = 1.0
    xlsx_step_deg: float = 1.0
    machining: Mapping[str, Any] = field(default_factory=dict)
    angle: float = 0.0
    poses: int = 0

    @classmethod
    def from_design(cls, spec: DesignSpec, outputs: Iterable[str] | None = None, **over: Any) -> Request:
        """The request a design's ``[outputs]`` table makes (``outputs`` replaces it), with overrides."""
        o = spec.outputs
        if outputs is None:
            chosen = {Output(k) for k in ("dxf", "step", "stl", "lift_table", "xlsx", "report", "drawing", "pdf",
                                          "assembly", "iges") if getattr(o, k)}
            if o.gcode:
                chosen.add(Output.GCODE)
        else:
            chosen = {Output(k) for k in outputs}
        post = over.pop("post", None) or o.gcode or "linuxcnc"
        return cls(frozenset(chosen), post, **{k: v for k, v in over.items() if v is not None})

    def key(self) -> dict[str, Any]:
        """The options that change the output (for incremental builds)."""
        return {"outputs": sorted(self.outputs), "post": self.post, "tol": self.tol, "force": self.force,
                "dxf_flavour": self.dxf_flavour, "tool_paths": self.tool_paths, "lift_step_deg": self.lift_step_deg,
                "xlsx_step_deg": self.xlsx_step_deg, "machining": dict(sorted(self.machining.items())),
                "angle": self.angle, "poses": self.poses}


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
    #: shop files an earlier run left in the folder, removed because the verdict is now unacceptable
    removed: list[str] = field(default_factory=list)
    #: outputs skipped because a library is missing (cadquery: STEP and assembly), with a warning
    skipped: list[str] = field(default_factory=list)
    not_applicable: dict[str, str] = field(default_factory=dict)  #: outputs the cam's kind lacks, and why


# ---------------------------------------------------------------------------
class Cam:
    """A cam built from a validated design, each stage computed once on first use.

    >>> import camfab
    >>> cam = camfab.load("ejemplo9rt")
    >>> cam.check().verdict
    <Verdict.NOT_FOR_HIGH_SPEED: 'not_for_high_speed'>
    >>> round(float(cam.profile([0.0]).point[0, 1]), 6)   # the contact point at 0°, on +Y (mm)
    35.0
    """

    def __init__(self, spec: DesignSpec):
        self.spec = spec
        self._shapes: dict[float, CamShapes] = {}
        self._tool_paths: dict[Any, Any] = {}  # the tool-centre paths (camfab.gcode.cam.contour_paths' cache)
        self._report: CheckReport | None = None
        self._geometry: CamGeometry | None = None

    def __repr__(self) -> str:
        return f"<Cam {self.spec.name!r}: {self.spec.cam.kind} cam, {self.spec.follower.motion} " \
               f"{self.spec.follower.type} follower>"

    @property
    def name(self) -> str:
        return self.spec.name

    @property
    def mechanism(self) -> Any:
        """The mechanism (cam family) the design describes."""
        return mechanism_from_spec(self.spec)

    @property
    def geometry(self) -> CamGeometry:
        """The exact geometry (built once)."""
        if self._geometry is None:
            self._geometry = geometry_from_spec(self.spec)
        return self._geometry

    @property
    def tool_radius_mm(self) -> float | None:
        tool = self.spec.manufacturing.tool_diameter_mm
        return tool / 2 if tool else None

    def check(self) -> CheckReport:
        """The ``camfab check`` report: findings and verdict (the design's tool radius, dynamics and knot
        warnings included); computed once."""
        if self._report is None:
            self._report = check_design(self.spec, tool_radius_mm=self.tool_radius_mm)
        return self._report

    @property
    def verdict(self) -> Verdict:
        return self.check().verdict

    def tolerance(self, tol: float | None = None) -> float:
        """``tol`` or the design's tolerance, validated (mm): within the accepted range, and no finer than
        1/:data:`~camfab.limits.MAX_SIZE_OVER_TOL` of the cam's largest radius (``docs/decisions.md``,
        "Input limits")."""
        t = validate_tol(self.spec.manufacturing.tolerance_mm if tol is None else tol)
        size = self.geometry.max_radius
        if size > t * MAX_SIZE_OVER_TOL:
            rule = (f"{t:g} mm is finer than 1/{MAX_SIZE_OVER_TOL:.0e} of the cam's largest radius {size:.6g} mm "
                    "(the input limit: no machine holds it, and the fit's cost grows with the ratio)")
            fix = f"give a tolerance of at least {size / MAX_SIZE_OVER_TOL:.2g} mm"
            if tol is None:
                raise SpecError(Problem("manufacturing.tolerance_mm", t, rule, fix), self.spec.source)
            raise InputError(f"{rule}; {fix}")
        return t

    def shapes(self, tol: float | None = None) -> CamShapes:
        """Every profile arc-fitted within ``tol`` (and the pitch curves), measured; once per tolerance.

        Raises GeometryError at once for a profile no file can follow (an undercut or cusp ``check`` found)."""
        t = self.tolerance(tol)
        if t not in self._shapes:
            require_followable(self.check())
            self._shapes[t] = cam_shapes(self.geometry, tol=t)
        return self._shapes[t]

    def profile(self, x, *, profile: int = 0) -> ProfileSample:
        """The exact profile at cam angles ``x`` in degrees (mm of travel for a translating cam), cam frame."""
        axis = self.geometry.axis
        return self.geometry.evaluate(axis.from_user(np.asarray(x, dtype=float)), profile)

    # ---- exports -------------------------------------------------------------
    def to_dxf(self, path: str | Path | None = None, *, tol: float | None = None, flavour: str = "lwpolyline",
               tool_paths: bool = False) -> Any:
        """The DXF drawing of the profile(s): an ``ezdxf`` document, or written to ``path`` (returned)."""
        req = Request(frozenset({Output.DXF}), tol=tol, dxf_flavour=flavour, tool_paths=tool_paths)
        (art,) = kind_exporter(self.spec.cam.kind, "dxf", _dxf)(self, req)
        if path is not None:
            return atomic_write(path, art.data)
        import io

        import ezdxf

        return ezdxf.read(io.StringIO(art.data.decode("utf-8")))

    def to_stl(self, path: str | Path | None = None, *, tol: float | None = None) -> Any:
        """The plate as a mesh: a ``trimesh.Trimesh`` (profile 1 of a pair), or written to ``path``."""
        arts = kind_exporter(self.spec.cam.kind, "stl", _stl)(self, Request(frozenset({Output.STL}), tol=tol))
        if path is not None:
            return atomic_write(path, arts[0].data)
        import io

        import trimesh

        return trimesh.load(io.BytesIO(arts[0].data), file_type="stl")

    def to_step(self, path: str | Path, *, tol: float | None = None) -> Path:
        """The plate as a STEP solid, written to ``path`` (needs cadquery)."""
        arts = kind_exporter(self.spec.cam.kind, "step", _step)(self, Request(frozenset({Output.STEP}), tol=tol))
        return atomic_write(path, arts[0].data)

    def to_assembly(self, path: str | Path, *, angle: float = 0.0, tol: float | None = None) -> Path:
        """The mechanism as a STEP assembly at cam ``angle`` (degrees; mm of travel for a translating cam),
        written to ``path`` (needs cadquery; README, "CAD assemblies")."""
        arts = _assembly(self, Request(frozenset({Output.ASSEMBLY}), tol=tol, angle=angle))
        return atomic_write(path, arts[0].data)

    def to_gcode(self, post: str | None = None, path: str | Path | None = None, *, tol: float | None = None,
                 **machining: Any) -> str | Path:
        """The contour-milling program of profile 1 (``[machining]`` values may be overridden as keywords):
        its text, or written to ``path``."""
        req = Request(frozenset({Output.GCODE}), post or self.spec.outputs.gcode or "linuxcnc", tol=tol,
                      machining=machining)
        text = kind_exporter(self.spec.cam.kind, "gcode", _gcode)(self, req)[0].data
        return atomic_write(path, text) if path is not None else text.decode("utf-8")

    def to_shapely(self, *, tol: float | None = None, profile: int = 0) -> Any:
        """The profile as a ``shapely.Polygon`` (a polyline within ``tol`` of the exact curve)."""
        from shapely.geometry import Polygon

        from .discretize import polyline
        from .offset import profile_curve

        line = polyline(profile_curve(self.geometry.profiles[profile]), tol=self.tolerance(tol))
        return Polygon(line.points)

    def run(self, outdir: str | Path, outputs: Iterable[str] | None = None, *, force: bool = False,
            tol: float | None = None) -> RunResult:
        """Everything the design's ``[outputs]`` (or ``outputs``) asks for, written into ``outdir``."""
        return run(self, outdir, Request.from_design(self.spec, outputs, force=force, tol=tol))


#: check findings whose profile no file can follow, forced or not: the envelope crosses itself (undercut) or
#: comes to a point (cusp)
UNFOLLOWABLE = (IssueCode.UNDERCUT, IssueCode.CUSP)


def require_followable(report: CheckReport) -> None:
    """Refuse, before any fitting, a profile that ``check`` found undercut or cusped (GeometryError, exit 2).

    ``--force`` writes an unacceptable design's files, but an undercut profile (the roller's or the face's
    envelope crosses itself) or a cusp has no curve a file could lie within the tolerance of: searching for
    one only costs time and memory (minutes and gigabytes for a thousand undercut segments) before failing.
    """
    bad = [f for f in report.findings if f.code in UNFOLLOWABLE and f.severity == Severity.ERROR]
    if not bad:
        return
    where = ", ".join(f"{f.code} {f.from_deg:.6g}–{f.to_deg:.6g}" if f.from_deg != f.to_deg
                      else f"{f.code} at {f.from_deg:.6g}" for f in bad[:5])
    more = f" and {len(bad) - 5} more" if len(bad) > 5 else ""
    raise GeometryError(f"no file can follow this profile, even with --force: check finds {where}{more} (cam angle "
                        f"in degrees, travel in mm for a translating cam), where the profile crosses itself or comes "
                        f"to a point. {bad[0].message}")


def load(design: str | Path, *, allow_outside_files: bool = False) -> Cam:
    """A :class:`Cam` from a design file (TOML or xlsx) or the name of a built-in example.  The knot file a
    design names must lie in its folder (or below) unless ``allow_outside_files``."""
    return Cam(load_design(resolve_design_path(design), allow_outside_files=allow_outside_files))


def examples() -> list[str]:
    """The names of the built-in example designs (for :func:`load`)."""
    return sorted(p.stem for p in EXAMPLES_DIR.glob("*.toml"))


# ---------------------------------------------------------------------------
# the G-code job: [machining], overridden by the command line
def gcode_job(spec: DesignSpec, *, tol: float, overrides: Mapping[str, Any] | None = None) -> Any:
    """The :class:`camfab.gcode.Job` of a design, ``overrides`` (the command line) applied:
    :func:`camfab.gcode.model.design_job`."""
    from .gcode.model import design_job

    return design_job(spec, tol=tol, overrides=overrides)


def machining_of(spec: DesignSpec, overrides: Mapping[str, Any] | None = None) -> Any:
    """``[machining]`` with the given overrides applied (None values ignored)."""
    from .gcode.model import machining_of as of

    return of(spec, overrides)


# ---------------------------------------------------------------------------
# stages: (cam, request) -> artifacts
Stage = Callable[[Cam, Request], list[Artifact]]


def _suffix(i: int, n: int) -> str:
    return f"_cam{i + 1}" if n > 1 else ""


def _contour_paths(cam: Cam, req: Request, tol: float) -> tuple | None:
    """The plate program's tool-centre paths (None without a tool), made once per cam for the DXF's TOOL_PATH
    layer and the G-code (docs/decisions.md, "The DXF tool path is the program's")."""
    from .gcode.cam import contour_paths

    return contour_paths(cam.spec, cam.geometry, req.machining, tol=tol, post=req.post, cache=cam._tool_paths,
                         profiles=cam.shapes(tol).profiles)


def _dxf(cam: Cam, req: Request) -> list[Artifact]:
    tol, draw = cam.tolerance(req.tol), bool(Output.GCODE in req.outputs if req.tool_paths is None else req.tool_paths)
    paths = _contour_paths(cam, req, tol) if draw and cam.spec.cam.kind != "groove" else None
    return build_artifacts(cam.spec, cam.geometry, ["dxf"], tol=tol, dxf_flavour=req.dxf_flavour,
                           tool_paths=draw, shapes=cam.shapes(tol), tool_centre=paths)


def _stl(cam: Cam, req: Request) -> list[Artifact]:
    tol = cam.tolerance(req.tol)
    require_followable(cam.check())  # as cam.shapes does; without the plate's fit the mesh fits the same arcs itself
    return build_artifacts(cam.spec, cam.geometry, ["stl"], tol=tol, shapes=cam._shapes.get(tol))


def _step(cam: Cam, req: Request) -> list[Artifact]:
    tol = cam.tolerance(req.tol)
    return build_artifacts(cam.spec, cam.geometry, ["step"], tol=tol, shapes=cam.shapes(tol))


def _iges(cam: Cam, req: Request) -> list[Artifact]:
    """``<stem>.igs`` (``_cam1``/``_cam2`` for a pair): the plate for older CAM systems."""
    from .cad import iges
    from .cad.export import plate_of

    if cam.shapes(req.tol).groove:  # one plate with the groove pocketed
        from .cad.groove import groove_iges

        return [groove_iges(cam.spec, cam.geometry, shapes=cam.shapes(req.tol), tol=cam.tolerance(req.tol))]
    loops, devs = iges.outlines(cam.shapes(req.tol), cam.tolerance(req.tol))
    n = len(loops)
    return [Artifact(f"{safe_stem(cam.name)}{_suffix(i, n)}.igs",
                     iges.dumps(loop, plate_of(cam.spec), name=f"{cam.name}{_suffix(i, n)}").encode("ascii"),
                     "iges", loop.n_entities, dev)
            for i, (loop, dev) in enumerate(zip(loops, devs, strict=True))]


def _assembly(cam: Cam, req: Request) -> list[Artifact]:
    """``<stem>_assembly.step``: the mechanism at ``req.angle``; with ``req.poses`` = N, also N poses at
    equally spaced angles, ``<stem>_assembly_pose<k>.step``."""
    from .cad import assembly
    from .cad.export import solid_outlines

    outlines, devs = solid_outlines(cam.shapes(req.tol), cam.tolerance(req.tol))
    axis, geometry = cam.geometry.axis, cam.geometry
    if not math.isfinite(req.angle) or abs(req.angle) > 1e6:
        raise InputError(f"--angle {req.angle}: must be a finite number of at most 1e6 (degrees; mm of travel "
                         "for a translating cam)")
    if not 0 <= req.poses <= MAX_POSES:
        raise InputError(f"--poses {req.poses}: must be a whole number from 0 to {MAX_POSES}")
    span = float(axis.to_user(geometry.period))
    if not geometry.closed and not 0.0 <= req.angle <= span:
        raise InputError(f"--angle {req.angle:g}: a translating cam's position is its travel in mm, from 0 to "
                         f"its length {span:g}")
    stem = safe_stem(cam.name)
    dims = assembly.dimensions(cam.spec, geometry)
    dev = max(devs)

    def one(user: float) -> bytes:
        x = float(axis.from_user(user % span))
        return assembly.dumps(cam.spec, geometry, outlines, x, dims=dims).encode("utf-8")

    out = [Artifact(f"{stem}_assembly.step", one(req.angle), "step", None, dev,
                    f"the mechanism at {req.angle:g}{axis.x_symbol}")]
    width = len(str(req.poses))
    for k in range(req.poses):
        at = req.angle + k * span / req.poses
        out.append(Artifact(f"{stem}_assembly_pose{k + 1:0{width}d}.step", one(at), "step", None, dev,
                            f"pose {k + 1} of {req.poses}: {at:g}{axis.x_symbol}"))
    return out


def _gcode(cam: Cam, req: Request) -> list[Artifact]:
    from .gcode import dumps
    from .gcode.cam import cam_program
    from .gcode.groove import groove_gcode

    tol = cam.tolerance(req.tol)
    require_followable(cam.check())
    job = gcode_job(cam.spec, tol=tol, overrides=req.machining)
    m = machining_of(cam.spec, req.machining)
    n = len(cam.geometry.profiles)
    if cam.spec.cam.kind == "cylindrical":  # the 4-axis program of the groove or rib (camfab.gcode.cylinder)
        from .gcode.cylinder import cylinder_gcode

        data, moves, dev = cylinder_gcode(cam.geometry, job, tol, req.post)
        return [Artifact(f"{safe_stem(cam.name)}.nc", data, "gcode", moves, dev, req.post)]
    if cam.spec.cam.kind == "groove":  # one program mills the slot of both flanks
        return [Artifact(f"{safe_stem(cam.name)}.nc", *groove_gcode(cam.geometry, job, tol, m, req.post), req.post)]
    out, paths = [], _contour_paths(cam, req, tol)
    for i, contact in enumerate(cam.geometry.profiles):
        cp = cam_program(contact, job, tol=tol, compensation=m.compensation, arcs_allowed=not m.lines_only,
                         post=req.post, path=paths[i] if paths else None)
        out.append(Artifact(f"{safe_stem(cam.name)}{_suffix(i, n)}.nc", dumps(cp.program, req.post).encode(), "gcode",
                            cp.entities, cp.deviation_mm, req.post))
    return out


def _lift_table(cam: Cam, req: Request) -> list[Artifact]:
    from .gcode import lift_angles, lift_table_csv
    from .gcode.lift_table import cylinder_lift_csv, lift_metadata

    if cam.spec.cam.kind == "cylindrical":  # developed on the pitch cylinder
        text = cylinder_lift_csv(cam.spec, cam.geometry, req.lift_step_deg)
        return [Artifact(f"{safe_stem(cam.name)}_lift.csv", text.encode(), "lift_table")]
    prog = cam.spec.program()
    if not prog.axis.rotating:
        raise GeometryError("a polar lift table needs a rotating cam")
    ang = lift_angles(req.lift_step_deg)
    t = np.radians(ang)
    radii = [np.hypot(*np.asarray(c.evaluate(t).point, dtype=float).reshape(-1, 2).T) for c in cam.geometry.profiles]
    text = lift_table_csv(ang, prog(t), lift_unit=prog.axis.lift_unit, radii_mm=radii,
                          meta=lift_metadata(cam.spec, req.lift_step_deg, str(prog.axis.lift_unit), len(radii)))
    return [Artifact(f"{safe_stem(cam.name)}_lift.csv", text.encode(), "lift_table")]


def _xlsx(cam: Cam, req: Request) -> list[Artifact]:
    from .formats.camdas_workbook import camdas_workbook

    data = camdas_workbook(cam.spec, cam.geometry, cam.check(), step_deg=req.xlsx_step_deg)
    return [Artifact(f"{safe_stem(cam.name)}.xlsx", data, "xlsx")]


def _report(cam: Cam, req: Request) -> list[Artifact]:
    from .report.html import render_report, require_report_dependencies

    require_report_dependencies()
    return [Artifact(name, data, "report") for name, data in render_report(cam.spec, cam.geometry,
                                                                           cam.check()).items()]


def _drawing(cam: Cam, req: Request) -> list[Artifact]:
    from .cad.drawing import drawing_sheet

    shapes = cam.shapes(req.tol)
    text = drawing_sheet(cam.spec, cam.geometry, cam.check(), shapes)
    return [Artifact(f"{safe_stem(cam.name)}_drawing.dxf", text.encode(), "drawing", None,
                     max(shapes.profile_deviation))]


def _pdf(cam: Cam, req: Request) -> list[Artifact]:
    """Each drawing sheet as a one-page PDF at its paper size (:func:`camfab.cad.pdf.sheet_pdf`)."""
    from .cad.pdf import sheet_pdf

    return [Artifact(a.filename.removesuffix(".dxf") + ".pdf", sheet_pdf(a.data), "pdf", None, a.deviation_mm)
            for a in _drawing(cam, req)]


#: every artifact's stage, in the order :func:`run` builds them
EXPORTERS: dict[Output, Stage] = {
    Output.DXF: _dxf,
    Output.STL: _stl,
    Output.STEP: _step,
    Output.ASSEMBLY: _assembly,
    Output.IGES: _iges,
    Output.DRAWING: _drawing,
    Output.PDF: _pdf,
    Output.GCODE: _gcode,
    Output.LIFT_TABLE: _lift_table,
    Output.XLSX: _xlsx,
    Output.REPORT: _report,
}


def run(cam: Cam, outdir: str | Path, req: Request, *, progress: Callable[[str], None] | None = None,
        lock: bool = True) -> RunResult:
    """Build what ``req`` asks for and write it into ``outdir`` (``check.json`` always).

    Before computing, ``outdir`` is created, proved writable and locked (:func:`camfab.io.output_folder`;
    ``lock=False``: the caller holds it).  The files are written as one set (:func:`camfab.io.write_all`):
    all or, on a failure, none.  An unacceptable design's shop files are withheld unless forced, and the shop
    files an earlier run left in ``outdir`` for this cam are removed (:func:`shop_file_names`).

    Raises the usual camfab errors (SpecError, GeometryError, MissingDependencyError) before anything is
    written; an ``OSError`` naming the path it could not write.
    """
    say = progress or (lambda m: None)
    res = RunResult(cam.name, "", tol=cam.tolerance(req.tol))
    with output_folder(outdir) if lock else contextlib.nullcontext(Path(outdir)) as folder:
        files = build_files(cam, req, res, say)
        paths = {name: inside(folder, name) for name in files}  # every path proved inside outdir before any write
        names = sorted(files)
        written = write_all({paths[n]: files[n] for n in names})
        res.files = dict(zip(names, written, strict=True))
        if res.verdict == Verdict.UNACCEPTABLE and not req.force:  # no shop file beside an unacceptable verdict
            poses = {p.name for p in folder.glob(f"{safe_stem(cam.name)}_assembly_pose*.step")}  # any --poses N
            res.removed = [name for name in sorted(shop_file_names(cam) | poses) if (folder / name).is_file()]
            for name in res.removed:
                (folder / name).unlink(missing_ok=True)
        return res


def build_files(cam: Cam, req: Request, res: RunResult, say: Callable[[str], None]) -> dict[str, bytes]:
    """The files ``req`` asks for, by name, not written (:func:`run` writes them; ``package`` workers return them);
    ``res`` gets the verdict, the withheld and skipped outputs, the deviations and the timings."""
    report = _timed(res, "check", say, cam.check)
    res.verdict = report.verdict
    wanted, res.not_applicable = applicable(cam, [o for o in EXPORTERS if o in req.outputs])
    refused = report.verdict == Verdict.UNACCEPTABLE and not req.force
    if refused:
        res.withheld = [str(o) for o in SHOP_OUTPUTS if o in req.outputs]
        wanted = [o for o in wanted if o not in SHOP_OUTPUTS]
    _timed(res, "geometry", say, lambda: cam.geometry)
    files: dict[str, bytes] = {"check.json": (json.dumps(report.to_dict(), indent=2) + "\n").encode()}
    for out in wanted:
        try:
            arts = _timed(res, str(out), say, kind_exporter(cam.spec.cam.kind, out, EXPORTERS[out]), cam, req)
        except MissingDependencyError as exc:
            if out not in CAD_OUTPUTS and out not in KIND_CAD_OUTPUTS.get(cam.spec.cam.kind, ()):
                raise
            log.warning("%s: %s skipped: %s; the other files are written", cam.name, out, exc)
            res.skipped.append(str(out))
            continue
        for art in arts:
            files[art.filename] = art.data
            if art.kind != "report":
                res.deviations[art.filename] = art.deviation_mm
    return files


def shop_file_names(cam: Cam) -> set[str]:
    """The names of every shop file (:data:`SHOP_OUTPUTS`) camfab writes for ``cam``: what an unacceptable
    verdict withholds, and removes when an earlier run left it."""
    stem = safe_stem(cam.name)
    n = 1 if cam.spec.cam.kind == "groove" else len(cam.geometry.profiles)  # a groove: one plate, one program
    per_profile = [f"{stem}{_suffix(i, n)}" for i in range(n)]
    names = {f"{stem}.dxf", f"{stem}_drawing.dxf", f"{stem}_drawing.pdf", f"{stem}_lift.csv",
             f"{stem}_assembly.step", *([f"{stem}_pair.step"] if n > 1 else [])}
    return names | {f"{s}.{ext}" for s in per_profile for ext in ("stl", "step", "nc", "igs")}


def _timed(res: RunResult, stage: str, say: Callable[[str], None], fn: Callable[..., Any], *args: Any) -> Any:
    say(stage)
    t = time.perf_counter()
    out = fn(*args)
    res.timings[stage] = res.timings.get(stage, 0.0) + time.perf_counter() - t
    return out
