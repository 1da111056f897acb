"""One arc fit per profile (docs/decisions.md, "One arc fit per profile"): the plate files draw one fit within
tol/2, and the pitch curve, the program's finishing contour and its roughing passes are its exact offsets —
concentric arcs, each measured on its own exact curve by the general measurement here — and a file's bytes do not
depend on which other files a run makes."""
from __future__ import annotations

import numpy as np
import pytest

import camfab
import camfab.discretize.fit as fit_mod
from camfab.discretize import measure_deviation
from camfab.gcode.cam import contour_fit_tolerance
from camfab.gcode.model import design_job
from camfab.offset.cutter import offset_curve, pitch_curve
from camfab.pipeline import Output, Request, RunResult, build_files
from camfab.tolerances import PROFILE_FIT_SHARE

EXAMPLES = ["ejemplo9rt", "ejemplo11ro", "press_feed_oscillating"]


def _same_arcs(a, b) -> bool:
    """The same chain: the same vertices (to rounding of the offset) and the same bulges (exactly)."""
    return (a.n_entities == b.n_entities and np.array_equal(a.bulges, b.bulges)
            and float(np.abs(a.starts - b.starts).max()) < 1e-9)


@pytest.mark.parametrize("name", EXAMPLES)
def test_the_offsets_are_the_plate_fits_own_arcs_within_their_tolerances(name):
    cam = camfab.load(name)
    tol = cam.tolerance()
    shapes = cam.shapes(tol)
    contact, fit = cam.geometry.profiles[0], shapes.profiles[0]
    assert measure_deviation(fit, shapes.curves[0]).max <= PROFILE_FIT_SHARE * tol
    if contact.roller_radius > 0:  # the pitch loop: the fit moved out by the roller radius
        assert _same_arcs(shapes.pitch[0], fit.offset_g1(contact.roller_radius))
        assert measure_deviation(shapes.pitch[0], pitch_curve(contact)).max <= tol
    req = Request(frozenset({Output.GCODE}), "linuxcnc")
    job = design_job(cam.spec, tol=tol)
    (path,) = cam_paths(cam, req, tol)
    r = job.tool_radius_mm
    assert _same_arcs(path.arcs, fit.offset_g1(r))  # the finishing contour's arcs: the fit moved out by r
    assert measure_deviation(path.arcs, offset_curve(contact, r)).max <= contour_fit_tolerance(tol, "linuxcnc")


def cam_paths(cam, req, tol):
    from camfab.gcode.cam import contour_paths

    return contour_paths(cam.spec, cam.geometry, req.machining, tol=tol, post=req.post, cache=cam._tool_paths,
                         profiles=cam.shapes(tol).profiles)


def test_a_package_cam_fits_each_profile_once(monkeypatch):
    """DXF, STL, drawing and G-code (finishing contour and roughing passes) of a roller cam: one arc fit."""
    calls = []
    real = fit_mod._arcs
    monkeypatch.setattr(fit_mod, "_arcs", lambda curve, tol: calls.append(tol) or real(curve, tol))
    cam = camfab.load("ejemplo9rt")
    outputs = frozenset({Output.DXF, Output.STL, Output.DRAWING, Output.GCODE})
    files = build_files(cam, Request(outputs, "linuxcnc"), RunResult(cam.name, ""), lambda m: None)
    assert {"Ejemplo9RT.dxf", "Ejemplo9RT.stl", "Ejemplo9RT.nc", "Ejemplo9RT_drawing.dxf"} <= set(files)
    assert calls == [PROFILE_FIT_SHARE * cam.tolerance()]


@pytest.mark.parametrize("name", ["ejemplo9rt", "groove_translating"])
def test_a_files_bytes_do_not_depend_on_the_other_files_asked_for(name):
    """The STL and the G-code made alone equal those made with every other plate file (the fit is the same)."""
    def build(outputs):
        cam = camfab.load(name)
        return build_files(cam, Request(frozenset(outputs), "linuxcnc"), RunResult(cam.name, ""), lambda m: None)

    every = build({Output.DXF, Output.STL, Output.DRAWING, Output.GCODE})
    for kind, ext in ((Output.STL, ".stl"), (Output.GCODE, ".nc")):
        alone = build({kind})
        assert alone and all(every[f] == data for f, data in alone.items() if f.endswith(ext))
