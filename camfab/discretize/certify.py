"""How many curve samples a deviation measurement needs to certify a fit within ``tol``.

:func:`~camfab.discretize.measure.measure_deviation` takes the exact distance from ``samples`` curve points
(shared out by parameter length) to the chain and refines the worst local maxima; its default (20 000
points) is fixed whatever the curve.  The fit's own acceptance test only needs to know that the true maximum
is within ``tol``, and a bound on the distance between samples tells how many points guarantee that.

Derivation. Let ``f(s)`` be the *signed* distance from the curve point at arc length ``s`` to the chain, so that
``g = |f|`` is the distance. A G1 chain of lines and arcs is a C¹ curve whose curvature is piecewise constant, at
most ``1/r_min``; within its reach (``r_min`` at most, less where distant parts of the chain come close; and nearer
an inner point of it than an open chain's ends, which the fit puts on the curve) its signed distance function ``d``
is C¹ with a gradient of length 1 and a Hessian of norm at most ``1/(r_min - |d|)`` (the level line at distance
``d`` from an arc of curvature ``k`` is a concentric arc of curvature ``k/(1 - k·d)``; from a line, a line). So
``f(s) = d(P(s))`` has ``f'' = Hess d[P′, P′] + ∇d·P″`` and ``|f''| ≤ K = max|κ_curve| + 1/(r_min - tol)`` (a chain
of lines: ``K = max|κ_curve|``) wherever ``|f| ≤ tol``; ``d`` is 1-Lipschitz, so between samples ``h`` apart of at
most ``tol`` it stays within ``tol + h/2``, and the bound there is ``1/(r_min - tol - h/2)``, within the stand-in's
safety factor below of the one used (``h`` is a fraction of a millimetre, ``r_min`` tens of them). The bound is
two-sided: ``f`` minus its linear interpolation vanishes at both samples and has a second derivative in ``[-K,
K]``, so it lies within ``K·(s - a)(b - s)/2`` of zero, hence on a sample interval of arc length ``h``::

    g(s) ≤ |linear interpolation of the two samples of f| + K·(s - a)(b - s)/2 ≤ max(samples) + K·h²/8.

(A one-sided bound ``f'' ≤ K`` — semiconcavity — would bound ``f`` from below only.)  A sample's distance may be an
upper bound rather than the exact one (the fit's measurement takes it to a window of entities): the bound then
holds for the distance to the union of those entities, itself a G1 chain, and the true distance is smaller.

The sampled maximum ``D`` the measurement reports is at least the largest sample (its refinement only adds),
so the true curve-to-chain maximum is at most ``D + K·h²/8`` with ``h ≤ max|P′|·period / samples`` (at least
``samples·(hi - lo)/period`` points fall on every smooth piece).  The other direction (chain to curve) does not
depend on ``samples``: each of its distances is taken to an exact curve point (an upper bound), and its
maximum is the first one's to second order (within the tube the chain is a graph ``P + f·n`` over the curve, and
a curve point's distance to it is ``|f|`` less a term in ``f′²``).  Hence
:func:`certified_deviation` measures with the fewest samples whose gap ``K·h²/8`` is
:data:`CERTIFY_SHARE` of ``tol``, and accepts that measurement when ``D + gap ≤ tol`` (less the writers'
room); otherwise it measures as before (the default sample count), so a fit is never accepted on weaker
evidence than it was.  ``K`` and ``max|P′|`` come from the fit's Hermite stand-in (its midpoint error is a
two-hundredth of ``tol``), sampled at both ends and the midpoint of every interval and enlarged by
:data:`_SAFETY`.
"""
from __future__ import annotations

import math

import numpy as np

from ..geom2d import cross
from .chain import Chain
from .curve import ParametricCurve
from .measure import measure_deviation, measure_fit
from .results import Deviation
from .surrogate import HermiteSurrogate
from .tolerance import WRITE_ROOM_MM, within

__all__ = ["CERTIFY_SHARE", "DEFAULT_SAMPLES", "curvature_bound", "sample_gap", "samples_for", "certified_deviation"]

#: the share of ``tol`` the gap between curve samples may cost (the fit aims at 97 % of tol less the stand-in's
#: error; the measured deviation of the examples lands at 80–97 %)
CERTIFY_SHARE = 0.05
#: the measurement's default curve samples (:func:`~camfab.discretize.measure.measure_deviation`)
DEFAULT_SAMPLES = 20000
#: the sampled curvature and speed maxima of the stand-in are enlarged by this factor (their maxima between the
#: samples: the stand-in has thousands of nodes over a smooth curve)
_SAFETY = 1.25


def _curve_bounds(sur: HermiteSurrogate) -> tuple[float, float]:
    """``(max |κ|, max |P′|)`` of the stand-in at both ends and the midpoint of every interval (each inside its
    own smooth piece: one-sided at breakpoints), enlarged by :data:`_SAFETY`."""
    a, b = sur.x[:-1], sur.x[1:]
    # each interval's own cubic at offsets 0, (a + b)/2 - a and b - a (at b the next interval's start agrees to
    # rounding: the stand-in is C¹ inside a piece), evaluated from the coefficients without locating the cubics
    c = sur.coef
    k_max = v_max = -np.inf
    for u in (np.zeros_like(a), 0.5 * (a + b) - a, b - a):  # (one offset at a time: no tiled copy of the cubics)
        u = u[:, None]
        d, dd = c[1] + u * (2 * c[2] + 3 * u * c[3]), 2 * c[2] + 6 * u * c[3]
        v = np.hypot(d[:, 0], d[:, 1])
        with np.errstate(divide="ignore", invalid="ignore"):
            k = np.abs(cross(d, dd)) / v ** 3
        k_max, v_max = np.maximum(k_max, np.max(k)), np.maximum(v_max, np.max(v))  # (a NaN stays NaN)
    return _SAFETY * float(k_max), _SAFETY * float(v_max)


def curvature_bound(sur: HermiteSurrogate, chain: Chain, tol: float) -> tuple[float, float]:
    """``(K, max |P′|)``: the bound of ``|f''|`` (module notes) and the curve's largest speed; ``K`` is inf when
    an arc's radius is not above ``tol``."""
    kc, vmax = _curve_bounds(sur)
    r = 1.0 / np.abs(chain.curvature[chain.curvature != 0.0])
    if r.size == 0:
        return kc, vmax
    rmin = float(r.min())
    return (kc + 1.0 / (rmin - tol) if rmin > tol else math.inf), vmax


def sample_gap(K: float, vmax: float, period: float, samples: int) -> float:
    """``K·h²/8`` with ``h = vmax·period/samples``: how far the curve-to-chain maximum may exceed the sampled one."""
    h = vmax * period / samples
    return K * h * h / 8.0


def samples_for(K: float, vmax: float, period: float, gap: float) -> int | None:
    """The fewest samples whose :func:`sample_gap` is at most ``gap`` (None when the bound is not finite)."""
    if not (math.isfinite(K) and math.isfinite(vmax) and gap > 0):
        return None
    n = vmax * period * math.sqrt(K / (8.0 * gap))
    return max(8, math.ceil(n)) if math.isfinite(n) else None


def certified_deviation(chain: Chain, curve: ParametricCurve, sur: HermiteSurrogate, tol: float,
                        expected: float = 0.0) -> Deviation:
    """The measured deviation of ``chain`` from ``curve``: with the fewest samples that certify it within
    ``tol`` (module notes) when they are fewer than the default and the certificate holds, else as measured
    with the default samples.  ``expected`` (the fit's model error, mm) narrows the gap allowed to half the
    room it leaves when that is less than :data:`CERTIFY_SHARE` of ``tol``."""
    K, vmax = curvature_bound(sur, chain, tol)
    gap = min(CERTIFY_SHARE * tol, 0.5 * (tol - WRITE_ROOM_MM - expected))
    n = samples_for(K, vmax, curve.period, gap)
    if n is not None and n < DEFAULT_SAMPLES:
        g = sample_gap(K, vmax, curve.period, n)
        dev = measure_fit(chain, curve, sur, n, g, bound=(K, vmax))
        if within(dev.max + g, tol):
            return dev
    return measure_deviation(chain, curve)
