"""Stages share their geometry: the DXF's TOOL_PATH layer is the program's own tool path (read back from both
files), and a cam offsets, guards and fits each tool path once (docs/decisions.md, "The DXF tool path is the
program's")."""
from __future__ import annotations

import io

import ezdxf
import numpy as np
import pytest

import camfab
import camfab.offset.cutter as cutter
from camfab.gcode import parse
from camfab.pipeline import Output, Request, RunResult, build_files


def _files(cam, post: str = "linuxcnc", **machining) -> dict[str, bytes]:
    req = Request(frozenset({Output.DXF, Output.GCODE}), post, machining=machining)
    return build_files(cam, req, RunResult(cam.name, ""), lambda m: None)


def _dxf_arcs(xyb: np.ndarray) -> list[tuple[np.ndarray, float, float, float]]:
    """(centre, radius, start angle, counter-clockwise sweep) of every arc of a closed LWPOLYLINE's (x, y, bulge)."""
    out = []
    for (x0, y0, b), (x1, y1, _) in zip(xyb, np.roll(xyb, -1, axis=0), strict=True):
        if abs(b) > 1e-12:
            c, a0, a1, r = ezdxf.math.bulge_to_arc((x0, y0), (x1, y1), b)
            out.append((np.array([c.x, c.y]), r, a0, (a1 - a0) % (2 * np.pi)))
    return out


@pytest.mark.parametrize("post", ["linuxcnc", "fanuc"])
def test_dxf_tool_path_is_the_programs_finishing_contour(post):
    """The DXF's TOOL_PATH polyline and the program's finishing contour, both read back: every vertex of the
    polyline is the end of a finishing move and every arc of the program is one of the polyline's, to the
    program's output rounding; the program's other ends lie on the polyline's arcs (the chords a post writes
    for arcs above its largest radius: Fanuc)."""
    cam = camfab.load("ejemplo9rt")
    files = _files(cam, post)
    doc = ezdxf.read(io.StringIO(files["Ejemplo9RT.dxf"].decode()))
    (poly,) = doc.modelspace().query("LWPOLYLINE[layer=='TOOL_PATH']")
    xyb = np.array(list(poly.get_points("xyb")))
    moves = [m for m in parse(files["Ejemplo9RT.nc"].decode()).moves if m.label == "FINISH CONTOUR"]
    ends = np.array([m.end[:2] for m in moves])
    rounding = 2e-4 if post == "linuxcnc" else 2e-3  # 4 decimals (linuxcnc), 3 (fanuc), as written
    to_end = np.hypot(*(xyb[:, None, :2] - ends[None]).T)  # (ends, vertices)
    assert to_end.min(axis=0).max() < rounding  # every DXF vertex ends a move
    arcs = _dxf_arcs(xyb)
    on_arc = [min(abs(np.hypot(*(p - c)) - r) if (np.arctan2(*(p - c)[::-1]) - a0) % (2 * np.pi) <= sw + 1e-9
                  else np.inf for c, r, a0, sw in arcs) for p in ends]
    assert max(min(d, dv) for d, dv in zip(on_arc, to_end.min(axis=1), strict=True)) < rounding
    for m in (m for m in moves if m.kind == "arc"):  # every programmed arc is a DXF arc (centre and radius)
        c = np.array(m.center)
        assert min(np.hypot(*(c - ca)) / max(1.0, ra / 50) for ca, ra, *_ in arcs) < rounding * 5, m
    if post == "linuxcnc":  # no radius cap: the same arcs, one move each (the contour may start inside one)
        assert len(moves) in (len(xyb), len(xyb) + 1)


def test_one_guard_and_fit_per_tool_path(monkeypatch):
    """DXF and G-code of one cam: the shapely guard runs once per profile, not once per stage."""
    calls = []
    guard = cutter.shapely_guard
    monkeypatch.setattr(cutter, "shapely_guard", lambda *a, **k: calls.append(1) or guard(*a, **k))
    cam = camfab.load("ejemplo8da_conjugate")
    _files(cam)
    assert len(calls) == len(cam.geometry.profiles) == 2
    _files(cam, tool_diameter_mm=5.0)  # another tool: its own paths
    assert len(calls) == 4
