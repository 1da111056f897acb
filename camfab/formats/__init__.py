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

from .camdas_workbook import camdas_workbook
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
from .xlsx_design import design_rows, design_to_xlsx, load_design_xlsx

__all__ = [
    "EXAMPLES_DIR",
    "camdas_workbook",
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
