"""Benchmark: polyline vs G1 arc discretisation of a 12-segment cam profile.

The curve is P(φ) = (R + S(φ))·(sin φ, cos φ) with R = 40 mm and a 12-segment
program of 30° segments (cycloidal / dwell / poly345 / dwell / poly4567 / dwell,
lifts ±10 mm).  For every tolerance from 0.1 mm to 1e-6 mm it reports the
number of entities, the *measured* two-way maximum deviation and the wall time
(best of ``--repeat``) of :func:`camfab.offset.discretize.polyline` and
:func:`camfab.offset.discretize.arcs`.

The harsh cam has pressure angles near 40° (no real design would use it); the same table is
then printed for the profile of a *typical* 12-segment roller cam that passes ``camfab check``
(``typical_cam.py``: same program, Rb = 60 mm, Rr = 10 mm, peak pressure angle 29.2°).

Run:  PYTHONPATH=. python3 benchmarks/bench_discretize.py [--repeat 3] [--base 40]
"""
from __future__ import annotations

import argparse
import time

import numpy as np

from camfab.design.program import MotionProgram
from camfab.offset.discretize import ParametricCurve, arcs, polyline

ROWS = [("cycloidal", 10, 30), ("dwell", 0, 30), ("poly345", -10, 30), ("dwell", 0, 30),
        ("poly4567", 10, 30), ("dwell", 0, 30), ("cycloidal", -10, 30), ("dwell", 0, 30),
        ("poly345", 10, 30), ("dwell", 0, 30), ("poly4567", -10, 30), ("dwell", 0, 30)]
TOLS = (1e-1, 1e-2, 1e-3, 1e-4, 1e-5, 1e-6)


def cam_curve(rows=ROWS, base: float = 40.0) -> ParametricCurve:
    """The cam-like test curve with its analytic derivative and breakpoints."""
    prog = MotionProgram.from_segments(rows)

    def point(t):
        r = base + prog.evaluate(t, (0,))[0]
        return np.column_stack([r * np.sin(t), r * np.cos(t)])

    def derivative(t):
        s, ds = prog.evaluate(t, (0, 1))
        r = base + s
        return np.column_stack([ds * np.sin(t) + r * np.cos(t), ds * np.cos(t) - r * np.sin(t)])

    return ParametricCurve(point, prog.breakpoints, derivative=derivative)


def timed(fn, curve, tol, repeat):
    best, res = np.inf, None
    for _ in range(repeat):
        t0 = time.perf_counter()
        res = fn(curve, tol=tol)
        best = min(best, time.perf_counter() - t0)
    return res, best


def table(curve, repeat) -> None:
    head = (f"{'tol mm':>8} | {'lines':>6} {'max dev mm':>10} {'time s':>7} | "
            f"{'arcs':>5} {'max dev mm':>10} {'time s':>7} | {'ratio':>5}")
    print(head)
    print("-" * len(head))
    for tol in TOLS:
        pl, t_pl = timed(polyline, curve, tol, repeat)
        ar, t_ar = timed(arcs, curve, tol, repeat)
        print(f"{tol:8.0e} | {pl.n_entities:6d} {pl.max_deviation:10.3e} {t_pl:7.3f} | "
              f"{ar.n_entities:5d} {ar.max_deviation:10.3e} {t_ar:7.3f} | "
              f"{pl.n_entities / ar.n_entities:5.1f}")


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--base", type=float, default=40.0)
    args = ap.parse_args(argv)
    curve = cam_curve(base=args.base)
    print(f"12-segment cam, R = {args.base:g} mm, lifts 10 mm; {curve.breakpoints.size - 1} smooth pieces")
    table(curve, args.repeat)
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).resolve().parent))
    from typical_cam import typical_geometry

    from camfab.offset.cutter import profile_curve

    spec, geom = typical_geometry()
    print(f"\ntypical 12-segment roller cam ({spec.name}): Rb = 60 mm, Rr = 10 mm, peak pressure angle 29.2°")
    table(profile_curve(geom.profiles[0]), args.repeat)


if __name__ == "__main__":
    main()
