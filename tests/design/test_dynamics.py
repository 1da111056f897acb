"""Follower dynamics: contact force, jump, drive torque and work, against closed forms and
independent physics (virtual work / power balance, energy per cycle), over random designs."""
from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from camfab.design.assemble import check_design, dynamics_of, geometry_from_spec, loads_from_spec
from camfab.design.dynamics import ContactDynamics, Loads, analyse_dynamics
from camfab.design.mechanisms import (
    OscillatingCurved,
    OscillatingFlat,
    OscillatingRoller,
    TranslatingCamRoller,
    TranslatingCurved,
    TranslatingFlat,
    TranslatingRoller,
)
from camfab.design.profile import CamGeometry
from camfab.design.program import MotionProgram
from camfab.design.spec import design_from_dict
from camfab.errors import SpecError
from camfab.formats import load_design
from camfab.numeric import integrate
from camfab.units import RPM

from ..conftest import EXAMPLES

SHM = MotionProgram.from_segments([("simple_harmonic", 20, 180), ("simple_harmonic", -20, 180)])
RISE = MotionProgram.from_segments([("cycloidal", 12, 100), ("dwell", 0, 40), ("poly345", -12, 120),
                                    ("dwell", 0, 100)])
SWING = MotionProgram.from_segments([("cycloidal", 15, 120), ("dwell", 0, 60), ("modified_sine", -15, 120),
                                     ("dwell", 0, 60)])
WEDGE = MotionProgram.from_segments([("cycloidal", 12, 40), ("dwell", 0, 30), ("poly345", -12, 50),
                                     ("dwell", 0, 30)], unit="mm")
W = 600 * RPM


def test_translating_flat_shm_closed_form():
    """Flat face, SHM 180/180: N = m·S″ω² + F₀ + k·S exactly; the drive torque is N·S′ (virtual work,
    no friction); the follower jumps at the top when 0.5·0.01·ω² reaches F₀ + k·h = 150 N."""
    g = CamGeometry(TranslatingFlat(40.0), SHM)
    L = Loads(0.5, 5000.0, 50.0)
    d = ContactDynamics(g.profiles[0], L, W)
    x = np.linspace(0, 2 * np.pi, 721)
    s = d.evaluate(x)
    S0, S1, S2 = 10 * (1 - np.cos(x)), 10 * np.sin(x), 10 * np.cos(x)  # mm, per radian
    N = 0.5 * S2 * 1e-3 * W * W + 50.0 + 5000.0 * S0 * 1e-3
    np.testing.assert_allclose(s.contact_force, N, rtol=1e-13, atol=1e-11)
    np.testing.assert_allclose(s.drive, N * S1 * 1e-3, rtol=1e-12, atol=1e-13)
    np.testing.assert_allclose(s.bearing_force, np.abs(N), rtol=1e-14)
    rep = analyse_dynamics(g, L, W)
    # at this speed the bottom (S = 0, S″ = +10) is the weakest point, the top the strongest
    cf = rep.summary.contact_force
    assert cf.min == pytest.approx(50 + 0.005 * W * W, rel=1e-12) and cf.at_min == pytest.approx(0, abs=1e-6)
    assert cf.max == pytest.approx(150 - 0.005 * W * W, rel=1e-12) and cf.at_max == pytest.approx(180, abs=1e-6)
    # jump: 150 − 0.005·ω² = 0 at the top
    assert rep.summary.jump_speed.value == pytest.approx(math.sqrt(150 / 0.005) / RPM, rel=1e-10)
    assert rep.summary.jump_speed.unit == "rpm"
    assert abs(rep.summary.work_per_cycle_j) < 1e-12
    assert rep.findings == ()


def test_translating_roller_force_is_axial_over_cos_pressure_angle():
    g = CamGeometry(TranslatingRoller(35.0, 8.0, 6.0), RISE)
    L = Loads(0.3, 8000.0, 120.0, damping=15.0, external=20.0)
    c = g.profiles[0]
    x = np.linspace(0.01, 2 * np.pi - 0.01, 500)
    s = ContactDynamics(c, L, W).evaluate(x)
    S = RISE.evaluate(x, (0, 1, 2))
    G = 0.3 * S[2] * 1e-3 * W**2 + 120 + 8000 * S[0] * 1e-3 + 15 * S[1] * 1e-3 * W + 20
    np.testing.assert_allclose(s.required, G, rtol=1e-13)
    np.testing.assert_allclose(s.contact_force, G / np.cos(c.evaluate(x).pressure_angle), rtol=1e-12)


# ---------------------------------------------------------------------------
# property-based: power balance and energy per cycle over random designs
@st.composite
def cams(draw):
    kind = draw(st.sampled_from(["tr", "knife", "tf", "or", "of", "wedge", "tc", "oc"]))
    rot = draw(st.sampled_from(["cw", "ccw"]))
    mu = draw(st.sampled_from([0.0, 0.0, 0.05, 0.2]))
    damping = draw(st.sampled_from([0.0, 0.0, 30.0]))
    if kind == "wedge":
        mech = TranslatingCamRoller(draw(st.floats(0.0, 10.0)), draw(st.floats(0.0, 20.0)),
                                    "left" if rot == "cw" else "right")
        prog, speed = WEDGE, draw(st.floats(50.0, 2000.0))
        if mech.roller_radius_mm > 0:
            mu = 0.0
        loads = Loads(draw(st.floats(0.05, 2.0)), draw(st.floats(0.0, 2e4)), draw(st.floats(0.0, 300.0)),
                      damping, 0.0, mu)
        return mech, prog, loads, speed
    speed = draw(st.floats(10.0, 1500.0)) * RPM
    if kind in ("or", "of", "oc"):
        m = draw(st.floats(60.0, 150.0))
        if kind == "oc":  # a finger: the face's centre of curvature at A = f + R from the pivot
            rb, R = draw(st.floats(20.0, 0.5 * m)), draw(st.floats(5.0, 80.0))
            lo, hi = abs(m - rb - R) + 3, m + rb + R - 3
            a = lo + draw(st.floats(0.1, 0.9)) * (hi - lo)
            mech = OscillatingCurved(rb, R, m, a - R, rot)
        elif kind == "or":
            a = draw(st.floats(0.6, 1.1)) * m
            rr = draw(st.floats(0.0, 10.0))
            rp = abs(a - m) + 5 + draw(st.floats(0.2, 0.6)) * (a + m - abs(a - m) - 10)
            assume(rp - rr > 8)
            mech = OscillatingRoller(rp - rr, rr, m, a, rot)
            if rr > 0:
                mu = 0.0
        else:
            mech = OscillatingFlat(draw(st.floats(25.0, 0.6 * m)), m, draw(st.floats(-10.0, 10.0)), rot)
        loads = Loads(draw(st.floats(1e-3, 0.05)), draw(st.floats(0.0, 50.0)), draw(st.floats(0.0, 20.0)),
                      damping * 1e-3, 0.0, mu)
        return mech, SWING, loads, speed
    rb = draw(st.floats(25.0, 80.0))
    if kind == "tf":
        mech = TranslatingFlat(rb, draw(st.floats(-5.0, 5.0)), rot)
    elif kind == "tc":  # a mushroom: face radius from a near-roller to a near-flat face
        mech = TranslatingCurved(rb, draw(st.floats(3.0, 500.0)), draw(st.floats(-0.3, 0.3)) * rb, rot)
    else:
        rr = 0.0 if kind == "knife" else draw(st.floats(2.0, 12.0))
        mech = TranslatingRoller(rb, rr, draw(st.floats(-0.3, 0.3)) * rb, rot)
        if rr > 0:
            mu = 0.0
    loads = Loads(draw(st.floats(0.05, 2.0)), draw(st.floats(0.0, 2e4)), draw(st.floats(0.0, 300.0)), damping,
                  draw(st.floats(-10.0, 10.0)), mu)
    return mech, RISE, loads, speed


def _built(cam):
    """(geometry, contact, ContactDynamics, program, loads, speed) of a drawn design (invalid ones are
    discarded)."""
    mech, prog, L, speed = cam
    try:
        g = CamGeometry(mech, prog)
    except SpecError:
        assume(False)
    return g, g.profiles[0], ContactDynamics(g.profiles[0], L, speed), prog, L, speed


@settings(max_examples=40, deadline=None)
@given(cams())
def test_power_balance_and_work_per_cycle(cam):
    """The drive torque from the forces on the cam (T = σ·P × F) balances the power the follower takes
    (G·q̇, by virtual work) plus the friction loss μN·|v_rel|; over a cycle the work is the damping
    loss c·∮q̇² dt plus the friction loss — 0 for a conservative follower."""
    g, c, d, prog, L, speed = _built(cam)
    x = np.linspace(0.0, c.period, 2001)[:-1] + 1e-3
    s = d.evaluate(x)
    assume(np.all(s.lever > 1e-6))
    k = d.q_per_s
    S = prog.evaluate(x, (0, 1, 2))
    qd = k * S[1] * speed
    _, _, samp, w, u = d._kinematics(x)
    slip = np.hypot(*(u - w * qd[:, None]).T)
    loss = s.friction_force * slip if d.sliding else 0.0  # μN·|v_rel|
    scale = np.abs(s.power).max() + np.abs(s.required * qd).max() + 1e-9
    np.testing.assert_allclose(s.power, s.required * qd + loss, rtol=0, atol=1e-10 * scale)
    if not d.sliding:
        assert np.all(s.friction_force == 0)
    # work per cycle (J): ∮ drive dφ = damping loss + friction loss
    per = (lambda v: v) if c.closed else (lambda v: v * 1e-3)  # drive force × mm of travel
    work = per(integrate(lambda y: d.evaluate(y).drive, c.breakpoints, atol=1e-12 * scale * c.period))
    damp = L.damping * k * k * speed * integrate(lambda y: prog.evaluate(y, (1,))[0] ** 2, c.breakpoints)
    fric = 0.0  # ∫ μN·|v_rel| dt, dt = dφ/ω (or dx/v)
    if d.sliding and L.friction_coefficient:
        fric = integrate(lambda y: _friction_loss(d, y) / speed, c.breakpoints)
    assert work == pytest.approx(damp + fric, rel=1e-8, abs=1e-9 * scale * c.period / max(speed, 1e-9))


def _friction_loss(d, y):
    s = d.evaluate(y)
    _, S, _, w, u = d._kinematics(y)
    qd = d.q_per_s * S[1] * d.speed
    return s.friction_force * np.hypot(*(u - w * qd[:, None]).T)


@pytest.mark.parametrize("mech,mu", [
    (OscillatingRoller(40.0, 10.0, 100.0, 90.0), 0.0),
    (OscillatingCurved(40.0, 30.0, 100.0, 60.0), 0.08),
    (OscillatingCurved(30.0, 20.0, 90.0, 75.0, "ccw"), 0.15),
])
def test_contact_force_moment_balances_the_arm(mech, mu):
    """Oscillating roller (N·A·cos δ = G) and finger follower with friction: the moment about the pivot
    of the force on the follower — N along the normal plus the friction μN along the cam's slip past the
    follower's point at the contact — equals the required torque, an independent statement of the arm's
    moment balance."""
    g = CamGeometry(mech, SWING)
    c = g.profiles[0]
    assert c.sliding is (mu > 0)
    L = Loads(0.02, 30.0, 5.0, friction_coefficient=mu)
    x = np.linspace(0.02, 2 * np.pi - 0.02, 400)
    s = ContactDynamics(c, L, W).evaluate(x)
    fs = c.evaluate_fixed(x)
    force = s.contact_force[:, None] * (fs.normal + mu * _slip(c, fs.point, x, W))
    arm = (fs.point - np.array([c.m, 0.0])) * 1e-3  # a roller's normal passes through its centre: same moment
    moment = -(arm[:, 0] * force[:, 1] - arm[:, 1] * force[:, 0])  # clockwise (ξ increasing) positive
    np.testing.assert_allclose(moment, s.required, rtol=1e-11, atol=1e-12 * np.abs(s.required).max())
    np.testing.assert_allclose(s.friction_force, mu * s.contact_force, rtol=1e-14)


def _slip(c, point, x, speed):
    """Unit velocity of the cam's surface past the follower's material point at ``point`` (fixed frame,
    mm): the cam turns at −σω about its centre, the follower's point turns clockwise about the pivot
    (oscillating) or moves up (translating) at the rate of its lift."""
    S1 = c.motion.evaluate(x, (1,))[0]
    p = point * 1e-3
    cam = -c.sense * speed * np.stack([-p[:, 1], p[:, 0]], axis=1)
    if c.oscillating:
        r = p - np.array([c.m * 1e-3, 0.0])
        follower = (math.pi / 180 * S1 * speed)[:, None] * np.stack([r[:, 1], -r[:, 0]], axis=1)
    else:
        follower = np.stack([np.zeros_like(S1), 1e-3 * S1 * speed], axis=1)
    rel = cam - follower
    return rel / np.hypot(rel[:, 0], rel[:, 1])[:, None]


@pytest.mark.parametrize("name", ["finger_follower", "valve_mushroom"])
def test_curved_face_contact_force_from_first_principles(name):
    """The contact force of the curved-face examples built without the contact's formulas: the face's
    centre of curvature C from its definition (finger: pivot + (f + R)·n(ξ), ξ = ξ₀ + S; mushroom:
    (e, √((R_b + R)² − e²) + S)), the contact as the point of the cam's profile, turned to the cam angle,
    nearest to C (at the distance R), the normal along P→C, friction μN along the cam's slip, and the
    balance of the follower — moments about the pivot, or forces along the stem — against the spring,
    inertia and preload; with the example's friction μ = 0.05."""
    from scipy.optimize import minimize_scalar

    spec = load_design(EXAMPLES / f"{name}.toml")
    g = geometry_from_spec(spec)
    c, mech, L = g.profiles[0], g.mechanism, loads_from_spec(spec.dynamics)
    w = spec.speed
    assert L.friction_coefficient == 0.05 and c.sliding and c.curved_face
    x = np.radians(np.arange(2.5, 360.0, 7.5))
    S = spec.program().evaluate(x, (0, 1, 2))
    R = mech.face_radius_mm
    if c.oscillating:
        xi = mech.initial_arm_angle + np.radians(S[0])
        pivot = np.array([mech.pivot_distance_mm, 0.0])
        C = pivot + (mech.face_offset_mm + R) * np.stack([np.sin(xi), np.cos(xi)], axis=1)
        k = math.pi / 180  # q in rad per degree of S
    else:
        e = mech.offset_mm
        C = np.stack([np.full_like(x, e), math.sqrt((mech.base_radius_mm + R) ** 2 - e * e) + S[0]], axis=1)
        k = 1e-3  # q in m per mm of S
    G = L.inertia * k * S[2] * w * w + L.preload + L.spring_rate * k * S[0]
    grid = np.linspace(0.0, 2 * np.pi, 7201)
    prof = c.evaluate(grid).point  # the cam (cam frame)
    P = np.empty_like(C)
    for i, (phi, ci) in enumerate(zip(x, C, strict=True)):
        turn = -c.sense * phi  # the cam frame → the fixed frame at cam angle φ
        cs, sn = math.cos(turn), math.sin(turn)

        def dist(t, ci=ci, cs=cs, sn=sn):
            q = c.evaluate(np.array([t])).point[0]
            return math.hypot(q[0] * cs - q[1] * sn - ci[0], q[0] * sn + q[1] * cs - ci[1])

        fixed = np.stack([prof[:, 0] * cs - prof[:, 1] * sn, prof[:, 0] * sn + prof[:, 1] * cs], axis=1)
        j = int(np.argmin(np.hypot(*(fixed - ci).T)))
        t = minimize_scalar(dist, bracket=(grid[j - 1], grid[j], grid[j + 1]), tol=1e-12).x
        def slope(u, ci=ci, cs=cs, sn=sn):  # (q − C)·q′: 0 at the nearest point
            q, d = _turned(c, u, cs, sn)
            return float(np.dot(q - ci, d))

        for _ in range(3):  # polish the minimiser's t with secant steps on the slope
            f0, f1 = slope(t), slope(t + 1e-7)
            t -= f0 * 1e-7 / (f1 - f0) if f1 != f0 else 0.0
        P[i] = _turned(c, t, cs, sn)[0]
    np.testing.assert_allclose(np.hypot(*(P - C).T), R, rtol=0, atol=1e-9)  # the face touches the cam
    n = (C - P) / R
    F = n + L.friction_coefficient * _slip(c, P, x, w)  # force on the follower per newton of N
    if c.oscillating:
        arm = (P - pivot) * 1e-3
        lever = -(arm[:, 0] * F[:, 1] - arm[:, 1] * F[:, 0])  # clockwise moment per newton
    else:
        lever = F[:, 1]  # along the stem
    N = G / lever
    got = ContactDynamics(c, L, w).evaluate(x).contact_force
    np.testing.assert_allclose(got, N, rtol=1e-9)
    assert N.min() > L.safety_force_n


def _turned(c, t, cs, sn):
    """The profile point and its tangent (d/dt) at cam-frame parameter t, turned by the angle (cos, sin)."""
    s = c.evaluate(np.array([t]))
    q, d = s.point[0], s.point_d1[0]
    return (np.array([q[0] * cs - q[1] * sn, q[0] * sn + q[1] * cs]),
            np.array([d[0] * cs - d[1] * sn, d[0] * sn + d[1] * cs]))


# ---------------------------------------------------------------------------
# design helpers: the preload and the speed at the limit
@pytest.mark.parametrize("mech,prog,L", [
    (TranslatingRoller(35.0, 8.0, 4.0), RISE, Loads(0.4, 6000.0, 60.0, damping=20.0, safety_force_n=40.0)),
    (TranslatingFlat(45.0, 2.0, "ccw"), RISE, Loads(0.4, 3000.0, 40.0, friction_coefficient=0.1,
                                                    safety_force_n=25.0)),
    (OscillatingRoller(40.0, 10.0, 100.0, 90.0), SWING, Loads(0.02, 20.0, 3.0, safety_force_n=30.0)),
])
def test_needed_preload_and_jump_speed_sit_exactly_at_the_safety_force(mech, prog, L):
    g = CamGeometry(mech, prog)
    speed = 900 * RPM
    rep = analyse_dynamics(g, L, speed)
    pre = rep.summary.preload_needed.value
    at_limit = analyse_dynamics(g, Loads(**{**L.__dict__, "preload": pre}), speed)
    assert at_limit.summary.contact_force.min == pytest.approx(L.safety_force_n, rel=1e-9)
    jump = rep.summary.jump_speed.value * RPM
    for f, ok in ((1 - 1e-6, True), (1 + 1e-6, False)):
        r = analyse_dynamics(g, L, jump * f)
        assert (r.summary.contact_force.min >= L.safety_force_n * (1 - 1e-9)) is ok
        assert bool(r.findings) is not ok


def test_jump_ranges_and_messages():
    g = CamGeometry(TranslatingFlat(40.0), SHM)
    rep = analyse_dynamics(g, Loads(0.5, 500.0, 10.0, safety_force_n=5.0), 1200 * RPM)
    jump = [f for f in rep.findings if f.code == "FOLLOWER_JUMP"]
    low = [f for f in rep.findings if f.code == "CONTACT_FORCE_BELOW_SAFETY"]
    assert len(jump) == 1 and len(low) == 1
    # N = 0.5·10cos φ·1e-3·ω² + 10 + 0.5·10(1 − cos φ) = 0 where cos φ = −15/(0.005ω² − 5)
    w = 1200 * RPM
    phi = math.degrees(math.acos(-15 / (0.005 * w * w - 5)))
    assert jump[0].from_deg == pytest.approx(phi, abs=1e-8) and jump[0].to_deg == pytest.approx(360 - phi, abs=1e-8)
    assert jump[0].severity == "error" and jump[0].value == pytest.approx(20 - 0.005 * w * w, rel=1e-10)
    assert "raise the spring preload to at least" in jump[0].message and "rpm" in jump[0].message
    assert low[0].from_deg < jump[0].from_deg and low[0].limit == 5.0


def test_self_locking_with_high_friction_on_a_knife_edge():
    g = CamGeometry(TranslatingRoller(20.0, 0.0, 0.0), MotionProgram.from_segments(
        [("cycloidal", 25, 80), ("dwell", 0, 40), ("cycloidal", -25, 80), ("dwell", 0, 160)]))
    rep = analyse_dynamics(g, Loads(0.1, 1000.0, 50.0, friction_coefficient=1.5), 100 * RPM)
    lock = [f for f in rep.findings if f.code == "SELF_LOCKING"]
    assert lock and all(f.severity == "error" for f in lock)


# ---------------------------------------------------------------------------
# the design file
BASE = {"name": "t", "cam": {"speed_rpm": 1000}, "follower": {"type": "flat", "base_radius_mm": 30},
        "motion": [{"law": "cycloidal", "lift": 9, "angle_deg": 90}, {"law": "dwell", "angle_deg": 20},
                   {"law": "cycloidal", "lift": -9, "angle_deg": 90}, {"law": "dwell", "angle_deg": 160}]}


def _design(dyn, **over):
    d = {**BASE, **over, "dynamics": dyn}
    return design_from_dict(d)


def test_design_file_units_convert_to_si():
    spec = _design({"mass_kg": 0.2, "spring_rate_n_per_mm": 20, "spring_preload_n": 200, "damping_n_s_per_m": 3,
                    "external_force_n": 4, "friction_coefficient": 0.05, "safety_force_n": 100})
    L = loads_from_spec(spec.dynamics)
    assert (L.inertia, L.spring_rate, L.preload, L.damping, L.external, L.friction_coefficient,
            L.safety_force_n) == (0.2, 20000.0, 200.0, 3.0, 4.0, 0.05, 100.0)
    osc = load_design(EXAMPLES / "press_feed_oscillating.toml")
    L = loads_from_spec(osc.dynamics)
    assert L.spring_rate == pytest.approx(osc.dynamics.spring_rate * 180 / math.pi)
    assert osc.dynamics.preload_unit == "N·m"


@pytest.mark.parametrize("dyn,over,path", [
    ({"spring_rate_n_per_mm": 20}, {}, "dynamics.mass_kg"),
    ({"mass_kg": -1}, {}, "dynamics.mass_kg"),
    ({"mass_kg": 1, "spring_rate_n_per_mm": -5}, {}, "dynamics.spring_rate_n_per_mm"),
    ({"mass_kg": 1, "inertia_kg_m2": 0.1}, {}, "dynamics.inertia_kg_m2"),
    ({"mass_kg": 1, "spring_rate": 3}, {}, "dynamics.spring_rate"),
    ({"mass_kg": 1, "friction_coefficient": 0.1},
     {"follower": {"type": "roller", "base_radius_mm": 30, "roller_radius_mm": 5}}, "dynamics.friction_coefficient"),
    ({"mass_kg": 1}, {"cam": {}}, "cam.speed_rpm"),
    ({"mass_kg": 1, "spring_preload_n": 50}, {"cam": {"kind": "conjugate", "speed_rpm": 100},
                      "follower": {"type": "flat", "base_radius_mm": 30, "follower_distance_mm": 80}},
     "dynamics.spring_preload_n"),
    ({"mass_kg": 1, "safety_force_n": -1}, {}, "dynamics.safety_force_n"),
    ({"mass_kg": 1, "friction_coefficient": 3}, {}, "dynamics.friction_coefficient"),
])
def test_bad_dynamics_input_is_refused_naming_the_field(dyn, over, path):
    with pytest.raises(SpecError) as err:
        _design(dyn, **over)
    assert any(p.path == path for p in err.value.problems), [p.path for p in err.value.problems]


def test_a_curved_face_slides_and_takes_friction():
    """A curved face (mushroom or finger) is accepted with a friction coefficient, as a flat face is; a
    roller is refused it."""
    mushroom = {"type": "curved", "base_radius_mm": 30, "face_radius_mm": 80, "offset_mm": 2}
    spec = _design({"mass_kg": 0.1, "spring_rate_n_per_mm": 20, "spring_preload_n": 200,
                    "friction_coefficient": 0.06}, follower=mushroom)
    assert loads_from_spec(spec.dynamics).friction_coefficient == 0.06
    g = geometry_from_spec(spec)
    assert g.profiles[0].sliding and g.profiles[0].curved_face
    rep = check_design(spec)
    assert rep.dynamics.work_per_cycle_j > 0  # friction dissipates
    with pytest.raises(SpecError):
        _design({"mass_kg": 0.1, "friction_coefficient": 0.06},
                follower={"type": "roller", "base_radius_mm": 30, "roller_radius_mm": 8})


def test_check_report_carries_dynamics_and_its_verdict():
    ok = check_design(_design({"mass_kg": 0.2, "spring_rate_n_per_mm": 20, "spring_preload_n": 200,
                               "safety_force_n": 100}))
    d = ok.to_dict()["dynamics"]
    assert d["contact_force_n"]["min"] == pytest.approx(200.0, rel=1e-12)  # the dwell at S = 0
    assert ok.verdict != "unacceptable"
    weak = check_design(_design({"mass_kg": 0.2, "spring_rate_n_per_mm": 2, "spring_preload_n": 20}))
    assert weak.verdict == "unacceptable" and "FOLLOWER_JUMP" in weak.codes()
    none = check_design(design_from_dict(BASE))
    assert none.to_dict()["dynamics"] is None
    assert dynamics_of(_design({"mass_kg": 0.2, "spring_preload_n": 200})).summary.safety_force_n == 0.0


@pytest.mark.parametrize("name", ["valve_exhaust_ej1", "press_feed_oscillating", "valve_mushroom", "finger_follower"])
def test_examples_with_dynamics_hold_their_safety_force(name):
    rep = check_design(load_design(EXAMPLES / f"{name}.toml"))
    d = rep.to_dict()["dynamics"]
    assert d["contact_force_n"]["min"] >= d["safety_force_n"] > 0
    assert not rep.codes() & {"FOLLOWER_JUMP", "CONTACT_FORCE_BELOW_SAFETY", "SELF_LOCKING"}


# ---------------------------------------------------------------------------
# form-closed followers: conjugate pairs, constant width and constant diameter
from camfab.design.dynamics import pair_of  # noqa: E402
from camfab.design.mechanisms import (  # noqa: E402
    ConjugateOscillatingFlat,
    ConjugateOscillatingRoller,
    ConjugateTranslatingFlat,
    ConjugateTranslatingRoller,
    ConstantDiameterCam,
    ConstantWidthCam,
)

E9 = MotionProgram.from_segments([("modified_sine", 10, 50), ("dwell", 0, 40), ("cycloidal", -10, 50),
                                  ("dwell", 0, 40), ("poly345", 10, 50), ("dwell", 0, 40), ("poly4567", -10, 50),
                                  ("dwell", 0, 40)])
E2 = MotionProgram.from_segments([("poly4567", 10, 120), ("dwell", 0, 120), ("poly4567", -10, 120)])
PAIRS = [
    (ConjugateTranslatingFlat(100, 210), E9, Loads(0.4, damping=25.0, external=5.0, friction_coefficient=0.1)),
    (ConjugateTranslatingFlat(100, 210, "ccw"), E9, Loads(0.4)),
    (ConjugateTranslatingRoller(35, 7, 110, 4.0, 6.0, "ccw"), E9, Loads(0.4, damping=25.0, external=-3.0)),
    (ConjugateTranslatingRoller(35, 7, 110, 0.0, -5.0), E9, Loads(0.4)),
    (ConjugateOscillatingFlat(40, 100, 5, 60), E2, Loads(0.01, damping=0.02, friction_coefficient=0.08)),
    (ConjugateOscillatingRoller(40, 10, 100, 90, 95, 6.0, "ccw"), E2, Loads(0.01, external=0.3)),
    (ConstantWidthCam(40, 100, 120), None, Loads(0.4, damping=10.0, friction_coefficient=0.05)),
    (ConstantDiameterCam(40, 8, 110, 150, 0.0, "ccw"), None, Loads(0.4, external=2.0)),
]


@pytest.mark.parametrize("mech,prog,L", PAIRS)
def test_form_closed_power_balance_and_load_sharing(mech, prog, L):
    """Follower 1 carries G where G > 0 and follower 2 where G < 0 (never both); the drive torque from
    both contacts' forces on the cam balances G·q̇₁ plus the friction loss — an independent check that
    follower 2's contact (mirrored conjugate, or the same profile half a turn on) is mapped right."""
    g = mech.geometry(prog)
    pair = pair_of(g, L, W)
    x = np.linspace(0.0, 2 * np.pi, 1441)[:-1] + 1e-3
    s = pair.evaluate(x)
    G = s.required
    assert np.all(s.contact_force >= 0) and np.all(s.contact_force_2 >= 0)
    assert np.all((s.contact_force == 0) | (s.contact_force_2 == 0))
    np.testing.assert_allclose(np.where(G > 0, s.contact_force, -s.contact_force_2) * s.lever, G,
                               rtol=1e-12, atol=1e-12 * np.abs(G).max())
    S = g.profiles[0].motion.evaluate(x, (0, 1, 2))
    qd = pair.first.q_per_s * S[1] * W
    loss = 0.0
    for dyn, shift, N in ((pair.first, 0.0, s.contact_force), (pair.second, pair.shift, s.contact_force_2)):
        if dyn.sliding and L.friction_coefficient:
            _, S2, _, w, u = dyn._kinematics(x + shift)
            qd2 = dyn.q_per_s * S2[1] * W
            loss = loss + L.friction_coefficient * N * np.hypot(*(u - w * qd2[:, None]).T)
    scale = np.abs(G * qd).max() + 1e-12
    np.testing.assert_allclose(s.power, G * qd + loss, rtol=0, atol=1e-10 * scale)
    rep = analyse_dynamics(g, L, W)
    assert rep.summary.form_closed and rep.summary.jump_speed is None
    assert not [f for f in rep.findings if f.severity == "error"]


def test_constant_width_shm_loads_and_reversals():
    """Constant width, SHM rise 120°: G = m·S″·ω², so follower 1 pushes while S″ > 0 and follower 2 while
    S″ < 0; the load crosses at the SHM mid-points 60° and 240° only (the dwells carry nothing)."""
    mech = ConstantWidthCam(40, 100, 120)
    g = mech.geometry()
    rep = analyse_dynamics(g, Loads(0.4), W)
    h = 20.0  # width − 2·Rb
    peak = 0.4 * (h / 2) * (math.pi / (120 * math.pi / 180)) ** 2 * 1e-3 * W * W  # m·(h/2)(π/β)²·ω²
    assert rep.summary.contact_force.max == pytest.approx(peak, rel=1e-10)
    assert rep.summary.second_contact_force.max == pytest.approx(peak, rel=1e-10)
    rev = [f for f in rep.findings if f.code == "LOAD_REVERSAL"]
    assert [(round(f.from_deg, 9), round(f.to_deg, 9)) for f in rev] == [(60.0, 60.0), (240.0, 240.0)]
    assert all(f.severity == "info" for f in rev)
    assert abs(rep.summary.work_per_cycle_j) < 1e-12


def test_form_closed_design_file():
    d = {"name": "cw", "cam": {"kind": "constant_width", "speed_rpm": 300},
         "follower": {"type": "flat", "motion": "translating", "base_radius_mm": 40.0, "width_mm": 100.0},
         "dynamics": {"mass_kg": 0.4, "friction_coefficient": 0.05}}
    rep = check_design(design_from_dict(d))
    dyn = rep.to_dict()["dynamics"]
    assert dyn["form_closed"] and dyn["second_contact_force_n"]["max"] > 0 and dyn["load_reversals_deg"]
    assert rep.verdict != "unacceptable"
    for bad in ("spring_rate_n_per_mm", "spring_preload_n", "safety_force_n"):
        with pytest.raises(SpecError) as err:
            design_from_dict({**d, "dynamics": {"mass_kg": 0.4, bad: 10.0}})
        assert [p.path for p in err.value.problems] == [f"dynamics.{bad}"]


@settings(max_examples=15, deadline=None)
@given(cams())
def test_summary_extremes_are_exact_against_dense_sampling(cam):
    """The summary's extremes are refined, not sampled: never beaten by a dense grid, and attained at
    the angle they name."""
    g, c, d, prog, L, speed = _built(cam)
    x = np.linspace(0.0, c.period, 20001)
    s = d.evaluate(x)
    assume(np.all(s.lever > 1e-6) and np.all(np.isfinite(s.contact_force)))
    rep = analyse_dynamics(g, L, speed).summary
    to_x = (lambda v: math.radians(v)) if c.closed else (lambda v: v)
    for key, arr in (("contact_force", s.contact_force), ("drive", s.drive)):
        e = getattr(rep, key)
        tol = 1e-9 * (1 + np.abs(arr).max())
        assert e.min <= arr.min() + tol and e.max >= arr.max() - tol
        got = getattr(d.evaluate(np.array([to_x(e.at_min), to_x(e.at_max)])), key)
        np.testing.assert_allclose(got, [e.min, e.max], rtol=1e-9, atol=tol)
