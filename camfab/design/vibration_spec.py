"""The ``[vibration]`` section of a design: the follower train's elasticity for the vibration model
(:mod:`camfab.design.vibration`).

The moving mass, the return spring (rate and preload), the absolute damper and the loads are those of
``[dynamics]``, which ``[vibration]`` needs; it adds the train's stiffness (units in the key's name, like
``[dynamics]``: N/mm for a translating follower or a translating cam, N·m/degree for an arm), the damping
ratio of the train and the number of harmonics reported.  Form-closed cams (conjugate, constant
width/diameter) have no return spring to separate from: refused.  Nothing here raises: problems go into
the :class:`~camfab.design.validator.Validator` (docs/decisions.md, "Follower vibration").
"""
from __future__ import annotations

import math
from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

from ..records import dataclass
from .kinds import CamKind, FollowerMotion
from .validator import Validator

if TYPE_CHECKING:
    from .vibration import Train

__all__ = ["VibrationSpec", "vibration_section", "train_of", "DAMPING_RATIO_MAX", "HARMONICS_MAX"]

_TRANSLATING, _OSCILLATING = "stiffness_n_per_mm", "stiffness_nm_per_deg"
_COMMON = ("damping_ratio", "harmonics")
#: the damping ratio lies in (0, DAMPING_RATIO_MAX): undamped, the start never dies out (no steady state);
#: from 1 the train no longer rings (overdamped: no follower train is)
DAMPING_RATIO_MAX = 1.0
#: at most this many harmonics are listed
HARMONICS_MAX = 200


@dataclass(frozen=True, slots=True)
class VibrationSpec:
    """``[vibration]``: the train's stiffness (N/mm, or N·m/degree for an arm: ``motion``), its damping ratio
    and the harmonics to list."""

    motion: FollowerMotion
    stiffness: float
    damping_ratio: float = 0.05
    harmonics: int = 12

    @property
    def stiffness_key(self) -> str:
        return _OSCILLATING if self.motion == FollowerMotion.OSCILLATING else _TRANSLATING


def train_of(spec: VibrationSpec) -> Train:
    """The :class:`~camfab.design.vibration.Train` in SI units of the follower's coordinate (N/m or N·m/rad)."""
    k = spec.stiffness * (180.0 / math.pi if spec.motion == FollowerMotion.OSCILLATING else 1e3)
    from .vibration import Train  # the vibration model, imported by the designs that have [vibration]

    return Train(k, spec.damping_ratio)


def vibration_section(v: Validator, data: Mapping[str, Any], kind: CamKind,
                      motion: FollowerMotion) -> VibrationSpec | None:
    """``[vibration]`` (None when absent): the stiffness key of the follower's motion (required, > 0), the
    damping ratio in (0, 1), the harmonics 1 … :data:`HARMONICS_MAX`; it needs ``[dynamics]`` and a
    spring-loaded follower."""
    if "vibration" not in data:
        return None
    t = v.table(data, "vibration")
    osc = motion == FollowerMotion.OSCILLATING and kind != CamKind.TRANSLATING
    own, other = (_OSCILLATING, _TRANSLATING) if osc else (_TRANSLATING, _OSCILLATING)
    if other in t:
        v.add(f"vibration.{other}", t[other], f"is for {'translating' if osc else 'oscillating'} followers",
              f"give {own}")
    v.keys({k: t[k] for k in t if k != other}, (own, *_COMMON), "vibration")
    if kind.form_closed:
        v.add("vibration", "...", f"a {kind.replace('_', '-')} cam drives its follower both ways (form closure): "
              "the spring-loaded vibration model does not apply", "remove [vibration]")
    if "dynamics" not in data:
        v.add("vibration", "...", "needs the moving mass, spring and preload of [dynamics]",
              "add a [dynamics] section (mass_kg or inertia_kg_m2, spring_rate, spring_preload)")
    unit = "N·m per degree of arm angle" if osc else "N/mm"
    k = v.number(t, own, "vibration", None, lo=0.0, lo_open=True, hi=1e12,
                 fix=f"give the follower train's stiffness in {unit} (> 0)")
    if own not in t:
        v.add(f"vibration.{own}", None, "is required", f"add {own} = ... (the follower train's stiffness, {unit})")
    zeta = v.number(t, "damping_ratio", "vibration", 0.05, lo=0.0, hi=DAMPING_RATIO_MAX, lo_open=True,
                    hi_open=True, fix="give the train's damping ratio ζ, 0 < ζ < 1 (typically 0.02 to 0.2)")
    harmonics = _harmonics(v, t)
    if k is None:
        return None
    return VibrationSpec(FollowerMotion.OSCILLATING if osc else FollowerMotion.TRANSLATING, k, zeta, harmonics)


def _harmonics(v: Validator, t: Mapping[str, Any]) -> int:
    val = t.get("harmonics", 12)
    if isinstance(val, bool) or not isinstance(val, int) or not 1 <= val <= HARMONICS_MAX:
        v.add("vibration.harmonics", val, f"must be a whole number from 1 to {HARMONICS_MAX}",
              "e.g. harmonics = 12")
        return 12
    return val
