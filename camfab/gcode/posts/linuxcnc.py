"""LinuxCNC post-processor.

* no ``%`` delimiters, no line numbers (LinuxCNC ignores them), program end ``M2``;
* ``T.. M6`` then ``G43 H..`` on the first rapid; ``S.. M3``; ``M8``/``M7``/``M9``;
* arcs ``G2``/``G3`` with incremental ``I J`` (LinuxCNC default ``G91.1``), arcs over 180 degrees split;
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

    def sanitize_comment(self, text: str) -> str:
        t = super().sanitize_comment(text)
        return "- " + t if _ACTIVE.match(t) else t


#: the registered instance
POST = LinuxCNCPost()
