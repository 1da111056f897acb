"""The shipped templates — report pages, the package index, the drawing title block — wherever camfab runs from.

The templates live in the repository's top-level ``templates/`` folder.  A wheel ships them as package data at
``camfab/templates/`` (``pyproject.toml`` maps the package ``camfab.templates`` to that folder), and they are read
through :mod:`importlib.resources`.  An editable install (``pip install -e .``) or a plain checkout on
``sys.path`` has no ``camfab/templates/``: there the folder beside the package, ``<checkout>/templates/``, is
the one.  Only the location of the ``camfab`` package decides, never another installed copy of camfab
(``docs/decisions.md, "Where the templates and the examples live"``).

>>> "report.html.j2" in {p.name for p in templates().joinpath("report").iterdir()}
True
"""
from __future__ import annotations

import functools
import hashlib
from importlib import resources
from importlib.resources.abc import Traversable
from pathlib import Path

from .errors import MissingDependencyError

__all__ = ["read_template", "templates", "templates_hash"]

#: the folders every copy of the templates has (an empty leftover ``camfab/templates/`` is not a copy)
_FOLDERS = ("report", "package", "drawing")


def _complete(node: Traversable) -> bool:
    return node.is_dir() and all(node.joinpath(name).is_dir() for name in _FOLDERS)


@functools.lru_cache(maxsize=1)
def templates() -> Traversable:
    """The folder of the shipped templates (``report/``, ``package/``, ``drawing/``).

    Raises
    ------
    MissingDependencyError
        When neither an installed ``camfab/templates/`` nor a checkout's ``templates/`` is there (a broken
        install: the command line exits 3, as for any missing part of the installation).
    """
    shipped = resources.files("camfab").joinpath("templates")
    if _complete(shipped):
        return shipped
    checkout = Path(__file__).resolve().parent.parent / "templates"
    if _complete(checkout):
        return checkout
    raise MissingDependencyError(f"camfab's templates are missing: neither {shipped} nor {checkout} exists; "
                                 "reinstall camfab")


def read_template(*parts: str) -> str:
    """The text (UTF-8) of one template, e.g. ``read_template("report", "report.css")``."""
    node = templates()
    for part in parts:
        node = node.joinpath(part)
    return node.read_text(encoding="utf-8")


def _files(node: Traversable, prefix: tuple[str, ...] = ()) -> list[tuple[tuple[str, ...], Traversable]]:
    out: list[tuple[tuple[str, ...], Traversable]] = []
    for child in node.iterdir():
        if child.name == "__pycache__":
            continue
        if child.is_dir():
            out += _files(child, (*prefix, child.name))
        elif child.is_file():
            out.append(((*prefix, child.name), child))
    return out


def templates_hash() -> str:
    """sha256 over every template's relative path and bytes, in path order: a package's input keys change
    when a template does (the same value wherever the templates were loaded from)."""
    h = hashlib.sha256()
    for parts, f in sorted(_files(templates()), key=lambda item: item[0]):
        h.update("/".join(parts).encode())
        h.update(f.read_bytes())
    return h.hexdigest()
