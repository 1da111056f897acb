"""Benchmark: ``check()`` of every built-in example, cold, against the target of 25 ms.

``check()`` is the design's whole check as ``camfab check`` runs it (``camfab.design.assemble.check_design``
with the design's tool radius; follower dynamics and knot-table warnings included where the design has
them), timed *cold*: the design read afresh and numeric's caches cleared each time, so nothing computed by
an earlier run is reused.  Best of ``--repeat`` (the machine may be shared).

``--baseline [REF]`` times the same in the code before the redesign (``benchmarks/baseline.py``) in the
same run.

Run:  python3 benchmarks/bench_check.py [--repeat 7] [--baseline]
"""
from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
TARGET_MS = 25.0


def _api():
    """(list of (name, path), load_design, check_design) of whichever camfab is imported."""
    from camfab.design.assemble import check_design

    try:
        from camfab.formats import load_design
    except ImportError:  # the code before the redesign read designs in the core
        from camfab.design.spec import load_design
    import camfab

    base = Path(camfab.__file__).parent
    folder = next(p for p in (base / "examples", base / "templates" / "examples") if p.is_dir())
    return sorted((p.stem, p) for p in folder.glob("*.toml")), load_design, check_design


def timings(repeat: int) -> dict[str, float]:
    examples, load_design, check_design = _api()
    try:
        from camfab.numeric import clear_caches
    except ImportError:
        clear_caches = lambda: None  # noqa: E731
    out = {}
    for name, path in examples:
        best = math.inf
        for _ in range(repeat):
            spec = load_design(path)
            tool = spec.manufacturing.tool_diameter_mm
            clear_caches()
            t0 = time.perf_counter()
            check_design(spec, tool_radius_mm=tool / 2 if tool else None)
            best = min(best, time.perf_counter() - t0)
        out[name] = best
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=7)
    ap.add_argument("--baseline", nargs="?", const="", default=None, metavar="REF")
    ap.add_argument("--rounds", type=int, default=2)
    ap.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    a = ap.parse_args()
    if a.child:
        print(json.dumps(timings(a.repeat)))
        return
    t = timings(a.repeat)
    print(f"check() cold, best of {a.repeat}; target <= {TARGET_MS:g} ms")
    worst = max(t.values())
    for name, s in t.items():
        print(f"  {name:28}{s * 1e3:8.2f} ms" + ("" if s * 1e3 <= TARGET_MS else "  MISSED"))
    print(f"slowest {worst * 1e3:.2f} ms: {'OK' if worst * 1e3 <= TARGET_MS else 'MISSED'}")
    if a.baseline is not None:
        from baseline import print_ratios, run_both

        mine, base = run_both(__file__, ["--repeat", str(a.repeat)], a.baseline or None, a.rounds)
        print_ratios(mine, base, a.baseline or None, math.inf)


if __name__ == "__main__":
    main()
