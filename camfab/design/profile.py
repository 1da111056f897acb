"""Exact cam profiles: the profile sample, the contact (one cam surface), the cam geometry.

Everything is a closed-form function of the cam angle φ (radians) — or of the
travel B (mm) for a translating cam — built from S, S′, S″ of the motion
program; nothing is a fixed table and nothing is finite-differenced.

Derivation (one scheme for every mechanism)
-------------------------------------------
The follower is described in the **fixed frame** (cam centre at the origin,
follower above it, see :mod:`camfab.design.mechanism`).  A cam turning by φ
with sense σ (+1 cw, −1 ccw) maps a fixed-frame point q to the cam-frame point
``R(σφ)·q``.  With J the +90° rotation, derivatives along the cam-frame curve
are, expressed in fixed-frame components (then rotated by R(σφ))::

    T  = σ·J·C + C′                     (tangent, per radian)
    C̈  = −C + 2σ·J·C′ + C″              (second derivative)

so with C the roller centre the pitch curve is exact, its signed curvature is
``κ_p = σ·(T × C̈)/|T|³`` and the outward unit normal is ``n = −σ·J·T/|T|``.
The profile is the parallel curve ``P = C − R_r·n`` with ``ρ = ρ_p − R_r``.
A flat face with unit normal angle β(φ) and distance p(φ) from the cam centre
envelopes the profile ``P = p·n + s·J·n`` with ``s = p′/(σ + β′)`` and
``ρ = p + p″/(σ+β′)² − p′β″/(σ+β′)³`` (translating face: ρ = R_b + S + S″).

Sign conventions
----------------
* Radius of curvature ρ (and curvature κ = 1/ρ): **positive = convex** (the
  profile bulges towards the follower), negative = concave.  For rollers a
  convex pitch radius 0 < ρ_p < R_r is an undercut, ρ_p = R_r a cusp (ρ = 0).
* Outward unit normal; unit tangent ``t = σ·J·n`` points the way the contact
  point travels for increasing φ on a regular stretch.
* Pressure angle δ (radians, signed): the angle from the follower point's
  rise-direction velocity to the contact normal (the line of force), positive
  when the normal leans the way the cam surface moves past the follower.  It is
  positive while rising on a centred translating follower:
  ``tan δ = (S′ + σ·e)/(S + √(R_p² − e²))``.  Hence **a positive (right)
  offset raises the rise pressure angle of a cw cam** (and lowers the return
  magnitude); for a ccw cam it lowers it.  CAM-DAS's manual claims the
  opposite for "+ = right", but its own formulas put +m on the left
  (``docs/decisions.md``, "offset sign").
* Flat-face contact position: translating face — signed distance along the
  face from the stem axis, positive to the right (a cw cam touches the left
  side, −S′, while rising); oscillating face — distance along the face from
  the right-angle vertex (the pivot's foot when f = 0), ``m·cos ξ + s``.
* Oscillating arm angle ξ (radians): angle at the pivot between pivot→cam
  centre and the arm; ξ = ξ₀ + lift, increasing = clockwise.

A :class:`CamGeometry` holds one or more :class:`Contact` profiles (conjugate
cams have two) and evaluates any of them at any φ.  The concrete contacts live
with their families: :mod:`~camfab.design.rollers`, :mod:`~camfab.design.faces`,
:mod:`~camfab.design.curved`, :mod:`~camfab.design.wedge` and the form-closed
:mod:`~camfab.design.conjugate`.
"""
from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any, ClassVar, Protocol

import numpy as np

from ..errors import ApiError, InputError, SpecError
from ..geom2d import cross, dot, pair
from ..numeric import extrema, integrate
from ..records import dataclass
from ..sets import sorted_unique
from .kinds import Axis, ContactKind

__all__ = [
    "MotionLike",
    "ProfileSample",
    "Extremes",
    "Contact",
    "CamGeometry",
    "DEG",
    "CHUNK",
    "block",
    "rot_into",
    "inverse",
    "xy",
    "pressure_angle",
]

#: radians per degree: oscillating lifts are in degrees
DEG = math.pi / 180.0


class MotionLike(Protocol):
    """What a contact needs from a motion: S and derivatives, breakpoints, period, axis.

    Read-only members: motions are immutable (frozen dataclasses such as
    :class:`~camfab.design.program.MotionProgram` satisfy the protocol).
    """

    @property
    def period(self) -> float: ...

    @property
    def axis(self) -> Axis: ...

    @property
    def breakpoints(self) -> np.ndarray: ...

    def evaluate(self, x, orders: Sequence[int] = (0, 1, 2, 3)) -> np.ndarray: ...


@dataclass(frozen=True)
class ProfileSample:
    """One profile evaluated at n parameter values (all arrays, cam frame).

    Attributes
    ----------
    phi : (n,) float
        Cam angle in radians (travel in mm for a translating cam).
    point : (n, 2) float
        Profile contact point (mm).
    point_d1 : (n, 2) float
        d point / d phi (mm per radian, or mm/mm).
    normal, tangent : (n, 2) float
        Unit outward normal and unit tangent ``σ·J·normal``.
    curvature, rho : (n,) float
        Signed profile curvature (1/mm) and radius ρ = 1/κ (mm, ±inf at an
        inflection); positive = convex.
    pitch : (n, 2) float or None
        Pitch curve (roller centre; a curved face's centre of curvature); None for flat faces.
    curvature_pitch, rho_pitch : (n,) float or None
        The same for the pitch curve (rollers only).
    pressure_angle : (n,) float
        Signed pressure angle in radians (0 for a translating flat face).
    face_position : (n,) float or None
        Faces (flat or curved): contact position along the face (mm), see module notes and
        :mod:`camfab.design.curved`.
    arm_angle : (n,) float or None
        Oscillating followers: arm angle ξ (radians).
    """

    phi: np.ndarray
    point: np.ndarray
    point_d1: np.ndarray
    normal: np.ndarray
    tangent: np.ndarray
    curvature: np.ndarray
    rho: np.ndarray
    pitch: np.ndarray | None = None
    curvature_pitch: np.ndarray | None = None
    rho_pitch: np.ndarray | None = None
    pressure_angle: np.ndarray | None = None
    face_position: np.ndarray | None = None
    arm_angle: np.ndarray | None = None


@dataclass(frozen=True)
class Extremes:
    """Minimum and maximum of a quantity and where they occur (parameter units)."""

    min: float
    at_min: float
    max: float
    at_max: float


# ---------------------------------------------------------------------------
def xy(x, y) -> np.ndarray:
    """(n, 2) array of the broadcast coordinates x, y."""
    x, y = np.broadcast_arrays(np.asarray(x, float), np.asarray(y, float))
    return pair(x, y) if x.ndim == 1 else np.stack([x, y], axis=1)


def pressure_angle(v: np.ndarray, n: np.ndarray, sigma: int) -> np.ndarray:
    """Signed angle from the follower's rise velocity ``v`` to the normal ``n``."""
    return np.arctan2(-sigma * cross(v, n), dot(v, n))


# ---------------------------------------------------------------------------
class Contact:
    """One profile of a cam: the envelope of one follower.  Subclasses fill in
    :meth:`evaluate`.

    Attributes
    ----------
    motion : MotionLike
    sense : int
        σ = +1 (cw) or −1 (ccw); for a translating cam +1 = slides right.
    kind : ContactKind
        ROLLER (a circle about a point of the follower; a knife edge has radius 0) or FLAT.
    roller_radius : float
        R_r in mm (0 for flat faces and knife edges; the face radius of a curved face).
    closed : bool
        True for disc cams (periodic closed curve), False for a translating cam.
    oscillating : bool
        True when the follower turns about a pivot (its lift S is in degrees).
    has_face : bool
        True when the follower touches with a face whose contact position the sample gives
        (``ProfileSample.face_position``): its length is checked.
    sliding : bool
        True when the follower slides on the cam (knife edges and faces; friction applies), False
        for a roller that rolls.
    curved_face : bool
        True for a curved (convex circular) face: kind ROLLER with a face; ``roller_radius`` is the
        face radius and ``pitch`` the face's centre of curvature.
    """

    kind = ContactKind.ROLLER
    closed = True
    oscillating = False
    has_face = False
    roller_radius = 0.0
    #: how the checks name this profile when a cam has several ("" = "profile k"); e.g. "inner flank"
    label = ""

    @property
    def sliding(self) -> bool:
        """Knife edges and faces slide on the cam; a roller of radius > 0 rolls."""
        return self.has_face or self.kind is ContactKind.FLAT or self.roller_radius == 0.0

    @property
    def curved_face(self) -> bool:
        """A convex circular face (mushroom, finger follower): it envelopes the cam as a roller of radius
        ``roller_radius`` about the face's centre of curvature (``pitch``), and has a contact position
        along the face."""
        return self.kind is ContactKind.ROLLER and self.has_face

    def __init__(self, motion: MotionLike, sense: int = 1):
        if sense not in (1, -1):
            raise InputError(f"sense = {sense!r}: must be +1 (cw) or -1 (ccw)")
        self.motion = motion
        self.sense = sense

    @property
    def period(self) -> float:
        return float(self.motion.period)

    @property
    def axis(self) -> Axis:
        """The motion's axis: what the parameter is (cam angle or travel) and the lift unit."""
        return self.motion.axis

    @property
    def breakpoints(self) -> np.ndarray:
        """Parameter values where a formula changes, 0 and the period included."""
        return np.asarray(self.motion.breakpoints, dtype=float)

    def evaluate(self, phi) -> ProfileSample:
        """The profile at parameters ``phi`` (cam frame)."""
        return self._evaluate(phi, True)

    def evaluate_fields(self, phi, fields: Sequence[str]) -> dict[str, np.ndarray | None]:
        """Only the named :class:`ProfileSample` fields at ``phi`` (cam frame), bit for bit those of
        :meth:`evaluate` (None where the sample has none): e.g. ``evaluate_fields(t, ("point",))``.

        At most :data:`CHUNK` angles at a time are evaluated whole and only the requested fields are kept,
        so the working memory is the outputs asked for plus one chunk's sample, whatever the angle count
        (the full sample of 10⁷ angles is 16 arrays, ~1.4 GB).

        Raises
        ------
        ApiError
            For a name that is not a field of :class:`ProfileSample`.
        """
        names = tuple(fields)
        bad = [f for f in names if f not in _SAMPLE_FIELDS]
        if bad:
            raise ApiError(f"unknown profile field(s) {bad}: choose from {sorted(_SAMPLE_FIELDS)}")
        x = np.atleast_1d(np.asarray(phi, dtype=float))
        if x.size <= CHUNK:
            s = self.evaluate(x)
            return {f: getattr(s, f) for f in names}
        return _chunked_fields(self, x, names)

    def evaluate_fixed(self, phi, S=None) -> ProfileSample:
        """The same sample in the fixed (follower) frame: where the contact is in the machine at
        each φ — the cam-frame sample rotated back by −σφ.  Quantities that do not depend on the
        frame (curvatures, pressure angle, face position, |point|, point × point′) are those of
        :meth:`evaluate`, to rounding; the checks use this form, which skips the rotation.  ``S``: the
        motion's S, S′, S″ at ``phi`` (3, n) when the caller has them already."""
        return self._evaluate(phi, False, S)

    def _evaluate(self, phi, rotate: bool, S=None) -> ProfileSample:  # pragma: no cover - abstract
        """The sample in the cam frame (``rotate``) or in the fixed frame."""
        raise NotImplementedError

    def _S(self, phi, S=None) -> tuple[np.ndarray, np.ndarray]:
        x = np.atleast_1d(np.asarray(phi, dtype=float))
        return x, (self.motion.evaluate(x, (0, 1, 2)) if S is None else S)

    def radius(self, phi) -> tuple[np.ndarray, np.ndarray]:
        """Distance of the profile from the cam centre (mm; height above the bottom
        edge for a translating cam) and its derivative per unit parameter."""
        s = self.evaluate(phi)
        if not self.closed:
            return s.point[:, 1], s.point_d1[:, 1]
        r = np.hypot(s.point[:, 0], s.point[:, 1])
        return r, dot(s.point, s.point_d1) / r


#: samples per chunk of the elementwise geometry (64 KiB per float64 temporary)
CHUNK = 16384


#: the names of :class:`ProfileSample`'s fields
_SAMPLE_FIELDS = frozenset(ProfileSample.__dataclass_fields__)


def _chunked_fields(contact: Contact, x: np.ndarray, names: tuple[str, ...]) -> dict[str, np.ndarray | None]:
    """:meth:`Contact.evaluate_fields` of more than :data:`CHUNK` angles: one chunk's whole sample at a time."""
    out: dict[str, np.ndarray | None] = {}
    for a in range(0, x.size, CHUNK):
        b = min(a + CHUNK, x.size)
        s = contact.evaluate(x[a:b])
        for f in names:
            v = getattr(s, f)
            if a == 0:  # vectors are stored as (2, n) and handed out transposed, as evaluate does
                out[f] = None if v is None else (np.empty((v.shape[1], x.size)).T if v.ndim == 2
                                                 else np.empty(x.size))
            dst = out[f]
            if dst is not None:
                dst[a:b] = v
    if "phi" in out:
        out["phi"] = x
    return out


def block(rows: int, n: int) -> np.ndarray:
    """Uninitialised (rows, n) storage for the outputs of one evaluation.  One block instead
    of many arrays: at large n fresh memory costs more than the arithmetic, and one large
    allocation is faulted in far more cheaply (huge pages) than a dozen separate ones;
    rows left unused are never touched and cost no memory."""
    return np.empty((rows, n))


def rot_into(out: np.ndarray, a: int, b: int, x, y, c: np.ndarray, s: np.ndarray) -> None:
    """``out[:, a:b]`` (a (2, n) array) = components (x, y) rotated by the angle whose cos/sin are c, s."""
    np.subtract(x * c, y * s, out=out[0, a:b])
    np.add(x * s, y * c, out=out[1, a:b])


def inverse(k: np.ndarray) -> np.ndarray:
    """1/k, ±inf where k = 0."""
    with np.errstate(divide="ignore"):
        return 1.0 / k


# ---------------------------------------------------------------------------
class CamGeometry:
    """Exact geometry of a cam: one or more :class:`Contact` profiles.

    Parameters
    ----------
    mechanism : Mechanism
        A cam family of :mod:`camfab.design.mechanisms` (``mechanism.geometry(program)`` is the
        same call, and picks the family's geometry type).
    program : MotionProgram (or MotionLike)
        S in mm (translating followers) or degrees (oscillating), per radian;
        per mm for a translating cam.
    bore_mm : float, optional
        Shaft bore diameter (a conjugate pair's second cam must clear it).

    Raises
    ------
    SpecError
        Every mechanism and motion/mechanism problem found, together.
    """

    #: the cam drives its follower both ways (conjugate pair, constant width/diameter, groove, cylindrical
    #: groove or rib): no return spring, no jump; equal to the families' ``CamKind.form_closed``
    form_closed: ClassVar[bool] = False
    #: one roller between two flanks of one pitch curve (a disc groove: profile 0 the inner flank, 1 the outer),
    #: whose force model is :class:`~camfab.design.dynamics.GrooveDynamics`
    flank_pair: ClassVar[bool] = False

    def __init__(self, mechanism: Any, program: MotionLike, *, bore_mm: float | None = None):
        kind = getattr(mechanism, "geometry_class", None)
        if kind is None or not isinstance(self, kind):
            raise ApiError(f"a {type(mechanism).__name__} builds its geometry with mechanism.geometry(program)")
        problems = mechanism.validate()
        if not problems:
            problems = mechanism.validate_motion(program, bore_mm=bore_mm)
        if problems:
            raise SpecError(problems)
        self.mechanism, self.program = mechanism, program
        self.profiles: tuple[Contact, ...] = tuple(mechanism.contacts(program))

    @classmethod
    def from_contacts(cls, contacts: Sequence[Contact], mechanism=None, program=None) -> CamGeometry:
        """A geometry made of ready-built contacts (conjugate cams and the like)."""
        self = cls.__new__(cls)
        self.mechanism, self.program, self.profiles = mechanism, program, tuple(contacts)
        return self

    # ---- basic properties ---------------------------------------------
    @property
    def closed(self) -> bool:
        return self.profiles[0].closed

    @property
    def axis(self) -> Axis:
        """What the parameter is (cam angle or travel) and the lift unit."""
        return self.profiles[0].axis

    @property
    def period(self) -> float:
        return self.profiles[0].period

    @property
    def x_unit(self) -> str:
        """"deg" (disc cams; internals in radians) or "mm" (translating cam)."""
        return "deg" if self.closed else "mm"

    def to_user(self, x):
        """Parameter in internal units → user units (degrees, or mm)."""
        return np.degrees(x) if self.closed else x

    @property
    def breakpoints(self) -> np.ndarray:
        """Union of every profile's breakpoints (radians, or mm), 0 and period included."""
        return sorted_unique(np.concatenate([c.breakpoints for c in self.profiles]))

    def evaluate(self, phi, profile: int = 0) -> ProfileSample:
        """Evaluate profile ``profile`` at cam angles ``phi`` (radians, any real; (n,))."""
        return self.profiles[profile].evaluate(phi)

    @property
    def initial_arm_angle(self) -> float | None:
        """ξ₀ (radians) of an oscillating follower, else None."""
        return getattr(self.mechanism, "initial_arm_angle", None)

    @property
    def initial_arm_angle_deg(self) -> float | None:
        a = self.initial_arm_angle
        return None if a is None else math.degrees(a)

    def summarised(self, report: Any) -> Any:
        """The check report (:class:`~camfab.results.CheckReport`) with this geometry's own summary: unchanged
        here; a cylindrical cam adds its cylinder's radii, roller and slip."""
        return report

    # ---- extremes and area --------------------------------------------
    def radius_extremes(self, profile: int = 0) -> Extremes:
        """R min / R max: extremes of the profile's distance from the cam centre (mm); found once per
        profile (the geometry is immutable), as the summaries, drawings and reports each ask for them."""
        memo = self.__dict__.setdefault("_radius_extremes", {})
        if profile not in memo:
            c = self.profiles[profile]
            edges = c.breakpoints
            lo, hi = extrema(lambda x: c.radius(x)[0], edges, (False, True), rows=(0, 0))
            memo[profile] = Extremes(lo.value, lo.at, hi.value, hi.at)
        return memo[profile]

    @property
    def min_radius(self) -> float:
        """Smallest distance of profile 0 from the cam centre (= R_b), mm."""
        return self.radius_extremes().min

    @property
    def max_radius(self) -> float:
        """Largest distance of profile 0 from the cam centre, mm."""
        return self.radius_extremes().max

    def area(self, profile: int = 0, *, rtol: float = 1e-11) -> float:
        """Area enclosed by the profile (mm²), Green's theorem ½∮(x dy − y dx).

        For a translating cam: the area between the profile and the bottom edge
        (∫ y dx over one cam length).
        """
        c = self.profiles[profile]
        if c.closed:
            def f(x):
                s = c.evaluate(x)
                return 0.5 * cross(s.point, s.point_d1)
        else:
            def f(x):
                s = c.evaluate(x)
                return s.point[:, 1] * s.point_d1[:, 0]
        return abs(integrate(f, c.breakpoints, rtol=rtol))
