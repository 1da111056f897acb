"""The accepted discretisation tolerance and the margin every fit keeps below it."""
from __future__ import annotations

import math

from ..errors import InputError
from ..tolerances import DEFAULT_EXPORT_TOL_MM, MAX_EXPORT_TOL_MM, MIN_EXPORT_TOL_MM

__all__ = ["MARGIN", "ToleranceError", "validate_tol"]

#: refinement stops when the measured deviation is below ``tol * (1 - MARGIN)``
MARGIN = 0.05


class ToleranceError(InputError):
    """A discretisation tolerance outside the accepted range."""


def validate_tol(tol) -> float:
    """``tol`` (mm) as a float.

    Raises
    ------
    ToleranceError
        (a ``ValueError``) unless ``tol`` is a number in ``[MIN_EXPORT_TOL_MM, MAX_EXPORT_TOL_MM]``
        (1e-6 … 0.1 mm).
    """
    try:
        value = float(tol)
    except (TypeError, ValueError):
        value = math.nan
    if not (MIN_EXPORT_TOL_MM <= value <= MAX_EXPORT_TOL_MM):
        raise ToleranceError(f"tol must be in [{MIN_EXPORT_TOL_MM:g}, {MAX_EXPORT_TOL_MM:g}] mm, got {tol!r}; "
                             f"give a tolerance in that range (the default is {DEFAULT_EXPORT_TOL_MM:g} mm)")
    return value
