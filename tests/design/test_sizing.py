"""Sizing helpers return the value at which their constraint is exactly active."""
from __future__ import annotations

import math

import numpy as np
import pytest

from camfab.design import sizing
from camfab.design.checks import check
from camfab.design.mechanisms import OscillatingFlat, OscillatingRoller, TranslatingFlat, TranslatingRoller
from camfab.design.profile import CamGeometry
from camfab.design.program import MotionProgram

from ..conftest import EJEMPLO9RT, EJEMPLO11RO

E1 = MotionProgram.from_segments([("simple_harmonic", 50, 180), ("simple_harmonic", -50, 180)])
E9 = MotionProgram.from_segments(EJEMPLO9RT)
E11 = MotionProgram.from_segments(EJEMPLO11RO)
E2 = MotionProgram.from_segments([("poly4567", 10, 120), ("dwell", 0, 120), ("poly4567", -10, 120)])
REL = 1e-6


def _codes(mech, prog, **kw):
    return check(CamGeometry(mech, prog), **kw).codes()


def _active(make, rb, prog, code, also=(), **kw):
    """No ``code`` just above rb, ``code`` just below."""
    above, below = _codes(make(rb * (1 + REL)), prog, **kw), _codes(make(rb * (1 - REL)), prog, **kw)
    assert code not in above and not (set(also) & above), above
    assert code in below, below


@pytest.mark.parametrize("offset,rot", [(0.0, "cw"), (4.0, "cw"), (4.0, "ccw"), (-6.0, "cw")])
def test_pressure_angle_translating(offset, rot):
    make = lambda rb: TranslatingRoller(rb, 7, offset, rot)  # noqa: E731
    rb = sizing.min_base_radius_for_pressure_angle(make(30.0), E9)
    assert sizing.peak_pressure_angle_deg(make(rb), E9) == pytest.approx(30.0, abs=1e-9)
    _active(make, rb, E9, "PRESSURE_ANGLE_EXCEEDED")
    # other limits
    rb25 = sizing.min_base_radius_for_pressure_angle(make(30.0), E9, limit_deg=25.0)
    assert rb25 > rb
    _active(make, rb25, E9, "PRESSURE_ANGLE_EXCEEDED", pressure_angle_limit_deg=25.0)


def test_pressure_angle_translating_offset_direction():
    """Ejemplo9RT's worst pressure angle is on the (steeper) return, so a right offset
    (which lowers the return magnitude of a cw cam) allows a smaller cam."""
    rb0 = sizing.min_base_radius_for_pressure_angle(TranslatingRoller(30, 7, 0.0), E9)
    assert sizing.min_base_radius_for_pressure_angle(TranslatingRoller(30, 7, 3.0), E9) < rb0
    assert sizing.min_base_radius_for_pressure_angle(TranslatingRoller(30, 7, -3.0), E9) > rb0
    assert sizing.min_base_radius_for_pressure_angle(TranslatingRoller(30, 7, 3.0, "ccw"), E9) > rb0


def test_pressure_angle_oscillating():
    make = lambda rb: OscillatingRoller(rb, 8, 100, 60)  # noqa: E731
    rb = sizing.min_base_radius_for_pressure_angle(make(50.0), E11)
    assert sizing.peak_pressure_angle_deg(make(rb), E11) == pytest.approx(35.0, abs=1e-8)
    _active(make, rb, E11, "PRESSURE_ANGLE_EXCEEDED")
    with pytest.raises(ValueError, match="no base radius"):
        sizing.min_base_radius_for_pressure_angle(make(50.0), E11, limit_deg=20.0)


@pytest.mark.parametrize("make,prog", [
    (lambda rb: TranslatingRoller(rb, 12, 0.0), E9),
    (lambda rb: TranslatingRoller(rb, 10, 5.0, "ccw"), E9),
    (lambda rb: OscillatingRoller(rb, 20, 90, 80), E11),
])
def test_no_undercut(make, prog):
    rb = sizing.min_base_radius_no_undercut(make(30.0), prog)
    roc = check(CamGeometry(make(rb), prog)).curvature
    assert roc.pitch_min_convex == pytest.approx(make(rb).roller_radius_mm, rel=1e-9)
    _active(make, rb, prog, "UNDERCUT", also=("CUSP",))
    assert "CUSP" in _codes(make(rb), prog)


def test_no_cusp_translating_flat():
    x = np.linspace(0, 2 * np.pi, 400001)
    s = E9.evaluate(x, (0, 2))
    rb = sizing.min_base_radius_no_cusp(TranslatingFlat(30.0), E9)
    assert rb == pytest.approx(-(s[0] + s[1]).min(), rel=1e-7)  # Ejemplo3PT rule R_b,min = −min(S + S″)
    _active(TranslatingFlat, rb, E9, "UNDERCUT", also=("CUSP",))
    # SHM 180/180: S + S″ = h/2 > 0, the constraint never binds
    shm = MotionProgram.from_segments([("simple_harmonic", 30, 180), ("simple_harmonic", -30, 180)])
    assert sizing.min_base_radius_no_cusp(TranslatingFlat(30.0), shm) == 0.0


def test_no_cusp_oscillating_flat():
    make = lambda rb: OscillatingFlat(rb, 100, 0.0)  # noqa: E731
    rb = sizing.min_base_radius_no_cusp(make(40.0), E2)
    assert 20 < rb < 30
    _active(make, rb, E2, "UNDERCUT", also=("CUSP",))


def test_optimal_offset():
    mech = TranslatingRoller(35, 7)
    e = sizing.optimal_offset(mech, E9)
    peak = sizing.peak_pressure_angle_deg(TranslatingRoller(35, 7, e), E9)
    assert e > 0  # cw cam, steeper return: move the follower to the right
    for de in (-0.05, 0.05):
        assert peak <= sizing.peak_pressure_angle_deg(TranslatingRoller(35, 7, e + de), E9) + 1e-9
    assert peak < sizing.peak_pressure_angle_deg(mech, E9) - 1
    # at the optimum the rise and return peaks balance
    pa = check(CamGeometry(TranslatingRoller(35, 7, e), E9)).pressure_angle
    assert pa.max == pytest.approx(-pa.min, abs=1e-4)
    assert sizing.optimal_offset(TranslatingRoller(35, 7, 0.0, "ccw"), E9) == pytest.approx(-e, abs=1e-4)
    # a symmetric law needs no offset
    assert sizing.optimal_offset(TranslatingRoller(50, 5), E1) == pytest.approx(0.0, abs=1e-4)


def test_wrong_mechanisms():
    with pytest.raises(TypeError):
        sizing.min_base_radius_for_pressure_angle(TranslatingFlat(30.0), E9)
    with pytest.raises(TypeError):
        sizing.min_base_radius_no_undercut(TranslatingFlat(30.0), E9)
    with pytest.raises(ValueError, match="knife"):
        sizing.min_base_radius_no_undercut(TranslatingRoller(30.0, 0.0), E9)
    with pytest.raises(TypeError):
        sizing.min_base_radius_no_cusp(TranslatingRoller(30.0, 5.0), E9)
    with pytest.raises(TypeError):
        sizing.optimal_offset(TranslatingFlat(30.0), E9)  # type: ignore[arg-type]
    assert math.isfinite(sizing.peak_pressure_angle_deg(TranslatingRoller(30.0, 5.0), E9))
