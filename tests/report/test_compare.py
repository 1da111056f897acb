"""``camfab compare``: overlaid plots and the side-by-side table (CAM-DAS "Pizarra")."""
from __future__ import annotations

import io
from html.parser import HTMLParser

import pytest

from camfab.cli import main
from camfab.report import figure_bytes
from camfab.report.compare import compare_svaj_figure, comparison_rows, design_labels, render_comparison

from ..conftest import EXAMPLES

pytest.importorskip("jinja2", reason="HTML reports need jinja2")
pytest.importorskip("matplotlib", reason="report plots need matplotlib")


class _Table(HTMLParser):
    def __init__(self):
        super().__init__()
        self.rows, self._row, self.table_cell, self.imgs = [], None, None, []

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if tag == "tr":
            self._row = []
        elif tag in ("td", "th") and self._row is not None:
            self.table_cell = {"text": "", "value": a.get("data-value")}
        elif tag == "img":
            self.imgs.append(a)

    def handle_data(self, data):
        if self.table_cell is not None:
            self.table_cell["text"] += data

    def handle_endtag(self, tag):
        if tag in ("td", "th") and self.table_cell is not None:
            self._row.append(self.table_cell)
            self.table_cell = None
        elif tag == "tr" and self._row is not None:
            self.rows.append(self._row)
            self._row = None


@pytest.fixture(scope="module")
def compared(e9, valve, bad):
    items = [e9, valve, bad]
    return items, render_comparison(items)


def test_files_and_overlaid_plots(compared):
    items, files = compared
    assert sorted(files) == sorted(["compare.html"] + [f"plots/{n}.svg" for n in ("svaj", "curvature",
                                                                               "pressure_angle")])
    from PIL import Image

    png = figure_bytes(compare_svaj_figure(items, design_labels(items)), "png")  # what --png writes
    im = Image.open(io.BytesIO(png))
    assert im.format == "PNG" and im.width > 500


def test_overlay_has_one_curve_per_design(e9, valve, bad):
    from camfab.report.compare import compare_curvature_figure, compare_svaj_figure

    items = [e9, valve, bad]
    fig = compare_svaj_figure(items)
    labels = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    assert labels == ["Ejemplo9RT", "ValveExhaustEj1", "TooSmall"]
    assert all(len(ax.lines) >= 3 for ax in fig.axes)
    assert len(compare_curvature_figure(items).axes[0].lines) == 3 + 1  # + the ρ = 0 line


def test_side_by_side_table_matches_the_reports(compared):
    items, files = compared
    t = _Table()
    t.feed(files["compare.html"].decode())
    head = [c["text"] for c in t.rows[0]]
    assert head[1].startswith("Ejemplo9RT") and head[2].startswith("ValveExhaustEj1") and head[3].startswith("TooSmall")
    by_label = {r[0]["text"]: r[1:] for r in t.rows[1:]}
    ds = [rep.to_dict() for _, _, rep in items]
    for q in "VAJ":
        for key in ("max", "min"):
            assert [float(c["value"]) for c in by_label[f"{q} {key}"]] == [d["peaks"][q][key] for d in ds]
    assert [c["text"] for c in by_label["Verdict"]] == ["Not suitable for high speeds",
                                                         "Not suitable for high speeds", "Cam KO (unacceptable)"]
    assert float(by_label["Ø max = 2·R max, blank (mm)"][0]["value"]) == 2 * ds[0]["max_radius_mm"]
    assert [c["value"] and float(c["value"]) for c in by_label["Pressure angle max (°)"]] == \
        [ds[0]["pressure_angle_deg"]["max"], None, ds[2]["pressure_angle_deg"]["max"]]
    assert by_label["Face length left (mm)"][1]["value"] is not None
    assert by_label["V max"][1]["text"].endswith("mm/s")
    # the valve's dynamics (the others have none)
    dyn = ds[1]["dynamics"]
    assert [c["value"] and float(c["value"]) for c in by_label["Min contact force (N)"]] == \
        [None, dyn["contact_force_n"]["min"], None]
    assert float(by_label["Peak drive torque (N·m)"][1]["value"]) == max(abs(dyn["drive_torque_nm"]["max"]),
                                                                         abs(dyn["drive_torque_nm"]["min"]))
    assert float(by_label["Jump speed (rpm)"][1]["value"]) == dyn["jump_speed"]["value"]
    assert by_label["Jump speed (rpm)"][0]["text"] == "--"
    assert len(t.imgs) == 3


def test_duplicate_names_get_numbered(e9):
    assert design_labels([e9, e9, e9]) == ["Ejemplo9RT", "Ejemplo9RT (2)", "Ejemplo9RT (3)"]
    rows = comparison_rows([e9, e9])
    assert all(len(r["cells"]) == 2 for r in rows)
    with pytest.raises(ValueError):
        render_comparison([])


def test_compare_and_report_commands(tmp_path, capsys):
    out = tmp_path / "cmp"
    rc = main(["compare", str(EXAMPLES / "ejemplo9rt.toml"), "valve_exhaust_ej1", "-o", str(out)])
    assert rc == 0 and (out / "compare.html").is_file() and (out / "plots" / "svaj.svg").is_file()
    assert "Ejemplo9RT: not_for_high_speed" in capsys.readouterr().out
    rc = main(["report", "ejemplo9rt", "-o", str(tmp_path / "rep"), "--standalone"])
    assert rc == 0 and (tmp_path / "rep" / "report.html").is_file()
    assert b"data:image/svg+xml;base64," in (tmp_path / "rep" / "report.html").read_bytes()
