"""Benchmark: S, S', S'', S''' of a 12-segment program at 10^6 angles, and at few angles.

Compares ``MotionProgram.evaluate`` with a bare numpy evaluation of the same
formulas (hand-written polynomials and trig, one boolean mask per segment), and
reports wall time (best of N) and peak traced memory.  Target: within 3x of the
bare evaluation.  Small inputs (10, 100, 1000 angles, as a check's searches ask for)
are timed on the same program and on one made of the piecewise and double-harmonic laws.

``--baseline [REF]`` also times the same programs with the code of git ref REF (default: the code
before the core redesign, ``benchmarks/baseline.py``), checked out into a temporary ``git worktree``
and run in a subprocess, and prints both figures and their ratio; the redesign's target is a ratio of
at most 1.3 at 10^6 angles.  Both sides run alternately ``--rounds`` times and keep their best.

Run:  python3 benchmarks/bench_motion.py [--n 1000000] [--repeat 5] [--baseline [REF]]
"""
from __future__ import annotations

import argparse
import json
import math
import os
import subprocess
import sys
import tempfile
import time
import tracemalloc
from pathlib import Path

import numpy as np

from camfab.design.program import MotionProgram

ROOT = Path(__file__).resolve().parent.parent
ROWS = [("cycloidal", 10, 30), ("dwell", 0, 30), ("poly345", 10, 30), ("dwell", 0, 30),
        ("poly4567", -10, 30), ("dwell", 0, 30), ("cycloidal", -5, 30), ("dwell", 0, 30),
        ("poly345", 10, 30), ("dwell", 0, 30), ("poly4567", -15, 30), ("dwell", 0, 30)]
#: piecewise and double-harmonic laws, for the small-input timings
ROWS_PIECEWISE = [("modified_sine", 10, 50), ("dwell", 0, 40), ("modified_trapezoid", -10, 50), ("dwell", 0, 40),
                  ("double_harmonic", 10, 50), ("dwell", 0, 40), ("constant_acceleration", -10, 50),
                  ("dwell", 0, 40)]
SMALL = (10, 100, 1000)
#: the ratio (this code / baseline) at 10^6 angles the redesign must stay within
TARGET_RATIO = 1.3


def bare(theta: np.ndarray) -> np.ndarray:
    """The same program, formulas written out by hand."""
    out = np.empty((4, theta.size))
    x = np.mod(theta, 2 * math.pi)
    b = math.radians(30.0)
    s0 = 0.0
    for k, (law, lift, _) in enumerate(ROWS):
        sel = np.flatnonzero((x >= k * b) & (x < (k + 1) * b))
        u = (x[sel] - k * b) / b
        L = float(lift)
        if law == "dwell":
            f = [np.zeros_like(u)] * 4
        elif law == "cycloidal":
            s, c = np.sin(2 * math.pi * u), np.cos(2 * math.pi * u)
            f = [u - s / (2 * math.pi), 1 - c, 2 * math.pi * s, 4 * math.pi**2 * c]
        elif law == "poly345":
            u2 = u * u
            f = [u2 * u * (10 - 15 * u + 6 * u2), 30 * u2 * (1 - u) ** 2,
                 60 * u * (1 - u) * (1 - 2 * u), 60 - 360 * u + 360 * u2]
        else:
            u2 = u * u
            w = u * (1 - u)
            f = [u2 * u2 * (35 - 84 * u + 70 * u2 - 20 * u2 * u), 140 * w**3,
                 420 * w * w * (1 - 2 * u), 840 * w * (1 - 5 * u + 5 * u2)]
        out[0, sel] = s0 + L * f[0]
        for j in range(1, 4):
            out[j, sel] = L / b**j * f[j]
        s0 += L
    return out


def best_time(fn, arg, repeat: int) -> float:
    best = math.inf
    for _ in range(repeat):
        t = time.perf_counter()
        fn(arg)
        best = min(best, time.perf_counter() - t)
    return best


def peak_memory(fn, arg) -> int:
    tracemalloc.start()
    fn(arg)
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    return peak


def small_timings(repeat: int) -> dict[str, float]:
    """Seconds (best of many) of ``evaluate`` at the :data:`SMALL` sizes, keyed by label."""
    rng = np.random.default_rng(0)
    out = {}
    for name, rows in (("12-segment", ROWS), ("piecewise", ROWS_PIECEWISE)):
        prog = MotionProgram.from_segments(rows)
        for m in SMALL:
            out[f"{name}, {m:,} angles"] = best_time(prog.evaluate, rng.uniform(0, 2 * math.pi, m),
                                                     max(repeat, 20_000 // m))
    return out


def timings(n: int, repeat: int) -> dict[str, float]:
    """Seconds of ``evaluate`` at n angles (best of ``repeat``), then :func:`small_timings`;
    the code measured is whichever ``camfab`` is imported."""
    theta = np.random.default_rng(0).uniform(0, 2 * math.pi, n)
    big = best_time(MotionProgram.from_segments(ROWS).evaluate, theta, repeat)
    return {f"12-segment, {n:,} angles": big, **small_timings(repeat)}


def _child(root: Path, n: int, repeat: int) -> dict[str, float]:
    """:func:`timings` in a fresh interpreter importing ``camfab`` from ``root``."""
    env = {**os.environ, "PYTHONPATH": str(root)}
    cmd = [sys.executable, str(Path(__file__).resolve()), "--child", "--n", str(n), "--repeat", str(repeat)]
    res = subprocess.run(cmd, env=env, capture_output=True, text=True, check=True)
    return json.loads(res.stdout)


def compare(ref: str, n: int, repeat: int, rounds: int) -> bool:
    """Time this tree and ``ref`` alternately; print both, the ratios and the verdict."""
    with tempfile.TemporaryDirectory(prefix="camfab-baseline-") as tmp:
        wt = Path(tmp) / "tree"
        subprocess.run(["git", "-C", str(ROOT), "worktree", "add", "--detach", str(wt), ref],
                       capture_output=True, text=True, check=True)
        try:
            mine: dict[str, float] = {}
            base: dict[str, float] = {}
            for _ in range(rounds):
                for store, root in ((mine, ROOT), (base, wt)):
                    for key, t in _child(root, n, repeat).items():
                        store[key] = min(store.get(key, math.inf), t)
        finally:
            subprocess.run(["git", "-C", str(ROOT), "worktree", "remove", "--force", str(wt)],
                           capture_output=True, text=True, check=False)
    print(f"\nthis tree against {ref} (best of {rounds} alternating rounds)")
    print(f"{'':34}{'this (ms)':>12}{'baseline (ms)':>15}{'ratio':>8}")
    for key in mine:
        print(f"{key:34}{mine[key] * 1e3:>12.3f}{base[key] * 1e3:>15.3f}{mine[key] / base[key]:>8.2f}")
    main_key = next(iter(mine))
    ratio = mine[main_key] / base[main_key]
    ok = ratio <= TARGET_RATIO
    print(f"{main_key}: ratio {ratio:.2f}x (target <= {TARGET_RATIO}x): {'OK' if ok else 'MISSED'}")
    return ok


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=1_000_000)
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--baseline", nargs="?", const="", default=None, metavar="REF",
                    help="also time git ref REF (default: the merge-base with main) in a temporary worktree")
    ap.add_argument("--rounds", type=int, default=3, help="alternating rounds with --baseline")
    ap.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    a = ap.parse_args()
    if a.child:
        print(json.dumps(timings(a.n, a.repeat)))
        return
    prog = MotionProgram.from_segments(ROWS)
    theta = np.random.default_rng(0).uniform(0, 2 * math.pi, a.n)
    ref = bare(theta)
    got = prog.evaluate(theta)
    err = np.max(np.abs(got - ref) / (1 + np.abs(ref)))
    t_prog, m_prog = best_time(prog.evaluate, theta, a.repeat), peak_memory(prog.evaluate, theta)
    t_bare, m_bare = best_time(bare, theta, a.repeat), peak_memory(bare, theta)
    print(f"12-segment program, {a.n:,} angles (max relative difference {err:.1e})")
    print(f"{'':22}{'time (ms)':>12}{'peak memory (MB)':>20}")
    print(f"{'MotionProgram':22}{t_prog * 1e3:>12.1f}{m_prog / 1e6:>20.1f}")
    print(f"{'bare numpy':22}{t_bare * 1e3:>12.1f}{m_bare / 1e6:>20.1f}")
    ratio = t_prog / t_bare
    print(f"ratio {ratio:.2f}x (target <= 3x): {'OK' if ratio <= 3 else 'MISSED'}")
    print("\nfew angles (best of many)")
    for key, t in small_timings(a.repeat).items():
        print(f"  {key:32}{t * 1e6:>10.1f} us")
    if a.baseline is not None:
        sys.path.insert(0, str(Path(__file__).resolve().parent))
        from baseline import BASELINE_REF

        ok = compare(a.baseline or BASELINE_REF, a.n, a.repeat, a.rounds)
        sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
