"""Input limits: the largest design camfab reads, in one place (``docs/decisions.md``, "Input limits").

A small file must not exhaust the machine.  Every input beyond one of these limits is refused before it is
computed — a :class:`~camfab.errors.SpecError` (exit 2) naming the field, the limit and the fix; nothing is
clamped.  The file limits are applied by :mod:`camfab.formats` (which reads the files), the limits of the data
by :func:`data_problems` (a design dict, from any source), the counts where the sequences are consumed
(segments in :mod:`camfab.design.resolve` and :mod:`camfab.design.spec`, knots in :mod:`camfab.design.knots`
and :mod:`camfab.formats.knot_files`).

>>> data_problems({"name": "x" * 300})[0].rule
'text longer than 256 characters'
"""
from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from .errors import Problem
from .textsafe import excerpt

__all__ = [
    "MAX_FILE_BYTES",
    "MAX_XLSX_UNCOMPRESSED_BYTES",
    "MAX_XLSX_MEMBERS",
    "MAX_SHEET_ROWS",
    "MAX_SHEET_COLUMNS",
    "MAX_NESTING",
    "MAX_SEGMENTS",
    "MAX_KNOTS",
    "MAX_NAME_CHARS",
    "MAX_DESCRIPTION_CHARS",
    "MAX_TEXT_CHARS",
    "MAX_KEY_CHARS",
    "MAX_LIFT_MM",
    "MAX_LENGTH_MM",
    "MAX_SIZE_OVER_TOL",
    "MAX_DEPTH_LEVELS",
    "MAX_PROGRAM_MOVES",
    "MAX_ITEMS",
    "MAX_LISTED",
    "data_problems",
    "preview",
]

#: a design file (TOML or xlsx, as stored) and a knot file, in bytes
MAX_FILE_BYTES = 4_000_000
#: an xlsx workbook unpacked: the sum of its members' sizes (checked before openpyxl reads it: a zip bomb)
MAX_XLSX_UNCOMPRESSED_BYTES = 20_000_000
#: members in an xlsx workbook (a real one has about a dozen)
MAX_XLSX_MEMBERS = 1000
#: rows and columns of a spreadsheet sheet that is read (blank rows included; a knot sheet needs MAX_KNOTS + 1)
MAX_SHEET_ROWS = 20_000
MAX_SHEET_COLUMNS = 100
#: tables and arrays inside each other (a design needs 3: ``motion_table.rows[i][k]``)
MAX_NESTING = 10
#: ``[[motion]]`` segments in one program
MAX_SEGMENTS = 1000
#: rows of a knot table (inline, in a file or in a sheet)
MAX_KNOTS = 10_000
#: characters of the design's ``name``, of its ``description`` and of any other text value
MAX_NAME_CHARS = 256
MAX_DESCRIPTION_CHARS = 10_000
MAX_TEXT_CHARS = 4096
#: characters of a key (every key camfab knows has fewer than 40)
MAX_KEY_CHARS = 100
#: a follower lift or knot displacement in mm (or degrees on an arm), and any other length in mm
MAX_LIFT_MM = 1e5
MAX_LENGTH_MM = 1e6
#: a cam's largest radius over its export tolerance (a 1 m cam to 1 nm, a 10 m cam to 10 nm)
MAX_SIZE_OVER_TOL = 1e9
#: depth levels of a milling program (plate thickness / step-down), and the moves of the whole program
#: (levels × passes × contour entities; a real cam's program has a few tens of thousands)
MAX_DEPTH_LEVELS = 1000
MAX_PROGRAM_MOVES = 500_000
#: entries of one table or array (the longest a design has: the knot rows)
MAX_ITEMS = MAX_KNOTS
#: problems listed by :func:`data_problems` before it sums up the rest
MAX_LISTED = 100
#: most assembly poses one run writes (``--poses``; :data:`camfab.pipeline.MAX_POSES`)
MAX_POSES = 360


def preview(value: Any, width: int = 40) -> str:
    """A short stand-in for an over-long or deeply nested value in a message (never its whole text)."""
    if isinstance(value, str):
        return excerpt(value, width) + ("" if len(value) <= width else f" ({len(value)} characters)")
    if isinstance(value, Mapping):
        return f"<a table of {len(value)} keys>"
    if isinstance(value, (list, tuple)):
        return f"<an array of {len(value)} items>"
    return type(value).__name__


def _text_limit(path: str) -> int:
    return {"name": MAX_NAME_CHARS, "description": MAX_DESCRIPTION_CHARS}.get(path, MAX_TEXT_CHARS)


def _path(parent: str, key: object) -> str:
    if isinstance(key, int):
        return f"{parent}[{key}]"
    return f"{parent}.{key}" if parent else str(key)


def data_problems(data: Mapping[str, Any]) -> list[Problem]:
    """The limits of a design dict's shape: nesting depth, array, key and text lengths (iterative: any depth).

    Returns
    -------
    list of Problem
        One per offending field (at most :data:`MAX_LISTED`, then one that counts the rest); empty when the
        data lie within the limits.
    """
    out: list[Problem] = []
    containers = (Mapping, list, tuple)
    stack: list[tuple[str, Any, int]] = [("", data, 1)]
    while stack and len(out) <= MAX_LISTED:
        path, node, depth = stack.pop()
        if isinstance(node, str):
            if len(node) > _text_limit(path):
                out.append(Problem(path, preview(node), f"text longer than {_text_limit(path)} characters",
                                   "shorten it"))
        elif depth > MAX_NESTING:
            out.append(Problem(path, preview(node), f"nesting too deep (more than {MAX_NESTING} levels of tables "
                               "and arrays)", "a design nests at most motion_table.rows[i][k]; remove the "
                               "extra brackets"))
        elif len(node) > MAX_ITEMS:
            out.append(Problem(path, preview(node), f"more than {MAX_ITEMS} items", "no table or array of a "
                               "design is this long: check the file"))
        else:
            items = node.items() if isinstance(node, Mapping) else enumerate(node)
            kids = []
            for key, value in items:
                if isinstance(key, str) and len(key) > MAX_KEY_CHARS:
                    out.append(Problem(_path(path, preview(key)), "...", f"key longer than {MAX_KEY_CHARS} "
                                       "characters", "remove it (no such key)"))
                elif isinstance(value, (str, *containers)):  # numbers and booleans have no limit here
                    kids.append((_path(path, key), value, depth + 1))
            stack.extend(reversed(kids))
    if len(out) > MAX_LISTED:
        out = out[:MAX_LISTED] + [Problem("...", None, "more fields over the limits", "fix the ones listed first")]
    return out
