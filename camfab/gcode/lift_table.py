"""Polar lift table for cam grinders: cam angle against follower lift (and the cam's radius), as CSV.

Format (docs/decisions.md, "Lift table format"): first the metadata, one ``# key: value`` line each (design
name, follower type and motion, roller and base radius, rotation sense, units, angle step, what angle 0 and
lift 0 mean, what the radius column is) - comment lines that ``pandas.read_csv(comment="#")``, spreadsheet
imports with a skip and ``grep -v '^#'`` pass over; then the column header ``angle_deg,lift_mm``
(``angle_deg,lift_deg`` for an oscillating follower, whose lift is the arm angle in degrees), with
``radius_mm`` (``radius_cam1_mm,radius_cam2_mm,...`` for several profiles) when radii are given: the distance
from the cam centre to the contact point on the profile at that angle.  One row per angle, every column with
exactly 6 decimals, ``\\n`` line ends and a final newline; ``-0.000000`` is written ``0.000000``.
Deterministic.  Without metadata and radii the table is the two columns alone.
"""
from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from camfab.errors import Problem, SpecError
from camfab.io import atomic_write
from camfab.textsafe import plain

__all__ = ["HEADER", "lift_table_csv", "lift_angles", "write_lift_table", "lift_metadata", "cylinder_lift_columns",
           "cylinder_lift_metadata", "cylinder_lift_csv"]

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


def lift_table_csv(angles_deg, lift_mm, *, lift_unit: str = "mm", radii_mm: Sequence | None = None,
                   meta: Mapping[str, str] | None = None, columns: Mapping[str, Any] | None = None) -> str:
    """The polar lift table as CSV text.

    Parameters
    ----------
    angles_deg : array_like (n,)
        Cam angles in degrees.
    lift_mm : array_like (n,) or callable
        Follower lift at each angle in mm, or a function of the angle array (degrees) returning it.
    lift_unit : {"mm", "deg"}
        The unit of the lift, written into the header: "deg" for an oscillating follower's arm angle.
    radii_mm : sequence of array_like (n,), optional
        Per profile, the cam radius at the contact point at each angle (mm): column ``radius_mm`` for one
        profile, ``radius_cam1_mm``, ``radius_cam2_mm``, ... for several.
    meta : mapping of str to str, optional
        Metadata written first as ``# key: value`` lines (values made one line of plain text).
    columns : mapping of str to array_like (n,), optional
        More columns after the lift (and the radii), by header name (a cylindrical cam's axial position and
        developed flanks: :func:`cylinder_lift_columns`).

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
    more = {k: np.asarray(v, dtype=float).reshape(-1) for k, v in (columns or {}).items()}
    radii = [np.asarray(r, dtype=float).reshape(-1) for r in (radii_mm or ())] + list(more.values())
    problems = []
    if a.size == 0:
        problems.append(Problem("angles_deg", [], "must not be empty", "give at least one angle"))
    if a.shape != lift.shape:
        problems.append(Problem("lift_mm", f"{lift.size} values", f"must match the {a.size} angles", ""))
    if any(r.shape != a.shape for r in radii):
        problems.append(Problem("radii_mm", [r.size for r in radii], f"must each match the {a.size} angles", ""))
    if not np.all(np.isfinite(a)):
        problems.append(Problem("angles_deg", "non-finite", "must be finite", ""))
    if not np.all(np.isfinite(lift)):
        problems.append(Problem("lift_mm", "non-finite", "must be finite", ""))
    if not all(np.all(np.isfinite(r)) for r in radii):
        problems.append(Problem("radii_mm", "non-finite", "must be finite", ""))
    if lift_unit not in ("mm", "deg"):
        problems.append(Problem("lift_unit", lift_unit, "is not a valid option", "must be one of: mm, deg"))
    if problems:
        raise SpecError(problems)
    rows = [f"# {plain(k)}: {plain(v)}" for k, v in (meta or {}).items()]
    n = len(radii) - len(more)
    names = ["radius_mm"] if n == 1 else [f"radius_cam{i + 1}_mm" for i in range(n)]
    names += list(more)
    rows.append(",".join(["angle_deg", f"lift_{lift_unit}", *names]))
    cols = [a.tolist(), lift.tolist(), *(r.tolist() for r in radii)]
    rows += [",".join(_f6(v) for v in row) for row in zip(*cols, strict=True)]
    return "\n".join(rows) + "\n"


def write_lift_table(path: str | Path, angles_deg, lift_mm: np.ndarray | Callable, *,
                     lift_unit: str = "mm") -> Path:
    """Write :func:`lift_table_csv` atomically to ``path``."""
    return atomic_write(path, lift_table_csv(angles_deg, lift_mm, lift_unit=lift_unit))


def lift_metadata(spec, step_deg: float, unit: str, n: int) -> dict[str, str]:
    """The lift table's metadata lines of the design ``spec`` (a DesignSpec) for ``n`` cams, lift in ``unit``
    (docs/decisions.md, "Lift table header and units")."""
    f = spec.follower
    roller = {"roller": f.roller_radius_mm, "curved": f.face_radius_mm}.get(str(f.type))
    lift = "arm angle of the oscillating follower, deg" if unit == "deg" else "follower travel, mm"
    col = "radius_mm" if n == 1 else f"radius_cam1_mm ... radius_cam{n}_mm"
    meta = {"table": "camfab polar lift table", "design": spec.name, "follower": f"{f.type.title}, {f.motion}",
            "roller radius": "none" if roller is None else f"{roller:g} mm",
            "base radius": "none" if f.base_radius_mm is None else f"{f.base_radius_mm:g} mm",
            "cam rotation": f"{spec.cam.rotation}",
            "units": f"angle_deg in degrees, lift_{unit} in {unit}, radius in mm",
            "angle step": f"{step_deg:g} deg",
            "angle 0": "the start of the first [[motion]] segment (S = 0 mark on the drawing)",
            "lift": f"{lift}; 0 = the follower on the base circle (its lowest position)",
            col: "distance from the cam centre to the contact point on the profile at that cam angle, mm"}
    return meta


def cylinder_lift_columns(geometry, angles_deg) -> dict[str, np.ndarray]:
    """A cylindrical cam's columns after the lift, on the pitch cylinder R developed (x = R·θ along its
    circumference from the follower's generator at cam angle 0, z along the axis): the roller axis's z (``z_mm``,
    the drawing sheet's ``Z mm``), the pitch point's x, and the contact point of the +z and the −z flank (a rib:
    the flank facing each roller) as x, z."""
    x = np.radians(np.asarray(angles_deg, dtype=float))
    r = geometry.cylinder.radius_mm
    plus, minus = geometry.at_radius(r, 1).evaluate(x), geometry.at_radius(r, -1).evaluate(x)
    return {"z_mm": plus.pitch[:, 1], "pitch_x_mm": plus.pitch[:, 0],
            "plus_flank_x_mm": plus.point[:, 0], "plus_flank_z_mm": plus.point[:, 1],
            "minus_flank_x_mm": minus.point[:, 0], "minus_flank_z_mm": minus.point[:, 1]}


def cylinder_lift_metadata(spec, geometry, step_deg: float, unit: str) -> dict[str, str]:
    """The metadata lines of a cylindrical cam's lift table (:func:`cylinder_lift_columns`)."""
    f, cyl = spec.follower, geometry.cylinder
    lift = "arm angle of the oscillating follower, deg" if unit == "deg" else "follower travel along the axis, mm"
    rib = str(cyl.feature) == "rib"
    return {"table": "camfab cylindrical cam lift table", "design": spec.name,
            "follower": f"{f.type.title}, {f.motion}", "roller radius": f"{f.roller_radius_mm:g} mm",
            "pitch radius": f"{cyl.radius_mm:g} mm", "feature": str(cyl.feature),
            "cam rotation": f"{spec.cam.rotation}",
            "units": f"angle_deg in degrees, lift_{unit} in {unit}, positions in mm",
            "angle step": f"{step_deg:g} deg",
            "angle 0": "the start of the first [[motion]] segment, the follower's generator at x = 0",
            "lift": f"{lift}; 0 = the start of the law",
            "z_mm": ("the rib's mid-line (the follower's pitch point; its rollers either side)" if rib else
                     "the roller axis's position")
                    + " along the cylinder axis from its z = 0 end face (the pitch curve)",
            "pitch_x_mm": "the pitch point on the pitch cylinder developed: x = R·theta along the circumference",
            "plus_flank_x_mm, plus_flank_z_mm": f"contact point on the +z {'rib' if rib else 'groove'} flank, "
                                                 "developed on the pitch cylinder",
            "minus_flank_x_mm, minus_flank_z_mm": f"contact point on the -z {'rib' if rib else 'groove'} flank, "
                                                   "developed on the pitch cylinder"}


def cylinder_lift_csv(spec, geometry, step_deg: float) -> str:
    """A cylindrical cam's lift table (docs/decisions.md, "Cylindrical cams: the lift table CSV"): every
    ``step_deg`` from 0 below 360, the lift and :func:`cylinder_lift_columns`, after its metadata."""
    ang = lift_angles(step_deg)
    unit = str(geometry.axis.lift_unit)
    lift = geometry.program.evaluate(np.radians(ang), (0,))[0]
    return lift_table_csv(ang, lift, lift_unit=unit, columns=cylinder_lift_columns(geometry, ang),
                          meta=cylinder_lift_metadata(spec, geometry, step_deg, unit))
