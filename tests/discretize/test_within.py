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
def test_a_polygon_has_corners_so_it_gets_the_full_measurement(n):
    """A regular n-gon inscribed in a circle deviates by its sagitta R·(1 − cos(π/n)); a chain with corners gets
    no certificate (the curve inside a corner puts a first-order kink in the distance): the full measurement."""
    sagitta = R * (1.0 - math.cos(math.pi / n))
    dev = measure_within(_inscribed(n), circle(), TOL)
    assert dev.max == measure_deviation(_inscribed(n), circle()).max
    assert dev.max == pytest.approx(sagitta, rel=1e-6)


def test_a_g1_chain_is_certified_below_the_full_measurement(monkeypatch):
    """The fit of an ellipse moved 0.3 tol: tangent-continuous, so certified with fewer samples (the full
    measurement is not called) — a value within the gap below the full measurement's."""
    import camfab.discretize.within as within_mod

    curve = ellipse()
    fit = arcs(curve, tol=TOL / 2)
    moved = ArcChain.from_bulges(fit.starts + np.array([0.3 * TOL, 0.0]), fit.bulges, closed=True)
    full = measure_deviation(moved, curve).max

    def refused(*args, **kwargs):
        raise AssertionError("the full measurement ran")

    monkeypatch.setattr(within_mod, "measure_deviation", refused)
    dev = measure_within(moved, curve, TOL).max
    assert full - CERTIFY_SHARE * TOL <= dev <= full + 1e-12


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
