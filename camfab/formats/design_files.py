"""Design files of either format, chosen by suffix (TOML or xlsx), and the built-in examples by name."""
from __future__ import annotations

from pathlib import Path

from ..design.spec import DesignSpec
from .toml_design import load_design_toml
from .xlsx_design import load_design_xlsx

__all__ = ["EXAMPLES_DIR", "load_design", "resolve_design_path"]

#: the built-in example designs (TOML files and the knot files they name): data shipped inside the package
#: (``camfab/examples/``), apart from the templates
EXAMPLES_DIR = Path(__file__).resolve().parent.parent / "examples"


def load_design(path: str | Path) -> DesignSpec:
    """Read and validate a design file: TOML, or an xlsx workbook (``*.xlsx``, see
    :mod:`camfab.formats.xlsx_design`).

    Raises
    ------
    SpecError
        On unreadable or invalid files; every problem found is listed.
    """
    p = Path(path)
    return load_design_xlsx(p) if p.suffix.lower() == ".xlsx" else load_design_toml(p)


def resolve_design_path(name: str | Path) -> Path:
    """A design path, or the name of a built-in example (``ejemplo9rt``, any case).

    A name that is neither is returned as a path, so that :func:`load_design` reports the
    missing file.
    """
    p = Path(name)
    if p.exists():
        return p
    for cand in sorted(EXAMPLES_DIR.glob("*.toml")):
        if cand.stem.lower() == str(name).lower():
            return cand
    return p
