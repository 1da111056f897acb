"""The 4-axis program of a ribbed cylindrical cam (camfab.gcode.rib_program) and its ``camfab verify``
(camfab.gcode.rib_verify): LinuxCNC's ``rs274`` runs it (the dwell's finishing passes exactly r_c beyond the rib
flanks, nothing below the root, the root cleared from end to end); verify passes it for both rotary posts and
fails it mutated (a shifted A word, a flank pass moved into the rib, a missing block, a wrong depth, one roughing
ring deleted: the uncut band's area measured on the (θ, z) grid); a cutter too large is refused naming the field
and the diameters that fit."""
from __future__ import annotations

import dataclasses
import json
import math
import re
import shutil
import subprocess

import numpy as np
import pytest

from camfab import pipeline
from camfab.cli import main
from camfab.errors import SpecError
from camfab.gcode.model import design_job
from camfab.gcode.rib_program import check_rib_tool, rib_gcode
from camfab.gcode.rib_verify import verify_rib_program
from camfab.gcode.rotary import cylinder_job
from camfab.offset.cutter import concave_limit
from tests.design.test_cylinder_rib import RIB_TOML as RIB_6MM

RS274 = shutil.which("rs274")
#: the rib of tests/design/test_cylinder_rib.py: pitch radius 40, height 10 (root 35, top 45), width 8, rollers
#: of radius 6 with 0.1 backlash (w = 6.05 each side), a cycloidal rise of 20 mm over 140°, a dwell of 40° (the
#: rib's mid-line at z = 50, its flanks at 46 and 54), a cycloidal return over 180°; travel centred on 80 mm
TOOL_D = 12.1
RIB_TOML = RIB_6MM.replace("tool_diameter_mm = 6.0", f"tool_diameter_mm = {TOOL_D}")


@pytest.fixture(scope="module")
def design(tmp_path_factory):
    src = tmp_path_factory.mktemp("rib") / "rib.toml"
    src.write_text(RIB_TOML, encoding="utf-8")
    return src


@pytest.fixture(scope="module")
def setup(design):
    cam = pipeline.load(str(design))
    tol = cam.tolerance()
    job = cylinder_job(design_job(cam.spec, tol=tol), cam.geometry)
    data, _, _ = rib_gcode(cam.geometry, job, tol, "linuxcnc")
    return cam.geometry, job, tol, data.decode()


def _verify(setup, text, job=None):
    geometry, job0, tol, _ = setup
    return verify_rib_program(text, geometry, job or job0, tol=tol)


@pytest.mark.skipif(RS274 is None, reason="LinuxCNC's rs274 interpreter is not installed (linuxcnc-uspace)")
@pytest.mark.parametrize("post", ["linuxcnc", "fanuc"])
def test_rs274_runs_the_rib_program(setup, tmp_path, post):
    """rs274 runs it to the end; no feed below the root radius; in the dwell (cam angles 142° to 178°, A = −θ for
    a cw cam) the finishing passes run exactly r_c beyond the flanks (z = 54 + 6.05 and 46 − 6.05); the feeds on
    the root reach past both ends of the cylinder."""
    geometry, job, tol, text = setup
    if post != "linuxcnc":
        text = rib_gcode(geometry, job, tol, post)[0].decode()
    (tmp_path / "p.ngc").write_text(text)
    proc = subprocess.run([str(RS274), "-g", str(tmp_path / "p.ngc")], capture_output=True, text=True, timeout=300,
                          stdin=subprocess.DEVNULL)
    assert proc.returncode == 0, proc.stdout[-600:]
    assert "PROGRAM_END" in proc.stdout
    feeds = np.array([[float(v) for v in m.group(1).split(",")[:4]] for m in
                      re.finditer(r"STRAIGHT_FEED\(([^)]*)\)", proc.stdout)])
    X, Y, Z, A = feeds.T
    assert np.allclose(Y, 0.0) and Z.min() == pytest.approx(35.0, abs=1e-9)
    root = Z < 35.0 + 1e-9
    assert X[root].min() - TOOL_D / 2 < 0.0 and X[root].max() + TOOL_D / 2 > 80.0
    up = text.upper()
    n_fin = len(re.findall(r"^(N\d+ )?G1 ", up[up.index("(FINISHING PASS +Z"):], re.MULTILINE))  # the last feeds
    theta = np.mod(-A[-n_fin:], 360.0)
    dwell = (theta > 142.0) & (theta < 178.0)
    assert np.sum(dwell) >= 4 and np.all(Z[-n_fin:] == 35.0)
    np.testing.assert_allclose(np.abs(X[-n_fin:][dwell] - 50.0), 4.0 + TOOL_D / 2, atol=tol)


@pytest.mark.slow
@pytest.mark.parametrize("post", ["linuxcnc", "fanuc"])
def test_verify_passes_the_written_program(design, tmp_path, capsys, post):
    prog = tmp_path / "rib.ngc"
    assert main(["gcode", str(design), "-o", str(prog), "--post", post]) in (0, 1)
    capsys.readouterr()
    assert main(["verify", str(prog), "--design", str(design), "--json"]) == 0
    rep = json.loads(capsys.readouterr().out)
    assert rep["ok"] and not rep["problems"] and not rep["gouge"]
    r = rep["rotary"]
    assert r["feature"] == "rib" and r["finishing_passes"] == 2 and r["roughing_levels"] == [42.5, 40.0, 37.5, 35.0]
    assert r["max_penetration_mm"] <= rep["tolerance_mm"] and r["deepest_tip_radius_mm"] == 35.0
    assert r["coverage"]["uncovered_points"] == 0 and r["coverage"]["grid_points"] > 100_000


def _block(lines, label):
    """Indices of the lines of the pass whose comment opens with ``label`` (to the next comment)."""
    i = next(k for k, ln in enumerate(lines) if ln.startswith(f"({label}"))
    j = next(k for k in range(i + 1, len(lines)) if lines[k].startswith("(") or lines[k].startswith("M9"))
    return i, j


@pytest.mark.slow
def test_mutated_programs_fail(setup):
    lines = setup[3].splitlines()
    i, j = _block(lines, "finishing pass +z")
    k = next(n for n in range(i + 40, j) if re.match(r"G1 X\S+ A-\S+ F", lines[n]))  # a block well into the pass
    shifted = lines.copy()
    a = float(re.search(r"A(-?[0-9.]+)", lines[k]).group(1))
    shifted[k] = re.sub(r"A-?[0-9.]+", f"A{a + 0.5:.4f}", lines[k])
    rep = _verify(setup, "\n".join(shifted))
    assert not rep.ok and "DEVIATION" in rep.codes() and any(p.line == k + 1 for p in rep.problems)

    def into_rib(m):  # the +z flank's pass 0.05 mm towards −z, into the rib
        return f"X{float(m.group(1)) - 0.05:.4f}"

    moved = lines[:i] + [re.sub(r"X([0-9.]+)", into_rib, ln) for ln in lines[i:j]] + lines[j:]
    rep = _verify(setup, "\n".join(moved))
    assert rep.gouge and "GOUGE" in rep.codes() and rep.gouge_at["penetration_mm"] > 0.03
    rep = _verify(setup, "\n".join(lines[:k] + lines[k + 1:]))
    assert not rep.ok and {"DEVIATION", "FEED_OUT_OF_RANGE"} & rep.codes()
    deeper = lines.copy()
    plunge = next(n for n in range(i, j) if lines[n] == "G1 Z35.0000 F" + lines[n].split(" F")[-1])
    deeper[plunge] = deeper[plunge].replace("Z35.0000", "Z34.9000")
    assert {"TOO_DEEP", "FINISH_DEPTH"} <= _verify(setup, "\n".join(deeper)).codes()


@pytest.mark.slow
def test_coverage_catches_a_deleted_roughing_ring(setup):
    """With a stepover of 0.75 D, deleting the last ring of the +z side on the root leaves uncut a part of the band
    from the ring before it (its X plus r_c) to the cylinder's end, the part the last following pass (which swings
    with the rib) does not reach: its area, measured on the (θ, z) grid, is positive, well above one grid row and
    below that band's width times 2π·r_b."""
    geometry, job, tol, _ = setup
    job = dataclasses.replace(job, roughing_stepover_mm=0.75 * TOOL_D)
    lines = rib_gcode(geometry, job, tol, "linuxcnc")[0].decode().splitlines()
    assert _verify(setup, "\n".join(lines), job).ok
    rings = [ln for ln in lines if ln.startswith("(roughing pass level 4") and "+z" in ln and "ring" in ln]
    assert len(rings) >= 2
    i, j = _block(lines, rings[-1].strip("(").split("[")[0])
    rep = _verify(setup, "\n".join(lines[:i] + lines[j:]), job)
    assert rep.codes() == {"COVERAGE"}
    before = float(re.search(r"ring X([0-9.]+)", rings[-2]).group(1))
    want = (80.0 - before - TOOL_D / 2) * 2 * math.pi * 35.0
    assert 0.1 * want < rep.rotary["coverage"]["uncovered_area_mm2"] < want


@pytest.mark.slow
def test_a_too_large_cutter_leaves_material_verify_sees_it(setup, monkeypatch):
    """With the cutter check bypassed, a 14 mm end mill's finishing passes, tangent to the flanks on the root, fall
    short of them higher up (material left on the rib): verify finds it as ``DEVIATION`` above the root, not as a
    gouge."""
    from camfab.gcode import rib_program

    geometry, job, tol, _ = setup
    big = dataclasses.replace(job, tool_diameter_mm=14.0)
    monkeypatch.setattr(rib_program, "check_rib_tool", lambda *a, **k: 0.0)
    rep = _verify(setup, rib_gcode(geometry, big, tol, "linuxcnc")[0], big)
    assert rep.codes() == {"DEVIATION"} and not rep.gouge
    assert all("above the root" in p.message for p in rep.problems) and rep.max_deviation_mm > 0.03


@pytest.mark.slow
def test_a_thin_allowance_roughs_within_the_tolerance(setup):
    """With a roughing allowance of 1 µm the first following pass runs along the finishing path: its chords, sampled
    on the level's radius, sag more on the cylinders above it (by r/ρ, up to the rib's top), so each level's chord
    tolerance is scaled by ρ/r_top and the roughing cuts past no flank by more than the tolerance (verify's exact
    cutter sections on six radii; 9.1 µm of 10 before the scaling, 7.6 µm with it)."""
    geometry, job, tol, _ = setup
    thin = dataclasses.replace(job, roughing_allowance_mm=0.001)
    rep = _verify(setup, rib_gcode(geometry, thin, tol, "linuxcnc")[0].decode(), thin)
    assert rep.ok and not rep.gouge
    assert rep.rotary["max_penetration_mm"] <= 0.8 * tol


def test_a_cutter_too_large_is_refused_naming_the_field(design, tmp_path, capsys):
    """A 14 mm end mill, radial and tangent to a flank on the root, cuts past the flank higher up (the rib's
    twist): exit 2 naming manufacturing.tool_diameter_mm and the diameters that fit; both ends of that range
    pass the check, and the rollers' 12.1 mm lies in it."""
    src = tmp_path / "big.toml"
    src.write_text(RIB_TOML.replace(f"tool_diameter_mm = {TOOL_D}", "tool_diameter_mm = 14.0"), encoding="utf-8")
    assert main(["gcode", str(src), "-o", str(tmp_path / "p.ngc")]) == 2
    err = capsys.readouterr().err
    assert "manufacturing.tool_diameter_mm" in err and not (tmp_path / "p.ngc").exists()
    small, large = (float(v) for v in re.search(r"from ([0-9.]+) mm .* to ([0-9.]+) mm", err).groups())
    assert small < TOOL_D < large < 14.0
    geometry = pipeline.load(str(design)).geometry
    for d in (small, large):
        assert check_rib_tool(geometry, d / 2, 0.01) <= 0.005
    # a cutter larger than the flanks' tightest concave stretch (seen from the rollers' side) is refused first
    tight = min(concave_limit(c)[0] for c in geometry.profiles)
    with pytest.raises(SpecError) as exc:
        check_rib_tool(geometry, tight * 1.01, 0.01)
    assert exc.value.problems[0].path == "manufacturing.tool_diameter_mm" and "gouge a rib flank" in str(exc.value)


def test_the_grooves_functions_refuse_a_rib(setup):
    """The caller chooses by [cylinder] feature; the groove's program and verify given a rib say so (an ApiError
    naming the rib's function) instead of taking its flanks for a groove's walls."""
    from camfab.errors import ApiError
    from camfab.gcode.rotary import rotary_gcode
    from camfab.gcode.rotary_verify import verify_rotary_program

    geometry, job, tol, text = setup
    with pytest.raises(ApiError, match="rib_gcode"):
        rotary_gcode(geometry, job, tol, "linuxcnc")
    with pytest.raises(ApiError, match="verify_rib_program"):
        verify_rotary_program(text, geometry, job, tol=tol)
