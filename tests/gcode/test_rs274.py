"""Every built-in example × post through LinuxCNC's own interpreter, ``rs274`` (package linuxcnc-uspace).

``rs274 -g FILE`` reads the program as a LinuxCNC controller would and prints the canonical machine calls it
makes (``STRAIGHT_FEED(x, y, z, ...)``, ``ARC_FEED(end1, end2, centre1, centre2, rotation, end3, ...)``,
``COMMENT("...")``); it exits non-zero on the first block it cannot run.  The finishing contour it would cut
(between the ``FINISH CONTOUR`` and ``FINISH LEAD-OUT`` comments, sampled along its lines, arcs and - where the
written end radius differs from the start radius - LinuxCNC's spiral) must lie within the tolerance of the
exact tool-centre curve (the offset of the exact profile by the tool radius, measured with the project's exact
:class:`~camfab.gcode.distance.CurveDistance`, not the arcs camfab wrote).  ``camfab verify`` must pass on the
same text.  The Fanuc and GRBL dialects run through it too (``%`` and the ``O`` line are accepted by rs274).
"""
from __future__ import annotations

import math
import re
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

from camfab import pipeline
from camfab.cad.kind_exports import applies
from camfab.gcode.cam import verify_cam_program
from camfab.gcode.distance import CurveDistance
from camfab.geom2d import TWO_PI
from camfab.offset.cutter import offset_curve
from camfab.tolerances import MAX_ARC_RADIUS_MM

RS274 = shutil.which("rs274")
pytestmark = pytest.mark.skipif(RS274 is None, reason="LinuxCNC's rs274 interpreter is not installed "
                                                      "(Debian package linuxcnc-uspace; .ci/run installs it)")

POSTS = ("linuxcnc", "fanuc", "grbl")
EXAMPLES = [e for e in pipeline.examples() if applies(pipeline.load(e).spec.cam.kind, "gcode")  # milled plates
            and pipeline.load(e).spec.cam.kind != "cylindrical"]  # the 4-axis program: tests/gcode/test_rotary.py
FAST = ("wedge_translating", "ejemplo11ro")  # the two with near-straight stretches (huge arcs before the limit)

_CALL = re.compile(r"^\s*\d+\s+N\S*\s+([A-Z_]+)\((.*)\)\s*$")


def _programs(name: str, post: str) -> tuple[pipeline.Cam, list[bytes]]:
    cam = pipeline.load(name)
    req = pipeline.Request(frozenset({pipeline.Output.GCODE}), post)
    return cam, [a.data for a in pipeline.EXPORTERS[pipeline.Output.GCODE](cam, req)]


def interpret(text: bytes, tmp_path: Path, tool_table: str | None = None) -> list[tuple[str, str]]:
    """The canonical calls ``rs274`` makes for ``text``, as ``(name, arguments)``; fails on an interpreter error."""
    path = tmp_path / "prog.ngc"
    path.write_bytes(text)
    cmd = [str(RS274)]
    if tool_table is not None:
        (tmp_path / "tool.tbl").write_text(tool_table)
        cmd += ["-t", str(tmp_path / "tool.tbl")]
    proc = subprocess.run(cmd + ["-g", str(path)], capture_output=True, text=True, timeout=120,
                          stdin=subprocess.DEVNULL)
    calls = [(m.group(1), m.group(2)) for m in map(_CALL.match, proc.stdout.splitlines()) if m]
    assert proc.returncode == 0, f"rs274 refused the program:\n{proc.stdout[-600:]}\n{proc.stderr[-600:]}"
    assert calls and calls[-1][0] == "ON_RESET" and any(c[0] == "PROGRAM_END" for c in calls), proc.stdout[-400:]
    return calls


def finishing_points(calls: list[tuple[str, str]], step_mm: float = 0.05) -> tuple[np.ndarray, list[float]]:
    """Points (mm, ``(n, 2)``) along the finishing contour rs274 would cut, and the radii of its arcs."""
    scale = 1.0
    pos = None
    inside = False
    pts: list[np.ndarray] = []
    radii: list[float] = []
    for name, args in calls:
        if name == "USE_LENGTH_UNITS":
            scale = 25.4 if "INCHES" in args else 1.0
        elif name == "COMMENT":
            label = args.strip('"').upper()
            if label.endswith("CONTOUR"):
                inside = label.startswith("FINISH")
            elif "LEAD-OUT" in label or "LEAD-IN" in label:
                inside = False
        elif name in ("STRAIGHT_TRAVERSE", "STRAIGHT_FEED"):
            v = [float(x) * scale for x in args.split(",")[:3]]
            end = np.array(v[:2])
            if inside and name == "STRAIGHT_FEED" and pos is not None:
                n = max(2, math.ceil(np.hypot(*(end - pos)) / step_mm) + 1)
                pts.append(pos + np.linspace(0.0, 1.0, n)[:, None] * (end - pos))
            pos = end
        elif name == "ARC_FEED":
            v = [float(x) for x in args.split(",")]
            end, centre, rot = np.array(v[:2]) * scale, np.array(v[2:4]) * scale, int(v[4])
            if inside and pos is not None:
                r0, r1 = np.hypot(*(pos - centre)), np.hypot(*(end - centre))
                a0 = math.atan2(*(pos - centre)[::-1])
                a1 = math.atan2(*(end - centre)[::-1])
                sweep = (a1 - a0) % TWO_PI if rot > 0 else -((a0 - a1) % TWO_PI)
                sweep += math.copysign(TWO_PI, rot) * (abs(rot) - 1)
                u = np.linspace(0.0, 1.0, max(3, math.ceil(abs(sweep) * max(r0, r1) / step_mm) + 1))
                r = r0 + u * (r1 - r0)  # LinuxCNC's spiral when the two radii differ
                ang = a0 + u * sweep
                pts.append(centre + r[:, None] * np.column_stack([np.cos(ang), np.sin(ang)]))
                radii.append(max(r0, r1))
            pos = end
    assert pts, "no finishing contour found in the interpreter's output"
    return np.concatenate(pts), radii


def arc_radii(calls: list[tuple[str, str]]) -> list[float]:
    """The start radius of every arc the interpreter runs (mm), roughing and lead arcs included."""
    out, pos, scale = [], None, 1.0
    for name, args in calls:
        if name == "USE_LENGTH_UNITS":
            scale = 25.4 if "INCHES" in args else 1.0
        elif name in ("STRAIGHT_TRAVERSE", "STRAIGHT_FEED", "ARC_FEED"):
            v = [float(x) * scale for x in args.split(",")]
            if name == "ARC_FEED" and pos is not None:
                out.append(float(np.hypot(pos[0] - v[2], pos[1] - v[3])))
            pos = v[:2]
    return out


def _check(name: str, post: str, tmp_path: Path) -> None:
    cam, texts = _programs(name, post)
    tol = cam.tolerance()
    job = pipeline.gcode_job(cam.spec, tol=tol)
    if cam.spec.cam.kind == "groove":  # one program, two flanks: each finishing point on one of their paths
        from camfab.gcode.groove import verify_groove_program

        (text,) = texts
        pts, _ = finishing_points(interpret(text, tmp_path))
        paths = [CurveDistance(offset_curve(c, job.tool_radius_mm)) for c in cam.geometry.profiles]
        dev = float(np.max(np.minimum(*(np.abs(d(pts)) for d in paths))))
        assert dev <= tol, f"{name} {post}: rs274's finishing path is {dev:.6f} mm off the exact tool-centre curves"
        rep = verify_groove_program(text, *cam.geometry.profiles, job, tol=tol, post=post)
        assert rep.ok, f"{name} {post}: camfab verify finds {[p.message for p in rep.problems][:3]}"
        return
    for contact, text in zip(cam.geometry.profiles, texts, strict=True):
        calls = interpret(text, tmp_path)
        pts, _ = finishing_points(calls)
        assert max(arc_radii(calls)) <= MAX_ARC_RADIUS_MM
        exact = CurveDistance(offset_curve(contact, job.tool_radius_mm))
        dev = float(np.max(np.abs(exact(pts))))
        assert dev <= tol, f"{name} {post}: rs274's finishing path is {dev:.6f} mm off the exact tool-centre curve"
        rep = verify_cam_program(text, contact, job, tol=tol, post=post)
        assert rep.ok, f"{name} {post}: camfab verify finds {[p.message for p in rep.problems][:3]}"


@pytest.mark.parametrize("post", POSTS)
@pytest.mark.parametrize("name", FAST)
def test_rs274_runs_examples_within_tolerance(name, post, tmp_path):
    _check(name, post, tmp_path)


@pytest.mark.slow
@pytest.mark.parametrize("post", POSTS)
@pytest.mark.parametrize("name", [e for e in EXAMPLES if e not in FAST])
def test_rs274_runs_every_example_within_tolerance(name, post, tmp_path):
    _check(name, post, tmp_path)


def test_rs274_cutter_compensation_within_tolerance(tmp_path):
    """G41 with the tool's diameter in the tool table: rs274 offsets the part contour itself.  (The standalone
    interpreter's machine units are inches, and so are its tool table's.)"""
    cam = pipeline.load("ejemplo1rt")
    tol = cam.tolerance()
    req = pipeline.Request(frozenset({pipeline.Output.GCODE}), "linuxcnc", machining={"compensation": "G41"})
    text = pipeline.EXPORTERS[pipeline.Output.GCODE](cam, req)[0].data
    job = pipeline.gcode_job(cam.spec, tol=tol, overrides={"compensation": "G41"})
    calls = interpret(text, tmp_path, tool_table=f"T{job.tool_number} P{job.tool_number} "
                                                 f"D{job.tool_diameter_mm / 25.4:.6f} ;\n")
    pts, _ = finishing_points(calls)
    exact = CurveDistance(offset_curve(cam.geometry.profiles[0], job.tool_radius_mm))
    assert float(np.max(np.abs(exact(pts)))) <= tol


def test_finishing_points_reads_a_known_arc():
    """The reader itself: a quarter circle of radius 10 about the origin comes back on that circle."""
    calls = [("USE_LENGTH_UNITS", "CANON_UNITS_MM"), ("STRAIGHT_TRAVERSE", "10, 0, 0, 0, 0, 0"),
             ("COMMENT", '"FINISH CONTOUR"'), ("ARC_FEED", "0, 10, 0, 0, 1, 0, 0, 0, 0"),
             ("COMMENT", '"FINISH LEAD-OUT"')]
    pts, radii = finishing_points(calls)
    assert np.allclose(np.hypot(*pts.T), 10.0) and radii == [10.0]
    assert np.allclose(pts[-1], [0.0, 10.0]) and np.all(pts[:, 0] >= -1e-12)
