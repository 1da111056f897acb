"""``camfab optimise``'s core: never worse than the start, constraints met, the 360° sum kept, every input problem
named; the valve-cam trade-off (a heavier weight on the force lowers the peak force and the minimum radius)."""
from __future__ import annotations

import copy

import pytest

from camfab.design.optimise import build_problem, measure, solve
from camfab.design.spec import design_from_dict
from camfab.errors import SpecError

from ..conftest import EJEMPLO9RT


def _e9(optimise, **over):
    data = {"name": "e9", "cam": {"kind": "disc", "speed_rpm": 100},
            "follower": {"type": "roller", "motion": "translating", "base_radius_mm": 35.0, "roller_radius_mm": 7.0},
            "motion": [{"law": law, "lift": float(h), "angle_deg": float(a)} for law, h, a in EJEMPLO9RT],
            "optimise": optimise}
    data.update(over)
    return data


ANGLES = [{"name": f"motion[{i}].angle_deg", "lo": 30.0, "hi": 70.0} for i in range(4)]


def _problem(data):
    return build_problem(data, design_from_dict(data))


def test_slsqp_improves_and_meets_constraints():
    data = _e9({"variables": ANGLES + [{"name": "follower.base_radius_mm", "lo": 32.0, "hi": 40.0}],
                "objectives": {"peak_pressure_angle_deg": 1.0, "peak_acceleration": 0.5},
                "constraints": {"min_radius_mm": 5.0}})
    prob = _problem(data)
    res = solve(prob)
    assert res.improved and res.score < res.score_start
    angles = [s["angle_deg"] for s in res.data["motion"]]
    assert sum(angles) == pytest.approx(360.0, abs=1e-9)
    assert all(30.0 - 1e-9 <= a <= 70.0 + 1e-9 for a in angles[:4])
    again = measure(design_from_dict(res.data))  # the written design, validated in full
    assert again["min_radius_mm"] >= 5.0 - 1e-9
    assert again["peak_pressure_angle_deg"] <= 30.0 + 1e-9  # the default [checks] limit
    assert again == pytest.approx(res.best)
    assert data == _e9(data["optimise"])  # the input dict is untouched


def test_never_worse_than_the_start():
    """A start that is already the optimum (the base radius at its upper bound for the pressure angle) is kept."""
    data = _e9({"variables": [{"name": "follower.base_radius_mm", "lo": 20.0, "hi": 35.0}],
                "objectives": {"peak_pressure_angle_deg": 1.0}})
    res = solve(_problem(data))
    assert res.score <= res.score_start
    assert res.values["follower.base_radius_mm"] == pytest.approx(35.0, abs=1e-6)


@pytest.mark.slow
def test_differential_evolution_is_seeded():
    data = _e9({"variables": ANGLES[:3], "objectives": {"peak_acceleration": 1.0}, "method": "differential_evolution",
                "seed": 7, "max_iterations": 3})
    a, b = solve(_problem(data)), solve(_problem(copy.deepcopy(data)))
    assert a.values == b.values and a.score <= a.score_start


@pytest.mark.parametrize("optimise,path,words", [
    ({"variables": [{"name": "motion[9].angle_deg", "lo": 10, "hi": 50}]}, "optimise.variables[0].name",
     "segments"),
    ({"variables": [{"name": "follower.arm_length_mm", "lo": 10, "hi": 50}]}, "optimise.variables[0].name",
     "not a dimension"),
    ({"variables": [{"name": "cam.speed_rpm", "lo": 10, "hi": 50}]}, "optimise.variables[0].name", "unknown"),
    ({"variables": [{"name": "motion[0].angle_deg", "lo": 10, "hi": 40}]}, "optimise.variables[0].lo",
     "leave out"),
    ({"variables": [{"name": "motion[0].angle_deg", "lo": 10, "hi": 60}]}, "optimise.variables[0].name",
     "at least two"),
    ({"variables": ANGLES, "constraints": {"min_radius_mm": 100.0}}, "optimise.constraints.min_radius_mm",
     "start design"),
    ({"variables": ANGLES, "objectives": {"peak_contact_force_n": 1.0}}, "optimise.objectives.peak_contact_force_n",
     "[dynamics]"),
    ({"variables": ANGLES, "objectives": {"min_radius_mm": 0.0}}, "optimise.objectives", "weight > 0"),
    ({"variables": ANGLES, "pareto": ["min_radius_mm", "peak_contact_force_n"]}, "optimise.pareto[1]", "[dynamics]"),
    ({"variables": ANGLES, "pareto": ["min_radius_mm", "min_radius_mm"]}, "optimise.pareto", "two different"),
    ({"variables": [{"name": "motion[0].angle_deg", "lo": 60, "hi": 10}]}, "optimise.variables[0].hi", "greater"),
    ({"variables": ANGLES, "method": "newton"}, "optimise.method", "valid option"),
])
def test_input_problems_name_the_field(optimise, path, words):
    with pytest.raises(SpecError) as e:
        _problem(_e9(optimise))
    p = e.value.problems[0]
    assert p.path == path and words in f"{p.rule} {p.fix}", p


def _valve_like(weight: float):
    """A valve-like knot table (9 mm lift and return over 180° at 1500 rpm, a flat tappet, a heavy train on a soft
    spring, so inertia sets the peak force): the middle knots of the lift and the return free (s, v, a), as the
    valve case frees its inner knots."""
    rows = [[0, 0, 0, 0], [45, 0.0045, 1.8, 0], [90, 0.009, 0, 0], [135, 0.0045, -1.8, 0], [180, 0, 0, 0],
            [360, 0, 0, 0]]
    var = []
    for i in (1, 3):
        var += [{"name": f"motion_table.rows[{i}].s", "lo": 0.0025, "hi": 0.0065},
                {"name": f"motion_table.rows[{i}].v", "lo": rows[i][2] - 0.8, "hi": rows[i][2] + 0.8},
                {"name": f"motion_table.rows[{i}].a", "lo": -600.0, "hi": 600.0}]
    data = {"name": "valve-like", "cam": {"kind": "disc", "speed_rpm": 1500},
            "follower": {"type": "flat", "motion": "translating", "base_radius_mm": 30.0},
            "motion_table": {"rows": rows, "units": {"angle": "deg", "s": "m", "v": "m/s", "a": "m/s2"},
                             "speed_rpm": 1500},
            "dynamics": {"mass_kg": 0.3, "spring_rate_n_per_mm": 10.0, "spring_preload_n": 100.0},
            "optimise": {"variables": var, "objectives": {"min_radius_mm": 1.0, "peak_contact_force_n": weight},
                         "max_iterations": 40}}
    return solve(build_problem(data, design_from_dict(data)))


@pytest.mark.slow
def test_valve_cam_trade_off():
    """The valve case's compromise: raising the weight on the force lowers the optimum's peak force and its minimum
    radius of curvature together; each optimum is no worse than the start in its own score."""
    alone, weighed = _valve_like(0.0), _valve_like(3.0)
    assert weighed.best["peak_contact_force_n"] < alone.best["peak_contact_force_n"] - 10.0
    assert weighed.best["min_radius_mm"] < alone.best["min_radius_mm"] - 1.0
    assert alone.best["min_radius_mm"] > alone.start["min_radius_mm"]
    assert weighed.score < weighed.score_start and weighed.best["min_contact_force_n"] >= 0.0
