"""Exporters of the cam kinds whose files are not the plate's (cylindrical cams), for :mod:`camfab.pipeline`.

:data:`KIND_EXPORTERS` maps a ``[cam] kind`` to its own exporters by output name (``"dxf"``, ``"step"``);
an output a kind's entry lacks does not apply to it: ``camfab run`` and ``camfab export`` skip it and say why
(:func:`not_applicable_reason`; the run's ``not_applicable``).  Each exporter takes the pipeline's ``Cam`` and
``Request`` and returns its :class:`~camfab.cad.export.Artifact` list.
"""
from __future__ import annotations

import logging
import math
import weakref
from collections.abc import Callable, Sequence
from typing import Any

from ..errors import ExportError
from ..io import safe_stem
from .artifact import Artifact

__all__ = ["KIND_EXPORTERS", "KIND_CAD_OUTPUTS", "not_applicable_reason", "kind_exporter", "applicable", "applies",
           "cylinder_solid"]

log = logging.getLogger("camfab.pipeline")


def _cylinder_dxf(cam: Any, req: Any) -> list[Artifact]:
    """``<stem>.dxf``: the developed groove of a cylindrical cam (:mod:`camfab.cad.cylinder`)."""
    from .cylinder import developed_dxf  # ezdxf and the fitter only when a file is made

    text, dev = developed_dxf(cam.geometry, tol=cam.tolerance(req.tol), name=cam.name)
    return [Artifact(f"{safe_stem(cam.name)}.dxf", text.encode("utf-8"), "dxf", deviation_mm=dev)]


#: each cam's cylinder solid by (tolerance, bore): built once per design and shared by its STEP, IGES and
#: assembly (the build is the slow part of a cylindrical run), dropped with the cam
_SOLIDS: weakref.WeakKeyDictionary[Any, dict[tuple[float, float], tuple[Any, float]]] = weakref.WeakKeyDictionary()


def _is_rib(cam: Any) -> bool:
    return cam.spec.cylinder.rib_width_mm is not None


def cylinder_solid(cam: Any, req: Any) -> tuple[Any, float]:
    """The cam's grooved (or ribbed) cylinder (cadquery solid) and its path's measured deviation (mm), built once
    per cam, tolerance and bore (:func:`camfab.cad.cylinder.cylinder_solid`, :func:`camfab.cad.rib.rib_solid`)."""
    from .cylinder import cylinder_solid as grooved  # cadquery only when a file is made
    from .rib import rib_solid

    tol, bore = cam.tolerance(req.tol), float(cam.spec.manufacturing.bore_mm)
    made = _SOLIDS.setdefault(cam, {})
    if (tol, bore) not in made:
        made[(tol, bore)] = (rib_solid if _is_rib(cam) else grooved)(cam.geometry, tol=tol, bore_mm=bore)
    return made[(tol, bore)]


def _cylinder_step(cam: Any, req: Any) -> list[Artifact]:
    """``<stem>.step``: the grooved cylinder (:mod:`camfab.cad.cylinder`) or the ribbed one (:mod:`.rib`)."""
    from .step import solid_dumps

    solid, dev = cylinder_solid(cam, req)
    text = solid_dumps(solid, name=cam.name)
    return [Artifact(f"{safe_stem(cam.name)}.step", text.encode("utf-8"), "step", deviation_mm=dev)]


def _cylinder_stl(cam: Any, req: Any) -> list[Artifact]:
    """``<stem>.stl``: the grooved (or ribbed) cylinder meshed from its exact surfaces with numpy
    (:mod:`.cylinder_mesh`: no cadquery, no solid), its deviation the mesh's measured one."""
    from .cylinder_mesh import part_stl

    data, dev = part_stl(cam.geometry, tol=cam.tolerance(req.tol), name=cam.name,
                         bore_mm=float(cam.spec.manufacturing.bore_mm))
    return [Artifact(f"{safe_stem(cam.name)}.stl", data, "stl", deviation_mm=dev)]


def _cylinder_drawing(cam: Any, req: Any) -> list[Artifact]:
    """``<stem>_drawing.dxf``: the sheet of the developed groove, a side view and the lift table
    (:mod:`camfab.cad.cylinder_sheet`)."""
    from .cylinder_sheet import cylinder_drawing_sheet

    text, dev = cylinder_drawing_sheet(cam.spec, cam.geometry, cam.check(), tol=cam.tolerance(req.tol))
    return [Artifact(f"{safe_stem(cam.name)}_drawing.dxf", text.encode("utf-8"), "drawing", deviation_mm=dev)]


def _cylinder_pdf(cam: Any, req: Any) -> list[Artifact]:
    """``<stem>_drawing.pdf``: that sheet as a one-page PDF (:func:`camfab.cad.pdf.sheet_pdf`)."""
    from .pdf import sheet_pdf

    return [Artifact(a.filename.removesuffix(".dxf") + ".pdf", sheet_pdf(a.data), "pdf", deviation_mm=a.deviation_mm)
            for a in _cylinder_drawing(cam, req)]


def _cylinder_iges(cam: Any, req: Any) -> list[Artifact]:
    """``<stem>.igs``: the grooved cylinder (the STEP's solid) as IGES (:func:`camfab.cad.iges.shape_dumps`)."""
    from .iges import shape_dumps

    solid, dev = cylinder_solid(cam, req)
    text = shape_dumps(solid, name=cam.name)
    return [Artifact(f"{safe_stem(cam.name)}.igs", text.encode("ascii"), "iges", deviation_mm=dev)]


def _cylinder_assembly(cam: Any, req: Any) -> list[Artifact]:
    """``<stem>_assembly.step`` (and ``_pose<k>`` for ``req.poses``): the grooved (or ribbed) cylinder, its shaft
    and the follower (a rib's: two rollers) at ``req.angle`` degrees (:mod:`camfab.cad.cylinder_assembly`)."""
    from ..errors import InputError
    from ..limits import MAX_POSES
    from .cylinder_assembly import dumps

    if not math.isfinite(req.angle) or abs(req.angle) > 1e6:
        raise InputError(f"--angle {req.angle}: must be a finite number of at most 1e6 (degrees)")
    if not 0 <= req.poses <= MAX_POSES:
        raise InputError(f"--poses {req.poses}: must be a whole number from 0 to {MAX_POSES}")
    solid, dev = cylinder_solid(cam, req)
    stem = safe_stem(cam.name)

    def one(deg: float) -> bytes:
        return dumps(cam.spec, cam.geometry, solid, math.radians(deg % 360.0)).encode("utf-8")

    out = [Artifact(f"{stem}_assembly.step", one(req.angle), "step", None, dev, f"the mechanism at {req.angle:g}°")]
    width = len(str(req.poses))
    for k in range(req.poses):
        at = req.angle + k * 360.0 / req.poses
        out.append(Artifact(f"{stem}_assembly_pose{k + 1:0{width}d}.step", one(at), "step", None, dev,
                            f"pose {k + 1} of {req.poses}: {at:g}°"))
    return out


#: cam kinds whose files are made by their own exporters, by output name; an output missing from a kind's
#: entry does not apply to it (:func:`not_applicable_reason`); None: the pipeline's own stage, which handles the kind
#: (the report and workbook; the 4-axis program of :mod:`camfab.gcode.rotary`, dispatched in ``pipeline._gcode``;
#: the lift table of :func:`camfab.gcode.lift_table.cylinder_lift_csv`, in ``pipeline._lift_table``)
KIND_EXPORTERS: dict[str, dict[str, Callable[[Any, Any], list[Artifact]] | None]] = {
    "cylindrical": {"dxf": _cylinder_dxf, "step": _cylinder_step, "xlsx": None, "report": None,
                    "stl": _cylinder_stl, "gcode": None, "drawing": _cylinder_drawing, "pdf": _cylinder_pdf,
                    "iges": _cylinder_iges, "assembly": _cylinder_assembly, "lift_table": None},
}

#: a kind's own outputs that need cadquery: a run skips them with a warning when it is missing, as the STEP
KIND_CAD_OUTPUTS: dict[str, frozenset[str]] = {"cylindrical": frozenset({"step", "iges", "assembly"})}


def not_applicable_reason(kind: str, output: str) -> str:
    """Why ``output`` is not made for a cam of ``kind`` (an entry of :data:`KIND_EXPORTERS` lacks it)."""
    made = ", ".join(sorted(KIND_EXPORTERS.get(kind, {})))
    return f"not yet made for a {kind} cam (it gets {made}; see README, \"Cylindrical cams\")"


def kind_exporter(kind: str, out: str, default: Callable[[Any, Any], list[Artifact]]) -> Any:
    """The function making ``out`` for a cam of ``kind``: its kind's own, else ``default`` (the plate's)."""
    own = KIND_EXPORTERS.get(kind)
    if own is not None and out not in own:
        raise ExportError(f"{out}: {not_applicable_reason(kind, str(out))}")
    return default if own is None or own[out] is None else own[out]


def applicable(cam: Any, outputs: Sequence[Any]) -> tuple[list[Any], dict[str, str]]:
    """``outputs`` split into those that apply to the cam's kind and, for the others, why not (each logged as
    a warning)."""
    keep = [o for o in outputs if applies(cam.spec.cam.kind, str(o))]
    why = {str(o): not_applicable_reason(cam.spec.cam.kind, str(o)) for o in outputs if o not in keep}
    for out, reason in why.items():
        log.warning("%s: %s skipped: %s", cam.name, out, reason)
    return keep, why


def applies(kind: str, output: str) -> bool:
    """Whether ``output`` is made for a cam of ``kind``."""
    own = KIND_EXPORTERS.get(kind)
    return own is None or output in own
