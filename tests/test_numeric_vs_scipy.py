"""camfab.numeric against scipy.optimize.elementwise on the checks' real searches (built-in examples):
the extrema and the positive ranges the check rules ask for (:class:`ContactSample`) have the values,
the roots and — where the extremum is not flat — the places that ``find_minimum`` and ``find_root``
find from the same dense sample.  The reference refines *every* local minimum and sign change of the
sample (not numeric's four best candidates), with tolerances as tight as numeric's.  Timing is
``benchmarks/bench_numeric.py``'s business, not this test's."""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize.elementwise import find_minimum, find_root

import camfab
from camfab.design.checks.common import QUANTITIES, ContactSample
from camfab.numeric import dense_grid

EPS = float(np.finfo(float).eps)
#: numeric's tolerances: a minimum's bracket within 1e-9 of its first width (two sample spacings) or its
#: values within 64 eps of the best; a root's bracket within 1e-14 + 1e-15·|x|
ROOT_TOL = {"xatol": 1e-14, "xrtol": 1e-15}


def _min_tol(step: float) -> dict[str, float]:
    return {"xatol": 1e-9 * 2 * step / 4, "xrtol": 0.0, "frtol": 32 * EPS}


def scipy_minimum(f, edges, step: float | None = None) -> tuple[float, float]:
    """Global minimum (at, value) of f (x (n,) → (n,)) between ``edges``: every local minimum of the dense
    sample refined by find_minimum (an interval's end sample through a probe 1e-6 of the spacing inside:
    kept if f rises from it).  Minima within 1e-10 relative of the best are ties, resolved to the smallest
    parameter (numeric's documented rule: repeated lobes equal to rounding)."""
    g = dense_grid(edges, step)
    x, v = g.x, f(g.x)
    last = np.append(g.starts[1:], x.size) - 1
    first_s, last_s = np.zeros(x.size, bool), np.zeros(x.size, bool)
    first_s[g.starts], last_s[last] = True, True
    le_prev = np.append(True, v[1:] <= v[:-1]) | first_s
    le_next = np.append(v[:-1] <= v[1:], True) | last_s
    loc = np.flatnonzero(le_prev & le_next)
    inner = loc[~first_s[loc] & ~last_s[loc]]
    x1, x2, x3 = [x[inner - 1]], [x[inner]], [x[inner + 1]]
    ends = loc[first_s[loc] | last_s[loc]]
    nb = np.where(first_s[ends], x[np.minimum(ends + 1, x.size - 1)], x[ends - 1])
    probe = x[ends] + 1e-6 * (nb - x[ends])
    down = f(probe) < v[ends]
    x1.append(np.minimum(x[ends], nb)[down])
    x2.append(probe[down])
    x3.append(np.maximum(x[ends], nb)[down])
    res = find_minimum(lambda t: f(t.ravel()).reshape(t.shape), tuple(np.concatenate(a) for a in (x1, x2, x3)),
                       tolerances=_min_tol(g.step))
    assert np.all(res.success)
    at, val = np.r_[x[loc], res.x], np.r_[v[loc], res.f_x]
    tie = np.flatnonzero(val <= val.min() + 1e-10 * abs(val.min()))
    k = int(tie[np.argmin(at[tie])])
    return float(at[k]), float(val[k])


def scipy_roots(f, edges) -> np.ndarray:
    """Every root of f between ``edges`` that the dense sample brackets (sign of f > 0 changes)."""
    g = dense_grid(edges)
    x, v = g.x, f(g.x)
    inner = np.ones(x.size - 1, bool)
    inner[g.starts[1:] - 1] = False
    q = np.flatnonzero(((v[:-1] > 0) != (v[1:] > 0)) & inner)
    res = find_root(lambda t: f(t.ravel()).reshape(t.shape), (x[q], x[q + 1]), tolerances=ROOT_TOL)
    assert np.all(res.success)
    return res.x


def _contact(example: str):
    return camfab.load(example).geometry.profiles[0]


def _of(contact, q):
    return lambda x: np.asarray(q(contact.evaluate_fixed(np.atleast_1d(x))), dtype=float)


def _same_place(f, a: float, b: float, value: float, period: tuple[float, float]) -> bool:
    """a and b within 1e-6 rad, or joined by a stretch where f is flat (a dwell: the extremum's place is not
    unique), directly or through the end of the period."""
    a, b = sorted((a, b))
    flat = [np.linspace(a, b, 64), np.r_[np.linspace(b, period[1], 32), np.linspace(period[0], a, 32)]]
    return abs(a - b) < 1e-6 or any(np.ptp(f(t)) <= 1e-12 * max(abs(value), 1.0) for t in flat)


@pytest.mark.parametrize("example", ["ejemplo9rt", "ejemplo11ro", "valve_exhaust_ej1"])
def test_extremes_match_scipy_find_minimum(example):
    c = _contact(example)
    sample = ContactSample(c)
    for name, (q, applies) in QUANTITIES.items():
        if not applies(c):
            continue
        f = _of(c, q)
        for sign, opt in zip((1.0, -1.0), sample.extremes(name), strict=True):
            at, v = scipy_minimum(lambda x, f=f, s=sign: s * f(x), c.breakpoints)
            assert sign * opt.value == pytest.approx(v, rel=1e-12, abs=1e-14), (name, sign)
            assert float(f(opt.at)[0]) == pytest.approx(opt.value, rel=1e-14, abs=1e-15)  # the value is f there
            assert _same_place(f, opt.at, at, v, (c.breakpoints[0], c.breakpoints[-1])), (name, sign, opt.at, at)


def _pressure_curvature(lim_deg: float, rp: float):
    lim = math.radians(lim_deg)
    return (lambda s: s.pressure_angle - lim, lambda s: -s.pressure_angle - lim, lambda s: rp * s.curvature_pitch - 1.0)


@pytest.mark.parametrize(("example", "functions"), [
    ("ejemplo9rt", _pressure_curvature(20.0, 25.0)),
    ("valve_exhaust_ej1", (lambda s: 10.0 - s.rho, lambda s: s.face_position - 8.0, lambda s: -s.face_position - 8.0)),
])
def test_positive_ranges_match_scipy_find_root_and_find_minimum(example, functions):
    """The limits are below the rules' own (there the examples pass and no range is searched)."""
    c = _contact(example)
    edges = c.breakpoints
    found = ContactSample(c).ranges(*functions)
    assert sum(map(len, found)) >= 6
    for q, ranges in zip(functions, found, strict=True):
        f = _of(c, q)
        roots = scipy_roots(f, edges)
        ends = np.array([e for r in ranges for e in (r.start, r.end)])
        assert ends.size == roots.size and np.all(np.diff(ends) > 0)  # no range here wraps or ends at a breakpoint
        np.testing.assert_allclose(ends, roots, rtol=0, atol=1e-13)
        for r in ranges:
            sub = np.r_[r.start, edges[(edges > r.start) & (edges < r.end)], r.end]
            at, v = scipy_minimum(lambda x, f=f: -f(x), sub, dense_grid(edges).step)
            assert r.worst == pytest.approx(-v, rel=1e-12, abs=1e-14)
            assert abs(r.at_worst - at) < 1e-6
