"""Reported defects: each test fails before its fix and passes after."""
from __future__ import annotations

import pytest

from camfab.design.program import MotionProgram
from camfab.errors import SpecError
from camfab.formats import load_design
from tests.conftest import EXAMPLES, cv_jump


def _with_dwell_lift(tmp_path, lift: float):
    text = (EXAMPLES / "ejemplo9rt.toml").read_text()
    old = 'law = "dwell"\nlift = 0.0'
    i = text.index(old, text.index(old) + 1)  # the second dwell: motion[3]
    d = tmp_path / "dwell_lift.toml"
    d.write_text(text[:i] + f'law = "dwell"\nlift = {lift}' + text[i + len(old):])
    return d


def test_dwell_with_lift_refused_in_design_file(tmp_path):
    with pytest.raises(SpecError) as e:
        load_design(_with_dwell_lift(tmp_path, 5.0)).program()
    (p,) = [p for p in e.value.problems if p.path == "motion[3].lift"]
    assert p.value == 5.0 and p.rule == "a dwell does not move the follower"
    assert p.fix == "set lift = 0, or use a rise/return law for the motion"


def test_dwell_with_lift_refused_by_the_api():
    with pytest.raises(SpecError) as e:
        MotionProgram.from_segments([("simple_harmonic", 10, 90), ("dwell", 5, 90),
                                     ("simple_harmonic", -10, 90), ("dwell", 0, 90)])
    assert [p.path for p in e.value.problems] == ["motion[1].lift"]
    assert "a dwell does not move the follower" in str(e.value)


def test_dwell_with_zero_lift_still_accepted():
    MotionProgram.from_segments([("simple_harmonic", 10, 90), ("dwell", 0, 90),
                                 ("simple_harmonic", -10, 90), ("dwell", 0, 90)])


# ---- a closed stdout pipe ends quietly
def test_closed_pipe_is_quiet():
    import os
    import subprocess
    import sys
    from pathlib import Path

    root = Path(__file__).resolve().parent.parent
    env = {**os.environ, "PYTHONPATH": str(root)}
    r = subprocess.run(f"set -o pipefail; '{sys.executable}' -m camfab check ejemplo9rt | head -1",
                       shell=True, executable="/bin/bash", capture_output=True, text=True, env=env, cwd=root)
    assert r.stdout.startswith("Ejemplo9RT")
    assert "Traceback" not in r.stderr and "Broken pipe" not in r.stderr and "BrokenPipe" not in r.stderr
    assert r.returncode in (0, 141)  # the command's own code, or 128 + SIGPIPE when cut off mid-output


# ---- example names: a suggestion for a typo, and a command that lists them
def test_mistyped_example_suggests_the_closest(capsys):
    from camfab.cli import main

    assert main(["check", "ejemplo9r"]) == 2
    err = capsys.readouterr().err
    assert "'ejemplo9rt'" in err and "camfab examples" in err


def test_examples_command(capsys):
    import json

    import camfab
    from camfab.cli import main

    assert main(["examples"]) == 0
    names = capsys.readouterr().out.split()
    assert names == camfab.examples() and "ejemplo9rt" in names
    assert main(["examples", "--json"]) == 0
    assert json.loads(capsys.readouterr().out) == names


# ---- --force on a design whose velocity jumps (constant velocity beside dwells)


@pytest.mark.parametrize("argv", [["run", "--force"], ["export", "--dxf", "--force"]])
def test_force_on_a_velocity_jump_with_a_roller_writes_the_roller_profile(tmp_path, capsys, argv):
    """The roller's envelope jumps where the pitch curve has a corner; forced, the files carry the profile the
    roller makes there (tests/offset/test_corners.py checks its geometry) and the exit code stays 1."""
    from camfab.cli import main

    d = tmp_path / "cv.toml"
    d.write_text(cv_jump("roller"))
    out = tmp_path / "out"
    assert main([argv[0], str(d), "-o", str(out), *argv[1:]]) == 1
    err = capsys.readouterr().err
    assert "repeats" not in err and "Traceback" not in err
    assert (out / "cv_jump.dxf").exists()


def test_force_on_a_velocity_jump_with_a_knife_edge_writes_within_tolerance(tmp_path):
    """A knife edge's profile is the pitch curve: continuous with corners, so --force exports it, measured."""
    import camfab
    from camfab.cad.export import cam_shapes

    d = tmp_path / "cv.toml"
    d.write_text(cv_jump("knife"))
    cam = camfab.load(str(d))
    assert cam.verdict == "unacceptable"
    shapes = cam_shapes(cam.geometry, tol=0.01)
    assert max(shapes.profile_deviation) <= 0.01


def test_fit_of_a_jumping_curve_says_so():
    import numpy as np

    from camfab.discretize.curve import ParametricCurve
    from camfab.discretize.fit import arcs
    from camfab.errors import GeometryError

    def point(t):  # a circle of radius 10 that steps out to 11 on [π/2, π)
        t = np.asarray(t)
        r = np.where((t >= np.pi / 2) & (t < np.pi), 11.0, 10.0)
        return np.stack([r * np.cos(t), r * np.sin(t)], axis=-1)

    with pytest.raises(GeometryError, match="P jumps by"):
        arcs(ParametricCurve(point, [np.pi / 2, np.pi]), tol=0.01)
