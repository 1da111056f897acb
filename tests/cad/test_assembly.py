"""The assembly STEP read back with cadquery/OCP: valid named solids, and each follower touching its cam.

At several cam angles, for every follower type of the built-in examples: the minimum distance between the
follower's contact part (roller or face) and its cam is 0 within the export tolerance, and the two do not
interfere — their boolean common has about zero volume: the arc fit lies within ``tol`` of the exact profile on
either side, so a roller may sink at most ``tol`` into it, over a chord ``2·√(2·tol·R)`` long, hence a common
volume below ``tol · 2·√(2·tol·R) · width`` (R the larger of the radii, ~ the cam size).  The same check with
the follower pushed ``20·tol`` into the cam finds interference: the test can fail.
"""
from __future__ import annotations

import dataclasses
import math
import sys

import pytest

cq = pytest.importorskip("cadquery")
from OCP.BRepAlgoAPI import BRepAlgoAPI_Common  # noqa: E402
from OCP.BRepCheck import BRepCheck_Analyzer  # noqa: E402
from OCP.BRepExtrema import BRepExtrema_DistShapeShape  # noqa: E402
from OCP.BRepGProp import BRepGProp  # noqa: E402
from OCP.GProp import GProp_GProps  # noqa: E402

import camfab  # noqa: E402
from camfab.cad import assembly  # noqa: E402


def _volume(shape) -> float:
    props = GProp_GProps()
    BRepGProp.VolumeProperties_s(shape, props)
    return props.Mass()


def _read(path):
    """{part name: located cadquery Shape} of an assembly STEP."""
    assy = cq.Assembly.importStep(str(path))
    out = {}
    for name, sub in assy.objects.items():
        if sub is assy or not sub.shapes:
            continue
        shape = sub.shapes[0] if len(sub.shapes) == 1 else cq.Compound.makeCompound(sub.shapes)
        out[name] = shape.moved(sub.loc) if sub.loc is not None else shape
    return out


def _write(cam, angle_deg, tmp_path):
    x = float(cam.geometry.axis.from_user(angle_deg))
    text = assembly.dumps(cam.spec, cam.geometry, list(cam.shapes().profiles), x)
    path = tmp_path / f"{angle_deg:g}.step"
    path.write_text(text, encoding="utf-8")
    return path


def _contact_pairs(parts):
    """(follower contact part, its cam) pairs."""
    pairs = []
    for name in parts:
        kind, _, sfx = name.partition("_")
        if kind in ("roller", "face", "knife"):
            cam = "cam" if "cam" in parts else f"cam_{sfx}"
            pairs.append((name, cam))
    return pairs


def _bound(tol, size, width):
    """The largest common volume of a follower and a cam fitted within ``tol`` (module notes)."""
    return tol * 2 * math.sqrt(2 * tol * size) * width


def _check_touching(parts, tol, size, width):
    for follower, cam in _contact_pairs(parts):
        a, b = parts[follower].wrapped, parts[cam].wrapped
        dist = BRepExtrema_DistShapeShape(a, b)
        assert dist.IsDone()
        assert dist.Value() <= 2 * tol, (follower, dist.Value())
        vol = _volume(BRepAlgoAPI_Common(a, b).Shape())
        assert vol <= _bound(tol, size, width), (follower, vol)


# (example, expected part names) — one per follower type
CASES = {
    "ejemplo1rt": {"cam", "shaft", "roller", "pin", "stem", "frame"},                      # translating roller
    "ejemplo11ro": {"cam", "shaft", "roller", "pin", "arm", "pivot", "frame"},            # oscillating roller
    "ejemplo10ex": {"cam", "shaft", "face", "stem", "frame"},                              # translating flat
    "ejemplo8da_conjugate": {"cam_1", "cam_2", "shaft", "face_1", "face_2", "stem_1", "stem_2", "frame_1",
                             "frame_2"},                                                   # conjugate flat pair
    "constant_width": {"cam", "shaft", "face_1", "face_2", "stem_1", "stem_2", "frame_1", "frame_2"},
    "constant_diameter": {"cam", "shaft", "roller_1", "roller_2", "pin_1", "pin_2", "stem_1", "stem_2",
                          "frame_1", "frame_2"},
    "wedge_translating": {"cam", "slide", "roller", "pin", "stem", "frame"},               # translating cam
    "valve_mushroom": {"cam", "shaft", "face", "stem", "frame"},                           # translating curved
    "finger_follower": {"cam", "shaft", "face", "arm", "pivot", "frame"},                  # oscillating curved
    "press_feed_oscillating": {"cam", "shaft", "roller", "pin", "arm", "pivot", "frame"},  # ccw oscillating
    "oscillating_flat": {"cam", "shaft", "face", "arm", "pivot", "frame"},                 # no example has one
    "translating_knife": {"cam", "shaft", "knife", "stem", "frame"},
    "oscillating_knife": {"cam", "shaft", "knife", "arm", "pivot", "frame"},
    "conjugate_roller": {"cam_1", "cam_2", "shaft", "roller_1", "roller_2", "pin_1", "pin_2", "stem_1", "stem_2",
                         "frame_1", "frame_2"},
    "conjugate_oscillating_roller": {"cam_1", "cam_2", "shaft", "roller_1", "roller_2", "pin_1", "pin_2", "arm_1",
                                     "arm_2", "pivot_1", "pivot_2", "frame_1", "frame_2"},
}

_RISE = [{"law": "cycloidal", "lift": 20.0, "angle_deg": 120.0},
         {"law": "cycloidal", "lift": -20.0, "angle_deg": 120.0},
         {"law": "dwell", "lift": 0.0, "angle_deg": 120.0}]
_SWING = [dict(m, lift=m["lift"] / 2) for m in _RISE]
#: follower types no built-in example has
DESIGNS = {
    "oscillating_flat": ({"type": "flat", "motion": "oscillating", "base_radius_mm": 40.0,
                          "pivot_distance_mm": 80.0, "face_offset_mm": 10.0}, _SWING),
    "translating_knife": ({"type": "knife", "motion": "translating", "base_radius_mm": 40.0, "offset_mm": 5.0},
                          _RISE),
    "oscillating_knife": ({"type": "knife", "motion": "oscillating", "base_radius_mm": 40.0,
                           "pivot_distance_mm": 80.0, "arm_length_mm": 60.0}, _SWING),
    "conjugate_roller": ({"type": "roller", "motion": "translating", "base_radius_mm": 35.0, "roller_radius_mm": 7.0,
                          "follower_distance_mm": 120.0}, _RISE),
    "conjugate_oscillating_roller": ({"type": "roller", "motion": "oscillating", "base_radius_mm": 40.0,
                                      "roller_radius_mm": 10.0, "pivot_distance_mm": 100.0, "arm_length_mm": 90.0,
                                      "follower_angle_deg": 80.0}, _SWING),
}


def _load(name):
    if name not in DESIGNS:
        return camfab.load(name)
    from camfab.design.spec import design_from_dict

    follower, motion = DESIGNS[name]
    kind = "conjugate" if name.startswith("conjugate") else "disc"
    return camfab.Cam(design_from_dict({"name": name, "cam": {"kind": kind}, "follower": follower,
                                        "motion": motion, "manufacturing": {"bore_mm": 12.0}}))


def _size(cam, angle_deg):
    """The largest |radius of curvature| of the cam's profiles where the followers touch at ``angle_deg``
    (and half a turn on, for the second follower of a constant-width cam), at most 10 × the cam's size."""
    g = cam.geometry
    big = 10 * (g.max_radius if g.closed else g.period)
    at = [angle_deg, angle_deg + 180.0] if g.closed else [angle_deg]
    rho = max(float(abs(cam.profile([a % 360.0 if g.closed else a], profile=i).rho[0]))
              for a in at for i in range(len(g.profiles)))
    return min(rho, big)


def _run(name, angles, tmp_path):
    cam = _load(name)
    tol = cam.tolerance()
    width = cam.spec.manufacturing.thickness_mm
    for ang in angles:
        parts = _read(_write(cam, ang, tmp_path))
        assert set(parts) == CASES[name]
        for pname, shape in parts.items():
            assert shape.isValid() and BRepCheck_Analyzer(shape.wrapped).IsValid(), pname
            assert len(shape.Solids()) == 1, pname
        _check_touching(parts, tol, _size(cam, ang), width)


@pytest.mark.parametrize("name", ["ejemplo1rt", "ejemplo11ro"])
def test_rollers_touch_their_cam(name, tmp_path):
    _run(name, [0.0, 75.0, 200.0], tmp_path)


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(set(CASES) - {"ejemplo1rt", "ejemplo11ro"}))
def test_every_follower_type_touches_its_cam(name, tmp_path):
    angles = [0.0, 40.0, 130.0] if name != "wedge_translating" else [0.0, 70.0, 180.0]
    _run(name, angles, tmp_path)


def test_the_check_finds_a_follower_pushed_into_the_cam(tmp_path):
    """The same measure on the roller of ejemplo1rt moved 20·tol towards the cam centre (at 0° the follower
    is on +Y): the common volume is far above the bound — the contact test can fail."""
    cam = camfab.load("ejemplo1rt")
    tol = cam.tolerance()
    parts = _read(_write(cam, 0.0, tmp_path))
    pushed = parts["roller"].translate(cq.Vector(0, -20 * tol, 0))
    vol = _volume(BRepAlgoAPI_Common(pushed.wrapped, parts["cam"].wrapped).Shape())
    assert vol > 10 * _bound(tol, _size(cam, 0.0), cam.spec.manufacturing.thickness_mm)


def test_follower_positions_are_the_exact_geometry():
    """The poses come from the design: ejemplo1rt's roller centre at 75° is at (e, R_p + S(75°)) (cw cam,
    follower fixed) and the cam turns by −75°; ejemplo11ro's roller is A from the pivot (m, 0) at ξ0 + S."""
    cam = camfab.load("ejemplo1rt")
    x = math.radians(75.0)
    (pose,), turn = assembly.follower_poses(cam.geometry, x)
    f = cam.spec.follower
    s = float(cam.spec.program()([x])[0])
    assert pose.origin == pytest.approx((0.0, f.base_radius_mm + f.roller_radius_mm + s), abs=1e-9)
    assert turn == pytest.approx(-75.0)
    cam = camfab.load("ejemplo11ro")
    (pose,), turn = assembly.follower_poses(cam.geometry, x)
    f = cam.spec.follower
    xi = cam.geometry.initial_arm_angle + math.radians(float(cam.spec.program()([x])[0]))
    assert pose.origin == pytest.approx((f.pivot_distance_mm, 0.0))
    centre = (pose.origin[0] + pose.centre[1] * pose.up[0], pose.origin[1] + pose.centre[1] * pose.up[1])
    assert centre == pytest.approx((f.pivot_distance_mm - f.arm_length_mm * math.cos(xi),
                                    f.arm_length_mm * math.sin(xi)), abs=1e-9)


def test_run_writes_the_step_and_the_assembly(tmp_path):
    """`camfab run -o out` (the built-in example, default outputs) writes the STEP and the assembly, and the
    assembly reads back with its named parts."""
    from camfab.cli import main

    assert main(["run", "-o", str(tmp_path), "--outputs", "step,assembly"]) == 0
    assert (tmp_path / "Ejemplo9RT.step").is_file()
    parts = _read(tmp_path / "Ejemplo9RT_assembly.step")
    assert set(parts) == {"cam", "shaft", "roller", "pin", "stem", "frame"}
    spec = camfab.load("ejemplo9rt").spec
    assert spec.outputs.step and spec.outputs.assembly  # on by default


def test_missing_cadquery_skips_only_the_step(tmp_path, monkeypatch, capsys):
    """Without cadquery a run writes everything else, says what it skipped, and exits 0."""
    from camfab.cli import main

    monkeypatch.setitem(sys.modules, "cadquery", None)  # `import cadquery` raises ImportError
    assert main(["run", "-o", str(tmp_path), "--outputs", "dxf,step,assembly"]) == 0
    assert sorted(p.name for p in tmp_path.iterdir() if p.suffix != ".lock") == ["Ejemplo9RT.dxf", "check.json"]
    assert "skipped (cadquery is missing" in capsys.readouterr().out


def test_assembly_step_is_reproducible_and_its_header_names_the_design(monkeypatch):
    cam = camfab.load("ejemplo1rt")
    outlines = list(cam.shapes().profiles)
    monkeypatch.delenv("SOURCE_DATE_EPOCH", raising=False)
    a = assembly.dumps(cam.spec, cam.geometry, outlines, 0.3)
    assert a == assembly.dumps(cam.spec, cam.geometry, outlines, 0.3)
    head = a.partition("DATA;")[0]
    assert "'Author'" not in head and "FILE_NAME('Ejemplo1RT','1970-01-01T00:00:00',('')," in head
    monkeypatch.setenv("SOURCE_DATE_EPOCH", "1700000000")
    b = assembly.dumps(cam.spec, cam.geometry, outlines, 0.3)
    assert "'2023-11-14T22:13:20'" in b.partition("DATA;")[0]


def test_assembly_table_is_validated():
    from camfab.design.spec import design_from_dict
    from camfab.errors import SpecError
    from camfab.formats import load_design, resolve_design_path

    base = load_design(resolve_design_path("ejemplo1rt"))
    with pytest.raises(SpecError) as err:
        design_from_dict({"name": "x", "cam": {"kind": "disc"},
                          "follower": {"type": "roller", "motion": "translating", "base_radius_mm": 50,
                                       "roller_radius_mm": 5},
                          "motion": [{"law": "simple_harmonic", "lift": 10, "angle_deg": 180},
                                     {"law": "simple_harmonic", "lift": -10, "angle_deg": 180}],
                          "assembly": {"pin_diameter_mm": -1, "stem_diam_mm": 4}})
    paths = {p.path for p in err.value.problems}
    assert paths == {"assembly.pin_diameter_mm", "assembly.stem_diam_mm"}
    spec = dataclasses.replace(base, assembly=dataclasses.replace(base.assembly, pin_diameter_mm=10.0))
    with pytest.raises(SpecError, match="assembly.pin_diameter_mm"):
        assembly.dimensions(spec, camfab.Cam(spec).geometry)  # a 10 mm pin in a 10 mm roller
    # a value given is the one built: a 6 mm wide roller on a 4 mm pin (defaults: 12 mm = the plate, 4 mm)
    spec = dataclasses.replace(base, assembly=dataclasses.replace(base.assembly, roller_width_mm=6.0))
    cam = camfab.Cam(spec)
    parts = {n: wp.val() for n, wp, _, _ in assembly.build(spec, cam.geometry, cam.shapes().profiles, 0.0).items}
    assert parts["roller"].BoundingBox().zlen == pytest.approx(6.0)
    assert parts["pin"].BoundingBox().xlen == pytest.approx(4.0)


def test_iges_reads_back_as_the_plate(tmp_path, monkeypatch):
    """The IGES of ejemplo1rt read back with OpenCascade: one valid solid of the plate's exact volume (outline
    area × thickness − bore), and the same bytes on a second write (no time of writing in its header)."""
    from OCP.IFSelect import IFSelect_RetDone
    from OCP.IGESControl import IGESControl_Reader

    from camfab.cad import iges
    from camfab.cad.export import plate_of
    from camfab.cad.plate import plate_volume

    monkeypatch.delenv("SOURCE_DATE_EPOCH", raising=False)
    cam = camfab.load("ejemplo1rt")
    loop = cam.shapes().profiles[0]
    text = iges.dumps(loop, plate_of(cam.spec), name=cam.name)
    assert text == iges.dumps(loop, plate_of(cam.spec), name=cam.name)
    assert "15H19700101.000000" in text and "Ejemplo1RT.igs" in text
    path = tmp_path / "cam.igs"
    path.write_text(text, encoding="ascii")
    reader = IGESControl_Reader()
    assert reader.ReadFile(str(path)) == IFSelect_RetDone
    reader.TransferRoots()
    shape = cq.Shape.cast(reader.OneShape())
    assert len(shape.Solids()) == 1 and BRepCheck_Analyzer(shape.wrapped).IsValid()
    assert _volume(shape.wrapped) == pytest.approx(plate_volume(loop, plate_of(cam.spec)), rel=1e-6)


@pytest.mark.parametrize("args", [["--poses", "-1"], ["--poses", "361"], ["--angle", "nan"], ["--angle", "1e7"]])
def test_bad_angle_or_poses_is_refused_before_any_work(args, tmp_path):
    from camfab.cli import main

    assert main(["run", "-o", str(tmp_path / "o"), "--outputs", "dxf", *args]) == 2
    assert not (tmp_path / "o").exists()


def test_an_unacceptable_rerun_removes_the_assembly_and_its_poses(tmp_path):
    """The assembly (and any `--poses` files) are shop files: a rerun whose verdict is unacceptable removes
    those an earlier run left, and keeps another design's."""
    from camfab.cli import main
    from camfab.formats import EXAMPLES_DIR

    d = tmp_path / "bad.toml"  # ejemplo9rt on a 12 mm base circle: undercut, unacceptable
    d.write_text((EXAMPLES_DIR / "ejemplo9rt.toml").read_text().replace("base_radius_mm = 35.0",
                                                                       "base_radius_mm = 12.0"))
    out = tmp_path / "out"
    out.mkdir()
    left = ["Ejemplo9RT_assembly.step", "Ejemplo9RT_assembly_pose1.step", "Ejemplo9RT_assembly_pose12.step"]
    for name in [*left, "Other_assembly_pose1.step"]:
        (out / name).write_text("an earlier run's file")
    assert main(["run", str(d), "-o", str(out), "--outputs", "assembly"]) == 1
    assert {p.name for p in out.iterdir() if p.suffix == ".step"} == {"Other_assembly_pose1.step"}
