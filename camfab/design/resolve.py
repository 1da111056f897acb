"""Validation and resolution of segment inputs into the segments of a motion program.

Every rule of the CAM-DAS data entry is checked and **all** problems are reported
together, each naming its field path (``motion[3].angle_deg``), the value, the rule and a
fix.  Rules 1–3 are judged in one pass (a chain or closure rule wherever the segments it
involves are valid); rule 4 needs the resolved motion, so it waits for 1–3 to pass:

0. at most :data:`~camfab.limits.MAX_SEGMENTS` segments (``docs/decisions.md``, "Input limits");
1. each segment alone: a known law, a finite and sensible lift (0 for a dwell), a positive span (or
   ``"auto"`` for a half-period law with a lift), a double-harmonic ``shape``;
2. the chain: the first segment is not a return; two generic polynomials are adjacent
   (cyclically) only when the first gives the joint's free values ``end_v``, ``end_a`` (and
   ``end_j`` where a poly7 meets the joint), since each is solved from its neighbours' S, S′, S″
   (S‴); those keys are refused where the next segment is a standard law (its values rule);
   a half-period law's moving end matches its neighbour's slope — its span is solved from
   it (``"auto"``) or must agree with it;
3. closure: the spans sum to the period (to 1e-9° or 1e-9 mm) and the lifts to 0;
4. the resolved motion: S never goes below 0 (the follower would cross the base or
   prime circle), generic polynomials included.
"""
from __future__ import annotations

import math
from collections.abc import Callable, Sequence

import numpy as np

from ..errors import Problem, SpecError
from ..limits import MAX_LIFT_MM, MAX_SEGMENTS
from ..records import dataclass
from ..tolerances import ANGLE_SUM_TOL_DEG
from .extrema import segment_candidates
from .laws import GENERIC, HALF_PERIOD, LAWS, get_law, law_names
from .segment import Segment, solve_generic

__all__ = ["SegmentInput", "resolve_segments", "END_KEYS"]

#: a generic polynomial's joint values with a generic next segment: S′, S″, S‴ at its end
END_KEYS = ("end_v", "end_a", "end_j")


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
    ends : tuple of 3 (float or None)
        A generic polynomial's S′, S″, S‴ at its end (per unit x: per radian, or per mm of a translating cam),
        given where the next segment is a generic polynomial too (``end_v``, ``end_a``, ``end_j``); None: not
        given, NaN: given but already reported.
    """

    law: str
    lift: float
    span: float | None
    shape: str | None = None
    ends: tuple[float | None, float | None, float | None] = (None, None, None)


@dataclass(frozen=True)
class _Context:
    """Where the inputs come from and in which unit the user wrote the spans."""

    path: str
    unit: str
    source: str | None

    @property
    def span_key(self) -> str:
        return "length_mm" if self.unit == "mm" else "angle_deg"

    @property
    def to_user(self) -> Callable[[float], float]:
        return (lambda v: v) if self.unit == "mm" else math.degrees

    def raise_if(self, problems: list[Problem]) -> None:
        if problems:
            raise SpecError(problems, self.source)


# ---- 1. each segment alone
def _law_problems(i: int, s: SegmentInput, ctx: _Context) -> list[Problem]:
    known = set(law_names())
    if s.law in known:
        return []
    return [Problem(f"{ctx.path}[{i}].law", s.law, "unknown motion law", "use one of: " + ", ".join(sorted(known)))]


def _lift_problems(i: int, s: SegmentInput, ctx: _Context) -> list[Problem]:
    p = f"{ctx.path}[{i}].lift"
    if not math.isfinite(s.lift):
        return [Problem(p, s.lift, "lift must be a finite number", "give the lift in mm or degrees")]
    if abs(s.lift) > MAX_LIFT_MM:
        return [Problem(p, s.lift, f"lift magnitude is absurd (> {MAX_LIFT_MM:g})",
                        "check the units: lift is in mm (translating) or degrees (oscillating)")]
    if s.law == "dwell" and s.lift != 0:  # the follower would step by the lift at the next junction
        return [Problem(p, s.lift, "a dwell does not move the follower",
                        "set lift = 0, or use a rise/return law for the motion")]
    return []


def _span_problems(i: int, s: SegmentInput, ctx: _Context) -> list[Problem]:
    p, key = f"{ctx.path}[{i}].{ctx.span_key}", ctx.span_key
    if s.span is None:
        if s.law not in HALF_PERIOD:
            return [Problem(p, "auto", "only half-period laws can solve their span",
                            f"give {key} for a '{s.law}' segment")]
        if s.lift == 0:  # lift 0 = dwell: no slope to match
            return [Problem(p, "auto", "a half-period segment with lift 0 is a dwell, which has no span to solve",
                            f"give {key} or a non-zero lift")]
        return []
    if not math.isfinite(s.span) or s.span <= 0:
        return [Problem(p, ctx.to_user(s.span) if math.isfinite(s.span) else s.span,
                        "segment span must be a finite number > 0", f"give a positive {key}")]
    return []


def _shape_problems(i: int, s: SegmentInput, ctx: _Context) -> list[Problem]:
    if s.shape is not None and (s.law != "double_harmonic" or s.shape not in ("rise", "return")):
        return [Problem(f"{ctx.path}[{i}].shape", s.shape,
                        "shape applies to double_harmonic only, as 'rise' or 'return'", "remove it or fix its value")]
    return []


def _end_problems(i: int, s: SegmentInput, ctx: _Context) -> list[Problem]:
    """The joint values are a generic polynomial's, and each alone moves the follower at most
    :data:`~camfab.limits.MAX_LIFT_MM` over the segment: |S⁽ᵏ⁾|·spanᵏ/k! (as a knot table's)."""
    given = [(k, e) for k, e in zip(END_KEYS, s.ends, strict=True) if e is not None]
    if not given:
        return []
    out = [Problem(f"{ctx.path}[{i}].{k}", e, "must be a finite number", "give S′, S″ or S‴ per radian")
           for k, e in given if not math.isfinite(e)]  # reported by the design's reading already: merged there
    given = [(k, e) for k, e in given if math.isfinite(e)]
    if s.law not in GENERIC:
        return [Problem(f"{ctx.path}[{i}].{k}", e, f"joint values belong to a generic polynomial (poly5, poly7), not "
                        f"to '{s.law}', whose end is fixed by its law", f"remove {k}") for k, e in given] + out
    for k, e in given:
        n = END_KEYS.index(k) + 1
        move = abs(e) * (s.span or 0.0) ** n / math.factorial(n) if s.span and math.isfinite(s.span) else 0.0
        if move > MAX_LIFT_MM:
            out.append(Problem(f"{ctx.path}[{i}].{k}", e, f"alone it would move the follower {move:.3g} over the "
                               f"segment, beyond the input limit of {MAX_LIFT_MM:g}",
                               "check the value and its unit (the lift's unit per radian, or per mm of travel)"))
    return out


_INPUT_RULES = (_law_problems, _lift_problems, _span_problems, _shape_problems, _end_problems)


# ---- 2. the chain
def _first_problems(inputs: Sequence[SegmentInput], ctx: _Context) -> list[Problem]:
    if inputs[0].lift < 0:
        return [Problem(f"{ctx.path}[0].lift", inputs[0].lift, "the first segment cannot be a return",
                        "start the program with a rise or a dwell (rotate the program)")]
    return []


_POWER = {"end_v": "", "end_a": "²", "end_j": "³"}


def _joint_keys(a: str, b: str) -> tuple[str, ...]:
    """The keys a joint of two generic polynomials needs: S′, S″, and S‴ where a poly7 meets it."""
    return END_KEYS if 7 in (GENERIC[a], GENERIC[b]) else END_KEYS[:2]


def _adjacent_generic_problems(inputs: Sequence[SegmentInput], laws: list[str], ctx: _Context) -> list[Problem]:
    n, out = len(inputs), []
    for i in range(n):
        j = (i + 1) % n
        if laws[i] not in GENERIC or laws[j] is None:
            continue
        given = {k for k, e in zip(END_KEYS, inputs[i].ends, strict=True) if e is not None}
        p = f"{ctx.path}[{i}]"
        if laws[j] not in GENERIC:
            out += [Problem(f"{p}.{k}", inputs[i].ends[END_KEYS.index(k)], f"the next segment {ctx.path}[{j}] "
                            f"('{inputs[j].law}') fixes the joint's values", f"remove {k}")
                    for k in END_KEYS if k in given]
            continue
        need = _joint_keys(laws[i], laws[j])
        if not given:
            out.append(Problem(f"{ctx.path}[{j}].law", inputs[j].law,
                               f"two generic polynomials may not be adjacent ({p} and {ctx.path}[{j}], "
                               "cyclically) unless the joint's values are given",
                               f"give {', '.join(need)} on {p} (the lift's unit per radian, per mm on a translating "
                               "cam), or put a standard law between them"))
            continue
        out += [Problem(f"{p}.{k}", None, f"is required: {p} and {ctx.path}[{j}] are generic polynomials "
                        "meeting there", f"give {k} (the lift's unit per radian{_POWER[k]}, "
                        f"per mm{_POWER[k]} on a translating cam)") for k in need if k not in given]
        out += [Problem(f"{p}.{k}", inputs[i].ends[END_KEYS.index(k)], "S‴ is free only where a poly7 meets the "
                        "joint", f"remove {k}") for k in END_KEYS if k in given and k not in need]
    return out


def _neighbour_slope(i: int, inputs: Sequence[SegmentInput], laws: list[str], ctx: _Context,
                     problems: list[Problem]) -> float | None:
    """The slope of the neighbour at a half-period segment's moving end, or None (and a
    problem when the span cannot be solved or checked)."""
    end, _ = HALF_PERIOD[laws[i]]
    j = (i - 1) % len(inputs) if end == "start" else (i + 1) % len(inputs)
    s, p, key = inputs[i], f"{ctx.path}[{i}]", ctx.span_key
    if laws[j] in GENERIC:
        if s.span is None:
            problems.append(Problem(f"{p}.{key}", "auto", "cannot solve the span next to a generic polynomial",
                                    f"give {key} explicitly"))
        return None
    nb = inputs[j]
    if nb.span is None:
        problems.append(Problem(f"{p}.{key}", "auto", f"its neighbour {ctx.path}[{j}] also has an unknown span",
                                "give one of the two spans"))
        return None
    slope = Segment(laws[j], nb.lift, nb.span, 0.0, 0.0).end_values(end == "start")[1]
    if slope == 0 or (s.lift != 0 and np.sign(slope) != np.sign(s.lift)):
        side = "previous" if end == "start" else "next"
        problems.append(Problem(f"{p}.law", s.law,
                                f"a half-period law needs its {side} segment ({ctx.path}[{j}], "
                                f"slope {slope:.6g}/unit) to move in the same direction",
                                "put a constant-velocity (or other moving) segment of the same sense beside it"))
        return None
    return slope


def _spans(inputs: Sequence[SegmentInput], laws: list[str], ctx: _Context,
           problems: list[Problem]) -> list[float | None]:
    """The spans, a half-period segment's ``"auto"`` solved from its neighbour's slope and a
    given one checked against it (span = end slope coefficient · lift / slope)."""
    spans = [s.span for s in inputs]
    for i, s in enumerate(inputs):
        if laws[i] not in HALF_PERIOD:
            continue
        slope = _neighbour_slope(i, inputs, laws, ctx, problems)
        if slope is None:
            continue
        end, coefficient = HALF_PERIOD[laws[i]]
        need = coefficient * s.lift / slope
        if s.span is None:
            spans[i] = need
        elif abs(need - s.span) > 1e-9 * max(need, 1e-9):
            side = "previous" if end == "start" else "next"
            j = (i - 1) % len(inputs) if end == "start" else (i + 1) % len(inputs)
            problems.append(Problem(f"{ctx.path}[{i}].{ctx.span_key}", ctx.to_user(s.span),
                                    f"the velocity does not match the {side} segment ({ctx.path}[{j}])",
                                    f"set {ctx.span_key} = {ctx.to_user(need):.12g} or \"auto\""))
    return spans


# ---- 3. closure
def _closure_problems(inputs: Sequence[SegmentInput], spans: Sequence[float | None], period: float,
                      ctx: _Context, *, lifts: bool = True) -> list[Problem]:
    """The spans sum to the period and the lifts (when ``lifts``) to 0, each judged when all its terms are
    known and valid."""
    out, to_user, key = [], ctx.to_user, ctx.span_key
    if all(sp is not None and math.isfinite(sp) and sp > 0 for sp in spans):
        total = sum(spans)  # type: ignore[arg-type]
        tol = ANGLE_SUM_TOL_DEG if ctx.unit != "mm" else 1e-9
        if abs(to_user(total) - to_user(period)) > tol:
            out.append(Problem(f"{ctx.path}[*].{key}", round(to_user(total), 12),
                               f"segment spans must sum to {to_user(period):.12g}",
                               f"change the spans by {to_user(period - total):+.12g} in total"))
    values = [s.lift for s in inputs]
    if lifts and all(math.isfinite(h) for h in values):
        net = sum(values)
        if abs(net) > 1e-9 * max(1.0, max(abs(h) for h in values)):
            out.append(Problem(f"{ctx.path}[*].lift", round(net, 12), "lifts must sum to 0 so the cycle closes",
                               f"change the lifts by {-net:+.12g} in total"))
    return out


# ---- resolution
def _segments(inputs: Sequence[SegmentInput], laws: list[str], spans: list[float],
              period: float) -> tuple[Segment, ...]:
    """The resolved segments: starts scaled so that the spans close the period exactly,
    generic polynomials solved from their (standard) neighbours' end values."""
    n, k = len(inputs), period / sum(spans)
    spans = [sp * k for sp in spans]
    starts = np.concatenate([[0.0], np.cumsum(spans)[:-1]])
    s0 = np.concatenate([[0.0], np.cumsum([s.lift for s in inputs])[:-1]])
    segs: list[Segment | None] = [
        None if laws[i] in GENERIC else
        Segment(laws[i], inputs[i].lift, spans[i], float(starts[i]), float(s0[i]), None, LAWS[laws[i]].title)
        for i in range(n)
    ]
    def joint(i: int) -> np.ndarray:  # S, S′, S″, S‴ where segment i ends (S unused)
        j = (i + 1) % n
        if laws[i] in GENERIC and laws[j] in GENERIC:
            return np.array([0.0, *(0.0 if e is None else e for e in inputs[i].ends)])
        return segs[i].end_values(True) if laws[i] not in GENERIC else segs[j].end_values(False)  # type: ignore

    for i in range(n):
        if laws[i] in GENERIC:
            prev_end, next_start = joint((i - 1) % n), joint(i)
            c = solve_generic(GENERIC[laws[i]], float(s0[i]), inputs[i].lift, spans[i], prev_end, next_start)
            segs[i] = Segment(laws[i], inputs[i].lift, spans[i], float(starts[i]), float(s0[i]), c,
                              f"Generic {GENERIC[laws[i]]}th-degree polynomial")
    return tuple(segs)  # type: ignore[arg-type]


# ---- 4. the resolved motion
def _below_zero_problems(segs: Sequence[Segment], ctx: _Context) -> list[Problem]:
    out = []
    for i, seg in enumerate(segs):
        u, v = segment_candidates(seg, 0)
        k = int(np.argmin(v))
        tol_s = 1e-9 * max(1.0, abs(seg.s0), abs(seg.s0 + seg.lift))
        if v[k] < -tol_s and seg.s0 >= -tol_s:  # report where S goes below 0, not where it stays there
            at = seg.start + u[k] * seg.span
            out.append(Problem(f"{ctx.path}[{i}]", round(float(v[k]), 9),
                               f"S goes below 0 (to {v[k]:.6g} at {ctx.to_user(at):.6g}); the follower would "
                               "cross the base/prime circle",
                               "reduce the return, or change the law or the neighbours of a generic polynomial"))
    return out


def _known_laws(inputs: Sequence[SegmentInput], bad: set[int]) -> list[str | None]:
    """The resolved law key of every segment whose own inputs are valid (None for the others)."""
    return [None if i in bad else s.law if s.law in GENERIC else get_law(s.law, s.lift, s.shape).name
            for i, s in enumerate(inputs)]


def _count_problems(inputs: Sequence[SegmentInput], ctx: _Context) -> list[Problem]:
    if len(inputs) == 0:
        return [Problem(ctx.path, [], "the program has no segments",
                        "add [[motion]] segments whose spans sum to the cycle")]
    if len(inputs) > MAX_SEGMENTS:
        return [Problem(ctx.path, f"{len(inputs)} segments", f"more than the limit of {MAX_SEGMENTS} segments",
                        "join consecutive segments, or give the motion as a knot table ([motion_table])")]
    return []


def resolve_segments(inputs: Sequence[SegmentInput], *, period: float, unit: str = "rad",
                     path: str = "motion", source: str | None = None) -> tuple[Segment, ...]:
    """Validate segment inputs (rules in the module docstring) and resolve them into segments.

    Every rule that can be judged is judged in one pass: each segment's own inputs, the chain rules among
    segments whose inputs are valid, the half-period spans once every input is valid, and the closure of the
    spans and of the lifts whenever they are all known.  Only S ≥ 0 waits for a motion without problems.

    Parameters
    ----------
    inputs : sequence of SegmentInput
    period : float
        The cycle: 2π, or the cam length in mm.
    unit : {"rad", "deg", "mm"}
        How the user gave the spans (messages quote them so: degrees unless "mm").
    path, source : str
        Field path prefix and file named in the problems.

    Raises
    ------
    SpecError
        With every problem found.
    """
    ctx = _Context(path, unit, source)
    ctx.raise_if(_count_problems(inputs, ctx))
    problems: list[Problem] = []
    bad: set[int] = set()
    for i, s in enumerate(inputs):
        own = [p for rule in _INPUT_RULES for p in rule(i, s, ctx)]
        problems += own
        if own:
            bad.add(i)
    laws = _known_laws(inputs, bad)
    spans = _spans(inputs, laws, ctx, problems) if not bad else [s.span for s in inputs]  # type: ignore[arg-type]
    judged = [p.path.rpartition(".")[2] for p in problems]  # a term already reported is not summed
    first = _first_problems(inputs, ctx) if 0 not in bad else []
    problems += first + _adjacent_generic_problems(inputs, laws, ctx)  # type: ignore[arg-type]
    problems += _closure_problems(inputs, spans if ctx.span_key not in judged else [None], period, ctx,
                                  lifts="lift" not in judged)
    ctx.raise_if(problems)
    segs = _segments(inputs, laws, spans, period)  # type: ignore[arg-type]
    ctx.raise_if(_below_zero_problems(segs, ctx))
    return segs
