"""PDF drawing sheets read back by poppler (``pdfinfo``, ``pdftotext``): the page is the paper at true scale,
the sheet's text is real text, the bytes are the same on every run; ``[outputs] pdf`` and ``camfab run``."""
from __future__ import annotations

import io
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from camfab.cad.drawing import drawing_sheet
from camfab.cad.export import cam_shapes
from camfab.cad.pdf import CONTENTS_ROWS, PT_PER_MM, SetEntry, contents_layout, sheet_pdf, write_drawing_set
from camfab.design.assemble import check_design, geometry_from_spec
from camfab.design.spec import design_from_dict
from camfab.errors import SpecError
from tests.conftest import base_design

ezdxf = pytest.importorskip("ezdxf")
POPPLER = {t: shutil.which(t) for t in ("pdfinfo", "pdftotext")}
needs_poppler = pytest.mark.skipif(not all(POPPLER.values()),
                                   reason="poppler-utils is missing (apt-get install poppler-utils)")

HOSTILE = 'Cam $\\alpha$ <b>&amp; "q" (x)'
PAPERS_MM = {"A4": (297.0, 210.0), "A3": (420.0, 297.0)}


def _sheet(name: str = "Ejemplo9RT", paper: str = "auto") -> str:
    d = base_design(manufacturing={"thickness_mm": 10.0, "bore_mm": 12.0, "keyway": True, "material": "C45E"})
    d["name"] = name
    spec = design_from_dict(d)
    geom = geometry_from_spec(spec)
    return drawing_sheet(spec, geom, check_design(spec), cam_shapes(geom, tol=1e-3), paper=paper)


@pytest.fixture(scope="module")
def e9(tmp_path_factory):
    text = _sheet()
    pdf = tmp_path_factory.mktemp("pdf") / "e9.pdf"
    pdf.write_bytes(sheet_pdf(text))
    return text, ezdxf.read(io.StringIO(text)), pdf


def _info(pdf: Path) -> dict[str, str]:
    out = subprocess.run([POPPLER["pdfinfo"], str(pdf)], capture_output=True, text=True, check=True).stdout
    return dict(line.split(":", 1) for line in out.splitlines() if ":" in line)


def _page_mm(pdf: Path) -> tuple[float, float]:
    w, h = re.match(r"\s*([\d.]+) x ([\d.]+) pts", _info(pdf)["Page size"]).groups()
    return float(w) / PT_PER_MM, float(h) / PT_PER_MM


def _text(pdf: Path, *args: str) -> str:
    return subprocess.run([POPPLER["pdftotext"], *args, str(pdf), "-"], capture_output=True, text=True,
                          check=True).stdout


def _flat(s: str) -> str:
    return " ".join(s.split())


@needs_poppler
@pytest.mark.parametrize("paper", ["A4", "A3"])
def test_page_is_the_paper(paper, tmp_path):
    pdf = tmp_path / "s.pdf"
    pdf.write_bytes(sheet_pdf(_sheet(paper=paper)))
    w, h = _page_mm(pdf)
    assert (w, h) == pytest.approx(PAPERS_MM[paper], abs=0.01)
    assert _info(pdf)["Pages"].strip() == "1"


@needs_poppler
def test_every_text_of_the_sheet_is_real_text(e9):
    _, doc, pdf = e9
    lines = {"".join(line.split()) for line in _text(pdf, "-layout").splitlines()}
    solid = "\n".join(lines)  # pdftotext sets narrow spaces apart or not ("1 / 1" → "1/1"): compared without
    texts = [t.plain_text() for t in doc.modelspace().query("TEXT") if t.plain_text().strip()]  # %%c → Ø
    assert len(texts) > 50  # title block, lift table, annotations
    missing = [t for t in texts if "".join(t.split()) not in solid]
    assert not missing, missing
    assert all(w in solid for w in ("Ejemplo9RT", "C45E", "NOTES"))


@needs_poppler
def test_true_scale_text_lands_where_the_sheet_puts_it(e9):
    """pdftotext's word boxes (pt) / (72/25.4) are the sheet's paper mm: a left-aligned one-word TEXT starts
    where its insertion point is."""
    _, doc, pdf = e9
    _, h = _page_mm(pdf)
    html = _text(pdf, "-bbox")
    boxes: dict[str, list[tuple[float, float]]] = {}
    for x0, y1, word in re.findall(r'<word xMin="([\d.]+)" yMin="[\d.]+" xMax="[\d.]+" yMax="([\d.]+)">([^<]*)<',
                                   html):
        boxes.setdefault(word, []).append((float(x0) / PT_PER_MM, h - float(y1) / PT_PER_MM))
    checked = 0
    for t in doc.modelspace().query("TEXT"):
        align, at, _ = t.get_placement()
        word = t.dxf.text
        if not align.name.endswith("LEFT") or " " in word or word not in boxes or not word.isalpha():
            continue
        assert min(abs(x - at[0]) for x, _ in boxes[word]) < 0.3, word  # mm
        checked += 1
    assert checked >= 5


def test_same_bytes_in_another_process(e9, tmp_path):
    text, _, pdf = e9
    dxf = tmp_path / "s.dxf"
    dxf.write_text(text)
    code = "import sys; from pathlib import Path; from camfab.cad.pdf import sheet_pdf; " \
           "sys.stdout.buffer.write(sheet_pdf(Path(sys.argv[1])))"
    env = {**os.environ, "PYTHONHASHSEED": "12345"}
    other = subprocess.run([sys.executable, "-c", code, str(dxf)], capture_output=True, check=True, env=env).stdout
    assert other == pdf.read_bytes()
    assert b"/CreationDate" not in other and b"/ModDate" not in other


@needs_poppler
def test_hostile_name_is_plain_text(tmp_path):
    pdf = tmp_path / "h.pdf"
    pdf.write_bytes(sheet_pdf(_sheet(name=HOSTILE)))
    assert HOSTILE in _text(pdf)  # no mathtext, no markup: the characters as given
    assert _info(pdf)["Title"].strip() == HOSTILE


def test_contents_pages_number_the_sheets():
    entries = [SetEntry(f"c{i}", "acceptable", sheet=Path(f"{i}.dxf") if i % 3 else None, reason="x")
               for i in range(100)]
    n, pages = contents_layout(entries)
    assert n == -(-100 // CONTENTS_ROWS) >= 2
    with_sheets = [p for p in pages if p is not None]
    assert with_sheets == list(range(n + 1, n + 1 + len(with_sheets)))
    assert [p is None for p in pages] == [i % 3 == 0 for i in range(100)]


@needs_poppler
def test_drawing_set_with_two_contents_pages(e9, tmp_path):
    text, _, _ = e9
    dxf = tmp_path / "s.dxf"
    dxf.write_text(text)
    n = CONTENTS_ROWS + 5
    entries = [SetEntry(f"cam{i:02d}", "acceptable", f"D-{i}", dxf if i == n - 2 else None, f"reason {i}")
               for i in range(n)]
    out = tmp_path / "set.pdf"
    assert write_drawing_set(out, entries) == 3
    assert _info(out)["Pages"].strip() == "3"
    assert _page_mm(out) == pytest.approx((210.0, 297.0), abs=0.01)  # contents: A4 portrait
    second = _text(out, "-layout", "-f", "2", "-l", "2")
    assert f"cam{CONTENTS_ROWS:02d}" in second and f"cam{CONTENTS_ROWS - 1:02d}" not in second
    line = next(ln for ln in second.splitlines() if f"cam{n - 2:02d}" in ln)
    assert line.split()[-1] == "3" and f"D-{n - 2}" in line
    assert "reason 0" in _text(out, "-f", "1", "-l", "1")
    assert "Ejemplo9RT" in _text(out, "-f", "3", "-l", "3")


# ---------------------------------------------------------------------------
# [outputs] pdf
def _outputs(**o):
    return design_from_dict(base_design(outputs=o)).outputs


def test_pdf_output_follows_the_drawing_unless_given():
    assert _outputs(drawing=True).pdf is True
    assert _outputs(drawing=False).pdf is False
    assert _outputs(drawing=True, pdf=False).pdf is False
    assert _outputs(drawing=False, pdf=True).pdf is True
    with pytest.raises(SpecError, match=r"outputs\.pdf"):
        _outputs(pdf="yes")


@needs_poppler
def test_run_writes_the_pdf_beside_the_sheet(tmp_path):
    from camfab import pipeline

    d = base_design(outputs={"dxf": False, "step": False, "report": False, "drawing": True})
    d["name"] = "RunPdf"
    cam = pipeline.Cam(design_from_dict(d))
    req = pipeline.Request.from_design(cam.spec)
    assert req.outputs == {pipeline.Output.DRAWING, pipeline.Output.PDF}
    res = pipeline.run(cam, tmp_path / "o", req)
    assert {"RunPdf_drawing.dxf", "RunPdf_drawing.pdf"} <= set(res.files)
    pdf = tmp_path / "o" / "RunPdf_drawing.pdf"
    assert _page_mm(pdf) == pytest.approx(PAPERS_MM["A4"], abs=0.01)
    assert "RunPdf" in _text(pdf)
    assert "RunPdf_drawing.pdf" in pipeline.shop_file_names(cam)  # withheld with the sheet when unacceptable
