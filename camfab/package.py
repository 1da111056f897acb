"""Drawing packages: many designs in parallel, a manifest, an index, incremental rebuilds.

``package(paths, out)`` finds the designs (``*.toml`` and ``*.xlsx`` files, folders searched recursively), runs
each design through :mod:`camfab.pipeline` in its own folder ``out/<name>/`` on a process pool, and writes
``out/manifest.json`` (each file's sha256 and size, measured deviation, tolerance, verdict, key figures and the
reasons for the verdict (:func:`camfab.report.overview.cam_summary`), stage timings), ``out/index.html``
(:func:`camfab.report.overview.index_html`) and, when any cam has a PDF sheet, ``out/drawings.pdf``: a contents page,
then every cam's sheet (:func:`camfab.cad.pdf.write_drawing_set`; docs/decisions.md, "The package index and the
drawing set").

Folders: each design's folder is :func:`~camfab.io.safe_stem` of its name (of its file's stem when it cannot
be read), made unique in the order the designs are found (:func:`folders`): a stem already taken — by an
earlier design or by the package's own ``manifest.json`` / ``index.html``, compared without case — gets
``_2``, ``_3``, … .  The manifest records each cam's folder.

A failing design's error is recorded bounded (:func:`camfab.textsafe.bounded`: at most 10 lines of 300
characters, control characters removed), since it may quote a line of any file.

Incremental: each cam's *input key* hashes its design file, the files it references (knot tables), the camfab
version, the shipped templates and the job options.  A cam whose key is unchanged and whose files are all present
with their recorded hashes is not rebuilt.  A design that fails is recorded with its error (in the manifest, the
index and the exit status) without stopping the others; an error after a Ctrl-C is the interrupt instead
(:func:`camfab.terminal.raise_if_interrupted`).

Faults (docs/decisions.md, "Faults: staging, locks, durability"): the output folder is locked while a package is
written into it; each cam is written into a staging folder ``out/.<name>.camfab-staging-<pid>`` and swapped in
whole, so a cam folder holds either its old or its new complete set; files an earlier package wrote (recorded in its
manifest) that the new manifest does not list are removed, any other file is kept; worker processes ignore Ctrl-C
(the parent stops them) and die with their parent.
"""
from __future__ import annotations

import contextlib
import hashlib
import itertools
import json
import logging
import multiprocessing
import os
import shutil
import signal
import sys
import tempfile
import threading
import time
from collections.abc import Callable, Generator, Iterable, Sequence
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
from typing import Any

from .assets import templates_hash
from .design.spec import DesignSpec
from .errors import ApiError, CamfabError, ExportError, InputError, InternalError, MissingDependencyError
from .formats import load_design
from .formats.knot_files import relocated
from .io import atomic_write, hold_sigint, inside, leftover_name, output_folder, safe_stem, swap_dir, write_all
from .pipeline import Cam, Output, Request, RunResult, build_files, shop_file_names
from .records import dataclass, replace
from .report.overview import cam_summary, index_html
from .results import Verdict
from .terminal import raise_if_interrupted
from .textsafe import bounded, plain
from .threads import blas_single_threaded
from .version import __version__

__all__ = ["discover", "folders", "input_key", "package", "exit_status", "build_cam", "Job", "EXECUTORS",
           "MANIFEST", "INDEX", "DRAWING_SET"]

MANIFEST = "manifest.json"
INDEX = "index.html"
#: the package's drawing set: a contents page, then every cam's sheet (:func:`camfab.cad.pdf.write_drawing_set`)
DRAWING_SET = "drawings.pdf"
#: where the cams are built: camfab's own process pool, or Dask (:mod:`camfab.package_dask`)
EXECUTORS = ("builtin", "dask", "dask-local")

log = logging.getLogger(__name__)


def discover(paths: Iterable[str | Path]) -> list[Path]:
    """Design files named directly or found (recursively) in folders, sorted, de-duplicated."""
    found: list[Path] = []
    for p in map(Path, paths):
        if p.is_dir():
            found += sorted(q for q in p.rglob("*") if q.suffix in (".toml", ".xlsx") and q.is_file())
        else:
            found.append(p)
    seen, out = set(), []
    for p in found:
        r = p.resolve()
        if r not in seen:
            seen.add(r)
            out.append(p)
    return out


def folders(stems: Sequence[str]) -> list[str]:
    """Unique folder names for designs whose :func:`~camfab.io.safe_stem` are ``stems``, in order: a stem
    taken (case-insensitively) by an earlier one or by :data:`MANIFEST` / :data:`INDEX` gets ``_2``, ``_3``…"""
    taken = {MANIFEST.casefold(), INDEX.casefold(), DRAWING_SET.casefold()}
    out = []
    for stem in stems:
        name, k = stem, 1
        while name.casefold() in taken:
            k += 1
            name = f"{stem}_{k}"
        taken.add(name.casefold())
        out.append(name)
    return out


def _sha(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def input_key(sources: Sequence[str | Path], options: dict, templates: str) -> str:
    """Hash of everything a cam's outputs depend on (see the module docstring).

    Parameters
    ----------
    sources : sequence of str or Path
        The design file, then the files it references: the :attr:`~camfab.design.spec.DesignSpec.sources`
        its spec recorded when it was read (the design file alone when it could not be read).
    options : dict
        The job options.
    templates : str
        Hash of the shipped templates."""
    h = hashlib.sha256()
    design, *refs = map(Path, sources)
    h.update(design.read_bytes())
    for ref in refs:
        h.update(ref.name.encode())
        h.update(ref.read_bytes() if ref.exists() else b"<missing>")
    h.update(__version__.encode())
    h.update(templates.encode())
    h.update(json.dumps(options, sort_keys=True, default=str).encode())
    return h.hexdigest()


def _read(path: Path, allow_outside_files: bool = False) -> tuple[DesignSpec | None, tuple[str | Path, ...],
                                                                   Exception | None]:
    """The design's spec and the files it was built from; (None, the file, why) when it cannot be read (its
    entry then records why, without a worker)."""
    try:
        spec = load_design(path, allow_outside_files=allow_outside_files)
    except Exception as exc:  # any failure is reported in this design's entry, with the others kept
        raise_if_interrupted()  # (the interrupt turned into this error: not this design's failure)
        log.info("%s cannot be read (%s: %s); its key hashes the file alone", path, type(exc).__name__, exc)
        return None, (path,), exc
    return spec, spec.sources, None


@dataclass(frozen=True)
class Job:
    """One cam to build, as a worker receives it: the design's bytes and those of the files it references
    (``inputs``: (path as the parent knows it, bytes), the design first), the job options, its input key and
    folder; ``spec`` only when it is built in the parent's own process (then not read again)."""

    source: str
    name: str
    stem: str
    key: str
    options: dict
    inputs: tuple[tuple[str, bytes], ...]
    spec: DesignSpec | None = None


def build_cam(job: Job) -> dict:
    """Worker: build one cam from bytes and return its manifest entry with the files' bytes (``entry["output"]``:
    name → bytes, deviations, shop file names); nothing is written outside a temporary folder, so any machine
    can run it (the parent writes: :func:`_commit`).  Never raises but on an interrupt: errors go into the entry."""
    t0, c0 = time.perf_counter(), time.process_time()
    entry: dict = {"source": job.source, "key": job.key, "rebuilt": True}
    back: Callable[[str], str] = str
    try:
        with contextlib.ExitStack() as stack:
            spec = job.spec
            if spec is None:  # the design read again from its bytes, its knot files beside it as on the disk
                design, back, base = _unpack(job.inputs, Path(stack.enter_context(tempfile.TemporaryDirectory(
                    prefix="camfab-design-"))))
                stack.enter_context(relocated(*base))
                spec = load_design(design, allow_outside_files=bool(job.options.get("allow_outside_files")))
            entry["name"] = spec.name
            outputs = job.options.get("outputs")
            req = Request.from_design(spec, outputs, force=job.options.get("force") or None,
                                      post="linuxcnc" if outputs is not None else None)
            if Output.PDF in req.outputs:  # the drawing set's page is rendered from the sheet: keep it beside the PDF
                req = replace(req, outputs=req.outputs | {Output.DRAWING})
            cam = Cam(spec)
            res = RunResult(cam.name, "", tol=cam.tolerance(req.tol))
            files = build_files(cam, req, res, lambda m: None)
        entry.update(status="unacceptable" if res.verdict == Verdict.UNACCEPTABLE else "ok", verdict=str(res.verdict),
                     tolerance_mm=res.tol, withheld=res.withheld, skipped=res.skipped, timings=res.timings,
                     not_applicable=res.not_applicable, folder=job.stem, files=[])
        entry.update(cam_summary(spec, cam.geometry, cam.check(), res.deviations.values()))
        entry["output"] = {"files": files, "deviations": res.deviations, "shop": sorted(shop_file_names(cam))}
    except Exception as exc:  # contained: one design's failure must not lose the others
        raise_if_interrupted()  # (the interrupt turned into this error: not this design's failure)
        _failed(entry, exc, back)
    entry.setdefault("name", job.name)
    entry["seconds"] = time.perf_counter() - t0
    entry["cpu_seconds"] = time.process_time() - c0  # of the whole worker process meanwhile
    return entry


def _unpack(inputs: Sequence[tuple[str, bytes]], root: Path) -> tuple[Path, Callable[[str], str], tuple[Path, Path]]:
    """Write the design and its knot files under ``root``, in the same places relative to each other; returns
    the design's path there, a function putting its real folder back into a message, and (the files' common
    folder as the parent knows it, ``root``) for :func:`~camfab.formats.knot_files.relocated`."""
    where = [Path(os.path.abspath(p)) for p, _ in inputs]
    base = Path(os.path.commonpath([w.parent for w in where]))
    for w, (_, data) in zip(where, inputs, strict=True):
        local = root / w.relative_to(base)
        local.parent.mkdir(parents=True, exist_ok=True)
        local.write_bytes(data)
    design = root / where[0].relative_to(base)
    here, there = str(design.parent), str(Path(inputs[0][0]).parent)

    def back(text: str) -> str:
        return text.replace(here + os.sep, "" if there == "." else there + os.sep).replace(here, there)

    return design, back, (base, root)


def _commit(entry: dict, out: Path, recorded: frozenset[str]) -> dict:
    """Parent: write a built cam's files into a staging folder, carry over the files camfab did not write, swap
    it in as ``out/<folder>/`` and list the files in the entry; an error goes into the entry."""
    made = entry.pop("output", None)
    if made is None:  # the build failed: nothing to write
        return entry
    t0 = time.perf_counter()
    folder = staging = None
    try:
        folder = inside(out, entry["folder"])
        staging = inside(out, leftover_name(folder.name, "staging"))
        shutil.rmtree(staging, ignore_errors=True)
        files = made["files"]
        write_all({inside(staging, n): files[n] for n in sorted(files)})
        _keep_other_files(folder, staging, out, recorded, set(made["shop"]))
        swap_dir(staging, folder)
        entry["files"] = [_file_entry(folder / n, out, files[n], made["deviations"].get(n)) for n in sorted(files)]
    except Exception as exc:  # contained, like a failure of the build
        raise_if_interrupted()  # (the interrupt turned into this error: not this design's failure)
        where = str(staging) if staging is not None else None
        _failed(entry, exc, (lambda t: t.replace(where, str(folder))) if where else str)
    finally:
        if staging is not None:
            shutil.rmtree(staging, ignore_errors=True)
    entry["seconds"] = entry.get("seconds", 0.0) + time.perf_counter() - t0
    return entry


def _failed(entry: dict, exc: Exception, back: Callable[[str], str] = str) -> None:
    """Record why a design could not be built: an input, I/O or dependency error with its message (``back``
    names the real files), any other exception as an internal failure."""
    if isinstance(exc, (ApiError, InternalError)) or not isinstance(exc, (CamfabError, OSError, ValueError)):
        _internal_error(entry, exc)  # bugs of camfab: recorded as internal failures
        return
    kind = "io" if isinstance(exc, OSError) else "dependency" if isinstance(exc, MissingDependencyError) else "input"
    entry.update(status="error", verdict=None, error=bounded(back(str(exc))), files=[], error_type=type(exc).__name__,
                 error_kind=kind)


def _lost(job: Job, reason: str) -> dict:
    """The entry of a cam whose worker was lost (:mod:`camfab.package_dask`): an error of kind ``worker``."""
    return {"source": job.source, "key": job.key, "rebuilt": True, "name": job.name, "status": "error",
            "verdict": None, "files": [], "error_type": "WorkerLost", "error_kind": "worker",
            "error": bounded(reason), "seconds": 0.0}


def _keep_other_files(folder: Path, staging: Path, out: Path, recorded: frozenset[str], shop: set[str]) -> None:
    """Carry into ``staging`` the files of the old ``folder`` that camfab did not write: not recorded in the
    previous manifest, not a shop file of this cam (:func:`~camfab.pipeline.shop_file_names`), not a
    leftover, not replaced by a new file.  Hard links (copies where the file system has none), so the old
    folder stays whole until the swap."""
    if not folder.is_dir():
        return
    for root, _dirs, names in os.walk(folder):
        for name in names:
            p = Path(root, name)
            rel = p.relative_to(folder)
            dest = staging / rel
            if (p.relative_to(out).as_posix() in recorded or rel.as_posix() in shop or ".camfab-" in name
                    or dest.exists() or dest.is_symlink()):
                continue
            dest.parent.mkdir(parents=True, exist_ok=True)
            try:
                os.link(p, dest, follow_symlinks=False)
            except OSError:
                shutil.copy2(p, dest, follow_symlinks=False)


def _internal_error(entry: dict, exc: Exception) -> None:
    """Record (and log) an internal failure of one design's build, with its traceback."""
    import traceback

    log.error("%s: internal error (%s: %s)", entry["source"], type(exc).__name__, exc, exc_info=exc)
    entry.update(status="error", verdict=None, files=[], error_type=type(exc).__name__, error_kind="internal",
                 error=bounded(f"internal error ({type(exc).__name__}: {exc}); please report it with this design"),
                 traceback=traceback.format_exc())


def _file_entry(p: Path, out: Path, data: bytes, dev) -> dict:
    return {"path": str(p.relative_to(out)), "sha256": _sha(data), "bytes": len(data), "deviation_mm": dev}


def _still_valid(entry: dict, out: Path) -> bool:
    if entry.get("status") == "error" or not entry.get("files"):
        return False
    for f in entry["files"]:
        p = out / f["path"]
        if not p.is_file() or _sha(p.read_bytes()) != f["sha256"]:
            return False
    return True


def package(paths: Iterable[str | Path], out: str | Path, *, jobs: int = 1, outputs: Sequence[str] | None = None,
            force: bool = False, progress: Callable[[str], None] | None = None,
            allow_outside_files: bool = False, executor: str = "builtin", scheduler: str | None = None,
            dask_workers: int | None = None, dask_config: dict | None = None) -> dict:
    """Build every design; returns the manifest (also written to ``out/manifest.json``).

    ``outputs`` replaces every design's ``[outputs]`` (None: each design's own); ``force`` writes the shop
    outputs of unacceptable designs too; ``allow_outside_files`` lets designs read knot files outside their
    folders.  ``out`` is created, proved writable and locked before any design is read
    (:func:`camfab.io.output_folder`: an ``OSError`` naming it otherwise).

    ``executor`` (:data:`EXECUTORS`): ``builtin``, camfab's process pool of ``jobs`` processes; ``dask``, the
    Dask cluster whose scheduler is at ``scheduler``; ``dask-local``, a local Dask cluster of ``dask_workers``
    processes (:mod:`camfab.package_dask`; ``dask_config``: Dask settings over camfab's).  Dask is connected to
    before ``out`` is touched."""
    if executor not in EXECUTORS:
        raise InputError(f"executor {executor!r}: must be one of {', '.join(EXECUTORS)}")
    with contextlib.ExitStack() as stack:
        if executor == "builtin":
            def runner(items: list[Job]) -> Generator[dict, None, None]:
                return _map(build_cam, items, jobs)
        else:
            from .package_dask import dask_executor

            mapper = stack.enter_context(dask_executor(scheduler if executor == "dask" else None, dask_workers,
                                                       dask_config or {}))

            def runner(items: list[Job]) -> Generator[dict, None, None]:
                return mapper(build_cam, [replace(j, spec=None) for j in items], _lost)
        folder = stack.enter_context(output_folder(out))
        return _package(paths, folder, runner, {"jobs": jobs, "executor": executor}, outputs, force,
                        progress or (lambda m: None), allow_outside_files)


#: builds a list of jobs, yielding their entries as they are done
Runner = Callable[[list[Job]], Generator[dict, None, None]]


def _package(paths: Iterable[str | Path], out: Path, runner: Runner, meta: dict,
             outputs: Sequence[str] | None, force: bool, say: Callable[[str], None], allow_outside_files: bool) -> dict:
    options = {"outputs": sorted(outputs) if outputs is not None else None, "force": force}
    designs = discover(paths)
    old = _old_entries(out)
    recorded = frozenset(f for e in old.values() for f in _recorded(e))
    templates = templates_hash()
    opts = options if (outputs is not None or force) else {}
    if allow_outside_files:  # only then in the key: the keys of existing packages do not change
        options["allow_outside_files"] = True
        opts = {**opts, "allow_outside_files": True}
    read = [(p, *_read(p, allow_outside_files)) for p in designs]
    stems = folders([safe_stem(spec.name if spec is not None else p.stem) for p, spec, _, _ in read])
    todo: list[Job] = []
    unreadable: list[dict[str, Any]] = []
    entries: dict[str, dict] = {}
    for (p, spec, sources, error), stem in zip(read, stems, strict=True):
        key = input_key(sources, opts, templates) if p.is_file() else "missing"
        prev = old.get(str(p))
        if prev and prev.get("key") == key and prev.get("folder") == stem and _still_valid(prev, out):
            entries[str(p)] = {**prev, "rebuilt": False}
            say(f"[up to date] {plain(str(prev.get('name', p.stem)))}")
        elif spec is None:  # its entry records why, as a worker's would
            bad: dict[str, Any] = {"source": str(p), "key": key, "rebuilt": True}
            _failed(bad, error or OSError(f"{p}: cannot be read"))
            unreadable.append({**bad, "name": p.stem, "seconds": 0.0})
        else:
            todo.append(Job(str(p), spec.name, stem, key, options,
                            tuple((str(f), Path(f).read_bytes()) for f in sources if Path(f).is_file()), spec))
    if len(todo) > 1:  # worker processes read their design again from its bytes (a program does not pickle)
        todo = [replace(j, spec=None) for j in todo]
    t0 = time.perf_counter()
    total = len(todo) + len(unreadable)
    with contextlib.closing(runner(todo)) as results:
        for done, built in enumerate(itertools.chain(unreadable, results), 1):
            entry = _commit(built, out, recorded)
            entries[entry["source"]] = entry
            first = (entry.get("error") or "").split("\n", 1)[0]  # an empty error has no first line to index
            tail = entry.get("verdict") or f"ERROR: {first}"
            say(f"{_bar(done, total)} {done}/{total} {plain(entry['name'])}: {tail} ({entry['seconds']:.2f} s)")
    manifest = {"camfab_version": __version__, **meta, "wall_seconds": time.perf_counter() - t0,
                "cams": [entries[str(p)] for p in designs]}
    _remove_stale(out, old, manifest)
    failed: list[OSError] = []
    try:
        manifest["drawing_set"] = _drawing_set(out, manifest, _old_set(out), say)
    except OSError as exc:  # the manifest and the index are still written
        failed.append(exc)
    for name, text in ((MANIFEST, lambda: json.dumps(manifest, indent=2) + "\n"),
                       (INDEX, lambda: index_html(manifest))):
        try:  # the index is still written when the manifest cannot be, and the other way round
            atomic_write(out / name, text())
        except OSError as exc:
            failed.append(exc)
    if failed:
        raise failed[0]
    return manifest


def _old_set(out: Path) -> dict | None:
    """The ``drawing_set`` record of the previous manifest (None when there is none)."""
    try:
        data = json.loads((out / MANIFEST).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    rec = data.get("drawing_set") if isinstance(data, dict) else None
    return rec if isinstance(rec, dict) else None


def _set_entries(out: Path, manifest: dict) -> list:
    """Every cam of the package as a :class:`~camfab.cad.pdf.SetEntry`: its sheet (the ``*_drawing.dxf`` of a
    cam that has its ``*_drawing.pdf``), or why it has none."""
    from .cad.pdf import SetEntry

    items = []
    for e in manifest["cams"]:
        paths = [f["path"] for f in e.get("files", [])]
        sheets = [p for p in paths if p.endswith("_drawing.dxf") and p.removesuffix(".dxf") + ".pdf" in paths]
        if e.get("status") == "error":
            error, source = e.get("error") or "error", str(e.get("source", ""))
            reason = " ".join(error.removeprefix(f"{source}: ").split())  # the contents names the cam already
        elif "drawing" in e.get("withheld", []):
            codes = ", ".join(r["code"] for r in e.get("reasons", []) if r.get("severity") == "error")
            reason = f"withheld: the verdict is unacceptable ({codes})" if codes else "withheld: unacceptable"
        else:
            reason = "no PDF drawing asked for ([outputs] pdf)"
        items.append(SetEntry(str(e.get("name", "")), e.get("verdict"), e.get("drawing_number"),
                              out / sheets[0] if sheets else None, "" if sheets else reason))
    return items


def _drawing_set(out: Path, manifest: dict, old: dict | None, say: Callable[[str], None]) -> dict | None:
    """Write :data:`DRAWING_SET` (a contents page, then every cam's sheet) when any cam has a PDF sheet; returns
    its manifest record, or None (an earlier set is then removed).  Not rendered again when nothing it shows
    changed (its key: every cam's name, verdict, drawing number, reason and sheet hash) and the file is
    still the one recorded."""
    from .cad.pdf import write_drawing_set

    path = out / DRAWING_SET
    items = _set_entries(out, manifest)
    if not any(i.sheet is not None for i in items):
        if old is not None and path.is_file():
            path.unlink()
        return None
    sha = {f["path"]: f["sha256"] for e in manifest["cams"] for f in e.get("files", [])}
    key = _sha(json.dumps([__version__, [[i.name, i.verdict, i.number, i.reason,
                                          sha.get(i.sheet.relative_to(out).as_posix()) if i.sheet else None]
                                         for i in items]]).encode())
    if old and old.get("key") == key and path.is_file() and _sha(path.read_bytes()) == old.get("sha256"):
        say(f"[up to date] {DRAWING_SET}")
        return old
    say(f"{DRAWING_SET}: contents and {sum(i.sheet is not None for i in items)} sheet(s)")
    pages = write_drawing_set(path, items)
    data = path.read_bytes()
    return {"path": DRAWING_SET, "key": key, "pages": pages, "sha256": _sha(data), "bytes": len(data)}


def _recorded(entry: dict) -> list[str]:
    """The paths (relative to the package folder, POSIX form) of the files a manifest entry lists."""
    try:
        return [Path(f["path"]).as_posix() for f in entry.get("files", [])]
    except (TypeError, KeyError, AttributeError):
        return []


def _remove_stale(out: Path, old: dict, manifest: dict) -> None:
    """Remove the files the previous manifest listed that the new one does not (what camfab wrote before:
    outputs no longer asked for, designs gone or failing now), then the folders this leaves empty.  Files
    camfab did not record are never touched."""
    keep = {f for e in manifest["cams"] for f in _recorded(e)}
    emptied: set[Path] = set()
    for rel in sorted({f for e in old.values() for f in _recorded(e)} - keep):
        try:
            p = inside(out, rel)
        except ExportError:  # a manifest edited to point outside: ignored
            continue
        if p.is_file() or p.is_symlink():
            p.unlink()
            emptied.update(d for d in p.parents if d != out and d.is_relative_to(out))
    for d in sorted(emptied, key=lambda d: len(d.parts), reverse=True):
        with contextlib.suppress(OSError):
            d.rmdir()


def _bar(done: int, total: int, width: int = 20) -> str:
    """A text progress bar ``[#####---------------]``."""
    k = round(width * done / max(total, 1))
    return "[" + "#" * k + "-" * (width - k) + "]"


def _map(fn: Callable, items: list, jobs: int) -> Generator[dict, None, None]:
    if jobs <= 1 or len(items) <= 1:
        yield from map(fn, items)
        return
    # "spawn": a forked worker can deadlock on locks held by threads of the parent (OCCT, browsers)
    ctx = multiprocessing.get_context("spawn")
    tracker = _idle_resource_tracker()
    pool = ProcessPoolExecutor(max_workers=min(jobs, len(items), os.cpu_count() or 1), mp_context=ctx,
                               initializer=_worker_init, initargs=(os.getpid(),))
    before = set(multiprocessing.active_children())
    try:
        with hold_sigint():  # the workers start with Ctrl-C blocked (they ignore it); the parent gets it after
            results = pool.map(fn, items)
        yield from results
    except BaseException:  # Ctrl-C, or the consumer gone: stop the workers now, do not wait for them
        _stop(pool, [p for p in multiprocessing.active_children() if p not in before])
        raise
    pool.shutdown()
    del pool
    if tracker is not None:  # the pool's semaphores are gone: the tracker it started has nothing to watch
        with contextlib.suppress(Exception):
            tracker._stop()


def _idle_resource_tracker():
    """multiprocessing's resource tracker (CPython's) when it is not running yet: the pool starts it for its
    semaphores and ends it with itself, so that ``package --jobs 2`` leaves no process in its group at exit."""
    from multiprocessing import resource_tracker

    tracker = getattr(resource_tracker, "_resource_tracker", None)
    return tracker if getattr(tracker, "_fd", 0) is None and hasattr(tracker, "_stop") else None


def _stop(pool: ProcessPoolExecutor, workers: list) -> None:
    """Terminate the pool's worker processes, cancel what is queued, reap them (killed if they linger)."""
    for w in workers:
        w.terminate()
    pool.shutdown(wait=False, cancel_futures=True)
    for w in workers:
        w.join(2.0)
        if w.is_alive():
            w.kill()
            w.join(1.0)


def _worker_init(parent: int) -> None:
    """A worker process ignores Ctrl-C (its parent stops it), dies with its parent, and runs BLAS on one thread
    (the pool already keeps every core busy: more threads per worker only oversubscribe them)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    if hasattr(signal, "pthread_sigmask"):
        signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})
    _die_with_parent(parent)
    blas_single_threaded()


def _die_with_parent(parent: int) -> None:
    """End this process when ``parent`` ends (even by ``kill -9``): Linux ``prctl(PR_SET_PDEATHSIG, SIGKILL)``,
    then a check that the parent is not already gone; elsewhere a thread that watches the parent."""
    if sys.platform.startswith("linux"):
        try:
            import ctypes

            pr_set_pdeathsig = 1
            if ctypes.CDLL(None, use_errno=True).prctl(pr_set_pdeathsig, int(signal.SIGKILL), 0, 0, 0) == 0:
                if os.getppid() != parent:  # the parent died before the prctl
                    os._exit(1)
                return
        except (OSError, AttributeError):
            pass
    threading.Thread(target=_watch_parent, args=(parent,), daemon=True, name="camfab-parent-watch").start()


def _watch_parent(parent: int) -> None:
    while os.getppid() == parent:
        time.sleep(0.5)
    os._exit(1)


def _old_entries(out: Path) -> dict:
    try:
        data = json.loads((out / MANIFEST).read_text(encoding="utf-8"))
        return {e["source"]: e for e in data.get("cams", []) if "source" in e}
    except FileNotFoundError:
        return {}
    except (OSError, ValueError, KeyError, TypeError) as exc:
        log.warning("%s cannot be read (%s: %s); every design is rebuilt", out / MANIFEST, type(exc).__name__, exc)
        return {}


def exit_status(manifest: dict) -> int:
    """3 if any design could not be written (an I/O error, a missing dependency, its Dask worker lost), else 2 if
    any design is invalid, else 1 if any is unacceptable, else 0."""
    st = [e.get("status") for e in manifest["cams"]]
    if any(e.get("status") == "error" and e.get("error_kind") in ("io", "dependency", "worker")
           for e in manifest["cams"]):
        return 3
    return 2 if "error" in st else 1 if "unacceptable" in st else 0
