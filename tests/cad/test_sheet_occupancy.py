"""A drawing's dimension placement (camfab.cad.sheet_check.Occupancy.free) refuses a dimension whose lines pass
through a text already on the sheet, and only then: checked on random turned boxes and segments against
shapely: a segment through the box shrunk by the rule's rim is refused, one that misses the whole box is not
(within the rim either answer keeps the rule)."""
from __future__ import annotations

import numpy as np
import pytest

from camfab.cad.sheet_check import Occupancy

shapely = pytest.importorskip("shapely")
from shapely.geometry import LineString, Polygon  # noqa: E402

RIM = 0.05  # the rim a line may touch (sheet_check's eps)


def _box(rng) -> np.ndarray:
    c, (w, h), a = rng.uniform(0, 10, 2), rng.uniform(0.3, 3, 2), rng.uniform(0, np.pi)
    u = np.array([np.cos(a), np.sin(a)])
    v = np.array([-u[1], u[0]])
    return np.array([c, c + w * u, c + w * u + h * v, c + h * v])


def _occupancy(boxes: list[np.ndarray]) -> Occupancy:
    occ = Occupancy.__new__(Occupancy)  # no sheet: only the texts already placed
    occ.quads, occ.segments, occ.frame = boxes, np.zeros((0, 4)), (-100.0, -100.0, 100.0, 100.0)
    return occ


def test_lines_through_a_text_are_refused_and_only_those():
    rng = np.random.default_rng(7)
    seen = {True: 0, False: 0}
    for _ in range(400):
        boxes = [_box(rng) for _ in range(rng.integers(1, 6))]
        segs = rng.uniform(0, 12, (rng.integers(1, 4), 4))
        shrunk = [Polygon(b).buffer(-RIM, join_style="mitre") for b in boxes]
        lines = [LineString(s.reshape(2, 2)) for s in segs]
        crossing = any(p.intersects(ln) and ln.intersection(p).length > 1e-6
                       for p in shrunk for ln in lines)
        clear = min(Polygon(b).distance(ln) for b in boxes for ln in lines) > 1e-6
        if not (crossing or clear):
            continue  # in the rim: either answer keeps the rule
        free = _occupancy(boxes).free([], segs)
        assert free == (not crossing), (boxes, segs)
        seen[crossing] += 1
    assert seen[True] > 50 and seen[False] > 50


def test_a_text_over_a_text_is_refused_and_only_that():
    """All boxes at once (sheet_check._any_overlap) give shapely's answer: a new text box overlapping one already
    placed by more than the rim is refused, one clear of them all is not."""
    rng = np.random.default_rng(11)
    seen = {True: 0, False: 0}
    for _ in range(400):
        boxes = [_box(rng) for _ in range(rng.integers(1, 8))]
        new = _box(rng)
        grown, shrunk = Polygon(new), Polygon(new).buffer(-2 * RIM, join_style="mitre")
        overlapping = any(Polygon(b).buffer(-2 * RIM, join_style="mitre").intersects(shrunk) for b in boxes)
        clear = min(Polygon(b).distance(grown) for b in boxes) > 1e-6
        if not (overlapping or clear):
            continue  # within the rims: either answer keeps the rule
        assert _occupancy(boxes).free([new], np.zeros((0, 4))) == (not overlapping), (boxes, new)
        seen[overlapping] += 1
    assert seen[True] > 50 and seen[False] > 50
