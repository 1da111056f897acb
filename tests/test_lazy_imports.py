"""``camfab check`` loads only what checking needs: none of the heavy libraries (plotting, pages, CAD,
spreadsheets, meshes, scipy) and none of camfab's exporters — the guard behind its start-up time
(docs/decisions.md "Lazy imports"); and the scipy-free Brent root finder camfab uses instead of
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
         "dask", "numpy.ma")
#: camfab's own exporters (``camfab.cad`` itself and ``camfab.cad.artifact``, the stages' light entry points, are
#: allowed)
EXPORTERS = ("camfab.cad.export", "camfab.cad.dxf", "camfab.cad.step", "camfab.cad.stl", "camfab.cad.plate",
             "camfab.cad.drawing", "camfab.discretize", "camfab.offset", "camfab.gcode", "camfab.report.plots",
             "camfab.report.html", "camfab.package")

_RUN = """
import json, runpy, sys
sys.argv = ["camfab", *sys.argv[1:]]
try:
    runpy.run_module("camfab", run_name="__main__", alter_sys=True)
except SystemExit as e:
    code = e.code
print(json.dumps({"code": code, "modules": sorted(sys.modules)}), file=sys.stderr)
"""


def _modules_after(tmp_path: Path, *args: str) -> tuple[int, set[str]]:
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    r = subprocess.run([sys.executable, "-c", _RUN, *args], cwd=tmp_path, env=env, capture_output=True,
                       text=True, timeout=120)
    last = json.loads(r.stderr.strip().splitlines()[-1])
    return last["code"], set(last["modules"])


@pytest.mark.parametrize("example", ["ejemplo9rt", "ejemplo8da_conjugate", "constant_width"])
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
