"""Benchmark: ``camfab verify`` time versus the size of the cam (issue 12: it grew with the part, not the program).

Ejemplo9RT (translating roller Rr 7 mm, 10 mm lifts, 6 mm cutter, 10 mm plate, tol 1 um) with the base radius
Rb = 50 mm, 1 m and 10 m.  For each: the program's lines and finishing entities, the time to write it
(``cam_program`` + LinuxCNC text), the time to build the exact part distance (a polyline within tol/50 of the
profile, as ``camfab verify`` does) and the time of the checks themselves (parse, back-plot, every check,
coverage), which follow the number of moves.  CPU seconds of this process.

Before the fix (fixed 0.05 mm sampling of every move, a distance pass over every polyline vertex per point):
2.8 s for Rb 50 mm, 116 s for Rb 1 m, unfinished after 25 min for Rb 10 m.

Run:  python3 benchmarks/bench_verify.py      (about a minute; the 10 m polyline needs ~1 GB)
"""
from __future__ import annotations

import time
import tomllib
from pathlib import Path

from camfab.design.assemble import geometry_from_spec
from camfab.design.spec import design_from_dict
from camfab.gcode import dumps
from camfab.gcode.cam import cam_program, signed_distance, verify_cam_program
from camfab.offset import profile_curve
from camfab.pipeline import gcode_job

EXAMPLE = Path(__file__).resolve().parents[1] / "camfab" / "examples" / "ejemplo9rt.toml"


def _cpu() -> float:
    return time.process_time()


def main() -> None:
    base = tomllib.loads(EXAMPLE.read_text(encoding="utf-8"))
    print("Ejemplo9RT scaled by its base radius; LinuxCNC; tol 0.001 mm; CPU seconds")
    print(f"{'Rb mm':>8} {'lines':>6} {'finish':>6} | {'gcode s':>8} | {'part distance s':>15} {'checks s':>9} "
          f"{'verify s':>9} | ok")
    for rb in (50.0, 1000.0, 10000.0):
        data = dict(base, name=f"rb{rb:g}", follower=dict(base["follower"], base_radius_mm=rb))
        spec = design_from_dict(data)
        contact = geometry_from_spec(spec).profiles[0]
        tol = spec.manufacturing.tolerance_mm
        job = gcode_job(spec, tol=tol)
        t0 = _cpu()
        cp = cam_program(contact, job, tol=tol)
        text = dumps(cp.program, "linuxcnc")
        t1 = _cpu()
        part = signed_distance(profile_curve(contact), tol=tol)
        t2 = _cpu()
        rep = verify_cam_program(text, contact, job, tol=tol, part=part)
        t3 = _cpu()
        print(f"{rb:>8g} {len(text.splitlines()):>6} {rep.finish_moves:>6} | {t1 - t0:>8.2f} | {t2 - t1:>15.2f} "
              f"{t3 - t2:>9.2f} {t3 - t1:>9.2f} | {rep.ok}")


if __name__ == "__main__":
    main()
