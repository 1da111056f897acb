"""Curves to lines and arcs within a tolerance: :func:`polyline` and :func:`arcs`.

Both guarantee that the two-way maximum distance between the entities and the exact curve is at most
``tol``.  The guarantee is *measured*, never assumed from an error model: every fit is checked in both
directions (curve samples to the entities and entity samples to the curve, with a local maximisation
of each distance) and refined until the measured worst deviation is below ``tol·(1 - MARGIN)``; the
result is then verified once more by the independent, global
:func:`~camfab.discretize.measure.measure_deviation`.  Every breakpoint where the tangent jumps (a
kink) is a vertex of the result, and so are an open curve's ends; polylines keep every breakpoint, arc
chains may run across breakpoints where the curve is tangent continuous.

Polyline: the initial grid follows the chord-error estimate ``L²κ/8``; intervals whose measured
deviation exceeds ``tol·(1 - MARGIN)`` are cut; a second grid equidistributing the measured errors
is tried and the smaller result kept (:mod:`camfab.discretize.interpolate`).

Arcs: first a *free* (non-interpolating) G1 arc spline (:mod:`camfab.discretize.arcspline`), by
spans clamped to the exact point and one-sided tangent at their ends.  Spans end at kinks and at
circular pieces (dwells), whose exact arcs the neighbouring spans continue: their arcs next to a
dwell keep its curvature and merge with it; G1 breakpoints in between are crossed by arcs (without
kinks or circular pieces every breakpoint ends a span).  Long spans are cut into spans of about
:data:`~camfab.discretize.spans.SPLINE_SPAN` arcs, joined G1 on the curve with its tangent.  Per span
knots and curvatures are optimised together on a linear model of the normal deviation (its prefix
integrals exact for cubic Hermite data, so the model matches the built chain to a fraction of a
percent) and the fewest arcs kept; two arcs of a span (the last two, or the two before a
fixed-curvature last arc) are the biarc closing it exactly.  The chain is measured on the exact
curve; should it exceed ``tol``, only the offending spans are refitted to a lower target.  It is used
when it measures within ``tol``, else the same spline clamped at every breakpoint, else
*interpolating biarcs*: each parameter interval ``[a, b]`` of a smooth piece gets a biarc through
``P(a)`` and ``P(b)`` with the exact one-sided tangents there (the ratio of its two tangent lengths
chosen by a golden-section search to minimise the deviation at curve samples), so neighbouring
intervals share their end tangent; the initial grid turns at most ``MAX_TURNING_RAD`` per interval,
intervals above ``tol·(1 - MARGIN)`` are split, and a second grid equidistributing the measured
errors is tried.  Consecutive co-circular arcs in one piece are merged.  All fitting runs on a
Hermite surrogate of a few batched exact samples; only the verification calls the exact curve again.
"""
from __future__ import annotations

import logging

import numpy as np

from ..errors import GeometryError
from ..geom2d import ArcChain, chord_large_arcs
from ..threads import one_blas_thread
from ..tolerances import DEFAULT_EXPORT_TOL_MM
from .arcspline import fit_spline
from .chain import Chain, merge_cocircular
from .curve import ParametricCurve, check_closed, points_at
from .interpolate import biarc_chain, fit_grid
from .measure import measure_deviation
from .results import ArcDiscretisation, Discretisation
from .surrogate import fit_surrogate
from .tolerance import validate_tol, within
from .within import measure_within

__all__ = ["polyline", "arcs", "arcs_within_radius", "REFIT_SHARE"]

#: when the room a fit leaves below ``tol`` is less than this share of it, :func:`arcs_within_radius` fits again
#: at ``tol·(1 - REFIT_SHARE)`` so that the chords of its large arcs have that much room
REFIT_SHARE = 0.1

log = logging.getLogger(__name__)


def polyline(curve: ParametricCurve, *, tol: float = DEFAULT_EXPORT_TOL_MM) -> Discretisation:
    """Polyline whose segments lie within ``tol`` of the exact curve.

    Parameters
    ----------
    curve : ParametricCurve
        The exact curve, closed or open.
    tol : float, keyword-only
        Maximum distance (mm) between the segments and the curve, in ``[1e-6, 0.1]``.

    Returns
    -------
    Discretisation
        Vertices on the curve (every breakpoint is one) and the measured
        two-way maximum deviation, which is ``<= tol``.

    Raises
    ------
    ToleranceError
        If ``tol`` is outside the accepted range.
    CurveError
        If a closed curve's ends do not meet.
    """
    tol = validate_tol(tol)
    check_closed(curve, tol)

    def build(nodes):
        pts = points_at(curve, nodes)
        if curve.closed:
            pts[-1] = pts[0]
        return pts

    nodes, measured = fit_grid(curve, tol, "line", lambda nodes: measure_deviation(build(nodes), curve).max)
    return Discretisation(params=nodes, points=build(nodes), max_deviation=float(measured), tol=tol,
                          closed=curve.closed)


class _BiarcGrids:
    """Interpolating biarc chains of node grids, merged and measured (the last grid's result cached)."""

    def __init__(self, curve: ParametricCurve, fit_curve: ParametricCurve, tol: float):
        self.curve, self.fit_curve, self.tol = curve, fit_curve, tol
        self.cache: dict = {}

    def __call__(self, nodes: np.ndarray) -> tuple[Chain, float]:
        key = nodes.tobytes()
        if key not in self.cache:
            self.cache.clear()
            self.cache[key] = self._build(nodes)
        return self.cache[key]

    def _build(self, nodes: np.ndarray) -> tuple[Chain, float]:
        chain, pieces = biarc_chain(self.curve, nodes, self.fit_curve)
        merged = merge_cocircular(chain, pieces)
        if merged is chain:
            return chain, measure_deviation(chain, self.curve).max
        measured = measure_deviation(merged, self.curve).max
        return (merged, measured) if within(measured, self.tol) else (chain, measure_deviation(chain, self.curve).max)


def arcs(curve: ParametricCurve, *, tol: float = DEFAULT_EXPORT_TOL_MM) -> ArcDiscretisation:
    """G1 chain of circular arcs within ``tol`` of the exact curve (see the module notes).

    Parameters
    ----------
    curve : ParametricCurve
        The exact curve, closed or open.
    tol : float, keyword-only
        Maximum distance (mm) between the chain and the curve, in ``[1e-6, 0.1]``.

    Returns
    -------
    ArcDiscretisation
        The arcs (nearly straight ones as lines), tangent-continuous except at the curve's kinks, and
        the measured two-way maximum deviation, which is ``<= tol``.

    Raises
    ------
    ToleranceError
        If ``tol`` is outside the accepted range.
    CurveError
        If a closed curve's ends do not meet.
    """
    tol = validate_tol(tol)
    check_closed(curve, tol)
    with one_blas_thread():  # the same arcs whatever the machine's BLAS threads (and no threads for tiny solves)
        return _arcs(curve, tol)


def _arcs(curve: ParametricCurve, tol: float) -> ArcDiscretisation:
    sur = fit_surrogate(curve, tol)
    spline = fit_spline(curve, sur, tol)
    if spline is None:
        log.info("arcs: the arc spline across the %d breakpoints misses tol = %g mm (or a dwell arc does); "
                 "falling back to spans clamped at every breakpoint", len(curve.breakpoints), tol)
        spline = fit_spline(curve, sur, tol, anchored=False)
    if spline is not None:
        chain, measured, nodes = spline
    else:
        log.info("arcs: the arc spline clamped at every breakpoint misses tol = %g mm too; falling back to "
                 "interpolating biarcs (slower, more arcs)", tol)
        build = _BiarcGrids(curve, sur[0].as_curve(), tol)
        nodes, _ = fit_grid(curve, tol, "biarc", lambda nodes: build(nodes)[1], sur)
        chain, measured = build(nodes)
    return ArcDiscretisation.from_chain(chain, nodes, measured, tol, curve.closed)


def arcs_within_radius(fit: ArcChain, curve: ParametricCurve, *, tol: float, max_radius_mm: float) -> ArcChain:
    """``fit`` (an arc chain within ``tol`` of ``curve``) with every arc of radius above ``max_radius_mm`` replaced
    by chords (:func:`~camfab.geom2d.chord_large_arcs`), still within ``tol`` of the curve, measured.

    The chords get the room the fit leaves: sagitta ``<= tol - measured deviation``, so the two-way distance
    stays below ``tol`` by the triangle inequality.  When that room is less than :data:`REFIT_SHARE` of ``tol``
    the curve is fitted again at ``tol·(1 - REFIT_SHARE)`` first (fewer, shorter chords than a sliver of room
    would need).  The result's deviation is measured again on the exact curve (``max_deviation``).  A chain
    without such arcs comes back unchanged (the same object).

    Raises
    ------
    GeometryError
        If the measured result exceeds ``tol`` (it cannot, but it is checked, never assumed).
    """
    tol = validate_tol(tol)
    if not np.any(~fit.is_line & (fit.radii > max_radius_mm)):
        return fit
    dev = fit.max_deviation
    if dev is None:
        dev = float(measure_within(fit, curve, tol).max)
    if tol - dev < REFIT_SHARE * tol:
        fit = arcs(curve, tol=tol * (1.0 - REFIT_SHARE))
        dev = float(fit.max_deviation)
    chords, _ = chord_large_arcs(fit, max_radius_mm, tol - dev)
    measured = float(measure_within(chords, curve, tol).max)
    if not within(measured, tol):
        raise GeometryError(f"arcs above R{max_radius_mm:g} mm as chords deviate {measured:.3g} mm from the curve "
                            f"(> tol {tol:g} mm); give a larger tolerance")
    return chords.with_deviation(measured)
