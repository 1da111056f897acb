"""Spans that are copies or mirror images of one another: one arc-count search for all of them.

A cam whose return mirrors its rise (the same law both ways: cycloidal +h then -h) has two free spans that are
mirror images, and a cam of repeated lobes has spans that are copies.  The search of the fewest arcs
(:mod:`camfab.discretize.arcspline`) is the costly part of the fit, and it gives congruent spans congruent
arcs, so the arcs (knots and curvatures, in arc length) of the first span are reused for the others: as they are
for a copy, reversed for a mirror image (a reflected curve run backwards has the curvature ``κ(L - s)``).  The
reused arcs are laid from the span's own end points and tangents like any fitted arcs, and the chain is measured
on the exact curve as always; a span whose reused arcs measure above ``tol`` is fitted on its own.

Two spans are taken as congruent when their lengths and sample positions agree within :data:`SIGNATURE_TOL` and
their curvatures along the arc length (at :data:`SIGNATURE_POINTS` points of the surrogate) and fixed end
curvatures within :data:`CURVATURE_TOL` (relative).
"""
from __future__ import annotations

import numpy as np

from .spanmodel import span_model
from .spans import Span
from .surrogate import HermiteSurrogate

__all__ = ["SIGNATURE_POINTS", "SIGNATURE_TOL", "CURVATURE_TOL", "CongruentSpans"]

#: surrogate samples of a span's curvature compared
SIGNATURE_POINTS = 65
#: relative agreement of two spans' lengths and sample positions
SIGNATURE_TOL = 1e-9
#: relative agreement of their curvatures and fixed end curvatures (of the largest |κ|, at least 1/L): the
#: surrogate's curvatures of mirror-image pieces differ by a few 1e-9 of it
CURVATURE_TOL = 1e-7


def _close(a: np.ndarray, b: np.ndarray, tol: float) -> bool:
    return bool(np.all(np.abs(a - b) <= tol))


def _same_fixed(a: tuple, b: tuple, tol: float) -> bool:
    return all((x is None and y is None) or (x is not None and y is not None and abs(x - y) <= tol)
               for x, y in zip(a, b, strict=True))


class CongruentSpans:
    """The fitted spans of one target by length: :meth:`find` a fitted span congruent to a new one, :meth:`add`
    a fitted span."""

    def __init__(self, sur: HermiteSurrogate):
        self.sur = sur
        self.fitted: list = []  # (signature, fixed, fit)

    def signature(self, span: Span) -> tuple[np.ndarray, np.ndarray]:
        """Arc length and curvature of the surrogate at :data:`SIGNATURE_POINTS` points of the span."""
        _, s, _, kappa = span_model(self.sur, span.segs, SIGNATURE_POINTS, curvature=True)
        return s, kappa

    def add(self, sig: tuple, span: Span, fit: tuple) -> None:
        """Remember ``fit`` ``(knots, k, error, fixed)`` of ``span`` (signature ``sig``)."""
        self.fitted.append((sig, span.fixed, fit))

    def find(self, sig: tuple, span: Span) -> tuple | None:
        """The fit of a remembered span congruent to ``span`` (signature ``sig``) carried over to it, or None."""
        s, k = sig
        for (s0, k0), fixed0, fit in self.fitted:
            if s0.size != s.size:
                continue
            length = float(s0[-1])
            tol_s, tol_k = SIGNATURE_TOL * length, CURVATURE_TOL * max(float(np.abs(k0).max()), 1.0 / length)
            if not abs(float(s[-1]) - length) <= tol_s:
                continue
            if _same_fixed(fixed0, span.fixed, tol_k) and _close(s, s0, tol_s) and _close(k, k0, tol_k):
                return _carried(fit, float(s[-1]) / length, mirror=False)
            if (_same_fixed(fixed0[::-1], span.fixed, tol_k) and _close(s[-1] - s[::-1], s0, tol_s)
                    and _close(k[::-1], k0, tol_k)):
                return _carried(fit, float(s[-1]) / length, mirror=True)
        return None


def _carried(fit: tuple, ratio: float, mirror: bool) -> tuple:
    """``fit`` ``(knots, k, error, fixed)`` on a congruent span ``ratio`` times as long (reversed: ``mirror``)."""
    knots, k, err, fixed = fit
    if mirror:
        knots, k, fixed = knots[-1] - knots[::-1], k[::-1], fixed[::-1]
    knots = knots * ratio
    knots[0] = 0.0
    return knots, np.array(k, dtype=float), err, fixed
