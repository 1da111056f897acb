"""The signed area that orients contours (camfab.gcode.contour._signed_area) is exact, and ContourDistance makes
its dense polygon only for a query at a sharp vertex (docs/decisions.md, "Contours: exact signed area")."""
from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from camfab.gcode import ContourDistance
from camfab.gcode.contour import Segment, _signed_area, as_contour, contour_is_clockwise, orient_contour
from camfab.gcode.distance import IndexedContourDistance


def _arc(a, b, sweep: float) -> Segment:
    """The arc from ``a`` to ``b`` turning ``sweep`` (rad, > 0 counter-clockwise, 0 < |sweep| < 2π)."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    chord = b - a
    length = float(np.hypot(*chord))
    left = np.array([-chord[1], chord[0]]) / length
    centre = 0.5 * (a + b) + left * (0.5 * length / math.tan(0.5 * sweep))
    return Segment(tuple(a), tuple(b), tuple(centre), sweep < 0)


def _dense_area(segs) -> float:
    """Shoelace area of a polygon through 4 000 points per arc (an independent reference)."""
    pts = np.concatenate([s.polyline(4000)[:-1] if s.is_arc else np.array([s.start]) for s in segs])
    x, y = pts[:, 0], pts[:, 1]
    return 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))


def _rounded_rectangle(w: float, h: float, r: float, at=(0.0, 0.0)) -> list[Segment]:
    x0, y0 = at
    c = [(x0 + w - r, y0 + r), (x0 + w - r, y0 + h - r), (x0 + r, y0 + h - r), (x0 + r, y0 + r)]
    segs = []
    for i, (cx, cy) in enumerate(c):
        a0 = -math.pi / 2 + i * math.pi / 2
        start = (cx + r * math.cos(a0), cy + r * math.sin(a0))
        end = (cx + r * math.cos(a0 + math.pi / 2), cy + r * math.sin(a0 + math.pi / 2))
        segs.append(Segment(start, end, (cx, cy), False))
        nxt = c[(i + 1) % 4]
        a1 = a0 + math.pi / 2
        segs.append(Segment(end, (nxt[0] + r * math.cos(a1), nxt[1] + r * math.sin(a1))))
    return segs


@pytest.mark.parametrize("at", [(0.0, 0.0), (1e4, -3e4)])
def test_closed_forms(at):
    r = 7.5
    circle = [Segment((at[0] + r, at[1]), (at[0] + r, at[1]), at, False)]
    assert _signed_area(as_contour(circle)) == pytest.approx(math.pi * r * r, rel=1e-12)
    rect = as_contour(_rounded_rectangle(40.0, 25.0, 5.0, at))
    exact = 40.0 * 25.0 - (4.0 - math.pi) * 25.0
    assert _signed_area(rect) == pytest.approx(exact, rel=1e-9)
    back = orient_contour(rect, clockwise=True)
    assert _signed_area(back) == pytest.approx(-exact, rel=1e-9)
    assert contour_is_clockwise(back) and not contour_is_clockwise(rect)


def test_a_concave_arc_takes_its_segment_away():
    """A 20 × 20 square whose top side is a semicircular notch of radius 5 (clockwise, into the square)."""
    segs = [Segment((0, 0), (20, 0)), Segment((20, 0), (20, 20)), Segment((20, 20), (15, 20)),
            _arc((15, 20), (5, 20), -math.pi + 1e-12), Segment((5, 20), (0, 20)), Segment((0, 20), (0, 0))]
    assert _signed_area(as_contour(segs)) == pytest.approx(400.0 - math.pi * 25.0 / 2, rel=1e-9)


@settings(max_examples=60, deadline=None)
@given(n=st.integers(5, 14), seed=st.integers(0, 2**31 - 1), clockwise=st.booleans())
def test_random_star_contours_against_a_dense_polygon(n, seed, clockwise):
    """Star-shaped contours of lines and arcs bulging in or out: the exact area equals the dense polygon's."""
    rng = np.random.default_rng(seed)
    angles = 2 * math.pi * (np.arange(n) + rng.uniform(-0.3, 0.3, n)) / n  # (every gap below π: star-shaped)
    radii = rng.uniform(6.0, 10.0, n)
    pts = np.column_stack([radii * np.cos(angles), radii * np.sin(angles)]) + rng.uniform(-50, 50, 2)
    segs = []
    for i in range(n):
        a, b = pts[i], pts[(i + 1) % n]
        sweep = rng.uniform(-0.6, 0.6)
        segs.append(_arc(a, b, sweep) if abs(sweep) > 0.05 else Segment(tuple(a), tuple(b)))
    contour = as_contour(segs)
    if clockwise:
        contour = tuple(s.reversed() for s in reversed(contour))
    area = _signed_area(contour)
    assert area == pytest.approx(_dense_area(contour), rel=1e-6)
    assert (area < 0) == clockwise == contour_is_clockwise(contour)


def test_contour_distance_makes_its_polygon_only_for_a_vertex():
    """Points whose nearest contour point lies inside an entity need no polygon; a point nearest to a sharp corner
    does (and gets the indexed distance's signed value either way)."""
    square = [Segment((0, 0), (10, 0)), Segment((10, 0), (10, 10)), Segment((10, 10), (0, 10)),
              Segment((0, 10), (0, 0))]
    dist = ContourDistance(square)
    inner = np.array([[5.0, 1.0], [5.0, 12.0], [-3.0, 5.0]])
    assert dist._polygon is None
    np.testing.assert_array_equal(dist(inner), IndexedContourDistance(square)(inner))
    assert dist._polygon is None
    corner = np.array([[12.0, 12.0], [-1.0, -1.0]])
    np.testing.assert_allclose(dist(corner), IndexedContourDistance(square)(corner), rtol=0, atol=1e-12)
    assert dist._polygon is not None
