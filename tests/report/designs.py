"""Design dicts covering every mechanism the report draws (shared by the report tests)."""
from __future__ import annotations

from ..conftest import base_design

_OSC = [{"law": "dwell", "lift": 0.0, "angle_deg": 90.0}, {"law": "poly4567", "lift": 15.0, "angle_deg": 90.0},
        {"law": "dwell", "lift": 0.0, "angle_deg": 60.0}, {"law": "poly4567", "lift": -15.0, "angle_deg": 120.0}]
_E2 = [{"law": "poly4567", "lift": 10.0, "angle_deg": 120.0}, {"law": "dwell", "lift": 0.0, "angle_deg": 120.0},
       {"law": "poly4567", "lift": -10.0, "angle_deg": 120.0}]

#: name → design dict; each builds a different mechanism
DESIGNS = {
    "translating_roller_offset_ccw": base_design(
        name="OffsetCCW", cam={"kind": "disc", "rotation": "ccw", "speed_rpm": 120.0},
        follower={"type": "roller", "motion": "translating", "base_radius_mm": 30.0, "roller_radius_mm": 8.0,
                  "offset_mm": 6.0}),
    "oscillating_roller": base_design(
        name="OscRoller", follower={"type": "roller", "motion": "oscillating", "base_radius_mm": 40.0,
                                    "roller_radius_mm": 8.0, "pivot_distance_mm": 100.0, "arm_length_mm": 80.0},
        motion=_OSC),
    "oscillating_flat": base_design(
        name="OscFlat", follower={"type": "flat", "motion": "oscillating", "base_radius_mm": 40.0,
                                  "pivot_distance_mm": 100.0, "face_offset_mm": 0.0},
        motion=_OSC),
    "translating_cam": base_design(
        name="Wedge", cam={"kind": "translating", "speed_mm_s": 10.0},
        follower={"type": "roller", "motion": "translating", "roller_radius_mm": 5.0, "cam_length_mm": 200.0},
        motion=[{"law": "cycloidal", "lift": 10.0, "length_mm": 100.0},
                {"law": "cycloidal", "lift": -10.0, "length_mm": 100.0}]),
    "conjugate_roller": base_design(
        name="ConjRoller", cam={"kind": "conjugate"},
        follower={"type": "roller", "motion": "translating", "base_radius_mm": 35.0, "roller_radius_mm": 7.0,
                  "follower_distance_mm": 120.0}),
    "conjugate_osc_flat": base_design(
        name="ConjOscFlat", cam={"kind": "conjugate"},
        follower={"type": "flat", "motion": "oscillating", "base_radius_mm": 40.0, "pivot_distance_mm": 100.0,
                  "face_offset_mm": 5.0, "follower_angle_deg": 60.0}, motion=_E2),
    "constant_width": {k: v for k, v in base_design(
        name="ConstWidth", cam={"kind": "constant_width"},
        follower={"type": "flat", "motion": "translating", "base_radius_mm": 40.0, "width_mm": 100.0}).items()
        if k != "motion"},
    "constant_diameter": {k: v for k, v in base_design(
        name="ConstDiam", cam={"kind": "constant_diameter"},
        follower={"type": "roller", "motion": "translating", "base_radius_mm": 40.0, "roller_radius_mm": 8.0,
                  "width_mm": 100.0}).items() if k != "motion"},
    "mushroom": base_design(
        name="Mushroom", cam={"kind": "disc", "rotation": "ccw", "speed_rpm": 600.0},
        follower={"type": "curved", "motion": "translating", "base_radius_mm": 40.0, "face_radius_mm": 30.0,
                  "offset_mm": 2.0}),
    "finger": base_design(
        name="Finger", follower={"type": "curved", "motion": "oscillating", "base_radius_mm": 30.0,
                                 "face_radius_mm": 25.0, "pivot_distance_mm": 90.0, "face_offset_mm": 70.0},
        motion=_OSC),
    # small base circle: undercut and pressure-angle errors (unacceptable)
    "bad_roller": base_design(
        name="TooSmall", follower={"type": "roller", "motion": "translating", "base_radius_mm": 12.0,
                                   "roller_radius_mm": 9.0, "offset_mm": 0.0}),
}


def checked_design(spec):
    """``(spec, geometry, check report)`` of a design, as the report commands build them."""
    from camfab.pipeline import Cam

    cam = Cam(spec)
    return spec, cam.geometry, cam.check()
