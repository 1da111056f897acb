"""camfab: cam mechanisms from design data to exact profiles, checks and shop-ready files.

Public names are re-exported here; import submodules only for what this façade
does not offer.  Heavy optional dependencies (cadquery) are never imported by
``import camfab``.
"""
from __future__ import annotations

__version__ = "0.1.0"

from .errors import CamfabError, ExportError, GeometryError, MissingDependencyError, Problem, SpecError
from .design import (
    LAWS,
    DesignSpec,
    MotionProgram,
    analyse_motion,
    build_program,
    design_from_dict,
)
from .formats import load_design

__all__ = [
    "__version__",
    "CamfabError",
    "SpecError",
    "GeometryError",
    "ExportError",
    "MissingDependencyError",
    "Problem",
    "LAWS",
    "MotionProgram",
    "build_program",
    "DesignSpec",
    "load_design",
    "design_from_dict",
    "analyse_motion",
]
