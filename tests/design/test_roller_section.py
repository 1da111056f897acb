"""The exact roller section of a cylindrical cam: the flank against a brute-force 3D sweep of the roller, the
circular offset as the roller shrinks, the flank's curvature against finite differences, and the width across
the roller (the roller axis's distance to each flank is R_r + b/2)."""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import minimize_scalar

from camfab.design.mechanisms import geometry_from_spec
from camfab.design.roller_section import RollerSection, envelope
from tests.design.test_cylindrical import design

OSC = ([{"law": "cycloidal", "lift": 25.0, "angle_deg": 180.0},
        {"law": "cycloidal", "lift": -25.0, "angle_deg": 180.0}], {"motion": "oscillating", "arm_length_mm": 50.0})
FAST = [{"law": "cycloidal", "lift": 30.0, "angle_deg": 100.0}, {"law": "dwell", "lift": 0.0, "angle_deg": 40.0},
        {"law": "cycloidal", "lift": -30.0, "angle_deg": 180.0}, {"law": "dwell", "lift": 0.0, "angle_deg": 40.0}]


def brute_force_flank(geom, r: float, flank: int, x0: float, near: float) -> float:
    """z of the flank ``flank`` at the developed abscissa x0 on the cylinder r, from the 3D roller alone: the
    cylinder point at polar offset β from the roller's radial line lies at ``r·sin β − e`` across the roller
    axis and ``r·cos β`` along it, where the (enlarged) roller's radius is ``c·r·cos β + h``; the groove's
    edge at x0 is the extreme over the cam angle of the sections' top (+z) or bottom (−z) there."""
    mech = geom.mechanism
    sec = mech.section(r)
    c0 = geom.at_radius(r)

    def edge(theta: float) -> float:
        C, _ = c0.pitch(np.array([theta]))
        e = r * math.sin(C[0, 0] / r - theta)
        beta = x0 / r - theta
        a = sec.c * r * math.cos(beta) + sec.h
        across = r * math.sin(beta) - e
        if abs(across) >= a:
            return -1e9
        return flank * C[0, 1] + math.sqrt(a * a - across * across)

    span = 1.5 * (sec.h + sec.c * r) / r
    grid = near + np.linspace(-span, span, 201)
    best = grid[int(np.argmax([edge(t) for t in grid]))]
    res = minimize_scalar(lambda t: -edge(t), bounds=(best - 2 * span / 200, best + 2 * span / 200),
                          method="bounded", options={"xatol": 1e-13})
    return flank * -res.fun


@pytest.mark.parametrize("motion, follower, cyl", [
    (FAST, None, {}),
    (*OSC, {}),
    (FAST, None, {"roller": "conical"}),
    (*OSC, {"roller": "conical", "backlash_mm": 0.4}),
])
def test_flank_against_a_3d_sweep_of_the_roller(motion, follower, cyl):
    """On the groove bottom, the pitch and the outer cylinder, both flanks lie within 1e-6 mm of the
    brute-force envelope of the 3D roller (cylindrical or conical, translating or oscillating)."""
    geom = geometry_from_spec(design(motion, follower, **cyl))
    phi = np.array([0.3, 1.4, 3.3, 5.0])
    worst = 0.0
    for r in (35.0, 40.0, 45.0):
        for flank in (1, -1):
            s = geom.at_radius(r, flank).evaluate(phi)
            for (x, z), th in zip(s.point, phi, strict=True):
                worst = max(worst, abs(brute_force_flank(geom, r, flank, x, th) - z))
    assert worst < 1e-6


def test_small_roller_tends_to_the_circular_offset():
    """As R_r/r → 0 the flank tends to the pitch curve offset by R_r along its normal, the gap shrinking as
    (R_r/r)² (the section's stretch R_r³/(6r²) at its sides)."""
    gaps = []
    for r in (40.0, 400.0, 4000.0):
        theta = np.linspace(0.0, 2 * math.pi, 200)
        z = 15.0 * np.sin(theta) * r / 40.0
        z1 = 15.0 * np.cos(theta) * r / 40.0
        z2 = -z
        zero = 0.0 * theta
        B = np.stack([r * theta, z], axis=1)
        Bp = np.stack([r + zero, z1], axis=1)
        Bpp = np.stack([zero, z2], axis=1)
        f = envelope(RollerSection(r, 0.0, 6.0), 1, B, Bp, Bpp, zero, zero, zero)
        up = np.stack([-z1, r + zero], axis=1) / np.hypot(r, z1)[:, None]
        gaps.append(np.max(np.linalg.norm(f.point - (B + 6.0 * up), axis=1)))
        kp = (Bp[:, 0] * Bpp[:, 1] - Bp[:, 1] * Bpp[:, 0]) / np.hypot(r, z1) ** 3
        np.testing.assert_allclose(f.curvature, kp / (1 - 6.0 * kp), atol=gaps[-1] * 1e-2 + 1e-12)
    assert gaps[0] < 6.0**3 / (6 * 40.0**2) * 1.01
    assert gaps[1] == pytest.approx(gaps[0] / 100, rel=0.02)
    assert gaps[2] == pytest.approx(gaps[1] / 100, rel=0.02)


def test_flank_derivative_and_curvature_against_finite_differences():
    """point_d1 and the signed curvature of the exact flank (oscillating follower, conical roller) against
    central differences of the flank points."""
    geom = geometry_from_spec(design(OSC[0], OSC[1], roller="conical"))
    phi = np.linspace(0.2, 6.0, 41)
    h = 1e-5
    for r in (35.0, 45.0):
        for flank in (1, -1):
            c = geom.at_radius(r, flank)
            s, sp, sm = c.evaluate(phi), c.evaluate(phi + h), c.evaluate(phi - h)
            d1 = (sp.point - sm.point) / (2 * h)
            np.testing.assert_allclose(s.point_d1, d1, atol=1e-6 * np.abs(d1).max())
            d2 = (sp.point - 2 * s.point + sm.point) / h**2
            k = flank * (d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]) / np.hypot(*d1.T) ** 3
            sign = np.sign(np.einsum("ij,ij->i", s.point_d1, s.tangent))
            np.testing.assert_allclose(s.curvature, k * sign, atol=1e-4 * np.abs(k).max())


def axis_distances(geom, r: float, flank: int, thetas, shift: float = 0.0) -> list[float]:
    """The smallest 3D distance from the roller's axis (offset ``shift`` along the cam axis from the pitch
    point; on its own side of the cam axis) at each cam angle of ``thetas`` to the flank ``flank`` on r."""
    sense = geom.mechanism.sense
    s = geom.at_radius(r, flank).evaluate(np.linspace(0.0, 2 * math.pi, 40001))
    a = 0.5 * math.pi + sense * s.point[:, 0] / r
    pts = np.stack([r * np.cos(a), r * np.sin(a), s.point[:, 1]], axis=1)
    out = []
    for th in thetas:
        C, _ = geom.at_radius(r).pitch(np.array([th]))
        ang = 0.5 * math.pi + sense * th
        axis = np.array([math.cos(ang), math.sin(ang), 0.0])
        rel = pts - np.array([0.0, 0.0, C[0, 1] + shift])
        out.append(float(np.linalg.norm(rel - np.outer(rel @ axis, axis), axis=1)[rel @ axis > 0].min()))
    return out


def test_roller_axis_is_half_the_groove_width_from_each_flank():
    """The width in the correct sense: at any cam angle the roller's axis (a 3D line) lies exactly
    R_r + b/2 from each flank on every radius (closest flank point), though the developed normal distance
    between the flanks at the pitch radius exceeds 2R_r + b on slopes (the section is stretched along x)."""
    geom = geometry_from_spec(design(FAST))
    for r in (35.0, 40.0, 45.0):
        for flank in (1, -1):
            np.testing.assert_allclose(axis_distances(geom, r, flank, (0.4, 1.0, 4.0)), 6.05, atol=2e-6)
