"""The grooved cylinder's STL (``camfab run``; meshed from the exact surfaces, :mod:`camfab.cad.cylinder_mesh`): read
back with trimesh, watertight, and its volume that of the STEP's solid measured by OpenCascade (``BRepGProp`` with an
adaptive precision) within the tolerance times the solid's surface area."""
from __future__ import annotations

import io
from pathlib import Path

import pytest

from camfab.pipeline import Output, Request, load, run

pytest.importorskip("cadquery", reason="the grooved cylinder needs cadquery (the step extra)")
trimesh = pytest.importorskip("trimesh")

from OCP.BRepGProp import BRepGProp  # noqa: E402
from OCP.GProp import GProp_GProps  # noqa: E402

from camfab.cad.kind_exports import cylinder_solid  # noqa: E402

pytestmark = pytest.mark.slow  # the STEP's grooved cylinder (~6 s), the reference here

EXAMPLE = Path(__file__).parents[2] / "camfab" / "examples" / "cylindrical_translating.toml"
TOL = 0.01


def test_run_writes_a_watertight_stl_of_the_step_solid(tmp_path):
    cam = load(EXAMPLE)
    res = run(cam, tmp_path, Request(frozenset({Output.STL}), tol=TOL))
    assert "stl" not in res.not_applicable and sorted(res.files) == ["BarrelCam.stl", "check.json"]
    data = (tmp_path / "BarrelCam.stl").read_bytes()
    assert data.startswith(b"camfab BarrelCam units=mm")
    mesh = trimesh.load(io.BytesIO(data), file_type="stl")
    assert mesh.is_watertight and mesh.is_volume
    solid, _ = cylinder_solid(cam, Request(frozenset({Output.STL}), tol=TOL))  # the run's, built once
    vol, area = GProp_GProps(), GProp_GProps()
    assert BRepGProp.VolumeProperties_s(solid.wrapped, vol, 1e-6, True) < 1e-5
    BRepGProp.SurfaceProperties_s(solid.wrapped, area, 1e-6, True)
    # every mesh vertex lies on the exact part and each facet within TOL of it: |ΔV| ≤ TOL · area
    assert abs(mesh.volume - vol.Mass()) <= TOL * area.Mass()
    assert abs(mesh.volume - vol.Mass()) < 2e-4 * vol.Mass()
    lo, hi = mesh.bounds
    assert hi[2] - lo[2] == pytest.approx(60.0, abs=1e-6)
    assert max(-lo[0], hi[0], -lo[1], hi[1]) == pytest.approx(45.0, abs=1e-6)
