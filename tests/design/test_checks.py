"""Profile checks: every finding code, its angle range, the verdict and the summary."""
from __future__ import annotations

import json
import math

import numpy as np
import pytest

from camfab.design.checks import CUSP_TOL_MM, check
from camfab.design.mechanisms import (
    OscillatingFlat,
    OscillatingRoller,
    TranslatingCamRoller,
    TranslatingFlat,
    TranslatingRoller,
)
from camfab.design.profile import CamGeometry
from camfab.design.program import MotionProgram
from camfab.numeric import extremum
from camfab.results import IssueCode

from ..conftest import EJEMPLO9RT, EJEMPLO11RO

DEG = math.pi / 180
E1 = MotionProgram.from_segments([("simple_harmonic", 50, 180), ("simple_harmonic", -50, 180)])
E9 = MotionProgram.from_segments(EJEMPLO9RT)
E11 = MotionProgram.from_segments(EJEMPLO11RO)
E2 = MotionProgram.from_segments([("poly4567", 10, 120), ("dwell", 0, 120), ("poly4567", -10, 120)])


def _dense(geom, attr, n=72001):
    x = np.linspace(0, geom.period, n)
    return x, getattr(geom.evaluate(x), attr)


def test_ejemplo9rt_is_sound():
    g = CamGeometry(TranslatingRoller(35, 7), E9)
    r = check(g, name="Ejemplo9RT")
    assert r.verdict == "not_for_high_speed"  # jerk jumps (modified sine, cycloidal, 3-4-5 next to dwells)
    assert r.codes() == {"JERK_DISCONTINUITY"}
    pa = r.pressure_angle
    x, d = _dense(g, "pressure_angle")
    assert pa.max == pytest.approx(np.degrees(d.max()), abs=1e-6) and 20 < pa.max < 30
    assert pa.min == pytest.approx(np.degrees(d.min()), abs=1e-6) and -30 < pa.min < -25
    assert 180 < pa.at_max < 230 and 270 < pa.at_min < 320  # the 3-4-5 rise, the 4-5-6-7 return
    roc = r.curvature
    _, kp = _dense(g, "curvature_pitch")
    assert roc.pitch_min_convex == pytest.approx(1 / kp.max(), rel=1e-6) and roc.pitch_min_convex > 7
    assert roc.min_convex == pytest.approx(roc.pitch_min_convex - 7)
    assert roc.min_concave == pytest.approx(-1 / kp.min() + 7, rel=1e-6)
    assert r.base_radius_mm == pytest.approx(35.0, abs=1e-9)
    assert r.max_radius_mm == pytest.approx(45.0, abs=1e-9)
    assert r.face_length is None and r.initial_arm_angle_deg is None
    d = json.loads(json.dumps(r.to_dict()))
    for key in ("name", "verdict", "peaks", "junctions", "pressure_angle_deg", "radius_of_curvature_mm",
                "face_length_mm", "base_radius_mm", "max_radius_mm", "area_mm2", "findings"):
        assert key in d
    assert d["verdict"] == "not_for_high_speed" and d["peaks"]["S"]["max"] == pytest.approx(10.0)
    assert {"code", "severity", "from_deg", "to_deg", "value", "limit", "message"} <= set(d["findings"][0])


def test_undercut_roller_range_is_exact():
    rr = 12.0
    g = CamGeometry(TranslatingRoller(8, rr), E9)
    r = check(g)
    assert r.verdict == "unacceptable"
    under = r.by_code(IssueCode.UNDERCUT)
    assert under and all(f.severity == "error" and f.limit == rr and 0 < f.value < rr for f in under)
    for f in under:
        rho = g.evaluate(np.radians([f.from_deg, f.to_deg])).rho_pitch
        np.testing.assert_allclose(rho, rr, rtol=1e-8)  # the range ends where ρ_pitch = R_r
        mid = np.radians(np.linspace(f.from_deg, f.to_deg, 9)[1:-1])
        assert np.all((g.evaluate(mid).rho_pitch < rr) & (g.evaluate(mid).rho_pitch > 0))
        assert "undercut" in f.message and "smaller than the roller" in f.message
    worst = min(f.value for f in under)
    assert worst == pytest.approx(r.curvature.pitch_min_convex, rel=1e-9)


def test_undercut_and_cusp_flat_face():
    smin = extremum(lambda x: np.sum(E9.evaluate(x, (0, 2)), axis=0), E9.breakpoints)[1]
    rb_cusp = -smin
    g = CamGeometry(TranslatingFlat(rb_cusp - 2.0), E9)
    r = check(g)
    under = r.by_code("UNDERCUT")
    assert under and r.verdict == "unacceptable" and under[0].limit == 0.0
    assert under[0].value == pytest.approx(-2.0, abs=1e-9)
    np.testing.assert_allclose(g.evaluate(np.radians([under[0].from_deg, under[0].to_deg])).rho, 0.0, atol=1e-9)
    cusp = check(CamGeometry(TranslatingFlat(rb_cusp), E9))
    assert cusp.codes() >= {"CUSP"} and "UNDERCUT" not in cusp.codes() and cusp.verdict == "unacceptable"
    c = cusp.by_code("CUSP")[0]
    assert abs(c.value) <= CUSP_TOL_MM and c.from_deg == c.to_deg and "cusp" in c.message
    ok = check(CamGeometry(TranslatingFlat(rb_cusp + 1e-3), E9))
    assert not ok.codes() & {"CUSP", "UNDERCUT"}


def test_cusp_roller():
    from camfab.design.sizing import min_base_radius_no_undercut

    rb = min_base_radius_no_undercut(TranslatingRoller(30, 12), E9)
    r = check(CamGeometry(TranslatingRoller(rb, 12), E9))
    assert "CUSP" in r.codes() and "UNDERCUT" not in r.codes()
    assert r.by_code("CUSP")[0].value == pytest.approx(12.0, abs=CUSP_TOL_MM)


def test_concave_radius_below_tool():
    g = CamGeometry(TranslatingRoller(35, 7), E9)
    r0 = check(g)
    fits = r0.curvature.min_concave
    assert "CONCAVE_RADIUS_BELOW_ROLLER" not in r0.codes()  # a roller always fits its own envelope (D10)
    r = check(g, tool_radius_mm=fits + 5.0)
    found = r.by_code(IssueCode.CONCAVE_RADIUS_BELOW_ROLLER)
    assert found and all(f.severity == "warning" for f in found)
    assert r.verdict == r0.verdict  # a manufacturing warning does not change the CAM-DAS verdict
    assert f"{fits:.6g}" in found[0].message and found[0].limit == fits + 5.0
    for f in found:
        rho = g.evaluate(np.radians([f.from_deg, f.to_deg])).rho
        np.testing.assert_allclose(rho, -(fits + 5.0), rtol=1e-8)
    assert not check(g, tool_radius_mm=fits - 0.01).by_code(IssueCode.CONCAVE_RADIUS_BELOW_ROLLER)


def test_pressure_angle_exceeded():
    g = CamGeometry(TranslatingRoller(50, 5), E1)
    r = check(g, pressure_angle_limit_deg=15.0)
    pa = r.by_code("PRESSURE_ANGLE_EXCEEDED")
    assert len(pa) == 2 and r.verdict == "unacceptable"
    rise, ret = sorted(pa, key=lambda f: f.from_deg)
    phi = np.linspace(0, np.pi, 200001)
    peak = np.degrees(np.arctan(25 * np.sin(phi) / (55 + 25 * (1 - np.cos(phi))))).max()  # 18.20996° (18.21)
    assert rise.value == pytest.approx(peak, abs=1e-8) and rise.limit == 15.0
    assert ret.value == pytest.approx(-peak, abs=1e-8) and ret.limit == -15.0
    assert rise.from_deg < 72 < rise.to_deg < 180 < ret.from_deg < 288 < ret.to_deg
    for f in pa:
        d = np.degrees(g.evaluate(np.radians([f.from_deg, f.to_deg])).pressure_angle)
        np.testing.assert_allclose(np.abs(d), 15.0, atol=1e-9)
    assert not check(g).by_code("PRESSURE_ANGLE_EXCEEDED")  # default 30°
    small = check(CamGeometry(TranslatingRoller(15, 5), E1))
    assert small.by_code("PRESSURE_ANGLE_EXCEEDED")[0].limit == 30.0
    # oscillating default 35°
    osc = CamGeometry(OscillatingRoller(40, 10, 100, 90), E11)
    pa = check(osc, pressure_angle_limit_deg=89).pressure_angle
    peak = max(abs(pa.max), abs(pa.min))
    assert 35 < peak < 50
    assert check(osc).by_code("PRESSURE_ANGLE_EXCEEDED")[0].limit in (35.0, -35.0)
    assert not check(osc, pressure_angle_limit_deg=peak + 0.1).by_code("PRESSURE_ANGLE_EXCEEDED")


def test_face_length_translating():
    x = np.linspace(0, 2 * np.pi, 200001)
    s1 = E9.evaluate(x, (1,))[0]
    for rot, left, right in (("cw", s1.max(), -s1.min()), ("ccw", -s1.min(), s1.max())):
        r = check(CamGeometry(TranslatingFlat(100, 0.0, rot), E9), face_margin_mm=1.0)
        fl = r.face_length
        assert fl.left == pytest.approx(left + 1.0, rel=1e-7) and fl.right == pytest.approx(right + 1.0, rel=1e-7)
        info = r.by_code(IssueCode.FACE_LENGTH)
        assert len(info) == 2 and all(f.severity == "info" for f in info)
        assert r.pressure_angle is None and r.verdict == "not_for_high_speed"
    # a stem offset to the right moves the contact to the left of the stem
    fl = check(CamGeometry(TranslatingFlat(100, 4.0), E9)).face_length
    assert fl.left == pytest.approx(s1.max() + 4.0, rel=1e-7)
    assert fl.right == pytest.approx(-s1.min() - 4.0, rel=1e-7)


def test_face_length_oscillating():
    g = CamGeometry(OscillatingFlat(40, 100, 5), E2)
    r = check(g)
    x, pos = _dense(g, "face_position")
    fl = r.face_length
    assert fl.max == pytest.approx(pos.max(), rel=1e-8) and fl.min == pytest.approx(pos.min(), rel=1e-8)
    assert fl.left is None and fl.right is None
    (f,) = r.by_code("FACE_LENGTH")
    assert f.value == pytest.approx(pos.max(), rel=1e-8) and "vertex" in f.message
    assert r.initial_arm_angle_deg == pytest.approx(math.degrees(math.asin(35 / 100)))
    assert r.verdict == "acceptable"


def test_motion_discontinuities_and_verdicts():
    vel = MotionProgram.from_segments([("constant_velocity", 10, 90), ("dwell", 0, 90),
                                       ("constant_velocity", -10, 90), ("dwell", 0, 90)])
    r = check(CamGeometry(TranslatingRoller(60, 5), vel))
    f = r.by_code("VELOCITY_DISCONTINUITY")
    assert len(f) == 4 and f[0].severity == "error" and r.verdict == "unacceptable"
    assert sorted(x.from_deg for x in f) == [0.0, 90.0, 180.0, 270.0]
    acc = MotionProgram.from_segments([("simple_harmonic", 10, 90), ("dwell", 0, 90),
                                       ("simple_harmonic", -10, 90), ("dwell", 0, 90)])
    g = CamGeometry(TranslatingRoller(60, 5), acc)
    r = check(g)
    assert r.by_code("ACCELERATION_DISCONTINUITY") and r.verdict == "unacceptable"
    assert not r.by_code("VELOCITY_DISCONTINUITY")
    r = check(g, allow_acceleration_jump=True)
    assert {f.severity for f in r.by_code("ACCELERATION_DISCONTINUITY")} == {"warning"}
    assert r.verdict == "not_for_high_speed"
    r = check(CamGeometry(TranslatingRoller(35, 7), E9), speed=2.0)
    jerk = r.by_code("JERK_DISCONTINUITY")
    assert jerk and jerk[0].severity == "warning" and r.verdict == "not_for_high_speed"
    assert r.motion.peaks.V.max == pytest.approx(2 * 21.4859, rel=1e-4)
    smooth = MotionProgram.from_segments([("poly4567", 10, 120), ("dwell", 0, 120), ("poly4567", -10, 120)])
    assert check(CamGeometry(TranslatingRoller(35, 7), smooth)).verdict == "acceptable"


def test_translating_cam():
    prog = MotionProgram.from_segments([("cycloidal", 12, 40), ("dwell", 0, 30), ("poly345", -12, 50),
                                        ("dwell", 0, 30)], unit="mm")
    g = CamGeometry(TranslatingCamRoller(6, 10.0), prog)
    r = check(g)
    x = np.linspace(0, prog.period, 100001)
    s1 = prog.evaluate(x, (1,))[0]
    pa = r.pressure_angle
    assert pa.max == pytest.approx(math.degrees(math.atan(s1.max())), abs=1e-6)
    assert pa.at_max == pytest.approx(20.0, abs=1e-5)  # mm of travel: middle of the cycloidal rise
    assert r.base_radius_mm is None and r.max_radius_mm is None
    assert r.x_unit == "mm" and r.area_mm2 > 150 * 10
    assert "PRESSURE_ANGLE_EXCEEDED" in r.codes()  # 12 mm over 40 mm of cycloidal: 31°
    assert r.by_code("PRESSURE_ANGLE_EXCEEDED")[0].limit == 30.0


def test_two_profiles_are_both_checked():
    a = CamGeometry(TranslatingRoller(35, 7), E9)
    b = CamGeometry(TranslatingRoller(8, 12), E9)
    two = CamGeometry.from_contacts([a.profiles[0], b.profiles[0]], a.mechanism, E9)
    r = check(two)
    assert r.by_code("UNDERCUT") and all(f.message.startswith("profile 2") for f in r.by_code("UNDERCUT"))
    assert len(r.by_code("JERK_DISCONTINUITY")) == len(check(a).by_code("JERK_DISCONTINUITY"))


def test_rules_run_in_registry_order_and_a_new_rule_is_one_entry(monkeypatch):
    import camfab.design.checks as checks_mod
    from camfab.design.checks import RULES, Rule, RuleResult, Scope
    from camfab.results import Finding, Severity

    assert [r.name for r in RULES] == ["continuity", "curvature", "pressure_angle", "face", "extent", "contact_stress"]
    seen = []

    def lift_rule(contact, limits, sample):
        """A contact rule: the dense sample is the one every rule reads; it may add report fields."""
        (_, lo), (_, hi) = sample.extremes("pressure_angle")
        seen.append(sample)
        return RuleResult((Finding(IssueCode.PRESSURE_ANGLE_EXCEEDED, Severity.INFO, None, None, hi - lo, None,
                                   "span of the pressure angle"),), {})

    monkeypatch.setattr(checks_mod, "RULES", RULES + (Rule("span", Scope.CONTACT, lift_rule),))
    a = CamGeometry(TranslatingRoller(35, 7), E9)
    two = CamGeometry.from_contacts([a.profiles[0], CamGeometry(TranslatingRoller(30, 7), E9).profiles[0]],
                                    a.mechanism, E9)
    r = check(two)
    span = [f for f in r.findings if f.severity == "info"]
    assert [f.message for f in span] == [f"profile {k}: span of the pressure angle" for k in (1, 2)]
    assert len(seen) == 2 and seen[0].dense is seen[0].dense  # one dense evaluation per contact, kept
    # registered after the extent rule, the new rule runs last (profile by profile): its findings come last
    assert r.findings[-1] is span[-1]
