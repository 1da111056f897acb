"""Exact cam profiles: envelope properties, analytic curvature and pressure angle
against finite differences of the generated curves, conventions and refusals."""
from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from camfab.design.mechanisms import (
    OscillatingFlat,
    OscillatingRoller,
    TranslatingCamRoller,
    TranslatingFlat,
    TranslatingRoller,
)
from camfab.design.profile import CamGeometry
from camfab.design.program import MotionProgram
from camfab.errors import SpecError
from camfab.numeric import integrate, positive_ranges

from ..conftest import EJEMPLO9RT, EJEMPLO11RO, EXAMPLES

DEG = math.pi / 180
E1 = MotionProgram.from_segments([("simple_harmonic", 50, 180), ("simple_harmonic", -50, 180)])
E9 = MotionProgram.from_segments(EJEMPLO9RT)
E11 = MotionProgram.from_segments(EJEMPLO11RO)
E2 = MotionProgram.from_segments([("poly4567", 10, 120), ("dwell", 0, 120), ("poly4567", -10, 120)])
WEDGE = MotionProgram.from_segments([("cycloidal", 12, 40), ("dwell", 0, 30), ("poly345", -12, 50),
                                     ("dwell", 0, 30)], unit="mm")

MECHS = [
    (TranslatingRoller(35, 7), E9),
    (TranslatingRoller(40, 8, -9.0, "ccw"), E9),
    (TranslatingRoller(50, 0.0, 5.0), E1),  # knife edge
    (OscillatingRoller(40, 10, 100, 90), E11),
    (OscillatingRoller(40, 10, 100, 90, "ccw"), E11),
    (TranslatingFlat(60, 3.0), E1),
    (TranslatingFlat(45, 0.0, "ccw"), E9),
    (OscillatingFlat(40, 100, 5), E2),
    (OscillatingFlat(35, 110, -8, "ccw"), E2),
]


def _mirror(v):
    return v * np.array([-1.0, 1.0])


def _rot(v, a):
    c, s = np.cos(a), np.sin(a)
    return np.stack([v[:, 0] * c - v[:, 1] * s, v[:, 0] * s + v[:, 1] * c], axis=1)


def _away_from_breaks(geom, x, h):
    b = geom.breakpoints
    d = np.min(np.abs(np.mod(x[:, None] - b[None, :] + geom.period / 2, geom.period) - geom.period / 2), axis=1)
    return x[d > 4 * h]


# ---------------------------------------------------------------------------
# CAM-DAS reference values and closed forms
def test_ejemplo1rt_pressure_angle_peaks():
    g = CamGeometry(TranslatingRoller(50, 5, 0.0), E1)
    phi = np.arange(0, 360, 1.0) * DEG
    d = np.degrees(g.evaluate(phi).pressure_angle)
    assert round(d.max(), 2) == 18.21 and phi[d.argmax()] / DEG == pytest.approx(72.0)
    assert round(d.min(), 2) == -18.21 and phi[d.argmin()] / DEG == pytest.approx(288.0)
    # Norton's form tan δ = S'/(R_p + S) for e = 0; positive while rising
    s = E1.evaluate(phi, (0, 1))
    np.testing.assert_allclose(np.tan(g.evaluate(phi).pressure_angle), s[1] / (55 + s[0]), atol=1e-13)


@pytest.mark.parametrize("mech,prog", MECHS)
def test_min_radius_is_base_radius(mech, prog):
    g = CamGeometry(mech, prog)
    ext = g.radius_extremes()
    assert ext.min == pytest.approx(mech.base_radius_mm, abs=1e-9)
    phi = np.linspace(0, 2 * np.pi, 7201)
    r = np.hypot(*g.evaluate(phi).point.T)
    assert r.min() >= mech.base_radius_mm - 1e-9
    assert ext.max == pytest.approx(r.max(), rel=1e-6) and ext.max >= r.max() - 1e-9


def test_translating_cam_min_height_and_area():
    g = CamGeometry(TranslatingCamRoller(6, 10.0), WEDGE)
    ext = g.radius_extremes()
    assert ext.min == pytest.approx(10.0, abs=1e-9)
    assert ext.max == pytest.approx(22.0, abs=1e-9)  # crest: roller on top, n vertical
    x = np.linspace(0, g.period, 200001)
    s = g.evaluate(x)
    assert g.area() == pytest.approx(np.trapezoid(s.point[:, 1], s.point[:, 0]), rel=1e-8)


@pytest.mark.parametrize("mech,prog", [m for m in MECHS if m[0].follower == "roller"])
def test_roller_profile_is_parallel_to_pitch(mech, prog):
    g = CamGeometry(mech, prog)
    phi = np.linspace(0, 2 * np.pi, 721)
    s = g.evaluate(phi)
    rr = mech.roller_radius_mm
    np.testing.assert_allclose(s.point, s.pitch - rr * s.normal, atol=1e-12)
    np.testing.assert_allclose(np.hypot(*(s.point - s.pitch).T), rr, atol=1e-12)
    # envelope: no other pitch point is closer than R_r (dense samples)
    dense = g.evaluate(np.concatenate([np.linspace(0, 2 * np.pi, 40001), phi[::6]])).pitch
    d = np.sqrt(((s.point[::6, None, :] - dense[None, :, :]) ** 2).sum(-1)).min(axis=1)
    np.testing.assert_allclose(d, rr, atol=1e-9)


def test_translating_flat_shm_is_circle():
    """Ejemplo10EX: SHM 180/180 with a translating flat face is a circle R_b + h/2."""
    rb, h = 40.0, 30.0
    prog = MotionProgram.from_segments([("simple_harmonic", h, 180), ("simple_harmonic", -h, 180)])
    for rot in ("cw", "ccw"):
        g = CamGeometry(TranslatingFlat(rb, 0.0, rot), prog)
        s = g.evaluate(np.linspace(0, 2 * np.pi, 1001))
        np.testing.assert_allclose(s.rho, rb + h / 2, rtol=1e-12)
        centres = s.point - s.rho[:, None] * s.normal
        np.testing.assert_allclose(centres, np.tile(centres[0], (len(centres), 1)), atol=1e-9)
        assert np.hypot(*centres[0]) == pytest.approx(h / 2, rel=1e-12)
        assert g.area() == pytest.approx(math.pi * (rb + h / 2) ** 2, rel=1e-10)
        assert g.max_radius == pytest.approx(rb + h, rel=1e-12)


def test_area_by_green_matches_polygon():
    g = CamGeometry(TranslatingRoller(35, 7), E9)
    p = g.evaluate(np.linspace(0, 2 * np.pi, 400001)[:-1]).point
    poly = 0.5 * abs(np.sum(p[:, 0] * np.roll(p[:, 1], -1) - np.roll(p[:, 0], -1) * p[:, 1]))
    assert g.area() == pytest.approx(poly, rel=1e-8)
    assert integrate(np.cos, [0.0, 1.0, 2.0]) == pytest.approx(math.sin(2.0), rel=1e-13)


# ---------------------------------------------------------------------------
# the thesis' own (cw) formulas, ch. 4–5 (as corrected in docs/decisions.md, "offset sign" and
# "oscillating followers")
def test_spec_formulas_translating_roller_offset():
    e, rb, rr = 8.0, 35.0, 7.0
    g = CamGeometry(TranslatingRoller(rb, rr, e), E9)
    phi = np.linspace(0.01, 2 * np.pi - 0.01, 997)
    s, (S, S1, S2) = g.evaluate(phi), E9.evaluate(phi, (0, 1, 2))
    m = -e  # the thesis' m is positive to the LEFT (90° ccw of the follower axis)
    L = S + math.sqrt((rb + rr) ** 2 - m * m)
    rho_p = ((S1 - m) ** 2 + L**2) ** 1.5 / (L**2 + (S1 - m) * (2 * S1 - m) - L * S2)
    np.testing.assert_allclose(s.rho_pitch, rho_p, rtol=1e-10)
    np.testing.assert_allclose(np.tan(s.pressure_angle), (S1 - m) / L, rtol=1e-10, atol=1e-13)


def test_spec_formulas_oscillating():
    m, a, rb, rr = 100.0, 90.0, 40.0, 10.0
    g = CamGeometry(OscillatingRoller(rb, rr, m, a), E11)
    phi = np.linspace(0.01, 2 * np.pi - 0.01, 997)
    s = g.evaluate(phi)
    S, S1, S2 = E11.evaluate(phi, (0, 1, 2)) * DEG
    xi0 = math.acos((a * a + m * m - (rb + rr) ** 2) / (2 * a * m))
    assert g.initial_arm_angle == pytest.approx(xi0)
    xi = xi0 + S
    c, d = m - a * (1 - S1) * np.cos(xi), a * (1 - S1) * np.sin(xi)
    rho_p = (c * c + d * d) ** 1.5 / ((c * c + d * d) * (1 - S1) + m * c * S1 - m * a * S2 * np.sin(xi))
    np.testing.assert_allclose(s.rho_pitch, rho_p, rtol=1e-9)
    # δ = γ + α − π/2 (ch. 5), in magnitude
    L = np.sqrt(a * a + m * m - 2 * a * m * np.cos(xi))
    gam = np.arccos((L**2 + a * a - m * m) / (2 * L * a))
    alpha = np.arctan2(a * np.sin(gam) * S1, L - a * np.cos(gam) * S1)
    np.testing.assert_allclose(np.abs(s.pressure_angle), np.abs(gam + alpha - np.pi / 2), atol=1e-10)
    # oscillating flat face: closed-form ρ and face position m cos ξ + R sin θ
    f = 5.0
    gf = CamGeometry(OscillatingFlat(rb, m, f), E11)
    sf = gf.evaluate(phi)
    xi = math.asin((rb - f) / m) + S
    rho = f + m * np.sin(xi) + m * (S2 * np.cos(xi) - S1**2 * (1 - S1) * np.sin(xi)) / (1 - S1) ** 3
    np.testing.assert_allclose(sf.rho, rho, rtol=1e-10)
    theta = np.arctan(S1 / (1 - S1) * m * np.cos(xi) / (f + m * np.sin(xi)))
    R = (f + m * np.sin(xi)) / np.cos(theta)
    np.testing.assert_allclose(sf.face_position, m * np.cos(xi) + R * np.sin(theta), rtol=1e-10)
    np.testing.assert_allclose(np.hypot(*sf.point.T), R, rtol=1e-12)


def test_translating_flat_face_position_and_curvature():
    g = CamGeometry(TranslatingFlat(45, 2.0), E9)
    phi = np.linspace(0, 2 * np.pi, 501)
    s, (S, S1, S2) = g.evaluate(phi), E9.evaluate(phi, (0, 1, 2))
    np.testing.assert_allclose(s.rho, 45 + S + S2, rtol=1e-12)
    np.testing.assert_allclose(s.face_position, -S1 - 2.0, atol=1e-12)  # cw: rising contact on the left
    np.testing.assert_allclose(s.pressure_angle, 0.0, atol=1e-15)
    assert s.pitch is None and s.arm_angle is None


# ---------------------------------------------------------------------------
# conventions: rotation sense and offset sign
def test_ccw_is_mirror_image():
    phi = np.linspace(0, 2 * np.pi, 361)
    for cw, ccw in [(TranslatingRoller(35, 7, 0.0), TranslatingRoller(35, 7, 0.0, "ccw")),
                    (TranslatingRoller(35, 7, -6.0), TranslatingRoller(35, 7, 6.0, "ccw")),
                    (TranslatingFlat(45, 3.0), TranslatingFlat(45, 3.0, "ccw"))]:
        a, b = CamGeometry(cw, E9).evaluate(phi), CamGeometry(ccw, E9).evaluate(phi)
        np.testing.assert_allclose(b.point, _mirror(a.point), atol=1e-12)
        np.testing.assert_allclose(b.normal, _mirror(a.normal), atol=1e-12)
        np.testing.assert_allclose(b.rho, a.rho, rtol=1e-12)
        np.testing.assert_allclose(b.pressure_angle, a.pressure_angle, atol=1e-12)
    # the translating cam: "right" is the mirror of "left" about the middle of the cam
    x = np.linspace(0, WEDGE.period, 301)
    a = CamGeometry(TranslatingCamRoller(5, 4.0, "left"), WEDGE).evaluate(x)
    b = CamGeometry(TranslatingCamRoller(5, 4.0, "right"), WEDGE).evaluate(x)
    np.testing.assert_allclose(b.point, _mirror(a.point) + [WEDGE.period, 0.0], atol=1e-12)
    np.testing.assert_allclose(b.pressure_angle, a.pressure_angle, atol=1e-14)


def test_offset_sign_convention():
    """A positive (right) offset raises the rise pressure angle of a cw cam:
    tan δ = (S' + σe)/(S + √(R_p² − e²)); for a ccw cam it lowers it."""
    def rise_peak(e, rot):
        g = CamGeometry(TranslatingRoller(50, 5, e, rot), E1)
        return np.degrees(g.evaluate(np.arange(0, 180, 0.25) * DEG).pressure_angle).max()

    base = rise_peak(0.0, "cw")
    assert rise_peak(10.0, "cw") > base + 5 and rise_peak(-10.0, "cw") < base - 5
    assert rise_peak(10.0, "ccw") < base - 5 and rise_peak(-10.0, "ccw") > base + 5
    # the follower axis really is to the right: pitch point at φ = 0 is (e, √(R_p² − e²))
    s = CamGeometry(TranslatingRoller(50, 5, 10.0), E1).evaluate(0.0)
    np.testing.assert_allclose(s.pitch[0], [10.0, math.sqrt(55**2 - 100)], atol=1e-12)
    # oscillating: pivot to the right, roller above the line of centres, rise turns the arm clockwise
    g = CamGeometry(OscillatingRoller(40, 10, 100, 90), E11)
    s0, s1 = g.evaluate(0.0), g.evaluate(180 * DEG)  # S = 0 and S = 25°
    assert s0.pitch[0, 1] > 0 and s1.arm_angle[0] - s0.arm_angle[0] == pytest.approx(25 * DEG)


def test_evaluate_shapes_and_breakpoints():
    g = CamGeometry(TranslatingRoller(35, 7), E9)
    s = g.evaluate(0.3)
    assert s.point.shape == (1, 2) and s.rho.shape == (1,)
    s = g.evaluate(np.linspace(0, 1, 17))
    assert s.point.shape == (17, 2) and s.tangent.shape == (17, 2) and s.pressure_angle.shape == (17,)
    b = g.breakpoints
    assert b[0] == 0.0 and b[-1] == pytest.approx(2 * np.pi) and np.all(np.diff(b) > 0)
    assert 50 * DEG in set(np.round(b, 15)) or np.any(np.isclose(b, 50 * DEG))
    np.testing.assert_allclose(np.hypot(*s.normal.T), 1.0, atol=1e-14)
    np.testing.assert_allclose((s.normal * s.tangent).sum(1), 0.0, atol=1e-14)
    assert CamGeometry(TranslatingRoller(35, 7), E9).initial_arm_angle is None
    osc = CamGeometry(OscillatingRoller(40, 10, 100, 90), E11)
    assert osc.initial_arm_angle_deg == pytest.approx(math.degrees(math.acos((90**2 + 100**2 - 50**2) / 18000)))


def test_multiple_profiles():
    a = CamGeometry(TranslatingRoller(35, 7), E9)
    b = CamGeometry(TranslatingFlat(45), E9)
    two = CamGeometry.from_contacts([a.profiles[0], b.profiles[0]], a.mechanism, E9)
    np.testing.assert_allclose(two.evaluate(0.7, profile=1).point, b.evaluate(0.7).point)
    assert two.radius_extremes(1).min == pytest.approx(45.0)


def test_positive_ranges_wraps_and_merges():
    edges = np.array([0.0, 1.0, 2 * np.pi])
    r = positive_ranges(lambda x: np.cos(x) - 0.5, edges)
    assert len(r) == 1
    lo, hi, xw, gw = r[0]
    assert lo == pytest.approx(5 * np.pi / 3, abs=1e-10) and hi == pytest.approx(np.pi / 3, abs=1e-10)
    assert gw == pytest.approx(0.5, abs=1e-12)
    assert positive_ranges(lambda x: np.cos(x) - 0.5, edges, closed=False)[0][0] == pytest.approx(0, abs=1e-9)


# ---------------------------------------------------------------------------
# refusals
@pytest.mark.parametrize("mech,path,rule", [
    (TranslatingRoller(30, 5, 35.0), "follower.offset_mm", "prime radius"),
    (TranslatingRoller(30, 5, -35.0), "follower.offset_mm", "prime radius"),
    (TranslatingRoller(-3, 5), "follower.base_radius_mm", "must be a length > 0"),
    (TranslatingRoller(30, -1), "follower.roller_radius_mm", ">= 0"),
    (TranslatingRoller(float("nan"), 5), "follower.base_radius_mm", "finite"),
    (TranslatingRoller(30, 5, float("inf")), "follower.offset_mm", "finite"),
    (TranslatingRoller(30, 5, rotation="up"), "cam.rotation", "cw"),
    (OscillatingRoller(40, 10, 100, 8), "follower.arm_length_mm", "longer than the roller"),
    (OscillatingRoller(40, 10, 300, 90), "follower.pivot_distance_mm", "prime circle"),
    (OscillatingRoller(40, 10, 20, 90), "follower.pivot_distance_mm", "prime circle"),
    (OscillatingRoller(40, 10, 0.0, 90), "follower.pivot_distance_mm", "> 0"),
    (OscillatingRoller(40, 10, 100, -90), "follower.arm_length_mm", "> 0"),
    (TranslatingFlat(0.0), "follower.base_radius_mm", "> 0"),
    (OscillatingFlat(40, 100, -70), "follower.face_offset_mm", "cannot touch"),
    (OscillatingFlat(40, -100, 0), "follower.pivot_distance_mm", "> 0"),
    (TranslatingCamRoller(-1.0), "follower.roller_radius_mm", ">= 0"),
    (TranslatingCamRoller(5.0, -2.0), "follower.base_height_mm", ">= 0"),
    (TranslatingCamRoller(5.0, 0.0, "up"), "cam.direction", "left"),
])
def test_refusals(mech, path, rule):
    probs = mech.validate()
    assert any(p.path == path and rule in p.rule and p.fix for p in probs), probs
    prog = WEDGE if isinstance(mech, TranslatingCamRoller) else (E11 if mech.motion == "oscillating" else E9)
    with pytest.raises(SpecError, match=path.replace(".", r"\.")):
        CamGeometry(mech, prog)


def test_refusals_collects_every_problem():
    probs = TranslatingRoller(-3, -1, 0.0, "sideways").validate()
    assert {p.path for p in probs} == {"cam.rotation", "follower.base_radius_mm", "follower.roller_radius_mm"}


def test_refusals_depending_on_motion():
    with pytest.raises(SpecError, match="one revolution"):
        CamGeometry(TranslatingRoller(35, 7), WEDGE)
    big = MotionProgram.from_segments([("cycloidal", 160, 180), ("cycloidal", -160, 180)])
    with pytest.raises(SpecError, match=r"motion\[\*\]\.lift.*180°"):
        CamGeometry(OscillatingRoller(40, 10, 100, 90), big)
    with pytest.raises(SpecError, match=r"past perpendicular"):
        CamGeometry(OscillatingFlat(40, 100, 0), MotionProgram.from_segments(
            [("cycloidal", 70, 180), ("cycloidal", -70, 180)]))
    fast = MotionProgram.from_segments([("cycloidal", 30, 20), ("dwell", 0, 160), ("cycloidal", -30, 180)])
    with pytest.raises(SpecError, match=r"as fast as the cam"):
        CamGeometry(OscillatingFlat(40, 100, 0), fast)
    with pytest.raises(TypeError):
        CamGeometry(object(), E9)  # type: ignore[arg-type]


# ---------------------------------------------------------------------------
# property-based: analytic curvature, normal and pressure angle vs finite differences
SMOOTH = ["cycloidal", "poly345", "poly4567", "modified_sine"]


@st.composite
def designs(draw):
    kind = draw(st.sampled_from(["tr", "or", "tf", "of", "wedge"]))
    laws = [draw(st.sampled_from(SMOOTH)) for _ in range(2)]
    b1, b2, b3 = (draw(st.floats(50, 140)), draw(st.floats(10, 60)), draw(st.floats(50, 140)))
    rot = draw(st.sampled_from(["cw", "ccw"]))
    if kind == "wedge":
        h = draw(st.floats(2, 15))
        prog = MotionProgram.from_segments([(laws[0], h, b1 / 2), ("dwell", 0, b2 / 2), (laws[1], -h, b3 / 2),
                                            ("dwell", 0, 20.0)], unit="mm")
        mech = TranslatingCamRoller(draw(st.floats(0, 10)), draw(st.floats(0, 20)),
                                    "left" if rot == "cw" else "right")
        return mech, prog
    osc = kind in ("or", "of")
    h = draw(st.floats(3, 18)) if osc else draw(st.floats(2, 30))
    prog = MotionProgram.from_segments([(laws[0], h, b1), ("dwell", 0, b2), (laws[1], -h, b3),
                                        ("dwell", 0, 360 - b1 - b2 - b3)])
    if kind == "tr":
        rb, rr = draw(st.floats(20, 80)), draw(st.floats(0, 15))
        mech = TranslatingRoller(rb, rr, draw(st.floats(-0.5, 0.5)) * (rb + rr), rot)
    elif kind == "tf":
        mech = TranslatingFlat(draw(st.floats(20, 80)), draw(st.floats(-10, 10)), rot)
    elif kind == "or":
        m = draw(st.floats(60, 150))
        a = draw(st.floats(0.5, 1.2)) * m
        rr = draw(st.floats(0, 12))
        rp = abs(a - m) + 5 + draw(st.floats(0.1, 0.6)) * (a + m - abs(a - m) - 10)
        assume(rp - rr > 5)
        mech = OscillatingRoller(rp - rr, rr, m, a, rot)
    else:
        m = draw(st.floats(60, 150))
        mech = OscillatingFlat(draw(st.floats(20, 0.6 * m)), m, draw(st.floats(-15, 15)), rot)
    return mech, prog


def _fixed_frame(geom, v, x):
    return v if not geom.closed else _rot(v, -geom.profiles[0].sense * x)


@settings(max_examples=25, deadline=None)
@given(designs())
def test_analytic_geometry_matches_finite_differences(design):
    mech, prog = design
    try:
        g = CamGeometry(mech, prog)
    except SpecError:
        assume(False)
    h = 1e-4 if g.closed else 1e-2  # mm: larger steps keep roundoff of S below the truncation error
    tol = 1e-6 if g.closed else 1e-5
    # curvature by central differences: truncation h²/12·|P⁗| reaches ~2e-7 /mm for h = 1e-2 mm on steep
    # translating cams (a hypothesis case: 4-5-6-7 of 12 mm over 25 mm)
    katol = 2e-7 if g.closed else 2e-6
    x = _away_from_breaks(g, np.linspace(0.013, g.period - 0.013, 151), h)
    s, sp, sm = g.evaluate(x), g.evaluate(x + h), g.evaluate(x - h)
    d1 = (sp.point - sm.point) / (2 * h)
    d2 = (sp.point - 2 * s.point + sm.point) / h**2
    speed = np.hypot(*d1.T)
    ok = (speed > 1e-3 * (1 + np.abs(s.point).max())) & (np.abs(s.rho) > 0.5)
    # analytic derivative, normal ⟂ generated curve, unit normal
    np.testing.assert_allclose(s.point_d1, d1, atol=1e-5 * (1 + np.abs(d1).max()))
    assert np.all(np.abs((d1[ok] * s.normal[ok]).sum(1)) <= tol * speed.max())
    np.testing.assert_allclose(np.hypot(*s.normal.T), 1.0, atol=1e-13)
    # signed curvature (positive = convex w.r.t. the outward normal), valid through undercuts
    kfd = -(d2 * s.normal).sum(1) / speed**2
    np.testing.assert_allclose(kfd[ok], s.curvature[ok], rtol=2e-4, atol=katol)
    if s.pitch is not None:
        p1 = (sp.pitch - sm.pitch) / (2 * h)
        p2 = (sp.pitch - 2 * s.pitch + sm.pitch) / h**2
        kp = -(p2 * s.normal).sum(1) / (p1**2).sum(1)
        np.testing.assert_allclose(kp, s.curvature_pitch, rtol=2e-4, atol=katol)
        assert np.all(np.abs((p1 * s.normal).sum(1)) <= tol * np.hypot(*p1.T).max())
        assert np.allclose(np.hypot(*(s.point - s.pitch).T), mech.roller_radius_mm, atol=1e-12)
    # pressure angle = angle between the contact normal and the follower point's velocity (fixed frame)
    n_fixed = _fixed_frame(g, s.normal, x)
    if isinstance(mech, (TranslatingRoller, OscillatingRoller, TranslatingCamRoller)):
        follower = lambda y: _fixed_frame(g, g.evaluate(y).pitch, y)  # noqa: E731
        v = (follower(x + h) - follower(x - h)) / (2 * h)
        if isinstance(mech, TranslatingCamRoller):
            v[:, 0] = 0.0  # the follower only translates vertically; the cam slides beneath it
    elif isinstance(mech, TranslatingFlat):
        v = np.stack([np.zeros_like(x), prog.evaluate(x, (1,))[0]], axis=1)
    else:  # material point of the face at the contact, turned rigidly about the pivot
        q = np.array([mech.pivot_distance_mm, 0.0])
        c = _fixed_frame(g, s.point, x) - q
        dxi = (prog.evaluate(x + h, (0,))[0] - prog.evaluate(x - h, (0,))[0]) * DEG
        v = (_rot(c, -dxi / 2) - _rot(c, dxi / 2)) / (2 * h)
    vn = np.hypot(*v.T)
    moving = vn > 1e-3 * max(vn.max(), 1e-12)
    ang = np.arccos(np.clip(np.abs((v[moving] * n_fixed[moving]).sum(1)) / vn[moving], 0, 1))
    np.testing.assert_allclose(np.abs(s.pressure_angle[moving]), ang, atol=2e-6)
    # minimum distance from the cam centre (or above the bottom edge) is the base radius (height)
    base = mech.base_height_mm if isinstance(mech, TranslatingCamRoller) else mech.base_radius_mm
    assert g.radius_extremes().min == pytest.approx(base, abs=1e-8)


def test_cos_sin_kernels_match_the_library_to_an_ulp():
    """The profile's own cos/sin (fdlibm kernels on numpy arrays) agree with numpy's to ~1 ulp, and
    fall back to the library beyond their reduction range and for NaN/inf."""
    from camfab.design.trig import SINCOS_MAX as _SINCOS_MAX
    from camfab.design.trig import cos_sin as _cos_sin

    rng = np.random.default_rng(7)
    x = np.concatenate([rng.uniform(-20, 20, 200_000), rng.uniform(-_SINCOS_MAX, _SINCOS_MAX, 50_000),
                        np.arange(-64, 65) * (np.pi / 4), [0.0, 1e-300, -1e-12]])
    c, s = _cos_sin(x)
    assert np.abs(c - np.cos(x)).max() <= 2.3e-16 and np.abs(s - np.sin(x)).max() <= 2.3e-16
    big = np.array([2 * _SINCOS_MAX, np.nan, np.inf])
    with np.errstate(invalid="ignore"):
        c, s = _cos_sin(big)
    assert c[0] == pytest.approx(np.cos(big[0]), abs=1e-12) and np.isnan(c[1:]).all()


@pytest.mark.parametrize("name", sorted(p.stem for p in EXAMPLES.glob("*.toml")))
def test_fixed_frame_sample_is_the_cam_frame_sample_turned_back(name):
    """``evaluate_fixed`` (what the checks read) is the cam-frame sample rotated by −σφ, so every
    frame-independent quantity agrees to rounding — for every example, conjugate second profiles
    (mirrored contacts) included."""
    from camfab.design.assemble import geometry_from_spec
    from camfab.formats import load_design

    g = geometry_from_spec(load_design(EXAMPLES / f"{name}.toml"))
    x = np.linspace(0.0, g.period, 1001) if not g.closed else np.linspace(-1.0, 7.5, 1001)
    for c in g.profiles:
        cam, fix = c.evaluate(x), c.evaluate_fixed(x)
        turn = (lambda v: v) if not c.closed else (lambda v, c=c: _rot(v, -c.sense * x))  # noqa: E731
        for f in ("point", "point_d1", "normal", "tangent", "pitch"):
            a, b = getattr(cam, f), getattr(fix, f)
            if a is None:
                assert b is None
                continue
            np.testing.assert_allclose(turn(a), b, rtol=0, atol=1e-14 * (1 + np.abs(a).max()))
        for f in ("curvature", "curvature_pitch", "pressure_angle", "face_position", "arm_angle"):
            a, b = getattr(cam, f), getattr(fix, f)
            assert (a is None and b is None) or np.array_equal(a, b, equal_nan=True), f
        np.testing.assert_allclose(np.hypot(*fix.point.T), np.hypot(*cam.point.T), rtol=1e-14)
