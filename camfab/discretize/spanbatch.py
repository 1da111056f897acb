"""The first two-arc fit of many clamped spans at once (one batched model build and solve).

A long stretch of short smooth pieces (e.g. 1000 cycloidal segments) is cut into hundreds of spans whose first
arc count is the fewest, two arcs (the closing biarc alone).  Their fit is the minimax (Lawson) fit of
:class:`~camfab.discretize.spanmodel.SpanModel` with no free curvature left (the closure fixes both), so every
span costs a model build, one system and one least-squares solve: a few hundred numpy calls for little
arithmetic each.  :func:`two_arc_fits` builds the models of all such spans as stacked arrays and evaluates the
system for all of them in one pass.  Every value that decides the arcs (knots, curvatures) is computed with the
same element-wise operations as the per-span code, so the arcs are the same bit for bit; the error (only compared
with the target) comes from a stacked matrix product.
"""
from __future__ import annotations

import numpy as np

from ..geom2d import cross, dot
from .entities import MAX_TURNING_RAD
from .spanmodel import peak, stacked_span_model

__all__ = ["two_arc_fits", "TWO_ARC_GRID", "MIN_BATCH"]

#: the model grid of a two-arc span (``max(_SPLINE_MIN_GRID, _SPLINE_SAMPLES·2 + 1)`` in arcspline)
TWO_ARC_GRID = 129
#: fewest spans worth a batch (below this the per-span path runs)
MIN_BATCH = 8


def _cumhermite(f: np.ndarray, fp: np.ndarray, s: np.ndarray) -> np.ndarray:
    """Stacked :func:`~camfab.discretize.spanmodel._cumhermite`: ``f``, ``fp`` ``(S, n, 2)``, ``s`` ``(S, n)``."""
    ds = np.diff(s, axis=1)[..., None]
    inc = 0.5 * ds * (f[:, 1:] + f[:, :-1]) + ds * ds / 12.0 * (fp[:, :-1] - fp[:, 1:])
    return np.concatenate([np.zeros((f.shape[0], 1, f.shape[2])), np.cumsum(inc, axis=1)], axis=1)


def _models(sur, segs: list, n: int):
    """Stacked :func:`~camfab.discretize.spanmodel.span_model` (curvature too) and
    :class:`~camfab.discretize.spanmodel.SpanModel` fields of single-piece spans."""
    t, s, theta, d, sp, piece = stacked_span_model(sur, segs, n)
    kappa = cross(d, sur.second_derivative(t, piece)) / np.maximum(sp, 1e-300) ** 3
    tng = np.stack([np.cos(theta), np.sin(theta)], axis=-1)
    nrm = np.stack([-np.sin(theta), np.cos(theta)], axis=-1)
    dn = -kappa[..., None] * tng
    dth = (theta[:, :1] - theta)[..., None]
    N = _cumhermite(nrm, dn, s)
    Dt = _cumhermite(dth * nrm, -kappa[..., None] * nrm + dth * dn, s)
    m0, m1 = s[..., None] * nrm, nrm + s[..., None] * dn
    M = _cumhermite(m0, m1, s)
    return {"s": s, "theta": theta, "nrm": nrm, "N": N, "Dt": Dt, "b": dot(Dt, nrm), "nN": dot(nrm, N),
            "nM": dot(nrm, M), "nm": (np.concatenate([N, M], axis=-1), np.concatenate([nrm, m0], axis=-1),
                                       np.concatenate([dn, m1], axis=-1))}


def _hermite_at(x: np.ndarray, s: np.ndarray, F: np.ndarray, f: np.ndarray, fp: np.ndarray) -> np.ndarray:
    """Stacked :func:`~camfab.discretize.spanmodel._hermite_at`: ``x`` ``(S, q)``, ``s`` ``(S, n)``."""
    i = (s[:, None, :] <= x[:, :, None]).sum(axis=-1) - 1  # searchsorted(side="right") - 1, row by row
    i = np.minimum(np.maximum(i, 0), s.shape[1] - 2)
    row = np.arange(s.shape[0])[:, None]
    h = s[row, i + 1] - s[row, i]
    tau = np.minimum(np.maximum((x - s[row, i]) / np.where(h > 0, h, 1.0), 0.0), 1.0)
    t2, t3, t4 = tau * tau, tau ** 3, tau ** 4
    w = (h * (tau - t3 + 0.5 * t4), h * h * (0.25 * t4 - 2.0 * t3 / 3.0 + 0.5 * t2),
         h * (t3 - 0.5 * t4), h * h * (0.25 * t4 - t3 / 3.0))
    return (F[row, i] + w[0][..., None] * f[row, i] + w[1][..., None] * fp[row, i] + w[2][..., None] * f[row, i + 1]
            + w[3][..., None] * fp[row, i + 1])


def _system(mod: dict, knots: np.ndarray):
    """Stacked ``SpanModel.system`` of two-arc knots ``(S, 3)``: ``(A, C, d)``."""
    s, nrm, nN = mod["s"], mod["nrm"], mod["nN"]
    v = _hermite_at(knots, s, *mod["nm"])
    Nx, Mx = v[..., :2], v[..., 2:]
    G = Mx - knots[..., None] * Nx
    ell = np.diff(knots, axis=1)
    m = ell.shape[1]
    A = np.matmul(nrm, np.swapaxes(G[:, 1:] - G[:, :-1], 1, 2)) + nN[..., None] * ell[:, None, :]
    jj = (knots[:, None, :] <= s[:, :, None]).sum(axis=-1) - 1
    jj = np.minimum(np.maximum(jj, 0), m - 1)
    A[np.arange(m)[None, None, :] >= jj[..., None]] = 0.0
    row = np.arange(s.shape[0])[:, None]
    Gj = G[row, jj]
    A[row, np.arange(s.shape[1])[None, :], jj] = mod["nM"] - knots[row, jj] * nN - dot(nrm, Gj)
    N_end = mod["N"][:, -1]
    Dk_end = (Mx[:, 1:] - Mx[:, :-1]) - knots[:, :-1, None] * (Nx[:, 1:] - Nx[:, :-1]) \
        + ell[..., None] * (N_end[:, None] - Nx[:, 1:])
    scale = s[:, -1] / m
    C = np.concatenate([(ell * scale[:, None])[:, None, :], np.swapaxes(Dk_end, 1, 2)], axis=1)
    d = np.concatenate([((mod["theta"][:, -1] - mod["theta"][:, 0]) * scale)[:, None], -mod["Dt"][:, -1]], axis=1)
    return A, C, d


def two_arc_fits(sur, fits: list, target: float, place_knots) -> dict:
    """``{index: (error, fits, (knots, k, error))}``: the two-arc attempt of ``fits[index]`` (``_SpanFit`` objects
    of free single-piece spans), as ``_SpanFit.attempt(2)`` gives it; spans whose closure is rank deficient are
    left out (the per-span path fits them)."""
    if len(fits) < MIN_BATCH:
        return {}
    mod = _models(sur, [f.span.segs[0] for f in fits], TWO_ARC_GRID)
    knots = np.array([place_knots(s, np.interp(s, f.s0, f.density), 2) for s, f in zip(mod["s"], fits, strict=True)])
    A, C, d = _system(mod, knots)
    sv = np.linalg.svd(C, compute_uv=False)
    out = {}
    for i in np.flatnonzero(sv[:, -1] > 1e-9 * sv[:, 0]).tolist():
        k, *_ = np.linalg.lstsq(C[i], d[i], rcond=None)  # (the Lawson fit: no free curvature left)
        e = A[i] @ k + mod["b"][i]
        err = peak(e)
        ok = err <= target and bool(np.all(np.abs(k * np.diff(knots[i])) < MAX_TURNING_RAD * 1.5))
        out[i] = (err, ok, (knots[i], k, err))
    return out
