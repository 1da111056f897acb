"""camfab: cam mechanisms from design data to exact profiles, checks and shop-ready files.

The public API, in the style of ezdxf and trimesh: :func:`load` a design (a file or a built-in example's
name) into a :class:`Cam`, then ask it for what you need — its check report, its exact profile at any
angle, its files::

    >>> import camfab
    >>> cam = camfab.load("ejemplo9rt")
    >>> cam.check().verdict
    <Verdict.NOT_FOR_HIGH_SPEED: 'not_for_high_speed'>
    >>> "ejemplo9rt" in camfab.examples()
    True

Import submodules only for what this façade does not offer.  ``import camfab`` stays light (no numpy): the
design names are imported on first use, the pipeline
(and with it the exporters) is imported on first use of :func:`load`, :class:`Cam` or :func:`examples`, and
heavy optional dependencies (cadquery, matplotlib) only by the artifacts that need them.

Errors: everything camfab raises on purpose is a :class:`CamfabError` (see :mod:`camfab.errors`); the
classes that replaced a builtin also derive from it (:class:`InputError` is a ``ValueError``).

Logging: camfab logs the fallbacks it takes (a slower fit, a capped iteration, an unreadable manifest) to
the logger ``"camfab"`` — every module logs to ``logging.getLogger(__name__)``, a child such as
``"camfab.cad.export"`` — and prints nothing itself.  The logger has a ``NullHandler``; configure
``logging`` (or run ``camfab -v``) to see the records.
"""
from __future__ import annotations

import logging
from typing import TYPE_CHECKING, Any

from .errors import (
    ApiError,
    CamfabError,
    ExportError,
    GeometryError,
    InputError,
    InternalError,
    MissingDependencyError,
    Problem,
    SpecError,
)
from .version import __version__

if TYPE_CHECKING:
    from .design import LAWS, DesignSpec, MotionProgram, analyse_motion, build_program, design_from_dict
    from .formats import load_design
    from .pipeline import Cam, examples, load

__all__ = [
    "__version__",
    "load",
    "examples",
    "Cam",
    "CamfabError",
    "SpecError",
    "GeometryError",
    "ExportError",
    "MissingDependencyError",
    "InputError",
    "ApiError",
    "InternalError",
    "Problem",
    "LAWS",
    "MotionProgram",
    "build_program",
    "DesignSpec",
    "load_design",
    "design_from_dict",
    "analyse_motion",
]

_LAZY = ("load", "examples", "Cam")
#: the design names, imported on first use too: ``import camfab`` loads no numpy, so ``python -m camfab`` can set
#: the BLAS thread count before numpy starts (docs/decisions.md, "Start-up and export time")
_LAZY_DESIGN = ("LAWS", "DesignSpec", "MotionProgram", "analyse_motion", "build_program", "design_from_dict")

logging.getLogger(__name__).addHandler(logging.NullHandler())


def __getattr__(name: str) -> Any:
    """:func:`load`, :func:`examples` and :class:`Cam` come from :mod:`camfab.pipeline`, imported on first use."""
    if name in _LAZY:
        from . import pipeline

        return getattr(pipeline, name)
    if name in _LAZY_DESIGN:
        from . import design

        return getattr(design, name)
    if name == "load_design":
        from .formats import load_design

        return load_design
    if name in ("design", "formats", "results", "errors", "geom2d"):  # as when __init__ imported them
        import importlib

        return importlib.import_module(f"{__name__}.{name}")
    raise AttributeError(f"module 'camfab' has no attribute {name!r}")
