"""Tests of the normalised motion laws (camfab.design.laws).

Oracles are the closed forms of the laws (the thesis §3.4 where it prints them,
otherwise the standard forms chosen in docs/decisions.md), their boundary values,
peak coefficients computed from them (the thesis prints none) and the expected
peaks for the parameters of the thesis' Figs 3.5–3.22 (L = 50 mm, β = 100°,
ω = 1 rad/s).  Every numeric oracle below is written from a closed form, never
from camfab output.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

from camfab.design.laws import GENERIC, HALF_PERIOD, LAWS, get_law, law_names
from camfab.design.program import MotionProgram, Segment

PI = math.pi
K = 4.0 + PI  # modified sine
Q = 2.0 + PI  # modified trapezoid
DEG = PI / 180.0

ALL = sorted(LAWS)
MOVING = [n for n in ALL if n != "dwell"]
PIECEWISE = [n for n in ALL if LAWS[n].breaks]
#: laws whose shape satisfies f(1 − u) = 1 − f(u): the return is the time mirror of the rise
POINT_SYMMETRIC = ["simple_harmonic", "cycloidal", "poly345", "poly4567", "constant_velocity",
                   "modified_sine", "modified_trapezoid", "constant_acceleration"]

U = np.linspace(0.0, 1.0, 4001)
U_DENSE = np.linspace(0.0, 1.0, 400_001)


def _dense_peak(name: str, nu: int) -> float:
    return float(np.max(np.abs(LAWS[name](U_DENSE, nu))))


# ---------------------------------------------------------------------------
# registry
def test_law_names_cover_the_spec_list():
    names = set(law_names())
    spec = {"dwell", "simple_harmonic", "cycloidal", "poly5", "poly345", "poly7", "poly4567",
            "constant_velocity", "semiharmonic_vf0", "semiharmonic_vi0", "semicycloidal_vf0",
            "semicycloidal_vi0", "double_harmonic", "modified_sine", "modified_trapezoid"}
    assert spec <= names
    assert set(GENERIC) == {"poly5", "poly7"}
    assert set(HALF_PERIOD) == {"semiharmonic_vf0", "semiharmonic_vi0",
                                "semicycloidal_vf0", "semicycloidal_vi0"}
    # the two DH shapes are resolved, not user keys
    assert not any(n.startswith("double_harmonic_") for n in names)


@pytest.mark.parametrize("name", sorted(set(law_names()) - set(GENERIC) - {"double_harmonic"}))
def test_zero_lift_is_a_dwell(name):
    assert get_law(name, 0.0).name == "dwell"


@pytest.mark.parametrize("lift, shape, expected", [
    (10.0, None, "double_harmonic_rise"),
    (-10.0, None, "double_harmonic_return"),
    (10.0, "return", "double_harmonic_return"),
    (-10.0, "rise", "double_harmonic_rise"),
    (0.0, "rise", "dwell"),
])
def test_double_harmonic_shape_by_sign_of_lift(lift, shape, expected):
    assert get_law("double_harmonic", lift, shape).name == expected


# ---------------------------------------------------------------------------
# f(0) = 0, f(1) = 1
@pytest.mark.parametrize("name", MOVING)
def test_normalised_ends(name):
    f = LAWS[name](np.array([0.0, 1.0]), 0)
    assert f[0] == pytest.approx(0.0, abs=1e-12)
    assert f[1] == pytest.approx(1.0, abs=1e-12)


@pytest.mark.parametrize("nu", range(5))
def test_dwell_is_zero(nu):
    assert np.all(LAWS["dwell"](U, nu) == 0.0)


@pytest.mark.parametrize("nu", range(5))
@pytest.mark.parametrize("name", ALL)
def test_shapes_are_finite_and_vectorised(name, nu):
    out = LAWS[name](U, nu)
    assert out.shape == U.shape
    assert np.all(np.isfinite(out))
    # scalar-like input gives the same value as the vector
    assert LAWS[name](np.array([U[1234]]), nu)[0] == pytest.approx(out[1234], rel=1e-14, abs=1e-14)


# ---------------------------------------------------------------------------
# boundary values: S'(0), S''(0), S'''(0), S'(1), S''(1), S'''(1) in units of L/β^k
# (double harmonic in units of h = |L|, rise with L = +h, return with L = −h)
BOUNDARY = {
    "dwell": (0, 0, 0, 0, 0, 0),
    "simple_harmonic": (0, PI**2 / 2, 0, 0, -PI**2 / 2, 0),
    "cycloidal": (0, 0, 4 * PI**2, 0, 0, 4 * PI**2),
    "poly345": (0, 0, 60, 0, 0, 60),
    "poly4567": (0, 0, 0, 0, 0, 0),
    "constant_velocity": (1, 0, 0, 1, 0, 0),
    "semiharmonic_vf0": (PI / 2, 0, -PI**3 / 8, 0, -PI**2 / 4, 0),
    "semiharmonic_vi0": (0, PI**2 / 4, 0, PI / 2, 0, -PI**3 / 8),
    "semicycloidal_vf0": (2, 0, -PI**2, 0, 0, PI**2),
    "semicycloidal_vi0": (0, 0, PI**2, 2, 0, -PI**2),
    "modified_sine": (0, 0, 16 * PI**3 / K, 0, 0, 16 * PI**3 / K),
    "modified_trapezoid": (0, 0, 32 * PI**2 / Q, 0, 0, 32 * PI**2 / Q),
}
BOUNDARY_DH = {  # units of h
    "double_harmonic_rise": (+1, (0, 0, 0, 0, -PI**2, 0)),
    "double_harmonic_return": (-1, (0, -PI**2, 0, 0, 0, 0)),
}


def _ends(seg: Segment) -> tuple[float, ...]:
    s = seg.end_values(False)
    e = seg.end_values(True)
    return (s[1], s[2], s[3], e[1], e[2], e[3])


@pytest.mark.parametrize("lift", [50.0, -50.0, 7.5])
@pytest.mark.parametrize("span_deg", [100.0, 45.0])
@pytest.mark.parametrize("name", sorted(BOUNDARY))
def test_boundary_values_table(name, lift, span_deg):
    beta = span_deg * DEG
    seg = Segment(name, lift, beta, 0.0, max(0.0, -lift))
    got = _ends(seg)
    want = BOUNDARY[name]
    for k, (g, w) in enumerate(zip(got, want, strict=True)):
        order = k % 3 + 1
        scale = lift / beta**order
        assert g / scale == pytest.approx(w, abs=1e-9), f"{name} end value #{k}"


@pytest.mark.parametrize("h", [50.0, 100.0])
@pytest.mark.parametrize("span_deg", [180.0, 100.0])
@pytest.mark.parametrize("name", sorted(BOUNDARY_DH))
def test_boundary_values_double_harmonic(name, h, span_deg):
    sign, want = BOUNDARY_DH[name]
    beta = span_deg * DEG
    seg = Segment(name, sign * h, beta, 0.0, h if sign < 0 else 0.0)
    for k, (g, w) in enumerate(zip(_ends(seg), want, strict=True)):
        order = k % 3 + 1
        assert g / (h / beta**order) == pytest.approx(w, abs=1e-9), f"{name} end value #{k}"


@pytest.mark.parametrize("name", sorted(BOUNDARY))
def test_boundary_values_of_the_shape(name):
    """Same table on the normalised shape f^(k)(0), f^(k)(1)."""
    ends = np.array([0.0, 1.0])
    want = BOUNDARY[name]
    for k in (1, 2, 3):
        f = LAWS[name](ends, k)
        assert f[0] == pytest.approx(want[k - 1], abs=1e-9)
        assert f[1] == pytest.approx(want[k + 2], abs=1e-9)


def test_constant_acceleration_boundary_values():
    # the textbook chapter's parabolic ("gravity") law, not a CAM-DAS law: f' = 0 at both ends, f'' = ±4
    ends = np.array([0.0, 1.0])
    law = LAWS["constant_acceleration"]
    assert law(ends, 1) == pytest.approx([0.0, 0.0], abs=1e-12)
    assert law(ends, 2) == pytest.approx([4.0, -4.0], abs=1e-12)
    assert law(np.array([0.5]), 0)[0] == pytest.approx(0.5, abs=1e-12)


# ---------------------------------------------------------------------------
# peak coefficients (rise, L > 0): (V max, V min, A max, A min, J max, J min) / (L/β^k)
SQ3, SQ5 = math.sqrt(3.0), math.sqrt(5.0)
COEFFS = {
    "constant_velocity": (1.0, 1.0, 0.0, 0.0, 0.0, 0.0),
    "simple_harmonic": (PI / 2, 0.0, PI**2 / 2, -PI**2 / 2, 0.0, -PI**3 / 2),
    "cycloidal": (2.0, 0.0, 2 * PI, -2 * PI, 4 * PI**2, -4 * PI**2),
    "poly345": (1.875, 0.0, 10 / SQ3, -10 / SQ3, 60.0, -30.0),
    "poly4567": (2.1875, 0.0, 84 * SQ5 / 25, -84 * SQ5 / 25, 42.0, -52.5),
    "semiharmonic_vf0": (PI / 2, 0.0, 0.0, -PI**2 / 4, 0.0, -PI**3 / 8),
    "semiharmonic_vi0": (PI / 2, 0.0, PI**2 / 4, 0.0, 0.0, -PI**3 / 8),
    "semicycloidal_vf0": (2.0, 0.0, 0.0, -PI, PI**2, -PI**2),
    "semicycloidal_vi0": (2.0, 0.0, PI, 0.0, PI**2, -PI**2),
    "double_harmonic_rise": (3 * SQ3 * PI / 8, 0.0, 9 * PI**2 / 16, -PI**2, 20.576, -42.414),
    # return shape f = 1 − g(1 − u): f' = g'(1−u), f'' = −g''(1−u), f''' = g'''(1−u)
    "double_harmonic_return": (3 * SQ3 * PI / 8, 0.0, PI**2, -9 * PI**2 / 16, 20.576, -42.414),
    "modified_sine": (4 * PI / K, 0.0, 4 * PI**2 / K, -4 * PI**2 / K,
                      16 * PI**3 / K, -16 * PI**3 / (3 * K)),
    "modified_trapezoid": (2.0, 0.0, 8 * PI / Q, -8 * PI / Q, 32 * PI**2 / Q, -32 * PI**2 / Q),
}
#: coefficients written above to 3 decimals only (±5e-4)
LOOSE = {("double_harmonic_rise", 4), ("double_harmonic_rise", 5),
         ("double_harmonic_return", 4), ("double_harmonic_return", 5)}


def _single(name: str, lift: float, beta: float) -> MotionProgram:
    """A program made of one segment only (its peaks are the law's peaks)."""
    return MotionProgram((Segment(name, lift, beta, 0.0, 0.0),), period=beta)


@pytest.mark.parametrize("name", sorted(COEFFS))
def test_peak_coefficients_exact(name):
    lift, beta = 1.0, 1.0
    peaks = _single(name, lift, beta).peaks("exact")
    got = (peaks[1].max, peaks[1].min, peaks[2].max, peaks[2].min, peaks[3].max, peaks[3].min)
    for k, (g, w) in enumerate(zip(got, COEFFS[name], strict=True)):
        tol = 1e-3 if (name, k) in LOOSE else 1e-9
        assert g == pytest.approx(w, abs=tol), f"{name} coefficient #{k}"


@pytest.mark.parametrize("lift, span_deg", [(50.0, 100.0), (-12.5, 37.0), (3.0, 250.0)])
@pytest.mark.parametrize("name", sorted(COEFFS))
def test_peak_coefficients_scale_with_lift_and_span(name, lift, span_deg):
    """max|S^(k)| = C·|L|/β^k, with signs flipped for a negative lift."""
    beta = span_deg * DEG
    peaks = _single(name, lift, beta).peaks("exact")
    c = COEFFS[name]
    for k in (1, 2, 3):
        cmax, cmin = c[2 * k - 2], c[2 * k - 1]
        if lift < 0:
            cmax, cmin = -cmin, -cmax
        scale = abs(lift) / beta**k
        tol = 1e-3 if (name, 2 * k - 2) in LOOSE else 1e-9
        assert peaks[k].max / scale == pytest.approx(cmax, abs=tol)
        assert peaks[k].min / scale == pytest.approx(cmin, abs=tol)


@pytest.mark.parametrize("name", sorted(COEFFS))
def test_peak_coefficients_dense(name):
    """The coefficient itself by dense evaluation of the normalised shape."""
    c = COEFFS[name]
    for k in (1, 2, 3):
        f = LAWS[name](U_DENSE, k)
        tol = 1e-3 if (name, 2 * k - 2) in LOOSE else 1e-6 * max(1.0, abs(c[2 * k - 2]))
        assert f.max() == pytest.approx(c[2 * k - 2], abs=tol)
        assert f.min() == pytest.approx(c[2 * k - 1], abs=tol)


@pytest.mark.parametrize("name", sorted(COEFFS))
def test_law_attributes_match_peak_table(name):
    law = LAWS[name]
    c = COEFFS[name]
    assert law.cv == pytest.approx(max(abs(c[0]), abs(c[1])), abs=1e-9)
    assert law.ca == pytest.approx(max(abs(c[2]), abs(c[3])), abs=1e-9)
    tol = 1e-3 if (name, 4) in LOOSE else 1e-9
    assert law.cj == pytest.approx(max(abs(c[4]), abs(c[5])), abs=tol)


def test_constant_acceleration_coefficients():
    # standard coefficients of the parabolic law (the textbook chapter prints none): V 2.0, A 4.0
    law = LAWS["constant_acceleration"]
    assert (law.cv, law.ca) == (pytest.approx(2.0), pytest.approx(4.0))
    assert _dense_peak("constant_acceleration", 1) == pytest.approx(2.0, abs=1e-9)
    assert _dense_peak("constant_acceleration", 2) == pytest.approx(4.0, abs=1e-12)


# ---------------------------------------------------------------------------
# expected peaks for the thesis' Figs 3.5–3.22 parameters, L = 50 mm, β = 100° (DH: β = 180°), ω = 1 rad/s
# (law, β°, V max, A max, A min, J max, J min)
EXPECTED_50_100 = [
    ("simple_harmonic", 100, 45.000, 81.000, -81.000, 0.0, -145.800),
    ("cycloidal", 100, 57.296, 103.132, -103.132, 371.277, -371.277),
    ("poly345", 100, 53.715, 94.767, -94.767, 564.273, -282.136),
    ("poly4567", 100, 62.667, 123.322, -123.322, 394.991, -493.739),
    ("constant_velocity", 100, 28.648, 0.0, 0.0, 0.0, 0.0),
    ("semiharmonic_vf0", 100, 45.000, 0.0, -40.500, 0.0, -36.450),
    ("semiharmonic_vi0", 100, 45.000, 40.500, 0.0, 0.0, -36.450),
    ("semicycloidal_vf0", 100, 57.296, 0.0, -51.566, 92.819, -92.819),
    ("semicycloidal_vi0", 100, 57.296, 51.566, 0.0, 92.819, -92.819),
    ("double_harmonic_rise", 180, 32.476, 28.125, -50.000, 33.180, -68.395),
    ("modified_sine", 100, 50.409, 90.736, -90.736, 653.300, -217.767),
    ("modified_trapezoid", 100, 57.296, 80.234, -80.234, 577.684, -577.684),
]


@pytest.mark.parametrize("name, span_deg, vmax, amax, amin, jmax, jmin", EXPECTED_50_100,
                         ids=[r[0] for r in EXPECTED_50_100])
def test_expected_peaks_L50_beta100(name, span_deg, vmax, amax, amin, jmax, jmin):
    omega = 1.0
    peaks = _single(name, 50.0, span_deg * DEG).peaks("exact")
    assert peaks[0].max == pytest.approx(50.0, abs=1e-9)
    assert peaks[0].min == pytest.approx(0.0, abs=1e-9)
    assert peaks[1].max * omega == pytest.approx(vmax, abs=1e-3)
    assert peaks[2].max * omega**2 == pytest.approx(amax, abs=1e-3)
    assert peaks[2].min * omega**2 == pytest.approx(amin, abs=1e-3)
    assert peaks[3].max * omega**3 == pytest.approx(jmax, abs=1e-3)
    assert peaks[3].min * omega**3 == pytest.approx(jmin, abs=1e-3)


# ---------------------------------------------------------------------------
# derivatives agree with finite differences of the lower order
H = 1e-5


def _fd_points(name: str) -> np.ndarray:
    u = np.linspace(2 * H, 1 - 2 * H, 2001)
    for b in LAWS[name].breaks:
        u = u[np.abs(u - b) > 10 * H]
    return u


@pytest.mark.parametrize("nu", [1, 2, 3, 4])
@pytest.mark.parametrize("name", ALL)
def test_derivatives_match_central_differences(name, nu):
    law = LAWS[name]
    u = _fd_points(name)
    fd = (law(u + H, nu - 1) - law(u - H, nu - 1)) / (2 * H)
    exact = law(u, nu)
    scale = max(_dense_peak(name, nu), 1.0)
    assert np.max(np.abs(fd - exact)) <= 1e-6 * scale


@pytest.mark.parametrize("nu", [1, 2, 3, 4])
@pytest.mark.parametrize("name", MOVING)
def test_segment_derivatives_match_central_differences(name, nu):
    """Same check on a scaled segment: S^(k) = L/β^k f^(k)."""
    lift, beta = -35.0, 70.0 * DEG
    seg = Segment(name, lift, beta, 0.0, 35.0)
    u = _fd_points(name)
    h = H * beta  # step in x
    fd = (seg.values(u + H, nu - 1) - seg.values(u - H, nu - 1)) / (2 * h)
    exact = seg.values(u, nu)
    scale = max(_dense_peak(name, nu) * abs(lift) / beta**nu, 1.0)
    assert np.max(np.abs(fd - exact)) <= 1e-6 * scale


# ---------------------------------------------------------------------------
# rise / return symmetry
@pytest.mark.parametrize("h", [50.0, 3.0])
@pytest.mark.parametrize("name", [n for n in MOVING if not n.startswith("double_harmonic")])
def test_return_is_negative_lift_of_the_same_shape(name, h):
    beta = 100.0 * DEG
    rise = Segment(name, h, beta, 0.0, 0.0)
    ret = Segment(name, -h, beta, 0.0, h)  # Li = h
    f = LAWS[name](U, 0)
    assert ret.values(U, 0) == pytest.approx(h - h * f, abs=1e-12 * h)
    for nu in (1, 2, 3, 4):
        assert ret.values(U, nu) == pytest.approx(-rise.values(U, nu), rel=1e-14, abs=1e-12)


@pytest.mark.parametrize("name", POINT_SYMMETRIC)
def test_symmetric_laws_return_is_the_mirror_of_the_rise(name):
    """f(1 − u) = 1 − f(u): the return S(u) = h − h f(u) equals the rise at 1 − u."""
    h, beta = 50.0, 100.0 * DEG
    rise = Segment(name, h, beta, 0.0, 0.0)
    ret = Segment(name, -h, beta, 0.0, h)
    u = U.copy()
    for b in LAWS[name].breaks:  # keep off the breaks (1 - break is mirrored onto a break)
        u = u[np.abs(u - (1 - b)) > 1e-9]
    assert ret.values(u, 0) == pytest.approx(rise.values(1 - u, 0), abs=1e-10)
    # V_return(u) = -V_rise(1 - u), A_return(u) = A_rise(1 - u), J_return(u) = -J_rise(1 - u)
    for nu in (1, 2, 3):
        tol = 1e-10 * max(1.0, _dense_peak(name, nu) * h / beta**nu)
        assert ret.values(u, nu) == pytest.approx((-1) ** nu * rise.values(1 - u, nu), abs=tol)


@pytest.mark.parametrize("h", [50.0, 100.0])
def test_double_harmonic_return_is_the_mirror_of_the_rise(h):
    """Classical DH pair: return (L = −h from Li = h) is S_rise(1 − u) (docs/decisions.md, "double harmonic")."""
    beta = 180.0 * DEG
    rise = Segment(get_law("double_harmonic", h).name, h, beta, 0.0, 0.0)
    ret = Segment(get_law("double_harmonic", -h).name, -h, beta, 0.0, h)
    # closed form of the DH return for Li = h: S = (h/2)[(1 + cos πu) − ¼(1 − cos 2πu)]
    closed = (h / 2) * ((1 + np.cos(PI * U)) - 0.25 * (1 - np.cos(2 * PI * U)))
    assert ret.values(U, 0) == pytest.approx(closed, abs=1e-10 * h)
    for nu in range(4):
        assert ret.values(U, nu) == pytest.approx((-1) ** nu * rise.values(1 - U, nu),
                                                  abs=1e-10 * h / beta**nu)
    # the return's velocity is the negative of the rise's (mirrored in time)
    assert ret.values(U, 1) == pytest.approx(-rise.values(1 - U, 1), abs=1e-10 * h)


@pytest.mark.parametrize("pair", [("semiharmonic_vf0", "semiharmonic_vi0"),
                                  ("semicycloidal_vf0", "semicycloidal_vi0")])
def test_half_period_variants_are_mirrors(pair):
    """f_vi0(u) = 1 − f_vf0(1 − u)."""
    vf0, vi0 = (LAWS[n] for n in pair)
    for nu in range(4):
        lhs = vi0(U, nu)
        rhs = (1 - vf0(1 - U, 0)) if nu == 0 else (-1) ** (nu + 1) * vf0(1 - U, nu)
        assert lhs == pytest.approx(rhs, abs=1e-12 * max(1.0, _dense_peak(pair[0], nu)))


# ---------------------------------------------------------------------------
# closed forms of the laws (a few spot checks independent of the engine's construction)
CLOSED = {
    "simple_harmonic": lambda u: (1 - np.cos(PI * u)) / 2,
    "cycloidal": lambda u: u - np.sin(2 * PI * u) / (2 * PI),
    "poly345": lambda u: 10 * u**3 - 15 * u**4 + 6 * u**5,
    "poly4567": lambda u: 35 * u**4 - 84 * u**5 + 70 * u**6 - 20 * u**7,
    "constant_velocity": lambda u: u,
    "semiharmonic_vf0": lambda u: np.sin(PI * u / 2),
    "semiharmonic_vi0": lambda u: 1 - np.cos(PI * u / 2),
    "semicycloidal_vf0": lambda u: u + np.sin(PI * u) / PI,
    "semicycloidal_vi0": lambda u: u - np.sin(PI * u) / PI,
    "double_harmonic_rise": lambda u: 0.5 * ((1 - np.cos(PI * u)) - 0.25 * (1 - np.cos(2 * PI * u))),
    "modified_sine": lambda u: np.piecewise(
        u, [u < 1 / 8, (u >= 1 / 8) & (u < 7 / 8), u >= 7 / 8],
        [lambda v: PI * v / K - np.sin(4 * PI * v) / (4 * K),
         lambda v: 2 / K + PI * v / K - 9 / (4 * K) * np.sin(PI / 3 + 4 * PI * v / 3),
         lambda v: 4 / K + PI * v / K - np.sin(4 * PI * v) / (4 * K)]),
    "modified_trapezoid": lambda u: np.piecewise(
        u, [u < 1 / 8, (u >= 1 / 8) & (u < 3 / 8), (u >= 3 / 8) & (u < 5 / 8),
            (u >= 5 / 8) & (u < 7 / 8), u >= 7 / 8],
        [lambda v: (4 * PI * v - np.sin(4 * PI * v)) / (2 * PI * Q),
         lambda v: (16 * PI * v * (4 * PI * v - PI + 2) - 8 + PI**2) / (16 * PI * Q),
         lambda v: (4 * PI * v + 4 * PI**2 * v + np.sin(4 * PI * v) - PI**2) / (2 * PI * Q),
         lambda v: (16 * PI * v * (2 + 7 * PI - 4 * PI * v) - 33 * PI**2 + 8) / (16 * PI * Q),
         lambda v: (4 * PI * v - np.sin(4 * PI * v) + 2 * PI**2) / (2 * PI * Q)]),
}


@pytest.mark.parametrize("name", sorted(CLOSED))
def test_shape_matches_spec_closed_form(name):
    assert LAWS[name](U, 0) == pytest.approx(CLOSED[name](U), abs=1e-12)


def test_modified_trapezoid_norton_decimals():
    """Norton's decimal form of the modified trapezoid, pieces 2–5."""
    law = LAWS["modified_trapezoid"]
    cases = [
        (np.linspace(0.13, 0.37, 7), lambda u: 2.4440619 * u**2 - 0.22203094 * u + 0.0072340616),
        (np.linspace(0.38, 0.62, 7), lambda u: 1.6110155 * u + 0.030954405 * np.sin(4 * PI * u) - 0.30550774),
        (np.linspace(0.63, 0.87, 7), lambda u: -2.4440619 * u**2 + 4.6660928 * u - 1.2292650),
        (np.linspace(0.88, 1.0, 7), lambda u: 0.38898453 * u - 0.030954405 * np.sin(4 * PI * u) + 0.61101547),
    ]
    for u, fn in cases:
        assert law(u, 0) == pytest.approx(fn(u), abs=1e-7)  # 8-digit decimals


# ---------------------------------------------------------------------------
# piecewise laws: continuity at the internal breaks
# NB the written-out modified trapezoid is said to have jerk jumps between its pieces, but its own
# formulas give S''' = 0 on both sides of every internal break (cos 4πu = 0 at u = k/8, and
# the ramps have S''' = 0): the jerk is continuous inside the law and jumps only at the
# segment ends (32π²/Q against a dwell).  The tests follow the formulas.
CONTINUOUS_ORDERS = {"modified_sine": 3, "modified_trapezoid": 3, "constant_acceleration": 1}


def _sides(name: str, b: float, nu: int) -> tuple[float, float]:
    law = LAWS[name]
    lo = law(np.array([np.nextafter(b, -1.0)]), nu)[0]
    hi = law(np.array([np.nextafter(b, 2.0)]), nu)[0]
    return lo, hi


def test_piecewise_laws_are_listed():
    assert set(PIECEWISE) == set(CONTINUOUS_ORDERS)
    assert LAWS["modified_sine"].breaks == pytest.approx((1 / 8, 7 / 8))
    assert LAWS["modified_trapezoid"].breaks == pytest.approx((1 / 8, 3 / 8, 5 / 8, 7 / 8))


@pytest.mark.parametrize("name", sorted(CONTINUOUS_ORDERS))
def test_piecewise_continuity_at_internal_breaks(name):
    top = CONTINUOUS_ORDERS[name]
    for b in LAWS[name].breaks:
        for nu in range(top + 1):
            lo, hi = _sides(name, b, nu)
            assert hi == pytest.approx(lo, abs=1e-9 * max(1.0, _dense_peak(name, nu))), (b, nu)


@pytest.mark.parametrize("name", sorted(CONTINUOUS_ORDERS))
def test_piecewise_first_discontinuous_order_really_jumps(name):
    """The order above the guaranteed one does jump at (at least one) break."""
    nu = CONTINUOUS_ORDERS[name] + 1  # the 4th derivative for the modified sine
    jumps = [abs(np.subtract(*_sides(name, b, nu))) for b in LAWS[name].breaks]
    assert max(jumps) > 1e-3 * _dense_peak(name, nu)


def test_modified_trapezoid_jerk_at_breaks_and_ends():
    law = LAWS["modified_trapezoid"]
    for b in law.breaks:  # S''' is zero on both sides of every internal break (Norton's formulas)
        lo, hi = _sides("modified_trapezoid", b, 3)
        assert lo == pytest.approx(0.0, abs=1e-9)
        assert hi == pytest.approx(0.0, abs=1e-9)
    # ... and 32π²/Q at both ends, so a dwell next to it sees a jerk jump (boundary values)
    assert law(np.array([0.0, 1.0]), 3) == pytest.approx([32 * PI**2 / Q] * 2, rel=1e-12)


@pytest.mark.parametrize("name, expected", [("modified_sine", "C3"), ("modified_trapezoid", "C3")])
def test_internal_breaks_reported_by_program_junctions(name, expected):
    prog = MotionProgram.from_segments([("dwell", 0, 60), (name, 10, 100), ("dwell", 0, 100),
                                        (name, -10, 100)])
    internal = [j for j in prog.junctions(internal=True) if j.segment is None]
    assert len(internal) == 2 * len(LAWS[name].breaks)
    assert {j.continuity for j in internal} == {expected}
    # the positions are the breaks scaled into the segment
    b = np.array(LAWS[name].breaks)
    want = np.sort(np.concatenate([(60 + 100 * b) * DEG, (260 + 100 * b) * DEG]))
    assert np.array([j.at for j in internal]) == pytest.approx(want, abs=1e-12)
