"""The STEP header camfab writes: the design's name and [drawing] fields, escaped, and a reproducible stamp."""
from __future__ import annotations

from types import SimpleNamespace

import pytest

from camfab.cad.stepheader import StepMeta, design_meta, header_dumps, step_timestamp
from camfab.design.drawing import DrawingSpec
from camfab.errors import InputError

OCCT = ("ISO-10303-21;\nHEADER;\nFILE_DESCRIPTION(('Open CASCADE Model'),'2;1');\n"
        "FILE_NAME('Open CASCADE Shape Model','2026-11-25T22:51:59',('Author'),(\n    'Open CASCADE'),"
        "'Open CASCADE STEP processor 7.9','Open CASCADE 7.9'\n  ,'Unknown');\n"
        "FILE_SCHEMA(('AUTOMOTIVE_DESIGN { 1 0 10303 214 1 1 1 1 }'));\nENDSEC;\nDATA;\n#1 = X('Author');\nENDSEC;\n")


def test_header_from_the_design_and_its_drawing_table():
    spec = SimpleNamespace(name="Cam 'A' ä", drawing=DrawingSpec(author="Ann O'Hara", organisation="ACME",
                                                                 part_number="P-7"))
    text = header_dumps(OCCT, spec.name, design_meta(spec))
    head, _, data = text.partition("DATA;")
    assert "FILE_NAME('P-7','1970-01-01T00:00:00',('Ann O''Hara'),('ACME'),'camfab " in head
    assert "FILE_DESCRIPTION(('Cam ''A'' \\X2\\00E4\\X0\\ (camfab cam)'),'2;1');" in head
    assert "Author" not in head and "Open CASCADE Model" not in head
    assert data == "\n#1 = X('Author');\nENDSEC;\n"  # the data section is not touched
    plain = header_dumps(OCCT, "Ejemplo1RT", design_meta(SimpleNamespace(name="Ejemplo1RT", drawing=DrawingSpec())))
    assert "FILE_NAME('Ejemplo1RT','1970-01-01T00:00:00',(''),('camfab')," in plain


def test_timestamp_follows_source_date_epoch():
    assert step_timestamp(environ={}) == "1970-01-01T00:00:00"
    assert step_timestamp(environ={"SOURCE_DATE_EPOCH": "0"}) == "1970-01-01T00:00:00"
    assert step_timestamp(environ={"SOURCE_DATE_EPOCH": "86400"}) == "1970-01-02T00:00:00"
    assert step_timestamp("now", environ={}) != "1970-01-01T00:00:00"
    for bad in ("-1", "1e9", "soon", "999999999999999"):
        with pytest.raises(InputError, match="SOURCE_DATE_EPOCH"):
            step_timestamp(environ={"SOURCE_DATE_EPOCH": bad})
    assert StepMeta.of("x", timestamp=None).timestamp == step_timestamp()
