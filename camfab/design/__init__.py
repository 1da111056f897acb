"""Design stage: motion laws, segment programs, the design spec, profile synthesis and checks.

This package reads and writes no files and knows nothing of exporters: :mod:`camfab.formats`
reads designs into :class:`DesignSpec` values.
"""
from __future__ import annotations

from ..results import Finding, MotionReport
from .laws import LAWS, Law, get_law, law_names
from .motion_report import analyse_motion
from .program import MotionProgram, Segment, SegmentInput, build_program
from .spec import DesignSpec, design_from_dict

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
    "design_from_dict",
    "Finding",
    "MotionReport",
    "analyse_motion",
]
