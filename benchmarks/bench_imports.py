"""Benchmark: start-up costs no other benchmark measures, in CPU seconds of fresh interpreters.

- ``import ezdxf`` and ``import trimesh`` (the DXF and mesh libraries; camfab imports them only for the files
  that need them), and ``import camfab.cli``;
- ``python -m camfab check ejemplo9rt`` as a whole process (the path a ``camfab check`` takes).

Each figure is the child's user + system CPU time, the best of ``--repeat`` runs after one untimed warm-up, minus
the best of a bare ``python -c pass`` measured alternately in the same loop (the interpreter's own start).  For
the imports, ``-X importtime``'s cumulative time of the top-level module is printed too (wall µs, one run).
Bytecode is cached in a temporary ``PYTHONPYCACHEPREFIX`` and ``PYTHONDONTWRITEBYTECODE`` is unset, as an
installed wheel has its ``.pyc`` files: without them every import compiles its sources.

Run:  PYTHONPATH=. python3 benchmarks/bench_imports.py [--repeat 5]
"""
from __future__ import annotations

import argparse
import math
import os
import re
import resource
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent

#: label, interpreter arguments
CASES = (
    ("bare interpreter (python -c pass)", ["-c", "pass"]),
    ("import ezdxf", ["-c", "import ezdxf"]),
    ("import trimesh", ["-c", "import trimesh"]),
    ("import camfab.cli", ["-c", "import camfab.cli"]),
    ("camfab check ejemplo9rt (process)", ["-m", "camfab", "check", "ejemplo9rt"]),
)


def _cpu(args: list[str], env: dict[str, str], cwd: str) -> float:
    """The CPU time (user + system, s) of one fresh interpreter running ``args``."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    rc = subprocess.run([sys.executable, *args], env=env, cwd=cwd, stdout=subprocess.DEVNULL,
                        stderr=subprocess.DEVNULL, check=False).returncode
    if rc not in (0, 1):  # 1: a check's verdict; anything else did not run what is timed
        raise SystemExit(f"{' '.join(args)} exited {rc}: nothing to time")
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime


def _importtime(module: str, env: dict[str, str], cwd: str) -> float | None:
    """``-X importtime``'s cumulative time (s) of ``module`` itself, or None if it is not in the log."""
    r = subprocess.run([sys.executable, "-X", "importtime", "-c", f"import {module}"], env=env, cwd=cwd,
                       capture_output=True, text=True, check=False)
    for line in r.stderr.splitlines():
        m = re.match(r"import time:\s+\d+ \|\s+(\d+) \|\s?(\S.*)$", line)
        if m and m.group(2).strip() == module:
            return int(m.group(1)) * 1e-6
    return None


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5)
    args = ap.parse_args()
    cache = tempfile.mkdtemp(prefix="camfab-pyc-")
    env = dict(os.environ, PYTHONPATH=str(HERE.parent), PYTHONPYCACHEPREFIX=cache)
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    try:
        best = [math.inf] * len(CASES)
        for i in range(args.repeat + 1):  # the cases alternate; the first round (caches the bytecode) is untimed
            for k, (_, argv) in enumerate(CASES):
                t = _cpu(argv, env, cache)
                if i:
                    best[k] = min(best[k], t)
        bare = best[0]
        print(f"{CASES[0][0]}: {bare:.3f} s CPU (best of {args.repeat})")
        for (label, argv), t in zip(CASES[1:], best[1:], strict=True):
            extra = ""
            if argv[0] == "-c":
                it = _importtime(argv[1].split()[1], env, cache)
                extra = f"; -X importtime {it:.3f} s" if it is not None else ""
            print(f"{label}: {t:.3f} s CPU, {t - bare:.3f} s over the bare interpreter{extra}")
    finally:
        shutil.rmtree(cache, ignore_errors=True)


if __name__ == "__main__":
    main()
