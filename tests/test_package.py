"""`camfab run` and `camfab package`: artifacts, manifest hashes, incremental rebuilds, failures, stage skipping."""
from __future__ import annotations

import hashlib
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from camfab.cli import main
from tests.conftest import EXAMPLES

FAST = "dxf,lift_table,xlsx"


def _sha(p: Path) -> str:
    return hashlib.sha256(p.read_bytes()).hexdigest()


def _manifest(out: Path) -> dict:
    return json.loads((out / "manifest.json").read_text())


def _check_manifest(out: Path, manifest: dict) -> None:
    for cam in manifest["cams"]:
        for f in cam["files"]:
            p = out / f["path"]
            assert p.is_file(), p
            assert _sha(p) == f["sha256"] and p.stat().st_size == f["bytes"]


@pytest.fixture
def designs(tmp_path):
    src = tmp_path / "designs"
    src.mkdir()
    for name in ("ejemplo9rt", "ejemplo1rt", "ejemplo10ex"):
        shutil.copy(EXAMPLES / f"{name}.toml", src)
    return src


def test_package_incremental(designs, tmp_path, capsys):
    out = tmp_path / "out"
    assert main(["package", str(designs), "-o", str(out), "--outputs", FAST]) == 0
    m1 = _manifest(out)
    assert len(m1["cams"]) == 3 and all(c["rebuilt"] for c in m1["cams"])
    _check_manifest(out, m1)
    index = (out / "index.html").read_text()
    assert all(c["name"] in index for c in m1["cams"])
    # second run: nothing rebuilt, same hashes
    assert main(["package", str(designs), "-o", str(out), "--outputs", FAST]) == 0
    m2 = _manifest(out)
    assert not any(c["rebuilt"] for c in m2["cams"])
    assert [c["files"] for c in m2["cams"]] == [c["files"] for c in m1["cams"]]
    # touch one design (a real change): only that cam is rebuilt
    f = designs / "ejemplo1rt.toml"
    f.write_text(f.read_text().replace("roller_radius_mm = 5.0", "roller_radius_mm = 6.0"))
    assert main(["package", str(designs), "-o", str(out), "--outputs", FAST]) == 0
    m3 = _manifest(out)
    assert {c["name"]: c["rebuilt"] for c in m3["cams"]} == {"Ejemplo1RT": True, "Ejemplo9RT": False,
                                                              "Ejemplo10EX": False}
    _check_manifest(out, m3)
    # a deleted artifact is rebuilt
    (out / m3["cams"][0]["files"][0]["path"]).unlink()
    assert main(["package", str(designs), "-o", str(out), "--outputs", FAST]) == 0
    assert _manifest(out)["cams"][0]["rebuilt"]
    # other options are another input: a different output set rebuilds everything
    assert main(["package", str(designs), "-o", str(out), "--outputs", "dxf"]) == 0
    assert all(c["rebuilt"] for c in _manifest(out)["cams"])


def test_package_with_a_broken_design(designs, tmp_path, capsys):
    (designs / "broken.toml").write_text('name = "Broken"\n[follower]\ntype = "roller"\nbase_radius_mm = -3\n')
    out = tmp_path / "out"
    assert main(["package", str(designs), "-o", str(out), "--outputs", "dxf", "--jobs", "2"]) == 2
    m = _manifest(out)
    status = {Path(c["source"]).name: c["status"] for c in m["cams"]}
    assert status.pop("broken.toml") == "error"
    assert set(status.values()) == {"ok"}
    broken = next(c for c in m["cams"] if c["source"].endswith("broken.toml"))
    assert "follower.base_radius_mm" in broken["error"]
    assert "follower.base_radius_mm" in (out / "index.html").read_text()
    assert "broken.toml" in capsys.readouterr().err


def test_parallel_equals_serial(designs, tmp_path):
    a, b = tmp_path / "a", tmp_path / "b"
    assert main(["package", str(designs), "-o", str(a), "--outputs", FAST, "--jobs", "1"]) == 0
    assert main(["package", str(designs), "-o", str(b), "--outputs", FAST, "--jobs", "2"]) == 0
    fa = [(f["path"], f["sha256"]) for c in _manifest(a)["cams"] for f in c["files"]]
    fb = [(f["path"], f["sha256"]) for c in _manifest(b)["cams"] for f in c["files"]]
    assert fa == fb


def test_run_unacceptable_withholds_shop_files(tmp_path, capsys):
    d = tmp_path / "bad.toml"
    d.write_text((EXAMPLES / "ejemplo9rt.toml").read_text().replace("base_radius_mm = 35.0", "base_radius_mm = 12.0"))
    out = tmp_path / "out"
    assert main(["run", str(d), "-o", str(out), "--outputs", "dxf,gcode,xlsx"]) == 1
    names = {p.name for p in out.iterdir()}
    assert names == {"check.json", "Ejemplo9RT.xlsx"}
    assert "withheld" in capsys.readouterr().out
    assert main(["run", str(d), "-o", str(out), "--outputs", "dxf", "--force"]) == 1
    assert (out / "Ejemplo9RT.dxf").exists()


def test_run_default_example_and_bad_outputs(tmp_path, capsys):
    assert main(["run", "-o", str(tmp_path / "o"), "--outputs", "dxf"]) == 0
    assert (tmp_path / "o" / "Ejemplo9RT.dxf").exists()
    assert main(["run", "-o", str(tmp_path / "p"), "--outputs", "dxf,svg"]) == 2
    assert "'svg' is not a valid option" in capsys.readouterr().err
    assert not (tmp_path / "p").exists()


def test_no_cadquery_or_offsets_without_step_and_gcode(tmp_path):
    code = ("import sys, camfab.offset.cutter as c\n"
            "calls = []\n"
            "orig = c.tool_centre_path\n"
            "c.tool_centre_path = lambda *a, **k: calls.append(1) or orig(*a, **k)\n"
            "from camfab.cli import main\n"
            f"rc = main(['run', 'ejemplo9rt', '-o', r'{tmp_path / 'o'}', '--outputs', 'dxf,stl,xlsx'])\n"
            "print(rc, 'cadquery' in sys.modules, 'OCP' in sys.modules, len(calls))\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                         env={**os.environ, "PYTHONPATH": str(Path(__file__).resolve().parents[1])})
    assert out.stdout.splitlines()[-1].split() == ["0", "False", "False", "0"]


@pytest.mark.slow
def test_package_examples_library(tmp_path):
    """Every example in the library runs through `camfab package` with its own [outputs]."""
    out = tmp_path / "lib"
    rc = main(["package", str(EXAMPLES), "-o", str(out), "--jobs", "2"])
    m = _manifest(out)
    assert rc == 0, [(c["name"], c.get("error")) for c in m["cams"] if c["status"] != "ok"]
    assert {c["status"] for c in m["cams"]} == {"ok"}
    _check_manifest(out, m)
    assert main(["package", str(EXAMPLES), "-o", str(out), "--jobs", "2"]) == 0
    assert not any(c["rebuilt"] for c in _manifest(out)["cams"])


def test_internal_error_on_one_design_does_not_lose_the_others(designs, tmp_path, monkeypatch):
    import camfab.package

    real = camfab.package.build_files

    def flaky(cam, *a, **k):
        if cam.name == "Ejemplo1RT":
            raise RuntimeError("simulated bug")
        return real(cam, *a, **k)

    monkeypatch.setattr(camfab.package, "build_files", flaky)
    out = tmp_path / "out"
    assert main(["package", str(designs), "-o", str(out), "--outputs", "dxf", "--jobs", "1"]) == 2
    cams = {c["name"]: c for c in _manifest(out)["cams"]}
    assert cams["Ejemplo1RT"]["status"] == "error" and "simulated bug" in cams["Ejemplo1RT"]["error"]
    assert cams["Ejemplo9RT"]["status"] == cams["Ejemplo10EX"]["status"] == "ok"


def test_input_key_hashes_the_knot_file_a_design_names(tmp_path):
    from camfab.formats import design_to_xlsx, load_design
    from camfab.package import input_key

    for name in ("valve_exhaust_ej1.toml", "valve_recon_ej1.csv"):
        shutil.copy(EXAMPLES / name, tmp_path)
    toml = tmp_path / "valve_exhaust_ej1.toml"
    spec = load_design(toml)
    assert spec.sources == (str(toml), str(tmp_path / "valve_recon_ej1.csv"))
    book = tmp_path / "valve.xlsx"  # an xlsx design that names the same knot file
    book.write_bytes(design_to_xlsx(spec))
    import openpyxl

    wb = openpyxl.load_workbook(book)
    del wb["knots"]
    wb["design"].append(["motion_table.file", "valve_recon_ej1.csv"])
    wb.save(book)
    keys = [input_key(load_design(p).sources, {}, "t") for p in (toml, book)]
    csv = tmp_path / "valve_recon_ej1.csv"
    csv.write_text(csv.read_text().replace("0.0005,0.4744", "0.00051,0.4744"))
    new = [input_key(load_design(p).sources, {}, "t") for p in (toml, book)]
    assert new[0] != keys[0] and new[1] != keys[1] and len(set(keys)) == 2


# ---------------------------------------------------------------------------
# a worker reads the files it was sent, also when the design names its knot file by an absolute path
@pytest.mark.parametrize("knot_dir, allow", [("d", False), ("elsewhere", True)])
def test_a_worker_reads_the_sent_copy_of_an_absolute_knot_file(knot_dir, allow):
    """The design and its knot file as the parent sent them, under a folder this machine does not have (a remote
    worker's view): an absolute knot-file name is read from the copy sent, judged inside or outside the design's
    folder as on the parent — a knot file in the design's folder named absolutely was refused as lying outside
    the worker's temporary folder (and a remote worker would have had no such file)."""
    import camfab.package

    design, csv = "/nonexistent-camfab/d/valve.toml", f"/nonexistent-camfab/{knot_dir}/valve_recon_ej1.csv"
    text = (EXAMPLES / "valve_exhaust_ej1.toml").read_text().replace('file = "valve_recon_ej1.csv"', f'file = "{csv}"')
    assert csv in text and not Path(csv).exists()
    job = camfab.package.Job(design, "V", "V", "k", {"outputs": ["xlsx"], "allow_outside_files": allow},
                             ((design, text.encode()), (csv, (EXAMPLES / "valve_recon_ej1.csv").read_bytes())))
    entry = camfab.package.build_cam(job)
    assert entry["status"] == "ok", entry.get("error")
    assert any(name.endswith(".xlsx") for name in entry["output"]["files"])


def test_a_worker_still_refuses_an_absolute_knot_file_outside_the_design_folder():
    """Without allow_outside_files, the sent copy of a knot file outside the design's folder is refused on the
    worker as on the parent, naming the field and the path the user wrote."""
    import camfab.package

    design, csv = "/nonexistent-camfab/d/valve.toml", "/nonexistent-camfab/other/valve_recon_ej1.csv"
    text = (EXAMPLES / "valve_exhaust_ej1.toml").read_text().replace('file = "valve_recon_ej1.csv"', f'file = "{csv}"')
    job = camfab.package.Job(design, "V", "V", "k", {"outputs": ["xlsx"]},
                             ((design, text.encode()), (csv, (EXAMPLES / "valve_recon_ej1.csv").read_bytes())))
    entry = camfab.package.build_cam(job)
    assert entry["status"] == "error" and "motion_table.file" in entry["error"] and csv in entry["error"]
    assert "outside the design's folder" in entry["error"] and "camfab-design-" not in entry["error"]
