"""Exception tree of camfab.

Exceptions are for inputs that cannot be computed at all.  A design that *can*
be computed but fails its checks produces a coded report instead (see
:mod:`camfab.design.checks`).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

__all__ = [
    "CamfabError",
    "Problem",
    "SpecError",
    "GeometryError",
    "ExportError",
    "MissingDependencyError",
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
        text = f"{self.path} = {self.value!r}: {self.rule}"
        return f"{text}; {self.fix}" if self.fix else text


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


class GeometryError(CamfabError):
    """Geometry that cannot be built, e.g. a tool too large for a concave stretch."""


class ExportError(CamfabError):
    """An artifact could not be written."""


class MissingDependencyError(CamfabError, ImportError):
    """An optional dependency needed for the requested job is not installed."""
