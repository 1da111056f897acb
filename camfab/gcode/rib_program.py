"""The 4-axis program of a cylindrical cam's rib (``[cylinder] feature = "rib"``): a rotary table (A) and a radial
end mill clear the cylinder on both sides of the rib down to its root and finish each rib flank.

Set-up, work offset, posts, feeds and sampling are the groove program's (:mod:`camfab.gcode.rotary`): X along the
axis (X0 at the cylinder's z = 0 end), Z the tool tip's radius (Z0 on the rotary axis), A0 the cam angle 0 under
the tool, ``A = −σ·x/r``; cutting moves in inverse time (G93), plunges and rapids in G94; GRBL refused.

**Stock and what is removed.**  The stock is the cylinder at the rib's top radius R_o = R + h/2 over the whole
length.  Everything outside the rib down to the root radius R_b = R − h/2 is removed, over z from 0 to the length.

**Roughing** (docs/decisions.md, "Cylindrical cams: the rib's 4-axis program").  At each depth level
(:func:`~camfab.gcode.rotary.rotary_levels`: equal steps no larger than ``[machining] step_down_mm``, the last on
the root) and on each side of the rib (+z, then −z), passes run outwards from the rib:

* **following passes**: the flank's exact cutter path on the level's radius
  (:func:`~camfab.gcode.rotary_finish.flank_path`, the cutter outside the flank) shifted along the axis, away from
  the rib, by ``a + k·s`` (a = ``roughing_allowance_mm``, the stock left for the finishing pass; s the stepover,
  ``roughing_stepover_mm``, default the tool radius), k = 0, 1, … until the pass lies wholly beyond the highest
  point of the first one;
* then **rings** at constant X, ``a + j·s`` beyond that highest point, until a pass reaches past the
  cylinder's end.

A shift along the axis keeps each pass clear of the rib (the rib is, at each developed x, an interval of z, and
the shifted cutter lies beyond it), and at every x two neighbouring passes are s apart along z: with s less than
the tool diameter (less twice the chord tolerance) their cutter sections overlap, so the root is covered to the
end.  The chords of the roughing passes may be coarser than the finishing ones (half the allowance), but no coarser
than the finishing tolerance plus the allowance less the twist error, scaled by ρ/r_top: a chord's sag on a level's
radius ρ grows by r/ρ on the cylinders above it, which the cutter also cuts.

**Finishing**: one pass per rib flank at full depth, on the exact cutter path of the flank on the root radius
(the groove's machinery of :mod:`camfab.gcode.rotary_finish`, the cutter on the roller's side of the flank):
plunge in the cleared root ``a + s/2`` beyond the path along the axis, straight to the path at cam angle 0, once
round, back out.  Milling direction: a rib flank has the material on the other side of the cutter from the
groove's flank of the same name, so its pass runs as the groove's opposite flank (:func:`rib_direction`); the
roughing passes, with the uncut stock outwards, as the groove's flank on their side (:func:`roughing_direction`).

**Cutter checks** (:func:`check_rib_tool`): a cutter too large for a concave stretch of a flank (seen from the
cutter's side, as the roller sees it) is refused; so is one whose twist error (the radial cutter tangent to the
flank on the root, measured on six radii up to the top, :func:`rib_twist`: unlike the groove's
:func:`~camfab.gcode.rotary_finish.twist_overcut` both ways, since a cutter larger than the rollers leaves material
on the rib that the rollers' clearance does not allow) exceeds half the tolerance.  A rib's cutter may be smaller
or larger than the roller: only a cutter of the roller's size plus the backlash follows the flank exactly, so the
refusal names ``manufacturing.tool_diameter_mm`` and the smallest and largest diameters that fit.  An oscillating
follower's swing is checked as for the groove (a rib is translating only today, so it never applies).
"""
from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np

from ..errors import ExportError, Problem, SpecError
from ..offset.cutter import concave_limit
from ..offset.groove import flank_cutter_problem
from .model import Job
from .posts.base import Post
from .rotary import RotaryWriter, chord_error, rotary_levels, rotary_post, rotary_samples, to_machine
from .rotary_finish import (
    TWIST_SHARE,
    cutter_penetration,
    finishing_direction,
    flank_path,
    refuse_off_radial_axis,
)

__all__ = ["rib_gcode", "check_rib_tool", "rib_direction", "roughing_direction", "rib_roughing_paths", "rib_twist",
           "MAX_PASSES"]

#: the most roughing passes per side and level (an input limit: a tiny stepover on a long cylinder)
MAX_PASSES = 2000
#: samples per turn on which the cutter checks measure, and the radii (fractions from the root to the top)
_CHECK_SAMPLES = 1441
_RADII = np.linspace(0.0, 1.0, 6)


def rib_direction(flank: int, sense: int, climb: bool) -> int:
    """+1 to run the finishing pass of rib flank ``flank`` with increasing cam angle, −1 backwards: the material
    (the rib) lies on the other side of the cutter from a groove's flank of the same name."""
    return finishing_direction(-flank, sense, climb)


def roughing_direction(side: int, sense: int, climb: bool) -> int:
    """+1 / −1 for the roughing passes on side ``side`` of the rib, the uncut stock outwards (as a groove's flank
    on that side)."""
    return finishing_direction(side, sense, climb)


def rib_twist(geometry: Any, r_c: float, phi: np.ndarray) -> tuple[float, float]:
    """How far (mm) a radial cutter of radius ``r_c`` on the full-depth finishing path of either rib flank strays
    from the flank's exact section above the root, either way (past it into the rib, or short of it: material
    left on the rib, which the rollers' clearance of half the backlash does not allow either): the largest
    ``|cutter_penetration|`` on six radii from the root to the top, and the radius where it is worst."""
    cyl = geometry.cylinder
    r_b, r_o = cyl.inner_radius_mm, cyl.outer_radius_mm
    worst, where = 0.0, r_b
    for flank in (1, -1):
        P = flank_path(geometry, r_b, flank, r_c, phi)
        for r in r_b + _RADII * (r_o - r_b):
            pen = cutter_penetration(geometry, float(r), flank, r_c, P * np.array([r / r_b, 1.0]))
            err = float(np.max(np.abs(pen)))
            if err > worst:
                worst, where = err, float(r)
    return worst, where


def _overcut(geometry: Any, r_c: float, phi: np.ndarray) -> float:
    return rib_twist(geometry, r_c, phi)[0]


def _edge(geometry: Any, w: float, d: int, f_w: float, slope: float, budget: float, phi: np.ndarray) -> float:
    """The cutter radius on side ``d`` (−1 smaller, +1 larger) of the roller's w where the twist error reaches
    the budget: secant steps from the linear estimate (the overcut is nearly proportional to |r_c − w|)."""
    delta = 0.98 * (budget - f_w) / slope
    for _ in range(6):
        cur = _overcut(geometry, w + d * delta, phi)
        if cur <= budget:
            break
        delta *= 0.98 * (budget - f_w) / max(cur - f_w, 1e-12)
    return w + d * delta


def check_rib_tool(geometry: Any, tool_radius: float, tol: float, phi: np.ndarray | None = None) -> float:
    """Refuse (SpecError naming ``manufacturing.tool_diameter_mm``) a cutter too large for a concave stretch of a
    rib flank, or whose twist error (:func:`rib_twist`) exceeds ``TWIST_SHARE·tol`` (the message gives the smallest
    and the largest diameter that fit); return that error (mm)."""
    phi = np.linspace(0.0, float(geometry.period), _CHECK_SAMPLES) if phi is None else phi
    fits, contact = min(((concave_limit(c)[0], c) for c in geometry.profiles), key=lambda fc: fc[0])
    if tool_radius >= fits:
        why = flank_cutter_problem(contact, tool_radius)
        raise SpecError(Problem("manufacturing.tool_diameter_mm", 2 * tool_radius,
                                f"the finishing pass would gouge a rib flank: {why}",
                                f"use an end mill of diameter below {2 * fits:.4g} mm"))
    over, where = rib_twist(geometry, tool_radius, phi)
    budget = TWIST_SHARE * tol
    if over <= budget:
        return over
    w = geometry.mechanism.half_width(geometry.cylinder.inner_radius_mm)
    refuse_off_radial_axis(geometry, w, budget, phi)
    f_w = _overcut(geometry, w, phi)
    if f_w > budget:
        raise SpecError(Problem("manufacturing.tolerance_mm", tol,
                                f"even an end mill of the rollers' size strays {f_w:.4f} mm from a rib flank (allowed "
                                f"{budget:.4g} mm, half the tolerance)", "give a coarser tolerance"))
    slope = max((over - f_w) / max(abs(tool_radius - w), 1e-9), 1e-9)
    lo = _edge(geometry, w, -1, f_w, slope, budget, phi)
    hi = min(_edge(geometry, w, 1, f_w, slope, budget, phi), fits)
    small, large = math.ceil(2 * lo * 1000) / 1000, math.floor(2 * hi * 1000) / 1000
    raise SpecError(Problem("manufacturing.tool_diameter_mm", 2 * tool_radius,
                            "a radial end mill of another size than the rollers cannot follow the rib flank's twist "
                            f"across the rib's height: finishing tangent to the flank on the root it would stray "
                            f"{over:.4f} mm from the flank (into the rib, or leaving material on it) at radius "
                            f"{where:.4g} mm (allowed {budget:.4g} mm, half the tolerance)",
                            f"use an end mill of diameter from {small:g} mm (the smallest that fits) to {large:g} mm "
                            f"(the largest; the rollers are {2 * w:.6g} mm with the backlash), or a coarser "
                            "tolerance"))


def _check_stepover(job: Job, tol_rough: float) -> float:
    s, d = job.stepover, job.tool_diameter_mm
    most = d - 2.0 * tol_rough - 0.1 * d
    if not 0.0 < s <= most:
        raise SpecError(Problem("machining.roughing_stepover_mm", s,
                                "the rib's roughing passes would leave ridges on the root: neighbouring passes must "
                                "overlap", f"give a stepover of at most {most:.4g} mm (90% of the tool diameter less "
                                "twice the roughing chord tolerance)"))
    return s


def rib_roughing_paths(P: np.ndarray, side: int, r_c: float, a: float, s: float, length: float, span: float,
                       way: int, tol: float) -> list[tuple[str, float, np.ndarray]]:
    """The roughing passes of one side on one level (module notes) from the flank's cutter path ``P`` (developed
    (x, z) on the level's radius, in the pass's order): (kind, axial offset from P or ring z, developed points)."""
    u = side * P[:, 1]
    umin, umax = float(u.min()), float(u.max())
    u_end = length if side > 0 else 0.0
    out: list[tuple[str, float, np.ndarray]] = []
    for k in range(MAX_PASSES):
        o = a + k * s
        out.append(("following", o, P + np.array([0.0, side * o])))
        if umin + o + r_c >= u_end + tol:
            return out
        if umin + o >= umax + a:
            break
    x0 = float(P[0, 0])
    ring_x = x0 + way * span * np.linspace(0.0, 1.0, 5)
    for j in range(1, MAX_PASSES):
        uj = umax + a + j * s
        out.append(("ring", side * uj, np.stack([ring_x, np.full(5, side * uj)], axis=1)))
        if uj + r_c >= u_end + tol:
            return out
    raise ExportError(f"the rib's roughing needs more than {MAX_PASSES} passes per side and level: give a larger "
                      "[machining] roughing_stepover_mm or a larger tool")


def _header(w: RotaryWriter, geometry: Any, levels: list[float], safe: float, tol: float, over: float,
            s: float) -> None:
    cyl, mech, u = geometry.cylinder, geometry.mechanism, "in" if w.job.units == "inch" else "mm"
    w.header("camfab 4-axis program: cylindrical cam rib, roughing both sides to the root and a finishing pass "
             "per rib flank",
             [f"stock: cylinder Z{w.L(cyl.outer_radius_mm)} (the rib top) x {w.L(cyl.length_mm)} {u} long, "
              f"rib root Z{w.L(cyl.inner_radius_mm)}, rib width {w.L(cyl.rib_width_mm)} {u} where it runs round",
              f"roughing: stepover {w.L(s)} {u}, allowance {w.L(w.job.roughing_allowance_mm)} {u} on the flanks"],
             f"flanks: one finishing pass each at full depth, tangent on the root radius, twist above it "
             f"either way at most {max(over, 0.0) * w.k:.4f} {u}", levels, safe, tol, mech.sense, mech.rotation)


class _Cut:
    """Writes passes (developed points on a radius → X, A) and keeps the moves count and worst chord error."""

    def __init__(self, w: RotaryWriter, sigma: float, safe: float, clear: float, lenoff: list[str]):
        self.w, self.sigma, self.safe, self.clear, self.lenoff = w, sigma, safe, clear, lenoff
        self.moves, self.worst = 0, 0.0

    def run(self, label: str, P: np.ndarray, r: float) -> None:
        X, A = to_machine(P, r, self.sigma)
        self.w.comment(label)
        self.w.enter(X[0], A[0], r, self.safe, self.clear, self.lenoff)
        self.lenoff = []
        self.moves += self.w.inverse_time(X, A, r)
        self.w.leave(self.safe)

    def sampled(self, geometry: Any, r: float, tol: float, curve: Callable[[np.ndarray], np.ndarray],
                finishing: bool) -> np.ndarray:
        """The cam angles of ``curve`` on radius r within ``tol`` (keeping the finishing passes' worst chord
        error: the roughing passes' are not the part's surface)."""
        phi = rotary_samples(geometry, r, tol, curve)
        if finishing:
            self.worst = max(self.worst, float(np.max(chord_error(curve, phi))))
        return phi


def _roughing(cut: _Cut, geometry: Any, levels: list[float], s: float, tol_r: float, bound: float) -> None:
    """Roughing passes; ``bound`` (mm) is what a pass shifted by the allowance may cut past a flank: a chord's sag
    on a level's radius grows by r/ρ on the cylinders above it, up to the rib's top, so each level's chords are
    sampled within ``min(tol_r, bound)·ρ/r_top``."""
    job, w = cut.w.job, cut.w
    r_c, a, period = job.tool_radius_mm, job.roughing_allowance_mm, float(geometry.period)
    climb = job.direction == "climb"
    r_top = geometry.cylinder.outer_radius_mm
    for i, rho in enumerate(levels):
        tol_level = min(tol_r, bound) * rho / r_top
        for side, name in ((1, "+z"), (-1, "-z")):
            way = roughing_direction(side, int(cut.sigma), climb)

            def curve(t: np.ndarray, side: int = side, way: int = way, rho: float = rho) -> np.ndarray:
                return flank_path(geometry, rho, side, r_c, way * t)

            P = curve(cut.sampled(geometry, rho, tol_level, curve, False))
            paths = rib_roughing_paths(P, side, r_c, a, s, geometry.cylinder.length_mm, rho * period, way,
                                       2.0 * tol_r)
            for k, (kind, off, Q) in enumerate(paths):
                where = f"offset {w.L(off)}" if kind == "following" else f"X{w.L(off)}"
                cut.run(f"roughing pass level {i + 1} of {len(levels)} Z{w.L(rho)} {name} side {k + 1} of "
                        f"{len(paths)} ({kind} {where})", Q, rho)


def _finishing(cut: _Cut, geometry: Any, s: float, tol_fin: float) -> None:
    job, w = cut.w.job, cut.w
    r_b, r_c, period = geometry.cylinder.inner_radius_mm, job.tool_radius_mm, float(geometry.period)
    lead = job.roughing_allowance_mm + 0.5 * s
    for flank, name in ((1, "+z"), (-1, "-z")):
        way = rib_direction(flank, int(cut.sigma), job.direction == "climb")

        def curve(t: np.ndarray, flank: int = flank, way: int = way) -> np.ndarray:
            return flank_path(geometry, r_b, flank, r_c, way * t)

        P = curve(cut.sampled(geometry, r_b, tol_fin, curve, True))
        out = np.array([0.0, flank * lead])
        cut.run(f"finishing pass {name} rib flank Z{w.L(r_b)} ({'forwards' if way > 0 else 'backwards'}, "
                f"{job.direction})", np.vstack([P[:1] + out, P, curve(np.array([period])) + out]), r_b)


def rib_gcode(geometry: Any, job: Job, tol: float, post: str | Post = "linuxcnc") -> tuple[bytes, int, float]:
    """The rib's 4-axis program (module notes) as bytes, its number of cutting ``G1 X.. A..`` moves and the largest
    chord error (mm) of the written passes on the developed cylinder of each level's radius (before rounding)."""
    p = rotary_post(post)
    cyl = geometry.cylinder
    over = check_rib_tool(geometry, job.tool_radius_mm, tol)
    w = RotaryWriter(p, job, tol)
    h_lin = 0.5 * 10.0 ** -w.d / w.k
    h_ang = 0.5 * 10.0 ** -w.d * math.pi / 180.0 * cyl.outer_radius_mm
    tol_fit = max(tol - math.hypot(h_lin, h_ang), 0.5 * tol)
    tol_rough = max(tol_fit, 0.5 * job.roughing_allowance_mm)
    s = _check_stepover(job, tol_rough)
    levels = rotary_levels(cyl.outer_radius_mm, cyl.inner_radius_mm, job.step_down_mm)
    safe = cyl.outer_radius_mm + job.safe_z_mm
    _header(w, geometry, levels, safe, tol, over, s)
    lenoff = ["G43", f"H{job.tool_number}"] if p.tool_change and p.length_offset else []
    cut = _Cut(w, float(geometry.mechanism.sense), safe, cyl.outer_radius_mm + job.clearance_mm, lenoff)
    # the first following pass is the finishing path shifted by the allowance a: its sag plus the twist error (over)
    # stays within the finishing tolerance beyond the flank (at least a quarter of it)
    _roughing(cut, geometry, levels, s, tol_rough,
              max(tol_fit + job.roughing_allowance_mm - max(over, 0.0), 0.25 * tol_fit))
    # a chord's sag on the root grows by r/r_b on the cylinders above it, up to the rib's top
    scale = cyl.inner_radius_mm / cyl.outer_radius_mm
    _finishing(cut, geometry, s, max(tol_fit * scale - max(over, 0.0), 0.25 * tol_fit * scale))
    w.block(["M9"])
    w.block(["M5"])
    w.block([p.end_code])
    if p.percent:
        w.lines.append("%")
    return ("\n".join(w.lines) + "\n").encode("ascii"), cut.moves, cut.worst
