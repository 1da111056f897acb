"""Benchmark: exact profile + curvature + pressure angle (+ full checks) of a 12-segment cam at 10^5 angles.

Compares ``CamGeometry.evaluate`` (pitch curve, profile, normal, curvature of both, pressure angle) at 10^5
angles with the motion engine's evaluation of S…S‴ at the same count (target: within 3x), and reports
the time of the full ``check`` (exact extrema, ranges and verdict; it does not depend on a sample count,
its motion-law analysis included) and of profile evaluation + check together against the same target.
A program computes its exact peaks and junctions once, so a repeated check reuses them; the cold column
times check() on a freshly built program and geometry.
Timings are best-of-``--repeat`` (the machine may be shared).

``--baseline [REF]`` also times the motion and the profile evaluation at 10^5 angles in the code before the
core redesign (``benchmarks/baseline.py``), in the same run; the redesign's target is a ratio of at most
1.3 for each.

``--memory`` instead measures the peak memory of one profile evaluation of the translating roller at 10^6 and
10^7 angles, the whole sample (``evaluate``, 16 fields) against only the profile points
(``evaluate_fields(phi, ("point",))``, what the exporters and the arc fit ask for), each in a fresh process (peak
resident set less the resident set before the call, and the tracemalloc peak of numpy's allocations), and the
time per angle of the whole sample from 5 000 to 10^5 angles (best of ``--repeat``).

Run:  python3 benchmarks/bench_profile.py [--n 100000] [--repeat 5] [--baseline] [--memory]
"""
from __future__ import annotations

import argparse
import json
import math
import os
import sys
import time
from pathlib import Path

import numpy as np

from camfab.design.checks import check
from camfab.design.mechanisms import OscillatingRoller, TranslatingFlat, TranslatingRoller
from camfab.design.profile import CamGeometry
from camfab.design.program import MotionProgram

ROWS = [("cycloidal", 10, 30), ("dwell", 0, 30), ("poly345", 10, 30), ("dwell", 0, 30),
        ("poly4567", -10, 30), ("dwell", 0, 30), ("cycloidal", -5, 30), ("dwell", 0, 30),
        ("poly345", 10, 30), ("dwell", 0, 30), ("poly4567", -15, 30), ("dwell", 0, 30)]
#: the same program for an oscillating follower (lifts in degrees, halved)
OSC_ROWS = [(law, lift / 2, span) for law, lift, span in ROWS]


def best(fn, repeat):
    t = math.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        t = min(t, time.perf_counter() - t0)
    return t


def best_cold(make, repeat):
    """Best time of ``check`` on a freshly built geometry (nothing cached: the motion analysis,
    which a program computes once, and the sample grids included)."""
    from camfab import numeric

    t = math.inf
    for _ in range(repeat):
        geom = make()
        numeric.clear_caches()
        t0 = time.perf_counter()
        check(geom)
        t = min(t, time.perf_counter() - t0)
    return t


CAMS = (("translating roller", lambda p: CamGeometry(TranslatingRoller(40.0, 8.0, 5.0), p), ROWS),
        ("oscillating roller", lambda p: CamGeometry(OscillatingRoller(50.0, 8.0, 120.0, 90.0), p), OSC_ROWS),
        ("translating flat", lambda p: CamGeometry(TranslatingFlat(80.0), p), ROWS))
#: the ratio (this code / the code before the redesign) the redesign must stay within
TARGET_RATIO = 1.3


def timings(n: int, repeat: int) -> dict[str, float]:
    """Seconds of the motion and of each mechanism's profile evaluation at n angles (whichever camfab is
    imported; API common to the code before and after the redesign)."""
    phi = np.linspace(0, 2 * math.pi, n, endpoint=False)
    prog = MotionProgram.from_segments(ROWS)
    out = {f"motion S..S‴ at {n:,} angles": best(lambda: prog.evaluate(phi), repeat)}
    for name, build, rows in CAMS:
        geom = build(MotionProgram.from_segments(rows))
        out[f"profile, {name}, {n:,} angles"] = best(lambda geom=geom: geom.evaluate(phi), repeat)
    return out


def memory_child(n: int, mode: str) -> dict[str, float]:
    """Peak memory (MB) of one evaluation of the translating roller at ``n`` angles in this process: ``mode``
    "full" (``evaluate``) or "point" (``evaluate_fields(phi, ("point",))``); the angles are not counted."""
    import resource
    import tracemalloc

    geom = CAMS[0][1](MotionProgram.from_segments(ROWS))
    contact = geom.profiles[0]
    contact.evaluate(np.linspace(0, 1, 1000))  # per-law tables built, caches warm
    phi = np.linspace(0, 2 * math.pi, n, endpoint=False)
    rss0 = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    tracemalloc.start()
    t0 = time.process_time()
    r = contact.evaluate(phi).point if mode == "full" else contact.evaluate_fields(phi, ("point",))["point"]
    cpu = time.process_time() - t0
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    return {"rss_mb": (rss - rss0) / 1024.0, "traced_mb": peak / 2**20, "cpu_s": cpu, "check": float(r[-1, 0])}


def memory_report(repeat: int) -> None:
    import subprocess

    print("translating roller, one profile evaluation, peak memory in a fresh process (MB above the angles):")
    print(f"{'angles':>12}{'mode':>28}{'peak RSS MB':>14}{'tracemalloc MB':>16}{'CPU s':>8}")
    for n in (10**6, 10**7):
        for mode, label in (("full", "evaluate (16 fields)"), ("point", 'evaluate_fields("point")')):
            out = subprocess.run([sys.executable, __file__, "--memory-child", str(n), mode], check=True,
                                 capture_output=True, text=True).stdout
            r = json.loads(out)
            print(f"{n:>12,}{label:>28}{r['rss_mb']:>14.0f}{r['traced_mb']:>16.0f}{r['cpu_s']:>8.2f}")
    print(f"time per angle of evaluate (whole sample), ns, best of {repeat}; in a fresh process, glibc's defaults "
          "and with freed memory kept (MALLOC_TRIM_THRESHOLD_=64 MB, MALLOC_MMAP_THRESHOLD_=32 MB)")
    rows = []
    for env in ({}, {"MALLOC_TRIM_THRESHOLD_": str(64 << 20), "MALLOC_MMAP_THRESHOLD_": str(32 << 20)}):
        out = subprocess.run([sys.executable, __file__, "--per-angle-child", str(repeat)], check=True,
                             capture_output=True, text=True, env={**os.environ, **env}).stdout
        rows.append(json.loads(out))
    for n, a, b in zip(PER_ANGLE, *rows, strict=True):
        print(f"{n:>12,} angles {a:8.0f} {b:8.0f}")


#: angle counts of the per-angle timing (the issue: 5 000–40 000 angles 3x slower per angle than 10^5)
PER_ANGLE = (5_000, 10_000, 20_000, 40_000, 100_000, 1_000_000)


def per_angle_child(repeat: int) -> list[float]:
    contact = CAMS[0][1](MotionProgram.from_segments(ROWS)).profiles[0]
    out = []
    for n in PER_ANGLE:
        phi = np.linspace(0, 2 * math.pi, n, endpoint=False)
        out.append(best(lambda phi=phi: contact.evaluate(phi), repeat) * 1e9 / n)
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=100_000)
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--baseline", nargs="?", const="", default=None, metavar="REF")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    ap.add_argument("--memory", action="store_true", help="peak memory of evaluate vs evaluate_fields")
    ap.add_argument("--memory-child", nargs=2, metavar=("N", "MODE"), help=argparse.SUPPRESS)
    ap.add_argument("--per-angle-child", type=int, help=argparse.SUPPRESS)
    a = ap.parse_args()
    if a.per_angle_child:
        print(json.dumps(per_angle_child(a.per_angle_child)))
        return
    if a.memory_child:
        print(json.dumps(memory_child(int(a.memory_child[0]), a.memory_child[1])))
        return
    if a.memory:
        memory_report(a.repeat)
        return
    if a.child:
        print(json.dumps(timings(a.n, a.repeat)))
        return
    prog = MotionProgram.from_segments(ROWS)
    osc = MotionProgram.from_segments(OSC_ROWS)
    phi = np.linspace(0, 2 * math.pi, a.n, endpoint=False)
    t_motion = best(lambda: prog.evaluate(phi), a.repeat)
    print(f"12-segment cam, {a.n:,} angles; motion engine S..S''' {t_motion * 1e3:.1f} ms")
    print(f"{'mechanism':<22}{'profile+rho+pa ms':>18}{'ratio':>8}{'check() ms':>12}{'profile+check ms':>18}"
          f"{'ratio':>8}{'cold check() ms':>17}{'ratio (cold)':>14}")
    for name, build, rows in CAMS:
        geom = build(prog if rows is ROWS else osc)
        t_geo = best(lambda geom=geom: geom.evaluate(phi), a.repeat)
        t_chk = best(lambda geom=geom: check(geom), a.repeat)
        t_cold = best_cold(lambda build=build, rows=rows: build(MotionProgram.from_segments(rows)), a.repeat)
        t_all = t_geo + t_chk
        print(f"{name:<22}{t_geo * 1e3:>18.1f}{t_geo / t_motion:>7.2f}x{t_chk * 1e3:>12.1f}{t_all * 1e3:>18.1f}"
              f"{t_all / t_motion:>7.2f}x{t_cold * 1e3:>17.1f}{(t_geo + t_cold) / t_motion:>13.2f}x")
    print("target: profile evaluation (+ check) within 3x of the motion evaluation; check() is timed on a geometry")
    print("already checked (its program caches its exact peaks and junctions), cold check() on a fresh one; the")
    print("per-law tables (critical points, end values) are built once per process and kept")
    if a.baseline is not None:
        sys.path.insert(0, str(Path(__file__).resolve().parent))
        from baseline import print_ratios, run_both

        mine, base = run_both(__file__, ["--n", str(a.n), "--repeat", str(a.repeat)], a.baseline or None, a.rounds)
        sys.exit(0 if print_ratios(mine, base, a.baseline or None, TARGET_RATIO) else 1)


if __name__ == "__main__":
    main()
