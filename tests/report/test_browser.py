"""A real headless browser (Debian chromium through playwright) opens generated reports
from file:// with the network cut off: no console errors, every plot loaded, the canvas
drawn, and the animation advancing on Play and standing still on Pause.

Needs ``/usr/bin/chromium`` (``apt-get install chromium``) and ``pip install playwright``;
``playwright install`` is *not* used (it downloads its own browser).
"""
from __future__ import annotations

import os
import shutil

import pytest

CHROMIUM = "/usr/bin/chromium"
ARGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
        "--disable-background-networking", "--disable-component-update", "--disable-sync"]

if not os.path.exists(CHROMIUM):
    pytest.skip(f"{CHROMIUM} is missing (apt-get install chromium)", allow_module_level=True)
sync_api = pytest.importorskip("playwright.sync_api", reason="playwright is missing (pip install playwright)")


@pytest.fixture(scope="module")
def browser():
    with sync_api.sync_playwright() as p:
        b = p.chromium.launch(executable_path=CHROMIUM, args=ARGS)
        yield b
        b.close()


class Page:
    """A page with console/page errors and every non-local request recorded."""

    def __init__(self, browser, url: str):
        self.page = browser.new_page(viewport={"width": 1280, "height": 1000})
        self.errors: list[str] = []
        self.remote: list[str] = []
        self.page.on("console", lambda m: m.type in ("error", "warning") and self.errors.append(f"{m.type}: {m.text}"))
        self.page.on("pageerror", lambda e: self.errors.append(f"pageerror: {e}"))
        self.page.route("**/*", self._route)
        self.page.goto(url, wait_until="load")

    def _route(self, route):
        url = route.request.url
        if url.startswith(("file:", "data:", "blob:")):
            route.continue_()
        else:
            self.remote.append(url)
            route.abort()

    def text(self, sel: str) -> str:
        return self.page.inner_text(sel)


def _open(browser, directory, name="report.html") -> Page:
    return Page(browser, (directory / name).as_uri())


def _plots_loaded(pg: Page) -> list[dict]:
    return pg.page.evaluate("""() => Array.from(document.querySelectorAll('img[data-plot]')).map(i => ({
        name: i.dataset.plot, complete: i.complete, w: i.naturalWidth, h: i.naturalHeight}))""")


def _canvas_ink(pg: Page) -> int:
    """Number of non-white pixels drawn on the animation canvas."""
    return pg.page.evaluate("""() => { const c = document.getElementById('anim-canvas');
        const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data; let n = 0;
        for (let i = 0; i < d.length; i += 4) { if (d[i] < 240 || d[i + 1] < 240 || d[i + 2] < 240) n++; }
        return n; }""")


@pytest.mark.parametrize("which", ["e9", "bad", "valve"])
def test_report_loads_cleanly_with_plots_and_canvas(browser, which, request):
    directory = request.getfixturevalue(f"{which}_dir")
    pg = _open(browser, directory)
    pg.page.wait_for_timeout(200)
    imgs = _plots_loaded(pg)
    expected = sorted(p.stem for p in (directory / "plots").glob("*.svg"))
    assert sorted(i["name"] for i in imgs) == expected
    assert all(i["complete"] and i["w"] > 0 and i["h"] > 0 for i in imgs), imgs
    assert _canvas_ink(pg) > 5000
    assert pg.page.locator("#conclusions-table tbody tr").count() >= 5
    assert pg.page.locator("#verdict").get_attribute("data-verdict") == request.getfixturevalue(which)[2].verdict
    assert pg.errors == [] and pg.remote == []
    pg.page.close()


def test_animation_plays_pauses_and_scrubs(browser, e9_dir):
    pg = _open(browser, e9_dir)
    page = pg.page
    assert page.inner_text("#anim-play") == "Pause"  # it starts playing
    a0 = pg.text("#anim-angle-readout")
    page.wait_for_timeout(600)
    a1 = pg.text("#anim-angle-readout")
    assert a1 != a0 and a1.endswith("°")
    page.click("#anim-play")
    assert page.inner_text("#anim-play") == "Play" and page.evaluate("window.camfabAnimation.playing()") is False
    page.wait_for_timeout(100)
    p0, f0 = pg.text("#anim-angle-readout"), page.evaluate("window.camfabAnimation.frame()")
    page.wait_for_timeout(600)
    assert pg.text("#anim-angle-readout") == p0 and page.evaluate("window.camfabAnimation.frame()") == f0
    # faster speed → it advances further in the same time
    page.fill("#anim-speed", "60")
    page.dispatch_event("#anim-speed", "input")
    assert pg.text("#anim-speed-value") == "60"
    page.click("#anim-play")
    page.wait_for_timeout(500)
    f1 = page.evaluate("window.camfabAnimation.frame()")
    assert (f1 - f0) % 360 > 20  # 60 rev/min = 360°/s
    # scrubbing pauses and shows that angle, S and the pressure angle of that frame
    page.fill("#anim-angle", "296")
    page.dispatch_event("#anim-angle", "input")
    assert page.evaluate("window.camfabAnimation.playing()") is False
    assert pg.text("#anim-angle-readout") == "296.0°"
    assert pg.text("#anim-pa-readout").startswith("-28.1")  # Ejemplo9RT's worst pressure angle is near 296°
    assert pg.errors == [] and pg.remote == []
    page.close()


def test_pressure_angle_readout_turns_red_beyond_the_limit(browser, bad_dir):
    pg = _open(browser, bad_dir)
    pg.page.fill("#anim-angle", "22")
    pg.page.dispatch_event("#anim-angle", "input")
    assert "bad" in pg.page.get_attribute("#anim-pa-readout", "class")
    pg.page.fill("#anim-angle", "160")
    pg.page.dispatch_event("#anim-angle", "input")
    assert "bad" not in pg.page.get_attribute("#anim-pa-readout", "class")
    assert pg.errors == []
    pg.page.close()


def test_screenshot(browser, bad_dir, tmp_path):
    """A full-page screenshot (kept in the pytest tmp dir for a person to look at)."""
    pg = _open(browser, bad_dir)
    pg.page.fill("#anim-angle", "22")
    pg.page.dispatch_event("#anim-angle", "input")
    out = tmp_path / "report.png"
    pg.page.screenshot(path=str(out), full_page=True)
    assert out.stat().st_size > 50_000
    keep = os.environ.get("CAMFAB_SCREENSHOT")
    if keep:
        shutil.copy(out, keep)
    pg.page.close()
