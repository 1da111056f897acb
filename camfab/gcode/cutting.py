"""Cutting data (spindle speed, feeds) from a small tool-and-material table, when the design does not give them.

The table is data of the package (``camfab/gcode/cutting_data.toml``): surface speed ``vc`` (m/min) and chip
load per tooth ``fz`` (mm, by tool-diameter band) for each work material and tool material (carbide, HSS),
and the usual number of flutes per work material.  Then

* ``n = 1000 * vc / (pi * D)`` rpm, rounded to a whole rpm; above the machine's ``max_spindle_rpm`` the
  maximum is used and the feed follows it at the same chip load (and the program header says so:
  ``spindle LIMITED: ...``);
* ``feed = fz * z * n`` mm/min;
* ``plunge = plunge_fraction * feed``: the feed of every move that descends.

Every value the design gives (``spindle_rpm``, ``feed_mm_min``, ``plunge_feed_mm_min``, ``tool_flutes``)
wins over the table.  :attr:`CuttingData.notes` are the header lines that say where each number came from, each
at most 60 characters (what a Fanuc comment keeps).

Examples
--------
>>> cd = cutting_data(tool_diameter_mm=10.0, material="C45 steel", max_spindle_rpm=12000)
>>> cd.spindle_rpm, round(cd.feed_mm_min, 1), cd.flutes
(4775.0, 644.6, 3)
"""
from __future__ import annotations

import bisect
import math
import tomllib
from functools import cache
from importlib import resources
from typing import Any

from camfab.errors import Problem, SpecError
from camfab.records import dataclass
from camfab.words import earliest_word

__all__ = ["TOOL_MATERIALS", "CuttingData", "cutting_data", "known_materials", "match_material", "table"]

#: tool materials of the table
TOOL_MATERIALS = ("carbide", "hss")


@cache
def table() -> dict[str, Any]:
    """The cutting-data table (parsed ``cutting_data.toml``)."""
    text = resources.files("camfab.gcode").joinpath("cutting_data.toml").read_text(encoding="utf-8")
    return tomllib.loads(text)


def known_materials() -> tuple[str, ...]:
    """The work materials of the table, in table order."""
    return tuple(table()["materials"])


def match_material(text: str) -> str | None:
    """The table material ``text`` names (its name or an alias as a word, case-insensitive; the earliest
    in the text wins), or None.

    >>> match_material("42CrMo4, induction hardened"), match_material("EN AW-6082 T6"), match_material("brass")
    ('42CrMo4', 'AlMgSi1', None)
    """
    named = [(name, word) for name, row in table()["materials"].items() for word in (name, *row.get("aliases", ()))]
    i = earliest_word(text, [word for _, word in named])
    return None if i is None else named[i][0]


@dataclass(frozen=True)
class CuttingData:
    """Spindle speed (rpm), cutting and plunge feeds (mm/min), flutes, and the header lines stating their source."""

    spindle_rpm: float
    feed_mm_min: float
    plunge_feed_mm_min: float
    flutes: int | None
    notes: tuple[str, ...]


def cutting_data(*, tool_diameter_mm: float, material: str = "", tool_material: str = "carbide",
                 flutes: int | None = None, spindle_rpm: float | None = None, feed_mm_min: float | None = None,
                 plunge_feed_mm_min: float | None = None, max_spindle_rpm: float | None = None,
                 source: str | None = None) -> CuttingData:
    """The cutting data of one tool in one material: the design's values where given, the table's otherwise.

    Parameters
    ----------
    tool_diameter_mm : float
    material : str
        ``[manufacturing] material`` (free text naming a table material, e.g. ``"C45 steel, hardened"``);
        empty: the table's default material, and the header says it was assumed.
    tool_material : {"carbide", "hss"}
    flutes : int, optional
        Default: the table's number for the material.
    spindle_rpm, feed_mm_min, plunge_feed_mm_min : float, optional
        The design's values; each given one wins.
    max_spindle_rpm : float, optional
        The machine's highest spindle speed.

    Raises
    ------
    SpecError
        A material the table does not know (the known ones listed), a tool outside the table's diameters,
        or a given spindle speed above ``max_spindle_rpm`` — each only when the value is needed.
    """
    data = table()
    D = float(tool_diameter_mm)
    if flutes is not None and (isinstance(flutes, bool) or not isinstance(flutes, int) or not 1 <= flutes <= 12):
        raise SpecError(Problem("machining.tool_flutes", flutes, "must be a whole number in [1, 12]", ""), source)
    if max_spindle_rpm is not None and not (math.isfinite(max_spindle_rpm) and max_spindle_rpm >= 1):
        raise SpecError(Problem("machining.max_spindle_rpm", max_spindle_rpm, "must be at least 1 rpm", ""), source)
    if spindle_rpm is not None and max_spindle_rpm is not None and spindle_rpm > max_spindle_rpm:
        raise SpecError(Problem("machining.spindle_rpm", spindle_rpm,
                                f"is above the machine's max_spindle_rpm ({max_spindle_rpm:g})",
                                "lower spindle_rpm or raise max_spindle_rpm"), source)
    if spindle_rpm is not None and feed_mm_min is not None and plunge_feed_mm_min is not None:
        return CuttingData(float(spindle_rpm), float(feed_mm_min), float(plunge_feed_mm_min), flutes,
                           ("cutting data: rpm, feed and plunge feed given",))
    if tool_material not in TOOL_MATERIALS:
        raise SpecError(Problem("machining.tool_material", tool_material, "is not a valid option",
                                "must be one of: " + ", ".join(TOOL_MATERIALS)), source)
    notes: list[str] = []
    text = (material or "").strip()
    name = match_material(text) if text else data["default_material"]
    if name is None:
        raise SpecError(Problem("manufacturing.material", text, "names no material of the cutting-data table",
                                "name one of: " + ", ".join(known_materials()) + " (or give spindle_rpm, "
                                "feed_mm_min and plunge_feed_mm_min in [machining])"), source)
    edges = data["diameter_bands_mm"]
    lo = float(data["min_diameter_mm"])
    if not lo <= D <= edges[-1]:
        raise SpecError(Problem("manufacturing.tool_diameter_mm", D,
                                f"is outside the cutting-data table ({lo:g} to {edges[-1]:g} mm)",
                                "give spindle_rpm, feed_mm_min and plunge_feed_mm_min in [machining]"), source)
    row = data["materials"][name]
    cut = row[tool_material]
    band = bisect.bisect_left(edges, D)
    vc, fz = float(cut["vc"]), float(cut["fz"][band])
    z = int(flutes) if flutes is not None else int(row["flutes"])
    band_lo = lo if band == 0 else edges[band - 1]
    if not text:
        notes.append(f"material source: not given in the design, {name} assumed")
    notes.append(f"cutting data: camfab table, {name}")
    notes.append(f"material: {row['description']}")
    notes.append(f"tool material: {tool_material}, {z} flutes{' as given' if flutes is not None else ''}")
    notes.append(f"table: vc {vc:g} m/min, fz {fz:g} mm for D {band_lo:g}-{edges[band]:g} mm")
    n_table = 1000.0 * vc / (math.pi * D)
    if spindle_rpm is not None:
        n = float(spindle_rpm)
        notes.append(f"spindle source: {n:g} rpm given, table {n_table:.0f} rpm")
    elif max_spindle_rpm is not None and round(n_table) > max_spindle_rpm:
        n = float(math.floor(max_spindle_rpm))
        notes.append(f"spindle LIMITED: table {n_table:.0f} rpm over machine max {max_spindle_rpm:g}")
        notes.append(f"spindle source: {n:g} rpm, feed at the same fz, vc {math.pi * D * n / 1000.0:.0f} m/min")
    else:
        n = float(round(n_table))
        notes.append(f"spindle source: n = 1000 vc / pi D = {n:g} rpm")
    if feed_mm_min is not None:
        feed = float(feed_mm_min)
        notes.append(f"feed source: {feed:g} mm/min given")
    else:
        feed = fz * z * n
        notes.append(f"feed source: fz x z x n = {fz:g} x {z} x {n:g} = {feed:.1f} mm/min")
    frac = float(data["plunge_fraction"])
    if plunge_feed_mm_min is not None:
        plunge = float(plunge_feed_mm_min)
        notes.append(f"plunge source: {plunge:g} mm/min given")
    else:
        plunge = frac * feed
        notes.append(f"plunge source: plunge/helix feed = {frac:g} x feed = {plunge:.1f} mm/min")
    return CuttingData(n, feed, plunge, z, tuple(notes))
