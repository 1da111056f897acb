"""``python -m camfab`` and the ``camfab`` console script.

BLAS runs on one thread in the command line unless the user set a thread count: OpenBLAS starts a thread per core
when numpy is imported and keeps them spinning, which cost ~0.1 s of CPU of every command's start on 2 cores while
camfab's linear algebra is small (the fit already pins BLAS to one thread; docs/decisions.md, "One BLAS thread in
the fitter").  This runs before numpy is imported (``import camfab`` imports no numpy).
"""
from __future__ import annotations

import os
import sys
from collections.abc import MutableMapping

#: variables any BLAS build reads for its thread count; a user's explicit setting of any of them wins
BLAS_THREAD_VARIABLES = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS", "GOTO_NUM_THREADS")


def one_blas_thread_by_default(environ: MutableMapping[str, str] = os.environ) -> None:
    """Set OpenBLAS and OpenMP to one thread, unless a thread-count variable is already set."""
    if not any(v in environ for v in BLAS_THREAD_VARIABLES):
        environ["OPENBLAS_NUM_THREADS"] = "1"
        environ["OMP_NUM_THREADS"] = "1"


one_blas_thread_by_default()

from .cli import main  # noqa: E402  (after the thread count: it imports numpy)

if __name__ == "__main__":
    sys.exit(main())
