"""GRBL 1.1 post-processor (hobby routers and mills).

GRBL accepts a small G-code subset and rejects the rest with ``error:20`` (unsupported command):

* no ``%``, no ``O`` numbers, no line numbers, no ``M6`` (a comment asks for the tool), no ``G43 H``
  (only ``G43.1``), no G41/G42 (a compensated program raises :class:`~camfab.errors.ExportError`),
  no ``G49`` or ``G80`` in the safety block;
* lines at most 80 characters (GRBL's line buffer), comments single-level ``( )``, printable ASCII
  ``A-Z a-z 0-9 space . , - + / = * # _ :`` only, at most 70 characters;
* arcs by incremental ``I J`` split above 180 degrees; ``M8`` flood coolant when the option
  ``coolant`` is true (default; set it false for machines without a coolant pin), mist ``M7`` only when
  ``mist=True`` (a compile-time option in GRBL; otherwise flood ``M8`` is used); end ``M2``.
"""
from __future__ import annotations

import re

from camfab.errors import InputError
from camfab.gcode.posts.base import Post

__all__ = ["GrblPost", "POST"]


class GrblPost(Post):
    """GRBL 1.1 dialect."""

    name = "grbl"
    tool_change = False
    length_offset = False
    compensation = False
    end_code = "M2"
    defaults = {"coolant": True, "mist": False}

    def preamble(self, units: str) -> list[str]:
        """G17 XY plane, G21/G20, G40 compensation off, G54, G90 absolute, G91.1 incremental arc centres (GRBL's
        only mode, stated), G94 feed per minute."""
        return ["G17", "G20" if units == "inch" else "G21", "G40", "G54", "G90", "G91.1", "G94"]

    def sanitize_comment(self, text: str) -> str:
        t = re.sub(r"[^A-Za-z0-9 .,\-+/=*#_:]", " ", text)
        return re.sub(r"\s+", " ", t).strip()[:70]

    def check_options(self, options: dict) -> dict:
        opts = super().check_options(options)
        for k in ("coolant", "mist"):
            if not isinstance(opts[k], bool):
                raise InputError(f"post 'grbl': {k} must be true or false, got {opts[k]!r}")
        return opts

    def coolant_code(self, mode: str, opts: dict) -> str:
        if mode == "mist":
            return "M7" if opts["mist"] else "M8"
        return super().coolant_code(mode, opts)


#: the registered instance
POST = GrblPost()
