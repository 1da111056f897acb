"""Cylindrical cams with a rib (``[cylinder] feature = "rib"``): two rollers straddle a rib whose mid-line is the
follower's pitch curve.  The rib's width where it runs round, its closed form on a constant lead, the rollers'
clearance b/2 in 3D, the flanks' convex/concave swap against a groove, the design's rules, the check's object,
the developed DXF and the refused solid."""
from __future__ import annotations

import math

import numpy as np
import pytest

from camfab.design.assemble import check_design
from camfab.design.mechanisms import geometry_from_spec
from camfab.design.spec import design_from_dict
from camfab.errors import SpecError
from tests.design.test_cylindrical import helix_contact
from tests.design.test_roller_section import axis_distances

RR, B, W = 6.0, 0.1, 8.0
LAW = [{"law": "constant_velocity", "lift": 20.0, "angle_deg": 90.0}, {"law": "dwell", "lift": 0.0, "angle_deg": 70.0},
       {"law": "cycloidal", "lift": -20.0, "angle_deg": 200.0}]


def rib(motion=None, follower=None, **cyl):
    c = {"radius_mm": 40.0, "length_mm": 80.0, "feature": "rib", "rib_width_mm": W, "rib_height_mm": 10.0,
         "backlash_mm": B} | cyl
    c = {k: v for k, v in c.items() if v is not None}  # None: the key left out
    f = {"type": "roller", "motion": "translating", "roller_radius_mm": RR} | (follower or {})
    return design_from_dict({"name": "ribbed", "cam": {"kind": "cylindrical"}, "cylinder": c, "follower": f,
                             "motion": motion or LAW})


def test_rib_width_is_the_key_where_it_runs_round_and_closed_form_on_a_lead():
    """Where the rib runs round (dwells) its developed flanks are exactly ``rib_width_mm`` apart on every
    radius; on the constant-lead rise both flanks are straight lines, the rib's width across them
    ``2·(d·n_z − σ(t*)·n)`` with d = w/2 + R_r + b/2 the rollers' offset (narrower than w: a rigid fork)."""
    geom = geometry_from_spec(rib())
    d = W / 2 + RR + B / 2
    assert geom.mechanism.rib_offset_mm == d
    dwell = np.radians(np.linspace(92.0, 158.0, 23))
    rise = np.radians(np.linspace(2.0, 88.0, 23))
    for r in (35.0, 40.0, 45.0):
        up, down = geom.at_radius(r, 1), geom.at_radius(r, -1)
        gap = up.evaluate(dwell).point - down.evaluate(dwell).point
        np.testing.assert_allclose(gap, np.tile([0.0, W], (len(dwell), 1)), atol=1e-9)
        p = 20.0 / (math.pi / 2) / r
        ct, _ = helix_contact(p, RR + B / 2, r)
        n = np.array([-p, 1.0]) / math.hypot(1.0, p)
        support = np.array([r * math.asin((RR + B / 2) * ct / r), (RR + B / 2) * math.sqrt(1 - ct * ct)]) @ n
        across = (up.evaluate(rise).point - down.evaluate(rise).point) @ n
        np.testing.assert_allclose(across, 2 * (d * n[1] - support), rtol=1e-12)
        assert across[0] < W


def test_rollers_clear_the_rib_by_half_the_backlash():
    """At any cam angle each roller's axis (a 3D line) is exactly R_r + b/2 from the rib flank it faces on
    every radius: each roller clears the rib by b/2."""
    geom = geometry_from_spec(rib(roller="cylindrical"))
    d = geom.mechanism.rib_offset_mm
    for r in (35.0, 40.0, 45.0):
        for flank in (1, -1):
            np.testing.assert_allclose(axis_distances(geom, r, flank, (0.4, 1.0, 2.2, 4.0), flank * d), RR + B / 2,
                                       atol=2e-6)


def test_rib_flanks_swap_convex_and_concave_against_the_groove():
    """The rib's +z flank is enveloped by the −z side of the roller above it: its signed pitch curvature (positive
    = convex material) is the groove's −z flank's, and the undercut a tight stretch gives the groove's +z flank
    moves to the rib's −z flank."""
    law = [{"law": "cycloidal", "lift": 40.0, "angle_deg": 60.0}, {"law": "dwell", "lift": 0.0, "angle_deg": 60.0},
           {"law": "cycloidal", "lift": -40.0, "angle_deg": 180.0}, {"law": "dwell", "lift": 0.0, "angle_deg": 60.0}]
    groove = design_from_dict({"name": "g", "cam": {"kind": "cylindrical"}, "motion": law,
                               "cylinder": {"radius_mm": 20.0, "length_mm": 90.0, "groove_depth_mm": 6.0},
                               "follower": {"type": "roller", "motion": "translating", "roller_radius_mm": RR}})
    ribbed = rib(law, radius_mm=20.0, rib_height_mm=6.0, length_mm=90.0, backlash_mm=0.0)
    phi = np.linspace(0.0, 2 * math.pi, 721)
    g, rb = geometry_from_spec(groove), geometry_from_spec(ribbed)
    for flank in (1, -1):
        np.testing.assert_allclose(rb.at_radius(17.0, flank).evaluate(phi).curvature_pitch,
                                   g.at_radius(17.0, -flank).evaluate(phi).curvature_pitch, atol=1e-12)
    found = {}
    for name, spec in (("groove", groove), ("rib", ribbed)):
        msgs = [f.message for f in check_design(spec).findings if f.code.value == "UNDERCUT"]
        found[name] = {(m.split(",")[0], m.split(",")[1].split(":")[0].strip(), m.split(": ")[1]) for m in msgs}
    assert len(found["groove"]) == 6
    swap = {"+z flank": "-z rib flank", "-z flank": "+z rib flank"}
    names = {"groove bottom": "rib root", "outer cylinder": "rib top", "pitch cylinder": "pitch cylinder"}
    moved = set()
    for where, flank, text in found["groove"]:
        place, radius = where.split(" r = ")
        moved.add((f"{names[place]} r = {radius}", swap[flank], text))
    assert moved == found["rib"]


def test_check_object_names_the_feature():
    rep = check_design(rib()).to_dict()["cylinder"]
    assert rep["feature"] == "rib" and rep["rib_width_mm"] == W and rep["rib_height_mm"] == 10.0
    assert rep["groove_depth_mm"] is None and rep["roller_offset_mm"] == W / 2 + RR + B / 2
    assert [x["where"] for x in rep["radii"]] == ["rib root", "pitch cylinder", "rib top"]
    g = check_design(rib(feature="groove", rib_width_mm=None, rib_height_mm=None, groove_depth_mm=10.0))
    assert g.to_dict()["cylinder"]["feature"] == "groove"


@pytest.mark.parametrize("cyl, follower, path", [
    ({"rib_width_mm": None}, None, "cylinder.rib_width_mm"),
    ({"rib_height_mm": None}, None, "cylinder.rib_height_mm"),
    ({"groove_depth_mm": 5.0}, None, "cylinder.groove_depth_mm"),
    ({"feature": "ridge"}, None, "cylinder.feature"),
    ({}, {"motion": "oscillating", "arm_length_mm": 50.0}, "cylinder.feature"),
    ({"feature": "groove", "groove_depth_mm": 5.0}, None, "cylinder.rib_width_mm"),
])
def test_bad_rib_designs_name_their_field(cyl, follower, path):
    with pytest.raises(SpecError) as exc:
        check_design(rib(follower=follower, **cyl))
    assert path in {p.path for p in exc.value.problems}


RIB_TOML = """name = "Ribbed"
[cam]
kind = "cylindrical"
[cylinder]
radius_mm = 40.0
length_mm = 80.0
feature = "rib"
rib_width_mm = 8.0
rib_height_mm = 10.0
backlash_mm = 0.1
[follower]
type = "roller"
motion = "translating"
roller_radius_mm = 6.0
[[motion]]
law = "cycloidal"
lift = 20.0
angle_deg = 140.0
[[motion]]
law = "dwell"
lift = 0.0
angle_deg = 40.0
[[motion]]
law = "cycloidal"
lift = -20.0
angle_deg = 180.0
[manufacturing]
tolerance_mm = 0.01
tool_diameter_mm = 6.0
"""


def test_rib_files_dxf_and_refused_program(tmp_path, capsys):
    """``run`` writes the developed rib (DXF: both rib flanks exactly ``rib_width_mm`` apart where it runs round,
    read back with ezdxf) and the workbook; ``camfab gcode`` with this 6 mm end mill (half the rollers' size: it
    cannot follow the rib flanks' twist, :mod:`camfab.gcode.rib_program`) exits 2 naming
    ``manufacturing.tool_diameter_mm``."""
    ezdxf = pytest.importorskip("ezdxf")
    from camfab.cli import main
    from camfab.pipeline import Output, Request, load, run

    src = tmp_path / "rib.toml"
    src.write_text(RIB_TOML, encoding="utf-8")
    cam = load(src)
    run(cam, tmp_path / "out", Request(frozenset({Output.DXF, Output.XLSX})))
    assert sorted(p.name for p in (tmp_path / "out").iterdir() if p.suffix != ".lock") == [
        "Ribbed.dxf", "Ribbed.xlsx", "check.json"]
    doc = ezdxf.readfile(tmp_path / "out" / "Ribbed.dxf")
    z0 = cam.geometry.mechanism.z0_for(cam.geometry.program)
    x_dwell = 40.0 * np.radians([140.0, 180.0])
    for layer, side in (("PROFILE", 1), ("PROFILE_2", -1)):
        (pl,) = [e for e in doc.modelspace() if e.dxf.layer == layer]
        pts = np.array([(x, y) for x, y, *_ in pl.get_points("xyseb")])
        on = pts[np.abs(pts[:, 1] - (z0 + 20.0 + side * W / 2)) < 1e-9, 0]  # the dwell's straight segment's ends
        assert on.min() <= x_dwell[0] and on.max() >= x_dwell[1]
    assert main(["gcode", str(src), "-o", str(tmp_path / "nc")]) == 2
    assert "manufacturing.tool_diameter_mm" in capsys.readouterr().err
