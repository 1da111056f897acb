"""measure_within: the certified measurement exporters use, against closed forms and the general measurement."""
from __future__ import annotations

import math

import numpy as np
import pytest

from camfab.discretize import arcs, measure_deviation
from camfab.discretize.certify import CERTIFY_SHARE
from camfab.discretize.curve import ParametricCurve
from camfab.discretize.within import measure_within
from camfab.geom2d import ArcChain
from tests.discretize.test_discretize import circle, ellipse, limacon

TOL = 1e-3
R, C = 30.0, np.array([3.0, -2.0])  # test_discretize.circle


def _inscribed(n: int) -> np.ndarray:
    t = np.linspace(0.0, 2 * math.pi, n, endpoint=False)
    return C + R * np.column_stack([np.cos(t), np.sin(t)])


@pytest.mark.parametrize("n", [600, 1000, 3000])
def test_an_inscribed_polygon_deviates_by_its_sagitta(n):
    """A regular n-gon inscribed in a circle: the two-way deviation is the sagitta R·(1 − cos(π/n)), exactly."""
    sagitta = R * (1.0 - math.cos(math.pi / n))
    dev = measure_within(_inscribed(n), circle(), TOL)
    if sagitta < TOL:
        assert dev.max <= sagitta * (1 + 1e-9)
        assert dev.max >= sagitta - CERTIFY_SHARE * TOL  # a certified sample maximum is at most the gap below
    else:  # no certificate: the full measurement's own value
        assert dev.max == measure_deviation(_inscribed(n), circle()).max
        assert dev.max == pytest.approx(sagitta, rel=1e-6)


@pytest.mark.parametrize("make", [circle, ellipse, limacon])
@pytest.mark.parametrize("offset", [0.0, 0.3, 0.8])
def test_a_fit_moved_off_its_curve_measures_as_the_general_measurement(make, offset):
    """The arcs of a fit at tol/2, moved by ``offset·tol`` along x: the certified value is within the gap below
    the general measurement, never above it by more than rounding, and under tol exactly when that one is."""
    curve = make()
    fit = arcs(curve, tol=TOL / 2)
    moved = ArcChain.from_bulges(fit.starts + np.array([offset * TOL, 0.0]), fit.bulges, closed=True)
    full = measure_deviation(moved, curve).max
    dev = measure_within(moved, curve, TOL).max
    assert full - CERTIFY_SHARE * TOL <= dev <= full + 1e-12
    assert (dev <= TOL) == (full <= TOL)


def test_a_chain_beyond_tol_gets_the_full_measurement():
    curve = circle()
    far = _inscribed(64)  # sagitta 0.036 mm, 36 tol
    assert measure_within(far, curve, TOL).max == measure_deviation(far, curve).max


def test_the_certificate_covers_a_narrow_bump_between_samples():
    """A curve with a bump far narrower than a coarse sample spacing (a Gaussian 0.8 tol high, 0.02 rad wide) and
    a chain that ignores it (the bare circle's fit): the certificate's sampling must see the bump."""
    base = circle()

    def point(t):
        t = np.asarray(t, dtype=float)
        bump = 0.8 * TOL * np.exp(-((t - 1.0) / 0.02) ** 2)
        return C + (R + bump)[:, None] * np.column_stack([np.cos(t), np.sin(t)])

    bumpy = ParametricCurve(point, [0.0, 2 * math.pi])
    fit = arcs(base, tol=TOL / 4)
    full = measure_deviation(fit, bumpy).max
    dev = measure_within(fit, bumpy, TOL).max
    assert full > 0.75 * TOL  # the bump is seen by the general measurement
    assert full - CERTIFY_SHARE * TOL <= dev <= full + 1e-12
