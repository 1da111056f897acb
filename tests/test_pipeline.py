"""The one pipeline: ``[machining]`` reaches the program, ``gcode``, ``run``, ``package`` and the API write the
same program for the same inputs, command-line flags override the design, a bad table is refused by field,
and a cam computes each stage once."""
from __future__ import annotations

import re

import pytest

import camfab
from camfab.cli import main
from camfab.formats import design_to_xlsx, load_design
from camfab.pipeline import EXPORTERS, Output, gcode_job
from tests.conftest import EXAMPLES

MACHINING = """
[machining]
spindle_rpm = 4500
feed_mm_min = 750
plunge_feed_mm_min = 150
step_down_mm = 2.5
roughing_passes = 2
roughing_allowance_mm = 0.3
coolant = "mist"
safe_z_mm = 30.0
breakthrough_mm = 0.0
"""


@pytest.fixture()
def design(tmp_path):
    """Ejemplo9RT with a 6 mm tool, a 10 mm plate and a [machining] table away from every default."""
    text = (EXAMPLES / "ejemplo9rt.toml").read_text(encoding="utf-8")
    text = re.sub(r"(?ms)^\[manufacturing\].*?(?=^\[|\Z)", "", text)
    text = re.sub(r"(?ms)^\[outputs\].*?(?=^\[|\Z)", "", text)
    text += "\n[manufacturing]\nthickness_mm = 10.0\nbore_mm = 12.0\ntool_diameter_mm = 6.0\n" + MACHINING
    path = tmp_path / "nine.toml"
    path.write_text(text, encoding="utf-8")
    return path


def _words(program: str, letter: str) -> set[float]:
    """Every value of the word ``letter`` (F, S, Z …) in the program's code (comments left out)."""
    code = re.sub(r"\([^)]*\)", "", program)
    return {float(v) for v in re.findall(rf"\b{letter}(-?\d+(?:\.\d+)?)", code)}


def test_machining_table_reaches_the_job_and_the_program(design, tmp_path):
    spec = load_design(design)
    job = gcode_job(spec, tol=1e-3)
    assert (job.spindle_rpm, job.feed_mm_min, job.plunge_feed_mm_min, job.step_down_mm, job.roughing_passes,
            job.roughing_allowance_mm, job.coolant, job.safe_z_mm) == (4500, 750, 150, 2.5, 2, 0.3, "mist", 30.0)
    out = tmp_path / "nine.nc"
    assert main(["gcode", str(design), "-o", str(out)]) == 0
    text = out.read_text()
    assert _words(text, "S") == {4500.0}
    assert _words(text, "F") == {750.0, 150.0}
    assert re.search(r"\bM7\b", text) and not re.search(r"\bM8\b", text)  # mist, not flood
    assert max(_words(text, "Z")) == 30.0
    # 10 mm in levels of at most 2.5 mm: four equal levels, each reached
    assert {-2.5, -5.0, -7.5, -10.0} <= _words(text, "Z")


def test_gcode_run_package_and_the_api_write_the_same_program(design, tmp_path):
    assert main(["gcode", str(design), "-o", str(tmp_path / "g.nc")]) == 0
    assert main(["run", str(design), "-o", str(tmp_path / "run"), "--outputs", "gcode"]) == 0
    assert main(["package", str(design), "-o", str(tmp_path / "pkg"), "--outputs", "gcode"]) == 0
    programs = {
        "gcode": (tmp_path / "g.nc").read_bytes(),
        "run": next((tmp_path / "run").rglob("*.nc")).read_bytes(),
        "package": next((tmp_path / "pkg").rglob("*.nc")).read_bytes(),
        "api": camfab.load(design).to_gcode().encode(),
    }
    assert len(set(programs.values())) == 1, {k: len(v) for k, v in programs.items()}


def test_command_line_flags_override_the_table(design, tmp_path):
    out = tmp_path / "fast.nc"
    assert main(["gcode", str(design), "-o", str(out), "--feed", "900", "--coolant", "flood"]) == 0
    text = out.read_text()
    assert _words(text, "F") == {900.0, 150.0}  # the cutting feed from the flag, the plunge feed from the table
    assert _words(text, "S") == {4500.0}
    assert re.search(r"\bM8\b", text) and not re.search(r"\bM7\b", text)


@pytest.mark.parametrize("line,field", [("feed_mm_min = -750", "machining.feed_mm_min"),
                                        ('coolant = "oil"', "machining.coolant"),
                                        ("roughing_passes = 1.5", "machining.roughing_passes"),
                                        ("spindle = 4500", "machining.spindle")])
def test_a_bad_machining_table_is_refused_by_field_and_writes_nothing(design, tmp_path, capsys, line, field):
    key = line.split(" = ")[0]
    text = design.read_text(encoding="utf-8")
    text = re.sub(rf"(?m)^{key}\b.*$", "", text) if key != "spindle" else text
    bad = tmp_path / "bad.toml"
    bad.write_text(text.replace("[machining]\n", f"[machining]\n{line}\n"), encoding="utf-8")
    out = tmp_path / "out"
    assert main(["run", str(bad), "-o", str(out), "--outputs", "gcode"]) == 2
    assert field in capsys.readouterr().err
    assert not out.exists() or not any(out.rglob("*"))


def test_design_workbook_keeps_the_machining_table(design, tmp_path):
    spec = load_design(design)
    book = tmp_path / "nine.xlsx"
    book.write_bytes(design_to_xlsx(spec))
    back = load_design(book)
    assert back.machining == spec.machining
    # a design without the table writes no machining rows and reads back the defaults
    plain = load_design(EXAMPLES / "ejemplo9rt.toml")
    book.write_bytes(design_to_xlsx(plain))
    assert load_design(book).machining == plain.machining


def test_every_output_has_one_exporter():
    assert set(EXPORTERS) == set(Output)


def test_a_cam_computes_each_stage_once(design):
    cam = camfab.load(design)
    assert cam.geometry is cam.geometry
    assert cam.check() is cam.check()
    assert cam.shapes() is cam.shapes()
    assert cam.check().verdict == camfab.load(design).check().verdict
