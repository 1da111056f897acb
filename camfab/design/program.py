"""Segment programs: a closed chain of motion-law segments, evaluated exactly.

A :class:`MotionProgram` maps the cam's independent variable ``x`` (radians of
cam angle for rotating cams, mm of travel for translating cams) to the follower
coordinate ``S`` and its derivatives ``S′, S″, S‴`` per unit of ``x``.  It is
periodic with period :attr:`MotionProgram.period` (2π or the cam length).

Build one with :func:`build_program` (validating, reports every problem at
once) or :meth:`MotionProgram.from_segments` (the same, with degrees for
convenience).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Iterable, Sequence

import numpy as np

from ..errors import Problem, SpecError
from ..tolerances import ANGLE_SUM_TOL_DEG
from .kinds import ROTATING_MM, TRANSLATING_MM, Axis, LiftUnit
from .laws import GENERIC, HALF_PERIOD, LAWS, TRIG1, get_law, horner, law_names, trig_rows

__all__ = [
    "SegmentInput",
    "Segment",
    "MotionProgram",
    "build_program",
    "solve_generic",
    "hermite_coefficients",
]

TWO_PI = 2.0 * math.pi


@dataclass(frozen=True, slots=True)
class SegmentInput:
    """One segment as the user wrote it (before neighbours are resolved).

    Parameters
    ----------
    law : str
        Law key (see :func:`camfab.design.laws.law_names`).
    lift : float
        Signed lift: mm (translating follower) or degrees (oscillating).
    span : float or None
        Segment span in the program's unit (radians, or mm for translating
        cams).  ``None`` asks for a half-period law's span to be solved from
        its neighbour's slope.
    shape : str or None
        Double-harmonic shape override ("rise" or "return").
    """

    law: str
    lift: float
    span: float | None
    shape: str | None = None


@dataclass(frozen=True, slots=True)
class Segment:
    """A resolved segment: its law, span, start and exact polynomial data.

    ``S(u) = s0 + lift·f(u)`` for standard laws, or ``S(u) = Σ coeffs[i]·uⁱ``
    for polynomial segments (generic 5th/7th, knot-table Hermite pieces), with
    ``u = (x − start)/span``.
    """

    law: str
    lift: float
    span: float
    start: float
    s0: float
    coeffs: tuple[float, ...] | None = None
    title: str = ""
    _dcoeffs: tuple = field(default=(), repr=False, compare=False)

    def __post_init__(self) -> None:
        if self.coeffs is not None:  # derivative coefficients, computed once
            c = np.asarray(self.coeffs, dtype=float)
            ders = [c]
            for _ in range(5):
                ders.append(np.polynomial.polynomial.polyder(ders[-1]) if ders[-1].size > 1 else np.zeros(1))
            object.__setattr__(self, "_dcoeffs", tuple(tuple(float(v) for v in d) for d in ders))

    @property
    def end(self) -> float:
        return self.start + self.span

    @property
    def breaks(self) -> tuple[float, ...]:
        """Internal breakpoints in ``u``."""
        return LAWS[self.law].breaks if self.law in LAWS else ()

    def du(self, u: np.ndarray, nu: int) -> np.ndarray:
        """``nu``-th derivative of S with respect to ``u`` (absolute units)."""
        if self.coeffs is not None:  # Horner as numpy's polyval, without its overhead
            return horner(self._dcoeffs[nu], np.asarray(u, dtype=float))
        out = self.lift * LAWS[self.law](u, nu)
        return out + self.s0 if nu == 0 else out

    def values(self, u: np.ndarray, nu: int) -> np.ndarray:
        """``nu``-th derivative of S with respect to ``x`` at local ``u``."""
        return self.du(u, nu) / self.span**nu

    def value_at(self, u: float, nu: int) -> float:
        """``values(np.array([u]), nu)[0]``, bit for bit, in Python floats (a standard law's
        f⁽ᵛ⁾(u) is a constant of the law, taken once)."""
        if self.coeffs is not None:  # Horner as horner(), operation for operation
            c = self._dcoeffs[nu]
            out = c[-1] + u * 0.0
            for ci in c[-2::-1]:
                out = ci + out * u
        else:
            out = self.lift * _law_value(self.law, u, nu)
            if nu == 0:
                out = out + self.s0
        return out / self.span**nu

    def end_values(self, at_end: bool, n: int = 4) -> np.ndarray:
        """S, S′, S″, S‴ (per unit x) at the start (``at_end=False``) or end."""
        u = 1.0 if at_end else 0.0
        return np.array([self.value_at(u, k) for k in range(n)])


#: f⁽ᵛ⁾(u) of the standard laws at single points, keyed by (law, u, ν): constants of the laws
_LAW_VALUES: dict = {}


def _law_value(law: str, u: float, nu: int) -> float:
    key = (law, u, nu)
    v = _LAW_VALUES.get(key)
    if v is None:
        v = _LAW_VALUES[key] = float(LAWS[law](np.array([u]), nu)[0])
    return v


def hermite_coefficients(
    start: Sequence[float], end: Sequence[float], span: float
) -> tuple[float, ...]:
    """Polynomial (in u) through end conditions given per unit x.

    ``start`` and ``end`` hold ``(S, S′, S″)`` for a quintic or
    ``(S, S′, S″, S‴)`` for a 7th-degree polynomial; this is the CAM-DAS linear
    system of spec §5.4/§5.6 in closed form.
    """
    m = len(start)
    if m not in (3, 4) or len(end) != m:
        raise ValueError("hermite_coefficients needs 3 (quintic) or 4 (7th degree) values per end")
    fact = [1.0, 1.0, 2.0, 6.0]
    a = [start[k] * span**k / fact[k] for k in range(m)]  # C0..C(m-1)
    # Δk = S^(k)(1)·β^k − d^k/du^k of the known low-order part at u=1
    low = np.polynomial.Polynomial(a)
    d = [end[k] * span**k - (low.deriv(k) if k else low)(1.0) for k in range(m)]
    if m == 3:
        c3 = 10 * d[0] - 4 * d[1] + d[2] / 2
        c4 = -15 * d[0] + 7 * d[1] - d[2]
        c5 = 6 * d[0] - 3 * d[1] + d[2] / 2
        return (*a, c3, c4, c5)
    c4 = 35 * d[0] - 15 * d[1] + 2.5 * d[2] - d[3] / 6
    c5 = -84 * d[0] + 39 * d[1] - 7 * d[2] + d[3] / 2
    c6 = 70 * d[0] - 34 * d[1] + 6.5 * d[2] - d[3] / 2
    c7 = -20 * d[0] + 10 * d[1] - 2 * d[2] + d[3] / 6
    return (*a, c4, c5, c6, c7)


def solve_generic(degree: int, s0: float, lift: float, span: float,
                  prev_end: np.ndarray, next_start: np.ndarray) -> tuple[float, ...]:
    """Coefficients of a generic 5th/7th-degree segment from its neighbours.

    ``prev_end`` and ``next_start`` are the neighbours' ``S, S′, S″, S‴`` (per
    unit x); S itself is taken from ``s0`` and ``s0 + lift``.
    """
    m = 3 if degree == 5 else 4
    start = [s0, *prev_end[1:m]]
    end = [s0 + lift, *next_start[1:m]]
    return hermite_coefficients(start, end, span)


@dataclass(frozen=True)
class Peak:
    """Extremes of one quantity over the cycle (x in the program's unit)."""

    max: float
    min: float
    at_max: float
    at_min: float


@dataclass(frozen=True)
class Junction:
    """Continuity at a breakpoint.

    ``order`` is the highest derivative order k such that S…S⁽ᵏ⁾ are all
    continuous (−1 if S itself jumps); ``jumps`` holds |right − left| for
    S, S′, S″, S‴.
    """

    at: float
    order: int
    jumps: tuple[float, float, float, float]
    segment: int | None  # index of the segment starting here; None for internal breaks

    @property
    def continuity(self) -> str:
        return f"C{self.order}" if self.order >= 0 else "discontinuous"


@dataclass(frozen=True)
class MotionProgram:
    """A closed chain of resolved segments.  See the module docstring."""

    segments: tuple[Segment, ...]
    period: float = TWO_PI
    #: what x is (cam angle or travel) and the unit of S (mm or degrees)
    axis: Axis = ROTATING_MM
    _starts: np.ndarray = field(init=False, repr=False, compare=False)
    _tab: "_Tables" = field(init=False, repr=False, compare=False)
    _memo: dict = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "_starts", np.array([s.start for s in self.segments]))
        object.__setattr__(self, "_tab", _Tables(self.segments))
        object.__setattr__(self, "_memo", {})  # results of the analyses (the program is immutable)

    # ---- construction -------------------------------------------------
    @classmethod
    def from_segments(cls, rows: Iterable[Sequence], *, unit: str = "deg",
                      period: float | None = None, lift_unit: str = "mm") -> "MotionProgram":
        """Build from ``(law, lift, span[, shape])`` rows; span in degrees by default.

        ``unit="rad"`` takes spans in radians; ``unit="mm"`` builds a
        translating-cam program whose period is the sum of the spans (or
        ``period``).  A span of ``None`` is solved (half-period laws).  ``lift_unit``: "mm", or
        "deg" for an oscillating follower.
        """
        scale = {"deg": math.pi / 180.0, "rad": 1.0, "mm": 1.0}[unit]
        inputs = []
        for row in rows:
            law, lift, span, *rest = row
            inputs.append(SegmentInput(law, float(lift), None if span is None else float(span) * scale,
                                       rest[0] if rest else None))
        if period is None:
            period = TWO_PI if unit != "mm" else sum(i.span or 0.0 for i in inputs)
        return build_program(inputs, period=period, unit=unit, lift_unit=lift_unit)

    # ---- evaluation ---------------------------------------------------
    @property
    def junctions_x(self) -> np.ndarray:
        """Segment junctions in x, from 0 to :attr:`period` inclusive."""
        return np.append(self._starts, self.period)

    @property
    def breakpoints(self) -> np.ndarray:
        """Every point where a formula changes: junctions and internal law breaks."""
        pts = [self.junctions_x]
        for s in self.segments:
            if s.breaks:
                pts.append(s.start + s.span * np.asarray(s.breaks))
        return np.unique(np.concatenate(pts))

    def segment_index(self, x: np.ndarray) -> np.ndarray:
        """Index of the segment containing each ``x`` (already reduced to [0, period))."""
        idx = np.searchsorted(self._starts, x, side="right") - 1
        return np.clip(idx, 0, len(self.segments) - 1)

    def evaluate(self, x, orders: Sequence[int] = (0, 1, 2, 3)) -> np.ndarray:
        """S and its derivatives at ``x``.

        Parameters
        ----------
        x : (n,) float array or float
            Cam angle in radians (or travel in mm); any real value, the program
            is periodic.  A point on a junction takes the segment that starts there.
        orders : sequence of int
            Which derivatives to return (0 = S … 3 = S‴; 4 is available too).

        Returns
        -------
        (len(orders), n) float array
            Derivatives per unit of x (per radian or per mm).
        """
        xa = np.atleast_1d(np.asarray(x, dtype=float))
        xr = np.mod(xa, self.period)
        idx = self.segment_index(xr)
        out = np.empty((len(orders), xr.size))
        tab = self._tab
        if xr.size <= _GROUPED_MAX * len(self.segments):
            # few samples per segment: one pass per *kind* of segment (law), all its segments at
            # once with per-sample parameters, instead of one per segment and order
            tab.grouped(xr, idx, orders, out, xr.size <= _UNIFORM_MAX * len(self.segments))
            return out
        # many samples per segment: group the samples by segment (stable counting sort) and
        # visit only the segments hit, with scalar parameters
        order = np.argsort(idx.astype(np.int16), kind="stable")
        bounds = np.searchsorted(idx[order], np.arange(len(self.segments) + 1))
        for k in np.flatnonzero(bounds[1:] > bounds[:-1]):
            sel = order[bounds[k]:bounds[k + 1]]
            tab.segment(k, xr[sel], orders, out, sel)
        return out

    def __call__(self, x, nu: int = 0) -> np.ndarray:
        """The ``nu``-th derivative of S at ``x`` (vectorised, periodic)."""
        return self.evaluate(x, (nu,))[0]

    # ---- analysis -----------------------------------------------------
    def junctions(self, *, rel_tol: float | None = None, internal: bool = False) -> list[Junction]:
        """Continuity at every segment junction (360°→0° included, listed first).

        A jump counts as a discontinuity when it exceeds ``rel_tol`` times the
        peak magnitude of that derivative over the cycle (at least 1e-9 in
        absolute terms).  With ``internal=True`` the internal breakpoints of
        piecewise laws are included.
        """
        from ..tolerances import CONTINUITY_REL_TOL

        tol = CONTINUITY_REL_TOL if rel_tol is None else rel_tol
        key = ("junctions", tol, internal)
        if key not in self._memo:
            self._memo[key] = self._junctions(tol, internal)
        return list(self._memo[key])

    def _junctions(self, tol: float, internal: bool) -> list[Junction]:
        scale = [max(abs(p.max), abs(p.min), 1e-2) for p in self.peaks("exact")]
        out = []
        n = len(self.segments)
        for k, seg in enumerate(self.segments):
            left = self.segments[k - 1].end_values(True)
            right = seg.end_values(False)
            out.append(self._junction(seg.start, left, right, scale, tol, k))
            if internal:
                for ub in seg.breaks:
                    lo, hi = np.nextafter(ub, -1.0), np.nextafter(ub, 2.0)
                    left = np.array([seg.value_at(float(lo), j) for j in range(4)])
                    right = np.array([seg.value_at(float(hi), j) for j in range(4)])
                    out.append(self._junction(seg.start + ub * seg.span, left, right, scale, tol, None))
        del n
        return sorted(out, key=lambda j: j.at)

    @staticmethod
    def _junction(at, left, right, scale, tol, seg) -> Junction:
        jumps = np.abs(right - left)
        order = 3
        for j in range(4):
            if jumps[j] > tol * scale[j] + 1e-12:
                order = j - 1
                break
        return Junction(at, order, tuple(float(v) for v in jumps), seg)

    def peaks(self, mode: str = "exact", *, step: float | None = None) -> tuple[Peak, Peak, Peak, Peak]:
        """Extremes of S, S′, S″, S‴ over the cycle (per unit x).

        ``mode="exact"`` finds the analytic extrema: piece end values (one-sided
        at junctions, so a jerk jump reports the value on the segment side) and
        interior zeros of the next derivative, located to ~1e-12 in u.
        ``mode="camdas"`` reproduces CAM-DAS: samples every ``step`` (default
        1°, or 1 mm for translating cams) from 0 to the period inclusive, a
        sample on a junction counted on both sides.
        """
        if mode == "exact":  # computed once (the program is immutable; Peak is frozen)
            if "peaks" not in self._memo:
                self._memo["peaks"] = tuple(_exact_peak(self, nu) for nu in range(4))
            return self._memo["peaks"]  # type: ignore[return-value]
        if mode == "camdas":
            if step is None:
                step = math.pi / 180.0 if self.axis.rotating else 1.0
            return _sampled_peaks(self, step)
        raise ValueError(f"'{mode}' is not a valid peaks mode, must be one of: exact, camdas")


# ---------------------------------------------------------------------------
# fast evaluation
#: at most this many samples per segment (on average) are evaluated law by law, not segment by segment
_GROUPED_MAX = 256
#: at most this many per segment: one pass for all the segments of the common laws (see _Tables.grouped)
_UNIFORM_MAX = 16
_DWELL, _POLY, _LAW, _LAWPOLY, _TRIG, _UNIFORM = 0, 1, 2, 3, 4, 5


class _Tables:
    """Per-segment parameters of a program in arrays, for :meth:`MotionProgram.evaluate`.

    The arithmetic is :meth:`Segment.values`' operation for operation (so the results are
    bit-identical): ``(L·f⁽ᵛ⁾(u) + s0)`` for ν = 0 and ``L·f⁽ᵛ⁾(u) / βᵛ`` otherwise for a
    standard law, ``p⁽ᵛ⁾(u) / βᵛ`` (Horner) for a polynomial segment, ``u = (x − x0)/β``.
    """

    def __init__(self, segs: Sequence[Segment]):
        self.segs = segs
        self.start = np.array([s.start for s in segs], dtype=float)
        self.span = np.array([s.span for s in segs], dtype=float)
        self.lift = np.array([s.lift for s in segs], dtype=float)
        self.s0 = np.array([s.s0 for s in segs], dtype=float)
        # kind of each segment: dwell, polynomial (coefficients), or a law (key = its name)
        keys: list = []
        self.kind: list[tuple[int, object]] = []
        gid = []
        ukeys: list = []
        self.ukind: list[tuple[int, object]] = []
        ugid = []
        for s in segs:
            if s.coeffs is not None:
                key, kind = "#poly", (_POLY, None)
            elif s.law == "dwell":
                key, kind = "#dwell", (_DWELL, None)
            elif hasattr(LAWS[s.law].shape, "coeffs"):  # polynomial laws, together
                key, kind = "#lawpoly", (_LAWPOLY, None)
            elif s.law in TRIG1:
                key, kind = s.law, (_TRIG, s.law)
            else:
                key, kind = s.law, (_LAW, LAWS[s.law].shape)
            if key not in keys:
                keys.append(key)
                self.kind.append(kind)
            gid.append(keys.index(key))
            # the uniform grouping (few samples): dwells, polynomial and trigonometric laws together
            if kind[0] in (_DWELL, _LAWPOLY, _TRIG):
                key, kind = "#uniform", (_UNIFORM, None)
            if key not in ukeys:
                ukeys.append(key)
                self.ukind.append(kind)
            ugid.append(ukeys.index(key))
        self.gid = np.array(gid, dtype=np.int8 if len(keys) < 127 else np.int16)
        self.ngroups = len(keys)
        self.ugid = np.array(ugid, dtype=np.int8 if len(ukeys) < 127 else np.int16)
        self.nugroups = len(ukeys)
        self._pow: dict[int, np.ndarray] = {}
        self._dwell: dict[int, tuple] = {}
        self._coef: dict[int, np.ndarray] = {}

    def spanpow(self, nu: int) -> np.ndarray:
        """βᵛ per segment (as ``Segment.values`` computes it)."""
        p = self._pow.get(nu)
        if p is None:
            p = self._pow[nu] = np.array([s.span**nu for s in self.segs], dtype=float)
        return p

    def dwell(self, nu: int) -> tuple:
        """The constant value of S⁽ᵛ⁾ on each dwell segment (scalars, and as an array)."""
        d = self._dwell.get(nu)
        if d is None:
            vals = [((s.lift * 0.0) + s.s0) if nu == 0 else (s.lift * 0.0) / s.span**nu for s in self.segs]
            d = self._dwell[nu] = (vals, np.array(vals, dtype=float))
        return d

    def coef(self, nu: int) -> np.ndarray:
        """(n_segments, width) ascending coefficients of p⁽ᵛ⁾ of the polynomial segments (or of
        f⁽ᵛ⁾ of the polynomial laws), padded with high-order zeros (which leave Horner's rule
        exact), zero rows elsewhere."""
        c = self._coef.get(nu)
        if c is None:
            rows = []
            for s in self.segs:
                if s.coeffs is not None:
                    rows.append(s._dcoeffs[nu])
                elif s.law in LAWS and hasattr(LAWS[s.law].shape, "coeffs"):
                    rows.append(LAWS[s.law].shape.coeffs[nu])
                else:
                    rows.append((0.0,))
            c = np.zeros((len(rows), max(len(r) for r in rows)))
            for i, r in enumerate(rows):
                c[i, :len(r)] = r
            self._coef[nu] = c
        return c

    def uniform(self, orders) -> tuple:
        """Tables of the uniform formula for ``orders``: ``f⁽ᵛ⁾(u) = a·sin(w·u + φ) + p(u)``
        (dwell: a = w = φ = 0, p = 0; polynomial law: a = 0; single-term trigonometric law:
        p = what it adds at ν = 0, 1).  Returns (C (orders, segments, width), a (orders,
        segments), w (segments), φ (orders, segments), βᵛ (orders, segments))."""
        key = ("uniform", tuple(orders))
        hit = self._coef.get(key)  # type: ignore[call-overload]
        if hit is None:
            segs = self.segs
            rows, amp, ph = [], np.zeros((len(orders), len(segs))), np.zeros((len(orders), len(segs)))
            w = np.zeros(len(segs))
            for r, nu in enumerate(orders):
                row = []
                for i, s in enumerate(segs):
                    law = s.law if s.coeffs is None else None
                    if law in TRIG1:
                        kind, wi, a, add0, add1 = TRIG1[law]
                        w[i] = wi
                        amp[r, i] = a * wi**nu
                        ph[r, i] = {"s": 0.0, "c": math.pi / 2}[kind] + nu * math.pi / 2
                        add = add0 if nu == 0 else add1 if nu == 1 else None
                        row.append((0.0, 1.0) if add == "u" else (0.0,) if add is None else (float(add),))
                    elif law is not None and law != "dwell" and hasattr(LAWS[law].shape, "coeffs"):
                        row.append(LAWS[law].shape.coeffs[nu])
                    else:
                        row.append((0.0,))
                rows.append(row)
            width = max(len(c) for row in rows for c in row)
            C = np.zeros((len(orders), len(segs), width))
            for r, row in enumerate(rows):
                for i, c in enumerate(row):
                    C[r, i, :len(c)] = c
            D = np.array([self.spanpow(nu) if nu < 6 else np.array([s.span**nu for s in segs]) for nu in orders])
            hit = self._coef[key] = (C, amp, w, ph, D)  # type: ignore[index]
        return hit

    def dwells(self, orders) -> np.ndarray:
        """(len(orders), n_segments) :meth:`dwell` values."""
        key = ("dwell", tuple(orders))
        hit = self._coef.get(key)  # type: ignore[call-overload]
        if hit is None:
            hit = self._coef[key] = np.array([self.dwell(nu)[1] for nu in orders])  # type: ignore[index]
        return hit

    def stacked(self, orders) -> tuple[np.ndarray, np.ndarray]:
        """(len(orders), n_segments, width) :meth:`coef` and (len(orders), n_segments) βᵛ."""
        key = tuple(orders)
        hit = self._coef.get(key)
        if hit is None:
            cs = [self.coef(nu) for nu in key]
            w = max(c.shape[1] for c in cs)
            C = np.zeros((len(cs), cs[0].shape[0], w))
            for r, c in enumerate(cs):
                C[r, :, :c.shape[1]] = c
            D = np.array([self.spanpow(nu) if nu < 6 else np.array([s.span**nu for s in self.segs])
                          for nu in key])
            hit = self._coef[key] = (C, D)  # type: ignore[index]
        return hit

    def segment(self, k: int, x: np.ndarray, orders, out: np.ndarray, sel) -> None:
        """``out[:, sel]`` = the orders of segment k at x (its samples, already reduced)."""
        seg = self.segs[k]
        kind, shape = self.kind[self.gid[k]]
        if kind == _DWELL:
            for row, nu in enumerate(orders):
                out[row, sel] = self.dwell(nu)[0][k]
            return
        u = x
        u -= seg.start
        u /= seg.span
        if kind in (_LAWPOLY, _TRIG):
            shape = LAWS[seg.law].shape
        for row, nu in enumerate(orders):
            if kind == _POLY:
                v = horner(seg._dcoeffs[nu], u)
            else:
                v = shape(u, nu)
                v = seg.lift * v
                if nu == 0:
                    v += seg.s0
            if nu != 0:
                v /= self.spanpow(nu)[k] if nu < 6 else seg.span**nu
            out[row, sel] = v

    def _lifted(self, v: np.ndarray, si: np.ndarray, orders) -> np.ndarray:
        """Rows of a normalised law (per order) scaled by the segments' lifts, S0 added to the ν = 0 row."""
        v = self.lift[si] * v
        for row, nu in enumerate(orders):
            if nu == 0:
                v[row] += self.s0[si]
        return v

    def grouped(self, xr: np.ndarray, idx: np.ndarray, orders, out: np.ndarray, uniform: bool = False) -> None:
        """``out`` = the orders at every xr (segment indices idx), one pass per kind (with
        ``uniform``, one for all dwells, polynomial and single-term trigonometric laws: fewest
        operations, but each sample pays for a sine and the longest polynomial)."""
        if uniform and not np.isfinite(xr).all():
            uniform = False  # the uniform formula would turn a dwell's value at NaN into NaN
        gids, kinds = (self.ugid, self.ukind) if uniform else (self.gid, self.kind)
        if len(kinds) == 1:
            parts = [(0, slice(None))]
        else:
            key = gids[idx]
            order = np.argsort(key, kind="stable")
            bounds = np.searchsorted(key[order], np.arange(len(kinds) + 1))
            parts = [(g, order[bounds[g]:bounds[g + 1]]) for g in range(len(kinds)) if bounds[g + 1] > bounds[g]]
        for g, sel in parts:
            kind, shape = kinds[g]
            si = idx[sel]
            if kind == _DWELL:
                out[:, sel] = self.dwells(orders)[:, si]
                continue
            u = (xr[sel] - self.start[si]) / self.span[si]
            if kind == _UNIFORM:  # dwells, polynomial and single-term trigonometric laws, every order at once
                C, amp, w, ph, D = self.uniform(orders)
                v = _horner_per_sample(C[:, si, :], u)
                # the law's own order of operations: trig term first, then what it adds (p)
                v = amp[:, si] * np.sin(w[si] * u + ph[:, si]) + v
                v = self._lifted(v, si, orders)
                v /= D[:, si]  # 1 for ν = 0: exact
                out[:, sel] = v
                continue
            if kind in (_LAWPOLY, _POLY, _TRIG):  # every order at once
                C, D = self.stacked(orders)
                v = trig_rows(shape, orders, u) if kind == _TRIG else _horner_per_sample(C[:, si, :], u)
                if kind != _POLY:
                    v = self._lifted(v, si, orders)
                v /= D[:, si]  # 1 for ν = 0: exact
                out[:, sel] = v
                continue
            if kind == _LAW:
                lift = self.lift[si]
            for row, nu in enumerate(orders):
                if kind == _POLY:
                    v = _horner_per_sample(self.coef(nu)[si], u)
                else:
                    v = lift * shape(u, nu)
                    if nu == 0:
                        v += self.s0[si]
                if nu != 0:
                    v /= self.spanpow(nu)[si] if nu < 6 else np.array([s.span**nu for s in self.segs])[si]
                out[row, sel] = v


def _horner_per_sample(c: np.ndarray, u: np.ndarray) -> np.ndarray:
    """Σ c[..., j]·uʲ by Horner, with per-sample coefficients ``c`` (…, n, degree + 1)."""
    v = c[..., -1] + u * 0.0
    for j in range(c.shape[-1] - 2, -1, -1):
        v = c[..., j] + v * u
    return v


# ---------------------------------------------------------------------------
# exact and sampled extrema
def _pieces(seg: Segment) -> list[tuple[float, float]]:
    edges = [0.0, *seg.breaks, 1.0]
    return list(zip(edges[:-1], edges[1:]))


def _critical_points(seg: Segment, nu: int, lo: float, hi: float) -> list[float]:
    """Zeros of S^(nu+1) strictly inside (lo, hi) where it changes sign."""
    if seg.coeffs is not None:  # polynomial: exact real roots
        c = np.polynomial.polynomial.polyder(seg.coeffs, nu + 1)
        if not np.any(c):
            return []
        r = np.polynomial.polynomial.polyroots(np.trim_zeros(c, "b")) if len(np.trim_zeros(c, "b")) > 1 else []
        return [float(z.real) for z in np.atleast_1d(r) if abs(z.imag) < 1e-9 and lo < z.real < hi]
    if seg.law == "dwell" or seg.lift == 0:
        # constant: every point is a (non-strict) extremum, but none comes before the piece's
        # start, which is a candidate already with the same value — the peaks are unchanged
        return []
    # a standard law's critical points in u do not depend on its lift or span: found once per law
    key = (seg.law, nu, float(lo), float(hi), seg.lift > 0)
    if key not in _LAW_CRITICAL:
        _LAW_CRITICAL[key] = tuple(_law_critical_points(seg, nu, lo, hi))
    return list(_LAW_CRITICAL[key])


#: critical points (u) of the standard laws, keyed by (law, order, piece bounds, sign of the lift)
_LAW_CRITICAL: dict = {}


def _law_critical_points(seg: Segment, nu: int, lo: float, hi: float) -> list[float]:
    from scipy.optimize import brentq

    coeffs = getattr(LAWS[seg.law].shape, "coeffs", None)
    if coeffs is not None:  # polynomial law: Horner in Python floats, operation for operation as du()
        c, lift = coeffs[nu + 1], seg.lift

        def d(t):
            out = c[-1] + t * 0.0
            for ci in c[-2::-1]:
                out = ci + out * t
            return lift * out
    else:
        def d(t):
            return float(seg.du(np.array([t]), nu + 1)[0])

    grid = np.linspace(lo, hi, 129)
    vals = seg.du(grid, nu + 1)
    # at a flat end (derivative exactly 0) take the sign just inside, so an extremum in the
    # first or last cell is still bracketed
    inner = 1e-9 * (hi - lo)
    if vals[0] == 0.0:
        grid[0], vals[0] = lo + inner, d(lo + inner)
    if vals[-1] == 0.0:
        grid[-1], vals[-1] = hi - inner, d(hi - inner)
    sgn = np.sign(vals)
    out = list(grid[1:-1][sgn[1:-1] == 0])
    for i in np.flatnonzero(sgn[:-1] * sgn[1:] < 0):
        out.append(brentq(d, grid[i], grid[i + 1], xtol=1e-15, rtol=4 * np.finfo(float).eps))
    return out


def _segment_candidates(seg: Segment, nu: int) -> tuple[np.ndarray, np.ndarray]:
    """Local coordinates u and values of every extremum candidate of S^(nu) in a segment."""
    if seg.coeffs is None:
        # a standard law's candidates u and f⁽ᵛ⁾ there depend only on the law and the sign of
        # the lift: taken once; the values then as Segment.values computes them from f⁽ᵛ⁾
        key = (seg.law, nu, (seg.lift > 0) - (seg.lift < 0))
        hit = _LAW_CANDIDATES.get(key)
        if hit is None:
            u = _candidate_us(seg, nu)
            f = LAWS[seg.law](u, nu)
            u.setflags(write=False)
            hit = _LAW_CANDIDATES[key] = (u, f)
        u, f = hit
        out = seg.lift * f
        if nu == 0:
            out = out + seg.s0
        return u, out / seg.span**nu
    u = _candidate_us(seg, nu)
    return u, seg.values(u, nu)


#: (u, f⁽ᵛ⁾(u)) of the extremum candidates of the standard laws, by (law, ν, sign of the lift)
_LAW_CANDIDATES: dict = {}


def _candidate_us(seg: Segment, nu: int) -> np.ndarray:
    us: list[float] = []
    for ua, ub in _pieces(seg):
        lo = np.nextafter(ua, 2.0) if ua > 0 else ua
        hi = np.nextafter(ub, -1.0) if ub < 1 else ub
        us += [lo, hi, *_critical_points(seg, nu, lo, hi)]
    return np.asarray(us, dtype=float)


def _exact_peak(prog: MotionProgram, nu: int) -> Peak:
    xs, vals = [], []
    for seg in prog.segments:
        u, v = _segment_candidates(seg, nu)
        xs.append(seg.start + u * seg.span)
        vals.append(v)
    return _pick(np.concatenate(xs), np.concatenate(vals))


def _pick(xs: np.ndarray, vals: np.ndarray) -> Peak:
    order = np.argsort(xs, kind="stable")
    xs, vals = xs[order], vals[order]
    span = float(vals.max() - vals.min())
    tol = 1e-12 * max(span, abs(float(vals.max())), 1.0)
    imax = int(np.flatnonzero(vals >= vals.max() - tol)[0])
    imin = int(np.flatnonzero(vals <= vals.min() + tol)[0])
    return Peak(float(vals[imax]), float(vals[imin]), float(xs[imax]), float(xs[imin]))


def _sampled_peaks(prog: MotionProgram, step: float) -> tuple[Peak, ...]:
    n = int(round(prog.period / step))
    grid = np.arange(n + 1) * step
    xs, vals = [], []
    eps = 1e-9 * step
    for seg in prog.segments:
        sel = grid[(grid >= seg.start - eps) & (grid <= seg.end + eps)]
        u = np.clip((sel - seg.start) / seg.span, 0.0, 1.0)
        xs.append(sel)
        vals.append(np.array([seg.values(u, k) for k in range(4)]))
    x = np.concatenate(xs)
    v = np.concatenate(vals, axis=1)
    return tuple(_pick(x, v[k]) for k in range(4))


# ---------------------------------------------------------------------------
# validation and resolution
def _half_period_span(name: str, lift: float, slope: float) -> float:
    """Span that gives a half-period law the neighbour's slope at its moving end."""
    return HALF_PERIOD[name][1] * lift / slope


def build_program(inputs: Sequence[SegmentInput], *, period: float = TWO_PI, unit: str = "rad",
                  path: str = "motion", source: str | None = None, lift_unit: str = "mm") -> MotionProgram:
    """Validate segment inputs and resolve them into a :class:`MotionProgram`.

    Every rule of the CAM-DAS data entry (spec motion-laws §2, §3, §5.4, §5.9)
    is checked and **all** problems are reported together in one
    :class:`~camfab.errors.SpecError`, each naming its field path
    (``motion[3].angle_deg``), the value, the rule and a fix.
    """
    problems: list[Problem] = []
    n = len(inputs)
    span_key = "length_mm" if unit == "mm" else "angle_deg"
    to_user = (lambda v: v) if unit == "mm" else math.degrees
    if n == 0:
        raise SpecError(Problem(path, [], "the program has no segments",
                                "add [[motion]] segments whose spans sum to the cycle"), source)
    known = set(law_names())
    for i, s in enumerate(inputs):
        p = f"{path}[{i}]"
        if s.law not in known:
            problems.append(Problem(f"{p}.law", s.law, "unknown motion law",
                                    "use one of: " + ", ".join(sorted(known))))
        if not math.isfinite(s.lift):
            problems.append(Problem(f"{p}.lift", s.lift, "lift must be a finite number", "give the lift in mm or degrees"))
        elif abs(s.lift) > 1e5:
            problems.append(Problem(f"{p}.lift", s.lift, "lift magnitude is absurd (> 1e5)",
                                    "check the units: lift is in mm (translating) or degrees (oscillating)"))
        if s.span is None:
            if s.law not in HALF_PERIOD:
                problems.append(Problem(f"{p}.{span_key}", "auto", "only half-period laws can solve their span",
                                        f"give {span_key} for a '{s.law}' segment"))
            elif s.lift == 0:  # lift 0 = dwell: no slope to match
                problems.append(Problem(f"{p}.{span_key}", "auto",
                                        "a half-period segment with lift 0 is a dwell, which has no span to solve",
                                        f"give {span_key} or a non-zero lift"))
        elif not math.isfinite(s.span) or s.span <= 0:
            problems.append(Problem(f"{p}.{span_key}", to_user(s.span) if math.isfinite(s.span) else s.span,
                                    "segment span must be a finite number > 0", f"give a positive {span_key}"))
        if s.shape is not None and (s.law != "double_harmonic" or s.shape not in ("rise", "return")):
            problems.append(Problem(f"{p}.shape", s.shape, "shape applies to double_harmonic only, as 'rise' or 'return'",
                                    "remove it or fix its value"))
    if problems:
        raise SpecError(problems, source)

    laws = [get_law(s.law, s.lift, s.shape).name if s.law not in GENERIC else s.law for s in inputs]
    generic = [lw in GENERIC for lw in laws]
    if inputs[0].lift < 0:
        problems.append(Problem(f"{path}[0].lift", inputs[0].lift, "the first segment cannot be a return",
                                "start the program with a rise or a dwell (rotate the program)"))
    for i in range(n):
        if generic[i] and generic[(i + 1) % n]:
            j = (i + 1) % n
            problems.append(Problem(f"{path}[{j}].law", inputs[j].law,
                                    f"two generic polynomials may not be adjacent ({path}[{i}] and {path}[{j}], cyclically)",
                                    "put a standard law between them"))

    # spans: solve half-period 'auto' spans from the neighbour's slope, check given ones
    spans = [s.span for s in inputs]
    for i, s in enumerate(inputs):
        if laws[i] not in HALF_PERIOD:
            continue
        end, _ = HALF_PERIOD[laws[i]]
        j = (i - 1) % n if end == "start" else (i + 1) % n
        p = f"{path}[{i}]"
        if generic[j]:
            if s.span is None:
                problems.append(Problem(f"{p}.{span_key}", "auto", "cannot solve the span next to a generic polynomial",
                                        f"give {span_key} explicitly"))
            continue
        nb = inputs[j]
        if nb.span is None:
            problems.append(Problem(f"{p}.{span_key}", "auto",
                                    f"its neighbour {path}[{j}] also has an unknown span", "give one of the two spans"))
            continue
        nseg = Segment(laws[j], nb.lift, nb.span, 0.0, 0.0)
        slope = nseg.end_values(end == "start")[1]
        side = "previous" if end == "start" else "next"
        if slope == 0 or (s.lift != 0 and np.sign(slope) != np.sign(s.lift)):
            problems.append(Problem(f"{p}.law", s.law,
                                    f"a half-period law needs its {side} segment ({path}[{j}], "
                                    f"slope {slope:.6g}/unit) to move in the same direction",
                                    "put a constant-velocity (or other moving) segment of the same sense beside it"))
            continue
        need = _half_period_span(laws[i], s.lift, slope)
        if s.span is None:
            spans[i] = need
        elif abs(need - s.span) > 1e-9 * max(need, 1e-9):
            problems.append(Problem(f"{p}.{span_key}", to_user(s.span),
                                    f"the velocity does not match the {side} segment ({path}[{j}])",
                                    f"set {span_key} = {to_user(need):.12g} or \"auto\""))
    if problems:
        raise SpecError(problems, source)

    total = sum(spans)  # type: ignore[arg-type]
    tol = ANGLE_SUM_TOL_DEG if unit != "mm" else 1e-9
    if abs(to_user(total) - to_user(period)) > tol:
        problems.append(Problem(f"{path}[*].{span_key}", round(to_user(total), 12),
                                f"segment spans must sum to {to_user(period):.12g}",
                                f"change the spans by {to_user(period - total):+.12g} in total"))
    net = sum(s.lift for s in inputs)
    if abs(net) > 1e-9 * max(1.0, max(abs(s.lift) for s in inputs)):
        problems.append(Problem(f"{path}[*].lift", round(net, 12), "lifts must sum to 0 so the cycle closes",
                                f"change the lifts by {-net:+.12g} in total"))
    if problems:
        raise SpecError(problems, source)

    # resolve standard segments (starts scaled so the spans close the period exactly)
    k = period / total
    spans = [sp * k for sp in spans]  # type: ignore[operator]
    starts = np.concatenate([[0.0], np.cumsum(spans)[:-1]])
    s0 = np.concatenate([[0.0], np.cumsum([s.lift for s in inputs])[:-1]])
    segs: list[Segment] = [
        Segment(laws[i], inputs[i].lift, spans[i], float(starts[i]), float(s0[i]), None,
                LAWS[laws[i]].title if laws[i] in LAWS else f"Generic {GENERIC[laws[i]]}th-degree polynomial")
        for i in range(n)
    ]
    for i in range(n):
        if generic[i]:
            prev_end = segs[(i - 1) % n].end_values(True)
            next_start = segs[(i + 1) % n].end_values(False)
            if n == 1:
                prev_end = next_start = np.zeros(4)
            c = solve_generic(GENERIC[laws[i]], segs[i].s0, segs[i].lift, segs[i].span, prev_end, next_start)
            segs[i] = Segment(laws[i], segs[i].lift, segs[i].span, segs[i].start, segs[i].s0, c, segs[i].title)
    axis = (TRANSLATING_MM if unit == "mm" else ROTATING_MM).with_lift(LiftUnit(lift_unit))
    prog = MotionProgram(tuple(segs), period, axis)

    for i, seg in enumerate(prog.segments):
        u, v = _segment_candidates(seg, 0)
        k = int(np.argmin(v))
        tol_s = 1e-9 * max(1.0, abs(seg.s0), abs(seg.s0 + seg.lift))
        if v[k] < -tol_s and seg.s0 >= -tol_s:  # report where S goes below 0, not where it stays there
            at = seg.start + u[k] * seg.span
            problems.append(Problem(f"{path}[{i}]", round(float(v[k]), 9),
                                    f"S goes below 0 (to {v[k]:.6g} at {to_user(at):.6g}); the follower would "
                                    "cross the base/prime circle",
                                    "reduce the return, or change the law or the neighbours of a generic polynomial"))
    if problems:
        raise SpecError(problems, source)
    return prog
