"""Atomic, deterministic file writes shared by every exporter and the CLI, and the rule that turns a
design's name into a safe output file name (:func:`safe_stem`, :func:`inside`)."""
from __future__ import annotations

import hashlib
import os
import re
import tempfile
import unicodedata
from pathlib import Path

from .errors import ExportError

__all__ = ["atomic_write", "safe_stem", "inside", "STEM_MAX"]

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


def atomic_write(path: str | Path, data: str | bytes) -> Path:
    """Write ``data`` to ``path`` through a temporary file and a rename.

    A crash or error leaves either the old file or none, never a partial one.
    Text is written as UTF-8 with ``\\n`` line ends, so output is byte-identical
    across platforms.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    raw = data.encode("utf-8") if isinstance(data, str) else data
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(raw)
        os.chmod(tmp, 0o666 & ~_umask())  # mkstemp creates 0600; give the usual file mode
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return path


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask
