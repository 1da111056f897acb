"""``camfab check`` loads only what checking needs: none of the heavy libraries (plotting, pages, CAD,
spreadsheets, meshes, scipy) and none of camfab's exporters — the guard behind its start-up time
(docs/decisions.md "Lazy imports"), nor the cam families and models its design does not use, with BLAS on one
thread (docs/decisions.md "Start-up and export time"); and the scipy-free Brent root finder camfab uses instead of
``scipy.optimize.brentq`` gives scipy's roots bit for bit."""
from __future__ import annotations

import json
import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from camfab.brent import brentq

ROOT = Path(__file__).resolve().parents[1]
HEAVY = ("matplotlib", "jinja2", "ezdxf", "openpyxl", "shapely", "trimesh", "scipy", "cadquery", "OCP", "PIL",
         "dask", "numpy.ma", "numpy.polynomial")
#: camfab's own exporters (``camfab.cad`` itself and ``camfab.cad.artifact``, the stages' light entry points, are
#: allowed)
EXPORTERS = ("camfab.cad.export", "camfab.cad.dxf", "camfab.cad.step", "camfab.cad.stl", "camfab.cad.plate",
             "camfab.cad.drawing", "camfab.discretize", "camfab.offset", "camfab.gcode", "camfab.report.plots",
             "camfab.report.html", "camfab.package")

_RUN = """
import json, os, runpy, sys
sys.argv = ["camfab", *sys.argv[1:]]
try:
    runpy.run_module("camfab", run_name="__main__", alter_sys=True)
except SystemExit as e:
    code = e.code
from threadpoolctl import threadpool_info
blas = [p["num_threads"] for p in threadpool_info() if p["user_api"] == "blas"]
print(json.dumps({"code": code, "modules": sorted(sys.modules), "blas_threads": blas,
                  "env": {k: os.environ.get(k) for k in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS")}}),
      file=sys.stderr)
"""
#: the variables any BLAS reads for its thread count (none set: the command line's default applies)
_THREAD_VARS = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS", "GOTO_NUM_THREADS")


def _run(tmp_path: Path, *args: str, **env_over: str) -> dict:
    env = {k: v for k, v in os.environ.items() if k not in _THREAD_VARS}
    env.update(PYTHONPATH=str(ROOT), **env_over)
    r = subprocess.run([sys.executable, "-c", _RUN, *args], cwd=tmp_path, env=env, capture_output=True,
                       text=True, timeout=120)
    return json.loads(r.stderr.strip().splitlines()[-1])


def _modules_after(tmp_path: Path, *args: str) -> tuple[int, set[str]]:
    last = _run(tmp_path, *args)
    return last["code"], set(last["modules"])


@pytest.mark.parametrize("example", ["ejemplo9rt", "ejemplo8da_conjugate", "constant_width", "valve_exhaust_ej1"])
def test_check_imports_no_heavy_module(tmp_path, example):
    code, mods = _modules_after(tmp_path, "check", example)
    assert code in (0, 1), code  # it checked (1: a warning verdict)
    assert "camfab.design.checks" in mods  # the run really checked
    loaded = sorted(m for m in mods if m.split(".")[0] in HEAVY or m in HEAVY
                    or any(m == e or m.startswith(e + ".") for e in EXPORTERS))
    assert not loaded, f"`camfab check {example}` imported {loaded}"


def test_brentq_matches_scipy_bit_for_bit():
    scipy_brentq = pytest.importorskip("scipy.optimize").brentq
    rng = np.random.default_rng(7)
    n = 0
    for _ in range(300):
        c = rng.normal(size=6)
        for f in (lambda x, c=c: float(np.polyval(c, x)), lambda x, c=c: math.sin(c[0] * x) + c[1] * x ** 3 - c[2]):
            xs = np.linspace(-3.0, 3.0, 25)
            v = np.array([f(x) for x in xs])
            for i in np.flatnonzero(v[:-1] * v[1:] < 0):
                for xtol, rtol in ((2e-12, 4 * np.finfo(float).eps), (1e-15, 4 * np.finfo(float).eps), (1e-6, 1e-9)):
                    assert brentq(f, xs[i], xs[i + 1], xtol=xtol, rtol=rtol) == \
                        scipy_brentq(f, xs[i], xs[i + 1], xtol=xtol, rtol=rtol)
                    n += 1
    assert n > 500


def test_brentq_refuses_what_scipy_refuses():
    with pytest.raises(ValueError, match="different signs"):
        brentq(lambda x: x * x + 1, -1.0, 1.0)
    with pytest.raises(ValueError, match="NaN"):
        brentq(lambda x: math.nan, -1.0, 1.0)
    with pytest.raises(RuntimeError, match="converge"):
        brentq(lambda x: x, -1.0, 2.0, maxiter=1)
    assert brentq(lambda x: x, 0.0, 1.0) == 0.0  # a root at an end is returned as given


#: camfab's modules a check of each design must not import (each is imported on first use by the designs that
#: have it: the other cam families, the force/stress/vibration models without [dynamics], sizing)
_FAMILIES = ("conjugate", "cylindrical", "curved", "groove", "symmetric", "wedge")
_MODELS = ("dynamics", "strength", "vibration", "vibration_results", "sizing_plan", "sizing")
_NOT_NEEDED = {
    "ejemplo9rt": [*_FAMILIES, "faces", *_MODELS, "vibration_spec", "optimise_spec", "cylinder_spec", "strength_spec",
                   "materials"],
    "ejemplo8da_conjugate": ["cylindrical", "curved", "groove", "wedge", "sizing_plan", "vibration"],
    "constant_width": ["cylindrical", "curved", "groove", "wedge", "sizing_plan", "sizing", "vibration"],
    "cylindrical_translating": ["conjugate", "curved", "groove", "symmetric", "wedge", *_MODELS],
}


@pytest.mark.parametrize("example", sorted(_NOT_NEEDED))
def test_check_imports_only_its_own_family_and_models(tmp_path, example):
    code, mods = _modules_after(tmp_path, "check", example)
    assert code in (0, 1), code
    loaded = sorted(m for m in _NOT_NEEDED[example] if f"camfab.design.{m}" in mods)
    assert not loaded, f"`camfab check {example}` imported camfab.design.{loaded}"


def test_import_camfab_loads_no_numpy():
    """``import camfab`` is light: the command line sets BLAS's thread count before numpy starts."""
    code = "import sys, camfab; camfab.__version__; print('numpy' in sys.modules)"
    r = subprocess.run([sys.executable, "-c", code], env=dict(os.environ, PYTHONPATH=str(ROOT)), capture_output=True,
                       text=True, timeout=60, check=True)
    assert r.stdout.strip() == "False"


def test_cli_runs_blas_on_one_thread_unless_the_user_says(tmp_path):
    """``camfab`` sets OpenBLAS/OpenMP to one thread before numpy is imported (docs/decisions.md, "Start-up and
    export time"); a thread count the user set (any BLAS variable) is left as it is."""
    default = _run(tmp_path, "check", "ejemplo9rt")
    assert default["env"] == {"OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1"}
    assert default["blas_threads"] and set(default["blas_threads"]) == {1}
    user = _run(tmp_path, "check", "ejemplo9rt", OMP_NUM_THREADS="2")
    assert user["env"] == {"OPENBLAS_NUM_THREADS": None, "OMP_NUM_THREADS": "2"}
    if (os.cpu_count() or 1) >= 2:  # OpenBLAS caps the count at the cores
        assert set(user["blas_threads"]) == {2}


def test_check_of_a_toml_design_imports_no_workbook_module(tmp_path):
    """The workbook side of camfab.formats (and the lift table's module it writes) loads on first use only; its
    names are still importable from the package (docs/decisions.md, "Start-up: records' methods without compiled
    source")."""
    code, mods = _modules_after(tmp_path, "check", "valve_exhaust_ej1")
    assert code in (0, 1), code
    workbook = ("camfab.formats.xlsx_design", "camfab.formats.camdas_workbook", "camfab.formats.xlsx_blocks",
                "camfab.design.tables")
    assert not [m for m in workbook if m in mods]
    probe = ("import camfab.formats as f, camfab.formats.xlsx_design as x; "
             "print(f.design_to_xlsx is x.design_to_xlsx, f.load_design_xlsx is x.load_design_xlsx, "
             "f.design_rows is x.design_rows, hasattr(f, 'no_such_name'))")
    r = subprocess.run([sys.executable, "-c", probe], env=dict(os.environ, PYTHONPATH=str(ROOT)), capture_output=True,
                       text=True, timeout=60, check=True)
    assert r.stdout.split() == ["True", "True", "True", "False"]
