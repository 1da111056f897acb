"""The same bits on every x86-64 CPU with AVX2: numpy's and OpenBLAS's kernels chosen before numpy is imported.

numpy picks its float64 ``exp``, ``log``, ``power``, ``arctan2``, ``cbrt``, ``tan`` and the inverse and hyperbolic
functions by the CPU at run time. Its AVX-512 kernels round differently from the AVX2 and C-library ones. OpenBLAS
picks its core by the CPU too, and its SkylakeX kernels (Intel's AVX-512 parts) add in another order than its
Haswell ones (AMD's Zen parts use those). Either change reaches the arc fit's accept/reject decisions and so the
files: on an AVX-512 machine 230 of the golden manifest's records differed, every DXF and program among them.
``same_kernels_by_default`` sets ``NPY_DISABLE_CPU_FEATURES`` to numpy's AVX-512 groups and ``OPENBLAS_CORETYPE``
to ``Haswell`` where the CPU has what those kernels need. numpy and OpenBLAS read them once, when numpy is imported.
A variable the user has set is left alone. Nothing is changed on other CPUs or systems, or for a numpy before 2.4
(other feature names: a name numpy does not dispatch is an ``ImportWarning``, an error under ``-W error``).
docs/decisions.md, "The same bytes on every x86-64 CPU with AVX2". This module imports no numpy (and of camfab only
:mod:`camfab.installed`).
"""
from __future__ import annotations

import os
import sys
from collections.abc import MutableMapping

from .installed import installed_version

__all__ = ["NUMPY_AVX512_GROUPS", "OPENBLAS_CORE", "cpu_flags", "numpy_version", "same_kernels_by_default",
           "fingerprint"]

#: numpy's dispatched x86 groups above AVX2 (numpy >= 2.4's names; X86_V3, AVX2 and FMA3, stays on)
NUMPY_AVX512_GROUPS = "X86_V4 AVX512_ICL AVX512_SPR"
#: OpenBLAS's core for every CPU with AVX2 and FMA (what it picks itself on Haswell and later Intel without
#: AVX-512, and on AMD Zen)
OPENBLAS_CORE = "Haswell"
_NUMPY_VARIABLES = ("NPY_DISABLE_CPU_FEATURES", "NPY_ENABLE_CPU_FEATURES")
_READ = object()


def cpu_flags(path: str = "/proc/cpuinfo") -> frozenset[str] | None:
    """The first processor's feature flags on Linux x86-64, read from ``path``; None elsewhere or unreadable."""
    if not sys.platform.startswith("linux") or os.uname().machine.lower() not in ("x86_64", "amd64"):
        return None
    try:
        with open(path, encoding="ascii", errors="replace") as fh:
            for line in fh:
                if line.startswith("flags"):
                    return frozenset(line.partition(":")[2].split())
    except OSError:
        return None
    return None


def numpy_version() -> tuple[int, int] | None:
    """numpy's ``(major, minor)`` from its ``version.py``, without importing numpy; None when not found."""
    parts = (installed_version("numpy", "version") or "").split(".")
    try:
        return int(parts[0]), int(parts[1])
    except (IndexError, ValueError):
        return None


def same_kernels_by_default(environ: MutableMapping[str, str] = os.environ, flags: object = _READ,
                            version: object = _READ) -> dict[str, str]:
    """Set the variables that give every x86-64 CPU with AVX2 the same numpy and OpenBLAS kernels, where unset.

    ``flags``: the CPU's (:func:`cpu_flags`, read when not given; None: not Linux x86-64); ``version``: numpy's
    (:func:`numpy_version`, read only on an AVX-512 CPU). Returns what was set."""
    found = cpu_flags() if flags is _READ else flags
    if not isinstance(found, frozenset):
        return {}
    out: dict[str, str] = {}
    if "avx512f" in found and not any(v in environ for v in _NUMPY_VARIABLES):
        have = numpy_version() if version is _READ else version
        if isinstance(have, tuple) and have >= (2, 4):
            out["NPY_DISABLE_CPU_FEATURES"] = NUMPY_AVX512_GROUPS
    if {"avx2", "fma"} <= found and "OPENBLAS_CORETYPE" not in environ:
        out["OPENBLAS_CORETYPE"] = OPENBLAS_CORE
    environ.update(out)
    return out


def fingerprint() -> dict[str, list[str]]:
    """The kernels this process computes with: numpy's dispatched targets in use, and the cores of the BLAS
    libraries loaded (threadpoolctl; each core once, however many copies are loaded). Two processes with the same
    fingerprint (and the same versions) write the same bytes. This imports numpy."""
    import importlib

    from threadpoolctl import threadpool_info

    try:
        umath = importlib.import_module("numpy._core._multiarray_umath")
    except ImportError:  # numpy < 2
        umath = importlib.import_module("numpy.core._multiarray_umath")
    features = umath.__cpu_features__
    return {"numpy": sorted(k for k in umath.__cpu_dispatch__ if features.get(k)),
            "blas": sorted({f"{i.get('internal_api')}:{i.get('architecture')}" for i in threadpool_info()
                            if i.get("user_api") == "blas"})}  # (a set: scipy loads its own copy, or not yet)
