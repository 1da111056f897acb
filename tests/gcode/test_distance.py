"""Exact indexed distances (camfab.gcode.distance) against brute force: lines, arcs, spirals and exact cam curves."""
from __future__ import annotations

import math

import numpy as np
import pytest

from camfab import pipeline
from camfab.discretize.curve import points_at
from camfab.gcode import ContourDistance, parse
from camfab.gcode.distance import CurveDistance, Entities, IndexedContourDistance
from camfab.offset import profile_curve
from tests.gcode.parts import notched_disc, stadium

RNG = np.random.default_rng(12)


def _brute(ent: Entities, p: np.ndarray) -> np.ndarray:
    """The exact distance to every entity in turn, the smallest kept."""
    best = np.full(len(p), np.inf)
    for e in range(len(ent)):
        best = np.minimum(best, ent.pair(p, np.full(len(p), e))[0])
    return best


def _chain(n: int = 40) -> Entities:
    """An open chain of random short lines and arcs, some of them spirals."""
    pts = np.cumsum(RNG.normal(0, 3, (n + 1, 2)), axis=0)
    starts, ends = pts[:-1], pts[1:]
    arc = RNG.random(n) < 0.6
    sweeps = np.where(arc, RNG.uniform(-2.5, 2.5, n), 0.0)
    # the centre that makes an arc of that sweep through both ends
    mid, chord = 0.5 * (starts + ends), ends - starts
    half = np.hypot(*chord.T) / 2
    h = np.where(arc, half / np.tan(np.where(arc, sweeps, 1.0) / 2), 0.0)
    normal = np.column_stack([-chord[:, 1], chord[:, 0]]) / np.maximum(2 * half, 1e-12)[:, None]
    centres = np.where(arc[:, None], mid + h[:, None] * normal, np.nan)
    radius = np.hypot(*(starts - centres).T)
    radii_end = np.where(arc & (RNG.random(n) < 0.3), radius + 0.01, radius)
    return Entities(starts, ends, centres, sweeps, radii_end)


def test_nearest_entity_is_exact_near_and_far():
    ent = _chain()
    lo, hi = ent.a.min(axis=0) - 5, ent.a.max(axis=0) + 5
    near = ent.at(RNG.integers(0, len(ent), 3000), RNG.random(3000)) + RNG.normal(0, 0.3, (3000, 2))
    far = np.concatenate([RNG.uniform(lo, hi, (2000, 2)), RNG.uniform(lo - 500, hi + 500, (500, 2))])
    for p in (near, far):
        d, j, _, _ = ent.nearest(p)
        assert np.allclose(d, _brute(ent, p), rtol=0, atol=1e-12)
        assert np.allclose(ent.pair(p, j)[0], d, rtol=0, atol=1e-12)


def test_indexed_contour_distance_matches_contour_distance():
    for segs in (stadium(20.0, 15.0), notched_disc(30.0, 4.0), stadium(20.0, 15.0, ccw=False)):
        p = RNG.uniform(-60, 60, (4000, 2))
        assert np.allclose(IndexedContourDistance(segs)(p), ContourDistance(segs)(p), rtol=0, atol=1e-12)


def test_positions_along_a_contour_round_trip():
    icd = IndexedContourDistance(stadium(20.0, 15.0))
    s = np.linspace(0.0, icd.length, 500, endpoint=False)
    d, back = icd.project(icd.at_position(s))
    assert np.abs(d).max() < 1e-9
    assert np.abs((back - s + icd.length / 2) % icd.length - icd.length / 2).max() < 1e-9
    assert icd.length == pytest.approx(4 * 20.0 + 2 * math.pi * 15.0, rel=1e-12)


@pytest.fixture(scope="module", params=["ejemplo9rt", "valve_exhaust_ej1"])
def curve(request):
    return profile_curve(pipeline.load(request.param).geometry.profiles[0])


def _brute_curve(curve, p: np.ndarray) -> np.ndarray:
    """The nearest of 100 000 points of the exact curve, then a golden-section search between its neighbours."""
    t = np.linspace(0.0, curve.period, 100_001)
    pts = points_at(curve, t)
    from scipy.spatial import cKDTree

    _, k = cKDTree(pts).query(p)
    lo, hi = t[np.maximum(k - 1, 0)], t[np.minimum(k + 1, len(t) - 1)]
    g = (math.sqrt(5) - 1) / 2
    for _ in range(60):
        x1, x2 = hi - g * (hi - lo), lo + g * (hi - lo)
        f1 = np.hypot(*(points_at(curve, x1) - p).T)
        f2 = np.hypot(*(points_at(curve, x2) - p).T)
        hi, lo = np.where(f1 < f2, x2, hi), np.where(f1 < f2, lo, x1)
    return np.hypot(*(points_at(curve, (lo + hi) / 2) - p).T)


def test_curve_distance_is_the_exact_curve_distance(curve):
    cd = CurveDistance(curve)
    on = cd.at_position(RNG.uniform(0, cd.length, 800))
    # around the tool-centre distance on both sides, near the curve, and inside near centres of curvature
    p = np.concatenate([on + RNG.normal(0, 3, on.shape), on + RNG.normal(0, 0.01, on.shape),
                        RNG.uniform(on.min(axis=0), on.max(axis=0), (800, 2))])
    d = cd(p)
    assert np.abs(np.abs(d) - _brute_curve(curve, p)).max() < 1e-9
    # the side: negative inside the closed curve
    import shapely

    inside = shapely.contains_xy(shapely.Polygon(points_at(curve, np.linspace(0, curve.period, 20000))),
                                 p[:, 0], p[:, 1])
    clear = np.abs(d) > 1e-3
    assert np.array_equal((d < 0)[clear], inside[clear])


def test_curve_distance_far_points_are_close_with_the_right_sign(curve):
    exact = CurveDistance(curve)
    cheap = CurveDistance(curve, exact_within=3.0)
    p = RNG.uniform(-80, 80, (3000, 2))
    d, e = cheap(p), exact(p)
    near = np.abs(e) <= 3.0
    assert np.array_equal(d[near], e[near])
    assert np.abs(d - e).max() <= cheap.coarse_tol * (1 + 1e-9) and np.array_equal(np.sign(d), np.sign(e))


def test_spiral_distance_is_radial():
    text = "G17 G21 G40 G54 G90 G94\nG0 X10 Y0 Z0\nG3 X0 Y10.01 I-10 J0 F100\nM2\n"
    m = parse(text).moves[-1]
    ent = Entities.from_moves([m])
    assert ent.re[0] == pytest.approx(10.01) and ent.rs[0] == pytest.approx(10.0)
    ang = np.radians([10, 45, 80])
    r = 10 + 0.01 * ang / (math.pi / 2)
    p = np.column_stack([(r + 1) * np.cos(ang), (r + 1) * np.sin(ang)])
    assert np.allclose(ent.distance(p), 1.0, atol=1e-12)
