"""Knot-table motions: rows ``(angle, s, v, a[, j])`` joined by Hermite polynomials.

A knot table is the ``[motion_table]`` alternative to ``[[motion]]`` segments
(a valve lift given as a table of points, for instance).  Each row
fixes the follower's displacement and its derivatives at one cam angle; between
consecutive knots the displacement is the unique polynomial meeting both ends:

* ``degree = 5`` (default): quintic Hermite through ``s, v, a`` — C² everywhere,
  the jerk generally jumps at knots;
* ``degree = 7``: 7th-degree Hermite through ``s, v, a, j`` — C³ everywhere.

The result is an ordinary :class:`~camfab.design.program.MotionProgram` whose
segments have ``law = "hermite5" | "hermite7"``: S in mm, derivatives per
radian of cam angle, coefficients in ``u = (x − start)/span`` exactly like the
generic polynomials.

Units
-----
``units = {angle, s, v, a, j}`` with ``angle`` in ``deg | rad``, ``s`` in
``mm | m``, ``v`` in ``mm/deg | mm/rad | m/s | mm/s``, ``a`` in
``mm/deg2 | mm/rad2 | m/s2 | mm/s2`` and ``j`` likewise with ``3``.  ``^2`` and
``²`` are accepted for ``2``.  Time units need the design speed
``speed_rpm`` (ω in rad/s): ``S′ = v/ω``, ``S″ = a/ω²``, ``S‴ = j/ω³``.
Defaults: ``angle = "deg"``, ``s = "mm"``; a missing ``v``/``a``/``j`` takes the
length and denominator of the first of them that is given (``a = "m/s2"``
implies ``v = "m/s"``), or ``mm`` per table angle unit when none is given.

Cycle (closure rule)
--------------------
The table covers one revolution and starts at angle 0; angles increase
strictly and never exceed 360° (2π rad).

* Last row **at 360°**: it must repeat the 0° row (equal s, v, a and, for
  degree 7, j, to 1e-9 relative); the program closes there.
* Last row **below 360°**: a closing segment runs from the last row to 360°
  and ends on the values of the 0° row (the 0° row is reused at 360°).

Either way the program is periodic and C² (C³) at 0°/360° as well.

Validation and warnings
-----------------------
:func:`build_knot_table` checks everything that can be checked on the rows
and reports every problem at once in one :class:`~camfab.errors.SpecError`
(paths such as ``motion_table.rows[3][1]`` or ``motion_table.units.v``; rows
are counted from 0, after any header, also for rows read from a file).
:meth:`KnotTable.program` also rejects a program whose exact minimum S is
below 0 (the follower would cross the base/prime circle), naming every
offending segment.  :meth:`KnotTable.warnings` lists segments whose implied
peak ``|S″|`` (and ``|S‴|`` for degree 7) is more than ``ratio`` (default 5)
times the largest value given at the segment's two knots — the symptom of
rounded or otherwise inconsistent knots (s printed to 0.1 mm beside v and a
to four digits).  The default is 5, not 10: the printed valve PUNTOS matrix of
Example 2 peaks at 9× (Example 1 at 18.6×), while Example 1 with s
reconstructed to 1 µm (``valve_recon_ej1.csv``) stays at 4.1×; a smooth motion
sampled at several knots per acceleration swing stays close to 1×.  A segment whose two knots both
give exactly 0 leaves that derivative to the interpolant (a dwell or a
rest-to-rest rise) and is not compared.

Files
-----
The core reads no files.  A ``file = "puntos.csv"`` is read by
:mod:`camfab.formats` (relative to the design file's folder), which hands the
rows over as a :class:`KnotFile`; they are validated like inline rows and
messages name the file.
"""
from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import Problem, SpecError
from ..limits import MAX_KNOTS, MAX_LIFT_MM
from ..records import dataclass, field
from ..results import Finding, IssueCode, Severity
from ..tolerances import ANGLE_SUM_TOL_DEG
from ..units import DEG, rpm_to_rad_s
from .extrema import polynomial_roots
from .laws import derivative_rows, horner
from .program import MotionProgram, Segment, hermite_coefficients

__all__ = [
    "UNITS",
    "KnotTable",
    "KnotFile",
    "TABLE_KEYS",
    "build_knot_table",
]

TWO_PI = 2.0 * math.pi
#: valid unit strings per column, in the order they are listed in errors
UNITS: dict[str, tuple[str, ...]] = {
    "angle": ("deg", "rad"),
    "s": ("mm", "m"),
    "v": ("mm/deg", "mm/rad", "m/s", "mm/s"),
    "a": ("mm/deg2", "mm/rad2", "m/s2", "mm/s2"),
    "j": ("mm/deg3", "mm/rad3", "m/s3", "mm/s3"),
}
COLUMNS = ("angle", "s", "v", "a", "j")
TABLE_KEYS = ("rows", "file", "units", "speed_rpm", "degree")
#: the largest ``speed_rpm`` of a knot table: that of ``[cam] speed_rpm`` (past it ω³ overflows a float for a
#: table in time units)
MAX_TABLE_SPEED_RPM = 1e6
#: two knot values are "equal" (360° row = 0° row) within this relative tolerance
CLOSURE_REL_TOL = 1e-9
#: default ratio of implied peak to knot values above which a segment is flagged
WARN_RATIO = 5.0
_LENGTH_MM = {"mm": 1.0, "m": 1000.0}
_TITLES = {5: "Quintic Hermite knot segment", 7: "7th-degree Hermite knot segment"}


# ---------------------------------------------------------------------------
# results
@dataclass(frozen=True, slots=True)
class KnotFile:
    """The ``file`` of a ``[motion_table]`` once read (by :mod:`camfab.formats`).

    The formats layer reads the file once, relative to the design file's folder,
    and hands this value to the core in place of the name; the rows are then
    validated exactly like inline rows.

    Attributes
    ----------
    name : str
        The file name as written in the design (shown in reports).
    path : str
        The file that was read (named in messages).
    rows : tuple of tuple of float, or None
        The data rows, header and comments dropped; None when the file could
        not be read.
    problems : tuple of Problem
        Why it could not be read (reported with the design's other problems).
    """

    name: str
    path: str
    rows: tuple[tuple[float, ...], ...] | None
    problems: tuple[Problem, ...] = ()

    def __str__(self) -> str:
        return self.name


@dataclass(frozen=True, eq=False)
class KnotTable:
    """A validated knot table (build it with :func:`build_knot_table`).

    Attributes
    ----------
    angles : (n,) float, radians
        Knot angles, strictly increasing from 0, at most 2π.
    values : (n, 4) float
        S (mm), S′ (mm/rad), S″ (mm/rad²), S‴ (mm/rad³; NaN where not given).
    degree : int
        5 (quintic, C²) or 7 (C³).
    units : dict of str
        The resolved table units (every column).
    raw : (n, 5) float
        The rows as given (NaN where j is absent).
    speed_rpm : float or None
        Design speed the time units refer to.
    path, source : str
        Field path and file (for messages).
    """

    angles: np.ndarray
    values: np.ndarray
    degree: int = 5
    units: Mapping[str, str] = field(default_factory=dict)
    raw: np.ndarray | None = None
    speed_rpm: float | None = None
    path: str = "motion_table"
    source: str | None = None

    @classmethod
    def from_rows(cls, rows: Sequence[Sequence[float]], *, units: Mapping[str, str] | None = None,
                  speed_rpm: float | None = None, degree: int = 5, path: str = "motion_table",
                  source: str | None = None) -> KnotTable:
        """Validate rows ``(angle, s, v, a[, j])`` and build the table.

        Raises
        ------
        SpecError
            With every problem found (see the module docstring).
        """
        return _build(rows, units, speed_rpm, degree, path, source, [])

    @property
    def closed(self) -> bool:
        """True when the table has its own 360° row."""
        return bool(self.angles[-1] == TWO_PI)

    def cycle_knots(self) -> tuple[np.ndarray, np.ndarray]:
        """Knots of the full cycle, the 360° knot included.

        Returns
        -------
        x : (m,) float, radians
            From 0 to 2π inclusive.
        values : (m, 4) float
            S, S′, S″, S‴ per radian at each knot.
        """
        if self.closed:
            return self.angles, self.values
        return np.append(self.angles, TWO_PI), np.vstack([self.values, self.values[:1]])

    def segments(self) -> tuple[Segment, ...]:
        """The Hermite segments between consecutive knots."""
        x, vals = self.cycle_knots()
        m = 3 if self.degree == 5 else 4
        law = f"hermite{self.degree}"
        out = []
        for i in range(len(x) - 1):
            span = float(x[i + 1] - x[i])
            c = hermite_coefficients(vals[i, :m], vals[i + 1, :m], span)
            out.append(Segment(law, float(vals[i + 1, 0] - vals[i, 0]), span, float(x[i]),
                               float(vals[i, 0]), tuple(float(ci) for ci in c), _TITLES[self.degree]))
        return tuple(out)

    def program(self, *, check: bool = True) -> MotionProgram:
        """The knot motion as a :class:`MotionProgram` (S in mm, per radian).

        Parameters
        ----------
        check : bool
            Reject a program whose exact minimum S is below 0 (default).
            ``check=False`` returns it anyway, for inspecting a bad table.

        Raises
        ------
        SpecError
            When ``check`` and S goes below 0, naming every offending segment.
        """
        prog = MotionProgram(self.segments(), TWO_PI)
        if check:
            smin = prog.peaks("exact")[0]
            if smin.min < -1e-9 * max(1.0, abs(smin.max)):
                raise SpecError(self._below_zero(prog.segments), self.source)
        return prog

    def _below_zero(self, segs: Sequence[Segment]) -> list[Problem]:
        problems = []
        n = len(self.angles)
        for i, seg in enumerate(segs):
            lo, _, at, _ = _extremes(seg, 0)
            if lo < -1e-9 * max(1.0, float(np.max(np.abs(self.values[:, 0])))):
                deg = math.degrees(seg.start + at * seg.span)
                problems.append(Problem(
                    f"{self.path}.rows[{i}]", self.raw[i, :4].tolist() if self.raw is not None else i,
                    f"S goes below 0 (to {lo:.6g} mm at {deg:.6g}°) between rows {i} and {(i + 1) % n}: "
                    "the follower would cross the base/prime circle",
                    "give s, v, a at full precision and mutually consistent, or add a knot"))
        return problems

    def warnings(self, ratio: float = WARN_RATIO) -> list[Finding]:
        """Segments whose implied peak ``|S″|`` (``|S‴|``) is far above the knots'.

        Parameters
        ----------
        ratio : float
            Flag a segment when its peak exceeds ``ratio`` times the largest
            magnitude given at its two knots.

        Returns
        -------
        list of Finding
            ``KNOT_INCONSISTENT`` warnings in segment order (for degree 7, the acceleration before
            the jerk per segment): ``from_deg``/``to_deg`` the segment, ``value`` the implied peak
            and ``limit`` the largest knot magnitude, both in the table's ``a`` (``j``) unit.
        """
        segs = self.segments()
        _, vals = self.cycle_knots()
        orders = (2,) if self.degree == 5 else (2, 3)
        out = []
        for nu in orders:
            col = np.abs(vals[:, nu])
            floor = 1e-12 * float(col.max())
            for i, (seg, (lo, hi, _, _)) in enumerate(zip(segs, _extremes_all(segs, nu), strict=True)):
                ref = max(col[i], col[i + 1])
                peak = max(abs(lo), abs(hi))
                if ref > floor and peak > ratio * ref:
                    out.append((i, nu, self._warning(i, seg, nu, peak, ref)))
        return [w for _, _, w in sorted(out, key=lambda t: (t[0], t[1]))]

    def _warning(self, i: int, seg: Segment, nu: int, peak: float, ref: float) -> Finding:
        key = "a" if nu == 2 else "j"
        unit = self.units[key]
        f = _factor(unit, nu + 1, self._omega())
        lo, hi = math.degrees(seg.start), math.degrees(seg.end)
        name = "acceleration" if nu == 2 else "jerk"
        msg = (f"segment {i} ({lo:.6g}°–{hi:.6g}°): the {name} implied between the knots reaches "
               f"{peak / f:.6g} {unit}, {peak / ref:.3g}× the largest knot value ({ref / f:.6g} {unit}); "
               "the knot values are mutually inconsistent (rounded s?) — give them at full precision")
        return Finding(IssueCode.KNOT_INCONSISTENT, Severity.WARNING, lo, hi, peak / f, ref / f, msg)

    def _omega(self) -> float:
        return rpm_to_rad_s(self.speed_rpm) if self.speed_rpm else float("nan")


def _extremes(seg: Segment, nu: int) -> tuple[float, float, float, float]:
    """Exact (min, max, u_min, u_max) of S⁽ⁿᵘ⁾ (per radian) over one polynomial segment."""
    return _extremes_all([seg], nu)[0]


def _extremes_all(segs: Sequence[Segment], nu: int) -> list[tuple[float, float, float, float]]:
    """:func:`_extremes` of each segment, the roots of all found together: bit for bit numpy's
    ``Polynomial(coeffs).deriv(nu)`` path (``derivative_rows`` is polyder's ``j·cⱼ``, ``horner`` polyval's rule,
    :func:`extrema.polynomial_roots` polyroots; the domain map is the identity), without importing
    ``numpy.polynomial`` (~5 ms of a check)."""
    rows = []
    for seg in segs:
        assert seg.coeffs is not None  # a knot table's segments are Hermite polynomials (KnotTable.segments)
        rows.append(derivative_rows(seg.coeffs, nu + 2)[nu:])
    moving = [i for i, (d, _) in enumerate(rows) if len(d) > 1]
    roots = dict(zip(moving, polynomial_roots([np.asarray(rows[i][1]) for i in moving]), strict=True))
    out = []
    for i, (seg, (d, _)) in enumerate(zip(segs, rows, strict=True)):
        r = roots.get(i, np.array([]))
        r = r.real[(np.abs(r.imag) <= 1e-12) & (r.real > 0.0) & (r.real < 1.0)]
        u = np.concatenate([[0.0, 1.0], r])
        vals = horner(np.asarray(d), u) / seg.span**nu
        out.append((float(vals.min()), float(vals.max()), float(u[vals.argmin()]), float(u[vals.argmax()])))
    return out


# ---------------------------------------------------------------------------
# units
def _norm_unit(unit: Any) -> Any:
    if not isinstance(unit, str):
        return unit
    return unit.strip().lower().replace(" ", "").replace("^", "").replace("²", "2").replace("³", "3")


def _factor(unit: str, col: int, omega: float) -> float:
    """Multiplier from the table unit of column ``col`` to mm and radians."""
    if col == 0:
        return DEG if unit == "deg" else 1.0
    length, _, per = unit.partition("/")
    k = col - 1
    f = _LENGTH_MM[length]
    if k == 0 or per.startswith("rad"):
        return f
    return f / DEG**k if per.startswith("deg") else f / omega**k


def _resolve_units(units: Any, path: str, problems: list[Problem]) -> dict[str, str]:
    """Resolved unit strings for every column (invalid ones left out)."""
    p = f"{path}.units"
    if units is None:
        units = {}
    if not isinstance(units, Mapping):
        problems.append(Problem(p, units, "units must be a table", 'e.g. units = { angle = "deg", s = "mm", '
                                'v = "mm/deg", a = "mm/deg2" }'))
        units = {}
    out: dict[str, str] = {}
    for key, val in units.items():
        if key not in UNITS:
            problems.append(Problem(f"{p}.{key}", val, "unknown column", "use keys: " + ", ".join(UNITS)))
        elif _norm_unit(val) not in UNITS[key]:
            problems.append(Problem(f"{p}.{key}", val, f"unknown unit for {key}",
                                    "use one of: " + ", ".join(UNITS[key])))
        else:
            out[key] = _norm_unit(val)
    out.setdefault("angle", "deg")
    out.setdefault("s", "mm")
    given = [out[k] for k in ("v", "a", "j") if k in out]
    length, per = given[0].split("/") if given else ("mm", out["angle"])
    per = per.rstrip("23")
    for k, suffix in (("v", ""), ("a", "2"), ("j", "3")):
        out.setdefault(k, f"{length}/{per}{suffix}")
    return out


def _omega_from(speed: Any, units: Mapping[str, str], degree: int, path: str,
                problems: list[Problem]) -> float:
    """ω (rad/s) from ``speed_rpm``, checking it is there when time units need it."""
    used = ("v", "a", "j") if degree == 7 else ("v", "a")
    timed = [k for k in used if units.get(k, "").split("/")[-1].startswith("s")]
    p = f"{path}.speed_rpm"
    if speed is None:
        if timed:
            problems.append(Problem(p, None, f"time units ({', '.join(f'{k} = {units[k]}' for k in timed)}) "
                                    "need the design speed", "add speed_rpm = the camshaft speed the table "
                                    "was written for, or give v, a in mm/deg or mm/rad"))
        return float("nan")
    if not _is_real(speed) or not math.isfinite(speed) or not 0 < speed <= MAX_TABLE_SPEED_RPM:
        problems.append(Problem(p, speed, f"speed_rpm must be a number > 0 and <= {MAX_TABLE_SPEED_RPM:g} (the bound "
                                "of [cam] speed_rpm)", "give the speed in rpm"))
        return float("nan")
    return rpm_to_rad_s(float(speed))


# ---------------------------------------------------------------------------
# validation
def _is_real(x: Any) -> bool:
    return isinstance(x, (int, float, np.integer, np.floating)) and not isinstance(x, (bool, np.bool_))


def _rows_array(rows: Any, degree: int, path: str, problems: list[Problem]) -> np.ndarray | None:
    """(n, 5) float array of the rows (NaN where invalid or absent)."""
    p = f"{path}.rows"
    if isinstance(rows, (str, bytes)) or not isinstance(rows, Sequence) or len(rows) == 0:
        problems.append(Problem(p, rows, "the knot table has no rows", "give rows = [[angle, s, v, a], ...]"))
        return None
    if len(rows) > MAX_KNOTS:  # not read further (docs/decisions.md, "Input limits")
        problems.append(Problem(p, f"{len(rows)} rows", f"more than the limit of {MAX_KNOTS} knots",
                                f"give at most {MAX_KNOTS} knots (a 0.1° table has 3600; thin a denser one out)"))
        return None
    out = np.full((len(rows), 5), np.nan)
    for i, row in enumerate(rows):
        if isinstance(row, (str, bytes)) or not isinstance(row, Sequence) or len(row) not in (4, 5):
            problems.append(Problem(f"{p}[{i}]", row, "a knot row holds 4 numbers (angle, s, v, a) "
                                    "or 5 (angle, s, v, a, j)", "fix the length of this row"))
            continue
        if degree == 7 and len(row) == 4:
            problems.append(Problem(f"{p}[{i}][4]", None, "degree 7 needs the jerk j in a 5th column",
                                    "add j to every row, or set degree = 5"))
        for k, x in enumerate(row):
            if _is_real(x) and math.isfinite(x):
                out[i, k] = float(x)
            else:
                problems.append(Problem(f"{p}[{i}][{k}]", x, f"{COLUMNS[k]} must be a finite number",
                                        "fix or remove the value"))
    return out


def _check_cycle(raw: np.ndarray, degree: int, angle_unit: str, path: str,
                 problems: list[Problem]) -> None:
    """Angle order and coverage, s ≥ 0 and the 360° closure (vectorised)."""
    p = f"{path}.rows"
    full = 360.0 if angle_unit == "deg" else TWO_PI
    tol = ANGLE_SUM_TOL_DEG * (1.0 if angle_unit == "deg" else DEG)
    ang = raw[:, 0]
    if abs(ang[0]) > tol:
        problems.append(Problem(f"{p}[0][0]", float(ang[0]), "the table must start at angle 0",
                                "add a row at 0 or rotate the table so that it starts there"))
    for i in np.flatnonzero(np.diff(ang) <= 0):
        problems.append(Problem(f"{p}[{i + 1}][0]", float(ang[i + 1]), "angles must increase strictly",
                                f"make it larger than {ang[i]:.12g} (row {i})"))
    for i in np.flatnonzero(ang > full + tol):
        problems.append(Problem(f"{p}[{i}][0]", float(ang[i]),
                                f"angles must lie within one revolution (0 … {full:.12g})",
                                "the table covers one revolution; drop rows beyond it"))
    for i in np.flatnonzero(raw[:, 1] < 0):
        problems.append(Problem(f"{p}[{i}][1]", float(raw[i, 1]),
                                "s must not be below 0 (S = 0 is the base/prime circle)",
                                "measure s from the base circle"))
    if len(ang) > 1 and abs(ang[-1] - full) <= tol:
        _check_closure(raw, degree, f"{full:g}", p, problems)


def _check_closure(raw: np.ndarray, degree: int, full: str, p: str, problems: list[Problem]) -> None:
    """A row at 360° must repeat the 0° row (s, v, a and, for degree 7, j)."""
    cols = np.arange(1, 4 if degree == 5 else 5)
    scale = np.max(np.nan_to_num(np.abs(raw[:, cols])), axis=0)
    bad = np.abs(raw[-1, cols] - raw[0, cols]) > CLOSURE_REL_TOL * scale
    last = len(raw) - 1
    for k in cols[bad]:
        problems.append(Problem(f"{p}[{last}][{k}]", float(raw[-1, k]),
                                f"the {full} row must repeat the 0 row (the cycle closes)",
                                f"set {COLUMNS[k]} = {raw[0, k]:.12g}, or drop the {full} row "
                                "(the table then closes from its last row back to row 0)"))


def _knot_intervals(angles: np.ndarray) -> np.ndarray | None:
    """Per knot, the longer of the two segments it bounds (radians, the closing segment included); None
    when the angles do not increase strictly from 0 to at most 2π (reported by the cycle rules)."""
    seg = np.diff(angles)
    if angles[0] != 0.0 or not np.all(seg > 0) or angles[-1] > TWO_PI * (1 + 1e-12):
        return None
    if abs(angles[-1] - TWO_PI) > ANGLE_SUM_TOL_DEG * DEG or len(angles) == 1:
        seg = np.append(seg, TWO_PI - angles[-1])  # the closing segment back to row 0
    i = np.arange(len(angles))
    m = len(seg)
    return np.maximum(seg[np.minimum(i, m - 1)], seg[(i - 1) % m])


def _check_magnitudes(raw: np.ndarray, units: Mapping[str, str], omega: float, degree: int, path: str,
                      problems: list[Problem]) -> None:
    """The input limits of knot values (``docs/decisions.md``, "Input limits"): s within
    :data:`~camfab.limits.MAX_LIFT_MM`, and each derivative no larger than one that alone would move the
    follower that far over the knot's own interval g: |S⁽ᵏ⁾|·gᵏ/k! ≤ MAX_LIFT_MM (per radian)."""
    p = f"{path}.rows"
    angle_factor = DEG if units.get("angle", "deg") == "deg" else 1.0
    with np.errstate(over="ignore", invalid="ignore"):
        s_mm = np.abs(raw[:, 1] * _LENGTH_MM.get(units.get("s", "mm"), 1.0))
        for i in np.flatnonzero(s_mm > MAX_LIFT_MM):
            problems.append(Problem(f"{p}[{i}][1]", float(raw[i, 1]), f"s is {s_mm[i]:.6g} mm, beyond the "
                                    f"input limit of {MAX_LIFT_MM:g} mm", "check the value and the units of s"))
        g = _knot_intervals(raw[:, 0] * angle_factor)
        if g is None:
            return
        for k in range(1, 4 if degree == 7 else 3):
            unit = units.get(COLUMNS[k + 1])
            f = _factor(unit, k + 1, omega) if unit else math.nan
            move = np.abs(raw[:, k + 1] * f) * g**k / math.factorial(k)
            for i in np.flatnonzero(move > MAX_LIFT_MM):
                problems.append(Problem(
                    f"{p}[{i}][{k + 1}]", float(raw[i, k + 1]),
                    f"{COLUMNS[k + 1]} = {raw[i, k + 1]:.6g} {unit} alone would move the follower {move[i]:.3g} mm "
                    f"over its knot interval ({math.degrees(g[i]):.6g}°), beyond the input limit of "
                    f"{MAX_LIFT_MM:g} mm", f"check the value and the units of {COLUMNS[k + 1]}"))


def _build(rows: Any, units: Any, speed: Any, degree: Any, path: str, source: str | None,
           problems: list[Problem]) -> KnotTable:
    if isinstance(degree, bool) or degree not in (5, 7):
        problems.append(Problem(f"{path}.degree", degree, "degree must be 5 (quintic, C2) or 7 (C3)",
                                "set degree = 5 or 7"))
        degree = 5
    degree = int(degree)
    resolved = _resolve_units(units, path, problems)
    omega = _omega_from(speed, resolved, degree, path, problems)
    # rows is None when a file could not be read (already reported)
    raw = _rows_array(rows, degree, path, problems) if rows is not None or not problems else None
    if raw is not None:
        _check_cycle(raw, degree, resolved["angle"], path, problems)
        _check_magnitudes(raw, resolved, omega, degree, path, problems)
    if problems:
        raise SpecError(problems, source)
    assert raw is not None
    factors = np.array([_factor(resolved[c], k, omega) if c in resolved else np.nan
                        for k, c in enumerate(COLUMNS)])
    conv = raw * factors
    angles, values = conv[:, 0], conv[:, 1:]
    angles[0] = 0.0
    if len(angles) > 1 and abs(angles[-1] - TWO_PI) <= ANGLE_SUM_TOL_DEG * DEG:
        angles[-1] = TWO_PI
        values[-1] = values[0]
    if degree == 5:
        values[:, 3] = np.nan
    return KnotTable(angles, values, degree, resolved, raw, None if speed is None else float(speed),
                     path, source)


# ---------------------------------------------------------------------------
# the [motion_table] entry point
def build_knot_table(table: Mapping[str, Any], *, path: str = "motion_table") -> KnotTable:
    """Build a :class:`KnotTable` from a ``[motion_table]`` dict whose rows are at hand.

    Parameters
    ----------
    table : dict
        ``{"rows": [[angle, s, v, a(, j)], ...]}``, or ``{"file": KnotFile}`` (a
        file already read by the formats layer), plus optional ``units`` (dict),
        ``speed_rpm`` (float) and ``degree`` (5 or 7).
    path : str
        Field path used in messages.

    Returns
    -------
    KnotTable

    Raises
    ------
    SpecError
        With every problem found, each naming its field path.

    Examples
    --------
    >>> t = build_knot_table({"rows": [[0, 0, 0, 0], [90, 5, 0, 0], [180, 0, 0, 0]]})
    >>> round(float(t.program()(np.pi / 2)[0]), 12)
    5.0
    """
    if not isinstance(table, Mapping):
        raise SpecError(Problem(path, table, "must be a table", 'e.g. [motion_table] file = "puntos.csv"'))
    problems = [Problem(f"{path}.{k}", table[k], "unknown key", "use keys: " + ", ".join(TABLE_KEYS))
                for k in table if k not in TABLE_KEYS]
    rows, source = _table_rows(table, path, problems)
    return _build(rows, table.get("units"), table.get("speed_rpm"), table.get("degree", 5), path,
                  source, problems)


def _table_rows(table: Mapping[str, Any], path: str, problems: list[Problem]) -> tuple[Any, str | None]:
    """The rows (None when missing or unreadable, reported) and the file they came from."""
    has_rows, has_file = "rows" in table, "file" in table
    if has_rows == has_file:
        problems.append(Problem(path, sorted(k for k in ("rows", "file") if k in table),
                                "give exactly one of rows and file",
                                'rows = [[angle, s, v, a], ...] or file = "puntos.csv"'))
        return table.get("rows", [[]]) if has_rows else None, None
    if has_rows:
        return table["rows"], None
    file = table["file"]
    if isinstance(file, KnotFile):
        problems.extend(file.problems)
        return file.rows, file.path
    if not isinstance(file, (str, Path)) or not str(file):
        problems.append(Problem(f"{path}.file", file, "file must be a path", 'e.g. file = "puntos.csv"'))
    else:
        problems.append(Problem(f"{path}.file", file, "the file has not been read (the design core reads "
                                "no files)", "load the design with camfab.formats.load_design (or "
                                "camfab.formats.design_from_data for a dict), or give rows = [...]"))
    return None, None
