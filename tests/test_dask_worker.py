"""The local Dask workers' preload (camfab.dask_worker): the heartbeat failure that a worker's own close causes is
dropped, the same failure of a running worker and every other record are kept."""
from __future__ import annotations

import enum
import logging
import signal
from pathlib import Path

import pytest

from camfab.dask_worker import CLOSING, HEARTBEAT_FAILED, ClosingHeartbeatFilter, dask_setup


class State(enum.Enum):
    running = "running"
    closing = "closing"
    closing_gracefully = "closing_gracefully"
    closed = "closed"


class Worker:
    def __init__(self, status: State) -> None:
        self.status = status


def _record(msg: str) -> logging.LogRecord:
    return logging.LogRecord("distributed.worker", logging.ERROR, __file__, 1, msg, None, None)


def test_the_heartbeat_failure_of_a_closing_worker_is_dropped_and_kept_otherwise():
    worker = Worker(State.running)
    keep = ClosingHeartbeatFilter(worker)
    failed = _record(HEARTBEAT_FAILED + ".")
    assert keep.filter(failed)  # a running worker that cannot reach its scheduler: still logged
    assert keep.filter(_record("Unexpected exception during heartbeat. Closing worker."))
    for state in (State.closing, State.closing_gracefully, State.closed):
        worker.status = state
        assert not keep.filter(failed), state
        assert keep.filter(_record("Compute Failed")), state  # any other record of a closing worker is kept


def test_the_closing_states_are_dasks_own():
    core = pytest.importorskip("distributed.core", reason="Dask distributed is not installed")
    assert {s.name for s in core.Status} >= CLOSING
    worker = pytest.importorskip("distributed.worker")
    assert HEARTBEAT_FAILED in Path(worker.__file__).read_text(encoding="utf-8")  # the message Dask logs


def test_the_preload_ignores_sigint_and_installs_the_filter():
    logger = logging.getLogger("distributed.worker")
    before, handler = list(logger.filters), signal.getsignal(signal.SIGINT)
    try:
        worker = Worker(State.closing)
        dask_setup(worker)
        assert signal.getsignal(signal.SIGINT) is signal.SIG_IGN
        added = [f for f in logger.filters if f not in before]
        assert len(added) == 1 and not added[0].filter(_record(HEARTBEAT_FAILED + "."))
    finally:
        logger.filters[:] = before
        signal.signal(signal.SIGINT, handler)
