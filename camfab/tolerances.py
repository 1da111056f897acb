"""Named numerical tolerances, documented in one place."""
from __future__ import annotations

__all__ = [
    "ABS_TOL",
    "ANGLE_SUM_TOL_DEG",
    "CONTINUITY_REL_TOL",
    "PEAK_ANGLE_TOL_RAD",
    "CAMDAS_STEP_DEG",
    "DEFAULT_EXPORT_TOL_MM",
    "MIN_EXPORT_TOL_MM",
    "MAX_EXPORT_TOL_MM",
    "PROFILE_FIT_SHARE",
    "profile_fit_tolerance",
    "MAX_ARC_RADIUS_MM",
    "ARC_RADIUS_OVER_SIZE",
    "arc_radius_limit",
]

#: absolute tolerance for "equal" lengths in mm
ABS_TOL = 1e-12
#: the segment angles must sum to 360 degrees within this many degrees
ANGLE_SUM_TOL_DEG = 1e-9
#: a derivative is continuous at a junction when the jump is below this fraction of
#: that derivative's peak magnitude over the cycle (or of 1 when the peak is smaller)
CONTINUITY_REL_TOL = 1e-7
#: analytic extrema are located to this accuracy in the independent variable
PEAK_ANGLE_TOL_RAD = 1e-10
#: CAM-DAS evaluated and reported everything at 1 degree steps
CAMDAS_STEP_DEG = 1.0
#: default export tolerance (mm) and its accepted range
DEFAULT_EXPORT_TOL_MM = 0.001
MIN_EXPORT_TOL_MM = 1e-6
MAX_EXPORT_TOL_MM = 0.1
#: the share of the export tolerance a plate cam's one arc fit per profile may use (docs/decisions.md, "One arc fit
#: per profile"): the DXF, drawing and solids draw it, the pitch curve and the program's tool paths are its exact
#: offsets, and the STL flattens it within the rest of the tolerance
PROFILE_FIT_SHARE = 0.5
#: arcs of a larger radius (mm) are written as chords within the tolerance in STEP and, by default, in G-code
#: (``Post.max_arc_radius_mm``): docs/decisions.md, "Arc radius limit"
MAX_ARC_RADIUS_MM = 5000.0
#: an arc is a near-straight stretch of the fit, not the part's own curvature, above this many times the part's
#: size (its largest distance from the cam centre): the limit grows with the part (a 10 m cam keeps its arcs)
ARC_RADIUS_OVER_SIZE = 10.0


def arc_radius_limit(size_mm: float, cap_mm: float = float("inf")) -> float:
    """The largest arc radius written for a part of ``size_mm`` (its largest distance from the cam centre):
    ``max(MAX_ARC_RADIUS_MM, ARC_RADIUS_OVER_SIZE · size)``, at most ``cap_mm`` (the controller's limit)."""
    return min(cap_mm, max(MAX_ARC_RADIUS_MM, ARC_RADIUS_OVER_SIZE * float(size_mm)))


def profile_fit_tolerance(tol: float) -> float:
    """The tolerance (mm) of a plate profile's one arc fit for files within ``tol``: ``PROFILE_FIT_SHARE·tol``,
    never below :data:`MIN_EXPORT_TOL_MM` (at the finest tolerances the fit takes all of ``tol`` and an STL,
    which needs the other share for its facets, is refused)."""
    return max(tol * PROFILE_FIT_SHARE, MIN_EXPORT_TOL_MM)
