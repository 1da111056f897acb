"""Polar lift table CSV for cam grinders."""
from __future__ import annotations

import numpy as np
import pytest

from camfab.errors import SpecError
from camfab.gcode import lift_angles, lift_table_csv, write_lift_table


def test_format_and_rounding():
    text = lift_table_csv([0, 0.5, 359.5], [0.0, -1e-9, 10.1234567])
    assert text == "angle_deg,lift_mm\n0.000000,0.000000\n0.500000,0.000000\n359.500000,10.123457\n"


def test_callable_lift_and_angles():
    a = lift_angles(0.5)
    assert len(a) == 720 and a[0] == 0 and a[-1] == 359.5
    text = lift_table_csv(a, lambda deg: 5 * (1 - np.cos(np.radians(deg))))
    rows = text.splitlines()
    assert rows[0] == "angle_deg,lift_mm" and len(rows) == 721
    assert rows[361] == "180.000000,10.000000"
    for r in rows[1:]:
        x, y = r.split(",")
        assert len(x.split(".")[1]) == 6 and len(y.split(".")[1]) == 6


def test_deterministic_atomic_write(tmp_path):
    a = lift_angles(1.0)
    p1 = write_lift_table(tmp_path / "a.csv", a, np.sin(np.radians(a)))
    p2 = write_lift_table(tmp_path / "b.csv", a, np.sin(np.radians(a)))
    assert p1.read_bytes() == p2.read_bytes()


@pytest.mark.parametrize("angles,lift,path", [([], [], "angles_deg"), ([0, 1], [0], "lift_mm"),
                                              ([0, float("nan")], [0, 0], "angles_deg")])
def test_bad_input(angles, lift, path):
    with pytest.raises(SpecError) as info:
        lift_table_csv(angles, lift)
    assert path in {p.path for p in info.value.problems}


def test_step_must_divide_360():
    with pytest.raises(SpecError):
        lift_angles(0.7)
    with pytest.raises(SpecError):
        lift_angles(0)


@pytest.mark.parametrize("example,unit", [("ejemplo11ro", "deg"), ("ejemplo9rt", "mm")])
def test_header_names_the_lift_unit(tmp_path, example, unit):
    """Regression (core issue): an oscillating follower's lift table is in degrees of arm angle and
    its header says so; it was written as ``lift_mm``."""
    from camfab.cli import main

    assert main(["run", example, "-o", str(tmp_path), "--outputs", "lift_table"]) == 0
    (table,) = tmp_path.glob("*_lift.csv")
    assert table.read_text().splitlines()[0] == f"angle_deg,lift_{unit}"


def test_bad_lift_unit():
    with pytest.raises(SpecError):
        lift_table_csv([0.0], [0.0], lift_unit="inch")
