"""The layout rule of a drawing sheet (docs/decisions.md, "Drawing layout rule"), checked on the sheet itself:
the boxes of every text (conservatively measured, :func:`camfab.cad.sheet.text_width`), the line segments of
every entity and DIMENSION block, grouped into title block, lift table, notes, cam view and side view.

:func:`layout_problems` lists what breaks the rule (the tests require none on every example and paper);
:class:`Occupancy` applies it while drawing, to place each dimension at a free position.
"""
from __future__ import annotations

import math

import numpy as np

from ..records import dataclass
from .sheet import NOTE_PITCH, SheetLayout, text_width

__all__ = ["SheetItems", "sheet_items", "layout_problems", "Occupancy", "dimension_parts", "REFERENCE_LAYERS"]


_GROUP_OF_LAYER = {"TITLE_BLOCK": "title", "LIFT_TABLE": "table", "NOTES": "notes"}
#: thin reference circles (base circle, prime or face-centre circle) that may pass behind a text; a face-centre
#: circle can be larger than the cam, and a small base circle runs close round the bore's texts
REFERENCE_LAYERS = ("BASE_CIRCLE", "PRIME_CIRCLE")
_HALIGN = {"LEFT": 0.0, "CENTER": 0.5, "MIDDLE": 0.5, "RIGHT": 1.0, "ALIGNED": 0.0, "FIT": 0.0}


@dataclass(frozen=True)
class SheetItems:
    """What lies on a sheet, in paper mm: the text boxes and line segments with their group (``title``,
    ``table``, ``notes``, ``view``, ``side``) and owner (the handle of the DIMENSION they belong to, else
    ``""``)."""

    texts: list[tuple[str, str, str, np.ndarray]]  # (text, group, owner, corners (4, 2) of its box)
    segments: np.ndarray  # (n, 4) x0, y0, x1, y1
    seg_group: list[str]
    seg_owner: list[str]
    seg_reference: np.ndarray  # (n,) bool: on a layer of REFERENCE_LAYERS


def _rotated_box(x: float, y: float, local: tuple[float, float, float, float], deg: float) -> np.ndarray:
    """The corners (4, 2) of the box ``local`` = (u0, v0, u1, v1) turned by ``deg`` about (0, 0) and moved to
    (x, y)."""
    a = math.radians(deg)
    c, s = math.cos(a), math.sin(a)
    u0, v0, u1, v1 = local
    # the corner arithmetic in floats, in the order of the former array expression (x + u c - v s,
    # y + u s + v c): the same values, without numpy's overhead on four points (a sheet measures ~150 boxes)
    return np.array([(x + u * c - v * s, y + u * s + v * c) for u, v in ((u0, v0), (u1, v0), (u1, v1), (u0, v1))],
                    dtype=float)


#: a TEXT alignment's name -> (where its box starts along the text, in widths; its bottom and top, in heights)
#: (a bare LEFT, CENTER, RIGHT, ALIGNED or FIT sits on the baseline: a quarter height below it for descenders)
_TEXT_ANCHOR: dict[str, tuple[float, float, float]] = {}


def _text_anchor(name: str) -> tuple[float, float, float]:
    got = _TEXT_ANCHOR.get(name)
    if got is None:
        v, _, hname = name.partition("_") if "_" in name else ("BASELINE", "", name)
        got = _TEXT_ANCHOR[name] = (-_HALIGN.get(hname, 0.0), {"TOP": -1.0, "MIDDLE": -0.5}.get(v, -0.25),
                                    {"TOP": 0.0, "MIDDLE": 0.5}.get(v, 1.0))
    return got


def _text_box(e) -> tuple[str, np.ndarray]:
    """A TEXT's or MTEXT's text and its conservative box (:func:`text_width`; TEXT from the baseline less a
    quarter height for descenders to the cap height; MTEXT lines at :data:`NOTE_PITCH`)."""
    if e.dxftype() == "TEXT":
        dxf = e.dxf
        h, text = dxf.height, dxf.text
        w = text_width(text, h)
        name = e.get_align_enum().name  # e.g. MIDDLE_CENTER, BOTTOM_LEFT, LEFT
        # where Text.get_placement puts it: a LEFT text at its insert, any other at its align point (the insert
        # when it has none)
        at = dxf.insert if name == "LEFT" else dxf.get("align_point", dxf.insert)
        fu, fv0, fv1 = _text_anchor(name)
        u0 = fu * w
        return text, _rotated_box(at[0], at[1], (u0, fv0 * h, u0 + w, fv1 * h), dxf.rotation)
    lines = e.text.split("\\P")
    h = e.dxf.char_height
    w, tall = max(text_width(line, h) for line in lines), h + (len(lines) - 1) * h * NOTE_PITCH
    ap = e.dxf.attachment_point
    u0 = -w * ((ap - 1) % 3) / 2
    v1 = {0: 0.0, 1: tall / 2, 2: tall}[(ap - 1) // 3]
    direction = e.dxf.get("rotation", 0.0)
    if e.dxf.hasattr("text_direction"):
        d = e.dxf.text_direction
        direction = math.degrees(math.atan2(d[1], d[0]))
    x, y = e.dxf.insert[0], e.dxf.insert[1]
    return e.text, _rotated_box(x, y, (u0, v1 - tall, u0 + w, v1), direction)


def _segments(e, flat: float = 0.05) -> list[tuple[float, float, float, float]]:
    from ezdxf import path as ezpath

    kind = e.dxftype()
    if kind == "LINE":  # what the path of a LINE flattens to (its two end points), without building the path
        a, b = e.dxf.start, e.dxf.end
        return [(a.x, a.y, b.x, b.y)]
    if kind == "INSERT":
        return [s for v in e.virtual_entities() for s in _segments(v, flat)]
    if kind not in ("LWPOLYLINE", "ARC", "CIRCLE", "SOLID"):
        return []
    if kind == "LWPOLYLINE":
        straight = _straight_polyline(e)
        if straight is not None:
            return straight
    pts = [(p.x, p.y) for p in ezpath.make_path(e).flattening(flat)]
    return [(a[0], a[1], b[0], b[1]) for a, b in zip(pts[:-1], pts[1:], strict=True)]


def _straight_polyline(e) -> list[tuple[float, float, float, float]] | None:
    """The segments of an LWPOLYLINE of straight lines in the drawing plane (a rectangle of the frame, title
    block or lift table) as ezdxf's path of it flattens to (``ezdxf.path.tools.add_2d_polyline``: a line to
    every vertex, and back to the first when closed unless the last is there already), without building the
    path; None for any other polyline (bulges, elevation or a tilted plane: the path decides)."""
    from ezdxf.math import Vec3
    from ezdxf.path.tools import IS_CLOSE_TOL

    dxf = e.dxf
    if dxf.elevation or tuple(Vec3(dxf.extrusion)) != (0.0, 0.0, 1.0):  # (exactly: the OCS is no transform)
        return None
    pts = e.get_points("xyb")
    if any(abs(b) >= 1e-6 for _, _, b in pts):  # (add_2d_polyline takes a smaller bulge for none)
        return None
    xy = [(float(x), float(y)) for x, y, _ in pts]
    if e.closed and len(xy) > 1 and not Vec3(xy[0]).isclose(Vec3(xy[-1]), rel_tol=IS_CLOSE_TOL, abs_tol=0):
        xy.append(xy[0])
    return [(a[0], a[1], b[0], b[1]) for a, b in zip(xy[:-1], xy[1:], strict=True)]


def sheet_items(doc, layout: SheetLayout) -> SheetItems:
    """Every text box and line segment of a sheet (the frame excepted), grouped: by layer for the title
    block, lift table and notes, by position for the side view (right of ``layout.side``'s left edge),
    the rest is the cam view; a DIMENSION's lines and text are owned by it."""
    texts, segs, groups, owners, refs = [], [], [], [], []
    side = layout.side[0] if layout.side is not None else None

    def group_at(x: float) -> str:  # an item on no layer of its own: the side view or the cam view
        return "side" if side is not None and x >= side else "view"

    for e in doc.modelspace():
        layer, kind = e.dxf.layer, e.dxftype()
        if layer == "FRAME" or kind == "POINT":
            continue
        g = _GROUP_OF_LAYER.get(layer)  # (a position is found only for the items that need one)
        if kind == "DIMENSION":
            block = doc.blocks.get(e.dxf.geometry)
            lines = [s for t in block for s in _segments(t)]
            g = g or group_at(min(s[0] for s in lines))
            for text, box in _dimension_quads(doc, e):
                texts.append((text, g, e.dxf.handle, box))
            segs += lines
            groups += [g] * len(lines)
            owners += [e.dxf.handle] * len(lines)
            refs += [False] * len(lines)
        elif kind in ("TEXT", "MTEXT"):
            text, box = _text_box(e)
            texts.append((text, g or group_at(min(box[:, 0].tolist())), "", box))
        else:
            lines = _segments(e)
            if lines:
                g = g or group_at(min(min([s[0] for s in lines]), min([s[2] for s in lines])))
                segs += lines
                groups += [g] * len(lines)
                owners += [""] * len(lines)
                refs += [layer in REFERENCE_LAYERS] * len(lines)
    return SheetItems(texts, np.array(segs, dtype=float).reshape(-1, 4), groups, owners, np.array(refs, dtype=bool))


def _axes(quad: np.ndarray) -> np.ndarray:
    """The two edge normals of a box given by its corners (4, 2)."""
    e = np.array([quad[1] - quad[0], quad[3] - quad[0]])
    return np.column_stack([-e[:, 1], e[:, 0]])


def _crosses(quad: np.ndarray, seg: np.ndarray, eps: float = 0.05) -> np.ndarray:
    """Which segments pass through the inside of the box ``quad`` (corners (4, 2)) shrunk by ``eps``
    (separating axes: the box's two edge normals and each segment's normal)."""
    hit = np.ones(len(seg), dtype=bool)
    for n in _axes(quad):
        n = n / np.hypot(*n)
        q = quad @ n
        lo, hi = q.min() + eps, q.max() - eps
        a, b = seg[:, :2] @ n, seg[:, 2:] @ n
        hit &= (np.maximum(a, b) > lo) & (np.minimum(a, b) < hi)
    nx, ny = seg[:, 1] - seg[:, 3], seg[:, 2] - seg[:, 0]
    d = nx * (quad[:, :1] - seg[:, 0]) + ny * (quad[:, 1:] - seg[:, 1])  # (4, n): the corners' sides
    return hit & (d.max(axis=0) > 0) & (d.min(axis=0) < 0)


def _any_crosses(quads: np.ndarray, seg: np.ndarray, eps: float = 0.05) -> bool:
    """Whether any of the segments passes through the inside of any of the boxes ``quads`` (m, 4, 2): the test
    of :func:`_crosses`, all boxes at once (a new dimension's few lines against every text on the sheet)."""
    e = np.stack([quads[:, 1] - quads[:, 0], quads[:, 3] - quads[:, 0]], axis=1)  # (m, 2 edges, 2)
    normals = np.stack([-e[..., 1], e[..., 0]], axis=-1)
    hit = np.ones((len(quads), len(seg)), dtype=bool)
    for k in range(2):
        n = normals[:, k] / np.hypot(normals[:, k, 0], normals[:, k, 1])[:, None]  # (m, 2)
        q = quads[..., 0] * n[:, :1] + quads[..., 1] * n[:, 1:]  # (m, 4)
        lo, hi = q.min(axis=1)[:, None] + eps, q.max(axis=1)[:, None] - eps
        a = seg[None, :, 0] * n[:, :1] + seg[None, :, 1] * n[:, 1:]  # (m, n)
        b = seg[None, :, 2] * n[:, :1] + seg[None, :, 3] * n[:, 1:]
        hit &= (np.maximum(a, b) > lo) & (np.minimum(a, b) < hi)
    nx, ny = seg[:, 1] - seg[:, 3], seg[:, 2] - seg[:, 0]
    d = nx * (quads[..., :1] - seg[:, 0]) + ny * (quads[..., 1:] - seg[:, 1])  # (m, 4, n): the corners' sides
    return bool((hit & (d.max(axis=1) > 0) & (d.min(axis=1) < 0)).any())


def _overlap(a: np.ndarray, b: np.ndarray, eps: float = 0.05) -> bool:
    """Whether two boxes (corners (4, 2)) share more than a rim of ``eps``."""
    return _any_overlap(a, b[None], eps)


def _any_overlap(a: np.ndarray, others: np.ndarray, eps: float = 0.05) -> bool:
    """Whether the box ``a`` (corners (4, 2)) overlaps any of the boxes ``others`` (m, 4, 2): the test of
    :func:`_overlap`, all boxes at once (a new dimension's text against every text on the sheet)."""
    if not len(others):
        return False
    ea = np.array([a[1] - a[0], a[3] - a[0]])  # a's two edge normals, each tested against every box
    na = np.stack([-ea[:, 1], ea[:, 0]], axis=-1)
    na = na / np.hypot(na[:, 0], na[:, 1])[:, None]  # (2, 2)
    pa = a @ na.T  # (4, 2)
    pb = others @ na.T  # (m, 4, 2)
    sep = (pa.max(axis=0) - eps <= pb.min(axis=1)) | (pb.max(axis=1) - eps <= pa.min(axis=0))  # (m, 2)
    eb = np.stack([others[:, 1] - others[:, 0], others[:, 3] - others[:, 0]], axis=1)  # (m, 2, 2)
    nb = np.stack([-eb[..., 1], eb[..., 0]], axis=-1)
    nb = nb / np.hypot(nb[..., 0], nb[..., 1])[..., None]  # (m, 2 normals, 2)
    qa = np.einsum("pc,mkc->mkp", a, nb)  # (m, 2, 4): a's corners on each box's normals
    qb = np.einsum("mpc,mkc->mkp", others, nb)
    sep_b = (qa.max(axis=2) - eps <= qb.min(axis=2)) | (qb.max(axis=2) - eps <= qa.min(axis=2))  # (m, 2)
    return bool((~(sep.any(axis=1) | sep_b.any(axis=1))).any())


def _quad(b) -> np.ndarray:
    return np.array([(b[0], b[1]), (b[2], b[1]), (b[2], b[3]), (b[0], b[3])], dtype=float)


def layout_problems(doc, layout: SheetLayout) -> list[str]:
    """The layout rule (docs/decisions.md, "Drawing layout rule") checked on a sheet: everything inside the
    frame; the title block, lift table, notes, cam view and side view (each the box of all it holds) apart;
    no two texts overlapping; no line through a text except its own dimension's and the thin reference
    circles (:data:`REFERENCE_LAYERS`).  Returns the
    violations (empty when the sheet keeps the rule)."""
    it = sheet_items(doc, layout)
    out: list[str] = []
    fx0, fy0, fx1, fy1 = layout.frame
    for text, _, _, q in it.texts:
        if q[:, 0].min() < fx0 or q[:, 1].min() < fy0 or q[:, 0].max() > fx1 or q[:, 1].max() > fy1:
            out.append(f"text {text!r} {_fmt_box(q)} leaves the frame")
    s = it.segments
    if len(s):
        outside = ((np.minimum(s[:, 0], s[:, 2]) < fx0 - 1e-6) | (np.maximum(s[:, 0], s[:, 2]) > fx1 + 1e-6)
                   | (np.minimum(s[:, 1], s[:, 3]) < fy0 - 1e-6) | (np.maximum(s[:, 1], s[:, 3]) > fy1 + 1e-6))
        for i in np.flatnonzero(outside)[:5]:
            out.append(f"a {it.seg_group[i]} line {s[i].round(2).tolist()} leaves the frame")
    boxes: dict[str, list[float]] = {}
    for _, g, _, q in it.texts:
        b = [q[:, 0].min(), q[:, 1].min(), q[:, 0].max(), q[:, 1].max()]
        boxes.setdefault(g, list(b))
        boxes[g] = [min(boxes[g][0], b[0]), min(boxes[g][1], b[1]), max(boxes[g][2], b[2]), max(boxes[g][3], b[3])]
    for g in set(it.seg_group):
        m = np.array([x == g for x in it.seg_group])
        sg = s[m]
        b = [float(np.minimum(sg[:, 0], sg[:, 2]).min()), float(np.minimum(sg[:, 1], sg[:, 3]).min()),
             float(np.maximum(sg[:, 0], sg[:, 2]).max()), float(np.maximum(sg[:, 1], sg[:, 3]).max())]
        old = boxes.get(g, b)
        boxes[g] = [min(old[0], b[0]), min(old[1], b[1]), max(old[2], b[2]), max(old[3], b[3])]
    seg_group = np.array(it.seg_group)
    # nothing of one group inside the box of another; the cam view's items scatter round the cam (a leader, a
    # label below it), so its box is no container: its items are kept apart item by item (texts and lines)
    for g, box in sorted((g, b) for g, b in boxes.items() if g != "view"):
        quad = _quad(box)
        for text, tg, _, q in it.texts:
            if tg != g and _overlap(q, quad):
                out.append(f"text {text!r} of the {tg} {_fmt_box(q)} enters the {g} {_fmt_box(box)}")
        if len(s):
            inside = _crosses(quad, s) & (seg_group != g)
            for k in np.flatnonzero(inside)[:2]:
                out.append(f"a {seg_group[k]} line {s[k].round(2).tolist()} enters the {g} {_fmt_box(box)}")
    for i, (ta, _, _, ba) in enumerate(it.texts):
        for tb, _, _, bb in it.texts[i + 1:]:
            if _overlap(ba, bb):
                out.append(f"texts {ta!r} {_fmt_box(ba)} and {tb!r} {_fmt_box(bb)} overlap")
        owner = it.texts[i][2]
        hit = (_crosses(ba, s) & np.array([o != owner or not owner for o in it.seg_owner], dtype=bool)
               & ~it.seg_reference)
        for k in np.flatnonzero(hit)[:2]:
            out.append(f"a {it.seg_group[k]} line {s[k].round(2).tolist()} runs through text {ta!r} {_fmt_box(ba)}")
    return out


def _fmt_box(b) -> str:
    b = np.asarray(b, dtype=float)
    if b.ndim == 2:
        b = np.array([b[:, 0].min(), b[:, 1].min(), b[:, 0].max(), b[:, 1].max()])
    return "(" + ", ".join(f"{v:.1f}" for v in b) + ")"


def _dimension_quads(doc, dim) -> list[tuple[str, np.ndarray]]:
    """A DIMENSION's texts and their boxes as ezdxf renders them (centred on the text position) — and, for a
    linear dimension whose text is longer than its dimension line, also where LibreCAD puts it: starting at
    the text position (it shifts a text that does not fit by half its length along the reading direction)."""
    out = []
    for t in doc.blocks.get(dim.dxf.geometry):
        if t.dxftype() != "MTEXT":
            continue
        text, q = _text_box(t)
        if dim.dimtype == 0:  # linear: the measured length on paper, along the dimension line
            a = math.radians(dim.dxf.angle)
            u = np.array([math.cos(a), math.sin(a)])
            p2, p3 = dim.dxf.defpoint2, dim.dxf.defpoint3
            span = abs(float(np.dot((p3.x - p2.x, p3.y - p2.y), u)))
            length = float(np.hypot(*(q[1] - q[0])))
            if length > span:
                d = (q[1] - q[0]) / length * (length / 2)
                q = np.array([q[0], q[1] + d, q[2] + d, q[3]])
        out.append((text, q))
    return out


def dimension_parts(doc, dim) -> tuple[list[np.ndarray], np.ndarray]:
    """A rendered DIMENSION's text boxes (corners, see :func:`_dimension_quads`) and line segments (n, 4)."""
    block = doc.blocks.get(dim.dxf.geometry)
    quads = [q for _, q in _dimension_quads(doc, dim)]
    return quads, np.array([s for t in block for s in _segments(t)], dtype=float).reshape(-1, 4)


class Occupancy:
    """The text boxes and line segments already on a sheet, to place a new dimension where its text crosses
    no line and no text, and its lines cross no text (the layout rule, applied while drawing)."""

    def __init__(self, doc, layout: SheetLayout) -> None:
        it = sheet_items(doc, layout)
        self.quads = [q for *_, q in it.texts]
        self.segments = it.segments[~it.seg_reference]
        self.frame = layout.frame
        seg_group = np.array(it.seg_group) if len(it.segments) else None
        for g in ("title", "table", "notes", "side"):  # the other groups' boxes: no view text may enter them
            pts = [q for _, grp, _, q in it.texts if grp == g]
            if seg_group is not None:  # the group's segments' end points, all at once
                pts.append(it.segments[seg_group == g].reshape(-1, 2))
            allp = np.vstack(pts) if pts else np.empty((0, 2))
            if len(allp):
                self.quads.append(_quad((allp[:, 0].min(), allp[:, 1].min(), allp[:, 0].max(), allp[:, 1].max())))

    def free(self, quads: list[np.ndarray], segments: np.ndarray) -> bool:
        # Each test below is first asked of the items near enough to matter: when none is (clear bounds, or a
        # gap on a separating axis, see _plain), its answer is known (no crossing, no overlap) and the full test
        # is skipped; otherwise the full test runs as ever, on everything.  Most positions tried are free, so
        # most tests are skipped.
        x0, y0, x1, y1 = self.frame
        for q in quads:
            xs, ys = q[:, 0].tolist(), q[:, 1].tolist()  # (four corners: plain floats compare faster)
            box = (min(xs), min(ys), max(xs), max(ys))
            if box[0] < x0 or box[1] < y0 or box[2] > x1 or box[3] > y1:
                return False
            plain = _plain_box(q)
            if len(self.segments) and not (plain and self._segments_clear(q, box)) \
                    and _crosses(q, self.segments).any():
                return False
            if not (plain and self._quads_apart(box[0], box[1], box[2], box[3]).all()) \
                    and _any_overlap(q, self._stacked()):
                return False
        if not (len(segments) and self.quads):
            return True
        sb = _segment_bounds(segments)  # (k, 4): each of the new lines against every box
        if self._quads_apart(sb[None, :, 0], sb[None, :, 1], sb[None, :, 2], sb[None, :, 3]).all():
            return True
        return not _any_crosses(self._stacked(), segments)

    def _stacked(self) -> np.ndarray:
        """:attr:`quads` as one (m, 4, 2) array (made again when the list has changed length)."""
        st = getattr(self, "_stack", None)
        if st is None or len(st) != len(self.quads):
            st = self._stack = np.array(self.quads, dtype=float).reshape(-1, 4, 2)
        return st

    def _box_info(self) -> tuple[np.ndarray, np.ndarray]:
        """The bounds (m, 4) and plainness (m,) of :meth:`_stacked` (made again with it)."""
        st = self._stacked()
        got = getattr(self, "_info", None)
        if got is None or got[0] is not st:
            got = self._info = (st, _quad_bounds(st), _plain(st))
        return got[1], got[2]

    def _quads_apart(self, bx0, by0, bx1, by1) -> np.ndarray:
        """Which boxes of :attr:`quads` are plain (:func:`_plain`) and clear of the bounds ``b`` by more than
        :data:`_NEAR` on x or y: (m,) for one bounds given as floats, (m, k) for k given as (1, k) arrays."""
        b, plain = self._box_info()
        if np.ndim(bx0):  # several bounds: a column per box of the sheet
            b, plain = b[:, :, None], plain[:, None]
        return plain & ((b[:, 2] < bx0 - _NEAR) | (b[:, 0] > bx1 + _NEAR) | (b[:, 3] < by0 - _NEAR)
                        | (b[:, 1] > by1 + _NEAR))

    def _segment_bounds(self) -> np.ndarray:
        """The bounds (n, 4) of :attr:`segments` (made again when they have changed)."""
        got = getattr(self, "_seg_bounds", None)
        if got is None or got[0] is not self.segments:
            got = self._seg_bounds = (self.segments, _segment_bounds(self.segments))
        return got[1]

    def _segments_clear(self, q: np.ndarray, box: tuple[float, float, float, float]) -> bool:
        """Whether every segment of :attr:`segments` is clear of the plain box ``q`` (bounds ``box``): its
        bounds apart from ``box``, or a gap above :data:`_NEAR` on a separating axis (:func:`_gap_apart`)."""
        near = np.flatnonzero(~_apart(self._segment_bounds(), box))
        if len(near) > 16:  # (a box among many lines: the full test is as quick)
            return False
        return all(_gap_apart(q, s) for s in self.segments[near].tolist())

    def add(self, quads: list[np.ndarray], segments: np.ndarray) -> None:
        st, info = getattr(self, "_stack", None), getattr(self, "_info", None)
        if st is not None and len(st) == len(self.quads) and len(quads):  # the stack grows with the list
            new = np.array(quads, dtype=float).reshape(-1, 4, 2)
            self._stack = np.concatenate([st, new])
            if info is not None and info[0] is st:
                self._info = (self._stack, np.concatenate([info[1], _quad_bounds(new)]),
                              np.concatenate([info[2], _plain(new)]))
        self.quads += quads
        old, sb = self.segments, getattr(self, "_seg_bounds", None)
        segments = segments.reshape(-1, 4)
        self.segments = np.vstack([old.reshape(-1, 4), segments])
        if sb is not None and sb[0] is old:
            self._seg_bounds = (self.segments, np.vstack([sb[1], _segment_bounds(segments)]))


#: how far apart (paper mm, on x or y) two items' bounds must lie for :meth:`Occupancy.free` to take them as
#: clear of each other without the full test; any positive distance would do (the tests' rim ``eps`` absorbs
#: rounding), this one is also far above it
_NEAR = 1e-6


def _plain(quads: np.ndarray) -> np.ndarray:
    """Which boxes (m, 4, 2) are plain parallelograms (finite, no edge of zero length, opposite edges equal to
    rounding) — the text boxes of a sheet.  For those, bounds clear of another item's bounds imply the full
    tests' answer: :func:`_any_overlap` finds two such boxes apart, as separating axes among their edge normals
    are certain to exist for disjoint parallelograms, and :func:`_crosses` finds a segment clear of such a box
    (it leaves the box's line through an edge, beyond which its projection on that edge's normal clears the
    box's, shrunk by the rim); a degenerate box has no such normals, so the full test decides."""
    e1, e2 = quads[:, 1] - quads[:, 0], quads[:, 3] - quads[:, 0]
    skew = np.abs(quads[:, 0] + quads[:, 2] - quads[:, 1] - quads[:, 3]).max(axis=1)
    size = np.abs(quads).max(axis=(1, 2))
    return (np.isfinite(quads).all(axis=(1, 2)) & (np.hypot(e1[:, 0], e1[:, 1]) > 0)
            & (np.hypot(e2[:, 0], e2[:, 1]) > 0) & (skew <= 1e-9 * (1.0 + size)))


def _plain_box(q: np.ndarray) -> bool:
    """:func:`_plain` of one box, in floats."""
    (ax, ay), (bx, by), (cx, cy), (dx, dy) = q.tolist()
    coords = (ax, ay, bx, by, cx, cy, dx, dy)
    if not all(math.isfinite(v) for v in coords):
        return False
    skew = max(abs(ax + cx - bx - dx), abs(ay + cy - by - dy))
    return (math.hypot(bx - ax, by - ay) > 0 and math.hypot(dx - ax, dy - ay) > 0
            and skew <= 1e-9 * (1.0 + max(abs(v) for v in coords)))


def _gap_apart(q: np.ndarray, seg: list[float]) -> bool:
    """Whether the segment ``seg`` (x0, y0, x1, y1) lies more than :data:`_NEAR` from the plain box ``q`` along
    one of the separating axes of the two (the box's edge normals, the segment's normal), in floats: then the
    two are apart and :func:`_crosses` finds no crossing (see :func:`_plain`)."""
    (ax, ay), (bx, by), (cx, cy), (dx, dy) = q.tolist()
    x0, y0, x1, y1 = seg
    for nx, ny in ((ay - by, bx - ax), (ay - dy, dx - ax), (y0 - y1, x1 - x0)):
        norm = math.hypot(nx, ny)
        if norm == 0:
            continue
        nx, ny = nx / norm, ny / norm
        p = (ax * nx + ay * ny, bx * nx + by * ny, cx * nx + cy * ny, dx * nx + dy * ny)
        s0, s1 = x0 * nx + y0 * ny, x1 * nx + y1 * ny
        if min(s0, s1) - max(p) > _NEAR or min(p) - max(s0, s1) > _NEAR:
            return True
    return False


def _quad_bounds(quads: np.ndarray) -> np.ndarray:
    """Each box's bounds (m, 4): x0, y0, x1, y1."""
    return np.concatenate([quads.min(axis=1), quads.max(axis=1)], axis=1)


def _segment_bounds(seg: np.ndarray) -> np.ndarray:
    """Each segment's bounds (n, 4): x0, y0, x1, y1."""
    seg = seg.reshape(-1, 4)
    return np.column_stack([np.minimum(seg[:, 0], seg[:, 2]), np.minimum(seg[:, 1], seg[:, 3]),
                            np.maximum(seg[:, 0], seg[:, 2]), np.maximum(seg[:, 1], seg[:, 3])])


def _apart(bounds: np.ndarray, box: tuple[float, float, float, float]) -> np.ndarray:
    """Which of the bounds (n, 4) lie clear of ``box`` by more than :data:`_NEAR` on x or y."""
    return ((bounds[:, 2] < box[0] - _NEAR) | (bounds[:, 0] > box[2] + _NEAR)
            | (bounds[:, 3] < box[1] - _NEAR) | (bounds[:, 1] > box[3] + _NEAR))
