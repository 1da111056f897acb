"""Shared fixtures and helpers for the camfab tests."""
from __future__ import annotations

import math
import os
import signal
from pathlib import Path

import pytest
from hypothesis import settings

from camfab.kernels import same_kernels_by_default

# numpy's and OpenBLAS's kernels as the command line pins them (docs/decisions.md, "The same bytes on every x86-64
# CPU with AVX2"): numpy is not imported yet here, so the tests compute with the bits of the files camfab writes
same_kernels_by_default()

# CI runs property tests with a fixed seed sequence (reproducible runs); locally they explore freely.
settings.register_profile("ci", derandomize=True, print_blob=True)
if os.environ.get("CI"):
    settings.load_profile("ci")

# The Ctrl-C tests send SIGINT to camfab, in this process and in commands it starts.  A suite started as an
# asynchronous job of a shell without job control (`bash .ci/run &` in a script) inherits SIGINT ignored, and so would
# every command: camfab then rightly obeys that and goes on (13 of those tests failed so).  Python's own handler
# here makes SIGINT deliverable again, and the commands started from here get the default action back.
if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
    signal.signal(signal.SIGINT, signal.default_int_handler)

EXAMPLES = Path(__file__).resolve().parents[1] / "camfab" / "examples"

#: Ejemplo9RT's segment list (the CAM-DAS thesis, §7.4.9 Ejemplo9RT)
EJEMPLO9RT = [("modified_sine", 10, 50), ("dwell", 0, 40), ("cycloidal", -10, 50), ("dwell", 0, 40),
              ("poly345", 10, 50), ("dwell", 0, 40), ("poly4567", -10, 50), ("dwell", 0, 40)]
#: Ejemplo11RO's law (degrees; the CAM-DAS thesis, §7.4.11 Ejemplo11RO; reproduces Fig 7.19)
EJEMPLO11RO = [("dwell", 0, 90), ("poly4567", 25, 90), ("poly4567", -10, 45), ("poly4567", 10, 45),
               ("poly4567", -25, 90)]


#: the commonest unacceptable design: constant-velocity rise and return beside dwells (the velocity jumps at
#: every junction); placeholders ``follower``, ``roller`` (a ``roller_radius_mm = ...`` line or ""),
#: ``rotation``, ``offset`` and ``tool``
CV_JUMP = """name = "cv_jump"
[cam]
kind = "disc"
rotation = "{rotation}"
omega_rad_s = 1.0
[follower]
type = "{follower}"
motion = "translating"
base_radius_mm = 40.0
{roller}offset_mm = {offset}
[[motion]]
law = "constant_velocity"
lift = 10.0
angle_deg = 120.0
[[motion]]
law = "dwell"
angle_deg = 60.0
[[motion]]
law = "constant_velocity"
lift = -10.0
angle_deg = 120.0
[[motion]]
law = "dwell"
angle_deg = 60.0
[manufacturing]
thickness_mm = 10.0
bore_mm = 12.0
tool_diameter_mm = {tool}
tolerance_mm = 0.01
"""


def cv_jump(follower: str = "roller", roller: float = 8.0, rotation: str = "cw", offset: float = 0.0,
            tool: float = 6.0) -> str:
    """:data:`CV_JUMP` filled in (``roller`` ignored for a knife edge)."""
    line = f"roller_radius_mm = {roller}\n" if follower == "roller" else ""
    return CV_JUMP.format(follower=follower, roller=line, rotation=rotation, offset=offset, tool=tool)


def base_design(**over):
    """A valid design dict (Ejemplo9RT) with top-level sections replaced by ``over``."""
    d = {
        "name": "T",
        "cam": {"kind": "disc", "rotation": "cw", "omega_rad_s": 1.0},
        "follower": {"type": "roller", "motion": "translating", "base_radius_mm": 35.0,
                     "roller_radius_mm": 7.0, "offset_mm": 0.0},
        "motion": [{"law": law, "lift": float(h), "angle_deg": float(b)} for law, h, b in EJEMPLO9RT],
    }
    d.update(over)
    return d


#: the arm of :func:`oscillating_cylinder` (mm)
CYLINDER_ARM_MM = 60.0


def oscillating_cylinder(rotation: str = "cw") -> dict:
    """A cylindrical cam's design dict with an oscillating roller follower (arm :data:`CYLINDER_ARM_MM`, pivot
    perpendicular to the axis): a groove 10 mm deep around a 40 mm pitch radius, poly345 30° up over 180° and
    down over 180°."""
    return {"name": "b", "cam": {"kind": "cylindrical", "rotation": rotation},
            "cylinder": {"radius_mm": 40.0, "length_mm": 90.0, "groove_depth_mm": 10.0},
            "follower": {"type": "roller", "motion": "oscillating", "roller_radius_mm": 6.0,
                         "arm_length_mm": CYLINDER_ARM_MM},
            "motion": [{"law": "poly345", "lift": 30.0, "angle_deg": 180.0},
                       {"law": "poly345", "lift": -30.0, "angle_deg": 180.0}]}


def _designs():
    from camfab.design.spec import design_from_dict
    from camfab.formats import load_design

    osc = base_design(follower={"type": "roller", "motion": "oscillating", "base_radius_mm": 40.0,
                                "roller_radius_mm": 8.0, "pivot_distance_mm": 110.0, "arm_length_mm": 90.0},
                      motion=[{"law": "dwell", "lift": 0.0, "angle_deg": 90.0},
                              {"law": "poly4567", "lift": 15.0, "angle_deg": 90.0},
                              {"law": "poly4567", "lift": -6.0, "angle_deg": 45.0},
                              {"law": "poly4567", "lift": 6.0, "angle_deg": 45.0},
                              {"law": "poly4567", "lift": -15.0, "angle_deg": 90.0}])
    flat = base_design(follower={"type": "flat", "motion": "translating", "base_radius_mm": 100.0})
    return {"ejemplo9rt": lambda: load_design(EXAMPLES / "ejemplo9rt.toml"),
            "oscillating": lambda: design_from_dict(osc), "flat": lambda: design_from_dict(flat)}


#: three designs covering a translating roller, an oscillating roller and a flat face (factories)
DESIGNS = _designs()


@pytest.fixture
def design_dict():
    return base_design()


DEG = math.pi / 180
