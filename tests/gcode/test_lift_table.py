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
    first = next(line for line in table.read_text().splitlines() if not line.startswith("#"))
    assert first.split(",")[:2] == ["angle_deg", f"lift_{unit}"]


def test_bad_lift_unit():
    with pytest.raises(SpecError):
        lift_table_csv([0.0], [0.0], lift_unit="inch")


def _read(path) -> tuple[dict[str, str], list[str], np.ndarray]:
    """Metadata (``# key: value`` lines), column names and rows, read as a shop's script would."""
    import csv

    lines = path.read_text(encoding="utf-8").splitlines()
    meta = dict(line[2:].split(": ", 1) for line in lines if line.startswith("# "))
    rows = list(csv.reader(line for line in lines if not line.startswith("#")))
    return meta, rows[0], np.array(rows[1:], dtype=float)


def test_metadata_header_and_radius_column(tmp_path):
    """The oscillating roller follower's table: metadata names roller, base radius, rotation, units and step; the
    lift is in degrees; read with the csv module after dropping the ``#`` lines."""
    from camfab.cli import main

    assert main(["run", "press_feed_oscillating", "-o", str(tmp_path), "--outputs", "lift_table"]) == 0
    (table,) = tmp_path.glob("*_lift.csv")
    meta, cols, data = _read(table)
    assert cols == ["angle_deg", "lift_deg", "radius_mm"] and data.shape == (360, 3)
    assert meta["design"] == "PressFeedLever" and meta["follower"] == "roller, oscillating"
    assert meta["roller radius"] == "11 mm" and meta["base radius"] == "55 mm" and meta["cam rotation"] == "ccw"
    assert meta["angle step"] == "1 deg" and "lift_deg in deg" in meta["units"] and "radius_mm" in meta
    # the contact point on the base circle at S = 0, and never inside it
    assert data[0, 1] == 0.0 and data[0, 2] == pytest.approx(55.0, abs=1e-6)
    assert data[:, 2].min() >= 55.0 - 1e-6


def test_radius_column_is_the_flat_face_contact_radius(tmp_path):
    """A radial flat-faced translating follower touches the cam where r² = (R_b + s)² + (ds/dθ)² (the contact
    point lies ds/dθ along the face from the follower axis): the radius column against that formula."""
    from camfab import pipeline
    from camfab.cli import main

    assert main(["run", "ejemplo10ex", "-o", str(tmp_path), "--outputs", "lift_table"]) == 0
    (table,) = tmp_path.glob("*_lift.csv")
    meta, cols, data = _read(table)
    cam = pipeline.load("ejemplo10ex")
    rb = cam.spec.follower.base_radius_mm
    t = np.radians(data[:, 0])
    prog = cam.spec.program()
    expected = np.hypot(rb + prog(t), prog(t, 1))
    assert cols == ["angle_deg", "lift_mm", "radius_mm"] and meta["follower"] == "flat-face, translating"
    assert np.allclose(data[:, 2], expected, rtol=0, atol=2e-6)  # 6 decimals written
    assert np.allclose(data[:, 1], prog(t), rtol=0, atol=1e-6)
