"""Text from the design (its name, description, material; error messages) written into output files:
one function per format, so that no text can change a file's structure.

The rule (docs/decisions.md, "Text from the design in output files"):

* :func:`plain` first, for every format: each control character (Unicode category Cc: C0, DEL, C1 —
  newline, tab, ESC, NUL …) and each line or paragraph separator (U+2028, U+2029) becomes one space; a lone
  surrogate becomes U+FFFD.  Nothing else changes, so an ordinary name is written exactly as given.
* then the format's own escapes, which keep the text as the reader will show it:

  ===========  ==================================================================================
  format       function and escapes
  ===========  ==================================================================================
  DXF          :func:`dxf_string` (header values): ``^`` → ``^ `` (DXF caret notation); at most
               2049 characters.  :func:`dxf_text` (TEXT) adds ``%`` → ``%%%`` (``%%d`` and the
               other special codes stay literal) and ``\\U+``/``\\M+`` → ``\\U+005CU+``.
               :func:`dxf_mtext` (MTEXT) adds ``\\`` → ``\\\\``, ``{`` → ``\\{``, ``}`` → ``\\}``.
  xlsx         :func:`xlsx_text` (at most 32767 characters, Excel's cell limit); :func:`xlsx_put`
               stores text starting with ``= + - @`` as a string cell with Excel's quote prefix,
               never a formula; :func:`xlsx_no_formulas` turns any formula left in a workbook
               camfab writes into such a string.
  G-code       :func:`gcode_comment`: printable ASCII only, ``( )`` → ``[ ]``, ``;`` and ``%``
               → space, at most 240 characters (posts with narrower rules filter further).
  STEP         :func:`step_string`: ISO 10303-21 string content: ``'`` doubled, ``\\`` doubled,
               other non-ASCII as ``\\X2\\hhhh…\\X0\\`` (UTF-16 code units).
  matplotlib   :func:`mpl_text`: ``$`` → ``\\$`` (no mathtext; a stray ``$…$`` cannot crash a plot).
  messages     :func:`bounded`: a message echoed into a manifest or an index page: lines kept, each
               at most 300 characters, at most 10 lines, with ``…``.
  ===========  ==================================================================================

HTML and SVG need nothing here: the report and the package index are Jinja templates with autoescape on,
JSON embedded in a page escapes ``<``, ``>`` and ``&``, and matplotlib escapes SVG text.
"""
from __future__ import annotations

import unicodedata
from collections.abc import Callable, Iterable
from typing import Any

__all__ = ["plain", "excerpt", "bounded", "dxf_string", "dxf_text", "dxf_mtext", "xlsx_text", "xlsx_put",
           "xlsx_no_formulas", "gcode_comment", "step_string", "mpl_text", "DXF_MAX", "XLSX_MAX",
           "MESSAGE_LINE_MAX", "MESSAGE_LINES_MAX", "GCODE_COMMENT_MAX", "ELLIPSIS"]

#: longest DXF string value (R2000 and later, without line end)
DXF_MAX = 2049
#: longest text Excel holds in one cell
XLSX_MAX = 32767
#: longest line, and most lines, of a message echoed into a manifest or index page
MESSAGE_LINE_MAX = 300
MESSAGE_LINES_MAX = 10
ELLIPSIS = "…"
#: longest G-code comment body: with its parentheses within LinuxCNC's 255-character line
GCODE_COMMENT_MAX = 240
#: a text cell starting with one of these is a formula to a spreadsheet program that parses typed input
FORMULA_START = ("=", "+", "-", "@")


def _plain_char(c: str) -> str:
    cat = unicodedata.category(c)
    if cat in ("Cc", "Zl", "Zp"):
        return " "
    return "\ufffd" if cat == "Cs" else c


def plain(text: str) -> str:
    """``text`` with every control character and line/paragraph separator made a space (a lone surrogate
    U+FFFD): one line of printable text."""
    text = str(text)
    if text.isprintable():  # the common case: nothing to do (spaces are printable, controls are not)
        return text
    return "".join(_plain_char(c) for c in text)


def _take(pieces: Iterable[str], limit: int) -> str:
    """The escaped pieces (one per source character) joined, cut before the piece that would pass ``limit``
    characters with an ellipsis (an escape is never split)."""
    out: list[str] = []
    n = 0
    pieces = list(pieces)
    total = sum(map(len, pieces))
    if total <= limit:
        return "".join(pieces)
    for p in pieces:
        if n + len(p) + len(ELLIPSIS) > limit:
            break
        out.append(p)
        n += len(p)
    return "".join(out) + ELLIPSIS


def excerpt(text: str, limit: int = 80) -> str:
    """A short one-line quote of ``text`` (a line of an input file, a formula) for a message; only the first
    ``limit + 1`` characters are looked at (a 1 GB text costs nothing more than a short one)."""
    return _take(plain(str(text)[: limit + 1]), limit)


def bounded(message: str, *, line_max: int = MESSAGE_LINE_MAX, lines_max: int = MESSAGE_LINES_MAX) -> str:
    """A message safe to echo (manifest, index page): its lines kept, each made :func:`plain` and cut at
    ``line_max`` characters, at most ``lines_max`` lines (then a line saying how many were left out)."""
    lines = str(message).splitlines() or [""]
    kept = [_take(plain(ln), line_max) for ln in lines[:lines_max]]
    if len(lines) > lines_max:
        kept.append(f"{ELLIPSIS} ({len(lines) - lines_max} more lines)")
    return "\n".join(kept)


# ---------------------------------------------------------------------------
# DXF
def _dxf_pieces(text: str, extra: Callable[[str, str], str] | None = None) -> list[str]:
    t = plain(text)
    out = []
    for i, c in enumerate(t):
        if c == "^":
            out.append("^ ")  # caret notation: "^ " is a literal caret, "^J" would be a line feed
        elif extra is not None:
            out.append(extra(c, t[i + 1:i + 3]))
        else:
            out.append(c)
    return out


def dxf_string(text: str, *, limit: int = DXF_MAX) -> str:
    """A DXF string value (a header variable, a custom property): one line, carets escaped, at most
    ``limit`` characters.  A newline can no longer start a group code, so no entity can be injected."""
    if _untouched(text, "^", limit):
        return text
    return _take(_dxf_pieces(text), limit)


def _text_extra(c: str, nxt: str) -> str:
    if c == "%":
        return "%%%"  # "%%%" is a literal percent sign; "%%d", "%%u" … would be special codes
    if c == "\\" and nxt.upper() in ("U+", "M+"):
        return "\\U+005C"  # "\U+hhhh" is a Unicode escape in TEXT: write the backslash itself that way
    return c


def dxf_text(text: str, *, limit: int = DXF_MAX) -> str:
    """The value of a DXF TEXT entity: :func:`dxf_string` plus its special codes (``%%``, ``\\U+``) made
    literal."""
    if _untouched(text, "^%\\", limit):
        return text
    return _take(_dxf_pieces(text, _text_extra), limit)


def _untouched(text: Any, specials: str, limit: int | None = None) -> bool:
    """Whether the escaping would give ``text`` back as it is: a printable ``str`` (nothing for :func:`plain`)
    without any of ``specials`` (nothing to escape) and, when a ``limit`` is given, no longer than it (nothing
    to cut).  The common case on a drawing sheet (labels, values, notes), spared the character-by-character
    pass."""
    return (type(text) is str and text.isprintable() and (limit is None or len(text) <= limit)
            and not any(c in text for c in specials))


def _mtext_extra(c: str, nxt: str) -> str:
    if c == "%":
        return "%%%"
    if c in "\\{}":
        return "\\" + c  # MTEXT inline codes start with "\" and group with "{ }"
    return c


def dxf_mtext(text: str) -> str:
    """Text to place inside an MTEXT entity's content: no line breaks (``\\P`` can only come from camfab),
    inline codes, grouping braces, carets and ``%%`` codes literal.  ezdxf splits long content itself."""
    if _untouched(text, "^%\\{}"):
        return text
    return "".join(_dxf_pieces(text, _mtext_extra))


# ---------------------------------------------------------------------------
# xlsx
def xlsx_text(text: str) -> str:
    """Cell or property text: :func:`plain` (openpyxl refuses the control characters XML cannot hold) and
    at most 32767 characters."""
    return _take(plain(text), XLSX_MAX)


def _quote(cell: Any) -> None:
    cell.data_type = "s"  # a string, whatever it starts with
    cell.quotePrefix = True  # Excel's leading apostrophe: still text when the cell is edited


def xlsx_put(cell: Any, value: Any) -> Any:
    """Set an openpyxl ``cell`` to ``value``; text is made :func:`xlsx_text` and, when it starts with
    ``= + - @``, stored as a string with the quote prefix (never a formula).  Returns the cell."""
    if isinstance(value, str):
        value = xlsx_text(value)
        cell.value = value
        if value.startswith(FORMULA_START):
            _quote(cell)
    else:
        cell.value = value
    return cell


def xlsx_no_formulas(wb: Any) -> None:
    """Make every formula cell of a workbook camfab writes (it writes none on purpose: any is text that
    openpyxl took for one) a quoted string cell."""
    for ws in wb.worksheets:
        for cell in ws._cells.values():  # the cells that exist (iter_rows would create the empty ones)
            if cell.data_type == "f":
                _quote(cell)


# ---------------------------------------------------------------------------
# G-code
def gcode_comment(text: str, *, limit: int = GCODE_COMMENT_MAX) -> str:
    """The body of a ``( … )`` comment: printable ASCII (anything else ``?``), parentheses as brackets,
    ``;`` and ``%`` as spaces, runs of white space as one space, at most ``limit`` characters (``...``)."""
    t = plain(text).replace("(", "[").replace(")", "]").replace(";", " ").replace("%", " ")
    t = " ".join("".join(c if 32 <= ord(c) < 127 else "?" for c in t).split())
    return t if len(t) <= limit else t[:limit - 3] + "..."


# ---------------------------------------------------------------------------
# STEP
def step_string(text: str) -> str:
    """The content of an ISO 10303-21 string (between its apostrophes): printable ASCII as is with ``'``
    and ``\\`` doubled, every other character in ``\\X2\\`` … ``\\X0\\`` as UTF-16 code units."""
    out: list[str] = []
    wide: list[str] = []

    def flush() -> None:
        if wide:
            units = "".join(wide).encode("utf-16-be", "surrogatepass").hex().upper()
            out.append(f"\\X2\\{units}\\X0\\")
            wide.clear()

    for c in plain(text):
        if 32 <= ord(c) < 127:
            flush()
            out.append("''" if c == "'" else "\\\\" if c == "\\" else c)
        else:
            wide.append(c)
    flush()
    return "".join(out)


# ---------------------------------------------------------------------------
# matplotlib
def mpl_text(text: str) -> str:
    """Text for a matplotlib title or legend: one line, ``$`` escaped so that no mathtext is parsed."""
    return plain(text).replace("$", r"\$")
