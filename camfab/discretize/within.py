"""The deviation of entities from an exact curve, measured with the fewest samples that prove it within a tolerance.

:func:`~camfab.discretize.measure.measure_deviation` takes 20 000 exact curve samples (with derivatives, for its
stand-in) whatever the curve and the question: ~100 ms for one profile, as much as the arc fit that made the
chain.  An exporter asks a narrower question — is this chain (a pitch loop offset from the profile's arcs, a
flattened STL outline, chords of large arcs) within ``tol`` of the curve, and by how much — which the fit's own
certificate answers (:mod:`camfab.discretize.certify`, derivation there): the curve's stand-in within ``tol/200``
(:func:`~camfab.discretize.surrogate.fit_surrogate`), the curve sampled just densely enough that the
certificate's gap ``K·h²/8`` is 5 % of ``tol``, and the measurement accepted only when ``measured + gap ≤ tol``.
The local certificate (:class:`~camfab.discretize.certify.LocalBound`: each sample interval's gap from the
curvature difference between the curve and the entities there, the samples where that is large) is tried first;
the global one is what this paragraph describes.
A chain measured closer than ``tol`` whose gap leaves no room (a flattened outline at 95 % of ``tol``) is
measured once more with the gap half the room left (:data:`MIN_GAP_SHARE` of ``tol`` at least: a bounded number
of samples).  When no certificate holds (a chain farther than ``tol``, an arc tighter than ``tol``) the full
measurement runs, so the answer is never weaker than :func:`measure_deviation`'s; the value reported is then
exactly that measurement's.

The certificate is made only for tangent-continuous chains (a pitch loop, a tool path offset from a fit).  Where
a chain has a corner and the curve passes on its inner side, the distance to the chain is the smaller of two
entities' distances, whose slopes differ by up to the corner's turn ``θ``: a kink that may exceed the sampled
maximum by ``θ·h/4``, a first-order term the ``K·h²/8`` bound does not cover.  A polyline (an STL outline) or
chords of large arcs therefore get the full measurement, and so does a curve whose stand-in misses ``tol/200``
(:data:`~camfab.discretize.surrogate.SURROGATE_MAX_NODES` reached): its curvature and speed bounds would be
weaker evidence.
"""
from __future__ import annotations

import numpy as np

from ..geom2d import cross, dot
from .certify import (
    CERTIFY_SHARE,
    DEFAULT_SAMPLES,
    curvature_bound,
    local_certificate,
    sample_gap,
    samples_for,
    standin_samples,
)
from .curve import ParametricCurve
from .measure import as_chain, fit_chain_to_curve, measure_deviation, measure_fit
from .results import Deviation
from .surrogate import SURROGATE_FRACTION, fit_surrogate
from .tolerance import WRITE_ROOM_MM, validate_tol, within

__all__ = ["CORNER_RAD", "MIN_GAP_SHARE", "measure_within"]

#: a joint whose tangents turn by more than this (rad) is a corner: no certificate (module notes)
CORNER_RAD = 1e-9

#: the smallest gap (share of ``tol``) a second certificate may ask for: at most ``sqrt(CERTIFY_SHARE /
#: MIN_GAP_SHARE)`` = 5 times the first one's samples
MIN_GAP_SHARE = 0.002


def measure_within(entities, curve: ParametricCurve, tol: float) -> Deviation:
    """Two-way maximum distance between ``entities`` and ``curve``, certified ``<= tol`` when it is.

    Parameters
    ----------
    entities : Chain, ArcChain, Discretisation or array_like
        As :func:`~camfab.discretize.measure.measure_deviation` accepts them.
    curve : ParametricCurve
        The exact curve.
    tol : float
        The tolerance the caller judges the result against (mm, the accepted range of
        :func:`~camfab.discretize.tolerance.validate_tol`).

    Returns
    -------
    Deviation
        The sampled maximum when a certificate proves the true maximum within ``tol`` (it is then below the
        true maximum by at most the certificate's gap: about 5 % of ``tol``); otherwise :func:`measure_deviation`'s
        full measurement, which the caller compares with ``tol`` as before.
    """
    tol = validate_tol(tol)
    chain = as_chain(entities, curve.closed)
    if chain.n == 0 or _largest_turn(chain, curve.closed) > CORNER_RAD:
        return measure_deviation(chain, curve)
    sur, err = fit_surrogate(curve, tol)
    if not err <= tol / SURROGATE_FRACTION:
        return measure_deviation(chain, curve)
    samples = standin_samples(sur)
    K, vmax = curvature_bound(sur, chain, tol, samples)
    gap = CERTIFY_SHARE * tol
    # (every certificate's chain-to-curve half; none is made without a finite bound)
    to_curve = fit_chain_to_curve(chain, sur) if np.isfinite(K) else None
    dev = local_certificate(chain, curve, sur, tol, gap, K, vmax, samples, to_curve)
    if dev is not None:
        return dev
    while gap >= MIN_GAP_SHARE * tol:
        n = samples_for(K, vmax, curve.period, gap)
        if n is None or n >= DEFAULT_SAMPLES:
            break
        g = sample_gap(K, vmax, curve.period, n)
        dev = measure_fit(chain, curve, sur, n, g, bound=(K, vmax), chain_to_curve=to_curve)
        if within(dev.max + g, tol):
            return dev
        if gap < CERTIFY_SHARE * tol:  # the second certificate failed too
            break
        gap = 0.5 * (tol - WRITE_ROOM_MM - dev.max)
    return measure_deviation(chain, curve)


def _largest_turn(chain, closed: bool) -> float:
    """The largest tangent turn (rad) at the chain's joints (the closing one too when ``closed``)."""
    out, into = chain.end_tangent, np.roll(chain.tangent, -1, axis=0)
    turn = np.arctan2(np.abs(cross(out, into)), dot(out, into))
    return float(turn.max() if closed else turn[:-1].max(initial=0.0))
