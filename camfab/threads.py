"""Threads of the native libraries: BLAS/LAPACK limited to one thread where results must not depend on the
machine (docs/decisions.md, "One BLAS thread in the fitter")."""
from __future__ import annotations

import contextlib
from collections.abc import Iterator
from functools import lru_cache

__all__ = ["one_blas_thread", "blas_single_threaded"]


@lru_cache(maxsize=1)
def _blas_controller():
    """threadpoolctl's view of the BLAS libraries loaded (numpy's is, once numpy is imported); made once."""
    import numpy  # noqa: F401  (its BLAS must be loaded before the controller looks)
    from threadpoolctl import ThreadpoolController

    return ThreadpoolController()


@contextlib.contextmanager
def one_blas_thread() -> Iterator[None]:
    """Run the block with BLAS/LAPACK on one thread (docs/decisions.md, "One BLAS thread in the fitter").

    The arc fit solves many small least-squares problems (up to ~130×90): a threaded BLAS sums them in an order
    that depends on the thread count, so the fitted arcs (and the STL) differed between machines, and on a busy
    machine its threads made the fit 4–100× slower.  Costs ~30 µs per entry (the controller is made once)."""
    with _blas_controller().limit(limits=1, user_api="blas"):
        yield


def blas_single_threaded() -> None:
    """Limit BLAS to one thread for the rest of this process (a worker of a process pool that fills the cores)."""
    _blas_controller().limit(limits=1, user_api="blas")
