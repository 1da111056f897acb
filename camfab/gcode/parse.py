"""A strict G-code reader and back-plotter for the subset camfab writes (and what shops hand-edit in).

It tokenises each line into words, keeps the modal state - motion mode (G0/G1/G2/G3/G80), distance mode
(G90/G91), arc-centre mode (G91.1 incremental default, G90.1 absolute), units (G20/G21, converted to mm
internally), plane (G17 only for arcs), feed F, spindle S/M3/M4/M5, tool, coolant, cutter
compensation (G40/G41/G42) - and turns the motion blocks into :class:`Move` records in mm.

Accepted: ``%`` lines, ``O`` program numbers (alone on their line, optionally with a comment), ``N`` line
numbers, comments ``( ... )`` (not nested) and ``; ...``.  Anything else - an unknown letter or code, a
malformed number, two words of one modal group, an arc without centre or with both ``R`` and ``I J`` -
raises :class:`GcodeError` naming the line.  The last comment seen is attached to each move as its
``label`` (camfab's posts write ``FINISH CONTOUR`` etc.).

Arcs by ``R``: ``R > 0`` is the short arc (at most 180 degrees), ``R < 0`` the long one; an ``R`` arc
cannot be a full circle.  Arcs by ``I J`` whose start and end radii differ (rounding, or a hand edit)
are back-plotted as a spiral whose radius changes linearly with the angle (as LinuxCNC does), and
rejected when they differ by more than ``arc_radius_tol_mm`` (0.02 mm, about what controllers accept).
"""
from __future__ import annotations

import math
import re
from collections.abc import Sequence

import numpy as np

from camfab.errors import CamfabError, InputError
from camfab.geom2d import arc_sweep
from camfab.records import dataclass

__all__ = ["GcodeError", "Move", "Backplot", "Samples", "parse", "backplot", "points_along", "sample"]

MM_PER_INCH = 25.4

_NUMBER = r"[+-]?(?:\d+\.?\d*|\.\d+)"
_WORD = re.compile(r"([A-Za-z])\s*(" + _NUMBER + r")")
_LETTERS = set("NGMTSFXYZIJKRDHPO")

_G_GROUPS = {
    "motion": {"0", "1", "2", "3", "80"},
    "plane": {"17", "18", "19"},
    "units": {"20", "21"},
    "distance": {"90", "91"},
    "arc_distance": {"90.1", "91.1"},
    "comp": {"40", "41", "42"},
    "length": {"43", "49"},
    "wcs": {"54", "55", "56", "57", "58", "59"},
    "feed_mode": {"94"},
    "spindle_mode": {"97"},  # constant rpm (stated in the safety block)
    "dwell": {"4"},
}
_G_GROUP_OF = {code: g for g, codes in _G_GROUPS.items() for code in codes}
_M_GROUPS = {
    "stop": {"0", "1", "2", "30"},
    "spindle": {"3", "4", "5"},
    "toolchange": {"6"},
    "coolant_on": {"7", "8"},
    "coolant_off": {"9"},
}
_M_GROUP_OF = {code: g for g, codes in _M_GROUPS.items() for code in codes}


class GcodeError(CamfabError, ValueError):
    """A G-code line that cannot be read; ``line`` is the 1-based line number in the text."""

    def __init__(self, line: int, message: str, text: str = ""):
        self.line = line
        self.text = text
        tail = f": {text.strip()!r}" if text.strip() else ""
        super().__init__(f"line {line}: {message}{tail}")


@dataclass(frozen=True)
class Move:
    """One executed motion, in mm and absolute coordinates.

    Attributes
    ----------
    kind : {"rapid", "line", "arc"}
    start, end : tuple of float
        ``(x, y, z)``; ``nan`` for an axis whose position is not known yet.
    center : tuple of float or None
        Arc centre ``(x, y)``.
    clockwise : bool or None
        Arc direction (G2 true).
    sweep : float
        Signed arc sweep in radians (negative clockwise); 0 for straight moves.
    radius_start, radius_end : float
        Arc radius at the start and end (differ for a spiral); ``nan`` for straight moves.
    feed : float or None
        Feed in mm/min in effect (``None`` if none was set; always ``None`` for rapids).
    line : int
        Line in the text (1-based).
    n : int or None
        The block's N word.
    label : str or None
        The last comment before (or on) the line.
    comp : {"G40", "G41", "G42"}
        Cutter compensation in effect.
    spindle_on : bool
    spindle_rpm : float or None
    tool : int or None
        The tool loaded by the last ``T.. M6`` (None before any).
    spindle_dir : {"cw", "ccw"} or None
        ``M3`` clockwise, ``M4`` counter-clockwise (the last one given; None before any).
    coolant : {"off", "flood", "mist", "flood+mist"}
        Coolant in effect (``M8`` flood, ``M7`` mist, ``M9`` off).
    length_offset : int or None
        The tool-length offset register in effect (``G43 H..``; ``G43`` alone takes the loaded tool;
        None before any and after ``G49``).
    """

    kind: str
    start: tuple
    end: tuple
    line: int
    feed: float | None = None
    center: tuple | None = None
    clockwise: bool | None = None
    sweep: float = 0.0
    radius_start: float = math.nan
    radius_end: float = math.nan
    n: int | None = None
    label: str | None = None
    comp: str = "G40"
    spindle_on: bool = False
    spindle_rpm: float | None = None
    tool: int | None = None
    spindle_dir: str | None = None
    coolant: str = "off"
    length_offset: int | None = None

    @property
    def is_cutting(self) -> bool:
        """True for G1/G2/G3."""
        return self.kind != "rapid"


@dataclass(frozen=True)
class Backplot:
    """Result of :func:`parse`: the moves plus what the program declared.

    ``modal_before_motion`` holds the G-code modal groups the program sets before (or on) its first motion
    block: ``"plane"``, ``"units"``, ``"distance"``, ``"comp"``, ``"wcs"``, ``"feed_mode"``, ...  A group a
    program never sets is whatever the controller was left in.
    """

    moves: tuple
    units: str | None
    program_number: int | None
    comments: tuple
    warnings: tuple
    ended: bool
    modal_before_motion: frozenset = frozenset()


@dataclass(frozen=True)
class Samples:
    """Points along moves: ``points`` ``(n, 3)`` mm, ``index`` ``(n,)`` of the move each came from and ``param``
    ``(n,)``, where along it (0 at its start, 1 at its end)."""

    points: np.ndarray
    index: np.ndarray
    param: np.ndarray | None = None


def _strip_comments(raw: str, lineno: int) -> tuple[str, list[str]]:
    code: list[str] = []
    comments: list[str] = []
    i = 0
    while i < len(raw):
        c = raw[i]
        if c == "(":
            j = raw.find(")", i + 1)
            if j < 0:
                raise GcodeError(lineno, "comment not closed", raw)
            body = raw[i + 1:j]
            if "(" in body:
                raise GcodeError(lineno, "nested comment", raw)
            comments.append(body.strip())
            i = j + 1
        elif c == ")":
            raise GcodeError(lineno, "')' without '('", raw)
        elif c == ";":
            comments.append(raw[i + 1:].strip())
            break
        else:
            code.append(c)
            i += 1
    return "".join(code), comments


def _tokenise(code: str, lineno: int, raw: str) -> list[tuple[str, str]]:
    words = []
    pos = 0
    s = code
    while pos < len(s):
        if s[pos].isspace():
            pos += 1
            continue
        m = _WORD.match(s, pos)
        if not m:
            bad = s[pos:].split()[0] if s[pos:].split() else s[pos:]
            raise GcodeError(lineno, f"malformed word {bad!r}", raw)
        letter = m.group(1).upper()
        if letter not in _LETTERS:
            raise GcodeError(lineno, f"unknown word {letter}{m.group(2)}", raw)
        end = m.end()
        if end < len(s) and not s[end].isspace() and not s[end].isalpha():
            raise GcodeError(lineno, f"malformed word {s[pos:end + 1]!r}", raw)
        words.append((letter, m.group(2)))
        pos = end
    return words


def _code(value: str) -> str:
    v = float(value)
    return f"{v:g}"


def parse(text: str, *, arc_radius_tol_mm: float = 0.02) -> Backplot:
    """Read G-code text and back-plot it.

    Parameters
    ----------
    text : str
        The program.
    arc_radius_tol_mm : float
        Largest accepted difference between an I/J arc's start and end radius.

    Returns
    -------
    Backplot

    Raises
    ------
    GcodeError
        Unknown or malformed words, conflicting words, impossible arcs; the message names the line.
    """
    st = _State(arc_radius_tol_mm)
    for lineno, raw in enumerate(text.splitlines(), 1):
        st.line(lineno, raw)
    if not st.ended:
        st.warnings.append("the program has no end (M2/M30)")
    if st.units is None and st.moves:
        st.warnings.append("the program never sets units (G20/G21); mm assumed")
    return Backplot(moves=tuple(st.moves), units=st.units, program_number=st.program_number,
                    comments=tuple(st.comments), warnings=tuple(st.warnings), ended=st.ended,
                    modal_before_motion=frozenset(st.modal_before_motion if st.moves else st.groups_seen))


def backplot(text: str, **kw) -> list[Move]:
    """The moves of ``text`` (see :func:`parse`)."""
    return list(parse(text, **kw).moves)


class _State:
    def __init__(self, arc_tol: float):
        self.arc_tol = arc_tol
        self.pos = [math.nan, math.nan, math.nan]
        self.motion: str | None = None
        self.plane = "17"
        self.units: str | None = None
        self.incremental = False
        self.arc_incremental = True
        self.comp = "G40"
        self.F: float | None = None
        self.S: float | None = None
        self.spindle_on = False
        self.spindle_dir: str | None = None
        self.coolant: set[str] = set()
        self.length_offset: int | None = None
        self.groups_seen: set[str] = set()
        self.modal_before_motion: set[str] = set()
        self.tool: int | None = None
        self.selected: int | None = None
        self.label: str | None = None
        self.moves: list[Move] = []
        self.comments: list[str] = []
        self.warnings: list[str] = []
        self.program_number: int | None = None
        self.ended = False
        self.warned_units = False
        self.warned_after_end = False

    @property
    def f(self) -> float:
        return MM_PER_INCH if self.units == "inch" else 1.0

    def line(self, lineno: int, raw: str) -> None:
        code, comments = _strip_comments(raw, lineno)
        s = code.strip()
        if self.ended:
            if s and s != "%" and not self.warned_after_end:
                self.warnings.append(f"line {lineno}: blocks after the program end are ignored")
                self.warned_after_end = True
            return
        for c in comments:
            self.comments.append(c)
            self.label = c
        if not s:
            return
        if s == "%":
            return
        if "%" in s:
            raise GcodeError(lineno, "'%' must stand alone on its line", raw)
        if s.startswith("/"):
            raise GcodeError(lineno, "block delete '/' is not supported", raw)
        words = _tokenise(s, lineno, raw)
        if words[0][0] == "O":
            if len(words) > 1:
                raise GcodeError(lineno, "an O word must stand alone (subroutines and control flow are not "
                                         "supported)", raw)
            self.program_number = int(float(words[0][1]))
            return
        self.block(lineno, raw, words)

    def block(self, lineno: int, raw: str, words) -> None:
        err = lambda msg: GcodeError(lineno, msg, raw)  # noqa: E731
        n = None
        if words[0][0] == "N":
            n = int(float(words[0][1]))
            words = words[1:]
        vals: dict[str, float] = {}
        gs: dict[str, str] = {}
        ms: dict[str, str] = {}
        for letter, v in words:
            if letter == "N":
                raise err("N word must come first")
            if letter == "O":
                raise err("O word inside a block")
            if letter == "G":
                c = _code(v)
                g = _G_GROUP_OF.get(c)
                if g is None:
                    raise err(f"unsupported G-code G{v}")
                if g in gs:
                    raise err(f"G{gs[g]} and G{c} on one line are in the same modal group")
                gs[g] = c
            elif letter == "M":
                c = _code(v)
                g = _M_GROUP_OF.get(c)
                if g is None:
                    raise err(f"unsupported M-code M{v}")
                if g in ms:
                    raise err(f"M{ms[g]} and M{c} on one line are in the same modal group")
                ms[g] = c
            else:
                if letter in vals:
                    raise err(f"word {letter} appears twice")
                vals[letter] = float(v)
        # 1-6 feed, spindle speed, tool, tool change, spindle, coolant
        if "F" in vals:
            if vals["F"] < 0:
                raise err("negative feed")
            self.F = vals["F"]
        if "S" in vals:
            if vals["S"] < 0:
                raise err("negative spindle speed")
            self.S = vals["S"]
        if "T" in vals:
            self.selected = int(vals["T"])
        if "toolchange" in ms:
            self.tool = self.selected
        if "spindle" in ms:
            self.spindle_on = ms["spindle"] in ("3", "4")
            if self.spindle_on:
                self.spindle_dir = "cw" if ms["spindle"] == "3" else "ccw"
        if "coolant_on" in ms:
            self.coolant.add("mist" if ms["coolant_on"] == "7" else "flood")
        if "coolant_off" in ms:
            self.coolant.clear()
        # 7 dwell
        if "dwell" in gs and "P" not in vals:
            raise err("G4 needs a P word")
        if "P" in vals and "dwell" not in gs:
            raise err("P word without G4")
        # 8-13 plane, units, compensation, length offset, coordinate system, distance modes
        if "plane" in gs:
            self.plane = gs["plane"]
        if "units" in gs:
            self.units = "inch" if gs["units"] == "20" else "mm"
        if "comp" in gs:
            self.comp = "G" + gs["comp"]
            if gs["comp"] in ("41", "42") and "D" not in vals:
                raise err(f"G{gs['comp']} needs a D word")
        if "D" in vals and gs.get("comp") not in ("41", "42"):
            raise err("D word without G41/G42")
        if "H" in vals and gs.get("length") != "43":
            raise err("H word without G43")
        if gs.get("length") == "43":
            self.length_offset = int(vals["H"]) if "H" in vals else self.tool
        elif gs.get("length") == "49":
            self.length_offset = None
        self.groups_seen.update(gs)
        if "distance" in gs:
            self.incremental = gs["distance"] == "91"
        if "arc_distance" in gs:
            self.arc_incremental = gs["arc_distance"] == "91.1"
        # 14 motion
        if "motion" in gs:
            self.motion = gs["motion"]
        axes = [a for a in "XYZ" if a in vals]
        centre_words = [a for a in "IJKR" if a in vals]
        arc_now = self.motion in ("2", "3") and (axes or "motion" in gs)
        if centre_words and not arc_now:
            raise err(f"{'/'.join(centre_words)} word(s) without a G2/G3 arc")
        if axes:
            if self.motion is None:
                raise err("axis words without a motion mode (G0/G1/G2/G3)")
            if self.motion == "80":
                raise err("axis words with G80 (motion cancelled)")
            if not self.moves:
                self.modal_before_motion = set(self.groups_seen)
            if self.units is None and not self.warned_units:
                self.warned_units = True
                self.warnings.append(f"line {lineno}: coordinates before any G20/G21; mm assumed")
            self.move(lineno, n, vals, err)
        elif "motion" in gs and gs["motion"] in ("2", "3"):
            raise err("G2/G3 needs an end point (X/Y)")
        # 15 stop
        if ms.get("stop") in ("2", "30"):
            self.ended = True

    def target(self, vals, err) -> list[float]:
        t = list(self.pos)
        for i, a in enumerate("XYZ"):
            if a in vals:
                v = vals[a] * self.f
                if self.incremental:
                    if math.isnan(self.pos[i]):
                        raise err(f"incremental {a} from an unknown position")
                    t[i] = self.pos[i] + v
                else:
                    t[i] = v
        return t

    def move(self, lineno, n, vals, err) -> None:
        start = tuple(self.pos)
        end = self.target(vals, err)
        feed = None
        if self.motion != "0" and self.F is not None:
            fu = MM_PER_INCH if self.units == "inch" else 1.0
            feed = self.F * fu
        common = dict(line=lineno, n=n, label=self.label, comp=self.comp, spindle_on=self.spindle_on,
                      spindle_rpm=self.S, tool=self.tool, spindle_dir=self.spindle_dir,
                      coolant="+".join(sorted(self.coolant)) or "off", length_offset=self.length_offset)
        if self.motion in ("0", "1"):
            kind = "rapid" if self.motion == "0" else "line"
            self.moves.append(Move(kind, start, tuple(end), feed=feed, **common))
        else:
            self.moves.append(self.arc(start, end, vals, err, feed, common))
        self.pos = end

    def arc(self, start, end, vals, err, feed, common) -> Move:
        if self.plane != "17":
            raise err(f"arcs in plane G{self.plane} are not supported (G17 only)")
        if "K" in vals:
            raise err("K word in a G17 (XY) arc")
        if math.isnan(start[0]) or math.isnan(start[1]):
            raise err("arc from an unknown XY position")
        if math.isnan(end[2]) and not math.isnan(start[2]):
            raise err("arc with unknown Z")
        cw = self.motion == "2"
        sx, sy = start[0], start[1]
        ex, ey = end[0], end[1]
        has_ij = "I" in vals or "J" in vals
        if "R" in vals and has_ij:
            raise err("R and I/J on one arc")
        if "R" in vals:
            R = vals["R"] * self.f
            dx, dy = ex - sx, ey - sy
            d = math.hypot(dx, dy)
            if d < 1e-9:
                raise err("an R arc cannot be a full circle (start = end)")
            if abs(R) < 1e-9:
                raise err("R = 0")
            half = d / 2
            h2 = R * R - half * half
            if h2 < 0:
                if half - abs(R) > 0.002:
                    raise err(f"R {abs(R):.4f} mm is smaller than half the chord {half:.4f} mm")
                h2 = 0.0
            h = math.sqrt(h2)
            ux, uy = dx / d, dy / d
            rx, ry = uy, -ux  # right of the chord
            sign = (1.0 if cw else -1.0) * (1.0 if R > 0 else -1.0)
            cx = (sx + ex) / 2 + sign * h * rx
            cy = (sy + ey) / 2 + sign * h * ry
        elif has_ij:
            i = vals.get("I")
            j = vals.get("J")
            if self.arc_incremental:
                cx = sx + (i or 0.0) * self.f
                cy = sy + (j or 0.0) * self.f
            else:
                if i is None or j is None:
                    raise err("absolute arc centres (G90.1) need both I and J")
                cx, cy = i * self.f, j * self.f
        else:
            raise err("arc without centre (I/J) or radius (R)")
        rs = math.hypot(sx - cx, sy - cy)
        re_ = math.hypot(ex - cx, ey - cy)
        if rs < 1e-9:
            raise err("arc of zero radius")
        if abs(rs - re_) > self.arc_tol:
            raise err(f"arc start and end radii differ by {abs(rs - re_):.4f} mm "
                      f"(> {self.arc_tol} mm): the centre is wrong")
        sweep = arc_sweep((sx, sy), (ex, ey), (cx, cy), cw)
        return Move("arc", start, tuple(end), feed=feed, center=(cx, cy), clockwise=cw, sweep=sweep,
                    radius_start=rs, radius_end=re_, **common)


def _move_params(m: Move, step: float, max_per_move: int | None = None) -> np.ndarray:
    """Fractions along ``m`` of its sample points: at most ``step`` mm apart, at most ``max_per_move`` intervals,
    arcs at least one per 5.6 degrees."""
    s, e = np.array(m.start, dtype=float), np.array(m.end, dtype=float)
    if m.kind != "arc":
        if not np.all(np.isfinite(s)):
            return np.ones(1)
        L = float(np.linalg.norm(e - s))
        k = max(1, int(math.ceil(L / step)))
        if max_per_move is not None:
            k = min(k, max_per_move)
        return np.linspace(0.0, 1.0, k + 1)
    L = abs(m.sweep) * max(m.radius_start, m.radius_end)
    k = int(math.ceil(L / step))
    if max_per_move is not None:
        k = min(k, max_per_move)
    k = max(k, 2, int(math.ceil(abs(m.sweep) / (math.pi / 32))))
    return np.linspace(0.0, 1.0, k + 1)


def points_along(m: Move, u: np.ndarray) -> np.ndarray:
    """Points ``(n, 3)`` of move ``m`` at fractions ``u`` of it (along the arc for arcs and spirals)."""
    s, e = np.array(m.start, dtype=float), np.array(m.end, dtype=float)
    u = np.asarray(u, dtype=float)
    if m.kind != "arc":
        if not np.all(np.isfinite(s)):
            return np.repeat(e[None, :], len(u), axis=0)
        return s + u[:, None] * (e - s)
    assert m.center is not None  # an arc always carries its centre (_State.arc)
    cx, cy = m.center
    a = math.atan2(s[1] - cy, s[0] - cx) + m.sweep * u
    r = m.radius_start + (m.radius_end - m.radius_start) * u
    pts = np.column_stack([cx + r * np.cos(a), cy + r * np.sin(a), s[2] + (e[2] - s[2]) * u])
    pts[u >= 1.0] = e
    return pts


def sample(moves: Sequence[Move], step: float = 0.05, max_per_move: int | None = None) -> Samples:
    """Densify moves into points at most ``step`` mm apart (arcs along the arc, spirals included).

    Points with an unknown coordinate (before the first positioning) are left out.

    Parameters
    ----------
    moves : sequence of Move
    step : float
        Largest distance between consecutive points of a move, mm.
    max_per_move : int, optional
        At most this many intervals per move (a long move is then sampled more sparsely than ``step``),
        so that the number of points follows the number of moves, not their length; arcs keep at least
        one point per 5.6 degrees of sweep.

    Returns
    -------
    Samples
    """
    if step <= 0:
        raise InputError(f"step = {step!r}: must be > 0 (the largest distance between samples of a move, mm)")
    chunks, idx, par = [], [], []
    for i, m in enumerate(moves):
        u = _move_params(m, step, max_per_move)
        p = points_along(m, u)
        ok = np.all(np.isfinite(p), axis=1)
        chunks.append(p[ok])
        idx.append(np.full(int(ok.sum()), i, dtype=np.int64))
        par.append(u[ok])
    if not chunks:
        return Samples(np.zeros((0, 3)), np.zeros(0, dtype=np.int64), np.zeros(0))
    return Samples(np.concatenate(chunks), np.concatenate(idx), np.concatenate(par))
