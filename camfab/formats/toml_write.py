"""Design dicts (the TOML structure) → TOML design files, and a design file's dict with its knot rows inline.

:func:`dumps_design` writes every key of a design dict so that ``tomllib.loads(dumps_design(d)) == d``:
strings as TOML basic strings with every control character, quote and backslash escaped (user text cannot
end a string or start a new key), keys that are not bare written quoted, floats by ``repr`` (the shortest text
that reads back to the same double; ``inf``/``nan`` as TOML spells them).  Top-level values come first, then
tables in the design's order, sub-tables of a table inline.

:func:`design_data` reads a design file as that dict: a ``[motion_table]`` ``file`` is replaced by its rows
(inline), so the written design stands alone wherever it is written.
"""
from __future__ import annotations

import math
import re
import tomllib
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from ..design.spec import DesignSpec
from ..errors import ApiError, Problem, SpecError
from .design_files import load_design, resolve_design_path
from .input_limits import read_text_limited
from .knot_files import resolve_knot_file

__all__ = ["dumps_design", "design_data", "toml_string"]

_BARE = re.compile(r"[A-Za-z0-9_-]+")
_ESCAPES = {"\b": "\\b", "\t": "\\t", "\n": "\\n", "\f": "\\f", "\r": "\\r", '"': '\\"', "\\": "\\\\"}


def toml_string(text: str) -> str:
    """A TOML basic string holding ``text`` exactly: quotes, backslashes and every control character escaped
    (a lone surrogate, which UTF-8 cannot hold, as U+FFFD)."""
    out = []
    for c in text:
        o = ord(c)
        if c in _ESCAPES:
            out.append(_ESCAPES[c])
        elif o < 0x20 or o == 0x7F:
            out.append(f"\\u{o:04X}")
        elif 0xD800 <= o <= 0xDFFF:
            out.append("\\uFFFD")
        else:
            out.append(c)
    return '"' + "".join(out) + '"'


def _key(k: Any) -> str:
    k = str(k)
    return k if _BARE.fullmatch(k) else toml_string(k)


def _value(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if math.isnan(v):
            return "nan"
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return repr(v)
    if isinstance(v, str):
        return toml_string(v)
    if isinstance(v, Mapping):
        return "{ " + ", ".join(f"{_key(k)} = {_value(x)}" for k, x in v.items()) + " }" if v else "{}"
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_value(x) for x in v) + "]"
    raise ApiError(f"cannot write a {type(v).__name__} to TOML")


def _is_table_array(v: Any) -> bool:
    return isinstance(v, list) and bool(v) and all(isinstance(x, Mapping) for x in v)


def dumps_design(data: Mapping[str, Any], *, header: str = "") -> str:
    """The TOML text of a design dict (``header``: comment lines, each made one plain line)."""
    lines = [f"# {_comment(h)}" for h in header.splitlines() if h.strip()]
    top = [(k, v) for k, v in data.items() if not isinstance(v, Mapping) and not _is_table_array(v)]
    lines += [f"{_key(k)} = {_value(v)}" for k, v in top]
    for k, v in data.items():
        if isinstance(v, Mapping):
            lines += ["", f"[{_key(k)}]"] + [f"{_key(a)} = {_value(b)}" for a, b in v.items()]
        elif _is_table_array(v):
            for item in v:
                lines += ["", f"[[{_key(k)}]]"] + [f"{_key(a)} = {_value(b)}" for a, b in item.items()]
    return "\n".join(lines) + "\n"


def _comment(text: str) -> str:
    """One comment line: control characters (and line breaks) made spaces."""
    return "".join(" " if ord(c) < 0x20 or ord(c) == 0x7F or 0x2028 <= ord(c) <= 0x2029 or 0xD800 <= ord(c) <= 0xDFFF
                   else c for c in text)


def design_data(design: str | Path, *, allow_outside_files: bool = False) -> tuple[dict[str, Any], DesignSpec]:
    """A TOML design file (or a built-in example) as its dict, the rows of its knot file inline, and its
    validated spec.

    Raises
    ------
    SpecError
        An invalid design; an xlsx design (not a TOML one), naming the fix.
    """
    p = resolve_design_path(design)
    spec = load_design(p, allow_outside_files=allow_outside_files)
    if p.suffix.lower() != ".toml":
        raise SpecError(Problem("file", str(p), "camfab size and optimise write a TOML design and read TOML designs",
                                "give the TOML design file (an xlsx design: copy its values into a TOML file)"),
                        str(p))
    data = tomllib.loads(read_text_limited(p, field="file"))
    data.setdefault("name", p.stem)
    table = data.get("motion_table")
    if isinstance(table, Mapping) and "file" in table:
        read = resolve_knot_file(table, p.parent, allow_outside_files=allow_outside_files)
        rows = [list(r) for r in read["file"].rows]
        data["motion_table"] = {"rows" if k == "file" else k: (rows if k == "file" else x) for k, x in table.items()}
    return data, spec
