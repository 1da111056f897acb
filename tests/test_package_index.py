"""`camfab package`'s drawing set (``drawings.pdf``, read back by poppler) and its ``index.html`` overview opened in
a real headless browser (Debian chromium through playwright, network cut off): no horizontal overflow, even
with a long error; sortable columns; a thumbnail per built cam; hostile names shown as text, never run."""
from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
from pathlib import Path

import pytest

from camfab.cli import main
from tests.conftest import EXAMPLES

PDFTOTEXT, PDFINFO = shutil.which("pdftotext"), shutil.which("pdfinfo")
CHROMIUM = "/usr/bin/chromium"
ARGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
        "--disable-background-networking", "--disable-component-update", "--disable-sync"]
HOSTILE = 'Bad <script>window.pwned=1</script> & "q" $x$'
LONG = "broken_" + "x" * 200  # a design file's name the error quotes: one long word that must wrap

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def pkg(tmp_path_factory):
    src = tmp_path_factory.mktemp("designs")
    for name in ("ejemplo9rt", "wedge_translating"):
        shutil.copy(EXAMPLES / f"{name}.toml", src)
    e9 = (EXAMPLES / "ejemplo9rt.toml").read_text()
    (src / "bad.toml").write_text(re.sub(r'(?m)^name = .*$', lambda m: f"name = {json.dumps(HOSTILE)}", e9, count=1)
                                  .replace("base_radius_mm = 35.0", "base_radius_mm = 12.0"))
    (src / f"{LONG}.toml").write_text('name = "Broken"\n[follower]\nno_such_key = 1\n')
    out = tmp_path_factory.mktemp("pkg") / "out"
    assert main(["package", str(src), "-o", str(out), "--outputs", "drawing,pdf"]) == 2  # one design fails
    return out, json.loads((out / "manifest.json").read_text())


def test_manifest_holds_the_key_figures(pkg):
    _, m = pkg
    by = {c["name"]: c for c in m["cams"]}
    e9 = by["Ejemplo9RT"]["figures"]
    assert e9["r_max_mm"] == pytest.approx(45.0, abs=1e-6) and e9["d_max_mm"] == pytest.approx(90.0, abs=1e-6)
    assert e9["pressure_angle_max_deg"] <= e9["pressure_angle_limit_deg"]
    assert 0 < e9["deviation_mm"] <= by["Ejemplo9RT"]["tolerance_mm"]
    assert by["WedgeCam"]["figures"]["d_max_mm"] is None  # a translating plate has no diameter
    bad = by[HOSTILE]
    assert bad["status"] == "unacceptable" and "drawing" in bad["withheld"]
    assert any(r["severity"] == "error" for r in bad["reasons"])


# ---------------------------------------------------------------------------
@pytest.mark.skipif(not (PDFTOTEXT and PDFINFO), reason="poppler-utils is missing (apt-get install poppler-utils)")
def test_drawing_set_contents_and_pages(pkg):
    out, m = pkg
    pdf = out / "drawings.pdf"
    info = subprocess.run([PDFINFO, str(pdf)], capture_output=True, text=True, check=True).stdout
    pages = int(re.search(r"Pages:\s+(\d+)", info).group(1))
    sheets = [c for c in m["cams"] if any(f["path"].endswith("_drawing.dxf") for f in c["files"])]
    assert len(sheets) == 2 and pages == 1 + len(sheets) == m["drawing_set"]["pages"]

    def page(k: int) -> str:
        return subprocess.run([PDFTOTEXT, "-layout", "-f", str(k), "-l", str(k), str(pdf), "-"],
                              capture_output=True, text=True, check=True).stdout

    contents = page(1)
    for c in m["cams"]:  # every cam listed, in order, with the page its sheet is on (its title block names it)
        line = next(ln for ln in contents.splitlines() if c["name"][:30] in ln)
        last = line.split()[-1]
        if c in sheets:
            assert c["name"] in page(int(last))
        else:
            assert last == "—"
    assert "withheld" in contents and "in the design" in contents  # why the two have no sheet
    # a second package run renders nothing again: the same file
    before = pdf.read_bytes()
    assert main(["package", str(Path(m["cams"][0]["source"]).parent), "-o", str(out), "--outputs",
                 "drawing,pdf"]) == 2
    assert pdf.read_bytes() == before


# ---------------------------------------------------------------------------
@pytest.fixture(scope="module")
def browser():
    if not os.path.exists(CHROMIUM):
        pytest.skip(f"{CHROMIUM} is missing (apt-get install chromium)")
    sync_api = pytest.importorskip("playwright.sync_api", reason="playwright is missing (pip install playwright)")
    with sync_api.sync_playwright() as p:
        b = p.chromium.launch(executable_path=CHROMIUM, args=ARGS)
        yield b
        b.close()


def _open(browser, pkg, width: int):
    out, _ = pkg
    page = browser.new_page(viewport={"width": width, "height": 900})
    errors: list[str] = []
    page.on("pageerror", lambda e: errors.append(str(e)))
    page.on("console", lambda msg: msg.type == "error" and errors.append(msg.text))
    page.route("**/*", lambda r: r.continue_() if r.request.url.startswith(("file:", "data:")) else r.abort())
    page.goto((out / "index.html").as_uri(), wait_until="load")
    return page, errors


@pytest.mark.parametrize("width", [1280, 800])
def test_index_fits_the_window_and_wraps_the_error(browser, pkg, width):
    page, errors = _open(browser, pkg, width)
    assert not errors
    sw, iw = page.evaluate("() => [document.documentElement.scrollWidth, window.innerWidth]")
    assert sw <= iw
    right = page.evaluate("() => document.querySelector('tr[data-status=error] .errmsg').getBoundingClientRect()"
                          ".right")
    assert right <= iw
    assert LONG in page.inner_text("tr[data-status=error] .errmsg")
    page.close()


def test_index_overview(browser, pkg):
    _, m = pkg
    page, errors = _open(browser, pkg, 1280)
    counts = page.evaluate("() => Object.fromEntries([...document.querySelectorAll('[data-count]')]"
                           ".map(e => [e.dataset.count, +e.querySelector('b').textContent]))")
    assert counts == {"acceptable": 0, "not_for_high_speed": 2, "unacceptable": 1, "error": 1}
    assert page.get_attribute("#drawing-set", "href") == "drawings.pdf"
    # a thumbnail per built cam, with an outline path
    assert page.evaluate("() => document.querySelectorAll('td.thumb svg path').length") == 3
    # hostile name: shown as text, its script never ran, only our script is on the page
    assert page.evaluate("() => window.pwned") is None
    assert page.evaluate("() => document.scripts.length") == 1
    assert HOSTILE in page.inner_text("#cams")
    # grouped files instead of raw links: a "drawings" group with the sheet and its PDF
    groups = page.evaluate("() => [...document.querySelectorAll('td.files .kind')].map(e => e.textContent)")
    assert "drawings:" in groups
    # sorting: R max ascending, then descending (the error row last both ways)
    col = page.evaluate("() => [...document.querySelectorAll('#cams thead th')].findIndex(t => "
                        "t.textContent.startsWith('R max'))")

    def column():
        return page.evaluate(f"() => [...document.querySelectorAll('#cams tbody tr')].map(r => "
                             f"r.dataset.status === 'error' ? null : parseFloat(r.cells[{col}].dataset.value))")

    page.click(f"#cams thead th:nth-child({col + 1})")
    up = column()
    assert up[-1] is None and up[:-1] == sorted(up[:-1])
    page.click(f"#cams thead th:nth-child({col + 1})")
    down = column()
    assert down[-1] is None and down[:-1] == sorted(down[:-1], reverse=True)
    assert sorted(up[:-1]) == sorted(c["figures"]["r_max_mm"] for c in m["cams"] if c.get("figures"))
    assert not errors
    page.close()


def test_disk_full_on_the_drawing_set_keeps_the_old_one(pkg, tmp_path, monkeypatch, capsys):
    """The set is streamed into a temporary file: a full disk leaves the old set whole, no temporary file, and
    the manifest and index still written (exit 3, naming the set)."""
    import errno

    import camfab.io as cio

    out, m = pkg
    copy = tmp_path / "out"
    shutil.copytree(out, copy)
    old = (copy / "drawings.pdf").read_bytes()
    (copy / "manifest.json").write_text(json.dumps({**m, "drawing_set": None}))  # the set must be written again
    (copy / "index.html").unlink()
    real = cio.write_bytes

    def write_bytes(fh, raw, path):
        if path.name == "drawings.pdf":
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        real(fh, raw, path)

    monkeypatch.setattr(cio, "write_bytes", write_bytes)
    assert main(["package", str(Path(m["cams"][0]["source"]).parent), "-o", str(copy), "--outputs",
                 "drawing,pdf"]) == 3
    assert str(copy / "drawings.pdf") in capsys.readouterr().err
    assert (copy / "drawings.pdf").read_bytes() == old
    assert (copy / "index.html").is_file() and (copy / "manifest.json").is_file()
    assert not [p for p in copy.rglob("*") if ".camfab-" in p.name]
