"""The linear model of a G1 arc spline's normal deviation from one span of a curve, and its minimax fit.

On a span (consecutive smooth pieces joined G1, parametrised by arc length) the arcs are given by
their knots and curvatures; to first order the normal deviation is linear in the curvatures, with
prefix integrals exact for the cubic Hermite data of the surrogate.  :func:`equioscillate` optimises
knots and curvatures together until the local extrema of the deviation share one level.
"""
from __future__ import annotations

from typing import Literal

import numpy as np

from ..geom2d import TWO_PI, cross, dot
from .surrogate import HermiteSurrogate

__all__ = ["span_model", "stacked_span_model", "cumtrapz", "SpanModel", "lawson_start", "equioscillate", "peak"]


#: Lawson (minimax) reweighting iterations of the curvatures of given knots
_LAWSON_ITERS = 8
#: Gauss-Newton rounds equalising the arc errors (knots and curvatures together)
_EQUI_ITERS = 8
#: a failed step ends the rounds when every local extremum of the deviation lies within this share of the largest
_EQUI_LEVEL = 0.01


def span_model(sur: HermiteSurrogate, segs, n_grid: int, curvature: bool = False):
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
            ks.append(cross(d, sur.second_derivative(t, piece)) / np.maximum(sp, 1e-300) ** 3)
        s_off, th_off = float(sv[-1]), float(theta[-1])
    out = (np.concatenate(ts), np.concatenate(ss), np.concatenate(ths))
    return out + (np.concatenate(ks),) if curvature else out


def stacked_span_model(sur: HermiteSurrogate, segs: list, n: int):
    """:func:`span_model` of many one-piece spans ``[(piece, lo, hi)]`` at once, a row each: ``(t, s, theta, d,
    speed, piece)`` (``d``: the surrogate's derivative at ``t``, ``speed`` its norm, ``piece`` a column).  Every
    value is the same element-wise operation as :func:`span_model`'s, so the rows are its values bit for bit."""
    piece = np.array([sg[0] for sg in segs])[:, None]
    t = np.linspace(np.array([sg[1] for sg in segs], dtype=float), np.array([sg[2] for sg in segs], dtype=float), n,
                    axis=1)
    tm = 0.5 * (t[:, :-1] + t[:, 1:])
    d, dm = sur.derivative(t, piece), sur.derivative(tm, piece)
    sp, spm = np.hypot(d[..., 0], d[..., 1]), np.hypot(dm[..., 0], dm[..., 1])
    inc = (t[:, 1:] - t[:, :-1]) / 6.0 * (sp[:, :-1] + 4 * spm + sp[:, 1:])
    s = np.concatenate([np.zeros((t.shape[0], 1)), np.cumsum(inc, axis=1)], axis=1)
    theta = np.unwrap(np.arctan2(d[..., 1], d[..., 0]), axis=1)
    return t, s, theta, d, sp, piece


def cumtrapz(f: np.ndarray, s: np.ndarray) -> np.ndarray:
    """Cumulative trapezoid integral of ``f`` ``(n, ...)`` over the grid ``s`` ``(n,)``, 0 first."""
    ds = np.diff(s).reshape((-1,) + (1,) * (f.ndim - 1))
    return np.concatenate([np.zeros((1,) + f.shape[1:]), np.cumsum(0.5 * ds * (f[1:] + f[:-1]), axis=0)])


def _cumhermite(f: np.ndarray, fp: np.ndarray, s: np.ndarray) -> np.ndarray:
    """Cumulative integral of ``f`` (derivative ``fp``) on the grid ``s``: exact for piecewise cubics."""
    ds = np.diff(s).reshape((-1,) + (1,) * (f.ndim - 1))
    inc = 0.5 * ds * (f[1:] + f[:-1]) + ds * ds / 12.0 * (fp[:-1] - fp[1:])
    return np.concatenate([np.zeros((1,) + f.shape[1:]), np.cumsum(inc, axis=0)])


def _hermite_rows(F: np.ndarray, f: np.ndarray, fp: np.ndarray) -> np.ndarray:
    """The table :func:`_hermite_at` reads, one row per grid interval: ``F``, ``f``, ``fp`` at its start, ``f``,
    ``fp`` at its end."""
    return np.hstack([F[:-1], f[:-1], fp[:-1], f[1:], fp[1:]])


def _hermite_at(x: np.ndarray, grid: tuple, rows: np.ndarray) -> np.ndarray:
    """``F(x) = ∫₀ˣ f`` between grid points: integral of the cubic Hermite interpolant of ``f`` (``rows``: the
    :func:`_hermite_rows` of ``F``, ``f``, ``fp``; ``grid``: the :func:`_hermite_grid` of the grid ``s``).

    The interval of ``x`` is ``searchsorted(s[1:-1], x, "right")``: the number of grid points ``<= x`` less one,
    clipped to ``[0, n - 2]`` (the first point counts for every ``x >= s[0]`` and no inner one below it, the last
    only where the clip gives ``n - 2`` anyway), one call instead of four; the interval widths are the grid's,
    computed once."""
    inner, lo, width, safe = grid
    i = inner.searchsorted(x, side="right")  # (the method: np.searchsorted's wrapper costs as much as the search)
    h = width[i]
    tau = np.minimum(np.maximum((x - lo[i]) / safe[i], 0.0), 1.0)
    t2, t3, t4 = tau * tau, tau ** 3, tau ** 4
    hh, h4, q4 = h * h, 0.5 * t4, 0.25 * t4  # (each used twice: the same values)
    w = (h * (tau - t3 + h4), hh * (q4 - 2.0 * t3 / 3.0 + 0.5 * t2), h * (t3 - h4), hh * (q4 - t3 / 3.0))
    r = rows[i]
    q = r.shape[1] // 5
    return (r[:, :q] + w[0][:, None] * r[:, q:2 * q] + w[1][:, None] * r[:, 2 * q:3 * q]
            + w[2][:, None] * r[:, 3 * q:4 * q] + w[3][:, None] * r[:, 4 * q:])


def _hermite_grid(s: np.ndarray) -> tuple:
    """What :func:`_hermite_at` reads of the grid ``s``: its inner points, interval starts and widths, and the
    widths with empty intervals (a junction's two points) as 1."""
    width = s[1:] - s[:-1]
    return s[1:-1], s[:-1], width, np.where(width > 0, width, 1.0)


def _stack_order(fortran: bool) -> Literal["C", "F"]:
    """The memory order of a matrix preallocated for what ``np.vstack`` / ``np.hstack`` used to assemble.

    ``np.concatenate`` lays its result out like its inputs: Fortran order only when every input with no axis of
    length 1 is Fortran-ordered, else C order (numpy's ``PyArray_CreateMultiSortedStridePerm``), and the BLAS
    products of a matrix round differently in the two orders (the kernel a product takes depends on it: a
    closure matrix filled in C order changed an example's arcs, docs/decisions.md).  So each preallocated matrix
    takes the order its stacking gave: ``fortran`` is that condition worked out for its inputs (a transposed
    ``(m, 2)`` block is Fortran-ordered, a single row has an axis of length 1)."""
    return "F" if fortran else "C"


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
        H.reshape(-1)[::H.shape[0] + 1] += 1e-14 * H.trace() + 1e-300  # (its diagonal)
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


class SpanModel:
    """Linear model of the normal deviation of a G1 arc spline from one smooth piece.

    The arcs are parametrised by the arc length ``s`` of the piece: with knots
    ``x`` (arc ends) and curvatures ``k`` the spline's tangent angle is
    ``φ(s) = θ(0) + Σ k_j·clip(s - x_j, 0, ℓ_j)``; to first order its point at
    ``s`` is ``P(s) + V(s)`` with ``V(s) = ∫₀ˢ (φ - θ)·n ds'``, and the normal
    deviation is ``e(s) = n(s)·V(s) = A k + b``.  The spline starts at the
    piece's first point with its tangent; ``C k = d`` closes it on the last
    point with its tangent (first order; the last two arcs are re-fitted exactly).
    """

    def __init__(self, sur: HermiteSurrogate, segs, n_grid: int, fixed=(None, None)):
        _, s, theta, kappa = span_model(sur, segs, n_grid, curvature=True)
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
        self.b = dot(self.Dt, nrm)
        self.M = _cumhermite(*self.m_fp, s)                              # ∫ s·n ds
        self.nN, self.nM = dot(nrm, self.N), dot(nrm, self.M)
        self._nm = _hermite_rows(np.hstack([self.N, self.M]), np.hstack([nrm, self.m_fp[0]]),
                                 np.hstack([dn, self.m_fp[1]]))
        self._last_key: bytes | None = None
        self._grid = _hermite_grid(s)
        self._grid_rows = np.arange(s.size)
        self._before: dict = {}  # per arc count: row j marks the arcs before arc j
        self._n0, self._n1 = nrm[:, 0].copy(), nrm[:, 1].copy()
        self._rows: dict = {}  # the rows of the fixed curvatures, per arc count
        self._last_nm: tuple[np.ndarray, np.ndarray] = (np.empty((0, 2)), np.empty((0, 2)))

    def NM_at(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(N(x), M(x))`` between grid points (the last query is cached)."""
        key = x.tobytes()
        if self._last_key != key:
            v = _hermite_at(x, self._grid, self._nm)
            self._last_key, self._last_nm = key, (v[:, :2], v[:, 2:])
        return self._last_nm

    def system(self, knots: np.ndarray):
        """``(A, C, d)`` of the knots: ``e = A k + b`` on the grid, ``C k = d`` closes the span."""
        C, d, parts = self.closure(knots)
        return self.matrix(knots, parts), C, d

    def closure(self, knots: np.ndarray):
        """``(C, d, parts)`` of the knots: ``C k = d`` closes the span; ``parts`` (what :meth:`matrix` and
        :meth:`deviation` share): arc lengths, ``G = M - x·N`` at the knots, the arc of every grid point.

        The knots increase (placed by a cumulative density, moved only while every arc keeps a share of its
        length), so the arc of a grid point, the number of knots ``<= s`` less one clipped to ``[0, m - 1]``, is
        the number of interior knots ``<= s`` (one ``searchsorted``, as in :func:`_hermite_at`).  ``C`` is filled
        in place, in the memory order ``np.vstack([ℓ·L/m, Dk_endᵀ, fixed rows])`` gave it (:func:`_stack_order`:
        Fortran unless there are two fixed rows), so that every product with it rounds as before."""
        ell = knots[1:] - knots[:-1]
        # V_j(s) = ∫ clip(s' - x_j, 0, ℓ_j)·n ds' from the prefix integrals N = ∫ n, M = ∫ s'·n:
        # after arc j (s > x_{j+1}) n·V_j = n·W_j + ℓ_j·n·N(s), W_j = [M - x·N] from x_j to x_{j+1};
        # inside it n·V_j = n·M(s) - x_j·n·N(s) - n·(M(x_j) - x_j·N(x_j)); before it 0
        Nx, Mx = self.NM_at(knots)
        G = Mx - knots[:, None] * Nx                                        # (m + 1, 2)
        m = ell.size
        jj = knots[1:-1].searchsorted(self.s, side="right")
        Dk_end = (Mx[1:] - Mx[:-1]) - knots[:-1, None] * (Nx[1:] - Nx[:-1]) + ell[:, None] * (self.N[-1] - Nx[1:])
        rows, d = self._fixed_rows(m)
        C = np.empty((3 + rows.shape[0], m), order=_stack_order(rows.shape[0] < 2))
        np.multiply(ell, self.L / m, out=C[0])
        C[1:3] = Dk_end.T
        C[3:] = rows
        return C, d, (ell, G, jj)

    def matrix(self, knots: np.ndarray, parts) -> np.ndarray:
        """``A`` (``e = A k + b`` on the grid) of the knots (``parts`` from :meth:`closure`).

        Row ``i`` keeps the arcs before its own (columns ``< jj[i]``): row ``jj[i]`` of a per-count table, one
        ``take`` instead of a broadcast comparison; the gathers are ``take`` s too, and ``n·G`` the sum of
        :func:`~camfab.geom2d.dot` on contiguous columns (the same products and sums)."""
        ell, G, jj = parts
        m = ell.size
        full = self.nrm @ (G[1:] - G[:-1]).T
        full += self.nN[:, None] * ell[None, :]  # (in place: the same sums, one (n, m) array fewer)
        before = self._before.get(m)
        if before is None:
            before = self._before[m] = np.arange(m)[None, :] < np.arange(m)[:, None]
        A = np.where(before.take(jj, axis=0), full, 0.0)
        Gj = G.take(jj, axis=0)
        A[self._grid_rows, jj] = self.nM - knots.take(jj) * self.nN - (self._n0 * Gj[:, 0] + self._n1 * Gj[:, 1])
        return A

    def _fixed_rows(self, m: int):
        """The rows of the fixed curvatures of ``m`` arcs and the whole right-hand side ``d`` of the closure."""
        if m not in self._rows:
            rows, vals = self._make_fixed_rows(m)
            scale = self.L / m
            self._rows[m] = rows, np.concatenate([[(self.theta[-1] - self.theta[0]) * scale], -self.Dt[-1], vals])
        return self._rows[m]

    def _make_fixed_rows(self, m: int):
        rows, vals = [], []
        for j, kf in ((0, self.fixed[0]), (m - 1, self.fixed[1])):
            if kf is not None:
                r = np.zeros(m)
                r[j] = self.L
                rows.append(r)
                vals.append(kf * self.L)
        return np.array(rows).reshape(-1, m), np.array(vals)

    def knot_jacobian(self, knots: np.ndarray, k: np.ndarray, p: np.ndarray, out: np.ndarray) -> np.ndarray:
        """Derivatives of ``e`` at the grid points ``p`` and of ``C k - d`` with respect to the interior knots.

        Moving knot ``x_j`` by ``δ`` turns every later tangent by ``(k_{j-1} - k_j)·δ``.  The closure rows go
        to ``out`` (``C.shape[0]`` rows, those of the fixed curvatures 0); the grid rows are returned, only those
        of ``p`` computed (each element is the same product of its own row either way).
        """
        xi = knots[1:-1]
        Nx = self.NM_at(knots)[0][1:-1]
        jump = k[:-1] - k[1:]
        if p.size < 2:  # (one row would be numpy's vector-matrix product, which may round otherwise)
            B = np.where(self.s[:, None] <= xi[None, :], 0.0, (self.nN[:, None] - self.nrm @ Nx.T) * jump)[p]
        else:
            B = np.where(self.s[p, None] <= xi[None, :], 0.0, (self.nN[p, None] - self.nrm[p] @ Nx.T) * jump)
        np.multiply(jump, self.L / k.size, out=out[0])
        out[1:3] = ((self.N[-1][None] - Nx) * jump[:, None]).T
        out[3:] = 0.0
        return B


def _local_extrema(e: np.ndarray) -> np.ndarray:
    """Grid indices where ``|e|`` has a local maximum."""
    ae = np.abs(e)
    keep = ae > 0
    keep[1:] &= ae[1:] >= ae[:-1]
    keep[:-1] &= ae[:-1] >= ae[1:]
    return np.flatnonzero(keep)


def _normal_equations(J: np.ndarray, r: np.ndarray):
    """``(J, r, JᵀJ, Jᵀr, scale)`` of the least-squares problem ``J y ≈ r``, its columns scaled to unit norm."""
    scale = np.sqrt(np.einsum("ij,ij->j", J, J))
    scale = 1.0 / np.where(scale > 0, scale, 1.0)
    Js = J * scale
    return J, r, Js.T @ Js, Js.T @ r, scale


def _damped_step(lin, m: int, mu: float) -> np.ndarray:
    """The Levenberg step ``y`` minimising ``|J y - r|² + mu²·|dx|²`` (the knot moves ``dx`` = ``y[m:2m-1]``):
    the normal equations of the column-scaled system (a Cholesky-sized solve instead of an SVD least squares),
    the SVD least squares only when they are singular."""
    J, r, H, g, scale = lin
    H = H.copy()
    n = H.shape[0]
    H.reshape(-1)[m * (n + 1):(2 * m - 1) * (n + 1):n + 1] += (mu * scale[m:2 * m - 1]) ** 2  # (its diagonal)
    try:
        y = np.linalg.solve(H, g) * scale
    except np.linalg.LinAlgError:
        y = None
    if y is None or not np.isfinite(y).all():
        damp = np.zeros((m - 1, 2 * m))
        damp[:, m:2 * m - 1] = np.eye(m - 1) * mu
        y, *_ = np.linalg.lstsq(np.vstack([J, damp]), np.concatenate([r, np.zeros(m - 1)]), rcond=None)
    return y


def _linearisation(model: SpanModel, A: np.ndarray, C: np.ndarray, d: np.ndarray, knots: np.ndarray, k: np.ndarray,
                   e: np.ndarray, p: np.ndarray):
    """:func:`_normal_equations` of the Gauss-Newton step at the extrema ``p``: the system
    ``[[A[p], B[p], -sign(e[p])], wc·[C, Bc, 0]] y ≈ [-e[p], wc·(d - C k)]`` (``B``, ``Bc``: the
    :meth:`~SpanModel.knot_jacobian`; ``wc`` weighs the closure rows to 1e3 of its largest entry).

    The matrix is filled in place, in the memory order ``np.vstack([np.hstack(...), ...])`` gave it
    (:func:`_stack_order`: Fortran only for one extremum and fewer than two fixed rows)."""
    m, n_p = k.size, p.size
    J = np.empty((n_p + C.shape[0], 2 * m), order=_stack_order(n_p == 1 and C.shape[0] < 5))
    Cj = J[n_p:]
    J[:n_p, :m] = A[p]
    J[:n_p, m:2 * m - 1] = model.knot_jacobian(knots, k, p, Cj[:, m:2 * m - 1])
    ep = e[p]
    np.negative(np.sign(ep), out=J[:n_p, 2 * m - 1])
    Cj[:, :m] = C
    Cj[:, 2 * m - 1] = 0.0
    wc = 1e3 / max(float(np.abs(Cj).max()), 1e-300)
    Cj *= wc
    r = np.empty(J.shape[0])
    np.negative(ep, out=r[:n_p])
    np.multiply(wc, d - C @ k, out=r[n_p:])
    return _normal_equations(J, r)


def lawson_start(model: SpanModel, knots: np.ndarray):
    """Where :func:`equioscillate` starts from ``knots``: ``(A, C, d, k, e)``, the system of the knots and the
    (approximate) minimax curvatures ``k`` with their deviation ``e`` on the grid."""
    A, C, d = model.system(knots)
    k, e = _lawson(A, model.b, C, d, iters=4)
    return A, C, d, k, e


def equioscillate(model: SpanModel, knots: np.ndarray, iters: int = _EQUI_ITERS, start=None):
    """Jointly optimise knots and curvatures of a clamped span: ``(max |e|, knots, k)``.

    Starts from the (approximate) minimax curvatures of the given knots, then
    Gauss-Newton steps on knots and curvatures together drive every local
    extremum of the deviation to one common level (a Remez-like exchange: the
    extrema are re-located after every step), the knot moves damped
    (Levenberg) and each step accepted only if the largest deviation drops.
    ``start``: :func:`lawson_start` of ``knots``, when already made.
    """
    A, C, d, k, e = lawson_start(model, knots) if start is None else start
    best = (float(np.abs(e).max()), knots, k, e)
    m = k.size
    if m < 3:
        return peak(e), knots, k
    lam = 1e-2
    hmean = model.L / m
    lin = None  # the linearisation at ``best`` (kept while steps fail: only the damping changes)
    for _ in range(iters):
        emax, knots, k, e = best
        if lin is None:
            p = _local_extrema(e)
            lin = _linearisation(model, A, C, d, knots, k, e, p)
            level = np.abs(e[p])
            level_spread = 1.0 - float(level.min()) / emax if level.size else 1.0
        y = _damped_step(lin, m, lam * emax / hmean)
        dk, dx = y[:m], y[m:2 * m - 1]
        improved = False
        shortest = 0.3 * (knots[1:] - knots[:-1])
        for alpha in (1.0, 0.5, 0.25):
            xn = knots.copy()
            xn[1:-1] += alpha * dx
            if not (xn[1:] - xn[:-1] >= shortest).all():
                continue
            C2, d2, parts = model.closure(xn)
            k2 = k + alpha * dk
            try:  # restore the closure exactly (least-norm change of the curvatures)
                k2 = k2 + C2.T @ np.linalg.solve(C2 @ C2.T, d2 - C2 @ k2)
            except np.linalg.LinAlgError:
                continue
            A2 = model.matrix(xn, parts)
            e2 = A2 @ k2 + model.b
            emax2 = float(np.abs(e2).max())
            if emax2 < best[0]:
                best = (emax2, xn, k2, e2)
                A, C, d = A2, C2, d2
                improved, lin = True, None
                break
        if not improved:  # extrema level within _EQUI_LEVEL: minimax reached, more damping buys only that spread
            lam *= 4.0
            if lam > 10.0 or level_spread <= _EQUI_LEVEL:
                break
        elif emax - best[0] < 1e-3 * emax:
            break
    return peak(best[3]), best[1], best[2]


def peak(e: np.ndarray) -> float:
    """Largest ``|e|`` with every interior local extremum refined by a parabola through its neighbours."""
    ae = np.abs(e)
    j = np.clip(_local_extrema(e), 1, e.size - 2)
    a, b, c = ae[j - 1], ae[j], ae[j + 1]
    curv = a - 2 * b + c
    lift = np.where(curv < 0, -(c - a) ** 2 / (8 * np.where(curv < 0, curv, -1.0)), 0.0)
    return float(max(ae.max(), (b + np.minimum(lift, b)).max() if j.size else 0.0))
