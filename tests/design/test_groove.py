"""Groove (face-groove) cams: the flank distance is 2·R_r + b everywhere (measured on the flanks themselves with
shapely), every check runs on both flanks and names it, the design keys are validated."""
from __future__ import annotations

import math
import tomllib

import numpy as np
import pytest
import shapely

from camfab.design.checks import check
from camfab.design.groove import GrooveOscillatingRoller, GrooveTranslatingRoller
from camfab.design.program import MotionProgram
from camfab.design.spec import design_from_dict
from camfab.errors import SpecError
from camfab.formats import EXAMPLES_DIR
from camfab.results import IssueCode

LAW = MotionProgram.from_segments([("poly4567", 12, 100), ("dwell", 0, 80), ("poly4567", -12, 100),
                                   ("dwell", 0, 80)])
OSC = MotionProgram.from_segments([("poly4567", 15, 120), ("dwell", 0, 60), ("poly4567", -15, 120),
                                   ("dwell", 0, 60)])


def _flank_gap(geometry, n: int = 20000) -> np.ndarray:
    """For points of the inner flank, the shapely distance to a dense polyline of the outer flank."""
    phi = np.linspace(0.0, 2 * math.pi, n, endpoint=False)
    inner = geometry.evaluate(phi[::7], 0).point
    outer = shapely.LinearRing(geometry.evaluate(phi, 1).point)
    return shapely.distance(shapely.points(inner), outer)


@pytest.mark.parametrize("mech, law", [
    (GrooveTranslatingRoller(40.0, 8.0, 6.0, backlash_mm=0.1), LAW),
    (GrooveTranslatingRoller(40.0, 8.0, 6.0, backlash_mm=0.0, offset_mm=5.0, rotation="ccw"), LAW),
    (GrooveOscillatingRoller(40.0, 6.0, 80.0, 60.0, 5.0, backlash_mm=0.3), OSC),
])
def test_flank_distance_is_roller_diameter_plus_backlash(mech, law):
    geo = mech.geometry(law)
    width = 2 * mech.roller_radius_mm + mech.backlash_mm
    gap = _flank_gap(geo)
    # a 20000-gon of a curve of radius >= 30 mm lies within 1e-5 mm of it (chord sagitta)
    assert np.abs(gap - width).max() < 2e-5
    # the inner flank is the usual cam profile: its smallest radius is the base radius
    assert geo.min_radius == pytest.approx(mech.base_radius_mm, abs=1e-9)
    # both flanks lie on the pitch curve's normal, w from it on either side
    s0, s1 = geo.evaluate(np.linspace(0, 6, 50), 0), geo.evaluate(np.linspace(0, 6, 50), 1)
    np.testing.assert_allclose(s0.pitch, s1.pitch)
    np.testing.assert_allclose(np.hypot(*(s1.point - s0.pitch).T), width / 2, atol=1e-12)
    # each normal points into the groove (away from its flank's material): opposite to each other
    np.testing.assert_allclose((s0.normal * s1.normal).sum(1), -1.0, atol=1e-12)


def test_outer_flank_curvature_is_seen_from_the_roller():
    """Where the pitch curve is convex with radius ρ_p the inner flank is convex ρ_p − w and the outer flank
    concave ρ_p + w (finite differences of the flank points confirm the exact radius)."""
    mech = GrooveTranslatingRoller(40.0, 8.0, 6.0, backlash_mm=0.2)
    geo, w = mech.geometry(LAW), mech.half_width_mm
    x = np.linspace(0.1, 6.1, 40)
    a, b = geo.evaluate(x, 0), geo.evaluate(x, 1)
    np.testing.assert_allclose(a.rho, a.rho_pitch - w, rtol=1e-9)
    np.testing.assert_allclose(b.rho, -(a.rho_pitch + w), rtol=1e-9)
    h = 1e-4  # radius of the outer flank from three points: the circumradius
    p0, p1, p2 = (geo.evaluate(x + d, 1).point for d in (-h, 0.0, h))
    la, lb, lc = (np.hypot(*(u - v).T) for u, v in ((p0, p1), (p1, p2), (p0, p2)))
    u, v = p1 - p0, p2 - p0
    area2 = np.abs(u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0])
    np.testing.assert_allclose(la * lb * lc / (2 * area2), np.abs(b.rho), rtol=1e-5)
    # the pressure angle is the line of force's: the same on both flanks
    np.testing.assert_allclose(a.pressure_angle, b.pressure_angle, atol=1e-15)


def test_checks_name_the_flank_that_undercuts():
    # a sharp rise on a small base circle: the inner flank undercuts where the pitch curve is convex and
    # tighter than the groove half-width; the outer flank where the pitch curve is concave and tighter
    sharp = MotionProgram.from_segments([("cycloidal", 30, 40), ("dwell", 0, 140), ("cycloidal", -30, 40),
                                         ("dwell", 0, 140)])
    rep = check(GrooveTranslatingRoller(20.0, 15.0, 5.0).geometry(sharp))
    under = [f for f in rep.findings if f.code is IssueCode.UNDERCUT]
    assert any(f.message.startswith("inner flank: undercut") for f in under)
    assert any(f.message.startswith("outer flank: undercut") for f in under)
    ok = check(GrooveTranslatingRoller(40.0, 8.0, 6.0).geometry(LAW))
    assert not [f for f in ok.findings if f.code in (IssueCode.UNDERCUT, IssueCode.CUSP)]
    # the pressure angle is reported over both flanks
    assert ok.pressure_angle is not None and ok.pressure_angle.max > 5


def _example() -> dict:
    return tomllib.loads((EXAMPLES_DIR / "groove_translating.toml").read_text())


def test_example_design_builds_a_groove():
    spec = design_from_dict(_example())
    assert spec.cam.kind == "groove" and spec.follower.backlash_mm == 0.1 and spec.follower.groove_depth_mm == 6.0


@pytest.mark.parametrize("section, key, value, path", [
    ("follower", "groove_depth_mm", 12.0, "follower.groove_depth_mm"),  # = thickness: no floor left
    ("follower", "groove_depth_mm", -1.0, "follower.groove_depth_mm"),
    ("follower", "backlash_mm", -0.1, "follower.backlash_mm"),
    ("follower", "roller_radius_mm", 0.0, "follower.roller_radius_mm"),
])
def test_bad_groove_keys_name_the_field(section, key, value, path):
    d = _example()
    d[section][key] = value
    with pytest.raises(SpecError) as e:
        design_from_dict(d)
    assert path in {p.path for p in e.value.problems}


def test_groove_depth_is_required_and_unused_elsewhere():
    d = _example()
    del d["follower"]["groove_depth_mm"]
    with pytest.raises(SpecError) as e:
        design_from_dict(d)
    assert "follower.groove_depth_mm" in {p.path for p in e.value.problems}
    d = _example()
    d["cam"]["kind"] = "disc"
    with pytest.raises(SpecError) as e:
        design_from_dict(d)
    assert {"follower.groove_depth_mm", "follower.backlash_mm"} <= {p.path for p in e.value.problems}
