"""The report animations of the groove families, read from their frame data (not pixels).

Cylindrical cam: each frame's roller sits where the motion law puts it — z₀ + S (translating, the cycloidal law
in closed form) or z₀ + L·sin φ with the arm's shift −σ·L·(1 − cos φ) (oscillating: the arm keeps its length
from the pivot) — and between the groove's edges as the script turns them (the edges crossed at the follower's
generator, at least half the groove width either side, exactly that on a dwell).  Face-groove cam: each frame's
roller touches both flanks, on opposite sides, at half the groove width.  A headless browser plays the
cylinder's page without errors and shows the frame's S."""
from __future__ import annotations

import json
import math
import re

import numpy as np
import pytest

from camfab.design.assemble import check_design, geometry_from_spec
from camfab.design.spec import design_from_dict
from camfab.formats import load_design
from camfab.report.animation import animation_data
from camfab.report.cylinder_animation import cylinder_animation_data
from tests.conftest import CYLINDER_ARM_MM, EXAMPLES, oscillating_cylinder
from tests.report.test_cylinder_outputs import Z0, exact


def _data(spec):
    geom = geometry_from_spec(spec)
    return geom, cylinder_animation_data(spec, geom, check_design(spec))


def _edge_z(edge: list[float], theta: float, sense: int) -> float:
    """Where a turned edge (flat [a, z, …], cam frame) crosses the follower's generator (fixed angle 90°)."""
    a, z = np.asarray(edge).reshape(-1, 2)[:-1].T  # a closed track: its last point is its first
    d = (a - sense * theta - 0.5 * math.pi + math.pi) % (2 * math.pi) - math.pi
    d1, z1 = np.roll(d, -1), np.roll(z, -1)
    i = np.flatnonzero((np.sign(d) != np.sign(d1)) & (np.abs(d1 - d) < math.pi) & (d1 != 0))
    assert i.size == 1, "a groove edge crosses each generator once"
    k = int(i[0])
    return float(z[k] + d[k] / (d[k] - d1[k]) * (z1[k] - z[k]))


def test_cylinder_frames_follow_the_motion_law_between_the_groove_edges():
    spec = load_design(EXAMPLES / "cylindrical_translating.toml")
    geom, d = _data(spec)
    theta = np.asarray(d["frames"]["angle"])
    assert len(theta) == 360 and d["cylinder"] is True
    np.testing.assert_allclose(theta, np.radians(np.arange(360.0)), atol=1e-8)
    roller = np.asarray(d["frames"]["roller"]).reshape(-1, 2)
    want = exact(theta, 40.0)
    np.testing.assert_allclose(roller[:, 0], Z0 + want["S"], atol=6e-4)  # rounded to 1 µm
    np.testing.assert_array_equal(roller[:, 1], 0.0)
    np.testing.assert_allclose(d["frames"]["S"], want["S"], atol=6e-4)
    np.testing.assert_allclose(d["frames"]["pa"][0], want["delta"], atol=6e-4)
    w = geom.mechanism.half_width(45.0)  # the edges are on the outer cylinder
    plus, minus = d["edges"]
    for i in range(0, 360, 5):
        zp, zm = _edge_z(plus, theta[i], d["sense"]), _edge_z(minus, theta[i], d["sense"])
        assert zp - roller[i, 0] >= w - 2e-3 and roller[i, 0] - zm >= w - 2e-3, i
        if 145 <= i <= 175 or i >= 325:  # a dwell: the groove straight across, w either side
            assert (zp - roller[i, 0], roller[i, 0] - zm) == pytest.approx((w, w), abs=2e-3)


@pytest.mark.parametrize("rotation", ["cw", "ccw"])
def test_oscillating_roller_moves_on_its_arc(rotation):
    L = CYLINDER_ARM_MM
    spec = design_from_dict(oscillating_cylinder(rotation))
    geom, d = _data(spec)
    sigma = 1 if rotation == "cw" else -1
    theta = np.asarray(d["frames"]["angle"])
    phi = np.radians(spec.program().evaluate(theta, (0,))[0])
    z0 = geom.mechanism.z0_for(geom.program)
    roller = np.asarray(d["frames"]["roller"]).reshape(-1, 2)
    np.testing.assert_allclose(roller[:, 0], z0 + L * np.sin(phi), atol=6e-4)
    np.testing.assert_allclose(roller[:, 1], -sigma * L * (1 - np.cos(phi)), atol=6e-4)
    assert d["pivot"] == pytest.approx([z0, -sigma * L], abs=6e-4)
    np.testing.assert_allclose(np.hypot(*(roller - np.asarray(d["pivot"])).T), L, atol=2e-3)


def test_groove_cam_roller_touches_both_flanks():
    spec = load_design(EXAMPLES / "groove_translating.toml")
    geom = geometry_from_spec(spec)
    d = animation_data(spec, geom, check_design(spec))
    inner, outer = d["followers"]
    w = geom.mechanism.half_width_mm
    for f in (inner, outer):
        assert f["kind"] == "roller" and f["r"] == pytest.approx(w)
    centre = np.asarray(inner["centre"]).reshape(-1, 2)
    np.testing.assert_array_equal(centre, np.asarray(outer["centre"]).reshape(-1, 2))  # one roller
    a = np.asarray(inner["contact"]).reshape(-1, 2) - centre
    b = np.asarray(outer["contact"]).reshape(-1, 2) - centre
    np.testing.assert_allclose(np.hypot(*a.T), w, atol=2e-3)
    np.testing.assert_allclose(np.hypot(*b.T), w, atol=2e-3)
    np.testing.assert_allclose((a * b).sum(axis=1) / w**2, -1.0, atol=1e-3)  # opposite sides of the roller
    assert len(d["outline"]) == 2 and d["groove"] == pytest.approx(w)  # both flanks, drawn as a groove


def test_cylinder_report_plays_in_a_browser(tmp_path):
    """The report page with the cylinder's animation: no script errors, the canvas drawn, and scrubbing to 90°
    shows that frame's S."""
    import os

    if not os.path.exists("/usr/bin/chromium"):
        pytest.skip("/usr/bin/chromium is missing (apt-get install chromium)")
    sync_api = pytest.importorskip("playwright.sync_api", reason="playwright is missing (pip install playwright)")
    from camfab.pipeline import Output, Request, load, run

    run(load("cylindrical_translating"), tmp_path, Request(frozenset({Output.REPORT})))
    html = (tmp_path / "report.html").read_text()
    data = json.loads(re.search(r'id="anim-data">(.*?)</script>', html, re.S).group(1))
    assert data["cylinder"] is True
    with sync_api.sync_playwright() as p:
        b = p.chromium.launch(executable_path="/usr/bin/chromium", args=["--headless", "--no-sandbox", "--disable-gpu"])
        page = b.new_page(viewport={"width": 1280, "height": 1000})
        errors: list[str] = []
        page.on("pageerror", lambda e: errors.append(str(e)))
        page.on("console", lambda m: m.type == "error" and errors.append(m.text))
        page.goto((tmp_path / "report.html").as_uri(), wait_until="load")
        page.wait_for_timeout(300)
        page.fill("#anim-angle", "90")
        page.dispatch_event("#anim-angle", "input")
        assert page.inner_text("#anim-angle-readout") == "90.0°"
        assert page.inner_text("#anim-s-readout") == f"{exact(np.array([math.pi / 2]), 40.0)['S'][0]:.3f} mm"
        ink = page.evaluate("""() => { const c = document.getElementById('anim-canvas');
            const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data; let n = 0;
            for (let i = 0; i < d.length; i += 4) { if (d[i] < 240 || d[i + 1] < 240 || d[i + 2] < 240) n++; }
            return n; }""")
        b.close()
    assert ink > 5000 and errors == []
