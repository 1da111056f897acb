"""camfab.numeric: exact extrema, positive ranges, roots and integrals between breakpoints, and the
promise that makes sharing work — a search gives exactly the same result alone, together with other
searches, or from a dense sample computed beforehand."""
from __future__ import annotations

import math

import numpy as np
import pytest

from camfab import numeric
from camfab.numeric import Optimum, Range, dense_grid, extrema, extremum, integrate, positive_ranges, root, search

EDGES = np.array([0.0, 0.7, 2.0, 3.5, 5.1, 2 * math.pi])


def _bump(c: float, w: float, h: float, wave: float = 0.2):
    """A periodic Gaussian bump of width w and height h on a −0.5 floor with a slow wave."""
    return lambda x: (h * np.exp(-((np.mod(x - c + np.pi, 2 * np.pi) - np.pi) / w) ** 2) - 0.5
                      + wave * np.sin(3 * x))


FUNCS = [np.cos, np.sin, lambda x: np.sin(3 * x) * np.exp(-x), _bump(1.3, 1e-3, 1.2), _bump(4.0, 0.3, 0.9),
         _bump(1.3, 1e-3, 1.2, wave=0.0)]


def test_dense_grid_samples_every_interval_inside_its_breakpoints():
    g = dense_grid(EDGES)
    assert g is dense_grid(EDGES.tolist())  # memoised
    assert g.starts.size == EDGES.size - 1 and np.all(np.diff(g.x) > 0)
    assert np.all(g.lo > EDGES[:-1]) and np.all(g.hi < EDGES[1:]) and np.all(g.hi - g.lo > 0)
    assert np.all(g.sizes >= 9) and g.x.size >= 1440
    numeric.clear_caches()
    assert dense_grid(EDGES) is not g and np.array_equal(dense_grid(EDGES).x, g.x)


def test_extremum_finds_the_exact_global_extremum():
    at, v = extremum(np.cos, EDGES)
    assert v == pytest.approx(-1.0, abs=1e-15) and at == pytest.approx(math.pi, abs=1e-7)
    at, v = extremum(lambda x: (x - 1.234567) ** 2 + 0.5, EDGES)
    assert v == pytest.approx(0.5, abs=1e-15) and at == pytest.approx(1.234567, abs=1e-7)
    # a narrow spike between dense samples is still found (its bracket is refined)
    at, v = extremum(_bump(1.3, 1e-3, 1.2, wave=0.0), EDGES, maximize=True)
    assert at == pytest.approx(1.3, abs=1e-7) and v == pytest.approx(0.7, abs=1e-12)
    assert extremum(np.cos, [0.0, 1e-13]) == Optimum(0.0, math.inf)  # no interval wide enough to sample


def test_searches_give_the_same_result_alone_together_or_from_a_shared_sample():
    def rows(x):
        return np.stack([f(x) for f in FUNCS])

    wanted = [(k, mx) for k in range(len(FUNCS)) for mx in (False, True)]
    together = extrema(rows, EDGES, [mx for _, mx in wanted], rows=[k for k, _ in wanted])
    alone = [extremum(FUNCS[k], EDGES, maximize=mx) for k, mx in wanted]
    assert together == alone  # bit for bit
    shared = extrema(rows, EDGES, [mx for _, mx in wanted], rows=[k for k, _ in wanted],
                     values=rows(dense_grid(EDGES).x))
    assert shared == alone
    # extrema and ranges in one search: the same as each search alone
    found, ranges = search(rows, EDGES, extrema=wanted[:4], ranges=[3, 4, 5])
    assert found == alone[:4]
    assert ranges == [positive_ranges(FUNCS[k], EDGES) for k in (3, 4, 5)] and ranges[2]
    assert positive_ranges(lambda x: rows(x)[3:], EDGES) == ranges


def test_positive_ranges_end_at_roots_merge_at_breakpoints_and_wrap():
    r = positive_ranges(lambda x: np.cos(x) - 0.5, EDGES)
    assert len(r) == 1 and isinstance(r[0], Range)
    assert r[0].start == pytest.approx(5 * math.pi / 3, abs=1e-12) and r[0].end == pytest.approx(math.pi / 3, abs=1e-12)
    assert r[0].worst == pytest.approx(0.5, abs=1e-15) and r[0].start > r[0].end  # wraps through 0
    op = positive_ranges(lambda x: np.cos(x) - 0.5, EDGES, closed=False)
    assert [(a == pytest.approx(0.0, abs=1e-9), b == pytest.approx(2 * math.pi, abs=1e-9)) for a, b, _, _ in
            (op[0], op[-1])] == [(True, False), (False, True)]
    # the narrow bump (width 1e-3, far below the sample spacing) is a range of its own
    spike = positive_ranges(_bump(1.3, 1e-3, 1.2, wave=0.0), EDGES)
    inside = [x for x in spike if x.start < 1.3 < x.end]
    assert len(inside) == 1 and inside[0].end - inside[0].start < 4e-3
    assert positive_ranges(lambda x: np.full(x.shape, -1.0), EDGES) == []
    nan = positive_ranges(lambda x: np.where(x < 3.0, np.nan, np.sin(x)), EDGES)  # NaN is never positive
    assert nan and all(a > 3.0 - 1e-13 for a, _, _, _ in nan)


def test_root_brackets_a_sign_change_even_into_the_unknown():
    assert root(lambda x: x * x - 2.0, 0.0, 3.0) == pytest.approx(math.sqrt(2.0), abs=1e-14)
    # +inf (cannot be computed) counts as positive
    assert root(lambda x: np.where(x < 1.0, np.inf, 2.0 - x), 0.0, 5.0) == pytest.approx(2.0, abs=1e-13)
    with pytest.raises(ValueError, match="one end"):
        root(lambda x: x + 1.0, 0.0, 1.0)


def test_integrate_is_exact_for_smooth_functions():
    assert integrate(np.cos, [0.0, 1.0, 2.0]) == pytest.approx(math.sin(2.0), rel=1e-13)
    assert integrate(lambda x: x ** 7, EDGES) == pytest.approx((2 * math.pi) ** 8 / 8, rel=1e-13)
    assert abs(integrate(np.sin, EDGES, atol=1e-12)) < 1e-12


def test_integrate_stops_on_what_cannot_be_integrated():
    """NaN (an undefined integrand) is not split for ever: the result says so, quickly."""
    assert math.isnan(integrate(lambda x: np.where(x > 1.0, np.nan, x), [0.0, 2.0]))
    assert math.isfinite(integrate(lambda x: 1.0 / (x - 1.0) ** 2, [0.0, 2.0]))  # work bounded, not hung


def test_the_written_out_gauss_legendre_rule_is_numpys():
    """The quadrature's 20-point rule, written out so that a check does not import numpy.polynomial, is
    ``leggauss(20)`` bit for bit, and integrates x¹⁸ over [-1, 1] exactly (2/19)."""
    from camfab.quadrature import GAUSS_LEGENDRE_20

    x, w = np.polynomial.legendre.leggauss(20)
    assert np.array_equal(GAUSS_LEGENDRE_20[0], x) and np.array_equal(GAUSS_LEGENDRE_20[1], w)
    assert float(np.sum(GAUSS_LEGENDRE_20[1] * GAUSS_LEGENDRE_20[0] ** 18)) == pytest.approx(2 / 19, rel=1e-14)
