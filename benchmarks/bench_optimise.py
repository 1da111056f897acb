"""Benchmark: ``camfab optimise``'s solver on the typical 12-segment roller cam.

All 12 segment angles free (20° to 45°, their sum kept at 360°) and the base radius (50 to 70 mm);
objectives: the peak |acceleration| (weight 1) and the peak |pressure angle| (weight 1), with the default
constraints (no undercut, pressure angle within 30°).  SLSQP, then differential evolution (seeded) with a
budget of 5 generations of 6 × 13 members.  Target: under 10 s on 2 cores.  Best of ``--repeat`` (the
machine may be shared).

Run:  python3 benchmarks/bench_optimise.py [--repeat 3]
"""
from __future__ import annotations

import argparse
import time

from typical_cam import ROWS

from camfab.design.optimise import build_problem, solve
from camfab.design.spec import design_from_dict


def design(method: str) -> dict:
    return {
        "name": "typical12",
        "cam": {"kind": "disc", "rotation": "cw", "omega_rad_s": 1.0},
        "follower": {"type": "roller", "motion": "translating", "base_radius_mm": 60.0, "roller_radius_mm": 10.0,
                     "offset_mm": 0.0},
        "motion": [{"law": law, "lift": float(h), "angle_deg": float(a)} for law, h, a in ROWS],
        "optimise": {"method": method, "seed": 1, "max_iterations": 100 if method == "slsqp" else 5,
                     "variables": [{"name": f"motion[{i}].angle_deg", "lo": 20.0, "hi": 45.0} for i in range(12)]
                     + [{"name": "follower.base_radius_mm", "lo": 50.0, "hi": 70.0}],
                     "objectives": {"peak_acceleration": 1.0, "peak_pressure_angle_deg": 1.0}},
    }


def run(method: str):
    data = design(method)
    prob = build_problem(data, design_from_dict(data))
    t = time.perf_counter()
    res = solve(prob)
    return time.perf_counter() - t, res


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    a = ap.parse_args()
    print(f"{'method':<24}{'best s':>8}{'evaluations':>13}{'score':>22}")
    for method in ("slsqp", "differential_evolution"):
        runs = [run(method) for _ in range(a.repeat)]
        t, res = min(runs, key=lambda r: r[0])
        print(f"{method:<24}{t:>8.2f}{res.evaluations:>13}{res.score_start:>11.4f} → {res.score:.4f}")


if __name__ == "__main__":
    main()
