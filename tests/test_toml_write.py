"""The TOML design writer: every example round-trips (dict and validated design), hostile text stays text."""
from __future__ import annotations

import tomllib

import pytest

from camfab import pipeline
from camfab.formats.toml_design import design_from_data
from camfab.formats.toml_write import design_data, dumps_design, toml_string


@pytest.mark.parametrize("name", pipeline.examples())
def test_examples_round_trip(name):
    """load(write(load(x))) == load(x): the dict, and the validated design built from it."""
    data, spec = design_data(name)
    again = tomllib.loads(dumps_design(data, header=f"copy of {name}"))
    assert again == data
    assert design_from_data(again) == design_from_data(data)
    if spec.motion_table is not None and "file" in spec.motion_table:  # the knot file's rows, inline
        assert [list(r) for r in spec.motion_table["file"].rows] == again["motion_table"]["rows"]


HOSTILE = ['a"b', "back\\slash", "new\nline [cam]\nkind = \"x\"", "tab\tand\x00nul\x7f\x1b[31m", "''' \"\"\"",
           "\u2028sep\u2029", "ünïcødé ✓", "# not a comment", "]]]", ""]


@pytest.mark.parametrize("text", HOSTILE)
def test_user_text_is_escaped(text):
    """A design name, a [drawing] field, a key: read back exactly, and no new key or table appears."""
    data = {"name": text, "drawing": {"title": text, text or "empty": 1.5}, "cam": {"kind": "disc"}}
    out = dumps_design(data, header=text)
    back = tomllib.loads(out)
    assert back == data
    assert set(back) == {"name", "drawing", "cam"}
    assert tomllib.loads(f"x = {toml_string(text)}")["x"] == text


def test_numbers_and_lone_surrogate():
    data = {"v": [0.1, 1e-300, -0.0, 1e300, 3, True], "inf": float("inf"), "s": "\ud800"}
    back = tomllib.loads(dumps_design(data))
    assert back["v"] == data["v"] and back["inf"] == float("inf") and back["s"] == "\ufffd"
