"""Profile verification: coded findings, CAM-DAS conclusions and verdict.

Rules (``spec/profiles.md`` §13, ``spec/camdas-reference.md`` §1.6):

* ``UNDERCUT`` (error) — rollers: the pitch curve is convex with radius
  0 < ρ_p < R_r (tested on ρ_p, spec D10); flat faces: ρ < 0.
* ``CUSP`` (error) — the limit case: ρ_p = R_r (roller) or ρ = 0 (flat face)
  within :data:`CUSP_TOL_MM`, the profile has a sharp point.
* ``CONCAVE_RADIUS_BELOW_ROLLER`` — a concave stretch whose radius is smaller
  than the roller or than ``tool_radius_mm`` (whichever is larger).  For a true
  roller envelope the concave radius is |ρ_p| + R_r > R_r, so the roller part
  never fires (CAM-DAS's "|ρ| > R_f" rule only re-detects undercuts, D10); with
  a tool radius it names the stretches a cutter cannot finish (warning) and the
  largest tool that fits.
* ``PRESSURE_ANGLE_EXCEEDED`` (error) — |δ| above the limit (30° translating
  roller and translating cam, 35° oscillating roller; flat faces have none).
* ``FACE_LENGTH`` (info) — flat faces: the face length needed on each side.
* ``VELOCITY_/ACCELERATION_/JERK_DISCONTINUITY`` — from the motion program
  (:func:`camfab.design.motion_report.analyse_motion`).

Verdict: any error → ``unacceptable``; else a jerk (or allowed acceleration)
jump → ``not_for_high_speed``; else ``acceptable``.  Angles in findings are
degrees of cam angle (mm of travel for a translating cam); a range that wraps
through 360° has ``from_deg > to_deg``.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from enum import Enum
from typing import Any, Callable

import numpy as np

from .motion_report import Finding, MotionReport, analyse_motion, verdict_of
from .profile import CamGeometry, Contact, cross as _cross
from .rollers import OscillatingRollerContact
from .solvers import (_bracket_min, _bracket_root, _channel_solvers, _default_step, _ExtremaPlan, _extrema_steps,
                      _extremum_steps, _gather, _integrate_steps, _mapped, _sampling, _run)

__all__ = ["Code", "Finding", "Report", "check", "positive_ranges", "CUSP_TOL_MM", "DEFAULT_PRESSURE_LIMIT_DEG"]

#: a radius margin within this many mm of its limit is a cusp (not an undercut)
CUSP_TOL_MM = 1e-7
#: pressure-angle limits by follower motion (CAM-DAS, after Norton)
DEFAULT_PRESSURE_LIMIT_DEG = {"translating": 30.0, "oscillating": 35.0}
_PA_TOL_RAD = 1e-10


class Code(str, Enum):
    """Finding codes (stable strings, used in ``check --json``)."""

    UNDERCUT = "UNDERCUT"
    CUSP = "CUSP"
    CONCAVE_RADIUS_BELOW_ROLLER = "CONCAVE_RADIUS_BELOW_ROLLER"
    PRESSURE_ANGLE_EXCEEDED = "PRESSURE_ANGLE_EXCEEDED"
    FACE_LENGTH = "FACE_LENGTH"
    VELOCITY_DISCONTINUITY = "VELOCITY_DISCONTINUITY"
    ACCELERATION_DISCONTINUITY = "ACCELERATION_DISCONTINUITY"
    JERK_DISCONTINUITY = "JERK_DISCONTINUITY"


@dataclass(frozen=True)
class Report:
    """Result of :func:`check`: findings, verdict and the CAM-DAS conclusions.

    ``summary`` holds the geometry keys of ``check --json`` (design.md §6):
    ``pressure_angle_deg``, ``radius_of_curvature_mm``, ``face_length_mm``,
    ``base_radius_mm``, ``max_radius_mm``, ``area_mm2`` (None where they do not
    apply) plus ``initial_arm_angle_deg``.
    """

    name: str
    findings: tuple[Finding, ...]
    summary: dict[str, Any]
    motion: MotionReport | None = None
    x_unit: str = "deg"
    extra: dict[str, Any] = field(default_factory=dict)

    @property
    def verdict(self) -> str:
        return verdict_of(list(self.findings))

    def codes(self) -> set[str]:
        return {f.code for f in self.findings}

    def by_code(self, code: str | Code) -> list[Finding]:
        code = code.value if isinstance(code, Code) else code
        return [f for f in self.findings if f.code == code]

    def to_dict(self) -> dict[str, Any]:
        """The ``check --json`` object (JSON-ready: floats, str, None, lists, dicts)."""
        out: dict[str, Any] = {"name": self.name, "verdict": self.verdict}
        if self.motion is not None:
            m = self.motion.to_dict()
            out["peaks"], out["junctions"] = m["peaks"], m["junctions"]
        out.update(_plain(self.summary))
        out["x_unit"] = self.x_unit
        out["findings"] = [_plain(f.to_dict()) for f in self.findings]
        return out


def _plain(obj):
    if isinstance(obj, dict):
        return {k: _plain(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_plain(v) for v in obj]
    if isinstance(obj, (np.floating, np.integer)):
        return obj.item()
    return obj


# ---------------------------------------------------------------------------
def check(geometry: CamGeometry, *, pressure_angle_limit_deg: float | None = None,
          allow_acceleration_jump: bool = False, tool_radius_mm: float | None = None,
          face_margin_mm: float = 0.0, name: str = "cam", speed: float = 1.0) -> Report:
    """Verify a cam geometry.

    Parameters
    ----------
    geometry : CamGeometry
    pressure_angle_limit_deg : float, optional
        Limit on |δ| in degrees; default 30 (translating roller, translating
        cam) or 35 (oscillating roller).
    allow_acceleration_jump : bool
        Accept acceleration jumps (constant-width / constant-diameter cams).
    tool_radius_mm : float, optional
        Cutter radius: concave stretches tighter than it are reported.
    face_margin_mm : float
        Safety margin added to each required flat-face length (mm).
    name : str
        Cam name for the report.
    speed : float
        ω in rad/s (mm/s for a translating cam), for the motion peaks.

    Returns
    -------
    Report
    """
    findings: list[Finding] = []
    motion_report = None
    seen: list[Any] = []
    for c in geometry.profiles:
        if any(c.motion is m for m in seen) or not hasattr(c.motion, "junctions"):
            continue
        seen.append(c.motion)
        lift_unit = "deg" if getattr(c, "xi0", None) is not None else "mm"
        rep = analyse_motion(c.motion, name=name, speed=speed, lift_unit=lift_unit,
                             allow_acceleration_jump=allow_acceleration_jump)
        motion_report = motion_report or rep
        findings += rep.findings
    summary = _empty_summary()
    to_user = geometry.to_user
    # every quantity is planned as solver jobs; the jobs of all planners run together, so that
    # all refinements of one contact share one profile evaluation per round
    planners = []
    for k, c in enumerate(geometry.profiles):
        tag = f"profile {k + 1}: " if len(geometry.profiles) > 1 else ""
        planners.append(_curvature(c, tag, to_user, tool_radius_mm, summary))
        if c.kind == "roller":
            lim = pressure_angle_limit_deg
            if lim is None:
                lim = DEFAULT_PRESSURE_LIMIT_DEG["oscillating" if isinstance(c, OscillatingRollerContact)
                                                 else "translating"]
            planners.append(_pressure(c, tag, to_user, lim, summary))
        if c.has_face:
            planners.append(_face(c, tag, to_user, face_margin_mm, summary))
    planners.append(_extent(geometry, summary))
    for found in _schedule(planners):
        findings += found
    summary["initial_arm_angle_deg"] = geometry.initial_arm_angle_deg
    return Report(name, tuple(findings), summary, motion_report, geometry.x_unit)


# ---------------------------------------------------------------------------
# batched evaluation.  A planner is a generator that yields lists of jobs (contact, solver,
# extractor ProfileSample → values) and is sent the list of their results; it returns its
# findings.  _schedule runs the planners in lockstep and _Shared runs all their jobs together:
# the extremum (_Ext) and range (_Ranges) searches of one contact as one solver
# (:func:`_positive_ranges_multi`: one dense sampling, one solver step per round for all), and
# per round one evaluation per contact for every pending request.


class _Ext:
    """Job marker: the global extremum between breakpoints ``edges`` (as :func:`_extremum_steps`);
    the searches of one contact in a round are run as one solver (:func:`_extrema_steps`)."""

    __slots__ = ("edges", "maximize")

    def __init__(self, edges, maximize: bool = False):
        self.edges, self.maximize = np.asarray(edges, dtype=float), maximize


class _Ranges:
    """Job marker: the ranges where the extracted function is > 0 (as :func:`_positive_ranges_steps`
    with the default step); those of one contact and edges in a round run as one solver."""

    __slots__ = ("edges", "closed")

    def __init__(self, edges, closed: bool = True):
        self.edges, self.closed = np.asarray(edges, dtype=float), bool(closed)


def _stacked(exts):
    return lambda s: np.stack([np.asarray(e(s), dtype=float) for e in exts])


class _Shared:
    def run(self, jobs: list) -> list:
        # one solver per contact: its extremum and ranges searches (of the same edges) together
        per: dict[int, tuple[list[int], dict]] = {}
        for i, (c, gen, _) in enumerate(jobs):
            if isinstance(gen, _Ext):
                per.setdefault(id(c), ([], {}))[0].append(i)
            elif isinstance(gen, _Ranges):
                per.setdefault(id(c), ([], {}))[1].setdefault((gen.edges.tobytes(), gen.closed), []).append(i)
        if not per:
            return self._run(jobs)
        todo, owners = [], []
        for exts, rng in per.values():
            groups = list(rng.values())
            if not groups:
                groups = [[]]
            for g, idx in enumerate(groups):
                mine = exts if g == 0 else []
                c = jobs[(idx or mine)[0]][0]
                specs = [(jobs[i][1].edges, jobs[i][1].maximize) for i in mine]
                if idx:
                    first = jobs[idx[0]][1]
                    gen = _positive_ranges_multi(first.edges, first.closed, len(idx), specs)
                else:
                    gen = _extrema_steps(specs)
                todo.append((c, gen, _stacked([jobs[i][2] for i in idx + mine])))
                owners.append(idx + mine)
        plain = [i for i, (_, gen, _) in enumerate(jobs) if not isinstance(gen, (_Ext, _Ranges))]
        done = self._run([jobs[i] for i in plain] + todo)
        res: list = [None] * len(jobs)
        for i, r in zip(plain, done):
            res[i] = r
        for idx, r in zip(owners, done[len(plain):]):
            for i, ri in zip(idx, r):
                res[i] = ri
        return res

    def _run(self, jobs: list) -> list:
        res: list = [None] * len(jobs)
        req: dict[int, np.ndarray] = {}
        for i, (_, gen, _) in enumerate(jobs):
            try:
                req[i] = np.asarray(next(gen), dtype=float).ravel()
            except StopIteration as stop:
                res[i] = stop.value
        while req:
            vals = self._values(jobs, req)
            for i, v in vals.items():
                try:
                    req[i] = np.asarray(jobs[i][1].send(v), dtype=float).ravel()
                except StopIteration as stop:
                    res[i] = stop.value
                    del req[i]
        return res

    def _values(self, jobs, req) -> dict[int, np.ndarray]:
        """One evaluation per contact of all the pending requests (each extractor applied once)."""
        groups: dict[int, list[int]] = {}
        for i in req:
            groups.setdefault(id(jobs[i][0]), []).append(i)
        out: dict[int, np.ndarray] = {}
        for idx in groups.values():
            c = jobs[idx[0]][0]
            parts = [req[i] for i in idx]
            # every extractor reads a frame-independent quantity: the fixed-frame sample skips the rotation
            sample = c.evaluate_fixed(np.concatenate(parts) if len(parts) > 1 else parts[0])
            memo: dict = {}
            off = 0
            for i in idx:
                ext = jobs[i][2]
                if id(ext) not in memo:
                    memo[id(ext)] = ext(sample)
                out[i] = memo[id(ext)][..., off:off + req[i].size]
                off += req[i].size
        return out


def _schedule(planners: list) -> list:
    shared = _Shared()
    results: list = [None] * len(planners)
    cur: dict[int, list] = {}
    for i, p in enumerate(planners):
        try:
            cur[i] = next(p)
        except StopIteration as stop:
            results[i] = stop.value
    while cur:
        keys = list(cur)
        found = shared.run([job for i in keys for job in cur[i]])
        off = 0
        for i in keys:
            n = len(cur[i])
            try:
                cur[i] = planners[i].send(found[off:off + n])
            except StopIteration as stop:
                results[i] = stop.value
                del cur[i]
            off += n
    return results


def _kp(s):
    return s.curvature_pitch


def _rho(s):
    return s.rho


def _pa(s):
    return s.pressure_angle


def _face_pos(s):
    return s.face_position


def _radius(s):
    return np.hypot(s.point[:, 0], s.point[:, 1])


def _height(s):
    return s.point[:, 1]


def _green(s):
    return 0.5 * _cross(s.point, s.point_d1)


def _green_open(s):
    return s.point[:, 1] * s.point_d1[:, 0]


def _extent(geometry: CamGeometry, summary):
    """Planner: base and largest radius (closed cams) and the area, as
    :meth:`CamGeometry.radius_extremes` and :meth:`CamGeometry.area` compute them."""
    cls = type(geometry)
    plain = cls.radius_extremes is CamGeometry.radius_extremes and cls.area is CamGeometry.area and all(
        type(c).radius is Contact.radius for c in geometry.profiles)
    if not plain:
        if geometry.closed:
            summary["base_radius_mm"] = geometry.radius_extremes().min
            summary["max_radius_mm"] = max(geometry.radius_extremes(k).max for k in range(len(geometry.profiles)))
        summary["area_mm2"] = geometry.area()
        return []
    jobs = []
    c0 = geometry.profiles[0]
    if geometry.closed:
        jobs.append((c0, _Ext(c0.breakpoints), _radius if c0.closed else _height))
        jobs += [(c, _Ext(c.breakpoints, True), _radius if c.closed else _height)
                 for c in geometry.profiles]
    jobs.append((c0, _integrate_steps(c0.breakpoints, rtol=1e-11), _green if c0.closed else _green_open))
    res = yield jobs
    if geometry.closed:
        summary["base_radius_mm"] = res[0][1]
        summary["max_radius_mm"] = max(r[1] for r in res[1:-1])
    summary["area_mm2"] = abs(res[-1])
    return []


def _empty_summary() -> dict[str, Any]:
    return {"pressure_angle_deg": None, "radius_of_curvature_mm": None, "face_length_mm": None,
            "base_radius_mm": None, "max_radius_mm": None, "area_mm2": None, "dynamics": None}


def _where(to_user, x) -> float:
    return float(to_user(x))


def _span(to_user, lo, hi, unit) -> str:
    a, b = _where(to_user, lo), _where(to_user, hi)
    return f"at {a:.6g}{unit}" if abs(b - a) < 1e-9 else f"from {a:.6g}{unit} to {b:.6g}{unit}"


def _curvature(c: Contact, tag, to_user, tool, summary):
    """Planner: undercut, cusp and concave-radius findings (and the radius-of-curvature summary)."""
    out: list[Finding] = []
    edges, closed = c.breakpoints, c.closed
    unit = "°" if closed else " mm"
    if c.kind == "roller":
        rr = c.roller_radius
        lim = max(rr, tool or 0.0)

        def g(s):
            return np.where(s.curvature_pitch < 0, -lim * s.curvature - 1.0, -1.0)

        # the ranges are searched together with the extrema (used only if these call for them)
        jobs = [(c, _Ext(edges, True), _kp), (c, _Ext(edges), _kp)]
        if rr > 0:
            jobs.append((c, _Ranges(edges, closed), lambda s: rr * s.curvature_pitch - 1.0))
        if lim > 0:
            jobs.append((c, _Ranges(edges, closed), g))
        (xa, kmax), (xb, kmin), *found = yield jobs
        roc = {"min_convex": (1.0 / kmax - rr) if kmax > 0 else None,
               "min_concave": (1.0 / -kmin + rr) if kmin < 0 else None,
               "at_deg": _where(to_user, xa) if kmax > 0 else None,
               "at_min_concave_deg": _where(to_user, xb) if kmin < 0 else None,
               "pitch_min_convex": 1.0 / kmax if kmax > 0 else None, "max": None}
        _merge_roc(summary, roc)
        undercut = rr > 0 and kmax > 0 and rr - 1.0 / kmax > CUSP_TOL_MM
        concave = lim > 0 and kmin < 0 and 1.0 / -kmin + rr < lim
        if rr > 0 and not undercut:
            found.pop(0)
        if rr > 0 and kmax > 0:
            dev = rr - 1.0 / kmax  # > 0: undercut
            if undercut:
                for lo, hi, xw, gw in found.pop(0):
                    rp = rr / (1.0 + gw)
                    out.append(Finding(Code.UNDERCUT.value, "error", _where(to_user, lo), _where(to_user, hi), rp, rr,
                                       f"{tag}undercut {_span(to_user, lo, hi, unit)}: the pitch curve is convex with "
                                       f"radius down to {rp:.6g} mm (at {_where(to_user, xw):.6g}{unit}), smaller than "
                                       f"the roller ({rr:.6g} mm); the roller cannot follow the law there. Enlarge the "
                                       "base circle or use a smaller roller"))
            elif dev >= -CUSP_TOL_MM:
                out.append(_cusp(tag, to_user, xa, 1.0 / kmax, rr, unit, "the pitch-curve radius equals the roller radius"))
        if concave:
            fits = 1.0 / -kmin + rr
            for lo, hi, xw, gw in found.pop(0):
                out.append(Finding(Code.CONCAVE_RADIUS_BELOW_ROLLER.value, "warning", _where(to_user, lo),
                                   _where(to_user, hi), lim / (1.0 + gw), lim,
                                   f"{tag}concave stretch {_span(to_user, lo, hi, unit)} with radius down to "
                                   f"{fits:.6g} mm, tighter than the {lim:.6g} mm cutter; the largest tool radius "
                                   f"that fits is {fits:.6g} mm"))
        return out
    (xa, rmin), (xb, rmax), ranges = yield [(c, _Ext(edges), _rho),
                                            (c, _Ext(edges, True), _rho),
                                            (c, _Ranges(edges, closed), lambda s: -s.rho)]
    _merge_roc(summary, {"min_convex": rmin, "min_concave": None, "at_deg": _where(to_user, xa),
                         "at_min_concave_deg": None, "pitch_min_convex": None, "max": rmax})
    if rmin < -CUSP_TOL_MM:
        for lo, hi, xw, gw in ranges:
            out.append(Finding(Code.UNDERCUT.value, "error", _where(to_user, lo), _where(to_user, hi), -gw, 0.0,
                               f"{tag}undercut {_span(to_user, lo, hi, unit)}: the radius of curvature is negative "
                               f"(down to {-gw:.6g} mm at {_where(to_user, xw):.6g}{unit}); the profile crosses itself "
                               "between two cusps and the face cannot follow the law. Enlarge the base circle"))
    elif rmin <= CUSP_TOL_MM:
        out.append(_cusp(tag, to_user, xa, rmin, 0.0, unit, "the radius of curvature reaches 0"))
    return out


def _merge_roc(summary, roc):
    cur = summary["radius_of_curvature_mm"]
    if cur is None:
        summary["radius_of_curvature_mm"] = roc
        return
    for key, at in (("min_convex", "at_deg"), ("min_concave", "at_min_concave_deg"), ("pitch_min_convex", None)):
        if roc[key] is not None and (cur[key] is None or roc[key] < cur[key]):
            cur[key] = roc[key]
            if at:
                cur[at] = roc[at]
    if roc["max"] is not None and (cur["max"] is None or roc["max"] > cur["max"]):
        cur["max"] = roc["max"]


def _cusp(tag, to_user, x, value, limit, unit, why) -> Finding:
    a = _where(to_user, x)
    return Finding(Code.CUSP.value, "error", a, a, value, limit,
                   f"{tag}cusp at {a:.6g}{unit}: {why}, so the profile has a sharp point with very high contact "
                   "stress. Enlarge the base circle (or use a smaller roller)")


def _pressure(c: Contact, tag, to_user, lim_deg, summary):
    """Planner: pressure-angle findings and summary."""
    edges, unit = c.breakpoints, ("°" if c.closed else " mm")
    lim = math.radians(lim_deg)
    # the ranges beyond ± the limit are searched together with the extrema
    (xa, dmax), (xb, dmin), *found = yield [
        (c, _Ext(edges, True), _pa), (c, _Ext(edges), _pa),
        *[(c, _Ranges(edges, c.closed), lambda s, sign=sign: sign * s.pressure_angle - lim)
          for sign in (1.0, -1.0)]]
    cur = summary["pressure_angle_deg"]
    new = {"max": math.degrees(dmax), "min": math.degrees(dmin), "at_max_deg": _where(to_user, xa),
           "at_min_deg": _where(to_user, xb), "limit": lim_deg}
    if cur is None:
        summary["pressure_angle_deg"] = new
    else:
        if new["max"] > cur["max"]:
            cur["max"], cur["at_max_deg"] = new["max"], new["at_max_deg"]
        if new["min"] < cur["min"]:
            cur["min"], cur["at_min_deg"] = new["min"], new["at_min_deg"]
    out = []
    for sign, worst, ranges in zip((1.0, -1.0), (dmax, dmin), found):
        if sign * worst - lim <= _PA_TOL_RAD:
            continue
        for lo, hi, xw, gw in ranges:
            val = sign * math.degrees(gw + lim)
            out.append(Finding(Code.PRESSURE_ANGLE_EXCEEDED.value, "error", _where(to_user, lo), _where(to_user, hi),
                               val, sign * lim_deg,
                               f"{tag}pressure angle {val:.4g}° (at {_where(to_user, xw):.6g}{unit}) exceeds "
                               f"±{lim_deg:.4g}° {_span(to_user, lo, hi, unit)}: high side load, risk of jamming. "
                               "Enlarge the base circle, change the offset or the law, or use a larger roller"))
    return out


def _face(c: Contact, tag, to_user, margin, summary):
    """Planner: the face-length findings and summary."""
    edges = c.breakpoints
    (xa, pmin), (xb, pmax) = yield [(c, _Ext(edges), _face_pos), (c, _Ext(edges, True), _face_pos)]
    out = []
    a, b = _where(to_user, xa), _where(to_user, xb)
    if getattr(c, "xi0", None) is None:  # translating face: either side of the stem
        left, right = max(-pmin, 0.0) + margin, max(pmax, 0.0) + margin
        fl = {"left": left, "right": right, "min": pmin, "max": pmax}
        out.append(Finding(Code.FACE_LENGTH.value, "info", a, a, left, None,
                           f"{tag}the face must reach {left:.6g} mm to the left of the stem axis (contact furthest "
                           f"left at {a:.6g}°; margin {margin:g} mm included)"))
        out.append(Finding(Code.FACE_LENGTH.value, "info", b, b, right, None,
                           f"{tag}the face must reach {right:.6g} mm to the right of the stem axis (contact furthest "
                           f"right at {b:.6g}°; margin {margin:g} mm included)"))
    else:
        fl = {"left": None, "right": None, "min": pmin, "max": pmax}
        out.append(Finding(Code.FACE_LENGTH.value, "info", b, b, pmax + margin, None,
                           f"{tag}the face must be at least {pmax + margin:.6g} mm long from the vertex (contact "
                           f"between {pmin:.6g} mm at {a:.6g}° and {pmax:.6g} mm at {b:.6g}°; margin {margin:g} mm "
                           "included)" + ("; the contact passes behind the vertex" if pmin < 0 else "")))
    cur = summary["face_length_mm"]
    if cur is None:
        summary["face_length_mm"] = fl
    else:
        for k in fl:
            if fl[k] is not None:
                cur[k] = fl[k] if cur[k] is None else (min(cur[k], fl[k]) if k == "min" else max(cur[k], fl[k]))
    return out


# ---------------------------------------------------------------------------
def _merged_ranges(raw: list[list[float]], edges: np.ndarray, closed: bool, tol: float):
    """Ranges ``[from, to]`` (in order) merged where they meet at a breakpoint, joined across the period end
    of a closed curve, snapped to the period ends within ``tol``; yields ``(lo, hi, subs)`` with ``subs`` the
    breakpoint grids of the one or two (wrapping) pieces of each range."""
    per0, per1 = edges[0], edges[-1]
    merged: list[list[float]] = []
    for r in raw:
        if merged and abs(r[0] - merged[-1][1]) < tol:
            merged[-1][1] = r[1]
        else:
            merged.append(r)
    if closed and len(merged) > 1 and merged[0][0] - per0 < tol and per1 - merged[-1][1] < tol:
        last = merged.pop()
        merged[0][0] = last[0]
    for lo, hi in merged:
        lo = per0 if lo - per0 < tol else lo
        hi = per1 if per1 - hi < tol else hi
        parts = [(lo, hi)] if lo <= hi else [(lo, per1), (per0, hi)]
        yield lo, hi, [np.unique(np.r_[a, edges[(edges > a) & (edges < b)], b]) for a, b in parts]


def positive_ranges(g: Callable[[np.ndarray], np.ndarray], edges, *, closed: bool = True,
                    step: float | None = None) -> list[tuple[float, float, float, float]]:
    """Ranges where ``g > 0``, ends located by root refinement.

    Returns ``[(x_from, x_to, x_worst, g_worst), ...]``; ranges that meet at a
    breakpoint are merged, and for ``closed`` curves a range crossing the
    period end wraps (then ``x_from > x_to``).
    """
    return _run(g, _positive_ranges_steps(edges, closed=closed, step=step))


def _roots_of(xs_l, v_l, roots: dict):
    """Generator: refine (all at once) the sign changes of ``v > 0`` between adjacent samples
    of each interval that are not in ``roots`` yet (keyed by the sample pair); fills ``roots``."""
    A, FA, B, FB = [], [], [], []
    for xs, vv in zip(xs_l, v_l):
        pos = vv > 0
        for j in np.flatnonzero(pos[:-1] != pos[1:]):
            if (xs[j], xs[j + 1]) not in roots:
                A.append(xs[j]), FA.append(vv[j]), B.append(xs[j + 1]), FB.append(vv[j + 1])
    if A:
        r = yield from _bracket_root(np.array(A), np.array(FA), np.array(B), np.array(FB), xtol=1e-14, rtol=1e-15)
        roots.update({(a, b): float(x) for a, b, x in zip(A, B, r)})


def _positive_ranges_multi(edges, closed: bool, k: int, ext=()):
    """Generator: k :func:`_positive_ranges_steps` searches (default step) of k functions over
    the same ``edges`` and the :func:`_extremum_steps` searches ``ext`` (``(edges, maximize)``)
    of further functions, run as one: it yields parameter values and is sent a
    (k + len(ext), n) array, row j the j-th function at them (the ranges' first).  Every
    search gives exactly its own result (the solvers run one batch per search, see
    :func:`~.solvers._channel_solvers`).  Returns the k lists of ranges, then the extrema."""
    edges = np.asarray(edges, dtype=float)
    per0, per1 = edges[0], edges[-1]
    step = _default_step(per1 - per0)
    ivs, grid, starts = _sampling(edges, step)
    plan = _ExtremaPlan([(e, mx, None, k + i) for i, (e, mx) in enumerate(ext)], base=k)
    nrows = k + len(ext)
    if not ivs:
        return [[] for _ in range(k)] + ((yield from _extrema_steps(plan.specs, nrows=nrows)) if ext else [])
    if plan.grids and plan.grids[0] is grid:
        req, poff = plan.grids, 0
    else:
        req, poff = [grid, *plan.grids], grid.size
    Vall = np.asarray((yield np.concatenate(req) if len(req) > 1 else grid), dtype=float).reshape(nrows, -1)
    V = Vall[:k, :grid.size]
    nint = len(ivs)
    sizes = np.diff(np.r_[starts, grid.size])
    seg = np.repeat(np.arange(nint), sizes)
    inner = np.ones(grid.size - 1, dtype=bool)  # sample pairs inside one interval
    inner[starts[1:] - 1] = False
    # per search: refine each interval's largest sample (so that narrow bumps between samples are
    # seen), together with the roots of the sign changes already sampled
    mrows, info = [], []
    A, FA, B, FB, Jb = [], [], [], [], []
    for j in range(k):
        v = V[j]
        nan = np.isnan(v)
        w = np.where(nan, -np.inf, v)
        ok = np.flatnonzero(~np.logical_and.reduceat(nan, starts))
        q = np.flatnonzero(((v[:-1] > 0) != (v[1:] > 0)) & inner)
        A.append(grid[q]), FA.append(v[q]), B.append(grid[q + 1]), FB.append(v[q + 1]), Jb.append(np.full(q.size, j))
        if not ok.size:
            info.append(None)
            continue
        eq = np.flatnonzero(w == np.maximum.reduceat(w, starts)[seg])  # nanargmax per interval
        i = eq[np.searchsorted(eq, starts[ok])]
        il, ih = np.maximum(i - 1, starts[ok]), np.minimum(i + 1, starts[ok] + sizes[ok] - 1)
        lo, hi, f0 = grid[il], grid[ih], v[i]
        tol = np.maximum(1e-9 * (hi - lo), 16 * np.finfo(float).eps * np.maximum(1.0, np.abs(hi)))
        mrows.append((lo, _neg(v[il]), grid[i], _neg(f0), hi, _neg(v[ih]), tol, np.full(ok.size, j)))
        info.append((ok, lo, hi, f0, v[il], v[ih]))
    rootss: list[dict] = [{} for _ in range(k)]
    A, FA, B, FB, Jb = (np.concatenate(t) for t in (A, FA, B, FB, Jb))
    ecols = plan.prepare(Vall, poff) if ext else None
    if ecols is not None:
        mrows.append(ecols)
    mcols = [np.concatenate([r[q] for r in mrows]) for q in range(8)] if mrows else None
    vrow = np.r_[np.arange(k), plan.row].astype(np.intp)
    sgn = np.r_[np.full(k, -1.0), plan.sgn]
    # the maxima and the roots as two solvers in lockstep (each problem's steps are its own, so
    # the results are those of one solver); once the roots are in, the worst-value searches of
    # the ranges they give start alongside the maxima still being refined — speculatively: a
    # refined maximum changes the ranges only when it adds sign changes, and then (checked
    # below, the ranges recomputed with it) those searches are dropped and run again
    live: dict = {}
    if mrows:
        live["m"] = _channel_solvers(nrows, (mcols, vrow, sgn), None)
    if A.size:
        live["r"] = _channel_solvers(nrows, None, (A, FA, B, FB, Jb, vrow))
    res: dict = {"m": (None, None), "r": (None, None)}
    req: dict = {}
    for name in list(live):
        try:
            req[name] = np.asarray(next(live[name]), dtype=float).ravel()
        except StopIteration as stop:
            res[name] = stop.value
            del live[name]
    spec = None  # [specs, spans, generator, result, pending request]
    nofill: tuple = ([None] * k, [None] * k)
    while "m" in live or "r" in live:
        if spec is None and "r" not in live:
            if res["r"][1] is not None:
                for a, b, x, j in zip(A.tolist(), B.tolist(), res["r"][1].tolist(), Jb.tolist()):
                    rootss[j][(a, b)] = x
            s0, p0 = _range_specs(k, edges, closed, step, ivs, grid, starts, sizes, inner, V, nofill, rootss)
            spec = [s0, p0, None, [], None]
            if s0:
                spec[2], spec[3] = _extrema_steps(s0, nrows=nrows), None
                try:
                    req["s"] = np.asarray(next(spec[2]), dtype=float).ravel()
                    live["s"] = spec[2]
                except StopIteration as stop:
                    spec[3] = stop.value
        names = list(req)
        parts = [req[n] for n in names]
        Vr = np.asarray((yield np.concatenate(parts) if len(parts) > 1 else parts[0]), dtype=float)
        Vr = Vr.reshape(nrows, -1)
        off = 0
        for n in names:
            sz = req[n].size
            try:
                req[n] = np.asarray(live[n].send(Vr[:, off:off + sz]), dtype=float).ravel()
            except StopIteration as stop:
                del req[n], live[n]
                if n == "s":
                    spec[3] = stop.value
                else:
                    res[n] = stop.value
            off += sz
    if spec is not None and "s" in req:
        spec[4] = req["s"]
    mres, rr = res["m"][0], res["r"][1]
    if A.size:
        for a, b, x, j in zip(A.tolist(), B.tolist(), rr.tolist(), Jb.tolist()):
            rootss[j][(a, b)] = x
    ext_out = plan.finish(*(mres if mres is not None else (None, None)), mcols[7] if mrows else None) if ext else []
    # insert the refined maxima above their interval's samples; refine the sign changes they make
    xs_ls: list = [None] * k
    v_ls: list = [None] * k
    A, FA, B, FB, Jb = [], [], [], [], []
    for j in range(k):
        if info[j] is None:
            continue
        ok, lo, hi, f0, vl, vh = info[j]
        m = mcols[7] == j
        rx, rf = mres[0][m], mres[1][m]
        # a maximum is inserted only where it can change the sign changes: when its sign differs
        # from that of a sample beside it (else the sign-change pairs, so the roots and the
        # ranges, are those of the samples alone)
        p = -rf > 0
        matters = (p != (f0 > 0)) | (p != (vl > 0)) | (p != (vh > 0))
        for q in np.flatnonzero((-rf > f0) & (lo < rx) & (rx < hi) & matters):
            mm = ok[q]
            if xs_ls[j] is None:
                xs_ls[j] = {}
                v_ls[j] = {}
            xs = grid[starts[mm]:starts[mm] + sizes[mm]]
            vv = V[j, starts[mm]:starts[mm] + sizes[mm]]
            at = int(np.searchsorted(xs, rx[q]))
            xs = np.concatenate((xs[:at], rx[q:q + 1], xs[at:]))
            vv = np.concatenate((vv[:at], -rf[q:q + 1], vv[at:]))
            xs_ls[j][mm], v_ls[j][mm] = xs, vv
            pos = vv > 0
            for r in np.flatnonzero(pos[:-1] != pos[1:]):
                if (xs[r], xs[r + 1]) not in rootss[j]:
                    A.append(xs[r]), FA.append(vv[r]), B.append(xs[r + 1]), FB.append(vv[r + 1]), Jb.append(j)
    if A:
        if spec is not None and spec[2] is not None:  # new roots: the ranges may change
            spec[2].close()
            spec = None
        A, B, Jb = np.array(A), np.array(B), np.array(Jb, dtype=np.intp)
        _, rr = yield from _channel_solvers(nrows, None, (A, np.array(FA), B, np.array(FB), Jb, vrow))
        for a, b, x, j in zip(A.tolist(), B.tolist(), rr.tolist(), Jb.tolist()):
            rootss[j][(a, b)] = x
    if spec is not None and not any(xs_ls):
        specs, spans_l = spec[0], spec[1]  # the same samples and roots: the same ranges
    else:
        specs, spans_l = _range_specs(k, edges, closed, step, ivs, grid, starts, sizes, inner, V, (xs_ls, v_ls),
                                      rootss)
    if spec is not None and (specs is spec[0] or _same_specs(spec[0], spec[1], specs, spans_l)):
        # the speculative searches were of exactly these ranges: their results
        if spec[3] is None:
            g2, x = spec[2], spec[4]
            try:
                while True:
                    x = np.asarray(g2.send((yield x)), dtype=float).ravel()
            except StopIteration as stop:
                spec[3] = stop.value
        found = spec[3]
    else:
        if spec is not None and spec[2] is not None:
            spec[2].close()
        found = (yield from _extrema_steps(specs, nrows=nrows)) if specs else []
    out = []
    for spans in spans_l:
        res = []
        for lo, hi, q, m in spans:
            xw, gw = max(found[q:q + m], key=lambda t: t[1])
            res.append((float(lo), float(hi), float(xw), float(gw)))
        out.append(res)
    return out + ext_out


def _joined(xs_l):
    """The samples of consecutive intervals concatenated: ``(x, start index of each interval, mask
    of the adjacent pairs that lie in one interval)``."""
    xa = np.concatenate(xs_l)
    st = np.r_[0, np.cumsum([len(t) for t in xs_l])[:-1]]
    inn = np.ones(xa.size - 1, dtype=bool)
    inn[st[1:] - 1] = False
    return xa, st, inn


def _sign_ranges(ivs, xa, pos, st, inn, roots) -> list[list[float]]:
    """``[start, end]`` of every stretch where ``pos`` holds, per interval ``ivs[m] = (a, b, _)``
    of the concatenated samples ``xa`` (interval m from index ``st[m]``; ``inn`` marks the pairs
    inside one interval); ends at the refined ``roots`` of the sample pairs, or at a and b."""
    nint = len(ivs)
    anypos = np.logical_or.reduceat(pos, st)
    chg = np.flatnonzero((pos[:-1] != pos[1:]) & inn)
    cut = np.searchsorted(chg, st)
    raw: list[list[float]] = []
    for m in np.flatnonzero(anypos):
        a, b, _ = ivs[m]
        start = a if pos[st[m]] else None
        for q in chg[cut[m]:cut[m + 1] if m + 1 < nint else chg.size]:
            root = roots[(xa[q], xa[q + 1])]
            if pos[q + 1]:
                start = root
            else:
                raw.append([start, root])
                start = None
        if start is not None:
            raw.append([start, b])
    return raw


def _range_specs(k, edges, closed, step, ivs, grid, starts, sizes, inner, V, xs_ls, rootss):
    """The ranges of :func:`_positive_ranges_multi` from the samples (with the inserted maxima
    ``xs_ls``/``v_ls`` where any) and the refined roots: the worst-value searches (specs of
    :func:`~.solvers._extrema_steps`) and the spans ``(lo, hi, first search, searches)`` per function."""
    xs_ls, v_ls = xs_ls
    per0, per1 = edges[0], edges[-1]
    nint = len(ivs)
    specs, spans_l = [], []
    tol = 1e-9 * max(per1 - per0, 1.0)
    for j in range(k):
        spans, roots = [], rootss[j]
        if xs_ls[j]:  # the samples with the inserted maxima
            xs_l = [xs_ls[j].get(m, grid[starts[m]:starts[m] + sizes[m]]) for m in range(nint)]
            v_l = [v_ls[j].get(m, V[j, starts[m]:starts[m] + sizes[m]]) for m in range(nint)]
            xa, st, inn = _joined(xs_l)
            va = np.concatenate(v_l)
        else:
            xa, va, st, inn = grid, V[j], starts, inner
        raw = _sign_ranges(ivs, xa, va > 0, st, inn, roots)
        for lo, hi, subs in _merged_ranges(raw, edges, closed, tol):
            spans.append((lo, hi, len(specs), len(subs)))
            specs += [(sub, True, step, j) for sub in subs]
        spans_l.append(spans)
    return specs, spans_l


def _same_specs(specs0, spans0, specs, spans) -> bool:
    return spans0 == spans and len(specs0) == len(specs) and all(
        a[3] == b[3] and a[2] == b[2] and np.array_equal(a[0], b[0]) for a, b in zip(specs0, specs))


def _neg(y):
    y = np.asarray(y, dtype=float)
    return np.where(np.isnan(y), np.inf, -y)


def _positive_ranges_steps(edges, *, closed: bool = True, step: float | None = None):
    """Generator form of :func:`positive_ranges` (for :func:`~.solvers._run` / ``_gather``):
    one dense sampling, then every refinement batched (one call of g per round)."""
    edges = np.asarray(edges, dtype=float)
    per0, per1 = edges[0], edges[-1]
    step = step or _default_step(per1 - per0)
    ivs, grid, starts = _sampling(edges, step)
    if not ivs:
        return []
    v = np.asarray((yield grid), dtype=float)
    ends = np.r_[starts[1:], grid.size]
    xs_l = [grid[s:e] for s, e in zip(starts, ends)]
    v_l = [v[s:e] for s, e in zip(starts, ends)]
    # refine each interval's largest sample (so that narrow bumps between samples are seen)
    # together with the roots of the sign changes already sampled
    ok = [k for k, vv in enumerate(v_l) if not np.isnan(vv).all()]
    jobs = []
    if ok:
        i = np.array([int(np.nanargmax(v_l[k])) for k in ok])
        n = np.array([len(xs_l[k]) for k in ok])
        il, ih = np.maximum(i - 1, 0), np.minimum(i + 1, n - 1)
        pick = lambda idx: np.array([xs_l[k][j] for k, j in zip(ok, idx)])  # noqa: E731
        val = lambda idx: np.array([v_l[k][j] for k, j in zip(ok, idx)])  # noqa: E731
        lo, hi, f0 = pick(il), pick(ih), val(i)
        clean = lambda y: np.where(np.isnan(y), np.inf, -np.asarray(y, dtype=float))  # noqa: E731
        tol = np.maximum(1e-9 * (hi - lo), 16 * np.finfo(float).eps * np.maximum(1.0, np.abs(hi)))
        jobs.append(_mapped(_bracket_min(lo, clean(val(il)), pick(i), clean(f0), hi, clean(val(ih)), tol), clean))
    roots: dict[tuple[float, float], float] = {}
    jobs.append(_roots_of(xs_l, v_l, roots))
    done = yield from _gather(jobs)
    if ok:
        rx, rf = done[0]
        for m, k in enumerate(ok):
            if -rf[m] > f0[m] and lo[m] < rx[m] < hi[m]:
                j = int(np.searchsorted(xs_l[k], rx[m]))
                xs_l[k] = np.insert(xs_l[k], j, rx[m])
                v_l[k] = np.insert(v_l[k], j, -rf[m])
        yield from _roots_of(xs_l, v_l, roots)  # sign changes made by an inserted maximum
    xa, st, inn = _joined(xs_l)
    raw = _sign_ranges(ivs, xa, np.concatenate(v_l) > 0, st, inn, roots)
    tol = 1e-9 * max(per1 - per0, 1.0)
    # the worst value of every range, all searched at once
    spans, jobs = [], []
    for lo, hi, subs in _merged_ranges(raw, edges, closed, tol):
        spans.append((lo, hi, len(jobs), len(subs)))
        jobs += [_extremum_steps(sub, maximize=True, step=step) for sub in subs]
    found = yield from _gather(jobs)
    out = []
    for lo, hi, k, m in spans:
        xw, gw = max(found[k:k + m], key=lambda t: t[1])
        out.append((float(lo), float(hi), float(xw), float(gw)))
    return out
