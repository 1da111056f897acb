"""Every example's STEP solid read back by OpenCascade (through cadquery's OCP) and put through its checkers:
``BRepCheck_Analyzer`` (topology and geometry valid) and the boolean argument analyser
``BOPAlgo_ArgumentAnalyzer`` with its checks on (curve on surface, self-interference, small edges, rebuild face,
merge vertex/edge, continuity): FreeCAD's "check geometry" with BOP check.  Before the arc radius limit the wedge
cam's STEP held a cylinder of radius 22 497 266 mm that failed it (BOPAlgo_InvalidCurveOnSurface).  The
largest circle in every file stays within :data:`~camfab.tolerances.MAX_ARC_RADIUS_MM`.  The grooved cylinder
passes too since its opening edges are rebuilt from exact intersection points (``cylinder.exact_edges``): read back,
the boolean's edges failed the curve-on-surface check by up to 2.5e-6 mm.
"""
from __future__ import annotations

from pathlib import Path

import pytest

from camfab import pipeline
from camfab.cad.kind_exports import kind_exporter
from camfab.tolerances import MAX_ARC_RADIUS_MM

pytest.importorskip("cadquery", reason="STEP needs cadquery (the step extra)")

from OCP.BOPAlgo import BOPAlgo_ArgumentAnalyzer  # noqa: E402
from OCP.BRepAdaptor import BRepAdaptor_Curve  # noqa: E402
from OCP.BRepCheck import BRepCheck_Analyzer  # noqa: E402
from OCP.GeomAbs import GeomAbs_Circle  # noqa: E402
from OCP.IFSelect import IFSelect_RetDone  # noqa: E402
from OCP.STEPControl import STEPControl_Reader  # noqa: E402
from OCP.TopAbs import TopAbs_EDGE, TopAbs_SOLID  # noqa: E402
from OCP.TopExp import TopExp_Explorer  # noqa: E402
from OCP.TopoDS import TopoDS  # noqa: E402

FAST = ("wedge_translating", "ejemplo12po_roller")  # the failing one and a large-radius roller cam


def read_step(path: Path):
    reader = STEPControl_Reader()
    assert reader.ReadFile(str(path)) == IFSelect_RetDone
    reader.TransferRoots()
    return reader.OneShape()


def _bop_results(shape) -> list[tuple[str, float]]:
    """(status, largest distance) of each fault BOPAlgo_ArgumentAnalyzer reports for ``shape`` with every check
    on (empty: none)."""
    a = BOPAlgo_ArgumentAnalyzer()
    a.SetShape1(shape)
    for mode in ("ArgumentTypeMode", "CurveOnSurfaceMode", "SelfInterMode", "SmallEdgeMode", "RebuildFaceMode",
                 "TangentMode", "MergeVertexMode", "MergeEdgeMode", "ContinuityMode"):
        setattr(a, mode, True)
    a.Perform()
    return [(str(r.GetCheckStatus()), r.GetMaxDistance1()) for r in a.GetCheckResult()] if a.HasFaulty() else []


def bop_faults(shape) -> list[str]:
    """The statuses BOPAlgo_ArgumentAnalyzer reports for ``shape`` with every check on (empty: none)."""
    return [status for status, _ in _bop_results(shape)]


def circle_radii(shape) -> list[float]:
    out = []
    ex = TopExp_Explorer(shape, TopAbs_EDGE)
    while ex.More():
        c = BRepAdaptor_Curve(TopoDS.Edge_s(ex.Current()))
        if c.GetType() == GeomAbs_Circle:
            out.append(c.Circle().Radius())
        ex.Next()
    return out


def _check(name: str, tmp_path: Path) -> None:
    cam = pipeline.load(name)
    step = kind_exporter(cam.spec.cam.kind, "step", pipeline.EXPORTERS[pipeline.Output.STEP])
    arts = step(cam, pipeline.Request(frozenset({pipeline.Output.STEP})))
    tol = cam.tolerance()
    for art in arts:
        assert art.deviation_mm is not None and art.deviation_mm <= tol
        path = tmp_path / art.filename
        path.write_bytes(art.data)
        shape = read_step(path)
        solids = TopExp_Explorer(shape, TopAbs_SOLID)
        assert solids.More(), f"{art.filename}: no solid"
        assert BRepCheck_Analyzer(shape).IsValid(), f"{art.filename}: BRepCheck_Analyzer finds it invalid"
        assert bop_faults(shape) == [], f"{art.filename}: {bop_faults(shape)}"
        assert max(circle_radii(shape)) <= MAX_ARC_RADIUS_MM


@pytest.mark.parametrize("name", FAST)
def test_step_passes_occ_checks(name, tmp_path):
    _check(name, tmp_path)


@pytest.mark.slow
@pytest.mark.parametrize("name", [e for e in pipeline.examples() if e not in FAST])
def test_every_example_step_passes_occ_checks(name, tmp_path):
    _check(name, tmp_path)


def test_the_checker_finds_the_old_wedge_solid(tmp_path):
    """The analyser is live: the wedge's arc fit as the fitter once wrote it, before the limit (kept in
    tests/cad/data: an arc of radius ~2.2e7 mm, a cylinder face), fails its curve-on-surface check
    (test_step_passes_occ_checks: with the limit it passes)."""
    import json

    from camfab.cad import step
    from camfab.cad.plate import PlateSpec
    from camfab.geom2d import ArcChain

    data = json.loads((Path(__file__).parent / "data" / "wedge_fit_67222e9.json").read_text())
    fit = ArcChain.from_bulges(data["starts"], data["bulges"], closed=True)
    assert max(fit.radii[~fit.is_line]) > 1e7
    cam = pipeline.load("wedge_translating")
    path = tmp_path / "old.step"
    m = cam.spec.manufacturing
    plate = PlateSpec(m.thickness_mm, m.bore_mm, m.keyway, m.hub_diameter_mm, m.hub_length_mm)
    path.write_text(step.dumps(fit, plate))
    assert any("CurveOnSurface" in f for f in bop_faults(read_step(path)))
