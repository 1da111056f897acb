"""The materials of the contact-stress check: elastic constants, allowable contact stress and the
contact-fatigue line, by name (a Python table: the design core reads no files).

Values are **indicative** starting values for the usual cam and follower conditions (the cam track
hardened where the steel allows it), rounded; ``docs/decisions.md`` ("Contact stress and life")
names their sources.  A design adds or overrides a material with a ``[materials.NAME]`` table
(:func:`material_from_table`).

``allowable_mpa`` is the contact stress the surface carries for unlimited life (the contact endurance
limit σ_Hlim of the material); ``fatigue_limit_mpa`` the knee of its S–N line, with ``fatigue_cycles``
N_L and the exponent m of the line ``N = N_L·(σ_Hlim/p)^m`` (None where the material has no
endurance limit to speak of: bronze, aluminium, plastics — then no cam-life estimate).

The names match the work materials of the cutting-data table (``camfab/gcode/cutting_data.toml``): a
``[manufacturing] material`` free text names a material here by its name or an alias, as a word
(:func:`match_material`, the same rule as the cutting data's).
"""
from __future__ import annotations

from collections.abc import Mapping

from ..records import dataclass
from ..words import earliest_word

__all__ = ["Material", "MATERIALS", "DEFAULT_CAM_MATERIAL", "DEFAULT_FOLLOWER_MATERIAL", "known_materials",
           "match_material", "material_from_table"]

#: ISO 6336-2 life factor of steels: Z_NT = (N_L/N)^0.0756 between 1e5 and N_L = 5e7 load cycles → m = 1/0.0756
STEEL_EXPONENT = 13.2
STEEL_CYCLES = 5e7
#: the same for grey cast iron: Z_NT = (2e6/N)^0.0875 → m = 1/0.0875
IRON_EXPONENT = 11.4
IRON_CYCLES = 2e6


@dataclass(frozen=True)
class Material:
    """One material of the contact-stress check.

    Attributes
    ----------
    name : str
    e_mpa : float
        Young's modulus E (MPa).
    poisson : float
        Poisson's ratio ν.
    allowable_mpa : float
        Allowable (endurance) contact stress (MPa).
    fatigue_limit_mpa : float or None
        Contact-fatigue limit σ_Hlim (MPa) of the S–N line; None: no life estimate.
    fatigue_cycles : float
        N_L: load cycles at the knee of the S–N line.
    fatigue_exponent : float
        m of ``N = N_L·(σ_Hlim/p)^m``.
    description : str
        Condition (heat treatment, hardness) the values are for.
    aliases : tuple of str
        Other names that select it from free text.
    """

    name: str
    e_mpa: float
    poisson: float
    allowable_mpa: float
    fatigue_limit_mpa: float | None = None
    fatigue_cycles: float = STEEL_CYCLES
    fatigue_exponent: float = STEEL_EXPONENT
    description: str = ""
    aliases: tuple[str, ...] = ()


def _steel(name: str, sigma: float, description: str, aliases: tuple[str, ...] = ()) -> Material:
    return Material(name, 210_000.0, 0.30, sigma, sigma, STEEL_CYCLES, STEEL_EXPONENT, description, aliases)


#: the built-in table (the first names are those of the cutting-data table)
MATERIALS: dict[str, Material] = {m.name: m for m in (
    _steel("C45", 1150.0, "C45 1.0503, induction or flame hardened track (50-55 HRC)",
           ("Ck45", "1.0503", "AISI 1045", "1045")),
    _steel("42CrMo4", 1200.0, "42CrMo4 1.7225, induction hardened track (52-56 HRC)",
           ("1.7225", "AISI 4140", "4140")),
    _steel("16MnCr5", 1500.0, "16MnCr5 1.7131, case hardened (58-62 HRC)", ("1.7131", "AISI 5115", "5115")),
    _steel("100Cr6", 1500.0, "100Cr6 1.3505 bearing steel, through hardened (60-64 HRC)",
           ("1.3505", "AISI 52100", "52100")),
    Material("GG25", 110_000.0, 0.26, 350.0, 350.0, IRON_CYCLES, IRON_EXPONENT,
             "EN-GJL-250 grey cast iron, as cast (~200 HB)",
             ("GG-25", "EN-GJL-250", "GJL-250", "grey cast iron", "gray cast iron")),
    Material("bronze", 100_000.0, 0.34, 425.0, None, description="tin bronze CuSn12-C, as cast",
             aliases=("CuSn8", "CuSn12", "CuSn8P", "CuSn12-C")),
    Material("AlMgSi1", 70_000.0, 0.33, 200.0, None, description="AlMgSi1 EN AW-6082 T6 (~95 HB), estimate",
             aliases=("EN AW-6082", "AW-6082", "6082", "AlSi1MgMn")),
    Material("POM", 2_800.0, 0.35, 40.0, None, description="POM acetal, dry, 23 °C, estimate",
             aliases=("POM-C", "POM-H", "acetal", "Delrin")),
    _steel("C45N", 480.0, "C45 1.0503 normalised (~200 HB), soft track"),
    _steel("42CrMo4QT", 760.0, "42CrMo4 1.7225 quenched and tempered (~300 HB), soft track"),
)}
#: assumed when the design names no cam material (the cutting data's default too)
DEFAULT_CAM_MATERIAL = "C45"
#: the follower (roller) material when the design names none
DEFAULT_FOLLOWER_MATERIAL = "100Cr6"


def known_materials(extra: Mapping[str, Material] | None = None) -> tuple[str, ...]:
    """The material names: the built-in table, then the design's own."""
    return tuple(MATERIALS) + tuple(k for k in (extra or {}) if k not in MATERIALS)


def match_material(text: str, extra: Mapping[str, Material] | None = None) -> Material | None:
    """The material ``text`` names: a material's name exactly (the design's own first), else a name or
    alias found in the text as a word (case-insensitive; the earliest in the text wins); None when none.

    >>> match_material("C45 steel, induction hardened").name, match_material("EN AW-6082 T6").name
    ('C45', 'AlMgSi1')
    """
    table = {**MATERIALS, **(extra or {})}
    for name, mat in table.items():
        if text.strip().lower() == name.lower():
            return mat
    named = [(mat, word) for mat in table.values() for word in (mat.name, *mat.aliases)]
    i = earliest_word(text, [word for _, word in named])
    return None if i is None else named[i][0]


def material_from_table(name: str, values: Mapping[str, float]) -> Material:
    """A design's ``[materials.NAME]`` table (validated numbers) → :class:`Material`; the fatigue line of
    a steel unless given."""
    limit = values.get("contact_fatigue_limit_mpa")
    return Material(name, float(values["youngs_modulus_mpa"]), float(values["poisson_ratio"]),
                    float(values["allowable_contact_stress_mpa"]), None if limit is None else float(limit),
                    float(values.get("fatigue_cycles", STEEL_CYCLES)),
                    float(values.get("fatigue_exponent", STEEL_EXPONENT)), "defined in the design")
