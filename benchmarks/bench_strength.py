"""Benchmark: contact stress of the 12-segment cam — Hertz stress at 10^5 angles against the force evaluation it
rests on, and the full analysis (exact peak, ranges above the allowable, roller life, cam-life estimate).

The target (issue 16): the stress along 10^5 angles within 2x the force evaluation
(``ContactDynamics.evaluate``) at the same count.  Best of ``--repeat`` (the machine may be shared).

Run:  python3 benchmarks/bench_strength.py [--n 100000] [--repeat 5]
"""
from __future__ import annotations

import argparse
import math

import numpy as np
from bench_dynamics import cases
from bench_profile import OSC_ROWS, ROWS, best

from camfab.design.materials import MATERIALS
from camfab.design.program import MotionProgram
from camfab.design.strength import StrengthInput, StressModel, analyse_strength, effective_modulus
from camfab.units import RPM


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=100_000)
    ap.add_argument("--repeat", type=int, default=5)
    a = ap.parse_args()
    prog = MotionProgram.from_segments(ROWS)
    osc = MotionProgram.from_segments(OSC_ROWS)
    phi = np.linspace(0, 2 * math.pi, a.n, endpoint=False)
    w = 600 * RPM
    cam, roller = MATERIALS["C45"], MATERIALS["100Cr6"]
    e = effective_modulus(cam.e_mpa, cam.poisson, roller.e_mpa, roller.poisson)
    cams = cases(prog, osc, w)
    print(f"12-segment cam, {a.n:,} angles, 600 rpm")
    print(f"{'mechanism':<24}{'forces ms':>11}{'stress ms':>11}{'ratio':>8}{'analysis ms':>13}")
    for name, geom, _, dyn in cams:
        model = StressModel(dyn, e, 10.0)
        t_force = best(lambda dyn=dyn: dyn.evaluate(phi), a.repeat)
        t_stress = best(lambda model=model: model.evaluate(phi), a.repeat)
        inp = StrengthInput(dyn, cam, roller, 10.0, cam.allowable_mpa, 8000.0)
        t_an = best(lambda geom=geom, inp=inp: analyse_strength(geom, inp), a.repeat)
        print(f"{name:<24}{t_force * 1e3:>11.1f}{t_stress * 1e3:>11.1f}{t_stress / t_force:>7.2f}x{t_an * 1e3:>13.1f}")


if __name__ == "__main__":
    main()
