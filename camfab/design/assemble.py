"""From a validated :class:`DesignSpec` to mechanism, exact geometry and check report.

The one place that maps design-file sections onto the geometry classes, so the
CLI and the exporters never repeat the mapping.
"""
from __future__ import annotations

import dataclasses
import math
from typing import TYPE_CHECKING

from ..errors import InputError
from ..results import CheckReport, DynamicsReport, Finding
from .checks import check
from .mechanisms import geometry_from_spec, mechanism_from_spec
from .profile import CamGeometry
from .spec import DesignSpec, DynamicsSpec

if TYPE_CHECKING:  # the force, stress and vibration models are imported by the designs that have them
    from .dynamics import ContactDynamics, Loads, PairDynamics
    from .strength import StrengthInput
    from .vibration_results import VibrationReport

__all__ = ["mechanism_from_spec", "geometry_from_spec", "check_design", "knot_findings", "loads_from_spec",
           "dynamics_of", "dynamics_model", "is_form_closed", "vibration_of", "strength_input"]


def check_design(spec: DesignSpec, *, tool_radius_mm: float | None = None) -> CheckReport:
    """Geometry + checks + verdict for a design (the ``camfab check`` report), knot-table
    consistency warnings included."""
    geom = geometry_from_spec(spec)
    report = check(geom, pressure_angle_limit_deg=spec.pressure_angle_limit_deg,
                   allow_acceleration_jump=spec.cam.kind in ("constant_width", "constant_diameter"),
                   tool_radius_mm=tool_radius_mm, face_margin_mm=spec.face_margin_mm,
                   name=spec.name, speed=spec.speed, strength=strength_input(spec, geom))
    report = geom.summarised(report)  # a cylindrical cam's cylinder summary
    extra = knot_findings(spec)
    if spec.dynamics is not None:
        dyn = dynamics_of(spec, geom)
        report = dataclasses.replace(report, dynamics=dyn.summary)
        extra = list(dyn.findings) + extra
    if spec.vibration is not None and spec.dynamics is not None:
        vib = vibration_of(spec, geom)
        report = dataclasses.replace(report, vibration=vib.summary)
        extra = extra + list(vib.findings)
    if extra:
        report = dataclasses.replace(report, findings=report.findings + tuple(extra))
    return report


def loads_from_spec(d: DynamicsSpec) -> Loads:
    """``[dynamics]`` (units in the key names) → :class:`Loads` in SI units of the follower's
    coordinate (m, or rad for an arm)."""
    from .dynamics import Loads

    per_deg = 180.0 / math.pi  # N·m per degree → per radian
    if d.motion == "oscillating":
        return Loads(d.inertia, d.spring_rate * per_deg, d.spring_preload, d.damping * per_deg, d.external,
                     d.friction_coefficient, d.safety_force_n)
    return Loads(d.inertia, d.spring_rate * 1e3, d.spring_preload, d.damping, d.external,
                 d.friction_coefficient, d.safety_force_n)


def is_form_closed(spec: DesignSpec) -> bool:
    """Conjugate, constant-width, constant-diameter, groove and cylindrical cams drive their follower both ways."""
    return spec.cam.kind.form_closed


def dynamics_model(spec: DesignSpec, geometry: CamGeometry) -> ContactDynamics | PairDynamics:
    """The force model of a design with a ``[dynamics]`` section (``evaluate(x)`` → forces at x)."""
    if spec.dynamics is None:
        raise InputError(f"{spec.name} has no [dynamics] section: add one (mass_kg or inertia_kg_m2, spring, loads) "
                         "for its force model")
    from .dynamics import ContactDynamics, pair_of

    loads = loads_from_spec(spec.dynamics)
    if is_form_closed(spec):
        return pair_of(geometry, loads, spec.speed)
    return ContactDynamics(geometry.profiles[0], loads, spec.speed)


def dynamics_of(spec: DesignSpec, geometry: CamGeometry | None = None) -> DynamicsReport:
    """Contact force, jump, drive torque and work of a design with a ``[dynamics]`` section."""
    if spec.dynamics is None:
        raise InputError(f"{spec.name} has no [dynamics] section: add one (mass_kg or inertia_kg_m2, spring, loads) "
                         "to analyse the forces")
    from .dynamics import analyse_dynamics

    geom = geometry if geometry is not None else geometry_from_spec(spec)
    return analyse_dynamics(geom, loads_from_spec(spec.dynamics), spec.speed,
                            preload_unit=spec.dynamics.preload_unit,
                            form_closed=is_form_closed(spec))


def strength_input(spec: DesignSpec, geometry: CamGeometry) -> StrengthInput | None:
    """The contact-stress inputs of a design (None when the check does not apply: no ``[dynamics]``, no
    ``[strength]``); the force model None without ``[dynamics]``."""
    st = spec.strength
    if st is None:
        return None
    from .strength import BALL, ROLLER, StrengthInput

    dyn = dynamics_model(spec, geometry) if spec.dynamics is not None else None
    return StrengthInput(dyn, st.cam, st.follower, st.width_mm, st.allowable_mpa, st.dynamic_rating_n,
                         BALL if st.ball_bearing else ROLLER, st.notes,
                         spec.follower.roller_radius_mm if spec.cam.kind == "groove" else None)


def knot_findings(spec: DesignSpec) -> list[Finding]:
    """KNOT_INCONSISTENT warnings of a knot-table design (none for segment programs)."""
    if spec.knot_table is None:
        return []
    return list(spec.knot_table.warnings())


def vibration_of(spec: DesignSpec, geometry: CamGeometry | None = None) -> VibrationReport:
    """The follower vibration of a design with ``[dynamics]`` and ``[vibration]`` sections."""
    if spec.vibration is None or spec.dynamics is None:
        raise InputError(f"{spec.name} has no [vibration] (and [dynamics]) section: add one (the train's stiffness "
                         "and damping ratio) to analyse the follower's vibration")
    from .vibration import analyse_vibration
    from .vibration_spec import train_of

    geom = geometry if geometry is not None else geometry_from_spec(spec)
    return analyse_vibration(geom.profiles[0], loads_from_spec(spec.dynamics), train_of(spec.vibration), spec.speed,
                             harmonics=spec.vibration.harmonics)
