"""Cylindrical (barrel) cams: a groove around a cylinder drives a roller along the cylinder's axis.

Frame and development convention (``docs/decisions.md``, "Cylindrical cams")
-------------------------------------------------------------------------------
The cam axis is Z; at cam angle 0 the follower lies on +Y (as for every disc cam).  A cam turning by θ
with sense σ (+1 cw, −1 ccw, seen from +Z) brings the fixed-frame point at polar angle 90° to the cam-frame
polar angle ``90° + σθ``.  A cylinder of radius r is **developed** (unrolled) onto the plane

    x = r·θ   (arc length at which a point of radius r meets the follower),   y = z (axial position, mm)

so the developed plane is the same for both senses (σ only decides the hand of the 3D groove).  On it a
translating follower's roller axis meets radius r at ``C_r(θ) = (r·θ, z₀ + S(θ))``: the developed pitch
curve is exactly the motion law, on every radius, and its slope ``S′/r`` (per radian) differs across the
groove depth.  The groove flanks at radius r are the envelopes of the roller's exact section by the cylinder r
(enlarged by half the backlash: ``w = R_r(r) + backlash/2``), a circle stretched along x by up to about
``w³/(6r²)`` (:mod:`.roller_section`); a rib's (``feature = "rib"``) are those of two rollers ± (rib width/2 + w)
either side of the pitch curve, the rib's mid-line.

Oscillating follower (pivot perpendicular to the cam axis)
----------------------------------------------------------
The pivot axis is parallel to the radial line of the follower at cam angle 0 (the arm swings in the plane
tangent to the cylinder), at a distance L (``arm_length_mm``) ahead of the roller at rest along the
developed x (fixed-frame X = −σ·L).  The arm angle φ = S (degrees; 0 = the arm perpendicular to the cam
axis, positive = towards +z) puts the roller axis at ``X = −σ·e`` with ``e = L·(1 − cos φ)`` and at
``z = z₀ + L·sin φ``; the roller axis stays parallel to the radial line at 0°, so it meets the cylinder r at
the polar offset ``asin(e/r)``.  The exact developed pitch curve on radius r is therefore

    x_r(θ) = r·θ + r·asin(e/r),        z(θ) = z₀ + L·sin φ,

with no small-angle approximation: the circumferential shift ``r·asin(e/r)`` differs across the depth.

Rollers and slip
----------------
Relative to the roller axis the cam surface at radius r moves with ``−ω·C_r′``, speed ``ω·|C_r′|``.  A
cylindrical roller has one surface speed along its length, so it rolls without slip on one radius only
(taken as the pitch radius R) and slips elsewhere by ``ω·(|C_r′| − |C_R′|)``.  A **conical** roller
(``roller = "conical"``) whose apex lies on the cam axis has the radius ``R_r·r/R`` at radius r and the
surface speed ``∝ r``: it rolls without slip on a dwell (``|C_r′| = r``) at every radius, and during a rise
leaves only the slip of the axial part, ``ω·(|C_r′| − |C_R′|·r/R)``.  Its half-angle is ``atan(R_r/R)``.
:func:`slip_ratio` gives the largest slip over the cycle for either roller.
"""
from __future__ import annotations

import math
from typing import Any, ClassVar

import numpy as np

from ..errors import InputError, Problem
from ..geom2d import cross, dot
from ..records import dataclass
from .cylinder_spec import CYLINDER_KEYS, CylinderSpec, Feature, RollerShape, cylinder_section
from .kinds import CamKind, FollowerMotion, FollowerType
from .mechanism import Mechanism, finite_fields, lift_range, require_positive, require_rotation
from .profile import DEG, CamGeometry, Contact, MotionLike, ProfileSample, inverse, xy
from .roller_section import RollerSection, envelope

__all__ = ["RollerShape", "CylinderSpec", "cylinder_section", "DevelopedContact", "CylindricalGeometry",
           "CylindricalTranslating", "CylindricalOscillating", "CYLINDER_KEYS", "slip_ratio", "pitch_3d",
           "FAMILIES", "cylinder_report", "radius_summary", "Feature", "wrap"]

# ---------------------------------------------------------------------------
def _arm(mech: Any, S) -> tuple[np.ndarray, ...]:
    """The roller axis's shift e aside the radial line along the developed x, e′, e″ (per radian), its axial
    position z, z′, z″, and the follower's unit direction of increasing lift in the roller's plane (n, 2)."""
    s0, s1, s2 = S
    if mech.motion is FollowerMotion.TRANSLATING:
        z = np.zeros_like(s0)
        return z, z, z, mech.z0 + s0, s1, s2, xy(z, 1.0 + z)
    L = mech.arm_length_mm
    f, f1, f2 = s0 * DEG, s1 * DEG, s2 * DEG
    c, s = np.cos(f), np.sin(f)
    return (L * (1.0 - c), L * s * f1, L * (c * f1**2 + s * f2), mech.z0 + L * s, L * c * f1,
            L * (c * f2 - s * f1**2), xy(s, c))


def _path(mech: Any, r: float, phi, S) -> tuple[np.ndarray, ...]:
    """Developed pitch curve on radius r: C, C′, C″ (per radian of cam angle), each (n, 2)."""
    x = np.asarray(phi, dtype=float)
    e, e1, e2, z, z1, z2, _ = _arm(mech, S)
    k = 1.0 / np.sqrt(1.0 - (e / r) ** 2)
    g2 = e / r**2 * k**3
    return xy(r * x + r * np.arcsin(e / r), z), xy(r + k * e1, z1), xy(k * e2 + g2 * e1**2, z2)


class DevelopedContact(Contact):
    """One flank of the groove on the developed cylinder of radius r.

    ``sense`` is the flank: +1 the flank on the +z side of the roller, −1 the one on the −z side.  Its
    ``roller_radius`` is the half groove width there (``R_r(r) + backlash/2``); ``shift`` the roller's axial
    offset from the pitch point (a rib's rollers).  The pressure angle is the angle, in the roller's plane, from
    the follower's direction of increasing lift to the roller's normal at the contact, positive while the roller
    rises (``tan δ = S′/(r·cos β*)`` for a translating follower, :mod:`.roller_section`).
    """

    closed = False

    def __init__(self, mechanism: Any, motion: MotionLike, radius: float, half_width: float, flank: int,
                 label: str, shift: float = 0.0):
        super().__init__(motion, flank)
        self.mechanism, self.r, self.roller_radius, self.label = mechanism, float(radius), float(half_width), label
        #: the roller's axial offset from the follower's pitch point (a rib's rollers: ±(w/2 + R_r + b/2))
        self.shift = float(shift)
        self.oscillating = mechanism.motion is FollowerMotion.OSCILLATING

    def _evaluate(self, phi, rotate: bool, S=None) -> ProfileSample:
        return self._sample(phi, self.r, S)

    def on_radii(self, phi, radii) -> ProfileSample:
        """The flank at the cam angles ``phi``, each on its own cylinder ``radii`` (the same length), in one
        evaluation: what :meth:`evaluate` gives on each radius alone (every formula is elementwise in the radius),
        for a cylindrical roller, whose section and half width are the same on every radius (a conical roller's
        would be this contact's radius's, so it is refused).  The points are the same bit for bit; derivatives
        and directions may differ in the last bits (numpy's vector loops against one-element arrays: ≤ 4e-15
        relative, tested)."""
        if self.mechanism.cylinder.roller is not RollerShape.CYLINDRICAL:
            raise InputError("on_radii needs a cylindrical roller: a conical roller's section changes with the radius")
        return self._sample(phi, np.asarray(radii, dtype=float))

    def _sample(self, phi, r, S=None) -> ProfileSample:
        x, s = self._S(phi, S)
        mech, sg = self.mechanism, self.sense
        C, T, A = _path(mech, r, x, s)
        e, e1, e2, z, z1, z2, v = _arm(mech, s)
        f = envelope(mech.section(r), sg, xy(r * x, z + self.shift), xy(r + 0 * z1, z1), xy(0 * z2, z2), e, e1, e2)
        kp = sg * cross(T, A) / np.hypot(T[:, 0], T[:, 1]) ** 3
        up = sg * f.roller_normal
        delta = np.arctan2(-cross(up, v), dot(up, v))
        return ProfileSample(x, f.point, f.point_d1, f.normal, f.tangent, f.curvature, inverse(f.curvature), C, kp,
                             inverse(kp), delta, None, None)

    def pitch(self, phi) -> tuple[np.ndarray, np.ndarray]:
        """The follower's developed pitch curve on this radius (the groove's centre line, the rib's mid-line) and
        its derivative per radian, (n, 2) each."""
        x, s = self._S(phi)
        C, T, _ = _path(self.mechanism, self.r, x, s)
        return C, T


class CylindricalGeometry(CamGeometry):
    """A cylindrical cam's geometry: both flanks on the groove bottom, the pitch cylinder and the outer
    cylinder (a rib's root, pitch and top), in that order (six :class:`DevelopedContact`, the +z flank first),
    each checked like a profile."""

    #: the groove's two flanks (a rib's two rollers) drive the follower both ways
    form_closed: ClassVar[bool] = True

    @property
    def cylinder(self) -> CylinderSpec:
        return self.mechanism.cylinder

    @property
    def max_radius(self) -> float:
        """The outer radius of the cylinder (mm)."""
        return self.cylinder.outer_radius_mm

    @property
    def min_radius(self) -> float:
        """The radius of the groove bottom (mm)."""
        return self.cylinder.inner_radius_mm

    def summarised(self, report: Any) -> Any:
        """The check report with the cylinder's summary (:func:`cylinder_report`)."""
        return cylinder_report(report, self)

    def at_radius(self, r: float, flank: int = 1) -> DevelopedContact:
        """The flank ``flank`` (+1: +z side, −1: −z side) on the developed cylinder of radius ``r``."""
        return self.mechanism.flank(self.program, r, flank)


def pitch_3d(geometry: CylindricalGeometry, phi, r: float | None = None) -> np.ndarray:
    """The roller axis's point on the cylinder of radius ``r`` (default the pitch radius) in the cam frame
    (cam axis Z, (n, 3) mm) at cam angles ``phi``: developed (x, z) wrapped to the polar angle 90° + σ·x/r."""
    r = geometry.cylinder.radius_mm if r is None else r
    C, _ = geometry.at_radius(r).pitch(phi)
    return wrap(geometry.mechanism.sense, r, C[:, 0] / r, C[:, 1])


def wrap(sense: int, r: float | np.ndarray, u: np.ndarray, z: float | np.ndarray) -> np.ndarray:
    """Points ``(..., 3)`` in the cam frame of the cylinder(s) r at developed angles u (x/r; polar angle
    90° + σ·u, σ the cam's ``sense``) and heights z, broadcast together."""
    a = 0.5 * math.pi + sense * u
    r = np.asarray(r, dtype=float)
    return np.stack(np.broadcast_arrays(r * np.cos(a), r * np.sin(a), z), axis=-1)


def slip_ratio(geometry: CylindricalGeometry, n: int = 4001) -> float:
    """The largest slip of the roller over the cycle, as a fraction of the cam surface speed at the pitch
    radius: ``max |(|C_r′| − |C_R′|·ρ(r)/ρ(R))| / |C_R′|`` over the groove bottom and the outer cylinder, ρ the
    roller's section (constant for a cylindrical roller, ∝ r for a conical one); the roller rolls without slip
    at the pitch radius."""
    cyl = geometry.cylinder
    phi = np.linspace(0.0, geometry.period, n)
    R = cyl.radius_mm
    ref = np.hypot(*geometry.at_radius(R).pitch(phi)[1].T)
    worst = 0.0
    for r in (cyl.inner_radius_mm, cyl.outer_radius_mm):
        speed = np.hypot(*geometry.at_radius(r).pitch(phi)[1].T)
        ratio = r / R if cyl.roller is RollerShape.CONICAL else 1.0
        worst = max(worst, float(np.max(np.abs(speed - ref * ratio) / ref)))
    return worst


# ---------------------------------------------------------------------------
@dataclass(frozen=True)
class _Cylindrical(Mechanism):
    """Shared by both followers: the cylinder, the roller, the rotation sense."""

    roller_radius_mm: float
    cylinder: CylinderSpec
    rotation: str = "cw"
    cam_kind: ClassVar[CamKind] = CamKind.CYLINDRICAL
    geometry_class: ClassVar[type[CamGeometry]] = CylindricalGeometry

    @property
    def z0(self) -> float:
        """Axial position of the roller at S = 0 (set by :meth:`validate_motion`'s program; see ``_z0``)."""
        return self._z0 if self._z0 is not None else 0.0

    _z0: float | None = None

    def validate(self) -> list[Problem]:
        p: list[Problem] = []
        require_rotation(p, self.rotation)
        if finite_fields(self, p):
            require_positive(p, "roller_radius_mm", self.roller_radius_mm)
        c = self.cylinder
        if c is None:
            return [*p, Problem("cylinder", None, "a cylindrical cam needs its cylinder",
                                "add [cylinder] with radius_mm, length_mm and groove_depth_mm")]
        if c.groove_depth_mm >= 2 * c.radius_mm:
            p.append(Problem("cylinder.groove_depth_mm", c.groove_depth_mm,
                             f"the groove reaches the axis (it must be < 2·radius_mm = {2 * c.radius_mm:g} mm, "
                             "radius_mm being the pitch radius, the middle of the depth)",
                             "use a shallower groove or a larger radius_mm"))
        if c.feature is Feature.RIB and isinstance(self, CylindricalOscillating):
            p.append(Problem("cylinder.feature", c.feature.value, "a rib is followed by two rollers on a translating "
                             "follower only (an oscillating forked follower is not modelled)",
                             'use feature = "groove" or motion = "translating"'))
        if self.roller_radius_mm > 0 and c.radius_mm <= self.roller_radius_mm:
            p.append(Problem("follower.roller_radius_mm", self.roller_radius_mm,
                             f"the roller is wider than the pitch radius ({c.radius_mm:g} mm)",
                             "use a smaller roller or a larger [cylinder] radius_mm"))
        return p

    def axial_travel(self, program: MotionLike) -> tuple[float, float]:
        """Lowest and highest axial position of the roller axis relative to z₀ (mm)."""
        lo, hi = lift_range(program)
        if isinstance(self, CylindricalOscillating):
            L = self.arm_length_mm
            return L * math.sin(lo * DEG), L * math.sin(hi * DEG)
        return lo, hi

    def validate_motion(self, program: MotionLike, *, bore_mm: float | None = None) -> list[Problem]:
        p = super().validate_motion(program, bore_mm=bore_mm)
        if p:
            return p
        c = self.cylinder
        lo, hi = self.axial_travel(program)
        w = self.half_width(c.outer_radius_mm) if c.rib_width_mm is None else 0.5 * c.rib_width_mm
        need = hi - lo + 2 * w
        if need >= c.length_mm:
            return [Problem("cylinder.length_mm", c.length_mm,
                            f"the {c.feature.value} ({hi - lo:.6g} mm of travel plus the {2 * w:.6g} mm width) does "
                            "not fit in the length",
                            f"give length_mm > {need:.6g} (with walls at both ends) or a smaller lift")]
        z0 = self.z0_for(program)
        if z0 + lo - w <= 0 or z0 + hi + w >= c.length_mm:
            return [Problem("cylinder.zero_position_mm", c.zero_position_mm,
                            f"puts the {c.feature.value} (z from {z0 + lo - w:.6g} to {z0 + hi + w:.6g} mm) outside "
                            f"the cylinder (0 to {c.length_mm:g} mm)",
                            "remove zero_position_mm (the travel is then centred) or move it")]
        return []

    def z0_for(self, program: MotionLike) -> float:
        """z₀: ``zero_position_mm``, or the value that centres the travel on the length."""
        if self.cylinder.zero_position_mm is not None:
            return self.cylinder.zero_position_mm
        lo, hi = self.axial_travel(program)
        return 0.5 * self.cylinder.length_mm - 0.5 * (lo + hi)

    def half_width(self, r: float) -> float:
        """Half the groove width at radius r: the roller's section there plus half the backlash."""
        c = self.cylinder
        rr = self.roller_radius_mm * (r / c.radius_mm if c.roller is RollerShape.CONICAL else 1.0)
        return rr + 0.5 * c.backlash_mm

    def section(self, r: float) -> RollerSection:
        """The roller enlarged by half the backlash, cut by the cylinder r (:mod:`.roller_section`)."""
        c = self.cylinder
        if c.roller is RollerShape.CONICAL:
            return RollerSection(r, self.roller_radius_mm / c.radius_mm, 0.5 * c.backlash_mm)
        return RollerSection(r, 0.0, self.roller_radius_mm + 0.5 * c.backlash_mm)

    @property
    def cone_half_angle_deg(self) -> float | None:
        """A conical roller's half-angle (apex on the cam axis), degrees; None for a cylindrical one."""
        if self.cylinder.roller is not RollerShape.CONICAL:
            return None
        return math.degrees(math.atan2(self.roller_radius_mm, self.cylinder.radius_mm))

    @property
    def rib_offset_mm(self) -> float | None:
        """A rib's rollers: their axes' axial offset from the rib's mid-line, ``w/2 + R_r + b/2``; None for a
        groove."""
        c = self.cylinder
        if c.rib_width_mm is None:
            return None
        return 0.5 * c.rib_width_mm + self.roller_radius_mm + 0.5 * c.backlash_mm

    def flank(self, program: MotionLike, r: float, flank: int) -> DevelopedContact:
        """The flank ``flank`` (+1 the +z side) on the cylinder r: a groove's, enveloped by its roller's side
        facing it; a rib's, by the side facing it of the roller beyond it (offset ±:attr:`rib_offset_mm`)."""
        import dataclasses

        me = dataclasses.replace(self, _z0=self.z0_for(program))
        c = self.cylinder
        rib = c.feature is Feature.RIB
        names = ("rib root", "pitch cylinder", "rib top") if rib else ("groove bottom", "pitch cylinder",
                                                                       "outer cylinder")
        where = dict(zip((c.inner_radius_mm, c.radius_mm, c.outer_radius_mm), names, strict=True)).get(r, "cylinder")
        side = "+z" if flank > 0 else "-z"
        if rib:
            return DevelopedContact(me, program, r, self.half_width(r), -flank,
                                    f"{where} r = {r:.6g} mm, {side} rib flank", flank * (self.rib_offset_mm or 0.0))
        return DevelopedContact(me, program, r, self.half_width(r), flank, f"{where} r = {r:.6g} mm, {side} flank")

    def contacts(self, program: MotionLike) -> tuple[Contact, ...]:
        c = self.cylinder
        return tuple(self.flank(program, r, f) for r in (c.inner_radius_mm, c.radius_mm, c.outer_radius_mm)
                     for f in (1, -1))


@dataclass(frozen=True)
class CylindricalTranslating(_Cylindrical):
    """A cylindrical cam driving a roller follower that translates parallel to the cam axis."""

    required: ClassVar[tuple[str, ...]] = ("roller_radius_mm",)

    @classmethod
    def from_spec(cls, spec: Any) -> CylindricalTranslating:
        return cls(spec.follower.roller_radius_mm or 0.0, spec.cylinder, spec.cam.rotation)


@dataclass(frozen=True)
class CylindricalOscillating(_Cylindrical):
    """A cylindrical cam driving an oscillating roller follower whose pivot is perpendicular to the cam axis
    (module notes): the roller centre moves on an arc of radius ``arm_length_mm``."""

    arm_length_mm: float = 0.0
    motion: ClassVar[FollowerMotion] = FollowerMotion.OSCILLATING
    required: ClassVar[tuple[str, ...]] = ("roller_radius_mm", "arm_length_mm")

    @classmethod
    def from_spec(cls, spec: Any) -> CylindricalOscillating:
        f = spec.follower
        return cls(f.roller_radius_mm or 0.0, spec.cylinder, spec.cam.rotation, None, f.arm_length_mm or 0.0)

    def validate(self) -> list[Problem]:
        p = super().validate()
        require_positive(p, "arm_length_mm", self.arm_length_mm)
        return p

    def validate_motion(self, program: MotionLike, *, bore_mm: float | None = None) -> list[Problem]:
        lo, hi = lift_range(program)
        if max(abs(lo), abs(hi)) >= 90.0:
            return [Problem("motion", max(abs(lo), abs(hi)), "the arm must stay within ±90° of the perpendicular to "
                            "the cam axis (φ = S, degrees)", "use a smaller swing")]
        e = self.arm_length_mm * (1.0 - math.cos(max(abs(lo), abs(hi)) * DEG))
        r_in = self.cylinder.inner_radius_mm
        if e >= r_in:
            return [Problem("follower.arm_length_mm", self.arm_length_mm,
                            f"the roller axis swings {e:.6g} mm aside, off the groove bottom (radius {r_in:.6g} mm)",
                            "use a shorter arm or a smaller swing")]
        return super().validate_motion(program, bore_mm=bore_mm)


#: the registry entries of :mod:`camfab.design.mechanisms`
FAMILIES: dict[tuple[CamKind, FollowerType, FollowerMotion], type[Mechanism]] = {
    (CamKind.CYLINDRICAL, FollowerType.ROLLER, FollowerMotion.TRANSLATING): CylindricalTranslating,
    (CamKind.CYLINDRICAL, FollowerType.ROLLER, FollowerMotion.OSCILLATING): CylindricalOscillating,
}


def radius_summary(geometry: CylindricalGeometry) -> list[dict[str, Any]]:
    """Per radius checked (groove bottom, pitch, outer): the half groove width, the exact largest |pressure
    angle| and where, and the smallest |radius of curvature| of the developed pitch curve and where (user units:
    degrees of cam angle)."""
    from .checks.common import ContactSample

    out = []
    for k in range(0, len(geometry.profiles), 2):
        c = geometry.profiles[k]
        assert isinstance(c, DevelopedContact)
        s = ContactSample(c)
        (xb, dmin), (xa, dmax) = s.extremes("pressure_angle")
        (xk0, kmin), (xk1, kmax) = s.extremes("curvature_pitch")
        worst_d, at_d = (dmax, xa) if abs(dmax) >= abs(dmin) else (dmin, xb)
        worst_k, at_k = (kmax, xk1) if abs(kmax) >= abs(kmin) else (kmin, xk0)
        out.append({"radius_mm": c.r, "where": c.label.split(" r =")[0], "half_width_mm": c.roller_radius,
                    "pressure_angle_max_deg": abs(math.degrees(worst_d)), "at_deg": math.degrees(at_d),
                    "min_pitch_radius_of_curvature_mm": abs(1.0 / worst_k) if worst_k else None,
                    "at_curvature_deg": math.degrees(at_k)})
    return out


def cylinder_report(report: Any, geometry: CylindricalGeometry) -> Any:
    """The check report of a cylindrical cam: its ``cylinder`` summary (radii, roller, slip) and its extent (the
    outer radius; no profile area: the developed flanks enclose none)."""
    import dataclasses

    mech = geometry.mechanism
    cyl = geometry.cylinder
    rib = cyl.feature is Feature.RIB
    summary = {"feature": cyl.feature.value, "rib_width_mm": cyl.rib_width_mm,
               "rib_height_mm": cyl.groove_depth_mm if rib else None,
               "roller_offset_mm": mech.rib_offset_mm, "pitch_radius_mm": cyl.radius_mm,
               "inner_radius_mm": cyl.inner_radius_mm,
               "outer_radius_mm": cyl.outer_radius_mm, "length_mm": cyl.length_mm,
               "groove_depth_mm": None if rib else cyl.groove_depth_mm, "backlash_mm": cyl.backlash_mm,
               "zero_position_mm": mech.z0_for(geometry.program), "roller": cyl.roller.value,
               "cone_half_angle_deg": mech.cone_half_angle_deg, "slip_ratio_max": slip_ratio(geometry),
               "radii": radius_summary(geometry)}
    return dataclasses.replace(report, cylinder=summary, area_mm2=None, base_radius_mm=cyl.inner_radius_mm,
                               max_radius_mm=cyl.outer_radius_mm)
