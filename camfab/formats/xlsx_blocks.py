"""Large numeric cell blocks of an openpyxl workbook, written straight into the saved sheet XML.

openpyxl serialises each cell through an ElementTree element (without lxml, its pure-Python incremental
writer): ~25 µs a cell, 0.15 s for the ~5 600 numbers of a CAM-DAS workbook.  The numeric blocks (the
CAM-DAS columns, the lift table, the dynamics columns) are plain numbers or empty cells, so their XML is
fixed text: ``<row r="10"><c r="A10" t="n"><v>0.5</v></c>…</row>``, the numbers formatted as openpyxl
formats them (``"%.16g"``, :func:`openpyxl.compat.safe_string`), an empty row as ``<row r="11"></row>``.
openpyxl writes the rest of each sheet (text, styles, panes); the blocks are appended to its
``<sheetData>`` (they are the last rows of their sheet) and its ``<dimension>`` is widened to them: the
bytes are those openpyxl writes when the same numbers go through ``ws.cell``.  No text goes through here
(user text keeps going through :mod:`camfab.textsafe` and openpyxl).
"""
from __future__ import annotations

import io
import math
import re
from collections.abc import Callable, Iterable
from typing import Any

import numpy as np

from ..errors import ApiError, InternalError

__all__ = ["NumberBlocks", "workbook_bytes"]

_DIMENSION = re.compile(rb'<dimension ref="([A-Z]+[0-9]+(?::[A-Z]+[0-9]+)?)"\s*/>')
_SHEET_DATA_END = re.compile(rb"</sheetData>|<sheetData\s*/>")


class NumberBlocks:
    """Numeric blocks to add to worksheets when the workbook is saved (:meth:`patches`)."""

    def __init__(self) -> None:
        self._blocks: list[tuple[Any, int, list[tuple[int, list[str | None]]]]] = []

    def add(self, ws: Any, first_row: int, columns: Iterable[tuple[int, Any]]) -> None:
        """Rows ``first_row`` … of ``ws``: ``columns`` is (1-based column, values) pairs, all the same length;
        a value is a real number (NaN/±inf and None give an empty cell).  Nothing at or below ``first_row``
        may be written to ``ws`` through openpyxl; one block per sheet."""
        if any(ws is w for w, _, _ in self._blocks):
            raise ApiError(f"a second number block for sheet {ws.title!r}")
        cols = sorted(((int(c), _texts(vals)) for c, vals in columns), key=lambda cv: cv[0])
        if len({len(v) for _, v in cols}) > 1:
            raise ApiError("number block columns of different lengths")
        if any(c.row >= first_row for c in ws._cells.values()):
            raise ApiError(f"sheet {ws.title!r} has openpyxl cells inside its number block")
        self._blocks.append((ws, first_row, cols))

    def patches(self) -> dict[str, Callable[[bytes], bytes]]:
        """Zip entry name -> function rewriting that sheet's XML; call after the save (which names the
        sheet parts)."""
        return {ws.path.lstrip("/"): _patch(ws, first, cols) for ws, first, cols in self._blocks}


def _texts(vals: Any) -> list[str | None]:
    """Each value as openpyxl writes a number (``"%.16g"``), ``None`` for an empty cell."""
    if isinstance(vals, np.ndarray) and vals.dtype.kind in "fiu":
        a = vals.astype(float, copy=False)
        return [f"{v:.16g}" if ok else None for v, ok in zip(a.tolist(), np.isfinite(a).tolist(), strict=True)]
    out: list[str | None] = []
    for v in vals:
        if v is None:
            out.append(None)
            continue
        if isinstance(v, (bool, str)):
            raise ApiError(f"not a number for a number block: {v!r}")
        f = float(v)
        out.append(f"{f:.16g}" if math.isfinite(f) else None)
    return out


def _patch(ws: Any, first: int, cols: list[tuple[int, list[str | None]]]) -> Callable[[bytes], bytes]:
    from openpyxl.utils.cell import get_column_letter, range_boundaries

    def run(xml: bytes) -> bytes:
        if not cols or not cols[0][1]:
            return xml
        n = len(cols[0][1])
        cells = [[f'<c r="{letter}{first + i}" t="n"><v>{t}</v></c>' if t is not None else ""
                  for i, t in enumerate(texts)] for letter, texts in ((get_column_letter(c), t) for c, t in cols)]
        block = "".join(f'<row r="{first + i}">{"".join(row)}</row>'
                        for i, row in zip(range(n), zip(*cells, strict=True), strict=True)).encode()
        # cells or row settings added through openpyxl after add() would be rows of their own: a duplicate row
        if any(c.row >= first for c in ws._cells.values()) or any(r >= first for r in ws.row_dimensions):
            raise InternalError(f"sheet {ws.title!r} has openpyxl cells or rows inside its number block")
        xml, k = _SHEET_DATA_END.subn(lambda m: b"<sheetData>" * m.group().startswith(b"<sheetData") + block
                                      + b"</sheetData>", xml, count=1)
        if k != 1:  # openpyxl's writer changed (lxml's?): never write a sheet without its numbers
            raise InternalError(f"sheet {ws.title!r}: no <sheetData> in openpyxl's XML to add the numbers to")
        # the dimension openpyxl computes over every cell, the block's included
        min_col, min_row, max_col, max_row = cols[0][0], first, cols[-1][0], first + n - 1
        if ws._cells:
            c0, r0, c1, r1 = range_boundaries(ws.calculate_dimension())
            min_col, min_row, max_col, max_row = min(min_col, c0), min(min_row, r0), max(max_col, c1), max(max_row, r1)
        ref = f"{get_column_letter(min_col)}{min_row}:{get_column_letter(max_col)}{max_row}"
        xml, k = _DIMENSION.subn(f'<dimension ref="{ref}" />'.encode(), xml, count=1)
        if k != 1:
            raise InternalError(f"sheet {ws.title!r}: no <dimension> in openpyxl's XML to widen to the numbers")
        return xml

    return run


def workbook_bytes(wb: Any) -> bytes:
    """``wb.save`` into memory, its entries stored, not compressed (:func:`~camfab.formats.camdas_workbook.fixed_zip`
    re-packs and compresses them once) and each sheet written in memory (openpyxl's save writes each to a
    temporary file, reads it back and deletes it).  The entries are those of ``wb.save``, in its order."""
    import zipfile

    from openpyxl.drawing.spreadsheet_drawing import SpreadsheetDrawing
    from openpyxl.worksheet._writer import WorksheetWriter
    from openpyxl.writer.excel import ExcelWriter

    class _InMemory(ExcelWriter):
        def write_worksheet(self, ws):  # ExcelWriter.write_worksheet, the sheet's XML kept in memory
            if self.workbook.write_only:
                return super().write_worksheet(ws)
            ws._drawing = SpreadsheetDrawing()
            ws._drawing.charts = ws._charts
            ws._drawing.images = ws._images
            out = io.BytesIO()
            writer = WorksheetWriter(ws, out)
            writer.write()
            ws._rels = writer._rels
            self._archive.writestr(ws.path[1:], out.getvalue())
            self.manifest.append(ws)

    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w", zipfile.ZIP_STORED, allowZip64=True) as archive:
        _InMemory(wb, archive).write_data()
    return buf.getvalue()
