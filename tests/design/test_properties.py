"""Property tests of motion programs (hypothesis).

Random valid programs are chains of 2–12 dwell-compatible segments (zero S′ and
S″ at both ends) with optional generic 5th/7th-degree polynomials that
are never adjacent (cyclically included), random positive spans summing to 360°
and lifts keeping the cumulative S ≥ 0 and closing at 0.
"""
from __future__ import annotations

import math

import numpy as np
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

from camfab.design.program import MotionProgram
from camfab.errors import SpecError

TWO_PI = 2 * math.pi
DWELL_COMPATIBLE = ["dwell", "cycloidal", "poly345", "poly4567", "modified_sine", "modified_trapezoid"]
GENERICS = ["poly5", "poly7"]

SETTINGS = settings(max_examples=40, deadline=None,
                    suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much])


@st.composite
def programs(draw):
    n = draw(st.integers(2, 12))
    laws = []
    for i in range(n):
        pool = list(DWELL_COMPATIBLE)
        prev_generic = i > 0 and laws[-1] in GENERICS
        wraps_generic = i == n - 1 and laws[0] in GENERICS
        if not prev_generic and not wraps_generic:
            pool += GENERICS
        laws.append(draw(st.sampled_from(pool)))
    weights = draw(st.lists(st.integers(1, 20), min_size=n, max_size=n))
    spans = [360.0 * w / sum(weights) for w in weights]
    # ordinates at the junctions: levels[0] = levels[n] = 0, S >= 0, dwells keep the level
    levels = [0.0]
    for i in range(n - 1):
        if laws[i] == "dwell":
            levels.append(levels[-1])
        else:
            levels.append(draw(st.floats(0.0, 50.0, allow_nan=False).map(lambda v: round(v, 3))))
    levels.append(0.0)
    # trailing dwells: the last moving segment must already bring S back to 0
    j = n - 1
    while j >= 0 and laws[j] == "dwell":
        levels[j] = 0.0
        j -= 1
    lifts = [levels[i + 1] - levels[i] for i in range(n)]
    return [(law, lift, span) for law, lift, span in zip(laws, lifts, spans, strict=True)]


def _build(rows) -> MotionProgram:
    try:
        return MotionProgram.from_segments(rows)
    except SpecError as err:
        # the only admissible refusal of these programs: a generic polynomial dipping below 0
        assert any(law in GENERICS for law, *_ in rows), err
        assert all("below 0" in p.rule for p in err.problems), err
        assume(False)
        raise


def _away_from_breaks(p: MotionProgram, x: np.ndarray, gap: float) -> np.ndarray:
    b = p.breakpoints
    d = np.min(np.abs(x[:, None] - b[None, :]), axis=1)
    return x[d > gap]


def _scales(p: MotionProgram, n: int = 20001) -> np.ndarray:
    x = np.linspace(0.0, TWO_PI, n)
    return np.maximum(np.max(np.abs(p.evaluate(x, orders=(0, 1, 2, 3, 4))), axis=1), 1e-9)


@SETTINGS
@given(programs())
def test_program_is_periodic_and_finite(rows):
    p = _build(rows)
    x = np.linspace(0.0, TWO_PI, 4001)
    vals = p.evaluate(x, orders=(0, 1, 2, 3, 4))
    assert np.all(np.isfinite(vals))
    xi = _away_from_breaks(p, x, 1e-7)
    scale = _scales(p)[:4, None]
    base = p.evaluate(xi)
    for shift in (TWO_PI, -TWO_PI, 3 * TWO_PI):
        assert np.all(np.abs(p.evaluate(xi + shift) - base) <= 1e-9 * scale)
    # 0 and 2π are the same point (a sample on a junction takes the segment starting there)
    assert np.allclose(p.evaluate(0.0), p.evaluate(TWO_PI), rtol=0, atol=1e-12)


@SETTINGS
@given(programs())
def test_derivatives_consistent_with_finite_differences(rows):
    p = _build(rows)
    h = 1e-6
    x = _away_from_breaks(p, np.linspace(0.0, TWO_PI, 3001), 1e-4)
    scale = _scales(p)
    for nu in (1, 2, 3, 4):
        fd = (p(x + h, nu - 1) - p(x - h, nu - 1)) / (2 * h)
        err = np.max(np.abs(fd - p(x, nu)))
        # truncation ~ h²/6·S^(nu+2), rounding ~ eps·|S^(nu-1)|/h
        assert err <= 1e-6 * scale[nu] + 1e-14 * scale[nu - 1] / h


@SETTINGS
@given(programs())
def test_displacement_never_below_zero(rows):
    p = _build(rows)
    x = np.linspace(0.0, TWO_PI, 20001)
    s = p(x, 0)
    top = max(abs(h) for _, h, _ in rows) or 1.0
    assert s.min() >= -1e-9 * top
    assert p.peaks("exact")[0].min >= -1e-9 * top
    # the program visits its junction ordinates
    levels = np.concatenate([[0.0], np.cumsum([h for _, h, _ in rows])[:-1]])
    starts = np.concatenate([[0.0], np.cumsum([sp for _, _, sp in rows])[:-1]]) * math.pi / 180
    assert np.allclose(p(starts, 0), levels, atol=1e-9 * top)


@SETTINGS
@given(programs())
def test_exact_peaks_bound_dense_samples(rows):
    p = _build(rows)
    x = np.linspace(0.0, TWO_PI, 50001)
    vals = p.evaluate(x)
    scale = _scales(p)
    exact = p.peaks("exact")
    cam = p.peaks("camdas")
    for k, pk in enumerate(exact):
        tol = 1e-10 * max(abs(pk.max), abs(pk.min), 1.0)
        assert vals[k].max() <= pk.max + tol
        assert vals[k].min() >= pk.min - tol
        # dense samples come close to the exact extremes
        # (scale[k + 1] is itself a sampled maximum, which can fall short of the true one by
        # O(its own grid step) — e.g. at a one-sided peak on a junction: allow 1 % for that)
        slack = 1.01 * (x[1] - x[0]) * scale[k + 1] + tol
        assert pk.max - vals[k].max() <= slack
        assert vals[k].min() - pk.min <= slack
        # CAM-DAS 1° sampling never exceeds the exact extremes
        assert cam[k].max <= pk.max + tol
        assert cam[k].min >= pk.min - tol
        # the reported locations are on the cycle and carry the reported values
        assert 0.0 <= pk.at_max <= TWO_PI and 0.0 <= pk.at_min <= TWO_PI


@SETTINGS
@given(programs())
def test_junctions_at_least_c2(rows):
    p = _build(rows)
    js = p.junctions()
    assert len(js) == len(rows)
    for j in js:
        assert j.order >= 2, (j, rows)
    # a generic 7th-degree polynomial is jerk-continuous at both ends
    n = len(rows)
    for i, (law, _, _) in enumerate(rows):
        if law == "poly7":
            assert js[i].order == 3 and js[(i + 1) % n].order == 3
    # 4-5-6-7 / dwell / poly7 neighbours with zero jerk on both sides meet at C3
    zero_jerk = {"dwell", "poly4567"}
    for i in range(n):
        if rows[i - 1][0] in zero_jerk and rows[i][0] in zero_jerk:
            assert js[i].order == 3
