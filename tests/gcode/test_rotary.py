"""The 4-axis program of a cylindrical cam (camfab.gcode.rotary): back-plotted on the cylinder against the exact
motion law written out here (the example's cycloidal rise and return), read by LinuxCNC's ``rs274``, refused on
GRBL and with a tool as wide as the groove."""
from __future__ import annotations

import math
import re
import shutil
import subprocess
import tomllib
from pathlib import Path

import numpy as np
import pytest
from scipy.ndimage import maximum_filter1d
from scipy.spatial import cKDTree

from camfab import pipeline
from camfab.cli import main
from camfab.errors import ExportError, SpecError
from camfab.gcode.model import design_job
from camfab.gcode.rotary import cylinder_job, rotary_gcode

EXAMPLE = Path(pipeline.__file__).parent / "examples" / "cylindrical_translating.toml"
#: the example's end mill radius (its [manufacturing] tool_diameter_mm / 2)
TOOL_R = tomllib.loads(EXAMPLE.read_text())["manufacturing"]["tool_diameter_mm"] / 2
RS274 = shutil.which("rs274")
_WORD = re.compile(r"([A-Z])([+-]?\d+\.?\d*)")


def _law(theta: np.ndarray) -> np.ndarray:
    """The example's axial position (mm) at cam angle θ (rad): z₀ = 20 (the 20 mm travel centred on 60 mm),
    cycloidal rise 20 mm over 140°, dwell 40°, cycloidal return over 140°, dwell 40°."""
    t = np.mod(np.degrees(theta), 360.0)
    cyc = lambda u: u - np.sin(2 * np.pi * u) / (2 * np.pi)  # noqa: E731
    s = np.where(t < 140, 20 * cyc(t / 140), 20.0)
    s = np.where((t >= 180) & (t < 320), 20 - 20 * cyc((t - 180) / 140), s)
    s = np.where(t >= 320, 0.0, s)
    return 20.0 + s


def _program(post: str = "linuxcnc", **machining) -> tuple[bytes, float]:
    cam = pipeline.load(str(EXAMPLE))
    tol = cam.tolerance()
    job = cylinder_job(design_job(cam.spec, tol=tol, overrides=machining), cam.geometry)
    data, _, _ = rotary_gcode(cam.geometry, job, tol, post)
    return data, tol


def _passes(text: str) -> list[tuple[str, float, np.ndarray]]:
    """Each inverse-time pass as (the comment naming it, Z, array of (X, A, F)), read with a tiny modal reader
    (independent of camfab's readers); the start point of each pass (the plunge's X, A) comes first with
    F = nan."""
    out, pos, g93, cur, label = [], {"X": math.nan, "A": math.nan, "Z": math.nan}, False, None, ""
    for line in text.splitlines():
        if line.startswith("(") and "pass" in line.lower():
            label = line.strip("()").lower()
        if line.startswith("(") or line == "%" or line.startswith("O"):
            continue
        words = dict(_WORD.findall(line.split("(")[0]))
        words.pop("N", None)
        if words.get("G") == "93":
            g93, cur = True, [(pos["X"], pos["A"], math.nan)]
        elif words.get("G") == "94" and g93:
            g93 = False
            out.append((label, pos["Z"], np.array(cur)))
        for k in "XAZ":
            if k in words:
                pos[k] = float(words[k])
        if g93 and words.get("G") == "1":
            assert "F" in words, f"an inverse-time move without F: {line}"
            assert "Z" not in words
            cur.append((pos["X"], pos["A"], float(words["F"])))
    return out


def _centre(passes):
    return [(z, P) for label, z, P in passes if label.startswith("centre pass")]


@pytest.mark.parametrize("post", ["linuxcnc", "fanuc"])
def test_backplot_lies_on_the_exact_pitch_curve(post):
    data, tol = _program(post)
    passes = _centre(_passes(data.decode()))
    assert len(passes) == 4  # 10 mm deep, step-down 3 mm: four levels
    zs = [z for z, _ in passes]
    assert zs[-1] == pytest.approx(35.0, abs=1e-9)  # the last level on the groove bottom radius
    assert np.all(np.diff([45.0, *zs]) < 0) and np.all(-np.diff([45.0, *zs]) <= 3.0 + 1e-9)
    # the example's cutting data, as the header states it (linuxcnc "(feed: F mm/min", fanuc "(FEED F MM/MIN")
    feed = float(re.search(r"\(feed:? ([0-9.]+) mm/min", data.decode(), re.IGNORECASE).group(1))
    for r, P in passes:
        X, A, F = P.T
        theta = -np.radians(A)  # cw: A = −θ
        assert theta[0] == pytest.approx(0.0) and theta[-1] == pytest.approx(2 * np.pi)
        assert np.all(np.diff(theta) > 0)
        assert np.max(np.abs(X - _law(theta))) <= tol  # every programmed point on the exact law
        # every chord within tol of the exact curve between its ends, on the developed cylinder of radius r
        t = np.linspace(0.0, 1.0, 9)[1:-1, None]
        th = theta[:-1] + t * np.diff(theta)
        q = np.stack([r * th, _law(th)], axis=-1)
        a = np.stack([r * theta[:-1], X[:-1]], axis=-1)
        b = np.stack([r * theta[1:], X[1:]], axis=-1)
        d = b - a
        u = np.clip(np.sum((q - a) * d, axis=-1) / np.sum(d * d, axis=-1), 0, 1)
        dev = np.hypot(*(q - a - u[..., None] * d).transpose(2, 0, 1))
        assert dev.max() <= tol, f"chord {dev.max():.5f} mm off the exact pitch curve at r = {r}"
        # inverse time: each move's minutes (1/F) are its length on the tool tip's cylinder at the feed
        length = np.hypot(np.diff(X), r * np.diff(theta))
        assert np.allclose(1.0 / F[1:], length / feed, rtol=2e-3)


@pytest.mark.skipif(RS274 is None, reason="LinuxCNC's rs274 interpreter is not installed (linuxcnc-uspace)")
@pytest.mark.parametrize("post", ["linuxcnc", "fanuc"])
def test_rs274_runs_the_4_axis_program(post, tmp_path):
    """rs274's default configuration has the A axis: it runs the program and its feeds end on the groove bottom,
    every fed point on the exact law."""
    data, tol = _program(post)
    (tmp_path / "p.ngc").write_bytes(data)
    proc = subprocess.run([str(RS274), "-g", str(tmp_path / "p.ngc")], capture_output=True, text=True, timeout=120,
                          stdin=subprocess.DEVNULL)
    assert proc.returncode == 0, proc.stdout[-600:]
    feeds = np.array([[float(v) for v in m.group(1).split(",")[:4]] for m in
                      re.finditer(r"STRAIGHT_FEED\(([^)]*)\)", proc.stdout)])
    assert "PROGRAM_END" in proc.stdout
    cut = feeds[np.abs(feeds[:, 3]) > 0]  # the moves that turn the table
    n_centre = sum(len(P) - 1 for _, P in _centre(_passes(data.decode())))
    centre, finish = cut[:n_centre], cut[n_centre:]
    assert np.allclose(cut[:, 1], 0.0) and centre[-1, 2] == pytest.approx(35.0)
    assert np.max(np.abs(centre[:, 0] - _law(-np.radians(centre[:, 3])))) <= tol
    # the finishing passes (on the groove bottom): every fed point w − r_c from the pitch curve, but the two
    # lead-outs' ends, back on it
    assert np.allclose(finish[:, 2], 35.0)
    C, _ = _pitch_dense(35.0)
    d, _ = cKDTree(C).query(np.stack([35.0 * -np.radians(finish[:, 3]), finish[:, 0]], axis=1))
    off = np.abs(d - (6.025 - TOOL_R)) <= tol
    assert np.sum(~off) == 2 and np.all(d[~off] <= tol)


def _pitch_dense(r: float, n: int = 600_001) -> tuple[np.ndarray, np.ndarray]:
    """The exact developed pitch curve (r·θ, law(θ)) on radius r over θ in [−2π − 0.2, 2π + 0.2], and its unit
    normal towards +z (from the analytic law; derivative by central differences on the dense grid)."""
    th = np.linspace(-2 * np.pi - 0.2, 2 * np.pi + 0.2, n)
    C = np.stack([r * th, _law(th)], axis=1)
    T = np.gradient(C, th, axis=0)
    return C, np.stack([-T[:, 1], T[:, 0]], axis=1) / np.hypot(T[:, 0], T[:, 1])[:, None]


def _dense_chords(pts: np.ndarray, k: int = 64) -> np.ndarray:
    t = np.linspace(0.0, 1.0, k + 1)[:-1, None, None]
    return (pts[:-1] + t * np.diff(pts, axis=0)).reshape(-1, 2)


def _section(r: float, h: float, f: float, n: int = 81) -> np.ndarray:
    """The half facing the flank f (+1: +z) of the exact section of a radial cylinder of radius h (the cutter, or
    the roller enlarged by half the backlash) by the cylinder r, developed: (r·asin(h·cos t / r), h·sin t)."""
    t = f * (np.pi / 2 + np.linspace(-1.0, 1.0, n))
    return np.stack([r * np.arcsin(h * np.cos(t) / r), h * np.sin(t)], axis=1)


def _extent(tree, C: np.ndarray, up: np.ndarray, centres: np.ndarray, sec: np.ndarray, f: float,
            window: int = 13) -> np.ndarray:
    """The union of the sections ``sec`` placed at ``centres``: at each point of the pitch curve C (its unit normal
    up, its k-d tree), its farthest reach on the flank f's side, measured along the normal (−inf: none), the
    largest over the neighbours within ``window`` points (the sections' farthest points are sampled sparsely)."""
    X = (centres[:, None, :] + sec[None]).reshape(-1, 2)
    _, k = tree.query(X)
    ext = np.full(len(C), -np.inf)
    np.maximum.at(ext, k, f * np.sum((X - C[k]) * up[k], axis=1))
    return maximum_filter1d(ext, window)


def test_finishing_passes_lie_on_the_flank_offsets_and_cut_the_groove_width():
    """Each flank's finishing pass, back-plotted on the developed groove bottom (x = r·θ, θ = −A for a cw cam),
    runs once round, and the slot its radial end mill cuts — the union of the cutter's exact sections (a circle
    stretched along x, r·asin(r_c·cos t / r)) along the pass, measured from the law's pitch curve — is the exact
    groove, the union of the roller's sections (R_r + b/2, 12.05 mm wide where the track runs along x): on the
    bottom within the tolerance on each flank and across the groove (the chords' sagitta), each programmed point's
    section reaching its flank within it; on the outer radius (the twist) at most the tolerance wider."""
    data, tol = _program()
    fin = [(label, z, P) for label, z, P in _passes(data.decode()) if label.startswith("finishing pass")]
    assert len(fin) == 2 and {("+z" in label) for label, _, _ in fin} == {True, False}
    w, r_c, r_b = 6.025, TOOL_R, 35.0
    C, _ = _pitch_dense(r_b)
    cut = {}
    for label, z, P in fin:
        assert z == pytest.approx(r_b)
        f = 1.0 if "+z" in label else -1.0
        pts = np.stack([r_b * -np.radians(P[:, 1]), P[:, 0]], axis=1)
        path = pts[1:-1]  # between the lead-in from and the lead-out to the pitch curve
        assert abs(path[-1, 0] - path[0, 0]) == pytest.approx(2 * np.pi * r_b, abs=tol)
        assert cKDTree(C).query(pts[[0, -1]])[0].max() <= tol
        cut[f] = path if path[-1, 0] > 0 else path + [2 * np.pi * r_b, 0.0]  # the backwards pass, one turn on
    th = np.linspace(-0.3, 2 * np.pi + 0.3, 4_001)
    for r, slack in ((r_b, tol), (45.0, 2 * tol)):
        C_r, up = (a[::50] for a in _pitch_dense(r))  # one pitch point every 0.04 mm or less
        tree = cKDTree(C_r)
        inside = (C_r[:, 0] > 1.0) & (C_r[:, 0] < 2 * np.pi * r - 1.0)
        groove = np.stack([r * th, _law(th)], axis=1)
        width, exact = 0.0, 0.0
        for f, path in cut.items():
            flank_all = _extent(tree, C_r, up, groove, _section(r, w, f), f)
            flank = flank_all[inside]
            slot = _extent(tree, C_r, up, _dense_chords(path * [r / r_b, 1.0], 8), _section(r, r_c, f), f)[inside]
            assert np.all(slot - flank <= slack), (r, f, float(np.max(slot - flank)))
            if r == r_b:
                assert np.all(slot - flank >= -tol), (f, float(np.min(slot - flank)))
                # each programmed point: its cutter's exact section reaches the exact flank (within the sampling and
                # the program's rounding, 0.3 µm here; the circular offset r_c·n would miss it by 0.9 µm)
                X = path[:, None, :] + _section(r, r_c, f)[None]
                _, k = tree.query(X.reshape(-1, 2))
                k = k.reshape(X.shape[:2])
                d = f * np.sum((X - C_r[k]) * up[k], axis=2)
                j = np.argmax(d, axis=1)
                reach, foot = d[np.arange(len(d)), j], k[np.arange(len(d)), j]
                on = inside[foot]
                miss = np.abs(reach - flank_all[foot])[on]
                assert np.all(miss <= 0.06 * tol), float(np.max(miss))
            width, exact = width + slot, exact + flank
        assert np.min(exact) == pytest.approx(12.05, abs=1e-3)  # the roller's diameter + backlash, along x
        assert width.min() >= exact.min() - slack and np.all(width <= exact + slack), (r, np.max(width - exact))


def test_grbl_and_a_wide_tool_are_refused(tmp_path):
    with pytest.raises(ExportError, match="--post grbl.*rotary"):
        _program("grbl")
    with pytest.raises(SpecError, match="manufacturing.tool_diameter_mm"):
        _program(tool_diameter_mm=12.05)
    out = tmp_path / "g.nc"
    assert main(["gcode", str(EXAMPLE), "-o", str(out), "--post", "grbl"]) == 2
    assert main(["gcode", str(EXAMPLE), "-o", str(out), "--tool-diameter", "12.5"]) == 2
    assert not out.exists()


def test_a_cutter_that_cannot_finish_the_flanks_is_refused(tmp_path, capsys):
    """A 10 mm end mill in the 12.05 mm groove would cut past the flanks higher up (the twist): refused with exit 2
    naming the field and the diameter that fits, which is then accepted; an undercut flank refuses every cutter."""
    out = tmp_path / "g.nc"
    assert main(["gcode", str(EXAMPLE), "-o", str(out), "--tool-diameter", "10"]) == 2
    err = capsys.readouterr().err
    assert "manufacturing.tool_diameter_mm" in err and "past the flank" in err and not out.exists()
    fits = float(re.search(r"diameter at least ([0-9.]+) mm", err).group(1))
    assert 10.0 < fits < 12.05
    _program(tool_diameter_mm=fits)  # the diameter it names is accepted
    from camfab.design.mechanisms import geometry_from_spec
    from camfab.design.spec import design_from_dict
    from camfab.gcode.model import Job

    spec = design_from_dict({"name": "b", "cam": {"kind": "cylindrical"},
                             "follower": {"type": "roller", "motion": "translating", "roller_radius_mm": 6.0},
                             "cylinder": {"radius_mm": 20.0, "length_mm": 80.0, "groove_depth_mm": 10.0},
                             "motion": [{"law": "cycloidal", "lift": 25.0, "angle_deg": 60.0},
                                        {"law": "dwell", "lift": 0.0, "angle_deg": 120.0},
                                        {"law": "cycloidal", "lift": -25.0, "angle_deg": 60.0},
                                        {"law": "dwell", "lift": 0.0, "angle_deg": 120.0}]})
    with pytest.raises(SpecError, match=r"(?s)manufacturing.tool_diameter_mm.*concave radius.*undercut"):
        rotary_gcode(geometry_from_spec(spec), Job(tool_diameter_mm=11.0, depth_mm=10.0), 0.01, "linuxcnc")
    # an oscillating roller swung 15° on a 60 mm arm: its axis 2 mm off the radial line, no radial cutter follows it
    spec = design_from_dict({"name": "b", "cam": {"kind": "cylindrical"},
                             "follower": {"type": "roller", "motion": "oscillating", "roller_radius_mm": 6.0,
                                          "arm_length_mm": 60.0},
                             "cylinder": {"radius_mm": 40.0, "length_mm": 80.0, "groove_depth_mm": 10.0},
                             "motion": [{"law": "cycloidal", "lift": 15.0, "angle_deg": 150.0},
                                        {"law": "cycloidal", "lift": -15.0, "angle_deg": 210.0}]})
    with pytest.raises(SpecError, match=r"(?s)follower.arm_length_mm.*radial.*tolerance of at least 0\.1"):
        rotary_gcode(geometry_from_spec(spec), Job(tool_diameter_mm=11.9, depth_mm=10.0), 0.01, "linuxcnc")


def test_run_writes_the_program(tmp_path):
    assert main(["run", str(EXAMPLE), "-o", str(tmp_path), "--outputs", "gcode"]) in (0, 1)
    text = (tmp_path / "BarrelCam.nc").read_text()
    assert "G93" in text and "A-360.0000" in text and "Z0 on the rotary axis" in text


@pytest.mark.parametrize("rotation,follower", [
    ("ccw", {}),
    ("cw", {"motion": "oscillating", "arm_length_mm": 60.0}),  # a 5° swing: the axis swings 0.23 mm aside
    ("ccw", {"motion": "oscillating", "arm_length_mm": 60.0}),
])
def test_tool_tip_lies_on_the_3d_pitch_curve(rotation, follower):
    """The work offset and the sign of A, in 3D: each programmed tool tip (X, A, Z) taken back into the cam frame
    (machine (Y, Z, X) = cam (X_c, Y_c, Z_c), the part turned back by −A about X) lies on the 3D pitch curve of its
    radius (``pitch_3d``) within the tolerance, for either sense and the oscillating follower's exact arc."""
    from camfab.design.cylindrical import pitch_3d
    from camfab.design.mechanisms import geometry_from_spec
    from camfab.design.spec import design_from_dict
    from camfab.gcode.model import Job

    f = {"type": "roller", "motion": "translating", "roller_radius_mm": 6.0} | follower
    lift = 5.0 if follower else 20.0
    spec = design_from_dict({"name": "b", "cam": {"kind": "cylindrical", "rotation": rotation}, "follower": f,
                             "cylinder": {"radius_mm": 40.0, "length_mm": 80.0, "groove_depth_mm": 10.0},
                             "motion": [{"law": "cycloidal", "lift": lift, "angle_deg": 150.0},
                                        {"law": "cycloidal", "lift": -lift, "angle_deg": 210.0}]})
    geom = geometry_from_spec(spec)
    tol = 0.01
    data, _, _ = rotary_gcode(geom, Job(tool_diameter_mm=11.9, depth_mm=10.0, tolerance_mm=tol), tol, "linuxcnc")
    passes = _centre(_passes(data.decode()))
    assert [z for z, _ in passes][-1] == pytest.approx(35.0)
    for r, P in passes:
        X, A, _ = P.T
        a = np.radians(A)
        # the tool tip is at machine (X, 0, r); in the part frame (turned back by A): Y = r·sin A, Z = r·cos A
        tip = np.stack([r * np.sin(a), r * np.cos(a), X], axis=1)
        dense = pitch_3d(geom, np.linspace(0.0, 2 * np.pi, 400_001), r)
        dist, _ = cKDTree(dense).query(tip)
        assert dist.max() <= tol, f"{rotation} {follower}: tool tip {dist.max():.5f} mm off the 3D pitch curve"
