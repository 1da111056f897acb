"""`camfab run` end to end on both groove families' examples (a face-groove cam and a cylindrical cam), with the
outputs their design files ask for: every file written, nothing skipped (the cylinder's assembly is made too), and
each file read back by its own reader — the workbook by openpyxl (both flanks, or the
``Cylinder`` sheet), the report's animation data and plots, the drawing sheet's PDF by poppler."""
from __future__ import annotations

import io
import json
import re
import shutil
import subprocess

import numpy as np
import pytest

from camfab.cli import main
from tests.conftest import EXAMPLES

openpyxl = pytest.importorskip("openpyxl")

#: per example: the stem, the files every run writes besides check.json and the report
FILES = {
    "groove_translating": ("GrooveTranslating", {".dxf", ".nc", ".step", ".stl", ".xlsx", "_assembly.step",
                                                 "_drawing.dxf", "_drawing.pdf"}),
    "cylindrical_translating": ("BarrelCam", {".dxf", ".step", ".xlsx", "_assembly.step", "_drawing.dxf",
                                              "_drawing.pdf"}),
}


def _anim(html: str) -> dict:
    return json.loads(re.search(r'id="anim-data">(.*?)</script>', html, re.S).group(1))


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(FILES))
def test_run_writes_and_reads_back_every_output(name, tmp_path, capsys):
    pytest.importorskip("cadquery")
    stem, suffixes = FILES[name]
    assert main(["run", str(EXAMPLES / f"{name}.toml"), "-o", str(tmp_path)]) == 0
    out = capsys.readouterr()
    written = {p.name for p in tmp_path.iterdir() if p.is_file()}
    assert written == {f"{stem}{s}" for s in suffixes} | {"check.json", "report.html"}
    assert "skipped" not in out.err, out.err  # every output the design asks for is made for both kinds
    # the workbook: both flanks of the face groove; the cylinder's development
    wb = openpyxl.load_workbook(io.BytesIO((tmp_path / f"{stem}.xlsx").read_bytes()), data_only=True)
    if name == "groove_translating":
        assert {"CAM-DAS", "CAM-DAS 2", "Checks", "Lift table"} <= set(wb.sheetnames)
    else:
        assert wb.sheetnames == ["Cylinder", "Checks"] and wb["Cylinder"]["B4"].value == 40.0
    # the report: its plots and the animation of the family
    html = (tmp_path / "report.html").read_text()
    anim = _anim(html)
    plots = {p.stem for p in (tmp_path / "plots").glob("*.svg")}
    if name == "groove_translating":
        assert anim["closed"] and len(anim["outline"]) == 2 and len(anim["followers"]) == 2 and "profile" in plots
    else:
        assert anim["cylinder"] and len(anim["frames"]["roller"]) == 2 * 360 and "unrolled" in plots
        S = np.asarray(anim["frames"]["S"])
        assert S.max() == pytest.approx(20.0, abs=1e-3) and S.min() == pytest.approx(0.0, abs=1e-3)
    # the drawing sheet's PDF, read by poppler
    pdf = tmp_path / f"{stem}_drawing.pdf"
    assert pdf.read_bytes().startswith(b"%PDF")
    if shutil.which("pdftotext") is None:
        pytest.skip("pdftotext (poppler-utils) is not installed")
    words = subprocess.run(["pdftotext", "-layout", str(pdf), "-"], capture_output=True, text=True,
                           check=True).stdout
    assert stem in words and "LIFT TABLE" in words and "NOTES" in words
    if name == "groove_translating":
        assert "INNER FLANK" in words and "OUTER FLANK" in words
    else:
        assert "DEVELOPED GROOVE" in words and "Z mm" in words
