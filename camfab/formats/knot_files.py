"""Knot tables from files: the rows ``(angle, s, v, a[, j])`` of a CSV/text file or an xlsx sheet.

A design's ``[motion_table]`` may name a ``file`` instead of giving ``rows``.
:func:`resolve_knot_file` reads it once, relative to the design file's folder,
and puts a :class:`~camfab.design.knots.KnotFile` (the name as written, the file
read and its rows, or why it could not be read) in place of the name; the
design core then validates those rows exactly like inline rows, naming the file.
Rows are counted from 0 after any header, as for inline rows.

File formats
------------
``.csv .txt .dat .tsv`` are text; ``.xlsx .xlsm`` are read with openpyxl.

* Text: lines starting with ``#`` or ``%`` and blank lines are skipped; the
  first remaining line is a header when it is not numeric (so a MATLAB
  ``PUNTOS=`` paste works).  Separators: ``;`` if any line has one, else ``,``
  if any line has one, else whitespace.  Decimal commas are accepted only
  where they cannot be separators: in ``;``-separated files, and in
  whitespace-separated files whose commas, taken as separators, would not
  give numbers (``22 0,5 0,39 1875,3``).  A comma file is always read as
  comma-separated with decimal points.  Trailing separators are ignored.
* xlsx: the first sheet; empty rows are skipped; a first row holding text is
  a header.  Columns A–D are angle, s, v, a; column E is j when any data row
  has a number there; further columns are ignored.  Numeric text cells are
  accepted (a decimal comma in a cell is unambiguous).  A formula in columns A–E is refused naming its
  cells (its cached value may be stale or come from another workbook).

Where the file may be
---------------------
A design read from a file (TOML or xlsx: ``base_dir`` is its folder) may only name a file in that folder
or below it, after resolving symbolic links: ``../x.csv``, an absolute path elsewhere or a link leading out
is refused naming ``motion_table.file`` — a design received from someone else cannot make camfab read (and
echo into its messages) any file on the disk.  ``allow_outside_files=True`` (``--allow-outside-files`` on the
command line) lifts the rule for a design the user trusts.  A design given as data without a folder
(``base_dir=None``: a dict passed to :func:`~camfab.formats.toml_design.design_from_data` or
:func:`load_motion_table` by a program) has no folder to be kept in: its file is resolved against the current
directory and read as given; a program that passes on data it received gives the folder to confine it to as
``base_dir``.

Every failure is a :class:`~camfab.errors.SpecError` whose problem names the
field (``motion_table.file``), the file, and the line or cells at fault.
"""
from __future__ import annotations

import contextlib
import contextvars
import os
from collections.abc import Iterator, Mapping, Sequence
from pathlib import Path
from typing import Any, cast

from ..design.knots import KnotFile, KnotTable, build_knot_table
from ..errors import InputError, Problem, SpecError
from ..limits import MAX_KNOTS, MAX_SHEET_ROWS
from ..textsafe import excerpt
from .input_limits import check_xlsx, first_cells, read_text_limited

__all__ = [
    "TEXT_SUFFIXES",
    "XLSX_SUFFIXES",
    "load_motion_table",
    "read_knot_file",
    "read_knots",
    "read_knots_csv",
    "read_knots_xlsx",
    "relocated",
    "resolve_knot_file",
]

TEXT_SUFFIXES = (".csv", ".txt", ".dat", ".tsv")
XLSX_SUFFIXES = (".xlsx", ".xlsm")


#: (folder as the design's sender knew it, the local folder holding copies of its files), while a package worker
#: reads a design it received as bytes (:func:`relocated`)
_RELOCATION: contextvars.ContextVar[tuple[Path, Path] | None] = contextvars.ContextVar("camfab_relocation",
                                                                                      default=None)


@contextlib.contextmanager
def relocated(original: str | Path, local: str | Path) -> Iterator[None]:
    """Within the block, an absolute knot-file name under the folder ``original`` is read from the same place
    under ``local``: a package worker unpacks a design and its files (sent as bytes) into a temporary folder,
    and a design naming its knot file by an absolute path must read that copy — not a file of the worker's own
    disk, which a remote worker does not have — and be judged inside or outside its folder as on the sender's."""
    token = _RELOCATION.set((Path(os.path.abspath(original)), Path(local)))
    try:
        yield
    finally:
        _RELOCATION.reset(token)


def _relocate(file: Path) -> Path:
    """``file`` (absolute) as the current :func:`relocated` block maps it; unchanged outside one."""
    where = _RELOCATION.get()
    if where is None:
        return file
    original, local = where
    absolute = Path(os.path.abspath(file))
    return local / absolute.relative_to(original) if absolute.is_relative_to(original) else file


# ---------------------------------------------------------------------------
# a [motion_table] with a file
def resolve_knot_file(table: Any, base_dir: str | Path | None = None, *,
                      path: str = "motion_table", allow_outside_files: bool = False) -> Any:
    """The ``[motion_table]`` with its ``file`` read (a :class:`KnotFile` in place of the name).

    Parameters
    ----------
    table : Any
        The ``[motion_table]`` section as written.
    base_dir : str or Path, optional
        Folder a relative ``file`` is resolved against: the design file's folder
        (default: the current directory).
    path : str
        Field path used in messages.
    allow_outside_files : bool
        Read a file outside ``base_dir`` too (see "Where the file may be" in the module notes).

    Returns
    -------
    Any
        A new dict when a file was read; otherwise ``table`` itself (no file,
        inline rows as well, or a ``file`` that is not a path: the core names
        those problems).
    """
    if not isinstance(table, Mapping) or "rows" in table:
        return table
    name = table.get("file")
    if not isinstance(name, (str, Path)) or not str(name):
        return table
    return {**table, "file": read_knot_file(name, base_dir, field=f"{path}.file",
                                            allow_outside_files=allow_outside_files)}


def read_knot_file(name: str | Path, base_dir: str | Path | None = None, *,
                   field: str = "motion_table.file", allow_outside_files: bool = False) -> KnotFile:
    """Read the knot file ``name`` (relative to ``base_dir``, the current directory when None) into a
    :class:`KnotFile`.

    A file that cannot be read, or that lies outside ``base_dir`` when one is given (unless
    ``allow_outside_files``), gives a ``KnotFile`` without rows that carries the problem, so that the core
    reports it with the design's other problems.
    """
    file = Path(name)
    folder = None if base_dir is None else Path(base_dir)
    if folder is not None and not file.is_absolute():
        file = folder / file
    elif file.is_absolute():
        file = _relocate(file)
    try:
        target = file.resolve()
        outside = folder is not None and not target.is_relative_to(folder.resolve())
    except (OSError, ValueError, RuntimeError) as exc:  # a NUL in the name, a loop of symbolic links
        return KnotFile(str(name), str(file), None, (Problem(field, str(name), f"is not a usable path ({exc})",
                                                             "give the name of a file beside the design"),))
    if outside and not allow_outside_files:
        return KnotFile(str(name), str(file), None, (Problem(
            field, str(name), f"lies outside the design's folder {str(folder)!r}; a design may only read "
            "knot files in its folder or below it",
            "move the file into the design's folder (or a folder below it), or pass --allow-outside-files "
            "(Python: allow_outside_files=True) if you trust this design"),))
    try:
        rows = read_knots(file, field=field)
    except SpecError as exc:
        return KnotFile(str(name), str(file), None, tuple(exc.problems))
    return KnotFile(str(name), str(file), tuple(tuple(r) for r in rows))


def load_motion_table(table: Mapping[str, Any], *, base_dir: str | Path | None = None,
                      path: str = "motion_table", allow_outside_files: bool = False) -> KnotTable:
    """Build a :class:`KnotTable` from a ``[motion_table]`` dict, reading its ``file`` if it has one.

    Parameters
    ----------
    table : dict
        ``{"rows": [[angle, s, v, a(, j)], ...]}`` or ``{"file": "puntos.csv"}``,
        plus optional ``units`` (dict), ``speed_rpm`` (float) and ``degree``
        (5 or 7).
    base_dir : str or Path, optional
        Folder a relative ``file`` is resolved against (default: the current
        directory).
    path : str
        Field path used in messages.
    allow_outside_files : bool
        Read a file outside ``base_dir`` too.

    Raises
    ------
    SpecError
        With every problem found, each naming its field path (and the file).
    """
    return build_knot_table(resolve_knot_file(table, base_dir, path=path, allow_outside_files=allow_outside_files),
                            path=path)


# ---------------------------------------------------------------------------
# readers
def _is_real(x: Any) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool)


def _file_error(fld: str, file: Path, rule: str, fix: str) -> SpecError:
    return SpecError(Problem(fld, str(file), rule, fix), str(file))


def read_knots(path: str | Path, *, field: str = "motion_table.file") -> list[list[float]]:
    """Read knot rows from a text (CSV) or xlsx file, chosen by its suffix.

    Raises
    ------
    SpecError
        Unknown suffix, missing or unreadable file (naming the file).
    """
    file = Path(path)
    suffix = file.suffix.lower()
    if suffix in XLSX_SUFFIXES:
        return read_knots_xlsx(file, field=field)
    if suffix in TEXT_SUFFIXES:
        return read_knots_csv(file, field=field)
    raise _file_error(field, file, f"unknown knot-file type '{file.suffix}'",
                      "use one of: " + ", ".join(TEXT_SUFFIXES + XLSX_SUFFIXES))


def _number(tok: str, decimal_comma: bool) -> float:
    t = tok.strip()
    if decimal_comma and "," in t:
        if "." in t or t.count(",") > 1:
            raise InputError(f"{t!r} is not a number")
        t = t.replace(",", ".")
    return float(t)


def _split(line: str, sep: str | None, decimal_comma: bool) -> list[float]:
    toks = line.split(sep)
    while sep and toks and not toks[-1].strip():
        toks.pop()
    return [_number(t, decimal_comma) for t in toks]


def _dialects(lines: Sequence[str]) -> list[tuple[str | None, bool]]:
    if any(";" in ln for ln in lines):
        return [(";", True)]
    if any("," in ln for ln in lines):
        return [(",", False), (None, True)]
    return [(None, False)]


def _parse_rows(lines: list[tuple[int, str]], sep: str | None, dc: bool) -> list[list[float]]:
    """Rows of one dialect; the first line may be a header.  ValueError("line N: ...")."""
    rows = []
    for i, (no, text) in enumerate(lines):
        try:
            rows.append(_split(text, sep, dc))
        except ValueError:
            if i == 0 and len(lines) > 1:
                continue  # header
            raise InputError(f"line {no}: {excerpt(text.strip())!r} is not a row of numbers") from None
    return rows


def _parse_lines(lines: list[tuple[int, str]]) -> list[list[float]]:
    """Rows from (line number, text) pairs, trying each plausible dialect."""
    err: ValueError | None = None
    for sep, dc in _dialects([t for _, t in (lines[1:] or lines)]):
        try:
            return _parse_rows(lines, sep, dc)
        except ValueError as exc:
            err = err or exc
    assert err is not None
    raise err


def read_knots_csv(path: str | Path, *, field: str = "motion_table.file") -> list[list[float]]:
    """Read knot rows from a text file (CSV, ``;``- or whitespace-separated).

    Parameters
    ----------
    path : str or Path
        The file; see the module docstring for the accepted formats.
    field : str
        Field path used in messages.

    Returns
    -------
    list of list of float
        One list per data row (the header, comments and blank lines dropped).

    Raises
    ------
    SpecError
        Missing, undecodable or non-numeric file, naming the file and the line.
    """
    file = Path(path)
    try:
        text = read_text_limited(file, field=field, encoding="utf-8-sig")
    except FileNotFoundError:
        raise _file_error(field, file, "file not found", "check the path (relative paths are "
                          "resolved against the design file's folder)") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise _file_error(field, file, f"cannot read the file as UTF-8 text ({exc.__class__.__name__})",
                          "save the knot table as a UTF-8 CSV") from None
    lines = [(no, ln) for no, ln in enumerate(text.splitlines(), 1)
             if ln.strip() and not ln.lstrip().startswith(("#", "%"))]
    if not lines:
        raise _file_error(field, file, "the file holds no knot rows", "add rows: angle, s, v, a[, j]")
    _check_count(len(lines) - 1, field, file)  # one line may be a header
    try:
        rows = _parse_lines(lines)
    except ValueError as exc:
        raise _file_error(field, file, str(exc), "write one knot per line: angle, s, v, a[, j] "
                          "(separated by ',', ';' or spaces; one optional header line)") from None
    return rows


def _check_count(n: int, field: str, file: Path) -> None:
    """Refuse a knot file of more than :data:`~camfab.limits.MAX_KNOTS` rows before parsing them."""
    if n > MAX_KNOTS:
        raise _file_error(field, file, f"the file holds {n:,} knot rows, more than the limit of {MAX_KNOTS:,}",
                          f"give at most {MAX_KNOTS:,} knots (a 0.1° table has 3,600; thin a denser one out)")


def _cell_number(x: Any) -> float | None:
    if _is_real(x):
        return float(x)
    if isinstance(x, str) and x.strip():
        try:
            return _number(x, True)
        except ValueError:
            return None
    return None


def read_knots_xlsx(path: str | Path, *, field: str = "motion_table.file") -> list[list[float]]:
    """Read knot rows from the first sheet of an xlsx workbook.

    Columns A–D are angle, s, v, a and column E is j when any data row has a
    number there; a first row holding text is a header; empty rows are skipped.

    Raises
    ------
    SpecError
        Missing or corrupt workbook, or non-numeric cells (naming the cells).
    """
    from openpyxl.utils import get_column_letter

    file = Path(path)
    cells = _xlsx_cells(file, field)
    cells = [(no, r) for no, r in cells if any(c is not None and str(c).strip() for c in r)]
    if cells and any(isinstance(c, str) and _cell_number(c) is None for c in cells[0][1]):
        cells = cells[1:]
    _check_count(len(cells), field, file)
    if not cells:
        raise _file_error(field, file, "the first sheet holds no knot rows",
                          "put angle, s, v, a[, j] in columns A–E")
    width = 5 if any(len(r) > 4 and _cell_number(r[4]) is not None for _, r in cells) else 4
    rows: list[list[float | None]] = []
    bad: list[str] = []
    for no, r in cells:
        vals = [_cell_number(r[k]) if k < len(r) else None for k in range(width)]
        bad += [f"{get_column_letter(k + 1)}{no}" for k, v in enumerate(vals) if v is None]
        rows.append(vals)
    if bad:
        listed = ", ".join(bad[:20]) + (" …" if len(bad) > 20 else "")
        raise _file_error(field, file, f"cells are not numbers: {listed}",
                          f"fill columns A–{get_column_letter(width)} with numbers (angle, s, v, a[, j])")
    return cast(list[list[float]], rows)  # no None left: every cell is a number


def _xlsx_cells(file: Path, fld: str) -> list[tuple[int, tuple[Any, ...]]]:
    """(row number, values) of the first sheet; SpecError if the workbook cannot be read."""
    import openpyxl

    if not file.is_file():
        raise _file_error(fld, file, "file not found", "check the path (relative paths are resolved "
                          "against the design file's folder)")
    check_xlsx(file, field=fld)
    try:  # formulas as written, not their cached values: a formula is refused below
        wb = openpyxl.load_workbook(file, read_only=True, data_only=False)
        try:
            rows = first_cells(wb.worksheets[0], max_col=5)  # columns A–E are read, F… ignored
        finally:
            wb.close()
    except Exception as exc:  # openpyxl raises many types for a damaged file
        raise _file_error(fld, file, f"not a readable xlsx workbook ({exc.__class__.__name__}: {exc})",
                          "re-save it as .xlsx from a spreadsheet program, or export the table as CSV") from None
    if rows is None:
        raise _file_error(fld, file, f"the first sheet spans more than {MAX_SHEET_ROWS:,} rows (the input limit)",
                          f"give at most {MAX_KNOTS:,} knots, without far-away stray cells")
    formulas = [c.coordinate for _, r in rows for c in r if getattr(c, "data_type", None) == "f"]
    if formulas:
        listed = ", ".join(formulas[:20]) + (" …" if len(formulas) > 20 else "")
        raise _file_error(fld, file, f"cells hold formulas: {listed}; formulas are not accepted in a knot "
                          "workbook (their cached values may be stale or come from another workbook)",
                          "type the values (paste them as values), or export the table as CSV")
    return [(no, tuple(c.value for c in r)) for no, r in rows]
