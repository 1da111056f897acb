"""The deviation of entities from an exact curve, measured with the fewest samples that prove it within a tolerance.

:func:`~camfab.discretize.measure.measure_deviation` takes 20 000 exact curve samples (with derivatives, for its
stand-in) whatever the curve and the question: ~100 ms for one profile, as much as the arc fit that made the
chain.  An exporter asks a narrower question — is this chain (a pitch loop offset from the profile's arcs, a
flattened STL outline, chords of large arcs) within ``tol`` of the curve, and by how much — which the fit's own
certificate answers (:mod:`camfab.discretize.certify`, derivation there): the curve's stand-in within ``tol/200``
(:func:`~camfab.discretize.surrogate.fit_surrogate`), the curve sampled just densely enough that the
semiconcavity gap ``K·h²/8`` is 5 % of ``tol``, and the measurement accepted only when ``measured + gap ≤ tol``.
A chain measured closer than ``tol`` whose gap leaves no room (a flattened outline at 95 % of ``tol``) is
measured once more with the gap half the room left (:data:`MIN_GAP_SHARE` of ``tol`` at least: a bounded number
of samples).  When no certificate holds (a chain farther than ``tol``, an arc tighter than ``tol``) the full
measurement runs, so the answer is never weaker than :func:`measure_deviation`'s; the value reported is then
exactly that measurement's.
"""
from __future__ import annotations

from .certify import CERTIFY_SHARE, DEFAULT_SAMPLES, sample_gap, samples_for, semiconcavity
from .curve import ParametricCurve
from .measure import as_chain, measure_deviation, measure_fit
from .results import Deviation
from .surrogate import fit_surrogate
from .tolerance import WRITE_ROOM_MM, validate_tol, within

__all__ = ["MIN_GAP_SHARE", "measure_within"]

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
        The sampled maximum when the certificate proves the true maximum within ``tol`` (it is then below the
        true maximum by at most 5 % of ``tol``); otherwise :func:`measure_deviation`'s full measurement, which
        the caller compares with ``tol`` as before.
    """
    tol = validate_tol(tol)
    chain = as_chain(entities, curve.closed)
    sur, _ = fit_surrogate(curve, tol)
    K, vmax = semiconcavity(sur, chain, tol)
    gap = CERTIFY_SHARE * tol
    while gap >= MIN_GAP_SHARE * tol:
        n = samples_for(K, vmax, curve.period, gap)
        if n is None or n >= DEFAULT_SAMPLES:
            break
        g = sample_gap(K, vmax, curve.period, n)
        dev = measure_fit(chain, curve, sur, n, g)
        if within(dev.max + g, tol):
            return dev
        if gap < CERTIFY_SHARE * tol:  # the second certificate failed too
            break
        gap = 0.5 * (tol - WRITE_ROOM_MM - dev.max)
    return measure_deviation(chain, curve)
