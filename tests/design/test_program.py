"""Tests of segment programs (camfab.design.program).

Oracles: the CAM-DAS "Conclusiones" screens of the thesis (Fig 7.19, §7.3.5, and
Fig 7.45, §7.4.4 Ejemplo4PO), reference rows derived from the thesis' example inputs
(docs/decisions.md, "peaks"), the continuity rules of the thesis §3.3.1 with the
laws' boundary values, the half-period matching of §3.4.6 and the
generic-polynomial systems of §3.4.3.1/§3.4.4.1.  No expected value is a snapshot of
camfab output.
"""
from __future__ import annotations

import math
import re

import numpy as np
import pytest

from camfab.design.program import (
    MotionProgram,
    Segment,
    SegmentInput,
    build_program,
    hermite_coefficients,
    solve_generic,
)
from camfab.errors import SpecError

PI = math.pi
TWO_PI = 2 * PI
DEG = PI / 180.0
OMEGA = 1.0  # rad/s, every thesis screen

# ---------------------------------------------------------------------------
# example programs (the thesis' example library, §7.4)
EJ11RO = [("dwell", 0, 90), ("poly4567", 25, 90), ("poly4567", -10, 45), ("poly4567", 10, 45),
          ("poly4567", -25, 90)]
# Ejemplo4PO (thesis §7.4.4; its L/β are only in a figure): the 4-5-6-7 return −20°/45° is inferred from
# Fig 7.45, which it reproduces exactly; the rise split below is one consistent guess (unconfirmed)
EJ4PO = [("semicycloidal_vi0", 5, None), ("constant_velocity", 10, 90), ("semicycloidal_vf0", 5, None),
         ("dwell", 0, 45), ("poly4567", -20, 45)]
EJ4PO_EXPLICIT = [("semicycloidal_vi0", 5, 90), ("constant_velocity", 10, 90),
                  ("semicycloidal_vf0", 5, 90), ("dwell", 0, 45), ("poly4567", -20, 45)]
EXAMPLES = {
    "1RT": [("simple_harmonic", 50, 180), ("simple_harmonic", -50, 180)],
    "2RO": [("poly4567", 10, 120), ("dwell", 0, 120), ("poly4567", -10, 120)],
    "4PO": EJ4PO,
    "7CRT": [("poly4567", 20 * (-1) ** i, 36) for i in range(10)],
    "8DA": [("double_harmonic", 100, 180), ("double_harmonic", -100, 180)],
    "9RT": [("modified_sine", 10, 50), ("dwell", 0, 40), ("cycloidal", -10, 50), ("dwell", 0, 40),
            ("poly345", 10, 50), ("dwell", 0, 40), ("poly4567", -10, 50), ("dwell", 0, 40)],
    "11RO": EJ11RO,
    "12PO": [("modified_trapezoid", 10 * (-1) ** i, 60) for i in range(6)],
    "5ACRT": [("simple_harmonic", 30, 120), ("dwell", 0, 60), ("simple_harmonic", -30, 120),
              ("dwell", 0, 60)],
}
#: programs with generic polynomials between arbitrary neighbours
GENERIC_PROGRAMS = {
    # poly5 between SHM and constant velocity; poly7 last (cyclic neighbour: the SHM)
    "poly5-mid_poly7-last": [("simple_harmonic", 10, 80), ("poly5", 10, 60), ("constant_velocity", 10, 60),
                             ("semicycloidal_vf0", 5, None), ("dwell", 0, 40), ("poly7", -35, 60)],
    # poly7 first (cyclic neighbour: the final dwell), next to a semicycloid and a DH return
    "poly7-first": [("poly7", 20, 90), ("semicycloidal_vf0", 5, 45), ("dwell", 0, 45),
                    ("double_harmonic", -25, 90), ("dwell", 0, 90)],
    # poly5 last, its next neighbour is the first dwell; between modified sine and dwell
    "poly5-last": [("dwell", 0, 60), ("poly4567", 20, 60), ("cycloidal", -5, 60),
                   ("simple_harmonic", -5, 60), ("modified_sine", -5, 60), ("poly5", -5, 60)],
    # poly5 first between a 3-4-5 return (cyclic) and a cycloidal; poly7 between SHM and DH
    "poly5-first_poly7-mid": [("poly5", 15, 50), ("cycloidal", 5, 50), ("simple_harmonic", 10, 60),
                              ("poly7", 5, 70), ("double_harmonic", -20, 70), ("poly345", -15, 60)],
}
ALL_PROGRAMS = {**EXAMPLES, **GENERIC_PROGRAMS}


def prog(rows) -> MotionProgram:
    return MotionProgram.from_segments(rows)


def r2(x: float) -> float:
    return round(x, 2) + 0.0  # no "-0.0"


def screen(p: MotionProgram) -> list[tuple[float, float]]:
    """(max, min) of S, V, A, J as CAM-DAS prints them: 1° samples, ω = 1, 2 decimals."""
    pk = p.peaks("camdas")
    return [(r2(q.max * OMEGA**k), r2(q.min * OMEGA**k)) for k, q in enumerate(pk)]


# ---------------------------------------------------------------------------
# CAM-DAS screens
def test_fig_7_19_ejemplo11ro_screen():
    assert screen(prog(EJ11RO)) == [(25.0, 0.0), (34.82, -34.82), (121.51, -121.51), (1080.44, -1080.44)]


def test_fig_7_19_is_jerk_continuous():
    # "Continua" in all four rows: every junction of 11RO is C3
    assert {j.continuity for j in prog(EJ11RO).junctions()} == {"C3"}


@pytest.mark.parametrize("rows", [EJ4PO, EJ4PO_EXPLICIT], ids=["auto-spans", "explicit-spans"])
def test_fig_7_45_ejemplo4po_screen(rows):
    assert screen(prog(rows)) == [(20.0, 0.0), (6.37, -55.62), (243.02, -243.02), (2160.88, -1733.58)]


def test_fig_7_45_jerk_discontinuous_only():
    # "Continua" for S, V, A and "Discontinua" for J: every junction is at least C2, some only C2
    classes = [j.continuity for j in prog(EJ4PO).junctions()]
    assert set(classes) <= {"C2", "C3"}
    assert "C2" in classes


@pytest.mark.parametrize("rows", [
    [("poly345", 20, 315), ("poly4567", -20, 45)],
    [("dwell", 0, 200), ("cycloidal", 20, 115), ("poly4567", -20, 45)],
], ids=["after-345", "after-cycloidal"])
def test_4567_return_of_20_over_45_in_any_program(rows):
    """The return alone fixes V min, A ± and J ± of Fig 7.45 when the rest is gentler."""
    (smax, smin), (vmax, vmin), (amax, amin), (jmax, jmin) = screen(prog(rows))
    assert (smax, smin) == (20.0, 0.0)
    assert vmin == -55.62
    assert (amax, amin) == (243.02, -243.02)
    assert (jmax, jmin) == (2160.88, -1733.58)


def test_fig_7_45_exact_peaks_are_the_continuous_ones():
    # 4-5-6-7 return L = −20 over β = 45° (closed-form peaks of the 4-5-6-7 law)
    lift, beta = 20.0, PI / 4
    pk = prog(EJ4PO).peaks("exact")
    assert pk[1].min == pytest.approx(-2.1875 * lift / beta, rel=1e-12)
    assert pk[2].max == pytest.approx(84 * math.sqrt(5) / 25 * lift / beta**2, rel=1e-12)
    assert pk[2].min == pytest.approx(-84 * math.sqrt(5) / 25 * lift / beta**2, rel=1e-12)
    assert pk[3].max == pytest.approx(52.5 * lift / beta**3, rel=1e-12)
    assert pk[3].min == pytest.approx(-42.0 * lift / beta**3, rel=1e-12)
    # the exact peaks to one decimal, derived from the thesis' inputs ("−1733.9" is 1733.84 misrounded)
    assert pk[1].min == pytest.approx(-55.70, abs=0.005)
    assert pk[2].max == pytest.approx(243.6, abs=0.05)
    assert pk[3].max == pytest.approx(2167.3, abs=0.05)
    assert pk[3].min == pytest.approx(-1733.9, abs=0.1)


def test_fig_7_19_exact_peaks_are_the_continuous_ones():
    # exact peaks of the Ejemplo11RO law, derived from the thesis' inputs: A = 121.80, J = 1083.6
    # (truncated; 1083.65), where Fig 7.19 prints the 1° samples 121.51 and 1080.44
    lift, beta = 10.0, PI / 4  # the ±10 segments over 45° dominate A and J
    pk = prog(EJ11RO).peaks("exact")
    assert pk[2].max == pytest.approx(84 * math.sqrt(5) / 25 * lift / beta**2, rel=1e-12)
    assert pk[3].max == pytest.approx(52.5 * lift / beta**3, rel=1e-12)
    assert pk[2].max == pytest.approx(121.80, abs=0.005)
    assert pk[3].max == pytest.approx(1083.6, abs=0.1)


# reference rows derived from the thesis' example inputs at 1° sampling, ω = 1 (docs/decisions.md, "peaks"):
# (S max, S min, V max, V min, A max, A min, J max, J min)
DERIVED = {
    "1RT": (50, 0, 25.00, -25.00, 25.00, -25.00, 25.00, -25.00),
    "2RO": (10, 0, 10.44, -10.44, 17.13, -17.13, 57.15, -57.15),
    "7CRT": (20, 0, 69.63, -69.63, 380.60, -380.60, 4233.01, -4233.01),
    "9RT": (10, 0, 21.49, -25.07, 98.63, -98.63, 1045.28, -630.00),
    "11RO": (25, 0, 34.82, -34.82, 121.51, -121.51, 1080.44, -1080.44),
    "12PO": (10, 0, 19.10, -19.10, 44.57, -44.57, 534.89, -534.89),
    "8DA": (100, 0, 64.95, -64.95, 56.24, -100.00, 136.78, -136.78),
}


@pytest.mark.parametrize("name", sorted(DERIVED))
def test_derived_reference_rows(name):
    got = [v for pair in screen(prog(EXAMPLES[name])) for v in pair]
    assert got == pytest.approx(list(DERIVED[name]), abs=1e-9)


def test_camdas_step_is_one_degree_and_includes_360():
    # a sample exactly on 360° is taken (the grid is 0..360 inclusive): J of a cycloidal return
    # ending at 360° is sampled there (4π²L/β³ on the segment side)
    p = prog([("cycloidal", 10, 180), ("cycloidal", -10, 180)])
    pk = p.peaks("camdas")
    assert pk[3].max == pytest.approx(4 * PI**2 * 10 / PI**3, rel=1e-12)
    assert pk[3].min == pytest.approx(-4 * PI**2 * 10 / PI**3, rel=1e-12)
    # step keyword: coarser sampling can only lower the magnitudes
    coarse = p.peaks("camdas", step=5 * DEG)
    for c, f in zip(coarse, pk, strict=True):
        assert c.max <= f.max + 1e-12 and c.min >= f.min - 1e-12


def test_peaks_mode_is_checked():
    with pytest.raises(ValueError, match="exact"):
        prog(EJ11RO).peaks("sampled")


# ---------------------------------------------------------------------------
# exact versus CAM-DAS peaks, location of the exact extrema
def _scale(p: MotionProgram, nu: int, n: int = 20001) -> float:
    x = np.linspace(0, TWO_PI, n)
    return max(float(np.max(np.abs(p(x, nu)))), 1e-9)


@pytest.mark.parametrize("name", sorted(ALL_PROGRAMS))
def test_exact_peaks_dominate_camdas(name):
    p = prog(ALL_PROGRAMS[name])
    exact, cam = p.peaks("exact"), p.peaks("camdas")
    for k in range(4):
        tol = 1e-12 * max(abs(exact[k].max), abs(exact[k].min), 1.0)
        assert exact[k].max >= cam[k].max - tol
        assert exact[k].min <= cam[k].min + tol
        # and the sampled value is close: within half a step times the next derivative
        slack = 0.5 * DEG * _scale(p, k + 1) + tol
        assert exact[k].max - cam[k].max <= slack
        assert cam[k].min - exact[k].min <= slack


@pytest.mark.parametrize("name", sorted(ALL_PROGRAMS))
def test_exact_peaks_bound_dense_samples(name):
    p = prog(ALL_PROGRAMS[name])
    x = np.linspace(0, TWO_PI, 200_001)
    vals = p.evaluate(x)
    for k, pk in enumerate(p.peaks("exact")):
        tol = 1e-10 * max(abs(pk.max), abs(pk.min), 1.0)
        assert vals[k].max() <= pk.max + tol
        assert vals[k].min() >= pk.min - tol
        slack = (x[1] - x[0]) * _scale(p, k + 1) + tol
        assert pk.max - vals[k].max() <= slack
        assert vals[k].min() - pk.min <= slack


@pytest.mark.parametrize("span_deg, end_jerk", [(60.0, -60 * 20 / PI**3), (30.0, -200.0), (90.0, -5000.0)])
def test_exact_peaks_find_extremum_in_first_cell_next_to_a_flat_end(span_deg, end_jerk):
    """A 7th-degree piece starting with S = S' = S'' = 0 and S''' < 0 dips below 0 just after
    its start; the true minimum is the real root of S' in (0, 1), found here with numpy."""
    span = span_deg * DEG
    c = hermite_coefficients([0.0, 0.0, 0.0, end_jerk], [20.0, 0.0, 0.0, 0.0], span)
    p = MotionProgram((Segment("poly7", 20.0, span, 0.0, 0.0, c),), period=span)
    poly = np.polynomial.Polynomial(c)
    roots = poly.deriv().roots()
    roots = roots[(np.abs(roots.imag) < 1e-12) & (roots.real > 0) & (roots.real < 1)].real
    true_min = min(0.0, float(poly(roots).min()))
    assert true_min < 0.0
    assert p.peaks("exact")[0].min == pytest.approx(true_min, rel=1e-9, abs=1e-15)


def test_generic_dip_below_zero_near_its_start_is_refused():
    # poly7 begins at S = 0 after a 3-4-5 return whose end jerk is negative: S dips to about
    # −8.6e-7 within the first 1/128 of the segment, which is below the S >= 0 rule's tolerance
    with pytest.raises(SpecError, match="below 0"):
        prog([("poly7", 20, 60), ("dwell", 0, 120), ("poly345", -20, 180)])


def _near_break(p: MotionProgram, x: float, tol: float = 1e-9) -> bool:
    b = p.breakpoints
    return bool(np.min(np.abs(np.concatenate([b, b + TWO_PI, b - TWO_PI]) - x)) < tol)


@pytest.mark.parametrize("name", sorted(ALL_PROGRAMS))
def test_exact_extrema_locations(name):
    """Interior extrema sit where the next derivative vanishes, located to ~1e-9 rad."""
    p = prog(ALL_PROGRAMS[name])
    for k, pk in enumerate(p.peaks("exact")):
        span = max(abs(pk.max), abs(pk.min), 1.0)
        for value, at, sign in ((pk.max, pk.at_max, 1.0), (pk.min, pk.at_min, -1.0)):
            assert 0.0 <= at <= TWO_PI
            # the value is not exceeded anywhere near the reported location
            around = p(np.array([at - 1e-7, at + 1e-7, at - 1e-4, at + 1e-4]), k)
            assert np.all(sign * around <= sign * value + 1e-12 * span)
            if _near_break(p, at):
                continue  # an end value: the next derivative need not vanish
            assert p(np.array([at]), k)[0] == pytest.approx(value, abs=1e-12 * span)
            d1 = abs(p(np.array([at]), k + 1)[0])
            d2 = abs(p(np.array([at]), k + 2)[0])
            m1, m2 = _scale(p, k + 1), _scale(p, k + 2)
            if m1 <= 1e-9:  # flat derivative (e.g. S'' of a constant velocity)
                continue
            # Newton distance to the root of S^(k+1): |S^(k+1)| / |S^(k+2)|
            if d2 > 1e-3 * m2:
                assert d1 / d2 <= 1e-9
            else:
                assert d1 <= 1e-9 * m2 + 1e-12 * m1


# ---------------------------------------------------------------------------
# generic polynomials: C2 (5th) / C3 (7th) at both junctions, cyclic included
@pytest.mark.parametrize("name", sorted(GENERIC_PROGRAMS))
def test_generic_polynomials_match_their_neighbours(name):
    rows = GENERIC_PROGRAMS[name]
    p = prog(rows)
    n = len(rows)
    by_seg = {j.segment: j for j in p.junctions()}
    found = 0
    for i, row in enumerate(rows):
        if row[0] not in ("poly5", "poly7"):
            continue
        found += 1
        need = 2 if row[0] == "poly5" else 3
        for j in (by_seg[i], by_seg[(i + 1) % n]):
            assert j.order >= need, (i, j)
            assert max(j.jumps[: need + 1]) <= 1e-9 * max(1.0, max(j.jumps))
        # the polynomial reaches its own end ordinates
        seg = p.segments[i]
        s = seg.end_values(False)[0], seg.end_values(True)[0]
        assert s[0] == pytest.approx(seg.s0, abs=1e-9)
        assert s[1] == pytest.approx(seg.s0 + row[1], abs=1e-9)
    assert found >= 1


def _spec_quintic(s0, s1, beta):
    """The CAM-DAS 3×3 system of the thesis §3.4.3.1 (generic 5th degree), solved numerically."""
    c0, c1, c2 = s0[0], s0[1] * beta, s0[2] * beta**2 / 2
    m = np.array([[1, 1, 1], [3, 4, 5], [6, 12, 20]], float)
    rhs = np.array([s1[0] - c0 - c1 - c2, s1[1] * beta - (c1 + 2 * c2), s1[2] * beta**2 - 2 * c2])
    return (c0, c1, c2, *np.linalg.solve(m, rhs))


def _spec_septic(s0, s1, beta):
    """The CAM-DAS 4×4 system of the thesis §3.4.4.1 (generic 7th degree), solved numerically."""
    c0, c1, c2, c3 = s0[0], s0[1] * beta, s0[2] * beta**2 / 2, s0[3] * beta**3 / 6
    m = np.array([[1, 1, 1, 1], [4, 5, 6, 7], [12, 20, 30, 42], [24, 60, 120, 210]], float)
    rhs = np.array([s1[0] - c0 - c1 - c2 - c3, s1[1] * beta - (c1 + 2 * c2 + 3 * c3),
                    s1[2] * beta**2 - (2 * c2 + 6 * c3), s1[3] * beta**3 - 6 * c3])
    return (c0, c1, c2, c3, *np.linalg.solve(m, rhs))


@pytest.mark.parametrize("seed", range(6))
def test_hermite_coefficients_solve_the_spec_systems(seed):
    rng = np.random.default_rng(seed)
    beta = rng.uniform(0.2, 2.0)
    a, b = rng.normal(size=4) * [10, 5, 20, 50], rng.normal(size=4) * [10, 5, 20, 50]
    assert hermite_coefficients(a[:3], b[:3], beta) == pytest.approx(_spec_quintic(a, b, beta), abs=1e-9)
    assert hermite_coefficients(a, b, beta) == pytest.approx(_spec_septic(a, b, beta), abs=1e-8)
    c5 = solve_generic(5, a[0], b[0] - a[0], beta, np.r_[0, a[1:]], np.r_[0, b[1:]])
    assert c5 == pytest.approx(_spec_quintic(a, b, beta), abs=1e-9)
    # 4-5-6-7 is the septic with Δ0 = L and zero end derivatives (thesis §3.4.4.2)
    c7 = solve_generic(7, 0.0, 1.0, beta, np.zeros(4), np.zeros(4))
    assert c7 == pytest.approx([0, 0, 0, 0, 35, -84, 70, -20], abs=1e-12)
    # and 3-4-5 the quintic (thesis §3.4.3.2)
    c345 = solve_generic(5, 0.0, 1.0, beta, np.zeros(4), np.zeros(4))
    assert c345 == pytest.approx([0, 0, 0, 10, -15, 6], abs=1e-12)


def test_low_order_derivatives_at_one_are_numpys_bit_for_bit():
    """The closed-form derivatives at u = 1 that hermite_coefficients uses round as numpy's Polynomial.deriv(k)(1.0)
    did (the knot tables' coefficients, and so every file of a knot design, stay the same bytes)."""
    from camfab.design.segment import _derivatives_at_one

    rng = np.random.default_rng(7)
    for trial in range(3000):
        m = 3 + trial % 2
        a = rng.standard_normal(m) * 10.0 ** rng.uniform(-12, 12, size=m)
        if trial % 5 == 0:
            a[rng.integers(m)] = 0.0 if trial % 10 else -0.0
        low = np.polynomial.Polynomial(list(a))
        want = [(low.deriv(k) if k else low)(1.0) for k in range(m)]
        got = _derivatives_at_one(list(a))
        assert np.array(got).tobytes() == np.array(want, dtype=float).tobytes(), a


def test_hermite_coefficients_rejects_bad_sizes():
    with pytest.raises(ValueError):
        hermite_coefficients([0, 0], [1, 0], 1.0)


def test_generic_between_zero_derivative_neighbours_is_the_standard_polynomial():
    """poly5 / poly7 between dwells reduce to 3-4-5 / 4-5-6-7 (thesis §3.4.3.2, §3.4.4.2)."""
    for generic, standard in (("poly5", "poly345"), ("poly7", "poly4567")):
        a = prog([("dwell", 0, 90), (generic, 10, 90), ("dwell", 0, 90), ("poly4567", -10, 90)])
        b = prog([("dwell", 0, 90), (standard, 10, 90), ("dwell", 0, 90), ("poly4567", -10, 90)])
        x = np.linspace(0, TWO_PI, 3001)
        assert a.evaluate(x) == pytest.approx(b.evaluate(x), abs=1e-9)


# ---------------------------------------------------------------------------
# continuity classes without knots (thesis §3.3.1; the laws' boundary values)
def _classes(rows) -> list[str]:
    return [j.continuity for j in prog(rows).junctions()]


@pytest.mark.parametrize("rows, expected", [
    # dwell – cycloidal – dwell: jerk jumps by 4π²L/β³
    ([("dwell", 0, 90), ("cycloidal", 10, 90), ("dwell", 0, 90), ("cycloidal", -10, 90)], ["C2"] * 4),
    ([("dwell", 0, 90), ("poly345", 10, 90), ("dwell", 0, 90), ("poly345", -10, 90)], ["C2"] * 4),
    ([("dwell", 0, 90), ("poly4567", 10, 90), ("dwell", 0, 90), ("poly4567", -10, 90)], ["C3"] * 4),
    ([("dwell", 0, 90), ("modified_sine", 10, 90), ("dwell", 0, 90), ("modified_sine", -10, 90)],
     ["C2"] * 4),
    ([("dwell", 0, 90), ("modified_trapezoid", 10, 90), ("dwell", 0, 90),
      ("modified_trapezoid", -10, 90)], ["C2"] * 4),
    # SHM rise 180 + SHM return 180 = one cosine: acceleration continuous (thesis §3.4.1) and jerk 0 on both sides
    ([("simple_harmonic", 50, 180), ("simple_harmonic", -50, 180)], ["C3", "C3"]),
    # DH rise + return with equal β: continuous through jerk (thesis §3.4.7)
    ([("double_harmonic", 100, 180), ("double_harmonic", -100, 180)], ["C3", "C3"]),
    # constant velocity next to a dwell: velocity jump (thesis §3.4.5)
    ([("dwell", 0, 90), ("constant_velocity", 10, 90), ("dwell", 0, 90), ("poly4567", -10, 90)],
     ["C3", "C0", "C0", "C3"]),
    # constant-breadth law SHM/dwell/SHM/dwell: C1 only (thesis §3.3.1, the constant-width exception)
    (EXAMPLES["5ACRT"], ["C1"] * 4),
    # cycloid + cycloid rise/return without dwell: C2, jerk jumps (thesis §3.4.2)
    ([("cycloidal", 10, 180), ("cycloidal", -10, 180)], ["C2", "C2"]),
    # Ejemplo9RT: 4-5-6-7 junctions C3, the others C2
    (EXAMPLES["9RT"], ["C2", "C2", "C2", "C2", "C2", "C2", "C3", "C3"]),
    (EXAMPLES["12PO"], ["C2"] * 6),
], ids=["dwell-cyc-dwell", "dwell-345-dwell", "dwell-4567-dwell", "dwell-msine-dwell",
        "dwell-mtrap-dwell", "shm-180-180", "dh-pair", "cv-next-to-dwell", "constant-breadth",
        "cyc-cyc", "9RT", "12PO"])
def test_continuity_classes(rows, expected):
    assert _classes(rows) == expected


@pytest.mark.parametrize("law, coeff", [("cycloidal", 4 * PI**2), ("poly345", 60.0),
                                        ("modified_sine", 16 * PI**3 / (4 + PI)),
                                        ("modified_trapezoid", 32 * PI**2 / (2 + PI))])
def test_jerk_jump_against_dwells(law, coeff):
    lift, beta = 10.0, 90 * DEG
    p = prog([("dwell", 0, 90), (law, lift, 90), ("dwell", 0, 90), (law, -lift, 90)])
    for j in p.junctions():
        assert j.jumps[:3] == pytest.approx((0, 0, 0), abs=1e-9)
        assert j.jumps[3] == pytest.approx(coeff * lift / beta**3, rel=1e-9)


def test_velocity_jump_of_constant_velocity_next_to_dwell():
    p = prog([("dwell", 0, 90), ("constant_velocity", 10, 90), ("dwell", 0, 90), ("poly4567", -10, 90)])
    j = {j.segment: j for j in p.junctions()}
    assert j[1].jumps[0] == pytest.approx(0.0, abs=1e-12)
    assert j[1].jumps[1] == pytest.approx(10 / (PI / 2), rel=1e-12)


def test_junction_records():
    p = prog(EXAMPLES["9RT"])
    js = p.junctions()
    assert [j.segment for j in js] == list(range(8))
    starts = np.cumsum([0, 50, 40, 50, 40, 50, 40, 50]) * DEG
    assert [j.at for j in js] == pytest.approx(list(starts), abs=1e-12)
    # internal=True adds the two modified-sine breaks, marked segment=None
    internal = [j for j in p.junctions(internal=True) if j.segment is None]
    assert [j.at for j in internal] == pytest.approx([50 / 8 * DEG, 50 * 7 / 8 * DEG], abs=1e-12)
    assert p.junctions_x[-1] == pytest.approx(TWO_PI)


# ---------------------------------------------------------------------------
# half-period laws with solved spans (thesis §3.4.6)
@pytest.mark.parametrize("lift, cv_lift, cv_span", [(5, 10, 90), (3, 12, 60), (2.5, 7.5, 120)])
def test_semicycloidal_auto_spans(lift, cv_lift, cv_span):
    slope = cv_lift / (cv_span * DEG)
    beta = 2 * lift / slope  # semicycloids: 2L/β = neighbour slope (docs/decisions.md, "half-period laws")
    ret_span = 45.0
    dwell = 360 - cv_span - 2 * math.degrees(beta) - ret_span
    total = 2 * lift + cv_lift
    rows = [("semicycloidal_vi0", lift, None), ("constant_velocity", cv_lift, cv_span),
            ("semicycloidal_vf0", lift, None), ("dwell", 0, dwell), ("poly4567", -total, ret_span)]
    p = prog(rows)
    assert p.segments[0].span == pytest.approx(beta, rel=1e-12)
    assert p.segments[2].span == pytest.approx(beta, rel=1e-12)
    js = {j.segment: j for j in p.junctions()}
    assert js[1].continuity == "C2" and js[2].continuity == "C2"  # jerk jumps π²L/β³
    assert js[1].jumps[3] == pytest.approx(PI**2 * lift / beta**3, rel=1e-9)
    # the slope really matches
    assert p(np.array([beta]), 1)[0] == pytest.approx(slope, rel=1e-12)
    # dwell – semicycloid junctions are C2 as well (zero V and A at the far ends)
    assert js[0].order >= 2 and js[3].order >= 2


def test_semiharmonic_auto_spans():
    lift, cv_lift, cv_span = 5.0, 10.0, 90.0
    slope = cv_lift / (cv_span * DEG)
    beta = (PI / 2) * lift / slope  # thesis §3.4.6.1: πL/(2β) = neighbour slope
    assert math.degrees(beta) == pytest.approx(22.5 * PI)  # = π²/8 rad
    ret_span = 60.0
    dwell = 360 - cv_span - 2 * math.degrees(beta) - ret_span
    rows = [("dwell", 0, dwell), ("semiharmonic_vi0", lift, None), ("constant_velocity", cv_lift, cv_span),
            ("semiharmonic_vf0", lift, None), ("poly4567", -20, ret_span)]
    p = prog(rows)
    assert p.segments[1].span == pytest.approx(beta, rel=1e-12)
    assert p.segments[3].span == pytest.approx(beta, rel=1e-12)
    js = {j.segment: j for j in p.junctions()}
    # C2 at the constant-velocity junctions (A = 0 there, jerk jumps π³L/(8β³))
    assert js[2].continuity == "C2" and js[3].continuity == "C2"
    assert js[2].jumps[3] == pytest.approx(PI**3 * lift / (8 * beta**3), rel=1e-9)
    # the zero-velocity ends carry |A| = π²L/(4β²): C1 against a dwell / a 4-5-6-7 (boundary values)
    assert js[1].continuity == "C1" and js[4].continuity == "C1"
    assert js[1].jumps[2] == pytest.approx(PI**2 * lift / (4 * beta**2), rel=1e-9)


def test_half_period_returns_auto_spans():
    # returns: the neighbour must also descend; spans 2L/β with L, slope both negative
    rows = [("poly4567", 20, 90), ("dwell", 0, 30), ("semicycloidal_vi0", -5, None),
            ("constant_velocity", -10, 60), ("semicycloidal_vf0", -5, None), ("dwell", 0, 60)]
    p = prog(rows)
    assert math.degrees(p.segments[2].span) == pytest.approx(60.0, rel=1e-12)
    assert math.degrees(p.segments[4].span) == pytest.approx(60.0, rel=1e-12)
    assert p.peaks("exact")[0].min == pytest.approx(0.0, abs=1e-12)
    assert {j.continuity for j in p.junctions()} <= {"C2", "C3"}


def test_auto_span_equals_explicit_span():
    a, b = prog(EJ4PO), prog(EJ4PO_EXPLICIT)
    x = np.linspace(-1.0, 7.0, 2001)
    assert a.evaluate(x) == pytest.approx(b.evaluate(x), abs=1e-10)


def _number_after(text: str, key: str) -> float:
    m = re.search(re.escape(key) + r"\s*=?\s*([-+0-9.eE]+)", text)
    assert m, text
    return float(m.group(1))


@pytest.mark.parametrize("index, law, wrong, right", [
    (0, "semicycloidal_vi0", 80.0, 90.0),
    (2, "semicycloidal_vf0", 91.0, 90.0),
])
def test_mismatched_half_period_span_is_refused(index, law, wrong, right):
    rows = [list(r) for r in EJ4PO_EXPLICIT]
    rows[index][2] = wrong
    rows[3][2] += 90.0 - wrong  # keep the sum at 360 so only the mismatch is reported
    with pytest.raises(SpecError) as ei:
        prog([tuple(r) for r in rows])
    err = ei.value
    paths = [p.path for p in err.problems]
    assert f"motion[{index}].angle_deg" in paths
    assert f"motion[{index}].angle_deg" in str(err)
    assert _number_after(str(err), "set angle_deg") == pytest.approx(right, rel=1e-9)


def test_mismatched_semiharmonic_span_names_the_correct_value():
    lift, cv_lift, cv_span = 5.0, 10.0, 90.0
    right = math.degrees((PI / 2) * lift / (cv_lift / (cv_span * DEG)))
    rows = [("dwell", 0, 360 - cv_span - 2 * right - 60 - 1), ("semiharmonic_vi0", lift, right + 1),
            ("constant_velocity", cv_lift, cv_span), ("semiharmonic_vf0", lift, None),
            ("poly4567", -20, 60)]
    with pytest.raises(SpecError) as ei:
        prog(rows)
    assert "motion[1].angle_deg" in str(ei.value)
    assert _number_after(str(ei.value), "set angle_deg") == pytest.approx(right, rel=1e-9)


# ---------------------------------------------------------------------------
# periodicity and evaluation
@pytest.mark.parametrize("name", sorted(ALL_PROGRAMS))
def test_periodicity(name):
    p = prog(ALL_PROGRAMS[name])
    rng = np.random.default_rng(7)
    x = rng.uniform(0, TWO_PI, 500)
    b = p.breakpoints
    x = x[np.min(np.abs(x[:, None] - b[None, :]), axis=1) > 1e-6]
    base = p.evaluate(x)
    scale = np.array([_scale(p, k) for k in range(4)])[:, None]
    for shift in (TWO_PI, -TWO_PI, 5 * TWO_PI):
        assert np.all(np.abs(p.evaluate(x + shift) - base) <= 1e-9 * scale)


@pytest.mark.parametrize("name", sorted(ALL_PROGRAMS))
def test_closes_the_cycle(name):
    """S, S', S'' at 360° equal those at 0° (thesis §3.3.1, cyclic closure) for every C2 program."""
    p = prog(ALL_PROGRAMS[name])
    first = p.segments[0].end_values(False)
    last = p.segments[-1].end_values(True)
    assert last[0] == pytest.approx(first[0], abs=1e-9)
    if name != "5ACRT":  # the constant-breadth law is C1 only (thesis §3.3.1)
        for k in (1, 2):
            assert last[k] == pytest.approx(first[k], abs=1e-9 * max(1.0, _scale(p, k)))
    assert p(np.array([0.0]))[0] == pytest.approx(0.0, abs=1e-12)
    assert p(np.array([TWO_PI]))[0] == pytest.approx(p(np.array([0.0]))[0], abs=1e-12)


def test_evaluate_shapes_and_orders():
    p = prog(EJ11RO)
    x = np.linspace(0, TWO_PI, 17)
    out = p.evaluate(x)
    assert out.shape == (4, 17)
    assert p.evaluate(x, orders=(2,)).shape == (1, 17)
    assert p.evaluate(x, orders=(4,)).shape == (1, 17)
    assert p.evaluate(1.0).shape == (4, 1)
    assert p(x, 3) == pytest.approx(out[3])
    # S is the cumulative lift at each junction
    starts = np.cumsum([0, 90, 90, 45, 45]) * DEG
    assert p(starts, 0) == pytest.approx([0, 0, 25, 15, 25], abs=1e-12)


@pytest.mark.parametrize("name", ["9RT", "8DA", "4PO", "poly5-mid_poly7-last", "poly7-first"])
def test_program_derivatives_match_central_differences(name):
    p = prog(ALL_PROGRAMS[name])
    h = 1e-5
    x = np.linspace(0, TWO_PI, 4001)
    b = p.breakpoints
    x = x[np.min(np.abs(x[:, None] - b[None, :]), axis=1) > 10 * h]
    for nu in (1, 2, 3, 4):
        fd = (p(x + h, nu - 1) - p(x - h, nu - 1)) / (2 * h)
        assert np.max(np.abs(fd - p(x, nu))) <= 1e-6 * max(_scale(p, nu), 1.0)


def test_translating_cam_program_in_mm():
    rows = [("dwell", 0, 40), ("cycloidal", 10, 60), ("dwell", 0, 40), ("cycloidal", -10, 60)]
    p = MotionProgram.from_segments(rows, unit="mm")
    assert p.period == pytest.approx(200.0)
    x = np.linspace(0, 200, 101)
    assert p.evaluate(x + 200) == pytest.approx(p.evaluate(x), abs=1e-9)
    # V per mm of cam travel: cycloidal Cv = 2 → 2·10/60
    assert p.peaks("exact")[1].max == pytest.approx(2 * 10 / 60, rel=1e-12)
    # CAM-DAS samples 1 mm steps: 30 mm into the rise is a sample, so V max is exact too
    assert p.peaks("camdas")[1].max == pytest.approx(2 * 10 / 60, rel=1e-12)


# ---------------------------------------------------------------------------
# validation: every rule raises SpecError naming the field path
def _error(rows, **kw) -> SpecError:
    with pytest.raises(SpecError) as ei:
        MotionProgram.from_segments(rows, **kw)
    return ei.value


OK4 = [("dwell", 0, 90), ("cycloidal", 10, 90), ("dwell", 0, 90), ("cycloidal", -10, 90)]


def _with(i, row):
    rows = list(OK4)
    rows[i] = row
    return rows


INVALID = {
    "unknown-law": (_with(2, ("spline", 0, 90)), "motion[2].law", "unknown"),
    "lift-nan": (_with(1, ("cycloidal", float("nan"), 90)), "motion[1].lift", "finite"),
    "lift-inf": (_with(1, ("cycloidal", float("inf"), 90)), "motion[1].lift", "finite"),
    "lift-absurd": ([("cycloidal", 1e6, 180), ("cycloidal", -1e6, 180)], "motion[0].lift", "absurd"),
    "span-zero": (_with(2, ("dwell", 0, 0)), "motion[2].angle_deg", "> 0"),
    "span-negative": (_with(2, ("dwell", 0, -90)), "motion[2].angle_deg", "> 0"),
    "span-inf": (_with(2, ("dwell", 0, float("inf"))), "motion[2].angle_deg", "> 0"),
    "span-nan": (_with(2, ("dwell", 0, float("nan"))), "motion[2].angle_deg", "> 0"),
    "spans-short": (_with(2, ("dwell", 0, 30)), "motion[*].angle_deg", "+60"),
    "spans-long": (_with(2, ("dwell", 0, 100)), "motion[*].angle_deg", "-10"),
    "spans-tiny-excess": (_with(2, ("dwell", 0, 90 + 1e-6)), "motion[*].angle_deg", "360"),
    "lifts-not-zero": (_with(3, ("cycloidal", -8, 90)), "motion[*].lift", "-2"),
    "first-return": ([("cycloidal", -10, 180), ("cycloidal", 10, 180)], "motion[0].lift", "first"),
    "S-below-0": ([("cycloidal", 10, 90), ("cycloidal", -15, 90), ("dwell", 0, 90),
                   ("cycloidal", 5, 90)], "motion[", "below 0"),
    "generic-S-below-0": ([("poly345", 10, 90), ("constant_velocity", -10, 90), ("poly5", 0, 90),
                           ("dwell", 0, 90)], "motion[2]", "below 0"),
    "generics-adjacent": ([("poly5", 10, 90), ("poly7", 0, 90), ("cycloidal", -10, 180)],
                          "motion[1].law", "adjacent"),
    "generics-adjacent-cyclic": ([("poly5", 10, 90), ("cycloidal", 0, 90), ("cycloidal", -10, 90),
                                  ("poly7", 0, 90)], "motion[0].law", "motion[3]"),
    "half-period-auto-next-to-generic": ([("poly5", 10, 90), ("semicycloidal_vf0", 5, None),
                                          ("dwell", 0, 90), ("cycloidal", -15, 90)],
                                         "motion[1].angle_deg", "generic"),
    "half-period-neighbour-other-way": ([("dwell", 0, 90), ("semicycloidal_vi0", -5, 90),
                                         ("constant_velocity", 10, 90), ("cycloidal", -5, 90)],
                                        "motion[1].law", "same direction"),
    "half-period-neighbour-other-way-return": (
        [("poly4567", 20, 90), ("constant_velocity", -10, 90), ("semicycloidal_vf0", 5, 90),
         ("poly4567", -15, 90)], "motion[2].law", "same direction"),
    "half-period-neighbour-dwell": ([("dwell", 0, 90), ("semicycloidal_vf0", 10, 90), ("dwell", 0, 90),
                                     ("cycloidal", -10, 90)], "motion[1].law", "same direction"),
    "half-period-both-auto": ([("semicycloidal_vi0", 5, None), ("semicycloidal_vf0", 5, None),
                               ("dwell", 0, 180), ("cycloidal", -10, 90)], "motion[0].angle_deg", "span"),
    "half-period-zero-lift-auto": ([("dwell", 0, 90), ("semicycloidal_vi0", 0, None),
                                    ("constant_velocity", 10, 90), ("semicycloidal_vf0", 5, None),
                                    ("poly4567", -15, 90)], "motion[1].angle_deg", "angle_deg"),
    "auto-span-non-half-period": (_with(1, ("cycloidal", 10, None)), "motion[1].angle_deg", "half-period"),
    "shape-on-non-dh": (_with(1, ("cycloidal", 10, 90, "rise")), "motion[1].shape", "double_harmonic"),
    "shape-bad-value": ([("double_harmonic", 10, 180, "up"), ("double_harmonic", -10, 180)],
                        "motion[0].shape", "rise"),
    "no-segments": ([], "motion", "no segments"),
}


@pytest.mark.parametrize("name", sorted(INVALID))
def test_validation_rule(name):
    rows, path, words = INVALID[name]
    err = _error(rows)
    text = str(err)
    assert path in text
    assert words in text
    assert any(p.path.startswith(path) or p.path == path.rstrip("[") for p in err.problems), err.problems
    for p in err.problems:  # every problem carries a rule and a fix
        assert p.rule and p.fix


def test_s_below_zero_names_the_segment_where_the_minimum_lies():
    err = _error(INVALID["S-below-0"][0])
    (problem,) = err.problems
    # S reaches −5 at the end of motion[1] and stays there through the dwell motion[2]
    assert problem.path == "motion[1]"
    assert problem.value == pytest.approx(-5.0)


def test_generic_overshoot_above_zero_is_accepted():
    # overshoot of a generic polynomial is the user's decision (thesis §3.4.3.1); only S < 0 is refused
    p = prog([("poly345", 10, 90), ("constant_velocity", 10, 90), ("poly5", 0, 90), ("poly345", -20, 90)])
    assert p.peaks("exact")[0].max > 20.0
    assert p.peaks("exact")[0].min >= -1e-9


def test_spans_message_says_by_how_much():
    err = _error(_with(2, ("dwell", 0, 75.5)))
    (problem,) = err.problems
    assert problem.path == "motion[*].angle_deg"
    assert problem.value == pytest.approx(345.5)
    assert _number_after(problem.fix, "by") == pytest.approx(14.5)


def test_lifts_message_says_by_how_much():
    err = _error(_with(3, ("cycloidal", -7.25, 90)))
    (problem,) = err.problems
    assert problem.path == "motion[*].lift"
    assert problem.value == pytest.approx(2.75)
    assert _number_after(problem.fix, "by") == pytest.approx(-2.75)


@pytest.mark.parametrize("rows, paths", [
    # field-level problems, all at once
    ([("spline", 0, 90), ("cycloidal", float("nan"), 90), ("cycloidal", 10, -5, None),
      ("cycloidal", -10, 90, "rise")],
     {"motion[0].law", "motion[1].lift", "motion[2].angle_deg", "motion[3].shape"}),
    # structural problems, all at once
    ([("cycloidal", -10, 90), ("poly5", 10, 90), ("poly7", 0, 90), ("semicycloidal_vi0", 5, None),
      ("dwell", 0, 90)],
     {"motion[0].lift", "motion[2].law", "motion[3].law"}),
    # sums: spans and lifts together
    ([("cycloidal", 10, 100), ("cycloidal", -8, 200)], {"motion[*].angle_deg", "motion[*].lift"}),
], ids=["fields", "structure", "sums"])
def test_several_problems_reported_at_once(rows, paths):
    err = _error(rows)
    assert len(err.problems) >= 2
    assert paths <= {p.path for p in err.problems}
    for p in paths:
        assert p in str(err)


def test_custom_path_and_translating_units_in_messages():
    inputs = [SegmentInput("cycloidal", 10.0, 90.0), SegmentInput("cycloidal", -10.0, -1.0)]
    with pytest.raises(SpecError) as ei:
        build_program(inputs, period=89.0, unit="mm", path="cam.motion", source="design.toml")
    assert "cam.motion[1].length_mm" in str(ei.value)
    assert str(ei.value).startswith("design.toml")


def test_valid_program_from_build_program_in_radians():
    inputs = [SegmentInput(r[0], float(r[1]), r[2] * DEG) for r in EJ11RO]
    p = build_program(inputs)
    assert screen(p) == screen(prog(EJ11RO))


# ---------------------------------------------------------------------------
# the polynomial segments' extremum candidates, their roots found all together
def _random_coefficients(rng: np.random.Generator, count: int) -> list[np.ndarray]:
    """Coefficient arrays of degree 0–8 over many scales, some with trailing zeros, some all zero."""
    out = []
    for _ in range(count):
        n = int(rng.integers(1, 10))
        c = rng.normal(size=n) * 10.0 ** rng.integers(-8, 8, size=n)
        if rng.random() < 0.2:
            c = np.concatenate([c, np.zeros(int(rng.integers(1, 3)))])
        if rng.random() < 0.05:
            c = np.zeros(n)
        out.append(c)
    return out


def test_polynomial_roots_are_numpys_polyroots_bit_for_bit():
    """One eigenvalue call per degree gives each polynomial the roots numpy's polyroots gives it alone."""
    from camfab.design.extrema import polynomial_roots
    coeffs = _random_coefficients(np.random.default_rng(20261127), 3000)
    for c, got in zip(coeffs, polynomial_roots(coeffs), strict=True):
        t = np.trim_zeros(c, "b")
        ref = np.polynomial.polynomial.polyroots(t) if len(t) else np.array([])
        assert got.shape == ref.shape
        assert got.astype(complex).tobytes() == ref.astype(complex).tobytes(), (c, got, ref)


def test_knot_extremes_together_are_each_segments_own():
    """KnotTable's batched extremes (quintic and 7th-degree segments) equal numpy's Polynomial path segment by
    segment, bit for bit."""
    from types import SimpleNamespace

    from camfab.design.knots import _extremes_all
    rng = np.random.default_rng(7)
    scale = np.array([5.0, 20.0, 80.0, 300.0])
    segs = [SimpleNamespace(coeffs=hermite_coefficients(rng.normal(size=m) * scale[:m], rng.normal(size=m) * scale[:m],
                                                        span), span=span)
            for span, m in zip(rng.uniform(0.01, 2.0, size=300), rng.integers(3, 5, size=300), strict=True)]
    for nu in range(4):
        for seg, got in zip(segs, _extremes_all(segs, nu), strict=True):
            p = np.polynomial.Polynomial(seg.coeffs).deriv(nu)
            r = p.deriv().roots() if p.degree() > 0 else np.array([])
            r = r.real[(np.abs(r.imag) <= 1e-12) & (r.real > 0.0) & (r.real < 1.0)]
            u = np.concatenate([[0.0, 1.0], r])
            vals = p(u) / seg.span**nu
            assert got == (float(vals.min()), float(vals.max()), float(u[vals.argmin()]), float(u[vals.argmax()]))
