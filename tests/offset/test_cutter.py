"""Tool-centre offsets: exact vs shapely, concave refusal, roller-envelope cross-check, topology."""
from __future__ import annotations

import numpy as np
import pytest

from camfab.design.assemble import geometry_from_spec
from camfab.discretize import measure_deviation
from camfab.errors import GeometryError
from camfab.formats import load_design
from camfab.offset.cutter import (
    concave_limit,
    offset_curve,
    roller_envelope_deviation,
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
    assert tp.max_deviation <= tol and tp.shapely_deviation <= tol
    assert measure_deviation(tp.arcs, offset_curve(contact, 3.0)).max <= tol
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


def test_bad_tool_radius(contact):
    with pytest.raises(GeometryError, match="tool radius"):
        tool_centre_path(contact, -1.0)
    with pytest.raises(ValueError, match="tol"):
        tool_centre_path(contact, 3.0, tol=1.0)
