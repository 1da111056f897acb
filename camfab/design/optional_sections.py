"""The optional design sections whose readers a design without them never imports (docs/decisions.md "Start-up:
the command's own parser, the last eager imports")."""
from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from .kinds import CamKind, FollowerMotion
from .sizing_spec import sizing_section
from .validator import Validator


def optional_sections(v: Validator, data: Mapping[str, Any], kind: CamKind, motion: FollowerMotion) -> dict[str, Any]:
    """``vibration``, ``sizing``, ``optimise`` and ``cylinder`` of :class:`~camfab.design.spec.DesignSpec`, read in
    that order (the order of their problems in ``v``); ``[vibration]``'s, ``[optimise]``'s and ``[cylinder]``'s
    readers imported only when the design has the section (or is a cylindrical cam: ``[cylinder]`` is required)."""
    out: dict[str, Any] = {"vibration": None, "optimise": None, "cylinder": None}
    if "vibration" in data:
        from .vibration_spec import vibration_section

        out["vibration"] = vibration_section(v, data, kind, motion)
    out["sizing"] = sizing_section(v, v.table(data, "sizing"))
    if "optimise" in data:
        from .optimise_spec import optimise_section

        out["optimise"] = optimise_section(v, v.table(data, "optimise"))
    if "cylinder" in data or kind == CamKind.CYLINDRICAL:
        from .cylinder_spec import cylinder_section

        out["cylinder"] = cylinder_section(v, v.table(data, "cylinder"), kind)
    return out
