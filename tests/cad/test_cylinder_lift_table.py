"""A cylindrical cam's lift table (``<name>_lift.csv``), read back: the lift against the motion law in closed form,
the roller axis's z and the developed pitch point and flanks against the exact development on the pitch cylinder
(translating: x = R·θ, z = z₀ + S, the flanks at the roller section's contact point; oscillating: z = z₀ + L·sin φ);
the design name written as one line of plain text."""
from __future__ import annotations

import io
import math

import numpy as np
import pytest

from camfab.cli import main
from camfab.design.spec import design_from_dict
from camfab.pipeline import Cam, Output, Request, load, run
from tests.report.test_cylinder_outputs import EXAMPLE, Z0, exact

from ..conftest import CYLINDER_ARM_MM, oscillating_cylinder

HEAD = "angle_deg,lift_mm,z_mm,pitch_x_mm,plus_flank_x_mm,plus_flank_z_mm,minus_flank_x_mm,minus_flank_z_mm"


def _read(text: str) -> tuple[list[str], str, np.ndarray]:
    lines = text.splitlines()
    meta = [ln for ln in lines if ln.startswith("#")]
    head = lines[len(meta)]
    return meta, head, np.loadtxt(io.StringIO(text), delimiter=",", comments="#", skiprows=len(meta) + 1)


def test_translating_lift_table_is_the_exact_development(tmp_path):
    res = run(load(EXAMPLE), tmp_path, Request(frozenset({Output.LIFT_TABLE})))
    assert "lift_table" not in res.not_applicable
    meta, head, rows = _read((tmp_path / "BarrelCam_lift.csv").read_text(encoding="utf-8"))
    assert head == HEAD and "# design: BarrelCam" in meta and "# pitch radius: 40 mm" in meta
    assert rows.shape == (360, 8)
    np.testing.assert_array_equal(rows[:, 0], np.arange(360.0))
    ex = exact(np.radians(rows[:, 0]), 40.0)
    np.testing.assert_allclose(rows[:, 1], ex["S"], atol=6e-7)  # 6 decimals
    np.testing.assert_allclose(rows[:, 2], Z0 + ex["S"], atol=6e-7)
    np.testing.assert_allclose(rows[:, 2:4][:, ::-1], ex["pitch"], atol=6e-7)
    np.testing.assert_allclose(rows[:, 4:6], ex["plus"], atol=6e-7)
    np.testing.assert_allclose(rows[:, 6:8], ex["minus"], atol=6e-7)


@pytest.mark.parametrize("rotation", ["cw", "ccw"])
def test_oscillating_lift_table_follows_the_arm(tmp_path, rotation):
    """Lift in degrees of arm angle (poly345 30° over 180°), z = z₀ + L·sin φ, every 2° (forced: the 30° swing
    exceeds the pressure-angle limit); the flanks either side
    of the pitch point by at least R_r along the developed plane."""
    cam = Cam(design_from_dict(oscillating_cylinder(rotation)))
    run(cam, tmp_path, Request(frozenset({Output.LIFT_TABLE}), lift_step_deg=2.0, force=True))
    meta, head, rows = _read((tmp_path / "b_lift.csv").read_text(encoding="utf-8"))
    assert head == HEAD.replace("lift_mm", "lift_deg") and rows.shape == (180, 8)
    theta = np.radians(rows[:, 0])
    t = np.where(theta <= math.pi, theta, 2 * math.pi - theta) / math.pi
    phi = 30.0 * (10 * t**3 - 15 * t**4 + 6 * t**5)
    np.testing.assert_allclose(rows[:, 1], phi, atol=6e-7)
    z0 = cam.geometry.mechanism.z0_for(cam.geometry.program)
    np.testing.assert_allclose(rows[:, 2], z0 + CYLINDER_ARM_MM * np.sin(np.radians(phi)), atol=6e-7)
    gap = np.hypot(rows[:, 4] - rows[:, 3], rows[:, 5] - rows[:, 2]), np.hypot(rows[:, 6] - rows[:, 3],
                                                                                rows[:, 7] - rows[:, 2])
    for g in gap:
        assert np.all(g >= 6.0 - 1e-6)
    assert np.all(rows[:, 5] > rows[:, 2]) and np.all(rows[:, 7] < rows[:, 2])


def test_hostile_name_is_one_plain_line(tmp_path):
    data = oscillating_cylinder()
    data["name"] = 'x\r\n=HYPERLINK("http://e")\x1b[2J'
    cam = Cam(design_from_dict(data))
    res = run(cam, tmp_path, Request(frozenset({Output.LIFT_TABLE}), lift_step_deg=10.0, force=True))
    (path,) = [p for k, p in res.files.items() if k.endswith("_lift.csv")]
    text = path.read_text(encoding="utf-8")
    meta, head, rows = _read(text)
    design = [ln for ln in meta if ln.startswith("# design:")]
    assert len(design) == 1 and "\x1b" not in text and "\r" not in text and rows.shape == (36, 8)


@pytest.mark.slow
def test_gcode_writes_the_cylinder_lift_table(tmp_path):
    """``camfab gcode --lift-table`` of a cylindrical cam writes the same table as ``run`` (not the plate's radii
    of its six developed contacts)."""
    csv = tmp_path / "b.csv"
    assert main(["gcode", str(EXAMPLE), "-o", str(tmp_path / "b.nc"), "--lift-table", str(csv)]) in (0, 1)
    assert main(["run", str(EXAMPLE), "-o", str(tmp_path / "run"), "--outputs", "lift_table"]) in (0, 1)
    assert csv.read_bytes() == (tmp_path / "run" / "BarrelCam_lift.csv").read_bytes()


def test_rib_lift_table_gives_the_rib_flanks(tmp_path):
    """A rib (width 10 mm): z is its mid-line, the flanks 5 mm either side where it runs round (the dwells)."""
    import tomllib

    data = tomllib.loads(EXAMPLE.read_text(encoding="utf-8"))
    data["cylinder"].pop("groove_depth_mm")
    data["cylinder"].update(feature="rib", rib_width_mm=10.0, rib_height_mm=10.0)
    run(Cam(design_from_dict(data)), tmp_path, Request(frozenset({Output.LIFT_TABLE}), force=True))
    meta, head, rows = _read((tmp_path / "BarrelCam_lift.csv").read_text(encoding="utf-8"))
    assert head == HEAD and any("rib's mid-line" in ln for ln in meta)
    np.testing.assert_allclose(rows[:, 2], Z0 + exact(np.radians(rows[:, 0]), 40.0)["S"], atol=6e-7)
    dwell = (rows[:, 0] >= 141) & (rows[:, 0] <= 179)
    np.testing.assert_allclose(rows[dwell, 5] - rows[dwell, 2], 5.0, atol=1e-6)
    np.testing.assert_allclose(rows[dwell, 2] - rows[dwell, 7], 5.0, atol=1e-6)
