"""Plane geometry: vector operations, arc and bulge conversions (checked against ezdxf.math), ArcChain."""
from __future__ import annotations

import math

import numpy as np
import pytest
from ezdxf.math import bulge_center, bulge_to_arc
from hypothesis import given, settings
from hypothesis import strategies as st

from camfab.errors import GeometryError
from camfab.geom2d import (
    TWO_PI,
    ArcChain,
    J,
    arc_sweep,
    bulge_centre,
    bulge_midpoint,
    cross,
    dot,
    rotate,
    rotate_cs,
    unit,
)

RNG = np.random.default_rng(7)


def test_vector_ops_broadcast_over_leading_axes():
    u, v = RNG.normal(size=(4, 3, 2)), RNG.normal(size=(4, 3, 2))
    np.testing.assert_allclose(cross(u, v), np.cross(np.dstack([u, 0 * u[..., :1]]),
                                                     np.dstack([v, 0 * v[..., :1]]))[..., 2])
    np.testing.assert_allclose(dot(u, v), (u * v).sum(-1))
    np.testing.assert_array_equal(J(J(u)), -u)
    assert dot(J(u), u) == pytest.approx(np.zeros((4, 3)), abs=1e-15)
    ang = RNG.uniform(-4, 4, size=(4, 3))
    np.testing.assert_allclose(rotate(u, ang), u[..., 0:1] * np.stack([np.cos(ang), np.sin(ang)], -1)
                               + u[..., 1:2] * np.stack([-np.sin(ang), np.cos(ang)], -1))
    np.testing.assert_array_equal(rotate_cs(u, np.cos(ang), np.sin(ang)), rotate(u, ang))
    np.testing.assert_allclose(np.hypot(*unit(u).T), 1.0)
    np.testing.assert_array_equal(unit(np.zeros((2, 2))), 0.0)
    assert J(np.array([1.0, 2.0])).tolist() == [-2.0, 1.0]  # a single vector too


@pytest.mark.parametrize("cw", [False, True])
def test_arc_sweep(cw):
    s, e, c = (1.0, 0.0), (0.0, 1.0), (0.0, 0.0)
    assert arc_sweep(s, e, c, cw) == pytest.approx(-1.5 * math.pi if cw else 0.5 * math.pi)
    assert arc_sweep(s, s, c, cw) == (-TWO_PI if cw else TWO_PI)  # a full circle


def test_bulge_conversions_agree_with_ezdxf():
    for _ in range(200):
        p0, p1 = RNG.uniform(-50, 50, 2), RNG.uniform(-50, 50, 2)
        b = RNG.choice([-1, 1]) * RNG.uniform(0.01, 3.0)
        c = bulge_centre(p0, p1, b)
        np.testing.assert_allclose(c, np.array(bulge_center(p0, p1, b)), rtol=1e-11, atol=1e-9)
        _, a0, a1, r = bulge_to_arc(p0, p1, b)
        assert math.hypot(*(p0 - c)) == pytest.approx(r, rel=1e-11)
        assert math.hypot(*(p1 - c)) == pytest.approx(r, rel=1e-11)
        m = bulge_midpoint(p0, p1, b)
        assert math.hypot(*(m - c)) == pytest.approx(r, rel=1e-11)
        # the midpoint halves the sweep: equal chords to both ends
        assert math.hypot(*(m - p0)) == pytest.approx(math.hypot(*(m - p1)), rel=1e-11)


def _square_with_round_ends():
    """A stadium: lines and two counter-clockwise half circles of radius 15 about (±15, 0)."""
    pts = np.array([[-15.0, -15.0], [15.0, -15.0], [15.0, 15.0], [-15.0, 15.0]])
    return ArcChain.from_bulges(pts, np.array([0.0, 1.0, 0.0, 1.0]))


def test_arc_chain_from_bulges_and_derived_values():
    st = _square_with_round_ends()
    assert st.n_entities == 4 and st.closed
    np.testing.assert_array_equal(st.ends, np.roll(st.starts, -1, axis=0))
    np.testing.assert_array_equal(st.is_line, [True, False, True, False])
    np.testing.assert_allclose(st.centres[1], [15.0, 0.0], atol=1e-12)
    np.testing.assert_allclose(st.centres[3], [-15.0, 0.0], atol=1e-12)
    assert np.isnan(st.centres[[0, 2]]).all()
    np.testing.assert_allclose(st.sweeps, [0.0, math.pi, 0.0, math.pi])
    np.testing.assert_allclose(st.radii, [np.inf, 15.0, np.inf, 15.0])
    assert st.area() == pytest.approx(30 * 30 + math.pi * 15**2, rel=1e-14)
    np.testing.assert_array_equal(st.lwpolyline, np.column_stack([st.starts, st.bulges]))
    assert [b for _, _, b in st.segments()] == [0.0, 1.0, 0.0, 1.0]
    back = st.reversed()
    assert back.area() == pytest.approx(-st.area(), rel=1e-14)
    np.testing.assert_array_equal(back.starts[0], st.starts[0])
    assert st.with_deviation(1e-4).max_deviation == 1e-4 and st.max_deviation is None


def test_open_arc_chain():
    quarter = ArcChain.from_bulges([[10.0, 0.0], [0.0, 10.0], [-5.0, 10.0]], [math.tan(math.pi / 8), 0.0, 0.0],
                                   closed=False)
    assert quarter.n_entities == 2 and not quarter.closed
    np.testing.assert_array_equal(quarter.points, [[10.0, 0.0], [0.0, 10.0], [-5.0, 10.0]])
    np.testing.assert_allclose(quarter.centres[0], [0.0, 0.0], atol=1e-12)
    flat = quarter.flatten(1e-3)
    np.testing.assert_array_equal(flat[-1], [-5.0, 10.0])
    np.testing.assert_allclose(np.hypot(*flat[:-1].T), 10.0)
    assert quarter.lwpolyline.shape == (3, 3) and quarter.lwpolyline[-1, 2] == 0.0
    with pytest.raises(GeometryError, match="open arc chain"):
        quarter.area()
    line = ArcChain.from_polyline([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 0.0]])
    assert line.n_entities == 3 and line.closed  # the repeated closing vertex is dropped
    assert line.area() == pytest.approx(0.5)


def test_arc_chain_checks_its_shapes():
    with pytest.raises(GeometryError, match=r"ArcChain.centres has shape \(1, 2\)"):
        ArcChain(np.zeros((2, 2)), np.zeros((2, 2)), np.zeros((1, 2)), np.zeros(2), np.zeros(2))
    with pytest.raises(GeometryError, match="3 bulges for 2 vertices"):
        ArcChain.from_bulges(np.zeros((2, 2)), np.zeros(3))


@settings(max_examples=200, deadline=None)
@given(st.lists(st.integers(0, 4), max_size=3), st.sampled_from([np.float64, np.complex128, np.int64, np.bool_]),
       st.sampled_from([np.float64, np.complex128]), st.booleans())
def test_pair_is_np_stack_last_axis(shape, da, db, strided):
    """geom2d.pair gives np.stack([a, b], axis=-1)'s array: shape, dtype, bytes and memory order."""
    from camfab.geom2d import pair
    rng = np.random.default_rng(len(shape))
    a = (rng.normal(size=(*shape, 2)) * 3)[..., 0].astype(da)
    b = rng.normal(size=shape).astype(db)
    if strided and shape:
        a, b = a[::-1], b[::-1]
    ref = np.stack([a, b], axis=-1)
    got = pair(a, b)
    assert got.shape == ref.shape and got.dtype == ref.dtype and got.strides == ref.strides
    assert got.tobytes() == ref.tobytes()
