"""camfab.offset - a cam's exact curves and the tool-centre paths around them.

:func:`profile_curve`, :func:`pitch_curve` and :func:`offset_curve` give a profile (a
:class:`~camfab.design.profile.Contact`) as exact :class:`~camfab.discretize.ParametricCurve` values;
a translating cam's is its closed plate outline (:func:`translating_outline`, corners rounded in its
offsets).  :func:`tool_centre_path` refuses cutters larger than a concave stretch
(:func:`concave_limit`), offsets exactly, fits arcs within the tolerance and cross-checks with a shapely
buffer (:func:`shapely_offset`), which also guards the topology (split or self-intersecting offsets).
"""
from .cutter import (
    JOIN_STYLE,
    QUAD_SEGS,
    ToolCentrePath,
    concave_limit,
    offset_curve,
    pitch_curve,
    profile_curve,
    roller_envelope_deviation,
    shapely_offset,
    tool_centre_path,
)
from .outline import translating_outline

__all__ = [
    "JOIN_STYLE",
    "QUAD_SEGS",
    "ToolCentrePath",
    "concave_limit",
    "offset_curve",
    "pitch_curve",
    "profile_curve",
    "roller_envelope_deviation",
    "shapely_offset",
    "tool_centre_path",
    "translating_outline",
]
