"""The [drawing] design table: defaults, validation, and what the drawing sheet shows from it."""
from __future__ import annotations

import datetime
import io
import tomllib

import pytest

from camfab.cad.drawing import drawing_sheet
from camfab.cad.export import cam_shapes
from camfab.design.assemble import check_design, geometry_from_spec
from camfab.design.drawing import DrawingSpec, keyway_depth_tolerance
from camfab.design.spec import design_from_dict
from camfab.errors import SpecError
from tests.conftest import base_design

ezdxf = pytest.importorskip("ezdxf")


def _spec(drawing=None, **mfg):
    d = base_design(manufacturing={"thickness_mm": 10.0, "bore_mm": 12.0, "keyway": True, **mfg})
    if drawing is not None:
        d["drawing"] = drawing
    return design_from_dict(d)


def test_defaults():
    d = _spec().drawing
    assert d == DrawingSpec()
    assert (d.bore_fit, d.keyway_width_fit, d.general_tolerance, d.surface_finish_ra_um) == ("H7", "JS9", "m", 1.6)
    assert d.profile_tolerance_mm == 0.02 and d.date == "" and d.number == ""


@pytest.mark.parametrize(("key", "value", "rule"), [
    ("bore_fit", "h7", "not a valid option"),  # a shaft class, not a hole
    ("bore_fit", "H19", "not a valid option"),
    ("bore_fit", "Q7", "not a valid option"),
    ("keyway_width_fit", "N9", "not a valid option"),  # the shaft keyway's fit, not the hub's
    ("general_tolerance", "x", "not a valid option"),
    ("general_tolerance", "mQ", "not a valid option"),
    ("date", "25.11.2026", "ISO 8601"),
    ("date", "2026-02-30", "not a calendar date"),
    ("number", 42, "must be a string"),
    ("surface_finish_ra_um", 0.0, "must be in"),
    ("profile_tolerance_mm", 0.0005, "finer than the CAD approximation tolerance"),
    ("drawn", "x", "unknown key"),
])
def test_bad_values_name_the_field(key, value, rule):
    with pytest.raises(SpecError) as e:
        _spec({key: value})
    text = str(e.value)
    assert f"drawing.{key}" in text and rule in text


@pytest.mark.parametrize("fit", ["H7", "H8", "JS7", "K6", "ZC11", "G6"])
def test_iso_hole_fits_pass(fit):
    assert _spec({"bore_fit": fit, "general_tolerance": "fH"}).drawing.bore_fit == fit


def test_toml_date_and_iso_string():
    data = tomllib.loads('[drawing]\ndate = 2026-11-25\n')
    assert _spec(data["drawing"]).drawing.date == "2026-11-25"
    assert isinstance(data["drawing"]["date"], datetime.date)
    assert _spec({"date": "2026-01-02"}).drawing.date == "2026-01-02"


def test_din_6885_depth_tolerance():
    assert [keyway_depth_tolerance(d) for d in (12, 22, 22.5, 130, 131)] == [0.1, 0.1, 0.2, 0.2, 0.3]


def _sheet(spec):
    geom = geometry_from_spec(spec)
    return ezdxf.read(io.StringIO(drawing_sheet(spec, geom, check_design(spec), cam_shapes(geom, tol=1e-3))))


def test_the_sheet_shows_the_table():
    spec = _spec({"number": "CF-0042", "revision": "B", "date": "2026-11-25", "drawn_by": "A. Ruiz",
                  "checked_by": "M. Vidal", "material": "16MnCr5", "bore_fit": "H8", "keyway_width_fit": "P9",
                  "general_tolerance": "fH", "surface_finish_ra_um": 0.8, "profile_tolerance_mm": 0.05,
                  "organisation": "Taller Sur", "part_number": "P-7"}, material="C45")
    doc = _sheet(spec)
    title = [e.dxf.text for e in doc.modelspace().query("TEXT[layer=='TITLE_BLOCK']")]
    for v in ("CF-0042", "B", "2026-11-25", "A. Ruiz", "M. Vidal", "16MnCr5", "ISO 2768-fH", "Taller Sur", "P-7"):
        assert v in title
    dims = {d.dxf.text for d in doc.modelspace().query("DIMENSION")}
    assert {"%%c12 H8", "4 P9"} <= dims
    # the depth with its DIN 6885 tolerance, or (no room for that text in the hub) the bare value and the note
    assert dims & {"13.8 +0.1/0", "13.8"}
    (notes,) = doc.modelspace().query("MTEXT[layer=='NOTES']")
    text = " ".join(line.strip() for line in notes.plain_text().splitlines())
    assert "width 4 P9, d + t2 = 13.8 +0.1/0 mm" in text
    assert "ISO 2768-fH" in text and "Ra 0.8 µm" in text and "±0.05 mm of the true profile" in text
    assert "Material: 16MnCr5" in text  # [drawing] material before [manufacturing] material


def test_hostile_text_stays_text():
    spec = _spec({"number": "%%c\\P{x}^J", "drawn_by": "\\U+0041"})
    doc = _sheet(spec)
    title = [e.dxf.text for e in doc.modelspace().query("TEXT[layer=='TITLE_BLOCK']")]
    assert "%%%%%%c\\P{x}^ J" in title and "\\U+005CU+0041" in title
