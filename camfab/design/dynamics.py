"""Follower dynamics: contact forces, jump, drive torque — spring-loaded and form-closed followers.

Kinetostatics at constant cam speed: the motion is imposed, so every force follows from S, S′, S″
and the exact geometry; nothing is integrated in time and the follower is rigid.

Model (one generalised coordinate q of the follower: its travel in m, or its arm angle in rad)
-----------------------------------------------------------------------------------------------
The cam must supply the generalised force that the follower's inertia, spring, damper and
external load ask for::

    G = M·q̈ + F₀ + k·q + c·q̇ + F_ext          (q = q(S): q = S/1000 m, or S·π/180 rad)

with q̇ = q′·ṡ, q̈ = q″·ṡ² (ṡ = ω in rad/s, or the travel speed of a translating cam); F₀ is the
spring preload at S = 0 and F_ext a constant load, both pressing the follower onto the cam.
The cam touches the follower at P (fixed frame) with the outward unit normal n; the contact
force on the follower is ``N·n + f`` — f the sliding friction (knife edges and faces, flat or
curved — :attr:`~camfab.design.profile.Contact.sliding`: f = μN along the sliding velocity of the
cam past the follower; a roller is taken to roll without slip, f = 0).  With w the velocity of the
follower's point of force per unit q̇ (the roller centre, or the follower's material point at P),
virtual work gives::

    N = G / D,   D = n·w + μ·v̂·w      (rollers: D = |w|·cos δ, δ the pressure angle)

* ``N < 0``: the spring cannot keep the follower on the cam — it **jumps** (``FOLLOWER_JUMP``);
  ``N`` below the user's safety force: ``CONTACT_FORCE_BELOW_SAFETY``;
* ``D ≤ 0``: the friction wedges the follower — no contact force can move it (``SELF_LOCKING``).

The force on the cam is −(N·n + f) at P; the drive torque that keeps ω constant is
``T = σ·(P × F_cam)`` (σ = +1 cw), and ``T·ω = G·q̇ + μN·|v_rel|`` (power balance, tested).  A
translating cam needs the drive force along its travel instead.  Work per cycle ∮T dφ is the
energy lost to damping and friction (0 without them).

Form-closed followers (conjugate pairs, constant-width and constant-diameter cams) touch the cam
twice and cannot jump: follower 1 carries G where G > 0, follower 2 where G < 0 (:class:`PairDynamics`);
where G changes sign the load crosses to the other follower (``LOAD_REVERSAL``, info).

Design helpers: the preload that keeps N ≥ the safety force everywhere (N is linear in F₀),
and the speed at which the follower starts to jump (N ≥ F_s is a quadratic in the speed at every
angle; D does not depend on the speed).
"""
from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any, ClassVar

import numpy as np

from .. import numeric
from ..errors import InputError
from ..records import dataclass
from ..results import (
    DynamicsReport,
    DynamicsSummary,
    Extreme,
    Finding,
    IssueCode,
    JumpSpeed,
    Maximum,
    Preload,
    Severity,
)
from ..sets import sorted_unique
from ..units import DEG, RPM
from .profile import CamGeometry, Contact

__all__ = ["Loads", "DynamicsSample", "ContactDynamics", "PairDynamics", "GrooveDynamics", "pair_of",
           "analyse_dynamics"]


@dataclass(frozen=True)
class Loads:
    """The follower's dynamic data in SI units of its coordinate q (m, or rad for an arm).

    Attributes
    ----------
    inertia : float
        M: moving mass (kg) or the arm's moment of inertia about its pivot (kg·m²), > 0.
    spring_rate : float
        k: N/m or N·m/rad, ≥ 0.
    preload : float
        F₀ at S = 0: N or N·m (presses the follower onto the cam when > 0).
    damping : float
        c: N·s/m or N·m·s/rad, ≥ 0.
    external : float
        Constant load pressing the follower onto the cam (weight, process force): N or N·m.
    friction_coefficient : float
        μ ≥ 0 of the sliding contact (knife edges and faces, flat or curved).
    safety_force_n : float
        Smallest acceptable contact force (N), ≥ 0.
    """

    inertia: float
    spring_rate: float = 0.0
    preload: float = 0.0
    damping: float = 0.0
    external: float = 0.0
    friction_coefficient: float = 0.0
    safety_force_n: float = 0.0


@dataclass(frozen=True)
class DynamicsSample:
    """Forces at n parameter values (arrays (n,); SI units)."""

    phi: np.ndarray
    required: np.ndarray        # G: generalised force the cam must supply (N or N·m)
    lever: np.ndarray           # D: generalised force per newton of contact force (1 or m)
    contact_force: np.ndarray   # N (newtons), along the cam's outward normal
    friction_force: np.ndarray  # μN (N; signed like N, which is < 0 only where the follower jumps), 0 for rollers
    bearing_force: np.ndarray   # |N·n + f| (N): the load on the camshaft bearings
    drive: np.ndarray           # drive torque (N·m), or drive force along the travel (N) of a translating cam
    power: np.ndarray           # drive power (W)
    motion: np.ndarray | None = None           # S, S′, S″ at phi (3, n): lift unit per unit of phi
    contact_force_2: np.ndarray | None = None  # form-closed followers: follower 2's contact force (N)
    curvature: np.ndarray | None = None        # the profile's signed curvature at the contact (1/mm)
    curvature_2: np.ndarray | None = None      # form-closed followers: at follower 2's contact (1/mm)


class ContactDynamics:
    """Forces on one contact of a cam.

    Parameters
    ----------
    contact : Contact
        A single-follower contact (translating or oscillating roller, knife edge, flat or curved face,
        or a translating cam's roller).
    loads : Loads
    speed : float
        ω (rad/s), or the travel speed (mm/s) of a translating cam; > 0.
    """

    def __init__(self, contact: Contact, loads: Loads, speed: float):
        if not speed > 0:
            raise InputError(f"speed = {speed!r}: must be > 0 (ω in rad/s, or mm/s for a translating cam)")
        self.contact, self.loads, self.speed = contact, loads, float(speed)
        self.oscillating = contact.oscillating
        self.pivot = np.array([contact.m, 0.0]) if self.oscillating else None  # type: ignore[attr-defined]
        #: q per unit of S: m per mm, or rad per degree
        self.q_per_s = DEG if self.oscillating else 1e-3
        self.sliding = contact.sliding

    # ---- kinematics -------------------------------------------------------------------
    def _kinematics(self, x):
        """S, S′, S″, the fixed-frame sample, w (per unit q̇, m) and the cam surface velocity at P
        (m/s) at parameters x."""
        c = self.contact
        x = np.atleast_1d(np.asarray(x, dtype=float))
        S = np.asarray(c.motion.evaluate(x, (0, 1, 2)), dtype=float)
        s = c.evaluate_fixed(x, S)
        where = s.point if self.sliding else s.pitch  # point of force (a rolling roller's centre), mm
        if self.oscillating:  # ξ grows clockwise: d r/dξ = −J·(r − pivot)
            rel = (where - self.pivot) * 1e-3
            w = np.stack([rel[:, 1], -rel[:, 0]], axis=1)
        else:
            w = np.broadcast_to(np.array([0.0, 1.0]), (x.size, 2))
        if c.closed:  # a cam turning at ω_z = −σω carries its surface point P along ω_z·J·P
            wz = -c.sense * self.speed
            p = s.point * 1e-3
            u = np.stack([-wz * p[:, 1], wz * p[:, 0]], axis=1)
        else:  # the plate slides at −χ·v (χ = −σ: the follower runs along +x on the plate for "left")
            u = np.zeros((x.size, 2))
            u[:, 0] = c.sense * self.speed * 1e-3
        return x, S, s, w, u

    def _lever(self, x):
        """(x, S, q̇, the fixed-frame sample, D, v̂) at parameters x: D = n·w + μ·v̂·w is the
        generalised force per newton of contact force, v̂ the sliding direction (0 for rollers)."""
        L = self.loads
        x, S, s, w, u = self._kinematics(x)
        qd = self.q_per_s * S[1] * self.speed
        n = s.normal
        D = n[:, 0] * w[:, 0] + n[:, 1] * w[:, 1]
        vhat = None  # no sliding friction
        if self.sliding and L.friction_coefficient > 0:
            rel = u - w * qd[:, None]  # the cam's surface past the follower's point (m/s)
            speed = np.hypot(rel[:, 0], rel[:, 1])
            vhat = np.zeros_like(u)
            moving = speed > 0
            vhat[moving] = rel[moving] / speed[moving, None]
            D = D + L.friction_coefficient * (vhat[:, 0] * w[:, 0] + vhat[:, 1] * w[:, 1])
        return x, S, qd, s, D, vhat, u

    def required(self, S: np.ndarray) -> np.ndarray:
        """G = M·q̈ + F₀ + k·q + c·q̇ + F_ext from S, S′, S″ (rows of S)."""
        L, k, rate = self.loads, self.q_per_s, self.speed
        return (L.inertia * (k * S[2] * rate * rate) + L.preload + L.spring_rate * (k * S[0])
                + L.damping * (k * S[1] * rate) + L.external)

    def _transmit(self, N, s, vhat, u) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(friction μN, bearing force, drive, power) when the cam pushes with N (newtons) along n."""
        n = s.normal
        with np.errstate(invalid="ignore"):  # N = ±inf where wedged
            fx, fy = -N * n[:, 0], -N * n[:, 1]  # the force on the cam, at P
            if vhat is None:
                friction = np.zeros_like(N)
            else:
                friction = self.loads.friction_coefficient * N * (vhat != 0).any(axis=1)
                fx -= friction * vhat[:, 0]
                fy -= friction * vhat[:, 1]
        if self.contact.closed:
            drive = (self.contact.sense * 1e-3) * (s.point[:, 0] * fy - s.point[:, 1] * fx)
            power = drive * self.speed
        else:  # drive force along the plate's motion (velocity u)
            drive = -fx * np.sign(u[:, 0])
            power = drive * np.abs(u[:, 0])
        return friction, np.hypot(fx, fy), drive, power

    def evaluate(self, x) -> DynamicsSample:
        """Forces, torque and power at parameters x (radians, or mm of travel)."""
        x, S, qd, s, D, vhat, u = self._lever(x)
        G = self.required(S)
        with np.errstate(divide="ignore", invalid="ignore"):  # D = 0: wedged (N infinite), see SELF_LOCKING
            N = G / D
        return DynamicsSample(x, G, D, N, *self._transmit(N, s, vhat, u), S, curvature=s.curvature)

    # ---- design helpers (from a sample: no second evaluation) --------------------------
    def jump_speed(self, s: DynamicsSample) -> np.ndarray:
        """Per sample: the smallest speed (rad/s, or mm/s) at which N falls below the safety force
        there; inf where it never does, 0 where it already does at rest (or the follower is wedged,
        D ≤ 0).  (N − F_s)·D = a·ṡ² + b·ṡ + e, and D does not depend on the speed ṡ: the smallest
        positive root of that quadratic."""
        L, k, S, D = self.loads, self.q_per_s, s.motion, s.lever
        if S is None:  # evaluate() always fills it; a hand-made sample may not
            raise InputError("jump_speed needs the sample's motion (S, S′, S″); use ContactDynamics.evaluate")
        a = L.inertia * k * S[2]
        b = L.damping * k * S[1]
        e = L.preload + L.spring_rate * k * S[0] + L.external - L.safety_force_n * D
        with np.errstate(divide="ignore", invalid="ignore"):
            disc = b * b - 4 * a * e
            sq = np.sqrt(np.maximum(disc, 0.0))
            qq = -0.5 * (b + np.copysign(sq, b))  # stable roots qq/a and e/qq
            roots = np.stack([qq / a, e / qq, -e / b])  # the last: the linear case a = 0
        quad = (a != 0) & (disc >= 0)
        ok = np.stack([quad, quad, (a == 0) & (b < 0)]) & np.isfinite(roots) & (roots >= 0)
        r = np.min(np.where(ok, roots, np.inf), axis=0)
        return np.where((e < 0) | ~(D > 0), 0.0, r)

    def needed_preload(self, s: DynamicsSample) -> np.ndarray:
        """Per sample: the preload F₀ (N or N·m) that makes N equal the safety force there."""
        return self.loads.preload + self.loads.safety_force_n * s.lever - s.required


class PairDynamics:
    """Forces on a form-closed (desmodromic) follower: one rigid follower touching the cam twice —
    conjugate pairs, constant-width and constant-diameter cams.

    Follower 2's coordinate moves against follower 1's (q₂ = const − q₁), so the cam must supply G
    (of follower 1's coordinate) through follower 1 where G > 0 and through follower 2 where G < 0:
    N₁ = max(G, 0)/D₁, N₂ = max(−G, 0)/D₂ (no preload between the two, no clearance).  Where G
    changes sign the load passes from one follower to the other; across a clearance the follower
    knocks there (``LOAD_REVERSAL``).  The follower cannot leave the cam: no jump.

    Parameters
    ----------
    first, second : ContactDynamics
        Follower 1's and follower 2's contacts, each with its own coordinate.
    shift : float
        Follower 2 is evaluated at φ + shift (π for a constant-width/diameter cam, whose one
        profile follower 2 touches half a turn later; 0 for a conjugate pair).
    """

    #: the two contacts are a groove's flanks (:func:`~camfab.results.pair_names`)
    flanks: ClassVar[bool] = False

    def __init__(self, first: ContactDynamics, second: ContactDynamics, shift: float = 0.0):
        self.first, self.second, self.shift = first, second, float(shift)
        self.contact, self.loads, self.speed = first.contact, first.loads, first.speed

    def evaluate(self, x) -> DynamicsSample:
        x, S, qd, s1, D1, v1, u1 = self.first._lever(x)
        _, _, _, s2, D2, v2, u2 = self.second._lever(x + self.shift)
        G = self.first.required(S)
        with np.errstate(divide="ignore", invalid="ignore"):
            N1 = np.where(G > 0, G / D1, 0.0)
            N2 = np.where(G < 0, -G / D2, 0.0)
        f1, b1, d1, p1 = self.first._transmit(N1, s1, v1, u1)
        f2, b2, d2, p2 = self.second._transmit(N2, s2, v2, u2)
        # one of N₁, N₂ is 0 at every angle: the bearing carries the other's force
        return DynamicsSample(x, G, np.where(G < 0, D2, D1), N1, f1 + f2, b1 + b2, d1 + d2, p1 + p2, S, N2,
                              s1.curvature, s2.curvature)


class GrooveDynamics(PairDynamics):
    """Forces on a groove cam's one roller (:mod:`camfab.design.groove`): one follower and one coordinate, two
    flanks.  The inner flank (``first``) pushes the roller the way S grows, the outer (``second``) pushes it back,
    so the flank that carries the load is the sign of G: N₁ = G/D₁ where G > 0, N₂ = G/D₂ where G < 0.  The outer
    flank's normal (into the groove) is the inner's reversed on the same line through the roller centre, so
    D₂ = −D₁ and N₂ = |G|/D₁; the force acts at the outer flank's point (its own torque).  The nominal pitch
    curve drives the roller (the backlash is not crossed: the knock is the ``LOAD_REVERSAL`` finding); no jump.
    ``lever`` is the carrying flank's D, signed so that it is > 0 unless wedged."""

    names = ("the inner flank", "the outer flank")
    flanks: ClassVar[bool] = True

    def __init__(self, first: ContactDynamics, second: ContactDynamics):
        super().__init__(first, second, 0.0)

    def evaluate(self, x) -> DynamicsSample:
        x, S, qd, s1, D1, v1, u1 = self.first._lever(x)
        _, _, _, s2, D2, v2, u2 = self.second._lever(x)
        G = self.first.required(S)
        with np.errstate(divide="ignore", invalid="ignore"):
            N1 = np.where(G > 0, G / D1, 0.0)
            N2 = np.where(G < 0, G / D2, 0.0)
        f1, b1, d1, p1 = self.first._transmit(N1, s1, v1, u1)
        f2, b2, d2, p2 = self.second._transmit(N2, s2, v2, u2)
        return DynamicsSample(x, G, np.where(G < 0, -D2, D1), N1, f1 + f2, b1 + b2, d1 + d2, p1 + p2, S, N2,
                              s1.curvature, s2.curvature)


def pair_of(geometry: CamGeometry, loads: Loads, speed: float) -> PairDynamics:
    """The :class:`PairDynamics` of a desmodromic geometry (two profiles, or one touched twice), or the
    :class:`GrooveDynamics` of a groove cam."""
    profs = geometry.profiles
    first = ContactDynamics(profs[0], loads, speed)
    if geometry.flank_pair:
        return GrooveDynamics(first, ContactDynamics(profs[1], loads, speed))
    if len(profs) > 2:
        raise InputError(f"no force model for a {type(geometry).__name__} ({len(profs)} contacts): the dynamics "
                         "take a conjugate pair, a constant-width or -diameter cam, or a disc groove")
    if len(profs) == 2:  # conjugate: follower 2 is the mirror image of a plain follower on a mirrored cam,
        # and every scalar (N, D, G, torque, power) is the same computed in that mirrored world
        return PairDynamics(first, ContactDynamics(getattr(profs[1], "_inner", profs[1]), loads, speed))
    return PairDynamics(first, ContactDynamics(profs[0], loads, speed), math.pi)


def _user(c: Contact, x: float) -> float:
    """A parameter in user units: degrees of cam angle, or mm of travel."""
    return math.degrees(x) if c.axis.rotating else x


#: the rows of the force table searched by :func:`analyse_dynamics`: spring-loaded (False) or
#: form-closed (True) followers
_ROWS = {False: ("contact_force", "bearing_force", "drive", "lever", "preload", "jump"),
         True: ("contact_force", "bearing_force", "drive", "lever", "contact_force_2", "required")}
#: the exact extrema wanted: (row, maximise)
_EXTREMA = {False: (("contact_force", False), ("contact_force", True), ("drive", False), ("drive", True),
                    ("bearing_force", True), ("preload", True), ("jump", False)),
            True: (("contact_force", False), ("contact_force", True), ("drive", False), ("drive", True),
                   ("bearing_force", True), ("contact_force_2", False), ("contact_force_2", True))}


def _range_rows(form_closed: bool, fs: float) -> list[tuple[str, float, float]]:
    """The functions ``sign·row + offset`` whose positive ranges are findings: self-locking (−D > 0);
    form-closed: where each follower carries the load (±G > 0); spring-loaded: jump (−N > 0) and,
    with a safety force, F_s − N > 0."""
    out = [("lever", -1.0, 0.0)]
    if form_closed:
        return out + [("required", 1.0, 0.0), ("required", -1.0, 0.0)]
    return out + [("contact_force", -1.0, 0.0)] + ([("contact_force", -1.0, fs)] if fs > 0 else [])


def _force_table(dyn: ContactDynamics | PairDynamics, form_closed: bool) -> Callable[[np.ndarray], np.ndarray]:
    """x (n,) → the (6, n) table of :data:`_ROWS` (``+ 0.0``: a −0 force reads as 0)."""
    def table(x: np.ndarray) -> np.ndarray:
        sm = dyn.evaluate(x)
        more = ((sm.contact_force_2, sm.required) if form_closed else
                (dyn.needed_preload(sm), dyn.jump_speed(sm)))  # type: ignore[union-attr]
        return np.stack([sm.contact_force, sm.bearing_force, sm.drive, sm.lever, *more]) + 0.0
    return table


def _searches(dyn: ContactDynamics | PairDynamics, form_closed: bool, fs: float, edges: np.ndarray,
              closed: bool) -> tuple[dict, list[list[numeric.Range]]]:
    """The exact extrema (by (row, maximise): (at, value)) and the positive ranges of
    :func:`_range_rows`, all searched together: one evaluation of the forces per round."""
    names = _ROWS[form_closed]
    table = _force_table(dyn, form_closed)
    picks = [(names.index(n), sign, off) for n, sign, off in _range_rows(form_closed, fs)]

    def rows(x: np.ndarray) -> np.ndarray:  # the table, then the functions whose ranges are wanted
        T = table(x)
        return np.concatenate([T, [sign * T[j] + off for j, sign, off in picks]])

    spec = _EXTREMA[form_closed]
    with np.errstate(invalid="ignore"):  # the per-angle jump speed is +inf where N never drops
        found, ranges = numeric.search(rows, edges, extrema=[(names.index(n), mx) for n, mx in spec],
                                       ranges=range(len(names), len(names) + len(picks)), closed=closed)
    return dict(zip(spec, found, strict=True)), ranges


def analyse_dynamics(geometry: CamGeometry, loads: Loads, speed: float, *, preload_unit: str = "N",
                     form_closed: bool | None = None) -> DynamicsReport:
    """Contact force(s), jump or load reversals, bearing load, drive torque and work per cycle.

    A force-closed (spring-loaded) follower is checked for jump and its safety force, with the
    preload and the speed at the limit; a form-closed follower (``form_closed``, default: the
    geometry's ``form_closed``) reports both followers' forces and where the load passes between them.
    Every extreme is exact (refined between the motion's breakpoints); ranges are located by
    root refinement.  ``speed`` is ω (rad/s), or mm/s for a translating cam.
    """
    if form_closed is None:
        form_closed = geometry.form_closed
    if not form_closed and len(geometry.profiles) != 1:
        raise InputError(f"form_closed=False needs one profile, the geometry has {len(geometry.profiles)}: "
                         "a force-closed cam has one follower; pass form_closed=True for a conjugate pair")
    c = geometry.profiles[0]
    dyn = pair_of(geometry, loads, speed) if form_closed else ContactDynamics(c, loads, speed)
    edges = sorted_unique(np.concatenate([c.breakpoints, np.mod(c.breakpoints - math.pi, 2 * math.pi)])) \
        if form_closed and len(geometry.profiles) == 1 else geometry.breakpoints
    found, ranges = _searches(dyn, form_closed, loads.safety_force_n, edges, c.closed)

    def extreme(name: str) -> Extreme:
        (at_lo, lo), (at_hi, hi) = found[(name, False)], found[(name, True)]
        return Extreme(float(lo), _user(c, at_lo), float(hi), _user(c, at_hi))

    drive = extreme("drive")
    # the work may cancel to 0 (no damping, no friction): an absolute target of 1e-12 of the
    # largest |drive| over the cycle
    span = float(edges[-1] - edges[0])
    work = numeric.integrate(lambda x: dyn.evaluate(x).drive, edges,
                             atol=1e-12 * max(abs(drive.min), abs(drive.max)) * span)
    work *= 1.0 if c.closed else 1e-3
    cycle_s = (2 * math.pi / speed) if c.closed else c.period / speed
    at_b, bmax = found[("bearing_force", True)]
    common: dict[str, Any] = dict(
        form_closed=form_closed, contact_force=extreme("contact_force"), drive=drive, torque=c.closed,
        bearing_force=Maximum(float(bmax), _user(c, at_b)), work_per_cycle_j=work, mean_power_w=work / cycle_s)
    findings = _self_locking(ranges[0], c)
    if form_closed:
        rev = _reversals(ranges[1], ranges[2], c, getattr(dyn, "names", ("follower 1", "follower 2")))
        summary = DynamicsSummary(safety_force_n=None, second_contact_force=extreme("contact_force_2"),
                                  load_reversals=tuple((a, b) for a, b, _ in rev),
                                  flanks=getattr(dyn, "flanks", False), **common)
        return DynamicsReport(summary, tuple(findings + [f for _, _, f in rev]))
    fs = loads.safety_force_n
    (at_pre, pre), (at_jump, r_jump) = found[("preload", True)], found[("jump", False)]
    summary = DynamicsSummary(safety_force_n=fs, preload_needed=Preload(float(pre), preload_unit, _user(c, at_pre)),
                              jump_speed=_speed_user(float(r_jump), c.closed, _user(c, at_jump)), **common)
    findings += _force_closed(ranges[1], ranges[2] if fs > 0 else [], c, fs, speed, float(pre), float(r_jump),
                              preload_unit)
    return DynamicsReport(summary, tuple(findings))


def _self_locking(ranges, c) -> list[Finding]:
    """SELF_LOCKING from the ranges where −D > 0."""
    unit = c.axis.x_unit
    return [Finding(IssueCode.SELF_LOCKING, Severity.ERROR, _user(c, lo), _user(c, hi), float(-gw), 0.0,
                    f"friction wedges the follower from {_user(c, lo):.2f} to {_user(c, hi):.2f} {unit}: no "
                    "contact force can move it (μ too high for the pressure angle there); lower the friction "
                    "coefficient or the pressure angle (larger base radius)")
            for lo, hi, _, gw in ranges]


def _reversals(first, second, c, names=("follower 1", "follower 2")) -> list[tuple[float, float, Finding]]:
    """LOAD_REVERSAL (info) between consecutive stretches where different followers carry the load
    (``first``/``second``: the ranges where G > 0 / G < 0): ``(from, to, finding)`` in order."""
    unit = c.axis.x_unit
    # a stretch whose |G| is rounding noise (the end of a law whose S″ falls to 0, a dwell without load) is none
    top = max((gw for *_, gw in first + second if math.isfinite(gw)), default=0.0)
    first, second = ([r for r in rs if r[3] > 1e-9 * top] for rs in (first, second))
    runs = sorted([(lo, hi, 1) for lo, hi, _, _ in first] + [(lo, hi, 2) for lo, hi, _, _ in second])
    out: list[tuple[float, float, Finding]] = []
    if len({k for _, _, k in runs}) < 2:
        return out
    for (_, hi, k), (lo2, _, k2) in zip(runs, runs[1:] + runs[:1], strict=True):
        if k != k2:
            a, b = _user(c, hi), _user(c, lo2)
            where = f"at {a:.2f} {unit}" if abs(b - a) < 1e-9 else f"between {a:.2f} and {b:.2f} {unit}"
            out.append((a, b, Finding(
                IssueCode.LOAD_REVERSAL, Severity.INFO, a, b, None, None,
                f"the load passes from {names[k - 1]} to {names[k2 - 1]} {where}: across a clearance the follower "
                "knocks there — keep the clearance small (or preload the pair)")))
    return sorted(out, key=lambda t: t[0])


def _force_closed(jump, low, c, fs, speed, pre, r_jump, preload_unit) -> list[Finding]:
    """FOLLOWER_JUMP and CONTACT_FORCE_BELOW_SAFETY from the ranges where −N > 0 and F_s − N > 0."""
    closed, unit = c.closed, c.axis.x_unit
    speed_txt = _speed_text(speed, closed)
    fix = (f"raise the spring preload to at least {pre:.6g} {preload_unit}" if math.isfinite(pre) else
           "stiffen the spring")
    if math.isfinite(r_jump) and r_jump > 0:
        fix += f", or run slower than {_speed_text(r_jump, closed)}"
    out = [Finding(IssueCode.FOLLOWER_JUMP, Severity.ERROR, _user(c, lo), _user(c, hi), float(-gw), 0.0,
                   f"the follower leaves the cam from {_user(c, lo):.2f} to {_user(c, hi):.2f} {unit} at "
                   f"{speed_txt}: the contact force falls to {-gw:.6g} N (the spring cannot hold it); {fix}")
           for lo, hi, _, gw in jump]
    out += [Finding(IssueCode.CONTACT_FORCE_BELOW_SAFETY, Severity.ERROR, _user(c, lo), _user(c, hi), float(fs - gw),
                    fs, f"the contact force is below the safety force {fs:g} N from {_user(c, lo):.2f} to "
                    f"{_user(c, hi):.2f} {unit} (down to {fs - gw:.6g} N at {_user(c, xw):.2f} {unit}); {fix}")
            for lo, hi, xw, gw in low]
    return out


def _speed_user(r: float, closed: bool, at: float) -> JumpSpeed:
    unit = "rpm" if closed else "mm/s"
    if not math.isfinite(r):
        return JumpSpeed(None, unit, None)
    return JumpSpeed(float(r / RPM if closed else r), unit, at)


def _speed_text(r: float, closed: bool) -> str:
    return f"{r / RPM:.6g} rpm" if closed else f"{r:.6g} mm/s"
