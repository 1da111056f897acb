"""Benchmark: camfab.geom2d's arc-centre conversions against ezdxf.math.bulge_center.

``README.md`` ("What is hand-written") and :mod:`camfab.geom2d` quote the cost of finding the centres of a
chain of bulge arcs three ways; this measures them on a real chain (the exported profile of a built-in
example, thousands of arcs):

* ``ezdxf.math.bulge_center`` called once per arc (the library's API, the tests' reference);
* :func:`camfab.geom2d.bulge_centre` called once per arc (camfab's scalar formula);
* :meth:`camfab.geom2d.ArcChain.from_bulges` on the whole chain (vectorised: what the exporters use).

Reported: microseconds per arc, best of ``--repeat``, and the largest difference of the centres from
ezdxf's (they round differently, so a few 1e-12 mm are expected). No pass/fail on timing.

Run:  python3 benchmarks/bench_geom2d.py [--repeat 7] [--example ejemplo9rt] [--tol 1e-6]
"""
from __future__ import annotations

import argparse
import time

import numpy as np


def _best(fn, repeat: int) -> float:
    best = float("inf")
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=7)
    ap.add_argument("--example", default="ejemplo9rt")
    ap.add_argument("--tol", type=float, default=1e-6, help="profile tolerance in mm (more arcs when smaller)")
    args = ap.parse_args()

    from ezdxf.math import Vec2, bulge_center

    import camfab
    from camfab.geom2d import ArcChain, bulge_centre

    chain = camfab.load(args.example).shapes(args.tol).profiles[0]
    arcs = ~chain.is_line
    starts, ends, bulges = chain.starts[arcs], chain.ends[arcs], chain.bulges[arcs]
    n = len(bulges)

    def by_ezdxf():
        return [bulge_center(Vec2(a), Vec2(b), float(g)) for a, b, g in zip(starts, ends, bulges, strict=True)]

    def by_scalar():
        return [bulge_centre(a, b, float(g)) for a, b, g in zip(starts, ends, bulges, strict=True)]

    def by_chain():
        return ArcChain.from_bulges(np.vstack([starts, ends[-1:]]), np.append(bulges, 0.0), closed=False).centres

    t_ez, t_sc, t_ch = (_best(f, args.repeat) for f in (by_ezdxf, by_scalar, by_chain))
    ref = np.array([[c.x, c.y] for c in by_ezdxf()])
    d_sc = float(np.max(np.abs(np.array(by_scalar()) - ref)))
    d_ch = float(np.max(np.abs(by_chain() - ref)))
    print(f"{args.example} at tol {args.tol:g} mm: {n} arcs")
    print(f"  ezdxf.math.bulge_center per arc   {1e6 * t_ez / n:8.3f} µs/arc")
    print(f"  geom2d.bulge_centre per arc        {1e6 * t_sc / n:8.3f} µs/arc   max |Δ| {d_sc:.2e} mm")
    print(f"  ArcChain.from_bulges (vectorised)  {1e6 * t_ch / n:8.3f} µs/arc   max |Δ| {d_ch:.2e} mm")


if __name__ == "__main__":
    main()
