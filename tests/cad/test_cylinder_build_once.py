"""A cylindrical run asking for the STEP and the STL builds the grooved cylinder's solid once (the build is the slow
part: the sections of the loft), for the STEP; the STL is meshed from the exact surfaces without it
(:mod:`camfab.cad.cylinder_mesh`)."""
from __future__ import annotations

from pathlib import Path

import pytest

from camfab.pipeline import Output, Request, load, run

cq = pytest.importorskip("cadquery", reason="the grooved cylinder needs cadquery (the step extra)")

EXAMPLE = Path(__file__).parents[2] / "camfab" / "examples" / "cylindrical_translating.toml"


def test_run_with_step_and_stl_builds_the_cylinder_once(tmp_path, monkeypatch):
    from camfab.cad import cylinder

    builds = []

    def counted(geometry, *, n, bore_mm=0.0):  # a plain cylinder stands in for the loft: the count is the point
        builds.append(n)
        cyl = geometry.cylinder
        return cq.Solid.makeCylinder(cyl.outer_radius_mm, cyl.length_mm)

    monkeypatch.setattr(cylinder, "grooved_cylinder", counted)
    res = run(load(EXAMPLE), tmp_path, Request(frozenset({Output.STEP, Output.STL})))
    assert sorted(res.files) == ["BarrelCam.step", "BarrelCam.stl", "check.json"]
    assert len(builds) == 1
    assert (tmp_path / "BarrelCam.stl").read_bytes().startswith(b"camfab BarrelCam units=mm")
    assert "MANIFOLD_SOLID_BREP" in (tmp_path / "BarrelCam.step").read_text()
