"""The same bytes whatever the machine's thread count (docs/decisions.md, "One BLAS thread in the fitter"):
every artifact kind of ``camfab run``, in separate processes with BLAS/OpenMP on one and on two threads and
different hash seeds, is byte-identical (a plate cam's kinds and a cylindrical cam's: its developed DXF, STEP,
IGES, the STL meshed from the exact surfaces, the rotary program).  Before the fitter pinned BLAS to one thread,
Ejemplo11RO's STL had 5 576 triangles on one thread and 5 560 on two."""
from __future__ import annotations

import hashlib
import os
import subprocess
import sys
from pathlib import Path

import pytest

from camfab.pipeline import Output

ROOT = Path(__file__).resolve().parents[1]


def _run(example: str, out: Path, threads: int, seed: int) -> dict[str, str]:
    env = {**os.environ, "PYTHONPATH": str(ROOT), "OMP_NUM_THREADS": str(threads),
           "OPENBLAS_NUM_THREADS": str(threads), "MKL_NUM_THREADS": str(threads), "PYTHONHASHSEED": str(seed)}
    outputs = ",".join(o.value for o in Output)  # every artifact kind there is
    p = subprocess.run([sys.executable, "-m", "camfab", "run", example, "-o", str(out), "--outputs", outputs,
                        "--force"], env=env, capture_output=True, text=True, timeout=1200)
    assert p.returncode in (0, 1), p.stderr
    return {str(f.relative_to(out)): hashlib.sha256(f.read_bytes()).hexdigest()
            for f in sorted(out.rglob("*")) if f.is_file()}


def test_the_fitter_runs_blas_on_one_thread():
    """Inside the fit BLAS is limited to one thread, outside it is left as it was."""
    from threadpoolctl import threadpool_info

    from camfab.threads import one_blas_thread

    before = [i["num_threads"] for i in threadpool_info() if i["user_api"] == "blas"]
    with one_blas_thread():
        assert all(i["num_threads"] == 1 for i in threadpool_info() if i["user_api"] == "blas")
    assert [i["num_threads"] for i in threadpool_info() if i["user_api"] == "blas"] == before


@pytest.mark.slow
@pytest.mark.parametrize("example", ["ejemplo11ro", "constant_width", "cylindrical_translating"])
def test_every_artifact_identical_on_one_and_two_threads(tmp_path, example):
    one = _run(example, tmp_path / "one", 1, 1)
    two = _run(example, tmp_path / "two", 2, 2)
    assert len(one) >= 8, one  # every kind was written (several files per kind for some)
    assert one == two, sorted(k for k in one if one.get(k) != two.get(k))


@pytest.mark.slow
def test_a_conjugate_pair_step_is_the_same_after_other_work_in_the_process(tmp_path):
    """OpenCascade numbers the usage occurrences of a compound from a counter of the process: the pair's STEP
    written after another cam's assembly in the same process (a package worker) had other ids than in a fresh
    process (found by the golden manifest).  camfab numbers them in file order."""
    code = ("import sys; from camfab.cli import main\n"
            "for i, ex in enumerate(sys.argv[2:]):\n"
            "    main(['run', ex, '-o', sys.argv[1] + '-' + str(i), '--outputs', 'step,assembly'])\n")
    script = tmp_path / "s"
    runs = {"fresh": ["ejemplo8da_conjugate"], "after": ["ejemplo9rt", "ejemplo8da_conjugate"]}
    digests = {}
    for key, examples in runs.items():
        p = subprocess.run([sys.executable, "-c", code, str(script) + key, *examples],
                           env={**os.environ, "PYTHONPATH": str(ROOT)}, capture_output=True, text=True, timeout=1200)
        assert p.returncode == 0, p.stderr
        pair = Path(f"{script}{key}-{len(examples) - 1}") / "Ejemplo8DA_pair.step"
        digests[key] = hashlib.sha256(pair.read_bytes()).hexdigest()
    assert digests["fresh"] == digests["after"]
