"""Spreadsheet export (openpyxl): the CAM-DAS "Exportar-Excel" layout, checks and a lift table.

Sheet ``CAM-DAS`` follows the CAM-DAS program's own "Exportar-Excel" sheet cell for cell
(``docs/decisions.md``, "CAM-DAS spreadsheet layout"):

==========  =================================================================
Cells       Content
==========  =================================================================
A1          cam / follower type ("Rotating disc cam (clockwise) with ...")
A2          title (the design name)
A3          conclusion: the verdict sentence and the verdict code
A4:A8       geometry and speed as text ("Base radius R_b = 35 mm"); A8 is
            always the speed (ω, or v for a translating cam).  B4:B8 hold the
            same values as numbers and C4:C8 their units (machine-readable
            extras in cells CAM-DAS leaves empty)
row 9       column headings with units
A10:A...    cam angle in degrees, 0 to 360 inclusive at ``step_deg``
            (travel in mm, 0 to the cam length, for a translating cam)
B, C, D, E  S, V, A, J in time units at the design speed: mm, mm/s, mm/s²,
            mm/s³ — degrees (°, °/s, …) for oscillating followers
F           radius of curvature of the profile, mm (+ convex, − concave;
            empty where it is infinite, at an inflection)
G           rollers, knife edges and curved faces: pressure angle, degrees
            (signed)
H           curved faces: contact position along the face, mm — from the
            stem axis (+ = right) for a mushroom, the arc length from the
            face vertex for a finger follower
G, H        flat translating face: left / right distance of the contact
            point from the stem axis, mm (each ≥ 0, the other side 0)
G           flat oscillating face: distance along the face from the
            right-angle vertex (from the pivot's foot when the face offset
            is 0), mm
I, J        profile, polar: radius (mm), polar angle (degrees, 0 … 360)
L, M        profile, Cartesian: x, y (mm, cam frame)
O, P        pitch curve (roller centre; a curved face's centre of
            curvature), polar: radius, angle — rollers and curved faces
R, S        pitch curve, Cartesian: x, y — rollers and curved faces
==========  =================================================================

The 361-vs-362-rows mismatch of the thesis' map (§7.3.7) is resolved as follows: the map's
``A10:A371`` is the block CAM-DAS reserved, but the program stored 361
points (0° … 360°, both ends included), so at the CAM-DAS step of 1° the data
fill rows 10 … 370 and row 371 stays empty; row 9 holds the headings.  No row
is invented to reach 371.  At another step the block is ``360/step + 1`` rows.

Cam frame and angles follow camfab's convention (``docs/decisions.md``, "Rotation sense and the cam
frame": the follower along +Y at 0°).  A
translating cam has no polar coordinates (columns I, J, O, P stay empty).  A
cam with several profiles (conjugate cams) gets one ``CAM-DAS`` sheet per
profile (``CAM-DAS 2`` …).

Sheet ``Checks``: the verdict, the CAM-DAS "Conclusiones" table (concept,
maximum, minimum, comments), summary values and every finding with its
angle range.  Sheet ``Lift table``: cam angle, follower lift and the
follower radius (roller centre or face distance from the cam centre) at
``lift_step_deg``, 0 up to (not including) 360°.

Sheet ``Dynamics`` (designs with a ``[dynamics]`` section only): row 1 the
headings, then one row per angle of the CAM-DAS grid (0 … 360° inclusive at
``step_deg``; travel in mm, 0 … the cam length, for a translating cam):
angle, contact force (N), friction force (N), bearing force (N), drive torque
(N·m; drive force in N along the travel for a translating cam) and drive
power (W) at the design speed (empty where infinite: a self-locking
follower), then the Hertz contact stress (MPa) of each follower (not for a
knife edge; ``camfab.design.strength``).  The dynamics summary (extremes, work per cycle, mean power,
preload needed, jump speed) is in the ``Summary`` block of ``Checks``.

The bytes are deterministic: the workbook properties carry a fixed date and
the zip entries a fixed timestamp.
"""
from __future__ import annotations

import datetime
import io
import math
import re
import zipfile
from collections.abc import Callable
from typing import Any

import numpy as np

from ..design.kinds import ContactKind, FollowerType
from ..design.tables import LiftTable, intervals, lift_table, sample_params
from ..errors import InputError
from ..results import JUMP_CODES, IssueCode, Severity, Verdict, pair_names
from ..textsafe import xlsx_no_formulas, xlsx_put, xlsx_text
from .xlsx_blocks import NumberBlocks, workbook_bytes

__all__ = ["CAMDAS_COLUMNS", "FIXED_DATE", "LiftTable", "camdas_workbook", "camdas_columns", "conclusions",
           "dynamics_columns", "dynamics_summary_rows", "strength_summary_rows",
           "fixed_zip", "geometry_rows", "lift_table", "sample_params",
           "type_text", "verdict_sentence"]

#: the date written into the workbook properties (deterministic output)
FIXED_DATE = datetime.datetime(2000, 1, 1, 0, 0, 0)
#: column letter -> quantity, as in the CAM-DAS map (G/H depend on the follower)
CAMDAS_COLUMNS = {"A": "angle", "B": "S", "C": "V", "D": "A", "E": "J", "F": "radius of curvature",
                  "G": "pressure angle | left distance | distance along the face",
                  "H": "right distance | contact position along a curved face",
                  "I": "profile r", "J": "profile polar angle", "L": "profile x", "M": "profile y",
                  "O": "pitch r", "P": "pitch polar angle", "R": "pitch x", "S": "pitch y"}
FIRST_DATA_ROW = 10
_VERDICT_TEXT = {
    Verdict.ACCEPTABLE: "Acceptable cam",
    Verdict.NOT_FOR_HIGH_SPEED: "Jerk (or allowed acceleration) discontinuity. Cam not suitable for high speeds",
    Verdict.UNACCEPTABLE: "Unacceptable cam",
}


def verdict_sentence(report) -> str:
    """The A3 conclusion: a CAM-DAS-style sentence followed by the verdict code in brackets."""
    v = report.verdict
    text = _VERDICT_TEXT[v]
    if v == Verdict.UNACCEPTABLE:
        why = sorted({f.code.lower().replace("_", " ") for f in report.findings if f.severity == Severity.ERROR})
        text += ": " + ", ".join(why)
    return f"{text} [{v}]"


# ---------------------------------------------------------------------------
# texts
def _unit(spec) -> str:
    return spec.follower.lift_unit


def type_text(spec) -> str:
    """The A1 cam/follower type string."""
    f, cam = spec.follower, spec.cam
    ftype = FollowerType(f.type).title
    if spec.is_translating_cam:
        return f"Translating cam (slides {cam.direction}) with {ftype} follower, translating motion"
    sense = "clockwise" if cam.rotation == "cw" else "counter-clockwise"
    return f"Rotating {cam.kind} cam ({sense}) with {ftype} follower, {f.motion} motion"


def geometry_rows(spec, geometry) -> list[tuple[str, float | None, str]]:
    """Rows A4:A8: up to four geometry values, then the speed (label, value, unit).

    Which rows a follower has comes from its first contact: a roller (radius > 0) gives its radius and,
    translating, the prime radius; a curved face its face radius and, translating, the radius of the
    circle its centre of curvature starts on (R_b + R); a face (flat or curved) on an arm its face offset.
    """
    f = spec.follower
    c = geometry.profiles[0]
    rows: list[tuple[str, float | None, str]] = []
    if spec.is_translating_cam:
        rows += [("Roller radius R_r", f.roller_radius_mm, "mm"), ("Base height h", f.base_height_mm or 0.0, "mm"),
                 ("Cam length L", geometry.period, "mm")]
    else:
        rows.append(("Base radius R_b", f.base_radius_mm, "mm"))
        circle = c.kind is ContactKind.ROLLER and c.roller_radius > 0  # a roller or a curved face
        if circle:
            rows.append(("Face radius R", c.roller_radius, "mm") if c.curved_face
                        else ("Roller radius R_r", c.roller_radius, "mm"))
        if not c.oscillating:
            if c.kind is ContactKind.FLAT:
                rows.append(("Face offset", f.face_offset_mm or 0.0, "mm"))
            else:
                rows.append(("Offset e", f.offset_mm or 0.0, "mm"))
                rows.append(("Face-centre circle R_b + R" if c.curved_face else "Prime radius R_p",
                             f.base_radius_mm + (c.roller_radius if circle else 0.0), "mm"))
        else:
            rows.append(("Pivot distance PivCen", f.pivot_distance_mm, "mm"))
            if c.has_face:
                rows.append(("Face offset (Excentricidad)", f.face_offset_mm or 0.0, "mm"))
            else:
                rows.append(("Arm length", f.arm_length_mm, "mm"))
            if len(rows) < 4:
                rows.append(("Initial arm angle", geometry.initial_arm_angle_deg, "deg"))
    rows = rows[:4] + [("", None, "")] * (4 - len(rows[:4]))
    if spec.is_translating_cam:
        rows.append(("Cam speed v", spec.speed, "mm/s"))
    else:
        rows.append(("Angular speed ω", spec.speed, "rad/s"))
    return rows


# ---------------------------------------------------------------------------
# the CAM-DAS table
def _polar(p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    r = np.hypot(p[:, 0], p[:, 1])
    th = np.degrees(np.arctan2(p[:, 1], p[:, 0])) % 360.0
    return r, np.where(th >= 360.0, 0.0, th)


def camdas_columns(spec, geometry, *, step_deg: float = 1.0, profile: int = 0) -> tuple[dict[str, str],
                                                                                         dict[str, np.ndarray]]:
    """Headings (row 9) and data columns of one CAM-DAS sheet, keyed by column letter.

    Returns
    -------
    headings : dict of str
    columns : dict of (n,) float arrays
        NaN marks an empty cell.
    """
    c = geometry.profiles[profile]
    x = sample_params(geometry, step_deg)
    u = _unit(spec)
    w = spec.speed
    S = c.motion.evaluate(x, (0, 1, 2, 3))
    smp = c.evaluate(x)
    xu = "deg" if geometry.closed else "mm"
    head = {"A": f"Cam angle ({xu})" if geometry.closed else "Cam travel (mm)", "B": f"S ({u})",
            "C": f"V ({u}/s)", "D": f"A ({u}/s2)", "E": f"J ({u}/s3)", "F": "Radius of curvature (mm)"}
    cols: dict[str, np.ndarray] = {"A": geometry.to_user(x), "B": S[0], "C": S[1] * w, "D": S[2] * w**2,
                                   "E": S[3] * w**3, "F": np.where(np.isfinite(smp.rho), smp.rho, np.nan)}
    if c.kind is ContactKind.ROLLER:
        head["G"] = "Pressure angle (deg)"
        cols["G"] = np.degrees(smp.pressure_angle)
        if c.curved_face:
            head["H"] = ("Contact arc length from the face vertex (mm)" if c.oscillating
                         else "Contact position from the stem axis, + right (mm)")
            cols["H"] = smp.face_position
    elif not c.oscillating:
        head["G"], head["H"] = "Left contact distance (mm)", "Right contact distance (mm)"
        cols["G"], cols["H"] = np.maximum(-smp.face_position, 0.0), np.maximum(smp.face_position, 0.0)
    else:
        head["G"] = "Contact distance along the face (mm)"
        cols["G"] = smp.face_position
    if geometry.closed:
        head["I"], head["J"] = "Profile radius (mm)", "Profile polar angle (deg)"
        cols["I"], cols["J"] = _polar(smp.point)
    head["L"], head["M"] = "Profile x (mm)", "Profile y (mm)"
    cols["L"], cols["M"] = smp.point[:, 0], smp.point[:, 1]
    if c.kind is ContactKind.ROLLER and smp.pitch is not None:
        what = "Face centre" if c.curved_face else "Pitch"
        if geometry.closed:
            head["O"], head["P"] = f"{what} radius (mm)", f"{what} polar angle (deg)"
            cols["O"], cols["P"] = _polar(smp.pitch)
        head["R"], head["S"] = f"{what} x (mm)", f"{what} y (mm)"
        cols["R"], cols["S"] = smp.pitch[:, 0], smp.pitch[:, 1]
    return head, cols


# ---------------------------------------------------------------------------
# follower dynamics
def dynamics_columns(spec, geometry, *, step_deg: float = 1.0) -> tuple[list[str], list[np.ndarray]]:
    """Headings and columns of the ``Dynamics`` sheet (the CAM-DAS angle grid; see the module notes).

    Returns
    -------
    headings : list of str
    columns : list of (n,) float arrays
        Angle (deg, or travel in mm), contact, friction and bearing force (N), drive torque (N·m) or
        drive force (N), power (W); NaN where not finite.
    """
    from ..design.assemble import dynamics_model

    if spec.dynamics is None:
        raise InputError(f"{spec.name} has no [dynamics] section: add one (mass_kg or inertia_kg_m2, spring, loads) "
                         "for the force sheet")
    x = sample_params(geometry, step_deg)
    sm = dynamics_model(spec, geometry).evaluate(x)
    pair = sm.contact_force_2 is not None
    a, b = pair_names(geometry.flank_pair)
    head = ["Cam angle (deg)" if geometry.closed else "Cam travel (mm)",
            f"Contact force, {a} (N)" if pair else "Contact force (N)",
            *([f"Contact force, {b} (N)"] if pair else []), "Friction force (N)",
            "Bearing force (N)", "Drive torque (N·m)" if geometry.closed else "Drive force (N)", "Power (W)"]
    cols = [geometry.to_user(x), sm.contact_force, *([sm.contact_force_2] if pair else []), sm.friction_force,
            sm.bearing_force, sm.drive, sm.power]
    stress = _stress_columns(spec, geometry, sm)
    head += [h for h, _ in stress]
    cols += [c for _, c in stress]
    return head, [np.where(np.isfinite(c), c, np.nan) for c in cols]


def _stress_columns(spec, geometry, sm) -> list[tuple[str, np.ndarray]]:
    """The Hertz contact stress (MPa) of each follower from the force sample ``sm`` (none for a knife edge)."""
    from ..design.assemble import strength_input
    from ..design.strength import StressModel, effective_modulus

    inp = strength_input(spec, geometry)
    if inp is None or inp.dynamics is None:
        return []
    try:
        model = StressModel(inp.dynamics, effective_modulus(inp.cam.e_mpa, inp.cam.poisson, inp.follower.e_mpa,
                                                            inp.follower.poisson), inp.width_mm)
    except InputError:  # a knife edge: no finite contact stress
        return []
    st = model.of_sample(sm)
    if st.stress_2 is None:
        return [("Contact stress (MPa)", st.stress)]
    a, b = pair_names(geometry.flank_pair)
    return [(f"Contact stress, {a} (MPa)", st.stress), (f"Contact stress, {b} (MPa)", st.stress_2)]


def dynamics_summary_rows(report) -> list[tuple[str, Any, str, float | None]]:
    """The dynamics summary of ``report`` as ``(label, value, unit, at)`` rows ([] without dynamics).
    ``at`` is the cam angle in degrees (travel in mm); a jump speed that is never reached is "never"."""
    d = report.dynamics
    if d is None:
        return []
    cf, b, t, torque = d.contact_force, d.bearing_force, d.drive, d.torque
    tu, word = ("N·m", "drive torque") if torque else ("N", "drive force")
    common = [("Maximum bearing force", b.max, "N", b.at_max),
              (f"Minimum {word}", t.min, tu, t.at_min), (f"Maximum {word}", t.max, tu, t.at_max),
              ("Work per cycle", d.work_per_cycle_j, "J", None), ("Mean power", d.mean_power_w, "W", None)]
    if d.form_closed:
        cf2 = d.second_contact_force
        (a, b), other = d.contact_names, "flank" if d.flanks else "follower"
        return [(f"Maximum contact force, {a}", cf.max, "N", cf.at_max),
                (f"Maximum contact force, {b}", cf2.max, "N", cf2.at_max), *common,
                *[(f"Load passes to the other {other}", lo, "deg" if torque else "mm", None)
                  for lo, _ in d.load_reversals or ()]]
    pre, js = d.preload_needed, d.jump_speed
    return [("Minimum contact force", cf.min, "N", cf.at_min),
            ("Maximum contact force", cf.max, "N", cf.at_max),
            ("Safety force", d.safety_force_n, "N", None),
            ("Maximum bearing force", b.max, "N", b.at_max),
            (f"Minimum {word}", t.min, tu, t.at_min), (f"Maximum {word}", t.max, tu, t.at_max),
            ("Work per cycle", d.work_per_cycle_j, "J", None), ("Mean power", d.mean_power_w, "W", None),
            ("Preload needed", pre.value, pre.unit, pre.at),
            ("Jump speed", js.value if js.value is not None else "never", js.unit, js.at)]


def strength_summary_rows(report) -> list[tuple[str, Any, str, float | None]]:
    """The contact-stress summary of ``report`` as ``(label, value, unit, at)`` rows ([] when not computed)."""
    cs = report.contact_stress
    if cs is None or cs.max_mpa is None:
        return []
    rows: list[tuple[str, Any, str, float | None]] = [
        ("Maximum contact stress", cs.max_mpa, "MPa", cs.at),
        ("Allowable contact stress", cs.allowable_mpa, "MPa", None),
        ("Contact-stress safety factor", cs.safety_factor, "", None), ("Face width", cs.width_mm, "mm", None)]
    if cs.roller_life is not None:
        r = cs.roller_life
        rows += [("Roller equivalent load (ISO 281)", r.equivalent_load_n, "N", None),
                 ("Roller life L10", r.hours if r.hours is not None else "unlimited", "h", None)]
    if cs.cam_life is not None:
        rows.append(("Cam track life (estimate)", cs.cam_life.hours if cs.cam_life.hours is not None else "unlimited",
                     "h", None))
    return rows


# ---------------------------------------------------------------------------
# the lift table
# ---------------------------------------------------------------------------
# the workbook
def camdas_workbook(spec, geometry, report, *, step_deg: float = 1.0, lift_step_deg: float = 10.0) -> bytes:
    """The xlsx workbook: ``CAM-DAS`` sheet(s), ``Checks``, ``Lift table`` and, for designs with
    ``[dynamics]``, ``Dynamics`` (see the module notes).

    Parameters
    ----------
    spec : DesignSpec
    geometry : CamGeometry
    report : Report
        From :func:`camfab.design.assemble.check_design`.
    step_deg : float
        Angle step of the CAM-DAS sheet (CAM-DAS used 1°); must divide 360.
    lift_step_deg : float
        Angle step of the lift-table sheet; must divide 360.

    Returns
    -------
    bytes
        The xlsx file, byte-identical for the same input.

    Raises
    ------
    SpecError
        A step that is not a positive divisor of 360.
    """
    from openpyxl import Workbook

    intervals(step_deg, "step_deg")
    intervals(lift_step_deg, "lift_step_deg")
    wb = Workbook()
    wb.remove(wb.active)
    blocks = NumberBlocks()
    cylindrical = spec.cam.kind == "cylindrical"  # developed coordinates, no plate: camfab.formats.cylinder_sheet
    for k in range(0 if cylindrical else len(geometry.profiles)):
        _camdas_sheet(wb.create_sheet("CAM-DAS" if k == 0 else f"CAM-DAS {k + 1}"), spec, geometry, report,
                      step_deg, k, blocks)
    if cylindrical:
        from .cylinder_sheet import write_cylinder_sheet

        ws = wb.create_sheet("Cylinder")
        write_cylinder_sheet(ws, spec, geometry, title=type_text(spec), verdict=verdict_sentence(report),
                             step_deg=step_deg, blocks=blocks)
        xlsx_put(ws["A2"], spec.name)
    _checks_sheet(wb.create_sheet("Checks"), spec, report)
    if not cylindrical:
        _lift_sheet(wb.create_sheet("Lift table"), lift_table(geometry, lift_step_deg), geometry, blocks)
    if spec.dynamics is not None and not cylindrical:
        _dynamics_sheet(wb.create_sheet("Dynamics"), *dynamics_columns(spec, geometry, step_deg=step_deg),
                        blocks=blocks)
    wb.properties.creator = "camfab"
    wb.properties.title = xlsx_text(spec.name)
    wb.properties.created = FIXED_DATE
    wb.properties.modified = FIXED_DATE
    return _save(wb, blocks)


def _save(wb, blocks: NumberBlocks | None = None) -> bytes:
    xlsx_no_formulas(wb)  # camfab writes no formula: text openpyxl took for one stays text
    raw = workbook_bytes(wb)  # wb.save, in memory and uncompressed (fixed_zip compresses once)
    return fixed_zip(raw, blocks.patches() if blocks is not None else None)


_MODIFIED = re.compile(rb"(<dcterms:modified[^>]*>)[^<]*(</dcterms:modified>)")


def fixed_zip(raw: bytes, patches: dict[str, Callable[[bytes], bytes]] | None = None) -> bytes:
    """Re-pack an xlsx with fixed entry timestamps and a fixed ``modified`` property (equal content, equal bytes);
    ``patches`` rewrites the named entries (:meth:`camfab.formats.xlsx_blocks.NumberBlocks.patches`)."""
    out = io.BytesIO()
    with zipfile.ZipFile(io.BytesIO(raw)) as src, zipfile.ZipFile(out, "w", zipfile.ZIP_DEFLATED) as dst:
        for info in src.infolist():
            zi = zipfile.ZipInfo(info.filename, date_time=(1980, 1, 1, 0, 0, 0))
            zi.compress_type = zipfile.ZIP_DEFLATED
            zi.external_attr = 0o600 << 16
            data = src.read(info.filename)
            if info.filename == "docProps/core.xml":  # openpyxl stamps the save time into <modified>
                data = _MODIFIED.sub(rb"\g<1>" + FIXED_DATE.strftime("%Y-%m-%dT%H:%M:%SZ").encode() + rb"\2", data)
            if patches and info.filename in patches:
                data = patches[info.filename](data)
            dst.writestr(zi, data)
    return out.getvalue()


def _camdas_sheet(ws, spec, geometry, report, step_deg: float, profile: int, blocks: NumberBlocks) -> None:
    from openpyxl.styles import Font
    from openpyxl.utils.cell import column_index_from_string

    ws["A1"] = type_text(spec) + (f" — profile {profile + 1}" if profile else "")
    xlsx_put(ws["A2"], spec.name)  # the design's text: never a formula, no control characters
    ws["A3"] = verdict_sentence(report)
    for i, (label, value, unit) in enumerate(geometry_rows(spec, geometry)):
        if not label:
            continue
        ws.cell(4 + i, 1, f"{label} = {value:.10g} {unit}" if value is not None else f"{label}: n/a")
        ws.cell(4 + i, 2, value)
        ws.cell(4 + i, 3, unit)
    head, cols = camdas_columns(spec, geometry, step_deg=step_deg, profile=profile)
    bold = Font(bold=True)
    for letter, text in head.items():
        ws[f"{letter}9"] = text
        ws[f"{letter}9"].font = bold
    blocks.add(ws, FIRST_DATA_ROW, [(column_index_from_string(letter), values) for letter, values in cols.items()])
    ws.freeze_panes = "B10"


def _fmt(v) -> Any:
    return None if v is None or (isinstance(v, float) and not math.isfinite(v)) else v


def _continuity(report, code: str) -> str:
    return "Discontinuous" if report.by_code(code) else "Continuous"


def conclusions(spec, report) -> list[tuple[str, Any, Any, str]]:
    """The CAM-DAS "Conclusiones" rows: (concept, maximum, minimum, comments)."""
    u = _unit(spec)
    rows: list[tuple[str, Any, Any, str]] = []
    peaks = dict(report.motion.peaks.items()) if report.motion is not None else {}
    names = (("S", "Displacement", u), ("V", "Velocity", f"{u}/s"), ("A", "Acceleration", f"{u}/s2"),
             ("J", "Jerk", f"{u}/s3"))
    for key, word, unit in names:
        p = peaks.get(key)
        rows.append((f"{word} ({unit})", p.max if p else None, p.min if p else None,
                     _continuity(report, JUMP_CODES[key]) if key in JUMP_CODES else "Continuous"))
    roc = report.curvature
    big, convex = (roc.max, roc.min_convex) if roc is not None else (None, None)
    bad = [f for f in report.findings if f.code in (IssueCode.UNDERCUT, IssueCode.CUSP)]
    rows.append(("Radius of curvature (mm)" if big is not None else "Convex radius of curvature (mm)",
                 big, convex,
                 "; ".join(f.message for f in bad) if bad else "The profile is free of cusps and undercuts"))
    pa = report.pressure_angle
    if pa is not None:
        over = report.by_code(IssueCode.PRESSURE_ANGLE_EXCEEDED)
        rows.append(("Pressure angle (deg)", pa.max, pa.min,
                     f"Pressure angle > {pa.limit:g} deg, high pressure angle" if over else "Acceptable"))
    fl = report.face_length
    if fl is not None:
        note = "The maximum is the minimum face length needed to keep contact"
        if fl.left is not None:
            rows.append(("Left contact distance (mm)", fl.left, 0.0, note))
            rows.append(("Right contact distance (mm)", fl.right, 0.0, note))
        else:
            rows.append(("Contact distance along the face (mm)", fl.max, fl.min, note))
    return rows


def _checks_sheet(ws, spec, report) -> None:
    from openpyxl.styles import Font

    bold = Font(bold=True)
    ws["A1"], ws["B1"] = "Verdict", report.verdict
    ws["A2"], ws["B2"] = "Conclusion", verdict_sentence(report)
    ws["A1"].font = ws["A2"].font = bold
    row = 4
    for col, text in enumerate(("Concept", "Maximum", "Minimum", "Comments"), 1):
        ws.cell(row, col, text).font = bold
    for concept, mx, mn, note in conclusions(spec, report):
        row += 1
        for col, v in enumerate((concept, _fmt(mx), _fmt(mn), note), 1):
            xlsx_put(ws.cell(row, col), v)
    row += 2
    ws.cell(row, 1, "Summary").font = bold
    rmax = report.max_radius_mm
    for label, value, unit in (("Smallest radius R min", report.base_radius_mm, "mm"),
                               ("Largest radius R max", rmax, "mm"),
                               ("Blank diameter Ø max = 2·R max", None if rmax is None else 2 * rmax, "mm"),
                               ("Profile area", report.area_mm2, "mm2"),
                               ("Initial arm angle", report.initial_arm_angle_deg, "deg")):
        if value is not None:
            row += 1
            ws.cell(row, 1, label), ws.cell(row, 2, _fmt(value)), ws.cell(row, 3, unit)
    dyn = dynamics_summary_rows(report) + strength_summary_rows(report)
    if dyn:
        row += 2
        ws.cell(row, 1, "Dynamics").font = bold
        x = "deg" if report.x_unit == "deg" else "mm"
        for col, text in enumerate(("Quantity", "Value", "Unit", f"At ({x})"), 1):
            ws.cell(row + 1, col, text).font = bold
        row += 1
        for label, value, unit, at in dyn:
            row += 1
            for col, v in enumerate((label, _fmt(value), unit, _fmt(at)), 1):
                ws.cell(row, col, v)
    row += 2
    ws.cell(row, 1, "Findings").font = bold
    row += 1
    x = "deg" if report.x_unit == "deg" else "mm"
    for col, text in enumerate(("Code", "Severity", f"From ({x})", f"To ({x})", "Value", "Limit", "Message"), 1):
        ws.cell(row, col, text).font = bold
    if not report.findings:
        ws.cell(row + 1, 1, "none")
    for f in report.findings:
        row += 1
        for col, v in enumerate((f.code, f.severity, f.from_deg, f.to_deg, f.value, f.limit, f.message), 1):
            xlsx_put(ws.cell(row, col), _fmt(float(v)) if isinstance(v, (float, np.floating)) else v)


def _lift_sheet(ws, table: LiftTable, geometry, blocks: NumberBlocks) -> None:
    from openpyxl.styles import Font

    bold = Font(bold=True)
    heads = ("Cam angle (deg)" if geometry.closed else "Cam travel (mm)", f"Lift S ({table.lift_unit})",
             table.radius_label)
    for col, text in enumerate(heads, 1):
        ws.cell(1, col, text).font = bold
    blocks.add(ws, 2, [(1, table.angle), (2, table.lift), (3, table.radius)])
    ws.freeze_panes = "A2"


def _dynamics_sheet(ws, head: list[str], cols: list[np.ndarray], *, blocks: NumberBlocks) -> None:
    from openpyxl.styles import Font

    bold = Font(bold=True)
    for col, text in enumerate(head, 1):
        ws.cell(1, col, text).font = bold
    blocks.add(ws, 2, [(k, np.asarray(c, dtype=float)) for k, c in enumerate(cols, 1)])  # NaN → empty
    ws.freeze_panes = "A2"
