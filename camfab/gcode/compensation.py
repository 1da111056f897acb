"""Cutter radius compensation (G41/G42) simulated the way a controller executes it.

A program written with cutter compensation carries the finished **part** contour; the controller moves the
tool centre a tool radius ``r`` to the left (G41) or right (G42) of the direction of travel.
:func:`simulate_compensation` turns back-plotted moves (:class:`camfab.gcode.parse.Move`) into the
**tool-centre** moves the machine would make, so they can be verified like a tool-centre program.  The
behaviour follows LinuxCNC.  Fanuc (type B) differs in the shape of the ramp-on move and goes round outside
corners by extended offset lines instead of arcs; either way the tool touches the part only at the corner
point, so what is cut is the same:

* **offsets** - a line shifts by ``r`` along its normal; an arc keeps its centre and its radius changes by
  ``-r`` when the tool is on the centre's side (G41 on a G3 arc, G42 on a G2 arc) and by ``+r`` otherwise.
  An arc whose offset radius would be ``<= 0`` cannot be cut (``COMP_ARC_RADIUS``: "arc radius smaller
  than tool radius under G41/G42"); the simulated tool bridges it with a straight move.
* **corners** between consecutive compensated moves, at the programmed corner point ``P``: tangent joins
  need nothing; at a *convex* (outside) corner the tool rolls around ``P`` on an arc of radius ``r``; at
  a *concave* (inside) corner both offset moves are trimmed at their intersection.  When they do not
  intersect within the moves (a notch narrower than the tool, a move shorter than the trimming needs)
  ``COMP_CORNER`` is reported and the simulated tool goes straight from one offset move to the next -
  which then shows as a gouge.
* **entry** - the first move with X/Y motion after G41/G42 (G40 before) ramps compensation on.  It must be
  a straight move (G0/G1) longer than ``r`` (``COMP_ENTRY``).  As LinuxCNC does, the tool goes from its
  (uncompensated) position to the point at distance ``r`` from the programmed end ``P`` where its path
  is tangent to the circle of radius ``r`` about ``P`` (the cutter's edge then just touches ``P``), and
  from there joins the next move like at any corner.  A too short entry is simulated ending
  perpendicular to its end point.
* **exit** - the first move with X/Y motion after G40 goes straight (or along its arc, as a spiral) from
  the compensated position to its programmed end point.  It must be a straight move at least the tool
  diameter long, as programmed (``COMP_EXIT``).  Moves with Z motion only keep the tool where it is.
  Switching G41 <-> G42 without G40 between is reported (``COMP_SIDE_CHANGE``) and treated as an exit
  plus a new entry.

Everything stays in mm and the XY plane (G17); Z of each move is interpolated along it.  Offsets and tangents
of all moves are computed at once; the corner joins, which depend on each other, run in one pass.
"""
from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Literal

import numpy as np

from camfab.errors import InputError
from camfab.gcode.parse import Move
from camfab.geom2d import TWO_PI, arc_sweep
from camfab.records import dataclass, field, replace
from camfab.results import Finding, IssueCode

__all__ = ["CompensatedPath", "simulate_compensation", "move_lengths"]

#: offset moves whose ends are closer than this (mm) join without a corner move
JOIN_EPS_MM = 1e-9
#: relative slack on the parameter range of a move when trimming at a concave corner
_T_EPS = 1e-9


@dataclass(frozen=True)
class CompRun:
    """One stretch of the program under G41/G42: ``side`` and the first/last program line."""

    side: str
    first_line: int
    last_line: int
    entry_line: int | None


@dataclass(frozen=True)
class CompensatedPath:
    """Result of :func:`simulate_compensation`.

    Attributes
    ----------
    moves : tuple of Move
        The tool-centre moves, in order.  Each keeps the line, label, feed, spindle and ``comp`` of the
        program move it comes from (corner arcs and bridges: the move they lead into).
    source : ndarray of int
        Index into the input moves of the move each output move comes from.
    kind : tuple of str
        Per output move: ``"move"`` (not compensated, as programmed), ``"offset"`` (a compensated move,
        offset and possibly trimmed), ``"entry"``, ``"exit"``, ``"corner"`` (rolling arc about a convex
        corner), ``"bridge"`` (straight move where the offset moves could not be joined), ``"z"`` (Z-only
        move under or right after compensation, at the compensated position).
    run : ndarray of int
        Index into ``runs`` of the compensated stretch each output move belongs to (its exit included),
        ``-1`` outside.
    runs : tuple of CompRun
    problems : tuple of Finding
        The compensation findings (``COMP_*``), each with its program line.
    radius : float
        The compensation radius used, mm.
    corners : dict
        Counts: ``rolling`` (convex corner arcs), ``trimmed`` (concave corners), ``failed``.
    """

    moves: tuple
    source: np.ndarray
    kind: tuple
    run: np.ndarray
    runs: tuple
    problems: tuple
    radius: float
    corners: dict = field(default_factory=dict)

    def lengths(self) -> np.ndarray:
        """XY length of every output move, mm."""
        return move_lengths(self.moves)


def move_lengths(moves: Sequence[Move]) -> np.ndarray:
    """XY length of each move in mm (arcs along the arc, spirals by their mean radius; NaN ends give 0)."""
    out = np.zeros(len(moves))
    for i, m in enumerate(moves):
        if m.kind == "arc":
            out[i] = abs(m.sweep) * 0.5 * (m.radius_start + m.radius_end)
        else:
            d = math.hypot(m.end[0] - m.start[0], m.end[1] - m.start[1])
            out[i] = d if math.isfinite(d) else 0.0
    return out



# --------------------------------------------------------------------------------------------------
# pieces: one offset move whose ends can still be trimmed
def _rot(v):
    return np.array([-v[1], v[0]])


def _cross(a, b) -> float:
    return float(a[0] * b[1] - a[1] * b[0])


class _Piece:
    """An offset line or arc (a spiral when its radii differ), parameter ``t`` in [0, 1] over the whole
    offset move; ``t0``/``t1`` are where it is trimmed."""

    __slots__ = ("arc", "src", "a", "b", "c", "a0", "sw", "r0", "r1", "z0", "z1", "t0", "t1", "tan_in",
                 "tan_out", "p_start", "p_end", "kind", "exact")

    def __init__(self, src, kind, *, a=None, b=None, c=None, a0=0.0, sw=0.0, r0=0.0, r1=0.0, z0=math.nan,
                 z1=math.nan, tan_in=None, tan_out=None, p_start=None, p_end=None, exact=True):
        self.src, self.kind, self.arc = src, kind, c is not None
        self.a, self.b, self.c = a, b, c
        self.a0, self.sw, self.r0, self.r1 = a0, sw, r0, r1
        self.z0, self.z1, self.t0, self.t1 = z0, z1, 0.0, 1.0
        self.tan_in, self.tan_out = tan_in, tan_out
        self.p_start, self.p_end = p_start, p_end
        self.exact = exact  # ends at distance r from the programmed end points (corners can be rolled)

    def point(self, t: float) -> np.ndarray:
        if not self.arc:
            return self.a + t * (self.b - self.a)
        rr = self.r0 + (self.r1 - self.r0) * t
        ang = self.a0 + self.sw * t
        return np.array([self.c[0] + rr * math.cos(ang), self.c[1] + rr * math.sin(ang)])

    def z(self, t: float) -> float:
        return self.z0 + (self.z1 - self.z0) * t

    def param(self, x: np.ndarray) -> float:
        """Parameter of the point of the (infinite) line / circle nearest ``x``."""
        if not self.arc:
            ab = self.b - self.a
            L2 = float(ab @ ab)
            return float((x - self.a) @ ab) / L2 if L2 > 0 else 0.0
        phi = math.atan2(x[1] - self.c[1], x[0] - self.c[0])
        asw = abs(self.sw)
        rel = (phi - self.a0) % TWO_PI if self.sw > 0 else (self.a0 - phi) % TWO_PI
        if rel > asw + 0.5 * (TWO_PI - asw):  # just before the start
            rel -= TWO_PI
        return rel / asw if asw > 0 else 0.0

    def length(self) -> float:
        if not self.arc:
            return float(np.hypot(*(self.b - self.a)))
        return abs(self.sw) * 0.5 * (self.r0 + self.r1)

    def to_move(self, m: Move, kind: str | None = None) -> Move:
        s = self.point(self.t0)
        e = self.point(self.t1)
        start = (float(s[0]), float(s[1]), self.z(self.t0))
        end = (float(e[0]), float(e[1]), self.z(self.t1))
        if not self.arc:
            mk = kind or ("rapid" if m.kind == "rapid" else "line")
            return replace(m, kind=mk, start=start, end=end, center=None, clockwise=None, sweep=0.0,
                           radius_start=math.nan, radius_end=math.nan)
        rr0 = self.r0 + (self.r1 - self.r0) * self.t0
        rr1 = self.r0 + (self.r1 - self.r0) * self.t1
        return replace(m, kind="arc", start=start, end=end, center=(float(self.c[0]), float(self.c[1])),
                       clockwise=self.sw < 0, sweep=self.sw * (self.t1 - self.t0), radius_start=rr0,
                       radius_end=rr1)


def _line_piece(src, kind, a, b, z0, z1, p_start=None, p_end=None, exact=True):
    a, b = np.asarray(a, float), np.asarray(b, float)
    d = b - a
    L = float(np.hypot(*d))
    t = d / L if L > 0 else np.array([1.0, 0.0])
    return _Piece(src, kind, a=a, b=b, z0=z0, z1=z1, tan_in=t, tan_out=t, p_start=p_start, p_end=p_end,
                  exact=exact)



# --------------------------------------------------------------------------------------------------
# intersections of pieces (as infinite lines / full circles)
def _ll(a1, d1, a2, d2):
    den = _cross(d1, d2)
    scale = float(np.hypot(*d1) * np.hypot(*d2))
    if scale == 0 or abs(den) <= 1e-15 * scale:
        return []
    s = _cross(a2 - a1, d2) / den
    return [a1 + s * d1]


def _lc(a, d, c, R):
    f = a - c
    A = float(d @ d)
    B = 2.0 * float(f @ d)
    C = float(f @ f) - R * R
    disc = B * B - 4 * A * C
    if A == 0:
        return []
    if disc < 0:
        if disc > -1e-12 * B * B:
            disc = 0.0
        else:
            return []
    sq = math.sqrt(disc)
    return [a + ((-B + sq) / (2 * A)) * d, a + ((-B - sq) / (2 * A)) * d]


def _cc(c1, R1, c2, R2):
    dv = c2 - c1
    d = float(np.hypot(*dv))
    if d == 0:
        return []
    x = (d * d + R1 * R1 - R2 * R2) / (2 * d)
    h2 = R1 * R1 - x * x
    if h2 < 0:
        if h2 > -1e-12 * R1 * R1:
            h2 = 0.0
        else:
            return []
    h = math.sqrt(h2)
    u = dv / d
    base = c1 + x * u
    return [base + h * _rot(u), base - h * _rot(u)]


def _intersect(p: _Piece, q: _Piece, corner: np.ndarray):
    """The intersection of ``p`` (near its end) and ``q`` (near its start) nearest the corner, as
    ``(point, t_p, t_q)``, or None."""
    if not p.arc and not q.arc:
        cands = _ll(p.a, p.b - p.a, q.a, q.b - q.a)
    elif not p.arc:
        cands = _lc(p.a, p.b - p.a, q.c, q.r0)
    elif not q.arc:
        cands = _lc(q.a, q.b - q.a, p.c, p.r1)
    else:
        cands = _cc(p.c, p.r1, q.c, q.r0)
    best = None
    for x in cands:
        tp, tq = p.param(x), q.param(x)
        ep = _T_EPS + JOIN_EPS_MM / max(p.length(), 1e-300)
        eq = _T_EPS + JOIN_EPS_MM / max(q.length(), 1e-300)
        if p.t0 - ep <= tp <= p.t1 + ep and q.t0 - eq <= tq <= q.t1 + eq:
            d = float(np.hypot(*(x - corner)))
            if best is None or d < best[0]:
                best = (d, x, min(max(tp, p.t0), p.t1), min(max(tq, q.t0), q.t1))
    return None if best is None else best[1:]



# --------------------------------------------------------------------------------------------------
# the simulation
def _has_xy(m: Move) -> bool:
    """An arc, or a move to a known X/Y from an unknown one or from farther than :data:`JOIN_EPS_MM`."""
    s, e = m.start, m.end
    if m.kind == "arc" or not (math.isfinite(e[0]) and math.isfinite(e[1])):
        return m.kind == "arc"
    known = math.isfinite(s[0]) and math.isfinite(s[1])
    return not known or math.hypot(e[0] - s[0], e[1] - s[1]) > JOIN_EPS_MM


class _Sim:
    def __init__(self, moves, r, swap, join_tol) -> None:
        self.m, self.r, self.swap, self.join_tol = moves, float(r), swap, join_tol
        self.out: list[Move] = []
        self.src: list[int] = []
        self.kind: list[str] = []
        self.run: list[int] = []
        self.runs: list[CompRun] = []
        self.problems: list[Finding] = []
        self.corners = {"rolling": 0, "trimmed": 0, "failed": 0}
        self.tool: tuple[float, float] | None = None  # tool XY where it differs from the programmed one
        self.last_run = -1

    def report(self, code: IssueCode, message: str, line: int | None) -> None:
        self.problems.append(Finding.at_line(code, message, line))

    def emit(self, mv: Move, src: int, kind: str, run: int) -> None:
        self.out.append(mv)
        self.src.append(src)
        self.kind.append(kind)
        self.run.append(run)

    # -- moves outside compensation ----------------------------------------------------------------
    def plain(self, i: int, run: int = -1) -> None:
        m = self.m[i]
        if self.tool is None:
            self.emit(m, i, "move", run)
            return
        if run < 0:
            run = self.last_run
        tx, ty = self.tool
        start = (tx, ty, m.start[2])
        if not _has_xy(m):
            self.emit(replace(m, start=start, end=(tx, ty, m.end[2])), i, "z", run)
            return
        self._check_exit(m)
        if m.kind == "arc":
            cx, cy = m.center
            rs = math.hypot(tx - cx, ty - cy)
            sweep = arc_sweep((tx, ty), m.end[:2], m.center, bool(m.clockwise)) if rs > 0 else m.sweep
            mv = replace(m, start=start, sweep=sweep, radius_start=rs)
        else:
            mv = replace(m, start=start)
        self.emit(mv, i, "exit", run)
        self.tool = None

    def _check_exit(self, m: Move) -> None:
        """The move that ramps compensation off must be a straight move at least a tool diameter long."""
        if m.comp != "G40":
            return  # a side change: reported as COMP_SIDE_CHANGE
        if m.kind == "arc":
            self.report(IssueCode.COMP_EXIT, "the exit move after G40 is an arc: compensation must be turned off "
                        f"during a straight move (G0/G1) at least the tool diameter ({2 * self.r:.4f} mm) long", m.line)
            return
        L = math.hypot(m.end[0] - m.start[0], m.end[1] - m.start[1])
        if 2 * self.r - self.join_tol > L:
            self.report(IssueCode.COMP_EXIT, f"the exit move after G40 is {L:.4f} mm long, shorter than the tool "
                        f"diameter {2 * self.r:.4f} mm: the controller cannot ramp the compensation off (LinuxCNC "
                        "refuses it)", m.line)

    # -- one compensated stretch -------------------------------------------------------------------
    def stretch(self, lo: int, hi: int) -> None:
        m0 = self.m[lo]
        side = m0.comp
        sgn = 1.0 if side == "G41" else -1.0
        if self.swap:
            sgn = -sgn
        run = len(self.runs)
        xy = [k for k in range(lo, hi) if _has_xy(self.m[k])]
        entry_line = self.m[xy[0]].line if xy else None
        self.runs.append(CompRun(side, m0.line, self.m[hi - 1].line, entry_line))
        if not xy:
            for k in range(lo, hi):
                self.plain(k, run)
            return
        e = self.m[xy[0]]
        cur = np.array(self.tool if self.tool is not None else e.start[:2], float)  # the tool before the entry
        if not np.all(np.isfinite(cur)):
            self.report(IssueCode.COMP_ENTRY, f"{side} is turned on before the X/Y position is known: the "
                        "compensation cannot be simulated", e.line)
            for k in range(lo, hi):
                self.plain(k, run)
            return
        for k in range(lo, xy[0]):  # Z-only moves before the entry
            self.plain(k, run)
        r = self.r
        pieces = [self._entry(xy[0], cur, sgn, side)] + self._offsets(xy[1:], sgn, side)
        # Z-only moves between two XY moves go with the junction after the first of them (an arc that
        # cannot be offset - a None piece - hands its own over to the piece before it)
        zs = [list(range(a + 1, b)) for a, b in zip(xy[:-1], xy[1:], strict=True)] + [[]]
        pending, pz = pieces[0], list(zs[0])
        for q, qz in zip(pieces[1:], zs[1:], strict=True):
            if q is None:
                pz += qz
                continue
            self._join(pending, q, sgn, r, run, pz)
            pending, pz = q, list(qz)
        self.emit(pending.to_move(self.m[pending.src]), pending.src, pending.kind, run)
        end = pending.point(pending.t1)
        self.tool = (float(end[0]), float(end[1]))
        self.last_run = run
        for k in pz:
            self.plain(k, run)
        for k in range(xy[-1] + 1, hi):
            self.plain(k, run)

    def _entry(self, k: int, cur: np.ndarray, sgn: float, side: str) -> _Piece:
        m = self.m[k]
        r = self.r
        P = np.array(m.end[:2], float)
        z0, z1 = m.start[2], m.end[2]
        if m.kind == "arc":
            self.report(IssueCode.COMP_ENTRY, f"the {side} entry move is an arc: compensation must be turned on "
                        "during a straight move (G0/G1) longer than the tool radius", m.line)
            cx, cy = m.center
            rs = math.hypot(cur[0] - cx, cur[1] - cy)
            a0 = math.atan2(cur[1] - cy, cur[0] - cx)
            sw = arc_sweep(tuple(cur), tuple(P), m.center, bool(m.clockwise)) if rs > 0 else m.sweep
            c = np.array(m.center, float)
            pc = _Piece(k, "entry", c=c, a0=a0, sw=sw, r0=rs, r1=m.radius_end, z0=z0, z1=z1, p_end=P,
                        exact=False)
            ue = (P - c) / max(np.hypot(*(P - c)), 1e-300)
            pc.tan_out = _rot(ue) if sw > 0 else -_rot(ue)
            pc.tan_in = pc.tan_out
            return pc
        d = float(np.hypot(*(P - cur)))
        if d <= r * (1 + 1e-9):
            self.report(IssueCode.COMP_ENTRY, f"the {side} entry move is {d:.4f} mm long, not longer than the tool "
                        f"radius {r:.4f} mm: the controller cannot ramp the compensation on (LinuxCNC stops with "
                        "'length of cutter compensation entry move is not greater than the tool radius')", m.line)
            if d <= JOIN_EPS_MM:
                return _line_piece(k, "entry", cur, cur, z0, z1, p_end=P, exact=False)
            u = (P - cur) / d
            E = P + r * sgn * _rot(u)
            pc = _line_piece(k, "entry", cur, E, z0, z1, p_end=P)
            pc.tan_in = pc.tan_out = u
            return pc
        u = (P - cur) / d
        cos_t = r / d
        sin_t = math.sqrt(max(0.0, 1.0 - cos_t * cos_t))
        E = P + r * (-u * cos_t + sgn * _rot(u) * sin_t)
        return _line_piece(k, "entry", cur, E, z0, z1, p_end=P)

    def _offsets(self, ks: list[int], sgn: float, side: str) -> list:
        """Offset pieces of the compensated XY moves ``ks`` (vectorised)."""
        if not ks:
            return []
        r = self.r
        ms = [self.m[k] for k in ks]
        A = np.array([m.start[:2] for m in ms], float)
        B = np.array([m.end[:2] for m in ms], float)
        Z0 = np.array([m.start[2] for m in ms], float)
        Z1 = np.array([m.end[2] for m in ms], float)
        is_arc = np.array([m.kind == "arc" for m in ms])
        C = np.array([m.center if m.kind == "arc" else (math.nan, math.nan) for m in ms], float)
        SW = np.array([m.sweep if m.kind == "arc" else 0.0 for m in ms], float)
        RS = np.array([m.radius_start if m.kind == "arc" else 0.0 for m in ms], float)
        RE = np.array([m.radius_end if m.kind == "arc" else 0.0 for m in ms], float)
        # lines: unit tangent and the normal towards the tool side
        D = B - A
        L = np.hypot(D[:, 0], D[:, 1])
        T = D / np.where(L > 0, L, 1.0)[:, None]
        N = sgn * np.column_stack([-T[:, 1], T[:, 0]])
        # arcs: radial unit vectors at both ends, tangents, radius change
        with np.errstate(invalid="ignore", divide="ignore"):
            UA = (A - C) / np.where(RS > 0, RS, 1.0)[:, None]
            UB = (B - C) / np.where(RE > 0, RE, 1.0)[:, None]
        ccw = SW > 0
        rotA = np.column_stack([-UA[:, 1], UA[:, 0]])
        rotB = np.column_stack([-UB[:, 1], UB[:, 0]])
        TA = np.where(ccw[:, None], rotA, -rotA)
        TB = np.where(ccw[:, None], rotB, -rotB)
        # the tool is on the centre's side when it is left (G41) of a ccw arc or right (G42) of a cw one
        dR = np.where((sgn > 0) == ccw, -r, r)
        RS2, RE2 = RS + dR, RE + dR
        A0 = np.arctan2(A[:, 1] - C[:, 1], A[:, 0] - C[:, 0])
        out: list = []
        for j, k in enumerate(ks):
            m = ms[j]
            if not is_arc[j]:
                pc = _line_piece(k, "offset", A[j] + r * N[j], B[j] + r * N[j], Z0[j], Z1[j], p_start=A[j],
                                 p_end=B[j])
                out.append(pc)
                continue
            if min(RS2[j], RE2[j]) <= 0.0:
                self.report(IssueCode.COMP_ARC_RADIUS, f"arc radius smaller than tool radius under {side}: the "
                            f"{'G3' if ccw[j] else 'G2'} arc of radius {RS[j]:.4f} mm about X{C[j, 0]:.4f} "
                            f"Y{C[j, 1]:.4f} has the tool ({r:.4f} mm) on its centre's side; the largest tool "
                            f"that fits has diameter {2 * min(RS[j], RE[j]):.4f} mm", m.line)
                out.append(None)
                continue
            out.append(_Piece(k, "offset", c=C[j], a0=float(A0[j]), sw=float(SW[j]), r0=float(RS2[j]),
                              r1=float(RE2[j]), z0=Z0[j], z1=Z1[j], tan_in=TA[j], tan_out=TB[j],
                              p_start=A[j], p_end=B[j]))
        # a skipped arc: the next piece is joined to the previous one by a straight bridge
        for j in range(1, len(out)):
            if out[j] is not None and out[j - 1] is None:
                out[j].exact = False
        return out

    def _join(self, p: _Piece, q: _Piece, sgn: float, r: float, run: int, zs: list[int]) -> None:
        """Trim/roll the corner between ``p`` and ``q``, then emit ``p``, the Z-only moves ``zs`` and the
        corner move."""
        Ep = p.point(p.t1)
        Sq = q.point(q.t0)
        gap = float(np.hypot(*(Sq - Ep)))
        corner = p.p_end if p.p_end is not None else q.p_start
        connector: tuple[Literal["corner"], np.ndarray] | tuple[Literal["bridge"]] | None = None
        if gap > JOIN_EPS_MM:
            if not (p.exact and q.exact) or corner is None:
                connector = ("bridge",)
            else:
                turn = math.atan2(_cross(p.tan_out, q.tan_in), float(p.tan_out @ q.tan_in))
                convex = sgn * turn < 0 or abs(turn) > math.pi - 1e-9
                if convex:
                    connector = ("corner", corner)
                else:
                    hit = _intersect(p, q, corner)
                    if hit is not None:
                        _, tp, tq = hit
                        p.t1, q.t0 = tp, tq
                        self.corners["trimmed"] += 1
                    else:
                        connector = ("bridge",)
                        if gap > self.join_tol:
                            self.corners["failed"] += 1
                            mp, mq = self.m[p.src], self.m[q.src]
                            self.report(IssueCode.COMP_CORNER, f"concave corner at X{corner[0]:.4f} "
                                        f"Y{corner[1]:.4f} (lines {mp.line} and {mq.line}) is too tight for the tool "
                                        f"radius {r:.4f} mm under {mq.comp}: the offset moves do not meet (a notch or "
                                        "a move shorter than the tool needs); the tool would cut into the part",
                                        mq.line)
        self.emit(p.to_move(self.m[p.src]), p.src, p.kind, run)
        E = p.point(p.t1)
        z = p.z(p.t1)
        for k in zs:
            mk = self.m[k]
            self.emit(replace(mk, start=(float(E[0]), float(E[1]), mk.start[2]),
                              end=(float(E[0]), float(E[1]), mk.end[2])), k, "z", run)
            z = mk.end[2]
        if connector is None:
            return
        S = q.point(q.t0)
        zq = q.z(q.t0)
        mq = self.m[q.src]
        start = (float(E[0]), float(E[1]), z if zs else p.z(p.t1))
        end = (float(S[0]), float(S[1]), zq)
        if connector[0] == "corner":
            P = connector[1]
            cw = sgn > 0
            sweep = arc_sweep(E, S, P, cw)
            mv = replace(mq, kind="arc" if mq.kind != "rapid" else "rapid", start=start, end=end)
            if mq.kind != "rapid":
                mv = replace(mv, center=(float(P[0]), float(P[1])), clockwise=cw, sweep=sweep,
                             radius_start=float(np.hypot(*(E - P))), radius_end=float(np.hypot(*(S - P))))
            else:
                mv = replace(mv, center=None, clockwise=None, sweep=0.0, radius_start=math.nan,
                             radius_end=math.nan)
            self.corners["rolling"] += 1
            self.emit(mv, q.src, "corner", run)
        else:
            kind = "rapid" if mq.kind == "rapid" else "line"
            self.emit(replace(mq, kind=kind, start=start, end=end, center=None, clockwise=None, sweep=0.0,
                              radius_start=math.nan, radius_end=math.nan), q.src, "bridge", run)


def simulate_compensation(moves: Sequence[Move], radius: float, *, swap_side: bool = False,
                          join_tol: float = 1e-4) -> CompensatedPath:
    """The tool-centre moves a controller makes for a program with cutter compensation.

    Parameters
    ----------
    moves : sequence of Move
        Back-plotted program (:func:`camfab.gcode.parse.parse`).  Moves under G40 pass through unchanged
        (except the exit move and Z-only moves right after a compensated stretch, which start where the
        compensated tool is).
    radius : float
        Compensation radius in mm (what the D register holds: the tool radius).
    swap_side : bool
        Simulate G41 as G42 and vice versa (what-if for a program compensated to the wrong side).
    join_tol : float
        Offset moves whose ends are less than this apart (mm) at a concave corner that cannot be trimmed
        (rounding of near-tangent entities) are joined straight without a ``COMP_CORNER`` problem.

    Returns
    -------
    CompensatedPath
    """
    moves = list(moves)
    if not math.isfinite(radius) or radius < 0:
        raise InputError(f"radius = {radius!r}: must be finite and >= 0 mm (the D register, usually the tool radius)")
    sim = _Sim(moves, radius, swap_side, join_tol)
    i, n, prev_side = 0, len(moves), "G40"
    while i < n:
        m = moves[i]
        if m.comp == "G40":
            sim.plain(i)
            prev_side = "G40"
            i += 1
            continue
        j = i
        while j < n and moves[j].comp == m.comp:
            j += 1
        if prev_side != "G40":
            sim.report(IssueCode.COMP_SIDE_CHANGE, f"{m.comp} while {prev_side} is active: cancel compensation "
                       "with G40 (and an exit move) before changing sides", m.line)
        if radius == 0:
            for k in range(i, j):
                sim.plain(k)
        else:
            sim.stretch(i, j)
        prev_side = m.comp
        i = j
    return CompensatedPath(moves=tuple(sim.out), source=np.asarray(sim.src, dtype=np.int64),
                           kind=tuple(sim.kind), run=np.asarray(sim.run, dtype=np.int64), runs=tuple(sim.runs),
                           problems=tuple(sim.problems), radius=float(radius), corners=dict(sim.corners))
