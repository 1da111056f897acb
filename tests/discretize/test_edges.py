"""The discretisation at the numerical edges: short sharp pieces, pieces a few ulps wide, fine tolerances.

A cam whose rise of 1 µm takes 0.01° has a smooth piece 1.7e-4 rad long holding all of its curvature; a knot
table may put two knots 1e-9° apart.  The stand-in, the one-sided derivatives, the jump test and the two-way
measurement must all work there.  Deviations are compared with a brute-force checker written here (dense exact
samples in every piece, exact distances to the chain).
"""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.spatial import cKDTree

from camfab.design.mechanisms import geometry_from_spec
from camfab.design.spec import design_from_dict
from camfab.discretize import Chain, ParametricCurve, arcs, measure_deviation
from camfab.discretize.curve import derivatives_at, discontinuities, points_at
from camfab.discretize.surrogate import SURROGATE_FRACTION, SURROGATE_MAX_NODES, HermiteSurrogate, fit_surrogate
from camfab.offset.cutter import profile_curve


def sharp_design(span_deg=0.01, lift=0.001, roller=0.01, base=50.0, law="cycloidal"):
    """A rise of ``lift`` mm over ``span_deg``, a dwell, the return, a dwell: legal (no undercut) for the
    defaults, the issue's case."""
    rest = 180.0 - span_deg
    return design_from_dict({
        "name": "sharp", "cam": {"kind": "disc", "omega_rad_s": 1.0},
        "follower": {"type": "roller", "motion": "translating", "base_radius_mm": base,
                     "roller_radius_mm": roller},
        "motion": [{"law": law, "lift": lift, "angle_deg": span_deg}, {"law": "dwell", "angle_deg": rest},
                   {"law": law, "lift": -lift, "angle_deg": span_deg}, {"law": "dwell", "angle_deg": rest}]})


def sharp_curve(**kw) -> ParametricCurve:
    return profile_curve(geometry_from_spec(sharp_design(**kw)).profiles[0])


def brute_deviation(chain: Chain, curve: ParametricCurve, per_piece: int = 4000, per_entity: int = 400) -> float:
    """Two-way maximum distance by brute force: exact curve samples (``per_piece`` in every smooth piece, however
    short) to the chain, exactly; chain samples to the dense polyline of those samples, plus the sagitta
    of the chord (an upper bound of the distance to the curve)."""
    lo, hi = curve.pieces
    t = np.unique(np.concatenate([np.linspace(a, b, per_piece) for a, b in zip(lo, hi, strict=True)]
                                 + [np.linspace(0.0, curve.period, 200_000)]))
    p = points_at(curve, t)
    d_curve = float(chain.distance(p)[0].max())
    mid = points_at(curve, 0.5 * (t[:-1] + t[1:]))
    sag = np.hypot(*(mid - 0.5 * (p[:-1] + p[1:])).T)  # of every chord (its largest distance from the curve)
    x = chain.sample(per_entity)[0].reshape(-1, 2)
    _, j = cKDTree(p).query(x)
    best = np.full(x.shape[0], np.inf)
    for k0 in (j - 1, j):
        k0 = np.clip(k0, 0, p.shape[0] - 2)
        a, b = p[k0], p[k0 + 1]
        ab = b - a
        u = np.clip(np.einsum("ij,ij->i", x - a, ab) / np.maximum(np.einsum("ij,ij->i", ab, ab), 1e-300), 0, 1)
        best = np.minimum(best, np.hypot(*(x - a - u[:, None] * ab).T) + sag[k0])
    return max(d_curve, float(best.max()))


def test_stand_in_refines_only_the_short_sharp_pieces():
    """A stand-in with nodes shared out by parameter length gives a 0.01° piece only its 4 minimum nodes, whatever
    the total: its error stays above 1e-6 mm, so every fit target ``tol·(1 − MARGIN) − error`` at 1e-6 was
    negative.  The adaptive stand-in reaches ``tol / 200`` with a few hundred nodes more."""
    curve = sharp_curve()
    coarse = HermiteSurrogate(curve, 2 ** 17)
    assert coarse.error() > 1e-6
    sur, err = fit_surrogate(curve, 1e-6)
    assert err <= 1e-6 / SURROGATE_FRACTION
    assert err == pytest.approx(sur.error())
    assert 4096 < sur.x.size < 4096 + 2000 <= SURROGATE_MAX_NODES
    per_piece = np.diff(sur.first)
    short = np.diff(curve.breakpoints) < 1e-3
    assert per_piece[short].min() > 4 and per_piece[~short].max() < 4096
    assert np.all(np.isin(curve.breakpoints, sur.x))  # never across a breakpoint


def test_stand_in_is_bounded_on_a_curve_it_cannot_follow():
    """A curve that jumps inside a piece: the stand-in stops at its node budget and reports the error it has."""
    def point(t):
        r = np.where(t > 1.0, 11.0, 10.0)
        return np.stack([r * np.cos(t), r * np.sin(t)], axis=-1)

    sur, err = fit_surrogate(ParametricCurve(point), 1e-6)
    assert sur.x.size <= SURROGATE_MAX_NODES and err > 0.1


def test_one_sided_derivatives_on_a_piece_1e9_deg_wide():
    """δ = 1e-7 of a 1.7e-11 rad piece is below the spacing of floats near π/2: the two extrapolation
    points fell on one float and the derivative was 0/0 (NaN, then 'cannot convert float NaN to integer')."""
    r = 30.0
    a = math.pi / 2
    b = a + math.radians(1e-9)
    curve = ParametricCurve(lambda t: r * np.stack([np.cos(t), np.sin(t)], axis=-1), [a, b],
                            derivative=lambda t: r * np.stack([-np.sin(t), np.cos(t)], axis=-1))
    t = np.array([a, b, a, b])
    lo, hi = np.array([a, a, 0.0, b]), np.array([b, b, a, 2 * math.pi])
    d = derivatives_at(curve, t, lo, hi)
    assert np.all(np.isfinite(d))
    np.testing.assert_allclose(d, r * np.stack([-np.sin(t), np.cos(t)], axis=-1), atol=1e-6)
    assert discontinuities(curve, 1e-6) == []


def test_knots_1e9_deg_apart_fit_within_tol():
    rows = [[0, 0, 0, 0], [90, 1, 0, 0], [90 + 1e-9, 1, 0, 0], [180, 0, 0, 0]]
    spec = design_from_dict({"name": "k", "cam": {"kind": "disc", "omega_rad_s": 1.0},
                             "follower": {"type": "roller", "motion": "translating", "base_radius_mm": 40.0,
                                          "roller_radius_mm": 5.0},
                             "motion_table": {"rows": rows, "units": {"angle": "deg", "s": "mm", "v": "mm/deg",
                                                                      "a": "mm/deg2"}}})
    curve = profile_curve(geometry_from_spec(spec).profiles[0])
    assert np.diff(curve.breakpoints).min() < 1e-10
    for tol in (1e-3, 1e-6):
        res = arcs(curve, tol=tol)
        assert res.max_deviation <= tol
        assert brute_deviation(res.chain(), curve) <= tol * 1.001


@pytest.mark.parametrize("base, tol", [(50.0, 1e-6), (200.0, 1e-6), (50.0, 1e-5)])
def test_measurement_of_a_sharp_piece_is_neither_over_nor_under(base, tol):
    """The entity-to-curve feet were found on a stand-in with 8 samples in the 0.01° piece: the exact point at
    such a foot is off along the curve, which read a 1.1e-7 mm fit as 1.08e-6 mm and refused a legal design at
    1e-6 ("may have a cusp or cross itself").  Feet are now polished on the exact curve."""
    curve = sharp_curve(base=base)
    res = arcs(curve, tol=tol)
    chain = res.chain()
    measured = measure_deviation(chain, curve)
    brute = brute_deviation(chain, curve)
    assert measured.max <= tol and brute <= tol * 1.001
    assert measured.max == pytest.approx(brute, rel=0.02, abs=tol * 1e-3)


def test_points_and_derivatives_from_one_evaluation_are_the_two_calls():
    """``points_and_derivatives_at`` with a curve's ``point_and_derivative`` (one evaluation): the points and the
    one-sided derivatives of the two separate calls bit for bit, at breakpoints, next to them and on a piece a few
    ulps wide; a curve without it takes the two calls; a wrong shape is named."""
    from camfab.discretize.curve import CurveError, points_and_derivatives_at

    calls = []

    def point(t):
        return 30.0 * np.stack([np.cos(t), np.sin(2 * t)], axis=-1)

    def deriv(t):
        return 30.0 * np.stack([-np.sin(t), 2 * np.cos(2 * t)], axis=-1)

    def both(t):
        calls.append(t.size)
        return point(t), deriv(t)

    a = math.pi / 2
    bp = [1.0, a, a + math.radians(1e-9), 4.0]
    plain = ParametricCurve(point, bp, derivative=deriv)
    one = ParametricCurve(point, bp, derivative=deriv, point_and_derivative=both)
    x = np.concatenate([plain.breakpoints, np.linspace(0.0, 2 * math.pi, 97), [7.0, -0.5]])  # (two to wrap)
    lo_p, hi_p = plain.pieces
    inner = np.linspace(0.1, 6.2, 50)
    k = np.searchsorted(plain.breakpoints, inner, side="right") - 1
    # every piece's start and end (one-sided from inside it) and points inside the pieces
    t = np.concatenate([lo_p, hi_p, inner])
    lo, hi = np.concatenate([lo_p, lo_p, lo_p[k]]), np.concatenate([hi_p, hi_p, hi_p[k]])
    ref = points_at(plain, x), derivatives_at(plain, t, lo, hi)
    got = points_and_derivatives_at(one, x, t, lo, hi)
    assert calls and len(calls) == 1
    np.testing.assert_array_equal(got[0], ref[0])
    np.testing.assert_array_equal(got[1], ref[1])
    fallback = points_and_derivatives_at(plain, x, t, lo, hi)
    np.testing.assert_array_equal(fallback[0], ref[0])
    np.testing.assert_array_equal(fallback[1], ref[1])
    # without x: the points at t, from the same call (and the same values either way)
    calls.clear()
    for curve in (one, plain):
        at_t = points_and_derivatives_at(curve, None, t, lo, hi)
        np.testing.assert_array_equal(at_t[0], points_at(plain, t))
        np.testing.assert_array_equal(at_t[1], ref[1])
    assert len(calls) == 1
    assert points_and_derivatives_at(one, np.empty(0), t, lo, hi)[0].shape == (0, 2)
    wrong = ParametricCurve(point, bp, derivative=deriv, point_and_derivative=lambda t: (point(t)[:, 0], deriv(t)))
    with pytest.raises(CurveError, match="point_and_derivative must return an"):
        points_and_derivatives_at(wrong, x, t, lo, hi)
