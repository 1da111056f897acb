"""G1 arc splines fitted to a curve's cubic stand-in: knots and curvatures optimised per span.

The *free* (non-interpolating) arc spline that :func:`~camfab.discretize.fit.arcs` tries first.
The curve is cut into spans (:mod:`camfab.discretize.spans`); each span is clamped to the curve's
point and tangent at both ends and fitted on the Hermite surrogate
(:class:`~camfab.discretize.surrogate.HermiteSurrogate`): a linear model of the normal deviation
(:mod:`camfab.discretize.spanmodel`) gives the curvatures of given knots by a minimax (Lawson) fit,
then knots and curvatures are optimised together until the errors equioscillate, and the fewest
arcs that fit are kept.  The exact arcs are then laid out (two of them the biarc closing the span),
the chain is measured on the exact curve, and only the spans that exceed ``tol`` are refitted.
:func:`fit_spline` is the entry point.
"""
from __future__ import annotations

import logging
import math

import numpy as np

from ..geom2d import TWO_PI, cross, dot, rotate
from .certify import certified_deviation
from .chain import Chain, merge_cocircular
from .congruent import CongruentSpans
from .curve import ParametricCurve, points_at
from .entities import LINE_SWEEP_RAD, MAX_TURNING_RAD, arc_from, biarc, entity_point
from .spanbatch import two_arc_fits
from .spanmodel import SpanModel, cumtrapz, equioscillate, lawson_start
from .spans import Span, cut_spans, span_density, span_ends, span_shape
from .surrogate import HermiteSurrogate
from .tolerance import within

log = logging.getLogger(__name__)

__all__ = ["fit_spline"]


#: model samples per arc of the free arc spline
_SPLINE_SAMPLES = 16
#: the free spline's model deviation aims at this fraction of tol (less the surrogate error)
_SPLINE_FILL = 0.97
#: fewest model samples of one span
_SPLINE_MIN_GRID = 129
#: the first arc count tried is this multiple of the asymptotic estimate
_EST_FACTOR = 1.0
#: one arc fewer is tried while the predicted error (∝ 1/m³) stays below this multiple of the target (1.2 until
#: the counts had two starts: of the descents it let through above the target, 1 in 11 fitted; docs/decisions.md)
_DOWN_SLACK = 1.0
#: a span is only fitted up to this many arcs (else interpolating biarcs are used)
_SPAN_MAX_ARCS = 64
#: relative lengths of the two end arcs at each clamped end of a piece (an LP over C¹ patterns:
#: a clamped end then costs about half an arc instead of tripling the error of uniform arcs)
_END_ARCS = (0.6, 1.0)
#: further end-arc ratios tried at the smallest failing arc count (the optimum is not monotone in it)
_END_ARCS_ALT = ((0.7, 1.1),)
#: refits of the spans where the measured chain exceeds tol
_SPAN_REFITS = 4
#: relative lengths of the two end arcs at an end whose arc curvature is fixed (next to a dwell: the
#: arc matches the curve to second order there, so it is kept shorter)
_FIXED_END_ARCS = (0.35, 0.9)
#: further fixed-end ratios tried at the smallest failing count (none: they rarely paid for their time)
_FIXED_END_ARCS_ALT: tuple = ()
#: a span with a fixed end curvature whose first count (the asymptotic estimate, usually within a few % of the
#: count that fits) misses its target more than this many times over is refitted with free end curvatures: the
#: curvature jumps at its dwell (an SHM rise of a flat follower), no count would fit, and the search used to try a
#: dozen counts per span before the whole spline fell back to spans clamped at every breakpoint.  Fits that do
#: converge start at most 16× over (the examples at 1e-2…1e-4 mm), the hopeless ones at 80–1700×.
_FIXED_HOPELESS = 40.0
#: the smallest failing count, when it missed the target by at most this factor, gets other starts after the count
#: above has fitted (:meth:`_SpanFit.retry_one_fewer`)
_NARROW = 1.3
#: a span whose curvature varies by less than this share of its largest is taken as of constant curvature (no
#: maximum to centre an arc on: the stand-in's curvature of a circle varies by ~1e-9 of it)
_FLAT_KAPPA = 1e-6
#: spans whose search starts at this many arcs or more take the arcs of a congruent span already fitted
_CONGRUENT_MIN = 4


def _place_knots(s, density, m, ends=_END_ARCS, ends_hi=None):
    """``m`` arcs equidistributing ``density``, the two end arcs at each end scaled (``ends``, ``ends_hi``)."""
    ends_hi = ends if ends_hi is None else ends_hi
    w = np.ones(m)
    if m >= 4:
        w[0], w[1] = ends[0], ends[1]
        w[-1], w[-2] = ends_hi[0], ends_hi[1]
    elif m == 3:
        w[0], w[-1] = ends[0], ends_hi[0]
    q = np.concatenate([[0.0], np.cumsum(w)]) / w.sum()
    cum = cumtrapz(density, s)
    knots = np.interp(q * cum[-1], cum, s) if cum[-1] > 0 else q * s[-1]
    knots[0], knots[-1] = 0.0, s[-1]
    return knots


class _SpanFit:
    """The arc-count search of one clamped span: a model per arc count, the errors of the counts tried."""

    def __init__(self, sur: HermiteSurrogate, span: Span, target: float):
        self.sur, self.span, self.target = sur, span, target
        if span.shape is None:
            span.shape = span_shape(sur, span.segs)
        self.shape: tuple = span.shape
        _, self.s0, self.density, _ = span_density(sur, span.segs, target, shape=span.shape)
        self.est = float(cumtrapz(self.density, self.s0)[-1])
        self.n_fixed = sum(f is not None for f in span.fixed)
        self.m_min = 2 + self.n_fixed
        self.tried: dict = {}
        self.models: dict = {}
        self.others: dict = {}  # per count: the starts not yet optimised (:meth:`_starts`)
        self.pre: dict = {}  # attempts at the placed knots computed in a batch (spanbatch), by arc count

    def first_count(self) -> int:
        """The arc count :meth:`search` tries first."""
        return max(self.m_min, math.ceil(_EST_FACTOR * self.est))

    def _model(self, m: int) -> SpanModel:
        """The span's model for ``m`` arcs (made once)."""
        if m not in self.models:
            self.models[m] = SpanModel(self.sur, self.span.segs, max(_SPLINE_MIN_GRID, _SPLINE_SAMPLES * m + 1),
                                       self.span.fixed)
        return self.models[m]

    def _placed(self, model: SpanModel, m: int, ends=_END_ARCS, fixed_ends=_FIXED_END_ARCS) -> np.ndarray:
        """``m`` arcs placed by the density on ``model``'s grid, the end-arc ratios ``ends`` at a free end and
        ``fixed_ends`` at one of fixed curvature."""
        fixed = self.span.fixed
        return _place_knots(model.s, np.interp(model.s, self.s0, self.density), m,
                            fixed_ends if fixed[0] is not None else ends, fixed_ends if fixed[1] is not None else ends)

    def attempt(self, m: int, ends=_END_ARCS, knots=None, fixed_ends=_FIXED_END_ARCS, start=None):
        """``(error, fits, (knots, k, error))`` of ``m`` arcs optimised from ``knots`` (``start``: their
        :func:`~camfab.discretize.spanmodel.lawson_start`, when made); without ``knots``, from the better of the
        count's starts (:meth:`_starts`), or from the knots placed with the end-arc ratios ``ends`` and
        ``fixed_ends`` when those are not the defaults."""
        span = self.span
        if knots is None and ends is _END_ARCS and fixed_ends is _FIXED_END_ARCS and m in self.pre:
            return self.pre.pop(m)
        model = self._model(m)
        if knots is None and ends is _END_ARCS and fixed_ends is _FIXED_END_ARCS:
            (knots, start), *self.others[m] = self._starts(model, m)
        elif knots is None:
            knots = self._placed(model, m, ends, fixed_ends)
        err, knots, k = equioscillate(model, knots, start=start)
        free = np.ones(m, bool)
        free[0] = span.fixed[0] is None
        free[-1] = span.fixed[1] is None
        ok = err <= self.target and np.all(np.abs(k * np.diff(knots))[free] < MAX_TURNING_RAD * 1.5)
        return err, ok, (knots, k, err)

    def _narrow(self, m: int, err: float) -> bool:
        """Whether ``m`` arcs (error ``err``) missed the target narrowly enough for a warm start at that count."""
        return m >= max(4, self.m_min) and err <= _NARROW * self.target

    def centred_knots(self, m: int) -> np.ndarray | None:
        """Knots of ``m`` arcs with one long arc over the span's largest curvature maximum: ``m + 1`` arcs placed by
        the density, less their interior joint (not an end arc's) nearest that maximum; None without an interior
        maximum (a curvature constant to :data:`_FLAT_KAPPA` has none) or with fewer than 4 arcs.  The density
        ``|κ'|^(1/3)`` vanishes at a curvature extremum, where the error of an arc is set by ``κ″`` instead, so the
        placed knots may put a joint next to the maximum where the optimum has an arc centred on it
        (docs/decisions.md, "Arc-fit cost")."""
        _, s, _, kappa, _ = self.shape
        inner = (kappa[1:-1] > kappa[:-2]) & (kappa[1:-1] >= kappa[2:])
        if m < 4 or not inner.any() or not kappa.max() - kappa.min() > _FLAT_KAPPA * kappa.max():
            return None  # (no maximum, or one of rounding: the curvature is constant along the span)
        at = s[1:-1][inner][np.argmax(kappa[1:-1][inner])]
        model = self._model(m)
        knots = self._placed(model, m + 1)
        j = 2 + int(np.argmin(np.abs(knots[2:-2] - at)))
        return np.delete(knots, j)

    def _starts(self, model: SpanModel, m: int) -> list:
        """The starts of ``m`` arcs in the order they are optimised, ``[(knots, lawson_start), ...]``: the knots
        placed by the density, preceded by :meth:`centred_knots` (4 arcs or more, an interior curvature maximum)
        when the minimax curvatures of those deviate less before the knots move.  A centred start that begins no
        lower than the placed knots is not optimised at all (it costs one linear fit)."""
        placed = self._placed(model, m)
        starts = [(placed, lawson_start(model, placed))]
        centred = self.centred_knots(m)
        if centred is not None:
            start = lawson_start(model, centred)
            if float(np.abs(start[4]).max()) < float(np.abs(starts[0][1][4]).max()):
                starts.insert(0, (centred, start))
        return starts

    def other_start(self, m: int):
        """The fit of ``m`` arcs from the count's second start (:meth:`_starts`: the placed knots, after the centred
        ones missed, so that every count still tries the knots it used to) when it fits (once), else None."""
        others = self.others.pop(m, [])
        for knots, start in others:
            _, ok, fit = self.attempt(m, knots=knots, start=start)
            if ok:
                return fit
        return None

    def search(self):
        """The fewest arcs that fit from the count search, or None (no fit, or more than the span allows)."""
        m = self.first_count()
        best = None
        for _ in range(12):
            if m in self.tried:
                break
            if m > _SPAN_MAX_ARCS:
                return None
            err, ok, fit = self.attempt(m)
            self.tried[m] = err
            if not ok:
                other = self.other_start(m)
                if other is not None:
                    err, ok, fit = other[2], True, other
                    self.tried[m] = err
            if self.n_fixed and len(self.tried) == 1 and not (err <= _FIXED_HOPELESS * self.target):
                return None  # the fixed end curvature does not fit the curve (see _FIXED_HOPELESS)
            if ok and (best is None or m < best[0].size - 1):
                best = fit
            nxt = self._next_count(m, err, ok, best)
            if nxt is None:
                break
            m = nxt
        return best

    def _next_count(self, m: int, err: float, ok: bool, best) -> int | None:
        """The next arc count to try after ``m`` arcs (error ``err``), or None to stop."""
        if ok:
            # one arc fewer raises the error by about (m / (m - 1))³: not worth trying beyond the target
            if (m - 1) in self.tried or m <= self.m_min or err * (m / (m - 1)) ** 3 > _DOWN_SLACK * self.target:
                return None
            return m - 1
        if best is not None and best[0].size - 1 == m + 1:
            return None
        jump = math.ceil(m * (err / self.target) ** (1.0 / 3.0)) - m  # (a single count may fail badly)
        return m + 1 if err < 1.6 * self.target else m + max(1, min(jump, math.ceil(0.1 * m) + 1))

    def retry_one_fewer(self, best):
        """``best``, or a fit with one arc fewer when that count failed narrowly: a warm start from the
        optimised knots of ``best`` less the joint of the smallest curvature jump (not an end arc), then
        other end-arc ratios."""
        m = best[0].size - 2
        if not (m in self.tried and self._narrow(m, self.tried[m])):
            return best
        kb, kk = best[0], best[1]
        jump = np.abs(np.diff(kk))[1:-1]
        if jump.size:
            j = 2 + int(np.argmin(jump))
            _, ok, fit = self.attempt(m, knots=np.delete(kb, j))
            if ok:
                return fit
        alts = [(ends, _FIXED_END_ARCS) for ends in _END_ARCS_ALT] if self.n_fixed < 2 else []
        alts += [(_END_ARCS, fe) for fe in _FIXED_END_ARCS_ALT] if self.n_fixed else []
        for ends, fixed_ends in alts:
            _, ok, fit = self.attempt(m, ends, fixed_ends=fixed_ends)
            if ok:
                return fit
        return best


def _fit_span(sur: HermiteSurrogate, span: Span, target: float, fit: _SpanFit | None = None):
    """Fewest arcs (model) for a clamped span: ``(knots, k, error, fixed)`` or None.

    The arc count starts from the asymptotic estimate ``∫ (|κ'| / (124.7·target))^(1/3) ds``;
    every count gets knots equidistributing that density (end arcs shortened at clamped ends),
    then knots and curvatures are optimised together (:func:`equioscillate`);
    the count goes down while the span still fits ``target`` (one arc fewer when its predicted error does) and up
    until it does.  A count starts from knots with one long arc over the curvature maximum
    (:meth:`_SpanFit.centred_knots`) when their linear fit deviates less than that of the placed knots, which
    follow when it misses.  The optimum is not monotone in the count: at the smallest failing count a
    warm start and other end-arc ratios (:data:`_END_ARCS_ALT`) are tried when it failed narrowly.
    A span with a fixed end curvature that misses by far at its first count (:data:`_FIXED_HOPELESS`) is fitted
    again with free end curvatures (``fixed`` returned: the curvatures the fit imposes).  ``fit``: the span's
    search when already made (:func:`_fit_span_chains`).
    """
    fit = _SpanFit(sur, span, target) if fit is None else fit
    best = fit.search()
    if best is None and fit.n_fixed and len(fit.tried) == 1:
        log.info("arcs: span %s cannot keep its neighbour's end curvature (misses by more than %gx at its first "
                 "arc count); fitted with free end curvatures", span.label, _FIXED_HOPELESS)
        free = Span(span.segs, (None, None), span.exact, span.label, span.shape)
        fit = _SpanFit(sur, free, target)
        best = fit.search()
    return None if best is None else fit.retry_one_fewer(best) + (fit.span.fixed,)


def _tanlen(kk, ll):
    x = 0.5 * kk * ll
    return ll / 2 if abs(x) < 1e-12 else math.tan(x) / kk


def _sinc_factors(k: np.ndarray, u: np.ndarray) -> tuple[list, list]:
    """The two ``np.sinc`` factors :func:`~camfab.discretize.entities.entity_point` takes for entities of curvature
    ``k`` and length ``u``, all in two calls (as floats: the arcs of a span are laid one after another)."""
    ku = k * u
    return np.sinc(ku / math.pi).tolist(), np.sinc(ku / TWO_PI).tolist()


def _end_of(sx: float, sy: float, tx: float, ty: float, k: float, u: float, f1: float, f2: float) -> tuple:
    """:func:`~camfab.discretize.entities.entity_point` at ``u`` of the entity from ``(sx, sy)`` along ``(tx, ty)``
    (curvature ``k``) on floats, operation for operation (``f1``, ``f2``: its :func:`_sinc_factors`; a float's
    ``** 2`` is the C library's ``pow``, as a numpy scalar's): the same point bit for bit, without a dozen small
    arrays per arc."""
    x = u * f1
    y = 0.5 * k * u * u * f2 ** 2
    return sx + x * tx + y * -ty, sy + x * ty + y * tx


def _lay_backward(p1, t1, k, ell, j: int):
    """Arcs ``j + 2 … m - 1`` laid backward from ``p1`` (tangent ``t1``): their starts and start tangents,
    and the point and tangent angle where the closing biarc must end."""
    b_starts: list[np.ndarray] = []
    b_tans: list[np.ndarray] = []
    end_p, end_ang = p1, math.atan2(t1[1], t1[0])
    idx = np.arange(ell.size - 1, j + 1, -1)
    if not idx.size:
        return b_starts, b_tans, end_p, end_ang
    k_back = -k[idx]  # (laid along the reversed tangent: the curvature negated)
    kb, lb = k_back.tolist(), ell[idx].tolist()
    f1, f2 = _sinc_factors(k_back, ell[idx])
    px, py = float(end_p[0]), float(end_p[1])
    for n, i in enumerate(idx.tolist()):
        ang_s = end_ang - k[i] * ell[i]
        c, sn = math.cos(end_ang), math.sin(end_ang)
        px, py = _end_of(px, py, -c, -sn, kb[n], lb[n], f1[n], f2[n])
        b_starts.insert(0, np.array([px, py]))
        b_tans.insert(0, np.array([math.cos(ang_s), math.sin(ang_s)]))
        end_ang = ang_s
    return b_starts, b_tans, b_starts[0], end_ang


def _cut_long_arcs(S, TT, K, L):
    """Starts and tangents of the arcs ``(S, TT, K, L)`` with every arc turning more than π/2 cut into
    equal parts (fixed dwell arcs)."""
    parts = np.maximum(1, np.ceil(np.abs(K * L) / (0.5 * math.pi))).astype(int)
    if parts.max() == 1:
        return S, TT
    idx = np.repeat(np.arange(K.size), parts)
    sub = np.arange(idx.size) - np.repeat(np.cumsum(parts) - parts, parts)
    u = L[idx] * sub / parts[idx]
    return entity_point(S[idx], TT[idx], K[idx], u), rotate(TT[idx], K[idx] * u)


def _span_chain(p0, t0, p1, t1, knots, k, fixed=(None, None)):
    """Exact G1 arcs of a span from ``(p0, t0)`` to ``(p1, t1)``: the planned arcs, closed by a biarc.

    The arcs before the closing biarc are laid forward from ``p0``; with a fixed last curvature the
    last arc is laid backward from ``p1`` (the biarc closes the arcs before it).  Arcs turning more
    than π/2 are cut into equal parts (co-circular parts merge again later)."""
    ell = np.diff(knots)
    k = np.array(k, dtype=float)
    if fixed[0] is not None:
        k[0] = fixed[0]
    if fixed[1] is not None:
        k[-1] = fixed[1]
    m = ell.size
    j = m - 3 if fixed[1] is not None else m - 2  # the closing biarc is arcs j, j + 1
    if j < (1 if fixed[0] is not None else 0):
        return None
    starts, tans, ks, ls = [p0], [t0], [], []
    base = math.atan2(t0[1], t0[0])
    ang = base + np.concatenate([[0.0], np.cumsum(k * ell)])
    f1, f2 = _sinc_factors(k[:j], ell[:j])
    kf, lf = k[:j].tolist(), ell[:j].tolist()
    px, py, tx, ty = float(p0[0]), float(p0[1]), float(t0[0]), float(t0[1])
    for i in range(j):
        px, py = _end_of(px, py, tx, ty, kf[i], lf[i], f1[i], f2[i])
        tx, ty = math.cos(ang[i + 1]), math.sin(ang[i + 1])
        ks.append(k[i])
        ls.append(ell[i])
        starts.append(np.array([px, py]))
        tans.append(np.array([tx, ty]))
    b_starts, b_tans, end_p, end_ang = _lay_backward(p1, t1, k, ell, j)
    d1, d2 = _tanlen(k[j], ell[j]), _tanlen(k[j + 1], ell[j + 1])
    ratio = d1 / d2 if d1 > 0 and d2 > 0 else 1.0
    tgt_t = np.array([math.cos(end_ang), math.sin(end_ang)])
    bi = biarc(starts[-1][None], tans[-1][None], end_p[None], tgt_t[None], np.array([ratio]))
    if not bi["valid"][0]:
        bi = biarc(starts[-1][None], tans[-1][None], end_p[None], tgt_t[None], np.array([1.0]))
        if not bi["valid"][0]:
            return None
    S = np.concatenate([np.array(starts[:j]).reshape(-1, 2), bi["s"][0], np.array(b_starts).reshape(-1, 2)])
    TT = np.concatenate([np.array(tans[:j]).reshape(-1, 2), bi["T"][0], np.array(b_tans).reshape(-1, 2)])
    K = np.concatenate([np.array(ks), bi["k"][0], k[j + 2:]])
    L = np.concatenate([np.array(ls), bi["ell"][0], ell[j + 2:]])
    S, TT = _cut_long_arcs(S, TT, K, L)
    # make every arc consistent with both its end points (ends[i] == starts[i + 1] exactly)
    S_next = np.concatenate([S[1:], [p1]])
    TT2, K2, L2, ok = arc_from(S, TT, S_next)
    if not ok.all():
        return None
    return S, TT2, K2, L2, S_next


def _fit_span_chain(curve: ParametricCurve, sur: HermiteSurrogate, span: Span, target: float,
                    search: _SpanFit | None = None):
    """The exact G1 arcs of one span fitted to ``target`` and the model error, or None."""
    if span.exact is not None:
        return span.exact, 0.0
    fit = _fit_span(sur, span, target, search)
    if fit is None:
        return None
    knots, k, err, fixed = fit
    p0, t0, p1, t1 = span_ends(sur, span)
    chain = _span_chain(p0, t0, p1, t1, knots, k, fixed)
    return None if chain is None else (chain, err)


def _fit_span_chains(curve: ParametricCurve, sur: HermiteSurrogate, spans: list, target: float) -> tuple[list, list]:
    """:func:`_fit_span_chain` of every span, and which spans took a congruent span's arcs (:func:`_fit_spans`).

    The first attempt of the free single-piece spans whose search starts at two arcs is made in one batch
    (:func:`~camfab.discretize.spanbatch.two_arc_fits`): the same arcs."""
    searches = [None if sp.exact is not None else _SpanFit(sur, sp, target) for sp in spans]
    two = [f for f in searches if f is not None and f.n_fixed == 0 and len(f.span.segs) == 1 and f.first_count() == 2]
    for i, res in two_arc_fits(sur, two, target, _place_knots).items():
        two[i].pre[2] = res
    fits, carried = _fit_spans(sur, spans, target, searches)
    return _span_chains(sur, spans, fits), carried


def _fit_spans(sur: HermiteSurrogate, spans: list, target: float, searches: list) -> tuple[list, list]:
    """:func:`_fit_span` of every span (None: exact or failed) and whether it was carried over from a congruent
    span (:class:`~camfab.discretize.congruent.CongruentSpans`, spans of :data:`_CONGRUENT_MIN` arcs or more:
    the search of the smaller ones costs less than the comparison)."""
    same = CongruentSpans(sur)
    fits, carried = [], []
    for sp, f in zip(spans, searches, strict=True):
        fit = sig = None
        if f is not None:
            sig = same.signature(sp) if f.first_count() >= _CONGRUENT_MIN else None
            fit = None if sig is None else same.find(sig, sp)
        carried.append(fit is not None)
        if f is not None and fit is None:
            fit = _fit_span(sur, sp, target, f)
            if sig is not None and fit is not None:
                same.add(sig, sp, fit)
        fits.append(fit)
    return fits, carried


def _span_chains(sur: HermiteSurrogate, spans: list, fits: list) -> list:
    """The exact arcs and model error of every span (``fits``: each span's :func:`_fit_span`, None for an exact
    span or a failed fit), the two-arc spans' biarcs laid in one call (:func:`_two_arc_chains`)."""
    out = [(sp.exact, 0.0) if sp.exact is not None else None for sp in spans]
    two_arc = [i for i, f in enumerate(fits) if f is not None and f[0].size == 3 and f[3] == (None, None)]
    if not two_arc:
        return _other_chains(sur, spans, fits, out)
    ends = [span_ends(sur, spans[i]) for i in two_arc]
    for i, chain in zip(two_arc, _two_arc_chains(ends, [fits[i][1] for i in two_arc],
                                                  [fits[i][0] for i in two_arc]), strict=True):
        out[i] = None if chain is None else (chain, fits[i][2])
    return _other_chains(sur, spans, fits, out, set(two_arc))


def _other_chains(sur: HermiteSurrogate, spans: list, fits: list, out: list, done: set | None = None) -> list:
    """``out`` with the exact arcs of every fitted span not in ``done`` laid one by one (:func:`_span_chain`)."""
    for i, f in enumerate(fits):
        if f is not None and out[i] is None and i not in (done or ()):
            knots, k, err, fixed = f
            p0, t0, p1, t1 = span_ends(sur, spans[i])
            chain = _span_chain(p0, t0, p1, t1, knots, k, fixed)
            out[i] = None if chain is None else (chain, err)
    return out


def _two_arc_chains(ends: list, ks: list, knots: list) -> list:
    """:func:`_span_chain` of two-arc spans with free end curvatures (the closing biarc alone), their biarcs
    laid in one call; a span whose biarc needs the fallback ratio (or cutting) takes the per-span path."""
    ratio = np.empty(len(ends))
    tgt = np.empty((len(ends), 2))
    for i, ((_, _, _, t1), k, x) in enumerate(zip(ends, ks, knots, strict=True)):
        ell = np.diff(x)
        d1, d2 = _tanlen(k[0], ell[0]), _tanlen(k[1], ell[1])
        ratio[i] = d1 / d2 if d1 > 0 and d2 > 0 else 1.0
        end_ang = math.atan2(t1[1], t1[0])
        tgt[i] = math.cos(end_ang), math.sin(end_ang)
    p0, t0, p1 = (np.array([e[j] for e in ends]) for j in range(3))
    bi = biarc(p0, t0, p1, tgt, ratio)
    s_next = np.stack([bi["s"][:, 1], p1], axis=1)
    tt2, k2, l2, ok = arc_from(bi["s"], bi["T"], s_next)
    # (no arc to cut: the test of _cut_long_arcs)
    simple = bi["valid"] & ok.all(axis=1) & (np.ceil(np.abs(bi["k"] * bi["ell"]) / (0.5 * math.pi)) <= 1).all(axis=1)
    return [(bi["s"][i], tt2[i], k2[i], l2[i], s_next[i]) if simple[i]
            else _span_chain(ends[i][0], ends[i][1], ends[i][2], ends[i][3], knots[i], ks[i])
            for i in range(len(ends))]


def _merge_wrap(chain: Chain, labels: np.ndarray) -> tuple[Chain, np.ndarray]:
    """Roll the chain by one entity when its last and first entities lie on one circle (G1 joint)."""
    if chain.n < 2 or labels[0] != labels[-1]:
        return chain, labels
    k, ell = chain.curvature, chain.length
    tj = chain.end_tangent[-1]
    g1 = abs(math.atan2(cross(tj, chain.tangent[0]), dot(tj, chain.tangent[0]))) < 1e-12
    if not (g1 and abs(k[0] - k[-1]) * (ell[0] + ell[-1]) <= LINE_SWEEP_RAD):
        return chain, labels
    roll = lambda a: np.roll(a, 1, axis=0)  # noqa: E731
    return Chain(*(roll(a) for a in (chain.start, chain.tangent, chain.curvature, chain.length, chain.end))), \
        roll(labels)


def _span_deviations(curve: ParametricCurve, spans: list, parts: list, merged: Chain, dev) -> np.ndarray:
    """The measured deviation of every span: the largest distance from its exact curve samples (16 per
    arc) to the chain, and the measured maximum ``dev`` for the span holding it."""
    counts = [c[0].shape[0] for c in parts]
    t = [sp.sample(16 * n) for sp, n in zip(spans, counts, strict=True)]
    d, _ = merged.distance(points_at(curve, np.concatenate(t)))
    worst = np.maximum.reduceat(d, np.concatenate([[0], np.cumsum([x.size for x in t])[:-1]]))
    at = float(dev.at_param)
    for j in (i for i, sp in enumerate(spans) if sp.contains(at)):  # (both spans of a joint it lies on)
        worst[j] = max(worst[j], dev.max)
    return worst


def fit_spline(curve: ParametricCurve, surrogate: tuple[HermiteSurrogate, float], tol: float,
               anchored: bool = True) -> tuple[Chain, float, np.ndarray] | None:
    """The free arc spline within ``tol`` (measured on the exact curve) and its span-end parameters, or None.

    Spans are independent (their ends are fixed points with fixed tangents), so
    when the measured chain exceeds ``tol`` only the offending spans are refitted (the one holding
    the worst deviation and every span whose exact curve samples lie farther than ``tol`` from the
    chain), each to a target lowered by its measured / model error ratio.
    """
    sur, sur_err = surrogate
    target = _SPLINE_FILL * tol - sur_err
    if not (target > 0):
        return None
    spans = cut_spans(curve, sur, target, tol, anchored)
    targets = [target] * len(spans)
    with np.errstate(invalid="ignore", divide="ignore"):
        fits, carried = _fit_span_chains(curve, sur, spans, target)
    if any(f is None for f in fits):
        return None
    parts, errs = [f[0] for f in fits], [f[1] for f in fits]
    params = np.unique(np.append([sp.segs[0][1] for sp in spans], curve.period))
    for _ in range(_SPAN_REFITS + 1):
        cat = [np.concatenate([c[i] for c in parts]) for i in range(5)]
        labels = np.concatenate([np.full(c[0].shape[0], spans[j].label) for j, c in enumerate(parts)])
        chain = Chain(*cat)
        if curve.closed:
            chain, labels = _merge_wrap(chain, labels)
        merged = merge_cocircular(chain, labels)
        dev = certified_deviation(merged, curve, sur, tol, expected=max(errs))
        if within(dev.max, tol):
            return merged, dev.max, params
        worst = _span_deviations(curve, spans, parts, merged, dev)
        refitted = False
        for j in np.flatnonzero(worst > 0.99 * tol):
            if spans[j].exact is not None:
                return None
            if carried[j]:  # a congruent span's arcs: fitted on its own first
                carried[j] = False
            else:  # the measured / model ratio of this span scales its next target
                lower = min(0.98 * targets[j], 0.97 * tol * errs[j] / worst[j])
                if not lower > 0:  # no model error (a straight piece's line): a lower target cannot help it
                    continue
                targets[j] = lower
            with np.errstate(invalid="ignore", divide="ignore"):
                fit = _fit_span_chain(curve, sur, spans[j], targets[j])
            if fit is None:
                return None
            parts[j], errs[j] = fit
            refitted = True
        if not refitted:
            return None
    return None
