"""The HTML report: files, verdict, every finding in words, the conclusions numbers equal
the report's, animation frames consistent with the geometry, offline, deterministic."""
from __future__ import annotations

import html
import json
import math
import re
import xml.etree.ElementTree as ET
from html.parser import HTMLParser

import numpy as np
import pytest

from camfab.assets import templates
from camfab.design.spec import design_from_dict
from camfab.report._common import VERDICT_TEXT, conclusions_rows
from camfab.report.animation import animation_data
from camfab.report.html import render_report
from tests.report.designs import checked_design

from ..conftest import base_design
from .designs import DESIGNS

pytest.importorskip("jinja2", reason="HTML reports need jinja2")
pytest.importorskip("matplotlib", reason="report plots need matplotlib")


class _Cells(HTMLParser):
    """data-value attributes of <td>s, by the id of the enclosing table."""

    def __init__(self):
        super().__init__()
        self.table, self.values, self.imgs, self.scripts = None, {}, [], []

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if tag == "table" and "id" in a:
            self.table = a["id"]
        if tag == "td" and "data-value" in a:
            self.values.setdefault(self.table, []).append(float(a["data-value"]))
        if tag == "img":
            self.imgs.append(a)
        if tag == "script":
            self.scripts.append(a)


def _parse(page: bytes) -> _Cells:
    p = _Cells()
    p.feed(page.decode("utf-8"))
    return p


def _anim(page: bytes) -> dict:
    m = re.search(r'<script type="application/json" id="anim-data">(.*?)</script>', page.decode(), re.S)
    return json.loads(m.group(1))


def test_report_templates_are_found():
    base = templates().joinpath("report")
    for name in ("report.html.j2", "compare.html.j2", "base.html.j2", "_macros.html.j2", "animation.js",
                 "report.css"):
        assert base.joinpath(name).is_file(), name


def test_report_files_and_plots_are_valid(e9_files):
    names = ["svaj", "profile", "curvature", "pressure_angle"]
    assert sorted(e9_files) == sorted(["report.html"] + [f"plots/{n}.svg" for n in names])  # PNG only when asked
    for n in names:
        assert ET.fromstring(e9_files[f"plots/{n}.svg"]).tag.endswith("svg")
    page = _parse(e9_files["report.html"])
    assert sorted(i["data-plot"] for i in page.imgs) == sorted(names)
    assert all(i["src"] == f"plots/{i['data-plot']}.svg" for i in page.imgs)
    assert ".png" not in e9_files["report.html"].decode()  # no link to a file that was not written


def test_report_png_on_request(e9, tmp_path, capsys):
    from PIL import Image

    from camfab.cli import main

    assert main(["report", "ejemplo9rt", "-o", str(tmp_path), "--png"]) == 0
    names = ["svaj", "profile", "curvature", "pressure_angle"]
    for n in names:
        im = Image.open(tmp_path / "plots" / f"{n}.png")
        assert im.format == "PNG" and im.width > 500 and im.height > 300
    page = (tmp_path / "report.html").read_text()
    assert all(f'href="plots/{n}.png"' in page for n in names)


def test_flat_face_report_has_the_face_plot(valve_files):
    assert "plots/face_position.svg" in valve_files and "plots/pressure_angle.svg" not in valve_files
    text = valve_files["report.html"].decode()
    assert "Face length left / right (mm)" in text and "Knot table" in text


@pytest.mark.parametrize("which", ["e9", "bad", "valve"])
def test_verdict_and_every_finding_in_words(which, request):
    spec, geom, rep = request.getfixturevalue(which)
    text = request.getfixturevalue(f"{which}_files")["report.html"].decode()
    assert f'data-verdict="{rep.verdict}"' in text and html.escape(VERDICT_TEXT[rep.verdict]) in text
    assert rep.findings
    for f in rep.findings:
        assert html.escape(f.message) in text, f.message
        assert f'data-code="{f.code}"' in text
    assert text.count('class="finding ') == len(rep.findings)


def test_undercut_is_reported_with_its_range(bad_files):
    text = bad_files["report.html"].decode()
    assert "Cam KO (unacceptable)" in text and 'class="verdict bad"' in text
    assert re.search(r"from 279\.0° to 285\.6°</span>: undercut", text)
    assert "High pressure angle (&gt; 30°)" in text


@pytest.mark.parametrize("which", ["e9", "bad", "valve"])
def test_conclusions_numbers_are_the_reports(which, request):
    spec, geom, rep = request.getfixturevalue(which)
    page = _parse(request.getfixturevalue(f"{which}_files")["report.html"])
    d = rep.to_dict()
    want = []
    for q in "SVAJ":
        want += [d["peaks"][q]["max"], d["peaks"][q]["min"]]
    want.append(d["radius_of_curvature_mm"]["min_convex"])
    if d["radius_of_curvature_mm"]["min_concave"] is not None:
        want.append(d["radius_of_curvature_mm"]["min_concave"])
    if d["pressure_angle_deg"]:
        want += [d["pressure_angle_deg"]["max"], d["pressure_angle_deg"]["min"]]
    if d["face_length_mm"]:
        want += [d["face_length_mm"]["left"], d["face_length_mm"]["right"]]
    assert page.values["conclusions-table"] == want  # exact floats, in table order
    dims = page.values["dimensions"]
    assert dims[:4] == [d["base_radius_mm"], 2 * d["base_radius_mm"], d["max_radius_mm"], 2 * d["max_radius_mm"]]
    assert dims[4] == d["area_mm2"]
    rows = conclusions_rows(spec, rep)
    text = request.getfixturevalue(f"{which}_files")["report.html"].decode()
    for r in rows:
        assert html.escape(r["concept"]) in text and r["min"]["text"] in text


def test_animation_frames_follow_the_geometry(e9_files, e9):
    spec, geom, rep = e9
    a = _anim(e9_files["report.html"])
    assert len(a["frames"]["x"]) == 360 and a["sense"] == 1 and a["closed"]
    f = a["followers"][0]
    assert f["kind"] == "roller" and f["r"] == 7.0
    centre = np.reshape(f["centre"], (-1, 2))
    S = spec.program().evaluate(np.radians(np.arange(360)))[0]
    np.testing.assert_allclose(centre[:, 1], 42.0 + S, atol=1e-3)  # roller centre on the axis, R_p + S
    np.testing.assert_allclose(centre[:, 0], 0.0, atol=1e-3)
    np.testing.assert_allclose(a["frames"]["S"], S, atol=1e-3)
    pa = np.degrees(geom.evaluate(np.radians(np.arange(360))).pressure_angle)
    np.testing.assert_allclose(a["frames"]["pa"][0], pa, atol=1e-3)
    # the outline turned by the frame angle touches the roller: contact point = rotated profile point
    ang = a["frames"]["angle"][77]
    p = geom.evaluate(np.radians([77.0])).point[0]
    q = [p[0] * math.cos(ang) - p[1] * math.sin(ang), p[0] * math.sin(ang) + p[1] * math.cos(ang)]
    np.testing.assert_allclose(np.reshape(f["contact"], (-1, 2))[77], q, atol=1e-3)
    assert np.hypot(*(np.reshape(f["contact"], (-1, 2))[77] - centre[77])) == pytest.approx(7.0, abs=2e-3)


@pytest.mark.parametrize("name", sorted(DESIGNS))
def test_animation_data_for_every_mechanism(name):
    spec, geom, rep = checked_design(design_from_dict(DESIGNS[name]))
    a = animation_data(spec, geom, rep, frames=72)
    json.dumps(a, allow_nan=False)
    expect = len(geom.profiles) + (spec.cam.kind in ("constant_width", "constant_diameter"))
    assert len(a["followers"]) == expect and len(a["outline"]) == len(geom.profiles)
    x0, x1, y0, y1 = a["bounds"]
    for f in a["followers"]:
        for key in ("link", "face"):
            if key in f:
                pts = np.reshape(f[key], (-1, 2))
                assert np.all((pts[:, 0] >= x0) & (pts[:, 0] <= x1) & (pts[:, 1] >= y0) & (pts[:, 1] <= y1))
        assert len(f["contact"]) == 2 * 72
    if spec.follower.motion == "oscillating":
        assert a["pivot"] == [spec.follower.pivot_distance_mm, 0.0]


def test_offline_small_and_deterministic(e9, e9_files):
    text = e9_files["report.html"].decode()
    assert not re.search(r'(src|href)="(https?:)?//', text)
    assert "<script src" not in text and "@import" not in text
    assert len(e9_files["report.html"]) < 1_500_000
    assert render_report(*e9) == e9_files  # byte-identical, plots included


def test_standalone_embeds_plots_and_escapes_names():
    d = base_design(name='A<b>&"c</script>')
    files = render_report(*checked_design(design_from_dict(d)), standalone=True)
    text = files["report.html"].decode()
    assert "A&lt;b&gt;&amp;&#34;c&lt;/script&gt;" in text and 'A<b>&"c' not in text
    page = _parse(files["report.html"])
    assert page.imgs and all(i["src"].startswith("data:image/svg+xml;base64,") for i in page.imgs)
    assert _anim(files["report.html"])["name"] == 'A<b>&"c</script>'
    assert len(files["report.html"]) < 1_500_000
