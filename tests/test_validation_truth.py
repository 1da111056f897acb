"""Reported defects: each test fails before its fix and passes after."""
from __future__ import annotations

import pytest

from camfab.design.program import MotionProgram
from camfab.errors import SpecError
from camfab.formats import load_design
from tests.conftest import EXAMPLES


def _with_dwell_lift(tmp_path, lift: float):
    text = (EXAMPLES / "ejemplo9rt.toml").read_text()
    old = 'law = "dwell"\nlift = 0.0'
    i = text.index(old, text.index(old) + 1)  # the second dwell: motion[3]
    d = tmp_path / "dwell_lift.toml"
    d.write_text(text[:i] + f'law = "dwell"\nlift = {lift}' + text[i + len(old):])
    return d


def test_dwell_with_lift_refused_in_design_file(tmp_path):
    with pytest.raises(SpecError) as e:
        load_design(_with_dwell_lift(tmp_path, 5.0)).program()
    (p,) = [p for p in e.value.problems if p.path == "motion[3].lift"]
    assert p.value == 5.0 and p.rule == "a dwell does not move the follower"
    assert p.fix == "set lift = 0, or use a rise/return law for the motion"


def test_dwell_with_lift_refused_by_the_api():
    with pytest.raises(SpecError) as e:
        MotionProgram.from_segments([("simple_harmonic", 10, 90), ("dwell", 5, 90),
                                     ("simple_harmonic", -10, 90), ("dwell", 0, 90)])
    assert [p.path for p in e.value.problems] == ["motion[1].lift"]
    assert "a dwell does not move the follower" in str(e.value)


def test_dwell_with_zero_lift_still_accepted():
    MotionProgram.from_segments([("simple_harmonic", 10, 90), ("dwell", 0, 90),
                                 ("simple_harmonic", -10, 90), ("dwell", 0, 90)])
