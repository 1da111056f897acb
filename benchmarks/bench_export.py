"""Benchmark: accuracy versus run time of the CAD/CAM geometry for a real cam design.

For tol in 1e-1 … 1e-6 mm on the built-in Ejemplo9RT (8 segments) and IndexingPackaging designs:
arc count and measured deviation of the profile, of the 6 mm tool-centre path, and the wall time of a
whole arc-fitted DXF export (profile + pitch curve + circles + bore, written to bytes).

Run:  python3 benchmarks/bench_export.py
"""
from __future__ import annotations

import time

from camfab.cad.export import build_artifacts
from camfab.cli import resolve_design_path
from camfab.design.assemble import geometry_from_spec
from camfab.design.spec import load_design
from camfab.offset.cutter import profile_curve, tool_centre_path
from camfab.offset.discretize import arcs

TOLS = (1e-1, 1e-2, 1e-3, 1e-4, 1e-5, 1e-6)


def _timed(fn, *a, **kw):
    t = time.perf_counter()
    out = fn(*a, **kw)
    return out, time.perf_counter() - t


def main() -> None:
    for name in ("ejemplo9rt", "indexing_packaging"):
        spec = load_design(resolve_design_path(name))
        geom = geometry_from_spec(spec)
        c = geom.profiles[0]
        r = spec.manufacturing.tool_diameter_mm / 2
        print(f"\n{spec.name}: {len(spec.program().segments)} segments, tool radius {r:g} mm")
        print(f"{'tol mm':>8} | {'profile arcs':>12} {'max dev':>9} {'s':>6} | {'tool-path arcs':>14} {'max dev':>9}"
              f" {'s':>6} | {'DXF export s':>12}")
        for tol in TOLS:
            fit, t1 = _timed(arcs, profile_curve(c), tol=tol)
            tp, t2 = _timed(tool_centre_path, c, r, tol=tol)
            _, t3 = _timed(build_artifacts, spec, geom, ["dxf"], tol=tol)
            print(f"{tol:>8.0e} | {fit.n_entities:>12} {fit.max_deviation:>9.2e} {t1:>6.3f} | {tp.arcs.n_entities:>14}"
                  f" {tp.max_deviation:>9.2e} {t2:>6.3f} | {t3:>12.3f}")


if __name__ == "__main__":
    main()
