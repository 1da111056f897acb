"""IGES of the cam plate (for older CAM systems), through OpenCascade's IGES writer, reproducible.

The solid is the STEP's (:func:`camfab.cad.step.plate_solid`: exact lines and arcs; a groove cam's pocketed
plate, a cylindrical cam's grooved cylinder: :func:`shape_dumps`), written as an IGES 5.3 B-rep (manifold solid,
type 186).  The global section names camfab and the design's file stem; its two dates are
the STEP header's time stamp (``docs/decisions.md``, "STEP header": ``SOURCE_DATE_EPOCH`` or 1970-01-01), so the
file is byte-identical from run to run.
"""
from __future__ import annotations

import re
import tempfile
from pathlib import Path

from ..errors import ExportError
from ..geom2d import ArcChain
from ..io import safe_stem
from ..version import __version__
from .plate import PlateSpec
from .step import cadquery, plate_solid
from .stepheader import step_timestamp

__all__ = ["dumps", "outlines", "shape_dumps"]

_DATE = re.compile(r"15H\d{8}\.\d{6}")


def outlines(shapes, tol: float) -> tuple[list, list[float]]:
    """The plate outlines an IGES file extrudes (:func:`~camfab.cad.export.solid_outlines`).

    Raises
    ------
    ExportError
        A groove cam: its plate is a pocketed solid, not one extruded outline
        (:func:`camfab.cad.groove.groove_iges` writes it).
    """
    from .export import solid_outlines

    if shapes.groove:
        raise ExportError("a groove cam's IGES is its pocketed plate (camfab.cad.groove.groove_iges), not one "
                          "extruded outline")
    return solid_outlines(shapes, tol)


def dumps(outline: ArcChain, plate: PlateSpec, *, name: str = "cam") -> str:
    """IGES text of the plate (mm), byte-identical for the same input."""
    cadquery()  # MissingDependencyError when cadquery (and its OCP) is missing
    return shape_dumps(plate_solid(outline, plate).val(), name=name)


def shape_dumps(solid, *, name: str = "cam") -> str:
    """IGES text of any cadquery solid (mm; a groove cam's pocketed plate, a grooved cylinder), the global
    section as :func:`dumps` writes it."""
    cadquery()
    from OCP.IGESControl import IGESControl_Writer
    from OCP.TCollection import TCollection_HAsciiString

    stamp = step_timestamp().replace("-", "").replace(":", "").replace("T", ".")  # YYYYMMDD.HHNNSS
    writer = IGESControl_Writer("MM", 1)  # 1: B-rep solids (type 186), not trimmed faces
    writer.AddShape(solid.wrapped)
    writer.ComputeModel()
    model = writer.Model()
    gs = model.GlobalSection()
    ascii_ = TCollection_HAsciiString
    gs.SetFileName(ascii_(f"{safe_stem(name)}.igs"))  # safe_stem: ASCII letters, digits, . _ -
    gs.SetSendName(ascii_("camfab"))
    gs.SetSystemId(ascii_(f"camfab {__version__}"))
    gs.SetAuthorName(ascii_(""))
    gs.SetCompanyName(ascii_("camfab"))
    gs.SetDate(ascii_(stamp))
    model.SetGlobalSection(gs)
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "cam.igs"  # never a path built from the name
        writer.Write(str(path))
        text = path.read_text(encoding="ascii", errors="replace")
    head, body = _split_global(text)
    return _DATE.sub(f"15H{stamp}", head) + body  # the last-change date OpenCascade sets to the time of writing


def _split_global(text: str) -> tuple[str, str]:
    """(the start and global sections, the rest): the lines whose column 73 is S or G come first."""
    lines = text.splitlines(keepends=True)
    n = next((i for i, line in enumerate(lines) if len(line) > 72 and line[72] not in "SG"), len(lines))
    return "".join(lines[:n]), "".join(lines[n:])
