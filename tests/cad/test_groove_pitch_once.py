"""A groove cam's DXF measures and fits its one pitch curve once: the inner flank's arcs offset by the half-width w
(concentric arcs), measured on the exact pitch curve. The outer flank's arcs offset by +w lay 2w off that curve,
so their measurement ran on the k-d tree fallback (importing scipy.spatial) and was followed by a fit of its own,
both thrown away (the DXF draws one pitch curve). The pitch loop and its measured deviation are the same, and the
outer flank's arcs offset by −w are within the tolerance of the same curve: it is the centre of both flanks."""
from __future__ import annotations

import json
import subprocess
import sys

from camfab.cad.artifact import cam_shapes
from camfab.discretize import measure_deviation, measure_within
from camfab.discretize.certify import CERTIFY_SHARE
from camfab.offset import pitch_curve
from camfab.pipeline import load

from ..conftest import EXAMPLES

ROOT = EXAMPLES.parents[1]


def test_one_pitch_loop_with_its_measured_deviation():
    cam = load("groove_translating")
    tol = cam.tolerance(None)
    shapes = cam_shapes(cam.geometry, tol=tol)
    inner, outer = cam.geometry.profiles
    w = cam.geometry.half_width_mm
    assert len(shapes.pitch) == 1 and inner.roller_radius == outer.roller_radius == w
    exact = pitch_curve(inner)
    loop = shapes.profiles[0].offset_g1(w)
    dev = float(measure_within(loop, exact, tol).max)  # certified (docs/decisions.md, "measure_within")
    assert shapes.pitch[0].max_deviation == dev <= tol
    assert -1e-12 <= float(measure_deviation(loop, exact).max) - dev <= CERTIFY_SHARE * tol
    assert shapes.pitch[0].n_entities == shapes.profiles[0].n_entities  # the offset, not a fit of its own
    back = shapes.profiles[1].offset_g1(-w)
    assert back is not None and float(measure_deviation(back, exact).max) <= tol


def test_groove_dxf_export_imports_no_scipy(tmp_path):
    code = ("import json, sys\nfrom camfab.cli import main\n"
            f"rc = main(['export', 'groove_translating', '--dxf', '-o', {str(tmp_path)!r}])\n"
            "print(json.dumps([rc, sorted(m for m in sys.modules if m.split('.')[0] == 'scipy')]))")
    r = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True, text=True, timeout=300,
                       env={"PYTHONPATH": str(ROOT), "PATH": "/usr/bin:/bin"})
    rc, scipy_modules = json.loads(r.stdout.strip().splitlines()[-1])
    assert rc in (0, 1) and (tmp_path / "GrooveTranslating.dxf").is_file()
    assert scipy_modules == []
