"""Exact cam profiles of single-follower cams (``spec/profiles.md`` §3–§6, §13.5).

Everything is a closed-form function of the cam angle φ (radians) — or of the
travel B (mm) for a translating cam — built from S, S′, S″ of the motion
program; nothing is a fixed table and nothing is finite-differenced.

Derivation (one scheme for every mechanism)
-------------------------------------------
The follower is described in the **fixed frame** (cam centre at the origin,
follower above it, see :mod:`camfab.design.mechanisms`).  A cam turning by φ
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
  opposite for "+ = right" (spec D6); its own formulas put +m on the left.
* Flat-face contact position: translating face — signed distance along the
  face from the stem axis, positive to the right (a cw cam touches the left
  side, −S′, while rising); oscillating face — distance along the face from
  the right-angle vertex (the pivot's foot when f = 0), ``m·cos ξ + s``.
* Oscillating arm angle ξ (radians): angle at the pivot between pivot→cam
  centre and the arm; ξ = ξ₀ + lift, increasing = clockwise.

A :class:`CamGeometry` holds one or more :class:`Contact` profiles (conjugate
cams have two) and evaluates any of them at any φ.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Protocol, Sequence

import numpy as np

from ..errors import SpecError
from .kinds import Axis, ContactKind
from ..numeric import extrema, extremum, integrate
from .mechanisms import (Mechanism, OscillatingFlat, OscillatingRoller, TranslatingCamRoller,
                         TranslatingFlat, TranslatingRoller)

__all__ = [
    "MotionLike",
    "ProfileSample",
    "Extremes",
    "Contact",
    "DiscRollerContact",
    "TranslatingRollerContact",
    "OscillatingRollerContact",
    "DiscFlatContact",
    "TranslatingFlatContact",
    "OscillatingFlatContact",
    "TranslatingCamContact",
    "CamGeometry",
    "extremum",
    "integrate",
]

_K = math.pi / 180.0  # oscillating lifts are in degrees


class MotionLike(Protocol):
    """What a contact needs from a motion: S and derivatives, breakpoints, period, axis."""

    period: float
    axis: Axis

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
        Pitch curve (roller centre); None for flat faces.
    curvature_pitch, rho_pitch : (n,) float or None
        The same for the pitch curve (rollers only).
    pressure_angle : (n,) float
        Signed pressure angle in radians (0 for a translating flat face).
    face_position : (n,) float or None
        Flat faces: contact position along the face (mm), see module notes.
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
# small vector helpers on (n, 2) arrays
def _J(v: np.ndarray) -> np.ndarray:
    return np.stack([-v[:, 1], v[:, 0]], axis=1)


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]


def _dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return a[:, 0] * b[:, 0] + a[:, 1] * b[:, 1]


def _rot(v: np.ndarray, c: np.ndarray, s: np.ndarray) -> np.ndarray:
    return np.stack([v[:, 0] * c - v[:, 1] * s, v[:, 0] * s + v[:, 1] * c], axis=1)


def _xy(x, y) -> np.ndarray:
    x, y = np.broadcast_arrays(np.asarray(x, float), np.asarray(y, float))
    return np.stack([x, y], axis=1)


def _pressure(v: np.ndarray, n: np.ndarray, sigma: int) -> np.ndarray:
    """Signed angle from the follower's rise velocity ``v`` to the normal ``n``."""
    return np.arctan2(-sigma * _cross(v, n), _dot(v, n))


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
        R_r in mm (0 for flat faces and knife edges).
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
    """

    kind = ContactKind.ROLLER
    closed = True
    oscillating = False
    has_face = False
    roller_radius = 0.0

    @property
    def sliding(self) -> bool:
        """Knife edges and faces slide on the cam; a roller of radius > 0 rolls."""
        return self.has_face or self.kind is ContactKind.FLAT or self.roller_radius == 0.0

    def __init__(self, motion: MotionLike, sense: int = 1):
        if sense not in (1, -1):
            raise ValueError("sense must be +1 (cw) or -1 (ccw)")
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
        return r, _dot(s.point, s.point_d1) / r


class DiscRollerContact(Contact):
    """Generic roller on a rotating cam.  Subclasses give the fixed-frame roller
    centre path ``C, C′, C″`` (each (n, 2)), the unit rise velocity of the roller
    centre (n, 2) and the arm angle (or None) from ``S, S′, S″``."""

    def __init__(self, motion: MotionLike, roller_radius: float, sense: int = 1):
        super().__init__(motion, sense)
        self.roller_radius = float(roller_radius)

    def _path(self, S: np.ndarray):  # pragma: no cover - abstract
        raise NotImplementedError

    def _components(self, S):
        """``(cx, cy, c1x, c1y, c2x, c2y, vx, vy, arm)`` of :meth:`_path` as separate arrays
        (or scalars); subclasses override it with a direct, cheaper form."""
        C, C1, C2, v, arm = self._path(S)
        return C[:, 0], C[:, 1], C1[:, 0], C1[:, 1], C2[:, 0], C2[:, 1], v[:, 0], v[:, 1], arm

    def _evaluate(self, phi, rotate: bool, S=None) -> ProfileSample:
        x, S = self._S(phi, S)
        n = x.size
        sg, rr = self.sense, self.roller_radius
        # outputs filled chunk by chunk: the long chain of elementwise temporaries then
        # stays in cache (and off fresh pages), which is most of the cost at large n
        out = _block(16, n)  # the last row is the arm angle, when there is one
        pitch, point, point_d1, normal, tangent = out[0:2], out[2:4], out[4:6], out[6:8], out[8:10]
        kp, k, rho_p, rho, delta = out[10:15]
        arm = None
        for a in range(0, max(n, 1), _CHUNK):
            b = min(a + _CHUNK, n)
            cx, cy, c1x, c1y, c2x, c2y, vx, vy, xi = self._components(S[:, a:b])
            if xi is not None:
                arm = out[15]
                arm[a:b] = xi
            # component arrays instead of (n, 2) column slices: this is the hot path
            if not (isinstance(cx, np.ndarray) and cx.shape == cy.shape):
                cx = cx + 0.0 * cy  # broadcast a scalar coordinate to the sample count
            # (σ = ±1 is applied by choosing the operation or the sign of one factor: exact, and
            # no extra pass over the arrays)
            tx, ty = (c1x - cy, c1y + cx) if sg > 0 else (c1x + cy, c1y - cx)  # T = σ·J·C + C′
            ax = c2x - cx - 2 * sg * c1y                                        # A2 = −C + 2σ·J·C′ + C″
            ay = c2y - cy + 2 * sg * c1x
            speed = np.sqrt(tx * tx + ty * ty)  # |T| is far from overflow: no need for hypot's care
            inv = np.divide(sg, speed)  # σ/|T|
            # n = −σ·J·t = σ·(ty, −tx)/|T|, pitch curvature κp = σ·(T × A2)/|T|³
            nx = ty * inv
            ny = np.negative(tx * inv)
            inv3 = inv * inv
            inv3 *= inv  # σ³/|T|³ = σ/|T|³
            kpc = np.multiply(tx * ay - ty * ax, inv3, out=kp[a:b])
            scale = 1.0 - rr * kpc
            with np.errstate(divide="ignore", invalid="ignore"):
                kc = np.divide(kpc, scale, out=k[a:b])
                np.divide(1.0, kc, out=rho[a:b])
                np.divide(1.0, kpc, out=rho_p[a:b])
            # δ = atan2(−σ·(v × n), v·n)
            cr = vy * nx - vx * ny if sg > 0 else vx * ny - vy * nx
            np.arctan2(cr, vx * nx + vy * ny, out=delta[a:b])
            if rotate:
                c, s = _cos_sin(sg * x[a:b])
                _rot_into(pitch, a, b, cx, cy, c, s)
                _rot_into(normal, a, b, nx, ny, c, s)
            else:
                pitch[0, a:b], pitch[1, a:b], normal[0, a:b], normal[1, a:b] = cx, cy, nx, ny
            # rotation commutes with J: the rotated tangent is σ·J·(rotated normal), the profile point is
            # the rotated pitch point − Rr·(rotated normal), and P′ = T·(1 − Rr·κp) = t·|T|·(1 − Rr·κp)
            nrx, nry = normal[0, a:b], normal[1, a:b]
            np.multiply(nry, -sg, out=tangent[0, a:b])
            np.multiply(nrx, sg, out=tangent[1, a:b])
            np.subtract(pitch[0, a:b], rr * nrx, out=point[0, a:b])
            np.subtract(pitch[1, a:b], rr * nry, out=point[1, a:b])
            f = speed * scale
            np.multiply(tangent[0, a:b], f, out=point_d1[0, a:b])
            np.multiply(tangent[1, a:b], f, out=point_d1[1, a:b])
        return ProfileSample(x, point.T, point_d1.T, normal.T, tangent.T, k, rho, pitch.T, kp, rho_p, delta, None,
                             arm)


#: samples per chunk of the elementwise geometry (64 KiB per float64 temporary)
_CHUNK = 16384


def _block(rows: int, n: int) -> np.ndarray:
    """Uninitialised (rows, n) storage for the outputs of one evaluation.  One block instead
    of many arrays: at large n fresh memory costs more than the arithmetic, and one large
    allocation is faulted in far more cheaply (huge pages) than a dozen separate ones;
    rows left unused are never touched and cost no memory."""
    return np.empty((rows, n))


# fdlibm's kernel polynomials for sin and cos on [−π/4, π/4] (k_sin.c, k_cos.c) and its two-part π/2
_PIO2_1, _PIO2_1T = 1.57079632673412561417e+00, 6.07710050650619224932e-11
_SIN_C = (1.58969099521155010221e-10, -2.50507602534068634195e-08, 2.75573137070700676789e-06,
          -1.98412698298579493134e-04, 8.33333333332248946124e-03, -1.66666666666666324348e-01)
_COS_C = (-1.13596475577881948265e-11, 2.08757232129817482790e-09, -2.75573143513906633035e-07,
          2.48015872894767294178e-05, -1.38888888888741095749e-03, 4.16666666666666019037e-02)
#: |x| below which the reduction x − k·π/2 is exact enough (k·_PIO2_1 exact for |k| < 2²⁰)
_SINCOS_MAX = 1.0e5
#: cos and sin of q·π/2 for the quadrant q = 0…3
_QUAD_COS, _QUAD_SIN = np.array([1.0, 0.0, -1.0, 0.0]), np.array([0.0, 1.0, 0.0, -1.0])


def _cos_sin(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(cos x, sin x)`` to ~1 ulp, vectorised.

    numpy's float64 sin/cos are scalar library calls on most builds, slower than these
    ~40 elementwise operations: Cody–Waite reduction by π/2, fdlibm's minimax kernels,
    quadrant selection.  Beyond ``_SINCOS_MAX`` (never a cam angle) a complex exponential.
    """
    x = np.asarray(x, dtype=float)
    if x.size == 0 or not np.abs(x).max() < _SINCOS_MAX:  # also NaN / inf
        e = np.exp(x * 1j)
        return e.real, e.imag
    k = np.rint(x * (2.0 / math.pi))
    r = x - k * _PIO2_1
    r -= k * _PIO2_1T
    z = r * r
    ps = _SIN_C[0] * z
    for cf in _SIN_C[1:]:
        ps += cf
        ps *= z
    ps *= r
    sin_r = r + ps
    pc = _COS_C[0] * z
    for cf in _COS_C[1:]:
        pc += cf
        pc *= z
    pc *= z
    cos_r = 1.0 - 0.5 * z
    cos_r += pc
    # quadrant q = k mod 4: cos x = a·cos r − b·sin r, sin x = b·cos r + a·sin r with (a, b) the
    # quadrant's (cos, sin) of q·π/2 (0 or ±1, so the result is exactly ±cos r or ±sin r)
    q = k.astype(np.intp) & 3
    a, b = _QUAD_COS.take(q), _QUAD_SIN.take(q)
    c = cos_r * a
    c -= sin_r * b
    s = cos_r * b
    s += sin_r * a
    return c, s


def _rot_into(out: np.ndarray, a: int, b: int, x, y, c: np.ndarray, s: np.ndarray) -> None:
    """``out[:, a:b]`` (a (2, n) array) = components (x, y) rotated by the angle whose cos/sin are c, s."""
    np.subtract(x * c, y * s, out=out[0, a:b])
    np.add(x * s, y * c, out=out[1, a:b])


def _inv(k: np.ndarray) -> np.ndarray:
    with np.errstate(divide="ignore"):
        return 1.0 / k


def _roller(C, T, A2, v, rr, sg):
    """Pitch/profile quantities from the cam-frame tangent T and second derivative A2."""
    speed = np.hypot(T[:, 0], T[:, 1])
    t = T / speed[:, None]
    kp = sg * _cross(T, A2) / speed**3
    n = -sg * _J(t)
    point = C - rr * n
    scale = 1.0 - rr * kp
    with np.errstate(divide="ignore", invalid="ignore"):
        k = kp / scale
    return C, point, T * scale[:, None], n, t, kp, k, _pressure(v, n, sg)


class TranslatingRollerContact(DiscRollerContact):
    """Translating roller with offset e: C = (e, √(R_p² − e²) + S) in the fixed frame."""

    def __init__(self, motion: MotionLike, prime_radius: float, roller_radius: float,
                 offset: float = 0.0, sense: int = 1):
        super().__init__(motion, roller_radius, sense)
        self.offset = float(offset)
        self.axial_base = math.sqrt(prime_radius**2 - offset**2)

    def _path(self, S):
        s0, s1, s2 = S
        z = np.zeros_like(s0)
        return (_xy(self.offset + z, self.axial_base + s0), _xy(z, s1), _xy(z, s2), _xy(z, 1.0 + z), None)

    def _components(self, S):
        s0, s1, s2 = S
        return self.offset, self.axial_base + s0, 0.0, s1, 0.0, s2, 0.0, 1.0, None


class OscillatingRollerContact(DiscRollerContact):
    """Oscillating roller: pivot (m, 0), C = (m − A cos ξ, A sin ξ), ξ = ξ₀ + S (S in degrees)."""

    oscillating = True

    def __init__(self, motion: MotionLike, pivot_distance: float, arm_length: float,
                 initial_arm_angle: float, roller_radius: float, sense: int = 1):
        super().__init__(motion, roller_radius, sense)
        self.m, self.a, self.xi0 = float(pivot_distance), float(arm_length), float(initial_arm_angle)

    def _path(self, S):
        xi, x1, x2 = self.xi0 + _K * S[0], _K * S[1], _K * S[2]
        sx, cx, a = np.sin(xi), np.cos(xi), self.a
        C = _xy(self.m - a * cx, a * sx)
        C1 = _xy(a * x1 * sx, a * x1 * cx)
        C2 = _xy(a * (x2 * sx + x1**2 * cx), a * (x2 * cx - x1**2 * sx))
        return C, C1, C2, _xy(sx, cx), xi

    def _components(self, S):
        xi, x1, x2 = self.xi0 + _K * S[0], _K * S[1], _K * S[2]
        (cx, sx), a = _cos_sin(xi), self.a
        ax1, ax1sq = a * x1, a * x1 * x1
        return (self.m - a * cx, a * sx, ax1 * sx, ax1 * cx, a * x2 * sx + ax1sq * cx, a * x2 * cx - ax1sq * sx,
                sx, cx, xi)


class DiscFlatContact(Contact):
    """Generic flat face on a rotating cam.  Subclasses give, from S, S′, S″, the
    fixed-frame face normal angle β, β′, β″, its distance p, p′, p″ from the cam
    centre, and implement :meth:`_extras` (follower velocity direction, face
    position, arm angle)."""

    kind = ContactKind.FLAT
    has_face = True

    def _face(self, S):  # pragma: no cover - abstract
        raise NotImplementedError

    def _extras(self, px, py, s, S):  # pragma: no cover - abstract
        """``(vx, vy, face position, arm angle)``: the follower's unit rise velocity at the
        contact point (px, py) (fixed frame), and the optional outputs (or None)."""
        raise NotImplementedError

    def _evaluate(self, phi, rotate: bool, S=None) -> ProfileSample:
        x, S = self._S(phi, S)
        n = x.size
        sg = self.sense
        out = _block(13, n)  # the last two rows are the face position and the arm angle, when given
        point, point_d1, normal, tangent = out[0:2], out[2:4], out[4:6], out[6:8]
        k, rho, delta = out[8:11]
        pos = arm = None
        for a in range(0, max(n, 1), _CHUNK):  # chunked as in DiscRollerContact.evaluate
            b = min(a + _CHUNK, n)
            Sc = S[:, a:b]
            beta, b1, b2, p, p1, p2 = self._face(Sc)
            w = sg + b1
            s = p1 / w
            rc = np.subtract(p + p2 / w**2, p1 * b2 / w**3, out=rho[a:b])
            nx, ny = _cos_sin(beta)                             # face normal; J·n = (−ny, nx)
            px, py = p * nx - s * ny, p * ny + s * nx
            vx, vy, pc, xi = self._extras(px, py, s, Sc)
            if pc is not None:
                pos = out[11]
                pos[a:b] = pc
            if xi is not None:
                arm = out[12]
                arm[a:b] = xi
            np.arctan2(-sg * (vx * ny - vy * nx), vx * nx + vy * ny, out=delta[a:b])
            with np.errstate(divide="ignore"):
                np.divide(1.0, rc, out=k[a:b])
            wr = w * rc
            if rotate:
                c, sn = _cos_sin(sg * x[a:b])
                _rot_into(point, a, b, px, py, c, sn)
                _rot_into(point_d1, a, b, -ny * wr, nx * wr, c, sn)
                _rot_into(normal, a, b, nx, ny, c, sn)
                _rot_into(tangent, a, b, -sg * ny, sg * nx, c, sn)
            else:
                point[0, a:b], point[1, a:b], point_d1[0, a:b], point_d1[1, a:b] = px, py, -ny * wr, nx * wr
                normal[0, a:b], normal[1, a:b], tangent[0, a:b], tangent[1, a:b] = nx, ny, -sg * ny, sg * nx
        return ProfileSample(x, point.T, point_d1.T, normal.T, tangent.T, k, rho, None, None, None, delta, pos, arm)


class TranslatingFlatContact(DiscFlatContact):
    """Translating flat face at distance R_b + S; ρ = R_b + S + S″."""

    def __init__(self, motion: MotionLike, base_radius: float, face_offset: float = 0.0, sense: int = 1):
        super().__init__(motion, sense)
        self.rb, self.face_offset = float(base_radius), float(face_offset)

    def _face(self, S):
        # the face normal angle is the constant π/2: given as a scalar (its cos/sin are then
        # taken once, not per sample), β′ = β″ = 0 likewise
        return math.pi / 2, 0.0, 0.0, self.rb + S[0], S[1], S[2]

    def _extras(self, px, py, s, S):
        return 0.0, 1.0, px - self.face_offset, None


class OscillatingFlatContact(DiscFlatContact):
    """Oscillating flat face: normal (sin ξ, cos ξ), distance f + m sin ξ (spec §6)."""

    oscillating = True

    def __init__(self, motion: MotionLike, pivot_distance: float, face_offset: float,
                 initial_arm_angle: float, sense: int = 1):
        super().__init__(motion, sense)
        self.m, self.f, self.xi0 = float(pivot_distance), float(face_offset), float(initial_arm_angle)

    def _xi(self, S):
        return self.xi0 + _K * S[0], _K * S[1], _K * S[2]

    def _face(self, S):
        xi, x1, x2 = self._xi(S)
        (cx, sx), m = _cos_sin(xi), self.m
        return (math.pi / 2 - xi, -x1, -x2, self.f + m * sx, m * cx * x1, m * (cx * x2 - sx * x1**2))

    def _extras(self, px, py, s, S):
        xi = self._xi(S)[0]
        rx, ry = px - self.m, py - 0.0
        d = np.hypot(rx, ry)
        return ry / d, -rx / d, s + self.m * np.cos(xi), xi  # clockwise about the pivot


class TranslatingCamContact(Contact):
    """Roller on a translating (wedge) cam: pitch (x₀ ± B, h + R_r + S) (spec §13.5)."""

    closed = False

    def __init__(self, motion: MotionLike, roller_radius: float, base_height: float = 0.0,
                 direction: str = "left"):
        super().__init__(motion, 1 if direction == "right" else -1)
        self.roller_radius, self.base_height = float(roller_radius), float(base_height)

    def _evaluate(self, phi, rotate: bool, S=None) -> ProfileSample:
        # a sliding plate is not turned: one sample serves both frames (the checked quantities and the
        # normal do not depend on where the plate has slid to)
        x, (s0, s1, s2) = self._S(phi, S)
        chi = -self.sense  # +1: x = B (cam slides left)
        x0 = 0.0 if chi > 0 else self.period
        z = np.zeros_like(s0)
        C = _xy(x0 + chi * x, self.base_height + self.roller_radius + s0)
        out = _roller(C, _xy(chi + z, s1), _xy(z, s2), _xy(z, 1.0 + z), self.roller_radius, self.sense)
        pitch, point, dpoint, n, t, kp, k, delta = out
        return ProfileSample(x, point, dpoint, n, t, k, _inv(k), pitch, kp, _inv(kp), delta, None, None)


# ---------------------------------------------------------------------------
class CamGeometry:
    """Exact geometry of a cam: one or more :class:`Contact` profiles.

    Parameters
    ----------
    mechanism : Mechanism
        One of :mod:`camfab.design.mechanisms`.
    program : MotionProgram (or MotionLike)
        S in mm (translating followers) or degrees (oscillating), per radian;
        per mm for a translating cam.

    Raises
    ------
    SpecError
        Every mechanism and motion/mechanism problem found, together.
    """

    def __init__(self, mechanism: Mechanism, program: MotionLike):
        if not isinstance(mechanism, Mechanism):
            raise TypeError(f"unsupported mechanism {type(mechanism).__name__}")
        problems = mechanism.validate()
        if not problems:
            problems = mechanism.validate_motion(program)
        if problems:
            raise SpecError(problems)
        self.mechanism, self.program = mechanism, program
        self.profiles: tuple[Contact, ...] = (_contact(mechanism, program),)

    @classmethod
    def from_contacts(cls, contacts: Sequence[Contact], mechanism=None, program=None) -> "CamGeometry":
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
        return np.unique(np.concatenate([c.breakpoints for c in self.profiles]))

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

    # ---- extremes and area --------------------------------------------
    def radius_extremes(self, profile: int = 0) -> Extremes:
        """DMIN/DMAX: extremes of the profile's distance from the cam centre (mm); found once per
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
                return 0.5 * _cross(s.point, s.point_d1)
        else:
            def f(x):
                s = c.evaluate(x)
                return s.point[:, 1] * s.point_d1[:, 0]
        return abs(integrate(f, c.breakpoints, rtol=rtol))


def _contact(mech: Mechanism, prog: MotionLike) -> Contact:
    if isinstance(mech, TranslatingRoller):
        return TranslatingRollerContact(prog, mech.prime_radius_mm, mech.roller_radius_mm, mech.offset_mm, mech.sense)
    if isinstance(mech, OscillatingRoller):
        return OscillatingRollerContact(prog, mech.pivot_distance_mm, mech.arm_length_mm, mech.initial_arm_angle,
                                        mech.roller_radius_mm, mech.sense)
    if isinstance(mech, TranslatingFlat):
        return TranslatingFlatContact(prog, mech.base_radius_mm, mech.face_offset_mm, mech.sense)
    if isinstance(mech, OscillatingFlat):
        return OscillatingFlatContact(prog, mech.pivot_distance_mm, mech.face_offset_mm, mech.initial_arm_angle,
                                      mech.sense)
    if isinstance(mech, TranslatingCamRoller):
        return TranslatingCamContact(prog, mech.roller_radius_mm, mech.base_height_mm, mech.direction)
    raise TypeError(f"unsupported mechanism {type(mech).__name__}")
