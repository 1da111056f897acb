"""Preloaded by the workers of ``camfab package --executor dask-local``: they ignore SIGINT, and a heartbeat that
their own close cut short is not logged.

The local workers are processes in the terminal's process group, so Ctrl-C reached them too, and each printed
Dask's own ``KeyboardInterrupt`` traceback while camfab was already stopping them.  The command itself handles
Ctrl-C (exit 130, only complete cam folders) and closes the cluster, which ends the workers.  Listed in
``distributed.worker.preload`` by :data:`camfab.package_dask.LOCAL_CONFIG` (docs/decisions.md, "Dask executor").
"""
from __future__ import annotations

import logging
import signal
import threading
import weakref
from typing import Any

__all__ = ["dask_setup", "ClosingHeartbeatFilter", "HEARTBEAT_FAILED", "CLOSING"]

#: the start of the message ``distributed.worker`` logs (at ERROR, with a traceback) when a heartbeat's call to the
#: scheduler raises an ``OSError``
HEARTBEAT_FAILED = "Failed to communicate with scheduler during heartbeat"
#: the worker states in which that failure is the worker's own close: ``Worker.close`` sets the state, then
#: closes the connections a heartbeat already on its way uses ("Stream is closed")
CLOSING = frozenset({"closing", "closing_gracefully", "closed"})


class ClosingHeartbeatFilter(logging.Filter):
    """Drops the heartbeat failure of a worker that is closing (a shutdown race inside Dask, seen after camfab's
    ``interrupted`` when ``package`` closed its local cluster on Ctrl-C); the same failure of a running worker
    is still logged.  Holds the worker weakly."""

    def __init__(self, worker: Any) -> None:
        super().__init__()
        self._worker = weakref.ref(worker)

    def filter(self, record: logging.LogRecord) -> bool:
        if not str(record.msg).startswith(HEARTBEAT_FAILED):
            return True
        worker = self._worker()
        state = getattr(getattr(worker, "status", None), "name", None)
        return worker is not None and state not in CLOSING


def dask_setup(worker: Any = None) -> None:
    """Dask's preload hook, run in the worker process as it starts: ignore SIGINT (main thread only, where
    Python allows a handler to be set) and filter the closing worker's heartbeat failure."""
    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGINT, signal.SIG_IGN)
    if worker is not None:
        logging.getLogger("distributed.worker").addFilter(ClosingHeartbeatFilter(worker))
