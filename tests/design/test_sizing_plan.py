"""``camfab size``'s core: each constraint's smallest base radius against a brute-force scan of the checks, the
governing constraint, and the sized design re-checked."""
from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from camfab.design import sizing
from camfab.design.assemble import check_design
from camfab.design.checks import check
from camfab.design.mechanisms import OscillatingRoller, TranslatingFlat, TranslatingRoller
from camfab.design.profile import CamGeometry
from camfab.design.program import MotionProgram
from camfab.design.sizing_plan import size_design
from camfab.design.spec import design_from_dict
from camfab.errors import InputError, SpecError

from ..conftest import EJEMPLO9RT, EJEMPLO11RO

E9 = MotionProgram.from_segments(EJEMPLO9RT)
E11 = MotionProgram.from_segments(EJEMPLO11RO)


def _first_feasible(make, prog, bad: set[str], grid, **kw) -> float:
    """Brute force: the first base radius of ``grid`` whose check has none of the codes ``bad``."""
    for rb in grid:
        if not (check(CamGeometry(make(rb), prog), **kw).codes() & bad):
            return float(rb)
    raise AssertionError("no feasible radius on the grid")


@pytest.mark.parametrize("name,make,prog,helper,bad,kw", [
    ("pressure angle", lambda rb: TranslatingRoller(rb, 7.0, 2.0), E9,
     lambda m, p: sizing.min_base_radius_for_pressure_angle(m, p), {"PRESSURE_ANGLE_EXCEEDED"}, {}),
    ("undercut", lambda rb: TranslatingRoller(rb, 12.0), E9,
     lambda m, p: sizing.min_base_radius_no_undercut(m, p), {"UNDERCUT", "CUSP"}, {}),
    ("cutter", lambda rb: TranslatingRoller(rb, 2.0), E9,
     lambda m, p: sizing.min_base_radius_for_cutter(m, p, 6.0), {"CONCAVE_RADIUS_BELOW_ROLLER"},
     {"tool_radius_mm": 6.0}),
    ("flat cusp", lambda rb: TranslatingFlat(rb), E9,
     lambda m, p: sizing.min_base_radius_no_cusp(m, p), {"UNDERCUT", "CUSP"}, {}),
])
def test_helpers_match_a_brute_force_scan(name, make, prog, helper, bad, kw):
    """The helper's radius r: the first feasible radius of a 0.02 mm grid lies in [r, r + 0.02)."""
    r = helper(make(40.0), prog)
    step = 0.02
    grid = np.round(np.arange(np.floor(r) - 0.5, np.floor(r) + 1.5, step), 6)
    found = _first_feasible(make, prog, bad, grid, **kw)
    assert r - 1e-9 <= found < r + step + 1e-9, (name, r, found)


def test_cutter_oscillating_is_active():
    make = lambda rb: OscillatingRoller(rb, 3.0, 100.0, 60.0)  # noqa: E731
    r = sizing.min_base_radius_for_cutter(make(50.0), E11, 8.0)
    below = check(CamGeometry(make(r * (1 - 1e-5)), E11), tool_radius_mm=8.0).codes()
    above = check(CamGeometry(make(r * (1 + 1e-5)), E11), tool_radius_mm=8.0).codes()
    assert "CONCAVE_RADIUS_BELOW_ROLLER" in below and "CONCAVE_RADIUS_BELOW_ROLLER" not in above


def test_cutter_smaller_than_roller_never_binds():
    assert sizing.min_base_radius_for_cutter(TranslatingRoller(30.0, 7.0), E9, 3.0) < 1e-6


def _e9(**over):
    data = {"name": "e9", "cam": {"kind": "disc"},
            "follower": {"type": "roller", "motion": "translating", "base_radius_mm": 35.0,
                         "roller_radius_mm": 7.0},
            "motion": [{"law": law, "lift": float(h), "angle_deg": float(a)} for law, h, a in EJEMPLO9RT],
            "manufacturing": {"tool_diameter_mm": 6.0}}
    data.update(over)
    return data


def test_governing_constraint_and_sized_design_passes():
    """The largest radius governs, rounded up; the re-built design meets every constraint (no finding of them),
    and one step below the rounding a constraint fails."""
    spec = design_from_dict(_e9())
    res = size_design(spec)
    rows = {r.constraint: r for r in res.rows}
    assert rows["cusp"].radius_mm is None and "flat-face" in rows["cusp"].note
    top = max((r for r in res.rows if r.radius_mm is not None), key=lambda r: r.radius_mm)
    assert res.governing == top.constraint == "pressure_angle" and top.governing
    assert sum(r.governing for r in res.rows) == 1
    assert top.radius_mm <= res.base_radius_mm < top.radius_mm + 0.01 + 1e-9
    sized = dataclasses.replace(spec, follower=dataclasses.replace(spec.follower, base_radius_mm=res.base_radius_mm))
    codes = check_design(sized, tool_radius_mm=3.0).codes()
    assert not codes & {"PRESSURE_ANGLE_EXCEEDED", "UNDERCUT", "CUSP", "CONCAVE_RADIUS_BELOW_ROLLER"}
    less = top.radius_mm - 0.01
    smaller = dataclasses.replace(spec, follower=dataclasses.replace(spec.follower, base_radius_mm=less))
    assert "PRESSURE_ANGLE_EXCEEDED" in check_design(smaller).codes()


def test_sizing_table_limits_and_offset():
    """A tighter [sizing] pressure-angle limit needs a larger cam; set_offset writes the best offset and the cam
    sized with it is smaller (the offset lowers the peak pressure angle)."""
    base = size_design(design_from_dict(_e9()))
    tight = size_design(design_from_dict(_e9(sizing={"pressure_angle_limit_deg": 25.0})))
    assert tight.base_radius_mm > base.base_radius_mm and tight.limits["pressure_angle_limit_deg"] == 25.0
    off = size_design(design_from_dict(_e9(sizing={"set_offset": True, "constraints": ["pressure_angle"]})))
    assert off.changes["follower.offset_mm"] == pytest.approx(base.best_offset_mm, abs=1e-3)
    assert off.base_radius_mm < base.base_radius_mm
    assert [r.constraint for r in off.rows] == ["pressure_angle"]


def test_flat_face_governed_by_cusp():
    spec = design_from_dict({**_e9(), "follower": {"type": "flat", "motion": "translating", "base_radius_mm": 35.0}})
    res = size_design(spec)
    assert res.governing == "cusp"
    assert res.base_radius_mm == pytest.approx(sizing.min_base_radius_no_cusp(TranslatingFlat(35.0), E9), abs=0.0101)


def test_bad_sizing_tables_name_the_field():
    with pytest.raises(SpecError) as e:
        design_from_dict(_e9(sizing={"constraints": ["pressure_angel"], "round_up_mm": 0, "arm_length_mm": [5, 1]}))
    paths = {p.path for p in e.value.problems}
    assert {"sizing.constraints[0]", "sizing.round_up_mm", "sizing.arm_length_mm"} <= paths
    with pytest.raises(SpecError) as e:
        size_design(design_from_dict(_e9(sizing={"constraints": ["cusp"]})))
    assert e.value.problems[0].path == "sizing.constraints[0]" and "remove it" in e.value.problems[0].fix


@pytest.mark.slow
def test_best_pivot_lowers_the_peak_pressure_angle():
    mech = OscillatingRoller(50.0, 8.0, 100.0, 60.0)
    m, a = sizing.best_pivot_and_arm(mech, E11, (80.0, 150.0), (50.0, 90.0))
    assert 80.0 <= m <= 150.0 and 50.0 <= a <= 90.0
    before = sizing.peak_pressure_angle_deg(mech, E11)
    after = sizing.peak_pressure_angle_deg(dataclasses.replace(mech, pivot_distance_mm=m, arm_length_mm=a), E11)
    assert after < before - 1.0


def _stressed(follower: dict, allowable: float) -> dict:
    """Ejemplo9RT's motion at 300 rpm driving 2 kg against a 20 N/mm spring, a 5 mm wide steel face judged
    against a low allowable stress, so that the contact stress sizes the cam."""
    return _e9(follower=follower, cam={"kind": "disc", "speed_rpm": 300.0},
               dynamics={"mass_kg": 2.0, "spring_rate_n_per_mm": 20.0, "spring_preload_n": 100.0},
               strength={"roller_width_mm": 5.0, "allowable_contact_stress_mpa": allowable})


def _with_rb(spec, rb: float):
    return dataclasses.replace(spec, follower=dataclasses.replace(spec.follower, base_radius_mm=float(rb)))


@pytest.mark.parametrize("follower,allowable", [
    ({"type": "roller", "motion": "translating", "base_radius_mm": 35.0, "roller_radius_mm": 7.0}, 595.0),
    ({"type": "flat", "motion": "translating", "base_radius_mm": 35.0}, 300.0),
])
def test_contact_stress_sizing_matches_a_brute_force_scan(follower, allowable):
    """The contact-stress constraint's radius r: on a 0.05 mm grid of whole designs checked by `check` (the exact
    stress search of the contact-stress rule), the first radius without CONTACT_STRESS_ABOVE_LIMIT lies in
    [r, r + 0.05); the sized design (governed by the stress) has no such finding, 0.01 mm under r has."""
    spec = design_from_dict(_stressed(follower, allowable))
    res = size_design(spec)
    r = {row.constraint: row for row in res.rows}["contact_stress"].radius_mm
    assert res.governing == "contact_stress" and r is not None
    step = 0.05
    grid = np.round(np.arange(np.floor(r / step) * step - 0.2, r + 0.3, step), 6)
    found = next(rb for rb in grid if "CONTACT_STRESS_ABOVE_LIMIT" not in check_design(_with_rb(spec, rb)).codes())
    assert r - 1e-9 <= found < r + step + 1e-9, (r, found)
    assert "CONTACT_STRESS_ABOVE_LIMIT" not in check_design(_with_rb(spec, res.base_radius_mm)).codes()
    assert "CONTACT_STRESS_ABOVE_LIMIT" in check_design(_with_rb(spec, r - 0.01)).codes()


def test_contact_stress_out_of_reach_is_said():
    """A roller's stress never falls below the roller-on-a-plane value: asking for less is refused with the fix."""
    spec = design_from_dict(_stressed({"type": "roller", "motion": "translating", "base_radius_mm": 35.0,
                                       "roller_radius_mm": 7.0}, 420.0))
    with pytest.raises(InputError, match="larger roller"):
        size_design(spec)


def test_contact_stress_constraint_needs_the_force():
    res = size_design(design_from_dict(_e9()))
    row = {r.constraint: r for r in res.rows}["contact_stress"]
    assert row.radius_mm is None and "[dynamics]" in row.note
    assert "peak_stress" not in res.to_dict()["limits"]  # the stated limits are numbers only
