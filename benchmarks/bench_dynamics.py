"""Benchmark: follower dynamics of the 12-segment cam — forces at 10^5 angles and the full analysis.

``ContactDynamics.evaluate`` (contact force, friction, bearing force, drive torque, power) at 10^5
angles against the motion engine's S…S‴ at the same count, and ``analyse_dynamics`` (exact extremes,
jump ranges, work per cycle, preload and jump speed; independent of a sample count).  Best of
``--repeat`` (the machine may be shared).

Run:  python3 benchmarks/bench_dynamics.py [--n 100000] [--repeat 5]
"""
from __future__ import annotations

import argparse
import math
from typing import Any

import numpy as np
from bench_profile import OSC_ROWS, ROWS, best

from camfab.design.dynamics import ContactDynamics, Loads, analyse_dynamics, pair_of
from camfab.design.mechanisms import ConjugateTranslatingRoller, OscillatingRoller, TranslatingFlat, TranslatingRoller
from camfab.design.profile import CamGeometry
from camfab.design.program import MotionProgram
from camfab.units import RPM


def cases(prog: MotionProgram, osc: MotionProgram, w: float) -> list[tuple[str, CamGeometry, Loads, Any]]:
    """The four mechanisms of the dynamics benchmarks on the 12-segment cam: (name, geometry, loads, force model
    at ``w`` rad/s); shared with ``bench_strength.py``."""
    cams = (("translating roller", CamGeometry(TranslatingRoller(40.0, 8.0, 5.0), prog),
             Loads(0.3, 20000.0, 400.0, damping=20.0, safety_force_n=50.0)),
            ("oscillating roller", CamGeometry(OscillatingRoller(50.0, 8.0, 120.0, 90.0), osc),
             Loads(0.02, 30.0, 20.0, safety_force_n=50.0)),
            ("translating flat", CamGeometry(TranslatingFlat(80.0), prog),
             Loads(0.3, 20000.0, 400.0, damping=20.0, friction_coefficient=0.05, safety_force_n=50.0)),
            ("conjugate roller pair", ConjugateTranslatingRoller(40.0, 8.0, 110.0).geometry(prog),
             Loads(0.3, damping=20.0)))
    return [(name, geom, loads,
             pair_of(geom, loads, w) if len(geom.profiles) > 1 else ContactDynamics(geom.profiles[0], loads, w))
            for name, geom, loads in cams]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=100_000)
    ap.add_argument("--repeat", type=int, default=5)
    a = ap.parse_args()
    prog = MotionProgram.from_segments(ROWS)
    osc = MotionProgram.from_segments(OSC_ROWS)
    phi = np.linspace(0, 2 * math.pi, a.n, endpoint=False)
    t_motion = best(lambda: prog.evaluate(phi), a.repeat)
    w = 600 * RPM
    cams = cases(prog, osc, w)
    print(f"12-segment cam, {a.n:,} angles, 600 rpm; motion engine S..S''' {t_motion * 1e3:.1f} ms")
    print(f"{'mechanism':<24}{'forces ms':>11}{'ratio':>8}{'analysis ms':>13}")
    for name, geom, loads, dyn in cams:
        t_ev = best(lambda dyn=dyn: dyn.evaluate(phi), a.repeat)
        t_an = best(lambda geom=geom, loads=loads: analyse_dynamics(geom, loads, w), a.repeat)
        print(f"{name:<24}{t_ev * 1e3:>11.1f}{t_ev / t_motion:>7.2f}x{t_an * 1e3:>13.1f}")


if __name__ == "__main__":
    main()
