"""The arc fit's cheaper paths (issue 15): a fixed end curvature freed when it cannot fit, one derivative per
stand-in node, a line's infinite radius kept out of products, and closed forms (a circle fitted exactly).

Deviations are checked by the independent dense checker of ``test_discretize.py``.
"""
from __future__ import annotations

import logging
import math
import warnings

import numpy as np

from camfab.discretize import ParametricCurve, arcs
from camfab.discretize.chain import Chain
from camfab.discretize.curve import derivatives_at, points_at
from camfab.discretize.results import ArcDiscretisation
from camfab.discretize.surrogate import HermiteSurrogate

from .test_arc_spline import example
from .test_discretize import Dense, check_arcs, tangent_jumps


def test_constant_width_keeps_its_dwells_and_frees_the_end_curvatures(monkeypatch, caplog):
    """SHM under a flat face: the curvature jumps where the rise meets a dwell, so no arc of the dwell's curvature
    can start the rise.  The span is refitted with free end curvatures after one count (it used to try twelve
    per span, then refit the whole curve clamped at every breakpoint): the dwells stay single exact arcs."""
    import camfab.discretize.arcspline as a

    attempts = []
    attempt = a._SpanFit.attempt

    def spy(self, m, *args, **kw):
        attempts.append((self.n_fixed, m))
        return attempt(self, m, *args, **kw)

    monkeypatch.setattr(a._SpanFit, "attempt", spy)
    g, curve, dense = example("constant_width")
    with caplog.at_level(logging.INFO, logger="camfab"):
        res = arcs(curve, tol=1e-3)
    assert not [r for r in caplog.records if "falling back" in r.getMessage()]
    assert len(attempts) <= 5, attempts  # 30 before, 10 before the return took the rise's arcs (a mirror image)
    assert sum(1 for n_fixed, _ in attempts if n_fixed) == 1  # one count for the rise, then freed
    assert res.n_entities <= 22
    assert check_arcs(res, dense) <= 1e-3
    assert tangent_jumps(res).max() < 1e-7
    # both dwells (base radius 40 mm and 40 + 20 mm of lift) are exact arcs of their radius
    radii = res.radii[~res.is_line]
    for r in (40.0, 60.0):
        assert np.any(np.abs(radii - r) < 1e-9 * r), (r, np.sort(radii))


def _lens(derivative: bool) -> ParametricCurve:
    """Half an ellipse closed by its straight diameter: corners (tangent jumps) at both ends of the diameter."""
    def point(t):
        up = t < math.pi
        x = np.where(up, -10 * np.cos(t), 10 - 20 * (t - math.pi) / math.pi)
        y = np.where(up, 6 * np.sin(t), 0.0)
        return np.column_stack([x, y])

    def der(t):
        up = t < math.pi
        return np.column_stack([np.where(up, 10 * np.sin(t), -20 / math.pi), np.where(up, 6 * np.cos(t), 0.0)])

    return ParametricCurve(point, np.array([math.pi]), derivative=der if derivative else None)


def test_stand_in_takes_each_nodes_derivative_once_and_one_sided_at_breakpoints():
    """The stand-in evaluates the derivative once per node (an interval's end is the next one's start) and
    twice at a breakpoint (each side's own): its cubics equal those built from both ends' derivatives, bit for
    bit, with an analytic derivative and with finite differences, across two corners."""
    for analytic in (True, False):
        curve = _lens(analytic)
        sur = HermiteSurrogate(curve, 64)
        x, piece = sur.x, sur.piece
        lo, hi = curve.breakpoints[piece], curve.breakpoints[piece + 1]
        d0 = derivatives_at(curve, x[:-1], lo, hi)
        d1 = derivatives_at(curve, x[1:], lo, hi)
        p = points_at(curve, x)
        p[-1] = p[0]
        h = np.diff(x)[:, None]
        coef = np.stack([p[:-1], d0, (3 * (p[1:] - p[:-1]) / h - 2 * d0 - d1) / h,
                         (2 * (p[:-1] - p[1:]) / h + d0 + d1) / h ** 2])
        assert np.array_equal(sur.coef, coef)
        # the breakpoints' derivatives are one-sided: the tangent jumps there
        k = sur.first[1]
        t_in, t_out = d1[k - 1], d0[k]
        assert abs(t_in[0] * t_out[1] - t_in[1] * t_out[0]) > 0.1 * np.hypot(*t_in) * np.hypot(*t_out)


def test_a_chain_with_lines_converts_without_warnings():
    """A line's radius is infinite: the conversion to a Chain never multiplies it by the zero sweep."""
    c = Chain(np.array([[0.0, 0.0], [3.0, 0.0]]), np.array([[1.0, 0.0], [1.0, 0.0]]), np.array([0.0, 0.5]),
              np.array([3.0, math.pi]), np.array([[3.0, 0.0], [3.0, 4.0]]))
    res = ArcDiscretisation.from_chain(c, np.array([0.0, 1.0]), 0.0, 1e-3, closed=False)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        back = res.chain()
    assert back.curvature[0] == 0.0 and back.length[0] == 3.0
    assert abs(back.curvature[1] - 0.5) < 1e-15 and abs(back.length[1] - math.pi) < 1e-14


def test_a_circle_is_fitted_exactly():
    """A circle of radius 30 (uneven parametrisation speed, one piece): every arc lies on it to a millionth of a
    millimetre whatever the tolerance (the stand-in's own error), once around."""
    def point(t):
        u = t + 0.3 * np.sin(t)
        return np.column_stack([5 + 30 * np.cos(u), -2 + 30 * np.sin(u)])

    curve = ParametricCurve(point)
    for tol in (1e-2, 1e-5):
        res = arcs(curve, tol=tol)
        arc = ~res.is_line
        assert arc.all()
        assert np.abs(res.radii - 30).max() < 1e-6
        assert np.abs(res.centres - [5, -2]).max() < 1e-6
        assert abs(np.abs(res.sweeps).sum() - 2 * math.pi) < 1e-9  # once around, no overlap
        assert res.max_deviation < 1e-6
        assert check_arcs(res, Dense(curve)) <= tol
