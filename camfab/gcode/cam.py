"""Cam profiles → milling programs, and the exact distance functions the verifier needs.

Takes geometry (a profile :class:`~camfab.design.profile.Contact`) and a
:class:`~camfab.gcode.model.Job`; never a design file.  The finishing
contour is the exact tool-centre offset arc-fitted within ``tol``; roughing
contours are exact offsets by the allowance plus the step-over.  Every contour
reaches the toolpath builder as an :class:`~camfab.geom2d.ArcChain`.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace

from ..discretize import ParametricCurve, arcs, polyline
from ..geom2d import ArcChain
from ..offset.cutter import offset_curve, profile_curve, tool_centre_path
from .distance import CurveDistance
from .model import Job, Program
from .toolpath import contour_toolpath
from .verify import VerifyReport, verify_program

__all__ = ["FIT_SHARE", "CamProgram", "cam_program", "signed_distance", "verify_cam_program"]


@dataclass(frozen=True)
class CamProgram:
    """A milling program of one cam profile and what was measured while building it."""

    program: Program
    deviation_mm: float  # arc chain vs exact tool-centre curve
    shapely_deviation_mm: float
    entities: int


#: share of the tolerance given to the arc fit; the rest absorbs the rounding of the written
#: coordinates and arc centres (the posts write at least tol/10 resolution)
FIT_SHARE = 0.8


def cam_program(contact, job: Job, *, tol: float, compensation: str | None = None,
                arcs_allowed: bool = True) -> CamProgram:
    """The contour-milling program of one profile (periphery, outside).

    ``arcs_allowed=False`` writes the finishing contour as G1 lines only (a polyline within the
    same tolerance), for controllers or shops that do not want G2/G3.
    """
    r = job.tool_radius_mm
    tol_fit = max(tol * FIT_SHARE, 1e-6)
    path = tool_centre_path(contact, r, tol=tol_fit)
    if compensation:
        part = arcs(profile_curve(contact), tol=tol_fit)
        job = replace(job, achieved_deviation_mm=path.max_deviation)
        prog = contour_toolpath(part, job, compensation=compensation)
        return CamProgram(prog, part.max_deviation, path.shapely_deviation, part.n_entities)
    contour: ArcChain
    if arcs_allowed:
        contour, dev = path.arcs, path.max_deviation
    else:
        line = polyline(path.curve, tol=tol_fit)
        contour, dev = line.arc_chain(), line.max_deviation
    job = replace(job, achieved_deviation_mm=dev)
    prog = contour_toolpath(contour, job, roughing_contours=_rough(contact, job, tol))
    return CamProgram(prog, dev, path.shapely_deviation, contour.n_entities)


def _rough(contact, job: Job, tol: float) -> list[ArcChain]:
    """Roughing contours, outermost first: exact offsets by tool radius + allowance + k·step-over."""
    out: list[ArcChain] = []
    for k in range(job.roughing_passes, 0, -1):
        d = job.tool_radius_mm + job.roughing_allowance_mm + (k - 1) * job.stepover
        out.append(arcs(offset_curve(contact, d), tol=max(tol, 1e-3)))
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
