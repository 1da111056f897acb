"""Benchmark: the groove families' slow stages, in CPU seconds (numbers measured by hand before this script).

- ``--build``: the cylindrical example's grooved cylinder (``camfab/cad/kind_exports.py::cylinder_solid``): the
  solid alone, then STEP + STL + IGES + assembly written by one run (the solid built once and shared; cadquery's
  import is done before and not counted), with the STEP files' sizes;
- ``--verify``: ``camfab verify`` of the cylindrical example's 4-axis program (``verify_rotary_program``) and of
  the rib of ``tests/gcode/test_rib_program.py`` (``verify_rib_program``); each program written once, untimed;
  with the read-back's deviation;
- ``--dxf``: ``export --dxf`` of the groove example: the DXF stage in this process (``build_artifacts``), and
  ``python -m camfab export groove_translating --dxf`` as a whole process (bytecode cached, as installed).

Every figure is CPU time (``time.process_time``, or the child's user + system time), the best of ``--repeat``
after one untimed warm-up: on a shared machine wall time is noisy. Without a flag, all three.

Run:  PYTHONPATH=. python3 benchmarks/bench_cylinder.py [--build] [--verify] [--dxf] [--repeat 3] [--root DIR]
"""
from __future__ import annotations

import argparse
import functools
import math
import os
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

HERE = Path(__file__).resolve().parent


def _best(fn: Callable[[], Any], repeat: int) -> tuple[float, Any]:
    """The best CPU time of ``fn()`` over ``repeat`` runs after one warm-up, and its last result."""
    out = fn()
    best = math.inf
    for _ in range(repeat):
        t0 = time.process_time()
        out = fn()
        best = min(best, time.process_time() - t0)
    return best, out


def build(repeat: int) -> None:
    import cadquery  # noqa: F401  (its ~3 s import is not the build's)

    from camfab.cad.kind_exports import cylinder_solid
    from camfab.pipeline import Output, Request, load, run

    req = Request(frozenset({Output.STEP, Output.STL, Output.IGES, Output.ASSEMBLY}))

    def solid() -> float:
        return cylinder_solid(load("cylindrical_translating"), req)[1]  # a fresh cam: its cache is empty

    t, dev = _best(solid, repeat)
    print(f"cylindrical_translating: the grooved cylinder's build {t:.2f} s CPU (path deviation {dev:.3g} mm)")
    with tempfile.TemporaryDirectory() as folder:
        def files() -> Any:
            return run(load("cylindrical_translating"), folder, req)

        t, res = _best(files, repeat)
        sizes = {k: Path(v).stat().st_size for k, v in res.files.items() if k.lower().endswith((".step", ".stp"))}
    names = sorted(k for k in res.files if k != "check.json")
    stages = ", ".join(f"{k} {v:.2f}" for k, v in res.timings.items())
    print(f"  STEP + STL + IGES + assembly from one build: {t:.2f} s CPU ({', '.join(names)}; stage wall s: {stages})")
    print("  STEP sizes: " + ", ".join(f"{k} {n / 1000:.0f} kB" for k, n in sorted(sizes.items())))


def verify(repeat: int) -> None:
    from camfab.gcode.rib_program import rib_gcode
    from camfab.gcode.rib_verify import verify_rib_program
    from camfab.gcode.rotary import cylinder_job, rotary_gcode
    from camfab.gcode.rotary_verify import verify_rotary_program
    from camfab.pipeline import gcode_job, load
    from tests.gcode.test_rib_program import RIB_TOML  # the rib of the tests, with a 12.1 mm cutter

    with tempfile.TemporaryDirectory() as folder:
        rib = Path(folder) / "rib.toml"
        rib.write_text(RIB_TOML, encoding="utf-8")
        cases = (("cylindrical_translating", load("cylindrical_translating"), rotary_gcode, verify_rotary_program),
                 ("rib (test_rib_program)", load(str(rib)), rib_gcode, verify_rib_program))
        for name, cam, program, check in cases:
            tol = cam.tolerance(None)
            job = cylinder_job(gcode_job(cam.spec, tol=tol), cam.geometry)
            t0 = time.process_time()
            data, moves, _ = program(cam.geometry, job, tol, "linuxcnc")
            made = time.process_time() - t0
            t, rep = _best(functools.partial(check, data, cam.geometry, job, tol=tol), repeat)
            print(f"{name}: 4-axis program {len(data.splitlines())} lines, {moves} moves, written in "
                  f"{made:.2f} s CPU; verify {t:.2f} s CPU: {'OK' if rep.ok else 'FAILED'}, max deviation "
                  f"{rep.max_deviation_mm:.3g} mm (tol {tol:g})")


def dxf(repeat: int, root: str | None) -> None:
    from camfab.cad.artifact import build_artifacts
    from camfab.pipeline import load

    cam = load("groove_translating")
    tol = cam.tolerance(None)
    t, (art,) = _best(lambda: build_artifacts(cam.spec, cam.geometry, ["dxf"], tol=tol), repeat)
    print(f"groove_translating: DXF stage {t:.2f} s CPU in process ({art.entities} entities, max deviation "
          f"{art.deviation_mm:.3g} mm, tol {tol:g})")
    cache = tempfile.mkdtemp(prefix="camfab-pyc-")
    env = dict(os.environ, PYTHONPATH=root or str(HERE.parent), PYTHONPYCACHEPREFIX=cache)
    env.pop("PYTHONDONTWRITEBYTECODE", None)  # cached bytecode, as an installed wheel has
    folder = os.path.join(cache, "out")
    best = math.inf
    for i in range(repeat + 1):
        shutil.rmtree(folder, ignore_errors=True)
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        subprocess.run([sys.executable, "-m", "camfab", "export", "groove_translating", "--dxf", "--force", "-o",
                        folder], env=env, cwd=cache, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=True)
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        if i:
            best = min(best, after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime)
    shutil.rmtree(cache, ignore_errors=True)
    print(f"  python -m camfab export groove_translating --dxf: {best:.2f} s CPU as a process")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--build", action="store_true", help="the cylinder solid and its four files from one build")
    ap.add_argument("--verify", action="store_true", help="verify of the cylindrical example's 4-axis program")
    ap.add_argument("--dxf", action="store_true", help="export --dxf of the groove example")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--root", default=None, help="with --dxf: the checkout whose camfab the process runs")
    args = ap.parse_args()
    every = not (args.build or args.verify or args.dxf)
    if every or args.build:
        build(args.repeat)
    if every or args.verify:
        verify(args.repeat)
    if every or args.dxf:
        dxf(args.repeat, args.root)


if __name__ == "__main__":
    main()
