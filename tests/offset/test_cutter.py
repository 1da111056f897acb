"""Tool-centre offsets: exact vs shapely, concave refusal, roller-envelope cross-check, topology."""
from __future__ import annotations

import numpy as np
import pytest

from camfab.design.assemble import geometry_from_spec
from camfab.discretize import ParametricCurve, measure_deviation, polyline
from camfab.errors import GeometryError
from camfab.formats import load_design
from camfab.offset.cutter import (
    GUARD_MIN_MM,
    concave_limit,
    offset_curve,
    profile_curve,
    roller_envelope_deviation,
    shapely_guard,
    shapely_offset,
    tool_centre_path,
)
from tests.conftest import EXAMPLES


@pytest.fixture(scope="module")
def contact():
    return geometry_from_spec(load_design(EXAMPLES / "ejemplo9rt.toml")).profiles[0]


def test_offset_is_normal_offset(contact):
    phi = np.linspace(0, 2 * np.pi, 997)
    s = contact.evaluate(phi)
    off = offset_curve(contact, 3.0)
    p = off.point(phi)
    np.testing.assert_allclose(np.hypot(*(p - s.point).T), 3.0, atol=1e-12)
    # analytic derivative of the offset agrees with finite differences
    h = 1e-6
    fd = (off.point(phi + h) - off.point(phi - h)) / (2 * h)
    ok = np.min(np.abs(phi[:, None] - contact.breakpoints[None, :]), axis=1) > 1e-4
    np.testing.assert_allclose(off.derivative(phi)[ok], fd[ok], atol=1e-5)


@pytest.mark.parametrize("tol", [1e-2, 1e-3])
def test_tool_centre_path_within_tol_and_agrees_with_shapely(contact, tol):
    tp = tool_centre_path(contact, 3.0, tol=tol)
    assert tp.max_deviation <= tol and tp.shapely_deviation <= GUARD_MIN_MM
    assert measure_deviation(tp.arcs, offset_curve(contact, 3.0)).max <= tol
    # the fine comparison (the run-time guard is coarse): shapely's buffer of a polyline of the profile within
    # tol/4 lies within tol of the exact offset, both ways
    base = polyline(profile_curve(contact), tol=tol / 4)
    ring = np.asarray(shapely_offset(base.points[:-1], 3.0).exterior.coords)
    assert measure_deviation(ring, offset_curve(contact, 3.0)).max <= tol
    # the tool-centre path stays outside the part by the tool radius (never gouges)
    pts = tp.arcs.chain().sample(9)[0]
    r_min = np.min(np.hypot(*pts.T))
    assert r_min >= 35.0 + 3.0 - tol


def test_concave_limit_and_refusal(contact):
    fits, ranges = concave_limit(contact)
    assert fits == pytest.approx(47.5309, abs=1e-3)
    assert len(ranges) == 4
    with pytest.raises(GeometryError, match=r"largest cutter that fits has radius 47\.53.*choose a smaller tool") as e:
        tool_centre_path(contact, 50.0)
    assert "°–" in str(e.value)
    tool_centre_path(contact, 47.0, tol=1e-2)  # just below the limit is fine


def test_roller_envelope_cross_check(contact):
    assert roller_envelope_deviation(contact, tol=1e-3) <= 1e-3


def test_shapely_topology_errors():
    # dumbbell: an inward offset larger than half the neck splits it
    t = np.linspace(0, 2 * np.pi, 400, endpoint=False)
    r = 20 + 15 * np.cos(2 * t)
    pts = np.column_stack([r * np.cos(t), r * np.sin(t)])
    with pytest.raises(GeometryError, match="splits into 2 pieces"):
        shapely_offset(pts, -6.0)
    bow = np.array([[0, 0], [10, 10], [10, 0], [0, 10]], float)
    with pytest.raises(GeometryError, match="not a simple closed curve"):
        shapely_offset(bow, 1.0)


def _c_shape(offset: float) -> ParametricCurve:
    """A C: the annulus sector 15 < r < 20 over 20°…340°, its ends capped by half circles of radius 2.5; and its
    exact outward offset by ``offset`` (the outer arc grows, the caps grow, the inner arc shrinks). The mouth
    between the caps is 6.97 mm wide; every concave radius is 15 - offset."""
    a0, a1 = np.radians(20.0), np.radians(340.0)
    c0, c1 = 17.5 * np.array([np.cos(a0), np.sin(a0)]), 17.5 * np.array([np.cos(a1), np.sin(a1)])

    def point(t):
        t = np.asarray(t, float)
        k = np.minimum(np.floor(t), 3).astype(int)
        u = t - k
        out = np.empty((t.size, 2))
        for piece, (centre, radius, start, sweep) in enumerate([
                ((0.0, 0.0), 20.0 + offset, a0, a1 - a0),        # outer arc, counter-clockwise
                (c1, 2.5 + offset, a1, np.pi),                  # cap at 340°, into the mouth
                ((0.0, 0.0), 15.0 - offset, a1, a0 - a1),        # inner arc, clockwise
                (c0, 2.5 + offset, a0 + np.pi, np.pi)]):         # cap at 20°, into the mouth
            m = k == piece
            ang = start + sweep * u[m]
            out[m] = np.asarray(centre) + radius * np.column_stack([np.cos(ang), np.sin(ang)])
        return out

    return ParametricCurve(point, [0.0, 1.0, 2.0, 3.0, 4.0], period=4.0)


def test_the_shapely_guard_refuses_an_offset_that_crosses_itself():
    """No concave radius is below the cutter (15 - 4 > 0), yet the offsets of the C's two lips cross in its
    6.97 mm mouth: the exact offset crosses itself, and the guard says so."""
    assert shapely_guard(_c_shape(0.0), _c_shape(3.0), 3.0) <= GUARD_MIN_MM  # 2 × 3 < 6.97: the mouth stays open
    with pytest.raises(GeometryError, match="encloses 1 hole|folds or crosses itself"):
        shapely_guard(_c_shape(0.0), _c_shape(4.0), 4.0)


def test_bad_tool_radius(contact):
    with pytest.raises(GeometryError, match="tool radius"):
        tool_centre_path(contact, -1.0)
    with pytest.raises(ValueError, match="tol"):
        tool_centre_path(contact, 3.0, tol=1.0)


@pytest.mark.parametrize("path", sorted(EXAMPLES.glob("*.toml")), ids=lambda p: p.stem)
def test_point_and_derivative_from_one_evaluation_are_the_curves_own(path):
    """A profile's and its offsets' ``point_and_derivative`` (one evaluation of the motion for both, which the
    discretisation's stand-ins use) equal their ``point`` and ``derivative`` bit for bit: the curve's contract
    (``ParametricCurve``), at random angles, breakpoints and both ends of the period."""
    for contact in geometry_from_spec(load_design(path)).profiles:
        if not contact.closed:  # a translating cam's plate outline (no combined evaluation)
            continue
        curves = [profile_curve(contact), offset_curve(contact, 3.0), offset_curve(contact, -0.5)]
        for curve in curves:
            if curve.point_and_derivative is None:  # a profile with corners (only under --force)
                continue
            t = np.concatenate([np.random.default_rng(5).uniform(0.0, curve.period, 2001), curve.breakpoints])
            p, d = curve.point_and_derivative(t)
            np.testing.assert_array_equal(p, curve.point(t))
            np.testing.assert_array_equal(d, curve.derivative(t))
