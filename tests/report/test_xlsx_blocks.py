"""Number blocks written straight into the sheet XML and the in-memory save (camfab.formats.xlsx_blocks): the
same bytes openpyxl's own save writes cell by cell, and openpyxl reads the numbers back."""
from __future__ import annotations

import io
import math
import zipfile

import numpy as np
import pytest

from camfab.errors import ApiError
from camfab.formats.camdas_workbook import fixed_zip
from camfab.formats.xlsx_blocks import NumberBlocks, workbook_bytes

openpyxl = pytest.importorskip("openpyxl")

VALUES = [0.0, -0.0, 1 / 3, -2.5e-13, 1e16, 123456.789, math.nan, None, math.inf, 7.0]


def _book(through_blocks: bool, in_memory: bool = False) -> bytes:
    wb = openpyxl.Workbook()
    ws = wb.active
    ws.title = "Data"
    ws["A1"] = "head"
    ws["B2"] = 5
    n = len(VALUES)  # and a last row empty in every column
    cols = [(1, np.array(VALUES + [None], dtype=float)), (3, VALUES[::-1] + [math.nan]), (6, [None] * (n + 1))]
    blocks = NumberBlocks()
    if through_blocks:
        blocks.add(ws, 3, cols)
    else:
        for c, vals in cols:
            for i, v in enumerate(vals):
                ok = v is not None and math.isfinite(v)
                ws.cell(3 + i, c, float(v) if ok else None)
    if in_memory:  # what camdas_workbook does: stored entries, no temporary files
        return fixed_zip(workbook_bytes(wb), blocks.patches())
    buf = io.BytesIO()
    wb.save(buf)
    return fixed_zip(buf.getvalue(), blocks.patches())


def test_blocks_equal_openpyxl_bytes_and_read_back():
    fast, slow = _book(True), _book(False)
    assert fast == slow == _book(True, in_memory=True)
    with zipfile.ZipFile(io.BytesIO(fast)) as z:
        xml = z.read("xl/worksheets/sheet1.xml")
    assert b'<dimension ref="A1:F13" />' in xml and b'<row r="13"></row>' in xml
    ws = openpyxl.load_workbook(io.BytesIO(fast))["Data"]
    got = [ws.cell(3 + i, 1).value for i in range(len(VALUES))]
    want = [None if v is None or not math.isfinite(v) else v for v in VALUES]
    assert got[:6] == pytest.approx(want[:6], rel=1e-15) and got[6:9] == [None] * 3 and got[9] == 7
    assert ws["A1"].value == "head" and ws["B2"].value == 5


def test_blocks_refuse_text_and_overlap():
    wb = openpyxl.Workbook()
    ws = wb.active
    ws["A5"] = "x"
    with pytest.raises(ApiError, match="inside its number block"):
        NumberBlocks().add(ws, 3, [(1, [1.0])])
    with pytest.raises(ApiError, match="not a number"):
        NumberBlocks().add(ws, 6, [(1, ["=cmd|' /C calc'!A0"])])
    with pytest.raises(ApiError, match="different lengths"):
        NumberBlocks().add(ws, 6, [(1, [1.0]), (2, [1.0, 2.0])])


def test_the_patch_takes_lxml_forms_and_never_drops_the_numbers():
    """lxml's writer (openpyxl uses it when installed) writes ``<dimension ref="A1"/>`` and ``<sheetData/>``;
    the numbers go in all the same, and XML without a ``<sheetData>`` or a cell added inside the block after
    ``add`` is an InternalError, never a sheet without its numbers or with a duplicate row."""
    from camfab.errors import InternalError

    wb = openpyxl.Workbook()
    ws = wb.active
    blocks = NumberBlocks()
    blocks.add(ws, 1, [(2, [1.5, 2.5])])
    (patch,) = blocks.patches().values()
    out = patch(b'<worksheet><dimension ref="A1"/><sheetData/></worksheet>')
    assert out == (b'<worksheet><dimension ref="B1:B2" /><sheetData><row r="1"><c r="B1" t="n"><v>1.5</v></c>'
                   b'</row><row r="2"><c r="B2" t="n"><v>2.5</v></c></row></sheetData></worksheet>')
    with pytest.raises(InternalError, match="sheetData"):
        patch(b'<worksheet><dimension ref="A1"/></worksheet>')
    ws["C2"] = 4.0
    with pytest.raises(InternalError, match="inside its number block"):
        patch(b'<worksheet><dimension ref="A1"/><sheetData/></worksheet>')
