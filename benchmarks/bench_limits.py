"""Benchmark: the input limits (docs/decisions.md, "Input limits") — what a design at each limit costs, and that
a design past it is refused cheaply.

Each case runs ``camfab check`` (and, where the decision quotes it, ``camfab export --dxf --tol 1e-3``) in a child
process and reports its CPU seconds and peak resident memory (the child's own ``getrusage``), so the numbers
quoted in decisions.md can be re-measured on any machine:

- at the limit: 1000 segments (smooth and steep), 10 000 knots (smooth and rough), a 4 MB TOML of numbers;
- past the limit (must exit 2 within a second or two and a few hundred MB): 10 000 segments, 100 000 knot rows,
  one knot value 1e300, 100 000 nested brackets, a 1.5 GB name is not built here (it needs 1.5 GB of disk) —
  a 5 MB name stands in for it.

Run:  python3 benchmarks/bench_limits.py [--quick]      (--quick: skips the export column and the slowest cases)
"""
from __future__ import annotations

import argparse
import json
import math
import subprocess
import sys
import tempfile
from pathlib import Path

HEAD = ('[cam]\nspeed_rpm = 60.0\n[follower]\ntype = "roller"\nmotion = "translating"\nbase_radius_mm = 35.0\n'
        'roller_radius_mm = 5.0\n[manufacturing]\nthickness_mm = 10.0\nbore_mm = 12.0\ntool_diameter_mm = 6.0\n')

#: the child: runs one CLI command and prints its exit code, CPU seconds and peak RSS (MB) as JSON on stderr's
#: last line (the command's own output is discarded)
CHILD = """
import json, resource, sys, io, contextlib
from camfab.cli import main
with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
    rc = main(sys.argv[1:])
r = resource.getrusage(resource.RUSAGE_SELF)
print(json.dumps({"rc": rc, "cpu": r.ru_utime + r.ru_stime, "mb": r.ru_maxrss / 1024}), file=sys.stderr)
"""


def segments(n: int, lift: float) -> str:
    """``n`` segments: cycloidal rises and returns of ``lift`` mm, alternating, equal angles summing to 360."""
    n -= n % 2
    ang = 360.0 / n
    rows = "".join(f'[[motion]]\nlaw = "cycloidal"\nlift = {lift if i % 2 == 0 else -lift}\nangle_deg = {ang!r}\n'
                   for i in range(n))
    return f'name = "Seg{n}"\n{HEAD}{rows}'


def knots(folder: Path, n: int, rough: bool) -> str:
    """A design reading ``n`` knots (a 10 mm harmonic rise-return over 360°, or that with noise in s, v, a)."""
    import random

    rng = random.Random(1)
    lines = ["angle_deg,s_mm,v_mm_s,a_mm_s2"]
    w = 2 * math.pi  # rad/s at 60 rpm
    for i in range(n):
        th = 360.0 * i / (n - 1)
        x = math.radians(th)
        s, v, a = 5 * (1 - math.cos(x)), 5 * w * math.sin(x), 5 * w * w * math.cos(x)
        if rough and 0 < i < n - 1:
            s += rng.uniform(0, 1e-3)
            v += rng.uniform(-1, 1)
            a += rng.uniform(-10, 10)
        lines.append(f"{th!r},{s!r},{v!r},{a!r}")
    (folder / f"k{n}{rough:d}.csv").write_text("\n".join(lines) + "\n")
    return (f'name = "Knots{n}"\n{HEAD}[motion_table]\nfile = "k{n}{rough:d}.csv"\n'
            'units = { angle = "deg", s = "mm", v = "mm/s", a = "mm/s2" }\nspeed_rpm = 60\ndegree = 5\n')


def numbers_toml(size: int) -> str:
    """A design whose knot rows are inline: a TOML near ``size`` bytes of arrays of numbers."""
    row = "[0.123456789012345, 0.123456789012345, 0.123456789012345, 0.123456789012345],\n"
    n = max(2, size // len(row))
    return f'name = "Big"\n{HEAD}[motion_table]\nrows = [\n{row * n}]\n'


def run(argv: list[str]) -> dict:
    p = subprocess.run([sys.executable, "-c", CHILD, *argv], capture_output=True, text=True, timeout=1800)
    try:
        return json.loads(p.stderr.strip().splitlines()[-1])
    except (IndexError, json.JSONDecodeError):
        return {"rc": p.returncode, "cpu": math.nan, "mb": math.nan}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="no export column, no 1000-segment steep case")
    a = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        d = Path(tmp)
        cases: list[tuple[str, str, bool]] = [  # label, design text, also export?
            ("1000 segments, smooth", segments(1000, 0.001), True),
            ("10 000 knots, smooth", knots(d, 10_000, False), True),
            ("10 000 knots, rough", knots(d, 10_000, True), False),
            ("4 MB TOML of numbers (> 10 000 knots)", numbers_toml(3_900_000), False),
            ("past: 10 000 segments", segments(10_000, 0.01), False),
            ("past: 100 000 knots", knots(d, 100_000, False), False),
            ("past: a knot s = 1e300", knots(d, 50, False).replace("k500.csv", "big.csv"), False),
            ("past: 100 000 nested [", 'name = "x"\nv = ' + "[" * 100_000 + "\n", False),
            ("past: a 5 MB name", 'name = "' + "n" * 5_000_000 + '"\n' + HEAD, False),
        ]
        if not a.quick:
            cases.insert(1, ("1000 segments, steep (±1 mm in 0.36°)", segments(1000, 1.0), False))
        (d / "big.csv").write_text("angle_deg,s_mm,v_mm_s,a_mm_s2\n0,0,0,0\n180,1e300,0,0\n360,0,0,0\n")
        print(f"{'case':<40}{'check':>22}{'export --dxf 1e-3':>26}")
        for i, (label, text, export) in enumerate(cases):
            f = d / f"case{i}.toml"
            f.write_text(text)
            c = run(["check", str(f)])
            row = f"{label:<40}{_fmt(c):>22}"
            if export and not a.quick:
                row += f"{_fmt(run(['export', str(f), '--dxf', '--tol', '1e-3', '-o', str(d / f'out{i}')])):>26}"
            print(row, flush=True)
        print("exit 2 = refused as invalid input (past a limit); 0/1 = computed (acceptable / not)")


def _fmt(r: dict) -> str:
    return f"rc {r['rc']}  {r['cpu']:6.1f} s {r['mb']:6.0f} MB"


if __name__ == "__main__":
    main()
