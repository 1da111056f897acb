"""Two adjacent generic polynomials joined by free values (``end_v``, ``end_a``, ``end_j`` on the first): continuity
at the joint by construction (finite differences of the evaluated motion), the refusals with their field paths,
the keys read from a design, and the joint values as variables of ``camfab optimise``."""
from __future__ import annotations

import math

import numpy as np
import pytest

from camfab.design.optimise import build_problem, measure, solve
from camfab.design.program import MotionProgram
from camfab.design.spec import design_from_dict
from camfab.errors import SpecError

JOINT_DEG = 130.0  # dwell 90° + the first piece's 40°


def _program(first: str, second: str, ends) -> MotionProgram:
    return MotionProgram.from_segments([("dwell", 0, 90), (first, 6, 40, None, ends), (second, 4, 50),
                                        ("dwell", 0, 90), ("cycloidal", -10, 90)])


def _one_sided(p: MotionProgram, x: float, h: float) -> tuple[np.ndarray, np.ndarray]:
    """S′, S″, S‴ at x from the left and from the right, by one-sided differences of S alone (second order for S′
    and S″; S‴ first order)."""
    k = np.arange(5)
    left = p.evaluate(x - k * h, (0,))[0]
    right = p.evaluate(x + k * h, (0,))[0]

    def d(s: np.ndarray, sign: float) -> np.ndarray:
        d1 = (3 * s[0] - 4 * s[1] + s[2]) / (2 * h)
        d2 = (2 * s[0] - 5 * s[1] + 4 * s[2] - s[3]) / h**2
        d3 = (-5 * s[0] + 18 * s[1] - 24 * s[2] + 14 * s[3] - 3 * s[4]) / (2 * h**3)  # second order too
        return np.array([sign * d1, d2, sign * -d3])

    return d(left, 1.0), d(right, -1.0)


@pytest.mark.parametrize("first, second, ends, orders", [
    ("poly5", "poly5", (9.0, -20.0, None), 2),
    ("poly7", "poly7", (9.0, -20.0, 150.0), 3),
    ("poly5", "poly7", (9.0, -20.0, 150.0), 2),
])
def test_joint_is_continuous_by_construction(first, second, ends, orders):
    """S (the cumulative lift 6), S′ and S″ (and S‴ for poly7–poly7) agree across the joint and equal the given
    values, per radian — seen by one-sided finite differences of S on each side, not by the coefficients.  The
    ends of the pair meet the dwells at rest."""
    p = _program(first, second, ends)
    x = math.radians(JOINT_DEG)
    assert float(p.evaluate(np.array([x]), (0,))[0][0]) == pytest.approx(6.0, abs=1e-12)
    left, right = _one_sided(p, x, 1e-3)
    want = np.array([e if e is not None else np.nan for e in ends])
    tol = np.array([1e-4, 1e-2, 2.0])
    for k in range(orders):
        assert left[k] == pytest.approx(right[k], abs=tol[k])
        assert left[k] == pytest.approx(want[k], abs=tol[k])
    if first == second == "poly5":  # the differences do see a jump: S‴ is not matched between two quintics
        assert abs(left[2] - right[2]) > 3 * tol[2]
    exact = [p.evaluate(np.array([x - 1e-12, x + 1e-12]), (k,))[0] for k in (1, 2, 3)]
    for k in range(orders):
        assert exact[k][0] == pytest.approx(exact[k][1], rel=1e-6, abs=1e-6)
    for deg in (90.0, 180.0):  # at rest where the pair meets the dwells
        ends_at = [p.evaluate(np.array([math.radians(deg)]), (k,))[0][0] for k in (1, 2)]
        assert ends_at == pytest.approx([0.0, 0.0], abs=1e-9)


def _data(motion, **extra) -> dict:
    return {"name": "joint", "cam": {"kind": "disc", "speed_rpm": 100},
            "follower": {"type": "roller", "motion": "translating", "base_radius_mm": 40.0, "roller_radius_mm": 8.0},
            "motion": motion, **extra}


RISE = [{"law": "dwell", "lift": 0, "angle_deg": 90}, {"law": "poly5", "lift": 5, "angle_deg": 45},
        {"law": "poly5", "lift": 5, "angle_deg": 45}, {"law": "cycloidal", "lift": -10, "angle_deg": 180}]


def _paths(exc: SpecError) -> dict[str, str]:
    return {p.path: f"{p.rule}; {p.fix}" for p in exc.problems}


def test_design_keys_and_refusals():
    """From a design dict: the keys build the program; without them the refusal names them as the fix; on a
    generic followed by a standard law they are refused (that law fixes the joint); a missing end_a, a stray end_j
    (poly5–poly5), a non-number and an absurd value each name their field."""
    rise = [dict(s) for s in RISE]
    rise[1].update(end_v=8.0, end_a=0.0)
    spec = design_from_dict(_data(rise))
    x = math.radians(135.0)
    assert spec.program().evaluate(np.array([x]), (1,))[0][0] == pytest.approx(8.0, abs=1e-12)

    with pytest.raises(SpecError) as e:
        design_from_dict(_data([dict(s) for s in RISE])).program()
    fix = _paths(e.value)["motion[2].law"]
    assert "may not be adjacent" in fix and "end_v, end_a on motion[1]" in fix

    bad = [dict(s) for s in RISE]
    bad[2].update(end_v=1.0)  # poly5 followed by the cycloidal return
    bad[1].update(end_v=8.0, end_j=1.0)  # no end_a; end_j between two poly5
    with pytest.raises(SpecError) as e:
        design_from_dict(_data(bad)).program()
    got = _paths(e.value)
    assert "fixes the joint" in got["motion[2].end_v"] and "remove end_v" in got["motion[2].end_v"]
    assert "is required" in got["motion[1].end_a"] and "per radian²" in got["motion[1].end_a"]
    assert "poly7" in got["motion[1].end_j"]

    bad = [dict(s) for s in RISE]
    bad[1].update(end_v="fast", end_a=1e12)
    with pytest.raises(SpecError) as e:
        design_from_dict(_data(bad)).program()
    got = _paths(e.value)
    assert "must be a number" in got["motion[1].end_v"] and "input limit" in got["motion[1].end_a"]

    bad = [dict(s) for s in RISE]
    bad[0].update(end_v=1.0)
    bad[1].update(end_v=8.0, end_a=0.0)
    with pytest.raises(SpecError) as e:
        design_from_dict(_data(bad)).program()
    assert "generic polynomial" in _paths(e.value)["motion[0].end_v"]


def test_optimise_joint_values_lowers_peak_acceleration():
    """A 10 mm rise over 90° split into two poly5 pieces, started from a poor joint (S′ = 8 mm/rad, S″ = 0): freeing
    motion[1].end_v and motion[1].end_a lowers the peak acceleration, never above the start, the constraints met
    (no undercut, the pressure-angle limit), and the written design reproduces the measures."""
    rise = [dict(s) for s in RISE]
    rise[1].update(end_v=8.0, end_a=0.0)
    data = _data(rise, optimise={"variables": [{"name": "motion[1].end_v", "lo": 2.0, "hi": 16.0},
                                               {"name": "motion[1].end_a", "lo": -40.0, "hi": 40.0}],
                                 "objectives": {"peak_acceleration": 1.0}})
    prob = build_problem(data, design_from_dict(data))
    res = solve(prob)
    assert res.score <= res.score_start
    assert res.best["peak_acceleration"] < 0.9 * res.start["peak_acceleration"]
    again = measure(design_from_dict(res.data))
    assert again == pytest.approx(res.best)
    assert again["min_radius_mm"] >= 0.0 and again["peak_pressure_angle_deg"] <= 30.0 + 1e-9
    assert 2.0 <= res.data["motion"][1]["end_v"] <= 16.0 and -40.0 <= res.data["motion"][1]["end_a"] <= 40.0


def test_optimise_names_a_missing_joint_value():
    rise = [dict(s) for s in RISE]
    rise[1].update(end_v=8.0, end_a=0.0)
    data = _data(rise, optimise={"variables": [{"name": "motion[2].end_v", "lo": 2.0, "hi": 16.0}],
                                 "objectives": {"peak_acceleration": 1.0}})
    with pytest.raises(SpecError) as e:
        build_problem(data, design_from_dict(data))
    assert "optimise.variables[0].name" in _paths(e.value)


def test_joint_values_survive_the_design_workbook(tmp_path):
    """A design with joint values written as a design workbook and read back keeps them (the motion sheet's
    end_v/end_a columns), so the program is the same."""
    from camfab.formats.xlsx_design import design_to_xlsx, load_design_xlsx

    rise = [dict(s) for s in RISE]
    rise[1].update(end_v=8.0, end_a=0.5)
    spec = design_from_dict(_data(rise))
    (tmp_path / "d.xlsx").write_bytes(design_to_xlsx(spec))
    back = load_design_xlsx(tmp_path / "d.xlsx")
    assert back.motion[1].ends == (8.0, 0.5, None) and back.motion[2].ends == (None, None, None)
    x = np.linspace(0, 2 * np.pi, 721)
    np.testing.assert_array_equal(back.program().evaluate(x, (2,))[0], spec.program().evaluate(x, (2,))[0])


def test_cli_refuses_a_bad_joint_value_with_exit_2(tmp_path, capsys):
    """A non-number joint value in a TOML design: exit 2 naming motion[1].end_a, no traceback."""
    from camfab.cli import main

    rows = "".join(f'\n[[motion]]\nlaw = "{s["law"]}"\nlift = {s["lift"]}\nangle_deg = {s["angle_deg"]}\n'
                   for s in RISE)
    rows = rows.replace("lift = 5\nangle_deg = 45\n", 'lift = 5\nangle_deg = 45\nend_v = 8.0\nend_a = "x"\n', 1)
    p = tmp_path / "joint.toml"
    p.write_text('name = "joint"\n[cam]\nkind = "disc"\nspeed_rpm = 100\n[follower]\ntype = "roller"\n'
                 'motion = "translating"\nbase_radius_mm = 40.0\nroller_radius_mm = 8.0\n' + rows, encoding="utf-8")
    assert main(["check", str(p)]) == 2
    err = capsys.readouterr().err
    assert "motion[1].end_a" in err and "Traceback" not in err
    p.write_text(p.read_text(encoding="utf-8").replace('end_a = "x"', "end_a = 0.0"), encoding="utf-8")
    assert main(["check", str(p)]) == 0
