"""All problems at once (README, "Rules checked when a design is read"): one run, one exit 2, every field.

Before, a design's problems came in stages — the sections, then the motion's chain, then its closure, then
the mechanism — so a user fixed one and met the next.  Each test below builds a design whose problems are
independent and asserts that one read reports all of them, each once; the one rule that depends on others
(S ≥ 0 needs a motion without problems) is shown to wait, as documented.
"""
from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from camfab.design.program import MotionProgram
from camfab.design.spec import design_from_dict
from camfab.errors import SpecError
from camfab.formats import design_to_xlsx, load_design
from tests.conftest import EXAMPLES, base_design

ROOT = Path(__file__).resolve().parent.parent

STAGED = """name = "staged"
[cam]
kind = "disc"
[follower]
type = "roller"
motion = "translating"
base_radius_mm = 35.0
roller_radius_mm = 7.0
offset_mm = 50.0
[[motion]]
law = "cycloidal"
lift = 10.0
angle_deg = 100.0
[[motion]]
law = "dwell"
angle_deg = 100.0
[[motion]]
law = "cycloidal"
lift = -8.0
angle_deg = 100.0
[checks]
pressure_angle_limit_deg = 95.0
"""
#: its four problems, from four rules that were four stages: a section's range, the spans' and the lifts'
#: closure, the mechanism (|offset| < prime radius).  Before: 1, then 2 more, then 1 more.
STAGED_PATHS = ["checks.pressure_angle_limit_deg", "motion[*].angle_deg", "motion[*].lift", "follower.offset_mm"]


def _paths(exc: pytest.ExceptionInfo) -> list[str]:
    return [p.path for p in exc.value.problems]


def _cli(*args: str) -> subprocess.CompletedProcess:
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    return subprocess.run([sys.executable, "-m", "camfab", *args], capture_output=True, text=True, env=env,
                          timeout=120)


def test_the_staged_design_reports_all_four_in_one_run_text_and_json(tmp_path):
    f = tmp_path / "staged.toml"
    f.write_text(STAGED)
    r = _cli("check", str(f))
    assert r.returncode == 2 and "4 problems in the design" in r.stderr and r.stdout == ""
    for path in STAGED_PATHS:
        assert f"  - {path} = " in r.stderr
    r = _cli("check", str(f), "--json")
    assert r.returncode == 2
    doc = json.loads(r.stdout)
    assert doc["error"] == "invalid_design" and doc["source"] == str(f)
    assert [p["path"] for p in doc["problems"]] == STAGED_PATHS
    assert doc["problems"][1] == {"path": "motion[*].angle_deg", "value": 300.0,
                                  "rule": "segment spans must sum to 360", "fix": "change the spans by +60 in total"}
    # fixing them one by one never uncovers a new one
    text = STAGED
    for old, new in (("pressure_angle_limit_deg = 95.0", "pressure_angle_limit_deg = 30.0"),
                     ("lift = -8.0\nangle_deg = 100.0", "lift = -10.0\nangle_deg = 160.0"),
                     ("offset_mm = 50.0", "offset_mm = 5.0")):
        text = text.replace(old, new)
        f.write_text(text)
        left = _cli("check", str(f), "--json")
        if left.returncode == 2:
            assert {p["path"] for p in json.loads(left.stdout)["problems"]} < set(STAGED_PATHS)
    assert left.returncode in (0, 1) and "Traceback" not in left.stderr


def test_sections_motion_and_laws_together():
    """The issue's list: a negative base radius, a bad roller, a misspelt law and spans that do not close."""
    d = base_design()
    d["follower"] = {**d["follower"], "base_radius_mm": -35.0, "roller_radius_mm": -7.0}
    d["motion"] = [dict(r) for r in d["motion"]]
    d["motion"][2]["law"] = "cycloidl"
    d["motion"][1]["angle_deg"] = 30.0
    with pytest.raises(SpecError) as e:
        design_from_dict(d)
    assert _paths(e) == ["follower.base_radius_mm", "follower.roller_radius_mm", "motion[2].law",
                         "motion[*].angle_deg"]
    assert e.value.problems[2].fix == "did you mean 'cycloidal'?"  # the section's report stands, once


def test_a_value_reported_by_its_section_is_not_reported_again_nor_summed():
    d = base_design()
    d["motion"] = [dict(r) for r in d["motion"]]
    d["motion"][1]["angle_deg"] = -40.0  # bad span: the spans' sum cannot be judged
    d["motion"][2]["lift"] = "ten"  # bad lift: nor the lifts' sum
    d["motion"][4]["law"] = "poly3456"
    with pytest.raises(SpecError) as e:
        design_from_dict(d)
    assert _paths(e) == ["motion[1].angle_deg", "motion[2].lift", "motion[4].law"]


def test_chain_rules_among_valid_segments_and_closure_together():
    with pytest.raises(SpecError) as e:
        MotionProgram.from_segments([("poly5", 10, 90), ("cycloidl", 0, 90), ("poly7", -10, 90),
                                     ("poly5", 0, 80)])
    assert _paths(e) == ["motion[1].law", "motion[3].law", "motion[0].law", "motion[*].angle_deg"]
    assert all("two generic polynomials may not be adjacent" in p.rule for p in e.value.problems[1:3])


def test_a_knot_table_and_the_other_sections_together():
    d = base_design(motion_table={"rows": [[0, 0, 0, 0], [90, 5, 0, 0], [80, 5, 0, 0], [270, -1, 0, 0]]},
                    cam={"kind": "disc", "speed_rpm": -5})
    del d["motion"]
    with pytest.raises(SpecError) as e:
        design_from_dict(d)
    assert _paths(e) == ["cam.speed_rpm", "motion_table.rows[2][0]", "motion_table.rows[3][1]"]


def test_mechanism_rules_that_need_the_motion_come_with_the_sections():
    """An arm that would swing past the line of centres (a rule on mechanism and motion together)."""
    d = base_design(follower={"type": "roller", "motion": "oscillating", "base_radius_mm": 40.0,
                              "roller_radius_mm": 8.0, "pivot_distance_mm": 110.0, "arm_length_mm": 90.0},
                    motion=[{"law": "cycloidal", "lift": 170.0, "angle_deg": 180.0},
                            {"law": "cycloidal", "lift": -170.0, "angle_deg": 180.0}],
                    manufacturing={"thickness_mm": -1.0})
    with pytest.raises(SpecError) as e:
        design_from_dict(d)
    assert _paths(e) == ["manufacturing.thickness_mm", "motion[*].lift"]
    assert "would swing to" in e.value.problems[1].rule


def test_s_below_zero_waits_for_a_motion_without_problems():
    """The one rule that needs the resolved motion: with a misspelt law elsewhere it is not judged; once
    the law is fixed it is (documented in camfab.design.resolve)."""
    rows = [("poly345", 10, 90), ("constant_velocity", -10, 90), ("poly5", 0, 90), ("dwel", 0, 90)]
    with pytest.raises(SpecError) as e:
        MotionProgram.from_segments(rows)
    assert _paths(e) == ["motion[3].law"]
    rows[3] = ("dwell", 0, 90)
    with pytest.raises(SpecError) as e:
        MotionProgram.from_segments(rows)
    assert _paths(e) == ["motion[2]"] and "S goes below 0" in e.value.problems[0].rule


def test_xlsx_sheet_problems_and_design_problems_together(tmp_path):
    import openpyxl

    book = openpyxl.load_workbook(__import__("io").BytesIO(design_to_xlsx(load_design(EXAMPLES / "ejemplo9rt.toml"))))
    ws = book["design"]
    keys = {row[0].value: row[1] for row in ws.iter_rows() if row[0].value}
    keys["follower.offset_mm"].value = 50.0
    ws.append(["cam.kind", "disc"])  # given twice: a sheet problem
    book["motion"]["C2"] = 10.0  # the first segment's span 50 -> 10: the spans do not close
    f = tmp_path / "d.xlsx"
    book.save(f)
    with pytest.raises(SpecError) as e:
        load_design(f)
    paths = [p.split(" [")[0] for p in _paths(e)]
    assert paths == ["cam.kind", "motion[*].angle_deg", "follower.offset_mm"], _paths(e)
    assert "is given twice" in e.value.problems[0].rule and "[design!B" in _paths(e)[2]
