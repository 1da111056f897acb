"""Fixtures of the HTML-report tests: checked designs and their rendered files (built once per session).

Nothing here needs jinja2 or matplotlib until a ``*_files`` fixture is used."""
from __future__ import annotations

import pytest

from camfab.design.spec import design_from_dict
from camfab.formats import load_design
from camfab.report.html import render_report, write_files
from tests.report.designs import checked_design

from ..conftest import EXAMPLES
from .designs import DESIGNS


@pytest.fixture(scope="session")
def e9():
    """Ejemplo9RT: (spec, geometry, report) — jerk jumps only, not_for_high_speed."""
    return checked_design(load_design(EXAMPLES / "ejemplo9rt.toml"))


@pytest.fixture(scope="session")
def valve():
    """The exhaust-valve knot-table cam with a flat-face follower."""
    return checked_design(load_design(EXAMPLES / "valve_exhaust_ej1.toml"))


@pytest.fixture(scope="session")
def bad():
    """A roller cam with a too-small base circle: undercut and pressure-angle errors."""
    return checked_design(design_from_dict(DESIGNS["bad_roller"]))


@pytest.fixture(scope="session")
def e9_files(e9):
    return render_report(*e9)


@pytest.fixture(scope="session")
def bad_files(bad):
    return render_report(*bad)


@pytest.fixture(scope="session")
def valve_files(valve):
    return render_report(*valve)


@pytest.fixture(scope="session")
def e9_dir(e9_files, tmp_path_factory):
    out = tmp_path_factory.mktemp("report_e9")
    write_files(e9_files, out)
    return out


@pytest.fixture(scope="session")
def bad_dir(bad_files, tmp_path_factory):
    out = tmp_path_factory.mktemp("report_bad")
    write_files(bad_files, out)
    return out


@pytest.fixture(scope="session")
def valve_dir(valve_files, tmp_path_factory):
    out = tmp_path_factory.mktemp("report_valve")
    write_files(valve_files, out)
    return out
