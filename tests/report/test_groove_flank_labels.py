"""A groove cam's two contact forces belong to one roller's two flanks: the report, its figures and the workbook
label them "inner flank" / "outer flank" (a conjugate or constant-width cam keeps "follower 1" / "follower 2":
tests/report/test_dynamics_report.py::test_form_closed_figure_xlsx_and_html). Read back from the files `camfab run`
writes (the xlsx with openpyxl, the HTML's text)."""
from __future__ import annotations

import html
import re

import pytest

from camfab.cli import main

from ..conftest import EXAMPLES

openpyxl = pytest.importorskip("openpyxl")
pytest.importorskip("jinja2", reason="HTML reports need jinja2")
pytest.importorskip("matplotlib", reason="report plots need matplotlib")

#: the groove example with a force model and a contact-stress check (inertia alone: the load changes flanks)
EXTRA = """
[dynamics]
mass_kg = 2.0

[strength]
roller_dynamic_rating_n = 9000.0
"""


@pytest.mark.slow
def test_groove_report_and_workbook_name_the_flanks(tmp_path):
    src = (EXAMPLES / "groove_translating.toml").read_text(encoding="utf-8")
    design = tmp_path / "groove.toml"
    design.write_text(src.replace("omega_rad_s = 1.0", "speed_rpm = 300.0") + EXTRA, encoding="utf-8")
    out = tmp_path / "out"
    assert main(["run", str(design), "-o", str(out), "--outputs", "xlsx,report"]) in (0, 1)
    wb = openpyxl.load_workbook(out / "GrooveTranslating.xlsx")
    head = [c.value for c in next(wb["Dynamics"].iter_rows(max_row=1))]
    assert head[1:3] == ["Contact force, inner flank (N)", "Contact force, outer flank (N)"]
    assert "Contact stress, inner flank (MPa)" in head and "Contact stress, outer flank (MPa)" in head
    labels = [r[0] for r in wb["Checks"].iter_rows(values_only=True) if isinstance(r[0], str)]
    assert "Maximum contact force, inner flank" in labels and "Maximum contact force, outer flank" in labels
    assert "Load passes to the other flank" in labels
    cells = [str(v) for ws in wb for row in ws.iter_rows(values_only=True) for v in row if v is not None]
    assert not [c for c in cells if "follower 1" in c or "follower 2" in c or "other follower" in c]
    page = html.unescape(re.sub(r"<[^>]+>", " ", (out / "report.html").read_text(encoding="utf-8")))
    for text in ("Contact force, inner flank (N)", "Contact force, outer flank (N)",
                 "Pushes where the inner flank cannot", "The load passes to the other flank",
                 "between the groove's flanks"):
        assert text in page, text
    assert "follower 1" not in page and "follower 2" not in page
    for figure in ("dynamics", "contact_stress"):  # the legends (the SVG keeps its text as text)
        svg = (out / "plots" / f"{figure}.svg").read_text(encoding="utf-8")
        assert "inner flank" in svg and "outer flank" in svg and "follower 1" not in svg, figure
