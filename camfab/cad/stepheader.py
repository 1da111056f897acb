"""The header of camfab's STEP files: who made the part, what it is, and when — reproducible by default.

OpenCascade writes ``FILE_NAME('Open CASCADE Shape Model', <now>, ('Author'), ('Open CASCADE'), …)``.  camfab
writes instead the design's name, the author, organisation and part number it is given (``[drawing]`` in the
design, wired by the caller), ``camfab <version>`` as the preprocessor, and a timestamp that does not change
from run to run (``docs/decisions.md``, "STEP header"): ``SOURCE_DATE_EPOCH`` when set (the reproducible-builds
convention), else 1970-01-01T00:00:00 — the project promises byte-identical files for the same input.  A caller
that wants the time of writing passes ``timestamp="now"``.

>>> meta = StepMeta.of("Ejemplo9RT", author="A. Smith")
>>> meta.part_number, meta.organisation, meta.author
('Ejemplo9RT', 'camfab', 'A. Smith')
"""
from __future__ import annotations

import os
import re
from datetime import UTC, datetime

from ..errors import InputError
from ..records import dataclass
from ..textsafe import step_string
from ..version import __version__

__all__ = ["StepMeta", "step_timestamp", "header_dumps", "design_meta"]

_EPOCH0 = "1970-01-01T00:00:00"


def step_timestamp(timestamp: str | datetime | None = None, *, environ=None) -> str:
    """The ISO 8601 time stamp of a STEP header.

    ``None``: ``SOURCE_DATE_EPOCH`` (whole seconds since 1970, UTC) when set, else 1970-01-01T00:00:00 (a
    fixed stamp keeps the file byte-identical); ``"now"``: the current UTC time; a ``datetime`` as given (UTC).

    >>> step_timestamp(environ={"SOURCE_DATE_EPOCH": "1700000000"})
    '2023-11-14T22:13:20'
    >>> step_timestamp(environ={})
    '1970-01-01T00:00:00'
    """
    env = os.environ if environ is None else environ
    if isinstance(timestamp, datetime):
        when = timestamp.astimezone(UTC) if timestamp.tzinfo else timestamp
        return when.strftime("%Y-%m-%dT%H:%M:%S")
    if timestamp == "now":
        return datetime.now(UTC).strftime("%Y-%m-%dT%H:%M:%S")
    if timestamp is not None:
        raise InputError(f"timestamp {timestamp!r}: give None, 'now' or a datetime")
    epoch = env.get("SOURCE_DATE_EPOCH")
    if not epoch:
        return _EPOCH0
    if not epoch.strip().isdigit() or int(epoch) > 253402300799:
        raise InputError(f"SOURCE_DATE_EPOCH={epoch[:40]!r}: must be whole seconds since 1970-01-01 UTC "
                         "(e.g. the output of `git log -1 --format=%ct`), up to year 9999")
    return datetime.fromtimestamp(int(epoch), UTC).strftime("%Y-%m-%dT%H:%M:%S")


@dataclass(frozen=True)
class StepMeta:
    """The header fields: file name (the part number), author, organisation, description, timestamp."""

    part_number: str
    author: str
    organisation: str
    description: str
    timestamp: str

    @classmethod
    def of(cls, name: str, *, author: str | None = None, organisation: str | None = None,
           part_number: str | None = None, timestamp: str | datetime | None = None,
           description: str | None = None) -> StepMeta:
        """The header of a part of the design ``name``; what is not given is derived: part number = the design
        name, author = "" (unknown; never OpenCascade's 'Author'), organisation = "camfab"."""
        return cls(part_number or name, author or "", organisation or "camfab",
                   description or f"{name} (camfab cam)", step_timestamp(timestamp))


def design_meta(spec) -> StepMeta:
    """The header of a design's STEP files: its ``[drawing]`` author, organisation and part number where the
    design gives them, else the defaults of :meth:`StepMeta.of`."""
    d = spec.drawing
    return StepMeta.of(spec.name, author=d.author or None, organisation=d.organisation or None,
                       part_number=d.part_number or d.number or None)


_FILE_NAME = re.compile(r"FILE_NAME\(.*?\);", re.S)
_FILE_DESCRIPTION = re.compile(r"FILE_DESCRIPTION\(.*?\);", re.S)


def header_dumps(text: str, name: str, meta: StepMeta | None = None) -> str:
    """``text`` (a STEP file OpenCascade wrote) with camfab's header: FILE_DESCRIPTION and FILE_NAME from
    ``meta`` (default :meth:`StepMeta.of` ``(name)``), every user string through :func:`step_string`."""
    meta = meta or StepMeta.of(name)
    head, sep, data = text.partition("DATA;")
    q = step_string
    fname = (f"FILE_NAME('{q(meta.part_number)}','{meta.timestamp}',('{q(meta.author)}'),"
             f"('{q(meta.organisation)}'),'camfab {__version__}','camfab {__version__} (Open CASCADE)','');")
    desc = f"FILE_DESCRIPTION(('{q(meta.description)}'),'2;1');"
    head = _FILE_NAME.sub(lambda m: fname, head, count=1)
    head = _FILE_DESCRIPTION.sub(lambda m: desc, head, count=1)
    return head + sep + data
