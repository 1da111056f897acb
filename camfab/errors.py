"""Exception tree of camfab.

Exceptions are for inputs that cannot be computed at all.  A design that *can*
be computed but fails its checks produces a coded report instead (see
:mod:`camfab.design.checks`).

Every error camfab raises on purpose derives from :class:`CamfabError`; a class that
replaced a builtin exception also derives from that builtin (``InputError`` is a
``ValueError``, ``ApiError`` a ``TypeError``, ...), so ``except ValueError`` keeps
working.  The command line maps them to its exit codes: ``MissingDependencyError``
and ``UnreachableError`` → 3; ``ApiError`` and ``InternalError`` are bugs and keep their traceback; every
other ``CamfabError`` → 2 (invalid input, nothing written).  ``tests/test_errors.py``
fails on a ``raise`` of a builtin exception anywhere in the package.
"""
from __future__ import annotations

import math
from typing import Any

from .records import dataclass
from .textsafe import excerpt

__all__ = [
    "CamfabError",
    "Problem",
    "SpecError",
    "GeometryError",
    "ExportError",
    "MissingDependencyError",
    "UnreachableError",
    "InputError",
    "ApiError",
    "InternalError",
]


class CamfabError(Exception):
    """Root of every error raised on purpose by camfab."""


@dataclass(frozen=True, slots=True)
class Problem:
    """One validation problem: where, what value, which rule, and how to fix it."""

    path: str
    value: Any
    rule: str
    fix: str = ""

    def __str__(self) -> str:
        text = f"{self.path} = {excerpt(repr(self.value))}: {self.rule}"  # a 5 MB value is not repeated
        return f"{text}; {self.fix}" if self.fix else text

    def to_dict(self) -> dict[str, Any]:
        """``{"path", "value", "rule", "fix"}``; a value strict JSON cannot hold (NaN, a list…) as its text."""
        v = self.value
        ok = v is None or isinstance(v, (str, int, bool)) or (isinstance(v, float) and math.isfinite(v))
        return {"path": self.path, "value": v if ok else repr(v), "rule": self.rule,
                "fix": self.fix}


class SpecError(CamfabError, ValueError):
    """Invalid design input; carries every problem found, not only the first."""

    def __init__(self, problems: list[Problem] | Problem, source: str | None = None):
        if isinstance(problems, Problem):
            problems = [problems]
        self.problems: list[Problem] = list(problems)
        self.source = source
        head = f"{source}: " if source else ""
        n = len(self.problems)
        lines = [f"{head}{n} problem{'s' if n != 1 else ''} in the design:"]
        lines += [f"  - {p}" for p in self.problems]
        super().__init__("\n".join(lines))

    def to_dict(self) -> dict[str, Any]:
        """The ``--json`` form of the error: ``{"error": "invalid_design", "source", "problems": [...]}``."""
        return {"error": "invalid_design", "source": self.source, "problems": [p.to_dict() for p in self.problems]}


class GeometryError(CamfabError):
    """Geometry that cannot be built, e.g. a tool too large for a concave stretch."""


class ExportError(CamfabError):
    """An artifact could not be written."""


class MissingDependencyError(CamfabError, ImportError):
    """An optional dependency needed for the requested job is not installed."""


class UnreachableError(CamfabError, OSError):
    """An outside service the job needs (a Dask scheduler, its workers) cannot be reached: an I/O fault of the
    environment, not of the input (exit 3); the message names the address and what to start or check."""


class InputError(CamfabError, ValueError):
    """A bad argument value given to an API function (a tolerance, a speed, a post-processor name or option,
    a mode string...); the message names the argument, its value and what is accepted.  Design-file input is
    reported as :class:`SpecError` instead."""


class ApiError(CamfabError, TypeError):
    """An object of the wrong kind given to an API function (e.g. pressure-angle sizing of a flat-face
    follower, or a program that is not a :class:`camfab.gcode.Program`): a mistake in the calling code."""


class InternalError(CamfabError, RuntimeError):
    """An invariant of camfab broken: a bug in camfab, to be reported with the input that caused it."""
