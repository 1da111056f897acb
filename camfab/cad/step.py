"""STEP export of the cam plate through cadquery (OCCT), imported only here.

The outline and bore keep their exact lines and circular arcs (no tessellation).
The file is made deterministic by fixing the timestamp in the STEP header.
"""
from __future__ import annotations

import re
import signal
import tempfile
import threading
from pathlib import Path

from ..errors import MissingDependencyError
from ..geom2d import ArcChain, bulge_midpoint
from ..textsafe import step_string
from .plate import PlateSpec
from .stepheader import StepMeta, header_dumps

__all__ = ["plate_solid", "groove_solid", "dumps", "groove_dumps", "stack_dumps", "solid_dumps", "canonical_reals",
           "cadquery"]


def cadquery():
    """The cadquery module (MissingDependencyError when it is not installed: it is a dependency of camfab,
    but an install may lack it).

    A Ctrl-C during the import (one to three seconds of a command's start) is a ``KeyboardInterrupt``, never the
    missing dependency: OCP's extension modules turn the interrupt raised in their initialisation into
    ``ImportError('initialization failed')``, or cadquery's optional imports swallow it and a later one fails on a
    half-made module.  So an import that fails while SIGINT came (noted by a handler that then calls the one in
    place), or whose error chain holds the interrupt, raises ``KeyboardInterrupt``; so does one that succeeded
    after swallowing it."""
    came: list[int] = []
    prev = signal.getsignal(signal.SIGINT)
    own = threading.current_thread() is threading.main_thread() and callable(prev)

    def note(signum, frame):
        came.append(signum)
        prev(signum, frame)  # type: ignore[operator]

    if own:
        signal.signal(signal.SIGINT, note)
    try:
        import cadquery as cq
    except ImportError as exc:
        if came or _holds_interrupt(exc):
            signal.default_int_handler(signal.SIGINT, None)  # raises KeyboardInterrupt (its context: ``exc``)
        raise MissingDependencyError("STEP export needs cadquery, a dependency of camfab that this install lacks: "
                                     "pip install cadquery (or reinstall camfab)") from exc
    finally:
        if own and signal.getsignal(signal.SIGINT) is note:  # (the handler in place may have replaced itself)
            signal.signal(signal.SIGINT, prev)
    if came:
        signal.default_int_handler(signal.SIGINT, None)  # raises KeyboardInterrupt
    return cq


def _holds_interrupt(exc: BaseException) -> bool:
    """Whether a ``KeyboardInterrupt`` is among the causes and contexts of ``exc``."""
    seen: set[int] = set()
    todo: list[BaseException | None] = [exc]
    while todo:
        e = todo.pop()
        if e is None or id(e) in seen:
            continue
        if isinstance(e, KeyboardInterrupt):
            return True
        seen.add(id(e))
        todo += [e.__cause__, e.__context__]
    return False


_cq = cadquery


def _wire(cq, loop: ArcChain, z: float = 0.0):
    wp = cq.Workplane("XY", origin=(0, 0, z)).moveTo(*loop.points[0])
    for p0, p1, b in loop.segments():
        wp = wp.lineTo(*p1) if abs(b) < 1e-15 else wp.threePointArc(tuple(bulge_midpoint(p0, p1, b)), tuple(p1))
    return wp.close() if loop.closed else wp


def plate_solid(outline: ArcChain, plate: PlateSpec):
    """The plate as a cadquery ``Workplane`` holding one valid solid (z = 0 … thickness [+ hub])."""
    cq = _cq()
    body = _wire(cq, outline).extrude(plate.thickness_mm)
    if plate.hub_diameter_mm and plate.hub_length_mm:
        hub = (cq.Workplane("XY", origin=(0, 0, plate.thickness_mm))
               .circle(plate.hub_diameter_mm / 2).extrude(plate.hub_length_mm))
        body = body.union(hub)
    hole = plate.hole()
    if hole is not None:
        height = plate.thickness_mm + (plate.hub_length_mm or 0.0) + 2.0
        body = body.cut(_wire(cq, hole, -1.0).extrude(height))
    return body


def groove_solid(outline: ArcChain, inner: ArcChain, outer: ArcChain, plate: PlateSpec, depth_mm: float):
    """A groove cam's plate: :func:`plate_solid` of ``outline`` with the region between the ``inner`` and
    ``outer`` flank loops pocketed from the face z = 0 (the face opposite the hub) up to z = ``depth_mm``."""
    cq = _cq()
    body = plate_solid(outline, plate)
    tall = depth_mm + 1.0
    pocket = _wire(cq, outer, -1.0).extrude(tall).cut(_wire(cq, inner, -2.0).extrude(tall + 2.0))
    return body.cut(pocket)


def groove_dumps(outline: ArcChain, inner: ArcChain, outer: ArcChain, plate: PlateSpec, depth_mm: float, *,
                 name: str = "cam", meta: StepMeta | None = None) -> str:
    """STEP text of a groove cam's plate (:func:`groove_solid`), as :func:`dumps`."""
    return _export(groove_solid(outline, inner, outer, plate, depth_mm), name, meta)


def dumps(outline: ArcChain, plate: PlateSpec, *, name: str = "cam", meta: StepMeta | None = None) -> str:
    """STEP (AP214) text of the plate, in millimetres, byte-identical for the same input (header: ``meta``, by
    default derived from ``name``, :mod:`.stepheader`)."""
    return _export(plate_solid(outline, plate), name, meta)


def stack_dumps(outlines, plate: PlateSpec, *, gap_mm: float = 2.0, name: str = "cam",
                meta: StepMeta | None = None) -> str:
    """Several plates on one shaft (a conjugate pair): plate i at z = i·(thickness + hub + gap)."""
    cq = _cq()
    pitch = plate.thickness_mm + (plate.hub_length_mm or 0.0) + gap_mm
    solids = [plate_solid(o, plate).val().translate(cq.Vector(0, 0, i * pitch)) for i, o in enumerate(outlines)]
    return _export(cq.Workplane("XY").add(cq.Compound.makeCompound(solids)), name, meta)


def solid_dumps(solid, *, name: str = "cam", meta: StepMeta | None = None) -> str:
    """STEP text of any cadquery solid (or Workplane), with camfab's header and canonical reals."""
    return _export(solid, name, meta)


def _export(solid, name: str, meta: StepMeta | None = None) -> str:
    cq = _cq()
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "cam.step"  # never a path built from the name
        cq.exporters.export(solid, str(path), "STEP")
        text = path.read_text(encoding="utf-8", errors="replace")
    text = header_dumps(text, name, meta)  # camfab's header: name, organisation, reproducible timestamp
    product = step_string(name)  # the full name, as an ISO 10303-21 string (a function: no backslash expansion)
    text = re.sub(r"Open CASCADE STEP translator [0-9.]+ [0-9]+", lambda m: product, text)
    return canonical_reals(canonical_occurrences(text))


_NAUO = re.compile(r"NEXT_ASSEMBLY_USAGE_OCCURRENCE\('[^']*'")


def canonical_occurrences(text: str) -> str:
    """``text`` with its usage occurrences (the solids of a compound, the parts of an assembly) numbered 1, 2 …
    in file order: OpenCascade numbers them from a counter of the process, so a conjugate pair written after
    another file in the same process (a ``package`` worker, a script) had other ids than in a fresh one."""
    counter = iter(range(1, 1 << 30))
    return _NAUO.sub(lambda m: f"NEXT_ASSEMBLY_USAGE_OCCURRENCE('{next(counter)}'", text)


def canonical_reals(text: str) -> str:
    """``text`` with every real of its DATA section rounded to 12 significant digits (see below)."""
    head, sep, data = text.partition("DATA;")
    return head + sep + _REAL.sub(_canonical_real, data)


# OCCT's booleans leave run-to-run noise of ~1e-16 in some coordinates; rounding every real
# to 12 significant digits (1e-12 relative, far below any tolerance) makes the file reproducible.
_REAL = re.compile(r"(?<![#\w])-?\d+\.\d*(?:E[+-]?\d+)?")


def _canonical_real(m: re.Match) -> str:
    v = float(m.group(0))
    if abs(v) < 1e-12:
        return "0."
    out = f"{v:.12G}"
    if "." not in out:
        out = out.replace("E", ".E") if "E" in out else out + "."
    return out
