"""Designs in a spreadsheet: read a whole design from xlsx, and write one back.

Workbook format
---------------
``design`` sheet (required)
    Key/value rows: column A a dotted key spelt exactly as in the TOML design
    file (``name``, ``cam.kind``, ``cam.speed_rpm``, ``follower.type``,
    ``follower.base_radius_mm``, ``manufacturing.tolerance_mm``,
    ``outputs.dxf``, ``checks.pressure_angle_limit_deg``,
    ``motion_table.units.s``, ``motion_table.speed_rpm``, …), column B its
    value.  Further columns are ignored (use them for notes).  An optional
    first row ``key | value`` is a header; blank rows and rows whose key
    starts with ``#`` are skipped.
``motion`` sheet (the ``[[motion]]`` segments)
    A header row naming the columns — ``law``, ``lift``, ``angle_deg`` (or
    ``length_mm`` for a translating cam), optional ``shape`` — then one row
    per segment, in order.  ``angle_deg`` may be ``auto``.
``knots`` sheet (instead of ``motion``: the ``[motion_table]`` rows)
    Columns A–D = angle, s, v, a and E = j (degree 7); an optional header row
    of text.  Units, speed and degree come from the ``motion_table.*`` keys of
    the ``design`` sheet, exactly as in TOML.

The ``[dynamics]`` and ``[machining]`` sections are key/value rows of the ``design`` sheet too
(``dynamics.mass_kg``, ``dynamics.spring_rate_n_per_mm``, … or
``dynamics.inertia_kg_m2``, … for an oscillating follower; ``machining.feed_mm_min``, …),
validated like the TOML sections.

Cell values: numbers, text and booleans as Excel stores them.  Text that
reads as a number (``35`` or ``35,5``) or as a boolean (``true``/``false``,
any case) is converted, except for the free-text keys ``name``,
``description``, ``manufacturing.material`` and ``motion_table.file``.
A relative ``motion_table.file`` is resolved against the workbook's folder (and must lie in it, see
:func:`~camfab.formats.knot_files.read_knot_file`).  A formula in a cell that is read (columns A–B of
``design``, any cell of ``motion``, columns A–E of ``knots``) is refused naming its cell — its cached value
may be stale or come from another workbook; type the value.

The dict is validated by :func:`~camfab.formats.toml_design.design_from_data`,
so the rules and messages are those of TOML files; every problem's field path is
followed by the cell it came from, e.g.
``follower.base_radius_mm [design!B7] = -3.0: must be in (0.0, 1000000.0]``.
"""
from __future__ import annotations

import io
import math
import re
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from ..design.knots import KnotFile
from ..design.resolve import END_KEYS
from ..design.shop import MachiningSpec
from ..design.spec import CamSpec, DesignSpec, FollowerSpec, ManufacturingSpec, OutputsSpec, dynamics_items
from ..errors import Problem, SpecError
from ..textsafe import excerpt, xlsx_no_formulas, xlsx_put, xlsx_text
from ..units import RPM
from .camdas_workbook import FIXED_DATE, fixed_zip
from .input_limits import check_xlsx, sheet_problems
from .toml_design import design_from_data

__all__ = ["load_design_xlsx", "design_to_xlsx", "design_rows", "SEGMENT_COLUMNS", "KNOT_COLUMNS"]

SEGMENT_COLUMNS = ("law", "lift", "angle_deg", "length_mm", "shape", *END_KEYS)
KNOT_COLUMNS = ("angle", "s", "v", "a", "j")
_TEXT_KEYS = {"name", "description", "manufacturing.material", "motion_table.file", "strength.cam_material",
              "strength.follower_material"}
_FIX_FORMAT = ("save it as an .xlsx workbook with a 'design' sheet of key/value rows "
               "(see camfab.formats.xlsx_design), or use a TOML design file")


# ---------------------------------------------------------------------------
# reading
def load_design_xlsx(path: str | Path, *, allow_outside_files: bool = False) -> DesignSpec:
    """Read and validate a design workbook (format in the module notes).

    Parameters
    ----------
    path : str or Path
        The ``.xlsx`` file.
    allow_outside_files : bool
        Read a ``motion_table.file`` outside the workbook's folder too.

    Returns
    -------
    DesignSpec

    Raises
    ------
    SpecError
        A missing, corrupt or non-xlsx file (naming the file and the fix), or
        every problem of the design, each naming its field and its cell.
    """
    p = Path(path)
    wb = _open(p)
    try:
        too_big = [q for ws in wb.worksheets if ws.title.lower() in ("design", "motion", "knots")
                   for q in sheet_problems(ws)]
        if too_big:  # the sheets are read cell by cell: refuse before
            raise SpecError(too_big, str(p))
        formulas = _formula_problems(wb)
        if formulas:
            raise SpecError(formulas, str(p))
        cells: dict[str, str] = {}
        problems: list[Problem] = []
        data = _read_design_sheet(wb, cells, problems)
        names = {ws.title.lower(): ws for ws in wb.worksheets}
        if "motion" in names:
            data["motion"] = _read_motion_sheet(names["motion"], cells, problems)
        if "knots" in names:
            table = data.get("motion_table")
            if table is not None and not isinstance(table, dict):
                table = None  # reported by the validator
            table = dict(table or {})
            table["rows"] = _read_knots_sheet(names["knots"], cells, problems)
            data["motion_table"] = table
    finally:
        wb.close()
    if any(q.path == "design" for q in problems):  # no design sheet: nothing to validate
        raise SpecError(problems, str(p))
    data.setdefault("name", p.stem)
    try:
        spec = design_from_data(data, source=str(p), base_dir=p.parent,
                                  allow_outside_files=allow_outside_files)
    except SpecError as exc:  # with the sheets' own problems: all at once, a field reported once
        seen = {q.path.split(" [")[0] for q in problems}
        problems += [q for q in (_locate(q, cells) for q in exc.problems) if q.path.split(" [")[0] not in seen]
    if problems:
        raise SpecError(problems, str(p))
    return spec


def _open(p: Path):
    import openpyxl

    if not p.is_file():
        raise SpecError(Problem("file", str(p), "no such design workbook", "check the path"), str(p))
    check_xlsx(p, field="file")
    try:  # formulas as written (not their cached values), so that they can be refused
        return openpyxl.load_workbook(p, data_only=False)
    except Exception as exc:  # openpyxl raises many types for a damaged or foreign file
        raise SpecError(Problem("file", str(p), f"is not a readable xlsx workbook ({exc.__class__.__name__}: "
                                f"{exc})", _FIX_FORMAT), str(p)) from None


#: the columns read as input, by sheet (the design sheet's further columns are notes)
_INPUT_COLUMNS = {"design": 2, "motion": None, "knots": 5}
_EXTERNAL = re.compile(r"\[\d+\]")


def _formula_problems(wb) -> list[Problem]:
    """One problem per input cell that holds a formula (its cached value is never used: it may be stale or
    come from another workbook); empty when there is none."""
    problems = []
    linked = bool(getattr(wb, "_external_links", None))
    for ws in wb.worksheets:
        low = ws.title.lower()
        if low not in _INPUT_COLUMNS:
            continue
        for row in ws.iter_rows(max_col=_INPUT_COLUMNS[low]):
            for cell in row:
                if cell.data_type != "f":
                    continue
                formula = cell.value if isinstance(cell.value, str) else getattr(cell.value, "text", None)
                text = str(formula or "")
                link = linked and _EXTERNAL.search(text) is not None
                key = ws.cell(cell.row, 1).value if low == "design" and cell.column == 2 else None
                where = f"{ws.title}!{cell.coordinate}"
                problems.append(Problem(
                    f"{key.strip()} [{where}]" if isinstance(key, str) and key.strip() else where,
                    excerpt(text),
                    "formulas are not accepted in a design workbook" + (" (this one reads another workbook)"
                                                                          if link else ""),
                    "type the value (copy the cell and paste it as a value)"))
    return problems


def _convert(key: str, value: Any) -> Any:
    """Excel cell value → the TOML value type (see the module notes)."""
    if isinstance(value, str):
        text = value.strip()
        if key in _TEXT_KEYS:
            return text
        low = text.lower()
        if low in ("true", "false"):
            return low == "true"
        num = _number(text)
        return text if num is None else num
    if key in _TEXT_KEYS and isinstance(value, (int, float)) and not isinstance(value, bool):
        return f"{value:g}" if isinstance(value, float) else str(value)
    if isinstance(value, float) and value.is_integer() and key.endswith("degree"):
        return int(value)
    return value


def _number(text: str) -> int | float | None:
    t = text.replace(",", ".") if text.count(",") == 1 and "." not in text else text
    try:
        return int(t)
    except ValueError:
        pass
    try:
        v = float(t)
    except ValueError:
        return None
    return v if math.isfinite(v) else None


def _read_design_sheet(wb, cells: dict[str, str], problems: list[Problem]) -> dict[str, Any]:
    ws = next((w for w in wb.worksheets if w.title.lower() == "design"), None)
    if ws is None:
        problems.append(Problem("design", wb.sheetnames, "the workbook has no 'design' sheet",
                                "add a sheet named 'design' with key/value rows (e.g. cam.kind | disc)"))
        return {}
    data: dict[str, Any] = {}
    seen: dict[str, str] = {}
    for no, row in enumerate(ws.iter_rows(min_col=1, max_col=2, values_only=True), 1):
        key, value = (tuple(row) + (None, None))[:2]
        if key is None and value is None:
            continue
        where = f"design!A{no}"
        if not isinstance(key, str) or not key.strip():
            problems.append(Problem(where, key, "the key must be text", 'write a dotted key such as "cam.kind"'))
            continue
        key = key.strip()
        if key.startswith("#") or (no == 1 and key.lower() == "key"):
            continue
        if key in seen:
            problems.append(Problem(f"{key} [{where}]", value, f"is given twice (also {seen[key]})",
                                    "keep one row per key"))
            continue
        seen[key] = where
        cell = f"design!B{no}"
        if value is None or (isinstance(value, str) and not value.strip()):
            problems.append(Problem(f"{key} [{cell}]", None, "has no value", "fill the value in column B "
                                    "or delete the row"))
            continue
        if key == "motion" or key.startswith(("motion.", "motion[")) or key.startswith("motion_table.rows"):
            problems.append(Problem(f"{key} [{where}]", value, "motion rows do not go in the 'design' sheet",
                                    "put segments in a 'motion' sheet or knots in a 'knots' sheet"))
            continue
        if not _put(data, key.split("."), _convert(key, value)):
            problems.append(Problem(f"{key} [{where}]", value, "clashes with another key (a value and a "
                                    "section of the same name)", "remove one of them"))
            continue
        cells[key] = cell
    return data


def _put(data: dict[str, Any], parts: list[str], value: Any) -> bool:
    node = data
    for part in parts[:-1]:
        nxt = node.setdefault(part, {})
        if not isinstance(nxt, dict):
            return False
        node = nxt
    if parts[-1] in node:
        return False
    node[parts[-1]] = value
    return True


def _read_motion_sheet(ws, cells: dict[str, str], problems: list[Problem]) -> list[dict[str, Any]]:
    from openpyxl.utils import get_column_letter

    rows = [(no, tuple(r)) for no, r in enumerate(ws.iter_rows(values_only=True), 1)
            if any(c is not None and str(c).strip() for c in r)]
    if not rows:
        problems.append(Problem("motion [motion sheet]", None, "the 'motion' sheet is empty",
                                "add a header row law | lift | angle_deg and one row per segment"))
        return []
    head_no, head = rows[0]
    columns: dict[int, str] = {}
    for k, name in enumerate(head):
        if name is None or not str(name).strip():
            continue
        name = str(name).strip().lower()
        if name not in SEGMENT_COLUMNS:
            problems.append(Problem(f"motion [motion!{get_column_letter(k + 1)}{head_no}]", name,
                                    "unknown column heading", "use: " + ", ".join(SEGMENT_COLUMNS)))
            continue
        columns[k] = name
    segs = []
    for i, (no, row) in enumerate(rows[1:]):
        cells[f"motion[{i}]"] = f"motion!A{no}:{get_column_letter(max(len(row), 1))}{no}"
        seg: dict[str, Any] = {}
        for k, name in columns.items():
            value = row[k] if k < len(row) else None
            if value is None or (isinstance(value, str) and not value.strip()):
                continue
            seg[name] = _convert(f"motion.{name}", value)
            cells[f"motion[{i}].{name}"] = f"motion!{get_column_letter(k + 1)}{no}"
        segs.append(seg)
    return segs


def _read_knots_sheet(ws, cells: dict[str, str], problems: list[Problem]) -> list[list[Any]]:
    from openpyxl.utils import get_column_letter

    rows = [(no, tuple(r)[:5]) for no, r in enumerate(ws.iter_rows(values_only=True), 1)
            if any(c is not None and str(c).strip() for c in tuple(r)[:5])]
    if rows and any(isinstance(c, str) and _number(c) is None for c in rows[0][1]):
        rows = rows[1:]  # header
    width = 5 if any(len(r) > 4 and r[4] is not None for _, r in rows) else 4
    out = []
    for i, (no, row) in enumerate(rows):
        cells[f"motion_table.rows[{i}]"] = f"knots!A{no}:{get_column_letter(width)}{no}"
        vals = []
        for k in range(5):
            cells[f"motion_table.rows[{i}][{k}]"] = f"knots!{get_column_letter(k + 1)}{no}"
            if k < width:
                v = row[k] if k < len(row) else None
                vals.append(_convert("knot", v) if isinstance(v, str) else v)
        while len(vals) > 4 and vals[-1] is None:
            vals.pop()
        out.append(vals)
    if not out:
        cells["motion_table.rows"] = "knots!A1"
    return out


_PARENT = re.compile(r"^(.*?)(?:\.[^.\[\]]+|\[\d+\])$")


def _locate(problem: Problem, cells: dict[str, str]) -> Problem:
    """The problem with the cell of its field (or of the nearest enclosing field) added to its path."""
    path = problem.path
    probe = path
    while probe:
        if probe in cells:
            cell = cells[probe]
            if problem.rule == "unknown key" and probe == path and cell.startswith("design!B"):
                cell = "design!A" + cell[len("design!B"):]
            return Problem(f"{path} [{cell}]", problem.value, problem.rule, problem.fix)
        m = _PARENT.match(probe)
        if not m:
            break
        probe = m.group(1)
    if "required" in problem.rule and "[" not in path:
        return Problem(f"{path} [design sheet: no such row]", problem.value, problem.rule,
                       f"add a row '{path}' with its value to the design sheet")
    return problem


# ---------------------------------------------------------------------------
# writing
def _num(v: Any) -> Any:
    """A float that survives openpyxl's ``%.16g`` as a number; else its exact repr as text."""
    if isinstance(v, float) and not v.is_integer() and float(f"{v:.16g}") != v:
        return repr(v)
    return v


def design_rows(spec: DesignSpec) -> tuple[list[tuple[str, Any]], list[dict[str, Any]] | None,
                                           list[list[Any]] | None]:
    """The ``design`` key/value rows, the ``motion`` segments and the ``knots`` rows of a spec.

    The rows of a ``motion_table.file`` are written inline as ``knots`` rows, so
    the workbook stands alone.
    """
    kv: list[tuple[str, Any]] = [("name", spec.name)]
    if spec.description:
        kv.append(("description", spec.description))
    kv += _cam_rows(spec.cam, spec.is_translating_cam)
    kv += _follower_rows(spec.follower)
    kv += _manufacturing_rows(spec.manufacturing)
    kv += _machining_rows(spec.machining)
    kv += _output_rows(spec.outputs)
    if spec.pressure_angle_limit_deg is not None:
        kv.append(("checks.pressure_angle_limit_deg", _num(spec.pressure_angle_limit_deg)))
    kv.append(("checks.face_margin_mm", _num(spec.face_margin_mm)))
    if spec.dynamics is not None:
        kv += [(f"dynamics.{k}", _num(v)) for k, v in dynamics_items(spec.dynamics)]
    if spec.vibration is not None:
        vib = spec.vibration
        kv += [(f"vibration.{vib.stiffness_key}", _num(vib.stiffness)), ("vibration.damping_ratio",
               _num(vib.damping_ratio)), ("vibration.harmonics", vib.harmonics)]
    if spec.strength is not None:
        from ..design.strength_spec import strength_rows
        kv += [(k, _num(v)) for k, v in strength_rows(spec.strength)]
    segs = None if spec.motion is None else _segment_rows(spec)
    knots = None
    if spec.motion_table is not None:
        table_kv, knots = _table_rows(spec.motion_table)
        kv += table_kv
    return kv, segs, knots


def _cam_rows(cam: CamSpec, translating: bool) -> list[tuple[str, Any]]:
    """``cam.*``: the kind, the sense of motion and the speed (rpm when it survives the round trip)."""
    kv: list[tuple[str, Any]] = [("cam.kind", str(cam.kind))]
    if translating:
        if cam.direction != "left":
            kv.append(("cam.direction", str(cam.direction)))
        if cam.speed_given:
            kv.append(("cam.speed_mm_s", _num(cam.speed_mm_s)))
        return kv
    kv.append(("cam.rotation", str(cam.rotation)))
    if cam.speed_given:
        rpm = float(f"{cam.omega_rad_s / RPM:.16g}")
        if rpm * RPM == cam.omega_rad_s:
            kv.append(("cam.speed_rpm", rpm))
        else:
            kv.append(("cam.omega_rad_s", _num(cam.omega_rad_s)))
    return kv


def _follower_rows(f: FollowerSpec) -> list[tuple[str, Any]]:
    """``follower.*``: type, motion and every dimension given."""
    kv: list[tuple[str, Any]] = [("follower.type", str(f.type)), ("follower.motion", str(f.motion))]
    for name in ("base_radius_mm", "roller_radius_mm", "offset_mm", "pivot_distance_mm", "arm_length_mm",
                 "face_offset_mm", "follower_distance_mm", "second_roller_radius_mm", "follower_angle_deg",
                 "cam_length_mm", "base_height_mm", "width_mm", "rise_deg", "face_radius_mm", "backlash_mm",
                 "groove_depth_mm"):
        v = getattr(f, name)
        if v is not None:
            kv.append((f"follower.{name}", _num(v)))
    return kv


def _manufacturing_rows(m: ManufacturingSpec) -> list[tuple[str, Any]]:
    """``manufacturing.*``: every value given, the material when named."""
    kv = [(f"manufacturing.{name}", _num(getattr(m, name)))
          for name in ("thickness_mm", "bore_mm", "keyway", "hub_diameter_mm", "hub_length_mm", "tool_diameter_mm",
                       "tolerance_mm") if getattr(m, name) is not None]
    if m.material:
        kv.append(("manufacturing.material", m.material))
    return kv


def _machining_rows(m: MachiningSpec) -> list[tuple[str, Any]]:
    """``machining.*``: every value that differs from the default (a design without the table writes none)."""
    default = MachiningSpec()
    return [(f"machining.{name}", _num(getattr(m, name))) for name in MachiningSpec.__dataclass_fields__
            if getattr(m, name) != getattr(default, name)]


def _output_rows(o: OutputsSpec) -> list[tuple[str, Any]]:
    """``outputs.*``: every flag, the G-code post (or false)."""
    kv: list[tuple[str, Any]] = [(f"outputs.{name}", getattr(o, name)) for name in ("dxf", "step", "stl")]
    kv.append(("outputs.gcode", o.gcode if o.gcode is not None else False))
    kv += [(f"outputs.{name}", getattr(o, name)) for name in ("report", "xlsx", "drawing", "lift_table")]
    if o.pdf != o.drawing:  # by default the PDF follows the drawing: written only when it does not
        kv.append(("outputs.pdf", o.pdf))
    return kv


def _segment_rows(spec: DesignSpec) -> list[dict[str, Any]]:
    """The ``motion`` sheet: one dict per segment (law, lift, span or ``auto``, shape when given)."""
    span = "length_mm" if spec.is_translating_cam else "angle_deg"
    segs = []
    for s in spec.motion or ():
        seg: dict[str, Any] = {"law": s.law, "lift": _num(s.lift), span: "auto" if s.span is None else _num(s.span)}
        if s.shape is not None:
            seg["shape"] = s.shape
        seg.update({k: _num(e) for k, e in zip(END_KEYS, s.ends, strict=True) if e is not None})
        segs.append(seg)
    return segs


def _table_rows(motion_table: Mapping[str, Any]) -> tuple[list[tuple[str, Any]], list[list[Any]]]:
    """``motion_table.*`` key/value rows (units, speed, degree) and the knot rows, a file's rows inline."""
    table = dict(motion_table)
    file = table.pop("file", None)
    if isinstance(file, KnotFile):
        table["rows"] = file.rows or ()
    knots = [[_num(float(x)) if isinstance(x, float) else x for x in r] for r in table.pop("rows")]
    kv: list[tuple[str, Any]] = []
    for key, v in table.items():
        if isinstance(v, dict):
            kv += [(f"motion_table.{key}.{k}", _num(x)) for k, x in v.items()]
        else:
            kv.append((f"motion_table.{key}", _num(v)))
    return kv, knots


def design_to_xlsx(spec: DesignSpec) -> bytes:
    """The design as a workbook in the format :func:`load_design_xlsx` reads (deterministic bytes).

    Parameters
    ----------
    spec : DesignSpec

    Returns
    -------
    bytes
    """
    from openpyxl import Workbook
    from openpyxl.styles import Font

    kv, segs, knots = design_rows(spec)
    wb = Workbook()
    ws = wb.active
    ws.title = "design"
    bold = Font(bold=True)
    ws.append(["key", "value"])
    ws["A1"].font = ws["B1"].font = bold
    for row, (key, value) in enumerate(kv, 2):  # text as text (never a formula), without control characters
        xlsx_put(ws.cell(row, 1), key), xlsx_put(ws.cell(row, 2), value)
    ws.column_dimensions["A"].width = 34
    if segs is not None:
        ms = wb.create_sheet("motion")
        heads = [c for c in SEGMENT_COLUMNS if any(c in s for s in segs)]
        ms.append(heads)
        for c in ms[1]:
            c.font = bold
        for s in segs:
            ms.append([s.get(c) for c in heads])
    if knots is not None:
        ks = wb.create_sheet("knots")
        width = max(len(r) for r in knots) if knots else 4
        ks.append(list(KNOT_COLUMNS[:width]))
        for c in ks[1]:
            c.font = bold
        for r in knots:
            ks.append(list(r))
    wb.properties.creator = "camfab"
    wb.properties.title = xlsx_text(spec.name)
    wb.properties.created = FIXED_DATE
    wb.properties.modified = FIXED_DATE
    xlsx_no_formulas(wb)
    buf = io.BytesIO()
    wb.save(buf)
    return fixed_zip(buf.getvalue())
