"""Vectorised searches between breakpoints: global extrema, ranges where a function is positive,
and integrals — each problem refined by safeguarded bracketing, many problems stepped together.

Every function searched here is a vectorised ``f(x)`` of the cam angle (or travel) that is smooth
between the given breakpoints (``edges``).  A search is a generator that yields the points it
wants ``f`` at and is sent the values (:func:`_run` drives one, :func:`_gather` several at once),
so that callers — :mod:`camfab.design.checks` above all — can evaluate a profile once per round
for every pending search.
"""
from __future__ import annotations

import math
from typing import Callable

import numpy as np

__all__ = ["extremum", "integrate"]


def _intervals(edges: np.ndarray, step: float):
    """Sample grids per breakpoint interval, ends pulled in by a hair (one-sided limits)."""
    per = edges[-1] - edges[0]
    eps = 1e-11 * max(per, 1.0)
    out = []
    for a, b in zip(edges[:-1], edges[1:]):
        if b - a <= 4 * eps:
            continue
        n = max(8, int(math.ceil((b - a) / step)))
        out.append((a + eps, b - eps, np.linspace(a + eps, b - eps, n + 1)))
    return out


_GRIDS: dict = {}


def _sampling(edges: np.ndarray, step: float):
    """``(ivs, grid, starts)``: :func:`_intervals` and :func:`_grid` of ``edges``, memoised (the
    checks sample the same breakpoints many times); the arrays are read-only."""
    key = (edges.tobytes(), float(step))
    hit = _GRIDS.get(key)
    if hit is None:
        ivs = _intervals(edges, step)
        grid, starts = _grid(ivs) if ivs else (np.empty(0), np.empty(0, dtype=int))
        for arr in (grid, starts, *(xs for _, _, xs in ivs)):
            arr.setflags(write=False)
        if len(_GRIDS) >= 256:
            _GRIDS.clear()
        hit = _GRIDS[key] = (ivs, grid, starts)
    return hit


def _default_step(period: float) -> float:
    return period / 1440.0


# Solvers as generators: a solver ``yield``s the parameter values it needs (1-D array) and is
# sent f at them; :func:`_run` drives one with a plain f, :func:`_gather` runs several in
# lockstep (one request per round), so that many searches share one f call per round — the
# cost of a profile evaluation is mostly per call, not per point.
def _run(f: Callable[[np.ndarray], np.ndarray], gen):
    """Drive solver generator ``gen`` with ``f``; its return value."""
    try:
        x = next(gen)
        while True:
            x = gen.send(np.asarray(f(x), dtype=float))
    except StopIteration as stop:
        return stop.value


def _gather(gens):
    """Generator: run solver generators in lockstep, each round one request (their
    concatenation); returns the list of their results."""
    gens = list(gens)
    res: list = [None] * len(gens)
    req: dict[int, np.ndarray] = {}
    for i, g in enumerate(gens):
        try:
            req[i] = np.asarray(next(g), dtype=float).ravel()
        except StopIteration as stop:
            res[i] = stop.value
    while req:
        keys = list(req)
        v = yield (req[keys[0]] if len(keys) == 1 else np.concatenate([req[i] for i in keys]))
        off = 0
        for i in keys:
            n = req[i].size
            try:
                req[i] = np.asarray(gens[i].send(v[off:off + n]), dtype=float).ravel()
            except StopIteration as stop:
                res[i] = stop.value
                del req[i]
            off += n
    return res


def _mapped(gen, fn):
    """Generator: ``gen`` with every value array it is sent passed through ``fn`` first."""
    try:
        x = next(gen)
        while True:
            x = gen.send(fn((yield x)))
    except StopIteration as stop:
        return stop.value


#: extrema equal to this relative difference are ties (rounding of repeated lobes)
_TIE = 1e-10
#: bracket values within this relative difference of the best are equal to rounding
_FLAT = 64 * np.finfo(float).eps
#: ratio of the point ladder placed around each estimate per round
_LADDER = 0.01


def _trials(u: np.ndarray, a: np.ndarray, b: np.ndarray, tol: np.ndarray) -> np.ndarray:
    """(k, m) trial points of one round: the estimate u, u ± w·r^j (w = b − a, r =
    :data:`_LADDER`, down to the tolerance) and the quarter points of [a, b] (so that the
    bracket at least halves whatever the estimate), clipped to [a, b]."""
    w = b - a
    ratio = float(np.max(w / np.maximum(tol, 1e-300)))
    J = int(min(max(math.ceil(math.log(max(ratio, 1.0)) / -math.log(_LADDER)), 1), 8))
    steps = w[:, None] * _LADDER ** np.arange(1, J + 1)[None, :]
    pts = np.concatenate([u[:, None], u[:, None] - steps, u[:, None] + steps,
                          a[:, None] + w[:, None] * np.array([0.25, 0.5, 0.75])[None, :]], axis=1)
    return np.clip(pts, a[:, None], b[:, None])


def _neighbours(P: np.ndarray, F: np.ndarray, j: np.ndarray):
    """For sample rows P (positions) / F (values) and chosen column j per row: the nearest
    sample on each side (position, value), or the chosen sample itself where none."""
    r = np.arange(len(P))
    xj, fj = P[r, j], F[r, j]
    xc = xj[:, None]
    li = np.argmax(np.where(P < xc, P, -np.inf), axis=1)  # positions are finite
    ri = np.argmin(np.where(P > xc, P, np.inf), axis=1)
    pl, pr = P[r, li], P[r, ri]
    hl, hr = pl < xj, pr > xj
    return (np.where(hl, pl, xj), np.where(hl, F[r, li], fj), xj, fj,
            np.where(hr, pr, xj), np.where(hr, F[r, ri], fj))


def _bracket_min(a, fa, x, fx, b, fb, tol, *, rounds: int = 60):
    """Generator: vectorised safeguarded minimisation of k one-dimensional problems.

    Each problem has a bracket [a, b] with its best sample x (a ≤ x ≤ b, fx ≤ fa, fb;
    x may be an end).  Each round samples, for all problems at once, the vertex of the
    parabola through (a, x, b) with a ladder of points around it and the quarter points
    of the bracket, then shrinks the bracket to the neighbours of the best sample: the
    bracket at least halves per round and shrinks by ~1/r² per round once the parabola
    is accurate.  Stops when b − a ≤ tol or when f at a and b equals f at x to rounding
    (:data:`_FLAT`).  Values must be NaN-free (use +inf).
    Returns ``(x, fx)`` arrays.
    """
    a, fa, x, fx, b, fb = (np.array(t, dtype=float) for t in (a, fa, x, fx, b, fb))
    tol = np.broadcast_to(np.asarray(tol, dtype=float), a.shape).copy()
    done = ~(b - a > tol)
    for _ in range(rounds):
        act = np.flatnonzero(~done)
        if act.size == 0:
            break
        A, FA, X, FX, B, FB = a[act], fa[act], x[act], fx[act], b[act], fb[act]
        d1, d2, f1, f2 = X - A, B - X, FA - FX, FB - FX
        with np.errstate(all="ignore"):
            u = X + 0.5 * (d2 * d2 * f1 - d1 * d1 * f2) / (d2 * f1 + d1 * f2)
        u = np.where(np.isfinite(u) & (d1 > 0) & (d2 > 0), u, X)
        pts = _trials(u, A, B, tol[act])
        v = yield pts.ravel()
        v = np.asarray(v, dtype=float).reshape(pts.shape)
        P = np.concatenate([X[:, None], A[:, None], B[:, None], pts], axis=1)
        F = np.concatenate([FX[:, None], FA[:, None], FB[:, None], v], axis=1)
        j = np.argmin(F, axis=1)  # ties keep the current best (column 0)
        a[act], fa[act], x[act], fx[act], b[act], fb[act] = _neighbours(P, F, j)
        # done when the bracket is narrow, or when its ends differ from the best by rounding only
        # (the samples cannot locate the extremum any better; the value is then exact to rounding)
        with np.errstate(invalid="ignore"):
            flat = np.maximum(fa[act], fb[act]) - fx[act] <= _FLAT * np.abs(fx[act])
        done[act] = ~(b[act] - a[act] > tol[act]) | flat
    return x, fx


def _bracket_root(a, fa, b, fb, *, xtol: float = 1e-14, rtol: float = 1e-15, rounds: int = 80):
    """Generator: vectorised bracketing root refinement of k problems, where ``f > 0`` differs
    at a and b (NaN counts as not positive).

    Each round samples, for all problems at once, the secant estimate with a ladder of
    points around it and the quarter points of the bracket, and keeps the first sign
    change from a (the bracket at least halves per round, and shrinks by ~1/r² once
    the secant is accurate).  Stops when b − a < xtol + rtol·|x| (brentq's test).
    Returns the bracket end with the smaller |f| per problem.
    """
    a, fa, b, fb = (np.array(t, dtype=float) for t in (a, fa, b, fb))
    for _ in range(rounds):
        act = np.flatnonzero(b - a >= xtol + rtol * np.maximum(np.abs(a), np.abs(b)))
        if act.size == 0:
            break
        A, FA, B, FB = a[act], fa[act], b[act], fb[act]
        with np.errstate(all="ignore"):
            u = A - FA * (B - A) / (FB - FA)
        u = np.where(np.isfinite(u), u, 0.5 * (A + B))
        pts = _trials(u, A, B, np.full(act.size, xtol))
        v = yield pts.ravel()
        v = np.asarray(v, dtype=float).reshape(pts.shape)
        P = np.concatenate([A[:, None], pts, B[:, None]], axis=1)
        F = np.concatenate([FA[:, None], v, FB[:, None]], axis=1)
        o = np.argsort(P, axis=1, kind="stable")
        P, F = np.take_along_axis(P, o, 1), np.take_along_axis(F, o, 1)
        flip = (F[:, :-1] > 0) != (F[:, 1:] > 0)  # the ends differ, so some adjacent pair does
        j = np.argmax(flip, axis=1)
        r = np.arange(act.size)
        a[act], fa[act], b[act], fb[act] = P[r, j], F[r, j], P[r, j + 1], F[r, j + 1]
    with np.errstate(invalid="ignore"):
        take_a = ~(np.abs(fb) < np.abs(fa))
    return np.where(take_a, a, b)


def _candidates(grid: np.ndarray, starts: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Indices of local minima of v (NaN-free) within each interval of the concatenated grid
    (intervals start at ``starts``; the first and last sample of an interval compare one-sidedly)."""
    le_prev = np.empty(v.size, dtype=bool)
    le_next = np.empty(v.size, dtype=bool)
    np.less_equal(v[1:], v[:-1], out=le_prev[1:])
    np.less_equal(v[:-1], v[1:], out=le_next[:-1])
    le_prev[starts] = True  # the first sample of an interval (and of the grid)
    le_next[starts[1:] - 1] = True  # the last one
    le_next[-1] = True
    return np.flatnonzero(le_prev & le_next)


def _grid(ivs) -> tuple[np.ndarray, np.ndarray]:
    """Concatenated sample grid of :func:`_intervals` and the start index of each interval."""
    sizes = np.array([len(xs) for _, _, xs in ivs], dtype=int)
    starts = np.r_[0, np.cumsum(sizes)[:-1]]
    return np.concatenate([xs for _, _, xs in ivs]), starts


def _extremum_steps(edges, *, maximize: bool = False, step: float | None = None, keep: int = 4):
    """Generator form of :func:`extremum` (for :func:`_run` / :func:`_gather`)."""
    edges = np.asarray(edges, dtype=float)
    step = step or _default_step(edges[-1] - edges[0])
    sgn = -1.0 if maximize else 1.0
    ivs, grid, starts = _sampling(edges, step)
    if not ivs:
        return 0.0, float(sgn * math.inf)

    def clean(y):
        y = sgn * np.asarray(y, dtype=float)
        return np.where(np.isnan(y), np.inf, y)

    v = clean((yield grid))
    loc = _candidates(grid, starts, v)
    loc = loc[np.argsort(v[loc], kind="stable")][:keep]
    end = np.r_[starts[1:], grid.size] - 1
    iv = np.searchsorted(starts, loc, side="right") - 1
    lo_i, hi_i = np.maximum(loc - 1, starts[iv]), np.minimum(loc + 1, end[iv])
    lo, hi = grid[lo_i], grid[hi_i]
    ref = hi > lo
    rx, rv = grid[loc].copy(), np.full(loc.size, np.inf)
    if ref.any():
        tol = 1e-9 * (hi[ref] - lo[ref])
        tol = np.maximum(tol, 16 * np.finfo(float).eps * np.maximum(1.0, np.abs(hi[ref])))
        xr, fr = yield from _mapped(_bracket_min(lo[ref], v[lo_i[ref]], grid[loc[ref]], v[loc[ref]], hi[ref],
                                                 v[hi_i[ref]], tol), clean)
        rx[ref], rv[ref] = xr, np.where(np.isfinite(fr), fr, np.inf)
    # the best of (grid value, refined value) per candidate; equal extrema (to rounding, e.g.
    # repeated lobes) resolve to the smallest parameter, not to whichever rounding favoured
    seq = np.stack([v[loc], rv], axis=1).ravel()
    at = np.stack([grid[loc], rx], axis=1).ravel()
    best = float(np.min(seq))
    if not best < math.inf:
        return 0.0, float(sgn * math.inf)
    tie = np.flatnonzero(seq <= best + _TIE * abs(best))
    k = int(tie[np.argmin(at[tie])])
    return float(at[k]), float(sgn * seq[k])


def _trials_multi(u, a, b, tol, bt, nb: int) -> np.ndarray:
    """:func:`_trials` of rows from several independent batches (row r in batch ``bt[r]``):
    each row gets the points it would get in a call of its batch alone, the ladder entries
    beyond its batch's ladder length being repeats of the estimate u."""
    w = b - a
    ratio = w / np.maximum(tol, 1e-300)
    n = u.size
    lad = -math.log(_LADDER)
    if nb == 1 or n == 1:
        r = float(np.max(ratio))
        Jr = min(max(math.ceil(math.log(max(r, 1.0)) / lad), 1), 8)
        jm = Jr = int(Jr)
        steps = w[:, None] * _LADPOW[None, :jm]
    else:
        if n > 1 and bt[0] <= bt[-1] and not (bt[1:] < bt[:-1]).any():
            # rows grouped by batch (the solvers' order): the largest ratio per group
            cut = np.flatnonzero(bt[1:] != bt[:-1]) + 1
            gmax = np.maximum.reduceat(ratio, np.r_[0, cut]) if cut.size else np.array([np.max(ratio)])
            Jg = [int(min(max(math.ceil(math.log(max(r, 1.0)) / lad), 1), 8)) for r in gmax.tolist()]
            jm = max(Jg)
            Jr = np.repeat(np.array(Jg, dtype=np.intp), np.diff(np.r_[0, cut, n])) if min(Jg) < jm else None
        else:
            rmax = np.full(nb, -np.inf)
            np.maximum.at(rmax, bt, ratio)
            Jb = np.array([int(min(max(math.ceil(math.log(max(r, 1.0)) / lad), 1), 8)) if r > -math.inf else 1
                           for r in rmax.tolist()], dtype=np.intp)
            Jr = Jb[bt]
            jm = int(Jr.max())
            if int(Jr.min()) == jm:
                Jr = None
        steps = w[:, None] * _LADPOW[None, :jm]
        if Jr is not None:
            steps[_LADIDX[None, :jm] > Jr[:, None]] = 0.0  # u ± 0 = u: a repeat
    pts = np.empty((n, 2 * jm + 4))
    pts[:, 0] = u
    uc = u[:, None]
    np.subtract(uc, steps, out=pts[:, 1:jm + 1])
    np.add(uc, steps, out=pts[:, jm + 1:2 * jm + 1])
    np.add(a[:, None], w[:, None] * _QUARTERS[None, :], out=pts[:, 2 * jm + 1:])
    # np.clip(pts, a, b) (every value is finite)
    np.maximum(pts, a[:, None], out=pts)
    return np.minimum(pts, b[:, None], out=pts)


#: the ladder ratios r^j (j = 1…8) and their exponents
_LADPOW = _LADDER ** np.arange(1, 9)
_LADIDX = np.arange(1, 9)
_QUARTERS = np.array([0.25, 0.5, 0.75])


class _ExtremaPlan:
    """Several :func:`_extremum_steps` searches of functions given as rows of a value array:
    their dense grids (:attr:`grids`), the refinement rows after the dense sampling
    (:meth:`prepare`) and the results (:meth:`finish`), each exactly as its own search.

    ``specs`` holds ``(edges, maximize[, step[, row]])``; search i reads row ``row`` (default
    i) of the values and is refinement batch ``base + i``."""

    def __init__(self, specs, base: int = 0):
        self.specs = [(np.asarray(sp[0], dtype=float), sp[1], sp[2] if len(sp) > 2 else None,
                       sp[3] if len(sp) > 3 else i) for i, sp in enumerate(specs)]
        self.sgn = np.array([-1.0 if mx else 1.0 for _, mx, _, _ in self.specs])
        self.row = np.array([r for _, _, _, r in self.specs], dtype=np.intp)
        self.base = base
        self.samp = [_sampling(e, st or _default_step(e[-1] - e[0])) for e, _, st, _ in self.specs]
        offs, parts, total = [], {}, 0
        for ivs, grid, starts in self.samp:
            if ivs and id(grid) not in parts:
                parts[id(grid)] = (total, grid)
                total += grid.size
            offs.append(parts[id(grid)][0] if ivs else 0)
        self.offs, self.grids, self.size = offs, [g for _, g in parts.values()], total
        self.plan: list = []

    def prepare(self, V: np.ndarray, off: int = 0):
        """The refinement rows (lo, f(lo), x, f(x), hi, f(hi), tol, batch) from the values V at
        the dense grids (which start at column ``off``), or None.  All searches at once: their
        samples concatenated (each interval of each search an interval of the whole)."""
        act = [i for i, (ivs, _, _) in enumerate(self.samp) if ivs]
        self.act = act
        if not act:
            return None
        sizes = np.array([self.samp[i][1].size for i in act])
        base = np.r_[0, np.cumsum(sizes)[:-1]]
        gx = np.concatenate([self.samp[i][1] for i in act])
        cols = np.concatenate([off + self.offs[i] + np.arange(self.samp[i][1].size) for i in act])
        own = np.repeat(np.arange(len(act)), sizes)
        v = np.repeat(self.sgn[act], sizes) * V[np.repeat(self.row[act], sizes), cols]
        v = np.where(np.isnan(v), np.inf, v)
        starts = np.concatenate([self.samp[i][2] + bs for i, bs in zip(act, base)])
        loc = _candidates(gx, starts, v)
        loc = loc[np.lexsort((loc, v[loc], own[loc]))]  # per search, by value (stable)
        grp = own[loc]
        first = np.searchsorted(grp, np.arange(len(act)))
        rank = np.arange(loc.size) - first[grp]
        keep = rank < 4
        loc, grp, rank = loc[keep], grp[keep], rank[keep]
        end = np.r_[starts[1:], gx.size] - 1
        iv = np.searchsorted(starts, loc, side="right") - 1
        lo_i, hi_i = np.maximum(loc - 1, starts[iv]), np.minimum(loc + 1, end[iv])
        lo, hi = gx[lo_i], gx[hi_i]
        ref = hi > lo
        self.cand = (len(act), grp, rank, v[loc], gx[loc], ref)
        if not ref.any():
            return None
        tol = 1e-9 * (hi[ref] - lo[ref])
        tol = np.maximum(tol, 16 * np.finfo(float).eps * np.maximum(1.0, np.abs(hi[ref])))
        return [lo[ref], v[lo_i[ref]], gx[loc[ref]], v[loc[ref]], hi[ref], v[hi_i[ref]], tol,
                self.base + np.asarray(act)[grp[ref]]]

    def channels(self) -> tuple[np.ndarray, np.ndarray]:
        """Value row and sign of every batch (indexed from :attr:`base`)."""
        return self.row, self.sgn

    def finish(self, xr_all=None, fr_all=None, owner=None) -> list:
        """``(x, value)`` of every search, from the refined rows (``owner`` = their batches)."""
        out = [(0.0, float(sg * math.inf)) for sg in self.sgn]
        if not getattr(self, "act", None):
            return out
        m, grp, rank, vloc, xloc, ref = self.cand
        seq = np.full((m, 4, 2), np.inf)
        at = np.full((m, 4, 2), np.inf)
        seq[grp, rank, 0], at[grp, rank, 0], at[grp, rank, 1] = vloc, xloc, xloc
        if ref.any():
            # the refined rows in the order prepare gave them
            act = np.asarray(self.act)
            mine = np.zeros(max(int(owner.max()), self.base + int(act.max())) + 1, dtype=bool)
            mine[self.base + act] = True
            sel = np.flatnonzero(mine[owner])
            fr = fr_all[sel]
            at[grp[ref], rank[ref], 1] = xr_all[sel]
            seq[grp[ref], rank[ref], 1] = np.where(np.isfinite(fr), fr, np.inf)
        # the best of (grid value, refined value) per candidate; equal extrema (to rounding,
        # e.g. repeated lobes) resolve to the smallest parameter
        seq, at = seq.reshape(m, 8), at.reshape(m, 8)
        best = np.min(seq, axis=1)
        with np.errstate(invalid="ignore"):
            tie = seq <= (best + _TIE * np.abs(best))[:, None]
        j = np.argmin(np.where(tie, at, np.inf), axis=1)
        r = np.arange(m)
        xs, vs = at[r, j], seq[r, j]
        for q, i in enumerate(self.act):
            if best[q] < math.inf:
                out[i] = (float(xs[q]), float(self.sgn[i] * vs[q]))
        return out


def _channel_solvers(nrows: int, mins=None, roots=None, *, min_rounds: int = 60, root_rounds: int = 80):
    """Generator: independent batches of :func:`_bracket_min` and :func:`_bracket_root` problems,
    stepped together (one request per round), on functions given as the rows of the
    (nrows, n) value arrays it is sent (it yields the points).

    ``mins`` = (rows (lo, f(lo), x, f(x), hi, f(hi), tol, batch), value row of each batch,
    sign of each batch): the minimised value is ``sign·f`` (NaN → +inf); ``roots`` = (a, f(a),
    b, f(b), batch, value row of each batch), refined to ``b − a < 1e-14 + 1e-15·|x|``.  Every
    problem takes exactly the trial points it takes in its batch's own solver (the ladder
    length of a round is its batch's, see :func:`_trials_multi`), so it ends with exactly that
    result.  Returns ``((x, fx), roots)`` (None where not asked)."""
    xtol, rtol = 1e-14, 1e-15
    if mins is not None:
        a, fa, x, fx, b, fb = (np.array(t, dtype=float) for t in mins[0][:6])
        tol = np.asarray(mins[0][6], dtype=float)
        mb = np.asarray(mins[0][7], dtype=np.intp)
        done = ~(b - a > tol)
        mrow, msg = np.asarray(mins[1], dtype=np.intp), np.asarray(mins[2], dtype=float)
        nbm = int(mb.max()) + 1 if mb.size else 0
    else:
        nbm, done = 0, np.zeros(0, dtype=bool)
    if roots is not None:
        ra, rfa, rb, rfb = (np.array(t, dtype=float) for t in roots[:4])
        rbt = np.asarray(roots[4], dtype=np.intp)
        rrow = np.asarray(roots[5], dtype=np.intp)
        nbr = int(rbt.max()) + 1 if rbt.size else 0
    else:
        nbr = 0
    mround = rround = 0
    empty = np.zeros(0, dtype=np.intp)
    while True:
        mact = np.flatnonzero(~done) if mins is not None and mround < min_rounds else empty
        ract = (np.flatnonzero(rb - ra >= xtol + rtol * np.maximum(np.abs(ra), np.abs(rb)))
                if roots is not None and rround < root_rounds else empty)
        nm, nr = mact.size, ract.size
        if nm + nr == 0:
            break
        parts = []
        if nm:
            A, FA, X, FX, B, FB = a[mact], fa[mact], x[mact], fx[mact], b[mact], fb[mact]
            d1, d2, f1, f2 = X - A, B - X, FA - FX, FB - FX
            with np.errstate(all="ignore"):
                u = X + 0.5 * (d2 * d2 * f1 - d1 * d1 * f2) / (d2 * f1 + d1 * f2)
            u = np.where(np.isfinite(u) & (d1 > 0) & (d2 > 0), u, X)
            parts.append((u, A, B, tol[mact], mb[mact], mrow[mb[mact]]))
        if nr:
            RA, RFA, RB, RFB = ra[ract], rfa[ract], rb[ract], rfb[ract]
            with np.errstate(all="ignore"):
                ur = RA - RFA * (RB - RA) / (RFB - RFA)
            ur = np.where(np.isfinite(ur), ur, 0.5 * (RA + RB))
            parts.append((ur, RA, RB, np.full(nr, xtol), nbm + rbt[ract], rrow[rbt[ract]]))
        cols = [np.concatenate(t) for t in zip(*parts)] if len(parts) > 1 else list(parts[0])
        pts = _trials_multi(*cols[:5], nbm + nbr)
        V = np.asarray((yield pts.ravel()), dtype=float).reshape(nrows, -1)
        Y = V[cols[5][:, None], np.arange(pts.size).reshape(pts.shape)]
        if nm:
            v = msg[mb[mact]][:, None] * Y[:nm]
            v = np.where(np.isnan(v), np.inf, v)
            P = np.concatenate([X[:, None], A[:, None], B[:, None], pts[:nm]], axis=1)
            F = np.concatenate([FX[:, None], FA[:, None], FB[:, None], v], axis=1)
            j = np.argmin(F, axis=1)  # ties keep the current best (column 0)
            a[mact], fa[mact], x[mact], fx[mact], b[mact], fb[mact] = _neighbours(P, F, j)
            with np.errstate(invalid="ignore"):
                flat = np.maximum(fa[mact], fb[mact]) - fx[mact] <= _FLAT * np.abs(fx[mact])
            done[mact] = ~(b[mact] - a[mact] > tol[mact]) | flat
            mround += 1
        if nr:
            P = np.concatenate([RA[:, None], pts[nm:], RB[:, None]], axis=1)
            F = np.concatenate([RFA[:, None], Y[nm:], RFB[:, None]], axis=1)
            o = np.argsort(P, axis=1, kind="stable")
            P, F = np.take_along_axis(P, o, 1), np.take_along_axis(F, o, 1)
            flip = (F[:, :-1] > 0) != (F[:, 1:] > 0)  # the ends differ, so some adjacent pair does
            j = np.argmax(flip, axis=1)
            r = np.arange(nr)
            ra[ract], rfa[ract], rb[ract], rfb[ract] = P[r, j], F[r, j], P[r, j + 1], F[r, j + 1]
            rround += 1
    out_r = None
    if roots is not None:
        with np.errstate(invalid="ignore"):
            take_a = ~(np.abs(rfb) < np.abs(rfa))
        out_r = np.where(take_a, ra, rb)
    return ((x, fx) if mins is not None else None), out_r


def _extrema_steps(specs, nrows: int | None = None):
    """Generator: many :func:`_extremum_steps` searches of different functions run as one.

    ``specs`` holds ``(edges, maximize[, step[, row]])`` per search; the generator yields the
    parameter values it needs and is sent a (rows, n) array of the functions at them, search
    i using row ``row`` (default i).
    Each search gives exactly the result of its own :func:`_extremum_steps`.  Returns the
    list of ``(x, value)``."""
    plan = _ExtremaPlan(specs)
    nrows = nrows or (int(plan.row.max()) + 1 if len(plan.row) else 0)
    if not plan.grids:
        return [(0.0, float(sg * math.inf)) for sg in plan.sgn]
    allx = np.concatenate(plan.grids) if len(plan.grids) > 1 else plan.grids[0]
    V = np.asarray((yield allx), dtype=float).reshape(nrows, -1)
    cols = plan.prepare(V)
    if cols is None:
        return plan.finish()
    (xr, fr), _ = yield from _channel_solvers(nrows, (cols, *plan.channels()))
    return plan.finish(xr, fr, cols[7])


def extremum(f: Callable[[np.ndarray], np.ndarray], edges, *, maximize: bool = False,
             step: float | None = None, keep: int = 4) -> tuple[float, float]:
    """Global extremum of a vectorised ``f`` between breakpoints ``edges``.

    Dense sampling of every breakpoint interval (one call of f), then a safeguarded
    parabolic refinement (:func:`_bracket_min`) of the best ``keep`` local candidates,
    all at once (one call of f per round).  Returns ``(x, value)``.
    """
    return _run(f, _extremum_steps(edges, maximize=maximize, step=step, keep=keep))


_GAUSS20 = np.polynomial.legendre.leggauss(20)


def _integrate_steps(edges, *, rtol: float = 1e-11, atol: float = 0.0):
    """Generator form of :func:`integrate`."""
    xg, wg = _GAUSS20
    edges = np.asarray(edges, dtype=float)
    todo = np.stack([edges[:-1], edges[1:]], axis=1)
    todo = todo[todo[:, 1] > todo[:, 0]]

    def nodes(iv):
        mid, half = (iv[:, 0] + iv[:, 1]) / 2, (iv[:, 1] - iv[:, 0]) / 2
        return mid[:, None] + half[:, None] * xg[None, :], half

    pts, half = nodes(todo)
    whole = half * ((yield pts.ravel()).reshape(pts.shape) @ wg)
    total, scale = 0.0, max(abs(whole.sum()), 1e-300)
    span = edges[-1] - edges[0]
    for _ in range(40):
        if len(todo) == 0:
            break
        mid = (todo[:, 0] + todo[:, 1]) / 2
        left, right = np.stack([todo[:, 0], mid], 1), np.stack([mid, todo[:, 1]], 1)
        pl, hl = nodes(left)
        pr, hr = nodes(right)
        v = yield np.concatenate([pl.ravel(), pr.ravel()])
        ql = hl * (v[:pl.size].reshape(pl.shape) @ wg)
        qr = hr * (v[pl.size:].reshape(pr.shape) @ wg)
        ok = np.abs(ql + qr - whole) <= (rtol * scale + atol) * (todo[:, 1] - todo[:, 0]) / span + 1e-300
        total += float((ql + qr)[ok].sum())
        todo = np.concatenate([left[~ok], right[~ok]])
        whole = np.concatenate([ql[~ok], qr[~ok]])
    return total + float(whole.sum())


def integrate(f: Callable[[np.ndarray], np.ndarray], edges, *, rtol: float = 1e-11, atol: float = 0.0) -> float:
    """∫ f between breakpoints by adaptive 20-point Gauss–Legendre (vectorised: one call of f per pass).
    Error target ``rtol·|∫f| + atol``: give ``atol`` where the integral may cancel to ~0."""
    return _run(f, _integrate_steps(edges, rtol=rtol, atol=atol))
