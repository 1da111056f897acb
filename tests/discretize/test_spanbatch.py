"""The batched two-arc fit of many short spans (spanbatch) against the per-span fit it stands in for.

A profile of 240 short cycloidal segments is cut into hundreds of spans whose fit starts at two arcs; the batch
must give every span the same knots and curvatures bit for bit (so the arcs and the files do not change), the
same verdict and the same error up to rounding, and the whole fit must stay within tol by the independent checker.
"""
from __future__ import annotations

import numpy as np

from camfab.discretize import arcs
from camfab.discretize.arcspline import _place_knots, _SpanFit
from camfab.discretize.spanbatch import MIN_BATCH, two_arc_fits
from camfab.discretize.spans import cut_spans
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


def test_many_segment_profile_within_tol():
    curve = cam(ROWS, base=40.0)
    res = arcs(curve, tol=TOL)
    assert res.max_deviation <= TOL
    assert check_arcs(res, Dense(curve)) <= TOL
