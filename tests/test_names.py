"""Output file names from design names: :func:`camfab.io.safe_stem` and :func:`camfab.io.inside`
(docs/decisions.md, "Output file names from design names")."""
from __future__ import annotations

import json
import re
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from camfab.cli import main
from camfab.errors import ExportError
from camfab.io import inside, safe_stem
from tests.conftest import EXAMPLES

RULE = re.compile(r"^[A-Za-z0-9][A-Za-z0-9._-]{0,99}$")
RESERVED = {"CON", "PRN", "AUX", "NUL", *(f"COM{i}" for i in range(1, 10)), *(f"LPT{i}" for i in range(1, 10))}
FAST = "dxf,drawing,gcode,lift_table,xlsx"


@pytest.mark.parametrize(("name", "stem"), [
    ("../../x", "x"),
    ("/etc/x", "etc_x"),
    ("..", "cam"),
    (".", "cam"),
    ("", "cam"),
    ("   ", "cam"),
    ("a/b", "a_b"),
    ("..\\..\\x", "x"),
    ("a\x00b\x1bc\nd", "a_b_c_d"),
    (".hidden", "hidden"),
    ("-rf", "rf"),
    ("name.", "name"),
    ("Leva ñ", "Leva_n"),
    ("Excéntrica  1", "Excentrica_1"),
    ("ﬁle", "file"),  # NFKC: the ligature becomes two letters
    ("日本", "cam"),
    ("CON", "CON_"),
    ("con", "con_"),
    ("Lpt9", "Lpt9_"),
    ("nul.cam", "nul_.cam"),
    ("COM10", "COM10"),
    ("CONSOLE", "CONSOLE"),
    ("Cam-1_v2.3", "Cam-1_v2.3"),
])
def test_safe_stem_table(name, stem):
    assert safe_stem(name) == stem


def test_long_names_truncated_and_distinct():
    a, b = "x" * 299 + "a", "x" * 299 + "b"
    sa, sb = safe_stem(a), safe_stem(b)
    assert len(sa) == len(sb) == 100 and sa != sb
    assert sa.startswith("x" * 91 + "_") and RULE.match(sa)
    assert safe_stem("y" * 100) == "y" * 100  # exactly at the cap: unchanged


def _example_names() -> list[str]:
    names = []
    for p in sorted(EXAMPLES.glob("*.toml")):
        m = re.search(r'^name\s*=\s*"([^"]*)"', p.read_text(encoding="utf-8"), re.M)
        assert m, p
        names.append(m.group(1))
    return names


@pytest.mark.parametrize("name", _example_names())
def test_builtin_example_names_unchanged(name):
    """No output file name of a built-in example changes."""
    assert safe_stem(name) == name


@settings(max_examples=500, deadline=None)
@given(st.text())
def test_any_text_gives_a_safe_stem(name):
    stem = safe_stem(name)
    assert RULE.match(stem), stem
    assert stem.split(".")[0].upper() not in RESERVED
    assert safe_stem(stem) == stem  # idempotent


def test_inside(tmp_path):
    out = tmp_path / "out"
    assert inside(out, "a.dxf") == out / "a.dxf"
    assert inside(out, "plots/x.svg") == out / "plots" / "x.svg"
    for bad in ("../x", "../../x", "/etc/x", ".", "", "plots/../../x"):
        with pytest.raises(ExportError):
            inside(out, bad)
    out.mkdir()
    (out / "link").symlink_to(tmp_path)
    with pytest.raises(ExportError):
        inside(out, "link/x")


# --- the command line ------------------------------------------------------------------------------------
def _design(folder: Path, name: str, file: str = "d.toml") -> Path:
    text = (EXAMPLES / "ejemplo9rt.toml").read_text(encoding="utf-8")
    assert 'name = "Ejemplo9RT"' in text
    p = folder / file
    p.write_text(text.replace('name = "Ejemplo9RT"', f"name = {json.dumps(name)}"), encoding="utf-8")
    return p


def _everything(root: Path) -> set[Path]:
    return {p for p in root.rglob("*")}


def _assert_contained(tmp_path: Path, before: set[Path], out: Path) -> list[Path]:
    new = _everything(tmp_path) - before
    outside = sorted(p for p in new if not (p == out or out in p.parents) and p not in out.parents)
    assert not outside, outside
    files = sorted(p for p in new if p.is_file())
    assert files and all(out in p.parents for p in files)
    return files


EVIL = ["../../evil", "/tmp/abs_evil", "..", "a/b/c", "..\\..\\evil"]


@pytest.mark.parametrize("name", EVIL)
def test_run_writes_only_inside_out(tmp_path, name):
    src = tmp_path / "src"
    src.mkdir()
    d = _design(src, name)
    out = tmp_path / "a" / "b" / "out"
    before = _everything(tmp_path)
    assert main(["run", str(d), "-o", str(out), "--outputs", FAST]) == 0
    files = _assert_contained(tmp_path, before, out)
    stem = safe_stem(name)
    names = {p.relative_to(out).as_posix() for p in files}
    assert names == {"check.json", f"{stem}.dxf", f"{stem}_drawing.dxf", f"{stem}.nc", f"{stem}_lift.csv",
                     f"{stem}.xlsx"}
    assert not Path("/tmp/abs_evil.dxf").exists()


@pytest.mark.parametrize("name", EVIL)
def test_package_writes_only_inside_out(tmp_path, name):
    src = tmp_path / "src"
    src.mkdir()
    _design(src, name)
    out = tmp_path / "a" / "b" / "out"
    before = _everything(tmp_path)
    assert main(["package", str(src), "-o", str(out), "--outputs", FAST]) == 0
    files = _assert_contained(tmp_path, before, out)
    assert {p.relative_to(out).parts[0] for p in files} == {safe_stem(name), "manifest.json", "index.html"}
    manifest = json.loads((out / "manifest.json").read_text())
    assert manifest["cams"][0]["name"] == name  # the full name stays in the contents


def test_export_writes_only_inside_out(tmp_path):
    src = tmp_path / "src"
    src.mkdir()
    d = _design(src, "../../evil")
    out = tmp_path / "a" / "b" / "out"
    before = _everything(tmp_path)
    assert main(["export", str(d), "--dxf", "--stl", "--step", "-o", str(out)]) == 0
    files = _assert_contained(tmp_path, before, out)
    assert {p.name for p in files} == {"evil.dxf", "evil.stl", "evil.step"}


def test_long_name_writes_every_file(tmp_path):
    """A 230-character name writes every file of Ejemplo9RT's default run (it wrote 4 of 15 and exited 3):
    DXF, STEP, assembly STEP, STL, G-code, xlsx, drawing DXF and PDF, check.json, report page and its plots."""
    name = "Leva de escape " * 15 + "X" * 5
    assert len(name) == 230
    d = _design(tmp_path, name)
    ref, out = tmp_path / "ref", tmp_path / "out"
    assert main(["run", "ejemplo9rt", "-o", str(ref)]) == 0
    assert main(["run", str(d), "-o", str(out)]) == 0
    stem = safe_stem(name)
    assert len(stem) == 100
    want = sorted(p.relative_to(ref).as_posix().replace("Ejemplo9RT", stem) for p in ref.rglob("*") if p.is_file())
    got = sorted(p.relative_to(out).as_posix() for p in out.rglob("*") if p.is_file())
    assert got == want
    kinds = {Path(g).suffix for g in got}
    assert {".dxf", ".step", ".stl", ".nc", ".xlsx", ".pdf", ".html", ".svg", ".json"} <= kinds, kinds
    assert sum(g.endswith("_assembly.step") for g in got) == 1 and len(got) >= 14
    assert name.encode() in (out / f"{stem}.dxf").read_bytes()  # contents keep the full name
