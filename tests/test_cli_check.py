"""`camfab check`: conclusions table, JSON contract (docs/decisions.md, "the user-facing contract"), exit codes,
refusals."""
from __future__ import annotations

import json

import pytest

from camfab.cli import main
from tests.conftest import EXAMPLES

KEYS = {"name", "verdict", "peaks", "junctions", "pressure_angle_deg", "radius_of_curvature_mm",
        "face_length_mm", "base_radius_mm", "max_radius_mm", "area_mm2", "findings"}


def _json(capsys, *argv):
    code = main(["check", *argv, "--json"])
    return code, json.loads(capsys.readouterr().out)


def test_check_json_contract_ejemplo9rt(capsys):
    code, d = _json(capsys, "ejemplo9rt")
    assert code == 0
    assert set(d) >= KEYS
    assert d["verdict"] == "not_for_high_speed"
    assert d["base_radius_mm"] == pytest.approx(35.0, abs=1e-9)
    assert d["max_radius_mm"] == pytest.approx(45.0, abs=1e-9)
    assert d["face_length_mm"] is None  # roller follower
    assert set(d["radius_of_curvature_mm"]) >= {"min_convex", "min_concave", "at_deg"}
    assert set(d["pressure_angle_deg"]) >= {"max", "min", "at_max_deg", "at_min_deg"}
    for f in d["findings"]:
        assert set(f) >= {"code", "severity", "from_deg", "to_deg", "value", "limit", "message"}


def test_check_table_text(capsys):
    assert main(["check", "ejemplo9rt"]) == 0
    out = capsys.readouterr().out
    assert "Not suitable for high speeds" in out
    assert "Pressure angle" in out and "Jerk" in out and "Discontinuous" in out


def _design(tmp_path, follower: str, motion: str = None) -> str:
    text = (EXAMPLES / "ejemplo9rt.toml").read_text()
    start, end = text.index("[follower]"), text.index("[[motion]]")
    text = text[:start] + follower + "\n" + text[end:]
    if motion is not None:
        text = text[:text.index("[[motion]]")] + motion + text[text.index("[manufacturing]"):]
    p = tmp_path / "d.toml"
    p.write_text(text)
    return str(p)


def test_ejemplo1rt_pressure_angle(tmp_path, capsys):
    p = _design(tmp_path, '[follower]\ntype = "roller"\nmotion = "translating"\nbase_radius_mm = 50.0\n'
                          'roller_radius_mm = 5.0\n',
                '[[motion]]\nlaw = "simple_harmonic"\nlift = 50.0\nangle_deg = 180.0\n'
                '[[motion]]\nlaw = "simple_harmonic"\nlift = -50.0\nangle_deg = 180.0\n')
    code, d = _json(capsys, p)
    assert code == 0 and d["verdict"] == "acceptable"
    pa = d["pressure_angle_deg"]
    assert round(abs(pa["max"]), 2) == 18.21 and round(abs(pa["min"]), 2) == 18.21


def test_unacceptable_exit_1(tmp_path, capsys):
    # a small base circle: pressure angle far above 30°
    p = _design(tmp_path, '[follower]\ntype = "roller"\nmotion = "translating"\nbase_radius_mm = 8.0\n'
                          'roller_radius_mm = 2.0\n')
    code, d = _json(capsys, p)
    assert code == 1 and d["verdict"] == "unacceptable"
    assert "PRESSURE_ANGLE_EXCEEDED" in {f["code"] for f in d["findings"]}


@pytest.mark.parametrize("follower, field", [
    ('type = "roller"\nmotion = "translating"\nbase_radius_mm = 35.0\nroller_radius_mm = 7.0\noffset_mm = 50.0\n',
     "follower.offset_mm"),
    ('type = "roller"\nmotion = "oscillating"\nbase_radius_mm = 35.0\nroller_radius_mm = 7.0\n'
     'pivot_distance_mm = 80.0\narm_length_mm = 5.0\n', "follower.arm_length_mm"),
])
def test_bad_geometry_refused_exit_2(tmp_path, capsys, follower, field):
    p = _design(tmp_path, "[follower]\n" + follower)
    assert main(["check", p]) == 2
    assert field in capsys.readouterr().err


def test_flat_face_reports_face_lengths(tmp_path, capsys):
    p = _design(tmp_path, '[follower]\ntype = "flat"\nmotion = "translating"\nbase_radius_mm = 100.0\n')
    code, d = _json(capsys, p)
    assert code == 0
    assert d["face_length_mm"]["left"] > 0 and d["face_length_mm"]["right"] > 0
    assert d["pressure_angle_deg"] is None


def test_valve_example_runs(capsys):
    code, d = _json(capsys, "valve_exhaust_ej1")
    assert code == 0 and d["verdict"] == "not_for_high_speed"


def test_check_dynamics_json_table_and_exit_code(tmp_path, capsys):
    """A [dynamics] section adds the "dynamics" object and the force rows; a spring too weak for the
    speed makes the follower jump: FOLLOWER_JUMP, verdict unacceptable, exit code 1."""
    code, d = _json(capsys, "valve_exhaust_ej1")
    assert code == 0 and d["dynamics"]["contact_force_n"]["min"] >= 100.0
    assert set(d["dynamics"]) >= {"contact_force_n", "safety_force_n", "bearing_force_n", "drive_torque_nm",
                                  "work_per_cycle_j", "mean_power_w", "preload_needed", "jump_speed"}
    code, d = _json(capsys, "ejemplo9rt")
    assert d["dynamics"] is None
    text = (EXAMPLES / "valve_exhaust_ej1.toml").read_text().replace("spring_preload_n = 250.0",
                                                                      "spring_preload_n = 20.0")
    (tmp_path / "valve_recon_ej1.csv").write_bytes((EXAMPLES / "valve_recon_ej1.csv").read_bytes())  # beside it
    p = tmp_path / "weak.toml"
    p.write_text(text)
    code, d = _json(capsys, str(p))
    assert code == 1 and d["verdict"] == "unacceptable"
    codes = {f["code"] for f in d["findings"]}
    assert "CONTACT_FORCE_BELOW_SAFETY" in codes
    assert main(["check", str(p)]) == 1
    out = capsys.readouterr().out
    assert "Contact force (N)" in out and "jump speed:" in out and "spring preload for the safety force" in out


def test_check_form_closed_dynamics_table(tmp_path, capsys):
    """A constant-width cam with [dynamics]: both followers' forces and the load reversals, no jump rows."""
    text = (EXAMPLES / "constant_width.toml").read_text() + "\n[dynamics]\nmass_kg = 0.4\n"
    p = tmp_path / "cw.toml"
    p.write_text(text)
    assert main(["check", str(p)]) == 0
    out = capsys.readouterr().out
    assert "Contact force, follower 1 (N)" in out and "Contact force, follower 2 (N)" in out
    assert "the load changes follower 2 times per turn" in out and "jump speed" not in out
    code, d = _json(capsys, str(p))
    assert d["dynamics"]["form_closed"] and d["dynamics"]["jump_speed"] is None
    assert [f["code"] for f in d["findings"]].count("LOAD_REVERSAL") == 2
