"""``python -m camfab`` and the ``camfab`` console script.

BLAS runs on one thread in the command line unless the user set a thread count: OpenBLAS starts a thread per core
when numpy is imported and keeps them spinning, which cost ~0.1 s of CPU of every command's start on 2 cores while
camfab's linear algebra is small (the fit already pins BLAS to one thread; docs/decisions.md, "One BLAS thread in
the fitter").  This runs before numpy is imported (``import camfab`` imports no numpy).

numpy's and OpenBLAS's kernels are pinned the same way, to those every x86-64 CPU with AVX2 runs, so that the files'
bytes do not depend on the CPU (:mod:`camfab.kernels`; docs/decisions.md, "The same bytes on every x86-64 CPU with
AVX2"). ``package``'s workers inherit both settings.
"""
from __future__ import annotations

import os
import signal
import sys
import threading
from collections.abc import MutableMapping
from typing import Any

from .exitcodes import EXIT_INTERRUPTED
from .kernels import same_kernels_by_default

#: variables any BLAS build reads for its thread count; a user's explicit setting of any of them wins
BLAS_THREAD_VARIABLES = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS", "GOTO_NUM_THREADS")


def one_blas_thread_by_default(environ: MutableMapping[str, str] = os.environ) -> None:
    """Set OpenBLAS and OpenMP to one thread, unless a thread-count variable is already set."""
    if not any(v in environ for v in BLAS_THREAD_VARIABLES):
        environ["OPENBLAS_NUM_THREADS"] = "1"
        environ["OMP_NUM_THREADS"] = "1"


one_blas_thread_by_default()
same_kernels_by_default()


def main(argv: list[str] | None = None) -> int:
    """The console script: :func:`camfab.cli.main` with Ctrl-C covered from the import of the command line to
    the process's exit (docs/decisions.md, "Ctrl-C from start to exit").

    - A Ctrl-C while ``camfab.cli`` and numpy are imported (most of a short command's start) is ``camfab:
      interrupted``, exit 130, as one during the command; numpy's import may turn it into an ``ImportError``
      ("PyCapsule_Import could not import module datetime"), which counts as the interrupt when SIGINT came.
    - Once the command has returned, SIGINT is ignored: the process ends with the command's code.
    - An interrupted command returns 130 after :func:`forget_caught_interrupt`: CPython 3.11 had sometimes set
      its "unhandled KeyboardInterrupt" flag although camfab caught the interrupt, and then killed the process by
      SIGINT on its way out (-2 to a parent). The interpreter's own finalisation still runs (the pool's
      semaphores, Dask's workers)."""
    came: list[int] = []
    own = threading.current_thread() is threading.main_thread() and \
        signal.getsignal(signal.SIGINT) is signal.default_int_handler

    def during_import(signum: int, frame: Any) -> None:
        came.append(signum)
        signal.default_int_handler(signum, frame)  # raises KeyboardInterrupt

    try:
        if own:
            signal.signal(signal.SIGINT, during_import)
        try:
            from .cli import main as cli_main  # after the thread count: it imports numpy
        finally:
            if own:
                signal.signal(signal.SIGINT, signal.default_int_handler)
        code = cli_main(argv)
    except KeyboardInterrupt:  # before the command's own handler, or after it
        code = _interrupted()
    except ImportError:
        if not came:
            raise
        code = _interrupted()
    if own:
        signal.signal(signal.SIGINT, signal.SIG_IGN)
    if code == EXIT_INTERRUPTED:
        forget_caught_interrupt()
        if own:  # the process's own entry: its exit is near
            quiet_leftovers()
    return code


def quiet_leftovers() -> None:
    """After an interrupt: finalise now what the interrupted command left suspended, and report none of their
    cleanup errors. An xlsx writer stopped inside openpyxl's worksheet stream (a generator writing into a zip
    member the command had closed) printed "Exception ignored in ... ValueError: I/O operation on closed file"
    when the garbage collector closed it at exit; the command has reported the interrupt and removed what it was
    writing, so such errors are noise (docs/decisions.md, "Ctrl-C from start to exit")."""
    import gc

    sys.unraisablehook = _ignore_unraisable
    gc.collect()


def _ignore_unraisable(unraisable: Any) -> None:
    return None


#: CPython's flag that makes ``Py_RunMain`` kill the process by SIGINT at exit (``Python/pythonrun.c``, 3.8-3.11)
UNHANDLED_INTERRUPT_FLAG = "_Py_UnhandledKeyboardInterrupt"


def forget_caught_interrupt() -> bool:
    """Clear CPython's "unhandled KeyboardInterrupt" flag for an interrupt camfab has caught; True if cleared.

    CPython sets the flag whenever a ``KeyboardInterrupt`` ends code it runs through ``run_eval_code_obj`` (the
    ``PyRun_*`` functions: ``exec`` of a string, as ``dataclasses`` and ``namedtuple`` do while a module is
    imported), caught or not, and then ``python -m`` ends by SIGINT instead of its exit code. Read and cleared
    through ``ctypes``; where the symbol is not exported (CPython 3.12 keeps the flag inside ``_PyRuntime``;
    other interpreters) nothing is cleared, and a parent may see the process end by SIGINT after the same cleanup
    (a shell shows 130 either way) -- docs/decisions.md, "Ctrl-C from start to exit"."""
    try:
        import ctypes

        flag = ctypes.c_int.in_dll(ctypes.pythonapi, UNHANDLED_INTERRUPT_FLAG)
    except (ImportError, AttributeError, ValueError, OSError):
        return False
    flag.value = 0
    return True


def _interrupted() -> int:
    print("camfab: interrupted", file=sys.stderr)
    return EXIT_INTERRUPTED


if __name__ == "__main__":
    sys.exit(main())
