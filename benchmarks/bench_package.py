"""Benchmark: `camfab package` of N generated cams, without and with STEP, on 1 and 2 processes.

Prints, per run, the stage times summed over the cams (from the manifest's ``timings``): where the time goes.

Generates N valid designs (translating and oscillating rollers, flat faces; 4-8 segments of
dwell-compatible laws; random geometry scaled to pass the checks), then times
``camfab package --outputs dxf,stl,gcode,lift_table,xlsx,report,drawing`` (and the same plus step) with
--jobs 1 and --jobs 2, each into a fresh folder.  Reports wall time, peak resident memory (the parent and
its worker processes) and the speed-up.

``--stages`` instead builds the cams in one process per checkout (this one and each ``--root``), alternating
rounds, and prints each stage's CPU time per cam (``time.process_time``; the manifest's timings are wall time,
which a loaded machine inflates); ``--profile`` adds a cProfile of one cam (after a first, as in a worker).

``--fsync`` instead times the built-in examples' package (every output but STEP, one process) with fsync on
(``camfab.io.DURABLE``, the default) and off, alternating, and reports what the durability costs
(docs/decisions.md, "Faults: staging, locks, durability").

Goals (issue 15): 100 cams, every artifact but STEP, ``--jobs 2`` on 2 cores in <= 40 s; with STEP <= 90 s.
Each run also reports the CPU time of the package's processes (user + system, ``getrusage`` of the children:
the measure least disturbed on a shared machine) and the stage CPU summed over the cams.  ``--jobs 2`` runs
only that count; ``--root DIR`` runs the camfab found in DIR (a checkout to compare with).

Run:  python3 benchmarks/bench_package.py [--cams 100] [--jobs 1,2] [--no-step | --step-only] [--root DIR]
      python3 benchmarks/bench_package.py --stages [--cams 20] [--root DIR ...] [--repeat 2] [--profile]
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


GOALS = {"all but STEP": 40.0, "all with STEP": 90.0}  # s for 100 cams, --jobs 2


def run(src: Path, out: Path, jobs: int, outputs: str, root: str | None = None) -> tuple[float, float, str]:
    import os

    cmd = [sys.executable, "-m", "camfab", "package", str(src), "-o", str(out), "--jobs", str(jobs),
           "--outputs", outputs, "--force"]
    env = dict(os.environ, **({"PYTHONPATH": root} if root else {}))
    before = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
    cpu0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t = time.perf_counter()
    rc = subprocess.run(cmd, capture_output=True, text=True, env=env, cwd=src).returncode
    wall = time.perf_counter() - t
    cpu1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = cpu1.ru_utime - cpu0.ru_utime + cpu1.ru_stime - cpu0.ru_stime
    peak = max(resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss, before) / 1024
    cams = json.loads((out / "manifest.json").read_text())["cams"]
    files = sum(len(c["files"]) for c in cams)
    status = ",".join(f"{k}:{v}" for k, v in sorted(Counter(c["status"] for c in cams).items()))
    return wall, peak, f"rc {rc}, {status}, {files} files, CPU {cpu:.1f} s ({cpu / len(cams):.2f} s/cam)\n" \
                       f"{_stages(cams)}"


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


#: one process builds every design of a folder (every artifact but STEP, as a package worker does) and prints
#: the CPU seconds of each stage summed over the cams, as JSON; with a second argument, a cProfile of the last cam
STAGES_CHILD = """
import json, sys, time, types
from pathlib import Path
import camfab.pipeline as pl
from camfab.formats import load_design
pl.time = types.SimpleNamespace(perf_counter=time.process_time)  # the stage timings in CPU seconds
total, cams = {}, sorted(Path(sys.argv[1]).glob("*.toml"))
c0 = time.process_time()
for k, path in enumerate(cams):
    t = time.process_time()
    spec = load_design(path)
    req = pl.Request.from_design(spec, sys.argv[2].split(","), post="linuxcnc")
    cam = pl.Cam(spec)
    res = pl.RunResult(cam.name, "", tol=cam.tolerance(req.tol))
    total["load"] = total.get("load", 0.0) + time.process_time() - t
    if len(sys.argv) > 3 and k == len(cams) - 1:
        import cProfile, pstats
        prof = cProfile.Profile()
        prof.runcall(pl.build_files, cam, req, res, lambda m: None)
        pstats.Stats(prof, stream=sys.stderr).sort_stats("cumulative").print_stats(int(sys.argv[3]))
    else:
        pl.build_files(cam, req, res, lambda m: None)
    for key, v in res.timings.items():
        total[key] = total.get(key, 0.0) + v
total["all"] = time.process_time() - c0
print(json.dumps({k: v / len(cams) for k, v in total.items()}))
"""


def stage_cpu(src: Path, roots: list[str], repeat: int, profile: int) -> None:
    """Per-stage CPU seconds per cam of each checkout, best of ``repeat`` alternating rounds."""
    import os

    best: dict[str, dict[str, float]] = {r: {} for r in roots}
    for _ in range(repeat):
        for r in roots:
            env = dict(os.environ, PYTHONPATH=r, OMP_NUM_THREADS="1")
            args = [sys.executable, "-c", STAGES_CHILD, str(src), OUTPUTS] + ([str(profile)] if profile else [])
            p = subprocess.run(args, capture_output=True, text=True, env=env, cwd=src)
            if p.returncode:
                sys.exit(p.stderr)
            for k, v in json.loads(p.stdout.splitlines()[-1]).items():
                best[r][k] = min(best[r].get(k, v), v)
            if profile:
                print(f"--- cProfile of one cam, {r}\n" + "\n".join(p.stderr.splitlines()[:profile + 40]))
    keys = sorted({k for b in best.values() for k in b}, key=lambda k: -best[roots[0]].get(k, 0.0))
    print(f"CPU s per cam (best of {repeat}, one process, OMP_NUM_THREADS=1)")
    print(f"{'stage':<12}" + "".join(f"{Path(r).name[-14:]:>16}" for r in roots))
    for k in keys:
        print(f"{k:<12}" + "".join(f"{best[r].get(k, 0.0):>16.3f}" for r in roots))


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
    ap.add_argument("--cams", "--n", dest="n", type=int, default=100, help="generated cams (default 100)")
    ap.add_argument("--jobs", default="1,2", help="process counts to run, comma-separated (default 1,2)")
    ap.add_argument("--root", default=None, action="append",
                    help="run the camfab found in this checkout (--stages: repeat it to compare several)")
    ap.add_argument("--no-step", action="store_true", help="only the set without STEP")
    ap.add_argument("--step-only", action="store_true", help="only the set with STEP")
    ap.add_argument("--fsync", action="store_true", help="the cost of fsync on the built-in examples' package")
    ap.add_argument("--repeat", type=int, default=3, help="rounds of --fsync or --stages")
    ap.add_argument("--stages", action="store_true", help="per-stage CPU per cam in one process, per checkout")
    ap.add_argument("--profile", type=int, default=0, metavar="N",
                    help="--stages: also a cProfile of one cam, its N largest cumulative entries")
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
        if a.stages:
            here = str(Path(__file__).resolve().parents[1])
            stage_cpu(src, [here, *(a.root or [])], a.repeat, a.profile)
            return
        print(f"{a.n} generated cams")
        print(f"{'outputs':<16}{'jobs':>5}{'wall s':>9}{'s/cam':>8}{'peak MB':>9}{'speed-up':>10}  result")
        sets = [] if a.step_only else [("all but STEP", OUTPUTS)]
        sets += [] if a.no_step else [("all with STEP", OUTPUTS + ",step")]
        for label, outputs in sets:
            base = None
            for jobs in (int(j) for j in a.jobs.split(",")):
                wall, peak, res = run(src, Path(tmp) / f"out_{label[:3]}_{jobs}", jobs, outputs,
                                      a.root[-1] if a.root else None)
                base = base or wall
                print(f"{label:<16}{jobs:>5}{wall:>9.1f}{wall / a.n:>8.2f}{peak:>9.0f}{base / wall:>9.2f}x  {res}")
                if jobs == 2:
                    goal = GOALS[label] * a.n / 100
                    print(f"    goal at --jobs 2: <= {goal:.1f} s for {a.n} cams: "
                          f"{'OK' if wall <= goal else 'MISSED'} (wall, on whatever else the machine runs)")


if __name__ == "__main__":
    main()
