"""The sample count that certifies a fit within tol (:mod:`camfab.discretize.certify`): the bound
``max ≤ sampled max + K·h²/8`` checked against dense exact samples (10⁶ per profile), with the independent
point-to-arc distances of ``test_discretize.py``."""
from __future__ import annotations

import numpy as np
import pytest

from camfab.design.assemble import geometry_from_spec
from camfab.design.spec import design_from_dict
from camfab.discretize import ParametricCurve, arcs, measure_deviation, points_at
from camfab.discretize.certify import CERTIFY_SHARE, certified_deviation, curvature_bound, sample_gap, samples_for
from camfab.discretize.measure import measure_fit
from camfab.discretize.surrogate import HermiteSurrogate, fit_surrogate
from camfab.formats import load_design
from camfab.offset.cutter import profile_curve

from .test_discretize import Dense, arc_dist, check_arcs

TOL = 1e-3


def issue15_curve():
    """Issue 15's roller cam: Rb 50, Rr 5, cycloidal ±25 mm over 120°, dwells of 60°."""
    return profile_curve(geometry_from_spec(design_from_dict({
        "name": "issue15", "cam": {"kind": "disc", "rotation": "cw", "omega_rad_s": 1.0},
        "follower": {"type": "roller", "motion": "translating", "base_radius_mm": 50.0, "roller_radius_mm": 5.0},
        "motion": [{"law": "cycloidal", "lift": 25.0, "angle_deg": 120.0},
                   {"law": "dwell", "lift": 0.0, "angle_deg": 60.0},
                   {"law": "cycloidal", "lift": -25.0, "angle_deg": 120.0},
                   {"law": "dwell", "lift": 0.0, "angle_deg": 60.0}]})).profiles[0])


CURVES = {"issue15": issue15_curve,
          "constant_width": lambda: profile_curve(geometry_from_spec(
              load_design("camfab/examples/constant_width.toml")).profiles[0])}


def _to_arcs(res, pts):
    """Exact distance from every point to the arcs (all of them: a few tens)."""
    out = np.empty(len(pts))
    for a in range(0, len(pts), 20000):
        q = pts[a:a + 20000, None]
        out[a:a + 20000] = arc_dist(q, res.starts[None], res.ends[None], res.centres[None], res.radii[None],
                                    res.sweeps[None]).min(axis=1)
    return out


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(CURVES))
def test_sampled_maximum_plus_gap_bounds_the_dense_maximum(name):
    curve = CURVES[name]()
    res = arcs(curve, tol=TOL)
    K, vmax = curvature_bound(fit_surrogate(curve, TOL)[0], res.chain(), TOL)
    dense_t = np.unique(np.concatenate([np.linspace(0.0, curve.period, 10**6), curve.breakpoints]))
    dense = _to_arcs(res, points_at(curve, dense_t)).max()
    gaps = []
    for n in (300, 1000, 3000, 10000):  # the curve samples the measurement takes (shared out by parameter length)
        raw = _to_arcs(res, points_at(curve, HermiteSurrogate(curve, n, min_count=8).x)).max()
        gap = sample_gap(K, vmax, curve.period, n)
        assert raw <= dense + 1e-12
        assert dense <= raw + gap + 1e-12, (n, raw, gap, dense)
        gaps.append(gap)
    assert gaps == sorted(gaps, reverse=True) and gaps[-1] < 0.05 * TOL  # not vacuous: h² scaling, small at 10⁴


@pytest.mark.slow
def test_certified_fit_matches_a_dense_independent_check():
    curve = issue15_curve()
    res = arcs(curve, tol=TOL)
    sur = fit_surrogate(curve, TOL)[0]
    K, vmax = curvature_bound(sur, res.chain(), TOL)
    n = samples_for(K, vmax, curve.period, CERTIFY_SHARE * TOL)
    assert n is not None and n < 20000  # fewer samples than the default measurement
    independent = check_arcs(res, Dense(curve, 10**6))
    assert independent <= TOL and res.max_deviation <= TOL
    # the reported maximum is the dense one to the digits printed (the refinement finds the peak)
    assert res.max_deviation == pytest.approx(independent, rel=1e-5)
    dev = certified_deviation(res.chain(), curve, sur, TOL)  # certified with n samples: within tol with the gap
    assert dev.max + sample_gap(K, vmax, curve.period, n) <= TOL
    # the same to the last digits: ``res.chain()`` rebuilds curvatures and lengths from centres and sweeps (a few ulps
    # off the chain the fit certified); on a CPU whose numpy rounds otherwise the two maxima part at ~1e-15 mm
    assert dev.max == pytest.approx(res.max_deviation, rel=1e-12, abs=0.0)


def test_no_finite_bound_means_no_shortcut():
    assert samples_for(float("inf"), 1.0, 1.0, 1e-3) is None
    assert samples_for(1.0, 1.0, 1.0, 0.0) is None
    assert sample_gap(2.0, 3.0, 1.0, 30) == pytest.approx(2.0 * 0.1 ** 2 / 8)


def _scaled(curve, factor):
    """``curve`` scaled about the origin: a fit of ``curve`` lies up to ``(factor - 1)·radius`` off it."""
    return ParametricCurve(lambda t: factor * curve.point(t), curve.breakpoints, curve.period,
                           lambda t: factor * curve.derivative(t), curve.closed)


def _fit_measurement_case(factor: float):
    """The issue cam's fit against its curve scaled by ``factor`` (1: the fit's own curve; ``1 + 2e-5``: 1–2.5 tol
    off): ``(chain, curve, stand-in, (K, max|P′|), samples, gap)`` as the certificate takes them."""
    base = issue15_curve()
    chain = arcs(base, tol=TOL).chain()
    curve = _scaled(base, factor)
    sur = fit_surrogate(curve, TOL)[0]
    K, vmax = curvature_bound(sur, chain, TOL)
    n = samples_for(K, vmax, curve.period, CERTIFY_SHARE * TOL)
    return chain, curve, sur, (K, vmax), n, sample_gap(K, vmax, curve.period, n)


@pytest.mark.parametrize("factor", [1.0, 1.0 + 2e-5])
def test_fit_measurement_agrees_with_the_general_one(factor):
    """The fit's own measurement (one exact call at the certified samples, the chain projected on the fit's
    stand-in, each sample against its own entity and neighbours) against ``measure_deviation`` (its own stand-in,
    grid search over every entity, polished feet): the same maximum, on the fit and on a chain 1–2.5 tol off."""
    chain, curve, sur, (K, vmax), n, gap = _fit_measurement_case(factor)
    fit = measure_fit(chain, curve, sur, n, gap)
    general = measure_deviation(chain, curve)
    assert fit.max == pytest.approx(general.max, rel=1e-6)
    assert fit.curve_to_entities == pytest.approx(general.curve_to_entities, rel=1e-6)
    # chain to curve: 8 maxima refined on 17-point grids (not 32 on 33): a few parts in 10⁶ lower at most
    assert fit.entities_to_curve == pytest.approx(general.entities_to_curve, rel=1e-5)
    assert (fit.max > 1.5 * TOL) == (factor > 1.0)  # the off chain is really off


@pytest.mark.slow
def test_fit_measurement_bounds_a_dense_check_off_the_curve():
    """A chain 1–2.5 tol off the curve: the fit's measurement plus the certificate's gap bounds the dense
    independent maximum (10⁶ exact points, point-to-arc distances), and matches it."""
    base = issue15_curve()
    res = arcs(base, tol=TOL)
    curve = _scaled(base, 1.0 + 2e-5)
    sur = fit_surrogate(curve, TOL)[0]
    K, vmax = curvature_bound(sur, res.chain(), TOL)
    n = samples_for(K, vmax, curve.period, CERTIFY_SHARE * TOL)
    gap = sample_gap(K, vmax, curve.period, n)
    fit = measure_fit(res.chain(), curve, sur, n, gap)
    independent = check_arcs(res, Dense(curve, 10**6))
    assert independent <= fit.max + gap
    assert fit.max == pytest.approx(independent, rel=1e-5)


def test_refinement_skips_brackets_the_bound_rules_out():
    """:func:`~camfab.discretize.measure._zoom_max` with the certificate's bound zooms into fewer brackets and
    finds the same largest value in the same bracket, bit for bit; a bracket left out keeps a value within the
    bound below its full refinement (a function with ``|f''| ≤ K``: a sum of cosines)."""
    from camfab.discretize.measure import _zoom_max

    rng = np.random.default_rng(7)
    amp, freq, phase = rng.uniform(0.1, 1.0, 6), rng.uniform(1.0, 20.0, 6), rng.uniform(0, 2 * np.pi, 6)
    K = float((amp * freq ** 2).sum())  # |f''| ≤ Σ a·ω²
    calls = {"full": 0, "pruned": 0}

    def f(kind):
        def run(u, rows):
            calls[kind] += u.size
            return (amp * np.cos(freq * u[..., None] + phase)).sum(axis=-1)
        return run

    centres = np.sort(rng.uniform(0.0, 10.0, 60))
    lo, hi = centres - 0.02, centres + 0.02
    full = _zoom_max(f("full"), lo, hi, m=17)
    pruned = _zoom_max(f("pruned"), lo, hi, m=17, per_step=K / 8.0)
    assert pruned.max() == full.max() and pruned.argmax() == full.argmax()
    assert np.all(pruned <= full)
    step = (hi - lo) / 16
    assert np.all(full <= pruned + K / 8.0 * step ** 2 + 1e-12)
    assert calls["pruned"] < 0.7 * calls["full"]  # not vacuous: most brackets stop after the first level


@pytest.mark.parametrize("factor", [1.0, 1.0 + 2e-5])
def test_fit_measurement_with_its_bound_is_the_same(factor, monkeypatch):
    """The fit's measurement given the certificate's ``(K, max|P′|)`` (it then zooms only into the brackets that
    can hold the largest distance) reports exactly what it reports without, on the fit and on a chain 1–2.5 tol
    off its curve, and measures fewer curve points doing it."""
    import camfab.discretize.measure as measure_mod

    chain, curve, sur, (K, vmax), n, gap = _fit_measurement_case(factor)
    points = []
    near = measure_mod._near_entities

    def counted(ch, q, ent, *args, **kwargs):
        points.append(q.size // 2)
        return near(ch, q, ent, *args, **kwargs)

    monkeypatch.setattr(measure_mod, "_near_entities", counted)
    plain = measure_fit(chain, curve, sur, n, gap)
    plain_points, points[:] = sum(points), []
    bounded = measure_fit(chain, curve, sur, n, gap, bound=(K, vmax))
    assert (bounded.max, bounded.curve_to_entities, bounded.entities_to_curve, bounded.at_param) == \
        (plain.max, plain.curve_to_entities, plain.entities_to_curve, plain.at_param)
    assert sum(points) < plain_points  # the second zoom level left out for most brackets
