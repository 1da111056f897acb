"""camfab.results: the verdict rules, the finding record, the summaries' merging, and the JSON seam
(keys and key order of ``check --json`` are a contract)."""
from __future__ import annotations

import json

import pytest

from camfab.design.assemble import check_design
from camfab.formats import load_design
from camfab.results import (
    CheckReport,
    Curvature,
    DynamicsSummary,
    Extreme,
    FaceLength,
    Finding,
    IssueCode,
    JumpSpeed,
    Maximum,
    Preload,
    PressureAngle,
    Severity,
    Verdict,
)

from .conftest import EXAMPLES


def _f(code: IssueCode, severity: Severity) -> Finding:
    return Finding(code, severity, 1.0, 2.0, 3.0, 0.0, "x")


def test_verdict_rules():
    assert Verdict.of([]) is Verdict.ACCEPTABLE
    assert Verdict.of([_f(IssueCode.FACE_LENGTH, Severity.INFO)]) is Verdict.ACCEPTABLE
    assert Verdict.of([_f(IssueCode.JERK_DISCONTINUITY, Severity.WARNING)]) is Verdict.NOT_FOR_HIGH_SPEED
    assert Verdict.of([_f(IssueCode.ACCELERATION_DISCONTINUITY, Severity.WARNING)]) is Verdict.NOT_FOR_HIGH_SPEED
    assert Verdict.of([_f(IssueCode.CONCAVE_RADIUS_BELOW_ROLLER, Severity.WARNING)]) is Verdict.ACCEPTABLE
    assert Verdict.of([_f(IssueCode.JERK_DISCONTINUITY, Severity.WARNING),
                       _f(IssueCode.UNDERCUT, Severity.ERROR)]) is Verdict.UNACCEPTABLE
    assert Verdict.worst("acceptable", Verdict.NOT_FOR_HIGH_SPEED) is Verdict.NOT_FOR_HIGH_SPEED
    assert Verdict.worst(Verdict.UNACCEPTABLE, "acceptable") is Verdict.UNACCEPTABLE


def test_codes_are_their_own_strings():
    assert all(c == c.name and c.value == c.name for c in IssueCode)
    assert json.dumps([IssueCode.GOUGE, Severity.ERROR, Verdict.ACCEPTABLE]) == '["GOUGE", "error", "acceptable"]'


def test_finding_json_and_gcode_form():
    d = _f(IssueCode.UNDERCUT, Severity.ERROR).to_dict()
    assert list(d) == ["code", "severity", "from_deg", "to_deg", "value", "limit", "message"]
    assert d["code"] == "UNDERCUT" and type(d["code"]) is str and type(d["severity"]) is str
    g = Finding.at_line(IssueCode.GOUGE, "too deep", 12)
    assert (g.code, g.severity, g.line, g.from_deg) == (IssueCode.GOUGE, Severity.ERROR, 12, None)


def test_summaries_merge_over_profiles():
    a = Curvature(5.0, 10.0, 20.0, 30.0, 12.0, None)
    b = Curvature(4.0, 40.0, None, None, 11.0, None)
    assert a.merged(b) == Curvature(4.0, 40.0, 20.0, 30.0, 11.0, None)
    assert b.merged(a) == Curvature(4.0, 40.0, 20.0, 30.0, 11.0, None)
    p = PressureAngle(-20.0, 300.0, 25.0, 100.0, 30.0).merged(PressureAngle(-22.0, 310.0, 24.0, 90.0, 35.0))
    assert p == PressureAngle(-22.0, 310.0, 25.0, 100.0, 30.0)
    f = FaceLength(3.0, 4.0, -3.0, 4.0).merged(FaceLength(5.0, 1.0, -5.0, 1.0))
    assert f == FaceLength(5.0, 4.0, -5.0, 4.0)


def test_dynamics_json_key_order():
    e = Extreme(1.0, 10.0, 2.0, 20.0)
    spring = DynamicsSummary(False, e, 100.0, Maximum(3.0, 30.0), e, True, 0.5, 0.25,
                             preload_needed=Preload(50.0, "N", 5.0), jump_speed=JumpSpeed(None, "rpm", None))
    assert list(spring.to_dict()) == ["form_closed", "contact_force_n", "safety_force_n", "bearing_force_n",
                                      "drive_torque_nm", "work_per_cycle_j", "mean_power_w", "preload_needed",
                                      "jump_speed"]
    assert list(spring.to_dict()["contact_force_n"]) == ["min", "max", "at_min_deg", "at_max_deg"]
    pair = DynamicsSummary(True, e, None, Maximum(3.0, 30.0), e, False, 0.0, 0.0, second_contact_force=e,
                           load_reversals=((60.0, 60.0),))
    assert list(pair.to_dict()) == ["form_closed", "contact_force_n", "safety_force_n", "bearing_force_n",
                                    "drive_force_n", "work_per_cycle_j", "mean_power_w", "second_contact_force_n",
                                    "preload_needed", "jump_speed", "load_reversals_deg"]
    assert pair.to_dict()["load_reversals_deg"] == [[60.0, 60.0]]


@pytest.mark.parametrize("name", ["ejemplo9rt", "valve_exhaust_ej1", "ejemplo8da_conjugate"])
def test_check_json_keys_are_the_contract(name):
    rep = check_design(load_design(EXAMPLES / f"{name}.toml"))
    assert isinstance(rep, CheckReport)
    d = json.loads(json.dumps(rep.to_dict()))
    assert list(d) == ["name", "verdict", "peaks", "junctions", "pressure_angle_deg", "radius_of_curvature_mm",
                       "face_length_mm", "base_radius_mm", "max_radius_mm", "area_mm2", "dynamics",
                       "initial_arm_angle_deg", "x_unit", "findings", "vibration", "contact_stress",
                       "cylinder"]
    assert d["vibration"] is None  # no [vibration] section
    assert list(d["peaks"]) == ["S", "V", "A", "J"] and list(d["peaks"]["V"]) == ["max", "min", "at_max_deg",
                                                                                   "at_min_deg"]
    assert list(d["radius_of_curvature_mm"]) == ["min_convex", "min_concave", "at_deg", "at_min_concave_deg",
                                                 "pitch_min_convex", "max"]
    if d["pressure_angle_deg"] is not None:
        assert list(d["pressure_angle_deg"]) == ["max", "min", "at_max_deg", "at_min_deg", "limit"]
    if d["face_length_mm"] is not None:
        assert list(d["face_length_mm"]) == ["left", "right", "min", "max"]
    # the typed fields are what the JSON says
    assert d["verdict"] == rep.verdict and d["base_radius_mm"] == rep.base_radius_mm
    assert [f["code"] for f in d["findings"]] == [f.code for f in rep.findings]
    assert d["peaks"]["V"]["max"] == rep.motion.peaks.V.max
