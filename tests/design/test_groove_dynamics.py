"""Groove cams with ``[dynamics]``: the flank that carries the load is the sign of the required force (inner flank
G > 0, outer G < 0), against the open translating-roller cam of the same pitch curve without a spring; no jump;
the load reversals named by flank; the contact stress on each flank with the true roller radius."""
from __future__ import annotations

import math
import tomllib

import numpy as np
import pytest

from camfab.design.assemble import check_design, geometry_from_spec, strength_input
from camfab.design.dynamics import ContactDynamics, GrooveDynamics, Loads, analyse_dynamics, pair_of
from camfab.design.groove import GrooveOscillatingRoller, GrooveTranslatingRoller
from camfab.design.profile import CamGeometry
from camfab.design.program import MotionProgram
from camfab.design.rollers import OscillatingRoller, TranslatingRoller
from camfab.design.spec import design_from_dict
from camfab.design.strength import effective_modulus, hertz_line, relative_curvature
from camfab.errors import SpecError
from camfab.results import IssueCode
from camfab.units import RPM

from ..conftest import EXAMPLES

PROGRAM = MotionProgram.from_segments([("poly4567", 12, 100), ("dwell", 0, 80), ("poly4567", -12, 100),
                                       ("dwell", 0, 80)])
RB, RR, BACKLASH = 40.0, 8.0, 0.1
W = RR + BACKLASH / 2
LOADS = Loads(2.0, 0.0, 0.0)  # inertia alone: no spring (a groove has none)
SPEED = 300 * RPM


def _groove():
    return GrooveTranslatingRoller(RB, RR, 6.0, BACKLASH).geometry(PROGRAM)


OSC_PROGRAM = MotionProgram.from_segments([("cycloidal", 15, 120), ("dwell", 0, 60), ("cycloidal", -15, 120),
                                           ("dwell", 0, 60)], lift_unit="deg")


def test_oscillating_groove_against_the_open_arm():
    """The same for an oscillating roller (the arm's coordinate in radians, an inertia about the pivot): the
    carrying flank's force is the open arm's N or −N, by the sign of G."""
    geom = GrooveOscillatingRoller(RB, RR, 90.0, 70.0, 6.0, BACKLASH).geometry(OSC_PROGRAM)
    loads = Loads(0.01, 0.0, 0.0, external=0.5)
    groove = pair_of(geom, loads, SPEED)
    open_arm = ContactDynamics(CamGeometry(OscillatingRoller(RB, W, 90.0, 70.0), OSC_PROGRAM).profiles[0], loads,
                               SPEED)
    x = np.linspace(0, 2 * np.pi, 2001)
    g, o = groove.evaluate(x), open_arm.evaluate(x)
    up, down = o.required > 1e-9, o.required < -1e-9
    assert up.any() and down.any()
    np.testing.assert_allclose(g.contact_force[up], o.contact_force[up], rtol=1e-11)
    np.testing.assert_allclose(g.contact_force_2[down], -o.contact_force[down], rtol=1e-11)
    assert np.all(g.lever > 0)


def test_groove_forces_match_the_open_cam_without_spring():
    """The open cam with a roller of radius w on the same pitch curve (the inner flank is its profile) and no
    spring: the same required force G = M·S″ω²; where G > 0 the inner flank's force is the open cam's N; where
    G < 0 the open follower would leave its cam (N < 0) and the outer flank pushes with −N (its normal is the
    inner's reversed on the same line); never both; the drive power is G·q̇ (no friction), each flank's torque
    taken at its own contact point."""
    geom = _groove()
    groove = pair_of(geom, LOADS, SPEED)
    assert isinstance(groove, GrooveDynamics)
    open_cam = ContactDynamics(CamGeometry(TranslatingRoller(RB, W), PROGRAM).profiles[0], LOADS, SPEED)
    x = np.linspace(0, 2 * np.pi, 3601)
    g, o = groove.evaluate(x), open_cam.evaluate(x)
    np.testing.assert_allclose(g.required, o.required, rtol=1e-13, atol=1e-9)
    up, down = o.required > 1e-9, o.required < -1e-9
    assert up.any() and down.any()
    np.testing.assert_allclose(g.contact_force[up], o.contact_force[up], rtol=1e-12)
    np.testing.assert_allclose(g.contact_force_2[down], -o.contact_force[down], rtol=1e-12)
    assert np.all(g.contact_force[~up] == 0) and np.all(g.contact_force_2[~down] == 0)
    assert np.all(g.lever > 0)  # never wedged: the carrying flank's lever is positive
    np.testing.assert_allclose(g.drive[up], o.drive[up], rtol=1e-12, atol=1e-12)
    qd = 1e-3 * g.motion[1] * SPEED
    np.testing.assert_allclose(g.power, g.required * qd, rtol=1e-9, atol=1e-9)


def test_groove_analysis_has_no_jump_and_names_the_flanks():
    """analyse_dynamics on the groove: form-closed, no FOLLOWER_JUMP (the open cam without spring jumps), the
    load passes from flank to flank where S″ changes sign (50° into the rise, 230° in the return) and nowhere
    else (the rounding noise of G at the ends of the laws, next to the unloaded dwells, is no reversal), the outer
    flank's largest force the open cam's most negative one."""
    rep = analyse_dynamics(_groove(), LOADS, SPEED)
    s = rep.summary
    assert s.form_closed and not [f for f in rep.findings if f.code is IssueCode.FOLLOWER_JUMP]
    open_rep = analyse_dynamics(CamGeometry(TranslatingRoller(RB, W), PROGRAM), LOADS, SPEED)
    assert [f for f in open_rep.findings if f.code is IssueCode.FOLLOWER_JUMP]
    rev = [f for f in rep.findings if f.code is IssueCode.LOAD_REVERSAL]
    assert sorted(round(f.from_deg, 6) for f in rev) == [50.0, 230.0]  # not in the dwells (no load, no noise)
    np.testing.assert_allclose(s.load_reversals, [[50.0, 50.0], [230.0, 230.0]], atol=1e-6)
    assert all("inner flank" in f.message and "outer flank" in f.message for f in rev)
    assert s.second_contact_force.max == pytest.approx(-open_rep.summary.contact_force.min, rel=1e-9)
    assert s.contact_force.max == pytest.approx(open_rep.summary.contact_force.max, rel=1e-9)


def _design(**tables) -> dict:
    data = tomllib.loads((EXAMPLES / "groove_translating.toml").read_text(encoding="utf-8"))
    data["cam"] = {k: v for k, v in data["cam"].items() if k != "omega_rad_s"} | {"speed_rpm": 300.0}
    for key, table in tables.items():
        data[key] = {**data.get(key, {}), **table}
    return data


def test_groove_contact_stress_on_each_flank():
    """A groove design with [dynamics]: check runs, the contact stress is that of each flank's force on its own
    curvature (the outer flank concave where the pitch curve is convex) with the roller's radius R_r (not the
    groove half-width), over the groove depth as the face width; both flanks reported."""
    spec = design_from_dict(_design(dynamics={"mass_kg": 2.0}))
    geom = geometry_from_spec(spec)
    inp = strength_input(spec, geom)
    assert inp is not None and inp.width_mm == 6.0 and inp.roller_radius_mm == RR
    assert any("groove depth" in n for n in inp.notes)
    rep = check_design(spec)
    cs = rep.contact_stress
    assert cs is not None and cs.max_mpa is not None and cs.second is not None
    assert not [f for f in rep.findings if f.code is IssueCode.FOLLOWER_JUMP]
    x = np.linspace(0, 2 * np.pi, 100_001)
    sm = inp.dynamics.evaluate(x)
    e = effective_modulus(inp.cam.e_mpa, inp.cam.poisson, inp.follower.e_mpa, inp.follower.poisson)
    k1 = geom.profiles[0].evaluate_fixed(x).curvature
    k2 = geom.profiles[1].evaluate_fixed(x).curvature
    assert (k2 < 0).any()  # concave outer flank
    p1 = hertz_line(sm.contact_force, e, 6.0, relative_curvature(k1, RR))[0]
    p2 = hertz_line(sm.contact_force_2, e, 6.0, relative_curvature(k2, RR))[0]
    assert p1.max() > 0 and p2.max() > 0
    assert max(p1.max(), p2.max()) == pytest.approx(cs.max_mpa, rel=1e-6)
    assert cs.second[0] == pytest.approx(p2.max(), rel=1e-6)
    assert cs.roller_life is None  # no bearing rating given


def test_groove_roller_life_follows_the_carrying_flank():
    """One roller: P = (Σ∫N^p ds / Σ∫ds)^(1/p), s along the flank that carries it (the inner where G > 0, the
    outer where G < 0), turns Σ∫ds/(2π·R_r) — against dense sampling of the same sums; L10 = (C/P)^(10/3)."""
    spec = design_from_dict(_design(dynamics={"mass_kg": 2.0}, strength={"roller_dynamic_rating_n": 9000.0}))
    geom = geometry_from_spec(spec)
    life = check_design(spec).contact_stress.roller_life
    assert life is not None
    x = np.linspace(0, 2 * np.pi, 400_001)
    sm = strength_input(spec, geom).dynamics.evaluate(x)
    d1, d2 = (np.hypot(*geom.profiles[k].evaluate(x).point_d1.T) for k in (0, 1))
    p = 10 / 3
    load = np.trapezoid(np.maximum(sm.contact_force, 0) ** p * d1 + np.maximum(sm.contact_force_2, 0) ** p * d2, x)
    length = np.trapezoid(d1 * (sm.required > 0) + d2 * (sm.required < 0), x)
    assert life.equivalent_load_n == pytest.approx((load / length) ** (1 / p), rel=1e-5)
    assert life.roller_revolutions_per_cycle == pytest.approx(length / (2 * math.pi * RR), rel=1e-5)
    assert life.l10_million_revolutions == pytest.approx((9000.0 / life.equivalent_load_n) ** p, rel=1e-12)
    assert life.cam_cycles == pytest.approx(life.l10_million_revolutions * 1e6 / life.roller_revolutions_per_cycle,
                                            rel=1e-12)


def test_groove_refuses_a_spring_and_vibration():
    """A groove has no return spring and cannot jump: the spring keys and [vibration] are refused, naming the field."""
    with pytest.raises(SpecError) as e:
        design_from_dict(_design(dynamics={"mass_kg": 2.0, "spring_rate_n_per_mm": 5.0}))
    assert "dynamics.spring_rate_n_per_mm" in {p.path for p in e.value.problems}
    with pytest.raises(SpecError) as e:
        design_from_dict(_design(dynamics={"mass_kg": 2.0}, vibration={"stiffness_n_per_mm": 1e4}))
    assert any(p.path == "vibration" and "groove" in p.rule for p in e.value.problems)
    assert math.isfinite(design_from_dict(_design(dynamics={"mass_kg": 2.0})).speed)
