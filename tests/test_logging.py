"""One logger hierarchy, ``"camfab"``, for the fallbacks camfab takes, as a gate: real fallbacks leave a
record on a ``camfab.*`` logger, ``camfab -v`` shows them on stderr, no library module prints, and every
logger a module creates is ``logging.getLogger(__name__)`` (or a ``"camfab..."`` name)."""
from __future__ import annotations

import ast
import logging
from pathlib import Path

import numpy as np

import camfab
from camfab.cli import main

PACKAGE = Path(camfab.__file__).resolve().parent
#: modules whose job is to talk to the user on stdout/stderr
PRINTING = {"cli.py", "cli_design.py", "__main__.py"}  # the command line's presentation modules, its console entry
#: module-level logging calls that would log to (or configure) the root logger
#: a library's logger camfab filters, never logs through: the local Dask workers' preload drops the heartbeat
#: failure a closing worker's own close causes (docs/decisions.md, "Ctrl-C from start to exit")
FILTERED_LOGGERS = {("dask_worker.py", "distributed.worker")}
ROOT_CALLS = {"basicConfig", "debug", "info", "warning", "warn", "error", "exception", "critical", "log"}


def _records(caplog, level=logging.INFO) -> list[logging.LogRecord]:
    return [r for r in caplog.records if r.name.startswith("camfab.") and r.levelno >= level]


def test_the_camfab_logger_has_a_null_handler():
    assert any(isinstance(h, logging.NullHandler) for h in logging.getLogger("camfab").handlers)


def test_integrate_capped_logs_a_warning(caplog):
    from camfab.numeric import integrate

    with caplog.at_level(logging.WARNING, logger="camfab"):
        value = integrate(lambda x: 1.0 / np.sqrt(np.abs(x - 0.3)), [0.0, 1.0])  # singular: never converges
    assert abs(value - 2 * (np.sqrt(0.3) + np.sqrt(0.7))) < 1e-3
    (rec,) = _records(caplog, logging.WARNING)
    assert rec.name == "camfab.quadrature" and "not converged to rtol = 1e-11" in rec.getMessage()


def test_search_stopped_at_its_round_cap_logs_a_warning(caplog, monkeypatch):
    from camfab import numeric

    monkeypatch.setattr(numeric, "_MIN_ROUNDS", 1)  # one round cannot locate a minimum to 1e-9 of its bracket
    with caplog.at_level(logging.WARNING, logger="camfab"):
        at, _ = numeric.extremum(lambda x: np.abs(x - 1.234567) ** 1.3, [0.0, 3.0])
    assert abs(at - 1.234567) < 1e-3
    (rec,) = _records(caplog, logging.WARNING)
    assert rec.name == "camfab.numeric" and "still open at the round cap (1 rounds for minima" in rec.getMessage()
    caplog.clear()
    monkeypatch.undo()
    with caplog.at_level(logging.WARNING, logger="camfab"):
        at, _ = numeric.extremum(lambda x: np.abs(x - 1.234567) ** 1.3, [0.0, 3.0])
    assert _records(caplog) == [] and abs(at - 1.234567) < 1e-7


def test_pitch_curve_fit_of_its_own_is_logged(caplog):
    from camfab.cad.export import _pitch_loop
    from camfab.discretize import arcs
    from camfab.offset.cutter import pitch_curve, profile_curve

    c = camfab.load("ejemplo9rt").geometry.profiles[0]
    coarse = arcs(profile_curve(c), tol=0.01)  # its offset cannot meet the pitch curve within 0.001 mm
    with caplog.at_level(logging.INFO, logger="camfab"):
        loop = _pitch_loop(coarse, c.roller_radius, pitch_curve(c), 0.001)
    assert loop.max_deviation <= 0.001
    msgs = [r.getMessage() for r in _records(caplog) if r.name == "camfab.offset.cutter"]  # offset_loop's
    assert len(msgs) == 1 and "> tol = 0.001 mm" in msgs[0] and "fitted on its own" in msgs[0]


def test_arc_spline_fallback_is_logged(caplog):
    from camfab.discretize import arcs
    from camfab.offset.cutter import profile_curve

    c = camfab.load("constant_width").geometry.profiles[0]  # its SHM rise cannot keep the dwell's curvature
    with caplog.at_level(logging.INFO, logger="camfab"):
        assert arcs(profile_curve(c), tol=0.001).max_deviation <= 0.001
    assert any(r.name == "camfab.discretize.arcspline" and "free end curvatures" in r.getMessage()
               for r in _records(caplog))


def test_unreadable_package_manifest_is_logged(tmp_path, caplog):
    from camfab.package import MANIFEST, _old_entries

    (tmp_path / MANIFEST).write_text("{not json", encoding="utf-8")
    with caplog.at_level(logging.INFO, logger="camfab"):
        assert _old_entries(tmp_path) == {}
        assert _old_entries(tmp_path / "missing") == {}  # no manifest yet: the normal first build, silent
    (rec,) = _records(caplog)
    assert rec.levelno == logging.WARNING and "every design is rebuilt" in rec.getMessage()


def test_cli_verbose_shows_the_fallbacks_on_stderr(tmp_path, capsys):
    assert main(["export", "constant_width", "--dxf", "-o", str(tmp_path), "-v"]) == 0
    err = capsys.readouterr().err
    assert "camfab: INFO: arcs:" in err and "[camfab.discretize.arcspline]" in err
    assert main(["-v", "check", "ejemplo9rt"]) in (0, 1)  # the flag also goes before the command
    assert main(["export", "constant_width", "--dxf", "-o", str(tmp_path / "quiet")]) == 0
    assert "INFO" not in capsys.readouterr().err  # without -v: warnings only
    assert not any(isinstance(h, logging.StreamHandler) and not isinstance(h, logging.NullHandler)
                   for h in logging.getLogger("camfab").handlers)  # the command's handler is removed


def _calls(tree: ast.AST):
    return [n for n in ast.walk(tree) if isinstance(n, ast.Call)]


def test_no_library_module_prints_and_every_logger_is_camfab():
    prints, loggers = [], []
    for path in sorted(PACKAGE.rglob("*.py")):
        rel = path.relative_to(PACKAGE).as_posix()
        for call in _calls(ast.parse(path.read_text(encoding="utf-8"))):
            f = call.func
            if isinstance(f, ast.Name) and f.id == "print" and rel not in PRINTING:
                prints.append(f"{rel}:{call.lineno}")
            if isinstance(f, ast.Attribute) and isinstance(f.value, ast.Name) and f.value.id == "logging":
                if f.attr == "getLogger":
                    arg = call.args[0] if call.args else None
                    ok = (isinstance(arg, ast.Name) and arg.id == "__name__") or \
                        (isinstance(arg, ast.Constant) and str(arg.value).split(".")[0] == "camfab") or \
                        (isinstance(arg, ast.Constant) and (rel, arg.value) in FILTERED_LOGGERS)
                    if not ok:
                        loggers.append(f"{rel}:{call.lineno}: {ast.unparse(call)}")
                elif f.attr in ROOT_CALLS:
                    loggers.append(f"{rel}:{call.lineno}: {ast.unparse(call)} (the root logger)")
    assert prints == [], "library modules log (logging.getLogger(__name__)) instead of printing: " + str(prints)
    assert loggers == [], "use logging.getLogger(__name__), a child of 'camfab': " + str(loggers)
