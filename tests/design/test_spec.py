"""Design-file validation: every rule refused with the field named, all problems at once."""
from __future__ import annotations

import math

import numpy as np
import pytest

from camfab.design.spec import design_from_dict
from camfab.errors import SpecError
from camfab.formats import load_design
from tests.conftest import EXAMPLES, base_design


def _problems(data):
    with pytest.raises(SpecError) as info:
        design_from_dict(data)
    return info.value


def test_example_loads_and_builds_program():
    spec = load_design(EXAMPLES / "ejemplo9rt.toml")
    assert spec.name == "Ejemplo9RT"
    assert spec.follower.base_radius_mm == 35.0
    prog = spec.program()
    assert len(prog.segments) == 8
    assert spec.cam.omega_rad_s == 1.0 and spec.cam.speed_given


def test_speed_from_rpm_and_default():
    d = base_design(cam={"kind": "disc", "speed_rpm": 60.0})
    assert design_from_dict(d).cam.omega_rad_s == pytest.approx(2 * math.pi)
    d = base_design(cam={"kind": "disc"})
    spec = design_from_dict(d)
    assert spec.cam.omega_rad_s == 1.0 and not spec.cam.speed_given


@pytest.mark.parametrize(
    "section, value, field",
    [
        ("cam", {"kind": "disk"}, "cam.kind"),
        ("cam", {"rotation": "left"}, "cam.rotation"),
        ("cam", {"speed_rpm": -5.0}, "cam.speed_rpm"),
        ("cam", {"speed_rpm": 10.0, "omega_rad_s": 1.0}, "cam.speed_rpm"),
        ("cam", {"omega_rad_s": float("nan")}, "cam.omega_rad_s"),
        ("cam", {"speed_mm_s": 5.0}, "cam.speed_mm_s"),
        ("follower", {"type": "roller", "motion": "translating", "base_radius_mm": -35.0,
                      "roller_radius_mm": 7.0}, "follower.base_radius_mm"),
        ("follower", {"type": "roller", "motion": "translating", "base_radius_mm": 35.0}, "follower.roller_radius_mm"),
        ("follower", {"type": "roller", "motion": "oscillating", "base_radius_mm": 35.0,
                      "roller_radius_mm": 7.0}, "follower.pivot_distance_mm"),
        ("follower", {"type": "flat", "motion": "translating", "base_radius_mm": 35.0,
                      "roller_radius_mm": 7.0}, "follower.roller_radius_mm"),
        ("follower", {"type": "knife", "motion": "translating", "base_radius_mm": 35.0,
                      "roller_radius_mm": 7.0}, "follower.roller_radius_mm"),
        ("follower", {"type": "cylinder"}, "follower.type"),
        ("follower", {"type": "roller", "motion": "translating", "base_radius_mm": "35",
                      "roller_radius_mm": 7.0}, "follower.base_radius_mm"),
        ("manufacturing", {"bore_mm": 80.0}, "manufacturing.bore_mm"),
        ("manufacturing", {"tolerance_mm": 1.0}, "manufacturing.tolerance_mm"),
        ("manufacturing", {"tolerance_mm": 1e-9}, "manufacturing.tolerance_mm"),
        ("manufacturing", {"keyway": True}, "manufacturing.keyway"),
        ("manufacturing", {"thickness_mm": 0.0}, "manufacturing.thickness_mm"),
        ("outputs", {"gcode": "heidenhain"}, "outputs.gcode"),
        ("outputs", {"dxf": "yes"}, "outputs.dxf"),
        ("checks", {"pressure_angle_limit_deg": 95.0}, "checks.pressure_angle_limit_deg"),
    ],
)
def test_field_rules_name_the_field(section, value, field):
    err = _problems(base_design(**{section: value}))
    assert any(p.path == field for p in err.problems), str(err)
    assert field in str(err)


def test_unknown_key_suggests_the_right_one():
    d = base_design()
    d["motion"][1] = {"law": "dwell", "lfit": 0.0, "angle_deg": 40.0}
    err = _problems(d)
    assert "motion[1].lfit" in str(err) and "did you mean 'lift'" in str(err)


def test_unknown_law_suggests():
    d = base_design()
    d["motion"][0]["law"] = "cycloid"
    err = _problems(d)
    assert "motion[0].law" in str(err) and "cycloidal" in str(err)


def test_all_problems_reported_at_once():
    d = base_design(cam={"kind": "disk", "speed_rpm": -1.0})
    d["follower"]["base_radius_mm"] = -3.0
    d["motion"][0]["angle_deg"] = -50.0
    err = _problems(d)
    paths = {p.path for p in err.problems}
    assert {"cam.kind", "cam.speed_rpm", "follower.base_radius_mm", "motion[0].angle_deg"} <= paths


def test_program_rules_are_merged_into_the_spec_error():
    d = base_design()
    d["motion"][1]["angle_deg"] = 45.0  # sum 365
    err = _problems(d)
    assert "motion[*].angle_deg" in str(err) and "360" in str(err) and "-5" in str(err)


def test_motion_and_table_are_exclusive():
    err = _problems(base_design(motion_table={"rows": []}))
    assert any(p.path == "motion_table" for p in err.problems)


def test_missing_motion():
    d = base_design()
    del d["motion"]
    assert any(p.path == "motion" for p in _problems(d).problems)


def test_translating_cam_uses_length_mm():
    d = base_design(cam={"kind": "translating", "speed_mm_s": 10.0},
                    follower={"type": "roller", "motion": "translating", "roller_radius_mm": 5.0,
                              "cam_length_mm": 200.0},
                    motion=[{"law": "cycloidal", "lift": 10.0, "length_mm": 100.0},
                            {"law": "cycloidal", "lift": -10.0, "length_mm": 100.0}])
    spec = design_from_dict(d)
    assert spec.program().period == pytest.approx(200.0)
    assert spec.speed == 10.0
    d["motion"][0] = {"law": "cycloidal", "lift": 10.0, "angle_deg": 100.0}
    err = _problems(d)
    assert "motion[0].angle_deg" in str(err)


def test_half_period_auto_span_from_file():
    d = base_design(motion=[
        {"law": "semicycloidal_vi0", "lift": 5.0, "angle_deg": "auto"},
        {"law": "constant_velocity", "lift": 10.0, "angle_deg": 90.0},
        {"law": "semicycloidal_vf0", "lift": 5.0, "angle_deg": "auto"},
        {"law": "dwell", "lift": 0.0, "angle_deg": 45.0},
        {"law": "poly4567", "lift": -20.0, "angle_deg": 45.0},
    ])
    prog = design_from_dict(d).program()
    spans = [math.degrees(s.span) for s in prog.segments]
    assert spans[0] == pytest.approx(90.0) and spans[2] == pytest.approx(90.0)


def test_toml_syntax_error_names_the_file(tmp_path):
    p = tmp_path / "bad.toml"
    p.write_text("name = 'x'\n[cam\nkind='disc'\n")
    with pytest.raises(SpecError, match="bad.toml.*not valid TOML"):
        load_design(p)


def test_missing_file(tmp_path):
    with pytest.raises(SpecError, match="no such design file"):
        load_design(tmp_path / "nope.toml")


def test_spec_is_immutable(design_dict):
    spec = design_from_dict(design_dict)
    with pytest.raises(AttributeError):
        spec.name = "other"  # type: ignore[misc]


@pytest.mark.parametrize("cam, follower, field", [
    ({"kind": "conjugate"}, {"type": "flat", "motion": "translating", "base_radius_mm": 45.0},
     "follower.follower_distance_mm"),
    ({"kind": "conjugate"}, {"type": "roller", "motion": "oscillating", "base_radius_mm": 45.0,
                             "roller_radius_mm": 5.0, "pivot_distance_mm": 100.0, "arm_length_mm": 80.0},
     "follower.follower_angle_deg"),
    ({"kind": "constant_width"}, {"type": "flat", "motion": "translating", "base_radius_mm": 40.0},
     "follower.width_mm"),
    ({"kind": "constant_width"}, {"type": "roller", "motion": "translating", "base_radius_mm": 40.0,
                                  "roller_radius_mm": 5.0, "width_mm": 100.0}, "follower.type"),
    ({"kind": "constant_diameter"}, {"type": "roller", "motion": "oscillating", "base_radius_mm": 40.0,
                                     "roller_radius_mm": 5.0, "width_mm": 100.0, "pivot_distance_mm": 90.0,
                                     "arm_length_mm": 70.0}, "follower.type"),
])
def test_desmodromic_required_fields(cam, follower, field):
    err = _problems(base_design(cam=cam, follower=follower))
    assert any(p.path == field for p in err.problems), str(err)


def test_constant_width_builds_its_own_law():
    d = base_design(cam={"kind": "constant_width"},
                    follower={"type": "flat", "motion": "translating", "base_radius_mm": 40.0, "width_mm": 100.0,
                              "rise_deg": 150.0})
    del d["motion"]
    prog = design_from_dict(d).program()
    x = np.linspace(0, np.pi, 721)
    np.testing.assert_allclose(prog(x) + prog(x + np.pi), 20.0, atol=1e-12)
    assert [round(math.degrees(s.span), 9) for s in prog.segments] == [150.0, 30.0, 150.0, 30.0]
    d["follower"]["follower_distance_mm"] = 100.0
    assert any(p.path == "follower.follower_distance_mm" for p in _problems(d).problems)


def test_constant_width_too_narrow():
    d = base_design(cam={"kind": "constant_width"},
                    follower={"type": "flat", "motion": "translating", "base_radius_mm": 40.0, "width_mm": 70.0})
    del d["motion"]
    assert "follower.width_mm" in str(_problems(d))


def test_kinds_are_the_shared_enums():
    from camfab.design.kinds import CamKind, FollowerMotion, FollowerType, LiftUnit, Rotation

    spec = design_from_dict(base_design(cam={"kind": "disc", "rotation": "ccw"}))
    assert spec.cam.kind is CamKind.DISC and spec.cam.rotation is Rotation.CCW
    assert spec.follower.type is FollowerType.ROLLER and spec.follower.motion is FollowerMotion.TRANSLATING
    assert spec.follower.lift_unit is LiftUnit.MM and spec.cam.kind == "disc"
    err = _problems(base_design(cam={"kind": "disk"}))
    assert "must be one of: disc, conjugate, constant_width, constant_diameter, translating" in str(err)


def test_a_spec_holds_no_folder_and_knows_its_sources(tmp_path):
    import dataclasses

    from camfab.formats import design_from_data

    spec = load_design(EXAMPLES / "ejemplo9rt.toml")
    assert "base_dir" not in {f.name for f in dataclasses.fields(spec)}
    assert spec.sources == (str(EXAMPLES / "ejemplo9rt.toml"),) and design_from_dict(base_design()).sources == ()
    (tmp_path / "k.csv").write_text("0,0,0,0\n90,5,0,0\n180,0,0,0\n", encoding="utf-8")
    d = base_design(motion_table={"file": "k.csv"})
    del d["motion"]
    spec = design_from_data(d, source=str(tmp_path / "d.toml"), base_dir=tmp_path)
    assert spec.sources == (str(tmp_path / "d.toml"), str(tmp_path / "k.csv"))
    assert spec.motion_table["file"].name == "k.csv" and spec.knot_table.source == str(tmp_path / "k.csv")
    (tmp_path / "k.csv").unlink()  # nothing is read again
    assert float(spec.program()(math.pi / 2)[0]) == pytest.approx(5.0)


def test_knot_file_problems_keep_the_file_and_the_design_source(tmp_path):
    p = tmp_path / "d.toml"
    p.write_text('[follower]\ntype = "flat"\nbase_radius_mm = 30.0\n[motion_table]\nfile = "none.csv"\n',
                 encoding="utf-8")
    with pytest.raises(SpecError) as info:
        load_design(p)
    assert info.value.source == str(p)
    assert [q.path for q in info.value.problems] == ["motion_table.file"]
    assert info.value.problems[0].value == str(tmp_path / "none.csv") and "file not found" in str(info.value)


def test_design_from_dict_refuses_an_unread_knot_file():
    d = base_design(motion_table={"file": "puntos.csv"})
    del d["motion"]
    err = _problems(d)
    assert [p.path for p in err.problems] == ["motion_table.file"] and "camfab.formats" in str(err)


# ---------------------------------------------------------------------------
# the follower keys come from the mechanism registry: what each family needs, and nothing it ignores
_TWO = [{"law": "cycloidal", "lift": 5.0, "angle_deg": 180.0}, {"law": "cycloidal", "lift": -5.0, "angle_deg": 180.0}]


@pytest.mark.parametrize("motion,follower,path", [
    ("translating", {"base_radius_mm": 30.0}, "follower.face_radius_mm"),
    ("oscillating", {"base_radius_mm": 30.0, "face_radius_mm": 40.0}, "follower.pivot_distance_mm"),
    ("translating", {"base_radius_mm": 30.0, "face_radius_mm": 40.0, "roller_radius_mm": 3.0},
     "follower.roller_radius_mm"),
    ("translating", {"base_radius_mm": 30.0, "face_radius_mm": 0.0}, "follower.face_radius_mm"),
])
def test_curved_face_follower_keys(motion, follower, path):
    data = {"follower": {"type": "curved", "motion": motion, **follower}, "motion": _TWO}
    with pytest.raises(SpecError) as info:
        design_from_dict(data)
    assert path in {p.path for p in info.value.problems}


def test_curved_face_follower_design():
    spec = design_from_dict({"follower": {"type": "curved", "motion": "oscillating", "base_radius_mm": 18.0,
                                          "face_radius_mm": 25.0, "pivot_distance_mm": 60.0,
                                          "face_offset_mm": 44.8}, "motion": _TWO})
    assert spec.follower.face_radius_mm == 25.0 and spec.program().axis.lift_unit == "deg"


def test_unused_follower_keys_are_refused_not_ignored():
    data = {"follower": {"type": "flat", "base_radius_mm": 30.0, "arm_length_mm": 50.0}, "motion": _TWO}
    with pytest.raises(SpecError) as info:
        design_from_dict(data)
    (p,) = info.value.problems
    assert p.path == "follower.arm_length_mm" and "not used" in p.rule and p.fix


def test_a_combination_without_a_family_lists_the_ones_that_exist():
    data = {"cam": {"kind": "conjugate"}, "follower": {"type": "curved", "base_radius_mm": 30.0,
                                                       "face_radius_mm": 20.0}, "motion": _TWO}
    with pytest.raises(SpecError) as info:
        design_from_dict(data)
    (p,) = info.value.problems
    assert p.path == "follower.type" and "translating roller" in p.fix and "curved" not in p.fix
