"""Helpers shared by the plots, the animation and the HTML pages.

Nothing here imports matplotlib or jinja2: these are the numbers and words of
the report (sampling grids, angle ranges, the CAM-DAS conclusions rows).
"""
from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..design.kinds import FollowerType
from ..records import dataclass
from ..results import CURVATURE_CODES, JUMP_CODES, IssueCode, Severity, Verdict

__all__ = ["Axis", "axis_of", "sample_grid", "finding_spans", "fmt", "fmt_at", "range_text",
           "conclusions_rows", "VERDICT_TEXT", "VERDICT_CLASS", "mechanism_text", "key_values",
           "CURVATURE_CODES", "table_cell"]

#: verdict → headline (same words as ``camfab check``)
VERDICT_TEXT = {Verdict.ACCEPTABLE: "Cam OK (acceptable)",
                Verdict.NOT_FOR_HIGH_SPEED: "Not suitable for high speeds",
                Verdict.UNACCEPTABLE: "Cam KO (unacceptable)"}
#: verdict → CSS class / colour family
VERDICT_CLASS = {Verdict.ACCEPTABLE: "ok", Verdict.NOT_FOR_HIGH_SPEED: "warn", Verdict.UNACCEPTABLE: "bad"}


@dataclass(frozen=True)
class Axis:
    """The independent variable of a design in user units.

    Attributes
    ----------
    period : float
        Program period in internal units (2π rad, or the cam length in mm).
    scale : float
        User units per internal unit (180/π for disc cams, 1 for translating cams).
    unit : str
        "°" or "mm" (for labels).
    label : str
        Axis label ("cam angle (°)" or "cam travel (mm)").
    """

    period: float
    scale: float
    unit: str
    label: str

    @property
    def user_period(self) -> float:
        """The period in user units (360° or the cam length in mm)."""
        return self.period * self.scale

    @property
    def closed(self) -> bool:
        return self.unit == "°"


def axis_of(prog) -> Axis:
    """:class:`Axis` of a motion program (disc cam: degrees; translating cam: mm)."""
    per = float(prog.period)
    if abs(per - 2 * math.pi) < 1e-12:
        return Axis(per, 180.0 / math.pi, "°", "cam angle (°)")
    return Axis(per, 1.0, "mm", "cam travel (mm)")


def sample_grid(period: float, breakpoints, n: int = 1441) -> np.ndarray:
    """Sampling parameters (internal units) for plots: ``n`` even steps over one period
    plus both one-sided limits at every breakpoint, so jumps plot as vertical lines and
    no sample straddles a kink.

    Parameters
    ----------
    period : float
    breakpoints : (m,) float
        Where a formula changes (0 and ``period`` may be included).
    n : int

    Returns
    -------
    (k,) float, increasing, in [0, period)
        The last value is a hair below ``period`` (the left limit of the last segment).
    """
    eps = 1e-9 * period
    b = np.asarray(breakpoints, dtype=float)
    b = b[(b > 0) & (b < period)]
    x = np.concatenate([np.linspace(0.0, period, n)[:-1], b - eps, b, [period - eps]])
    return np.unique(x)


def finding_spans(findings, codes, axis: Axis) -> list[tuple[float, float]]:
    """``[(from, to), ...]`` in user units of the findings with the given codes; a range
    that wraps through the period end is split in two; a point has from == to."""
    out = []
    for f in findings:
        if f.code not in codes or f.from_deg is None:
            continue
        a, b = float(f.from_deg), float(f.to_deg if f.to_deg is not None else f.from_deg)
        if a > b and axis.closed:
            out += [(a, axis.user_period), (0.0, b)]
        else:
            out.append((a, b))
    return out


def fmt(v, digits: int = 2) -> str:
    """A table number: fixed ``digits`` decimals, or 5 significant digits when huge; "--" for None."""
    if v is None:
        return "--"
    v = float(v)
    if not math.isfinite(v):
        return "∞" if v > 0 else ("−∞" if v < 0 else "--")
    return f"{v:.{digits}f}" if abs(v) < 1e7 else f"{v:.5g}"


def fmt_at(v, unit: str = "°") -> str:
    """A position: ``123.4°`` or ``12.3 mm``; "" for None."""
    if v is None:
        return ""
    return f"{float(v):.1f}{unit}" if unit == "°" else f"{float(v):.2f} {unit}"


def range_text(f, unit: str = "°") -> str:
    """Where a finding applies, in words ("at 50.0°", "from 10.0° to 20.0°", "from 350.0° through 0° to 10.0°")."""
    if f.from_deg is None:
        return "whole cycle"
    a, b = float(f.from_deg), float(f.to_deg if f.to_deg is not None else f.from_deg)
    if abs(a - b) < 1e-9:
        return f"at {fmt_at(a, unit)}"
    if a > b and unit == "°":
        return f"from {fmt_at(a, unit)} through 0° to {fmt_at(b, unit)}"
    return f"from {fmt_at(a, unit)} to {fmt_at(b, unit)}"


def mechanism_text(spec) -> str:
    """One line describing the mechanism ("disc cam (cw), translating roller follower"); the follower's name
    is :attr:`FollowerType.title` ("roller", "flat-face", "knife-edge", "curved-face")."""
    c, f = spec.cam, spec.follower
    kind = c.kind.replace("_", "-")
    sense = f"slides {c.direction}" if c.kind == "translating" else c.rotation
    ftype = FollowerType(f.type).title
    double = "double " if c.kind in ("conjugate", "constant_width", "constant_diameter") else ""
    return f"{kind} cam ({sense}), {double}{f.motion} {ftype} follower"


def table_cell(value, at=None, unit="°") -> dict[str, Any]:
    """A cell of the conclusions table: the value as text and as a number, and where it is reached."""
    return {"text": fmt(value), "value": None if value is None else float(value),
            "at": fmt_at(at, unit) if value is not None else "", "at_value": None if at is None else float(at)}


def conclusions_rows(spec, report) -> list[dict[str, Any]]:
    """The CAM-DAS conclusions table (as ``camfab check`` prints it), one dict per row.

    Each row has ``concept``, ``max`` and ``min`` cells (``text``, ``value`` – the exact
    report number –, ``at``, ``at_value``), ``comment`` and ``status`` ("ok", "warn", "bad").
    """
    lu = spec.follower.lift_unit
    xu = "°" if report.x_unit == "deg" else "mm"
    codes = report.codes()
    names = {"S": f"Displacement ({lu})", "V": f"Velocity ({lu}/s)", "A": f"Acceleration ({lu}/s²)",
             "J": f"Jerk ({lu}/s³)"}
    rows = []
    for q, p in report.motion.peaks.items() if report.motion is not None else ():
        jump = q in JUMP_CODES and JUMP_CODES[q] in codes
        sev = {f.severity for f in report.findings if q in JUMP_CODES and f.code == JUMP_CODES[q]}
        rows.append({"concept": names[q], "max": table_cell(p.max, p.at_max, xu),
                     "min": table_cell(p.min, p.at_min, xu),
                     "comment": "Discontinuous" if jump else "Continuous",
                     "status": ("bad" if Severity.ERROR in sev else "warn") if jump else "ok"})
    roc = report.curvature
    if roc is not None:
        bad = codes & {IssueCode.UNDERCUT, IssueCode.CUSP}
        rows.append({"concept": "Convex radius of curvature (mm)", "max": table_cell(None),
                     "min": table_cell(roc.min_convex, roc.at_min_convex, xu),
                     "comment": "Undercut or cusp: see the findings" if bad
                     else "The profile is free of cusps and undercuts", "status": "bad" if bad else "ok"})
        if roc.min_concave is not None:
            tight = IssueCode.CONCAVE_RADIUS_BELOW_ROLLER in codes
            rows.append({"concept": "Concave radius of curvature (mm)", "max": table_cell(None),
                         "min": table_cell(roc.min_concave, roc.at_min_concave, xu),
                         "comment": "Tighter than the cutter: see the findings" if tight
                         else "Smallest concave radius (the cutter must be smaller)",
                         "status": "warn" if tight else "ok"})
    pa = report.pressure_angle
    if pa is not None:
        ok = IssueCode.PRESSURE_ANGLE_EXCEEDED not in codes
        rows.append({"concept": "Pressure angle (°)", "max": table_cell(pa.max, pa.at_max, xu),
                     "min": table_cell(pa.min, pa.at_min, xu),
                     "comment": (f"Acceptable (limit ±{pa.limit:g}°)" if ok
                                 else f"High pressure angle (> {pa.limit:g}°)"),
                     "status": "ok" if ok else "bad"})
    face = report.face_length
    if face is not None:
        if face.left is not None:
            rows.append({"concept": "Face length left / right (mm)", "max": table_cell(face.left),
                         "min": table_cell(face.right),
                         "comment": "Minimum face length on each side of the stem to keep contact",
                         "status": "ok"})
        else:
            rows.append({"concept": "Contact along the face (mm)", "max": table_cell(face.max),
                         "min": table_cell(face.min), "comment": "Distance of the contact from the face vertex",
                         "status": "ok"})
    return rows


def key_values(report) -> list[tuple[str, str, float | None]]:
    """Dimensions of the cam: ``[(label, text, exact value), ...]`` (rows that do not apply are left out)."""
    out = []
    rb, rmax = report.base_radius_mm, report.max_radius_mm
    if rb is not None:
        out.append(("Smallest radius R min (mm)", fmt(rb, 3), rb))
        out.append(("Smallest diameter Ø min = 2·R min (mm)", fmt(2 * rb, 3), 2 * rb))
    if rmax is not None:
        out.append(("Largest radius R max (mm)", fmt(rmax, 3), rmax))
        out.append(("Blank diameter Ø max = 2·R max (mm)", fmt(2 * rmax, 3), 2 * rmax))
    if report.area_mm2 is not None:
        out.append(("Profile area (mm²)", fmt(report.area_mm2, 2), report.area_mm2))
    if report.initial_arm_angle_deg is not None:
        arm = report.initial_arm_angle_deg
        out.append(("Initial arm angle ξ₀ (°)", fmt(arm, 3), arm))
    return out
