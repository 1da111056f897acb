"""The plate DXF's text written directly, byte-identical to ezdxf's.

(And the cylindrical cam's developed DXF, :func:`developed`: the same skeleton, layers and LWPOLYLINEs.)

:func:`camfab.cad.dxf.dumps` writes a :class:`~camfab.cad.dxf.DxfContent` through this module instead of
building an ezdxf document: importing ezdxf (its whole entity system) cost more than the rest of an
``export --dxf`` (docs/decisions.md, "The plate DXF is written without ezdxf").  The file is what
``write_deterministic(build_document(content, flavour=...))`` writes, byte for byte
(tests/cad/test_dxf_write.py):

* the constant parts (HEADER, CLASSES, TABLES, BLOCKS, OBJECTS of ``ezdxf.new("R2010"/"R12", setup=False)`` with
  the units and camfab's nine layers) are data, :mod:`camfab.cad.dxf_skeleton`, generated from ezdxf by
  ``tools/dxf_skeleton.py``;
* what varies is written here as ezdxf writes it: every tag is ``"%3d\\n%s\\n" % (code, value)``, a float
  by ``str(float)`` (``repr``), an int in decimal, a handle in upper-case hex; the 2D entities' points carry
  ``z = 0.0``; a bulge of zero is left out; handles count up from the skeleton's first free one in the order
  :func:`~camfab.cad.dxf.build_document` adds layers and entities, and the handles ezdxf allocates while
  writing (APPIDs, metadata, ``$HANDSEED``) come after them.

Everything here is ezdxf 1.4.5's format (``EZDXF_VERSION``): with another ezdxf installed the callers build the
file with ezdxf, as before (:func:`same_ezdxf`, read without importing it); the test regenerates the skeleton
from the installed ezdxf and compares.
"""
from __future__ import annotations

import functools
import importlib.util
from collections.abc import Iterator

from ..geom2d import ArcChain
from ..installed import installed_version
from ..textsafe import dxf_string
from . import dxf_skeleton as sk
from .dxf import LAYERS, DxfContent, centre_mark_size, loop_nurbs, r12_pieces

__all__ = ["write", "writes", "developed", "same_ezdxf", "installed_ezdxf_version", "EZDXF_VERSION"]

EZDXF_VERSION = sk.EZDXF_VERSION


def _f(value) -> str:
    """A float as ezdxf writes it (``str`` of a Python float)."""
    return repr(float(value))


def _xyz(code: int, x, y) -> str:
    """A 2D entity's point as ezdxf writes it: x, y and ``z = 0.0``."""
    return f"{code:3d}\n{_f(x)}\n{code + 10:3d}\n{_f(y)}\n{code + 20:3d}\n0.0\n"


class _Writer:
    """The entities of one file and the handles they take, in the order they are added."""

    def __init__(self, r12: bool) -> None:
        self.r12 = r12
        self.first = sk.R12_FIRST_HANDLE if r12 else sk.R2010_FIRST_HANDLE
        self.owner = sk.R12_OWNER if r12 else sk.R2010_OWNER
        self.next = self.first
        self.parts: list[str] = []
        self.layers: list[str] = []

    def handle(self) -> str:
        h = f"{self.next:X}"
        self.next += 1
        return h

    def head(self, kind: str, layer: str, subclass: str) -> str:
        """An entity's common tags (and its own subclass marker in R2000 and later)."""
        if self.r12:
            return f"  0\n{kind}\n  5\n{self.handle()}\n  8\n{layer}\n"
        return (f"  0\n{kind}\n  5\n{self.handle()}\n330\n{self.owner}\n100\nAcDbEntity\n  8\n{layer}\n"
                f"100\n{subclass}\n")

    def line(self, layer: str, start, end) -> None:
        self.parts.append(self.head("LINE", layer, "AcDbLine") + _xyz(10, *start[:2]) + _xyz(11, *end[:2]))

    def circle(self, layer: str, centre, radius) -> None:
        self.parts.append(self.head("CIRCLE", layer, "AcDbCircle") + _xyz(10, *centre[:2]) + f" 40\n{_f(radius)}\n")

    def arc(self, layer: str, centre, radius, a0, a1) -> None:
        text = self.head("ARC", layer, "AcDbCircle") + _xyz(10, *centre[:2]) + f" 40\n{_f(radius)}\n"
        text += "" if self.r12 else "100\nAcDbArc\n"
        self.parts.append(text + f" 50\n{_f(a0)}\n 51\n{_f(a1)}\n")

    def lwpolyline(self, layer: str, rows, closed: bool) -> None:
        rows = [(float(x), float(y), float(b)) for x, y, b in rows]
        text = [self.head("LWPOLYLINE", layer, "AcDbPolyline"), f" 90\n{len(rows)}\n 70\n{1 if closed else 0}\n"]
        for x, y, b in rows:
            text.append(f" 10\n{x!r}\n 20\n{y!r}\n" + (f" 42\n{b!r}\n" if b else ""))
        self.parts.append("".join(text))

    def rational_spline(self, layer: str, ctrl, weights, knots) -> None:
        # flags 4 (rational), degree 2, the knot, control point and fit point counts
        text = [self.head("SPLINE", layer, "AcDbSpline"),
                f" 70\n4\n 71\n2\n 72\n{len(knots)}\n 73\n{len(ctrl)}\n 74\n0\n"]
        text += [f" 40\n{_f(k)}\n" for k in knots]
        text += [f" 41\n{_f(w)}\n" for w in weights]
        text += [_xyz(10, x, y) for x, y in ctrl]
        self.parts.append("".join(text))

    def loop(self, loop: ArcChain, layer: str, flavour: str) -> None:
        """One loop as :func:`camfab.cad.dxf._add_loop` adds it."""
        if flavour == "spline":
            ctrl, w, knots = loop_nurbs(loop)
            self.rational_spline(layer, ctrl, w, knots)
        elif flavour == "lwpolyline":
            self.lwpolyline(layer, loop.lwpolyline, bool(loop.closed))
        else:
            for piece in r12_pieces(loop):
                if len(piece) == 2:
                    self.line(layer, *piece)
                else:
                    self.arc(layer, *piece)

    def add_layer(self, name: str) -> None:
        """A layer after the nine (``PLATE`` or ``OUTLINE``, the skeleton's ``EXTRA_LAYERS``), taking the next
        handle."""
        before, after = (sk.R12_EXTRA_LAYERS if self.r12 else sk.R2010_EXTRA_LAYERS)[name]
        self.layers.append(before + self.handle() + after)

    def text(self, custom: str) -> str:
        """The whole file: the skeleton with ``custom`` (the header's custom properties), the layers and
        entities added, and the handles ezdxf allocates while writing moved past theirs."""
        named = {"custom": custom, "extra_layers": "".join(self.layers), "entities": "".join(self.parts),
                 "layer_count": str((sk.R12_LAYER_COUNT if self.r12 else sk.R2010_LAYER_COUNT) + len(self.layers))}
        texts, slots = (sk.R12_TEXTS, sk.R12_SLOTS) if self.r12 else (sk.R2010_TEXTS, sk.R2010_SLOTS)
        return "".join(_fill(texts, slots, named, self.next - self.first))


def _custom_properties(name: str, tol_mm: float, deviation_mm: float | None) -> str:
    """The header's custom properties, as ezdxf's ``CustomVars.write`` writes them."""
    props = [("CAMFAB_NAME", dxf_string(name)), ("CAMFAB_TOL_MM", f"{tol_mm:g}")]
    if deviation_mm is not None:
        props.append(("CAMFAB_DEVIATION_MM", f"{deviation_mm:.3e}"))
    return "".join(f"  9\n$CUSTOMPROPERTYTAG\n  1\n{tag}\n  9\n$CUSTOMPROPERTY\n  1\n{value}\n" for tag, value in props)


def _entities(content: DxfContent, flavour: str, w: _Writer) -> None:
    """Add ``content``'s layers and entities in :func:`camfab.cad.dxf.build_document`'s order."""
    for i, loop in enumerate(content.profiles):
        w.loop(loop, "PROFILE" if i == 0 else f"PROFILE_{i + 1}", flavour)
    for i, loop in enumerate(content.pitch_curves):
        w.loop(loop, "PITCH_CURVE" if i == 0 else f"PITCH_CURVE_{i + 1}", flavour)
    for loop in content.tool_paths:
        w.loop(loop, "TOOL_PATH", flavour)
    if content.bore is not None:
        w.loop(content.bore, "BORE", flavour)
    if content.plate_outline is not None:
        w.add_layer("PLATE")
        w.loop(content.plate_outline, "PLATE", flavour)
    for layer, r in (("BASE_CIRCLE", content.base_radius), ("PRIME_CIRCLE", content.prime_radius),
                     *content.extra_circles):
        if r:
            w.circle(layer, (0.0, 0.0), float(r))
    size = centre_mark_size(content)
    w.line("CENTRE_MARKS", (-size, 0), (size, 0))
    w.line("CENTRE_MARKS", (0, -size), (0, size))


def _fill(texts: tuple[str, ...], slots: tuple[int | str, ...], named: dict[str, str], shift: int) -> Iterator[str]:
    """The skeleton's texts with its slots filled: named ones from ``named``, late handles moved by ``shift``."""
    yield texts[0]
    for slot, text in zip(slots, texts[1:], strict=True):
        yield named[slot] if isinstance(slot, str) else f"{slot + shift:X}"
        yield text


def installed_ezdxf_version() -> str | None:
    """The installed ezdxf's version, read from its ``version.py`` without importing it (~0.4 ms; importing
    ezdxf costs ~0.3 s, ``importlib.metadata`` ~30 ms); None without ezdxf or when the file does not say."""
    return installed_version("ezdxf")


@functools.cache
def same_ezdxf() -> bool:
    """Whether the ezdxf installed writes what this module writes (it is ezdxf :data:`EZDXF_VERSION`'s format),
    or none is installed; with another version the callers build the file with ezdxf, as before, so that the
    bytes never silently differ from the installed ezdxf's."""
    version = installed_ezdxf_version()
    return version == EZDXF_VERSION or importlib.util.find_spec("ezdxf") is None


def writes(content: DxfContent) -> bool:
    """Whether :func:`write` writes ``content`` as ezdxf would: the installed ezdxf is :data:`EZDXF_VERSION`
    (:func:`same_ezdxf`) and every layer is camfab's (``LAYERS``).  An extra circle on a layer of the caller's is
    left to ezdxf, which refuses a name with characters a layer name may not have
    (``ezdxf.lldxf.validator.is_valid_layer_name``): :func:`camfab.cad.dxf.dumps` falls back to it."""
    return same_ezdxf() and all(layer in LAYERS for layer, _ in content.extra_circles)


def write(content: DxfContent, flavour: str) -> str:
    """The DXF text of ``content`` in ``flavour`` (``lwpolyline``, ``r12`` or ``spline``): the bytes
    :func:`camfab.cad.dxf.build_document` and :func:`~camfab.cad.dxf.write_deterministic` make."""
    r12 = flavour == "r12"
    w = _Writer(r12)
    _entities(content, flavour, w)
    return w.text("" if r12 else _custom_properties(content.name, content.tol_mm, content.deviation_mm))


def developed(name: str, tol_mm: float, deviation_mm: float, chains: tuple[ArcChain, ...], width: float,
              length: float) -> str:
    """The cylindrical cam's developed DXF (:func:`camfab.cad.cylinder.developed_dxf`): the pitch curve and the
    flanks (``chains``, each an open LWPOLYLINE through its starts and last end) and the ``width`` × ``length``
    outline on ``OUTLINE``; the bytes :func:`camfab.cad.cylinder.developed_document` and
    :func:`~camfab.cad.dxf.write_deterministic` make."""
    w = _Writer(r12=False)
    w.add_layer("OUTLINE")
    for layer, chain in zip(("PITCH_CURVE", "PROFILE", "PROFILE_2"), chains, strict=True):
        rows = [(p[0], p[1], b) for p, b in zip(chain.starts, chain.bulges, strict=True)]
        end = chain.ends[-1]
        w.lwpolyline(layer, [*rows, (end[0], end[1], 0.0)], closed=False)
    w.lwpolyline("OUTLINE", [(0.0, 0.0, 0.0), (width, 0.0, 0.0), (width, length, 0.0), (0.0, length, 0.0)],
                 closed=True)
    return w.text(_custom_properties(name, tol_mm, deviation_mm))
