"""A cylindrical cam's workbook and report: the ``Cylinder`` sheet read back with openpyxl against the closed-form
development (cycloidal rise: x = r·θ, z = z₀ + S, the flanks at the exact roller section's contact point,
tan δ = S′/(r·k)), and the report's unrolled-profile plot against the exact developed curves."""
from __future__ import annotations

import io
import math
from pathlib import Path

import numpy as np
import pytest

from camfab.pipeline import Output, Request, load, run

openpyxl = pytest.importorskip("openpyxl")

EXAMPLE = Path(__file__).parents[2] / "camfab" / "examples" / "cylindrical_translating.toml"
H, BETA, RR, BACKLASH, Z0 = 20.0, math.radians(140.0), 6.0, 0.05, 20.0  # the example's rise, roller, groove


def exact(theta: np.ndarray, r: float) -> dict[str, np.ndarray]:
    """The example's developed pitch curve and flanks on radius r, from the cycloidal law in closed form."""
    s0 = np.zeros_like(theta)
    s1 = np.zeros_like(theta)
    up = theta <= BETA
    t = theta[up] / BETA
    s0[up] = H * (t - np.sin(2 * np.pi * t) / (2 * np.pi))
    s1[up] = H / BETA * (1 - np.cos(2 * np.pi * t))
    down = (theta >= BETA + math.radians(40)) & (theta <= 2 * BETA + math.radians(40))
    t = (theta[down] - BETA - math.radians(40)) / BETA
    s0[down] = H - H * (t - np.sin(2 * np.pi * t) / (2 * np.pi))
    s1[down] = -H / BETA * (1 - np.cos(2 * np.pi * t))
    s0[(theta > BETA) & ~down] = np.where(theta[(theta > BETA) & ~down] < math.pi, H, 0.0)
    pitch = np.stack([r * theta, Z0 + s0], axis=1)
    # the roller's section by the cylinder r: (r·asin(w·cos t/r), w·sin t) about the pitch point; it touches the
    # +z flank where r·k·cos t + S′·sin t = 0, k = √(1 − (w·cos t/r)²): (w/r)²C⁴ − (1 + p²)C² + p² = 0, C = cos t
    w, p = RR + BACKLASH / 2, s1 / r
    q = (w / r) ** 2
    c2 = ((1 + p * p) - np.sqrt((1 + p * p) ** 2 - 4 * p * p * q)) / (2 * q)
    ct, st = -np.sign(p) * np.sqrt(c2), np.sqrt(1 - c2)
    k = np.sqrt(1 - q * c2)
    off = np.stack([r * np.arcsin(w * ct / r), w * st], axis=1)
    return {"S": s0, "pitch": pitch, "plus": pitch + off, "minus": pitch - off, "delta": np.degrees(np.arctan(p / k))}


@pytest.fixture(scope="module")
def cam():
    return load(EXAMPLE)


def test_workbook_cylinder_sheet_is_the_exact_development(cam, tmp_path):
    res = run(cam, tmp_path, Request(frozenset({Output.XLSX})))
    assert "xlsx" not in res.not_applicable
    wb = openpyxl.load_workbook(io.BytesIO((tmp_path / "BarrelCam.xlsx").read_bytes()), data_only=True)
    assert wb.sheetnames == ["Cylinder", "Checks"]
    ws = wb["Cylinder"]
    assert ws["A2"].value == "BarrelCam" and ws["B4"].value == 40.0 and ws["B10"].value == Z0
    head = [c.value for c in ws[13]]
    rows = np.array([[np.nan if v is None else v for v in row] for row in ws.iter_rows(min_row=14, values_only=True)],
                    dtype=float)
    assert rows.shape == (361, 5 + 3 * 8)
    theta = np.radians(rows[:, 0])
    np.testing.assert_allclose(rows[:, 0], np.arange(361.0))
    np.testing.assert_allclose(rows[:, 1], exact(theta, 40.0)["S"], atol=1e-9)
    for k, r in enumerate((35.0, 40.0, 45.0)):
        c = 5 + 8 * k
        assert head[c] == f"r = {r:g} mm pitch x (mm)"
        ex = exact(theta, r)
        np.testing.assert_allclose(rows[:, c:c + 2], ex["pitch"], atol=1e-9)
        np.testing.assert_allclose(rows[:, c + 2:c + 4], ex["plus"], atol=1e-9)
        np.testing.assert_allclose(rows[:, c + 4:c + 6], ex["minus"], atol=1e-9)
        np.testing.assert_allclose(rows[:, c + 6], ex["delta"], atol=1e-9)
        # across the developed plane the flanks are the roller diameter plus the backlash apart where the groove
        # runs straight round (dwells), more on its slopes (the section is stretched along x)
        width = np.hypot(*(rows[:, c + 2:c + 4] - rows[:, c + 4:c + 6]).T)
        dwell = ex["delta"] == 0
        np.testing.assert_allclose(width[dwell], 2 * RR + BACKLASH, atol=1e-9)
        assert np.all(width >= 2 * RR + BACKLASH - 1e-9) and width.max() > 2 * RR + BACKLASH + 1e-4


def test_unrolled_plot_is_the_exact_development(cam):
    from camfab.report.cylinder_plot import unrolled_figure

    fig = unrolled_figure(cam.spec, cam.geometry)
    lines = {ln.get_label(): np.asarray(ln.get_xydata()) for ln in fig.axes[0].get_lines()}
    pitch = lines["pitch curve"]
    theta = pitch[:, 0] / 40.0
    assert theta.min() == 0.0 and theta.max() == pytest.approx(2 * math.pi) and len(theta) > 1000
    ex = exact(theta, 40.0)
    np.testing.assert_allclose(pitch, ex["pitch"], atol=1e-9)
    np.testing.assert_allclose(lines["+z flank"], ex["plus"], atol=1e-9)
    np.testing.assert_allclose(lines["-z flank"], ex["minus"], atol=1e-9)


def test_run_writes_the_report_with_the_unrolled_plot(cam, tmp_path):
    res = run(cam, tmp_path, Request(frozenset({Output.REPORT})))
    assert "report" not in res.not_applicable
    html = (tmp_path / "report.html").read_text(encoding="utf-8")
    for name in ("unrolled", "svaj", "pressure_angle"):
        assert f'src="plots/{name}.svg"' in html
        assert (tmp_path / "plots" / f"{name}.svg").read_bytes().startswith(b"<?xml")
    assert html.count('src="plots/unrolled.svg"') == 1 and "Unrolled groove" in html


def test_missing_cadquery_skips_the_cylinder_step(tmp_path, monkeypatch, capsys):
    """Without cadquery a run of the cylindrical example writes the rest (the grooved cylinder's STL too: meshed
    with numpy, :mod:`camfab.cad.cylinder_mesh`), names what it skipped, and exits 0."""
    import sys

    from camfab.cli import main

    monkeypatch.setitem(sys.modules, "cadquery", None)  # `import cadquery` raises ImportError
    assert main(["run", str(EXAMPLE), "-o", str(tmp_path), "--outputs", "dxf,step,stl,xlsx"]) == 0
    assert sorted(p.name for p in tmp_path.iterdir() if p.suffix != ".lock") == ["BarrelCam.dxf", "BarrelCam.stl",
                                                                                  "BarrelCam.xlsx", "check.json"]
    assert "skipped (cadquery is missing" in capsys.readouterr().out
