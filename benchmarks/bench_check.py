"""Benchmark: ``check()`` of every built-in example, cold, against the target of 25 ms.

``check()`` is the design's whole check as ``camfab check`` runs it (``camfab.design.assemble.check_design``
with the design's tool radius; follower dynamics and knot-table warnings included where the design has
them), timed *cold*: the design read afresh and numeric's caches cleared each time, so nothing computed by
an earlier run is reused.  Best of ``--repeat`` (the machine may be shared).

``--baseline [REF]`` times the same in the code before the redesign (``benchmarks/baseline.py``) in the
same run.  ``--steep`` times, instead, the steep designs of issue 12 (a 10 mm rise over 1° … 0.001°, a flat face
turning at 0.9995× the cam speed, knots 1e-6° apart with a 1 µm step) with their peak traced allocation: the
cost of a check must not grow with how steep the design is (docs/decisions.md, "Search budgets").

``--process`` times, instead, ``python -m camfab check EXAMPLE`` as a whole process (interpreter start,
imports, reading, checking, printing) for every built-in example: CPU time (user + system, from
``getrusage`` of the child, the measure a loaded machine disturbs least) and wall time, best of ``--repeat``,
against the goal of 0.35 s (issue 15).  ``--root DIR`` runs the camfab found in DIR instead (a checkout to
compare with); ``--against DIR`` times this tree and DIR in alternating rounds (one run of every example each), so
that both see the same load, and prints both.  ``--process --export`` times ``python -m camfab export EXAMPLE
--dxf`` and ``--stl`` (``--force``, into a temporary folder) the same way, against the goal of 1 s each (STEP,
IGES and the assembly are outside the goal: they import cadquery/OCP, ~3 s on their own; README "Benchmarks").
The child processes run without ``PYTHONDONTWRITEBYTECODE`` (bytecode cached in a temporary
``PYTHONPYCACHEPREFIX``, as an installed package has it) and one untimed warm-up run per command fills that cache.
Each timing ends with the floor of this Python: ``-c pass`` (the interpreter and ``site``, whose ``.pth`` files run
in every process) and ``-c "import numpy"``, and what is left of the slowest example above numpy's import.

Run:  python3 benchmarks/bench_check.py [--repeat 7] [--baseline | --steep | --process [--export [--only dxf|stl]]
      [--root DIR] [--against DIR]]
"""
from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
TARGET_MS = 25.0


def _api():
    """(list of (name, path), load_design, check_design) of whichever camfab is imported."""
    from camfab.design.assemble import check_design

    try:
        from camfab.formats import load_design
    except ImportError:  # the code before the redesign read designs in the core
        from camfab.design.spec import load_design
    import camfab

    base = Path(camfab.__file__).parent
    folder = next(p for p in (base / "examples", base / "templates" / "examples") if p.is_dir())
    return sorted((p.stem, p) for p in folder.glob("*.toml")), load_design, check_design


def timings(repeat: int) -> dict[str, float]:
    examples, load_design, check_design = _api()
    try:
        from camfab.numeric import clear_caches
    except ImportError:
        clear_caches = lambda: None  # noqa: E731
    out = {}
    for name, path in examples:
        best = math.inf
        for _ in range(repeat):
            spec = load_design(path)
            tool = spec.manufacturing.tool_diameter_mm
            clear_caches()
            t0 = time.perf_counter()
            check_design(spec, tool_radius_mm=tool / 2 if tool else None)
            best = min(best, time.perf_counter() - t0)
        out[name] = best
    return out


def _steep_designs() -> dict[str, dict]:
    roller = {"type": "roller", "motion": "translating", "base_radius_mm": 50.0, "roller_radius_mm": 5.0}
    flat = {"type": "flat", "motion": "translating", "base_radius_mm": 50.0}
    face = {"type": "flat", "motion": "oscillating", "base_radius_mm": 50.0, "pivot_distance_mm": 130.0,
            "face_offset_mm": 10.0}

    def design(follower, rows=None, **over):
        d = {"name": "steep", "cam": {"kind": "disc", "omega_rad_s": 1.0}, "follower": follower, **over}
        if rows:
            d["motion"] = [{"law": law, "lift": h, "angle_deg": b} for law, h, b in rows]
        return d

    def knots(follower):
        rows = [[0, 0, 0, 0], [90, 0, 0, 0], [90 + 1e-6, 1e-3, 0, 0], [270, 1e-3, 0, 0], [360, 0, 0, 0]]
        return design(follower, motion_table={"rows": rows, "units": {"angle": "deg", "s": "mm", "v": "mm/deg",
                                                                      "a": "mm/deg2"}})

    out = {f"rise 10 mm / {b:g}°": design(roller, [("cycloidal", 10.0, b), ("dwell", 0.0, 180 - b),
                                                   ("cycloidal", -10.0, 180.0)]) for b in (1.0, 0.01, 0.001)}
    b = 2 * 10.0 / 0.9995
    out["face at 0.9995x cam speed"] = design(face, [("cycloidal", 10.0, b), ("dwell", 0.0, 180 - b),
                                                     ("cycloidal", -10.0, 180.0)])
    out["knots 1e-6° / 1 um, roller"] = knots(roller)
    out["knots 1e-6° / 1 um, flat"] = knots(flat)
    return out


def steep(repeat: int) -> None:
    """Time and peak traced allocation of check() on the steep designs (a refusal counts: it is the answer)."""
    import contextlib
    import logging
    import tracemalloc

    from camfab.design.assemble import check_design
    from camfab.design.spec import design_from_dict
    from camfab.errors import CamfabError
    from camfab.numeric import clear_caches

    logging.disable(logging.WARNING)
    print(f"check() of steep designs, cold, best of {repeat}; peak traced allocation of one run")
    for name, d in _steep_designs().items():
        best, answer = math.inf, ""
        for _ in range(repeat):
            spec = design_from_dict(d)
            clear_caches()
            t0 = time.perf_counter()
            try:
                answer = check_design(spec).verdict.value
            except CamfabError:
                answer = "refused (exit 2)"
            best = min(best, time.perf_counter() - t0)
        clear_caches()
        tracemalloc.start()
        with contextlib.suppress(CamfabError):
            check_design(design_from_dict(d))
        peak = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
        print(f"  {name:30}{best * 1e3:9.1f} ms {peak / 2**20:7.1f} MB  {answer}")


PROCESS_TARGET_S = 0.35
EXPORT_TARGET_S = 1.0


def _child_env(root: str | None, cache: str) -> dict[str, str]:
    """The environment of a timed child: camfab from ``root`` (default this checkout), bytecode cached in
    ``cache`` as in an installed package (a checkout run with PYTHONDONTWRITEBYTECODE would compile every module
    on every start)."""
    import os

    env = dict(os.environ, PYTHONPATH=root or str(HERE.parent), PYTHONPYCACHEPREFIX=cache)
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    return env


def process_timings(repeat: int, root: str | None, export: tuple[str, ...] = (), cache: str | None = None,
                    warm: bool = True) -> dict[str, tuple[float, float]]:
    """{example: (best CPU s, best wall s)} of ``python -m camfab check EXAMPLE`` as a whole process, or of
    ``python -m camfab export EXAMPLE <export...> --force -o TMP`` when ``export`` names the output flags.
    ``cache``: a bytecode folder kept by the caller; ``warm``: one untimed run of each first."""
    import os
    import resource
    import shutil
    import subprocess
    import tempfile

    # bytecode cached as in an installed package (a checkout run with PYTHONDONTWRITEBYTECODE would
    # compile every module on every start); one untimed run per example fills the cache.  The runs start in
    # `cache`, not in a checkout, whose ./camfab `python -m` would import first.
    own = cache is None
    cache = cache or tempfile.mkdtemp(prefix="camfab-pyc-")
    env = _child_env(root, cache)
    examples = [name for name, _ in _api()[0]]
    out = {}
    for name in examples:
        cpu = wall = math.inf
        folder = os.path.join(cache, "out")
        args = ["export", name, *export, "--force", "-o", folder] if export else ["check", name]
        for i in range(0 if warm else 1, repeat + 1):
            shutil.rmtree(folder, ignore_errors=True)
            before = resource.getrusage(resource.RUSAGE_CHILDREN)
            t0 = time.perf_counter()
            subprocess.run([sys.executable, "-m", "camfab", *args], env=env, cwd=cache,
                           stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=False)
            if i == 0:
                continue
            wall = min(wall, time.perf_counter() - t0)
            after = resource.getrusage(resource.RUSAGE_CHILDREN)
            cpu = min(cpu, after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime)
        out[name] = (cpu, wall)
    if own:
        shutil.rmtree(cache, ignore_errors=True)
    return out


def _alternating(repeat: int, root: str | None, against: str, flags: tuple[str, ...]
                 ) -> tuple[dict[str, tuple[float, float]], dict[str, tuple[float, float]]]:
    """Both trees' :func:`process_timings`, in ``repeat`` alternating rounds of one run each (best of the
    rounds): on a loaded machine both see the same load."""
    import shutil
    import tempfile

    mine: dict[str, tuple[float, float]] = {}
    other: dict[str, tuple[float, float]] = {}
    caches = {id(mine): tempfile.mkdtemp(prefix="camfab-pyc-"), id(other): tempfile.mkdtemp(prefix="camfab-pyc-")}
    try:
        for k in range(repeat + 1):  # round 0 fills the bytecode caches, untimed
            for tree, out in ((root, mine), (against, other)):
                t = process_timings(1 if k else 0, tree, flags, caches[id(out)], warm=not k)
                for name, (cpu, wall) in t.items():
                    best = out.get(name, (math.inf, math.inf)) if k else (math.inf, math.inf)
                    out[name] = (min(best[0], cpu), min(best[1], wall))
    finally:
        for c in caches.values():
            shutil.rmtree(c, ignore_errors=True)
    return mine, other


def _instructions(root: str | None, name: str, cache: str) -> int:
    """Instructions (valgrind's callgrind, ``Collected``) of one ``python -m camfab check NAME`` from ``root``:
    the same count on a busy machine as on an idle one."""
    import re
    import subprocess

    env = _child_env(root, cache)
    cmd = [sys.executable, "-m", "camfab", "check", name]
    subprocess.run(cmd, env=env, cwd=cache, capture_output=True, check=False)  # bytecode cached first
    r = subprocess.run(["valgrind", "--tool=callgrind", "--callgrind-out-file=/dev/null", *cmd], env=env, cwd=cache,
                       capture_output=True, text=True, check=False)
    m = re.search(r"Collected : (\d+)", r.stderr)
    if m is None:
        raise SystemExit(f"valgrind gave no count for {name}: {r.stderr[-500:]}")
    return int(m.group(1))


def instructions(root: str | None, against: str | None) -> None:
    """Each example's check counted in instructions (``--process --instructions``), two at a time."""
    import shutil
    import tempfile
    from concurrent.futures import ThreadPoolExecutor

    if shutil.which("valgrind") is None:
        raise SystemExit("--instructions needs valgrind (apt-get install valgrind)")
    trees = [root] + ([against] if against is not None else [])
    caches = [tempfile.mkdtemp(prefix="camfab-pyc-") for _ in trees]
    examples = [name for name, _ in _api()[0]]
    try:
        with ThreadPoolExecutor(2) as pool:
            counts = {(k, name): pool.submit(_instructions, tree, name, caches[k])
                      for name in examples for k, tree in enumerate(trees)}
            got = {key: f.result() for key, f in counts.items()}
    finally:
        for c in caches:
            shutil.rmtree(c, ignore_errors=True)
    print("python -m camfab check EXAMPLE, instructions (valgrind callgrind)"
          + (f", this tree against {against}" if against is not None else ""))
    for name in examples:
        mine = got[(0, name)]
        if against is None:
            print(f"  {name:28}{mine / 1e6:9.1f} M")
        else:
            old = got[(1, name)]
            print(f"  {name:28}{old / 1e6:9.1f} M -> {mine / 1e6:7.1f} M  ({(mine - old) / old:+.1%})")


def _floor(repeat: int) -> tuple[float, float]:
    """Best CPU seconds of this Python doing nothing (``-c pass``: the interpreter and ``site``, whose ``.pth``
    files run for every process) and of ``-c "import numpy"``: the part of a check that is not camfab's.  BLAS on
    one thread, as ``python -m camfab`` sets it by default (OpenBLAS's start-up threads cost ~0.1 s of CPU)."""
    import os
    import resource
    import subprocess

    env = dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1")
    best = [math.inf, math.inf]
    for _ in range(repeat + 1):
        for i, code in enumerate(("pass", "import numpy")):
            before = resource.getrusage(resource.RUSAGE_CHILDREN)
            subprocess.run([sys.executable, "-c", code], check=True, env=env)
            after = resource.getrusage(resource.RUSAGE_CHILDREN)
            best[i] = min(best[i], after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime)
    return best[0], best[1]


def _print_floor(repeat: int, slowest: float) -> None:
    bare, numpy_ = _floor(repeat)
    print(f"floor (this Python, best of {repeat}): `-c pass` {bare:.3f} s, `-c 'import numpy'` {numpy_:.3f} s CPU; "
          f"camfab's own part of the slowest: {slowest - numpy_:.3f} s")


def process(repeat: int, root: str | None, export: bool = False, against: str | None = None,
            only: str | None = None) -> None:
    print("child processes without PYTHONDONTWRITEBYTECODE (bytecode cached as installed), "
          "one untimed warm-up run each")
    exports = [(f"--{only}",)] if only else [("--dxf",), ("--stl",)]
    for flags in (exports if export else [()]):
        goal = EXPORT_TARGET_S if export else PROCESS_TARGET_S
        if against is not None:
            t, old = _alternating(repeat, root, against, flags)
            what = f"export EXAMPLE {' '.join(flags)}" if export else "check EXAMPLE"
            print(f"python -m camfab {what}, this tree against {against}, alternating, best of {repeat}; "
                  f"goal <= {goal:g} s CPU")
            for name, (cpu, _) in t.items():
                print(f"  {name:28}{old[name][0]:7.3f} -> {cpu:6.3f} s CPU" + ("" if cpu <= goal else "  MISSED"))
            worst = max(c for c, _ in t.values())
            print(f"slowest {max(c for c, _ in old.values()):.3f} -> {worst:.3f} s CPU: "
                  f"{'MET' if worst <= goal else 'MISSED'}")
            _print_floor(repeat, worst)
            continue
        t = process_timings(repeat, root, flags)
        what = f"export EXAMPLE {' '.join(flags)}" if export else "check EXAMPLE"
        print(f"python -m camfab {what} as a process, best of {repeat}; goal <= {goal:g} s CPU")
        for name, (cpu, wall) in t.items():
            print(f"  {name:28}{cpu:7.3f} s CPU {wall:7.3f} s wall" + ("" if cpu <= goal else "  MISSED"))
        worst = max(c for c, _ in t.values())
        print(f"slowest {worst:.3f} s CPU: {'MET' if worst <= goal else 'MISSED'}")
        _print_floor(repeat, worst)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=7)
    ap.add_argument("--baseline", nargs="?", const="", default=None, metavar="REF")
    ap.add_argument("--rounds", type=int, default=2)
    ap.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    ap.add_argument("--steep", action="store_true", help="time the steep designs of issue 12 instead")
    ap.add_argument("--process", action="store_true", help="time `python -m camfab check` as a whole process")
    ap.add_argument("--root", default=None, help="with --process: the checkout whose camfab runs")
    ap.add_argument("--export", action="store_true", help="with --process: time `export --dxf` and `--stl`")
    ap.add_argument("--against", default=None, metavar="DIR",
                    help="with --process: also time the checkout DIR, alternating with this tree")
    ap.add_argument("--only", choices=("dxf", "stl"), default=None,
                    help="with --process --export: time only `export --dxf` (or only `--stl`)")
    ap.add_argument("--instructions", action="store_true",
                    help="with --process: count each check's instructions with valgrind instead of timing it")
    a = ap.parse_args()
    if a.process and a.instructions:
        instructions(a.root, a.against)
        return
    if a.process:
        process(a.repeat, a.root, a.export, a.against, a.only)
        return
    if a.steep:
        steep(a.repeat)
        return
    if a.child:
        print(json.dumps(timings(a.repeat)))
        return
    t = timings(a.repeat)
    print(f"check() cold, best of {a.repeat}; target <= {TARGET_MS:g} ms")
    worst = max(t.values())
    for name, s in t.items():
        print(f"  {name:28}{s * 1e3:8.2f} ms" + ("" if s * 1e3 <= TARGET_MS else "  MISSED"))
    print(f"slowest {worst * 1e3:.2f} ms: {'OK' if worst * 1e3 <= TARGET_MS else 'MISSED'}")
    if a.baseline is not None:
        from baseline import print_ratios, run_both

        mine, base = run_both(__file__, ["--repeat", str(a.repeat)], a.baseline or None, a.rounds)
        print_ratios(mine, base, a.baseline or None, math.inf)


if __name__ == "__main__":
    main()
