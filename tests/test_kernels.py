"""The same bytes on every x86-64 CPU with AVX2 (docs/decisions.md, "The same bytes on every x86-64 CPU with AVX2").

numpy's AVX-512 kernels and OpenBLAS's SkylakeX ones round differently from those of an AVX2 machine, and an
AVX-512 machine wrote 230 of the golden manifest's records differently (every example's DXF and programs among
them). The command line pins both before numpy is imported (:mod:`camfab.kernels`). Here:
- the rule itself, on described CPUs;
- the command line's numpy and OpenBLAS on this machine;
- ``run`` and ``package --jobs 2`` in fresh processes, their DXF and programs against the golden manifest's
  hashes. Those hashes were recorded on a machine without AVX-512; on an AVX-512 machine these tests failed before
  the pinning."""
from __future__ import annotations

import hashlib
import json
import os
import subprocess
import sys
from importlib import metadata
from pathlib import Path

import pytest

from camfab.kernels import NUMPY_AVX512_GROUPS, OPENBLAS_CORE, cpu_flags, numpy_version, same_kernels_by_default

ROOT = Path(__file__).resolve().parents[1]
MANIFEST = json.loads((ROOT / "tests" / "golden" / "manifest.json").read_text(encoding="utf-8"))
#: the variables a user sets to choose the kernels (removed to run the command line as on a plain machine)
USER_VARIABLES = ("NPY_DISABLE_CPU_FEATURES", "NPY_ENABLE_CPU_FEATURES", "OPENBLAS_CORETYPE")
AVX512 = frozenset({"sse4_2", "avx", "avx2", "fma", "avx512f", "avx512bw"})
AVX2 = frozenset({"sse4_2", "avx", "avx2", "fma"})
SANDYBRIDGE = frozenset({"sse4_2", "avx"})


def _plain_env() -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if k not in USER_VARIABLES}
    env["PYTHONPATH"] = str(ROOT)
    return env


@pytest.mark.parametrize("flags, version, expected", [
    (AVX512, (2, 4), {"NPY_DISABLE_CPU_FEATURES": NUMPY_AVX512_GROUPS, "OPENBLAS_CORETYPE": OPENBLAS_CORE}),
    (AVX512, (3, 0), {"NPY_DISABLE_CPU_FEATURES": NUMPY_AVX512_GROUPS, "OPENBLAS_CORETYPE": OPENBLAS_CORE}),
    (AVX512, (2, 3), {"OPENBLAS_CORETYPE": OPENBLAS_CORE}),  # other feature names before numpy 2.4: left alone
    (AVX512, None, {"OPENBLAS_CORETYPE": OPENBLAS_CORE}),
    (AVX2, (2, 4), {"OPENBLAS_CORETYPE": OPENBLAS_CORE}),  # numpy's AVX2 kernels are the reference already
    (SANDYBRIDGE, (2, 4), {}),  # no AVX2: OpenBLAS's Haswell kernels would not run there
    (None, (2, 4), {}),  # not Linux x86-64
])
def test_the_rule_on_described_cpus(flags, version, expected):
    env: dict[str, str] = {"PATH": "/usr/bin"}
    assert same_kernels_by_default(env, flags, version) == expected
    assert env == {"PATH": "/usr/bin", **expected}


@pytest.mark.parametrize("mine", [{"NPY_DISABLE_CPU_FEATURES": ""}, {"NPY_ENABLE_CPU_FEATURES": "X86_V3"},
                                  {"OPENBLAS_CORETYPE": "SkylakeX"}])
def test_a_users_choice_wins(mine):
    env = dict(mine)
    set_ = same_kernels_by_default(env, AVX512, (2, 4))
    assert not set(set_) & set(mine) and all(env[k] == v for k, v in mine.items())
    if "OPENBLAS_CORETYPE" in mine:
        assert set_ == {"NPY_DISABLE_CPU_FEATURES": NUMPY_AVX512_GROUPS}
    else:
        assert set_ == {"OPENBLAS_CORETYPE": OPENBLAS_CORE}  # the NPY pair is one choice


def test_flags_and_version_are_read_from_the_machine(tmp_path):
    import numpy

    assert numpy_version() == tuple(int(p) for p in numpy.__version__.split(".")[:2])
    if cpu_flags() is None:
        pytest.skip("not Linux x86-64")
    info = tmp_path / "cpuinfo"
    info.write_text("processor\t: 0\nvendor_id\t: X\nflags\t\t: fpu sse4_2 avx avx2 fma\n\nprocessor\t: 1\n"
                    "flags\t\t: fpu\n", encoding="ascii")
    assert cpu_flags(str(info)) == frozenset({"fpu", "sse4_2", "avx", "avx2", "fma"})
    assert cpu_flags(str(tmp_path / "missing")) is None


def test_the_command_lines_numpy_and_openblas_run_the_avx2_kernels():
    """``python -m camfab`` (``camfab.__main__``) pins them before numpy is imported, in a process whose
    environment does not choose them."""
    code = ("import camfab.__main__, json, numpy\n"
            "from numpy._core._multiarray_umath import __cpu_features__ as f, __cpu_dispatch__ as d\n"
            "from threadpoolctl import threadpool_info\n"
            "blas = [i.get('architecture') for i in threadpool_info() if i['user_api'] == 'blas']\n"
            "print(json.dumps({'on': sorted(k for k in d if f[k]), 'blas': blas}))")
    p = subprocess.run([sys.executable, "-c", code], env=_plain_env(), capture_output=True, text=True, timeout=120,
                       check=True)
    seen = json.loads(p.stdout)
    assert not set(NUMPY_AVX512_GROUPS.split()) & set(seen["on"]), seen  # numpy's dispatched targets in use
    flags = cpu_flags()
    if flags is not None and {"avx2", "fma"} <= flags and any("openblas" in (i.get("internal_api") or "")
                                                             for i in _blas_info()):
        assert set(seen["blas"]) == {OPENBLAS_CORE}, seen


def _blas_info() -> list[dict]:
    from threadpoolctl import threadpool_info

    return [i for i in threadpool_info() if i["user_api"] == "blas"]


def _golden_versions_or_skip() -> None:
    """The golden hashes hold for the numpy and scipy they were recorded with (the fit's arithmetic)."""
    for name in ("numpy", "scipy"):
        if MANIFEST["versions"].get(name) != metadata.version(name):
            pytest.skip(f"the golden manifest was recorded with {name} {MANIFEST['versions'].get(name)}")
    flags = cpu_flags()
    if flags is None or not {"avx2", "fma"} <= flags:
        pytest.skip("the same bytes are promised on x86-64 CPUs with AVX2 and FMA")


def _hashes(folder: Path) -> dict[str, str]:
    return {p.name: hashlib.sha256(p.read_bytes()).hexdigest() for p in folder.rglob("*")
            if p.is_file() and p.suffix in (".dxf", ".nc") and "_drawing" not in p.name}


@pytest.mark.slow
def test_run_writes_the_golden_bytes_on_this_cpu(tmp_path):
    _golden_versions_or_skip()
    for example, stem in (("ejemplo9rt", "Ejemplo9RT"), ("ejemplo11ro", "Ejemplo11RO")):
        out = tmp_path / example
        subprocess.run([sys.executable, "-m", "camfab", "run", example, "-o", str(out), "--outputs", "dxf,gcode"],
                       env=_plain_env(), capture_output=True, timeout=600, check=True)
        golden = MANIFEST["examples"][example]["sha256"]
        assert _hashes(out) == {f"{stem}.dxf": golden[f"run/{stem}.dxf"], f"{stem}.nc": golden[f"run/{stem}.nc"]}


@pytest.mark.slow
def test_package_workers_write_the_golden_bytes_on_this_cpu(tmp_path):
    """The workers are new processes: they inherit the pinning from the command line's environment."""
    _golden_versions_or_skip()
    from camfab.formats import EXAMPLES_DIR

    designs = tmp_path / "designs"
    designs.mkdir()
    for example in ("ejemplo9rt", "ejemplo11ro"):
        (designs / f"{example}.toml").write_bytes((EXAMPLES_DIR / f"{example}.toml").read_bytes())
    out = tmp_path / "out"
    subprocess.run([sys.executable, "-m", "camfab", "package", str(designs), "-o", str(out), "--outputs",
                    "dxf,gcode", "--jobs", "2"], env=_plain_env(), capture_output=True, timeout=900, check=True)
    got = _hashes(out)
    for example, stem in (("ejemplo9rt", "Ejemplo9RT"), ("ejemplo11ro", "Ejemplo11RO")):
        golden = MANIFEST["examples"][example]["sha256"]
        assert got[f"{stem}.dxf"] == golden[f"run/{stem}.dxf"] and got[f"{stem}.nc"] == golden[f"run/{stem}.nc"]
