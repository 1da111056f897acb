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

The local bound (:class:`LocalBound`, tried first by :func:`certified_deviation` and by
:func:`~camfab.discretize.within.measure_within`).  ``K`` above bounds ``|f''|`` by the curvature of the curve plus
that of the sharpest arc, everywhere; where an arc follows its curve, ``f''`` is their *difference*.  Take the
circle of an arc, signed curvature ``k`` along the curve's direction, and the unit-speed curve ``P(s)`` with
tangent ``T``, left normal ``N`` and signed curvature ``κ``; ``ρ = |P - c|``, ``e = (P - c)/ρ`` and ``β`` the angle
between the circle's tangent at the foot and ``T`` (``e·T = ±sin β``).  Then ``f = ±(ρ - 1/|k|)`` has
``f' = e·T`` and ``f'' = (1 - (e·T)²)/ρ + κ·e·N``, which with ``e·N = ∓cos β`` and ``1/ρ = k_f = k/(1 + k·f)`` is
``±(cos²β·k_f - κ·cos β)``, so::

    |f''| ≤ |k_f - κ| + |k_f|·(1 - cos β) ≤ |k - κ| + (k²·|f| + |k|·sin²β)/(1 - |k|·|f|)

(``1 - cos β ≤ sin²β`` for ``|β| ≤ π/2``, the curve running along the chain; a line is ``k = 0``).  At ``f = β = 0``
it is ``|k - κ|`` exactly (``test_local_bound.py`` checks the inequality and its sharpness by finite differences).
The nearest point on a G1 chain moves monotonically along it as the curve point moves (for ``β < π/2`` and
``|k·f| < 1``), so between two samples whose nearest points lie on the entities ``e₀`` and ``e₁`` it stays on the
entities from ``e₀`` to ``e₁``, and ``f`` there is the signed distance to that sub-chain, C¹ with ``|f''|`` at most
the bound above for the entity holding the foot.  On a sample interval (parameters ``[t₀, t₁]``) the bound takes:

- ``κ``'s range from the stand-in's curvature at the ends and midpoint of every stand-in interval it overlaps,
  widened by the largest change between two of those values (``_standin_ranges``), and the curvatures ``k`` of the
  entities ``e₀ … e₁`` (at most :data:`_LOCAL_SPAN` entities apart, else the global ``K``): the mismatch is the
  largest ``|k - κ|`` over both ranges.  ``e₀``, ``e₁`` are the samples' nearest entities, except that a sample as
  near (to 1e-12 mm, which its distance then takes on) a joint's point of the entity on the interval's side is read
  against that entity (``measure._interval_ends``): an interval ending on the joint of two arcs of different
  curvature reads the one it runs along;
- ``|f| ≤ F = max(d₀, d₁) + L·h²/8`` and ``sin β = |f'| ≤ (d₀ + d₁)/h + L·h/2`` (``f'`` differs from its mean
  over the interval by at most ``L·h/2``), where ``d₀``, ``d₁`` are the samples' distances, ``h`` the interval's arc
  length (at most the stand-in's largest speed there times ``t₁ - t₀``) and ``L`` a bound of ``|f''|`` on the
  interval.  So the bound is a fixed point ``L = R(L)`` of the right-hand side (enlarged by :data:`_SAFETY`), and the
  true supremum ``L*`` of ``|f''|`` satisfies ``L* ≤ R(L*)`` and, by the global argument, ``L* ≤ K``.
  :data:`_LOCAL_ROUNDS` rounds from ``L = mismatch`` give ``L̂``; it is taken when ``R(L̂) ≤ L̂`` and ``R(K) < K``:
  ``R`` is convex in ``L`` (``sin β``'s bound is not capped at 1), so ``R(L) < L`` on all of ``[L̂, K]``, where
  therefore ``L*`` cannot lie: ``L* ≤ L̂``.  Otherwise the interval takes ``K``.

Each interval's distance is then at most ``max(d₀, d₁) + L·h²/8``.  The samples follow the need: each stand-in
interval gets ``(t₁ - t₀)·sqrt(per-step bound / gap)`` of them (its curvature mismatch with the entities that own its
ends, its neighbours' ranges included, :data:`_LOCAL_MARGIN` more), at least 8 per smooth piece and per entity, spread
evenly by the cumulative need, every breakpoint a sample.  On the issue cam at 1 µm that is 470 samples instead of
6 372; at 0.1 µm on the valve profile 1 700 instead of 207 000 (beyond the default 20 000, so that fit was not
certified before).  The measurement refines only the local maxima whose two intervals' bounds reach the largest
sample (three nested grids: the samples are sparser), and a refined distance above its bracket's bound voids the
certificate (the bound was wrong: the global one is tried next).  The certificate holds when every interval's
bound, and the chain-to-curve maximum plus the gap, are within ``tol``.
"""
from __future__ import annotations

import math

import numpy as np

from ..geom2d import cross
from .chain import Chain
from .curve import ParametricCurve
from .measure import fit_chain_to_curve, fit_curve_to_chain, measure_deviation, measure_fit, owners, two_way_deviation
from .results import Deviation
from .surrogate import HermiteSurrogate
from .tolerance import WRITE_ROOM_MM, within

__all__ = ["CERTIFY_SHARE", "DEFAULT_SAMPLES", "LocalBound", "curvature_bound", "standin_samples", "sample_gap",
           "samples_for", "local_certificate", "certified_deviation"]

#: the share of ``tol`` the gap between curve samples may cost (the fit aims at 97 % of tol less the stand-in's
#: error; the measured deviation of the examples lands at 80–97 %)
CERTIFY_SHARE = 0.05
#: the measurement's default curve samples (:func:`~camfab.discretize.measure.measure_deviation`)
DEFAULT_SAMPLES = 20000
#: the sampled curvature and speed maxima of the stand-in are enlarged by this factor (their maxima between the
#: samples: the stand-in has thousands of nodes over a smooth curve); the local bound is enlarged by it too
_SAFETY = 1.25
#: the local certificate takes this many times the samples its estimate asks for (the estimate reads the entities
#: owning a stand-in interval's ends; a sample interval reads its samples' nearest ones)
_LOCAL_MARGIN = 1.25
#: fixed-point rounds of the local bound (its corrections depend on the bound itself; module notes)
_LOCAL_ROUNDS = 3
#: the most entities between the owners of a sample interval's two ends for which the local bound is taken (more:
#: the global bound for that interval)
_LOCAL_SPAN = 3


def standin_samples(sur: HermiteSurrogate) -> tuple[tuple, tuple]:
    """The stand-in's signed curvature and speed at both ends and the midpoint of every interval (each inside its
    own smooth piece: one-sided at breakpoints): ``((κ₀, κ_mid, κ₁), (v₀, v_mid, v₁))``, one value per interval
    each."""
    a, b = sur.x[:-1], sur.x[1:]
    # each interval's own cubic at offsets 0, (a + b)/2 - a and b - a (at b the next interval's start agrees to
    # rounding: the stand-in is C¹ inside a piece), evaluated from the coefficients without locating the cubics
    c = sur.coef
    ks, vs = [], []
    for u in (np.zeros_like(a), 0.5 * (a + b) - a, b - a):  # (one offset at a time: no tiled copy of the cubics)
        u = u[:, None]
        d, dd = c[1] + u * (2 * c[2] + 3 * u * c[3]), 2 * c[2] + 6 * u * c[3]
        v = np.hypot(d[:, 0], d[:, 1])
        with np.errstate(divide="ignore", invalid="ignore"):
            ks.append(cross(d, dd) / v ** 3)
        vs.append(v)
    return tuple(ks), tuple(vs)


def _curve_bounds(sur: HermiteSurrogate, samples: tuple | None = None) -> tuple[float, float]:
    """``(max |κ|, max |P′|)`` of the stand-in at both ends and the midpoint of every interval
    (:func:`standin_samples`, when not given), enlarged by :data:`_SAFETY`."""
    ks, vs = standin_samples(sur) if samples is None else samples
    k_max = v_max = -np.inf
    for k, v in zip(ks, vs, strict=True):
        k_max, v_max = np.maximum(k_max, np.max(np.abs(k))), np.maximum(v_max, np.max(v))  # (a NaN stays NaN)
    return _SAFETY * float(k_max), _SAFETY * float(v_max)


def _standin_ranges(samples: tuple) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per stand-in interval: the lowest and highest signed curvature and the highest speed of the curve on it,
    ``(κ_lo, κ_hi, v_hi)``, from its :func:`standin_samples`: the three values widened by the largest change
    between two of them (a smooth function between samples stays within that of them)."""
    (k0, km, k1), (v0, vm, v1) = samples
    dk = np.maximum(np.abs(km - k0), np.abs(k1 - km))
    dv = np.maximum(np.abs(vm - v0), np.abs(v1 - vm))
    return (np.minimum(np.minimum(k0, km), k1) - dk, np.maximum(np.maximum(k0, km), k1) + dk,
            np.maximum(np.maximum(v0, vm), v1) + dv)


class LocalBound:
    """The local certificate's bound of the distance between curve samples (module notes, "The local bound").

    Parameters
    ----------
    sur : HermiteSurrogate
        The fit's stand-in.
    chain : Chain
        The fitted chain.
    K : float
        The global bound (:func:`curvature_bound`), also the cap of every local one.
    foot : (n,) array
        The curve parameter of every entity's start (:func:`~camfab.discretize.measure.fit_chain_to_curve`): a
        curve sample belongs to the entity whose start's foot comes last before it.
    samples : tuple, optional
        The stand-in's :func:`standin_samples`, when already taken.
    """

    def __init__(self, sur: HermiteSurrogate, chain: Chain, K: float, foot: np.ndarray,
                 samples: tuple | None = None):
        self.x, self.period, self.K = sur.x, sur.curve.period, K
        self.first, self.closed = sur.first, sur.curve.closed
        self.k_lo, self.k_hi, self.v_hi = _standin_ranges(standin_samples(sur) if samples is None else samples)
        self.k, self.n = chain.curvature, chain.n
        self.owner = owners(foot, self.period)

    def _window(self, e0: np.ndarray, e1: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """``(k_min, k_max, max |k|, wide)`` of the entities from ``e0`` to ``e1`` (or from ``e1`` to ``e0``, whichever
        is shorter; around a closed chain), ``wide`` where more than :data:`_LOCAL_SPAN` lie between them."""
        n = self.n
        if self.closed:
            fwd, back = (e1 - e0) % n, (e0 - e1) % n
        else:
            fwd = back = np.abs(e1 - e0)
        lo = np.where(fwd <= back, e0, e1)
        span = np.minimum(fwd, back)
        k_min = k_max = self.k[lo]
        for off in range(1, _LOCAL_SPAN + 1):
            ki = np.where(span >= off, self.k[(lo + off) % n], k_min)  # (within the span when it is not wide)
            k_min, k_max = np.minimum(k_min, ki), np.maximum(k_max, ki)
        return k_min, k_max, np.maximum(np.abs(k_min), np.abs(k_max)), span > _LOCAL_SPAN

    def nodes(self, gap: float, least: int) -> np.ndarray | None:
        """Curve parameters whose local gaps are at most about ``gap`` (every breakpoint and the period among them,
        at least 8 intervals per smooth piece and ``least`` in all): each stand-in interval gets the samples its
        curvature mismatch with the entities owning its ends asks for (its neighbours' curvature ranges and speeds
        included, :data:`_LOCAL_MARGIN` more), spread evenly over it by the cumulative need; None when that is not
        finite or :data:`DEFAULT_SAMPLES` or more."""
        if not (gap > 0 and math.isfinite(self.K)):
            return None
        x = self.x
        e = self.owner(x)
        k_min, k_max, _, _ = self._window(e[:-1], e[1:])
        # a sample interval reads the curvature range and speed of every stand-in interval it overlaps: each one's
        # need takes its neighbours' too (a sample interval about as long as a stand-in interval overlaps two)
        k_lo, k_hi, v_hi = self.k_lo.copy(), self.k_hi.copy(), self.v_hi.copy()
        for a, b in ((slice(1, None), slice(None, -1)), (slice(None, -1), slice(1, None))):
            k_lo[a], k_hi[a] = np.minimum(k_lo[a], self.k_lo[b]), np.maximum(k_hi[a], self.k_hi[b])
            v_hi[a] = np.maximum(v_hi[a], self.v_hi[b])
        per_step = _SAFETY * np.maximum(k_max - k_lo, k_hi - k_min) * v_hi ** 2 / 8.0
        width = x[1:] - x[:-1]
        # the sample intervals each stand-in interval needs (gap of an interval Δt: per_step·Δt²), at least an even
        # share of ``least``
        with np.errstate(invalid="ignore", over="ignore"):
            need = np.maximum(_LOCAL_MARGIN * width * np.sqrt(per_step / gap), width * (least / self.period))
        total = float(need.sum())
        if not (math.isfinite(total) and total < DEFAULT_SAMPLES):
            return None
        cum = np.concatenate([[0.0], np.cumsum(need)])
        lo, hi = cum[self.first[:-1]], cum[self.first[1:]]
        counts = np.maximum(8, np.ceil(hi - lo)).astype(int)
        # per piece: ``count`` equal steps of the cumulative need, mapped back to parameters (its start exactly)
        start = np.repeat(np.cumsum(counts) - counts, counts)
        j = np.arange(start.size) - start
        piece = np.repeat(np.arange(counts.size), counts)
        levels = lo[piece] + (hi - lo)[piece] * (j / counts[piece])
        ts = np.interp(levels, cum, x)
        ts[j == 0] = x[self.first[:-1]]
        return self._split(np.append(ts, x[-1]), gap)

    def _split(self, ts: np.ndarray, gap: float) -> np.ndarray | None:
        """``ts`` with every interval cut evenly into as many as the curvature mismatch of its own window asks for
        (the entities owning its two ends, the stand-in intervals it overlaps; :data:`_LOCAL_MARGIN` more): a sample
        interval over a joint reads both arcs' curvatures along all its length, where :meth:`nodes` charged them to
        the stand-in interval holding the joint only.  None when that makes :data:`DEFAULT_SAMPLES` or more."""
        e = self.owner(ts)
        k_min, k_max, _, _ = self._window(e[:-1], e[1:])
        k_lo, k_hi, v_hi = self._overlap(ts)
        dt = ts[1:] - ts[:-1]
        per_step = _SAFETY * np.maximum(k_max - k_lo, k_hi - k_min) * v_hi ** 2 / 8.0
        with np.errstate(invalid="ignore", over="ignore"):
            parts = np.maximum(np.ceil(_LOCAL_MARGIN * dt * np.sqrt(per_step / gap)), 1.0)
        total = float(parts.sum())
        if not (math.isfinite(total) and total < DEFAULT_SAMPLES):
            return None
        if total == dt.size:
            return ts
        parts = parts.astype(int)
        idx = np.repeat(np.arange(dt.size), parts)
        sub = np.arange(idx.size) - np.repeat(np.cumsum(parts) - parts, parts)
        return np.append(ts[idx] + dt[idx] * (sub / parts[idx]), ts[-1])

    def _overlap(self, ts: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Per sample interval ``[ts[i], ts[i + 1]]``: the curvature range and highest speed of the stand-in intervals
        it overlaps, ``(κ_lo, κ_hi, v_hi)``."""
        last = self.k_lo.size - 1
        m0 = np.clip(self.x.searchsorted(ts[:-1], side="right") - 1, 0, last)
        m1 = np.maximum(np.clip(self.x.searchsorted(ts[1:], side="left") - 1, 0, last), m0)
        at = np.stack([m0, m1 + 1], axis=1).ravel()
        return (np.minimum.reduceat(np.append(self.k_lo, 0.0), at)[::2],
                np.maximum.reduceat(np.append(self.k_hi, 0.0), at)[::2],
                np.maximum.reduceat(np.append(self.v_hi, 0.0), at)[::2])

    def per_step(self, ts: np.ndarray, d0: np.ndarray, d1: np.ndarray, e0: np.ndarray, e1: np.ndarray) -> np.ndarray:
        """Per sample interval ``[ts[i], ts[i + 1]]``: ``c_i`` such that the curve's distance to the chain there is
        at most ``max(d0[i], d1[i]) + c_i·(ts[i + 1] - ts[i])²`` (module notes), where ``d0``, ``d1`` bound the
        distances at the interval's two ends to the entities ``e0``, ``e1`` (and those between them).  ``c_i``
        comes from the global bound where more than :data:`_LOCAL_SPAN` entities lie between ``e0`` and ``e1`` or
        the local one does not prove itself (module notes)."""
        dt = ts[1:] - ts[:-1]
        k_lo, k_hi, v_hi = self._overlap(ts)
        k_min, k_max, k_abs, wide = self._window(e0, e1)
        mismatch = np.maximum(k_max - k_lo, k_hi - k_min)
        h = v_hi * dt
        top = np.maximum(d0, d1)
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            slope = (d0 + d1) / h

            def rhs(L):
                F = top + L * h * h / 8.0
                s = slope + L * h / 2.0  # (a bound of sin β, not capped at 1: R stays convex in L)
                den = 1.0 - k_abs * F
                return np.where(den > 0, _SAFETY * (mismatch + (k_abs * k_abs * F + k_abs * s * s) / den), np.inf)

            L = _SAFETY * mismatch
            for _ in range(_LOCAL_ROUNDS):
                L = rhs(L)
            L = L * (1.0 + 1e-6)
            ok = (rhs(L) <= L) & (rhs(self.K) < self.K) & (L < self.K) & ~wide & np.isfinite(L)
        K = np.where(ok, L, self.K)
        return K * v_hi * v_hi / 8.0


def curvature_bound(sur: HermiteSurrogate, chain: Chain, tol: float, samples: tuple | None = None
                    ) -> tuple[float, float]:
    """``(K, max |P′|)``: the bound of ``|f''|`` (module notes) and the curve's largest speed; ``K`` is inf when
    an arc's radius is not above ``tol``.  ``samples``: the stand-in's :func:`standin_samples`, when taken."""
    kc, vmax = _curve_bounds(sur, samples)
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


def local_certificate(chain: Chain, curve: ParametricCurve, sur: HermiteSurrogate, tol: float, gap: float,
                      K: float, vmax: float, samples: tuple | None = None,
                      chain_to_curve: tuple[float, float, np.ndarray] | None = None) -> Deviation | None:
    """The fit's measurement of ``chain`` with the samples the local bound asks for (module notes, "The local
    bound"), when it certifies the chain within ``tol``: every sample interval's bound, the sampled and refined
    maxima, and the chain-to-curve maximum plus ``gap`` all within it; else None.  ``gap``: the largest share of
    ``tol`` a sample interval's bound may add (as :func:`certified_deviation`'s); ``K``, ``vmax``: the global bound
    (:func:`curvature_bound`); ``samples``: the stand-in's :func:`standin_samples`, ``chain_to_curve``:
    :func:`~camfab.discretize.measure.fit_chain_to_curve`'s result, when taken."""
    if not (math.isfinite(K) and gap > 0 and chain.n):
        return None
    worst_b, at_b, foot = fit_chain_to_curve(chain, sur) if chain_to_curve is None else chain_to_curve
    local = LocalBound(sur, chain, K, foot, samples)
    ts = local.nodes(gap, 8 * chain.n)
    if ts is None:
        return None
    worst_a, at_a, bound = fit_curve_to_chain(chain, curve, ts.size - 1, gap, foot, (K, vmax), local, nodes=ts)
    if not within(max(bound, worst_a, worst_b + gap), tol):
        return None
    return two_way_deviation(curve, worst_a, at_a, worst_b, at_b)


def certified_deviation(chain: Chain, curve: ParametricCurve, sur: HermiteSurrogate, tol: float,
                        expected: float = 0.0) -> Deviation:
    """The measured deviation of ``chain`` from ``curve``: with the samples the local bound asks for when they
    certify it within ``tol`` (:func:`local_certificate`), else with the fewest samples that certify it by the
    global bound (module notes) when they are fewer than the default and that certificate holds, else as measured
    with the default samples.  ``expected`` (the fit's model error, mm) narrows the gap allowed to half the room it
    leaves when that is less than :data:`CERTIFY_SHARE` of ``tol``."""
    samples = standin_samples(sur)
    K, vmax = curvature_bound(sur, chain, tol, samples)
    gap = min(CERTIFY_SHARE * tol, 0.5 * (tol - WRITE_ROOM_MM - expected))
    # (both certificates' chain-to-curve half; neither is made without entities or a finite bound)
    to_curve = fit_chain_to_curve(chain, sur) if chain.n and math.isfinite(K) else None
    dev = local_certificate(chain, curve, sur, tol, gap, K, vmax, samples, to_curve)
    if dev is not None:
        return dev
    n = samples_for(K, vmax, curve.period, gap)
    if n is not None and n < DEFAULT_SAMPLES:
        g = sample_gap(K, vmax, curve.period, n)
        dev = measure_fit(chain, curve, sur, n, g, bound=(K, vmax), chain_to_curve=to_curve)
        if within(dev.max + g, tol):
            return dev
    return measure_deviation(chain, curve)
