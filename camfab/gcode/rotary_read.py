"""Read back a 4-axis program (X along the axis, A rotary in degrees, Z the tool tip's radius; G93/G94 feeds).

camfab's plate reader (:mod:`camfab.gcode.parse`) knows X, Y, Z and arcs; this modal reader knows what the
rotary program of :mod:`camfab.gcode.rotary` may contain: ``G0``/``G1`` with X, A, Z (Y only as 0), ``G93`` /
``G94`` feed modes, ``G20``/``G21`` units (X, Z and the G94 feed in inches are converted to mm; A stays in
degrees; a G93 F is 1/minutes in either), the modal codes of the posts' preambles, ``T``/``M6``, ``S``/``M3``,
``M4``, ``M5``, coolant ``M7``/``M8``/``M9``, ``G43 H``, line numbers, comments in parentheses or after ``;``.
Each move remembers the last comment that opens with ``centre pass``, ``finishing pass`` or ``roughing pass``
(a rib's), its feed mode and F, and the spindle state.  Anything else (an arc, relative distances, a Y off 0, an
unknown word) is a :class:`RotaryReadError` naming the line.
"""
from __future__ import annotations

import re

from ..errors import CamfabError
from ..records import dataclass
from .posts.base import MM_PER_INCH

__all__ = ["RotaryMove", "RotaryReadError", "read_rotary"]

_WORD = re.compile(r"([A-Z])\s*([+-]?(?:\d+\.?\d*|\.\d+))")
_COMMENT = re.compile(r"\(([^)]*)\)")
#: modal G codes the posts write that change nothing the back-plot follows
_HARMLESS_G = {"17", "40", "49", "54", "55", "56", "57", "58", "59", "80", "90", "91.1", "97", "64", "61", "61.1",
               "43", "28", "53"}


class RotaryReadError(CamfabError, ValueError):
    """A line the 4-axis back-plot cannot follow (a camfab error, like the plate reader's ``GcodeError``)."""

    def __init__(self, line: int, message: str):
        super().__init__(f"line {line}: {message}")
        self.line = line


@dataclass(frozen=True)
class RotaryMove:
    """One straight move (X mm, A degrees, Z mm): ``kind`` 'rapid' or 'feed'."""

    kind: str
    start: tuple[float, float, float]
    end: tuple[float, float, float]
    line: int
    label: str
    inverse_time: bool
    feed: float | None
    spindle_rpm: float
    spindle_dir: int


@dataclass
class _State:
    pos: tuple[float | None, float | None, float | None] = (None, None, None)
    motion: str | None = None
    g93: bool = False
    inch: bool = False
    feed: float | None = None
    rpm: float = 0.0
    direction: int = 0
    label: str = ""


def _g_codes(state: _State, gs: list[str], n: int) -> None:
    for g in gs:
        g = g.rstrip("0").rstrip(".") if "." in g else str(int(float(g)))
        if g in ("0", "1"):
            state.motion = g
        elif g in ("93", "94"):
            state.g93 = g == "93"
            state.feed = None  # a new feed mode needs a new F
        elif g in ("20", "21"):
            state.inch = g == "20"
        elif g not in _HARMLESS_G:
            raise RotaryReadError(n, f"G{g} is not part of a 4-axis groove program (only G0/G1 with X, A, Z)")


def _m_codes(state: _State, ms: list[str], n: int) -> bool:
    """Apply the M words; True at the program's end."""
    for m in (str(int(float(v))) for v in ms):
        if m in ("3", "4"):
            state.direction = 1 if m == "3" else -1
        elif m == "5":
            state.direction = 0
        elif m in ("2", "30"):
            return True
        elif m not in ("6", "7", "8", "9", "0", "1"):
            raise RotaryReadError(n, f"M{m} is not part of a 4-axis groove program")
    return False


def _line_move(state: _State, words: dict[str, list[str]], n: int) -> RotaryMove | None:
    k = MM_PER_INCH if state.inch else 1.0
    if "Y" in words and abs(float(words["Y"][0])) > 1e-9:
        raise RotaryReadError(n, "a Y off 0: the 4-axis program keeps the tool over the rotary axis (Y0)")
    if "F" in words:
        f = float(words["F"][0])
        state.feed = f if state.g93 else f * k
    new = list(state.pos)
    for i, ax in enumerate("XAZ"):
        if ax in words:
            new[i] = float(words[ax][0]) * (1.0 if ax == "A" else k)
    moved = any(ax in words for ax in "XAZ")
    start = state.pos
    state.pos = (new[0], new[1], new[2])
    if not moved:
        return None
    if state.motion is None:
        raise RotaryReadError(n, "a move before any G0/G1")
    if None in start or None in new:
        if state.motion == "1":
            raise RotaryReadError(n, "a cutting move before X, A and Z are all known")
        return None
    return RotaryMove("rapid" if state.motion == "0" else "feed", start, state.pos, n,  # type: ignore[arg-type]
                      state.label, state.g93, state.feed, state.rpm, state.direction)


def read_rotary(text: str) -> list[RotaryMove]:
    """The moves of a 4-axis program (module notes); raises :class:`RotaryReadError`."""
    state, moves = _State(), []
    for n, raw in enumerate(text.splitlines(), start=1):
        for c in _COMMENT.findall(raw):
            if c.strip().lower().startswith(("centre pass", "finishing pass", "roughing pass")):
                state.label = c.strip().lower()
        code = _COMMENT.sub(" ", raw).split(";")[0].strip().upper()
        if not code or code == "%" or code.startswith("O"):
            continue
        words: dict[str, list[str]] = {}
        for letter, value in _WORD.findall(code):
            words.setdefault(letter, []).append(value)
        rest = _WORD.sub(" ", code)
        if rest.strip():
            raise RotaryReadError(n, f"cannot read {rest.strip()!r}")
        for ax in ("I", "J", "K", "R", "B", "C", "U", "V", "W"):
            if ax in words:
                raise RotaryReadError(n, f"{ax} words are not part of a 4-axis groove program")
        _g_codes(state, words.get("G", []), n)
        if "S" in words:
            state.rpm = float(words["S"][0])
        end = _m_codes(state, words.get("M", []), n)
        move = _line_move(state, words, n)
        if move is not None:
            moves.append(move)
        if end:
            break
    return moves
