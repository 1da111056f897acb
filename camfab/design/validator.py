"""Reading typed values out of nested dicts (a design's TOML structure) while collecting every problem.

Each problem names the field path, the value, the rule and a fix; the caller raises them together in one
:class:`~camfab.errors.SpecError`.
"""
from __future__ import annotations

import math
from collections.abc import Mapping
from enum import StrEnum
from typing import Any

from ..errors import Problem

__all__ = ["Validator"]


class Validator:
    """Collects problems while reading typed values out of nested dicts."""

    def __init__(self) -> None:
        self.problems: list[Problem] = []

    def add(self, path: str, value: Any, rule: str, fix: str = "") -> None:
        self.problems.append(Problem(path, value, rule, fix))

    def keys(self, table: Mapping[str, Any], allowed: tuple[str, ...], path: str) -> None:
        for k in table:
            if k not in allowed:
                import difflib  # only for a misspelt name

                close = difflib.get_close_matches(k, allowed, n=1)
                fix = f"did you mean '{close[0]}'?" if close else "allowed keys: " + ", ".join(allowed)
                self.add(f"{path}.{k}" if path else k, table[k], "unknown key", fix)

    def choice(self, table: Mapping[str, Any], key: str, path: str, options: type[StrEnum], default: Any) -> Any:
        """A member of the enum ``options`` (its string in the file); ``default`` when absent or invalid."""
        val = table.get(key, default)
        if val not in tuple(options):
            self.add(f"{path}.{key}", val, "is not a valid option", "must be one of: " + ", ".join(options))
            return default
        return options(val)

    def number(self, table: Mapping[str, Any], key: str, path: str, default: Any, *, lo: float | None = None,
               hi: float | None = None, lo_open: bool = False, hi_open: bool = False, fix: str = "") -> Any:
        """A finite float in [lo, hi] (open ends optional); None/default when absent."""
        if key not in table:
            return default
        val = table[key]
        where = f"{path}.{key}"
        if isinstance(val, bool) or not isinstance(val, (int, float)):
            self.add(where, val, "must be a number", fix or "write a plain number (no units, no quotes)")
            return default
        val = float(val)
        if not math.isfinite(val):
            self.add(where, val, "must be finite", fix or "give a finite number")
            return default
        bad_lo = lo is not None and (val <= lo if lo_open else val < lo)
        bad_hi = hi is not None and (val >= hi if hi_open else val > hi)
        if bad_lo or bad_hi:
            rng = (f"{'(' if lo_open else '['}{'-inf' if lo is None else lo}, "
                   f"{'inf' if hi is None else hi}{')' if hi_open else ']'}")
            self.add(where, val, f"must be in {rng}", fix or "change the value into that range")
            return default
        return val

    def boolean(self, table: Mapping[str, Any], key: str, path: str, default: bool) -> bool:
        val = table.get(key, default)
        if not isinstance(val, bool):
            self.add(f"{path}.{key}", val, "must be true or false", "write true or false (no quotes)")
            return default
        return val

    def table(self, data: Mapping[str, Any], key: str) -> Mapping[str, Any]:
        """The sub-table ``data[key]`` ({} when absent, or reported and {} when it is not a table)."""
        t = data.get(key, {})
        if not isinstance(t, Mapping):
            self.add(key, t, "must be a table", f"write it as a [{key}] section")
            return {}
        return t
