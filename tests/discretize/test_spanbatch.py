"""The batched two-arc fit of many short spans (spanbatch) against the per-span fit it stands in for.

A profile of 240 short cycloidal segments is cut into hundreds of spans whose fit starts at two arcs; the batch
must give every span the same knots and curvatures bit for bit (so the arcs and the files do not change), the
same verdict and the same error up to rounding, their biarcs laid in one call must be the per-span arcs bit for
bit, and the whole fit must stay within tol by the independent checker.
"""
from __future__ import annotations

import numpy as np

from camfab.discretize import arcs
from camfab.discretize.arcspline import _fit_span, _place_knots, _span_chain, _SpanFit, _two_arc_chains
from camfab.discretize.spanbatch import MIN_BATCH, two_arc_fits
from camfab.discretize.spans import cut_spans, span_ends
from camfab.discretize.surrogate import fit_surrogate

from .test_discretize import Dense, cam, check_arcs

TOL = 1e-3
ROWS = [("cycloidal", 0.001 * (-1) ** i, 1.5) for i in range(240)]


def test_two_arc_batch_equals_per_span_fit():
    curve = cam(ROWS, base=40.0)
    sur, sur_err = fit_surrogate(curve, TOL)
    target = 0.97 * TOL - sur_err
    searches = [_SpanFit(sur, sp, target) for sp in cut_spans(curve, sur, target, TOL) if sp.exact is None]
    two = [f for f in searches if f.n_fixed == 0 and len(f.span.segs) == 1 and f.first_count() == 2]
    assert len(two) >= 100 > MIN_BATCH
    batch = two_arc_fits(sur, two, target, _place_knots)
    assert len(batch) == len(two)
    for i, f in enumerate(two):
        err, ok, (knots, k, _) = f.attempt(2)  # the per-span model, system and Lawson fit
        b_err, b_ok, (b_knots, b_k, _) = batch[i]
        assert np.array_equal(knots, b_knots) and np.array_equal(k, b_k)
        assert b_ok == ok and abs(b_err - err) <= 1e-9 * err


def test_two_arc_chains_equal_per_span_chains():
    curve = cam(ROWS, base=40.0)
    sur, sur_err = fit_surrogate(curve, TOL)
    target = 0.97 * TOL - sur_err
    fits = [_fit_span(sur, sp, target) for sp in cut_spans(curve, sur, target, TOL) if sp.exact is None]
    spans = [sp for sp in cut_spans(curve, sur, target, TOL) if sp.exact is None]
    two = [(sp, f) for sp, f in zip(spans, fits, strict=True) if f[0].size == 3 and f[3] == (None, None)]
    assert len(two) >= 100
    ends = [span_ends(sur, sp) for sp, _ in two]
    batch = _two_arc_chains(ends, [f[1] for _, f in two], [f[0] for _, f in two])
    for e, (_, f), got in zip(ends, two, batch, strict=True):
        want = _span_chain(*e, f[0], f[1], f[3])
        assert all(np.array_equal(a, b) for a, b in zip(want, got, strict=True))


def test_many_segment_profile_within_tol():
    curve = cam(ROWS, base=40.0)
    res = arcs(curve, tol=TOL)
    assert res.max_deviation <= TOL
    assert check_arcs(res, Dense(curve)) <= TOL


def test_single_piece_shapes_equal_per_span_shapes():
    """The shapes of hundreds of one-piece spans made at once (:func:`~camfab.discretize.spans.single_piece_shapes`)
    are :func:`~camfab.discretize.spans.span_shape`'s bit for bit, and the spans ``cut_spans`` makes with them
    carry those shapes (the batch is taken from 8 stretches on); its row-wise gradient is ``np.gradient``'s,
    uneven and even steps."""
    from camfab.discretize.spans import _gradient_rows, single_piece_shapes, span_shape

    curve = cam(ROWS, base=40.0)
    sur, sur_err = fit_surrogate(curve, TOL)
    bp = curve.breakpoints
    segs = [(i, float(bp[i]), float(bp[i + 1])) for i in range(bp.size - 1)]
    for sg, shape in zip(segs, single_piece_shapes(sur, segs), strict=True):
        for mine, theirs in zip(shape, span_shape(sur, [sg]), strict=True):
            assert mine.shape == theirs.shape and np.array_equal(mine, theirs)
    spans = [sp for sp in cut_spans(curve, sur, 0.97 * TOL - sur_err, TOL) if sp.exact is None]
    assert len(spans) >= 100
    for sp in spans[:: len(spans) // 10]:
        for mine, theirs in zip(sp.shape, span_shape(sur, sp.segs), strict=True):
            assert np.array_equal(mine, theirs)
    rng = np.random.default_rng(3)
    f = rng.normal(size=(40, 30))
    x = np.cumsum(rng.uniform(0.1, 1.0, size=(40, 30)), axis=1)
    x[5] = 0.25 * np.arange(30)  # equal steps: numpy's uniform formula
    g = _gradient_rows(f, x)
    assert all(np.array_equal(g[i], np.gradient(f[i], x[i])) for i in range(40))


def test_stacked_span_model_rows_equal_span_model():
    """The stacked model of one-piece spans (shared by the batched shapes and the batched two-arc fit) gives every
    row :func:`~camfab.discretize.spanmodel.span_model`'s arc length and tangent angle bit for bit, and the
    surrogate's derivative and speed at its parameters."""
    from camfab.discretize.spanmodel import span_model, stacked_span_model

    curve = cam(ROWS, base=40.0)
    sur, _ = fit_surrogate(curve, TOL)
    bp = curve.breakpoints
    segs = [(i, float(bp[i]), float(bp[i + 1])) for i in range(0, bp.size - 1, 7)]
    t, s, theta, d, speed, piece = stacked_span_model(sur, segs, 129)
    assert t.shape == s.shape == theta.shape == speed.shape == (len(segs), 129) and d.shape == (len(segs), 129, 2)
    for i, sg in enumerate(segs):
        t1, s1, th1 = span_model(sur, [sg], 129)
        assert np.array_equal(t[i], t1) and np.array_equal(s[i], s1) and np.array_equal(theta[i], th1)
        assert piece[i, 0] == sg[0]
        assert np.array_equal(d[i], sur.derivative(t1, sg[0]))
        assert np.array_equal(speed[i], np.hypot(d[i, :, 0], d[i, :, 1]))
