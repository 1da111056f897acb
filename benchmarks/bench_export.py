"""Benchmark: accuracy versus run time of the CAD/CAM geometry for a real cam design.

For tol in 1e-1 … 1e-6 mm on the built-in Ejemplo9RT (8 segments), IndexingPackaging, a typical
12-segment roller cam (``typical_cam.py``, passes ``camfab check``) and the two reference cams: arc count and
measured deviation of the profile, of the tool-centre path, and the wall time (best of ``--repeat``) of a whole
arc-fitted DXF export (profile + pitch curve + circles + bore, written to bytes).

Run:  PYTHONPATH=. python3 benchmarks/bench_export.py [--repeat 3] [--tols 1e-3,1e-4]
"""
from __future__ import annotations

import time

from camfab.cad.export import build_artifacts
from camfab.design.assemble import geometry_from_spec
from camfab.discretize import arcs
from camfab.formats import load_design, resolve_design_path
from camfab.offset import profile_curve, tool_centre_path

TOLS = (1e-1, 1e-2, 1e-3, 1e-4, 1e-5, 1e-6)


REPEAT = 3


def _timed(fn, *a, **kw):
    best, out = float("inf"), None
    for _ in range(REPEAT):
        t = time.perf_counter()
        out = fn(*a, **kw)
        best = min(best, time.perf_counter() - t)
    return out, best


def _designs():
    import sys
    from pathlib import Path

    for name in ("ejemplo9rt", "indexing_packaging"):
        spec = load_design(resolve_design_path(name))
        yield spec, geometry_from_spec(spec)
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    from typical_cam import typical_geometry

    yield typical_geometry()
    from typical_cam import REFERENCE, reference_geometry

    for variant in REFERENCE:
        yield reference_geometry(variant)


def main(argv=None) -> None:
    import argparse

    global REPEAT
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--tols", default=",".join(f"{t:g}" for t in TOLS))
    args = ap.parse_args(argv)
    REPEAT = args.repeat
    tols = [float(t) for t in args.tols.split(",")]
    for spec, geom in _designs():
        c = geom.profiles[0]
        r = spec.manufacturing.tool_diameter_mm / 2
        print(f"\n{spec.name}: {len(spec.program().segments)} segments, tool radius {r:g} mm")
        print(f"{'tol mm':>8} | {'profile arcs':>12} {'max dev':>9} {'s':>6} | {'tool-path arcs':>14} {'max dev':>9}"
              f" {'s':>6} | {'DXF export s':>12}")
        for tol in tols:
            fit, t1 = _timed(arcs, profile_curve(c), tol=tol)
            tp, t2 = _timed(tool_centre_path, c, r, tol=tol)
            _, t3 = _timed(build_artifacts, spec, geom, ["dxf"], tol=tol)
            print(f"{tol:>8.0e} | {fit.n_entities:>12} {fit.max_deviation:>9.2e} {t1:>6.3f} | {tp.arcs.n_entities:>14}"
                  f" {tp.max_deviation:>9.2e} {t2:>6.3f} | {t3:>12.3f}")


if __name__ == "__main__":
    main()
