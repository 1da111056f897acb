"""Follower vibration (docs/decisions.md, "Follower vibration"): the single-mass elastic train's periodic
steady state against closed forms (a harmonic input; Duhamel's integral for a cycloidal rise), a long
``solve_ivp`` integration, the energy balance, the rigid limit, the separation speed, ``check --json`` and
the ``[vibration]`` table's refusals."""
from __future__ import annotations

import copy
import json
import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from camfab.cli import main
from camfab.design.assemble import check_design, loads_from_spec
from camfab.design.dynamics import ContactDynamics, Loads, analyse_dynamics
from camfab.design.mechanisms import geometry_from_spec
from camfab.design.spec import design_from_dict
from camfab.design.vibration import FollowerTrain, Train, analyse_vibration
from camfab.errors import SpecError
from camfab.results import IssueCode
from camfab.units import RPM

RPM_DESIGN = 1500.0
OMEGA = RPM_DESIGN * RPM
M, KS, F0 = 0.2, 20e3, 300.0  # kg, N/m, N


def _design(rows, *, vibration=None, dynamics=None, rpm=RPM_DESIGN):
    d = {"name": "vib", "cam": {"kind": "disc", "speed_rpm": rpm},
         "follower": {"type": "roller", "motion": "translating", "base_radius_mm": 40.0, "roller_radius_mm": 8.0},
         "motion": [{"law": law, "lift": lift, "angle_deg": ang} for law, lift, ang in rows],
         "dynamics": dynamics if dynamics is not None else
         {"mass_kg": M, "spring_rate_n_per_mm": KS / 1e3, "spring_preload_n": F0}}
    if vibration is not None:
        d["vibration"] = vibration
    return d


HARMONIC = [("simple_harmonic", 8.0, 180.0), ("simple_harmonic", -8.0, 180.0)]  # s = h/2·(1 − cos φ)
CYCLOIDAL = [("cycloidal", 6.0, 60.0), ("dwell", 0.0, 120.0), ("cycloidal", -6.0, 60.0), ("dwell", 0.0, 120.0)]


def _contact(rows):
    return geometry_from_spec(design_from_dict(_design(rows))).profiles[0]


@pytest.fixture(scope="module")
def harmonic_contact():
    return _contact(HARMONIC)


@pytest.fixture(scope="module")
def cycloidal_contact():
    return _contact(CYCLOIDAL)


@pytest.mark.parametrize("zeta, ca", [(0.0, 0.0), (0.1, 15.0)])
def test_harmonic_input_has_the_closed_form_steady_state(harmonic_contact, zeta, ca):
    """s = a(1 − cos Ωt) drives m·ü + C·u̇ + K·u = −(m·s̈ + c_a·ṡ + k_s·s): one harmonic and a constant,
    u = −k_s·a/K + Re(−ĝ·H·e^{iΩt}); undamped too (no resonance)."""
    k = 3e6
    loads = Loads(M, KS, F0, ca)
    model = FollowerTrain(harmonic_contact, loads, Train(k, zeta))
    r = model.response(OMEGA)
    a, K = 4e-3, k + KS
    c = 2 * zeta * math.sqrt(K * M)
    g = a * (M * OMEGA**2 - KS) - 1j * ca * a * OMEGA
    H = 1.0 / (K - M * OMEGA**2 + 1j * OMEGA * (c + ca))
    e = np.exp(1j * r.x)  # x = Ωt
    u = -KS * a / K + np.real(-g * H * e)
    du = np.real(-g * H * 1j * OMEGA * e)
    np.testing.assert_allclose(r.s, a * (1 - np.cos(r.x)), atol=1e-15)
    np.testing.assert_allclose(r.w - r.s, u, rtol=0, atol=1e-12 * np.abs(u).max())
    np.testing.assert_allclose(r.deflection_rate, du, rtol=0, atol=1e-10 * np.abs(du).max())
    np.testing.assert_allclose(r.force, F0 - k * u - c * du, rtol=1e-11)


def _duhamel(t, u0, v0, wn, zeta, a, Om):
    """ü + 2ζω_n·u̇ + ω_n²·u = −a·sin(Ωt) from (u0, v0): the steady part plus the free part (closed form)."""
    wd = wn * math.sqrt(1 - zeta * zeta)
    H = 1.0 / (wn * wn - Om * Om + 2j * zeta * wn * Om)
    up = -a * np.imag(H * np.exp(1j * Om * t))
    up0, vp0 = -a * np.imag(H), -a * np.imag(1j * Om * H)
    A = u0 - up0
    B = (v0 - vp0 + zeta * wn * A) / wd
    u = up + np.exp(-zeta * wn * t) * (A * np.cos(wd * t) + B * np.sin(wd * t))
    v = (-a * np.imag(1j * Om * H * np.exp(1j * Om * t)) + np.exp(-zeta * wn * t) * (
        (-zeta * wn * A + wd * B) * np.cos(wd * t) + (-zeta * wn * B - wd * A) * np.sin(wd * t)))
    return u, v


def _free(t, u0, v0, wn, zeta):
    wd = wn * math.sqrt(1 - zeta * zeta)
    B = (v0 + zeta * wn * u0) / wd
    return np.exp(-zeta * wn * t) * (u0 * np.cos(wd * t) + B * np.sin(wd * t))


@pytest.mark.parametrize("zeta", [0.0, 0.05])
def test_cycloidal_rise_follows_duhamel(cycloidal_contact, zeta):
    """Through a cycloidal rise (s̈ = 2πh/T²·sin 2πt/T) and the dwell after it, the periodic solution is
    Duhamel's closed form from its own state at the rise's start, then free vibration (undamped and damped;
    no return spring: the train alone)."""
    k = 2e5  # f_n ≈ 159 Hz, 6.4 cycles of the train per rise at 1500 rpm
    model = FollowerTrain(cycloidal_contact, Loads(M, 0.0, F0), Train(k, zeta))
    r = model.response(OMEGA)
    u, du = r.w - r.s, r.deflection_rate
    wn, T, h = math.sqrt(k / M), math.radians(60) / OMEGA, 6e-3
    t = r.x / OMEGA
    rise = t <= T
    ur, vr = _duhamel(t[rise], u[0], du[0], wn, zeta, 2 * math.pi * h / T**2, 2 * math.pi / T)
    scale = np.abs(u).max()
    np.testing.assert_allclose(u[rise], ur, rtol=0, atol=1e-7 * scale)
    uT, vT = _duhamel(np.array([T]), u[0], du[0], wn, zeta, 2 * math.pi * h / T**2, 2 * math.pi / T)
    dwell = (t >= T) & (t <= 3 * T)
    np.testing.assert_allclose(u[dwell], _free(t[dwell] - T, uT[0], vT[0], wn, zeta), rtol=0, atol=1e-7 * scale)
    if zeta == 0.0:  # undamped, from rest: the textbook residual amplitude a·Ω/(ω_n(ω_n² − Ω²))·2|sin(ω_n·T/2)|
        a, Om = 2 * math.pi * h / T**2, 2 * math.pi / T
        u0, v0 = _duhamel(np.array([T]), 0.0, 0.0, wn, 0.0, a, Om)
        amp = math.hypot(u0[0], v0[0] / wn)
        assert amp == pytest.approx(a * Om / (wn * (wn * wn - Om * Om)) * 2 * abs(math.sin(wn * T / 2)), rel=1e-12)


def test_periodic_state_matches_a_long_time_integration(cycloidal_contact):
    """From rest, solve_ivp over 8 cycles (the start dies out: e^(−2πζ·f_n/f) per cycle) reaches the periodic
    solution computed at once."""
    loads = Loads(M, KS, F0, 10.0)
    k, zeta = 1.6e5, 0.1
    model = FollowerTrain(cycloidal_contact, loads, Train(k, zeta))
    r = model.response(OMEGA)
    K, C = k + KS, 2 * zeta * math.sqrt((k + KS) * M) + 10.0
    motion = cycloidal_contact.motion

    def rhs(t, y):
        S = motion.evaluate(np.array([(OMEGA * t) % (2 * math.pi)]), (0, 1, 2))[:, 0] * 1e-3
        g = M * S[2] * OMEGA**2 + 10.0 * S[1] * OMEGA + KS * S[0]
        return [y[1], (-g - C * y[1] - K * y[0]) / M]

    T = 2 * math.pi / OMEGA
    t_end = 8 * T
    t_eval = t_end - T + r.x / OMEGA
    sol = solve_ivp(rhs, (0.0, t_end), [0.0, 0.0], method="DOP853", rtol=1e-11, atol=1e-15, t_eval=t_eval,
                    max_step=T / 720)
    u = r.w - r.s
    np.testing.assert_allclose(sol.y[0], u, rtol=0, atol=2e-6 * np.abs(u).max())
    np.testing.assert_allclose(sol.y[1], r.deflection_rate, rtol=0, atol=2e-5 * np.abs(r.deflection_rate).max())


def test_energy_balance_over_a_cycle(cycloidal_contact):
    """Steady state: the cam's work ∮F_c·ṡ dt equals the damping's ∮(c·u̇² + c_a·ẇ²) dt."""
    ca, k, zeta = 12.0, 4e5, 0.07
    model = FollowerTrain(cycloidal_contact, Loads(M, KS, F0, ca), Train(k, zeta))
    r = model.response(OMEGA)
    sdot = 1e-3 * cycloidal_contact.motion.evaluate(r.x, (1,))[0] * OMEGA
    wdot = sdot + r.deflection_rate
    c = 2 * zeta * math.sqrt((k + KS) * M)
    work_in = np.mean(r.force * sdot)
    dissipated = np.mean(c * r.deflection_rate**2 + ca * wdot**2)
    assert work_in > 0
    assert work_in == pytest.approx(dissipated, rel=1e-6)


def test_stiff_train_is_the_rigid_follower(cycloidal_contact):
    """k → ∞: the elastic follower becomes the kinematic one (the deviation falls as 1/k), its contact force
    the kinetostatic one (as ζ·f/f_n at a fixed ζ: the damper grows as √k) and the separation speed the
    rigid follower's jump speed."""
    loads = Loads(M, KS, F0, 5.0)
    rigid = ContactDynamics(cycloidal_contact, loads, OMEGA)
    jump = analyse_dynamics(geometry_from_spec(design_from_dict(_design(CYCLOIDAL))), loads, OMEGA).summary
    dev, err = [], []
    for fn in (1e4, 1e5):  # Hz, against 25 Hz of the cam
        model = FollowerTrain(cycloidal_contact, loads, Train(M * (2 * math.pi * fn) ** 2, 0.05))
        r = model.response(OMEGA)
        dev.append(np.abs(r.w - r.s).max() / 6e-3)
        N = rigid.evaluate(r.x).contact_force
        err.append(np.abs(r.contact_force - N).max() / np.abs(N).max())
        np.testing.assert_allclose(r.kinematic_force, N, rtol=1e-12)
    assert dev[1] < 1e-6 and dev[1] / dev[0] == pytest.approx(0.01, rel=0.02)
    assert err[1] < 5e-4 and err[1] < err[0] / 10
    rate, _ = model.separation_rate(OMEGA)
    assert rate / RPM == pytest.approx(jump.jump_speed.value, rel=1e-4)


def test_separation_speed_is_where_the_force_first_reaches_zero(cycloidal_contact):
    model = FollowerTrain(cycloidal_contact, Loads(M, KS, F0), Train(1e6, 0.05))
    rate, at = model.separation_rate(OMEGA)
    assert 0.5 * OMEGA < rate < 10 * OMEGA and at is not None
    assert model.min_force([rate * (1 - 1e-6)])[0] >= 0
    assert model.min_force([rate * (1 + 1e-6)])[0] < 0
    assert (model.min_force(np.linspace(0.01, 1 - 1e-4, 400) * rate) > 0).all()  # the first speed


def test_analysis_reports_dwell_vibration_and_resonance(cycloidal_contact):
    """Rise, dwell, return, dwell of equal spans: s(φ + π) = h − s(φ), so the acceleration has odd harmonics
    only.  Where harmonic 5 sits on f_n, the train rings (the elastic follower's harmonic 5 is magnified
    about 1/(2ζ)) and a warning names it."""
    fc = OMEGA / (2 * math.pi)
    k = M * (2 * math.pi * 5 * fc) ** 2 - KS  # f_n = 5·f
    rep = analyse_vibration(cycloidal_contact, Loads(M, KS, F0), Train(k, 0.03), OMEGA)
    s = rep.summary
    assert s.natural_frequency_hz == pytest.approx(5 * fc, rel=1e-12)
    assert s.nearest_resonance_order == 5
    h = {x.order: x for x in s.harmonics}
    assert sorted(h) == list(range(1, 13)) and h[1].frequency_hz == pytest.approx(fc)
    big = max(x.amplitude for x in s.harmonics)
    assert all(h[j].amplitude < 1e-9 * big for j in range(2, 13, 2))
    assert h[5].dynamic_amplitude / h[5].amplitude > 5  # magnified near 1/(2ζ) ≈ 17 (less the train's share)
    assert s.residual_amplitude is not None and s.residual_amplitude.max > 0
    (warn,) = [f for f in rep.findings if f.code == IssueCode.VIBRATION_RESONANCE]
    assert warn.value == pytest.approx(5 * fc) and warn.limit == pytest.approx(5 * fc)


def _toml(d: dict) -> str:
    """The design dicts above as TOML: top-level strings, tables of numbers and strings, [[motion]] rows."""
    def val(v):
        return f'"{v}"' if isinstance(v, str) else repr(v)

    out = [f"{k} = {val(v)}" for k, v in d.items() if not isinstance(v, (dict, list))]
    for k, v in d.items():
        rows = [(f"[[{k}]]", r) for r in v] if isinstance(v, list) else [(f"[{k}]", v)] if isinstance(v, dict) else []
        for head, r in rows:
            out += [head] + [f"{a} = {val(b)}" for a, b in r.items()]
    return "\n".join(out) + "\n"


TOML_VIB = {"stiffness_n_per_mm": 300.0, "damping_ratio": 0.05}


def test_check_json_vibration_object(tmp_path, capsys):
    path = tmp_path / "vib.toml"
    path.write_text(_toml(_design(CYCLOIDAL, vibration=TOML_VIB, rpm=3000.0)))
    code = main(["check", str(path), "--json"])
    d = json.loads(capsys.readouterr().out)
    v = d["vibration"]
    assert v["natural_frequency_hz"] == pytest.approx(math.sqrt((300e3 + KS) / M) / (2 * math.pi))
    assert v["cycle_frequency_hz"] == pytest.approx(50.0)
    assert v["lift_unit"] == "mm"
    assert set(v["contact_force_n"]) == {"min", "max", "at_min_deg", "at_max_deg"}
    assert v["separation_speed"]["unit"] == "rpm" and 0 < v["separation_speed"]["value"] < 3000
    assert [h["order"] for h in v["harmonics"]] == list(range(1, 13))
    seps = [f for f in d["findings"] if f["code"] == "FOLLOWER_SEPARATES_VIBRATION"]
    assert seps and code == 1 and d["verdict"] == "unacceptable"
    assert v["contact_force_n"]["min"] < 0 and min(f["value"] for f in seps) == pytest.approx(
        v["contact_force_n"]["min"], rel=1e-3)
    path.write_text(_toml(_design(CYCLOIDAL)))
    main(["check", str(path), "--json"])
    assert json.loads(capsys.readouterr().out)["vibration"] is None


@pytest.mark.parametrize("change, path", [
    (lambda d: d["vibration"].update(stiffness_n_per_mm=-5.0), "vibration.stiffness_n_per_mm"),
    (lambda d: d["vibration"].pop("stiffness_n_per_mm"), "vibration.stiffness_n_per_mm"),
    (lambda d: d["vibration"].update(damping_ratio=1.0), "vibration.damping_ratio"),
    (lambda d: d["vibration"].update(damping_ratio=0.0), "vibration.damping_ratio"),
    (lambda d: d["vibration"].update(harmonics=0), "vibration.harmonics"),
    (lambda d: d["vibration"].update(stiffness_nm_per_deg=3.0), "vibration.stiffness_nm_per_deg"),
    (lambda d: d["vibration"].update(zeta=0.1), "vibration.zeta"),
    (lambda d: d.pop("dynamics"), "vibration"),
    (lambda d: d["dynamics"].update(mass_kg=-1.0), "dynamics.mass_kg"),
])
def test_bad_vibration_tables_name_the_field(change, path):
    d = copy.deepcopy(_design(CYCLOIDAL, vibration=dict(TOML_VIB)))
    change(d)
    with pytest.raises(SpecError) as exc:
        design_from_dict(d)
    assert path in {p.path for p in exc.value.problems}


def test_form_closed_cam_refuses_vibration():
    d = {"name": "cw", "cam": {"kind": "constant_width", "speed_rpm": 100.0},
         "follower": {"type": "flat", "motion": "translating", "base_radius_mm": 30.0, "width_mm": 80.0},
         "dynamics": {"mass_kg": 0.5}, "vibration": TOML_VIB}
    with pytest.raises(SpecError) as exc:
        design_from_dict(d)
    assert "vibration" in {p.path for p in exc.value.problems}


def test_cli_bad_vibration_exits_2(tmp_path, capsys):
    path = tmp_path / "bad.toml"
    path.write_text(_toml(_design(CYCLOIDAL, vibration={"stiffness_n_per_mm": -1.0})))
    assert main(["check", str(path), "--json"]) == 2
    assert "vibration.stiffness_n_per_mm" in capsys.readouterr().err


def test_loads_from_spec_units_match_the_train():
    spec = design_from_dict(_design(CYCLOIDAL, vibration=TOML_VIB))
    loads = loads_from_spec(spec.dynamics)
    assert loads.spring_rate == pytest.approx(KS) and spec.vibration.stiffness == 300.0


def test_xlsx_design_keeps_the_vibration_table(tmp_path):
    pytest.importorskip("openpyxl")
    from camfab.formats import design_to_xlsx, load_design_xlsx

    spec = design_from_dict(_design(CYCLOIDAL, vibration={**TOML_VIB, "harmonics": 7}))
    path = tmp_path / "design.xlsx"
    path.write_bytes(design_to_xlsx(spec))
    assert load_design_xlsx(path).vibration == spec.vibration


def test_oscillating_arm_and_translating_cam():
    """An arm: k in N·m/degree, lengths in degrees, f_n = √((k + k_s)/I)/2π; a translating cam: speed in mm/s,
    the cycle is the cam length over the speed."""
    arm = design_from_dict({
        "name": "arm", "cam": {"kind": "disc", "speed_rpm": 600.0},
        "follower": {"type": "roller", "motion": "oscillating", "base_radius_mm": 40.0, "roller_radius_mm": 8.0,
                     "pivot_distance_mm": 110.0, "arm_length_mm": 90.0},
        "motion": [{"law": "cycloidal", "lift": 15.0, "angle_deg": 120.0}, {"law": "dwell", "angle_deg": 60.0},
                   {"law": "cycloidal", "lift": -15.0, "angle_deg": 120.0}, {"law": "dwell", "angle_deg": 60.0}],
        "dynamics": {"inertia_kg_m2": 0.002, "spring_rate_nm_per_deg": 0.05, "spring_preload_nm": 8.0},
        "vibration": {"stiffness_nm_per_deg": 50.0, "damping_ratio": 0.1}})
    v = check_vibration(arm)
    per_rad = 180 / math.pi
    assert v.lift_unit == "deg"
    assert v.natural_frequency_hz == pytest.approx(math.sqrt((50.05 * per_rad) / 0.002) / (2 * math.pi))
    assert v.cycle_frequency_hz == pytest.approx(10.0)
    assert 0 < v.max_deviation.max < 1.0  # degrees
    plate = design_from_dict({
        "name": "plate", "cam": {"kind": "translating", "speed_mm_s": 500.0},
        "follower": {"type": "roller", "motion": "translating", "roller_radius_mm": 5.0, "cam_length_mm": 200.0},
        "motion": [{"law": "cycloidal", "lift": 8.0, "length_mm": 100.0},
                   {"law": "cycloidal", "lift": -8.0, "length_mm": 100.0}],
        "dynamics": {"mass_kg": 0.5, "spring_rate_n_per_mm": 5.0, "spring_preload_n": 50.0},
        "vibration": {"stiffness_n_per_mm": 500.0}})
    v = check_vibration(plate)
    assert v.cycle_frequency_hz == pytest.approx(2.5) and v.separation_speed.unit == "mm/s"
    assert v.residual_amplitude is None  # no dwell


def check_vibration(spec):
    return check_design(spec).vibration


def test_separation_ranges_end_where_the_force_crosses_zero(cycloidal_contact):
    """Each FOLLOWER_SEPARATES_VIBRATION range starts and ends where the contact force with the vibration
    crosses 0, checked on a 4x finer, independent solution 0.1° either side."""
    loads, train = Loads(M, KS, F0), Train(3e5, 0.05)
    rep = analyse_vibration(cycloidal_contact, loads, train, 2 * OMEGA)
    seps = [f for f in rep.findings if f.code == IssueCode.FOLLOWER_SEPARATES_VIBRATION]
    assert seps
    fine = FollowerTrain(cycloidal_contact, loads, train, n=4 * 4096).response(2 * OMEGA)
    deg = np.degrees(fine.x)

    def force(at):
        return np.interp(at % 360, deg, fine.force, period=360)

    for f in seps:
        assert force(f.from_deg - 0.1) > 0 > force(f.from_deg + 0.1)
        assert force(f.to_deg - 0.1) < 0 < force(f.to_deg + 0.1)
        assert f.value < 0 and f.limit == 0.0
