"""Integrals between breakpoints: :func:`integrate`, adaptive 20-point Gauss–Legendre, vectorised; re-exported by
:mod:`camfab.numeric`, whose conventions it shares (a vectorised ``f(x)``, smooth between increasing ``edges``)."""
from __future__ import annotations

import logging
from collections.abc import Callable

import numpy as np

__all__ = ["integrate"]

log = logging.getLogger(__name__)

_GAUSS20 = np.polynomial.legendre.leggauss(20)


def _gauss_nodes(iv: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """20-point Gauss–Legendre nodes (k, 20) of the intervals ``iv`` (k, 2), and their half widths."""
    mid, half = (iv[:, 0] + iv[:, 1]) / 2, (iv[:, 1] - iv[:, 0]) / 2
    return mid[:, None] + half[:, None] * _GAUSS20[0][None, :], half


def integrate(f: Callable[[np.ndarray], np.ndarray], edges, *, rtol: float = 1e-11, atol: float = 0.0) -> float:
    """∫ f between breakpoints by adaptive 20-point Gauss–Legendre, vectorised (one call of f per pass):
    every interval is halved until its halves agree with it to ``(rtol·|∫f| + atol)`` times its share
    of the span (at most 40 passes, 2¹⁶ open intervals; a non-finite half is not split again, so a
    non-integrable f gives inf or NaN).  Give ``atol`` where the integral may cancel to ~0."""
    wg = _GAUSS20[1]
    edges = np.asarray(edges, dtype=float)
    todo = np.stack([edges[:-1], edges[1:]], axis=1)
    todo = todo[todo[:, 1] > todo[:, 0]]
    pts, half = _gauss_nodes(todo)
    whole = half * (np.asarray(f(pts.ravel()), dtype=float).reshape(pts.shape) @ wg)
    total, scale = 0.0, max(abs(whole.sum()), 1e-300)
    span = edges[-1] - edges[0]
    for _ in range(40):
        if not 0 < len(todo) <= 2**16:
            break
        mid = (todo[:, 0] + todo[:, 1]) / 2
        left, right = np.stack([todo[:, 0], mid], 1), np.stack([mid, todo[:, 1]], 1)
        pl, hl = _gauss_nodes(left)
        pr, hr = _gauss_nodes(right)
        v = np.asarray(f(np.concatenate([pl.ravel(), pr.ravel()])), dtype=float)
        ql = hl * (v[:pl.size].reshape(pl.shape) @ wg)
        qr = hr * (v[pl.size:].reshape(pr.shape) @ wg)
        ok = np.abs(ql + qr - whole) <= (rtol * scale + atol) * (todo[:, 1] - todo[:, 0]) / span + 1e-300
        ok |= ~np.isfinite(ql + qr)
        total += float((ql + qr)[ok].sum())
        todo = np.concatenate([left[~ok], right[~ok]])
        whole = np.concatenate([ql[~ok], qr[~ok]])
    if len(todo):
        log.warning("integrate over [%g, %g]: %d interval(s) not converged to rtol = %g, atol = %g after the pass or "
                    "interval cap; their last estimate is used", edges[0], edges[-1], len(todo), rtol, atol)
    return total + float(whole.sum())
