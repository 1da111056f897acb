"""``camfab package`` on Dask distributed: ``--executor dask --scheduler ADDRESS`` or ``--executor dask-local``.

Imported only when a package asks for Dask (the built-in process pool stays the default).  Each cam is one task:
the worker receives a :class:`camfab.package.Job` (the design's bytes, its knot files' bytes, the options) and
returns the manifest entry with the files' bytes (:func:`camfab.package.build_cam`); the parent writes them, so
the workers need no shared file system, only camfab (the same version) installed.

Workers that die: a cam whose worker dies is run again on another worker; when a second worker dies on it (the
scheduler's ``distributed.scheduler.allowed-failures``, set to 1 for ``dask-local``) Dask gives up on it with
``KilledWorker`` and the cam is recorded as failed (error kind ``worker``, exit status 3), the others built.

Worker settings (docs/decisions.md, "Dask executor"): for ``dask-local`` camfab applies :data:`LOCAL_CONFIG`
(Dask's statistical profiler off, glibc's own memory trimming, the workers' periodic monitors slowed down, one
task per worker process, one BLAS thread),
overridden by the caller's ``config`` (``--dask-config KEY=VALUE``).  A remote cluster keeps its own settings
(give its workers the same ones); ``config`` then only affects this client.
"""
from __future__ import annotations

import contextlib
import logging
import time
import uuid
from collections.abc import Callable, Generator, Iterator, Mapping
from typing import Any

from .errors import InputError, MissingDependencyError, UnreachableError

__all__ = ["dask_executor", "close_workers_first", "LOCAL_CONFIG", "NO_DASHBOARD", "CONNECT_TIMEOUT_S",
           "parse_config", "executor_options", "other_kernels"]

log = logging.getLogger(__name__)

#: seconds to reach the scheduler, and for it to have a worker, before giving up (exit 3, nothing written)
CONNECT_TIMEOUT_S = 10.0
#: seconds a local cluster's workers get to close before its scheduler closes (then the scheduler closes anyway)
CLOSE_WORKERS_S = 10.0

#: camfab's settings for a local cluster (docs/decisions.md, "Dask executor", for the measurement)
LOCAL_CONFIG: dict[str, Any] = {
    # the statistical profiler samples every worker thread's stack every 10 ms
    "distributed.worker.profile.enabled": False,
    # Dask sets MALLOC_TRIM_THRESHOLD_=65536: memory handed back to the OS and faulted in again on every call
    "distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_": None,
    # one BLAS thread per worker process (also Dask's default; the workers fill the cores)
    "distributed.nanny.pre-spawn-environ.OMP_NUM_THREADS": 1,
    "distributed.nanny.pre-spawn-environ.OPENBLAS_NUM_THREADS": 1,
    "distributed.nanny.pre-spawn-environ.MKL_NUM_THREADS": 1,
    # the workers' own periodic work beside the task: event-loop health ticks (20 ms), memory monitor (100 ms),
    # system monitor (500 ms) -- 15 % more CPU in the cams on 4 cams (docs/decisions.md, "Dask executor")
    "distributed.admin.tick.interval": "1s",
    "distributed.worker.memory.monitor-interval": "1s",
    "distributed.admin.system-monitor.interval": "5s",
    # the local workers share the terminal's process group: they ignore Ctrl-C, which camfab handles itself
    "distributed.worker.preload": ["camfab.dask_worker"],
    # a cam whose worker dies is retried once; a worker holds only the cam it runs (a death loses only it)
    "distributed.scheduler.allowed-failures": 1,
    "distributed.scheduler.worker-saturation": 1.0,
}


def executor_options(executor: str, scheduler: str | None, workers: int | None, config: list[str] | None,
                     jobs: int) -> dict[str, Any]:
    """``package``'s executor keywords from its command-line options, each checked to come with the executor it
    belongs to (:class:`~camfab.errors.InputError`, exit 2, naming the option and the fix); Dask is not imported
    for the built-in pool."""
    if scheduler is not None and executor != "dask":
        raise InputError(f"--scheduler {scheduler}: only with --executor dask (add it, or drop --scheduler)")
    if executor == "dask" and not scheduler:
        raise InputError("--executor dask needs --scheduler ADDRESS (the address `dask scheduler` prints), or use "
                         "--executor dask-local for a cluster on this machine")
    if workers is not None and (executor != "dask-local" or workers < 1):
        raise InputError(f"--dask-workers {workers}: a number of at least 1, only with --executor dask-local")
    if config and executor == "builtin":
        raise InputError("--dask-config: only with --executor dask or dask-local")
    if executor != "builtin" and jobs != 1:
        raise InputError(f"--jobs {jobs}: the built-in pool's processes; with Dask give --dask-workers N "
                         "(dask-local) or start the cluster's workers")
    if executor == "builtin":
        return {}
    return {"executor": executor, "scheduler": scheduler, "dask_workers": workers, "dask_config": parse_config(config)}


#: the scheduler of a local cluster: no dashboard, its HTTP server on a free port (not Dask's 8787)
NO_DASHBOARD = {"dashboard": False, "dashboard_address": ":0"}


def parse_config(items: list[str] | None) -> dict[str, Any]:
    """``KEY=VALUE`` strings (``--dask-config``) as Dask settings; values read as YAML scalars (``false``,
    ``10ms``, ``0.9``, ``null``), as Dask reads its own configuration files."""
    out: dict[str, Any] = {}
    if not items:
        return out
    _import()
    import yaml  # Dask's own dependency

    for item in items:
        key, sep, value = item.partition("=")
        if not sep or not key.strip():
            raise InputError(f"--dask-config {item!r}: give KEY=VALUE, e.g. distributed.worker.profile.enabled=false")
        try:
            out[key.strip()] = yaml.safe_load(value)
        except yaml.YAMLError as exc:
            raise InputError(f"--dask-config {item!r}: the value is not a YAML scalar ({exc})") from None
    return out


def _import() -> tuple[Any, Any]:
    try:
        import dask
        import distributed
    except ImportError as exc:
        raise MissingDependencyError(f"--executor dask needs Dask distributed ({exc}): pip install camfab[dask]") \
            from None
    return dask, distributed


@contextlib.contextmanager
def dask_executor(scheduler: str | None, workers: int | None, config: Mapping[str, Any]
                  ) -> Iterator[Callable[..., Generator[dict, None, None]]]:
    """A connected Dask client, as a function ``map(fn, jobs, lost)`` yielding ``fn(job)`` as the jobs finish
    (``lost(job, reason)`` for a job Dask gave up on).

    ``scheduler``: the address of a running cluster's scheduler; None: a local cluster of ``workers``
    processes (default: one per CPU) with :data:`LOCAL_CONFIG`.  Raises ``OSError`` (exit 3) when the
    scheduler cannot be reached or has no worker within :data:`CONNECT_TIMEOUT_S`, before anything is written.
    """
    dask, distributed = _import()
    settings = dict(config) if scheduler is not None else {**LOCAL_CONFIG, **config}
    with dask.config.set(settings), contextlib.ExitStack() as stack:
        if scheduler is None:
            cluster = stack.enter_context(distributed.LocalCluster(
                n_workers=workers, threads_per_worker=1, processes=True, silence_logs=logging.ERROR,
                dashboard_address=None, scheduler_kwargs=NO_DASHBOARD))
            client = stack.enter_context(distributed.Client(cluster, set_as_default=False))
            stack.callback(close_workers_first, cluster)  # runs first: the stack unwinds in reverse
        else:
            client = stack.enter_context(_connect(distributed, scheduler))
        yield lambda fn, items, lost: _map(distributed, client, fn, items, lost)


def close_workers_first(cluster: Any, timeout: float = CLOSE_WORKERS_S) -> None:
    """Close a local cluster's workers and wait for them (up to ``timeout`` s) before its scheduler is closed.

    Closing the cluster closes the scheduler first; a worker whose heartbeat was then on its way logged, at
    ERROR, "Failed to communicate with scheduler during heartbeat" with an ``OSError`` traceback, after camfab's
    own ``interrupted`` (a shutdown race inside Dask, seen on Ctrl-C).  Workers that have closed send no
    heartbeat."""
    with contextlib.suppress(Exception):  # the scheduler's own close follows whatever happens here
        cluster.scale(0)
        deadline = time.monotonic() + timeout
        while cluster.workers and time.monotonic() < deadline:
            time.sleep(0.02)


def _connect(distributed: Any, address: str) -> Any:
    """A client of the scheduler at ``address`` that has at least one worker, or an ``OSError`` naming it."""
    try:
        client = distributed.Client(address, timeout=CONNECT_TIMEOUT_S, set_as_default=False)
    except ValueError as exc:  # not an address
        raise InputError(f"--scheduler {address!r}: not a scheduler address ({exc}); give HOST:PORT or "
                         "tcp://HOST:PORT, as `dask scheduler` prints it") from None
    except (OSError, TimeoutError) as exc:
        raise UnreachableError(f"cannot reach the Dask scheduler at {address} within {CONNECT_TIMEOUT_S:g} s "
                               f"({exc}); check the address and that `dask scheduler` runs there") from None
    try:
        client.wait_for_workers(1, timeout=CONNECT_TIMEOUT_S)
    except (OSError, TimeoutError) as exc:
        client.close()
        raise UnreachableError(f"the Dask scheduler at {address} has no worker after {CONNECT_TIMEOUT_S:g} s "
                               f"({exc}); start one with `dask worker {address}`") from None
    return client


def _map(distributed: Any, client: Any, fn: Callable, items: list, lost: Callable[[Any, str], dict]
         ) -> Generator[dict, None, None]:
    """Submit every item, yield the results as they come; a task Dask gave up on yields ``lost(item, why)``.
    Leaving early (an interrupt) cancels what is left."""
    if not items:
        return
    other_kernels(client)
    run = uuid.uuid4().hex[:12]
    futures = {client.submit(fn, item, key=f"camfab-build-{run}-{i}", pure=False, retries=1): item
               for i, item in enumerate(items)}
    try:
        for future in distributed.as_completed(futures, loop=client.loop):
            try:
                yield future.result()
            except Exception as exc:  # KilledWorker, or the worker could not run camfab at all
                yield lost(futures[future], _why(exc))
    finally:
        client.cancel(list(futures), force=True)


def other_kernels(client: Any) -> list[str]:
    """The workers whose numpy or OpenBLAS kernels differ from this process's, named in a warning: their files may
    differ from this machine's in the last digits (docs/decisions.md, "The same bytes on every x86-64 CPU with
    AVX2"). A local cluster's workers inherit the command line's kernels; a remote cluster's have their own."""
    from .kernels import NUMPY_AVX512_GROUPS, OPENBLAS_CORE, fingerprint

    mine = fingerprint()
    try:  # a worker that cannot run it (no camfab there) is left out: its tasks say why
        theirs = client.run(fingerprint, on_error="ignore")
    except Exception:  # (a Dask without ``on_error``, or no answer at all)
        return []
    other = sorted(address for address, kernels in theirs.items() if isinstance(kernels, dict) and kernels != mine)
    if other:
        shown = ", ".join(other[:3]) + (f" and {len(other) - 3} more" if len(other) > 3 else "")
        log.warning("Dask worker(s) %s compute with other numpy or BLAS kernels than this machine (%s, here %s): "
                    "their files may differ from a build here in the last digits; start the workers with "
                    "NPY_DISABLE_CPU_FEATURES=\"%s\" (AVX-512 CPUs, numpy >= 2.4) and OPENBLAS_CORETYPE=%s "
                    "(AVX2 CPUs)", shown, theirs[other[0]], mine, NUMPY_AVX512_GROUPS, OPENBLAS_CORE)
    return other


def _why(exc: Exception) -> str:
    """The reason a cam's task failed on the cluster, and what to do."""
    if type(exc).__name__ == "KilledWorker":
        return ("the Dask worker building it died, and again on a retry (KilledWorker); a worker dies when it runs "
                "out of memory or is killed: see the workers' logs")
    return (f"the Dask worker could not build it ({type(exc).__name__}: {exc}); is camfab {_version()} installed "
            "on every worker?")


def _version() -> str:
    from .version import __version__

    return __version__
