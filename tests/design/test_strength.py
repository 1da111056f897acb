"""Contact stress (Hertz line contact) and life (ISO 281, the cam track's S–N estimate): closed forms, published
numbers, the cam's concave stretches, exact extremes, the check's finding and JSON, refusals."""
from __future__ import annotations

import json
import math
import tomllib

import numpy as np
import pytest

from camfab.cli import main
from camfab.design.assemble import check_design, dynamics_model, geometry_from_spec, strength_input
from camfab.design.dynamics import ContactDynamics, Loads
from camfab.design.materials import MATERIALS, match_material
from camfab.design.mechanisms import TranslatingFlat, TranslatingRoller
from camfab.design.profile import CamGeometry
from camfab.design.program import MotionProgram
from camfab.design.spec import design_from_dict
from camfab.design.strength import (
    BALL,
    ROLLER,
    StrengthInput,
    StressModel,
    analyse_strength,
    cam_life,
    effective_modulus,
    follower_radius,
    hertz_line,
    rating_life,
    relative_curvature,
)
from camfab.errors import InputError, SpecError
from camfab.units import RPM

from ..conftest import EXAMPLES

STEEL = MATERIALS["C45"]
SHM = MotionProgram.from_segments([("simple_harmonic", 20, 180), ("simple_harmonic", -20, 180)])
W = 600 * RPM


def _design(name: str, **tables) -> dict:
    data = tomllib.loads((EXAMPLES / f"{name}.toml").read_text(encoding="utf-8"))
    for key, table in tables.items():
        data[key] = {**data.get(key, {}), **table}
    return data


def test_two_cylinders_closed_form():
    """Two steel cylinders (E = 207 GPa, ν = 0.3; Ø50 and Ø80 mm, 20 mm long, 5 kN), worked by hand:
    E* = E/(2(1 − ν²)) = 113 736.3 MPa, R* = 25·40/65 = 15.3846 mm,
    p_max = √(5000·113736.3/(π·20·15.3846)) = 767.01 MPa, a = √(4·5000·15.3846/(π·20·113736.3)) = 0.20750 mm;
    and the same by the other textbook arrangement (full width w = 2a, same material, Carvill's *Mechanical
    Engineer's Data Handbook*): w = √(32F(1 − ν²)/(πLE(1/r₁ + 1/r₂))), σ_c = 4F/(πwL)."""
    e = effective_modulus(207e3, 0.3, 207e3, 0.3)
    assert e == pytest.approx(207e3 / (2 * (1 - 0.09)), rel=1e-14)
    p, a = hertz_line(5000.0, e, 20.0, relative_curvature(1 / 25, 40.0))
    assert float(p) == pytest.approx(767.01, abs=0.01) and float(a) == pytest.approx(0.20750, abs=1e-5)
    w = math.sqrt(32 * 5000 * (1 - 0.09) / (math.pi * 20 * 207e3 * (1 / 25 + 1 / 40)))
    assert 2 * float(a) == pytest.approx(w, rel=1e-13)
    assert float(p) == pytest.approx(4 * 5000 / (math.pi * w * 20), rel=1e-13)  # p_max = 4/π × the mean pressure


def test_published_width_scaling():
    """Published numbers (Engineers Edge forum, "material recommendation for cam and follower with high contact
    stress", 2006, after Clyde Moon's cam design manual): 331 228.24 psi with a 3/8" cam and roller,
    306 657.76 psi at 7/16" and 286 852.07 psi at 1/2" — p ∝ 1/√b."""
    e = effective_modulus(30e6, 0.3, 30e6, 0.3)  # psi and inches: the formula has no units of its own
    k = (331228.24 / float(hertz_line(1.0, e, 0.375, 1.0)[0])) ** 2  # the force·curvature that gives their peak
    for b, want in ((0.4375, 306657.76), (0.5, 286852.07)):
        assert float(hertz_line(k, e, b, 1.0)[0]) == pytest.approx(want, abs=0.01)


def test_flat_face_on_circular_cam():
    """A translating flat face on the SHM 180/180 cam, whose profile is a circle of radius R_b + h/2 = 50 mm
    (ρ = R_b + S + S″): the stress along the cycle is that of a cylinder of radius 50 on a plane,
    p = √(N·E*/(π·b·50)), with N = m·S″ω² + F₀ + k·S known in closed form."""
    g = CamGeometry(TranslatingFlat(40.0), SHM)
    loads = Loads(0.5, 5000.0, 50.0)
    e = effective_modulus(STEEL.e_mpa, STEEL.poisson, STEEL.e_mpa, STEEL.poisson)
    model = StressModel(ContactDynamics(g.profiles[0], loads, W), e, 12.0)
    x = np.linspace(0, 2 * np.pi, 721)
    N = 0.5 * 10 * np.cos(x) * 1e-3 * W * W + 50.0 + 5000.0 * 10 * (1 - np.cos(x)) * 1e-3
    np.testing.assert_allclose(model.evaluate(x).stress, np.sqrt(N * e / (math.pi * 12.0 * 50.0)), rtol=1e-12)
    assert math.isinf(follower_radius(g.profiles[0]))


def test_concave_contact():
    """A roller (R = 10 mm) in a concave track (ρ = −30 mm): 1/R* = 1/10 − 1/30, the "minus" of the textbooks
    (Carvill: roller on a concave surface, w = √(32F(1 − ν²)/(πLE(1/r₁ − 1/r₂))))."""
    e = effective_modulus(207e3, 0.3, 207e3, 0.3)
    p, a = hertz_line(2000.0, e, 10.0, relative_curvature(-1 / 30, 10.0))
    w = math.sqrt(32 * 2000 * 0.91 / (math.pi * 10 * 207e3 * (1 / 10 - 1 / 30)))
    assert 2 * float(a) == pytest.approx(w, rel=1e-13)
    convex, _ = hertz_line(2000.0, e, 10.0, relative_curvature(1 / 30, 10.0))
    assert float(p) < float(convex)  # a conforming contact spreads the load
    assert float(hertz_line(1.0, e, 10.0, relative_curvature(-1 / 30, math.inf))[0]) == math.inf  # flat, undercut


def test_roller_stress_on_the_cam_follows_its_curvature():
    """Ejemplo9RT (translating roller, R = 7 mm, concave flanks down to 47.5 mm) with a spring: along the cycle the
    stress is the Hertz stress of the contact force on 1/R* = κ + 1/R, and 1/R* stays positive on the concave
    stretches, where it is 1/R − 1/|ρ|."""
    spec = design_from_dict(_design("ejemplo9rt", dynamics={"mass_kg": 0.5, "spring_rate_n_per_mm": 5.0,
                                                            "spring_preload_n": 100.0}))
    geom = geometry_from_spec(spec)
    inp = strength_input(spec, geom)
    assert inp is not None and inp.dynamics is not None and inp.width_mm == 10.0
    x = np.linspace(0, 2 * np.pi, 2001)
    s = geom.profiles[0].evaluate_fixed(x)
    concave = s.curvature < 0
    assert concave.any()
    k = s.curvature + 1 / 7.0
    assert k.min() > 0
    np.testing.assert_allclose(k[concave], 1 / 7.0 - 1 / np.abs(s.rho[concave]), rtol=1e-12)
    e = effective_modulus(STEEL.e_mpa, STEEL.poisson, MATERIALS["100Cr6"].e_mpa, MATERIALS["100Cr6"].poisson)
    N = inp.dynamics.evaluate(x).contact_force
    model = StressModel(inp.dynamics, e, 10.0)
    np.testing.assert_allclose(model.evaluate(x).stress, np.sqrt(np.maximum(N, 0) * e * k / (math.pi * 10.0)),
                               rtol=1e-12)


def test_exact_peak_against_dense_sampling():
    """The reported peak is the exact one: at least every sample of a dense grid, and within 1e-9 of its best."""
    spec = design_from_dict(_design("press_feed_oscillating"))
    geom = geometry_from_spec(spec)
    inp = strength_input(spec, geom)
    summary, findings = analyse_strength(geom, inp)
    assert not findings and summary.safety_factor == pytest.approx(summary.allowable_mpa / summary.max_mpa)
    e = effective_modulus(inp.cam.e_mpa, inp.cam.poisson, inp.follower.e_mpa, inp.follower.poisson)
    x = np.linspace(0, 2 * np.pi, 200_001)
    dense = StressModel(inp.dynamics, e, inp.width_mm).evaluate(x).stress
    assert summary.max_mpa >= dense.max() * (1 - 1e-14)
    assert summary.max_mpa == pytest.approx(dense.max(), rel=1e-9)
    assert summary.at == pytest.approx(math.degrees(x[np.argmax(dense)]), abs=0.01)


def test_rating_life_is_iso_281():
    """L10 = (C/P)^p (p = 10/3 roller bearings, 3 ball); decreasing in the load; P = 0 never fails."""
    assert rating_life(20_000, 2_000) == pytest.approx(10 ** (10 / 3), rel=1e-14)
    assert rating_life(20_000, 2_000, BALL) == pytest.approx(1000.0, rel=1e-14)
    loads = np.linspace(100, 10_000, 50)
    lives = [rating_life(15_000, p, ROLLER) for p in loads]
    assert all(a > b for a, b in zip(lives, lives[1:], strict=False))
    assert rating_life(15_000, 0.0) == math.inf


def test_roller_life_of_a_design():
    """The press-feed roller with a bearing of C = 8 kN: P lies between the smallest and largest contact force,
    L10 = (C/P)^(10/3) million roller turns; cam revolutions = L10·10⁶ / (roller turns per cam turn), the turns
    being the profile length / (2π R); hours at 200 rpm.  A stiffer spring (more force) shortens the life."""
    def life(preload):
        data = _design("press_feed_oscillating", strength={"roller_dynamic_rating_n": 8000.0},
                       dynamics={"spring_preload_nm": preload})
        spec = design_from_dict(data)
        geom = geometry_from_spec(spec)
        return analyse_strength(geom, strength_input(spec, geom))[0], spec, geom

    s, spec, geom = life(12.0)
    r = s.roller_life
    dyn = check_design(spec).dynamics
    assert dyn.contact_force.min < r.equivalent_load_n < dyn.contact_force.max
    assert r.l10_million_revolutions == pytest.approx((8000.0 / r.equivalent_load_n) ** (10 / 3), rel=1e-12)
    perimeter = geom.profiles[0].evaluate(np.linspace(0, 2 * np.pi, 100_001)).point
    length = np.hypot(*np.diff(perimeter, axis=0).T).sum()
    assert r.roller_revolutions_per_cycle == pytest.approx(length / (2 * math.pi * 11.0), rel=1e-6)
    assert r.cam_cycles == pytest.approx(r.l10_million_revolutions * 1e6 / r.roller_revolutions_per_cycle, rel=1e-12)
    assert r.hours == pytest.approx(r.cam_cycles / (200 * 60), rel=1e-12)
    assert life(24.0)[0].roller_life.cam_cycles < r.cam_cycles


def test_cam_life_basquin_line():
    """N = N_L·(σ_Hlim/p)^m above the limit (ISO 6336-2 slope for steels: 1.6·σ_Hlim at 10⁵ cycles), unlimited at
    or below it, none for a material without a fatigue limit; shorter under more stress."""
    steel = MATERIALS["16MnCr5"]
    assert cam_life(1500.0, steel) == math.inf
    assert cam_life(1.6 * 1500.0, steel) == pytest.approx(1e5, rel=0.02)
    assert cam_life(2000.0, steel) > cam_life(2200.0, steel)
    assert cam_life(5000.0, MATERIALS["bronze"]) == math.inf


def test_undersized_cam_raises_the_finding(tmp_path, capsys):
    """The valve mushroom in a soft aluminium cam: CONTACT_STRESS_ABOVE_LIMIT over exact ranges (the stress equals
    the allowable at their ends), the safety factor in the message, exit 1."""
    data = _design("valve_mushroom", strength={"cam_material": "AlMgSi1"})
    spec = design_from_dict(data)
    rep = check_design(spec)
    found = rep.by_code("CONTACT_STRESS_ABOVE_LIMIT")
    cs = rep.contact_stress
    assert found and cs.safety_factor < 1 and cs.allowable_mpa == 200.0
    assert max(f.value for f in found) == pytest.approx(cs.max_mpa, rel=1e-9)
    geom = geometry_from_spec(spec)
    inp = strength_input(spec, geom)
    e = effective_modulus(inp.cam.e_mpa, inp.cam.poisson, inp.follower.e_mpa, inp.follower.poisson)
    model = StressModel(inp.dynamics, e, inp.width_mm)
    for f in found:
        ends = model.evaluate(np.radians([f.from_deg, f.to_deg])).stress
        np.testing.assert_allclose(ends, 200.0, rtol=1e-7)
        assert f"safety factor {200.0 / f.value:.3g}" in f.message
    assert rep.verdict == "unacceptable"


def test_check_json_contact_stress(tmp_path, capsys):
    """`check --json`: the contact_stress object, null without [dynamics]/[strength]."""
    assert main(["check", "press_feed_oscillating", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)["contact_stress"]
    assert list(d)[:4] == ["max_mpa", "at_deg", "allowable_mpa", "safety_factor"]
    assert d["allowable_mpa"] == 1150.0 and d["cam_material"] == "C45" and d["follower_material"] == "100Cr6"
    assert d["safety_factor"] == pytest.approx(d["allowable_mpa"] / d["max_mpa"]) and d["roller_life"] is None
    assert any("roller_dynamic_rating_n" in n for n in d["notes"])
    main(["check", "ejemplo9rt", "--json"])
    assert json.loads(capsys.readouterr().out)["contact_stress"] is None


@pytest.mark.parametrize("name, cam", [("constant_width", {}), ("ejemplo8da_conjugate", {"omega_rad_s": 30.0})])
def test_form_closed_cams_on_both_followers(name, cam):
    """Form-closed cams with [dynamics] — a constant-width cam (one profile, follower 2 half a turn on) and a
    conjugate pair (two profiles): each follower's stress; the peak is the larger of the two, both exact."""
    data = _design(name, dynamics={"mass_kg": 0.4}, cam=cam)
    spec = design_from_dict(data)
    cs = check_design(spec).contact_stress
    assert cs.second is not None and cs.max_mpa == pytest.approx(max(cs.max_mpa, cs.second[0]))
    geom = geometry_from_spec(spec)
    x = np.linspace(0, 2 * np.pi, 20_001)
    inp = strength_input(spec, geom)
    e = effective_modulus(inp.cam.e_mpa, inp.cam.poisson, inp.follower.e_mpa, inp.follower.poisson)
    sm = StressModel(dynamics_model(spec, geom), e, inp.width_mm).evaluate(x)
    assert cs.second[0] == pytest.approx(sm.stress_2.max(), rel=1e-6)
    assert cs.max_mpa == pytest.approx(max(sm.stress.max(), sm.stress_2.max()), rel=1e-6)


def test_knife_edge_is_refused_with_its_reason():
    g = CamGeometry(TranslatingRoller(40.0, 0.0), SHM)
    with pytest.raises(InputError, match="knife-edge.*infinite"):
        follower_radius(g.profiles[0])
    inp = StrengthInput(ContactDynamics(g.profiles[0], Loads(0.5, 5000.0, 50.0), W), STEEL, STEEL, 10.0, 1150.0)
    with pytest.raises(InputError, match="knife-edge"):
        analyse_strength(g, inp)
    # in `check` a knife edge is stated, not checked: no number, no finding, the reason in the notes
    data = _design("ejemplo9rt", dynamics={"mass_kg": 0.5, "spring_rate_n_per_mm": 5.0, "spring_preload_n": 100.0})
    data["follower"] = {k: v for k, v in data["follower"].items() if k != "roller_radius_mm"} | {"type": "knife"}
    rep = check_design(design_from_dict(data))
    cs = rep.contact_stress
    assert cs.max_mpa is None and cs.safety_factor is None and not rep.by_code("CONTACT_STRESS_ABOVE_LIMIT")
    assert any("knife-edge" in n and "infinite" in n for n in cs.notes)


def test_unknown_material_is_exit_2(tmp_path, capsys):
    """An unknown [strength] material and an unmatched [manufacturing] material: exit 2, the field named, the
    known names listed."""
    text = (EXAMPLES / "press_feed_oscillating.toml").read_text() + '\n[strength]\ncam_material = "unobtainium"\n'
    p = tmp_path / "bad.toml"
    p.write_text(text)
    assert main(["check", str(p)]) == 2
    err = capsys.readouterr().err
    assert "strength.cam_material" in err and "42CrMo4" in err and "AlMgSi1" in err
    with pytest.raises(SpecError, match="manufacturing.material"):
        design_from_dict(_design("press_feed_oscillating", manufacturing={"material": "brass"}))
    own = _design("press_feed_oscillating", manufacturing={"material": "brass"},
                  materials={"brass": {"youngs_modulus_mpa": 100e3, "poisson_ratio": 0.34,
                                       "allowable_contact_stress_mpa": 300.0}})
    assert design_from_dict(own).strength.cam.allowable_mpa == 300.0


def test_materials_map_the_cutting_data_names():
    """Every work material of the cutting-data table names a contact-stress material (the same name)."""
    from camfab.gcode.cutting import known_materials
    for name in known_materials():
        assert match_material(name).name == name
    assert match_material("C45 steel, induction hardened").name == "C45"
    assert match_material("42CrMo4QT").allowable_mpa < match_material("42CrMo4").allowable_mpa


def test_infinite_stress_is_stated_not_searched():
    """A flat face on a cam with an undercut (ρ < 0: a flat face cannot touch a concave stretch): the stress is
    infinite there — no number, the note says where and points at the curvature findings."""
    rise = MotionProgram.from_segments([("cycloidal", 30, 90), ("dwell", 0, 90), ("cycloidal", -30, 90),
                                        ("dwell", 0, 90)])
    g = CamGeometry(TranslatingFlat(10.0), rise)  # ρ = R_b + S + S″, S″ up to 2πh/β² = 76 mm: ρ < 0
    inp = StrengthInput(ContactDynamics(g.profiles[0], Loads(0.1, 5000.0, 50.0), 10 * RPM), STEEL, STEEL, 10.0,
                        1150.0)
    s, _ = analyse_strength(g, inp)
    assert s.max_mpa is None and s.safety_factor == 0.0 and any("infinite" in n for n in s.notes)


def test_form_closed_roller_life_covers_both_rollers():
    """A constant-diameter cam (two rollers, one profile, the second half a turn on) with a bearing rating: the
    shorter life of the two rollers, each from its own force history."""
    data = _design("constant_diameter", dynamics={"mass_kg": 0.4}, strength={"roller_dynamic_rating_n": 5000.0})
    spec = design_from_dict(data)
    cs = check_design(spec).contact_stress
    r = cs.roller_life
    assert r is not None and r.follower in (1, 2) and r.exponent == pytest.approx(10 / 3)
    dyn = check_design(spec).dynamics
    top = max(dyn.contact_force.max, dyn.second_contact_force.max)
    assert 0 < r.equivalent_load_n < top
    assert r.l10_million_revolutions == pytest.approx((5000.0 / r.equivalent_load_n) ** (10 / 3), rel=1e-12)


def test_stress_in_the_workbook_and_the_report_figure():
    """The xlsx (read back with openpyxl): the Dynamics sheet's stress column is the stress at its angles, and the
    Checks summary carries the exact peak; the report figure draws the allowable line and the curve below the peak."""
    import io

    import openpyxl

    from camfab.formats.camdas_workbook import camdas_workbook
    from camfab.report.plots import report_figures

    spec = design_from_dict(_design("press_feed_oscillating", strength={"roller_dynamic_rating_n": 8000.0}))
    geom = geometry_from_spec(spec)
    rep = check_design(spec)
    wb = openpyxl.load_workbook(io.BytesIO(camdas_workbook(spec, geom, rep)))
    ws = wb["Dynamics"]
    head = [c.value for c in ws[1]]
    col = head.index("Contact stress (MPa)")
    rows = [[c.value for c in r] for r in ws.iter_rows(min_row=2)]
    angle = np.radians([r[0] for r in rows])
    inp = strength_input(spec, geom)
    e = effective_modulus(inp.cam.e_mpa, inp.cam.poisson, inp.follower.e_mpa, inp.follower.poisson)
    np.testing.assert_allclose([r[col] for r in rows], StressModel(inp.dynamics, e, 14.0).evaluate(angle).stress,
                               rtol=1e-12)
    summary = {r[0].value: r[1].value for r in wb["Checks"].iter_rows() if r[0].value}
    assert summary["Maximum contact stress"] == pytest.approx(rep.contact_stress.max_mpa, rel=1e-12)
    assert summary["Roller life L10"] == pytest.approx(rep.contact_stress.roller_life.hours, rel=1e-12)
    fig = report_figures(spec, geom, rep)["contact_stress"]
    ax = fig.axes[0]
    curve, allow = ax.lines[0], ax.lines[1]
    assert set(allow.get_ydata()) == {1150.0}
    assert max(curve.get_ydata()) <= rep.contact_stress.max_mpa * (1 + 1e-12)


def test_strength_tables_survive_the_xlsx_design_round_trip(tmp_path):
    """[strength] and [materials.NAME] written to an xlsx design and read back give the same strength inputs."""
    from camfab.formats.xlsx_design import design_to_xlsx, load_design_xlsx

    data = _design("press_feed_oscillating", manufacturing={"material": "MyIron"},
                   strength={"follower_material": "42CrMo4", "roller_width_mm": 12, "roller_dynamic_rating_n": 8000.0,
                             "roller_bearing": "ball"},
                   materials={"MyIron": {"youngs_modulus_mpa": 120e3, "poisson_ratio": 0.26,
                                         "allowable_contact_stress_mpa": 420.0, "contact_fatigue_limit_mpa": 400.0}})
    spec = design_from_dict(data)
    assert spec.strength.cam.name == "MyIron" and spec.strength.width_mm == 12 and spec.strength.ball_bearing
    p = tmp_path / "d.xlsx"
    p.write_bytes(design_to_xlsx(spec))
    assert load_design_xlsx(p).strength == spec.strength
