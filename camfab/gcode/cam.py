"""Cam profiles → milling programs, and the exact distance functions the verifier needs.

Takes geometry (a profile :class:`~camfab.design.profile.Contact`) and a
:class:`~camfab.gcode.model.Job`; never a design file.  The finishing
contour is the exact tool-centre offset arc-fitted within ``tol``; roughing
contours are exact offsets by the allowance plus the step-over.  Every contour
reaches the toolpath builder as an :class:`~camfab.geom2d.ArcChain`.
"""
from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from ..discretize import ParametricCurve, arcs, arcs_within_radius, polyline
from ..discretize.fit import REFIT_SHARE
from ..errors import ApiError
from ..geom2d import ArcChain
from ..offset.cutter import ToolCentrePath, offset_curve, offset_loop, profile_curve, tool_centre_path
from ..records import dataclass, replace
from ..tolerances import arc_radius_limit
from .distance import CurveDistance
from .model import Job, Program, machining_of
from .toolpath import contour_toolpath
from .verify import VerifyReport, verify_program

__all__ = ["FIT_SHARE", "CamProgram", "cam_program", "contour_tolerance", "contour_fit_tolerance", "signed_distance",
           "verify_cam_program"]


@dataclass(frozen=True)
class CamProgram:
    """A milling program of one cam profile and what was measured while building it."""

    program: Program
    deviation_mm: float  # arc chain vs exact tool-centre curve
    shapely_deviation_mm: float
    entities: int


#: share of the tolerance the contour may use at most; the rest (and never less than the post's
#: :meth:`~camfab.gcode.posts.base.Post.rounding_allowance_mm`) absorbs the rounding of the written coordinates
#: and arc centres
FIT_SHARE = 0.8


def contour_tolerance(tol: float, post=None, units: str = "mm") -> float:
    """The share of ``tol`` (mm) the finishing contour may deviate from the exact curve: ``FIT_SHARE·tol``, less
    when the post's rounding needs more room (``tol - rounding allowance``; docs/decisions.md, "Fanuc decimals
    and the rounding budget")."""
    from .post import get_post

    room = tol - get_post(post or "linuxcnc").rounding_allowance_mm(units, tol)
    return max(min(tol * FIT_SHARE, room), 1e-6)


def contour_fit_tolerance(tol: float, post=None, units: str = "mm") -> float:
    """The tolerance (mm) the finishing contour's tool-centre path is arc-fitted within: the
    :func:`contour_tolerance` less the :data:`~camfab.discretize.fit.REFIT_SHARE` the chords of arcs above the
    post's largest radius may need.  The DXF's TOOL_PATH layer draws the same fit (docs/decisions.md, "The DXF
    tool path is the program's")."""
    return max(contour_tolerance(tol, post, units) * (1.0 - REFIT_SHARE), 1e-6)


def contour_paths(spec, geometry, overrides: Mapping[str, Any] | None = None, *, tol: float, post=None,
                  cache: dict | None = None, profiles: Sequence[ArcChain] = ()
                  ) -> tuple[ToolCentrePath, ...] | None:
    """The tool-centre path of every profile of ``geometry`` that :func:`cam_program` makes the finishing contour
    of: the design's tool (``overrides["tool_diameter_mm"]`` when given), fitted within
    :func:`contour_fit_tolerance` of ``tol`` for ``post`` and the ``[machining]`` units; None without a tool.

    ``cache`` (a dict the caller keeps, e.g. :class:`camfab.pipeline.Cam`'s) holds each path once per (profile,
    radius, tolerance): the DXF's TOOL_PATH layer and the program share one offset, one shapely guard and one fit
    (docs/decisions.md, "The DXF tool path is the program's").  ``profiles`` (the plate's arc fit of every
    profile, :func:`camfab.cad.export.cam_shapes` within ``tol``) make each path when their offset by the tool
    radius lies within the fit tolerance of the exact offset, measured (docs/decisions.md, "One arc fit per
    profile").
    """
    over = {k: v for k, v in (overrides or {}).items() if v is not None}
    tool = over.get("tool_diameter_mm", spec.manufacturing.tool_diameter_mm)
    if not tool:
        return None
    r = 0.5 * tool
    fit_tol = contour_fit_tolerance(tol, post, machining_of(spec, over).units)
    cache = {} if cache is None else cache
    for i, contact in enumerate(geometry.profiles):
        if (i, r, fit_tol, tol) not in cache:
            cache[i, r, fit_tol, tol] = tool_centre_path(contact, r, tol=fit_tol,
                                                         profile_arcs=profiles[i] if profiles else None)
    return tuple(cache[i, r, fit_tol, tol] for i in range(len(geometry.profiles)))


def cam_program(contact, job: Job, *, tol: float, compensation: str | None = None,
                arcs_allowed: bool = True, post=None, path: ToolCentrePath | None = None) -> CamProgram:
    """The contour-milling program of one profile (periphery, outside), for ``post`` (name or
    :class:`~camfab.gcode.posts.base.Post`; default linuxcnc), which sets the rounding budget and the
    largest arc radius written (larger arcs become chords within the tolerance).

    ``arcs_allowed=False`` writes the finishing contour as G1 lines only (a polyline within the
    same tolerance), for controllers or shops that do not want G2/G3.

    ``path`` is the tool-centre path of ``contact`` for ``job.tool_radius_mm`` when the caller has it already
    (:func:`~camfab.offset.cutter.tool_centre_path` at :func:`contour_fit_tolerance`, its shapely guard run):
    the finishing contour is then made from its arcs, and nothing is offset, guarded or fitted twice.
    """
    from .post import get_post

    cap = get_post(post or "linuxcnc").max_arc_radius_mm
    r = job.tool_radius_mm
    share = contour_tolerance(tol, post, job.units)
    # the arcs get (1 - REFIT_SHARE) of the share, the chords of arcs above max_r the room the fit leaves
    tol_fit = contour_fit_tolerance(tol, post, job.units)
    # the finishing contour's arcs are the tool path's own fit at tol_fit (one fit, not one at the usual share and
    # a finer one after it: the shapely cross-check does not depend on the tolerance); the compensated and
    # lines-only programs use the tool path only for its size and cross-check, at the usual share (when the caller
    # gives no path: the pipeline gives the shared one, contour_paths)
    usual = max(tol_fit, tol * FIT_SHARE * (1.0 - REFIT_SHARE))
    if path is None:
        path = tool_centre_path(contact, r, tol=tol_fit if arcs_allowed and not compensation else usual)
    elif not math.isclose(path.tool_radius, r, rel_tol=0.0, abs_tol=1e-12):
        raise ApiError(f"the tool path given is for a cutter of radius {path.tool_radius:g} mm, the job's is {r:g}")
    max_r = arc_radius_limit(float(np.hypot(*np.asarray(path.arcs.starts, dtype=float).T).max()), cap)
    if compensation:
        # the program carries the part contour (the controller offsets it exactly): its deviation is the claim
        curve = profile_curve(contact)
        part = arcs_within_radius(arcs(curve, tol=tol_fit), curve, tol=share, max_radius_mm=max_r)
        job = replace(job, achieved_deviation_mm=part.max_deviation)
        prog = contour_toolpath(part, job, compensation=compensation)
        return CamProgram(prog, float(part.max_deviation or 0.0), path.shapely_deviation, part.n_entities)
    contour: ArcChain
    if arcs_allowed:
        fit = path.arcs if path.tol <= tol_fit else arcs(path.curve, tol=tol_fit)
        contour = arcs_within_radius(fit, path.curve, tol=share, max_radius_mm=max_r)
        dev = float(contour.max_deviation or 0.0)
    else:
        line = polyline(path.curve, tol=tol_fit)
        contour, dev = line.arc_chain(), line.max_deviation
    job = replace(job, achieved_deviation_mm=dev)
    prog = contour_toolpath(contour, job, roughing_contours=_rough(contact, job, tol, max_r, path))
    return CamProgram(prog, dev, path.shapely_deviation, contour.n_entities)


def _rough(contact, job: Job, tol: float, max_r: float, path: ToolCentrePath) -> list[ArcChain]:
    """Roughing contours, outermost first: exact offsets by tool radius + allowance + k·step-over, each the
    finishing path's arcs offset outward when those lie within the roughing tolerance of it (measured,
    :func:`~camfab.offset.cutter.offset_loop`), else a fit of its own."""
    out: list[ArcChain] = []
    rough_tol = max(tol, 1e-3)
    for k in range(job.roughing_passes, 0, -1):
        d = job.tool_radius_mm + job.roughing_allowance_mm + (k - 1) * job.stepover
        curve = offset_curve(contact, d)
        fit = offset_loop(path.arcs, d - path.tool_radius, curve, rough_tol)
        if fit is None:
            fit = arcs(curve, tol=rough_tol)
        out.append(arcs_within_radius(fit, curve, tol=rough_tol, max_radius_mm=max_r))
    return out


def signed_distance(curve: ParametricCurve, *, tol: float, exact_within: float = math.inf) -> CurveDistance:
    """``f(points (n, 2)) -> (n,)``: signed distance to a closed exact curve, positive outside.

    Exact (to rounding: the nearest point of the curve itself, :class:`~camfab.gcode.distance.CurveDistance`),
    at a cost that follows the number of points, not the size of the curve.  ``tol`` is the caller's
    tolerance, kept for the signature (the distance no longer depends on it); points farther than
    ``exact_within`` may get a value off by at most 0.01 mm, with the right sign.
    """
    return CurveDistance(curve, exact_within=exact_within)


def verify_cam_program(program: str | bytes, contact, job: Job, *, tol: float, post: str | None = None,
                       default_post: str | None = None, comp_radius: float | None = None,
                       part: CurveDistance | None = None) -> VerifyReport:
    """What ``camfab verify`` checks: ``program`` (text or bytes) against the exact profile ``contact`` and
    the ``job`` (final depth, step-down, feeds, spindle, coolant, tool, direction, safe height), with
    coverage of the whole contour; a program that cannot be read is a ``PARSE_ERROR`` finding.

    The exact tool-centre curve is the set of points ``job.tool_radius_mm`` from the part, so its distance
    is ``|part distance - r|`` (one exact distance serves the deviation, the gouge and the coverage).
    ``part`` is :func:`signed_distance` of the profile (built when not given): exact up to ``r + tol`` and
    a little more, which every judgement needs (gouge below ``r - tol``, deviation ``|d - r| <= tol``).
    """
    if part is None:
        part = signed_distance(profile_curve(contact), tol=tol, exact_within=job.tool_radius_mm + tol + 0.05)
    return verify_program(program, post=post, default_post=default_post, exact_curve_distance=None,
                          part_distance=part, part_curve=part, tool_radius=job.tool_radius_mm, tol=tol,
                          safe_z=job.safe_z_mm, top_z=0.0, comp_radius=comp_radius, job=job)
