"""camfab.discretize - exact plane curves to lines and arcs with a measured two-way deviation.

It knows nothing of cams: a curve is a :class:`ParametricCurve` (points and derivatives at
parameters, breakpoints where its formula changes, closed or open; :func:`curvature_at` gives its
curvature).  :func:`polyline` and :func:`arcs` return entities whose
two-way maximum distance from the exact curve is measured and at most the tolerance;
:func:`measure_deviation` measures any lines and arcs (read back from a file, for instance) against
the curve.  An arc discretisation is an :class:`~camfab.geom2d.ArcChain`, what every writer reads.

Modules, in dependency order: ``tolerance``, ``curve``, ``surrogate``, ``entities``, ``chain``,
``results``, ``measure``, ``certify``, ``within``, ``interpolate``, ``spanmodel``, ``spans``, ``arcspline``, ``fit``.
"""
from .chain import Chain
from .curve import CurveError, ParametricCurve, curvature_at, points_at
from .fit import arcs, arcs_within_radius, polyline
from .measure import max_deviation, measure_deviation
from .results import ArcDiscretisation, Deviation, Discretisation
from .tolerance import ToleranceError, validate_tol
from .within import measure_within

__all__ = [
    "ArcDiscretisation",
    "Chain",
    "CurveError",
    "Deviation",
    "Discretisation",
    "ParametricCurve",
    "ToleranceError",
    "arcs",
    "arcs_within_radius",
    "curvature_at",
    "max_deviation",
    "measure_deviation",
    "measure_within",
    "points_at",
    "polyline",
    "validate_tol",
]
