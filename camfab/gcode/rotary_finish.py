"""The finishing passes of a cylindrical cam's groove, per flank, on the developed cylinders.

A cutter of radius r_c narrower than the groove (half-width w(r) = R_r(r) + backlash/2) leaves w − r_c on each
flank after the centre pass.  Like the face-groove cam (:mod:`camfab.gcode.groove`) one finishing pass per flank
runs at **full depth**: the cutter tip on the groove bottom radius r_b, the cutter's axis radial, placed so the
cutter's exact section on r_b touches the flank (of
:meth:`~camfab.design.cylindrical.CylindricalGeometry.at_radius`) *in the developed plane of r_b*.

**The cutter's section.**  A radial cylinder of radius r_c cut by the cylinder r is, developed, the roller's
section of :mod:`camfab.design.roller_section` with c = 0, h = r_c, e = 0: ``σ(t) = (r·asin(r_c·cos t / r),
r_c·sin t)``, a circle stretched along x by ``r·asin(r_c/r) − r_c ≈ r_c³/(6r²)``.  At a flank point F with unit
normal n (into the groove) the cutter touches the flank with its point σ(t_c) whose outward normal is −n
(``σ_t(t_c)·n = 0``, Newton from the circle's root, :func:`cutter_contact`), so its axis is at ``F − σ(t_c)``
(:func:`flank_path`); the circular offset ``F + r_c·n`` would cut past the flank by about
``(r·asin(r_c/r) − r_c)·n_x²``.

**The twist.**  The flank's section at radius r is the developed pitch curve ``C_r`` offset by w(r); its normal
turns with r (a translating follower's developed slope is S′/r).  A radial axis placed for tangency at r_b meets
the cylinder r at the developed point scaled by r/r_b, which lies off the flank's offset there: the cutter cuts
past the flank above the bottom by about ``(w − r_c)·(r·N_b/(r_b·N_r) − 1)`` (N_r = |C_r′|).  Only a cutter of
the roller's size (w − r_c = 0) cuts the exact flank with a radial axis.  :func:`twist_overcut` measures it
exactly (the cutter's axis on six radii from r_b to the outer radius, the point of its exact section there that
faces the flank, measured from the flank's exact section, :func:`cutter_penetration`) and
:func:`check_finishing_tool` refuses a cutter whose overcut exceeds half the tolerance, naming
``manufacturing.tool_diameter_mm`` and the smallest diameter that fits; it refuses too a cutter larger than a
concave stretch of a flank on any of the three radii the design checks (bottom, pitch, outer).  Seen from the
groove a flank's concave radius is the pitch curve's plus w, larger than any cutter narrower than the groove,
unless the flank folds over itself (an undercut): the refusal then says to fix the design.
"""
from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..design.cylinder_spec import Feature
from ..design.roller_section import RollerSection
from ..errors import ApiError, GeometryError, Problem, SpecError
from ..geom2d import dot
from ..offset.cutter import concave_limit
from ..offset.groove import flank_cutter_problem

__all__ = ["cutter_contact", "flank_path", "flank_at", "cutter_penetration", "pitch_distance", "twist_overcut",
           "check_finishing_tool", "finishing_direction", "TWIST_SHARE", "largest_overcut", "refuse_off_radial_axis",
           "require_groove"]

#: the share of the tolerance the twist overcut may take (the rest: the chords and the rounding)
TWIST_SHARE = 0.5
#: pitch-curve samples per period for the nearest-point search, and the refinement's iterations
_DENSE = 16384
_ITER = 40
#: radii (fractions from the bottom to the outer radius) on which the twist is measured
_RADII = np.linspace(0.0, 1.0, 6)


def cutter_contact(r: float, r_c: float, n: np.ndarray) -> np.ndarray:
    """The point σ(t_c) (developed, from the axis's point) of a radial cutter's section on the cylinder of radius
    ``r`` (:class:`~camfab.design.roller_section.RollerSection` with c = 0, h = ``r_c``, e = 0: a circle stretched
    along x) whose outward normal is −n, for unit vectors ``n`` (m, 2): Newton on ``σ_t·n = 0`` from the circle's
    root (t₀ the angle of −n), to 1e-12; (m, 2)."""
    sec = RollerSection(float(r), 0.0, float(r_c))
    n = np.asarray(n, dtype=float).reshape(-1, 2)
    t, e = np.arctan2(-n[:, 1], -n[:, 0]), np.zeros(len(n))
    for _ in range(_ITER):
        s_t, _, s_tt, _, _ = sec.derivatives(t, e)
        step = dot(s_t, n) / dot(s_tt, n)
        t = t - step
        if np.all(np.abs(step) < 1e-12):
            return sec.sigma(t, e)
    raise GeometryError("the cutter's section did not converge (Newton): the end mill is too large for the "
                        "cylinder radius; use a smaller manufacturing.tool_diameter_mm")


def flank_path(geometry: Any, r: float, flank: int, r_c: float, phi: np.ndarray) -> np.ndarray:
    """The centre of a radial cutter of radius ``r_c`` tangent to flank ``flank`` (+1: +z side) on the developed
    cylinder of radius ``r`` at cam angles ``phi``: each flank point F with normal n (into the groove) less the
    point of the cutter's exact section whose outward normal is −n (:func:`cutter_contact`), (n, 2) of (x, z)."""
    s = geometry.at_radius(r, flank).evaluate(np.asarray(phi, dtype=float))
    return s.point - cutter_contact(r, r_c, s.normal)


class _FlankAt:
    """A flank on the developed cylinder r sampled densely over a period and a quarter either side, for the signed
    distance of points from it (+ into the groove): the nearest sample, then Gauss–Newton steps on the flank's
    parameter (``t += (q − F)·F′/|F′|²``)."""

    def __init__(self, geometry: Any, r: float, flank: int):
        from scipy.spatial import cKDTree

        self.c, self.span, self.period = geometry.at_radius(r, flank), r * float(geometry.period), geometry.period
        self.h = float(geometry.period) / _DENSE
        self.grid = np.arange(-_DENSE // 4, _DENSE + _DENSE // 4 + 1) * self.h
        self.tree = cKDTree(self.c.evaluate(self.grid).point)

    def distance(self, pts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Signed distance (mm) of developed points (m, 2) from the flank, and its unit normal at the nearest
        point, (m,) and (m, 2)."""
        pts = np.asarray(pts, dtype=float).reshape(-1, 2)
        shift = np.floor(pts[:, 0] / self.span) * self.span
        q = pts - np.stack([shift, np.zeros_like(shift)], axis=1)
        t = self.grid[self.tree.query(q)[1]]
        for _ in range(3):
            s = self.c.evaluate(t)
            d1 = s.point_d1
            t = np.clip(t + dot(q - s.point, d1) / dot(d1, d1), t - 2 * self.h, t + 2 * self.h)
        s = self.c.evaluate(t)
        return dot(q - s.point, s.normal), s.normal


#: the dense flanks built for the finishing checks, by (geometry, radius, flank); kept small
_FLANKS: dict[tuple[int, float, int], tuple[Any, _FlankAt]] = {}


def flank_at(geometry: Any, r: float, flank: int) -> _FlankAt:
    """The dense flank ``flank`` on radius ``r`` of ``geometry`` (cached while the geometry lives)."""
    key = (id(geometry), round(float(r), 9), int(flank))
    hit = _FLANKS.get(key)
    if hit is None or hit[0] is not geometry:
        if len(_FLANKS) > 64:
            _FLANKS.clear()
        hit = _FLANKS[key] = (geometry, _FlankAt(geometry, float(r), int(flank)))
    return hit[1]


def cutter_penetration(geometry: Any, r: float, flank: int, r_c: float, axis: np.ndarray) -> np.ndarray:
    """How far (mm, > 0 past the flank) the exact section on radius ``r`` of a radial cutter of radius ``r_c``
    whose axis meets that cylinder at the developed points ``axis`` (m, 2) reaches past flank ``flank``: its
    point whose outward normal is minus the flank's normal nearest the axis, measured from the flank."""
    fa = flank_at(geometry, r, flank)
    _, n = fa.distance(axis)
    d, _ = fa.distance(np.asarray(axis, dtype=float).reshape(-1, 2) + cutter_contact(r, r_c, n))
    return -d


def pitch_distance(geometry: Any, r: float, pts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Signed distance (mm, + on the +z side of the travel) of developed points ``pts`` (n, 2) on radius ``r``
    from the exact developed pitch curve there, and the cam angle of the nearest point (rad, unwrapped to the
    points' x).  A dense search then a ternary refinement of each nearest parameter."""
    from scipy.spatial import cKDTree

    pts = np.asarray(pts, dtype=float).reshape(-1, 2)
    period = float(geometry.period)
    span = r * period  # the developed x of one period
    shift = np.floor(pts[:, 0] / span) * span
    q = pts - np.stack([shift, np.zeros_like(shift)], axis=1)
    c = geometry.at_radius(r)
    h = period / _DENSE
    grid = np.arange(-_DENSE // 4, _DENSE + _DENSE // 4 + 1) * h
    _, k = cKDTree(c.pitch(grid)[0]).query(q)
    lo, hi = grid[k] - 2 * h, grid[k] + 2 * h

    def d2(t: np.ndarray) -> np.ndarray:
        return np.sum((c.pitch(t)[0] - q) ** 2, axis=1)

    for _ in range(_ITER):
        a, b = lo + (hi - lo) / 3, hi - (hi - lo) / 3
        closer = d2(a) < d2(b)
        hi = np.where(closer, b, hi)
        lo = np.where(closer, lo, a)
    t = 0.5 * (lo + hi)
    C, T = c.pitch(t)
    up = np.stack([-T[:, 1], T[:, 0]], axis=1) / np.hypot(T[:, 0], T[:, 1])[:, None]
    return np.sum((q - C) * up, axis=1), t + shift / r


def twist_overcut(geometry: Any, flank: int, r_c: float, phi: np.ndarray) -> tuple[float, float]:
    """How far (mm, > 0 past the flank) a radial cutter on the full-depth finishing path of ``flank`` cuts past
    the flank's exact section above the bottom (module notes), and the radius where it is worst."""
    cyl = geometry.cylinder
    r_b, r_o = cyl.inner_radius_mm, cyl.outer_radius_mm
    P = flank_path(geometry, r_b, flank, r_c, phi)
    worst, where = -math.inf, r_b
    for r in r_b + _RADII * (r_o - r_b):
        over = float(np.max(cutter_penetration(geometry, float(r), flank, r_c, P * np.array([r / r_b, 1.0]))))
        if over > worst:
            worst, where = over, float(r)
    return worst, where


def largest_overcut(geometry: Any, r_c: float, phi: np.ndarray) -> tuple[float, float]:
    a, b = twist_overcut(geometry, 1, r_c, phi), twist_overcut(geometry, -1, r_c, phi)
    return a if a[0] >= b[0] else b


def check_finishing_tool(geometry: Any, tool_radius: float, tol: float, phi: np.ndarray) -> float:
    """Refuse (SpecError naming ``manufacturing.tool_diameter_mm``) a cutter too large for a concave stretch of a
    flank, or whose twist overcut exceeds ``TWIST_SHARE·tol``; return the overcut (mm)."""
    fits, contact = min(((concave_limit(c)[0], c) for c in geometry.profiles), key=lambda fc: fc[0])
    if tool_radius >= fits:
        fix = (f"use an end mill of diameter below {2 * fits:.4g} mm" if fits > 0.1 * tool_radius else
               "no cutter finishes a flank that folds over itself (an undercut, see the design's UNDERCUT check): "
               "give the design a larger [cylinder] radius_mm, a smaller lift or a longer rise")
        raise SpecError(Problem("manufacturing.tool_diameter_mm", 2 * tool_radius,
                                f"the finishing pass would gouge a flank: {flank_cutter_problem(contact, tool_radius)}",
                                fix))
    over, where = largest_overcut(geometry, tool_radius, phi)
    budget = TWIST_SHARE * tol
    if over <= budget:
        return over
    w = geometry.mechanism.half_width(geometry.cylinder.inner_radius_mm)
    refuse_off_radial_axis(geometry, w, budget, phi)
    fit, cur = tool_radius, over  # the overcut is nearly proportional to w − r_c: secant steps to the budget
    for _ in range(4):
        fit = w - (w - fit) * 0.98 * budget / cur
        cur = largest_overcut(geometry, fit, phi)[0]
        if cur <= budget:
            break
    raise SpecError(Problem("manufacturing.tool_diameter_mm", 2 * tool_radius,
                            f"a radial end mill narrower than the roller cannot follow the flank's twist across the "
                            f"groove depth: finishing tangent to the flank on the groove bottom it would cut "
                            f"{over:.4f} mm past the flank at radius {where:.4g} mm (allowed {budget:.4g} mm, half "
                            "the tolerance)",
                            f"use an end mill of diameter at least {math.ceil(2 * fit * 1000) / 1000:g} mm (the groove "
                            f"is {2 * w:.6g} mm wide), or a coarser tolerance"))


def refuse_off_radial_axis(geometry: Any, w: float, budget: float, phi: np.ndarray) -> None:
    """An oscillating follower's roller axis is parallel to the radial line at 0°, swung aside by
    e = L·(1 − cos φ): not radial, so even a cutter of the groove's width on the pitch curve of the bottom cuts
    past the flanks higher up.  Refused (naming ``follower.arm_length_mm``) when that alone exceeds the budget."""
    over, where = largest_overcut(geometry, w, phi)
    if over <= budget:
        return
    raise SpecError(Problem("follower.arm_length_mm", getattr(geometry.mechanism, "arm_length_mm", None),
                            "the oscillating roller's axis swings aside from the cylinder's radial line, which a "
                            "radial end mill cannot follow across the groove depth: even a cutter of the groove's "
                            f"width would cut {over:.4f} mm past a flank at radius {where:.4g} mm (allowed "
                            f"{budget:.4g} mm, half the tolerance)",
                            "give a smaller swing, a shallower groove or a coarser tolerance (the 4-axis program "
                            f"needs a tolerance of at least {math.ceil(1000 * over / TWIST_SHARE) / 1000:g} mm)"))


def finishing_direction(flank: int, sense: int, climb: bool) -> int:
    """+1 to run a flank's finishing pass with increasing cam angle, −1 backwards, for the job's milling
    direction with M3.  The tool moves along +x relative to the part as the cam angle grows; seen from outside
    the cylinder the developed plane (x, z) is right-handed for a cw cam (σ = +1) and mirrored for ccw, and climb
    milling keeps the material on the travel's right: the −z flank for σ = +1 going forwards."""
    forwards_is_climb = flank * sense < 0
    return 1 if forwards_is_climb == climb else -1


def require_groove(geometry: Any, what: str, instead: str) -> None:
    """Refuse a rib where ``what`` (a function of the groove's) would take its flanks for a groove's walls: the
    caller chooses by ``[cylinder] feature`` and calls ``instead`` for a rib."""
    if geometry.cylinder.feature is Feature.RIB:
        raise ApiError(f"{what} is the groove's; a rib's is {instead}")
