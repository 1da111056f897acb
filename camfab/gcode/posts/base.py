"""The shared post-processor machinery: one writer over the common toolpath model.

A controller module subclasses :class:`Post` and sets a handful of flags (program delimiters, line
numbers, arc format, which codes the controller accepts, comment rules).  Everything else - unit
conversion, fixed number formatting, modal suppression of unchanged words, arc splitting - lives here so
the three posts cannot drift apart.

Number formatting is fixed per program: by default ``decimals = max(4, ceil(-log10(tol)) + 1)`` in mm (4 for
the default 1 um tolerance) and one more in inch (a post may fix its own: Fanuc writes its least input
increment); feeds 1 decimal (mm/min) or 3 (in/min); spindle speed an integer.  The rounding of the written
coordinates and arc centres has a bound (:func:`rounding_allowance_mm`) that the contour's tolerance budget
leaves room for (:func:`camfab.gcode.cam.contour_tolerance`).  Arcs above :attr:`Post.max_arc_radius_mm` reach
the program as chords (:func:`camfab.discretize.arcs_within_radius`).  ``-0`` is written as ``0``.  There are
no timestamps: the same program gives the same bytes.
"""
from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

from camfab.errors import ApiError, ExportError, InputError
from camfab.gcode.model import Arc, Comment, Coolant, CutterComp, Feed, Program, Rapid, Spindle, ToolChange
from camfab.geom2d import arc_sweep
from camfab.textsafe import gcode_comment

__all__ = ["MM_PER_INCH", "Post", "decimals_for", "header_lines", "rounding_allowance_mm"]

#: millimetres per inch
MM_PER_INCH = 25.4


def decimals_for(tolerance_mm: float, units: str) -> int:
    """Decimals written for coordinates: enough that rounding stays well inside the tolerance."""
    d = max(4, int(math.ceil(-math.log10(tolerance_mm) - 1e-9)) + 1)
    return d + 1 if units == "inch" else d


def rounding_allowance_mm(decimals: int, units: str, max_sweep_deg: float) -> float:
    """Bound (mm) on how far rounding to ``decimals`` moves a written contour off the exact one.

    Each coordinate moves by at most half the increment ``h``, a point by ``h/√2``; the path between two
    rounded ends follows them (first order), and an arc whose centre moved by ``e`` (at most ``h√2``: the
    writer picks, of the four grid points around the exact centre, the one that gives both ends one radius)
    bulges by ``e (1 - cos(sweep/2))`` more at its middle.  So ``h/√2 + h√2 (1 - cos(max_sweep/2))`` with the
    largest sweep one arc block has (docs/decisions.md, "Fanuc decimals and the rounding budget").
    """
    h = 10.0 ** -decimals * (MM_PER_INCH if units == "inch" else 1.0)
    return h / math.sqrt(2.0) + h * math.sqrt(2.0) * (1.0 - math.cos(math.radians(max_sweep_deg) / 2.0))


def header_lines(program: Program, post_name: str, arc_note: str = "", decimals: int | None = None,
                 rounding_mm: float | None = None) -> list[str]:
    """The header comment texts: design, post, units, tool, tolerance, deviation, speeds, depths (and the bound
    on how far the rounding moves the path, when given)."""
    job = program.job
    inch = job.units == "inch"
    u = "in" if inch else "mm"
    k = 1.0 / MM_PER_INCH if inch else 1.0
    d = decimals_for(job.tolerance_mm, job.units) if decimals is None else decimals

    def L(v):
        return _fmt(v * k, d)

    def mm_in(v):
        text = f"{v:.6f} mm"
        return text + (f" = {v / MM_PER_INCH:.7f} in" if inch else "")

    dev = "not stated" if job.achieved_deviation_mm is None else mm_in(job.achieved_deviation_mm)
    fd = 3 if inch else 1
    if program.compensation:
        path = "part contour"
        comp = f"{program.compensation} with D{job.tool_number} = tool radius"
    else:
        path = "tool-centre path"
        comp = "none"
    lines = [
        "camfab contour milling program",
        f"design: {job.design_name}",
        f"post: {post_name}{arc_note}",
        f"units: {'inch' if inch else 'mm'}",
        f"tool: T{job.tool_number} flat end mill D{L(job.tool_diameter_mm)} {u}",
        f"tolerance: {mm_in(job.tolerance_mm)}",
        f"achieved deviation: {dev}",
        f"output resolution: {10.0 ** -d:.{d}f} {u}",
        *([f"rounding: path moved at most {mm_in(rounding_mm)}"] if rounding_mm is not None else []),
        f"spindle: {round(job.spindle_rpm)} rpm cw",
        f"feed: {job.feed_mm_min * k:.{fd}f} {u}/min, plunge {job.plunge_feed_mm_min * k:.{fd}f} {u}/min",
        f"stock top Z0, final depth Z{L(-job.depth_mm)}, safe Z{L(job.safe_z_mm)}",
        f"depth levels: {len(job.levels)}, step-down {L(job.depth_mm / len(job.levels))} {u}",
        f"milling: {job.direction}, {program.milled}, {path}",
        f"cutter compensation: {comp}",
        *([f"roughing passes: {job.roughing_passes}, allowance {L(job.roughing_allowance_mm)} {u}"]
          if program.milled == "outside contour" else []),
    ]
    return lines + list(program.notes)  # cutting data, stock, depth, entry, bore (camfab.gcode.toolpath)


def _fmt(v: float, d: int) -> str:
    s = f"{v:.{d}f}"
    if s.startswith("-") and float(s) == 0.0:
        s = s[1:]
    return s


def _centre_words(sx: float, sy: float, ex: float, ey: float, cx: float, cy: float, d: int) -> tuple[str, str]:
    """I and J (program units, ``d`` decimals) of the centre ``(cx, cy)`` of an arc from the written start
    ``(sx, sy)`` to the written end ``(ex, ey)``: of the four grid points around the exact centre, the one whose
    distances to the two written ends differ least (so a controller sees one radius), ties to the nearest."""
    h = 10.0 ** -d
    best = None
    for fi in (math.floor, math.ceil):
        for fj in (math.floor, math.ceil):
            i = fi((cx - sx) / h) * h
            j = fj((cy - sy) / h) * h
            mismatch = abs(math.hypot(i, j) - math.hypot(sx + i - ex, sy + j - ey))
            key = (round(mismatch / h, 6), math.hypot(sx + i - cx, sy + j - cy))
            if best is None or key < best[0]:
                best = (key, i, j)
    assert best is not None
    return _fmt(best[1], d), _fmt(best[2], d)


class Post:
    """Base post-processor.  Subclasses set the class attributes; see the controller modules.

    Attributes
    ----------
    name : str
        Registry name.
    percent : bool
        Wrap the program in ``%`` lines.
    program_number : bool
        Write an ``O`` program-number line (option ``program_number``).
    line_numbers : bool
        Prefix blocks with ``N`` words (option ``line_number_step``).
    tool_change : bool
        The controller accepts ``T.. M6`` (else a comment asks the operator).
    length_offset : bool
        Write ``G43 H..`` after the tool change.
    compensation : bool
        The controller accepts G41/G42.
    arc_formats : tuple of str
        ``"ij"`` (incremental centre) and/or ``"r"`` (radius).
    end_code : str
        ``M2`` or ``M30``.
    max_arc_radius_mm : float
        The controller's largest arc radius (default 99 999.999 mm: an R or I/J word of 8 digits); below it,
        arcs above :func:`~camfab.tolerances.arc_radius_limit` of the part are written as chords within the
        tolerance.
    max_arc_sweep_deg : float
        Largest sweep of one arc block; longer arcs are split into equal pieces (R arcs at most 90).
    """

    name = "base"
    percent = False
    program_number = False
    line_numbers = False
    tool_change = True
    length_offset = True
    compensation = True
    arc_formats: tuple[str, ...] = ("ij",)
    end_code = "M2"
    mist_code = "M7"
    max_arc_radius_mm = 99_999.999
    max_arc_sweep_deg = 180.0
    #: default values of the options this post accepts
    defaults: dict[str, Any] = {}

    # -- hooks -----------------------------------------------------------------------------------
    def decimals(self, units: str, tolerance_mm: float, achieved_mm: float | None = None) -> int:
        """Decimals of the written coordinates (default :func:`decimals_for`).  ``achieved_mm``: the contour's
        measured deviation, when known (a post may write coarser numbers when the contour leaves room)."""
        return decimals_for(tolerance_mm, units)

    def rounding_allowance_mm(self, units: str, tolerance_mm: float) -> float:
        """How far (mm) the rounding of this post's numbers can move the contour (:func:`rounding_allowance_mm`)."""
        return rounding_allowance_mm(self.decimals(units, tolerance_mm), units, self.arc_piece_deg("ij"))

    def arc_piece_deg(self, arc_format: str) -> float:
        """Largest sweep (degrees) of one written arc block for ``arc_format``."""
        return min(self.max_arc_sweep_deg, 90.0 if arc_format == "r" else 180.0)

    def preamble(self, units: str) -> list[str]:
        """Safety block words: plane, units, compensation/length/canned-cycle off, WCS, modes."""
        return ["G17", "G20" if units == "inch" else "G21", "G40", "G49", "G54", "G80", "G90", "G94"]

    def sanitize_comment(self, text: str) -> str:
        """Make ``text`` legal inside ``( )`` for this controller: one line of printable ASCII without
        parentheses, ``;`` or ``%`` (:func:`camfab.textsafe.gcode_comment`)."""
        return gcode_comment(text)

    def coolant_code(self, mode: str, opts: dict) -> str:
        """M-code switching coolant ``mode`` (flood, mist, off)."""
        return {"off": "M9", "flood": "M8", "mist": self.mist_code}[mode]

    def check_options(self, options: dict) -> dict:
        """Validate options; return them merged with the defaults."""
        unknown = sorted(set(options) - set(self.defaults))
        if unknown:
            valid = ", ".join(sorted(self.defaults)) or "none"
            raise InputError(f"post {self.name!r}: unknown option(s) {', '.join(unknown)}; valid: {valid}")
        opts = dict(self.defaults)
        opts.update(options)
        if "arc_format" in opts and opts["arc_format"] not in self.arc_formats:
            raise InputError(f"post {self.name!r}: arc_format must be one of {', '.join(self.arc_formats)}, "
                             f"got {opts['arc_format']!r}")
        return opts

    # -- driver ----------------------------------------------------------------------------------
    def dumps(self, program: Program, **options) -> str:
        """The program as G-code text for this controller (``\\n`` line ends, final newline).

        Raises
        ------
        InputError
            Unknown or invalid options (a ``ValueError``).
        ExportError
            The program needs something the controller lacks (e.g. G41/G42 on GRBL).
        """
        if not isinstance(program, Program):
            raise ApiError(f"dumps() takes a camfab.gcode.Program, got {type(program).__name__}; build one with "
                           "camfab.gcode.contour_toolpath")
        opts = self.check_options(options)
        if program.compensation and not self.compensation:
            raise ExportError(f"post {self.name!r}: the controller has no cutter radius compensation "
                              f"({program.compensation}); write the tool-centre program instead")
        return _Writer(self, program, opts).run()


class _Writer:
    def __init__(self, post: Post, program: Program, opts: dict):
        self.post = post
        self.program = program
        self.opts = opts
        job = program.job
        self.units = job.units
        self.k = 1.0 / MM_PER_INCH if job.units == "inch" else 1.0
        self.d = post.decimals(job.units, job.tolerance_mm, job.achieved_deviation_mm)
        self.fd = 3 if job.units == "inch" else 1
        self.arc_format = opts.get("arc_format", "ij")
        self.lines: list[str] = []
        self.n = 0
        self.exact = [math.nan, math.nan, math.nan]  # mm
        self.out: list[str | None] = [None, None, None]  # program units, as written
        self.feed: str | None = None
        self.pending: list[str] = []

    # -- low level -------------------------------------------------------------------------------
    def num(self, v_mm: float) -> str:
        return _fmt(v_mm * self.k, self.d)

    def comment(self, text: str) -> None:
        t = self.post.sanitize_comment(text)
        if t:
            self.lines.append(f"({t})")

    def block(self, words: list[str]) -> None:
        if self.post.line_numbers:
            step = int(self.opts.get("line_number_step", 10))
            self.n += 1
            num = (self.n * step - 1) % 99999 + 1 if self.n * step > 99999 else self.n * step
            words = [f"N{num}"] + words
        self.lines.append(" ".join(words))

    def feed_word(self, feed_mm_min: float) -> list[str]:
        f = f"{feed_mm_min * self.k:.{self.fd}f}"
        if f == self.feed:
            return []
        self.feed = f
        return [f"F{f}"]

    def take_pending(self) -> list[str]:
        p, self.pending = self.pending, []
        return p

    # -- items -----------------------------------------------------------------------------------
    def run(self) -> str:
        post, job = self.post, self.program.job
        if post.percent:
            self.lines.append("%")
        if post.program_number:
            onum = self.opts.get("program_number", 1000)
            self.lines.append(f"O{onum:04d} ({post.sanitize_comment(job.design_name)[:16]})")
        note = ", arcs by R" if self.arc_format == "r" else ", arcs by I J"
        rounding = rounding_allowance_mm(self.d, self.units, post.arc_piece_deg(self.arc_format))
        for text in header_lines(self.program, post.name, note, self.d, rounding):
            self.comment(text)
        self.block(post.preamble(self.units))
        for item in self.program.items:
            self.item(item)
        if self.pending:
            self.block(self.take_pending())
        self.block([post.end_code])
        if post.percent:
            self.lines.append("%")
        return "\n".join(self.lines) + "\n"

    def item(self, it) -> None:
        if isinstance(it, Rapid):
            self.rapid(it)
        elif isinstance(it, Feed):
            self.linear(it)
        elif isinstance(it, Arc):
            self.arc(it)
        elif isinstance(it, Comment):
            self.comment(it.text)
        elif isinstance(it, ToolChange):
            self.tool_change(it)
        elif isinstance(it, Spindle):
            if it.rpm > 0:
                self.block([f"S{round(it.rpm)}", "M3"])
            else:
                self.block(["M5"])
        elif isinstance(it, Coolant):
            self.coolant(it)
        elif isinstance(it, CutterComp):
            if it.mode == "G40":
                self.pending += ["G40"]
            elif it.mode in ("G41", "G42"):
                self.pending += [it.mode, f"D{it.register}"]
            else:
                raise ExportError(f"unknown cutter compensation mode {it.mode!r}")
        else:
            raise ExportError(f"post {self.post.name!r}: cannot write program item {it!r}")

    def tool_change(self, it: ToolChange) -> None:
        post = self.post
        u = "in" if self.units == "inch" else "mm"
        if post.tool_change:
            self.block([f"T{it.tool}", "M6"])
            if post.length_offset:
                self.pending += ["G43", f"H{it.tool}"]
        else:
            d = self.num(it.diameter_mm).rstrip("0").rstrip(".")
            self.comment(f"tool change by hand: load T{it.tool} end mill {d} {u} then set Z zero")

    def coolant(self, it: Coolant) -> None:
        if it.mode not in ("off", "flood", "mist"):
            raise ExportError(f"unknown coolant mode {it.mode!r}")
        code = self.post.coolant_code(it.mode, self.opts)
        if self.opts.get("coolant", True):
            self.block([code])
        else:
            self.comment(f"coolant {it.mode} - switch by hand")

    def _axis_words(self, target: Sequence[float | None], axes=(0, 1, 2), force=()) -> list[str]:
        words = []
        for i in axes:
            v = target[i]
            if v is None:
                continue
            s = self.num(v)
            if s != self.out[i] or i in force:
                words.append("XYZ"[i] + s)
        return words

    def _commit(self, target) -> None:
        for i, v in enumerate(target):
            if v is not None:
                self.exact[i] = float(v)
                self.out[i] = self.num(v)

    def rapid(self, it: Rapid) -> None:
        target = [it.x, it.y, it.z]
        xy = self._axis_words(target, (0, 1))
        z = self._axis_words(target, (2,))
        if xy and z:
            # never a diagonal rapid: climb first, or travel first and then descend
            going_up = self.out[2] is None or float(z[0][1:]) >= float(self.out[2])
            first, second = ((None, None, it.z), (it.x, it.y, None)) if going_up else \
                ((it.x, it.y, None), (None, None, it.z))
            self.rapid(Rapid(*first))
            self.rapid(Rapid(*second))
            return
        words = xy + z
        if not words and not self.pending:
            return
        self.block(["G0"] + self.take_pending() + words)
        self._commit(target)

    def linear(self, it: Feed) -> None:
        target = [it.x, it.y, it.z]
        words = self._axis_words(target)
        if not words and not self.pending:
            return
        if any(v is None for v in self.out):
            raise ExportError("a cutting move from an unknown position: position the tool with a rapid first")
        self.block(["G1"] + self.take_pending() + words + self.feed_word(it.feed))
        self._commit(target)

    def arc(self, it: Arc) -> None:
        if any(v is None for v in self.out) or any(math.isnan(v) for v in self.exact):
            raise ExportError("an arc from an unknown position: position the tool with a rapid first")
        sx, sy, z0 = self.exact
        cx, cy = it.cx, it.cy
        sweep = arc_sweep((sx, sy), (it.x, it.y), (cx, cy), it.clockwise)
        max_piece = math.radians(self.post.arc_piece_deg(self.arc_format))
        n = max(1, math.ceil(abs(sweep) / max_piece - 1e-9))
        r = math.hypot(it.x - cx, it.y - cy)
        a0 = math.atan2(sy - cy, sx - cx)
        for i in range(1, n + 1):
            if i == n:
                px, py = it.x, it.y
            else:
                a = a0 + sweep * i / n
                px, py = cx + r * math.cos(a), cy + r * math.sin(a)
            pz = z0 + (it.z - z0) * i / n
            self._arc_piece(px, py, pz, cx, cy, r, it.clockwise, it.feed)

    def _arc_piece(self, x, y, z, cx, cy, r, clockwise, feed) -> None:
        target = [x, y, z]
        ex, ey = self.num(x), self.num(y)
        if ex == self.out[0] and ey == self.out[1]:
            # shorter than the output resolution: an arc with equal ends would be a full circle
            if self.num(z) != self.out[2]:
                self.linear(Feed(x, y, z, feed))
            else:
                self._commit(target)
            return
        words = [f"X{ex}", f"Y{ey}"] + self._axis_words(target, (2,))
        if self.arc_format == "r":
            words.append("R" + _fmt(r * self.k, self.d))
        else:
            ox, oy = self.out[0], self.out[1]
            assert ox is not None and oy is not None  # arc() starts only from a known position
            i, j = _centre_words(float(ox), float(oy), float(ex), float(ey), cx * self.k, cy * self.k, self.d)
            words += [f"I{i}", f"J{j}"]
        self.block(["G2" if clockwise else "G3"] + self.take_pending() + words + self.feed_word(feed))
        self._commit(target)
