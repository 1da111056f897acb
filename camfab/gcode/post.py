"""Post-processor registry: ``dumps(program, post)`` and the atomic ``write_gcode``.

Examples
--------
>>> from camfab.gcode import Job, Segment, contour_toolpath
>>> circle = [Segment((20, 0), (20, 0), center=(0, 0))]
>>> prog = contour_toolpath(circle, Job(tool_diameter_mm=6, depth_mm=5, roughing_passes=0))
>>> text = dumps(prog, "fanuc", arc_format="r")
>>> text.splitlines()[0]
'%'
"""
from __future__ import annotations

from pathlib import Path

from camfab.errors import InputError
from camfab.gcode.model import Program
from camfab.gcode.posts.base import Post
from camfab.gcode.posts.fanuc import POST as _FANUC
from camfab.gcode.posts.grbl import POST as _GRBL
from camfab.gcode.posts.linuxcnc import POST as _LINUXCNC
from camfab.io import atomic_write

__all__ = ["POSTS", "get_post", "dumps", "write_gcode"]

#: registered post-processors by name
POSTS: dict[str, Post] = {"linuxcnc": _LINUXCNC, "fanuc": _FANUC, "grbl": _GRBL}


def get_post(post: str | Post) -> Post:
    """Look a post-processor up by name (a :class:`Post` instance passes through).

    Raises
    ------
    InputError
        Unknown name (a ``ValueError``); the message lists the valid ones.
    """
    if isinstance(post, Post):
        return post
    try:
        return POSTS[post]
    except (KeyError, TypeError):
        raise InputError(f"unknown post-processor {post!r}; valid: {', '.join(sorted(POSTS))}") from None


def dumps(program: Program, post: str | Post, **options) -> str:
    """Write ``program`` as G-code text for controller ``post``.

    Parameters
    ----------
    program : Program
        From :func:`camfab.gcode.contour_toolpath`.
    post : {"linuxcnc", "fanuc", "grbl"} or Post
    **options
        Post options: fanuc ``arc_format`` ("ij"|"r"), ``program_number``, ``line_number_step``;
        grbl ``coolant`` (bool), ``mist`` (bool).

    Returns
    -------
    str
        Deterministic text, ``\\n`` line ends, final newline.
    """
    return get_post(post).dumps(program, **options)


def write_gcode(path: str | Path, program: Program, post: str | Post, **options) -> Path:
    """Write the program atomically (temp file + rename) and return the path."""
    return atomic_write(path, dumps(program, post, **options))
