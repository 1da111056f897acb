"""Design files of either format, chosen by suffix (TOML or xlsx), and the built-in examples by name."""
from __future__ import annotations

from pathlib import Path

from ..design.spec import DesignSpec
from ..errors import Problem, SpecError
from .toml_design import load_design_toml

__all__ = ["EXAMPLES_DIR", "load_design", "resolve_design_path"]

#: the built-in example designs (TOML files and the knot files they name): data shipped inside the package
#: (``camfab/examples/``), apart from the templates
EXAMPLES_DIR = Path(__file__).resolve().parent.parent / "examples"


def load_design(path: str | Path, *, allow_outside_files: bool = False) -> DesignSpec:
    """Read and validate a design file: TOML, or an xlsx workbook (``*.xlsx``, see
    :mod:`camfab.formats.xlsx_design`).  A knot file it names must lie in its folder (or below) unless
    ``allow_outside_files`` (:mod:`camfab.formats.knot_files`).

    Raises
    ------
    SpecError
        On unreadable or invalid files; every problem found is listed.
    """
    p = Path(path)
    if p.suffix.lower() == ".xlsx":
        from .xlsx_design import load_design_xlsx  # the workbook reader only for a workbook

        return load_design_xlsx(p, allow_outside_files=allow_outside_files)
    return load_design_toml(p, allow_outside_files=allow_outside_files)


def resolve_design_path(name: str | Path) -> Path:
    """A design path, or the name of a built-in example (``ejemplo9rt``, any case).

    A bare name (no folder, no suffix) that is neither raises a :class:`SpecError` naming the closest
    examples; any other missing path is returned, so that :func:`load_design` reports the missing file.
    """
    p = Path(name)
    if p.exists():
        return p
    names = sorted(c.stem for c in EXAMPLES_DIR.glob("*.toml"))
    for stem in names:
        if stem.lower() == str(name).lower():
            return EXAMPLES_DIR / f"{stem}.toml"
    if not p.suffix and len(p.parts) == 1:
        import difflib  # only for a misspelt name

        close = difflib.get_close_matches(str(name).lower(), names, n=3, cutoff=0.6)
        hint = "did you mean " + " or ".join(f"'{c}'" for c in close) + "? " if close else ""
        raise SpecError(Problem("file", str(name), "no such design file or built-in example",
                                f"{hint}`camfab examples` lists the built-in examples"), str(name))
    return p
