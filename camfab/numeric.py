"""Vectorised one-dimensional searches between breakpoints: global extrema, the ranges where a
function is positive, roots and integrals (:mod:`camfab.quadrature`) — one implementation of each; nothing here
knows cams.

A searched function is a vectorised ``f(x)``, smooth between breakpoints ``edges`` (increasing; for
a closed curve the first and last are the ends of one period).  A search samples every interval
densely (:func:`dense_grid`), then refines what the samples show by safeguarded bracketing, every
open problem at once: one call of ``f`` per round, because evaluating a curve costs mostly per call,
not per point.  ``f`` may give several rows ((k, n) values), searched together, and its values on
the dense grid may be given (``values=``), so that several searches share one dense sample.  A
problem's trial points depend only on its batch: a search gives the same result alone or with others.
"""
from __future__ import annotations

import logging
import math
from collections.abc import Callable, Sequence
from functools import cached_property, lru_cache
from typing import NamedTuple

import numpy as np

from .errors import InputError
from .quadrature import Integral, integral, integrate
from .records import dataclass

__all__ = ["Grid", "Optimum", "Range", "dense_grid", "resolution", "unresolved", "clear_caches", "search",
           "extremum", "extrema", "positive_ranges", "root", "integrate", "integral", "Integral"]

Function = Callable[[np.ndarray], np.ndarray]
log = logging.getLogger(__name__)

#: dense samples per period (the span of the edges) when no step is given
SAMPLES_PER_PERIOD = 1440
#: extrema equal to this relative difference are ties (rounding of repeated lobes): the first wins
_TIE = 1e-10
#: bracket ends within this relative difference of the best value are equal to rounding: done
_FLAT = 64 * np.finfo(float).eps
_EPS16 = 16 * np.finfo(float).eps
#: ratio of the ladder of points placed around each estimate per round (powers 1…8)
_LADDER = 0.01
_LOG_LADDER = -math.log(_LADDER)
_LADPOW, _LADIDX = _LADDER ** np.arange(1, 9), np.arange(1, 9)
_QUARTERS = np.array([0.25, 0.5, 0.75])
#: local minima of the dense sample refined per search; rounds allowed to minima and to roots
_KEEP, _MIN_ROUNDS, _ROOT_ROUNDS = 4, 60, 80
#: root brackets end below ``_XTOL + _RTOL·|x|`` (brentq's test)
_XTOL, _RTOL = 1e-14, 1e-15
_EMPTY = np.zeros(0, dtype=np.intp)


class Optimum(NamedTuple):
    """Where an extremum is (``at``, parameter units) and its value."""

    at: float
    value: float


class Range(NamedTuple):
    """A range ``[start, end]`` where a function is positive (``start > end``: it wraps through the
    period end of a closed curve), and where in it the function is largest, with that value."""

    start: float
    end: float
    at_worst: float
    worst: float


@dataclass(frozen=True, eq=False)
class Grid:
    """Dense samples of every breakpoint interval, concatenated: ``x`` (m,), the index of each
    interval's first sample ``starts`` (k,), each interval's first and last sample ``lo``, ``hi`` (k,;
    the breakpoints pulled in by :func:`dense_grid`'s margins: one-sided limits), the spacing ``step``."""

    x: np.ndarray
    starts: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    step: float

    @cached_property
    def sizes(self) -> np.ndarray:
        """(k,) int: samples per interval."""
        return np.diff(np.append(self.starts, self.x.size))


RESOLUTION_ULPS = 2**16  #: narrower intervals (in ulps of the edges) have margins < 64 ulps: :func:`unresolved`


def resolution(edges) -> float:
    """The narrowest interval between ``edges`` that a search resolves: :data:`RESOLUTION_ULPS` ulps of the
    largest |edge| (at least of 1; 5.8e-11 for a period of 2π)."""
    e = np.asarray(edges, dtype=float)
    return float(RESOLUTION_ULPS * np.spacing(max(abs(float(e[0])), abs(float(e[-1])), 1.0)))


def unresolved(edges) -> np.ndarray:
    """Indices of the intervals narrower than :func:`resolution`: left out of every search (refuse them)."""
    e = np.asarray(edges, dtype=float)
    return np.flatnonzero(np.diff(e) < resolution(e))


def dense_grid(edges, step: float | None = None) -> Grid:
    """The dense sample of the intervals between ``edges`` (memoised, read-only): each interval gets
    ``max(8, ⌈width/step⌉) + 1`` samples from ``a + m`` to ``b − m``, the one-sided margin m = 1e-11·max(period, 1)
    or 2⁻¹⁰ of a narrower interval; ``step`` defaults to (edges[-1] − edges[0]) / 1440.  The :func:`unresolved`
    intervals are left out."""
    e = np.asarray(edges, dtype=float)
    return _grid(e.tobytes(), float(step or (e[-1] - e[0]) / SAMPLES_PER_PERIOD))


@lru_cache(maxsize=256)
def _grid(key: bytes, step: float) -> Grid:
    edges = np.frombuffer(key, dtype=float)
    keep, margin = np.diff(edges) >= resolution(edges), np.minimum(1e-11 * max(edges[-1] - edges[0], 1.0),
                                                                   np.diff(edges) / 1024)
    parts, lo, hi = [], [], []
    for a, b, m in zip(edges[:-1][keep], edges[1:][keep], margin[keep], strict=True):
        parts.append(np.linspace(a + m, b - m, max(8, int(math.ceil((b - a) / step))) + 1))
        lo.append(a + m)
        hi.append(b - m)
    sizes = np.array([p.size for p in parts], dtype=np.intp)
    out = Grid(np.concatenate(parts) if parts else np.empty(0), np.r_[0, np.cumsum(sizes)[:-1]].astype(np.intp)
               if parts else _EMPTY, np.array(lo), np.array(hi), step)
    for arr in (out.x, out.starts, out.lo, out.hi):
        arr.setflags(write=False)
    return out


def clear_caches() -> None:
    """Forget the memoised dense grids (to time a search from cold)."""
    _grid.cache_clear()


# ---------------------------------------------------------------------------
# the bracketing engine: minima and roots of rows of f, refined together
class _Minima:
    """k minimisation problems of ``sign·f[row]`` (NaN counts as +inf): bracket [a, b] around its best
    sample x and the values there, tolerance, batch; from tuples (a, fa, x, fx, b, fb, tol, batch,
    row, sign) of arrays."""

    def __init__(self, parts: list[tuple]):
        c = [np.concatenate([np.asarray(p[q]) for p in parts]) for q in range(10)]
        self.a, self.fa, self.x, self.fx, self.b, self.fb, self.tol = (v.astype(float) for v in c[:7])
        self.batch, self.row, self.sign = c[7].astype(np.intp), c[8].astype(np.intp), c[9].astype(float)


class _Roots:
    """k root problems: ``f[row] > 0`` differs at a and b (NaN counts as not positive); from tuples
    (a, fa, b, fb, batch, row) of arrays.  ``a0``, ``b0``: the brackets as given."""

    def __init__(self, parts: list[tuple]):
        c = [np.concatenate([np.asarray(p[q]) for p in parts]) for q in range(6)]
        self.a, self.fa, self.b, self.fb = (v.astype(float) for v in c[:4])
        self.batch, self.row = c[4].astype(np.intp), c[5].astype(np.intp)
        self.a0, self.b0 = self.a.copy(), self.b.copy()

    def best(self) -> np.ndarray:
        """The bracket end with the smaller |f| (a on ties)."""
        with np.errstate(invalid="ignore"):
            return np.where(~(np.abs(self.fb) < np.abs(self.fa)), self.a, self.b)


def _clean(y) -> np.ndarray:
    """Values to minimise: NaN → +inf."""
    y = np.asarray(y, dtype=float)
    return np.where(np.isnan(y), np.inf, y)


def _refine_tol(lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """Bracket width at which a minimum is located well enough (1e-9 of its first bracket)."""
    return np.maximum(1e-9 * (hi - lo), _EPS16 * np.maximum(1.0, np.abs(hi)))


def _ladder_length(ratio: float) -> int:
    """Ladder steps J (1…8) that reach from a bracket down to its tolerance (ratio width/tol)."""
    return min(max(math.ceil(math.log(max(ratio, 1.0)) / _LOG_LADDER), 1), 8)


def _trials(u, a, b, tol, batch) -> np.ndarray:
    """(n, 2J + 4) trial points of a round: the estimate u, the ladder u ± w·r^j (w = b − a, j = 1…J)
    and the quarter points of [a, b], clipped to [a, b].  J covers the largest w/tol of the row's
    batch; a row of a batch with a shorter ladder repeats u instead (never its own neighbour)."""
    w = b - a
    ratio = w / np.maximum(tol, 1e-300)
    if batch[0] == batch[-1] and (batch == batch[0]).all():  # one batch (the common case)
        J = np.full(batch.size, _ladder_length(float(ratio.max())), dtype=np.intp)
    else:
        rmax = np.full(int(batch.max()) + 1, -np.inf)
        np.maximum.at(rmax, batch, ratio)
        J = np.array([_ladder_length(r) for r in rmax.tolist()], dtype=np.intp)[batch]
    jm = int(J.max())
    steps = w[:, None] * _LADPOW[None, :jm]
    if int(J.min()) < jm:
        steps[_LADIDX[None, :jm] > J[:, None]] = 0.0
    uc = u[:, None]
    pts = np.concatenate([uc, uc - steps, uc + steps, a[:, None] + w[:, None] * _QUARTERS[None, :]], axis=1)
    np.maximum(pts, a[:, None], out=pts)
    return np.minimum(pts, b[:, None], out=pts)


def _neighbours(P: np.ndarray, F: np.ndarray, j: np.ndarray):
    """For sample rows P (positions) / F (values) and the chosen column j of each row: the nearest
    sample on each side (position, value), or the chosen sample itself where there is none."""
    r = np.arange(len(P))
    xj, fj = P[r, j], F[r, j]
    li = np.argmax(np.where(xj[:, None] > P, P, -np.inf), axis=1)  # positions are finite
    ri = np.argmin(np.where(xj[:, None] < P, P, np.inf), axis=1)
    pl, pr = P[r, li], P[r, ri]
    hl, hr = pl < xj, pr > xj
    return (np.where(hl, pl, xj), np.where(hl, F[r, li], fj), xj, fj,
            np.where(hr, pr, xj), np.where(hr, F[r, ri], fj))


def _min_step(m: _Minima, act: np.ndarray, pts: np.ndarray, y: np.ndarray, done: np.ndarray) -> None:
    """Shrink each open bracket to the neighbours of its best sample; done when narrow, or when its
    ends differ from the best by rounding only (the value is then exact to rounding)."""
    v = _clean(m.sign[act][:, None] * y)
    P = np.concatenate([m.x[act][:, None], m.a[act][:, None], m.b[act][:, None], pts], axis=1)
    F = np.concatenate([m.fx[act][:, None], m.fa[act][:, None], m.fb[act][:, None], v], axis=1)
    j = np.argmin(F, axis=1)  # ties keep the current best (column 0)
    m.a[act], m.fa[act], m.x[act], m.fx[act], m.b[act], m.fb[act] = _neighbours(P, F, j)
    with np.errstate(invalid="ignore"):
        flat = np.maximum(m.fa[act], m.fb[act]) - m.fx[act] <= _FLAT * np.abs(m.fx[act])
    done[act] = ~(m.b[act] - m.a[act] > m.tol[act]) | flat


def _root_step(r: _Roots, act: np.ndarray, pts: np.ndarray, y: np.ndarray) -> None:
    """Keep the first sign change from a of each open bracket."""
    P = np.concatenate([r.a[act][:, None], pts, r.b[act][:, None]], axis=1)
    F = np.concatenate([r.fa[act][:, None], y, r.fb[act][:, None]], axis=1)
    o = np.argsort(P, axis=1, kind="stable")
    P, F = np.take_along_axis(P, o, 1), np.take_along_axis(F, o, 1)
    j = np.argmax((F[:, :-1] > 0) != (F[:, 1:] > 0), axis=1)  # the ends differ, so some pair does
    k = np.arange(act.size)
    r.a[act], r.fa[act], r.b[act], r.fb[act] = P[k, j], F[k, j], P[k, j + 1], F[k, j + 1]


def _solve(f: Function, mins: _Minima | None = None, roots: _Roots | None = None) -> None:
    """Refine ``mins`` and ``roots`` in place, together: each round evaluates ``f`` once at the trial
    points of every open problem.  A minimum's estimate is the vertex of the parabola through
    (a, x, b) (x where there is none), a root's the secant (the midpoint where there is none)."""
    done = ~(mins.b - mins.a > mins.tol) if mins is not None else np.zeros(0, dtype=bool)
    base = int(mins.batch.max()) + 1 if mins is not None and mins.batch.size else 0  # root batches follow
    mround = rround = 0
    while True:
        mact = np.flatnonzero(~done) if mins is not None and mround < _MIN_ROUNDS else _EMPTY
        ract = _EMPTY
        if roots is not None and rround < _ROOT_ROUNDS:
            ract = np.flatnonzero(roots.b - roots.a >= _XTOL + _RTOL * np.maximum(abs(roots.a), abs(roots.b)))
        if mact.size + ract.size == 0:
            if mround >= _MIN_ROUNDS or rround >= _ROOT_ROUNDS:
                _log_capped(mins, done, roots)
            return
        parts = []
        with np.errstate(all="ignore"):
            if mact.size:
                A, FA, X, FX, B, FB = (getattr(mins, k)[mact] for k in ("a", "fa", "x", "fx", "b", "fb"))
                d1, d2, f1, f2 = X - A, B - X, FA - FX, FB - FX
                u = X + 0.5 * (d2 * d2 * f1 - d1 * d1 * f2) / (d2 * f1 + d1 * f2)
                u = np.where(np.isfinite(u) & (d1 > 0) & (d2 > 0), u, X)
                parts.append((u, A, B, mins.tol[mact], mins.batch[mact], mins.row[mact]))  # type: ignore
            if ract.size:
                A, FA, B, FB = roots.a[ract], roots.fa[ract], roots.b[ract], roots.fb[ract]  # type: ignore
                u = A - FA * (B - A) / (FB - FA)
                u = np.where(np.isfinite(u), u, 0.5 * (A + B))
                parts.append((u, A, B, np.full(ract.size, _XTOL), base + roots.batch[ract], roots.row[ract]))  # type: ignore
        u, a, b, tol, batch, row = (np.concatenate(t) for t in zip(*parts, strict=True))
        pts = _trials(u, a, b, tol, batch)
        V = np.asarray(f(pts.ravel()), dtype=float).reshape(-1, pts.size)
        Y = V[row[:, None], np.arange(pts.size).reshape(pts.shape)]
        if mact.size:
            _min_step(mins, mact, pts[:mact.size], Y[:mact.size], done)  # type: ignore[arg-type]
            mround += 1
        if ract.size:
            _root_step(roots, ract, pts[mact.size:], Y[mact.size:])  # type: ignore[arg-type]
            rround += 1


def _log_capped(mins: _Minima | None, done: np.ndarray, roots: _Roots | None) -> None:
    """A warning for the problems the round caps left open (their best estimates are used)."""
    parts = [(mins.b - mins.a)[~done]] if mins is not None else []
    if roots is not None:
        rw = roots.b - roots.a
        parts.append(rw[rw >= _XTOL + _RTOL * np.maximum(abs(roots.a), abs(roots.b))])
    open_widths = np.concatenate(parts or [np.zeros(0)])
    if open_widths.size:
        log.warning("search: %d bracket(s) still open at the round cap (%d rounds for minima, %d for roots; widest "
                    "%.3g); the best estimates are used", open_widths.size, _MIN_ROUNDS, _ROOT_ROUNDS,
                    float(open_widths.max()))


# ---------------------------------------------------------------------------
# extrema
class _Search(NamedTuple):
    """One extremum search: the grid, the row of f it reads, +1 to minimise or −1 to maximise."""

    grid: Grid
    row: int
    sign: float


def _candidates(grid: Grid, v: np.ndarray) -> np.ndarray:
    """Indices of the :data:`_KEEP` smallest local minima of v (NaN-free) within the intervals
    (stable by value; the first and last sample of an interval compare one-sidedly)."""
    le_prev, le_next = np.append(True, v[1:] <= v[:-1]), np.append(v[:-1] <= v[1:], True)
    le_prev[grid.starts] = True  # the first sample of an interval compares with its successor only
    le_next[grid.starts[1:] - 1] = True  # the last one with its predecessor only
    loc = np.flatnonzero(le_prev & le_next)
    return loc[np.argsort(v[loc], kind="stable")][:_KEEP]


def _prepare(searches: Sequence[_Search], dense: Sequence[np.ndarray | None], batch0: int = 0):
    """The candidates of every search (``dense[i]``: its row of f at its grid, None for an empty grid)
    and their refinement brackets, search i in batch ``batch0 + i``: ``(plans, minima tuples)``."""
    plans: list[tuple | None] = []
    parts, off = [], 0
    for i, (s, y) in enumerate(zip(searches, dense, strict=True)):
        if not s.grid.x.size:
            plans.append(None)
            continue
        g, v = s.grid, _clean(s.sign * np.asarray(y, dtype=float))
        loc = _candidates(g, v)
        iv = np.searchsorted(g.starts, loc, side="right") - 1
        lo_i = np.maximum(loc - 1, g.starts[iv])
        hi_i = np.minimum(loc + 1, np.append(g.starts[1:], g.x.size)[iv] - 1)
        ref = g.x[hi_i] > g.x[lo_i]
        plans.append((v, loc, ref, off))
        if k := int(ref.sum()):
            lo, hi = g.x[lo_i[ref]], g.x[hi_i[ref]]
            parts.append((lo, v[lo_i[ref]], g.x[loc[ref]], v[loc[ref]], hi, v[hi_i[ref]], _refine_tol(lo, hi),
                          np.full(k, batch0 + i), np.full(k, s.row), np.full(k, s.sign)))
            off += k
    return plans, parts


def _finish(searches: Sequence[_Search], plans: list, mins: _Minima | None, offset: int = 0) -> list[Optimum]:
    """Every search's best of its sampled and refined candidates (refined from row ``offset`` of
    ``mins`` on).  Equal extrema (to rounding, e.g. repeated lobes) resolve to the smallest
    parameter, not to whichever rounding favoured."""
    out = []
    for s, plan in zip(searches, plans, strict=True):
        if plan is None:
            out.append(Optimum(0.0, float(s.sign * math.inf)))
            continue
        v, loc, ref, off = plan
        rx, rv = s.grid.x[loc].copy(), np.full(loc.size, np.inf)
        if ref.any():
            sl = slice(offset + off, offset + off + int(ref.sum()))
            rx[ref], rv[ref] = mins.x[sl], np.where(np.isfinite(mins.fx[sl]), mins.fx[sl], np.inf)  # type: ignore
        seq, at = np.stack([v[loc], rv], axis=1).ravel(), np.stack([s.grid.x[loc], rx], axis=1).ravel()
        best = float(np.min(seq))
        if not best < math.inf:
            out.append(Optimum(0.0, float(s.sign * math.inf)))
            continue
        tie = np.flatnonzero(seq <= best + _TIE * abs(best))
        k = int(tie[np.argmin(at[tie])])
        out.append(Optimum(float(at[k]), float(s.sign * seq[k])))
    return out


# ---------------------------------------------------------------------------
# ranges where a function is positive
def _interval_maxima(grid: Grid, v: np.ndarray, batch: int, row: int):
    """The bracket around each interval's largest sample (NaN-only intervals skipped) as a minima tuple
    of −v, and ``(lo, hi, sampled maximum, value at lo, at hi)``; ``(None, None)`` if all NaN."""
    starts, sizes = grid.starts, grid.sizes
    nan = np.isnan(v)
    ok = np.flatnonzero(~np.logical_and.reduceat(nan, starts))
    if not ok.size:
        return None, None
    w = np.where(nan, -np.inf, v)
    eq = np.flatnonzero(w == np.repeat(np.maximum.reduceat(w, starts), sizes))  # nanargmax per interval
    i = eq[np.searchsorted(eq, starts[ok])]
    il, ih = np.maximum(i - 1, starts[ok]), np.minimum(i + 1, starts[ok] + sizes[ok] - 1)
    lo, hi, f0, k = grid.x[il], grid.x[ih], v[i], ok.size
    prob = (lo, _clean(-v[il]), grid.x[i], _clean(-f0), hi, _clean(-v[ih]), _refine_tol(lo, hi),
            np.full(k, batch), np.full(k, row), np.full(k, -1.0))
    return prob, (lo, hi, f0, v[il], v[ih])


def _sign_pairs(x: np.ndarray, v: np.ndarray, starts: np.ndarray, batch: int, row: int, known=None) -> tuple:
    """Root problems of the adjacent samples inside one interval (from ``starts``) where ``v > 0``
    changes (and whose pair is not a key of ``known``)."""
    inner = np.ones(x.size - 1, dtype=bool)
    inner[starts[1:] - 1] = False
    q = np.flatnonzero(((v[:-1] > 0) != (v[1:] > 0)) & inner)
    if known:
        q = q[[(a, b) not in known for a, b in zip(x[q].tolist(), x[q + 1].tolist(), strict=True)]]
    return x[q], v[q], x[q + 1], v[q + 1], np.full(q.size, batch), np.full(q.size, row)


def _with_maxima(grid: Grid, v: np.ndarray, inf, rx: np.ndarray, rf: np.ndarray):
    """The samples ``(x, v, starts)`` with the refined interval maxima (rx, rf) inserted where they can
    change a sign: above the sampled maximum, strictly inside its bracket, and of another sign than a
    sample beside it (elsewhere the sign changes, so the ranges, are the samples' own)."""
    lo, hi, f0, vl, vh = inf
    p = rf > 0
    keep = (rf > f0) & (lo < rx) & (rx < hi) & ((p != (f0 > 0)) | (p != (vl > 0)) | (p != (vh > 0)))
    if not keep.any():
        return grid.x, v, grid.starts
    at = np.searchsorted(grid.x, rx[keep])  # inside its interval: lo < rx < hi are samples of it
    return np.insert(grid.x, at, rx[keep]), np.insert(v, at, rf[keep]), grid.starts + np.searchsorted(at, grid.starts)


def _refine_roots(f: Function, parts: list[tuple], mins: _Minima | None, found: list[dict]) -> None:
    """Refine root problems (batch = function index), with ``mins`` in the same rounds; file every
    root under its function and its sample pair (as given) in ``found``."""
    roots = _Roots(parts) if any(p[0].size for p in parts) else None
    _solve(f, mins, roots)
    if roots is not None:
        for a, b, j, x in zip(roots.a0.tolist(), roots.b0.tolist(), roots.batch.tolist(), roots.best().tolist(),
                               strict=True):
            found[j][(a, b)] = x


def _refined_samples(f: Function, grid: Grid, V: np.ndarray, rows: Sequence[int], more: list[tuple]):
    """For the functions ``V[rows]``, all at once: refine each interval's largest sample and the sampled
    sign changes (with the minima ``more`` in the same rounds), insert the refined maxima into the
    samples (:func:`_with_maxima`) and refine the sign changes they add.  Returns per function
    ``(x, v, starts, roots by sample pair)``, the solved minima and the row where ``more`` starts."""
    info, mparts = [], []
    for j, r in enumerate(rows):
        prob, inf = _interval_maxima(grid, V[r], j, r)
        info.append(inf)
        mparts += [prob] if prob is not None else []
    offset = sum(p[0].size for p in mparts)
    mins = _Minima(mparts + more) if mparts or more else None
    found: list[dict] = [{} for _ in rows]
    _refine_roots(f, [_sign_pairs(grid.x, V[r], grid.starts, j, r) for j, r in enumerate(rows)], mins, found)
    out, off = [], 0
    for j, inf in enumerate(info):
        x, v, starts = grid.x, V[rows[j]], grid.starts
        if inf is not None:
            k = inf[0].size
            x, v, starts = _with_maxima(grid, v, inf, mins.x[off:off + k], -mins.fx[off:off + k])  # type: ignore
            off += k
        out.append((x, v, starts))
    _refine_roots(f, [_sign_pairs(*o, j, rows[j], found[j]) for j, o in enumerate(out)], None, found)
    return [(*o, found[j]) for j, o in enumerate(out)], mins, offset


def _sign_ranges(grid: Grid, xa: np.ndarray, pos: np.ndarray, st: np.ndarray, roots: dict) -> list[list[float]]:
    """``[start, end]`` of every stretch where ``pos`` holds, interval by interval of the samples ``xa``
    (interval m from index ``st[m]``); ends at the refined roots of the sample pairs, or at the
    interval's ends."""
    inn = np.ones(xa.size - 1, dtype=bool)  # the sample pairs inside one interval
    inn[st[1:] - 1] = False
    chg = np.flatnonzero((pos[:-1] != pos[1:]) & inn)
    cut = np.append(np.searchsorted(chg, st), chg.size)
    raw: list[list] = []
    for m in np.flatnonzero(np.logical_or.reduceat(pos, st)):
        start = grid.lo[m] if pos[st[m]] else None
        for q in chg[cut[m]:cut[m + 1]]:
            r = roots[(xa[q], xa[q + 1])]
            if pos[q + 1]:
                start = r
            else:
                raw.append([start, r])
                start = None
        if start is not None:
            raw.append([start, grid.hi[m]])
    return raw


def _merged_ranges(raw: list[list[float]], edges: np.ndarray, closed: bool, tol: float):
    """Ranges ``[from, to]`` (in order) merged where they meet at a breakpoint, joined across the period
    end of a closed curve, snapped to the period ends within ``tol``; yields ``(lo, hi, subs)`` with
    ``subs`` the breakpoints of the one or two (wrapping) pieces of each range."""
    per0, per1 = edges[0], edges[-1]
    merged: list[list[float]] = []
    for r in raw:
        if merged and abs(r[0] - merged[-1][1]) < tol:
            merged[-1][1] = r[1]
        else:
            merged.append(r)
    if closed and len(merged) > 1 and merged[0][0] - per0 < tol and per1 - merged[-1][1] < tol:
        last = merged.pop()
        merged[0][0] = last[0]
    for lo, hi in merged:
        lo = per0 if lo - per0 < tol else lo
        hi = per1 if per1 - hi < tol else hi
        parts = [(lo, hi)] if lo <= hi else [(lo, per1), (per0, hi)]
        yield lo, hi, [np.unique(np.r_[a, edges[(edges > a) & (edges < b)], b]) for a, b in parts]


def _worst_values(f: Function, step: float, raw: list, rows: Sequence[int], edges: np.ndarray,
                  closed: bool) -> list[list[Range]]:
    """The merged ranges of every function with the exact largest value of each, all searched together
    (a wrapping range in its two pieces, sampled at the parent's spacing: one call of f for all)."""
    tol = 1e-9 * max(edges[-1] - edges[0], 1.0)
    spans: list[list[tuple]] = []
    searches: list[_Search] = []
    for r, row in zip(raw, rows, strict=True):
        spans.append([])
        for lo, hi, subs in _merged_ranges(r, edges, closed, tol):
            spans[-1].append((lo, hi, len(searches), len(subs)))
            searches += [_Search(dense_grid(sub, step), row, -1.0) for sub in subs]
    grids = list({id(s.grid): s.grid for s in searches if s.grid.x.size}.values())
    xs = np.concatenate([g.x for g in grids]) if grids else np.empty(0)
    V = np.asarray(f(xs), dtype=float).reshape(-1, xs.size) if grids else None
    offs = np.cumsum([0] + [g.x.size for g in grids])
    cols = {id(g): np.arange(o, o + g.x.size) for g, o in zip(grids, offs[:-1], strict=True)}
    plans, parts = _prepare(searches, [V[s.row, cols[id(s.grid)]] if s.grid.x.size else None  # type: ignore
                                       for s in searches])
    mins = _Minima(parts) if parts else None
    _solve(f, mins)
    found = _finish(searches, plans, mins)
    return [[Range(float(lo), float(hi), *max(found[q:q + m], key=lambda t: t.value))
             for lo, hi, q, m in mine] for mine in spans]


# ---------------------------------------------------------------------------
# the searches
def search(f: Function, edges, *, extrema: Sequence[tuple[int, bool]] = (), ranges: Sequence[int] = (),
           closed: bool = True, step: float | None = None,
           values: np.ndarray | None = None) -> tuple[list[Optimum], list[list[Range]]]:
    """Global extrema of some rows of ``f`` and the ranges where other rows are positive, searched
    together: one dense sample, then one call of ``f`` per round for every open problem.

    Extrema: the four best local candidates of the dense sample are refined.  Ranges: the sample
    shows the sign changes; each interval's largest sample is refined (a narrow bump between samples
    is seen), every sign change is refined to its root, then those a refined maximum adds.  Ranges
    meeting at a breakpoint are merged; on a ``closed`` curve a range through the period end wraps
    (``start > end``).  The largest value of a range is an exact extremum over it.

    Parameters
    ----------
    f : callable
        x (n,) → (k, n) values (or (n,) for k = 1); NaN is never an extremum, never positive.
    edges : (e,) array_like
        Increasing breakpoints: f is smooth between them.
    extrema : sequence of (row, maximise)
        One search per entry: the largest (True) or smallest value of that row.
    ranges : sequence of int
        The rows whose positive ranges are wanted.
    closed : bool
        The edges span one period of a closed curve.
    step : float, optional
        Dense sample spacing (:func:`dense_grid`).
    values : (k, m) or (m,) array, optional
        f at ``dense_grid(edges, step).x``, when already computed.

    Returns
    -------
    (list of Optimum, list of list of Range)
        Per extremum search ``(at, value)`` (``(0, ±inf)`` when nothing finite was found); per range
        row its ranges, in order.
    """
    edges = np.asarray(edges, dtype=float)
    grid = dense_grid(edges, step)
    if not grid.x.size:
        return [Optimum(0.0, -math.inf if mx else math.inf) for _, mx in extrema], [[] for _ in ranges]
    V = np.asarray(f(grid.x) if values is None else values, dtype=float).reshape(-1, grid.x.size)
    searches = [_Search(grid, r, -1.0 if mx else 1.0) for r, mx in extrema]
    plans, parts = _prepare(searches, [V[s.row] for s in searches], len(ranges))
    samples, mins, offset = _refined_samples(f, grid, V, ranges, parts)
    raw = [_sign_ranges(grid, x, v > 0, starts, roots) for x, v, starts, roots in samples]
    return _finish(searches, plans, mins, offset), _worst_values(f, grid.step, raw, ranges, edges, closed)


def extrema(f: Function, edges, maximize: Sequence[bool], *, rows: Sequence[int] | None = None,
            values: np.ndarray | None = None, step: float | None = None) -> list[Optimum]:
    """Global extrema of rows of ``f`` between the same breakpoints, searched together (:func:`search`):
    search i finds the largest (``maximize[i]``) or smallest value of row ``rows[i]`` (default i)."""
    pairs = list(zip(range(len(maximize)) if rows is None else rows, maximize, strict=True))
    return search(f, edges, extrema=pairs, values=values, step=step)[0]


def extremum(f: Function, edges, *, maximize: bool = False, step: float | None = None,
             values: np.ndarray | None = None) -> Optimum:
    """Global minimum (or maximum) of a vectorised ``f`` (x (n,) → (n,)) between ``edges``: ``(at, value)``."""
    return search(f, edges, extrema=[(0, maximize)], values=values, step=step)[0][0]


def positive_ranges(g: Function, edges, *, closed: bool = True, step: float | None = None,
                    values: np.ndarray | None = None) -> list:
    """Ranges where ``g > 0`` with the largest value of each (:func:`search`): a list of :class:`Range`,
    or for a g of k rows ((k, n) values) a list of k such lists."""
    grid = dense_grid(edges, step)
    if not grid.x.size:
        return []
    V = np.asarray(g(grid.x) if values is None else values, dtype=float)
    found = search(g, edges, ranges=range(V.size // grid.x.size), closed=closed, step=step, values=V)[1]
    return found[0] if V.ndim == 1 else found


def root(f: Function, a: float, b: float, *, fa: float | None = None, fb: float | None = None) -> float:
    """A root of a vectorised ``f`` (x (n,) → (n,)) between ``a`` < ``b``, where ``f > 0`` holds at one end
    only (NaN counts as not positive, +inf as positive: a bracket may reach where f cannot be
    computed); ``fa``, ``fb``: f at the ends when known.  Located to 1e-14 + 1e-15·|x|; returns the
    bracket end with the smaller |f|."""
    fa = float(np.asarray(f(np.array([a]))).ravel()[0]) if fa is None else float(fa)
    fb = float(np.asarray(f(np.array([b]))).ravel()[0]) if fb is None else float(fb)
    if (fa > 0) == (fb > 0):
        raise InputError(f"f > 0 must hold at one end of [{a:g}, {b:g}] only (f = {fa:g}, {fb:g}); give a, b "
                         "that bracket a sign change")
    r = _Roots([(np.array([a]), np.array([fa]), np.array([b]), np.array([fb]), np.zeros(1), np.zeros(1))])
    _solve(f, None, r)
    return float(r.best()[0])
