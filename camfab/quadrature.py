"""Integrals between breakpoints: :func:`integrate`, adaptive 20-point Gauss–Legendre, vectorised; re-exported by
:mod:`camfab.numeric`, whose conventions it shares (a vectorised ``f(x)``, smooth between increasing ``edges``).

The work is bounded whatever the integrand (see docs/decisions.md, "Search budgets"): at most :data:`MAX_PASSES`
passes, and a pass refines at most :data:`MAX_OPEN` intervals (one call of ``f`` with at most
``2·20·MAX_OPEN`` points), so a steep integrand costs the same fixed budget as a singular one.  Within it, an
interval is done when its halves agree with it to its share of the tolerance; once more than
:data:`GLOBAL_FROM` intervals are open (a steep or noisy integrand: no ordinary cam gets near), the summed error
estimate of the open intervals decides instead.  :func:`integral` says whether the tolerance was met."""
from __future__ import annotations

import logging
from collections.abc import Callable
from typing import NamedTuple

import numpy as np

__all__ = ["integrate", "integral", "Integral", "MAX_OPEN", "MAX_PASSES", "GLOBAL_FROM", "NOISE", "GAUSS_LEGENDRE_20"]

log = logging.getLogger(__name__)


#: the 20-point Gauss–Legendre rule on [-1, 1]: the positive nodes and their weights, as
#: ``numpy.polynomial.legendre.leggauss(20)`` gives them (bit for bit; a test compares) — written out, so that a
#: check does not import numpy.polynomial (~5 ms of every start)
_NODES_POS = (0.07652652113349734, 0.22778585114164507, 0.37370608871541955, 0.5108670019508271, 0.636053680726515,
              0.7463319064601508, 0.8391169718222188, 0.912234428251326, 0.9639719272779138, 0.993128599185095)
_WEIGHTS_POS = (0.15275338713072628, 0.14917298647260424, 0.1420961093183824, 0.1316886384491769, 0.1181945319615186,
                0.1019301198172407, 0.08327674157670471, 0.06267204833410879, 0.040601429800386446,
                0.017614007139150893)
GAUSS_LEGENDRE_20 = (np.concatenate([-np.array(_NODES_POS[::-1]), _NODES_POS]),
            np.concatenate([_WEIGHTS_POS[::-1], _WEIGHTS_POS]))
#: the budget: passes, and intervals refined per pass (each pass evaluates f at 40 points per open interval)
MAX_PASSES, MAX_OPEN = 40, 2**13
#: open intervals beyond which the summed error of the open intervals decides (the local test alone would
#: split an integrand whose halves differ by rounding for ever)
GLOBAL_FROM = 256
#: the error floor of a cancelling integrand, relative to ∫|f| (~4096 ulps)
NOISE = 2.0**-40


class Integral(NamedTuple):
    """An integral, the estimate of its error, the error it had to reach, and the parameter interval that held
    the largest error share when the budget ran out (``(nan, nan)`` when converged)."""

    value: float
    error: float
    tolerance: float
    worst: tuple[float, float]

    @property
    def converged(self) -> bool:
        """The error estimate is within the tolerance (NaN never is)."""
        return bool(self.error <= self.tolerance)


def _gauss_nodes(iv: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """20-point Gauss–Legendre nodes (k, 20) of the intervals ``iv`` (k, 2), and their half widths."""
    mid, half = (iv[:, 0] + iv[:, 1]) / 2, (iv[:, 1] - iv[:, 0]) / 2
    return mid[:, None] + half[:, None] * GAUSS_LEGENDRE_20[0][None, :], half


def integral(f: Callable[[np.ndarray], np.ndarray], edges, *, rtol: float = 1e-11, atol: float = 0.0) -> Integral:
    """∫ f between breakpoints by adaptive 20-point Gauss–Legendre, vectorised (one call of f per pass): every
    interval is halved until its halves agree with it to ``(rtol·|∫f| + atol)`` times its share of the span;
    beyond :data:`GLOBAL_FROM` open intervals it is done when the open intervals' summed disagreement is within
    ``max(rtol·|∫f|, NOISE·∫|f|) + atol``.  At most :data:`MAX_PASSES` passes of at most :data:`MAX_OPEN`
    intervals; a non-finite half is not split again (a non-integrable f gives inf or NaN, not converged).
    Give ``atol`` where the integral may cancel to ~0."""
    wg = GAUSS_LEGENDRE_20[1]
    edges = np.asarray(edges, dtype=float)
    todo = np.stack([edges[:-1], edges[1:]], axis=1)
    todo = todo[todo[:, 1] > todo[:, 0]]
    pts, half = _gauss_nodes(todo)
    v0 = np.asarray(f(pts.ravel()), dtype=float).reshape(pts.shape)
    whole = half * (v0 @ wg)
    total, scale = 0.0, max(abs(whole.sum()), 1e-300)
    floor = NOISE * float(half @ (np.abs(v0) @ wg))  # ∫|f| (first estimate): the rounding of a cancelling f
    span = edges[-1] - edges[0]
    err, cap = np.full(len(todo), np.inf), max(MAX_OPEN, len(todo))  # the breakpoints' own intervals always fit
    for _ in range(MAX_PASSES):
        if not 0 < len(todo) <= cap:
            break
        mid = (todo[:, 0] + todo[:, 1]) / 2
        left, right = np.stack([todo[:, 0], mid], 1), np.stack([mid, todo[:, 1]], 1)
        pl, hl = _gauss_nodes(left)
        pr, hr = _gauss_nodes(right)
        v = np.asarray(f(np.concatenate([pl.ravel(), pr.ravel()])), dtype=float)
        ql = hl * (v[:pl.size].reshape(pl.shape) @ wg)
        qr = hr * (v[pl.size:].reshape(pr.shape) @ wg)
        err = np.abs(ql + qr - whole)
        ok = err <= (rtol * scale + atol) * (todo[:, 1] - todo[:, 0]) / span + 1e-300
        ok |= ~np.isfinite(ql + qr)
        if len(todo) > GLOBAL_FROM and float(err[~ok].sum()) <= max(rtol * scale, floor) + atol:
            ok[:] = True  # steep or noisy: converged as a whole
        total += float((ql + qr)[ok].sum())
        todo, err = np.concatenate([left[~ok], right[~ok]]), np.concatenate([err[~ok], err[~ok]]) / 2
        whole = np.concatenate([ql[~ok], qr[~ok]])
    value, tol = total + float(whole.sum()), float(max(rtol * scale, floor) + atol)
    if not len(todo):
        return Integral(value, 0.0 if np.isfinite(value) else np.inf, tol, (np.nan, np.nan))
    k = int(np.argmax(np.where(np.isnan(err), np.inf, err)))
    return Integral(value, float(err.sum()), tol, (float(todo[k, 0]), float(todo[k, 1])))


def integrate(f: Callable[[np.ndarray], np.ndarray], edges, *, rtol: float = 1e-11, atol: float = 0.0) -> float:
    """∫ f between breakpoints (:func:`integral`); a warning when the budget ran out before the tolerance was
    met (the last estimate is used)."""
    out = integral(f, edges, rtol=rtol, atol=atol)
    if not out.converged:
        edges = np.asarray(edges, dtype=float)
        log.warning("integrate over [%g, %g]: not converged to rtol = %g, atol = %g within the budget (%d passes of "
                    "at most %d intervals; error estimate %.3g, worst in [%.6g, %.6g]); the last estimate is used",
                    edges[0], edges[-1], rtol, atol, MAX_PASSES, MAX_OPEN, out.error, *out.worst)
    return out.value
