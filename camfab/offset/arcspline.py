"""G1 arc splines fitted to a curve's cubic stand-in: knots and curvatures optimised per smooth stretch.

The *free* (non-interpolating) arc spline that :func:`camfab.offset.discretize.arcs` tries first.
The curve is cut into spans at kinks and circular pieces (dwells, whose exact arcs the neighbouring
spans continue); long stretches are cut into spans of about :data:`_SPLINE_SPAN` arcs joined G1 on
the curve.  Each span is clamped to the curve's point and tangent at both ends and fitted on the
Hermite surrogate (:class:`~camfab.offset.discretize._Surrogate`): a linear model of the normal
deviation (prefix integrals exact for cubic Hermite data) gives the curvatures of given knots by a
minimax (Lawson) fit, then knots and curvatures are optimised together until the errors
equioscillate, and the fewest arcs that fit are kept.  The exact arcs are then laid out (two of
them the biarc closing the span), the chain is measured on the exact curve, and only the spans
that exceed ``tol`` are refitted.  Nothing here is public: :func:`_fit_spline` is the entry point.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Optional

import numpy as np

from .discretize import (
    LINE_SWEEP_RAD,
    MAX_TURNING_RAD,
    TWO_PI,
    Chain,
    ParametricCurve,
    _arc_from,
    _biarc,
    _cross,
    _dot,
    _entity_point,
    _merge_cocircular,
    _piece_index,
    _points,
    _rotate,
    _Surrogate,
    _unit,
    measure_deviation,
)


# --------------------------------------------------------------------------------------
# free G1 arc splines (non-interpolating): the arcs stay inside the ±tol band
# --------------------------------------------------------------------------------------
#: model samples per arc of the free arc spline, and Lawson (minimax) iterations of its start
_SPLINE_SAMPLES = 16
#: the free spline's model deviation aims at this fraction of tol (less the surrogate error)
_SPLINE_FILL = 0.97
#: fewest model samples of one span
_SPLINE_MIN_GRID = 129
#: the first arc count tried is this multiple of the asymptotic estimate
_EST_FACTOR = 1.0
#: one arc fewer is tried while the predicted error (∝ 1/m³) stays below this multiple of the target
_DOWN_SLACK = 1.2
_LAWSON_ITERS = 8
#: Gauss-Newton rounds equalising the arc errors (knots and curvatures together)
_EQUI_ITERS = 8
#: most arcs of one free span: a longer smooth piece is cut into spans joined G1 at (surrogate)
#: curve points with the curve's tangent, which keeps every linear system small
_SPLINE_SPAN = 40
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
#: a breakpoint whose one-sided tangents differ by less than this (radians) is G1 (arcs may run across it)
_G1_RAD = 1e-6


def _span_model(sur: _Surrogate, segs, n_grid: int, curvature: bool = False):
    """Arc length, tangent angle (and curvature) of the surrogate along a span.

    ``segs`` lists ``(piece, lo, hi)`` parameter ranges of consecutive smooth pieces joined G1; the
    grid points are shared out by parameter length, every junction appearing twice (its one-sided
    values: the curvature may jump there)."""
    total = sum(hi - lo for _, lo, hi in segs)
    ts, ss, ths, ks = [], [], [], []
    s_off, th_off = 0.0, None
    for piece, lo, hi in segs:
        n = max(5, int(round(n_grid * (hi - lo) / total)) + 1) if len(segs) > 1 else n_grid
        t = np.linspace(lo, hi, n)
        tm = 0.5 * (t[:-1] + t[1:])
        d = sur.derivative(t, piece)
        dm = sur.derivative(tm, piece)
        sp, spm = np.hypot(d[:, 0], d[:, 1]), np.hypot(dm[:, 0], dm[:, 1])
        sv = s_off + np.concatenate([[0.0], np.cumsum(np.diff(t) / 6.0 * (sp[:-1] + 4 * spm + sp[1:]))])
        theta = np.unwrap(np.arctan2(d[:, 1], d[:, 0]))
        if th_off is not None:
            theta = theta + TWO_PI * round((th_off - theta[0]) / TWO_PI)
        ts.append(t)
        ss.append(sv)
        ths.append(theta)
        if curvature:
            ks.append(_cross(d, sur.second_derivative(t, piece)) / np.maximum(sp, 1e-300) ** 3)
        s_off, th_off = float(sv[-1]), float(theta[-1])
    out = (np.concatenate(ts), np.concatenate(ss), np.concatenate(ths))
    return out + (np.concatenate(ks),) if curvature else out


def _cumtrapz(f: np.ndarray, s: np.ndarray) -> np.ndarray:
    ds = np.diff(s).reshape((-1,) + (1,) * (f.ndim - 1))
    return np.concatenate([np.zeros((1,) + f.shape[1:]), np.cumsum(0.5 * ds * (f[1:] + f[:-1]), axis=0)])


def _cumhermite(f: np.ndarray, fp: np.ndarray, s: np.ndarray) -> np.ndarray:
    """Cumulative integral of ``f`` (derivative ``fp``) on the grid ``s``: exact for piecewise cubics."""
    ds = np.diff(s).reshape((-1,) + (1,) * (f.ndim - 1))
    inc = 0.5 * ds * (f[1:] + f[:-1]) + ds * ds / 12.0 * (fp[:-1] - fp[1:])
    return np.concatenate([np.zeros((1,) + f.shape[1:]), np.cumsum(inc, axis=0)])


def _hermite_at(x: np.ndarray, s: np.ndarray, F: np.ndarray, f: np.ndarray, fp: np.ndarray) -> np.ndarray:
    """``F(x) = ∫₀ˣ f`` between grid points: integral of the cubic Hermite interpolant of ``f``."""
    i = np.clip(np.searchsorted(s, x, side="right") - 1, 0, s.size - 2)
    h = s[i + 1] - s[i]
    tau = np.clip((x - s[i]) / np.where(h > 0, h, 1.0), 0.0, 1.0)
    t2, t3, t4 = tau * tau, tau ** 3, tau ** 4
    w = (h * (tau - t3 + 0.5 * t4), h * h * (0.25 * t4 - 2.0 * t3 / 3.0 + 0.5 * t2),
         h * (t3 - 0.5 * t4), h * h * (0.25 * t4 - t3 / 3.0))
    return (F[i] + w[0][:, None] * f[i] + w[1][:, None] * fp[i] + w[2][:, None] * f[i + 1]
            + w[3][:, None] * fp[i + 1])


def _lawson(A: np.ndarray, b: np.ndarray, C: np.ndarray, dvec: np.ndarray, iters: int = _LAWSON_ITERS):
    """Approximately minimise ``max |A k + b|`` subject to ``C k = d`` (Lawson's reweighting)."""
    kp, *_ = np.linalg.lstsq(C, dvec, rcond=None)
    _, sv, vt = np.linalg.svd(C)
    rank = int((sv > sv[0] * 1e-12).sum()) if sv.size else 0
    Z = vt[rank:].T
    if Z.shape[1] == 0:
        return kp, A @ kp + b
    AZ = A @ Z
    r0 = A @ kp + b
    w = np.full(A.shape[0], 1.0 / A.shape[0])
    best_k, best_e = None, np.inf
    for _ in range(iters):
        M = AZ * w[:, None]
        H = AZ.T @ M
        H[np.diag_indices_from(H)] += 1e-14 * np.trace(H) + 1e-300
        y = np.linalg.solve(H, -(M.T @ r0))
        k = kp + Z @ y
        e = r0 + AZ @ y
        emax = np.abs(e).max()
        if emax < best_e:
            best_k, best_e, best_res = k, emax, e
        w = w * np.abs(e)
        total = w.sum()
        if not (total > 0):
            break
        w = np.maximum(w / total, 1e-12)
    return best_k, best_res


class _SpanModel:
    """Linear model of the normal deviation of a G1 arc spline from one smooth piece.

    The arcs are parametrised by the arc length ``s`` of the piece: with knots
    ``x`` (arc ends) and curvatures ``k`` the spline's tangent angle is
    ``φ(s) = θ(0) + Σ k_j·clip(s - x_j, 0, ℓ_j)``; to first order its point at
    ``s`` is ``P(s) + V(s)`` with ``V(s) = ∫₀ˢ (φ - θ)·n ds'``, and the normal
    deviation is ``e(s) = n(s)·V(s) = A k + b``.  The spline starts at the
    piece's first point with its tangent; ``C k = d`` closes it on the last
    point with its tangent (first order; the last two arcs are re-fitted exactly).
    """

    def __init__(self, sur: _Surrogate, segs, n_grid: int, fixed=(None, None)):
        _, s, theta, kappa = _span_model(sur, segs, n_grid, curvature=True)
        self.fixed = fixed  # curvatures imposed on the first / last arc (None: free)
        self.s, self.theta, self.L = s, theta, float(s[-1])
        # every prefix integral is the exact integral of the cubic Hermite interpolant of its
        # integrand (values and derivatives at the grid): knots fall between grid points, and
        # linear interpolation there would cost O(h²·κ) -- of the order of tol at fine tolerances
        tng = np.stack([np.cos(theta), np.sin(theta)], axis=-1)
        nrm = np.stack([-np.sin(theta), np.cos(theta)], axis=-1)
        dn = -kappa[:, None] * tng                                       # d n / ds
        dth = (theta[0] - theta)[:, None]
        self.nrm = nrm
        self.n_fp = (nrm, dn)
        self.m_fp = (s[:, None] * nrm, nrm + s[:, None] * dn)
        self.N = _cumhermite(nrm, dn, s)                                 # ∫ n ds
        self.Dt = _cumhermite(dth * nrm, -kappa[:, None] * nrm + dth * dn, s)
        self.b = _dot(self.Dt, nrm)
        self.M = _cumhermite(*self.m_fp, s)                              # ∫ s·n ds
        self.nN, self.nM = _dot(nrm, self.N), _dot(nrm, self.M)
        self._nm = (np.hstack([self.N, self.M]), np.hstack([nrm, self.m_fp[0]]), np.hstack([dn, self.m_fp[1]]))
        self._last = (None, None)

    def NM_at(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(N(x), M(x))`` between grid points (the last query is cached)."""
        key = x.tobytes()
        if self._last[0] != key:
            v = _hermite_at(x, self.s, *self._nm)
            self._last = (key, (v[:, :2], v[:, 2:]))
        return self._last[1]

    def system(self, knots: np.ndarray):
        """``(A, C, d)`` of the knots: ``e = A k + b`` on the grid, ``C k = d`` closes the span."""
        ell = np.diff(knots)
        s, nrm = self.s, self.nrm
        # V_j(s) = ∫ clip(s' - x_j, 0, ℓ_j)·n ds' from the prefix integrals N = ∫ n, M = ∫ s'·n:
        # after arc j (s > x_{j+1}) n·V_j = n·W_j + ℓ_j·n·N(s), W_j = [M - x·N] from x_j to x_{j+1};
        # inside it n·V_j = n·M(s) - x_j·n·N(s) - n·(M(x_j) - x_j·N(x_j)); before it 0
        Nx, Mx = self.NM_at(knots)
        G = Mx - knots[:, None] * Nx                                        # (m + 1, 2)
        m = ell.size
        A = nrm @ (G[1:] - G[:-1]).T + self.nN[:, None] * ell[None, :]
        jj = np.clip(np.searchsorted(knots, s, side="right") - 1, 0, m - 1)
        A[np.arange(m)[None, :] >= jj[:, None]] = 0.0
        A[np.arange(s.size), jj] = self.nM - knots[jj] * self.nN - _dot(nrm, G[jj])
        Dk_end = (Mx[1:] - Mx[:-1]) - knots[:-1, None] * (Nx[1:] - Nx[:-1]) + ell[:, None] * (self.N[-1] - Nx[1:])
        scale = self.L / ell.size
        C = np.vstack([ell * scale, Dk_end.T])
        d = np.concatenate([[(self.theta[-1] - self.theta[0]) * scale], -self.Dt[-1]])
        rows, vals = self._fixed_rows(m)
        if rows.shape[0]:
            C, d = np.vstack([C, rows]), np.concatenate([d, vals])
        return A, C, d

    def _fixed_rows(self, m: int):
        rows, vals = [], []
        for j, kf in ((0, self.fixed[0]), (m - 1, self.fixed[1])):
            if kf is not None:
                r = np.zeros(m)
                r[j] = self.L
                rows.append(r)
                vals.append(kf * self.L)
        return np.array(rows).reshape(-1, m), np.array(vals)

    def knot_jacobian(self, knots: np.ndarray, k: np.ndarray):
        """Derivatives of ``e`` (grid) and of ``C k - d`` with respect to the interior knots.

        Moving knot ``x_j`` by ``δ`` turns every later tangent by ``(k_{j-1} - k_j)·δ``.
        """
        xi = knots[1:-1]
        Nx = self.NM_at(knots)[0][1:-1]
        jump = k[:-1] - k[1:]
        B = (self.nN[:, None] - self.nrm @ Nx.T) * jump
        B[self.s[:, None] <= xi[None, :]] = 0.0
        Bc = np.vstack([jump * (self.L / k.size), ((self.N[-1][None] - Nx) * jump[:, None]).T])
        n_fixed = self._fixed_rows(k.size)[0].shape[0]
        if n_fixed:
            Bc = np.vstack([Bc, np.zeros((n_fixed, xi.size))])
        return B, Bc


def _local_extrema(e: np.ndarray) -> np.ndarray:
    """Grid indices where ``|e|`` has a local maximum."""
    ae = np.abs(e)
    left = np.concatenate([[-np.inf], ae[:-1]])
    right = np.concatenate([ae[1:], [-np.inf]])
    return np.flatnonzero((ae >= left) & (ae >= right) & (ae > 0))


def _equioscillate(model: _SpanModel, knots: np.ndarray, iters: int = _EQUI_ITERS):
    """Jointly optimise knots and curvatures of a clamped span: ``(max |e|, knots, k)``.

    Starts from the (approximate) minimax curvatures of the given knots, then
    Gauss-Newton steps on knots and curvatures together drive every local
    extremum of the deviation to one common level (a Remez-like exchange: the
    extrema are re-located after every step), the knot moves damped
    (Levenberg) and each step accepted only if the largest deviation drops.
    """
    A, C, d = model.system(knots)
    k, e = _lawson(A, model.b, C, d, iters=4)
    best = (float(np.abs(e).max()), knots, k, e)
    m = k.size
    if m < 3:
        return _peak(e), knots, k
    lam = 1e-2
    hmean = model.L / m
    for _ in range(iters):
        E, knots, k, e = best
        p = _local_extrema(e)
        B, Bc = model.knot_jacobian(knots, k)
        J = np.hstack([A[p], B[p], -np.sign(e[p])[:, None]])
        Cj = np.hstack([C, Bc, np.zeros((C.shape[0], 1))])
        wc = 1e3 / max(float(np.abs(Cj).max()), 1e-300)
        damp = np.zeros((m - 1, 2 * m))
        damp[:, m:2 * m - 1] = np.eye(m - 1) * (lam * E / hmean)
        y, *_ = np.linalg.lstsq(np.vstack([J, wc * Cj, damp]),
                                np.concatenate([-e[p], wc * (d - C @ k), np.zeros(m - 1)]), rcond=None)
        dk, dx = y[:m], y[m:2 * m - 1]
        improved = False
        for alpha in (1.0, 0.5, 0.25):
            xn = knots.copy()
            xn[1:-1] += alpha * dx
            if not np.all(np.diff(xn) >= 0.3 * np.diff(knots)):
                continue
            A2, C2, d2 = model.system(xn)
            k2 = k + alpha * dk
            try:  # restore the closure exactly (least-norm change of the curvatures)
                k2 = k2 + C2.T @ np.linalg.solve(C2 @ C2.T, d2 - C2 @ k2)
            except np.linalg.LinAlgError:
                continue
            e2 = A2 @ k2 + model.b
            E2 = float(np.abs(e2).max())
            if E2 < best[0]:
                best = (E2, xn, k2, e2)
                A, C, d = A2, C2, d2
                improved = True
                break
        if not improved:
            lam *= 4.0
            if lam > 10.0:
                break
        elif E - best[0] < 1e-3 * E:
            break
    return _peak(best[3]), best[1], best[2]


def _peak(e: np.ndarray) -> float:
    """Largest ``|e|`` with every interior local extremum refined by a parabola through its neighbours."""
    ae = np.abs(e)
    j = np.clip(_local_extrema(e), 1, e.size - 2)
    a, b, c = ae[j - 1], ae[j], ae[j + 1]
    curv = a - 2 * b + c
    lift = np.where(curv < 0, -(c - a) ** 2 / (8 * np.where(curv < 0, curv, -1.0)), 0.0)
    return float(max(ae.max(), (b + np.minimum(lift, b)).max() if j.size else 0.0))


def _place_knots(s, density, m, ends=_END_ARCS, ends_hi=None):
    """``m`` arcs equidistributing ``density``, the two end arcs at each end scaled (``ends``, ``ends_hi``)."""
    ends_hi = ends if ends_hi is None else ends_hi
    w = np.ones(m)
    if m >= 4:
        w[0], w[1] = ends[0], ends[1]
        w[-1], w[-2] = ends_hi[0], ends_hi[1]
    elif m >= 2:
        if m == 3:
            w[0], w[-1] = ends[0], ends_hi[0]
    q = np.concatenate([[0.0], np.cumsum(w)]) / w.sum()
    cum = _cumtrapz(density, s)
    if not (cum[-1] > 0):
        knots = q * s[-1]
    else:
        knots = np.interp(q * cum[-1], cum, s)
    knots[0], knots[-1] = 0.0, s[-1]
    return knots


def _span_density(sur: _Surrogate, segs, target: float, n: int = 257):
    """``(t, s, density)``: arcs per unit length, ``(|κ'| / (124.7·target))^(1/3)`` (+ a turning bound).

    ``t`` holds the parameters of the grid and ``piece`` (4th value) their pieces."""
    total = sum(hi - lo for _, lo, hi in segs)
    ts, ss, ds, ps = [], [], [], []
    s_off = 0.0
    for seg in segs:
        k = max(33, int(round(n * (seg[2] - seg[1]) / total))) if len(segs) > 1 else n
        t, s0, theta = _span_model(sur, [seg], k)
        kappa = np.gradient(theta, s0)
        dk = np.abs(np.gradient(kappa, s0))
        ts.append(t)
        ss.append(s0 + s_off)
        ds.append((dk / (124.7 * target)) ** (1.0 / 3.0) + np.abs(kappa) / MAX_TURNING_RAD)
        ps.append(np.full(t.size, seg[0]))
        s_off += float(s0[-1])
    return np.concatenate(ts), np.concatenate(ss), np.concatenate(ds), np.concatenate(ps)


@dataclass
class _Span:
    """A free span: consecutive smooth pieces joined G1, ``segs`` = ``[(piece, lo, hi), ...]``.

    Its ends are clamped (point and tangent of the curve); ``fixed`` imposes the curvature of the
    first / last arc (the span ends on a circular piece joined G1, e.g. a dwell: that arc continues
    the circle and merges with its exact arcs).  ``exact`` holds the exact arcs of a span that is
    one circular piece."""

    segs: list
    fixed: tuple = (None, None)
    exact: Optional[tuple] = None
    label: int = 0

    def sample(self, n: int) -> np.ndarray:
        total = sum(hi - lo for _, lo, hi in self.segs)
        return np.concatenate([np.linspace(lo, hi, max(2, int(n * (hi - lo) / total)) + 1)[:-1]
                               for _, lo, hi in self.segs])

    def contains(self, t: float) -> bool:
        return any(lo <= t <= hi for _, lo, hi in self.segs)


def _fit_span(sur: _Surrogate, span: _Span, target: float):
    """Fewest arcs (model) for a clamped span: ``(knots, k, error)`` or None.

    The arc count starts from the asymptotic estimate ``∫ (|κ'| / (124.7·target))^(1/3) ds``;
    every count gets knots equidistributing that density (end arcs shortened at clamped ends),
    then knots and curvatures are optimised together (:func:`_equioscillate`);
    the count goes down while the span still fits ``target`` and up until it does.
    The optimum is not monotone in the count: at the smallest failing count a warm start
    and other end-arc ratios (:data:`_END_ARCS_ALT`) are tried when it failed narrowly.
    """
    _, s0, density, _ = _span_density(sur, span.segs, target)
    est = float(_cumtrapz(density, s0)[-1])
    n_fixed = sum(f is not None for f in span.fixed)
    m_min = 2 + n_fixed
    m = max(m_min, math.ceil(_EST_FACTOR * est))
    best = None
    tried: dict = {}
    models: dict = {}

    def attempt(m, ends=_END_ARCS, knots=None, fixed_ends=_FIXED_END_ARCS):
        if m not in models:
            models[m] = _SpanModel(sur, span.segs, max(_SPLINE_MIN_GRID, _SPLINE_SAMPLES * m + 1), span.fixed)
        model = models[m]
        if knots is None:
            knots = _place_knots(model.s, np.interp(model.s, s0, density), m,
                                 fixed_ends if span.fixed[0] is not None else ends,
                                 fixed_ends if span.fixed[1] is not None else ends)
        err, knots, k = _equioscillate(model, knots)
        free = np.ones(m, bool)
        free[0] = span.fixed[0] is None
        free[-1] = span.fixed[1] is None
        ok = err <= target and np.all(np.abs(k * np.diff(knots))[free] < MAX_TURNING_RAD * 1.5)
        return err, ok, (knots, k, err)

    for _ in range(12):
        if m in tried:
            break
        if m > _SPAN_MAX_ARCS:
            return None
        err, ok, fit = attempt(m)
        tried[m] = err
        if ok and (best is None or m < best[0].size - 1):
            best = fit
        if ok:
            # one arc fewer raises the error by about (m / (m - 1))³: not worth trying beyond the target
            if (m - 1) in tried or m <= m_min or err * (m / (m - 1)) ** 3 > _DOWN_SLACK * target:
                break
            m -= 1
        else:
            if best is not None and best[0].size - 1 == m + 1:
                break
            jump = math.ceil(m * (err / target) ** (1.0 / 3.0)) - m  # (a single count may fail badly)
            m = m + 1 if err < 1.6 * target else m + max(1, min(jump, math.ceil(0.1 * m) + 1))
    if best is not None:
        m = best[0].size - 2
        if m >= max(4, m_min) and m in tried and tried[m] <= 1.3 * target:
            # warm start: the optimised knots of the fitting count less the joint of the smallest
            # curvature jump (not an end arc), then other end-arc ratios
            kb, kk = best[0], best[1]
            jump = np.abs(np.diff(kk))[1:-1]
            if jump.size:
                j = 2 + int(np.argmin(jump))
                err, ok, fit = attempt(m, knots=np.delete(kb, j))
                if ok:
                    return fit
            alts = [(ends, _FIXED_END_ARCS) for ends in _END_ARCS_ALT] if n_fixed < 2 else []
            alts += [(_END_ARCS, fe) for fe in _FIXED_END_ARCS_ALT] if n_fixed else []
            for ends, fixed_ends in alts:
                err, ok, fit = attempt(m, ends, fixed_ends=fixed_ends)
                if ok:
                    return fit
    return best


def _tanlen(kk, ll):
    x = 0.5 * kk * ll
    return ll / 2 if abs(x) < 1e-12 else math.tan(x) / kk


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
    for i in range(j):
        e = _entity_point(starts[-1], tans[-1], k[i], ell[i])
        ks.append(k[i])
        ls.append(ell[i])
        starts.append(e)
        tans.append(np.array([math.cos(ang[i + 1]), math.sin(ang[i + 1])]))
    # backward from p1: arcs j + 2 … m - 1
    b_starts, b_tans = [], []
    end_p, end_ang = p1, math.atan2(t1[1], t1[0])
    for i in range(m - 1, j + 1, -1):
        ang_s = end_ang - k[i] * ell[i]
        tb = np.array([math.cos(end_ang), math.sin(end_ang)])
        sp = _entity_point(end_p, -tb, -k[i], ell[i])
        b_starts.insert(0, sp)
        b_tans.insert(0, np.array([math.cos(ang_s), math.sin(ang_s)]))
        end_p, end_ang = sp, ang_s
    d1, d2 = _tanlen(k[j], ell[j]), _tanlen(k[j + 1], ell[j + 1])
    ratio = d1 / d2 if d1 > 0 and d2 > 0 else 1.0
    tgt_t = np.array([math.cos(end_ang), math.sin(end_ang)])
    bi = _biarc(starts[-1][None], tans[-1][None], end_p[None], tgt_t[None], np.array([ratio]))
    if not bi["valid"][0]:
        bi = _biarc(starts[-1][None], tans[-1][None], end_p[None], tgt_t[None], np.array([1.0]))
        if not bi["valid"][0]:
            return None
    S = np.concatenate([np.array(starts[:j]).reshape(-1, 2), bi["s"][0], np.array(b_starts).reshape(-1, 2)])
    TT = np.concatenate([np.array(tans[:j]).reshape(-1, 2), bi["T"][0], np.array(b_tans).reshape(-1, 2)])
    K = np.concatenate([np.array(ks), bi["k"][0], k[j + 2:]])
    L = np.concatenate([np.array(ls), bi["ell"][0], ell[j + 2:]])
    parts = np.maximum(1, np.ceil(np.abs(K * L) / (0.5 * math.pi))).astype(int)
    if parts.max() > 1:  # cut long arcs (fixed dwell arcs) into parts
        idx = np.repeat(np.arange(K.size), parts)
        sub = np.arange(idx.size) - np.repeat(np.cumsum(parts) - parts, parts)
        u = L[idx] * sub / parts[idx]
        S = _entity_point(S[idx], TT[idx], K[idx], u)
        TT = _rotate(TT[idx], K[idx] * u)
        K = K[idx]
    # make every arc consistent with both its end points (ends[i] == starts[i + 1] exactly)
    S_next = np.concatenate([S[1:], [p1]])
    TT2, K2, L2, ok = _arc_from(S, TT, S_next)
    if not ok.all():
        return None
    return S, TT2, K2, L2, S_next


def _circle_pieces(curve: ParametricCurve, sur: _Surrogate, tol: float):
    """``(g1, circ, k)``: tangent continuity at every piece start, circular pieces and their curvatures.

    A piece is circular (or straight) when 17 exact samples lie within ``tol/1000`` (and 1e-10 of
    its chord) of the circle through its samples 0, 4 and 8."""
    bp = curve.breakpoints
    n = bp.size - 1
    lo, hi = bp[:-1], bp[1:]
    idx = np.arange(n)
    t_in = _unit(sur.derivative(lo, idx))
    t_out = _unit(sur.derivative(hi, idx))
    prev = np.roll(t_out, 1, axis=0)
    g1 = np.abs(np.arctan2(_cross(prev, t_in), _dot(prev, t_in))) < _G1_RAD
    tt = lo[:, None] + (hi - lo)[:, None] * np.linspace(0.0, 1.0, 17)
    pts = _points(curve, tt)
    # the tangent at the start of the circle through samples 0, 4, 8 (parallel to the line through
    # their images under inversion about sample 0): independent of derivative errors
    wb, wc = pts[:, 4] - pts[:, 0], pts[:, 8] - pts[:, 0]
    d = wc / np.maximum(_dot(wc, wc), 1e-300)[:, None] - wb / np.maximum(_dot(wb, wb), 1e-300)[:, None]
    t_in = _unit(np.where((_dot(d, wb) < 0)[:, None], -d, d))
    _, k, _, valid = _arc_from(pts[:, 0], t_in, pts[:, 4])
    w = pts - pts[:, :1]
    x, y = _dot(w, t_in[:, None]), _cross(t_in[:, None], w)
    kk = k[:, None]
    radial = np.abs(kk * (x * x + y * y) - 2.0 * y) / (np.hypot(kk * x, 1.0 - kk * y) + 1.0)
    chord = np.hypot(*(pts[:, -1] - pts[:, 0]).T)
    circ = valid & (radial.max(axis=1) <= np.minimum(1e-3 * tol, 1e-10 * chord))
    return g1, circ, k


def _segments(curve: ParametricCurve, a: float, b: float, wrap: bool) -> list:
    """``[(piece, lo, hi), ...]`` from parameter ``a`` forward to ``b`` (across the period when ``wrap``)."""
    bp = curve.breakpoints
    n = bp.size - 1
    p = int(_piece_index(curve, np.array([a]))[0])
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


def _spans(curve: ParametricCurve, sur: _Surrogate, target: float, tol: float, anchored: bool = True) -> list:
    """The free spans (:class:`_Span`) in chain order.

    Spans run between *anchors*: true corners (kept as vertices) and the middles of circular
    pieces (dwells) between G1 junctions, so arcs run across the G1 breakpoints in between.
    Without anchors (or with ``anchored`` false) every breakpoint is a span end.  Long stretches
    are cut into equal shares of about :data:`_SPLINE_SPAN` arcs, joined G1 at (surrogate) curve
    points with the curve's tangent.
    """
    bp = curve.breakpoints
    n = bp.size - 1
    g1, circ, _ = _circle_pieces(curve, sur, tol)
    anchors: dict = {}   # t -> [k of the arc ending there, k of the arc leaving it, corner]
    exact = {}
    if anchored and n > 1:
        for p in range(n):
            if not g1[p]:
                anchors[float(bp[p])] = [None, None, True]
        for p in np.flatnonzero(circ):
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
    if not anchors:
        anchors = {float(t): [None, None, False] for t in bp[:-1]}
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
        fixed = (anchors[a][1], anchors[b][0])
        if len(segs) == 1 and segs[0][0] in exact and segs[0][1] == bp[segs[0][0]]:
            out.append(_Span(segs, (None, None), exact[segs[0][0]], label))
            continue
        if not segs:
            continue
        t, s0, density, piece = _span_density(sur, segs, target)
        cum = _cumtrapz(density, s0)
        m = max(1, math.ceil(1.08 * float(cum[-1]) / _SPLINE_SPAN))
        if m == 1:
            out.append(_Span(segs, fixed, None, label))
            continue
        # cut at equal shares of the density (never on a junction)
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
        for q, sg in enumerate(pieces_segs):
            f = (fixed[0] if q == 0 else None, fixed[1] if q == len(pieces_segs) - 1 else None)
            out.append(_Span(sg, f, None, label))
    return out


def _span_ends(sur: _Surrogate, span: _Span):
    """Points and unit tangents at both ends of a span: the exact samples at breakpoints."""
    ends = []
    for piece, t in ((span.segs[0][0], span.segs[0][1]), (span.segs[-1][0], span.segs[-1][2])):
        pt = None
        for i in (sur.first[piece], sur.first[piece + 1]):
            if t == sur.x[i]:
                pt = sur.points[i] if i < sur.x.size - 1 else sur.points[0]
        if pt is None:
            pt = sur.point(np.array([t]), piece)[0]
        ends.append((pt, _unit(sur.derivative(np.array([t]), piece)[0])))
    return ends[0][0], ends[0][1], ends[1][0], ends[1][1]


def _exact_arcs(curve: ParametricCurve, sur: _Surrogate, p: int):
    """Exact arcs (each turning ≤ π/2) of the circular piece ``p``: ``(S, T, K, L, E)`` or None."""
    lo, hi = float(curve.breakpoints[p]), float(curve.breakpoints[p + 1])
    span = _Span([(p, lo, hi)])
    _, _, theta = _span_model(sur, span.segs, 33)
    n = max(1, math.ceil(abs(theta[-1] - theta[0]) / (0.5 * math.pi)))
    p0, t0, p1, _ = _span_ends(sur, span)
    pts = np.concatenate([[p0], _points(curve, lo + (hi - lo) * np.arange(1, n) / n).reshape(-1, 2), [p1]])
    S, TT, K, L = [], [], [], []
    tan = t0
    for i in range(n):
        T, k, ell, ok = _arc_from(pts[i], tan, pts[i + 1])
        if not ok:
            return None
        S.append(pts[i])
        TT.append(T)
        K.append(float(k))
        L.append(float(ell))
        tan = _rotate(T, k * ell)
    return np.array(S), np.array(TT), np.array(K), np.array(L), pts[1:]


def _fit_span_chain(curve: ParametricCurve, sur: _Surrogate, span: _Span, target: float):
    """The exact G1 arcs of one span fitted to ``target`` and the model error, or None."""
    if span.exact is not None:
        return span.exact, 0.0
    fit = _fit_span(sur, span, target)
    if fit is None:
        return None
    knots, k, err = fit
    p0, t0, p1, t1 = _span_ends(sur, span)
    chain = _span_chain(p0, t0, p1, t1, knots, k, span.fixed)
    return None if chain is None else (chain, err)


def _merge_wrap(chain: Chain, labels: np.ndarray) -> tuple[Chain, np.ndarray]:
    """Roll the chain by one entity when its last and first entities lie on one circle (G1 joint)."""
    if chain.n < 2 or labels[0] != labels[-1]:
        return chain, labels
    k, ell = chain.curvature, chain.length
    tj = chain.end_tangent[-1]
    g1 = abs(math.atan2(_cross(tj, chain.tangent[0]), _dot(tj, chain.tangent[0]))) < 1e-12
    if not (g1 and abs(k[0] - k[-1]) * (ell[0] + ell[-1]) <= LINE_SWEEP_RAD):
        return chain, labels
    roll = lambda a: np.roll(a, 1, axis=0)  # noqa: E731
    return Chain(*(roll(a) for a in (chain.start, chain.tangent, chain.curvature, chain.length, chain.end))), \
        roll(labels)


def _fit_spline(curve: ParametricCurve, sur: tuple, tol: float, anchored: bool = True):
    """The free arc spline within ``tol`` (measured on the exact curve) and its span-end parameters, or None.

    Spans are independent (their ends are fixed points with fixed tangents), so
    when the measured chain exceeds ``tol`` only the span where the maximum
    occurs is refitted, to a target lowered by the measured excess.
    """
    sur, sur_err = sur
    target = _SPLINE_FILL * tol - sur_err
    if not (target > 0):
        return None
    spans = _spans(curve, sur, target, tol, anchored)
    targets = [target] * len(spans)
    with np.errstate(invalid="ignore", divide="ignore"):
        fits = [_fit_span_chain(curve, sur, sp, target) for sp in spans]
    if any(f is None for f in fits):
        return None
    parts, errs = [f[0] for f in fits], [f[1] for f in fits]
    params = np.unique(np.append([sp.segs[0][1] for sp in spans], curve.period))
    for _ in range(_SPAN_REFITS + 1):
        cat = [np.concatenate([c[i] for c in parts]) for i in range(5)]
        labels = np.concatenate([np.full(c[0].shape[0], spans[j].label) for j, c in enumerate(parts)])
        chain, labels = _merge_wrap(Chain(*cat), labels)
        merged = _merge_cocircular(chain, labels)
        dev = measure_deviation(merged, curve)
        if dev.max <= tol:
            return merged, dev.max, params
        # refit only the offending spans: the one holding the worst deviation and every span
        # whose exact curve samples (16 per arc) lie farther than tol from the chain
        counts = [c[0].shape[0] for c in parts]
        t = [sp.sample(16 * n) for sp, n in zip(spans, counts)]
        d, _ = merged.distance(_points(curve, np.concatenate(t)))
        worst = np.maximum.reduceat(d, np.concatenate([[0], np.cumsum([x.size for x in t])[:-1]]))
        at = float(dev.at_param)
        j = next((i for i, sp in enumerate(spans) if sp.contains(at)), None)
        if j is not None:
            worst[j] = max(worst[j], dev.max)
        for j in np.flatnonzero(worst > 0.99 * tol):
            if spans[j].exact is not None:
                return None
            # the measured / model ratio of this span scales its next target
            targets[j] = min(0.98 * targets[j], 0.97 * tol * errs[j] / worst[j])
            with np.errstate(invalid="ignore", divide="ignore"):
                fit = _fit_span_chain(curve, sur, spans[j], targets[j])
            if fit is None:
                return None
            parts[j], errs[j] = fit
    return None
