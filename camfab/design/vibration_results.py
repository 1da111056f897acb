"""Typed results of the follower vibration (``[vibration]``): the ``vibration`` object of ``check --json``.

:mod:`camfab.results` holds the finding codes ``FOLLOWER_SEPARATES_VIBRATION`` and ``VIBRATION_RESONANCE`` and
the :class:`~camfab.results.CheckReport` that carries the summary (as a :class:`~camfab.results.JsonPart`).  Lengths are
in the lift unit (mm, or degrees of arm angle), forces in N, positions in user units (degrees of cam angle,
or mm of travel for a translating cam; the JSON keys say ``_deg`` either way).
"""
from __future__ import annotations

from typing import Any

from ..records import dataclass
from ..results import Extreme, Finding, JumpSpeed, Maximum

__all__ = ["Harmonic", "VibrationSummary", "VibrationReport"]


def _num(v: float | None) -> float | None:
    return None if v is None else float(v)


@dataclass(frozen=True)
class Harmonic:
    """One harmonic of the follower acceleration: its order (multiple of the cycle frequency), frequency,
    amplitude of the kinematic follower's acceleration (lift unit/s²) and of the elastic follower's
    (``dynamic_amplitude``)."""

    order: int
    frequency_hz: float
    amplitude: float
    dynamic_amplitude: float

    def to_dict(self) -> dict[str, Any]:
        return {"order": int(self.order), "frequency_hz": _num(self.frequency_hz), "amplitude": _num(self.amplitude),
                "dynamic_amplitude": _num(self.dynamic_amplitude)}


@dataclass(frozen=True)
class VibrationSummary:
    """The elastic follower train's periodic steady state at the design speed.

    Attributes
    ----------
    natural_frequency_hz, cycle_frequency_hz : float
        The train's natural frequency √((k + k_s)/m)/2π and the cam's cycle frequency.
    damping_ratio : float
        ζ of the train's damper.
    lift_unit : str
        ``"mm"`` or ``"deg"`` (arm angle): the unit of the deviations.
    max_deviation : Maximum
        The largest |y − s|: dynamic against kinematic follower (static deflection included), and where.
    residual_amplitude : Maximum or None
        The largest vibration about the static position in a dwell, and where (None without dwells).
    contact_force : Extreme
        The contact force including vibration (N).
    separation_speed : JumpSpeed
        The lowest speed at which the contact force including vibration reaches 0, and where (``value`` None
        when it does not up to the searched limit).
    nearest_resonance_order : int
        The harmonic order closest to the natural frequency.
    harmonics : tuple of Harmonic
        The first harmonics of the follower acceleration.
    """

    natural_frequency_hz: float
    cycle_frequency_hz: float
    damping_ratio: float
    lift_unit: str
    max_deviation: Maximum
    residual_amplitude: Maximum | None
    contact_force: Extreme
    separation_speed: JumpSpeed
    nearest_resonance_order: int
    harmonics: tuple[Harmonic, ...]

    def to_dict(self) -> dict[str, Any]:
        """The ``vibration`` object of ``check --json``."""
        return {"natural_frequency_hz": _num(self.natural_frequency_hz),
                "cycle_frequency_hz": _num(self.cycle_frequency_hz), "damping_ratio": _num(self.damping_ratio),
                "lift_unit": self.lift_unit, "max_deviation": self.max_deviation.to_dict(),
                "residual_amplitude": None if self.residual_amplitude is None else self.residual_amplitude.to_dict(),
                "contact_force_n": self.contact_force.to_dict(), "separation_speed": self.separation_speed.to_dict(),
                "nearest_resonance_order": int(self.nearest_resonance_order),
                "harmonics": [h.to_dict() for h in self.harmonics]}


@dataclass(frozen=True)
class VibrationReport:
    """Summary and findings of the follower vibration."""

    summary: VibrationSummary
    findings: tuple[Finding, ...]
