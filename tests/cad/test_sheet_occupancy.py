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


def _full_free(occ: Occupancy, quads: list[np.ndarray], segs: np.ndarray) -> bool:
    """Occupancy.free as the full tests alone answer it (no skipping of the items far away)."""
    from camfab.cad import sheet_check as sc

    stack = np.array(occ.quads, dtype=float).reshape(-1, 4, 2)
    x0, y0, x1, y1 = occ.frame
    for q in quads:
        if q[:, 0].min() < x0 or q[:, 1].min() < y0 or q[:, 0].max() > x1 or q[:, 1].max() > y1:
            return False
        if len(occ.segments) and sc._crosses(q, occ.segments).any():
            return False
        if sc._any_overlap(q, stack):
            return False
    return not (len(segs) and len(stack) and sc._any_crosses(stack, segs))


def test_free_skips_only_what_the_full_tests_would_pass():
    """free() skips a full test when every item lies clear of the new box or lines: its answer is the full
    tests' on random boxes (some of zero width) and on lines passing through and close by their corners."""
    rng = np.random.default_rng(3)
    for _ in range(600):
        boxes = [_box(rng) for _ in range(rng.integers(0, 8))]
        for b in boxes[: rng.integers(0, 2)]:
            b[1], b[2] = b[0], b[3]  # a text of no width
        lines = []
        for _ in range(rng.integers(0, 8)):
            if boxes and rng.random() < 0.5:
                corner = boxes[rng.integers(len(boxes))][rng.integers(4)]
                p = corner + rng.normal(0, rng.choice([1e-9, 1e-6, 0.05, 0.5]), 2)
                d = rng.normal(0, 1, 2)
                t0, t1 = sorted(rng.uniform(-3, 3, 2))
                lines.append(np.r_[p + t0 * d, p + t1 * d])
            else:
                lines.append(rng.uniform(-2, 14, 4))
        occ = _occupancy(boxes)
        occ.segments = np.array(lines, dtype=float).reshape(-1, 4)
        new = [_box(rng) for _ in range(rng.integers(0, 3))]
        segs = rng.uniform(-2, 14, (rng.integers(0, 4), 4))
        with np.errstate(invalid="ignore", divide="ignore"):  # (a box of no width has no edge normal)
            assert occ.free(new, segs) == _full_free(occ, new, segs)
            occ.add([_box(rng)], rng.uniform(0, 12, (2, 4)))
            assert occ.free(new, segs) == _full_free(occ, new, segs)


def test_straight_polylines_give_the_segments_of_their_path():
    """sheet_items reads a straight LWPOLYLINE's segments off its vertices: the ones ezdxf's path of it
    flattens to (closing segment only when the last vertex is not the first already)."""
    ezdxf = pytest.importorskip("ezdxf")
    from ezdxf import path as ezpath

    from camfab.cad.sheet_check import _segments

    msp = ezdxf.new("R2010").modelspace()
    shapes = [msp.add_lwpolyline([(0, 0), (4, 0), (4, 2), (0, 2)], close=True),
              msp.add_lwpolyline([(0, 0), (1, 0), (1, 1), (0, 0)], close=True),
              msp.add_lwpolyline([(0, 0), (1, 0), (1, 0), (2, 3)], close=True),
              msp.add_lwpolyline([(0.1, 0.2), (3.3, 1.7)], close=False),
              msp.add_lwpolyline([(5.0, 5.0)], close=True),
              msp.add_lwpolyline([(0, 0, 0, 0, 1e-7), (1, 0), (0, 1)], format="xyseb", close=True),
              msp.add_lwpolyline([(0, 0, 0, 0, 0.4), (1, 0), (0, 1)], format="xyseb", close=True),
              msp.add_lwpolyline([(0, 0), (2, 0), (2, 1)], close=True, dxfattribs={"elevation": 1.5}),
              msp.add_line((1, 2), (3, 4))]
    for e in shapes:
        pts = [(p.x, p.y) for p in ezpath.make_path(e).flattening(0.05)]
        assert _segments(e) == [(a[0], a[1], b[0], b[1]) for a, b in zip(pts[:-1], pts[1:], strict=True)]
