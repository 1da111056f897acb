"""The layout rule of a drawing sheet (docs/decisions.md, "Drawing layout rule"), checked on the sheet itself:
the boxes of every text (conservatively measured, :func:`camfab.cad.sheet.text_width`), the line segments of
every entity and DIMENSION block, grouped into title block, lift table, notes, cam view and side view.

:func:`layout_problems` lists what breaks the rule (the tests require none on every example and paper);
:class:`Occupancy` applies it while drawing, to place each dimension at a free position.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

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
    uv = np.array([(u0, v0), (u1, v0), (u1, v1), (u0, v1)])
    return np.column_stack([x + uv[:, 0] * c - uv[:, 1] * s, y + uv[:, 0] * s + uv[:, 1] * c])


def _text_box(e) -> tuple[str, np.ndarray]:
    """A TEXT's or MTEXT's text and its conservative box (:func:`text_width`; TEXT from the baseline less a
    quarter height for descenders to the cap height; MTEXT lines at :data:`NOTE_PITCH`)."""
    if e.dxftype() == "TEXT":
        align, p1, p2 = e.get_placement()
        h = e.dxf.height
        w = text_width(e.dxf.text, h)
        name = align.name  # e.g. MIDDLE_CENTER, BOTTOM_LEFT, LEFT
        v, _, hname = name.partition("_") if "_" in name else ("BASELINE", "", name)
        at = p1 if name in ("LEFT",) else (p2 if p2 is not None else p1)
        u0 = -_HALIGN.get(hname, 0.0) * w
        v0 = {"TOP": -h, "MIDDLE": -h / 2, "BOTTOM": -0.25 * h}.get(v, -0.25 * h)
        v1 = {"TOP": 0.0, "MIDDLE": h / 2}.get(v, h)
        return e.dxf.text, _rotated_box(at[0], at[1], (u0, v0, u0 + w, v1), e.dxf.rotation)
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
    if kind == "INSERT":
        return [s for v in e.virtual_entities() for s in _segments(v, flat)]
    if kind not in ("LINE", "LWPOLYLINE", "ARC", "CIRCLE", "SOLID"):
        return []
    pts = [(p.x, p.y) for p in ezpath.make_path(e).flattening(flat)]
    return [(a[0], a[1], b[0], b[1]) for a, b in zip(pts[:-1], pts[1:], strict=True)]


def sheet_items(doc, layout: SheetLayout) -> SheetItems:
    """Every text box and line segment of a sheet (the frame excepted), grouped: by layer for the title
    block, lift table and notes, by position for the side view (right of ``layout.side``'s left edge),
    the rest is the cam view; a DIMENSION's lines and text are owned by it."""
    texts, segs, groups, owners, refs = [], [], [], [], []

    def group_of(e, x: float) -> str:
        g = _GROUP_OF_LAYER.get(e.dxf.layer)
        if g:
            return g
        return "side" if layout.side is not None and x >= layout.side[0] else "view"

    for e in doc.modelspace():
        if e.dxf.layer == "FRAME" or e.dxftype() == "POINT":
            continue
        if e.dxftype() == "DIMENSION":
            block = doc.blocks.get(e.dxf.geometry)
            lines = [s for t in block for s in _segments(t)]
            x = min(s[0] for s in lines)
            g = group_of(e, x)
            for text, box in _dimension_quads(doc, e):
                texts.append((text, g, e.dxf.handle, box))
            segs += lines
            groups += [g] * len(lines)
            owners += [e.dxf.handle] * len(lines)
            refs += [False] * len(lines)
        elif e.dxftype() in ("TEXT", "MTEXT"):
            text, box = _text_box(e)
            texts.append((text, group_of(e, float(box[:, 0].min())), "", box))
        else:
            lines = _segments(e)
            if lines:
                g = group_of(e, min(min(s[0], s[2]) for s in lines))
                segs += lines
                groups += [g] * len(lines)
                owners += [""] * len(lines)
                refs += [e.dxf.layer in REFERENCE_LAYERS] * len(lines)
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
        for g in ("title", "table", "notes", "side"):  # the other groups' boxes: no view text may enter them
            pts = [q for _, grp, _, q in it.texts if grp == g]
            segs = it.segments[np.array([x == g for x in it.seg_group], dtype=bool)] if len(it.segments) else []
            pts += [seg.reshape(2, 2) for seg in segs]
            if pts:
                allp = np.vstack(pts)
                self.quads.append(_quad((allp[:, 0].min(), allp[:, 1].min(), allp[:, 0].max(), allp[:, 1].max())))

    def free(self, quads: list[np.ndarray], segments: np.ndarray) -> bool:
        x0, y0, x1, y1 = self.frame
        for q in quads:
            if q[:, 0].min() < x0 or q[:, 1].min() < y0 or q[:, 0].max() > x1 or q[:, 1].max() > y1:
                return False
            if len(self.segments) and _crosses(q, self.segments).any():
                return False
            if _any_overlap(q, self._stacked()):
                return False
        return not (len(segments) and self.quads and _any_crosses(self._stacked(), segments))

    def _stacked(self) -> np.ndarray:
        """:attr:`quads` as one (m, 4, 2) array (made again when a box was added)."""
        st = getattr(self, "_stack", None)
        if st is None or len(st) != len(self.quads):
            st = self._stack = np.array(self.quads, dtype=float).reshape(-1, 4, 2)
        return st

    def add(self, quads: list[np.ndarray], segments: np.ndarray) -> None:
        self.quads += quads
        self.segments = np.vstack([self.segments.reshape(-1, 4), segments.reshape(-1, 4)])
