"""Follower dynamics in the reports: the HTML figure and table, the xlsx ``Dynamics`` sheet and the
``[dynamics]`` section of xlsx design workbooks.

Every number is checked against an independent evaluation of
:class:`camfab.design.dynamics.ContactDynamics` (or the ``check`` summary), never against the
exporter's own helpers."""
from __future__ import annotations

import dataclasses
import io
import re
import tomllib

import numpy as np
import pytest

from camfab.design.assemble import loads_from_spec
from camfab.design.dynamics import ContactDynamics
from camfab.design.spec import design_from_dict
from camfab.errors import SpecError
from camfab.formats import design_from_data, design_rows, design_to_xlsx, load_design, load_design_xlsx
from camfab.formats.camdas_workbook import camdas_workbook
from camfab.report._common import sample_grid
from camfab.report.html import render_report
from tests.report.designs import checked_design

from ..conftest import EXAMPLES
from .designs import DESIGNS

openpyxl = pytest.importorskip("openpyxl")
pytest.importorskip("jinja2", reason="HTML reports need jinja2")
pytest.importorskip("matplotlib", reason="report plots need matplotlib")

VALVE = EXAMPLES / "valve_exhaust_ej1.toml"
PRESS = EXAMPLES / "press_feed_oscillating.toml"


def _toml(path, **sections):
    """The TOML dict of an example with some keys of its sections replaced."""
    data = tomllib.loads(path.read_text(encoding="utf-8"))
    data.setdefault("name", path.stem)
    for name, over in sections.items():
        data[name] = {**data.get(name, {}), **over}
    return data


def _translating_cam(**dyn):
    d = dict(DESIGNS["translating_cam"])
    d["dynamics"] = {"mass_kg": 2.0, "spring_rate_n_per_mm": 1.0, "spring_preload_n": 20.0,
                     "damping_n_s_per_m": 50.0, "safety_force_n": 5.0, **dyn}
    return design_from_dict(d)


def _dynamics(spec, geom):
    """An independent ContactDynamics of the design (the path the brief names)."""
    return ContactDynamics(geom.profiles[0], loads_from_spec(spec.dynamics), spec.speed)


@pytest.fixture(scope="module")
def press_fast():
    """The press-feed lever at 320 rpm: the follower jumps (79°–101°, 193°–203°) and the contact
    force is below the 50 N safety force around both ranges."""
    return checked_design(design_from_dict(_toml(PRESS, cam={"speed_rpm": 320.0}), source=str(PRESS)))


@pytest.fixture(scope="module")
def press():
    return checked_design(load_design(PRESS))


@pytest.fixture(scope="module")
def wedge():
    return checked_design(_translating_cam())


# ---------------------------------------------------------------------------
# figure
def test_dynamics_figure_only_for_designs_with_dynamics(valve, e9):
    from camfab.report.plots import report_figures

    assert e9[0].dynamics is None and "dynamics" not in report_figures(*e9)
    figs = report_figures(*valve)
    assert list(figs)[-2:] == ["dynamics", "contact_stress"]  # the Hertz stress follows the forces
    spec, geom, rep = valve
    top, bottom = figs["dynamics"].axes
    # the contact-force curve is N of an independent evaluation on the plot grid
    c = geom.profiles[0]
    x = sample_grid(c.period, c.breakpoints, 1441)
    curve = top.lines[0]
    np.testing.assert_allclose(curve.get_xdata(), np.degrees(x), rtol=0, atol=1e-9)
    np.testing.assert_allclose(curve.get_ydata(), _dynamics(spec, geom).evaluate(x).contact_force, rtol=1e-12)
    flat = {float(ln.get_ydata()[0]) for ln in top.lines[1:] if len(set(ln.get_ydata())) == 1}
    assert {0.0, 100.0} <= flat  # the zero line and the 100 N safety force
    assert "drive torque" in bottom.get_ylabel()
    np.testing.assert_allclose(bottom.lines[0].get_ydata(), _dynamics(spec, geom).evaluate(x).drive, rtol=1e-12)
    # the exact extremes of the summary are marked
    cf = rep.dynamics.contact_force
    dots = [(ln.get_xdata()[0], ln.get_ydata()[0]) for ln in top.lines if ln.get_marker() == "o"]
    assert (cf.at_min, cf.min) in dots and (cf.at_max, cf.max) in dots
    assert top.get_xlim() == (0.0, 360.0)


def test_jump_and_below_safety_ranges_are_shaded(press_fast):
    from camfab.report.plots import dynamics_figure

    spec, geom, rep = press_fast
    jumps, low = rep.by_code("FOLLOWER_JUMP"), rep.by_code("CONTACT_FORCE_BELOW_SAFETY")
    assert len(jumps) == 2 and len(low) == 2
    top = dynamics_figure(spec, geom, rep).axes[0]
    spans = sorted((round(p.get_x(), 9), round(p.get_x() + p.get_width(), 9)) for p in top.patches)
    want = sorted((round(f.from_deg, 9), round(f.to_deg, 9)) for f in jumps + low)
    assert spans == want
    assert jumps[0].from_deg == pytest.approx(79.0, abs=0.05) and jumps[0].to_deg == pytest.approx(100.62, abs=0.05)
    # the curve dips below zero inside the first jump range
    y = top.lines[0].get_ydata()
    xs = top.lines[0].get_xdata()
    inside = (xs > jumps[0].from_deg) & (xs < jumps[0].to_deg)
    assert np.all(y[inside] < 0) and np.nanmin(y) == pytest.approx(rep.dynamics.contact_force.min,
                                                                   abs=0.01)


def test_self_locking_follower_stays_readable():
    """A knife edge with μ = 1.5 wedges where its pressure angle is large: N → ±∞ there; the plot
    blanks the blow-up, shades the range, and the table says why."""
    from camfab.report.html import dynamics_rows
    from camfab.report.plots import dynamics_figure
    from tests.conftest import base_design

    d = base_design(cam={"kind": "disc", "rotation": "cw", "speed_rpm": 100.0},
                    follower={"type": "knife", "motion": "translating", "base_radius_mm": 15.0, "offset_mm": 5.0},
                    dynamics={"mass_kg": 0.5, "spring_rate_n_per_mm": 2.0, "spring_preload_n": 30.0,
                              "friction_coefficient": 1.5, "safety_force_n": 5.0})
    spec, geom, rep = checked_design(design_from_dict(d))
    locks = rep.by_code("SELF_LOCKING")
    assert len(locks) == 2
    top = dynamics_figure(spec, geom, rep).axes[0]
    y = top.lines[0].get_ydata()
    assert np.nanmax(np.abs(y)) < 1e3 < abs(rep.dynamics.contact_force.min)
    assert top.get_ylim()[1] < 1e3  # the ±1e13 extremes are not drawn
    spans = {(round(p.get_x(), 6), round(p.get_x() + p.get_width(), 6)) for p in top.patches}
    assert {(round(f.from_deg, 6), round(f.to_deg, 6)) for f in locks} <= spans
    row = dynamics_rows(spec, rep)[0]
    assert row["status"] == "bad" and row["comment"].startswith("Friction wedges the follower")


def test_translating_cam_figure_shows_the_drive_force(wedge):
    from camfab.report.plots import report_figures

    spec, geom, rep = wedge
    top, bottom = report_figures(spec, geom, rep)["dynamics"].axes
    assert bottom.get_ylabel() == "drive force (N)" and bottom.get_xlabel() == "cam travel (mm)"
    xs = bottom.lines[0].get_xdata()
    np.testing.assert_allclose(bottom.lines[0].get_ydata(), _dynamics(spec, geom).evaluate(xs).drive, rtol=1e-12)
    assert top.get_xlim() == (0.0, 200.0)
    # at the top of the cycloidal rise S = 10 mm, S' = S'' = 0 and the normal is vertical: N = F0 + k·S
    s = _dynamics(spec, geom).evaluate([100.0])
    assert s.contact_force[0] == pytest.approx(20.0 + 1.0e3 * 0.010, rel=1e-9)
    assert rep.dynamics.contact_force.max == pytest.approx(30.0, rel=1e-9)


# ---------------------------------------------------------------------------
# HTML
def _table_values(page: str, table_id: str) -> list[float]:
    m = re.search(rf'<table id="{table_id}">(.*?)</table>', page, re.S)
    assert m, table_id
    return [float(v) for v in re.findall(r'data-value="([^"]+)"', m.group(1))]


def test_html_report_has_the_dynamics_section(valve, valve_files):
    spec, geom, rep = valve
    page = valve_files["report.html"].decode()
    assert '<section id="dynamics">' in page and '<a href="#dynamics">Dynamics</a>' in page
    assert '<figure id="plot-dynamics"' in page and 'src="plots/dynamics.svg"' in page
    assert "plots/dynamics.png" not in valve_files and b"<svg" in valve_files["plots/dynamics.svg"]
    assert page.count('data-plot="dynamics"') == 1  # shown in its section, not again among the plots
    d = rep.dynamics
    assert d.torque
    want = [d.contact_force.max, d.contact_force.min, d.safety_force_n, d.bearing_force.max, d.drive.max,
            d.drive.min, d.work_per_cycle_j, d.mean_power_w, d.preload_needed.value, d.jump_speed.value]
    assert _table_values(page, "dynamics-table") == want  # exact floats, in table order
    assert want[1] == pytest.approx(193.913, abs=1e-3) and want[2] == 100.0
    for text in ("Contact force (N)", "Drive torque (N·m)", "Work per cycle (J)", "Mean power (W)",
                 "Preload needed (N)", "Jump speed (rpm)", "Never below the safety force 100 N", "193.91",
                 "539.70", "25.6°", "(the design has 250 N)", "design: 1500 rpm"):
        assert text in page, text
    # the inputs list the [dynamics] keys in the file's units
    assert "<th>spring_rate_n_per_mm</th><td>30</td>" in page and "<th>friction_coefficient</th><td>0.06</td>" in page
    assert "Smallest contact force 193.91 N at 25.6° (safety force 100 N)" in page


def test_html_report_flags_a_jumping_follower(press_fast):
    spec, geom, rep = press_fast
    page = render_report(spec, geom, rep)["report.html"].decode()
    rows = re.findall(r'<tr class="(\w+)"><td>([^<]+)</td>', page.split('id="dynamics-table"')[1].split("</table>")[0])
    status = dict((concept, cls) for cls, concept in rows)
    assert status["Contact force (N)"] == "bad" and status["Preload needed (N·m)"] == "bad"
    assert status["Jump speed (rpm)"] == "bad" and status["Safety force (N)"] == "ok"
    assert "The follower leaves the cam (N &lt; 0): see the findings" in page
    assert 'data-code="FOLLOWER_JUMP"' in page
    assert _table_values(page, "dynamics-table")[1] == rep.dynamics.contact_force.min < 0


def test_html_report_without_dynamics(e9_files):
    page = e9_files["report.html"].decode()
    assert 'id="dynamics' not in page and "plots/dynamics" not in page
    assert not any(k.startswith("plots/dynamics") for k in e9_files)


# ---------------------------------------------------------------------------
# xlsx export
def _book(spec, geom, rep, **kw):
    return openpyxl.load_workbook(io.BytesIO(camdas_workbook(spec, geom, rep, **kw)))


def _sheet_columns(ws):
    rows = list(ws.iter_rows(values_only=True))
    return rows[0], np.array([[np.nan if v is None else v for v in r] for r in rows[1:]], dtype=float)


def test_xlsx_dynamics_sheet_values(valve):
    spec, geom, rep = valve
    wb = _book(spec, geom, rep)
    assert wb.sheetnames == ["CAM-DAS", "Checks", "Lift table", "Dynamics"]
    head, data = _sheet_columns(wb["Dynamics"])
    assert head == ("Cam angle (deg)", "Contact force (N)", "Friction force (N)", "Bearing force (N)",
                    "Drive torque (N·m)", "Power (W)", "Contact stress (MPa)")
    assert data.shape == (361, 7) and wb["Dynamics"].max_row == 362
    np.testing.assert_allclose(data[:, 0], np.arange(361.0), rtol=0, atol=1e-12)
    # the same grid as the CAM-DAS sheet
    camdas = [wb["CAM-DAS"][f"A{10 + i}"].value for i in range(361)]
    np.testing.assert_array_equal(data[:, 0], camdas)
    deg = np.array([0, 25, 26, 90, 185, 186, 300])
    ref = _dynamics(spec, geom).evaluate(np.radians(deg))
    np.testing.assert_allclose(data[deg, 1], ref.contact_force, rtol=1e-12)
    np.testing.assert_allclose(data[deg, 2], ref.friction_force, rtol=1e-12)
    np.testing.assert_allclose(data[deg, 3], ref.bearing_force, rtol=1e-12)
    np.testing.assert_allclose(data[deg, 4], ref.drive, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(data[deg, 5], ref.power, rtol=1e-12, atol=1e-9)
    # physics spot checks: base-circle dwell N = preload, friction = μN, power = T·ω
    assert data[300, 1] == pytest.approx(250.0, rel=1e-12) and data[300, 2] == pytest.approx(0.06 * 250.0, rel=1e-12)
    np.testing.assert_allclose(data[:, 5], data[:, 4] * spec.speed, rtol=1e-12, atol=1e-9)
    d = rep.dynamics.contact_force
    assert d.min <= np.nanmin(data[:, 1]) and np.nanmax(data[:, 1]) <= d.max * (1 + 1e-12)  # exact extremes


def test_xlsx_dynamics_summary_in_the_checks_sheet(press_fast):
    spec, geom, rep = press_fast
    ws = _book(spec, geom, rep)["Checks"]
    rows = {r[0]: r[1:5] for r in ws.iter_rows(values_only=True) if r[0]}
    d = rep.dynamics
    exact = lambda v: pytest.approx(v, rel=1e-15)  # noqa: E731 - openpyxl stores floats with 16 digits
    assert rows["Minimum contact force"] == (exact(d.contact_force.min), "N", exact(d.contact_force.at_min), None)
    assert d.torque and rows["Maximum drive torque"][:3] == (exact(d.drive.max), "N·m", exact(d.drive.at_max))
    assert rows["Safety force"][:2] == (50, "N")
    assert rows["Preload needed"][:2] == (exact(d.preload_needed.value), "N·m")
    assert rows["Jump speed"][:2] == (exact(d.jump_speed.value), "rpm")
    assert rows["Work per cycle"][1] == "J" and rows["Mean power"][1] == "W"
    assert "FOLLOWER_JUMP" in rows  # findings still follow


def test_xlsx_oscillating_step_and_translating_cam(press, wedge):
    spec, geom, rep = press
    head, data = _sheet_columns(_book(spec, geom, rep, step_deg=2.0)["Dynamics"])
    assert data.shape == (181, 7)
    np.testing.assert_allclose(data[:, 0], np.arange(0.0, 361.0, 2.0), rtol=0, atol=1e-12)
    ref = _dynamics(spec, geom).evaluate(np.radians(data[:, 0]))
    np.testing.assert_allclose(data[:, 1], ref.contact_force, rtol=1e-12)
    np.testing.assert_allclose(data[:, 4], ref.drive, rtol=1e-12, atol=1e-12)
    assert np.all(data[:, 2] == 0.0)  # a roller: no sliding friction
    spec, geom, rep = wedge
    wb = _book(spec, geom, rep)
    head, data = _sheet_columns(wb["Dynamics"])
    assert head[0] == "Cam travel (mm)" and head[4] == "Drive force (N)"
    assert data.shape == (361, 7)
    np.testing.assert_allclose(data[:, 0], np.arange(361) * 200.0 / 360, rtol=1e-15)
    idx = np.array([0, 45, 90, 180, 270, 360])
    ref = _dynamics(spec, geom).evaluate(data[idx, 0])
    np.testing.assert_allclose(data[idx, 1], ref.contact_force, rtol=1e-12)
    np.testing.assert_allclose(data[idx, 4], ref.drive, rtol=1e-12, atol=1e-12)
    rows = {r[0]: r[1:4] for r in wb["Checks"].iter_rows(values_only=True) if r[0]}
    assert not rep.dynamics.torque
    assert rows["Maximum drive force"][:2] == (pytest.approx(rep.dynamics.drive.max, rel=1e-15), "N")


def test_no_dynamics_sheet_without_dynamics(e9):
    wb = _book(*e9)
    assert wb.sheetnames == ["CAM-DAS", "Checks", "Lift table"]
    assert not any(r[0] == "Dynamics" for r in wb["Checks"].iter_rows(values_only=True))


# ---------------------------------------------------------------------------
# xlsx design round trip
FULL_TRANSLATING = {"mass_kg": 0.123456789, "spring_rate_n_per_mm": 30.5, "spring_preload_n": 250.0,
                    "damping_n_s_per_m": 1.0 / 3.0, "external_force_n": -4.25, "friction_coefficient": 0.06,
                    "safety_force_n": 100.0}
FULL_OSCILLATING = {"inertia_kg_m2": 0.03, "spring_rate_nm_per_deg": 0.05, "spring_preload_nm": 12.0,
                    "damping_nm_s_per_deg": 0.1 + 0.2, "external_torque_nm": 1.5, "safety_force_n": 50.0}


def _bare(spec):
    return dataclasses.replace(spec, source=None, motion_table=None)


@pytest.mark.parametrize("path, over", [(VALVE, None), (PRESS, None), (VALVE, FULL_TRANSLATING),
                                        (PRESS, FULL_OSCILLATING)], ids=["valve", "press", "valve-all", "press-all"])
def test_xlsx_design_round_trip_keeps_dynamics(tmp_path, path, over):
    data = _toml(path, **({"dynamics": over} if over else {}))
    spec = design_from_data(data, source=str(path), base_dir=path.parent)
    keys = {k: v for k, v in design_rows(spec)[0] if k.startswith("dynamics.")}
    file = tmp_path / "d.xlsx"
    file.write_bytes(design_to_xlsx(spec))
    back = load_design_xlsx(file)
    assert back.dynamics == spec.dynamics
    for field in dataclasses.fields(spec.dynamics):  # every field, the same float
        assert getattr(back.dynamics, field.name) == getattr(spec.dynamics, field.name), field.name
    assert _bare(back) == _bare(spec)
    given = data["dynamics"]
    assert {k[len("dynamics."):] for k in keys} >= set(given)
    for k, v in given.items():
        assert float(keys[f"dynamics.{k}"]) == v
    if over:  # nothing left at its default
        d = spec.dynamics
        assert d.damping == pytest.approx(over.get("damping_n_s_per_m", over.get("damping_nm_s_per_deg")))
        assert d.external != 0.0
    motion = "oscillating" if path == PRESS else "translating"
    assert back.dynamics.motion == motion
    assert (f"dynamics.{'inertia_kg_m2' if motion == 'oscillating' else 'mass_kg'}") in keys


def test_xlsx_design_without_dynamics_writes_no_dynamics_keys():
    spec = load_design(EXAMPLES / "ejemplo9rt.toml")
    assert not any(k.startswith("dynamics") for k, _ in design_rows(spec)[0])


def test_xlsx_design_dynamics_errors_name_the_cell(tmp_path):
    spec = load_design(PRESS)
    wb = openpyxl.load_workbook(io.BytesIO(design_to_xlsx(spec)))
    ws = wb["design"]
    row = next(r for r in ws.iter_rows() if r[0].value == "dynamics.inertia_kg_m2")
    row[1].value = -1.0
    ws.append(["dynamics.mass_kg", 0.5])  # a translating key on an oscillating follower
    file = tmp_path / "bad.xlsx"
    wb.save(file)
    with pytest.raises(SpecError) as info:
        load_design_xlsx(file)
    text = str(info.value)
    assert f"dynamics.inertia_kg_m2 [design!B{row[1].row}]" in text
    assert f"dynamics.mass_kg [design!B{ws.max_row}]" in text and "is for translating followers" in text


# ---------------------------------------------------------------------------
# form-closed followers (constant width: one profile touched twice)
@pytest.fixture(scope="module")
def width():
    data = _toml(EXAMPLES / "constant_width.toml", cam={"speed_rpm": 300.0})
    data["dynamics"] = {"mass_kg": 0.4, "friction_coefficient": 0.05}
    return checked_design(design_from_dict(data, source=str(EXAMPLES / "constant_width.toml")))


def test_form_closed_figure_xlsx_and_html(width):
    from camfab.design.assemble import dynamics_model
    from camfab.report.plots import report_figures

    spec, geom, rep = width
    d = rep.dynamics
    assert d.form_closed and [round(a, 6) for a, _ in d.load_reversals] == [60.0, 240.0]
    ref = dynamics_model(spec, geom)
    top, _ = report_figures(spec, geom, rep)["dynamics"].axes
    c = geom.profiles[0]
    x = sample_grid(c.period, c.breakpoints, 1441)
    sm = ref.evaluate(x)
    np.testing.assert_allclose(top.lines[0].get_ydata(), sm.contact_force, rtol=1e-12)
    np.testing.assert_allclose(top.lines[1].get_ydata(), sm.contact_force_2, rtol=1e-12)
    head, data = _sheet_columns(_book(spec, geom, rep)["Dynamics"])
    assert head[1:3] == ("Contact force, follower 1 (N)", "Contact force, follower 2 (N)")
    deg = np.array([10, 59, 61, 100, 200, 250])
    s = ref.evaluate(np.radians(deg))
    np.testing.assert_allclose(data[deg, 1], s.contact_force, rtol=1e-12)
    np.testing.assert_allclose(data[deg, 2], s.contact_force_2, rtol=1e-12)
    assert np.all((data[:, 1] == 0) | (data[:, 2] == 0))  # never both
    page = render_report(spec, geom, rep)["report.html"].decode()
    for text in ("Contact force, follower 2 (N)", "Load reversals", "60.0°, 240.0°", "Form-closed follower"):
        assert text in page, text
    rows = {r[0]: r[1:5] for r in _book(spec, geom, rep)["Checks"].iter_rows(values_only=True) if r[0]}
    assert rows["Maximum contact force, follower 2"][0] == pytest.approx(d.second_contact_force.max, rel=1e-15)
    assert "Jump speed" not in rows and "Safety force" not in rows
