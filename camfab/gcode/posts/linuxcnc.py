"""LinuxCNC post-processor.

* no ``%`` delimiters, no line numbers (LinuxCNC ignores them), program end ``M2``;
* ``T.. M6`` then ``G43 H..`` on the first rapid; ``S.. M3``; ``M8``/``M7``/``M9``;
* arcs ``G2``/``G3`` with incremental ``I J``, stated in the safety block (``G91.1``), arcs over 180 degrees
  split;
* the safety block states every mode the program relies on: ``G17 G21|G20 G40 G49 G54 G80 G90 G91.1 G94 G97``;
* comments in ``( )``; parentheses inside become ``[ ]`` and a comment never starts like the active
  comments ``MSG,``, ``DEBUG,``, ``PRINT,``, ``LOG...``, ``PROBE...``;
* G41/G42 cutter compensation supported (entry move a straight line).
"""
from __future__ import annotations

import re

from camfab.gcode.posts.base import Post

__all__ = ["LinuxCNCPost", "POST"]

_ACTIVE = re.compile(r"^\s*(msg|debug|print|log\w*|probe\w*)\s*,", re.IGNORECASE)


class LinuxCNCPost(Post):
    """LinuxCNC (rs274ngc) dialect."""

    name = "linuxcnc"
    end_code = "M2"

    def preamble(self, units: str) -> list[str]:
        """G17 XY plane, G21/G20, G40 G49 G80 off, G54, G90 absolute, G91.1 incremental arc centres, G94 feed per
        minute, G97 spindle rpm."""
        return ["G17", "G20" if units == "inch" else "G21", "G40", "G49", "G54", "G80", "G90", "G91.1", "G94",
                "G97"]

    def sanitize_comment(self, text: str) -> str:
        t = super().sanitize_comment(text)
        return "- " + t if _ACTIVE.match(t) else t


#: the registered instance
POST = LinuxCNCPost()
