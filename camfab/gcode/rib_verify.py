"""``camfab verify`` of a rib's 4-axis program (:mod:`camfab.gcode.rib_program`): the back-plot on the cylinder
against the exact rib.

Read back and sampled as the groove's program (:mod:`camfab.gcode.rotary_verify`: X, A, Z, G93; each cutting
move a straight line on the developed cylinder of the tool tip's radius r = Z, x = −σ·r·A), then measured:

* **deviation** — every finishing-pass point (leads left out) within ``tol`` of its rib flank's exact cutter path
  on the root (:func:`~camfab.gcode.rotary_finish.flank_path`, the cutter outside the flank), and above the root,
  on the radii of the gouge check, its cutter's section within ``tol`` of the rib flank either way (material left
  on the rib is an error too: the rollers clear it by half the backlash) (``DEVIATION``);
* **gouge** — on six radii from each cutting point's tip to the rib's top, the radial cutter's exact section there
  (the stretched circle) no more than ``tol`` past the rib flank on the point's side (the flank the cutter's axis
  lies farther outside of; a point inside the rib gouges whichever side it picks) (``GOUGE``; every cutting move,
  roughing, finishing, plunges and leads);
* **cleared region** — on a grid of (θ, z) over the root cylinder (θ from 0 to the period, z from 0 to the
  length), every point farther than the clearance (twice the tolerance) outside the rib lies inside the exact
  section of the cutter at some point of a move on the root radius (``COVERAGE``, with the uncovered area);
* **depth** — nothing below the root (``TOO_DEEP``), the finishing passes on it (``FINISH_DEPTH``), no plunge
  deeper than one step-down below what was cut before (``STEP_DOWN``);
* **feeds, spindle, rapids, end** — as the groove's; **direction** — each finishing pass and each roughing pass in
  the job's milling direction (:func:`~camfab.gcode.rib_program.rib_direction`,
  :func:`~camfab.gcode.rib_program.roughing_direction`; ``DIRECTION``).
"""
from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..results import Finding, IssueCode
from .model import Job
from .rib_program import rib_direction, roughing_direction
from .rotary_finish import cutter_contact
from .rotary_read import RotaryMove
from .rotary_verify import (
    RotaryContext,
    RotaryVerifyReport,
    Samples,
    feed_findings,
    floor_findings,
    from_cutter_path,
    is_lateral,
    rapid_findings,
    read_or_refused,
    step_down_findings,
    worst_per_pass,
)

__all__ = ["verify_rib_program", "rib_penetration", "uncovered_points"]

#: radii (fractions from the tip to the rib's top) of the gouge check, the grid's largest number of points and its
#: spacing when that allows (mm), and the spacing of the points along the moves for the coverage
_RADII = np.linspace(0.0, 1.0, 6)
_GRID_POINTS = 400_000
_GRID_STEP = 0.3
_ALONG = 0.1
_COARSE = 2048


class _Flank:
    """A rib flank on the developed cylinder r for the signed distance of points from it (+ outside the rib):
    ``_COARSE`` samples over a period and a quarter either side; a point within ``bound`` of a sample gets the
    nearest sample refined by Gauss–Newton steps on the flank's parameter, a farther one +inf when it lies beyond
    the flank (the flank's z at its developed x: the flank is a graph over x), else −inf."""

    def __init__(self, geometry: Any, r: float, flank: int):
        from scipy.spatial import cKDTree

        period = float(geometry.period)
        self.c, self.flank, self.span = geometry.at_radius(r, flank), flank, r * period
        self.t = np.linspace(-0.25, 1.25, _COARSE + 1) * period
        self.h = float(self.t[1] - self.t[0])
        self.P = self.c.evaluate(self.t).point
        self.tree = cKDTree(self.P)
        order = np.argsort(self.P[:, 0])
        self.graph = self.P[order, 0], self.P[order, 1]

    def distance(self, pts: np.ndarray, bound: float) -> tuple[np.ndarray, np.ndarray]:
        """Signed distance (mm) of developed points (m, 2) and the unit normal at the nearest point (nan: far)."""
        q = pts - np.floor(pts[:, 0] / self.span)[:, None] * np.array([self.span, 0.0])
        dist, k = self.tree.query(q, distance_upper_bound=bound)
        near = np.isfinite(dist)
        d, n = np.empty(len(q)), np.full((len(q), 2), np.nan)
        outside = self.flank * (q[:, 1] - np.interp(q[:, 0], *self.graph)) > 0
        d[~near] = np.where(outside[~near], np.inf, -np.inf)
        if np.any(near):
            qn, t = q[near], self.t[k[near]]
            for _ in range(4):
                s = self.c.evaluate(t)
                t = np.clip(t + np.sum((qn - s.point) * s.point_d1, axis=1) / np.sum(s.point_d1 ** 2, axis=1),
                            t - 2 * self.h, t + 2 * self.h)
            s = self.c.evaluate(t)
            d[near], n[near] = np.sum((qn - s.point) * s.normal, axis=1), s.normal
        return d, n


#: the flanks by (geometry, radius, flank); kept small
_FLANKS: dict[tuple[int, float, int], tuple[Any, _Flank]] = {}


def _flank(geometry: Any, r: float, flank: int) -> _Flank:
    key = (id(geometry), round(float(r), 9), int(flank))
    hit = _FLANKS.get(key)
    if hit is None or hit[0] is not geometry:
        if len(_FLANKS) > 64:
            _FLANKS.clear()
        hit = _FLANKS[key] = (geometry, _Flank(geometry, float(r), int(flank)))
    return hit[1]


def rib_penetration(geometry: Any, r: float, r_c: float, axis: np.ndarray) -> np.ndarray:
    """How far (mm, > 0 into the rib) the exact section on radius ``r`` of a radial cutter of radius ``r_c`` whose
    axis meets that cylinder at the developed points ``axis`` (m, 2) reaches past the rib flank on its side (the
    flank the axis lies farther outside of); −inf for axes farther outside the rib than the section reaches
    (``r·asin(r_c/r)``, its half-length) and 0.5 mm, +inf inside it that far."""
    axis = np.asarray(axis, dtype=float).reshape(-1, 2)
    up, down = _flank(geometry, r, 1), _flank(geometry, r, -1)
    bound = r * math.asin(min(r_c / r, 1.0)) + 0.5
    d_up, n_up = up.distance(axis, bound)
    d_dn, n_dn = down.distance(axis, bound)
    side = d_up >= d_dn
    d = np.where(side, d_up, d_dn)
    out = -d
    near = np.isfinite(d)
    if np.any(near):
        s = side[near]
        tip = axis[near] + cutter_contact(r, r_c, np.where(s[:, None], n_up[near], n_dn[near]))
        reach = np.empty(len(tip))
        reach[s] = up.distance(tip[s], bound)[0]
        reach[~s] = down.distance(tip[~s], bound)[0]
        out[near] = -reach
    return out


def _penetrations(ctx: RotaryContext) -> np.ndarray:
    """:func:`rib_penetration` of every cutting sample on the radii ``_RADII`` from its tip to the rib's top:
    (len(_RADII), n)."""
    smp = ctx.cut
    out = np.full((len(_RADII), len(smp.Z)), -np.inf)
    for i, frac in enumerate(_RADII):
        rho = smp.Z + frac * (ctx.r_o - smp.Z)
        pts = smp.developed(ctx.sigma, rho)
        for r in np.unique(np.round(rho, 9)):
            k = np.isclose(rho, r, rtol=0.0, atol=1e-9)
            out[i, k] = rib_penetration(ctx.g, float(r), ctx.r_c, pts[k])
    return out


def _gouge(ctx: RotaryContext, pens: np.ndarray) -> tuple[float, dict | None, list[Finding]]:
    """The cutter's exact section on every radius from its tip to the rib's top outside the rib."""
    smp = ctx.cut
    if not len(smp.Z):
        return -math.inf, None, []
    i, j = np.unravel_index(int(np.argmax(pens)), pens.shape)
    worst = float(pens[i, j])
    at = {"x": float(smp.X[j]), "y": 0.0, "z": float(smp.Z[j]), "a_deg": float(smp.A[j]),
          "radius_mm": float(smp.Z[j] + _RADII[i] * (ctx.r_o - smp.Z[j])), "line": ctx.moves[smp.move[j]].line,
          "penetration_mm": worst}
    found = worst_per_pass(pens.max(axis=0), smp, ctx.moves, ctx.tol, IssueCode.GOUGE,
                           "the cutter cuts into the rib by")
    return worst, (at if found else None), found


def _finishing_samples(ctx: RotaryContext, smp: Samples) -> np.ndarray:
    """Which samples of ``smp`` belong to a finishing pass, its first and last lateral moves (the leads) left out."""
    mv = ctx.moves
    keep = np.zeros(len(smp.Z), dtype=bool)
    for label in dict.fromkeys(mv[i].label for i in smp.move if mv[i].label.startswith("finishing")):
        idx = sorted({int(i) for i in smp.move if mv[i].label == label and is_lateral(mv[i])})
        keep |= np.isin(smp.move, idx[1:-1])
    return keep


def _finish_deviation(ctx: RotaryContext, pens: np.ndarray) -> tuple[float | None, list[Finding], int]:
    """The finishing passes (leads left out) against the exact cutter path of the flank their comment names on
    the tip's radius, and, above it up to the rib's top, the cutter's section within ``tol`` of the rib flank
    either way (past it, or short of it: material left on the rib)."""
    mv = ctx.moves
    f = ctx.finish.subset(_finishing_samples(ctx, ctx.finish))
    side = np.array([ctx.flank_of(mv[i].label) for i in f.move], dtype=float)
    dev = np.full(len(f.Z), np.inf)
    for fl in (1, -1):
        k = side == fl
        if np.any(k):
            dev[k] = from_cutter_path(ctx, f.subset(k), fl)
    found = worst_per_pass(dev, f, mv, ctx.tol, IssueCode.DEVIATION, "off its rib flank's exact cutter path by")
    up = _finishing_samples(ctx, ctx.cut)
    above = np.abs(pens[1:, up]).max(axis=0) if np.any(up) else np.zeros(0)
    found += worst_per_pass(above, ctx.cut.subset(up), mv, ctx.tol, IssueCode.DEVIATION,
                            "strays from the rib flank above the root (past it or short of it) by")
    worst = max([float(np.max(v)) for v in (dev, above) if len(v)], default=None)
    return worst, found, len(set(f.move.tolist()))


def _dense(moves: list[RotaryMove], ids: np.ndarray, sigma: float, r: float) -> np.ndarray:
    """Points every ``_ALONG`` mm along the moves ``ids``, developed on radius r: (n, 2)."""
    out = []
    for i in ids:
        a, b = np.array(moves[i].start), np.array(moves[i].end)
        pa = np.array([-sigma * r * math.radians(a[1]), a[0]])
        pb = np.array([-sigma * r * math.radians(b[1]), b[0]])
        n = max(1, math.ceil(float(np.hypot(*(pb - pa))) / _ALONG))
        out.append(pa + np.linspace(0.0, 1.0, n + 1)[:, None] * (pb - pa))
    return np.vstack(out) if out else np.zeros((0, 2))


def uncovered_points(geometry: Any, dense: np.ndarray, r_c: float, clearance: float) -> tuple[np.ndarray, float, int]:
    """The points of a (θ, z) grid over the root cylinder (developed (x, z), x in [0, span), z in [0, length])
    farther than ``clearance`` outside the rib that no cutter section centred on the ``dense`` points (developed on
    the root radius) reaches; with the area of one grid cell (mm²) and the number of points that must be cut."""
    from scipy.spatial import cKDTree

    r = geometry.cylinder.inner_radius_mm
    span, length = r * float(geometry.period), geometry.cylinder.length_mm
    step = max(_GRID_STEP, math.sqrt(span * length / _GRID_POINTS))
    nx, nz = max(2, math.ceil(span / step)), max(2, math.ceil(length / step) + 1)
    gx, gz = np.meshgrid(np.arange(nx) * span / nx, np.linspace(0.0, length, nz), indexing="ij")
    Q = np.stack([gx.ravel(), gz.ravel()], axis=1)
    d = np.maximum(_flank(geometry, r, 1).distance(Q, 2.0 * step + clearance)[0],
                   _flank(geometry, r, -1).distance(Q, 2.0 * step + clearance)[0])
    Q = Q[d > clearance]
    if not len(dense):
        return Q, span / nx * length / (nz - 1), len(Q)
    P = dense - np.floor(dense[:, 0] / span)[:, None] * np.array([span, 0.0])
    P = np.vstack([P + np.array([k * span, 0.0]) for k in (-1, 0, 1)])
    tree = cKDTree(P)
    d, _ = tree.query(Q, distance_upper_bound=r_c)
    rest = Q[~np.isfinite(d)]
    left = np.ones(len(rest), dtype=bool)
    reach = r * math.asin(min(r_c / r, 1.0))
    for j, near in enumerate(tree.query_ball_point(rest, reach)):  # the exact section: (r·sin(dx/r))² + dz² ≤ r_c²
        if near:
            dv = P[near] - rest[j]
            left[j] = not np.any((r * np.sin(dv[:, 0] / r)) ** 2 + dv[:, 1] ** 2 <= r_c * r_c)
    return rest[left], span / nx * length / (nz - 1), len(Q)


def _coverage(ctx: RotaryContext) -> tuple[float, dict, list[Finding]]:
    """The cleared region (module notes): the root outside the rib and the clearance reached by the cutter."""
    from scipy.spatial import cKDTree

    on_root = [i for i, m in enumerate(ctx.moves) if m.kind == "feed" and max(abs(m.start[2] - ctx.r_b),
                                                                                abs(m.end[2] - ctx.r_b)) <= ctx.tol]
    dense = _dense(ctx.moves, np.array(on_root, dtype=int), ctx.sigma, ctx.r_b)
    left, cell, total = uncovered_points(ctx.g, dense, ctx.r_c, 2.0 * ctx.tol)
    info = {"grid_points": total, "uncovered_points": len(left), "uncovered_area_mm2": len(left) * cell}
    if not len(left):
        return 0.0, info, []
    gap = math.inf if not len(dense) else float(np.max(cKDTree(dense).query(left)[0]) - ctx.r_c)
    x, z = left[0]
    return gap, info, [Finding.at_line(IssueCode.COVERAGE, f"the root outside the rib is left uncut over about "
                                       f"{len(left) * cell:.3g} mm² ({len(left)} of {total} grid points; the first at "
                                       f"cam angle {math.degrees(x / ctx.r_b):.4g}°, z = {z:.4g} mm)", None)]


def _depth(ctx: RotaryContext) -> list[Finding]:
    """Nothing below the root, the finishing passes on it, step-downs kept."""
    return floor_findings(ctx, "the rib's root") + step_down_findings(ctx)


def _directions(ctx: RotaryContext) -> list[Finding]:
    """Each finishing and roughing pass in the job's milling direction."""
    out, climb, sense = [], ctx.job.direction == "climb", int(ctx.sigma)
    for label in dict.fromkeys(m.label for m in ctx.moves if m.kind == "feed"):
        f = ctx.flank_of(label)
        rule = rib_direction if label.startswith("finishing") else roughing_direction
        turn = sum(m.end[1] - m.start[1] for m in ctx.moves if m.label == label and m.kind == "feed")
        if f and turn and label[:9] in ("finishing", "roughing ") and np.sign(turn) != -ctx.sigma * rule(f, sense,
                                                                                                          climb):
            line = next(m.line for m in ctx.moves if m.label == label)
            out.append(Finding.at_line(IssueCode.DIRECTION, f"{label}: not {ctx.job.direction} milling with M3",
                                       line))
    return out


def verify_rib_program(program: str | bytes, geometry: Any, job: Job, *, tol: float) -> RotaryVerifyReport:
    """``camfab verify`` of a rib's 4-axis program (module notes); ``job`` cut to the rib's height
    (:func:`~camfab.gcode.rotary.cylinder_job`)."""
    moves = read_or_refused(program, tol)
    if isinstance(moves, RotaryVerifyReport):
        return moves
    ctx = RotaryContext(geometry, job, tol, moves)
    problems: list[Finding] = []
    if not len(ctx.cut.Z):
        problems.append(Finding.at_line(IssueCode.NO_CUTTING_MOVES, "no cutting move below the rib's top", None))
    if not len(ctx.finish.Z):
        problems.append(Finding.at_line(IssueCode.NO_FINISH_PASS, "no finishing pass (comments 'finishing pass "
                                        "+z/-z rib flank')", None))
    pens = _penetrations(ctx)
    dev, found, n_fin = _finish_deviation(ctx, pens)
    pen, gouge_at, gouges = _gouge(ctx, pens)
    gap, cover, uncovered = _coverage(ctx)
    problems += found + gouges + uncovered + _depth(ctx) + feed_findings(ctx) + rapid_findings(ctx) + _directions(ctx)
    rough = [m for m in moves if m.label.startswith("roughing")]
    summary = {"feature": "rib", "finishing_max_deviation_mm": dev,
               "max_penetration_mm": pen if math.isfinite(pen) else None,
               "root_radius_mm": ctx.r_b, "top_radius_mm": ctx.r_o,
               "deepest_tip_radius_mm": float(ctx.cut.Z.min()) if len(ctx.cut.Z) else None,
               "roughing_levels": sorted({round(m.end[2], 6) for m in rough if m.kind == "feed"}, reverse=True),
               "roughing_passes": len({m.label for m in rough}),
               "finishing_passes": len({ctx.moves[i].label for i in ctx.finish.move}), "coverage": cover}
    notes = ("4-axis program of a rib: back-plotted on the developed cylinder of each tool-tip radius (X, A, Z; G93); "
             "the root outside the rib measured on a (θ, z) grid",
             "not checked on the 4-axis program: the tool number and length offset, the coolant, the spindle "
             "speed and the modal state")
    return RotaryVerifyReport(dev, bool(gouges), gouge_at, tuple(problems), tol, gap if math.isfinite(gap) else None,
                              n_fin, notes, summary)
