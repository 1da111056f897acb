"""Cylindrical (barrel) cams: the developed pitch curve, the oscillating follower's exact arc, the checks
across the groove depth, the conical roller's slip, and the design file's rules."""
from __future__ import annotations

import math

import numpy as np
import pytest

from camfab.design.assemble import check_design
from camfab.design.cylindrical import CylindricalGeometry, pitch_3d, slip_ratio
from camfab.design.mechanisms import geometry_from_spec
from camfab.design.spec import design_from_dict
from camfab.errors import SpecError

from ..conftest import CYLINDER_ARM_MM, oscillating_cylinder


def design(motion=None, follower=None, **cyl):
    c = {"radius_mm": 40.0, "length_mm": 80.0, "groove_depth_mm": 10.0, "backlash_mm": 0.1} | cyl
    f = {"type": "roller", "motion": "translating", "roller_radius_mm": 6.0} | (follower or {})
    m = motion or [{"law": "constant_velocity", "lift": 20.0, "angle_deg": 90.0},
                   {"law": "dwell", "lift": 0.0, "angle_deg": 70.0},
                   {"law": "cycloidal", "lift": -20.0, "angle_deg": 200.0}]
    return design_from_dict({"name": "barrel", "cam": {"kind": "cylindrical"}, "cylinder": c, "follower": f,
                             "motion": m})


def helix_contact(p: float, w: float, r: float) -> tuple[float, float]:
    """A groove of developed slope p on radius r, a cylindrical roller section of radius w: (cos t*, tan δ).
    The envelope condition r·k·cos t + p·r·sin t = 0 with k = √(1 − (w·cos t/r)²) squared is the quadratic
    (w/r)²C⁴ − (1 + p²)C² + p² = 0 in C = cos t (its small root; C < 0 on the rising +z flank), and the
    pressure angle in the roller's plane is tan δ = |cos t|/sin t = p/k."""
    q = (w / r) ** 2
    c2 = ((1 + p * p) - math.sqrt((1 + p * p) ** 2 - 4 * p * p * q)) / (2 * q)
    return -math.sqrt(c2), p / math.sqrt(1 - q * c2)


def test_constant_lead_groove_is_a_helix():
    """A rise at constant velocity: on every radius r the developed pitch curve is a straight line of slope
    h/(β·r), its curvature 0 and its pressure angle constant (closed form :func:`helix_contact`, → atan(h/(β·r))
    for a small roller) — a helix of lead 2π·h/β; each flank is a parallel straight line at the exact
    section's support distance."""
    geom = geometry_from_spec(design())
    assert isinstance(geom, CylindricalGeometry)
    beta, h = math.pi / 2, 20.0
    phi = np.linspace(0.01, beta - 0.01, 101)
    for r in (35.0, 40.0, 45.0):
        for flank in (1, -1):
            s = geom.at_radius(r, flank).evaluate(phi)
            d = s.pitch - s.pitch[0]
            np.testing.assert_allclose(d[:, 1], d[:, 0] * h / (beta * r), atol=1e-12)
            np.testing.assert_allclose(s.curvature_pitch, 0.0, atol=1e-15)
            p, w = h / (beta * r), 6.05
            ct, tan_d = helix_contact(p, w, r)
            np.testing.assert_allclose(s.pressure_angle, math.atan(tan_d), rtol=1e-12)
            # the flank: the pitch line moved along its normal by the section's support distance
            st = math.sqrt(1 - ct * ct)
            n = np.array([-p, 1.0]) / math.hypot(1.0, p)
            support = np.array([r * math.asin(w * ct / r), w * st]) @ n
            off = (s.point - s.pitch) @ n
            np.testing.assert_allclose(off, flank * support, rtol=1e-12)
            assert 0 < support - w < w**3 / r**2
    # 3D: every pitch point lies on the helix z = z0 + h·θ/β at radius R, polar angle 90° + σθ
    p = pitch_3d(geom, phi)
    np.testing.assert_allclose(np.hypot(p[:, 0], p[:, 1]), 40.0, rtol=1e-14)
    ang = np.unwrap(np.arctan2(p[:, 1], p[:, 0]))
    np.testing.assert_allclose(np.diff(p[:, 2]) / np.diff(ang), h / beta, rtol=1e-9)


def test_pressure_angle_worst_over_the_depth():
    """tan δ = S′/(r·k) (:func:`helix_contact`): the groove bottom has the largest pressure angle; the report's
    object is that worst, and the per-radius summary gives each radius its own."""
    spec = design()
    rep = check_design(spec)
    radii = rep.cylinder["radii"]
    want = [math.degrees(math.atan(helix_contact(20.0 / (math.pi / 2) / r, 6.05, r)[1])) for r in (35.0, 40.0, 45.0)]
    np.testing.assert_allclose([x["pressure_angle_max_deg"] for x in radii], want, rtol=1e-9)
    assert rep.pressure_angle.max == pytest.approx(want[0], rel=1e-9)
    assert rep.to_dict()["cylinder"]["radii"][0]["where"] == "groove bottom"


def test_curvature_exact_vs_finite_differences():
    """The developed pitch curve's derivatives (translating and oscillating, marked derived) against central
    differences of the curve itself, and κ_p = (C′ × C″)/|C′|³ with the flank's sign."""
    for spec in (design(), design([{"law": "cycloidal", "lift": 25.0, "angle_deg": 180.0},
                                   {"law": "cycloidal", "lift": -25.0, "angle_deg": 180.0}],
                                  {"motion": "oscillating", "arm_length_mm": 50.0})):
        geom = geometry_from_spec(spec)
        c = geom.at_radius(37.0, 1)
        phi = np.linspace(0.2, 6.0, 57)
        hstep = 1e-5
        C, T = c.pitch(phi)
        Cp, _ = c.pitch(phi + hstep)
        Cm, _ = c.pitch(phi - hstep)
        np.testing.assert_allclose(T, (Cp - Cm) / (2 * hstep), atol=2e-6 * np.abs(T).max())
        _, Tp = c.pitch(phi + hstep)
        _, Tm = c.pitch(phi - hstep)
        A = (Tp - Tm) / (2 * hstep)
        kfd = (T[:, 0] * A[:, 1] - T[:, 1] * A[:, 0]) / np.hypot(T[:, 0], T[:, 1]) ** 3
        np.testing.assert_allclose(c.evaluate(phi).curvature_pitch, kfd, atol=1e-7)


def test_oscillating_pitch_is_the_exact_arc():
    """The roller axis of an oscillating follower built in 3D (pivot axis parallel to the radial line at 0°, arm
    L, angle φ = S): it meets the cylinder r where the developed formula says, for both senses (not the
    small-angle z = L·φ, x = r·θ)."""
    L = CYLINDER_ARM_MM
    for rotation in ("cw", "ccw"):
        spec = design_from_dict(oscillating_cylinder(rotation))
        geom = geometry_from_spec(spec)
        sigma = 1 if rotation == "cw" else -1
        theta = np.linspace(0.0, 2 * math.pi, 73)
        phi = np.radians(spec.program().evaluate(theta, (0,))[0])
        z0 = geom.mechanism.z0_for(geom.program)
        for r in (35.0, 40.0, 45.0):
            # fixed frame: roller axis along +Y at X = -σ·L(1 - cos φ), Z = z0 + L sin φ; meets radius r at
            # Y = sqrt(r² - X²); the cam frame is the fixed frame turned by σθ
            X = -sigma * L * (1 - np.cos(phi))
            Y = np.sqrt(r**2 - X**2)
            c, s = np.cos(sigma * theta), np.sin(sigma * theta)
            want = np.stack([X * c - Y * s, X * s + Y * c, z0 + L * np.sin(phi)], axis=1)
            np.testing.assert_allclose(pitch_3d(geom, theta, r), want, atol=1e-11)
        small = z0 + L * np.radians(30.0)  # the small-angle lift would be 31.4 mm; the arc gives 30 mm
        assert pitch_3d(geom, [math.pi])[0, 2] == pytest.approx(z0 + L * math.sin(math.radians(30.0)))
        assert abs(small - pitch_3d(geom, [math.pi])[0, 2]) > 1.0


def test_conical_roller_removes_the_dwell_slip():
    """A cylindrical roller slips by (r − R)/R of the surface speed on a dwell; a cone with apex on the cam
    axis, half-angle atan(R_r/R), rolls there at every radius (only the rise's axial part remains)."""
    dwell = [{"law": "dwell", "lift": 0.0, "angle_deg": 360.0}]
    cyl = geometry_from_spec(design(dwell))
    cone = geometry_from_spec(design(dwell, roller="conical"))
    assert slip_ratio(cyl) == pytest.approx(5.0 / 40.0, rel=1e-12)
    assert slip_ratio(cone) == pytest.approx(0.0, abs=1e-14)
    assert cone.mechanism.cone_half_angle_deg == pytest.approx(math.degrees(math.atan(6.0 / 40.0)))
    assert slip_ratio(geometry_from_spec(design(roller="conical"))) < slip_ratio(geometry_from_spec(design()))
    # the conical roller's section grows with the radius: the groove is wider at the top
    assert cone.at_radius(45.0).roller_radius == pytest.approx(6.0 * 45 / 40 + 0.05)


@pytest.mark.parametrize("cyl, follower, path", [
    ({"groove_depth_mm": 80.0}, {}, "cylinder.groove_depth_mm"),
    ({"length_mm": 25.0}, {}, "cylinder.length_mm"),
    ({"zero_position_mm": 70.0}, {}, "cylinder.zero_position_mm"),
    ({"roller": "ball"}, {}, "cylinder.roller"),
    ({"radius_mm": 5.0, "groove_depth_mm": 2.0}, {}, "follower.roller_radius_mm"),
    ({}, {"motion": "oscillating"}, "follower.arm_length_mm"),
    ({}, {"base_radius_mm": 30.0}, "follower.base_radius_mm"),
])
def test_bad_designs_name_their_field(cyl, follower, path):
    with pytest.raises(SpecError) as exc:
        design(None, follower, **cyl)
    assert path in {p.path for p in exc.value.problems}
    assert all(p.fix for p in exc.value.problems)


def test_cylinder_table_required_and_refused():
    base = {"name": "b", "follower": {"type": "roller", "motion": "translating", "roller_radius_mm": 5.0},
            "motion": [{"law": "cycloidal", "lift": 10.0, "angle_deg": 180.0},
                       {"law": "cycloidal", "lift": -10.0, "angle_deg": 180.0}]}
    with pytest.raises(SpecError) as exc:
        design_from_dict(base | {"cam": {"kind": "cylindrical"}})
    assert "cylinder.radius_mm" in {p.path for p in exc.value.problems}
    with pytest.raises(SpecError) as exc:
        design_from_dict(base | {"cam": {"kind": "disc"}, "cylinder": {"radius_mm": 40.0},
                                 "follower": base["follower"] | {"base_radius_mm": 30.0}})
    assert "cylinder" in {p.path for p in exc.value.problems}


def test_run_writes_the_dxf_and_names_what_does_not_apply(tmp_path):
    """`camfab run` on the example: check.json with the cylinder summary, the developed DXF, and every output not
    made for this kind listed with its reason (no crash, nothing silently left out): none since the lift table is
    made too (a rib's: tests/design/test_cylinder_rib.py)."""
    import json

    from camfab import pipeline

    cam = pipeline.load("cylindrical_translating")
    res = cam.run(tmp_path, ["dxf", "xlsx", "gcode", "lift_table"])
    assert sorted(res.files) == ["BarrelCam.dxf", "BarrelCam.nc", "BarrelCam.xlsx", "BarrelCam_lift.csv", "check.json"]
    assert res.not_applicable == {}
    check = json.loads((tmp_path / "check.json").read_text())
    assert check["cylinder"]["radii"][0]["radius_mm"] == 35.0
    assert check["pressure_angle_deg"]["max"] == pytest.approx(check["cylinder"]["radii"][0]["pressure_angle_max_deg"])
