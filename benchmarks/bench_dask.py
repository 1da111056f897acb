"""Benchmark: `camfab package` of N generated cams on the built-in pool and on a local Dask cluster.

Generates N designs (:func:`bench_package.design`), then times, each into a fresh folder and as a whole process:

* ``builtin``: ``--jobs W`` (camfab's process pool);
* ``dask-local``: ``--executor dask-local --dask-workers W`` with camfab's worker settings
  (:data:`camfab.package_dask.LOCAL_CONFIG`);
* ``dask-defaults``: the same with Dask's own defaults put back (``--dask-config``: the statistical profiler on,
  ``MALLOC_TRIM_THRESHOLD_=65536``, the monitors' intervals, worker saturation 1.1, 3 allowed failures);
* ``dask-profiler`` and ``dask-trim``: camfab's settings with only the profiler, or only the memory trimming,
  of Dask's defaults: which of them matters (docs/decisions.md, "Dask executor");
* ``dask-monitors``: camfab's settings with Dask's intervals of the workers' periodic work put back (event-loop
  ticks 20 ms, memory monitor 100 ms, system monitor 500 ms; camfab: 1 s, 1 s, 5 s).

Reports per run the wall time of the process, the build's own wall time (the manifest's ``wall_seconds``: after
the cluster has started), the CPU time of the process and its children (user + system), the ratio to
``builtin``, and whether every file is byte-identical to the built-in pool's.  The runs alternate, ``--repeat``
times; the medians are printed.  On a busy machine compare the CPU times as well as the wall times.

Run:  python3 benchmarks/bench_dask.py [--n 8] [--workers 2] [--repeat 1] [--outputs LIST] [--only NAMES]
"""
from __future__ import annotations

import argparse
import hashlib
import json
import os
import random
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_package import OUTPUTS, design  # noqa: E402

PROFILER = ["distributed.worker.profile.enabled=true"]
TRIM = ["distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_=65536"]
#: Dask's intervals of the worker's own periodic work: event-loop ticks, memory monitor, system monitor
MONITORS = ["distributed.admin.tick.interval=20ms", "distributed.worker.memory.monitor-interval=100ms",
            "distributed.admin.system-monitor.interval=500ms"]
DEFAULTS = PROFILER + TRIM + MONITORS + ["distributed.scheduler.worker-saturation=1.1",
                                         "distributed.scheduler.allowed-failures=3"]


def variants(workers: int) -> dict[str, list[str]]:
    local = ["--executor", "dask-local", "--dask-workers", str(workers)]
    return {"builtin": ["--jobs", str(workers)], "dask-local": local,
            "dask-defaults": local + [f"--dask-config={c}" for c in DEFAULTS],
            "dask-profiler": local + [f"--dask-config={c}" for c in PROFILER],
            "dask-trim": local + [f"--dask-config={c}" for c in TRIM],
            "dask-monitors": local + [f"--dask-config={c}" for c in MONITORS]}


def run(src: Path, out: Path, args: list[str], outputs: str) -> tuple[float, float, float, float]:
    """(process wall s, build wall s from the manifest, CPU s of the process and its children, CPU s of the
    worker processes while they built the cams: the manifest's ``cpu_seconds`` summed)."""
    cmd = [sys.executable, "-m", "camfab", "package", str(src), "-o", str(out), "--outputs", outputs, "--force",
           *args]
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t = time.perf_counter()
    p = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.perf_counter() - t
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if p.returncode not in (0, 1):
        raise SystemExit(f"{' '.join(cmd)} failed ({p.returncode}):\n{p.stderr[-3000:]}")
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    m = json.loads((out / "manifest.json").read_text())
    return wall, m["wall_seconds"], cpu, sum(c.get("cpu_seconds", 0.0) for c in m["cams"])


def hashes(out: Path) -> dict[str, str]:
    return {p.relative_to(out).as_posix(): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(out.rglob("*")) if p.is_file() and p.parent != out}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--n", type=int, default=8)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--repeat", type=int, default=1)
    ap.add_argument("--outputs", default=OUTPUTS)
    ap.add_argument("--only", help="comma list of the runs (default: all)")
    a = ap.parse_args()
    runs = variants(a.workers)
    names = a.only.split(",") if a.only else list(runs)
    if "builtin" not in names:
        names.insert(0, "builtin")
    rng = random.Random(20261126)
    print(f"{a.n} cams, {a.workers} workers, outputs {a.outputs}, {os.cpu_count()} CPUs, "
          f"load {os.getloadavg()[0]:.1f}")
    with tempfile.TemporaryDirectory() as tmp:
        src = Path(tmp) / "designs"
        src.mkdir()
        for i in range(a.n):
            (src / f"bench{i:03d}.toml").write_text(design(i, rng))
        got: dict[str, list[tuple[float, float, float, float]]] = {n: [] for n in names}
        same: dict[str, bool] = {}
        for r in range(a.repeat):
            for name in names:
                out = Path(tmp) / f"{name}-{r}"
                got[name].append(run(src, out, runs[name], a.outputs))
                if name != "builtin":
                    same[name] = same.get(name, True) and hashes(out) == hashes(Path(tmp) / f"builtin-{r}")
                print(f"  {name:<14} run {r + 1}: wall {got[name][-1][0]:6.1f} s, build {got[name][-1][1]:6.1f} s, "
                      f"cpu {got[name][-1][2]:6.1f} s, in the cams {got[name][-1][3]:6.1f} s", flush=True)
    med = {n: [statistics.median(x[k] for x in got[n]) for k in range(4)] for n in names}
    base = med["builtin"]
    print(f"{'run':<14} {'wall s':>7} {'build s':>8} {'cpu s':>7} {'cams cpu s':>10} {'wall/builtin':>13} "
          f"{'build/builtin':>14} {'cpu/builtin':>12} {'cams cpu/builtin':>17}  identical")
    for n in names:
        w, b, c, t = med[n]
        print(f"{n:<14} {w:7.1f} {b:8.1f} {c:7.1f} {t:10.1f} {w / base[0]:13.2f} {b / base[1]:14.2f} "
              f"{c / base[2]:12.2f} {t / max(base[3], 1e-9):17.2f}  {'-' if n == 'builtin' else same[n]}")


if __name__ == "__main__":
    main()
