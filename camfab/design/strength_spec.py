"""The design's ``[strength]`` and ``[materials.NAME]`` tables: what the contact-stress check and the life
estimates read (materials, face width, the roller bearing's rating), validated into a :class:`StrengthSpec`.

``[strength]`` keys (all optional)::

    cam_material = "C45"              # default: [manufacturing] material, else C45 (assumed, stated)
    follower_material = "100Cr6"      # the roller's (or face's) material
    roller_width_mm = 12              # face width = min(plate thickness, roller width); default: [assembly]
                                      # roller_width_mm, else the plate thickness
    allowable_contact_stress_mpa = 900   # overrides the materials' (the lower of cam and follower)
    roller_dynamic_rating_n = 8000    # the roller bearing's C (ISO 281): roller life computed when given
    roller_bearing = "roller"         # "roller" (p = 10/3) or "ball" (p = 3)

``[materials.NAME]`` adds (or overrides) a material: ``youngs_modulus_mpa``, ``poisson_ratio``,
``allowable_contact_stress_mpa`` (required), ``contact_fatigue_limit_mpa``, ``fatigue_cycles``,
``fatigue_exponent`` (optional).  The check runs when the design has a ``[dynamics]`` section (the
contact force) or a ``[strength]`` table.
"""
from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from ..records import dataclass, field
from .materials import (
    DEFAULT_CAM_MATERIAL,
    DEFAULT_FOLLOWER_MATERIAL,
    MATERIALS,
    Material,
    known_materials,
    match_material,
    material_from_table,
)
from .validator import Validator

__all__ = ["StrengthSpec", "strength_section", "strength_rows", "STRENGTH_KEYS", "MATERIAL_KEYS"]

STRENGTH_KEYS = ("cam_material", "follower_material", "roller_width_mm", "allowable_contact_stress_mpa",
                 "roller_dynamic_rating_n", "roller_bearing")
#: [materials.NAME] numbers: (required, lower bound, lower bound open, upper bound)
MATERIAL_KEYS: dict[str, tuple[bool, float, bool, float]] = {
    "youngs_modulus_mpa": (True, 0.0, True, 1e7), "poisson_ratio": (True, 0.0, False, 0.5),
    "allowable_contact_stress_mpa": (True, 0.0, True, 1e5), "contact_fatigue_limit_mpa": (False, 0.0, True, 1e5),
    "fatigue_cycles": (False, 1.0, False, 1e15), "fatigue_exponent": (False, 1.0, False, 100.0)}


@dataclass(frozen=True)
class StrengthSpec:
    """The validated strength inputs (materials resolved, assumptions stated in ``notes``)."""

    cam: Material
    follower: Material
    width_mm: float
    allowable_mpa: float
    dynamic_rating_n: float | None = None
    ball_bearing: bool = False
    notes: tuple[str, ...] = ()
    materials: Mapping[str, Material] = field(default_factory=dict)
    #: the ``[strength]`` keys as written (valid ones), and each ``[materials.NAME]`` table's: what
    #: :func:`strength_rows` writes back
    given: tuple[tuple[str, Any], ...] = ()
    own_tables: tuple[tuple[str, tuple[tuple[str, float], ...]], ...] = ()


def strength_rows(st: StrengthSpec) -> list[tuple[str, Any]]:
    """``strength.*`` and ``materials.NAME.*`` key/value rows of the tables as written (a design file writer's)."""
    rows = [(f"strength.{k}", v) for k, v in st.given]
    return rows + [(f"materials.{name}.{k}", v) for name, values in st.own_tables for k, v in values]


def _own_materials(v: Validator, data: Mapping[str, Any],
                   tables: list[tuple[str, tuple[tuple[str, float], ...]]]) -> dict[str, Material]:
    out: dict[str, Material] = {}
    t = v.table(data, "materials")
    for name, row in t.items():
        path = f"materials.{name}"
        if not isinstance(row, Mapping):
            v.add(path, row, "must be a table", f"write it as a [{path}] section")
            continue
        v.keys(row, tuple(MATERIAL_KEYS), path)
        vals = {}
        for key, (required, lo, lo_open, hi) in MATERIAL_KEYS.items():
            x = v.number(row, key, path, None, lo=lo, lo_open=lo_open, hi=hi, hi_open=key == "poisson_ratio")
            if x is None and required and key not in row:
                v.add(f"{path}.{key}", None, "is required", f"add {key} = ...")
            if x is not None:
                vals[key] = x
        if all(k in vals for k, (req, *_) in MATERIAL_KEYS.items() if req):
            out[str(name)] = material_from_table(str(name), vals)
            tables.append((str(name), tuple(vals.items())))
    return out


def _named(v: Validator, t: Mapping[str, Any], key: str, own: Mapping[str, Material]) -> Material | None:
    """``[strength] key`` as a material name (exact, case-insensitive), reported when unknown."""
    if key not in t:
        return None
    val = t[key]
    table = {**MATERIALS, **own}
    hit = next((m for n, m in table.items() if isinstance(val, str) and n.lower() == val.strip().lower()), None)
    if hit is None:
        v.add(f"strength.{key}", val, "is not a known material",
              "use one of: " + ", ".join(known_materials(own)) + " (or define it in a [materials.NAME] table)")
    return hit


def strength_section(v: Validator, data: Mapping[str, Any], *, thickness_mm: float, manufacturing_material: str,
                     assembly_roller_width_mm: float | None, applies: bool,
                     face: str = "the plate thickness") -> StrengthSpec | None:
    """``[strength]`` and ``[materials.*]`` read into a :class:`StrengthSpec`; None when the check does not
    apply (no ``[dynamics]`` and no ``[strength]``).  Problems go to ``v``."""
    tables: list[tuple[str, tuple[tuple[str, float], ...]]] = []
    own = _own_materials(v, data, tables)
    t = v.table(data, "strength")
    v.keys(t, STRENGTH_KEYS, "strength")
    if not (applies or "strength" in data):
        return None
    notes: list[str] = []
    cam = _named(v, t, "cam_material", own)
    if cam is None and "cam_material" not in t:
        text = manufacturing_material.strip()
        cam = match_material(text, own) if text else MATERIALS[DEFAULT_CAM_MATERIAL]
        if not text:
            notes.append(f"cam material {DEFAULT_CAM_MATERIAL} assumed (the design names none)")
        elif cam is None:
            v.add("manufacturing.material", manufacturing_material, "names no material of the contact-stress table",
                  "name one of: " + ", ".join(known_materials(own)) + " (or set [strength] cam_material, or define "
                  "it in a [materials.NAME] table)")
    fol = _named(v, t, "follower_material", own)
    if fol is None and "follower_material" not in t:
        fol = MATERIALS[DEFAULT_FOLLOWER_MATERIAL]
        notes.append(f"follower material {DEFAULT_FOLLOWER_MATERIAL} assumed")
    width = v.number(t, "roller_width_mm", "strength", None, lo=0.0, lo_open=True, hi=1e4)
    if width is None:
        width = assembly_roller_width_mm
    if width is None:
        notes.append(f"face width = {face} {thickness_mm:g} mm (no roller width given)")
        width = thickness_mm
    width = min(width, thickness_mm)
    allow = v.number(t, "allowable_contact_stress_mpa", "strength", None, lo=0.0, lo_open=True, hi=1e5)
    rating = v.number(t, "roller_dynamic_rating_n", "strength", None, lo=0.0, lo_open=True, hi=1e9)
    bearing = t.get("roller_bearing", "roller")
    if bearing not in ("roller", "ball"):
        v.add("strength.roller_bearing", bearing, "is not a valid option", "must be one of: roller, ball")
    if cam is None or fol is None:
        return None
    if allow is None:
        allow = min(cam.allowable_mpa, fol.allowable_mpa)
    given = tuple((k, t[k]) for k in STRENGTH_KEYS if k in t)
    return StrengthSpec(cam, fol, width, allow, rating, bearing == "ball", tuple(notes), own, given, tuple(tables))
