"""The command line's behaviour as a process: Ctrl-C, a reader that closes the pipe, log records on stderr
(docs/decisions.md, "Faults: staging, locks, durability"; "Errors and logging")."""
from __future__ import annotations

import contextlib
import logging
import os
import signal
import sys
import threading
from typing import Any

__all__ = ["log_to_stderr", "first_interrupt_only", "interrupt_came", "raise_if_interrupted", "stdout_to_devnull"]

#: the Ctrl-Cs :func:`first_interrupt_only` has seen while in force (in this process)
_CAME: list[int] = []


@contextlib.contextmanager
def log_to_stderr(verbose: bool):
    """The ``camfab`` logger's records on stderr while a command runs: WARNING and above, INFO too if ``verbose``."""
    logger = logging.getLogger("camfab")
    handler = logging.StreamHandler(sys.stderr)
    handler.setFormatter(logging.Formatter("camfab: %(levelname)s: %(message)s [%(name)s]"))
    handler.setLevel(logging.INFO if verbose else logging.WARNING)
    level = logger.level
    if verbose:
        logger.setLevel(logging.INFO)
    logger.addHandler(handler)
    try:
        yield
    finally:
        logger.removeHandler(handler)
        logger.setLevel(level)


@contextlib.contextmanager
def first_interrupt_only():
    """The first Ctrl-C raises KeyboardInterrupt (the command cleans up and exits 130); it also restores the
    default action, so a second Ctrl-C ends the process at once.  Only in the main thread, and only where
    Ctrl-C has Python's default handler (a shell that made the command ignore it is obeyed)."""
    if threading.current_thread() is not threading.main_thread() or \
            signal.getsignal(signal.SIGINT) is not signal.default_int_handler:
        yield
        return

    def first(signum: int, frame: Any) -> None:
        _CAME.append(signum)
        signal.signal(signal.SIGINT, signal.SIG_DFL)
        signal.default_int_handler(signum, frame)  # raises KeyboardInterrupt

    _CAME.clear()
    signal.signal(signal.SIGINT, first)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, signal.default_int_handler)
        _CAME.clear()  # (a later command, or the API's package in this process, starts without it)


def interrupt_came() -> bool:
    """Whether a Ctrl-C came while :func:`first_interrupt_only` was in force.  Its ``KeyboardInterrupt`` can reach
    the command as another error: an extension module whose initialisation it interrupts fails its import with
    ``ImportError('initialization failed')`` (pybind11's: OCP's, matplotlib's), and code that catches that error
    (an optional import, a contained failure) goes on without it.  Such an error is the interrupt."""
    return bool(_CAME)


def raise_if_interrupted() -> None:
    """``KeyboardInterrupt`` if :func:`interrupt_came` (raised as Python's own handler raises it; inside an
    ``except`` clause its context is the error handled)."""
    if _CAME:
        signal.default_int_handler(signal.SIGINT, None)


def stdout_to_devnull() -> None:
    """The reader of stdout has gone (``camfab check X | head -1``): send what is left to /dev/null, so that
    neither the command nor the interpreter's last flush complains (the Python docs' recipe, "Note on SIGPIPE")."""
    with contextlib.suppress(OSError, ValueError):
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        os.close(devnull)
