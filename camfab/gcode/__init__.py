"""camfab.gcode - contour milling programs, post-processors, a G-code reader/back-plotter and verifier.

Flow: a closed tool-centre contour (lines and arcs, from :mod:`camfab.offset`) and a :class:`Job` (of a design:
:func:`job_from_machining`, its spindle speed and feeds from the cutting-data table, :func:`cutting_data`)
-> :func:`contour_toolpath` -> :class:`Program` (common model, mm) -> :func:`dumps` / :func:`write_gcode`
with a post-processor (``linuxcnc``, ``fanuc``, ``grbl``) -> G-code text -> :func:`parse` (back-plot)
-> :func:`verify` against the exact curves (programs under G41/G42 are first run through
:func:`simulate_compensation`, the controller's offset of the part contour).  :func:`lift_table_csv` writes
the polar lift table for cam grinders.
"""
from camfab.gcode.compensation import simulate_compensation
from camfab.gcode.contour import ContourDistance, Segment, as_contour, offset_contour, orient_contour
from camfab.gcode.cutting import CuttingData, cutting_data
from camfab.gcode.lift_table import lift_angles, lift_table_csv, write_lift_table
from camfab.gcode.model import (
    Arc,
    Comment,
    Coolant,
    CutterComp,
    Feed,
    Job,
    Program,
    Rapid,
    Spindle,
    ToolChange,
    job_from_machining,
)
from camfab.gcode.parse import Backplot, GcodeError, Move, Samples, backplot, parse, sample
from camfab.gcode.post import POSTS, dumps, get_post, write_gcode
from camfab.gcode.toolpath import contour_toolpath
from camfab.gcode.verify import VerifyReport, verify

__all__ = [
    "Arc", "Backplot", "Comment", "ContourDistance", "Coolant", "CutterComp", "CuttingData", "Feed", "GcodeError",
    "Job", "Move", "POSTS", "Program", "Rapid", "Samples", "Segment", "Spindle", "ToolChange",
    "VerifyReport", "as_contour", "backplot", "contour_toolpath", "cutting_data", "dumps", "get_post",
    "job_from_machining", "lift_angles",
    "lift_table_csv", "offset_contour", "orient_contour", "parse", "sample", "simulate_compensation", "verify",
    "write_gcode", "write_lift_table",
]
