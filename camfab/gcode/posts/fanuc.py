"""Fanuc-style post-processor (0i/30i family and the many controls that copy it).

* program between ``%`` lines, ``O`` number (option ``program_number``, 1..9999, default 1000);
* ``N`` words on every block (option ``line_number_step``, default 10), comments unnumbered;
* every coordinate with a decimal point (``X10.0000``, never ``X10`` = 10 um on a Fanuc);
* ``T.. M6`` then ``G43 H..`` on the first Z rapid; ``S.. M3``; ``M8``/``M7``/``M9``; end ``M30``;
* arcs by incremental ``I J`` (option ``arc_format="ij"``, default; arcs over 180 degrees split) or by
  ``R`` (``arc_format="r"``): ``R`` cannot describe a full circle and is ill-conditioned near 180
  degrees, so every R arc is split into pieces of at most 90 degrees and R is always positive;
* comments upper case, only ``A-Z 0-9 space . , - + / = * # _``.
"""
from __future__ import annotations

import re

from camfab.errors import InputError
from camfab.gcode.posts.base import Post

__all__ = ["FanucPost", "POST"]


class FanucPost(Post):
    """Fanuc-style dialect."""

    name = "fanuc"
    percent = True
    program_number = True
    line_numbers = True
    end_code = "M30"
    arc_formats = ("ij", "r")
    defaults = {"arc_format": "ij", "program_number": 1000, "line_number_step": 10}

    def sanitize_comment(self, text: str) -> str:
        t = re.sub(r"[^A-Z0-9 .,\-+/=*#_]", " ", text.upper())
        return re.sub(r"\s+", " ", t).strip()[:60]

    def check_options(self, options: dict) -> dict:
        opts = super().check_options(options)
        o = opts["program_number"]
        if isinstance(o, bool) or not isinstance(o, int) or not 1 <= o <= 9999:
            raise InputError(f"post 'fanuc': program_number must be an integer 1..9999, got {o!r}")
        s = opts["line_number_step"]
        if isinstance(s, bool) or not isinstance(s, int) or not 1 <= s <= 100:
            raise InputError(f"post 'fanuc': line_number_step must be an integer 1..100, got {s!r}")
        return opts


#: the registered instance
POST = FanucPost()
