"""Polar lift table for cam grinders: cam angle against follower lift, as CSV.

Format: header ``angle_deg,lift_mm`` (``angle_deg,lift_deg`` for an oscillating follower, whose lift is
the arm angle in degrees), one row per angle, both columns with exactly 6 decimals, ``\\n`` line ends and
a final newline; ``-0.000000`` is written ``0.000000``.  Deterministic.
"""
from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path

import numpy as np

from camfab.errors import Problem, SpecError
from camfab.io import atomic_write

__all__ = ["HEADER", "lift_table_csv", "lift_angles", "write_lift_table"]

#: the CSV header line
HEADER = "angle_deg,lift_mm"


def _f6(v: float) -> str:
    s = f"{v:.6f}"
    return s[1:] if s == "-0.000000" else s


def lift_angles(step_deg: float) -> np.ndarray:
    """Angles ``0, step, 2 step, ... < 360`` in degrees; ``step_deg`` must divide 360.

    Raises
    ------
    SpecError
        Step not positive or not a divisor of 360 (within 1e-9).
    """
    if not (isinstance(step_deg, (int, float)) and math.isfinite(step_deg) and step_deg > 0):
        raise SpecError(Problem("step_deg", step_deg, "must be a positive number", "e.g. 1 or 0.5"))
    n = 360.0 / step_deg
    if abs(n - round(n)) > 1e-9 * max(1.0, n):
        raise SpecError(Problem("step_deg", step_deg, "must divide 360", "e.g. 0.25, 0.5, 1, 2, 5"))
    return np.arange(int(round(n))) * float(step_deg)


def lift_table_csv(angles_deg, lift_mm, *, lift_unit: str = "mm") -> str:
    """The polar lift table as CSV text.

    Parameters
    ----------
    angles_deg : array_like (n,)
        Cam angles in degrees.
    lift_mm : array_like (n,) or callable
        Follower lift at each angle in mm, or a function of the angle array (degrees) returning it.
    lift_unit : {"mm", "deg"}
        The unit of the lift, written into the header: "deg" for an oscillating follower's arm angle.

    Returns
    -------
    str

    Raises
    ------
    SpecError
        Empty input, different lengths, or non-finite values.
    """
    a = np.asarray(angles_deg, dtype=float).reshape(-1)
    lift = np.asarray(lift_mm(a) if callable(lift_mm) else lift_mm, dtype=float).reshape(-1)
    problems = []
    if a.size == 0:
        problems.append(Problem("angles_deg", [], "must not be empty", "give at least one angle"))
    if a.shape != lift.shape:
        problems.append(Problem("lift_mm", f"{lift.size} values", f"must match the {a.size} angles", ""))
    if not np.all(np.isfinite(a)):
        problems.append(Problem("angles_deg", "non-finite", "must be finite", ""))
    if not np.all(np.isfinite(lift)):
        problems.append(Problem("lift_mm", "non-finite", "must be finite", ""))
    if lift_unit not in ("mm", "deg"):
        problems.append(Problem("lift_unit", lift_unit, "is not a valid option", "must be one of: mm, deg"))
    if problems:
        raise SpecError(problems)
    rows = [f"angle_deg,lift_{lift_unit}"]
    rows += [f"{_f6(x)},{_f6(y)}" for x, y in zip(a.tolist(), lift.tolist(), strict=True)]
    return "\n".join(rows) + "\n"


def write_lift_table(path: str | Path, angles_deg, lift_mm: np.ndarray | Callable, *,
                     lift_unit: str = "mm") -> Path:
    """Write :func:`lift_table_csv` atomically to ``path``."""
    return atomic_write(path, lift_table_csv(angles_deg, lift_mm, lift_unit=lift_unit))
