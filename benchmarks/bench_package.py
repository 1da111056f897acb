"""Benchmark: `camfab package` of N generated cams, without and with STEP, on 1 and 2 processes.

Prints, per run, the stage times summed over the cams (from the manifest's ``timings``): where the time goes.

Generates N valid designs (translating and oscillating rollers, flat faces; 4-8 segments of
dwell-compatible laws; random geometry scaled to pass the checks), then times
``camfab package --outputs dxf,stl,gcode,lift_table,xlsx,report,drawing`` (and the same plus step) with
--jobs 1 and --jobs 2, each into a fresh folder.  Reports wall time, peak resident memory (the parent and
its worker processes) and the speed-up.

``--fsync`` instead times the built-in examples' package (every output but STEP, one process) with fsync on
(``camfab.io.DURABLE``, the default) and off, alternating, and reports what the durability costs
(docs/decisions.md, "Faults: staging, locks, durability").

Run:  python3 benchmarks/bench_package.py [--n 100] [--no-step | --step-only]
      python3 benchmarks/bench_package.py --fsync [--repeat 3]
"""
from __future__ import annotations

import argparse
import json
import random
import resource
import subprocess
import sys
import tempfile
import time
from collections import Counter
from pathlib import Path

LAWS = ("cycloidal", "poly345", "poly4567", "modified_sine", "modified_trapezoid")
OUTPUTS = "dxf,stl,gcode,lift_table,xlsx,report,drawing"


def design(i: int, rng: random.Random) -> str:
    kind = ("translating_roller", "oscillating_roller", "translating_flat")[i % 3]
    n_moves = 1 if kind == "translating_flat" else rng.choice((1, 2))
    rows = []
    for _ in range(n_moves):  # rise, dwell, return, dwell per move
        h = rng.uniform(5, 15) if kind != "oscillating_roller" else rng.uniform(5, 12)
        b = rng.uniform(60, 100) / n_moves
        d = 180 / n_moves - b
        rows += [(rng.choice(LAWS), h, b), ("dwell", 0, d), (rng.choice(LAWS), -h, b), ("dwell", 0, d)]
    motion = "".join(f'[[motion]]\nlaw = "{law}"\nlift = {h:.3f}\nangle_deg = {b:.6f}\n' for law, h, b in rows)
    if kind == "translating_roller":
        fol = 'type = "roller"\nmotion = "translating"\nbase_radius_mm = 70.0\nroller_radius_mm = 8.0\n'
    elif kind == "oscillating_roller":
        fol = ('type = "roller"\nmotion = "oscillating"\nbase_radius_mm = 90.0\nroller_radius_mm = 10.0\n'
               'pivot_distance_mm = 150.0\narm_length_mm = 100.0\n')
    else:
        fol = 'type = "flat"\nmotion = "translating"\nbase_radius_mm = 150.0\n'
    return (f'name = "Bench{i:03d}"\n[cam]\nspeed_rpm = 60.0\n[follower]\n{fol}{motion}'
            '[manufacturing]\nthickness_mm = 10.0\nbore_mm = 20.0\nkeyway = true\ntool_diameter_mm = 6.0\n'
            'tolerance_mm = 0.001\n[checks]\npressure_angle_limit_deg = 40.0\n')


def run(src: Path, out: Path, jobs: int, outputs: str) -> tuple[float, float, str]:
    cmd = [sys.executable, "-m", "camfab", "package", str(src), "-o", str(out), "--jobs", str(jobs),
           "--outputs", outputs, "--force"]
    before = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
    t = time.perf_counter()
    rc = subprocess.run(cmd, capture_output=True, text=True).returncode
    wall = time.perf_counter() - t
    peak = max(resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss, before) / 1024
    cams = json.loads((out / "manifest.json").read_text())["cams"]
    files = sum(len(c["files"]) for c in cams)
    status = ",".join(f"{k}:{v}" for k, v in sorted(Counter(c["status"] for c in cams).items()))
    return wall, peak, f"rc {rc}, {status}, {files} files\n{_stages(cams)}"


def _stages(cams: list[dict]) -> str:
    """Per-stage seconds summed over the cams (the manifest's ``timings``), largest first, with shares."""
    total: Counter[str] = Counter()
    for c in cams:
        total.update(c.get("timings") or {})
    whole = sum(total.values()) or 1.0
    return "    stages: " + ", ".join(f"{k} {v:.1f} s ({100 * v / whole:.0f} %)" for k, v in total.most_common())


#: one package run in a child with ``camfab.io.DURABLE`` set; prints the wall time of the run
FSYNC_CHILD = """
import sys, time, io, contextlib
import camfab.io as cio
cio.DURABLE = sys.argv[1] == "on"
from camfab.cli import main
t = time.perf_counter()
with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
    rc = main(["package", sys.argv[2], "-o", sys.argv[3], "--outputs", sys.argv[4], "--force"])
print(rc, time.perf_counter() - t)
"""


def fsync_cost(repeat: int) -> None:
    from camfab.formats import EXAMPLES_DIR

    outputs = OUTPUTS
    print(f"package of the built-in examples ({outputs}), one process, fsync on/off alternating, {repeat} rounds")
    times: dict[str, list[float]] = {"on": [], "off": []}
    with tempfile.TemporaryDirectory() as tmp:
        for r in range(repeat):
            for mode in ("on", "off"):
                out = Path(tmp) / f"{mode}{r}"
                p = subprocess.run([sys.executable, "-c", FSYNC_CHILD, mode, str(EXAMPLES_DIR), str(out),
                                    outputs], capture_output=True, text=True, check=True)
                times[mode].append(float(p.stdout.split()[-1]))
        files = sum(1 for p in (Path(tmp) / "on0").rglob("*") if p.is_file())
    on, off = sorted(times["on"])[repeat // 2], sorted(times["off"])[repeat // 2]
    print(f"{files} files; median wall: fsync on {on:.2f} s, off {off:.2f} s; durability costs {on - off:+.2f} s "
          f"({100 * (on - off) / off:+.1f} %)")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=100)
    ap.add_argument("--no-step", action="store_true", help="only the set without STEP")
    ap.add_argument("--step-only", action="store_true", help="only the set with STEP")
    ap.add_argument("--fsync", action="store_true", help="the cost of fsync on the built-in examples' package")
    ap.add_argument("--repeat", type=int, default=3, help="rounds of --fsync")
    a = ap.parse_args()
    if a.fsync:
        fsync_cost(a.repeat)
        return
    rng = random.Random(1)
    with tempfile.TemporaryDirectory() as tmp:
        src = Path(tmp) / "designs"
        src.mkdir()
        for i in range(a.n):
            (src / f"bench{i:03d}.toml").write_text(design(i, rng))
        print(f"{a.n} generated cams")
        print(f"{'outputs':<16}{'jobs':>5}{'wall s':>9}{'s/cam':>8}{'peak MB':>9}{'speed-up':>10}  result")
        sets = [] if a.step_only else [("all but STEP", OUTPUTS)]
        sets += [] if a.no_step else [("all with STEP", OUTPUTS + ",step")]
        for label, outputs in sets:
            base = None
            for jobs in (1, 2):
                wall, peak, res = run(src, Path(tmp) / f"out_{label[:3]}_{jobs}", jobs, outputs)
                base = base or wall
                print(f"{label:<16}{jobs:>5}{wall:>9.1f}{wall / a.n:>8.2f}{peak:>9.0f}{base / wall:>9.2f}x  {res}")


if __name__ == "__main__":
    main()
