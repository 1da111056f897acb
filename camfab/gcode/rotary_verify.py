"""``camfab verify`` of a cylindrical cam's 4-axis program: the back-plot on the cylinder against the exact groove.

The program is read back with :func:`~camfab.gcode.rotary_read.read_rotary` (X, A, Z; G93 inverse time).  A
straight move in X and A at a fixed Z is a straight line on the developed cylinder of the tool tip's radius
r = Z (x = −σ·r·A in radians, z = X; σ = +1 cw), so each cutting move is sampled there (every 0.1 mm, at least
4 points) and measured against the exact developed curves of :mod:`camfab.design.cylindrical`:

* **deviation** — every centre-pass point within ``tol`` of the exact pitch curve on its radius; every
  finishing-pass point (its lead-in and lead-out, the first and last move of the pass, left out) within ``tol``
  of its flank's cutter path there: the axis of a radial cutter whose exact section on that cylinder (the
  stretched circle of :mod:`camfab.design.roller_section`, h = r_c) touches the flank its comment names
  (``DEVIATION``, the worst line of each pass);
* **gouge** — the cutter's axis is radial and reaches from its tip to the outer radius: on six radii from the tip
  to the outer surface, its exact section there (centred on the axis's developed point) must stay in the groove:
  its point facing each flank no more than ``tol`` past that flank's exact section
  (:func:`~camfab.gcode.rotary_finish.cutter_penetration`; ``GOUGE``; every cutting move, plunges and leads
  included);
* **coverage** — the centre pass on the groove bottom and each flank's finishing pass run the whole 360° track:
  4096 probes of each exact path (cam angles 0 to the period) no farther than ``tol`` from the moves
  (``COVERAGE``); **depth** — nothing below the groove bottom (``TOO_DEEP``), the finishing passes and the last
  centre pass on it (``FINISH_DEPTH``), no plunge deeper than one step-down below what was cut before
  (``STEP_DOWN``);
* **feeds, spindle, rapids, end** — inverse-time moves each with F, their time giving the job's cutting feed on
  the tool tip's cylinder and the plunges the plunge feed (``FEED_MISSING``, ``FEED_OUT_OF_RANGE``); the spindle
  on and turning M3 while cutting (``SPINDLE_OFF``, ``SPINDLE_DIRECTION``); rapids sideways only at the safe
  radius and never into the cylinder (``RAPID_BELOW_SAFE``, ``RAPID_INTO_STOCK``); the tool out of the cylinder
  at the end (``RETRACT_MISSING``); each flank's pass in the job's milling direction (``DIRECTION``).

The report has the plate verify's keys (:class:`~camfab.gcode.verify.VerifyReport`) and a ``rotary`` mapping.
"""
from __future__ import annotations

import dataclasses
import math
from typing import Any

import numpy as np

from ..records import dataclass
from ..results import Finding, IssueCode
from .model import Job
from .rotary_finish import cutter_penetration, finishing_direction, flank_path, pitch_distance, require_groove
from .rotary_read import RotaryMove, RotaryReadError, read_rotary
from .verify import VerifyReport

__all__ = ["RotaryVerifyReport", "verify_rotary_program", "RotaryContext", "floor_findings",
           "step_down_findings", "Samples", "sample_moves", "worst_per_pass",
           "feed_findings", "rapid_findings", "is_lateral", "from_cutter_path", "read_or_refused"]

#: sampling step of a move on its developed cylinder (mm), the coverage probes per target, and the radii (fractions
#: from the tip to the outer surface) on which the radial cutter's section is checked
_STEP = 0.1
_PROBES = 4096
_RADII = np.linspace(0.0, 1.0, 6)


@dataclass(frozen=True)
class RotaryVerifyReport(VerifyReport):
    """:class:`VerifyReport` with the ``rotary`` summary (added to the JSON; no key renamed)."""

    rotary: dict = dataclasses.field(default_factory=dict)

    def to_dict(self) -> dict:
        return super().to_dict() | {"rotary": self.rotary}


@dataclass(frozen=True)
class Samples:
    """Points of the cutting moves: X, A (deg), Z, the index of their move, on the tip's developed cylinder."""

    X: np.ndarray
    A: np.ndarray
    Z: np.ndarray
    move: np.ndarray

    def developed(self, sigma: float, r: np.ndarray | None = None) -> np.ndarray:
        """(x, z) on the developed cylinder of radius r (default: the tip's) of the radial axis through them."""
        r = self.Z if r is None else r
        return np.stack([-sigma * r * np.radians(self.A), self.X], axis=1)

    def subset(self, keep: np.ndarray) -> Samples:
        return Samples(self.X[keep], self.A[keep], self.Z[keep], self.move[keep])


def sample_moves(moves: list[RotaryMove]) -> Samples:
    """Every feed move sampled every ``_STEP`` mm of its length on the tip's cylinder (ends included)."""
    out: list[np.ndarray] = []
    for i, m in enumerate(moves):
        if m.kind != "feed":
            continue
        a, b = np.array(m.start), np.array(m.end)
        r = 0.5 * (a[2] + b[2])
        length = math.hypot(b[0] - a[0], r * math.radians(b[1] - a[1]))
        # a plunge: its end only (the radial axis above it is checked up to the outer radius from there)
        t = (np.linspace(0.0, 1.0, max(4, min(4096, math.ceil(length / _STEP))) + 1) if length > 0
             else np.ones(1))[:, None]
        out.append(np.hstack([a + t * (b - a), np.full((len(t), 1), i)]))
    arr = np.vstack(out) if out else np.zeros((0, 4))
    return Samples(arr[:, 0], arr[:, 1], arr[:, 2], arr[:, 3].astype(int))


def _by_radius(geometry: Any, smp: Samples, sigma: float, r: np.ndarray | None = None) -> np.ndarray:
    """Signed distance of each sample's axis from the exact pitch curve on radius r (default the tip's)."""
    r = smp.Z if r is None else r
    s = np.zeros(len(r))
    pts = smp.developed(sigma, r)
    for rho in np.unique(np.round(r, 9)):
        k = np.isclose(r, rho, rtol=0.0, atol=1e-9)
        s[k] = pitch_distance(geometry, float(rho), pts[k])[0]
    return s


def worst_per_pass(values: np.ndarray, smp: Samples, moves: list[RotaryMove], limit: float, code: IssueCode,
                    what: str) -> list[Finding]:
    """One finding per pass (label) whose worst value exceeds ``limit``, at the worst move's line."""
    out = []
    labels = np.array([moves[i].label for i in smp.move])
    for label in dict.fromkeys(labels):
        k = np.flatnonzero((labels == label) & (values > limit))
        if len(k):
            j = k[np.argmax(values[k])]
            m = moves[smp.move[j]]
            out.append(Finding.at_line(code, f"{label or 'unlabelled moves'}: {what} {values[j]:.4f} mm "
                                       f"(tolerance {limit:g} mm) at A{m.end[1]:g}", m.line))
    return out


class RotaryContext:
    """What every check needs: the design's geometry, the job, the tolerance and the read program."""

    def __init__(self, geometry: Any, job: Job, tol: float, moves: list[RotaryMove]):
        self.g, self.job, self.tol, self.moves = geometry, job, tol, moves
        cyl = geometry.cylinder
        self.r_b, self.r_o, self.r_c = cyl.inner_radius_mm, cyl.outer_radius_mm, job.tool_radius_mm
        self.sigma = float(geometry.mechanism.sense)
        cut = sample_moves(moves)
        self.cut = cut.subset(np.less(cut.Z, self.r_o - 1e-9))
        labels = np.array([moves[i].label for i in self.cut.move], dtype=object)
        self.centre = self.cut.subset(np.array([lb.startswith("centre") for lb in labels], dtype=bool))
        self.finish = self.cut.subset(np.array([lb.startswith("finishing") for lb in labels], dtype=bool))

    def w(self, r: np.ndarray) -> np.ndarray:
        return np.vectorize(self.g.mechanism.half_width)(r)

    def flank_of(self, label: str) -> int:
        return 1 if "+z" in label else -1 if "-z" in label else 0


def is_lateral(m: RotaryMove) -> bool:
    return m.start[0] != m.end[0] or m.start[1] != m.end[1]


def _deviation(ctx: RotaryContext) -> tuple[float | None, float | None, list[Finding], int]:
    """The centre passes against the pitch curve and the finishing passes (leads left out) against their flank
    paths, on the tip's radius; (centre max, finishing max, findings, finishing moves measured)."""
    mv, out = ctx.moves, []
    c = ctx.centre.subset(np.array([is_lateral(mv[i]) for i in ctx.centre.move], dtype=bool))
    dev_c = np.abs(_by_radius(ctx.g, c, ctx.sigma)) if len(c.Z) else np.zeros(0)
    out += worst_per_pass(dev_c, c, mv, ctx.tol, IssueCode.DEVIATION, "off the exact pitch curve by")
    keep = np.zeros(len(ctx.finish.Z), dtype=bool)
    for label in dict.fromkeys(mv[i].label for i in ctx.finish.move):
        idx = sorted({int(i) for i in ctx.finish.move if mv[i].label == label and is_lateral(mv[i])})
        inner = set(idx[1:-1])  # the first and last lateral moves are the lead-in and the lead-out
        keep |= np.array([int(i) in inner for i in ctx.finish.move], dtype=bool)
    f = ctx.finish.subset(keep)
    side = np.array([ctx.flank_of(mv[i].label) for i in f.move], dtype=float)
    dev_f = np.full(len(f.Z), np.inf)
    for fl in (1, -1):
        k = side == fl
        if np.any(k):
            dev_f[k] = from_cutter_path(ctx, f.subset(k), fl)
    out += worst_per_pass(dev_f, f, mv, ctx.tol, IssueCode.DEVIATION, "off its flank's exact cutter path by")
    best = lambda v: float(np.max(v)) if len(v) else None  # noqa: E731
    return best(dev_c), best(dev_f), out, len(set(f.move.tolist()))


def from_cutter_path(ctx: RotaryContext, smp: Samples, flank: int) -> np.ndarray:
    """Distance (mm) of finishing samples from their flank's exact cutter path on each tip radius
    (:func:`~camfab.gcode.rotary_finish.flank_path`): on the path the cutter's exact section touches the flank, so
    the distance is, to first order, how far the section through the sample reaches past or falls short of it."""
    out = np.zeros(len(smp.Z))
    pts = smp.developed(ctx.sigma)
    for rho in np.unique(np.round(smp.Z, 9)):
        k = np.isclose(smp.Z, rho, rtol=0.0, atol=1e-9)
        out[k] = np.abs(cutter_penetration(ctx.g, float(rho), flank, ctx.r_c, pts[k]))
    return out


def _penetration(ctx: RotaryContext, smp: Samples, r: np.ndarray) -> np.ndarray:
    """How far (mm) the exact section on radius r of the radial cutter through each sample reaches past either
    flank (:func:`~camfab.gcode.rotary_finish.cutter_penetration`)."""
    pen = np.full(len(r), -np.inf)
    pts = smp.developed(ctx.sigma, r)
    for rho in np.unique(np.round(r, 9)):
        k = np.isclose(r, rho, rtol=0.0, atol=1e-9)
        for fl in (1, -1):
            pen[k] = np.maximum(pen[k], cutter_penetration(ctx.g, float(rho), fl, ctx.r_c, pts[k]))
    return pen


def _gouge(ctx: RotaryContext) -> tuple[float, dict | None, list[Finding]]:
    """The radial cutter's section on six radii from its tip to the outer surface inside the groove."""
    smp = ctx.cut
    worst, at = -math.inf, None
    pen_all = np.full(len(smp.Z), -np.inf)
    for frac in _RADII:
        rho = smp.Z + frac * (ctx.r_o - smp.Z)
        pen = _penetration(ctx, smp, rho)
        pen_all = np.maximum(pen_all, pen)
        if len(pen) and float(pen.max()) > worst:
            j = int(np.argmax(pen))
            worst = float(pen[j])
            at = {"x": float(smp.X[j]), "y": 0.0, "z": float(smp.Z[j]), "a_deg": float(smp.A[j]),
                  "radius_mm": float(rho[j]), "line": ctx.moves[smp.move[j]].line, "penetration_mm": worst}
    found = worst_per_pass(pen_all, smp, ctx.moves, ctx.tol, IssueCode.GOUGE, "the cutter cuts past a flank by")
    return worst, (at if found else None), found


def _gap(probes: np.ndarray, smp: Samples, moves: list[RotaryMove], sigma: float, r: float, span: float) -> float:
    """Largest distance (mm) from the probes (developed on radius r, x in [0, span)) to the moves of ``smp``."""
    from scipy.spatial import cKDTree

    if not len(smp.Z):
        return math.inf
    ids = np.unique(smp.move)
    a = np.array([moves[i].start for i in ids])
    b = np.array([moves[i].end for i in ids])
    seg_a = np.stack([-sigma * r * np.radians(a[:, 1]), a[:, 0]], axis=1)
    seg_b = np.stack([-sigma * r * np.radians(b[:, 1]), b[:, 0]], axis=1)
    shift = np.floor(seg_a[:, 0] / span)[:, None] * np.array([span, 0.0])
    seg_a, seg_b = seg_a - shift, seg_b - shift
    copies = [np.array([k * span, 0.0]) for k in (-1, 0, 1)]
    A = np.vstack([seg_a + c for c in copies])
    B = np.vstack([seg_b + c for c in copies])
    t = np.linspace(0.0, 1.0, 33)[:, None, None]
    pts = (A + t * (B - A)).reshape(-1, 2)
    seg_of = np.tile(np.arange(len(A)), len(t))
    _, near = cKDTree(pts).query(probes, k=min(6, len(pts)))
    cand = seg_of[np.atleast_2d(near.T).T]
    d = B[cand] - A[cand]
    u = np.clip(np.sum((probes[:, None] - A[cand]) * d, axis=-1) / np.maximum(np.sum(d * d, axis=-1), 1e-300), 0, 1)
    dist = np.hypot(*(probes[:, None] - A[cand] - u[..., None] * d).transpose(2, 0, 1))
    return float(dist.min(axis=1).max())


def _coverage(ctx: RotaryContext) -> tuple[float, list[Finding]]:
    """The centre pass on the groove bottom and each flank's finishing pass over the whole track."""
    period = float(ctx.g.period)
    phi = np.linspace(0.0, period, _PROBES, endpoint=False)
    span = ctx.r_b * period
    on_bottom = lambda s: s.subset(np.abs(s.Z - ctx.r_b) <= ctx.tol)  # noqa: E731
    targets = [("the centre pass on the groove bottom", ctx.g.at_radius(ctx.r_b).pitch(phi)[0], on_bottom(ctx.centre))]
    fin = on_bottom(ctx.finish)
    for f, name in ((1, "+z"), (-1, "-z")):
        k = np.array([ctx.flank_of(ctx.moves[i].label) == f for i in fin.move], dtype=bool)
        targets.append((f"the {name} flank's finishing pass", flank_path(ctx.g, ctx.r_b, f, ctx.r_c, phi),
                        fin.subset(k)))
    worst, out = 0.0, []
    for what, probes, smp in targets:
        probes = probes - np.floor(probes[:, 0] / span)[:, None] * np.array([span, 0.0])
        gap = _gap(probes, smp, ctx.moves, ctx.sigma, ctx.r_b, span)
        worst = max(worst, gap)
        if gap > ctx.tol:
            out.append(Finding.at_line(IssueCode.COVERAGE, f"{what} leaves the exact track up to "
                                       f"{'the whole of it' if math.isinf(gap) else f'{gap:.4f} mm'} uncut "
                                       f"(tolerance {ctx.tol:g} mm)", None))
    return worst, out


def floor_findings(ctx: RotaryContext, floor: str) -> list[Finding]:
    """Nothing cut below the ``floor`` radius ``ctx.r_b`` (named: the groove bottom, the rib's root), every
    finishing pass on it."""
    out, tol, mv = [], ctx.tol, ctx.moves
    if len(ctx.cut.Z) and float(ctx.cut.Z.min()) < ctx.r_b - tol:
        j = int(np.argmin(ctx.cut.Z))
        out.append(Finding.at_line(IssueCode.TOO_DEEP, f"cuts to radius Z{ctx.cut.Z[j]:g}, below {floor} "
                                   f"({ctx.r_b:g} mm)", mv[ctx.cut.move[j]].line))
    off = np.abs(ctx.finish.Z - ctx.r_b) > tol
    if off.any():
        out.append(Finding.at_line(IssueCode.FINISH_DEPTH, f"a finishing pass runs at Z{ctx.finish.Z[off][0]:g}, not "
                                   f"on {floor} ({ctx.r_b:g} mm)", mv[ctx.finish.move[off][0]].line))
    return out


def step_down_findings(ctx: RotaryContext) -> list[Finding]:
    """No feed plunging deeper than the job's step-down below what was cut before."""
    out, tol, deepest = [], ctx.tol, ctx.r_o
    for m in ctx.moves:
        if m.kind == "feed" and m.end[2] < deepest:
            if m.end[2] < deepest - ctx.job.step_down_mm - tol:
                out.append(Finding.at_line(IssueCode.STEP_DOWN, f"plunges {deepest - m.end[2]:.4g} mm below what was "
                                           f"cut before (step-down {ctx.job.step_down_mm:g} mm)", m.line))
            deepest = m.end[2]
    return out


def _depth(ctx: RotaryContext) -> list[Finding]:
    """Nothing below the groove bottom, the finishing passes and a centre pass on it, step-downs kept."""
    out = floor_findings(ctx, "the groove bottom")
    if not (np.abs(ctx.centre.Z - ctx.r_b) <= ctx.tol).any():
        out.append(Finding.at_line(IssueCode.FINISH_DEPTH, f"no centre pass on the groove bottom ({ctx.r_b:g} mm)",
                                   None))
    return out + step_down_findings(ctx)


def feed_findings(ctx: RotaryContext) -> list[Finding]:
    """Inverse-time moves at the cutting feed on the tip's cylinder, plunges at the plunge feed, spindle on M3."""
    out, job = [], ctx.job
    for m in ctx.moves:
        if m.kind != "feed" or min(m.start[2], m.end[2]) >= ctx.r_o:
            continue
        if m.spindle_dir == 0 or m.spindle_rpm <= 0:
            out.append(Finding.at_line(IssueCode.SPINDLE_OFF, "cuts with the spindle off", m.line))
        elif m.spindle_dir < 0:
            out.append(Finding.at_line(IssueCode.SPINDLE_DIRECTION, "cuts with M4: camfab's end mills cut with M3",
                                       m.line))
        if not m.feed:
            out.append(Finding.at_line(IssueCode.FEED_MISSING, "a cutting move without a feed", m.line))
            continue
        r = 0.5 * (m.start[2] + m.end[2])
        length = math.hypot(m.end[0] - m.start[0], r * math.radians(m.end[1] - m.start[1]), m.end[2] - m.start[2])
        if is_lateral(m) and not m.inverse_time:
            out.append(Finding.at_line(IssueCode.FEED_OUT_OF_RANGE, "a move turning A in G94: its feed mixes mm and "
                                       "degrees; camfab writes them in inverse time (G93)", m.line))
            continue
        speed = length * m.feed if m.inverse_time else m.feed
        want = job.feed_mm_min if is_lateral(m) else job.plunge_feed_mm_min
        if length > 1e-6 and abs(speed - want) > 0.01 * want + 0.1:
            out.append(Finding.at_line(IssueCode.FEED_OUT_OF_RANGE, f"runs at {speed:.1f} mm/min on the tool tip's "
                                       f"cylinder, not the job's {want:.1f} mm/min", m.line))
    return out


def rapid_findings(ctx: RotaryContext) -> list[Finding]:
    out = []
    safe = ctx.r_o + ctx.job.safe_z_mm
    for m in ctx.moves:
        if m.kind != "rapid":
            continue
        if is_lateral(m) and min(m.start[2], m.end[2]) < safe - ctx.tol:
            out.append(Finding.at_line(IssueCode.RAPID_BELOW_SAFE, f"a rapid turns or moves along the axis at "
                                       f"Z{min(m.start[2], m.end[2]):g}, below the safe radius {safe:g}", m.line))
        if m.end[2] < ctx.r_o:
            out.append(Finding.at_line(IssueCode.RAPID_INTO_STOCK, f"a rapid down to Z{m.end[2]:g}, into the cylinder "
                                       f"(outer radius {ctx.r_o:g})", m.line))
    if ctx.moves and ctx.moves[-1].end[2] < ctx.r_o:
        out.append(Finding.at_line(IssueCode.RETRACT_MISSING, "the program ends with the tool in the groove",
                                   ctx.moves[-1].line))
    return out


def _directions(ctx: RotaryContext) -> list[Finding]:
    """Each flank's pass in the job's milling direction (:func:`~camfab.gcode.rotary_finish.finishing_direction`)."""
    out, climb = [], ctx.job.direction == "climb"
    for label in dict.fromkeys(ctx.moves[i].label for i in ctx.finish.move):
        f = ctx.flank_of(label)
        turn = sum(m.end[1] - m.start[1] for m in ctx.moves if m.label == label and m.kind == "feed")
        if f and turn and np.sign(turn) != -ctx.sigma * finishing_direction(f, int(ctx.sigma), climb):
            line = next(m.line for m in ctx.moves if m.label == label)
            out.append(Finding.at_line(IssueCode.DIRECTION, f"{label}: not {ctx.job.direction} milling with M3",
                                       line))
    return out


def _refused(message: str, line: int | None, tol: float) -> RotaryVerifyReport:
    return RotaryVerifyReport(None, False, None, (Finding.at_line(IssueCode.PARSE_ERROR, message, line),), tol)


def read_or_refused(program: str | bytes, tol: float) -> list[RotaryMove] | RotaryVerifyReport:
    """The program's moves (:func:`~camfab.gcode.rotary_read.read_rotary`), or the report refusing it
    (``PARSE_ERROR``: not text, or a line the back-plot cannot follow)."""
    try:
        text = program.decode("utf-8") if isinstance(program, bytes) else program
        return read_rotary(text)
    except UnicodeDecodeError as e:
        return _refused(f"not a text file: {e}", None, tol)
    except RotaryReadError as e:
        return _refused(str(e), e.line, tol)


def verify_rotary_program(program: str | bytes, geometry: Any, job: Job, *, tol: float) -> RotaryVerifyReport:
    """``camfab verify`` of a grooved cylindrical cam's 4-axis program (module notes); ``job`` cut to the
    groove's depth (:func:`~camfab.gcode.rotary.cylinder_job`).  A rib's program is verified by
    :func:`~camfab.gcode.rib_verify.verify_rib_program` (a rib here: ApiError)."""
    require_groove(geometry, "verify_rotary_program", "camfab.gcode.rib_verify.verify_rib_program")
    moves = read_or_refused(program, tol)
    if isinstance(moves, RotaryVerifyReport):
        return moves
    ctx = RotaryContext(geometry, job, tol, moves)
    problems: list[Finding] = []
    if not len(ctx.cut.Z):
        problems.append(Finding.at_line(IssueCode.NO_CUTTING_MOVES, "no cutting move below the outer radius", None))
    if not len(ctx.finish.Z):
        problems.append(Finding.at_line(IssueCode.NO_FINISH_PASS, "no finishing pass (comments 'finishing pass "
                                        "+z/-z flank')", None))
    dev_c, dev_f, found, n_fin = _deviation(ctx)
    pen, gouge_at, gouges = _gouge(ctx)
    gap, uncovered = _coverage(ctx)
    problems += found + gouges + uncovered + _depth(ctx) + feed_findings(ctx) + rapid_findings(ctx) + _directions(ctx)
    devs = [d for d in (dev_c, dev_f) if d is not None]
    summary = {"centre_max_deviation_mm": dev_c, "finishing_max_deviation_mm": dev_f,
               "max_penetration_mm": pen if math.isfinite(pen) else None,
               "groove_bottom_radius_mm": ctx.r_b, "outer_radius_mm": ctx.r_o,
               "deepest_tip_radius_mm": float(ctx.cut.Z.min()) if len(ctx.cut.Z) else None,
               "centre_levels": sorted({round(float(z), 6) for z in ctx.centre.Z}, reverse=True),
               "finishing_passes": len({ctx.moves[i].label for i in ctx.finish.move})}
    notes = ("4-axis program: back-plotted on the developed cylinder of each tool-tip radius (X, A, Z; G93)",
             "not checked on the 4-axis program: the tool number and length offset, the coolant, the spindle "
             "speed and the modal state")
    return RotaryVerifyReport(max(devs) if devs else None, bool(gouges), gouge_at, tuple(problems), tol,
                              gap if math.isfinite(gap) else None, n_fin, notes, summary)
