"""Knot-table motions (camfab.design.knots): interpolation, units, closure, validation, files."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import openpyxl
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from camfab.design.knots import KnotFile, KnotTable, build_knot_table
from camfab.design.program import MotionProgram
from camfab.errors import SpecError
from camfab.formats import load_design, load_motion_table, read_knot_file, read_knots_csv, read_knots_xlsx
from camfab.results import Finding

EXAMPLES = Path(__file__).resolve().parents[2] / "camfab" / "examples"
VALVE_UNITS = {"angle": "deg", "s": "m", "v": "m/s", "a": "m/s2"}
OMEGA_1500 = 1500 * 2 * math.pi / 60
REL = 1e-9


# ---------------------------------------------------------------------------
# helpers
def fourier(theta: np.ndarray, coef: np.ndarray, nu: int) -> np.ndarray:
    """nu-th derivative of s = c0 + Σ a_k cos kθ + b_k sin kθ (coef rows: k, a_k, b_k)."""
    out = np.full_like(theta, coef[0, 0] if nu == 0 else 0.0, dtype=float)
    for k, a, b in coef[1:]:
        ph = nu * math.pi / 2
        out += k**nu * (a * np.cos(k * theta + ph) + b * np.sin(k * theta + ph))
    return out


def smooth_coef(amps: list[float]) -> np.ndarray:
    """A smooth periodic lift with harmonics 1..len(amps)//2, kept above 0."""
    pairs = np.asarray(amps, dtype=float).reshape(-1, 2)
    c0 = 2.0 * np.abs(pairs).sum() + 1.0
    rows = [[c0, 0.0, 0.0]] + [[k + 1, a, b] for k, (a, b) in enumerate(pairs)]
    return np.array(rows)


def sampled_rows(coef: np.ndarray, angles_deg: np.ndarray, degree: int) -> list[list[float]]:
    """Knot rows (deg, mm, mm/rad, mm/rad2[, mm/rad3]) sampled from the Fourier lift."""
    th = np.radians(angles_deg)
    cols = [fourier(th, coef, nu) for nu in range(4 if degree == 7 else 3)]
    return np.column_stack([angles_deg, *cols]).tolist()


RAD_UNITS = {"angle": "deg", "s": "mm", "v": "mm/rad", "a": "mm/rad2", "j": "mm/rad3"}


def table(rows, degree=5, units=RAD_UNITS, **kw) -> KnotTable:
    return build_knot_table({"rows": rows, "units": units, "degree": degree, **kw})


def assert_reproduces_knots(t: KnotTable, prog: MotionProgram) -> None:
    """Both one-sided limits at every knot equal the knot values (per radian)."""
    x, vals = t.cycle_knots()
    m = 3 if t.degree == 5 else 4
    scale = np.abs(vals[:, :m]).max(axis=0)
    # a derivative that is ~0 everywhere (tiny harmonics on a large lift) is judged against the lift's size:
    # its rounding errors scale with S, not with itself
    scale = np.maximum(scale, 1e-9 * max(scale[0], 1e-300))
    right = prog.evaluate(x[:-1], range(m)).T
    left = np.array([seg.end_values(True)[:m] for seg in prog.segments])
    np.testing.assert_array_less(np.abs(right - vals[:-1, :m]) / scale, REL)
    np.testing.assert_array_less(np.abs(left - vals[1:, :m]) / scale, REL)


def assert_continuity(prog: MotionProgram, order: int) -> None:
    peaks = prog.peaks("exact")
    scale = np.array([max(abs(p.max), abs(p.min), 1e-12) for p in peaks])
    scale = np.maximum(scale, 1e-9 * scale[0])  # see assert_reproduces_knots
    for k, seg in enumerate(prog.segments):
        left = prog.segments[k - 1].end_values(True)
        right = seg.end_values(False)
        jumps = np.abs(right - left)[: order + 1] / scale[: order + 1]
        assert np.all(jumps < REL), (k, jumps)
    assert all(j.order >= order for j in prog.junctions())


def valve(name: str) -> KnotTable:
    return load_motion_table({"file": name, "units": VALVE_UNITS, "speed_rpm": 1500, "degree": 5},
                             base_dir=EXAMPLES)


# ---------------------------------------------------------------------------
# interpolation and continuity
COEF = smooth_coef([2.0, -1.0, 0.5, 0.8, -0.3, 0.2])
ANGLES = np.array([0.0, 15, 40, 75, 90, 130, 180, 200, 250, 300, 330])


@pytest.mark.parametrize("degree", [5, 7])
@pytest.mark.parametrize("closed", [False, True])
def test_program_reproduces_every_knot_and_is_smooth(degree, closed):
    angles = np.append(ANGLES, 360.0) if closed else ANGLES
    t = table(sampled_rows(COEF, angles, degree), degree)
    prog = t.program()
    assert t.closed is closed
    assert len(prog.segments) == len(ANGLES)
    assert {s.law for s in prog.segments} == {f"hermite{degree}"}
    assert prog.segments[-1].end == pytest.approx(2 * math.pi, abs=1e-15)
    assert_reproduces_knots(t, prog)
    assert_continuity(prog, 2 if degree == 5 else 3)


def test_segment_data_follow_the_contract():
    t = table(sampled_rows(COEF, ANGLES, 5))
    seg = t.program().segments[3]
    assert seg.title == "Quintic Hermite knot segment"
    assert seg.start == pytest.approx(math.radians(75))
    assert seg.span == pytest.approx(math.radians(15))
    assert seg.s0 == pytest.approx(t.values[3, 0])
    assert seg.lift == pytest.approx(t.values[4, 0] - t.values[3, 0])
    assert len(seg.coeffs) == 6
    assert len(table(sampled_rows(COEF, ANGLES, 7), 7).program().segments[0].coeffs) == 8


def test_quintic_is_exact_for_a_quintic_and_jerk_jumps():
    # one quintic over the whole rise: the knot motion must reproduce it in between too
    rows = [[0, 0, 0, 0], [90, 10, 0, 0], [180, 0, 0, 0]]
    prog = table(rows).program()
    u = np.linspace(0, 1, 7)
    expected = 10 * (10 * u**3 - 15 * u**4 + 6 * u**5)
    np.testing.assert_allclose(prog(u * math.pi / 2), expected, rtol=0, atol=1e-12)
    assert prog(np.radians([270.0]))[0] == 0.0
    junction = {round(math.degrees(j.at)): j.order for j in prog.junctions()}
    assert junction[90] == 2


def test_dense_smooth_knots_raise_no_warning():
    angles = np.arange(0.0, 360.0, 10.0)
    for degree in (5, 7):
        assert table(sampled_rows(COEF, angles, degree), degree).warnings() == []


# ---------------------------------------------------------------------------
# units
def test_time_units_equal_per_radian_units():
    rows_m = [[0, 0, 0, 0], [20, 0, 0, 0], [30, 0.0005, 0.4744, 1017.9], [110, 0.009, 0, 0],
              [130, 0.009, 0, 0], [200, 0, 0, 0]]
    a = build_knot_table({"rows": rows_m, "units": VALVE_UNITS, "speed_rpm": 1500})
    w = OMEGA_1500
    rows_mm = [[th, s * 1e3, v * 1e3 / w, acc * 1e3 / w**2] for th, s, v, acc in rows_m]
    b = table(rows_mm)
    np.testing.assert_allclose(a.values, b.values, rtol=1e-14, atol=0)
    x = np.linspace(0, 2 * np.pi, 721)
    np.testing.assert_allclose(a.program().evaluate(x), b.program().evaluate(x), rtol=1e-12, atol=1e-12)


def test_every_unit_spelling_converts_to_mm_per_radian():
    coef = smooth_coef([1.0, 0.5, -0.4, 0.3])
    base = np.array(sampled_rows(coef, ANGLES, 7))  # deg, mm, mm/rad, mm/rad2, mm/rad3
    ref = table(base.tolist(), 7)
    d = math.pi / 180
    w = 2.0 * math.pi * 600 / 60
    variants = {
        ("rad", "m", "mm/deg", "mm/deg2", "mm/deg3"): [d, 1e-3, d, d**2, d**3],
        ("deg", "mm", "mm/s", "mm/s^2", "mm/s³"): [1, 1, w, w**2, w**3],
        ("deg", "m", "m/s", "m/s2", "m/s3"): [1, 1e-3, 1e-3 * w, 1e-3 * w**2, 1e-3 * w**3],
    }
    for (ang, s, v, acc, j), f in variants.items():
        rows = base * np.array(f)
        t = table(rows.tolist(), 7, {"angle": ang, "s": s, "v": v, "a": acc, "j": j}, speed_rpm=600)
        np.testing.assert_allclose(t.angles, ref.angles, rtol=1e-14)
        np.testing.assert_allclose(t.values, ref.values, rtol=1e-12)


def test_default_units_and_derived_family():
    t = build_knot_table({"rows": [[0, 0, 0, 0], [180, 1, 0, 0]]})
    assert dict(t.units) == {"angle": "deg", "s": "mm", "v": "mm/deg", "a": "mm/deg2", "j": "mm/deg3"}
    t = build_knot_table({"rows": [[0, 0, 0, 0, 0], [180, 1, 0, 0, 0]], "degree": 7, "speed_rpm": 100,
                           "units": {"s": "m", "a": "m/s2"}})
    assert t.units["v"] == "m/s" and t.units["j"] == "m/s3"


# ---------------------------------------------------------------------------
# cycle closure
def test_open_table_closes_back_to_the_first_row():
    rows = sampled_rows(COEF, ANGLES, 5)
    open_ = table(rows).program()
    closed = table(rows + [[360.0, *rows[0][1:]]]).program()
    x = np.linspace(0, 2 * np.pi, 1441)
    np.testing.assert_allclose(open_.evaluate(x), closed.evaluate(x), rtol=0, atol=1e-9)
    assert_continuity(open_, 2)


def test_single_row_table_is_a_dwell():
    prog = table([[0, 2.0, 0, 0]]).program()
    assert len(prog.segments) == 1
    np.testing.assert_allclose(prog(np.linspace(0, 7, 50)), 2.0)


def test_closing_row_must_repeat_the_first():
    rows = [[0, 0, 0, 0], [90, 5, 0, 0], [180, 0, 0, 0], [360, 0, 1.0, 0]]
    with pytest.raises(SpecError, match=r"motion_table\.rows\[3\]\[2\].*repeat the 0 row") as exc:
        table(rows)
    assert len(exc.value.problems) == 1


# ---------------------------------------------------------------------------
# the valve case (CASO 3, LEVA TIPO 8): its printed PUNTOS matrices of Examples 1 and 2
PRINTED_EJ1_ROW_30 = [30, 0.0005, 0.4744, 1017.9]
PRINTED_EJ2_ROW_170 = [170, 0.0040, -2.0987, 277.2]


@pytest.mark.parametrize("name, row", [("valve_puntos_ej1.csv", PRINTED_EJ1_ROW_30),
                                       ("valve_puntos_ej2.csv", PRINTED_EJ2_ROW_170)])
def test_printed_puntos_load_evaluate_and_warn(name, row):
    raw = read_knots_csv(EXAMPLES / name)
    assert len(raw) == 21 and raw[0] == [0, 0, 0, 0] and raw[-1] == [360, 0, 0, 0]
    assert row in raw
    t = valve(name)
    assert t.closed
    prog = t.program(check=False)
    assert_reproduces_knots(t, prog)
    assert_continuity(prog, 2)
    s = prog(np.radians([0.0, 110.0, 120.0, 250.0]))
    np.testing.assert_allclose(s, [0, 9, 9, 0], atol=1e-12)
    # velocity at 30° in m/s at 1500 rpm
    assert prog(np.radians(30.0), 1)[0] * OMEGA_1500 / 1e3 == pytest.approx(raw[6][2], rel=1e-12)

    warns = t.warnings()
    assert warns, "rounded knots must be flagged"
    # implied peak (value) over the largest knot value (limit), of the acceleration
    assert all(isinstance(w, Finding) and w.value / w.limit > 5 and "the acceleration implied" in w.message
               for w in warns)
    ramp = [w for w in warns if 22 <= w.from_deg < 28]
    assert ramp and all(f"{w.value:.6g} m/s2," in w.message for w in ramp)
    # the mirrored seating ramp is flagged as well
    assert {round(w.from_deg) for w in warns} >= {22, 24, 194, 196}
    segments = [int(w.message.split()[1]) for w in warns]
    assert segments == sorted(segments) and all(w.to_deg > w.from_deg for w in warns)
    d = warns[0].to_dict()
    assert d["code"] == "KNOT_INCONSISTENT" and d["severity"] == "warning"
    assert {"code", "severity", "from_deg", "to_deg", "value", "limit", "message"} == set(d)
    assert "inconsistent" in d["message"]
    # interpolated as printed the valve accelerates at > 10 000 m/s² (docs/decisions.md, "knot tables")
    peak_a = max(abs(p) for p in (prog.peaks()[2].max, prog.peaks()[2].min)) * OMEGA_1500**2 / 1e3
    assert peak_a > 10_000


@pytest.mark.parametrize("name", ["valve_puntos_ej1.csv", "valve_puntos_ej2.csv"])
def test_printed_puntos_dip_below_the_base_circle(name):
    t = valve(name)
    assert t.program(check=False).peaks("exact")[0].min < -0.01  # mm
    with pytest.raises(SpecError, match=r"rows\[1\].*S goes below 0.*between rows 1 and 2") as exc:
        t.program()
    assert [p.path for p in exc.value.problems] == ["motion_table.rows[1]", "motion_table.rows[18]"]
    assert name in str(exc.value)


def test_full_precision_reconstruction_is_consistent():
    # minimum-jerk s values (mm) that round back to every printed value of Example 1
    # (docs/decisions.md, "knot tables")
    rec = {22: 0.039, 24: 0.155, 26: 0.279, 28: 0.395, 140: 8.775, 150: 7.928, 160: 6.488,
           170: 4.530, 180: 2.122, 192: 0.395, 194: 0.279, 196: 0.155, 198: 0.039}
    printed = read_knots_csv(EXAMPLES / "valve_puntos_ej1.csv")
    rows = [[r[0], rec.get(r[0], r[1] * 1e3) / 1e3, *r[2:]] for r in printed]
    t = build_knot_table({"rows": rows, "units": VALVE_UNITS, "speed_rpm": 1500})
    assert t.warnings() == []
    assert t.program().peaks("exact")[0].min >= -1e-12


def test_shipped_toml_example_uses_the_consistent_reconstruction():
    spec = load_design(EXAMPLES / "valve_exhaust_ej1.toml")
    assert spec.name == "ValveExhaustEj1" and spec.follower.base_radius_mm == 24.0
    t = spec.knot_table
    assert t.source == str(EXAMPLES / "valve_recon_ej1.csv")
    assert spec.sources == (str(EXAMPLES / "valve_exhaust_ej1.toml"), t.source)
    assert t.warnings() == []
    # every printed (rounded) value is reproduced by the reconstruction
    printed = valve("valve_puntos_ej1.csv").values
    # values are internal (s in mm, derivatives per radian): s rounds to the printed 0.1 mm
    np.testing.assert_allclose(np.round(t.values[:, 0], 1), printed[:, 0], atol=1e-9)
    np.testing.assert_array_equal(t.values[:, 1:], printed[:, 1:])
    # the valve case builds 30°→110° as one quintic; from its printed end conditions (derived) it
    # peaks at v ≈ 1.66 m/s near 53.5°
    v = spec.program().peaks("exact")[1]
    assert v.max * spec.speed / 1e3 == pytest.approx(1.66, abs=0.005)
    assert np.degrees(v.at_max) == pytest.approx(53.5, abs=0.1)


# ---------------------------------------------------------------------------
# validation: every rule names its field; all problems at once
GOOD = [[0, 0, 0, 0], [90, 5, 0, 0], [180, 0, 0, 0]]


@pytest.mark.parametrize("change, pattern", [
    ({"rows": [[0, 0, 0, 0], [90, float("nan"), 0, 0], [180, 0, 0, 0]]}, r"rows\[1\]\[1\].*finite"),
    ({"rows": [[0, 0, 0, 0], [90, 5, 0, float("inf")], [180, 0, 0, 0]]}, r"rows\[1\]\[3\].*finite"),
    ({"rows": [[0, 0, 0, 0], [90, "5", 0, 0], [180, 0, 0, 0]]}, r"rows\[1\]\[1\].*finite"),
    ({"rows": [[0, 0, 0, 0], [90, 5, 0, 0], [90, 0, 0, 0]]}, r"rows\[2\]\[0\].*increase strictly"),
    ({"rows": [[0, 0, 0, 0], [90, 5, 0], [180, 0, 0, 0]]}, r"rows\[1\] = .*4 numbers"),
    ({"rows": [[0, 0, 0, 0], [90, 5, 0, 0, 0, 0], [180, 0, 0, 0]]}, r"rows\[1\] = .*4 numbers"),
    ({"rows": [[10, 0, 0, 0], [90, 5, 0, 0]]}, r"rows\[0\]\[0\].*start at angle 0"),
    ({"rows": [[0, 0, 0, 0], [90, 5, 0, 0], [400, 0, 0, 0]]}, r"rows\[2\]\[0\].*one revolution"),
    ({"rows": [[0, 0, 0, 0], [90, -0.5, 0, 0], [180, 0, 0, 0]]}, r"rows\[1\]\[1\].*below 0"),
    ({"rows": []}, r"motion_table\.rows.*no rows"),
    ({"units": {"v": "km/h"}}, r"units\.v = 'km/h'.*mm/deg, mm/rad, m/s, mm/s"),
    ({"units": {"a": "mm/deg^4"}}, r"units\.a.*mm/deg2, mm/rad2, m/s2, mm/s2"),
    ({"units": {"angle": "grad"}}, r"units\.angle.*deg, rad"),
    ({"units": {"q": "mm"}}, r"units\.q.*unknown column"),
    ({"units": {"v": "m/s", "a": "m/s2"}}, r"motion_table\.speed_rpm = None.*time units.*v = m/s"),
    ({"units": {"v": "m/s", "a": "m/s2"}, "speed_rpm": -3}, r"speed_rpm = -3.*> 0"),
    ({"degree": 6}, r"motion_table\.degree = 6.*5.*7"),
    ({"degree": True}, r"motion_table\.degree = True"),
    ({"degree": 7}, r"rows\[0\]\[4\].*degree 7 needs the jerk"),
    ({"file": "x.csv"}, r"exactly one of rows and file"),
    ({"speed": 1500}, r"motion_table\.speed = 1500.*unknown key"),
])
def test_each_rule_names_its_field(change, pattern):
    spec = {"rows": GOOD, **change}
    with pytest.raises(SpecError, match=pattern):
        build_knot_table(spec)


def test_radian_tables_are_checked_against_two_pi():
    ok = build_knot_table({"rows": [[0, 0, 0, 0], [math.pi, 5, 0, 0], [2 * math.pi, 0, 0, 0]],
                            "units": {"angle": "rad"}})
    assert ok.closed
    with pytest.raises(SpecError, match=r"rows\[2\]\[0\].*6\.28318"):
        build_knot_table({"rows": [[0, 0, 0, 0], [3, 5, 0, 0], [7, 0, 0, 0]], "units": {"angle": "rad"}})


def test_all_problems_are_reported_at_once():
    spec = {"rows": [[5, -1, 0, 0], [3, 2, float("nan"), 0], [90, 1]], "units": {"v": "m/s", "s": "ft"},
            "degree": 4, "extra": 1}
    with pytest.raises(SpecError) as exc:
        build_knot_table(spec)
    paths = {p.path for p in exc.value.problems}
    assert paths >= {"motion_table.extra", "motion_table.degree", "motion_table.units.s",
                     "motion_table.speed_rpm", "motion_table.rows[2]", "motion_table.rows[1][2]",
                     "motion_table.rows[0][0]", "motion_table.rows[1][0]", "motion_table.rows[0][1]"}
    assert "problems in the design" in str(exc.value)


def test_program_below_zero_is_rejected_with_the_segment():
    rows = [[0, 0, 0, 0], [10, 0, 5.0, 0], [90, 5, 0, 0], [180, 0, 0, 0]]  # s = 0 but v > 0 at 10°
    t = table(rows)
    with pytest.raises(SpecError, match=r"motion_table\.rows\[0\].*S goes below 0") as exc:
        t.program()
    assert len(exc.value.problems) == 1
    assert t.program(check=False).peaks("exact")[0].min < 0


def test_jerk_warning_for_degree_7():
    rows = [[0, 0, 0, 0, 0], [90, 5, 0, 0, 0.01], [180, 0, 0, 0, -0.01]]
    warns = table(rows, 7).warnings()
    assert warns and all("the jerk implied" in w.message for w in warns)
    assert all(f"{w.value:.6g} mm/rad3," in w.message for w in warns)


def test_degree_5_ignores_a_jerk_column():
    rows5 = sampled_rows(COEF, ANGLES, 5)
    rows7 = sampled_rows(COEF, ANGLES, 7)
    x = np.linspace(0, 2 * np.pi, 100)
    np.testing.assert_array_equal(table(rows5).program().evaluate(x), table(rows7).program().evaluate(x))


# ---------------------------------------------------------------------------
# files
CSV_FORMATS = {
    "comma.csv": "# a comment\nangle,s,v,a\n0,0,0,0\n90,5.5,0,0,\n\n180,0,0,0\n",
    "semicolon.csv": "angle;s;v;a\n0;0;0;0\n90;5,5;0;0\n180;0;0;0\n",
    "spaces.txt": "PUNTOS=\n  0   0   0   0\n 90   5.5 0   0\n180\t0\t0\t0\n",
    "spaces_decimal_comma.txt": "% matlab\n0 0 0 0\n90 5,5 0 0\n180 0 0 0\n",
    "comma_spaces.csv": "0, 0, 0, 0\n90, 5.5, 0, 0\n180, 0, 0, 0\n",
}


@pytest.mark.parametrize("name", CSV_FORMATS)
def test_csv_dialects(tmp_path, name):
    f = tmp_path / name
    f.write_text(CSV_FORMATS[name], encoding="utf-8")
    assert read_knots_csv(f) == [[0, 0, 0, 0], [90, 5.5, 0, 0], [180, 0, 0, 0]]


def test_csv_with_utf8_bom_and_jerk_column(tmp_path):
    f = tmp_path / "bom.csv"
    f.write_bytes("\ufeffangle,s,v,a,j\n0,0,0,0,0\n180,1,0,0,0\n".encode())
    assert read_knots_csv(f) == [[0, 0, 0, 0, 0], [180, 1, 0, 0, 0]]


def test_xlsx_round_trip(tmp_path):
    rows = sampled_rows(COEF, ANGLES, 7)
    wb = openpyxl.Workbook()
    ws = wb.active
    ws.append(["angle_deg", "s_mm", "v_mm_rad", "a_mm_rad2", "j_mm_rad3", "note"])
    for r in rows:
        ws.append([*r, "ignored"])
    ws.append([])
    wb.create_sheet("other").append(["not", "read"])
    f = tmp_path / "knots.xlsx"
    wb.save(f)
    # openpyxl stores floats with 15-16 significant digits
    np.testing.assert_allclose(read_knots_xlsx(f), rows, rtol=1e-15, atol=1e-15)
    t = load_motion_table({"file": "knots.xlsx", "units": RAD_UNITS, "degree": 7}, base_dir=tmp_path)
    x = np.linspace(0, 2 * np.pi, 200)
    got, want = t.program().evaluate(x), table(rows, 7).program().evaluate(x)
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-12 * np.abs(want).max())


def test_xlsx_four_columns_and_text_numbers(tmp_path):
    wb = openpyxl.Workbook()
    for r in ([0, 0, 0, 0], [90, "5,5", 0, 0], [180, 0, 0, 0]):
        wb.active.append(r)
    f = tmp_path / "four.xlsx"
    wb.save(f)
    assert read_knots_xlsx(f) == [[0, 0, 0, 0], [90, 5.5, 0, 0], [180, 0, 0, 0]]


def test_xlsx_non_numeric_cells_are_named(tmp_path):
    wb = openpyxl.Workbook()
    for r in (["angle", "s", "v", "a"], [0, 0, 0, 0], [90, "five", 0, None]):
        wb.active.append(r)
    f = tmp_path / "bad.xlsx"
    wb.save(f)
    with pytest.raises(SpecError, match=r"bad\.xlsx.*B3, D3"):
        read_knots_xlsx(f)


@pytest.mark.parametrize("name, content, pattern", [
    ("corrupt.xlsx", b"PK\x03\x04 this is not a zip archive", r"corrupt\.xlsx.*not a readable xlsx.*re-save"),
    ("text.xlsx", b"angle,s,v,a\n0,0,0,0\n", r"text\.xlsx.*not a readable xlsx"),
    ("garbage.csv", b"angle,s,v,a\n0,0,0,0\n90,five,0,0\n", r"garbage\.csv.*line 3.*not a row of numbers"),
    ("binary.csv", b"\xff\xfe\x00\x01\x80\x81", r"binary\.csv.*UTF-8"),
    ("empty.csv", b"# only a comment\n\n", r"empty\.csv.*no knot rows"),
    ("table.ods", b"", r"table\.ods.*unknown knot-file type"),
])
def test_bad_files_give_spec_errors_naming_the_file(tmp_path, name, content, pattern):
    (tmp_path / name).write_bytes(content)
    with pytest.raises(SpecError, match=pattern) as exc:
        load_motion_table({"file": name}, base_dir=tmp_path)
    assert exc.value.problems[0].path == "motion_table.file"
    assert exc.value.problems[0].fix


def test_missing_file_is_named_and_other_problems_still_reported(tmp_path):
    with pytest.raises(SpecError, match=r"nothere\.csv.*file not found") as exc:
        load_motion_table({"file": "nothere.csv", "degree": 3}, base_dir=tmp_path)
    assert {p.path for p in exc.value.problems} == {"motion_table.file", "motion_table.degree"}
    with pytest.raises(SpecError, match=r"nothere\.xlsx.*file not found"):
        read_knots_xlsx(tmp_path / "nothere.xlsx")


def test_file_rows_are_validated_with_the_file_named(tmp_path):
    f = tmp_path / "bad_rows.csv"
    f.write_text("0,0,0,0\n90,-1,0,0\n", encoding="utf-8")
    with pytest.raises(SpecError, match=r"(?s)bad_rows\.csv.*rows\[1\]\[1\] = -1\.0"):
        load_motion_table({"file": str(f)})


def test_knot_file_is_read_into_a_value_the_core_validates(tmp_path):
    f = tmp_path / "k.csv"
    f.write_text("angle,s,v,a\n0,0,0,0\n90,5,0,0\n180,0,0,0\n", encoding="utf-8")
    kf = read_knot_file("k.csv", tmp_path)
    assert kf == KnotFile("k.csv", str(f), ((0, 0, 0, 0), (90, 5, 0, 0), (180, 0, 0, 0)))
    assert str(kf) == "k.csv"
    t = build_knot_table({"file": kf})
    assert t.source == str(f) and float(t.program()(np.pi / 2)[0]) == pytest.approx(5.0)
    missing = read_knot_file("gone.csv", tmp_path)
    assert missing.rows is None and [p.path for p in missing.problems] == ["motion_table.file"]
    with pytest.raises(SpecError, match=r"gone\.csv.*file not found") as exc:
        build_knot_table({"file": missing, "degree": 3})
    assert [p.path for p in exc.value.problems] == ["motion_table.file", "motion_table.degree"]


def test_the_core_reads_no_file(tmp_path, monkeypatch):
    (tmp_path / "k.csv").write_text("0,0,0,0\n90,5,0,0\n", encoding="utf-8")
    monkeypatch.chdir(tmp_path)  # the file is there, yet the core does not open it
    with pytest.raises(SpecError, match=r"motion_table\.file = 'k\.csv'.*has not been read.*camfab\.formats"):
        build_knot_table({"file": "k.csv"})
    with pytest.raises(SpecError, match=r"motion_table\.file = 3.*must be a path"):
        build_knot_table({"file": 3})


def test_a_design_reads_its_knot_file_once(monkeypatch):
    import camfab.formats.knot_files as knot_files
    from camfab.design.assemble import check_design
    from camfab.formats import design_to_xlsx

    calls = []
    real = knot_files.read_knots
    monkeypatch.setattr(knot_files, "read_knots", lambda *a, **k: calls.append(a) or real(*a, **k))
    spec = load_design(EXAMPLES / "valve_exhaust_ej1.toml")
    check_design(spec)
    design_to_xlsx(spec)
    assert spec.program() is spec.program() and spec.knot_table is spec.knot_table
    assert len(calls) == 1


# ---------------------------------------------------------------------------
# property: random consistent knots from a smooth periodic lift
@settings(max_examples=60, deadline=None)
@given(
    amps=st.lists(st.floats(-3, 3, allow_nan=False), min_size=2, max_size=6).filter(lambda a: len(a) % 2 == 0),
    cuts=st.lists(st.integers(1, 3599), min_size=1, max_size=14, unique=True),
    degree=st.sampled_from([5, 7]),
    closed=st.booleans(),
)
@example(amps=[0.0, 1e-13, 0.0, 1e-13], cuts=[1], degree=7, closed=False)  # ~zero derivatives on a 1 mm lift
def test_program_passes_through_random_consistent_knots(amps, cuts, degree, closed):
    coef = smooth_coef(amps)
    angles = np.concatenate([[0.0], np.sort(cuts) / 10.0, [360.0] if closed else []])
    t = table(sampled_rows(coef, angles, degree), degree)
    prog = t.program(check=False)
    assert_reproduces_knots(t, prog)
    assert_continuity(prog, 2 if degree == 5 else 3)
    # periodic: one revolution later the motion repeats
    x = np.linspace(0, 2 * np.pi, 37) + 0.0123  # off the knots: S‴ may jump there (degree 5)
    np.testing.assert_allclose(prog.evaluate(x + 2 * np.pi), prog.evaluate(x), rtol=1e-9, atol=1e-9)
