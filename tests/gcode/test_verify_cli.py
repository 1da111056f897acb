"""``camfab verify`` verifies what the README says (issue 12): coverage and full depth by default, every feed,
spindle direction and coolant as the job asks, parse failures as findings with JSON; ``camfab gcode --post grbl
--compensation G41`` refused cleanly; and the cost follows the program, not the size of the part."""
from __future__ import annotations

import json
import os
import re
import resource
import subprocess
import sys
import time
from pathlib import Path

import pytest

from camfab import pipeline
from camfab.cli import main
from camfab.gcode import Job, contour_toolpath, dumps, parse, verify
from camfab.gcode.cam import cam_program
from camfab.gcode.distance import IndexedContourDistance
from tests.gcode.parts import circle

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def program(tmp_path_factory):
    """Ejemplo9RT's LinuxCNC program as ``camfab gcode`` writes it."""
    out = tmp_path_factory.mktemp("verify") / "e9.nc"
    assert main(["gcode", "ejemplo9rt", "-o", str(out)]) == 0
    return out.read_text()


def _run(tmp_path, capsys, text, *extra, design="ejemplo9rt"):
    f = tmp_path / "p.nc"
    f.write_bytes(text.encode() if isinstance(text, str) else text)
    capsys.readouterr()
    code = main(["verify", str(f), "--design", design, "--json", *extra])
    return code, json.loads(capsys.readouterr().out)


def _lines(text):
    return text.splitlines()


def _finish(lines):
    return lines.index("(FINISH CONTOUR)"), lines.index("(FINISH LEAD-OUT)")


def _halfway(text):
    L = _lines(text)
    i, j = _finish(L)
    return "\n".join(L[:i + 1 + (j - i) // 2] + ["G0 Z25.0000", "M9", "M5", "M2"]) + "\n"


def _finish_at(z):
    def edit(text):
        L = _lines(text)
        k = max(n for n, t in enumerate(L) if t.startswith("G1 Z-10.5000"))  # the finishing plunge (with breakthrough)
        L[k] = L[k].replace("Z-10.5000", z)
        return "\n".join(L) + "\n"
    return edit


def _finish_feed(f):
    def edit(text):
        L = _lines(text)
        i, _ = _finish(L)
        L[i + 5] += f" {f}"
        return "\n".join(L) + "\n"
    return edit


ISSUE_CASES = {
    "contour stops halfway": (_halfway, "COVERAGE"),
    "finishing pass at Z-5 of Z-10": (_finish_at("Z-5.0000"), "FINISH_DEPTH"),
    "F0 on the finishing pass": (_finish_feed("F0"), "FEED_MISSING"),
    "F60000 on the finishing pass": (_finish_feed("F60000"), "FEED_OUT_OF_RANGE"),
    "M4 instead of M3": (lambda t: re.sub(r"(S\d+) M3", r"\1 M4", t), "SPINDLE_DIRECTION"),
    "coolant removed": (lambda t: t.replace("M8\n", ""), "COOLANT"),
    "coolant off before cutting": (lambda t: t.replace("M8\n", "M8\nM9\n"), "COOLANT"),
}


def test_the_generated_program_passes_with_coverage_and_depth_checked(tmp_path, capsys, program):
    code, rep = _run(tmp_path, capsys, program)
    assert code == 0 and rep["ok"] and rep["problems"] == []
    assert rep["coverage_gap_mm"] is not None and rep["coverage_gap_mm"] <= rep["tolerance_mm"]
    assert rep["max_deviation_mm"] <= rep["tolerance_mm"] and rep["gouge"] is False
    assert "checked as a linuxcnc program (declared by the program)" in rep["notes"]


@pytest.mark.parametrize("case", list(ISSUE_CASES))
def test_issue_cases_fail_with_their_finding(tmp_path, capsys, program, case):
    edit, code_name = ISSUE_CASES[case]
    text = edit(program)
    assert text != program
    code, rep = _run(tmp_path, capsys, text)
    assert code == 1 and not rep["ok"]
    found = [p for p in rep["problems"] if p["code"] == code_name]
    assert found and all(p["message"] for p in found), rep["problems"]


def test_parse_failure_is_a_finding_with_json(tmp_path, capsys, program):
    L = _lines(program)
    i, _ = _finish(L)
    L[i + 3] = "G2 X1 Y2 Q5"
    code, rep = _run(tmp_path, capsys, "\n".join(L) + "\n")
    assert code == 1
    # the --json contract: max_deviation_mm, gouge (bool and where), the problems
    assert rep["max_deviation_mm"] is None and rep["gouge"] is False and rep["gouge_at"] is None
    assert rep["ok"] is False and [p["code"] for p in rep["problems"]] == ["PARSE_ERROR"]
    assert rep["problems"][0]["line"] == i + 4 and "Q5" in rep["problems"][0]["message"]
    # bytes that are not text: the line of the first bad byte
    code, rep = _run(tmp_path, capsys, b"G17 G21 G40 G54 G90 G94\n\xff\xfe\n")
    assert code == 1 and rep["problems"][0]["code"] == "PARSE_ERROR" and rep["problems"][0]["line"] == 2
    # the table output says it too
    f = tmp_path / "p.nc"
    assert main(["verify", str(f), "--design", "ejemplo9rt"]) == 1
    assert "[PARSE_ERROR] line 2" in capsys.readouterr().out
    # a missing file is an I/O error
    assert main(["verify", str(tmp_path / "missing.nc"), "--design", "ejemplo9rt"]) == 3


def test_the_job_flags_state_what_gcode_was_told(tmp_path, capsys):
    cam = pipeline.load("ejemplo9rt")
    job = pipeline.gcode_job(cam.spec, tol=1e-3, overrides={"feed_mm_min": 800.0, "coolant": "mist"})
    text = dumps(cam_program(cam.geometry.profiles[0], job, tol=1e-3).program, "grbl")
    assert "\nM8\n" in text  # GRBL writes flood for mist unless compiled with M7
    code, rep = _run(tmp_path, capsys, text)
    assert code == 1 and {p["code"] for p in rep["problems"]} == {"FEED_OUT_OF_RANGE"}
    code, rep = _run(tmp_path, capsys, text, "--feed", "800", "--coolant", "mist")
    assert code == 0, rep["problems"]
    assert "checked as a grbl program (declared by the program)" in rep["notes"]
    # told it is for a machine with a tool changer, the program lacks T1 M6 and G43 H1
    code, rep = _run(tmp_path, capsys, text, "--feed", "800", "--coolant", "mist", "--post", "linuxcnc")
    assert code == 1 and {"TOOL", "TOOL_LENGTH_OFFSET"} <= {p["code"] for p in rep["problems"]}


def test_inch_and_conventional_programs(tmp_path, capsys):
    cam = pipeline.load("ejemplo9rt")
    job = pipeline.gcode_job(cam.spec, tol=1e-3, overrides={"units": "inch", "direction": "conventional"})
    text = dumps(cam_program(cam.geometry.profiles[0], job, tol=1e-3).program, "fanuc")
    assert "G20" in text and "POST FANUC" in text
    code, rep = _run(tmp_path, capsys, text)
    assert code == 1 and {p["code"] for p in rep["problems"]} == {"DIRECTION"}
    code, rep = _run(tmp_path, capsys, text, "--direction", "conventional")
    assert code == 0, rep["problems"]


def _gcode_cli(*args, cwd):
    return subprocess.run([sys.executable, "-m", "camfab", "gcode", *args], capture_output=True, text=True,
                          cwd=cwd, env={**os.environ, "PYTHONPATH": str(ROOT)}, timeout=300)


def test_grbl_has_no_cutter_compensation_refused_before_any_work(tmp_path):
    out = tmp_path / "x.nc"
    r = _gcode_cli("ejemplo9rt", "--post", "grbl", "--compensation", "G41", "-o", str(out), cwd=tmp_path)
    assert r.returncode == 2 and "Traceback" not in r.stderr and not out.exists()
    assert len(r.stderr.strip().splitlines()) == 1
    assert re.search(r"--compensation G41: the grbl post has no cutter radius compensation .*G41/G42", r.stderr)
    # the same asked by the design's [machining] table
    design = tmp_path / "d.toml"
    design.write_text((ROOT / "camfab" / "examples" / "ejemplo9rt.toml").read_text()
                      + '\n[machining]\ncompensation = "G41"\n')
    r = _gcode_cli(str(design), "--post", "grbl", "-o", str(out), cwd=tmp_path)
    assert r.returncode == 2 and "Traceback" not in r.stderr and not out.exists()
    assert "[machining] compensation = 'G41': the grbl post has no cutter radius compensation" in r.stderr


# ---- cost: proportional to the program, not to the size of the part ----------------------------------------
class _Counting:
    """A distance function that counts the points it is asked about."""

    def __init__(self, f):
        self.f, self.points = f, 0

    def __call__(self, p):
        self.points += len(p)
        return self.f(p)

    def __getattr__(self, name):  # length, project, at_position for the coverage check
        return getattr(self.f, name)


def _circle_case(radius):
    job = Job(tool_diameter_mm=6.0, depth_mm=10.0, step_down_mm=5.0, tolerance_mm=1e-3, design_name="disc")
    text = dumps(contour_toolpath(circle(radius + 3.0), job), "linuxcnc")
    part = _Counting(IndexedContourDistance(circle(radius)))
    rep = verify(parse(text), exact_curve_distance=None, part_distance=part, part_curve=part, tool_radius=3.0,
                 tol=1e-3, safe_z=job.safe_z_mm, job=job, post="linuxcnc")
    return rep, part.points, len(text.splitlines())


def test_verify_work_follows_the_moves_not_the_size():
    small, n_small, lines_small = _circle_case(50.0)
    t = time.process_time()
    big, n_big, lines_big = _circle_case(10_000.0)
    assert time.process_time() - t < 30
    assert small.ok and big.ok, (small.problems, big.problems)
    assert lines_big == lines_small
    # a disc 200 times larger: the same program, (nearly) the same number of points measured
    assert n_big <= 1.5 * n_small, (n_small, n_big)


@pytest.mark.slow
def test_verify_of_a_ten_metre_cam_finishes_quickly_within_a_memory_cap(tmp_path):
    design = tmp_path / "rb10m.toml"
    design.write_text((ROOT / "camfab" / "examples" / "ejemplo9rt.toml").read_text()
                      .replace("base_radius_mm = 35.0", "base_radius_mm = 10000.0"))
    nc = tmp_path / "rb10m.nc"

    def cap():
        resource.setrlimit(resource.RLIMIT_AS, (3 << 30, 3 << 30))

    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    r = subprocess.run([sys.executable, "-m", "camfab", "gcode", str(design), "-o", str(nc)], capture_output=True,
                       text=True, env=env, timeout=600, preexec_fn=cap)
    assert r.returncode == 0, r.stderr
    t = time.perf_counter()
    r = subprocess.run([sys.executable, "-m", "camfab", "verify", str(nc), "--design", str(design), "--json"],
                       capture_output=True, text=True, env=env, timeout=600, preexec_fn=cap)
    assert r.returncode == 0, r.stderr + r.stdout
    assert json.loads(r.stdout)["ok"] and time.perf_counter() - t < 120
