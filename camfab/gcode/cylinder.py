"""The 4-axis program of a cylindrical cam and its check, chosen by the geometry's ``[cylinder] feature``: a groove
(:mod:`camfab.gcode.rotary`, :mod:`camfab.gcode.rotary_verify`) or a rib (:mod:`camfab.gcode.rib_program`,
:mod:`camfab.gcode.rib_verify`); the one dispatch of the pipeline and ``camfab verify``."""
from __future__ import annotations

from typing import Any

from ..design.cylinder_spec import Feature
from .model import Job
from .posts.base import Post

__all__ = ["cylinder_gcode", "verify_cylinder_program"]


def _is_rib(geometry: Any) -> bool:
    return geometry.cylinder.feature is Feature.RIB


def cylinder_gcode(geometry: Any, job: Job, tol: float, post: str | Post = "linuxcnc") -> tuple[bytes, int, float]:
    """The cylindrical cam's program as bytes, its number of cutting moves and its largest chord error (mm);
    ``job`` is the design's plate job, cut here to the feature (:func:`~camfab.gcode.rotary.cylinder_job`)."""
    from .rotary import cylinder_job

    if _is_rib(geometry):
        from .rib_program import rib_gcode as program
    else:
        from .rotary import rotary_gcode as program
    return program(geometry, cylinder_job(job, geometry), tol, post)


def verify_cylinder_program(data: str | bytes, geometry: Any, job: Job, *, tol: float) -> Any:
    """``camfab verify`` of a cylindrical cam's program (a :class:`~camfab.gcode.rotary_verify.RotaryVerifyReport`);
    ``job`` as for :func:`cylinder_gcode`."""
    from .rotary import cylinder_job

    if _is_rib(geometry):
        from .rib_verify import verify_rib_program as check
    else:
        from .rotary_verify import verify_rotary_program as check
    return check(data, geometry, cylinder_job(job, geometry), tol=tol)
