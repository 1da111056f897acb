"""Atomic, deterministic file writes shared by every exporter and the CLI, the rule that turns a
design's name into a safe output file name (:func:`safe_stem`, :func:`inside`), and what keeps an output
folder whole through faults: one writer at a time (:func:`output_folder`), sets of files written together
(:func:`write_all`), folders swapped whole (:func:`swap_dir`), leftovers of killed processes removed
(:func:`clean_stale`)."""
from __future__ import annotations

import contextlib
import errno
import io
import os
import re
import shutil
import signal
import sys
import tempfile
import threading
import unicodedata
from collections.abc import Iterator, Mapping
from pathlib import Path
from typing import BinaryIO

from .errors import ExportError

try:
    import fcntl
except ImportError:  # Windows: no lock
    fcntl = None  # type: ignore[assignment]

__all__ = ["atomic_write", "write_all", "write_bytes", "named", "fsync_dir", "safe_stem", "inside", "STEM_MAX",
           "DURABLE", "LOCK", "TEMP_MARK", "hold_sigint", "leftover_name", "clean_stale", "output_folder",
           "swap_dir", "atomic_stream"]

#: fsync every file written and its folder (docs/decisions.md, "Faults: staging, locks, durability")
DURABLE = True
#: the lock file of an output folder while a camfab command writes into it
LOCK = ".camfab.lock"
#: marks camfab's temporary names: ``.<name>.camfab-<kind>-<pid>[-<random>]``
TEMP_MARK = ".camfab-"
_LEFTOVER = re.compile(r"^\..*\.camfab-(tmp|staging|old)-(\d+)(?:-[A-Za-z0-9_]*)?$")

#: longest stem :func:`safe_stem` returns (suffixes such as ``_drawing.dxf`` stay well under 255 bytes)
STEM_MAX = 100
_UNSAFE = re.compile(r"[^A-Za-z0-9._-]+")
_RUNS = re.compile(r"_{2,}")
#: device names Windows refuses as file names, whatever the extension (compared case-insensitively)
_RESERVED = frozenset({"CON", "PRN", "AUX", "NUL", *(f"COM{i}" for i in range(1, 10)),
                       *(f"LPT{i}" for i in range(1, 10))})


def safe_stem(name: str) -> str:
    """The file-name stem of a design called ``name``: never a path, never hidden, portable.

    The rule (docs/decisions.md, "Output file names from design names"):

    1. NFKC-normalise, then drop accents (NFKD, combining marks removed: ``"Leva ñ"`` → ``"Leva_n"``);
    2. replace every run of characters outside ``[A-Za-z0-9._-]`` (``/``, ``\\``, spaces, control
       characters, other scripts) by one ``_`` and collapse runs of ``_``;
    3. strip leading ``.``, ``_``, ``-`` and trailing ``.`` (no hidden files, no ``.`` or ``..``);
    4. an empty result becomes ``cam``;
    5. longer than :data:`STEM_MAX` (100) characters: the first 91 kept, then ``_`` and the first 8 hex
       digits of the SHA-256 of the original name, so two long names stay distinct;
    6. a Windows device name (``CON``, ``PRN``, ``AUX``, ``NUL``, ``COM1``–``COM9``, ``LPT1``–``LPT9``,
       any case, before the first ``.``) gets ``_`` appended to that part.

    Nothing is refused.  A name that already follows the rule (every built-in example's) is returned
    unchanged, so its output file names do not change.  The full name stays in file contents.
    """
    text = unicodedata.normalize("NFKC", name)
    text = "".join(c for c in unicodedata.normalize("NFKD", text) if not unicodedata.combining(c))
    stem = _RUNS.sub("_", _UNSAFE.sub("_", text)).lstrip("._-").rstrip(".")
    if not stem:
        return "cam"
    if len(stem) > STEM_MAX:
        import hashlib  # only for a long name (it loads OpenSSL: ~5 ms of every start)

        digest = hashlib.sha256(name.encode("utf-8", "surrogatepass")).hexdigest()[:8]
        stem = f"{stem[:STEM_MAX - 9]}_{digest}"
    base, dot, rest = stem.partition(".")
    if base.upper() in _RESERVED:
        stem = f"{base}_{dot}{rest}"
    return stem


def inside(outdir: str | Path, relative: str | Path) -> Path:
    """``outdir / relative``, after proving that it resolves to a path under the resolved ``outdir``.

    Raises :class:`~camfab.errors.ExportError` (exit code 2, nothing written) otherwise: an absolute
    ``relative``, a ``..`` that climbs out, or a symbolic link that leads out.
    """
    out = Path(outdir)
    path = out / relative
    root = out.resolve()
    target = path.resolve()
    if target == root or not target.is_relative_to(root):
        raise ExportError(f"refusing to write {str(relative)!r}: it is not inside the output folder {str(out)!r}")
    return path


def atomic_write(path: str | Path, data: str | bytes, *, durable: bool | None = None) -> Path:
    """Write ``data`` to ``path`` through a temporary file and a rename.

    A crash or error leaves either the old file or none, never a partial one.
    Text is written as UTF-8 with ``\\n`` line ends, so output is byte-identical
    across platforms.  ``durable`` (default :data:`DURABLE`): the file and its folder
    are fsynced.  An ``OSError`` names ``path``.
    """
    return write_all({Path(path): data}, durable=durable)[0]


def write_all(files: Mapping[Path, str | bytes], *, durable: bool | None = None) -> list[Path]:
    """Write several files as one set: every file to a temporary name first, then all renamed.

    A failure while writing (disk full, permission, an interrupt) removes the temporaries and leaves every
    old file untouched; Ctrl-C is held back during the renames, so an interrupt never leaves half a set.
    Temporary names are ``.<name>.camfab-tmp-<pid>-<random>`` (:func:`clean_stale` removes those of dead
    processes).  ``durable`` (default :data:`DURABLE`): each file is fsynced before its rename and each folder
    after.  An ``OSError`` is re-raised naming the file it was writing.  Returns the paths, in order.
    """
    sync = DURABLE if durable is None else durable
    temps: list[tuple[str, Path]] = []
    try:
        for path, data in files.items():
            raw = data.encode("utf-8") if isinstance(data, str) else data
            _write_temp(Path(path), raw, sync, temps)
        with hold_sigint():
            for tmp, path in temps:
                try:
                    os.replace(tmp, path)
                except OSError as exc:
                    raise named(exc, path) from exc
    except BaseException:
        for tmp, _ in temps:
            Path(tmp).unlink(missing_ok=True)
        raise
    if sync:
        for folder in dict.fromkeys(path.parent for _, path in temps):
            fsync_dir(folder)
    return [path for _, path in temps]


class _Stream:
    """A binary file a writer streams into: every write goes through :func:`write_bytes`; ``tell`` counts."""

    def __init__(self, fh: BinaryIO, path: Path):
        self._fh, self._path, self._at = fh, path, 0

    def write(self, raw: bytes) -> int:
        write_bytes(self._fh, bytes(raw), self._path)
        self._at += len(raw)
        return len(raw)

    def tell(self) -> int:
        return self._at

    def seek(self, offset: int, whence: int = 0) -> int:
        """Only where it stands (a stream is written forward)."""
        if (offset, whence) not in ((self._at, 0), (0, 1)):
            raise io.UnsupportedOperation(f"{self._path}: a stream cannot seek")  # as any unseekable file
        return self._at

    def flush(self) -> None:
        self._fh.flush()


@contextlib.contextmanager
def atomic_stream(path: str | Path, *, durable: bool | None = None) -> Iterator[_Stream]:
    """A file to stream a large output into (a writer that needs ``write`` and ``tell``, such as a multi-page
    PDF): a temporary file beside ``path``, renamed onto it when the block ends without an error and removed
    otherwise, so ``path`` holds either its old content or the whole new one, as :func:`atomic_write`.
    An ``OSError`` names ``path``."""
    path = Path(path)
    sync = DURABLE if durable is None else durable
    tmp = ""
    try:
        with hold_sigint():  # the name is known before an interrupt can land (delivered here, inside the try)
            fd, tmp = _new_temp(path)
        with os.fdopen(fd, "wb") as fh:
            yield _Stream(fh, path)
            if sync:
                fh.flush()
                os.fsync(fh.fileno())
        os.chmod(tmp, 0o666 & ~_umask())
        with hold_sigint():
            os.replace(tmp, path)
    except BaseException as exc:
        if tmp:
            Path(tmp).unlink(missing_ok=True)
        if isinstance(exc, OSError) and str(path) not in str(exc):
            raise named(exc, path) from exc
        raise
    if sync:
        fsync_dir(path.parent)


def _new_temp(path: Path) -> tuple[int, str]:
    """A new empty temporary file beside ``path`` (its folder made if missing), named with camfab's temporary
    mark so that the next run can recognise it: (open descriptor, name).  An ``OSError`` names ``path``."""
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        return tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}{TEMP_MARK}tmp-{os.getpid()}-")
    except OSError as exc:
        raise named(exc, path) from exc


def _write_temp(path: Path, raw: bytes, sync: bool, temps: list[tuple[str, Path]]) -> None:
    """``raw`` in a new temporary file beside ``path``, ``(name, path)`` appended to ``temps`` as soon as the file
    exists: Ctrl-C is held back from its creation until it is listed, so the caller's cleanup (which removes every
    listed name on any failure) always sees it: an interrupt that landed between ``mkstemp`` and the list once left
    ``.X.nc.camfab-tmp-…`` behind.  An ``OSError`` names ``path``."""
    with hold_sigint():
        fd, tmp = _new_temp(path)
        temps.append((tmp, path))
        fh = os.fdopen(fd, "wb")  # closed by its finaliser if the held interrupt lands before the block below
    try:
        with fh:
            write_bytes(fh, raw, path)
            if sync:
                fh.flush()
                os.fsync(fh.fileno())
        os.chmod(tmp, 0o666 & ~_umask())  # mkstemp creates 0600; give the usual file mode
    except OSError as exc:
        raise named(exc, path) from exc


def write_bytes(fh: BinaryIO, raw: bytes, path: Path) -> None:
    """The one place where camfab's output bytes reach a file: ``raw`` into ``fh``, the temporary file of
    ``path`` (a test replaces it to inject disk faults)."""
    fh.write(raw)


def named(exc: OSError, path: str | Path, doing: str = "") -> OSError:
    """``exc`` as an ``OSError`` of the same kind (``PermissionError``, ...) whose message names ``path`` (and
    what camfab was ``doing``)."""
    what = f"{exc.strerror or exc}{f' ({doing})' if doing else ''}"
    if exc.errno is None:
        return OSError(f"{what}: {str(path)!r}")
    return OSError(exc.errno, what, str(path))


def fsync_dir(folder: str | Path) -> None:
    """Make a folder's entries (a rename, a new file) durable; a no-op where folders cannot be fsynced."""
    try:
        fd = os.open(folder, os.O_RDONLY | getattr(os, "O_DIRECTORY", 0))
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:  # some file systems (and Windows) refuse to fsync a folder: nothing more can be done
        pass
    finally:
        os.close(fd)


@contextlib.contextmanager
def hold_sigint() -> Iterator[None]:
    """Hold SIGINT back while the block runs (it is delivered at the end), on POSIX in the main thread: a set of
    renames is not cut in half, and processes started inside begin with SIGINT blocked.

    Two layers (docs/decisions.md, "Faults: staging, locks, durability", "Later"): the signal mask, which processes
    started inside inherit, and a Python handler that only records the signal.  The mask alone holds nothing in a
    process with other threads (a BLAS worker, a pool's thread): the kernel hands a process-directed SIGINT to a
    thread that does not block it, and Python then runs the handler in the main thread at once, whichever thread
    took the signal.  A signal recorded is passed to the previous handler when the block ends."""
    if not hasattr(signal, "pthread_sigmask") or threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.getsignal(signal.SIGINT)
    caught: list = []
    if previous is not None:  # (None: a handler installed outside Python, which cannot be put back)
        signal.signal(signal.SIGINT, lambda signum, frame: caught.append((signum, frame)))
    old = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, old)
        if previous is not None:
            signal.signal(signal.SIGINT, previous)
            if caught:
                _deliver(previous, *caught[0])


def _deliver(handler, signum: int, frame) -> None:
    """Pass a SIGINT that :func:`hold_sigint` recorded to the handler it replaced (the default action: the signal
    raised again; ignored: dropped)."""
    if callable(handler):
        handler(signum, frame)
    elif handler == signal.SIG_DFL:
        signal.raise_signal(signum)


# ---------------------------------------------------------------------------
# leftovers of killed processes, and one writer per output folder
def leftover_name(name: str, kind: str) -> str:
    """The name of a temporary entry (``kind``: ``tmp``, ``staging``, ``old``) for ``name``, owned by this
    process: ``.<name>.camfab-<kind>-<pid>`` (:func:`clean_stale` recognises it)."""
    return f".{name}{TEMP_MARK}{kind}-{os.getpid()}"


def _alive(pid: int) -> bool:
    if pid == os.getpid():
        return True
    if os.name != "posix":  # no cheap, safe test: keep the entry
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:  # exists, owned by someone else
        return True
    return True


def clean_stale(folder: str | Path, depth: int = 2) -> list[Path]:
    """Remove camfab's temporary files and staging folders whose process is dead, in ``folder`` and its
    subfolders down to ``depth`` levels; returns what was removed.  Only names of the
    :func:`leftover_name` / :func:`write_all` pattern are touched, never another file."""
    removed: list[Path] = []
    try:
        entries = list(os.scandir(folder))
    except OSError:
        return removed
    for e in entries:
        m = _LEFTOVER.match(e.name)
        if m and not _alive(int(m.group(2))):
            p = Path(e.path)
            if e.is_dir(follow_symlinks=False):
                shutil.rmtree(p, ignore_errors=True)
            else:
                p.unlink(missing_ok=True)
            removed.append(p)
        elif depth > 0 and e.is_dir(follow_symlinks=False):
            removed += clean_stale(e.path, depth - 1)
    return removed


@contextlib.contextmanager
def output_folder(folder: str | Path, *, lock: bool = True) -> Iterator[Path]:
    """Prepare ``folder`` for one camfab command that writes into it, before any computing:

    1. create it (and its parents), then prove it writable with a temporary file: an ``OSError`` naming the
       folder otherwise (``run -o /proc/x`` fails at once, exit 3);
    2. take its lock ``<folder>/.camfab.lock`` (``fcntl.flock``, not waiting): a folder another camfab command
       is writing into raises ``BlockingIOError`` naming it.  The lock file is removed on exit;
    3. remove the leftovers of killed camfab processes (:func:`clean_stale`).

    On exit the folders it created are removed again if nothing was written into them.  Without ``fcntl``
    (Windows) there is no lock.  ``lock=False`` (a command that writes single named files, like ``gcode -o
    OUT.nc``, into a folder it does not own): steps 1 and 3 only, step 3 in ``folder`` itself, not below it.
    """
    folder = Path(folder)
    created = _missing_ancestors(folder)
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise named(exc, folder, "cannot create the output folder") from exc
    try:
        if not lock:
            _probe(folder)
            clean_stale(folder, depth=0)
            yield folder
            return
        fd = _lock(folder)
        try:
            _probe(folder)
            clean_stale(folder)
            yield folder
        finally:
            Path(folder, LOCK).unlink(missing_ok=True)  # before the unlock: see _lock
            os.close(fd)
            clean_stale(folder)  # what killed workers of this command left
    finally:
        for d in created:  # deepest first; stops at the first folder that is not empty
            try:
                d.rmdir()
            except OSError:
                break


def _missing_ancestors(folder: Path) -> list[Path]:
    """``folder`` and those of its parents that do not exist yet, deepest first."""
    out = []
    for d in (folder, *folder.parents):
        if d.exists() or d.is_symlink():
            break
        out.append(d)
    return out


def _lock(folder: Path) -> int:
    """An open descriptor of ``folder/.camfab.lock`` holding its exclusive lock.

    The lock file is unlinked by its holder before it unlocks, so a descriptor locked after that may belong
    to an unlinked file: the lock counts only if the path still names the locked file (else try again)."""
    path = folder / LOCK
    for _ in range(100):
        try:
            fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o666)
        except OSError as exc:
            raise named(exc, folder, "cannot write into the output folder") from exc
        if fcntl is None:
            return fd
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            os.close(fd)
            raise _busy(folder, f"another camfab command is writing into this folder (it holds {LOCK}); wait "
                                "until it ends, or choose another output folder") from None
        except BaseException:
            os.close(fd)
            raise
        try:
            if os.fstat(fd).st_ino == os.stat(path).st_ino:
                return fd
        except FileNotFoundError:
            pass
        os.close(fd)
    raise _busy(folder, f"its lock {LOCK} keeps changing hands")


def _busy(folder: Path, why: str) -> OSError:
    """The I/O error (a ``BlockingIOError``, exit code 3) of a folder another camfab command holds."""
    return OSError(errno.EWOULDBLOCK, why, str(folder))


def _probe(folder: Path) -> None:
    """Create and remove a temporary file in ``folder``: an ``OSError`` naming it if it cannot be written."""
    try:
        with hold_sigint():  # an interrupt never lands between the probe's creation and its removal
            fd, tmp = tempfile.mkstemp(dir=folder, prefix=f".probe{TEMP_MARK}tmp-{os.getpid()}-")
            os.close(fd)
            os.unlink(tmp)
    except OSError as exc:
        raise named(exc, folder, "cannot write into the output folder") from exc


def swap_dir(new: Path, target: Path) -> None:
    """Put the folder ``new`` at ``target``, replacing the folder there whole: ``target`` always holds either
    its old or its new complete contents.  Afterwards ``new`` is gone and the old contents are deleted.

    Linux: one ``renameat2(RENAME_EXCHANGE)``; elsewhere (or where the file system refuses it) ``target`` is
    first renamed aside, so for an instant it does not exist, but it never holds a mix."""
    if not target.exists():
        os.rename(new, target)
    elif _exchange(new, target):
        shutil.rmtree(new, ignore_errors=True)  # now the old contents
    else:
        aside = target.with_name(leftover_name(target.name, "old"))
        with hold_sigint():  # never interrupted between the two renames, with nothing at ``target``
            os.rename(target, aside)
            os.rename(new, target)
        shutil.rmtree(aside, ignore_errors=True)
    if DURABLE:
        fsync_dir(target.parent)


def _exchange(a: Path, b: Path) -> bool:
    """Atomically exchange two paths (Linux ``renameat2`` with ``RENAME_EXCHANGE``); False if unavailable."""
    if not sys.platform.startswith("linux"):
        return False
    try:
        import ctypes

        fn = ctypes.CDLL(None, use_errno=True).renameat2
    except (OSError, AttributeError):
        return False
    at_fdcwd, rename_exchange = -100, 2
    return fn(at_fdcwd, os.fsencode(a), at_fdcwd, os.fsencode(b), rename_exchange) == 0


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask
