"""Files read or written as data: design files (TOML, xlsx) and knot tables (CSV/text, xlsx).

The design core (:mod:`camfab.design`) reads no files; this package reads them once
and hands the data over.

Modules
-------
``design_files``
    :func:`load_design` (TOML or xlsx, by suffix) and the built-in examples by name.
``toml_design``
    TOML design files, and design dicts whose knot file is read relative to a folder.
``xlsx_design``
    Design workbooks: read one, and write a spec back (:func:`design_to_xlsx`).
``knot_files``
    Knot rows from CSV/text and xlsx files; a ``[motion_table]``'s ``file`` read.
``camdas_workbook``
    The CAM-DAS results workbook of a checked cam (tables, conclusions, lift table, dynamics).

Examples
--------
>>> from camfab.formats import load_design, resolve_design_path
>>> spec = load_design(resolve_design_path("valve_exhaust_ej1"))
>>> [p.rsplit("/", 1)[-1] for p in spec.sources]
['valve_exhaust_ej1.toml', 'valve_recon_ej1.csv']
"""
from __future__ import annotations

from typing import TYPE_CHECKING, Any

from .design_files import EXAMPLES_DIR, load_design, resolve_design_path
from .knot_files import (
    load_motion_table,
    read_knot_file,
    read_knots,
    read_knots_csv,
    read_knots_xlsx,
    resolve_knot_file,
)
from .toml_design import design_from_data, load_design_toml

if TYPE_CHECKING:
    from .xlsx_design import design_rows, design_to_xlsx, load_design_xlsx

#: the workbook side, imported on first use (a TOML design's ``check`` does not need it).  The CAM-DAS results
#: workbook is ``camdas_workbook.camdas_workbook``: a lazy re-export of a function named like its module would be
#: replaced by the module whenever another import loads it first.
_LAZY = {"design_rows": "xlsx_design", "design_to_xlsx": "xlsx_design", "load_design_xlsx": "xlsx_design"}


def __getattr__(name: str) -> Any:
    if name in _LAZY:
        import importlib

        return getattr(importlib.import_module(f"{__name__}.{_LAZY[name]}"), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


__all__ = [
    "EXAMPLES_DIR",
    "design_from_data",
    "design_rows",
    "design_to_xlsx",
    "load_design",
    "load_design_toml",
    "load_design_xlsx",
    "load_motion_table",
    "read_knot_file",
    "read_knots",
    "read_knots_csv",
    "read_knots_xlsx",
    "resolve_design_path",
    "resolve_knot_file",
]
