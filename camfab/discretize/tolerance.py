"""The accepted discretisation tolerance and the margin every fit keeps below it."""
from __future__ import annotations

import math

from ..errors import InputError
from ..tolerances import DEFAULT_EXPORT_TOL_MM, MAX_EXPORT_TOL_MM, MIN_EXPORT_TOL_MM

__all__ = ["MARGIN", "WRITE_ROOM_MM", "ToleranceError", "validate_tol", "within"]

#: refinement stops when the measured deviation is below ``tol * (1 - MARGIN)``
MARGIN = 0.05
#: a fit is accepted when its measured deviation is at most ``tol - WRITE_ROOM_MM`` (mm): the room the writers'
#: rounding and a reader's reconstruction need (17 significant digits, bulges back to arcs: ~1e-14 mm on a
#: 100 mm cam), so that a fit landing exactly on ``tol`` (a 1 µm bump left out at tol = 1 µm) still reads back
#: within it.  A thousandth of the smallest accepted tolerance.
WRITE_ROOM_MM = 1e-9


def within(measured: float, tol: float) -> bool:
    """True when a measured deviation is acceptable for ``tol``: at most ``tol - WRITE_ROOM_MM``."""
    return measured <= tol - WRITE_ROOM_MM


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
