"""The drawing sheets read back by outside renderers: LibreCAD's ``dxf2pdf`` and ezdxf's drawing add-on show the
true dimension values (plate length, bore Ø, base circle Ø, R max, thickness) with their Ø and R prefixes, at every
scale; and the layout rule (no overlaps, all inside the frame, the sheet's paper in the header) on every example and
paper.

LibreCAD draws text with its own stroke font (ISO 3098, ``standard.lff``): its PDF holds strokes, no text, so
``pdftotext`` reads nothing from it (checked below).  The values are read back the way a person reads them: LibreCAD
renders the expected text (``%%c12 H7``, ``R45`` …) as plain TEXT on a reference sheet, and that stroke pattern must
appear, at the dimension-text height and the dimension's direction, next to the DIMENSION on the rendered sheet —
and the half-size value a per-entity ``dimlfac`` would have given must not.
"""
from __future__ import annotations

import io
import math
import os
import re
import shutil
import subprocess
import zlib
from functools import cache
from pathlib import Path

import numpy as np
import pytest

from camfab.cad.drawing import build_drawing, dim_value, drawing_sheet
from camfab.cad.export import cam_shapes
from camfab.cad.kind_exports import applies
from camfab.cad.plate import keyway_size
from camfab.cad.sheet_check import layout_problems
from camfab.design.assemble import check_design, geometry_from_spec
from camfab.design.drawing import keyway_depth_tolerance
from camfab.formats import load_design
from tests.conftest import EXAMPLES

ezdxf = pytest.importorskip("ezdxf")
KDTree = pytest.importorskip("scipy.spatial").cKDTree

#: the examples with a plate sheet (a cylindrical cam's sheet is read back in tests/cad/test_cylinder_sheet.py)
ALL = sorted(p.stem for p in EXAMPLES.glob("*.toml")
             if applies(load_design(p).cam.kind, "drawing") and load_design(p).cam.kind != "cylindrical")
#: a 1:1 sheet with bore, keyway and fits; a 1:2 disc cam pair; the 1:2 wedge plate
FAST = ["ejemplo9rt", "ejemplo8da_conjugate", "wedge_translating"]
PT_MM = 25.4 / 72.0
TOL_MM = 0.12  # LibreCAD's PDF coordinates are 1/1200 in; its arcs are flattened afresh for each placement


@cache
def _job(name: str):
    spec = load_design(EXAMPLES / f"{name}.toml")
    geom = geometry_from_spec(spec)
    return spec, geom, check_design(spec), cam_shapes(geom, tol=1e-3)


def _true_dims(name: str, shown: set[str] | None = None) -> dict[str, str]:
    """The values each sheet must show, from the design (not from the sheet).  The keyway's width and depth
    carry their DIN 6885 tolerances, or — where a small hub leaves no room for that text (``shown``: the
    sheet's dimension texts) — the bare value, the tolerance then in note 2."""
    spec, geom, *_ = _job(name)
    m = spec.manufacturing
    out = {"thickness": dim_value(m.thickness_mm)}
    if geom.closed:
        out["base"] = f"%%c{dim_value(2 * spec.follower.base_radius_mm)}"
        out["rmax"] = f"R{dim_value(geom.max_radius)}"
        if m.bore_mm:
            out["bore"] = f"%%c{dim_value(m.bore_mm)} {spec.drawing.bore_fit}"
        if m.keyway:
            b, t2 = keyway_size(m.bore_mm)
            for key, full, bare in (
                    ("width", f"{dim_value(b)} {spec.drawing.keyway_width_fit}", dim_value(b)),
                    ("depth", f"{dim_value(m.bore_mm + t2)} +{keyway_depth_tolerance(m.bore_mm):g}/0",
                     dim_value(m.bore_mm + t2))):
                out[key] = bare if shown is not None and full not in shown and bare in shown else full
    else:
        out["length"] = dim_value(geom.profiles[0].period)
    return out


# ---------------------------------------------------------------------------
# LibreCAD
def _librecad() -> str:
    exe = shutil.which("librecad")
    if exe is None or shutil.which("pdftotext") is None:
        pytest.skip("librecad or pdftotext (poppler-utils) is not installed")
    return exe


def _to_pdf(exe: str, dxf: Path) -> Path:
    env = dict(os.environ, QT_QPA_PLATFORM="offscreen")
    subprocess.run([exe, "dxf2pdf", "-s", "1", "-t", str(dxf.parent), str(dxf)], env=env, check=True,
                   capture_output=True, timeout=120)
    pdf = dxf.with_suffix(".pdf")
    assert pdf.exists(), "LibreCAD wrote no PDF"
    return pdf


def _strokes(pdf: Path) -> tuple[np.ndarray, np.ndarray]:
    """The stroked polylines of a LibreCAD PDF (its content stream: ``m``/``l``/``c`` under one ``cm``) as
    segments (n, 4) in mm with y up, and their vertices (k, 2)."""
    data = pdf.read_bytes()
    segs, verts = [], []
    for m in re.finditer(rb"stream\r?\n(.*?)endstream", data, re.S):
        try:
            text = zlib.decompress(m.group(1)).decode("latin-1")
        except zlib.error:
            continue
        a = d = 1.0
        f = 0.0
        cur = None
        path: list[tuple[float, float, float, float]] = []
        pverts: list[tuple[float, float]] = []
        for line in text.splitlines():
            parts = line.split()
            if not parts:
                continue
            op = parts[-1]
            if op == "cm":
                a, d, f = float(parts[0]), float(parts[3]), float(parts[5])
            elif op in ("m", "l", "c"):
                x, y = float(parts[-3]), float(parts[-2])
                p = (a * x * PT_MM, (d * y + f) * PT_MM)
                if op != "m" and cur is not None:
                    path.append((*cur, *p))
                pverts.append(p)
                cur = p
            elif op in ("S", "s", "B", "b", "B*", "b*", "n"):  # painted (kept) or a clipping path (dropped)
                if op != "n":
                    segs += path
                    verts += pverts
                path, pverts, cur = [], [], None
    assert len(segs) > 4, f"LibreCAD drew nothing into {pdf.name}"
    return np.array(segs), np.array(verts)


def _dense(segs: np.ndarray, step: float = 0.03) -> np.ndarray:
    """Points every ``step`` mm along the segments (and their ends)."""
    d = np.hypot(segs[:, 2] - segs[:, 0], segs[:, 3] - segs[:, 1])
    n = np.maximum(1, np.ceil(d / step).astype(int))
    t = np.concatenate([np.linspace(0.0, 1.0, k + 1) for k in n])
    rep = np.repeat(np.arange(len(segs)), n + 1)
    s = segs[rep]
    return np.column_stack([s[:, 0] + t * (s[:, 2] - s[:, 0]), s[:, 1] + t * (s[:, 3] - s[:, 1])])


def _extents(doc, w: float, h: float) -> None:
    """The drawing's extents in the header (LibreCAD prints nothing without them; ezdxf writes the model
    space's, which it only keeps when they do not start at 0, 0, 0)."""
    doc.modelspace().dxf.extmin = (1e-3, 1e-3, 0.0)
    doc.modelspace().dxf.extmax = (w, h, 0.0)


@cache
def _glyphs(exe: str, tmp: str, texts: tuple[str, ...], height: float) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Each text as LibreCAD draws a TEXT of that height: (dense points, vertices) relative to its first vertex."""
    doc = ezdxf.new("R2010", units=4)
    msp = doc.modelspace()
    msp.add_lwpolyline([(0, 0), (400, 0), (400, 280), (0, 280)], close=True)
    rows = {}
    for i, t in enumerate(texts):
        y = 20.0 + 12.0 * i
        msp.add_text(t, height=height).set_placement((20.0, y))
        rows[t] = y
    _extents(doc, 400.0, 280.0)
    path = Path(tmp) / "glyphs.dxf"
    doc.saveas(path)
    segs, _ = _strokes(_to_pdf(exe, path))
    lo = segs[:, :2].min(axis=0)  # the reference sheet's corner (0, 0)
    segs = segs - np.tile(lo, 2)
    out = {}
    for t, y in rows.items():
        keep = ((np.minimum(segs[:, 0], segs[:, 2]) > 10.0) & (np.abs(segs[:, 1] - y - height / 2) < height)
                & (np.abs(segs[:, 3] - y - height / 2) < height))
        s = segs[keep]
        assert len(s), f"LibreCAD drew nothing for {t!r}"
        origin = s[0, :2]
        out[t] = (_dense(s) - origin, np.vstack([s[:, :2], s[:, 2:]]) - origin)
    return out


def _find(pattern: tuple[np.ndarray, np.ndarray], tree, verts: np.ndarray, near, angles,
          reach: float = 25.0) -> bool:
    """Whether the stroke pattern (dense points, vertices; relative) appears on the sheet (``tree`` over its
    dense points, ``verts`` its vertices) turned by one of ``angles`` (degrees) with its first vertex within
    ``reach`` mm of ``near``: every point of the pattern within :data:`TOL_MM` of a drawn stroke."""
    dense, pv = pattern
    cand = verts[np.hypot(*(verts - np.asarray(near)).T) < reach]
    for deg in angles:
        c, s = math.cos(math.radians(deg)), math.sin(math.radians(deg))
        rot = np.array([[c, -s], [s, c]])
        probe = (pv @ rot.T)[:12]
        full = dense @ rot.T
        # every candidate placement's 12 probe vertices in one query; the full pattern only where they all hit
        dist = tree.query((cand[:, None, :] + probe[None, :, :]).reshape(-1, 2), distance_upper_bound=TOL_MM)[0]
        for q in cand[(dist.reshape(len(cand), -1) <= TOL_MM).all(axis=1)]:
            if (tree.query(full + q, distance_upper_bound=TOL_MM)[0] <= TOL_MM).mean() >= 0.98:
                return True
    return False


def _dimension_texts(doc):
    """(text, position, direction in degrees) of each DIMENSION's text as ezdxf renders it (paper mm)."""
    out = []
    for dim in doc.modelspace().query("DIMENSION"):
        (mt,) = [e for e in doc.blocks.get(dim.dxf.geometry) if e.dxftype() == "MTEXT"]
        out.append((dim.dxf.text, (mt.dxf.insert.x, mt.dxf.insert.y), mt.dxf.get("rotation", 0.0)))
    return out


def _librecad_reads(name: str, exe: str, tmp: Path) -> None:
    spec, geom, report, shapes = _job(name)
    text = drawing_sheet(spec, geom, report, shapes)
    dxf = tmp / f"{name}.dxf"
    dxf.write_text(text)
    pdf = _to_pdf(exe, dxf)
    # LibreCAD's text is strokes: poppler finds no text in its PDF
    assert subprocess.run(["pdftotext", "-layout", str(pdf), "-"], capture_output=True, text=True,
                          check=True).stdout.strip() == ""
    segs, verts = _strokes(pdf)
    lo = segs[:, :2].min(axis=0)  # the paper's corner: the sheet's outer rectangle starts at (0, 0)
    doc = ezdxf.read(io.StringIO(text))
    w, h = doc.header["$LIMMAX"]
    span = segs[:, :2].max(axis=0) - lo
    assert span == pytest.approx((w, h), abs=0.2)  # drawn at 1:1 on the page: paper mm are PDF mm
    segs = segs - np.tile(lo, 2)
    verts = verts - lo
    tree = KDTree(_dense(segs))
    dims = _dimension_texts(doc)
    scale = float(doc.header.custom_vars.get("CAMFAB_SCALE"))
    want = _true_dims(name, {t for t, *_ in dims})
    wrong = {}
    if scale != 1.0:  # what LibreCAD showed before: the paper length of a <> dimension with dimlfac
        for t in want.values():
            v = float(re.sub(r"[^0-9.]", " ", t.replace("%%c", "")).split()[0])
            wrong[t] = t.replace(dim_value(v), dim_value(v * scale), 1)
    glyphs = _glyphs(exe, str(tmp), tuple(sorted({*want.values(), *wrong.values()})), 2.5)
    by_text = {t: (p, a) for t, p, a in dims}
    for key, t in want.items():
        assert t in by_text, f"{name}: no DIMENSION with the text {t!r} ({key})"
        at, deg = by_text[t]
        assert _find(glyphs[t], tree, verts, at, (deg, deg + 180.0)), \
            f"{name}: LibreCAD does not show {t!r} ({key}) at its dimension"
        if t in wrong:
            assert not _find(glyphs[wrong[t]], tree, verts, at, (deg, deg + 180.0), reach=14.0), \
                f"{name}: LibreCAD shows {wrong[t]!r} at the dimension {t!r}"


@pytest.mark.parametrize("name", FAST)
def test_librecad_shows_the_true_dimension_values(name, tmp_path):
    _librecad_reads(name, _librecad(), tmp_path)


@pytest.mark.slow
@pytest.mark.parametrize("name", [n for n in ALL if n not in FAST])
def test_librecad_shows_the_true_dimension_values_on_every_example(name, tmp_path):
    _librecad_reads(name, _librecad(), tmp_path)


# ---------------------------------------------------------------------------
# ezdxf
@pytest.mark.parametrize("name", FAST)
def test_ezdxf_shows_the_same_values(name):
    spec, geom, report, shapes = _job(name)
    doc, _ = build_drawing(spec, geom, report, shapes)
    shown: dict[str, str] = {}
    for dim in doc.modelspace().query("DIMENSION"):
        (mt,) = [e for e in doc.blocks.get(dim.dxf.geometry) if e.dxftype() == "MTEXT"]
        shown[dim.dxf.text] = mt.plain_text()
    for t in _true_dims(name, {d.dxf.text for d in doc.modelspace().query("DIMENSION")}).values():
        assert t in shown, t
        # ezdxf shows %%c as Ø: the same value with the diameter sign, the radius with R
        assert shown[t] == t.replace("%%c", "Ø")


# ---------------------------------------------------------------------------
# the layout rule
@pytest.mark.parametrize("name", FAST)
@pytest.mark.parametrize("paper", ["auto", "A4", "A3"])
def test_layout_is_free_of_overlaps(name, paper):
    doc, lay = build_drawing(*_job(name), paper=paper)
    assert layout_problems(doc, lay) == []
    # the header's limits and extents are the sheet's paper, as written
    written = ezdxf.read(io.StringIO(drawing_sheet(*_job(name), paper=paper)))
    w, h = lay.size
    assert tuple(written.header["$LIMMAX"]) == pytest.approx((w, h))
    assert tuple(written.header["$LIMMIN"]) == (0.0, 0.0)
    assert tuple(written.header["$EXTMIN"])[:2] == (0.0, 0.0)
    assert tuple(written.header["$EXTMAX"])[:2] == pytest.approx((w, h))


@pytest.mark.slow
@pytest.mark.parametrize("name", [n for n in ALL if n not in FAST])
def test_layout_is_free_of_overlaps_on_every_example(name):
    for paper in ("auto", "A4", "A3"):
        doc, lay = build_drawing(*_job(name), paper=paper)
        assert layout_problems(doc, lay) == [], (name, paper)


def test_the_read_back_sees_the_old_fault(tmp_path):
    """The read-back is able to fail: a ``<>`` dimension of Ø45 on paper with ``dimlfac = 2`` (a 1:2 sheet's
    Ø90, as camfab wrote them before) reads 45 in LibreCAD, not %%c90."""
    exe = _librecad()
    doc = ezdxf.new("R2010", units=4)
    doc.dimstyles.new("CAMFAB", dxfattribs={"dimtxt": 2.5, "dimasz": 2.5, "dimtad": 1, "dimdec": 2, "dimzin": 8})
    msp = doc.modelspace()
    msp.add_lwpolyline([(0, 0), (297, 0), (297, 210), (0, 210)], close=True)
    d = msp.add_diameter_dim((150.0, 100.0), radius=22.5, angle=30.0, dimstyle="CAMFAB", override={"dimlfac": 2.0})
    d.render()
    _extents(doc, 297.0, 210.0)
    dxf = tmp_path / "old.dxf"
    doc.saveas(dxf)
    segs, verts = _strokes(_to_pdf(exe, dxf))
    lo = segs[:, :2].min(axis=0)
    segs, verts = segs - np.tile(lo, 2), verts - lo
    tree = KDTree(_dense(segs))
    glyphs = _glyphs(exe, str(tmp_path), ("%%c90", "45"), 2.5)
    (mt,) = [e for e in doc.blocks.get(d.dimension.dxf.geometry) if e.dxftype() == "MTEXT"]
    at, deg = (mt.dxf.insert.x, mt.dxf.insert.y), mt.dxf.get("rotation", 0.0)
    assert _find(glyphs["45"], tree, verts, at, (deg, deg + 180.0))
    assert not _find(glyphs["%%c90"], tree, verts, at, (deg, deg + 180.0))
