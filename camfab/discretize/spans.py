"""The spans of a free arc spline: where a curve is cut (kinks, circular pieces, long stretches).

Spans run between *anchors*: true corners (kept as vertices) and circular pieces (dwells), whose
exact arcs the neighbouring spans continue; G1 breakpoints in between are crossed.  Long stretches
are cut into spans of about :data:`SPLINE_SPAN` arcs, joined G1 at curve points with the curve's
tangent.  Each span is clamped to the curve's point and tangent at both ends.
"""
from __future__ import annotations

import math

import numpy as np

from ..geom2d import cross, dot, rotate, unit
from ..records import dataclass, field
from .curve import ParametricCurve, piece_index, points_at
from .entities import MAX_TURNING_RAD, arc_from
from .spanmodel import cumtrapz, span_model, stacked_span_model
from .surrogate import HermiteSurrogate

__all__ = ["SPLINE_SPAN", "Span", "span_shape", "span_density", "span_ends", "cut_spans"]


#: most arcs of one free span: a longer smooth piece is cut into spans joined G1 at (surrogate)
#: curve points with the curve's tangent, which keeps every linear system small
SPLINE_SPAN = 40
#: a breakpoint whose one-sided tangents differ by less than this (radians) is G1 (arcs may run across it)
_G1_RAD = 1e-6
#: one-piece stretches from which their shapes are made at once (:func:`single_piece_shapes`)
_BATCH_SHAPES = 8


def span_shape(sur: HermiteSurrogate, segs, n: int = 257):
    """``(t, s, |κ'|, |κ|, piece)`` on a grid of about ``n`` points along the span (what its arc density needs,
    whatever the target): parameters, arc length, and the pieces of the grid points."""
    total = sum(hi - lo for _, lo, hi in segs)
    ts, ss, dks, ks, ps = [], [], [], [], []
    s_off = 0.0
    for seg in segs:
        k = max(33, int(round(n * (seg[2] - seg[1]) / total))) if len(segs) > 1 else n
        t, s0, theta = span_model(sur, [seg], k)
        kappa = np.gradient(theta, s0)
        ts.append(t)
        ss.append(s0 + s_off)
        dks.append(np.abs(np.gradient(kappa, s0)))
        ks.append(np.abs(kappa))
        ps.append(np.full(t.size, seg[0]))
        s_off += float(s0[-1])
    return tuple(np.concatenate(a) for a in (ts, ss, dks, ks, ps))


def _gradient_rows(f: np.ndarray, x: np.ndarray) -> np.ndarray:
    """``np.gradient(f[i], x[i])`` of every row ``i`` (first-order edges), operation for operation as numpy's: the
    centred formula for unequal steps, its uniform-step form on a row whose steps are all equal."""
    dx = x[:, 1:] - x[:, :-1]
    dx1, dx2 = dx[:, :-1], dx[:, 1:]
    out = np.empty_like(f)
    a = -(dx2) / (dx1 * (dx1 + dx2))
    b = (dx2 - dx1) / (dx1 * dx2)
    c = dx1 / (dx2 * (dx1 + dx2))
    out[:, 1:-1] = a * f[:, :-2] + b * f[:, 1:-1] + c * f[:, 2:]
    even = np.flatnonzero((dx == dx[:, :1]).all(axis=1))
    if even.size:
        out[even, 1:-1] = (f[even, 2:] - f[even, :-2]) / (2.0 * dx[even, :1])
    out[:, 0] = (f[:, 1] - f[:, 0]) / dx[:, 0]
    out[:, -1] = (f[:, -1] - f[:, -2]) / dx[:, -1]
    return out


def single_piece_shapes(sur: HermiteSurrogate, segs: list, n: int = 257) -> list:
    """:func:`span_shape` of every one-piece span ``[(piece, lo, hi)]`` of ``segs`` (one ``(piece, lo, hi)`` each) at
    once: the same values bit for bit (the rows of :func:`~camfab.discretize.spanmodel.stacked_span_model`, then
    every operation of :func:`span_shape` elementwise, numpy's gradient by :func:`_gradient_rows`), for a curve of
    hundreds of pieces (a knot table) whose spans would each cost their own few dozen small numpy calls."""
    t, s, theta, _, _, piece = stacked_span_model(sur, segs, n)
    kappa = _gradient_rows(theta, s)
    dk = np.abs(_gradient_rows(kappa, s))
    return [(t[i], s[i], dk[i], np.abs(kappa[i]), np.full(n, piece[i, 0])) for i in range(t.shape[0])]


def span_density(sur: HermiteSurrogate, segs, target: float, n: int = 257, shape=None):
    """``(t, s, density)``: arcs per unit length, ``(|κ'| / (124.7·target))^(1/3)`` (+ a turning bound).

    ``t`` holds the parameters of the grid and ``piece`` (4th value) their pieces; ``shape``: the span's
    :func:`span_shape`, when already computed."""
    t, s, dk, kappa, piece = span_shape(sur, segs, n) if shape is None else shape
    return t, s, (dk / (124.7 * target)) ** (1.0 / 3.0) + kappa / MAX_TURNING_RAD, piece


@dataclass
class Span:
    """A free span: consecutive smooth pieces joined G1, ``segs`` = ``[(piece, lo, hi), ...]``.

    Its ends are clamped (point and tangent of the curve); ``fixed`` imposes the curvature of the
    first / last arc (the span ends on a circular piece joined G1, e.g. a dwell: that arc continues
    the circle and merges with its exact arcs).  ``exact`` holds the exact arcs of a span that is
    one circular piece."""

    segs: list
    fixed: tuple = (None, None)
    exact: tuple | None = None
    label: int = 0
    #: its :func:`span_shape` when known (computed once: the cut and every fit of the span read it)
    shape: tuple | None = field(default=None, repr=False, compare=False)

    def sample(self, n: int) -> np.ndarray:
        """About ``n`` parameters spread over the span by parameter length (each piece's end left out)."""
        total = sum(hi - lo for _, lo, hi in self.segs)
        return np.concatenate([np.linspace(lo, hi, max(2, int(n * (hi - lo) / total)) + 1)[:-1]
                               for _, lo, hi in self.segs])

    def contains(self, t: float) -> bool:
        """Whether parameter ``t`` lies on the span."""
        return any(lo <= t <= hi for _, lo, hi in self.segs)


def _circle_pieces(curve: ParametricCurve, sur: HermiteSurrogate, tol: float):
    """``(g1, circ, k)``: tangent continuity at every piece start, circular pieces and their curvatures.

    A piece is circular (or straight) when 17 exact samples lie within ``tol/1000`` (and 1e-10 of
    its chord) of the circle through its samples 0, 4 and 8."""
    bp = curve.breakpoints
    n = bp.size - 1
    lo, hi = bp[:-1], bp[1:]
    idx = np.arange(n)
    t_in = unit(sur.derivative(lo, idx))
    t_out = unit(sur.derivative(hi, idx))
    prev = np.roll(t_out, 1, axis=0)
    g1 = np.abs(np.arctan2(cross(prev, t_in), dot(prev, t_in))) < _G1_RAD
    g1[0] &= curve.closed  # an open curve's start is a corner
    tt = lo[:, None] + (hi - lo)[:, None] * np.linspace(0.0, 1.0, 17)
    pts = points_at(curve, tt)
    # the tangent at the start of the circle through samples 0, 4, 8 (parallel to the line through
    # their images under inversion about sample 0): independent of derivative errors
    wb, wc = pts[:, 4] - pts[:, 0], pts[:, 8] - pts[:, 0]
    d = wc / np.maximum(dot(wc, wc), 1e-300)[:, None] - wb / np.maximum(dot(wb, wb), 1e-300)[:, None]
    t_in = unit(np.where((dot(d, wb) < 0)[:, None], -d, d))
    _, k, _, valid = arc_from(pts[:, 0], t_in, pts[:, 4])
    w = pts - pts[:, :1]
    x, y = dot(w, t_in[:, None]), cross(t_in[:, None], w)
    kk = k[:, None]
    radial = np.abs(kk * (x * x + y * y) - 2.0 * y) / (np.hypot(kk * x, 1.0 - kk * y) + 1.0)
    chord = np.hypot(*(pts[:, -1] - pts[:, 0]).T)
    circ = valid & (radial.max(axis=1) <= np.minimum(1e-3 * tol, 1e-10 * chord))
    return g1, circ, k


def _segments(curve: ParametricCurve, a: float, b: float, wrap: bool) -> list:
    """``[(piece, lo, hi), ...]`` from parameter ``a`` forward to ``b`` (across the period when ``wrap``)."""
    bp = curve.breakpoints
    n = bp.size - 1
    p = int(piece_index(curve, np.array([a]))[0])
    out, lo, laps = [], a, 0
    for _ in range(2 * n + 2):
        if laps == int(wrap) and b <= bp[p + 1] and not (laps == 0 and b < lo):
            out.append((p, lo, b))
            break
        out.append((p, lo, float(bp[p + 1])))
        p += 1
        if p == n:
            p, laps = 0, laps + 1
        lo = float(bp[p])
    return [sg for sg in out if sg[2] > sg[1]]


def _anchors(curve: ParametricCurve, sur: HermiteSurrogate, tol: float, anchored: bool) -> tuple[dict, dict]:
    """``(anchors, exact)``: ``anchors[t] = [k of the arc ending at t, k of the arc leaving it, corner]``
    at the corners and at the ends of circular pieces, ``exact[piece]`` the exact arcs of a circular
    piece; every breakpoint is a plain anchor when there is none (or ``anchored`` is false)."""
    bp = curve.breakpoints
    n = bp.size - 1
    g1, circ, _ = _circle_pieces(curve, sur, tol)
    anchors: dict = {}
    exact = {}
    if anchored and n > 1:
        for p in range(n):
            if not g1[p]:
                anchors[float(bp[p])] = [None, None, True]
        for p in np.flatnonzero(circ).tolist():
            arcs_p = _exact_arcs(curve, sur, int(p))
            if arcs_p is None:
                continue
            exact[int(p)] = arcs_p
            a0 = anchors.setdefault(float(bp[p]), [None, None, False])
            a1 = anchors.setdefault(float(bp[p + 1]) % curve.period, [None, None, False])
            if g1[p]:
                a0[0] = float(arcs_p[2][0])
            if g1[(p + 1) % n]:
                a1[1] = float(arcs_p[2][-1])
    if not anchors:  # (every breakpoint a span end; a corner stays one)
        anchors = {float(bp[p]): [None, None, not bool(g1[p])] for p in range(n)}
    return anchors, exact


def _split_stretch(sur: HermiteSurrogate, segs: list, target: float, shape: tuple | None = None
                   ) -> tuple[list, tuple | None]:
    """A stretch ``segs`` cut into equal shares of about :data:`SPLINE_SPAN` arcs (never on a junction):
    the ``[(piece, lo, hi), ...]`` of every share, and the stretch's :func:`span_shape` (``shape``, when already
    made) when it is one share."""
    shape = span_shape(sur, segs) if shape is None else shape
    t, s0, density, piece = span_density(sur, segs, target, shape=shape)
    cum = cumtrapz(density, s0)
    m = max(1, math.ceil(1.08 * float(cum[-1]) / SPLINE_SPAN))
    if m == 1:
        return [segs], shape
    goal = cum[-1] * np.arange(1, m) / m
    j = np.clip(np.searchsorted(cum, goal) - 1, 0, cum.size - 2)
    j = np.where(piece[j] == piece[j + 1], j, j + 1)
    j = np.clip(j, 0, cum.size - 2)
    frac = np.clip((goal - cum[j]) / np.maximum(cum[j + 1] - cum[j], 1e-300), 0.0, 1.0)
    cut_t, cut_p = t[j] + frac * (t[j + 1] - t[j]), piece[j]
    pieces_segs, cur, ci = [], [], 0
    for seg in segs:
        lo = seg[1]
        while ci < cut_t.size and cut_p[ci] == seg[0] and lo < cut_t[ci] < seg[2]:
            cur.append((seg[0], lo, float(cut_t[ci])))
            pieces_segs.append(cur)
            cur, lo, ci = [], float(cut_t[ci]), ci + 1
        cur.append((seg[0], lo, seg[2]))
    pieces_segs.append(cur)
    return pieces_segs, None


def _stretches(curve: ParametricCurve, anchors: dict, exact: dict) -> list:
    """``(segs, fixed, label, exact arcs)`` of every stretch between consecutive anchors, in chain order (from the
    first corner when there is one): a circular piece's exact arcs, or the curvatures its ends keep (``fixed``)."""
    bp = curve.breakpoints
    ts = sorted(anchors)
    corners = [i for i, t in enumerate(ts) if anchors[t][2]]
    if corners:
        ts = ts[corners[0]:] + ts[:corners[0]]
    out, label = [], -1
    for i, a in enumerate(ts):
        b = ts[(i + 1) % len(ts)]
        if anchors[a][2] or label < 0:
            label += 1
        segs = _segments(curve, a, b, wrap=len(ts) == 1 or b <= a)
        if len(segs) == 1 and segs[0][0] in exact and segs[0][1] == bp[segs[0][0]]:
            out.append((segs, (None, None), label, exact[segs[0][0]]))
        elif segs:
            out.append((segs, (anchors[a][1], anchors[b][0]), label, None))
    return out


def cut_spans(curve: ParametricCurve, sur: HermiteSurrogate, target: float, tol: float,
              anchored: bool = True) -> list:
    """The free spans (:class:`Span`) in chain order.

    Spans run between *anchors*: true corners (kept as vertices) and the middles of circular
    pieces (dwells) between G1 junctions, so arcs run across the G1 breakpoints in between.
    Without anchors (or with ``anchored`` false) every breakpoint is a span end.  Long stretches
    are cut into equal shares of about :data:`SPLINE_SPAN` arcs, joined G1 at (surrogate) curve
    points with the curve's tangent.  Spans between two corners share a label (their arcs may merge).
    """
    stretches = _stretches(curve, *_anchors(curve, sur, tol, anchored))
    # the shapes of one-piece stretches at once when there are many (a knot table's hundreds of pieces)
    single = [k for k, st in enumerate(stretches) if st[3] is None and len(st[0]) == 1]
    shapes = dict(zip(single, single_piece_shapes(sur, [stretches[k][0][0] for k in single]), strict=True)) \
        if len(single) >= _BATCH_SHAPES else {}
    out = []
    for k, (segs, fixed, lab, arcs_exact) in enumerate(stretches):
        if arcs_exact is not None:
            out.append(Span(segs, fixed, arcs_exact, lab))
            continue
        shares, shape = _split_stretch(sur, segs, target, shapes.get(k))
        for q, sg in enumerate(shares):
            f = (fixed[0] if q == 0 else None, fixed[1] if q == len(shares) - 1 else None)
            out.append(Span(sg, f, None, lab, shape))
    return out


def span_ends(sur: HermiteSurrogate, span: Span):
    """Points and unit tangents at both ends of a span: the exact samples at breakpoints."""
    ends = []
    for piece, t in ((span.segs[0][0], span.segs[0][1]), (span.segs[-1][0], span.segs[-1][2])):
        pt = None
        for i in (sur.first[piece], sur.first[piece + 1]):
            if t == sur.x[i]:
                pt = sur.points[i]  # (a closed curve's last sample is its first, bit for bit)
        if pt is None:
            pt = sur.point(np.array([t]), piece)[0]
        ends.append((pt, unit(sur.derivative(np.array([t]), piece)[0])))
    return ends[0][0], ends[0][1], ends[1][0], ends[1][1]


def _exact_arcs(curve: ParametricCurve, sur: HermiteSurrogate, p: int):
    """Exact arcs (each turning ≤ π/2) of the circular piece ``p``: ``(S, T, K, L, E)`` or None."""
    lo, hi = float(curve.breakpoints[p]), float(curve.breakpoints[p + 1])
    span = Span([(p, lo, hi)])
    _, _, theta = span_model(sur, span.segs, 33)
    n = max(1, math.ceil(abs(theta[-1] - theta[0]) / (0.5 * math.pi)))
    p0, t0, p1, _ = span_ends(sur, span)
    inner = points_at(curve, lo + (hi - lo) * np.arange(1, n) / n).reshape(-1, 2) if n > 1 else np.empty((0, 2))
    pts = np.concatenate([[p0], inner, [p1]])  # (a quarter turn or less: no inner point, no call of the curve)
    S, TT, K, L = [], [], [], []
    tan = t0
    for i in range(n):
        T, k, ell, ok = arc_from(pts[i], tan, pts[i + 1])
        if not ok:
            return None
        S.append(pts[i])
        TT.append(T)
        K.append(float(k))
        L.append(float(ell))
        tan = rotate(T, k * ell)
    return np.array(S), np.array(TT), np.array(K), np.array(L), pts[1:]
