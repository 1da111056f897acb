"""Curved-face followers (mushroom and finger): closed forms, the flat-face limit, finite differences and
independent geometry of the contact position and pressure angle, checks, and refusals."""
from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from camfab.design.checks import check
from camfab.design.curved import OscillatingCurved, TranslatingCurved
from camfab.design.kinds import ContactKind, FollowerMotion, FollowerType
from camfab.design.mechanisms import MECHANISMS, OscillatingFlat, TranslatingFlat, TranslatingRoller
from camfab.design.program import MotionProgram
from camfab.design.rollers import OscillatingRollerContact
from camfab.errors import SpecError

from ..conftest import EJEMPLO9RT

DEG = math.pi / 180
E9 = MotionProgram.from_segments(EJEMPLO9RT)
VALVE = MotionProgram.from_segments([("dwell", 0, 120), ("poly4567", 8, 60), ("poly4567", -8, 60),
                                     ("dwell", 0, 120)])
ARM = MotionProgram.from_segments([("dwell", 0, 100), ("poly4567", 12, 80), ("poly4567", -12, 80),
                                   ("dwell", 0, 100)], lift_unit="deg")
X = np.linspace(0.0, 2 * math.pi, 721)


def _fixed(g, v, x):
    """Cam-frame vectors turned back into the fixed (follower) frame."""
    a = -g.profiles[0].sense * x
    c, s = np.cos(a), np.sin(a)
    return np.stack([v[:, 0] * c - v[:, 1] * s, v[:, 0] * s + v[:, 1] * c], axis=1)


def test_registered_as_one_family_each():
    assert MECHANISMS[("disc", FollowerType.CURVED, FollowerMotion.TRANSLATING)] is TranslatingCurved
    assert MECHANISMS[("disc", FollowerType.CURVED, FollowerMotion.OSCILLATING)] is OscillatingCurved
    c = TranslatingCurved(30, 50).geometry(VALVE).profiles[0]
    assert c.kind is ContactKind.ROLLER and c.has_face and c.sliding and not c.oscillating


# ---------------------------------------------------------------------------
# closed form: a curved face of radius R touches the cam as a roller of radius R at its centre of curvature
@pytest.mark.parametrize("rot", ["cw", "ccw"])
@pytest.mark.parametrize("e", [0.0, 6.0, -4.0])
def test_mushroom_is_a_roller_at_the_centre_of_curvature(rot, e):
    curved = TranslatingCurved(30, 40, e, rot).geometry(VALVE).evaluate(X)
    roller = TranslatingRoller(30, 40, e, rot).geometry(VALVE).evaluate(X)
    for name in ("point", "point_d1", "normal", "pitch", "curvature", "curvature_pitch", "pressure_angle"):
        np.testing.assert_array_equal(getattr(curved, name), getattr(roller, name), err_msg=name)
    np.testing.assert_array_equal(curved.face_position, -40 * _fixed_geom_normal(TranslatingCurved(30, 40, e, rot)))


def _fixed_geom_normal(mech):
    g = mech.geometry(VALVE)
    return g.profiles[0].evaluate_fixed(X).normal[:, 0]


@pytest.mark.parametrize("rot", ["cw", "ccw"])
@pytest.mark.parametrize("f", [0.0, 8.0, -5.0])
def test_finger_is_a_roller_on_an_arm_to_the_centre_of_curvature(rot, f):
    R, m = 60.0, 90.0
    mech = OscillatingCurved(35, R, m, f, rot)
    # the roller's own construction (its arm need not be longer than the "roller" here: the face is no wheel)
    a_len, rp = f + R, 35 + R
    zeta0 = math.acos((a_len**2 + m**2 - rp**2) / (2 * a_len * m))
    roller = OscillatingRollerContact(ARM, m, a_len, zeta0, R, 1 if rot == "cw" else -1)
    # the arm to the centre of curvature stands 90° ahead of the face angle
    assert mech.initial_arm_angle + math.pi / 2 == pytest.approx(zeta0, abs=1e-12)
    a, b = mech.geometry(ARM).evaluate(X), roller.evaluate(X)
    for name in ("point", "point_d1", "normal", "pitch", "curvature", "curvature_pitch"):
        np.testing.assert_allclose(getattr(a, name), getattr(b, name), rtol=1e-12, atol=1e-10, err_msg=name)
    np.testing.assert_allclose(a.arm_angle, b.arm_angle - math.pi / 2, atol=1e-12)


# ---------------------------------------------------------------------------
# the flat face is the limit of an infinite face radius
@pytest.mark.parametrize("rot", ["cw", "ccw"])
def test_mushroom_tends_to_the_flat_face(rot):
    flat = TranslatingFlat(30, 5.0, rot).geometry(VALVE).evaluate(X)
    errs = []
    for R in (1e4, 1e5, 1e6):
        s = TranslatingCurved(30, R, 5.0, rot).geometry(VALVE).evaluate(X)
        errs.append([np.abs(s.point - flat.point).max(), np.abs(s.face_position - flat.face_position).max(),
                     np.abs(s.pressure_angle).max(), np.abs(s.rho - flat.rho).max()])
    _converges_like_one_over_r(np.array(errs), [1e-3, 1e-3, 3e-5, 5e-3])


@pytest.mark.parametrize("rot", ["cw", "ccw"])
@pytest.mark.parametrize("f", [0.0, 6.0])
def test_finger_tends_to_the_flat_face(rot, f):
    flat_mech = OscillatingFlat(35, 100, f, rot)
    flat = flat_mech.geometry(ARM).evaluate(X)
    errs = []
    for R in (1e4, 1e5, 1e6):
        mech = OscillatingCurved(35, R, 100, f, rot)
        s = mech.geometry(ARM).evaluate(X)
        errs.append([abs(mech.initial_arm_angle - flat_mech.initial_arm_angle),
                     np.abs(s.point - flat.point).max(), np.abs(s.face_position - flat.face_position).max(),
                     np.abs(s.pressure_angle - flat.pressure_angle).max(), np.abs(s.arm_angle - flat.arm_angle).max()])
    _converges_like_one_over_r(np.array(errs), [1e-4, 1e-2, 1e-2, 1e-4, 1e-4])


def _converges_like_one_over_r(errs, last):
    """Each error shrinks tenfold per decade of R (first order in 1/R: the face's sag d²/2R), so the
    limit is the flat face; at R = 1e6 mm each is below ``last``."""
    assert np.all(errs[-1] < last), errs
    ratio = errs[1:] / errs[:-1]
    assert np.all((ratio > 0.08) & (ratio < 0.12)), ratio


# ---------------------------------------------------------------------------
# property-based: finite differences, and the contact position and pressure angle rebuilt independently
SMOOTH = ["cycloidal", "poly345", "poly4567", "modified_sine"]


@st.composite
def designs(draw):
    osc = draw(st.booleans())
    laws = [draw(st.sampled_from(SMOOTH)) for _ in range(2)]
    b1, b2, b3 = draw(st.floats(60, 140)), draw(st.floats(10, 60)), draw(st.floats(60, 140))
    rot = draw(st.sampled_from(["cw", "ccw"]))
    h = draw(st.floats(3, 15)) if osc else draw(st.floats(2, 15))
    prog = MotionProgram.from_segments([(laws[0], h, b1), ("dwell", 0, b2), (laws[1], -h, b3),
                                        ("dwell", 0, 360 - b1 - b2 - b3)], lift_unit="deg" if osc else "mm")
    rb, R = draw(st.floats(20, 60)), draw(st.floats(8, 300))
    if osc:
        m = draw(st.floats(70, 160))
        mech = OscillatingCurved(rb, R, m, draw(st.floats(-0.5, 0.5)) * R, rot)
    else:
        mech = TranslatingCurved(rb, R, draw(st.floats(-0.4, 0.4)) * rb, rot)
    return mech, prog


@settings(max_examples=30, deadline=None)
@given(designs())
def test_curved_faces_match_finite_differences_and_their_definitions(design):
    mech, prog = design
    try:
        g = mech.geometry(prog)
    except SpecError:
        assume(False)
    h = 1e-4
    b = g.breakpoints
    x = np.linspace(0.013, 2 * math.pi - 0.013, 151)
    x = x[np.min(np.abs(np.mod(x[:, None] - b[None, :] + math.pi, 2 * math.pi) - math.pi), axis=1) > 4 * h]
    s, sp, sm = g.evaluate(x), g.evaluate(x + h), g.evaluate(x - h)
    d1 = (sp.point - sm.point) / (2 * h)
    np.testing.assert_allclose(s.point_d1, d1, atol=1e-5 * (1 + np.abs(d1).max()))
    np.testing.assert_allclose(np.hypot(*(s.point - s.pitch).T), mech.face_radius_mm, rtol=1e-12)
    # in the fixed frame: the contact point P, its normal n, the face's centre C = P + R·n
    P, n = _fixed(g, s.point, x), _fixed(g, s.normal, x)
    S = prog.evaluate(x, (0, 1))
    R = mech.face_radius_mm
    if isinstance(mech, TranslatingCurved):
        # C on the stem axis at √((R_b + R)² − e²) + S; the position is measured from the axis
        C = P + R * n
        np.testing.assert_allclose(C[:, 0], mech.offset_mm, atol=1e-9)
        np.testing.assert_allclose(C[:, 1], math.sqrt((mech.base_radius_mm + R) ** 2 - mech.offset_mm**2) + S[0],
                                   atol=1e-9)
        np.testing.assert_allclose(s.face_position, P[:, 0] - mech.offset_mm, atol=1e-9)
        v = np.stack([np.zeros_like(x), np.ones_like(x)], axis=1)
    else:
        xi = mech.initial_arm_angle + DEG * S[0]
        nf = np.stack([np.sin(xi), np.cos(xi)], axis=1)  # the face normal at its vertex
        pivot = np.array([mech.pivot_distance_mm, 0.0])
        V = pivot + mech.face_offset_mm * nf  # the vertex: the pivot's foot on the face's tangent
        np.testing.assert_allclose(P + R * n, V + R * nf, atol=1e-9)  # C rigid on the arm
        np.testing.assert_allclose(s.arm_angle, xi, atol=1e-12)
        # the arc length from the vertex: R × the angle turning the contact normal into the vertex normal
        psi = np.arctan2(n[:, 0] * nf[:, 1] - n[:, 1] * nf[:, 0], (n * nf).sum(1))
        np.testing.assert_allclose(s.face_position, R * psi, atol=1e-9)
        # to first order it is the flat face's distance along the tangent
        tangent = np.stack([-nf[:, 1], nf[:, 0]], axis=1)
        np.testing.assert_allclose(R * np.sin(psi), ((P - V) * tangent).sum(1), atol=1e-9)
        r = P - pivot
        v = np.stack([r[:, 1], -r[:, 0]], axis=1)  # the material point at P turns clockwise about the pivot
    ang = np.arctan2(np.abs(v[:, 0] * n[:, 1] - v[:, 1] * n[:, 0]), np.abs((v * n).sum(1)))
    np.testing.assert_allclose(np.abs(s.pressure_angle), ang, atol=1e-9)
    assert g.radius_extremes().min == pytest.approx(mech.base_radius_mm, abs=1e-8)


# ---------------------------------------------------------------------------
# the existing checks work on curved faces through the contact's declared properties
def test_checks_on_a_mushroom_follower():
    rep = check(TranslatingCurved(30, 40).geometry(VALVE))
    assert rep.verdict == "acceptable"
    face = [f for f in rep.findings if f.code == "FACE_LENGTH"]
    assert len(face) == 2  # either side of the stem
    s = TranslatingCurved(30, 40).geometry(VALVE).evaluate(np.linspace(0, 2 * math.pi, 20001))
    # exact extremes: never beaten by a dense sample, and within its resolution of it
    assert 0 <= face[0].value + s.face_position.min() < 1e-5
    assert 0 <= face[1].value - s.face_position.max() < 1e-5
    pa = rep.pressure_angle
    assert pa.max == pytest.approx(math.degrees(s.pressure_angle.max()), abs=1e-4) and pa.limit == 30.0


def test_a_small_face_radius_on_a_steep_cam_undercuts_like_the_roller():
    steep = MotionProgram.from_segments([("cycloidal", 30, 40), ("dwell", 0, 140), ("cycloidal", -30, 40),
                                         ("dwell", 0, 140)])
    a = check(TranslatingCurved(15, 25).geometry(steep))
    b = check(TranslatingRoller(15, 25).geometry(steep))
    assert {"UNDERCUT", "PRESSURE_ANGLE_EXCEEDED"} <= {f.code for f in a.findings}
    assert [(f.code, f.from_deg, f.to_deg) for f in a.findings if f.code != "FACE_LENGTH"] == \
        [(f.code, f.from_deg, f.to_deg) for f in b.findings]


def test_undercut_advice_for_a_curved_face():
    """The findings name the face and its radius, and their advice holds: a smaller face radius (or a larger
    base circle) cures an undercut, as for a roller — a larger one sharpens the profile towards the flat
    face's; a larger face radius lowers a mushroom's pressure angle (R_b + R grows)."""
    steep = MotionProgram.from_segments([("cycloidal", 30, 40), ("dwell", 0, 140), ("cycloidal", -30, 40),
                                         ("dwell", 0, 140)])
    rep = check(TranslatingCurved(15, 25).geometry(steep))
    under = [f.message for f in rep.findings if f.code == "UNDERCUT"]
    assert under and all("smaller than the face radius (25 mm); the face cannot follow the law there" in m
                         and m.endswith("Enlarge the base circle or use a smaller face radius") for m in under)
    pa = [f.message for f in rep.findings if f.code == "PRESSURE_ANGLE_EXCEEDED"]
    assert pa and all(m.endswith("change the offset or the law, or use a larger face radius") for m in pa)
    assert not any("roller" in f.message for f in rep.findings)
    assert "UNDERCUT" not in check(TranslatingCurved(15, 5).geometry(steep)).codes()
    assert "UNDERCUT" not in check(TranslatingCurved(60, 25).geometry(steep)).codes()
    # the smallest convex radius falls as R grows towards the flat face (valve_mushroom's geometry)
    valve = MotionProgram.from_segments([("dwell", 0, 70), ("poly4567", 8, 110), ("poly4567", -8, 110),
                                         ("dwell", 0, 70)])
    convex = [check(m.geometry(valve)).curvature.min_convex
              for m in (TranslatingCurved(20, 10, 1.5), TranslatingCurved(20, 60, 1.5), TranslatingFlat(20))]
    assert convex == sorted(convex, reverse=True)
    assert [round(v, 1) for v in convex] == [15.7, 13.3, 10.9]
    big = [check(TranslatingCurved(15, r).geometry(steep)).pressure_angle.max for r in (5, 25, 100)]
    assert big == sorted(big, reverse=True)
    # a finger's pressure-angle advice names its own dimensions
    swing = MotionProgram.from_segments([("poly4567", 30, 60), ("poly4567", -30, 60), ("dwell", 0, 240)],
                                        lift_unit="deg")
    rep = check(OscillatingCurved(20, 25, 60, 44.8).geometry(swing))
    msgs = [f.message for f in rep.findings if f.code == "PRESSURE_ANGLE_EXCEEDED"]
    assert msgs and all(m.endswith("move the pivot, or change the face offset, the face radius or the law")
                        for m in msgs)


@pytest.mark.parametrize("mech,path", [
    (TranslatingCurved(30, 0), "follower.face_radius_mm"),
    (TranslatingCurved(30, 10, 45), "follower.offset_mm"),
    (OscillatingCurved(30, 20, 100, -25), "follower.face_offset_mm"),
    (OscillatingCurved(30, 20, 300, 0), "follower.pivot_distance_mm"),
    (OscillatingCurved(30, math.nan, 100), "follower.face_radius_mm"),
])
def test_refusals_name_the_field(mech, path):
    with pytest.raises(SpecError) as info:
        mech.geometry(ARM if isinstance(mech, OscillatingCurved) else VALVE)
    assert path in {p.path for p in info.value.problems}
    assert all(p.fix for p in info.value.problems)


def test_finger_refuses_a_face_turning_past_perpendicular():
    big = MotionProgram.from_segments([("poly4567", 115, 180), ("poly4567", -115, 180)], lift_unit="deg")
    with pytest.raises(SpecError, match="past perpendicular"):
        OscillatingCurved(35, 60, 100).geometry(big)
