"""IGES of the solids that are not one extruded outline (a cylindrical cam's grooved cylinder; the groove cam's
pocketed plate: tests/cad/test_groove_files.py): read back by OpenCascade's IGES reader, one valid solid whose
volume is the STEP's."""
from __future__ import annotations

from pathlib import Path

import pytest

from camfab.pipeline import Output, Request, load, run

pytest.importorskip("cadquery", reason="IGES needs cadquery's OpenCascade")

from OCP.BRepCheck import BRepCheck_Analyzer  # noqa: E402
from OCP.BRepGProp import BRepGProp  # noqa: E402
from OCP.GProp import GProp_GProps  # noqa: E402
from OCP.IFSelect import IFSelect_RetDone  # noqa: E402
from OCP.IGESControl import IGESControl_Reader  # noqa: E402
from OCP.TopAbs import TopAbs_SOLID  # noqa: E402
from OCP.TopExp import TopExp_Explorer  # noqa: E402

from .test_step_occ import read_step  # noqa: E402

EXAMPLE = Path(__file__).parents[2] / "camfab" / "examples" / "cylindrical_translating.toml"


def read_iges(path: Path):
    """The shape of an IGES file (OCC's reader), checked to hold exactly one valid solid."""
    reader = IGESControl_Reader()
    assert reader.ReadFile(str(path)) == IFSelect_RetDone
    reader.TransferRoots()
    shape = reader.OneShape()
    ex, solids = TopExp_Explorer(shape, TopAbs_SOLID), 0
    while ex.More():
        solids += 1
        ex.Next()
    assert solids == 1 and BRepCheck_Analyzer(shape).IsValid()
    return shape


def volume(shape) -> float:
    """The volume (mm³) by ``BRepGProp`` with an adaptive precision (OCC's default is 0.6 % off on B-splines)."""
    props = GProp_GProps()
    BRepGProp.VolumeProperties_s(shape, props, 1e-7, True)
    return props.Mass()


@pytest.mark.slow  # one grooved cylinder (~6 s)
def test_cylindrical_iges_is_the_step_solid(tmp_path):
    res = run(load(EXAMPLE), tmp_path, Request(frozenset({Output.STEP, Output.IGES})))
    assert "iges" not in res.not_applicable
    text = (tmp_path / "BarrelCam.igs").read_text(encoding="ascii")
    assert "camfab" in text[:800]
    iges, step = read_iges(tmp_path / "BarrelCam.igs"), read_step(tmp_path / "BarrelCam.step")
    assert volume(iges) == pytest.approx(volume(step), rel=1e-7)
