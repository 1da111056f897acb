"""Benchmark: S, S', S'', S''' of a 12-segment program at 10^6 angles.

Compares ``MotionProgram.evaluate`` with a bare numpy evaluation of the same
formulas (hand-written polynomials and trig, one boolean mask per segment), and
reports wall time (best of N) and peak traced memory.  Target (issue 2): within
3x of the bare evaluation.

Run:  python3 benchmarks/bench_motion.py [--n 1000000] [--repeat 5]
"""
from __future__ import annotations

import argparse
import math
import time
import tracemalloc

import numpy as np

from camfab.design.program import MotionProgram

ROWS = [("cycloidal", 10, 30), ("dwell", 0, 30), ("poly345", 10, 30), ("dwell", 0, 30),
        ("poly4567", -10, 30), ("dwell", 0, 30), ("cycloidal", -5, 30), ("dwell", 0, 30),
        ("poly345", 10, 30), ("dwell", 0, 30), ("poly4567", -15, 30), ("dwell", 0, 30)]


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


def measure(fn, theta, repeat):
    best = math.inf
    for _ in range(repeat):
        t = time.perf_counter()
        fn(theta)
        best = min(best, time.perf_counter() - t)
    tracemalloc.start()
    fn(theta)
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    return best, peak


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=1_000_000)
    ap.add_argument("--repeat", type=int, default=5)
    a = ap.parse_args()
    prog = MotionProgram.from_segments(ROWS)
    theta = np.random.default_rng(0).uniform(0, 2 * math.pi, a.n)
    ref = bare(theta)
    got = prog.evaluate(theta)
    err = np.max(np.abs(got - ref) / (1 + np.abs(ref)))
    t_prog, m_prog = measure(prog.evaluate, theta, a.repeat)
    t_bare, m_bare = measure(bare, theta, a.repeat)
    print(f"12-segment program, {a.n:,} angles (max relative difference {err:.1e})")
    print(f"{'':22}{'time (ms)':>12}{'peak memory (MB)':>20}")
    print(f"{'MotionProgram':22}{t_prog * 1e3:>12.1f}{m_prog / 1e6:>20.1f}")
    print(f"{'bare numpy':22}{t_bare * 1e3:>12.1f}{m_bare / 1e6:>20.1f}")
    ratio = t_prog / t_bare
    print(f"ratio {ratio:.2f}x (target <= 3x): {'OK' if ratio <= 3 else 'MISSED'}")


if __name__ == "__main__":
    main()
