"""Benchmark: follower vibration of the 12-segment cam — one periodic steady state, the separation-speed
search, the whole analysis — and the accuracy of the steady state against ``solve_ivp`` over many cycles.

The one figure: the time of ``analyse_vibration`` (steady state, extremes, dwells, separation speed,
harmonics) for a translating roller at 600 rpm, next to the kinetostatic ``analyse_dynamics`` of the same cam.
Best of ``--repeat`` (the machine may be shared).

Run:  python3 benchmarks/bench_vibration.py [--repeat 5] [--cycles 3]
"""
from __future__ import annotations

import argparse
import math
import time

import numpy as np
from bench_profile import ROWS, best
from scipy.integrate import solve_ivp

from camfab.design.dynamics import Loads, analyse_dynamics
from camfab.design.mechanisms import TranslatingRoller
from camfab.design.profile import CamGeometry
from camfab.design.program import MotionProgram
from camfab.design.vibration import FollowerTrain, Train, analyse_vibration
from camfab.units import RPM


def _ivp_error(model: FollowerTrain, prog: MotionProgram, loads: Loads, w: float, cycles: int) -> tuple[float, float]:
    """(seconds, largest difference of the deflection relative to its largest) of solve_ivp from rest."""
    r = model.response(w)
    K, C = model.total_stiffness, model.damper + loads.damping

    def rhs(t, y):
        S = prog.evaluate(np.array([(w * t) % (2 * math.pi)]), (0, 1, 2))[:, 0] * 1e-3
        g = loads.inertia * S[2] * w * w + loads.damping * S[1] * w + loads.spring_rate * S[0]
        return [y[1], (-g - C * y[1] - K * y[0]) / loads.inertia]

    T = 2 * math.pi / w
    t0 = time.perf_counter()
    sol = solve_ivp(rhs, (0.0, cycles * T), [0.0, 0.0], method="DOP853", rtol=1e-10, atol=1e-14,
                    t_eval=(cycles - 1) * T + r.x / w, max_step=T / 720)
    u = r.w - r.s
    return time.perf_counter() - t0, float(np.abs(sol.y[0] - u).max() / np.abs(u).max())


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--cycles", type=int, default=3)
    a = ap.parse_args()
    prog = MotionProgram.from_segments(ROWS)
    geom = CamGeometry(TranslatingRoller(40.0, 8.0, 5.0), prog)
    loads = Loads(0.3, 20000.0, 400.0, damping=20.0)
    train = Train(5e6, 0.05)  # f_n ≈ 653 Hz against 10 Hz of the cam
    w = 600 * RPM
    c = geom.profiles[0]
    t_model = best(lambda: FollowerTrain(c, loads, train), a.repeat)
    model = FollowerTrain(c, loads, train)
    t_state = best(lambda: model.response(w), a.repeat)
    t_sep = best(lambda: model.separation_rate(w), a.repeat)
    t_all = best(lambda: analyse_vibration(c, loads, train, w), a.repeat)
    t_dyn = best(lambda: analyse_dynamics(geom, loads, w), a.repeat)
    t_ivp, err = _ivp_error(model, prog, loads, w, a.cycles)
    print(f"12-segment cam, translating roller, 600 rpm, f_n {model.natural_frequency_hz:.0f} Hz, "
          f"{model.n} samples per cycle")
    print(f"  model (motion harmonics, lever)     {t_model * 1e3:8.1f} ms")
    print(f"  one periodic steady state           {t_state * 1e3:8.1f} ms")
    print(f"  separation-speed search             {t_sep * 1e3:8.1f} ms")
    print(f"  analyse_vibration (the figure)      {t_all * 1e3:8.1f} ms   (analyse_dynamics {t_dyn * 1e3:.1f} ms)")
    print(f"  solve_ivp over {a.cycles} cycles from rest  {t_ivp * 1e3:8.1f} ms   last cycle vs the periodic "
          f"state: {err:.1e} of the deflection")


if __name__ == "__main__":
    main()
