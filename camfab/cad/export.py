"""Export pipeline: exact cam geometry → DXF / STEP / STL bytes with measured deviations.

Everything is built in memory first and written only when every requested
artifact succeeded, each file atomically, so an error never leaves partial
output.  Only the stages a job asks for run (cadquery is imported only for
STEP, shapely and earcut only for STL, tool paths only when a cutter is given).  Every
writer takes the profiles as :class:`~camfab.geom2d.ArcChain` values.
"""
from __future__ import annotations

import logging
import math
from collections.abc import Callable, Iterable, Sequence
from pathlib import Path

import numpy as np

from ..design.kinds import ContactKind
from ..discretize import ToleranceError, arcs, arcs_within_radius, measure_within, validate_tol
from ..discretize.curve import discontinuities
from ..discretize.tolerance import within
from ..errors import GeometryError
from ..geom2d import ArcChain
from ..io import atomic_write, inside, safe_stem
from ..offset.cutter import ToolCentrePath, offset_loop, pitch_curve, profile_curve, tool_centre_path
from ..tolerances import MIN_EXPORT_TOL_MM, PROFILE_FIT_SHARE, arc_radius_limit, profile_fit_tolerance
from . import dxf as dxf_mod
from . import step, stl
from .artifact import Artifact, CamShapes
from .plate import PlateSpec, bore_loop
from .stepheader import design_meta

__all__ = ["Artifact", "CamShapes", "cam_shapes", "build_artifacts", "write_artifacts", "FORMATS", "plate_of"]

FORMATS = ("dxf", "step", "stl")

log = logging.getLogger(__name__)


def cam_shapes(geometry, *, tol: float, with_pitch: bool = True) -> CamShapes:
    """Arc-fit every profile of ``geometry`` within ``PROFILE_FIT_SHARE·tol`` (measured), once for every file of
    the plate: the DXF, drawing and solids draw these arcs, the STL flattens them within the rest of ``tol``, and
    the pitch curve and the program's tool paths are their exact offsets where those lie within their tolerance
    (docs/decisions.md, "One arc fit per profile")."""
    tol = validate_tol(tol)
    profiles, pitch, curves = [], [], []
    groove = getattr(getattr(geometry, "mechanism", None), "cam_kind", None) == "groove"
    for i, c in enumerate(geometry.profiles):
        curve = profile_curve(c)
        _require_continuous(curve, tol)
        profiles.append(arcs(curve, tol=profile_fit_tolerance(tol)))
        curves.append(curve)
        # a groove's flanks share one pitch curve, the inner flank's offset (the outer flank's offset by +w lies
        # 2w off it: measured far from every sample, then fitted again, for nothing)
        pc = pitch_curve(c) if with_pitch and c.roller_radius > 0 and not (groove and i > 0) else None
        if pc is not None:
            pitch.append(_pitch_loop(profiles[-1], c.roller_radius, pc, tol))
    return CamShapes(tuple(profiles), tuple(pitch), tuple(curves), tol, groove)


def _require_continuous(curve, tol: float) -> None:
    """Refuse a profile that still jumps.  Where the follower's velocity jumps, :func:`profile_curve` builds the
    profile the follower makes (camfab.offset.corners: rollers, curved and flat faces); a jump left after that
    has no curve a file could follow within ``tol``."""
    gaps = discontinuities(curve, tol)
    if not gaps:
        return
    scale = 180.0 / math.pi if math.isclose(curve.period, 2 * math.pi) else 1.0
    unit = "°" if scale != 1.0 else " (curve parameter)"
    where = ", ".join(f"{(t % curve.period) * scale:.6g}{unit} (gap {g:.3g} mm)" for t, g in gaps)
    raise GeometryError(f"the profile is not continuous at {where}: no file can be made within the tolerance "
                        "even with --force; check the design for a velocity jump and match the velocities at the "
                        "junctions (e.g. cycloidal or modified-sine rises instead of constant velocity)")


def _pitch_loop(profile: ArcChain, roller_radius: float, pitch, tol: float) -> ArcChain:
    """The pitch curve's arcs: the profile's arc chain offset by the roller radius (exact for a G1 chain:
    concentric arcs, :func:`~camfab.offset.cutter.offset_loop`), kept when its deviation from the exact pitch
    curve, measured, is within ``tol``; otherwise (or for a chain with corners) a fit of its own."""
    loop = offset_loop(profile, roller_radius, pitch, tol)
    return loop if loop is not None else arcs(pitch, tol=tol)


def plate_of(spec) -> PlateSpec:
    """The plate a design's ``[manufacturing]`` describes."""
    m = spec.manufacturing
    return PlateSpec(m.thickness_mm, m.bore_mm, m.keyway, m.hub_diameter_mm, m.hub_length_mm)


_plate = plate_of


def _suffix(i: int, n: int) -> str:
    return f"_cam{i + 1}" if n > 1 else ""


def build_artifacts(spec, geometry, formats: Iterable[str], *, tol: float, dxf_flavour: str = "lwpolyline",
                    tool_paths: bool = False, progress: Callable[[str], None] | None = None,
                    shapes: CamShapes | None = None, tool_centre: Sequence[ToolCentrePath] | None = None
                    ) -> list[Artifact]:
    """Build the requested artifacts in memory.

    Parameters
    ----------
    spec : DesignSpec
    geometry : CamGeometry
    formats : iterable of {"dxf", "step", "stl"}
    tol : float
        Maximum distance (mm) between every written entity and the exact profile.
    tool_paths : bool
        Add the tool-centre paths (``[manufacturing] tool_diameter_mm``) on the DXF's TOOL_PATH layer.
    shapes : CamShapes, optional
        The arc fits within ``tol`` when the caller has them already (with the pitch curves for a DXF).
    tool_centre : sequence of ToolCentrePath, optional
        The tool-centre paths to draw with ``tool_paths`` (one per profile, each fitted within ``tol`` of its
        exact curve) when the caller has them: the pipeline gives the G-code program's own (docs/decisions.md, "The
        DXF tool path is the program's"); else each is fitted here within ``tol``.
    """
    say = progress or (lambda msg: None)
    formats = [f for f in FORMATS if f in set(formats)]
    groove = getattr(getattr(geometry, "mechanism", None), "cam_kind", None) == "groove"
    if shapes is None and formats == ["stl"]:
        # the mesh is fitted within tol/2 of each curve below: the fit within tol (and the pitch) would not be used
        curves = tuple(profile_curves(geometry, validate_tol(tol)))
        if not groove:
            return _stl_artifacts(spec, curves, _plate(spec), tol, say)
        shapes = CamShapes((), (), curves, tol, True)  # the groove plate's mesh reads the curves alone
    if shapes is None:
        say(f"fitting arcs within {tol:g} mm")
        shapes = cam_shapes(geometry, tol=tol, with_pitch="dxf" in formats)
    if groove:
        from .groove import groove_artifacts  # one plate, two flanks: camfab.cad.groove

        return groove_artifacts(spec, geometry, formats, shapes=shapes, tol=tol, dxf_flavour=dxf_flavour,
                                tool_paths=tool_paths)
    plate = _plate(spec)
    out: list[Artifact] = []
    n = len(shapes.profiles)
    if "dxf" in formats:
        say("DXF")
        out.append(_dxf(spec, geometry, shapes, plate, tol, dxf_flavour, tool_paths, tool_centre))
    if "stl" in formats:
        out += _stl_artifacts(spec, shapes.curves, plate, tol, say, shapes.profiles)
    if "step" in formats:
        loops, devs = solid_outlines(shapes, tol)
        for i, (loop, dev) in enumerate(zip(loops, devs, strict=True)):
            say(f"STEP{_suffix(i, n)}")
            text = step.dumps(loop, plate, name=f"{spec.name}{_suffix(i, n)}", meta=design_meta(spec))
            out.append(Artifact(f"{safe_stem(spec.name)}{_suffix(i, n)}.step", text.encode("utf-8"), "step",
                                loop.n_entities, dev))
        if n > 1:
            say("STEP pair on the shaft")
            text = step.stack_dumps(loops, plate, name=f"{spec.name}_pair", meta=design_meta(spec))
            out.append(Artifact(f"{safe_stem(spec.name)}_pair.step", text.encode("utf-8"), "step",
                                sum(lp.n_entities for lp in loops), max(devs),
                                "both cams positioned along the shaft"))
    return out


def profile_curves(geometry, tol: float) -> list:
    """The exact profile curves of ``geometry`` (:func:`~camfab.offset.cutter.profile_curve`), each refused
    when it still jumps by more than ``tol``."""
    curves = [profile_curve(c) for c in geometry.profiles]
    for curve in curves:
        _require_continuous(curve, tol)
    return curves


def _stl_artifacts(spec, curves, plate: PlateSpec, tol: float, say: Callable[[str], None],
                   fits: Sequence[ArcChain] = ()) -> list[Artifact]:
    """One STL per profile curve: its arcs within ``PROFILE_FIT_SHARE·tol`` (``fits``, the plate's own fit, when
    the caller has them; fitted here otherwise: the same arcs), flattened within the rest of ``tol``; the
    deviation is :func:`flattened_deviation`'s (the fit's plus the largest sagitta)."""
    out = []
    n = len(curves)
    rest = stl_facet_tolerance(tol)
    for i, curve in enumerate(curves):
        say(f"STL{_suffix(i, n)}")
        fine = fits[i] if fits else arcs(curve, tol=profile_fit_tolerance(tol))
        dev = flattened_deviation(fine, curve, tol, rest)
        data = stl.dumps(fine, plate, tol=rest, name=spec.name)
        out.append(Artifact(f"{safe_stem(spec.name)}{_suffix(i, n)}.stl", data, "stl", None, dev))
    return out


def flattened_deviation(fit: ArcChain, curve, tol: float, rest: float) -> float:
    """The deviation (mm) from ``curve`` of ``fit`` flattened within ``rest`` (:meth:`ArcChain.flatten`, what an
    STL's facets follow): the fit's own measured deviation plus the flattening's largest sagitta, by the triangle
    inequality (every chord is within its sagitta of its arc, both ways); measured on the polyline when the fit
    carries no deviation or the sum is not within ``tol`` (docs/decisions.md, "The STL's deviation is the fit's
    plus the sagitta")."""
    points, sagitta = fit.flatten_sagitta(rest)
    if fit.max_deviation is not None and within(fit.max_deviation + sagitta, tol):
        return float(fit.max_deviation) + sagitta
    return float(measure_within(points, curve, tol).max)


def stl_facet_tolerance(tol: float) -> float:
    """How far (mm) an STL's facets may lie from the plate fit's arcs: the rest of ``tol`` after
    :func:`~camfab.tolerances.profile_fit_tolerance`; a tolerance too fine to leave the facets any is refused."""
    rest = tol - profile_fit_tolerance(tol)
    if rest < tol * (1.0 - PROFILE_FIT_SHARE) * (1.0 - 1e-12):
        raise ToleranceError(f"an STL within {tol:g} mm needs a tolerance of at least "
                             f"{MIN_EXPORT_TOL_MM / PROFILE_FIT_SHARE:g} mm (one share for the arcs, the other for "
                             "the facets); give a coarser --tol for the STL")
    return rest


def solid_outlines(shapes: CamShapes, tol: float) -> tuple[list, list[float]]:
    """The outlines a solid (STEP, assembly, IGES) is built from, with their measured deviations: the arc fits
    with every arc above :func:`~camfab.tolerances.arc_radius_limit` of the part replaced by chords within
    ``tol`` (an arc of a huge radius, a near-straight stretch, is a cylinder OpenCascade cannot intersect
    reliably)."""
    loops = [arcs_within_radius(p, c, tol=tol, max_radius_mm=arc_radius_limit(_size(p)))
             for p, c in zip(shapes.profiles, shapes.curves, strict=True)]
    return loops, [float(lp.max_deviation or 0.0) for lp in loops]


def _size(loop) -> float:
    """A loop's largest distance from the origin (the cam centre), mm."""
    return float(np.hypot(*np.asarray(loop.starts, dtype=float).T).max())


def _dxf(spec, geometry, shapes: CamShapes, plate: PlateSpec, tol: float, flavour: str,
         tool_paths: bool, tool_centre: Sequence[ToolCentrePath] | None = None) -> Artifact:
    f = spec.follower
    tools: tuple[ArcChain, ...] = ()
    tool_d = spec.manufacturing.tool_diameter_mm
    if tool_paths and tool_centre is not None:
        tools = tuple(p.arcs for p in tool_centre)
    elif tool_paths and tool_d:
        tools = tuple(tool_centre_path(c, tool_d / 2, tol=tol, profile_arcs=p).arcs
                      for c, p in zip(geometry.profiles, shapes.profiles, strict=True))
    c = geometry.profiles[0]  # a roller's prime circle; a curved face's centre of curvature starts on R_b + R
    rr = c.roller_radius if c.kind is ContactKind.ROLLER else 0.0
    content = dxf_mod.DxfContent(
        profiles=shapes.profiles, pitch_curves=shapes.pitch, base_radius=f.base_radius_mm,
        prime_radius=(f.base_radius_mm + rr) if (rr > 0 and f.base_radius_mm) else None,
        bore=bore_loop(plate.bore_mm, plate.keyway) if plate.bore_mm > 0 else None,
        tool_paths=tools, tol_mm=tol, deviation_mm=max(shapes.profile_deviation), name=spec.name)
    text = dxf_mod.dumps(content, flavour=flavour)
    ents = sum(lp.n_entities for lp in shapes.profiles)
    return Artifact(f"{safe_stem(spec.name)}.dxf", text.encode("utf-8"), "dxf", ents, max(shapes.profile_deviation),
                    f"{flavour}; {len(tools)} tool path(s)" if tools else flavour)


def write_artifacts(artifacts: Iterable[Artifact], outdir: str | Path) -> list[Path]:
    """Write every artifact atomically into ``outdir``; returns the paths."""
    outdir = Path(outdir)
    artifacts = list(artifacts)
    targets = [inside(outdir, a.filename) for a in artifacts]  # all proved inside outdir before any write
    return [atomic_write(t, a.data) for t, a in zip(targets, artifacts, strict=True)]
