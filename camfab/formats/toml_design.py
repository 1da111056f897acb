"""TOML design files → :class:`~camfab.design.spec.DesignSpec`, and design dicts with the files they name.

A design is read once: the TOML text is parsed, the knot file its ``[motion_table]``
names is read relative to the design file's folder, and the data are handed to
:func:`camfab.design.spec.design_from_dict`, which validates them.  The spec
records the files it was built from (:attr:`~camfab.design.spec.DesignSpec.sources`).
"""
from __future__ import annotations

import tomllib
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from ..design.spec import DesignSpec, design_from_dict
from ..errors import Problem, SpecError
from ..limits import MAX_NESTING
from .input_limits import read_text_limited
from .knot_files import resolve_knot_file

__all__ = ["design_from_data", "load_design_toml"]


def load_design_toml(path: str | Path, *, allow_outside_files: bool = False) -> DesignSpec:
    """Read and validate a TOML design file (its name defaults to the file's stem); its knot file must lie in
    its folder unless ``allow_outside_files`` (:mod:`camfab.formats.knot_files`).

    Raises
    ------
    SpecError
        A missing, unreadable, non-TOML or over-limit file (naming the file and the line), or every
        problem of the design.
    """
    p = Path(path)
    try:
        text = read_text_limited(p, field="file")
    except FileNotFoundError:
        raise SpecError(Problem("file", str(p), "no such design file", "check the path"), str(p)) from None
    except (OSError, UnicodeDecodeError) as exc:
        raise SpecError(Problem("file", str(p), f"cannot be read ({exc})",
                                "give a UTF-8 TOML design file"), str(p)) from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise SpecError(Problem("file", p.name, f"is not valid TOML: {exc}",
                                "fix the TOML syntax at the line named"), str(p)) from None
    except RecursionError:  # tomllib parses nested brackets recursively
        raise SpecError(Problem("file", p.name, f"nesting too deep (more than {MAX_NESTING} levels of tables "
                                "and arrays)", "a design nests at most motion_table.rows[i][k]; remove the "
                                "extra brackets"), str(p)) from None
    data.setdefault("name", p.stem)
    return design_from_data(data, source=str(p), base_dir=p.parent, allow_outside_files=allow_outside_files)


def design_from_data(data: Mapping[str, Any], *, source: str | None = None,
                     base_dir: str | Path | None = None, allow_outside_files: bool = False) -> DesignSpec:
    """Validate a design dict (the TOML structure), reading the knot file its ``[motion_table]`` names.

    Parameters
    ----------
    data : Mapping
        The design.
    source : str, optional
        The design file, named in messages.
    base_dir : str or Path, optional
        Folder a relative ``motion_table.file`` is resolved against (the design file's folder;
        default: the current directory).  When given, the file must lie in it or below it.
    allow_outside_files : bool
        Read a ``motion_table.file`` outside ``base_dir`` too (a design the caller trusts).

    Raises
    ------
    SpecError
        Every problem found, the knot file's included.
    """
    if "motion_table" in data:
        data = {**data, "motion_table": resolve_knot_file(data["motion_table"], base_dir,
                                                          allow_outside_files=allow_outside_files)}
    return design_from_dict(data, source=source)
