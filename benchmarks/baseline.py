"""Timing this tree against the code before the core redesign, in the same run.

``run_both(script, args, ref, rounds)`` checks out git ref ``ref`` (default :data:`BASELINE_REF`, the commit
that recorded the golden manifest before the redesign began) into a temporary ``git worktree`` and runs
``script --child args…`` alternately with this tree's ``camfab`` and the baseline's (``PYTHONPATH``) in fresh
interpreters, ``rounds`` times; each side keeps its best time per key.  The script's ``--child`` mode
prints ``{key: seconds}`` as JSON and must use only API both trees have.
"""
from __future__ import annotations

import json
import math
import os
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
#: the code before the core redesign (the commit that recorded the golden manifest)
BASELINE_REF = "da27cbc"


def _child(script: Path, root: Path, args: list[str]) -> dict[str, float]:
    env = {**os.environ, "PYTHONPATH": str(root), "OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1"}
    res = subprocess.run([sys.executable, str(script), "--child", *args], env=env, capture_output=True, text=True,
                         check=True, cwd=str(root))
    return json.loads(res.stdout.strip().splitlines()[-1])


def run_both(script: str | Path, args: list[str], ref: str | None = None,
             rounds: int = 3) -> tuple[dict[str, float], dict[str, float]]:
    """Best seconds per key of this tree and of ``ref`` (alternating ``rounds`` times)."""
    ref = ref or BASELINE_REF
    script = Path(script).resolve()
    mine: dict[str, float] = {}
    base: dict[str, float] = {}
    with tempfile.TemporaryDirectory(prefix="camfab-baseline-") as tmp:
        wt = Path(tmp) / "tree"
        subprocess.run(["git", "-C", str(ROOT), "worktree", "add", "--detach", str(wt), ref],
                       capture_output=True, text=True, check=True)
        try:
            for _ in range(rounds):
                for store, root in ((mine, ROOT), (base, wt)):
                    for key, t in _child(script, root, args).items():
                        store[key] = min(store.get(key, math.inf), t)
        finally:
            subprocess.run(["git", "-C", str(ROOT), "worktree", "remove", "--force", str(wt)],
                           capture_output=True, text=True, check=False)
    return mine, base


def print_ratios(mine: dict[str, float], base: dict[str, float], ref: str | None, target: float,
                 keys: list[str] | None = None) -> bool:
    """Print both columns and their ratio; True when every key in ``keys`` (default: all) is within
    ``target``."""
    print(f"\nthis tree against {ref or BASELINE_REF} (the code before the redesign), same run")
    print(f"{'':44}{'this (ms)':>11}{'before (ms)':>13}{'ratio':>8}")
    ok = True
    for key in mine:
        if not base.get(key):  # new since the baseline (e.g. an example added by the redesign): nothing to compare
            print(f"{key:44}{mine[key] * 1e3:>11.3f}{'(new)':>13}{'':>8}")
            continue
        r = mine[key] / base[key]
        judged = keys is None or key in keys
        ok &= (not judged) or r <= target
        print(f"{key:44}{mine[key] * 1e3:>11.3f}{base[key] * 1e3:>13.3f}{r:>8.2f}"
              + ("" if not judged else ("" if r <= target else "  MISSED")))
    if math.isfinite(target):
        print(f"target: ratio <= {target} — {'OK' if ok else 'MISSED'}")
    return ok
