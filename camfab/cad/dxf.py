"""DXF export: millimetre units, named layers, exact arcs.

Who writes what: :func:`dumps` (the plate DXF of ``camfab export --dxf``) writes its text directly with
:mod:`camfab.cad.dxfwrite`, without importing ezdxf; only an extra circle on a layer not camfab's (ezdxf checks the
name), or any file when the installed ezdxf is not the version the writer reproduces, goes through ezdxf.
:func:`build_document` builds the same drawing as an ezdxf document and :func:`write_deterministic` writes it:
ezdxf's bytes, which ``dumps`` reproduces byte for byte (tests/cad/test_dxf_write.py; docs/decisions.md, "The plate
DXF is written without ezdxf").  The cylindrical cam's developed DXF is written by the same module
(:mod:`camfab.cad.cylinder`); the drawing sheets are built with ezdxf.

Flavours
--------
``lwpolyline`` (default)
    each loop is one closed LWPOLYLINE whose bulges carry the arcs exactly.
``r12``
    R12-safe LINE and ARC entities (DXF R12 file), for old CAM software.
``spline``
    each loop is one closed rational quadratic SPLINE (NURBS) that reproduces the
    arcs exactly (arcs split at 90°, weight cos(θ/2) on the middle control point),
    for CAD systems that want one smooth curve.

Layers: ``PROFILE``, ``PITCH_CURVE``, ``BASE_CIRCLE``, ``PRIME_CIRCLE``, ``BORE``,
``TOOL_PATH``, ``CENTRE_MARKS``; the second cam of a conjugate pair is on ``PROFILE_2``
and ``PITCH_CURVE_2``; a groove cam has its inner flank on ``PROFILE``, its outer flank on ``PROFILE_2`` and
its plate's rim on ``PLATE`` (:mod:`camfab.cad.groove`).  For a curved-face follower the pitch curve is the path of the
face's centre of curvature and the prime circle the circle R_b + R it starts on.  Units
are recorded as ``$INSUNITS = 4`` (mm) and the tolerance and achieved deviation as custom
header properties ``CAMFAB_TOL_MM`` / ``CAMFAB_DEVIATION_MM``; the design's name is ``CAMFAB_NAME``, one
line with DXF's escapes (:func:`camfab.textsafe.dxf_string`).  Output is byte-identical
for the same input (ezdxf's fixed-metadata mode, no timestamps; the CLASSES section sorted).
"""
from __future__ import annotations

import io
import math
import re

import numpy as np

from ..errors import InputError, MissingDependencyError
from ..geom2d import ArcChain, bulge_centre
from ..records import dataclass, field
from ..textsafe import dxf_string

__all__ = ["DxfContent", "LAYERS", "FLAVOURS", "dumps", "build_document", "loop_nurbs", "r12_pieces",
           "centre_mark_size", "write_deterministic"]

#: layer name -> ACI colour
LAYERS = {"PROFILE": 7, "PROFILE_2": 4, "PITCH_CURVE": 2, "PITCH_CURVE_2": 2, "BASE_CIRCLE": 3,
          "PRIME_CIRCLE": 1, "BORE": 5, "TOOL_PATH": 6, "CENTRE_MARKS": 8}
FLAVOURS = ("lwpolyline", "r12", "spline")


@dataclass(frozen=True)
class DxfContent:
    """What goes into the drawing; every length in mm, cam centre at the origin."""

    profiles: tuple[ArcChain, ...]
    pitch_curves: tuple[ArcChain, ...] = ()
    base_radius: float | None = None
    prime_radius: float | None = None
    bore: ArcChain | None = None
    tool_paths: tuple[ArcChain, ...] = ()
    tol_mm: float = 0.001
    deviation_mm: float | None = None
    name: str = "cam"
    extra_circles: tuple[tuple[str, float], ...] = field(default_factory=tuple)
    #: a groove cam's plate outline (its rim), on the layer ``PLATE`` (added only then)
    plate_outline: ArcChain | None = None


def ezdxf_module():
    """The ezdxf module, or a MissingDependencyError naming the install command."""
    try:
        import ezdxf
    except ImportError as exc:  # pragma: no cover
        raise MissingDependencyError("DXF export needs ezdxf: pip install ezdxf") from exc
    return ezdxf


def loop_nurbs(loop: ArcChain) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Control points, weights and knots of a degree-2 rational B-spline equal to ``loop``.

    Lines become a straight piece (middle control point halfway, weight 1); arcs are split into
    pieces of at most 90° whose middle control point lies at the tangents' intersection with
    weight cos(θ/2), the exact conic form of a circular arc.
    """
    ctrl, w = [], []
    for p0, p1, b in loop.segments():
        if abs(b) < 1e-15:
            ctrl += [p0, (p0 + p1) / 2]
            w += [1.0, 1.0]
            continue
        c = bulge_centre(p0, p1, b)
        r = float(math.hypot(*(p0 - c)))
        th = 4 * math.atan(b)
        k = max(1, math.ceil(abs(th) / (math.pi / 2) - 1e-12))
        a0 = math.atan2(p0[1] - c[1], p0[0] - c[0])
        d = th / k
        for i in range(k):
            a = a0 + i * d
            q0 = p0 if i == 0 else c + r * np.array([math.cos(a), math.sin(a)])
            am = a + d / 2
            ctrl += [q0, c + r / math.cos(d / 2) * np.array([math.cos(am), math.sin(am)])]
            w += [1.0, math.cos(d / 2)]
    m = len(ctrl) // 2
    ctrl.append(loop.points[0] if loop.closed else loop.ends[-1])
    w.append(1.0)
    knots = [0.0, 0.0, 0.0] + [float(j) for j in range(1, m) for _ in (0, 1)] + [float(m)] * 3
    return np.asarray(ctrl, dtype=float), np.asarray(w), np.asarray(knots)


def _add_loop(msp, loop: ArcChain, layer: str, flavour: str) -> None:
    if flavour == "spline":
        ctrl, w, knots = loop_nurbs(loop)
        msp.add_rational_spline([(float(x), float(y), 0.0) for x, y in ctrl], [float(v) for v in w], degree=2,
                                knots=[float(v) for v in knots], dxfattribs={"layer": layer})
        return
    if flavour == "lwpolyline":
        pts = [(float(x), float(y), 0.0, 0.0, float(b)) for x, y, b in loop.lwpolyline]
        msp.add_lwpolyline(pts, format="xyseb", close=loop.closed, dxfattribs={"layer": layer})
        return
    for piece in r12_pieces(loop):
        if len(piece) == 2:
            msp.add_line(*piece, dxfattribs={"layer": layer})
        else:
            msp.add_arc(*piece, dxfattribs={"layer": layer})


def r12_pieces(loop: ArcChain):
    """The R12 flavour's entities of ``loop``, in order: ``(start, end)`` for a LINE, ``(centre, radius,
    start_angle, end_angle)`` (degrees, counter-clockwise) for an ARC; points as tuples of numpy floats."""
    for p0, p1, b in loop.segments():
        if abs(b) < 1e-15:
            yield tuple(p0), tuple(p1)
            continue
        c = bulge_centre(p0, p1, b)
        r = float(math.hypot(*(p0 - c)))
        a0 = math.degrees(math.atan2(p0[1] - c[1], p0[0] - c[0]))
        a1 = math.degrees(math.atan2(p1[1] - c[1], p1[0] - c[0]))
        if b < 0:  # DXF arcs run counter-clockwise
            a0, a1 = a1, a0
        yield tuple(c), r, a0, a1


def build_document(content: DxfContent, *, flavour: str = "lwpolyline"):
    """An ezdxf document holding ``content`` (see the module docstring)."""
    if flavour not in FLAVOURS:
        raise InputError(f"'{flavour}' is not a valid DXF flavour, must be one of: {', '.join(FLAVOURS)}")
    ezdxf = ezdxf_module()
    doc = ezdxf.new("R12" if flavour == "r12" else "R2010", setup=False)
    if flavour != "r12":  # R12 headers have no unit variables: the R12 flavour is mm by contract
        doc.header["$INSUNITS"] = 4
        doc.header["$MEASUREMENT"] = 1
        doc.header.custom_vars.append("CAMFAB_NAME", dxf_string(content.name))
        doc.header.custom_vars.append("CAMFAB_TOL_MM", f"{content.tol_mm:g}")
        if content.deviation_mm is not None:
            doc.header.custom_vars.append("CAMFAB_DEVIATION_MM", f"{content.deviation_mm:.3e}")
    for name, colour in LAYERS.items():
        doc.layers.add(name, color=colour)
    msp = doc.modelspace()
    for i, loop in enumerate(content.profiles):
        _add_loop(msp, loop, "PROFILE" if i == 0 else f"PROFILE_{i + 1}", flavour)
    for i, loop in enumerate(content.pitch_curves):
        _add_loop(msp, loop, "PITCH_CURVE" if i == 0 else f"PITCH_CURVE_{i + 1}", flavour)
    for loop in content.tool_paths:
        _add_loop(msp, loop, "TOOL_PATH", flavour)
    if content.bore is not None:
        _add_loop(msp, content.bore, "BORE", flavour)
    if content.plate_outline is not None:
        doc.layers.add("PLATE", color=7)
        _add_loop(msp, content.plate_outline, "PLATE", flavour)
    for layer, r in (("BASE_CIRCLE", content.base_radius), ("PRIME_CIRCLE", content.prime_radius),
                     *content.extra_circles):
        if r:
            msp.add_circle((0.0, 0.0), float(r), dxfattribs={"layer": layer})
    size = centre_mark_size(content)
    msp.add_line((-size, 0), (size, 0), dxfattribs={"layer": "CENTRE_MARKS"})
    msp.add_line((0, -size), (0, size), dxfattribs={"layer": "CENTRE_MARKS"})
    return doc


def centre_mark_size(content: DxfContent) -> float:
    """Half the length of the centre mark's lines: 8 % of the profiles' largest coordinate (at least 1 mm)."""
    return max([float(np.max(np.abs(lp.points))) for lp in content.profiles] + [1.0]) * 0.08


def dumps(content: DxfContent, *, flavour: str = "lwpolyline") -> str:
    """DXF text, byte-identical for the same ``content``: written by :mod:`camfab.cad.dxfwrite`, the same bytes as
    ``write_deterministic(build_document(content, flavour=flavour))`` without importing ezdxf."""
    if flavour not in FLAVOURS:
        raise InputError(f"'{flavour}' is not a valid DXF flavour, must be one of: {', '.join(FLAVOURS)}")
    from .dxfwrite import write, writes

    if not writes(content):  # another ezdxf installed, or a layer of the caller's (ezdxf checks its name): ezdxf
        return write_deterministic(build_document(content, flavour=flavour))
    return write(content, flavour)


def write_deterministic(doc) -> str:
    """Write an ezdxf document as text that depends only on its content.

    ezdxf stamps the write time into its metadata and emits the CLASSES section in
    hash-seed order (it differs between processes); both are normalised here.
    """
    ezdxf = ezdxf_module()
    old = ezdxf.options.write_fixed_meta_data_for_testing
    ezdxf.options.write_fixed_meta_data_for_testing = True
    try:
        buf = io.StringIO()
        doc.write(buf)
    finally:
        ezdxf.options.write_fixed_meta_data_for_testing = old
    text = _EZDXF_STAMP.sub("@ 2000-01-01T00:00:00+00:00", buf.getvalue())
    return _sorted_classes(text)


_EZDXF_STAMP = re.compile(r"@ \d{4}-\d\d-\d\dT\d\d:\d\d:\d\d(?:\.\d+)?\+00:00")
_CLASSES = re.compile(r"(  0\nSECTION\n  2\nCLASSES\n)(.*?)(  0\nENDSEC\n)", re.S)


def _sorted_classes(text: str) -> str:
    def sort(m: re.Match) -> str:
        blocks = ["  0\nCLASS\n" + b for b in m.group(2).split("  0\nCLASS\n") if b]
        return m.group(1) + "".join(sorted(blocks)) + m.group(3)

    return _CLASSES.sub(sort, text, count=1)
