"""The file limits of :mod:`camfab.limits`, applied before a file is parsed (``docs/decisions.md``, "Input limits").

* :func:`read_text_limited`: a text file (TOML design, knot CSV) read up to :data:`~camfab.limits.MAX_FILE_BYTES`
  and no further — a larger file, or an endless one (``/dev/zero``, a pipe), is refused after that many bytes;
* :func:`first_cells` and :func:`sheet_problems`: a sheet's rows and columns (a few bytes can declare a cell at
  XFD1048576, and a reader padding every row to it would build 17 billion empty cells);
* :func:`check_xlsx`: an xlsx workbook's size on disk, number of members and unpacked size, read from the zip
  directory before openpyxl opens it (a 1.5 MB workbook can unpack to gigabytes of shared strings; the members'
  declared sizes are binding, since :mod:`zipfile` stops each member at its declared size).

Each refusal is a :class:`~camfab.errors.SpecError` naming the field (``file``, ``motion_table.file``), the file,
the limit and the fix.
"""
from __future__ import annotations

import zipfile
from pathlib import Path
from typing import Any

from ..errors import Problem, SpecError
from ..limits import (
    MAX_FILE_BYTES,
    MAX_SHEET_COLUMNS,
    MAX_SHEET_ROWS,
    MAX_XLSX_MEMBERS,
    MAX_XLSX_UNCOMPRESSED_BYTES,
)

__all__ = ["read_text_limited", "check_xlsx", "first_cells", "sheet_problems"]


def _too_big(field: str, file: Path, rule: str, fix: str) -> SpecError:
    return SpecError(Problem(field, str(file), rule, fix), str(file))


def read_text_limited(file: Path, *, field: str, encoding: str = "utf-8") -> str:
    """The text of ``file`` (newlines translated, as :meth:`pathlib.Path.read_text`), refused beyond
    :data:`~camfab.limits.MAX_FILE_BYTES` bytes (no more is read).

    Raises
    ------
    SpecError
        The file holds more than the limit.
    OSError, UnicodeDecodeError
        As :meth:`pathlib.Path.read_text` (the caller names them).
    """
    with open(file, "rb") as fh:
        data = fh.read(MAX_FILE_BYTES + 1)
    if len(data) > MAX_FILE_BYTES:
        raise _too_big(field, file, f"the file is larger than {MAX_FILE_BYTES:,} bytes (the input limit)",
                       "a design or knot file this large is not a cam design; check that it is the right file")
    return data.decode(encoding).replace("\r\n", "\n").replace("\r", "\n")  # universal newlines, as read_text


def check_xlsx(file: Path, *, field: str) -> None:
    """Refuse a workbook over the size limits before it is opened (nothing is unpacked).

    A file that is not a zip archive passes: the reader that opens it next reports it as unreadable.

    Raises
    ------
    SpecError
        Larger than :data:`~camfab.limits.MAX_FILE_BYTES` on disk, more than
        :data:`~camfab.limits.MAX_XLSX_MEMBERS` members, or more than
        :data:`~camfab.limits.MAX_XLSX_UNCOMPRESSED_BYTES` unpacked.
    """
    try:
        size = file.stat().st_size
    except OSError:
        return  # the reader reports the missing or unreadable file
    fix = "a design workbook needs a few sheets of a few thousand rows; re-save it from a spreadsheet program"
    if size > MAX_FILE_BYTES:
        raise _too_big(field, file, f"the workbook is larger than {MAX_FILE_BYTES:,} bytes (the input limit)", fix)
    try:
        with zipfile.ZipFile(file) as zf:
            infos = zf.infolist()
    except (zipfile.BadZipFile, OSError, ValueError):
        return
    if len(infos) > MAX_XLSX_MEMBERS:
        raise _too_big(field, file, f"the workbook holds {len(infos):,} parts, more than the limit of "
                       f"{MAX_XLSX_MEMBERS:,}", fix)
    unpacked = sum(i.file_size for i in infos)
    if unpacked > MAX_XLSX_UNCOMPRESSED_BYTES:
        raise _too_big(field, file, f"the workbook unpacks to {unpacked:,} bytes, more than the limit of "
                       f"{MAX_XLSX_UNCOMPRESSED_BYTES:,} (a zip bomb, or text cells far beyond any design)", fix)


def first_cells(ws: Any, *, max_col: int) -> list[tuple[int, tuple[Any, ...]]] | None:
    """(row number, cells of columns 1…``max_col``) of a sheet, blank rows included; None (nothing more read)
    once it spans more than :data:`~camfab.limits.MAX_SHEET_ROWS` rows.  Cells, not values: the caller sees
    a formula (``data_type == "f"``) as well as the value."""
    out = []
    for no, row in enumerate(ws.iter_rows(max_col=max_col), 1):
        if no > MAX_SHEET_ROWS:
            return None
        out.append((no, tuple(row)))
    return out


def sheet_problems(ws: Any) -> list[Problem]:
    """A problem when a (fully loaded) sheet spans more than :data:`~camfab.limits.MAX_SHEET_ROWS` rows or
    :data:`~camfab.limits.MAX_SHEET_COLUMNS` columns: its cells are iterated row by row."""
    rows, cols = ws.max_row, ws.max_column
    if rows <= MAX_SHEET_ROWS and cols <= MAX_SHEET_COLUMNS:
        return []
    return [Problem(f"{ws.title} sheet", f"{rows:,} rows × {cols:,} columns", f"spans more than the input limit "
                    f"of {MAX_SHEET_ROWS:,} rows × {MAX_SHEET_COLUMNS:,} columns",
                    "delete the far-away cells (Ctrl+End in a spreadsheet program finds the last one)")]
