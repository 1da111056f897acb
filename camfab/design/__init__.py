"""Design stage: motion laws, segment programs, the design spec, profile synthesis and checks.

This package knows nothing of exporters.
"""
from __future__ import annotations

from .laws import LAWS, Law, get_law, law_names
from ..results import Finding, MotionReport
from .motion_report import analyse_motion
from .program import MotionProgram, Segment, SegmentInput, build_program
from .spec import DesignSpec, design_from_dict, load_design

__all__ = [
    "LAWS",
    "Law",
    "get_law",
    "law_names",
    "MotionProgram",
    "Segment",
    "SegmentInput",
    "build_program",
    "DesignSpec",
    "load_design",
    "design_from_dict",
    "Finding",
    "MotionReport",
    "analyse_motion",
]
