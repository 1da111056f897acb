"""The deviation measurement without scipy's k-d tree: the grid search (camfab.discretize.grid) finds exactly the
nearest sites, the examples' measured deviations equal the k-d tree measurement's, and an arc moved by 5 µm is
caught (docs/decisions.md, "Start-up and export time")."""
from __future__ import annotations

import numpy as np
import pytest

import camfab.discretize.chain as chain_mod
import camfab.discretize.measure as measure_mod
from camfab.design.assemble import geometry_from_spec
from camfab.discretize import Chain, arcs, measure_deviation
from camfab.discretize.grid import grid_nearest
from camfab.formats import load_design
from camfab.offset.cutter import profile_curve
from tests.conftest import EXAMPLES

cKDTree = pytest.importorskip("scipy.spatial").cKDTree


def _kdtree_nearest(q, sites, cell, distance, reach=0.0, cells=None):
    """The measurement's search before the grid: the 16 nearest sites by a k-d tree, every site for a point
    the tree's candidates do not settle (`cell` and `cells` are unused)."""
    q = np.asarray(q, dtype=float).reshape(-1, 2)
    m = sites.shape[0]
    k = min(16, m)
    dm, idx = cKDTree(sites).query(q, k=k)
    dm, idx = dm.reshape(-1, k), idx.reshape(-1, k)
    d = distance(np.repeat(q, k, axis=0), idx.ravel()).reshape(-1, k)
    j = d.argmin(axis=1)
    rows = np.arange(q.shape[0])
    best, arg = d[rows, j], idx[rows, j]
    for i in np.flatnonzero((k < m) & (dm[:, -1] - reach < best)):
        dd = distance(np.repeat(q[i:i + 1], m, axis=0), np.arange(m))
        arg[i] = dd.argmin()
        best[i] = dd[arg[i]]
    return best, arg


def _brute(q, sites, distance):
    m = sites.shape[0]
    d = distance(np.repeat(q, m, axis=0), np.tile(np.arange(m), q.shape[0])).reshape(q.shape[0], m)
    return d.min(axis=1), d.argmin(axis=1)


def _euclid(sites):
    def dist(p, j):
        return np.hypot(*(p - sites[j]).T)
    return dist


def test_grid_nearest_is_the_brute_force_nearest():
    rng = np.random.default_rng(3)
    for sites, q in [
        (rng.normal(size=(500, 2)), rng.normal(size=(300, 2))),  # scattered
        (rng.normal(size=(500, 2)), 1e3 * rng.normal(size=(50, 2))),  # queries far outside the sites
        (np.c_[np.cos(t := np.linspace(0, 6, 1500)), np.sin(t)] * 40, rng.normal(scale=30, size=(200, 2))),
        # a dense ring and far queries: the k-d tree pass
        (np.c_[np.cos(t := np.linspace(0, 6, 20000)), np.sin(t)] * 40, rng.normal(scale=80, size=(200, 2))),
        (np.zeros((3, 2)), rng.normal(size=(20, 2))),  # all sites at one point
        (np.array([[1.0, 2.0]]), rng.normal(size=(5, 2))),
    ]:
        cells: dict = {}  # the sites' buckets kept across queries: the same answers, made once per cell side
        for cell in (1e-3, 0.05, 1.0, 1e4):
            d, j = grid_nearest(q, sites, cell, _euclid(sites))
            bd, _ = _brute(q, sites, _euclid(sites))
            np.testing.assert_array_equal(d, bd)
            np.testing.assert_array_equal(_euclid(sites)(q, j), bd)
            for half in (q[::2], q[1::2], q):
                dc, jc = grid_nearest(half, sites, cell, _euclid(sites), cells=cells)
                ref = grid_nearest(half, sites, cell, _euclid(sites))
                np.testing.assert_array_equal(dc, ref[0])
                np.testing.assert_array_equal(jc, ref[1])
        assert cells and all(v is None or v[3].size == sites.shape[0] for v in cells.values())


def test_chain_distance_is_exact_against_every_entity():
    """Points near and far from an arc chain: the grid's answer is the minimum over every entity."""
    rng = np.random.default_rng(5)
    t = np.linspace(0, 2 * np.pi, 41)[:-1]
    rows = np.c_[30 * np.cos(t) + rng.normal(scale=0.3, size=t.size), 30 * np.sin(t), rng.normal(0.05, 0.02, t.size)]
    chain = Chain.from_bulges(rows)
    q = np.vstack([rng.normal(scale=25, size=(500, 2)), rng.normal(scale=500, size=(50, 2)),
                   chain.sample(9)[0].reshape(-1, 2) + rng.normal(scale=1e-4, size=(360, 2))])
    d, which = chain.distance(q)
    every = chain._dist_to(q[:, None], np.arange(chain.n)[None, :])
    np.testing.assert_array_equal(d, every.min(axis=1))
    np.testing.assert_array_equal(chain._dist_to(q, which), d)


def _fitted(example):
    geom = geometry_from_spec(load_design(EXAMPLES / f"{example}.toml"))
    curve = profile_curve(geom.profiles[0])
    return arcs(curve, tol=1e-3), curve


def _with_kdtree(monkeypatch, fn):
    with monkeypatch.context() as m:
        m.setattr(chain_mod, "grid_nearest", _kdtree_nearest)
        m.setattr(measure_mod, "grid_nearest", _kdtree_nearest)
        return fn()


@pytest.mark.slow
@pytest.mark.parametrize("example", ["ejemplo9rt", "ejemplo11ro", "ejemplo8da_conjugate", "finger_follower",
                                     "valve_mushroom", "constant_diameter"])
def test_examples_measure_as_with_the_kdtree(monkeypatch, example):
    disc, curve = _fitted(example)
    new = measure_deviation(disc, curve)
    old = _with_kdtree(monkeypatch, lambda: measure_deviation(disc, curve))
    assert 0 < new.max <= 1e-3
    for a, b in [(new.max, old.max), (new.curve_to_entities, old.curve_to_entities),
                 (new.entities_to_curve, old.entities_to_curve)]:
        assert abs(a - b) <= 1e-9


def test_an_arc_moved_5um_is_caught(monkeypatch):
    """One arc of Ejemplo9RT's fitted chain (its two vertices) moved 5 µm along the profile's normal: both
    searches measure the 5 µm (give or take the fit's own deviation), in both directions."""
    disc, curve = _fitted("ejemplo9rt")
    rows = np.array(disc.lwpolyline, dtype=float)
    base = measure_deviation(rows, curve)
    i = int(np.argmax(np.hypot(*np.diff(rows[:, :2], axis=0).T)))  # the longest arc
    mid = 0.5 * (rows[i, :2] + rows[i + 1, :2])
    normal = mid / np.hypot(*mid)
    moved = rows.copy()
    moved[i:i + 2, :2] += 5e-3 * normal
    for dev in (measure_deviation(moved, curve), _with_kdtree(monkeypatch, lambda: measure_deviation(moved, curve))):
        assert 5e-3 - base.max - 1e-6 <= dev.max <= 5e-3 + base.max + 1e-6
        assert dev.curve_to_entities > 4e-3 - base.max and dev.entities_to_curve > 4e-3 - base.max


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_polyline_chain_distance_is_the_distance_to_the_nearest_segment(seed):
    """Chain.from_polyline(...).distance (the shapely guard's distances) against shapely's STRtree nearest
    segment and against every segment by brute force: points near a wavy ring with uneven vertices and a few long
    segments, and points far inside and outside it (answered on the coarser grids)."""
    import shapely

    rng = np.random.default_rng(seed)
    th = np.sort(rng.uniform(0.0, 2 * np.pi, 1500))
    th[200:260] = th[200]  # zero-length segments
    th = np.concatenate([th[:600], th[700:]])  # one long segment
    r = 80.0 + 5.0 * np.sin(3 * th)
    ring = np.column_stack([r * np.cos(th), r * np.sin(th)])
    ring = np.vstack([ring, ring[:1]])
    near = ring[:-1] + rng.normal(0.0, 0.05, (ring.shape[0] - 1, 2))
    q = np.vstack([near, rng.uniform(-120.0, 120.0, (40, 2))])
    got = Chain.from_polyline(ring, closed=True).distance(q)[0]
    tree = shapely.STRtree(shapely.linestrings(np.stack([ring[:-1], ring[1:]], axis=1)))
    ref = tree.query_nearest(shapely.points(q), return_distance=True, all_matches=False)[1]
    np.testing.assert_allclose(got, ref, rtol=1e-12, atol=1e-12)
    a, b = ring[:-1], ring[1:]
    ab = b - a
    l2 = np.einsum("ij,ij->i", ab, ab)
    w = q[:, None, :] - a[None]
    t = np.clip(np.einsum("nij,ij->ni", w, ab) / np.where(l2 > 0, l2, 1.0), 0.0, 1.0)
    brute = np.hypot(*np.moveaxis(w - t[..., None] * ab[None], -1, 0)).min(axis=1)
    np.testing.assert_allclose(got, brute, rtol=1e-12, atol=1e-12)
