"""The ``[drawing]`` section of a design: what the manufacturing drawing states besides the geometry —
drawing number, revision, date, names, material, the manufacturing tolerances (profile, bore fit, DIN 6885
keyway fits, ISO 2768 general tolerance) and the surface finish.

Every key is optional (defaults in :class:`DrawingSpec`, docs/decisions.md "[drawing] table defaults and
fits").  The profile tolerance here is the shop's tolerance on the finished profile; it is not
``[manufacturing] tolerance_mm``, the CAD approximation tolerance of the arcs camfab writes (that one must be
smaller).  The texts are the user's (hostile): the writers put them into files only through
:mod:`camfab.textsafe`.  Nothing here raises: problems go into the :class:`~camfab.design.validator.Validator`.
"""
from __future__ import annotations

import datetime
import re
from collections.abc import Mapping
from typing import Any

from ..records import dataclass
from .validator import Validator

__all__ = ["DrawingSpec", "drawing_section", "HOLE_FIT", "KEYWAY_WIDTH_FITS", "GENERAL_TOLERANCE",
           "keyway_depth_tolerance"]

#: an ISO 286 hole tolerance class: a fundamental deviation (capital letters) and an IT grade 1 … 18
HOLE_FIT = re.compile(r"(A|B|C|CD|D|E|EF|F|FG|G|H|JS|J|K|M|N|P|R|S|T|U|V|X|Y|Z|ZA|ZB|ZC)(1[0-8]|[1-9])")
#: DIN 6885-1 hub keyway width: JS9 normal fit, P9 tight fit, D10 sliding fit
KEYWAY_WIDTH_FITS = ("JS9", "P9", "D10")
#: ISO 2768-1 class (f, m, c, v), optionally with the ISO 2768-2 geometric class (H, K, L)
GENERAL_TOLERANCE = re.compile(r"[fmcv][HKL]?")
#: longest text of a [drawing] field (a title-block cell holds far less; the cell shrinks the text)
TEXT_MAX = 200

_TEXT_KEYS = ("number", "revision", "drawn_by", "checked_by", "material", "author", "organisation", "part_number")
_KEYS = (*_TEXT_KEYS, "date", "profile_tolerance_mm", "bore_fit", "keyway_width_fit", "general_tolerance",
         "surface_finish_ra_um")


@dataclass(frozen=True, slots=True)
class DrawingSpec:
    """``[drawing]``: the title block's texts and the manufacturing tolerances (lengths mm, roughness µm).

    An empty ``material`` takes ``[manufacturing] material``; an empty ``drawn_by`` shows camfab's name
    and version; an empty ``date`` leaves the cell blank (the output stays byte-identical from run to run).
    """

    number: str = ""
    revision: str = ""
    date: str = ""
    drawn_by: str = ""
    checked_by: str = ""
    material: str = ""
    author: str = ""
    organisation: str = ""
    part_number: str = ""
    profile_tolerance_mm: float = 0.02
    bore_fit: str = "H7"
    keyway_width_fit: str = "JS9"
    general_tolerance: str = "m"
    surface_finish_ra_um: float = 1.6


def keyway_depth_tolerance(bore_mm: float) -> float:
    """Upper deviation of the hub keyseat depth ``d + t2`` (mm, lower deviation 0), DIN 6885-1 by bore:
    +0.1 up to 22 mm, +0.2 up to 130 mm, +0.3 above."""
    return 0.1 if bore_mm <= 22.0 else 0.2 if bore_mm <= 130.0 else 0.3


def _text(v: Validator, t: Mapping[str, Any], key: str) -> str:
    val = t.get(key, "")
    if not isinstance(val, str):
        v.add(f"drawing.{key}", val, "must be a string", f'write it in quotes, e.g. {key} = "…"')
        return ""
    if len(val) > TEXT_MAX:
        v.add(f"drawing.{key}", val[:40] + "…", f"is longer than {TEXT_MAX} characters", "shorten it")
        return ""
    return val.strip()


def _pattern(v: Validator, t: Mapping[str, Any], key: str, default: str, pattern: re.Pattern[str],
             fix: str) -> str:
    val = t.get(key, default)
    if not isinstance(val, str) or not pattern.fullmatch(val):
        v.add(f"drawing.{key}", val, "is not a valid option", fix)
        return default
    return val


def drawing_section(v: Validator, t: Mapping[str, Any], cad_tolerance_mm: float | None = None) -> DrawingSpec:
    """``[drawing]``: strings, an ISO date, an ISO 286 hole fit, a DIN 6885 width fit, an ISO 2768 class,
    a profile tolerance no finer than the CAD approximation tolerance ``cad_tolerance_mm``."""
    v.keys(t, _KEYS, "drawing")
    d = DrawingSpec()
    values: dict[str, Any] = {k: _text(v, t, k) for k in _TEXT_KEYS}
    date = t.get("date", "")
    if isinstance(date, datetime.date) and not isinstance(date, datetime.datetime):
        date = date.isoformat()  # TOML's bare date
    if not isinstance(date, str) or (date and not re.fullmatch(r"\d{4}-\d{2}-\d{2}", date)):
        v.add("drawing.date", date, "must be an ISO 8601 date YYYY-MM-DD", 'e.g. date = "2026-11-25"')
        date = ""
    elif date:
        try:
            datetime.date.fromisoformat(date)
        except ValueError:
            v.add("drawing.date", date, "is not a calendar date", 'e.g. date = "2026-11-25"')
            date = ""
    values["date"] = date
    values["profile_tolerance_mm"] = v.number(t, "profile_tolerance_mm", "drawing", d.profile_tolerance_mm,
                                              lo=0.0, lo_open=True, hi=10.0)
    if cad_tolerance_mm is not None and values["profile_tolerance_mm"] < cad_tolerance_mm:
        v.add("drawing.profile_tolerance_mm", values["profile_tolerance_mm"],
              f"is finer than the CAD approximation tolerance [manufacturing] tolerance_mm = {cad_tolerance_mm:g}",
              "give a larger profile tolerance or a smaller manufacturing.tolerance_mm")
    values["bore_fit"] = _pattern(v, t, "bore_fit", d.bore_fit, HOLE_FIT,
                                  "an ISO 286 hole tolerance class: capital deviation letter(s) and IT grade "
                                  "1-18, e.g. H7, H8, JS7, K6")
    values["keyway_width_fit"] = _pattern(v, t, "keyway_width_fit", d.keyway_width_fit,
                                          re.compile("|".join(KEYWAY_WIDTH_FITS)),
                                          "must be one of: " + ", ".join(KEYWAY_WIDTH_FITS) + " (DIN 6885-1)")
    values["general_tolerance"] = _pattern(v, t, "general_tolerance", d.general_tolerance, GENERAL_TOLERANCE,
                                           "ISO 2768 class f, m, c or v, optionally with the geometric class "
                                           "H, K or L, e.g. m or mK")
    values["surface_finish_ra_um"] = v.number(t, "surface_finish_ra_um", "drawing", d.surface_finish_ra_um,
                                              lo=0.0, lo_open=True, hi=50.0)
    return DrawingSpec(**values)
