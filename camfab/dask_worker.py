"""Preloaded by the workers of ``camfab package --executor dask-local``: they ignore SIGINT.

The local workers are processes in the terminal's process group, so Ctrl-C reached them too, and each printed
Dask's own ``KeyboardInterrupt`` traceback while camfab was already stopping them.  The command itself handles
Ctrl-C (exit 130, only complete cam folders) and closes the cluster, which ends the workers.  Listed in
``distributed.worker.preload`` by :data:`camfab.package_dask.LOCAL_CONFIG` (docs/decisions.md, "Dask executor").
"""
from __future__ import annotations

import signal
import threading
from typing import Any

__all__ = ["dask_setup"]


def dask_setup(worker: Any = None) -> None:
    """Dask's preload hook, run in the worker process as it starts: ignore SIGINT (main thread only, where
    Python allows a handler to be set)."""
    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGINT, signal.SIG_IGN)
