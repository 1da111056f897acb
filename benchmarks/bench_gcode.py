"""Benchmark: G-code program size and generation time versus tolerance, arcs versus lines only.

A 12-segment cam (translating roller, Rb 40 mm, Rr 8 mm, 6 mm cutter, 10 mm plate, one roughing pass,
3 mm step-downs); for tol in 1e-1 … 1e-5 mm: finishing-contour entities, total program moves, file size and
the time to build the program and write the LinuxCNC text.

Run:  python3 benchmarks/bench_gcode.py
"""
from __future__ import annotations

import time

from camfab.design.mechanisms import TranslatingRoller
from camfab.design.profile import CamGeometry
from camfab.design.program import MotionProgram
from camfab.gcode import Job, dumps
from camfab.gcode.cam import cam_program

ROWS = [("cycloidal", 10, 30), ("dwell", 0, 30), ("poly345", 10, 30), ("dwell", 0, 30),
        ("poly4567", -10, 30), ("dwell", 0, 30), ("cycloidal", -5, 30), ("dwell", 0, 30),
        ("poly345", 10, 30), ("dwell", 0, 30), ("poly4567", -15, 30), ("dwell", 0, 30)]


def main() -> None:
    contact = CamGeometry(TranslatingRoller(40.0, 8.0), MotionProgram.from_segments(ROWS)).profiles[0]
    print("12-segment cam, 6 mm cutter, LinuxCNC")
    print(f"{'tol mm':>8} | {'arcs: contour':>13} {'moves':>7} {'kB':>7} {'s':>6} | {'lines: contour':>14} {'moves':>7}"
          f" {'kB':>7} {'s':>6}")
    for tol in (1e-1, 1e-2, 1e-3, 1e-4, 1e-5):
        row = []
        for arcs_allowed in (True, False):
            job = Job(tool_diameter_mm=6.0, depth_mm=10.0, tolerance_mm=tol)
            t = time.perf_counter()
            cp = cam_program(contact, job, tol=tol, arcs_allowed=arcs_allowed)
            text = dumps(cp.program, "linuxcnc")
            dt = time.perf_counter() - t
            moves = sum(1 for ln in text.splitlines() if ln.lstrip("N0123456789 ").startswith(("G0", "G1", "G2", "G3")))
            row.append(f"{cp.entities:>13} {moves:>7} {len(text) / 1e3:>7.1f} {dt:>6.2f}")
        print(f"{tol:>8.0e} | {row[0]} | {row[1]:>38}")


if __name__ == "__main__":
    main()
