"""A typical 12-segment translating-roller disc cam that passes ``camfab check``.

Same motion program as the harsh synthetic cam of ``bench_discretize.py`` (±10 mm over 30°,
cycloidal / poly345 / poly4567 with dwells) but with a roller follower (Rr = 10 mm) on a base
radius of 60 mm, so the peak pressure angle is 29.2° (≤ 30°) and there is no undercut
(minimum convex radius 8.9 mm > 0).  Its verdict is ``not_for_high_speed`` only because the
cycloidal/poly345 laws have jerk jumps at the dwells.
"""
from __future__ import annotations

from camfab.design.assemble import geometry_from_spec
from camfab.design.spec import design_from_dict

ROWS = [("cycloidal", 10, 30), ("dwell", 0, 30), ("poly345", -10, 30), ("dwell", 0, 30),
        ("poly4567", 10, 30), ("dwell", 0, 30), ("cycloidal", -10, 30), ("dwell", 0, 30),
        ("poly345", 10, 30), ("dwell", 0, 30), ("poly4567", -10, 30), ("dwell", 0, 30)]


def typical_spec(base_radius_mm: float = 60.0, roller_radius_mm: float = 10.0):
    """The DesignSpec of the typical 12-segment roller cam."""
    return design_from_dict({
        "name": "typical12",
        "cam": {"kind": "disc", "rotation": "cw", "omega_rad_s": 1.0},
        "follower": {"type": "roller", "motion": "translating", "base_radius_mm": base_radius_mm,
                     "roller_radius_mm": roller_radius_mm, "offset_mm": 0.0},
        "motion": [{"law": law, "lift": float(h), "angle_deg": float(a)} for law, h, a in ROWS],
        "manufacturing": {"thickness_mm": 10.0, "bore_mm": 20.0, "keyway": True, "tool_diameter_mm": 6.0,
                          "tolerance_mm": 0.001},
    })


def typical_geometry(**kw):
    """``(spec, CamGeometry)`` of the typical 12-segment roller cam."""
    spec = typical_spec(**kw)
    return spec, geometry_from_spec(spec)
