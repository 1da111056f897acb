"""The ``Cylinder`` sheet of a cylindrical cam's workbook (:func:`camfab.formats.camdas_workbook.camdas_workbook`).

A cylindrical cam has no plate coordinates: its CAM-DAS sheets would hold developed points under polar headings.
Its workbook gets instead, besides ``Checks``, one sheet ``Cylinder``:

==========  =================================================================
Cells       Content
==========  =================================================================
A1:A3       cam / follower type, the design name, the verdict sentence
A4:C11      the cylinder (label, value, unit): pitch radius, groove bottom,
            outer radius, length, groove depth, backlash, the roller's z at
            S = 0, angular speed
row 13      column headings with units
A14:A...    cam angle in degrees, 0 to 360 inclusive at ``step_deg``
B, C, D, E  S, V, A, J at the design speed (mm or °, per s, s², s³)
F onwards   per radius (groove bottom, pitch cylinder, outer cylinder), eight
            columns: the developed pitch curve x = r·θ (+ the oscillating
            arm's shift), z; the +z flank x, z; the −z flank x, z; the
            pressure angle (deg) and the pitch curve's radius of curvature (mm,
            empty where straight) — the development of docs/decisions.md,
            "Cylindrical cams"
==========  =================================================================
"""
from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..design.tables import sample_params

__all__ = ["CYLINDER_FIRST_ROW", "cylinder_columns", "cylinder_rows", "write_cylinder_sheet"]

#: the first data row of the ``Cylinder`` sheet (headings on the row above)
CYLINDER_FIRST_ROW = 14


def cylinder_rows(spec: Any, geometry: Any) -> list[tuple[str, float, str]]:
    """Rows A4:C11: the cylinder's dimensions and the speed (label, value, unit)."""
    cyl, mech = geometry.cylinder, geometry.mechanism
    rib = cyl.rib_width_mm is not None  # a rib: its root, top and height in the same rows
    return [("Pitch radius R", cyl.radius_mm, "mm"),
            ("Rib root radius" if rib else "Groove bottom radius", cyl.inner_radius_mm, "mm"),
            ("Rib top radius" if rib else "Outer radius", cyl.outer_radius_mm, "mm"), ("Length", cyl.length_mm, "mm"),
            ("Rib height" if rib else "Groove depth", cyl.groove_depth_mm, "mm"), ("Backlash", cyl.backlash_mm, "mm"),
            ("Roller z at S = 0", mech.z0_for(geometry.program), "mm"), ("Angular speed ω", spec.speed, "rad/s")]


def cylinder_columns(spec: Any, geometry: Any, *, step_deg: float = 1.0) -> tuple[list[str], list[np.ndarray]]:
    """Headings and columns (NaN = empty cell) of the ``Cylinder`` sheet's table (see the module notes)."""
    x = sample_params(geometry, step_deg)  # radians, 0 … 2π inclusive (the period of the developed profiles)
    u, w = spec.follower.lift_unit, spec.speed
    S = geometry.profiles[0].motion.evaluate(x, (0, 1, 2, 3))
    head = ["Cam angle (deg)", f"S ({u})", f"V ({u}/s)", f"A ({u}/s2)", f"J ({u}/s3)"]
    cols = [np.degrees(x), S[0], S[1] * w, S[2] * w**2, S[3] * w**3]
    for k in range(0, len(geometry.profiles), 2):
        plus, minus = geometry.profiles[k], geometry.profiles[k + 1]
        sp, sm = plus.evaluate(x), minus.evaluate(x)
        where = f"r = {plus.r:.6g} mm"
        head += [f"{where} pitch x (mm)", f"{where} pitch z (mm)", f"{where} +z flank x (mm)",
                 f"{where} +z flank z (mm)", f"{where} -z flank x (mm)", f"{where} -z flank z (mm)",
                 f"{where} pressure angle (deg)", f"{where} pitch radius of curvature (mm)"]
        cols += [sp.pitch[:, 0], sp.pitch[:, 1], sp.point[:, 0], sp.point[:, 1], sm.point[:, 0], sm.point[:, 1],
                 np.degrees(sp.pressure_angle), np.where(np.isfinite(sp.rho_pitch), sp.rho_pitch, np.nan)]
    return head, cols


def write_cylinder_sheet(ws: Any, spec: Any, geometry: Any, *, title: str, verdict: str, step_deg: float,
                         blocks: Any = None) -> None:
    """Fill the openpyxl sheet ``ws``, A2 (the design name) left to the caller (:mod:`camfab.textsafe`); the
    numbers go into ``blocks`` (a :class:`~camfab.formats.xlsx_blocks.NumberBlocks`, written at the save) when
    one is given, else cell by cell."""
    from openpyxl.styles import Font

    ws["A1"] = title
    ws["A3"] = verdict
    for i, (label, value, unit) in enumerate(cylinder_rows(spec, geometry)):
        ws.cell(4 + i, 1, f"{label} = {value:.10g} {unit}")
        ws.cell(4 + i, 2, float(value))
        ws.cell(4 + i, 3, unit)
    head, cols = cylinder_columns(spec, geometry, step_deg=step_deg)
    bold = Font(bold=True)
    for j, text in enumerate(head, 1):
        ws.cell(CYLINDER_FIRST_ROW - 1, j, text).font = bold
    if blocks is not None:
        blocks.add(ws, CYLINDER_FIRST_ROW, [(j, np.asarray(c, dtype=float)) for j, c in enumerate(cols, 1)])
    else:
        for i, values in enumerate(np.column_stack(cols).tolist()):
            for j, v in enumerate(values, 1):
                ws.cell(CYLINDER_FIRST_ROW + i, j, v if math.isfinite(v) else None)
    ws.freeze_panes = f"B{CYLINDER_FIRST_ROW}"
