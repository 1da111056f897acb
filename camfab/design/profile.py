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
from typing import Callable, Protocol, Sequence

import numpy as np

from ..errors import SpecError
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
    """What a contact needs from a motion: S and derivatives, breakpoints, period."""

    period: float

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
    kind : {"roller", "flat"}
    roller_radius : float
        R_r in mm (0 for flat faces and knife edges).
    closed : bool
        True for disc cams (periodic closed curve), False for a translating cam.
    """

    kind = "roller"
    closed = True
    roller_radius = 0.0

    def __init__(self, motion: MotionLike, sense: int = 1):
        if sense not in (1, -1):
            raise ValueError("sense must be +1 (cw) or -1 (ccw)")
        self.motion = motion
        self.sense = sense

    @property
    def period(self) -> float:
        return float(self.motion.period)

    @property
    def breakpoints(self) -> np.ndarray:
        """Parameter values where a formula changes, 0 and the period included."""
        return np.asarray(self.motion.breakpoints, dtype=float)

    def evaluate(self, phi) -> ProfileSample:  # pragma: no cover - abstract
        raise NotImplementedError

    def evaluate_fixed(self, phi) -> ProfileSample:
        """The same sample in the fixed (follower) frame: where the contact is in the machine at
        each φ — the cam-frame sample rotated back by −σφ.  Quantities that do not depend on the
        frame (curvatures, pressure angle, face position, |point|, point × point′) are those of
        :meth:`evaluate`, to rounding; the checks use this form, which skips the rotation."""
        return self.evaluate(phi)

    def _S(self, phi) -> tuple[np.ndarray, np.ndarray]:
        x = np.atleast_1d(np.asarray(phi, dtype=float))
        return x, self.motion.evaluate(x, (0, 1, 2))

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

    def evaluate(self, phi) -> ProfileSample:
        return self._evaluate(phi, True)

    def evaluate_fixed(self, phi) -> ProfileSample:
        return self._evaluate(phi, False)

    def _evaluate(self, phi, rotate: bool) -> ProfileSample:
        x, S = self._S(phi)
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

    kind = "flat"

    def _face(self, S):  # pragma: no cover - abstract
        raise NotImplementedError

    def _extras(self, px, py, s, S):  # pragma: no cover - abstract
        """``(vx, vy, face position, arm angle)``: the follower's unit rise velocity at the
        contact point (px, py) (fixed frame), and the optional outputs (or None)."""
        raise NotImplementedError

    def evaluate(self, phi) -> ProfileSample:
        return self._evaluate(phi, True)

    def evaluate_fixed(self, phi) -> ProfileSample:
        return self._evaluate(phi, False)

    def _evaluate(self, phi, rotate: bool) -> ProfileSample:
        x, S = self._S(phi)
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

    def evaluate(self, phi) -> ProfileSample:
        x, (s0, s1, s2) = self._S(phi)
        chi = -self.sense  # +1: x = B (cam slides left)
        x0 = 0.0 if chi > 0 else self.period
        z = np.zeros_like(s0)
        C = _xy(x0 + chi * x, self.base_height + self.roller_radius + s0)
        out = _roller(C, _xy(chi + z, s1), _xy(z, s2), _xy(z, 1.0 + z), self.roller_radius, self.sense)
        pitch, point, dpoint, n, t, kp, k, delta = out
        return ProfileSample(x, point, dpoint, n, t, k, _inv(k), pitch, kp, _inv(kp), delta, None, None)


# ---------------------------------------------------------------------------
# numerics shared with checks and sizing
def _intervals(edges: np.ndarray, step: float):
    """Sample grids per breakpoint interval, ends pulled in by a hair (one-sided limits)."""
    per = edges[-1] - edges[0]
    eps = 1e-11 * max(per, 1.0)
    out = []
    for a, b in zip(edges[:-1], edges[1:]):
        if b - a <= 4 * eps:
            continue
        n = max(8, int(math.ceil((b - a) / step)))
        out.append((a + eps, b - eps, np.linspace(a + eps, b - eps, n + 1)))
    return out


_GRIDS: dict = {}


def _sampling(edges: np.ndarray, step: float):
    """``(ivs, grid, starts)``: :func:`_intervals` and :func:`_grid` of ``edges``, memoised (the
    checks sample the same breakpoints many times); the arrays are read-only."""
    key = (edges.tobytes(), float(step))
    hit = _GRIDS.get(key)
    if hit is None:
        ivs = _intervals(edges, step)
        grid, starts = _grid(ivs) if ivs else (np.empty(0), np.empty(0, dtype=int))
        for arr in (grid, starts, *(xs for _, _, xs in ivs)):
            arr.setflags(write=False)
        if len(_GRIDS) >= 256:
            _GRIDS.clear()
        hit = _GRIDS[key] = (ivs, grid, starts)
    return hit


def _default_step(period: float) -> float:
    return period / 1440.0


# Solvers as generators: a solver ``yield``s the parameter values it needs (1-D array) and is
# sent f at them; :func:`_run` drives one with a plain f, :func:`_gather` runs several in
# lockstep (one request per round), so that many searches share one f call per round — the
# cost of a profile evaluation is mostly per call, not per point.
def _run(f: Callable[[np.ndarray], np.ndarray], gen):
    """Drive solver generator ``gen`` with ``f``; its return value."""
    try:
        x = next(gen)
        while True:
            x = gen.send(np.asarray(f(x), dtype=float))
    except StopIteration as stop:
        return stop.value


def _gather(gens):
    """Generator: run solver generators in lockstep, each round one request (their
    concatenation); returns the list of their results."""
    gens = list(gens)
    res: list = [None] * len(gens)
    req: dict[int, np.ndarray] = {}
    for i, g in enumerate(gens):
        try:
            req[i] = np.asarray(next(g), dtype=float).ravel()
        except StopIteration as stop:
            res[i] = stop.value
    while req:
        keys = list(req)
        v = yield (req[keys[0]] if len(keys) == 1 else np.concatenate([req[i] for i in keys]))
        off = 0
        for i in keys:
            n = req[i].size
            try:
                req[i] = np.asarray(gens[i].send(v[off:off + n]), dtype=float).ravel()
            except StopIteration as stop:
                res[i] = stop.value
                del req[i]
            off += n
    return res


def _mapped(gen, fn):
    """Generator: ``gen`` with every value array it is sent passed through ``fn`` first."""
    try:
        x = next(gen)
        while True:
            x = gen.send(fn((yield x)))
    except StopIteration as stop:
        return stop.value


#: extrema equal to this relative difference are ties (rounding of repeated lobes)
_TIE = 1e-10
#: bracket values within this relative difference of the best are equal to rounding
_FLAT = 64 * np.finfo(float).eps
#: ratio of the point ladder placed around each estimate per round
_LADDER = 0.01


def _trials(u: np.ndarray, a: np.ndarray, b: np.ndarray, tol: np.ndarray) -> np.ndarray:
    """(k, m) trial points of one round: the estimate u, u ± w·r^j (w = b − a, r =
    :data:`_LADDER`, down to the tolerance) and the quarter points of [a, b] (so that the
    bracket at least halves whatever the estimate), clipped to [a, b]."""
    w = b - a
    ratio = float(np.max(w / np.maximum(tol, 1e-300)))
    J = int(min(max(math.ceil(math.log(max(ratio, 1.0)) / -math.log(_LADDER)), 1), 8))
    steps = w[:, None] * _LADDER ** np.arange(1, J + 1)[None, :]
    pts = np.concatenate([u[:, None], u[:, None] - steps, u[:, None] + steps,
                          a[:, None] + w[:, None] * np.array([0.25, 0.5, 0.75])[None, :]], axis=1)
    return np.clip(pts, a[:, None], b[:, None])


def _neighbours(P: np.ndarray, F: np.ndarray, j: np.ndarray):
    """For sample rows P (positions) / F (values) and chosen column j per row: the nearest
    sample on each side (position, value), or the chosen sample itself where none."""
    r = np.arange(len(P))
    xj, fj = P[r, j], F[r, j]
    xc = xj[:, None]
    li = np.argmax(np.where(P < xc, P, -np.inf), axis=1)  # positions are finite
    ri = np.argmin(np.where(P > xc, P, np.inf), axis=1)
    pl, pr = P[r, li], P[r, ri]
    hl, hr = pl < xj, pr > xj
    return (np.where(hl, pl, xj), np.where(hl, F[r, li], fj), xj, fj,
            np.where(hr, pr, xj), np.where(hr, F[r, ri], fj))


def _bracket_min(a, fa, x, fx, b, fb, tol, *, rounds: int = 60):
    """Generator: vectorised safeguarded minimisation of k one-dimensional problems.

    Each problem has a bracket [a, b] with its best sample x (a ≤ x ≤ b, fx ≤ fa, fb;
    x may be an end).  Each round samples, for all problems at once, the vertex of the
    parabola through (a, x, b) with a ladder of points around it and the quarter points
    of the bracket, then shrinks the bracket to the neighbours of the best sample: the
    bracket at least halves per round and shrinks by ~1/r² per round once the parabola
    is accurate.  Stops when b − a ≤ tol or when f at a and b equals f at x to rounding
    (:data:`_FLAT`).  Values must be NaN-free (use +inf).
    Returns ``(x, fx)`` arrays.
    """
    a, fa, x, fx, b, fb = (np.array(t, dtype=float) for t in (a, fa, x, fx, b, fb))
    tol = np.broadcast_to(np.asarray(tol, dtype=float), a.shape).copy()
    done = ~(b - a > tol)
    for _ in range(rounds):
        act = np.flatnonzero(~done)
        if act.size == 0:
            break
        A, FA, X, FX, B, FB = a[act], fa[act], x[act], fx[act], b[act], fb[act]
        d1, d2, f1, f2 = X - A, B - X, FA - FX, FB - FX
        with np.errstate(all="ignore"):
            u = X + 0.5 * (d2 * d2 * f1 - d1 * d1 * f2) / (d2 * f1 + d1 * f2)
        u = np.where(np.isfinite(u) & (d1 > 0) & (d2 > 0), u, X)
        pts = _trials(u, A, B, tol[act])
        v = yield pts.ravel()
        v = np.asarray(v, dtype=float).reshape(pts.shape)
        P = np.concatenate([X[:, None], A[:, None], B[:, None], pts], axis=1)
        F = np.concatenate([FX[:, None], FA[:, None], FB[:, None], v], axis=1)
        j = np.argmin(F, axis=1)  # ties keep the current best (column 0)
        a[act], fa[act], x[act], fx[act], b[act], fb[act] = _neighbours(P, F, j)
        # done when the bracket is narrow, or when its ends differ from the best by rounding only
        # (the samples cannot locate the extremum any better; the value is then exact to rounding)
        with np.errstate(invalid="ignore"):
            flat = np.maximum(fa[act], fb[act]) - fx[act] <= _FLAT * np.abs(fx[act])
        done[act] = ~(b[act] - a[act] > tol[act]) | flat
    return x, fx


def _bracket_root(a, fa, b, fb, *, xtol: float = 1e-14, rtol: float = 1e-15, rounds: int = 80):
    """Generator: vectorised bracketing root refinement of k problems, where ``f > 0`` differs
    at a and b (NaN counts as not positive).

    Each round samples, for all problems at once, the secant estimate with a ladder of
    points around it and the quarter points of the bracket, and keeps the first sign
    change from a (the bracket at least halves per round, and shrinks by ~1/r² once
    the secant is accurate).  Stops when b − a < xtol + rtol·|x| (brentq's test).
    Returns the bracket end with the smaller |f| per problem.
    """
    a, fa, b, fb = (np.array(t, dtype=float) for t in (a, fa, b, fb))
    for _ in range(rounds):
        act = np.flatnonzero(b - a >= xtol + rtol * np.maximum(np.abs(a), np.abs(b)))
        if act.size == 0:
            break
        A, FA, B, FB = a[act], fa[act], b[act], fb[act]
        with np.errstate(all="ignore"):
            u = A - FA * (B - A) / (FB - FA)
        u = np.where(np.isfinite(u), u, 0.5 * (A + B))
        pts = _trials(u, A, B, np.full(act.size, xtol))
        v = yield pts.ravel()
        v = np.asarray(v, dtype=float).reshape(pts.shape)
        P = np.concatenate([A[:, None], pts, B[:, None]], axis=1)
        F = np.concatenate([FA[:, None], v, FB[:, None]], axis=1)
        o = np.argsort(P, axis=1, kind="stable")
        P, F = np.take_along_axis(P, o, 1), np.take_along_axis(F, o, 1)
        flip = (F[:, :-1] > 0) != (F[:, 1:] > 0)  # the ends differ, so some adjacent pair does
        j = np.argmax(flip, axis=1)
        r = np.arange(act.size)
        a[act], fa[act], b[act], fb[act] = P[r, j], F[r, j], P[r, j + 1], F[r, j + 1]
    with np.errstate(invalid="ignore"):
        take_a = ~(np.abs(fb) < np.abs(fa))
    return np.where(take_a, a, b)


def _candidates(grid: np.ndarray, starts: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Indices of local minima of v (NaN-free) within each interval of the concatenated grid
    (intervals start at ``starts``; the first and last sample of an interval compare one-sidedly)."""
    le_prev = np.empty(v.size, dtype=bool)
    le_next = np.empty(v.size, dtype=bool)
    np.less_equal(v[1:], v[:-1], out=le_prev[1:])
    np.less_equal(v[:-1], v[1:], out=le_next[:-1])
    le_prev[starts] = True  # the first sample of an interval (and of the grid)
    le_next[starts[1:] - 1] = True  # the last one
    le_next[-1] = True
    return np.flatnonzero(le_prev & le_next)


def _grid(ivs) -> tuple[np.ndarray, np.ndarray]:
    """Concatenated sample grid of :func:`_intervals` and the start index of each interval."""
    sizes = np.array([len(xs) for _, _, xs in ivs], dtype=int)
    starts = np.r_[0, np.cumsum(sizes)[:-1]]
    return np.concatenate([xs for _, _, xs in ivs]), starts


def _extremum_steps(edges, *, maximize: bool = False, step: float | None = None, keep: int = 4):
    """Generator form of :func:`extremum` (for :func:`_run` / :func:`_gather`)."""
    edges = np.asarray(edges, dtype=float)
    step = step or _default_step(edges[-1] - edges[0])
    sgn = -1.0 if maximize else 1.0
    ivs, grid, starts = _sampling(edges, step)
    if not ivs:
        return 0.0, float(sgn * math.inf)

    def clean(y):
        y = sgn * np.asarray(y, dtype=float)
        return np.where(np.isnan(y), np.inf, y)

    v = clean((yield grid))
    loc = _candidates(grid, starts, v)
    loc = loc[np.argsort(v[loc], kind="stable")][:keep]
    end = np.r_[starts[1:], grid.size] - 1
    iv = np.searchsorted(starts, loc, side="right") - 1
    lo_i, hi_i = np.maximum(loc - 1, starts[iv]), np.minimum(loc + 1, end[iv])
    lo, hi = grid[lo_i], grid[hi_i]
    ref = hi > lo
    rx, rv = grid[loc].copy(), np.full(loc.size, np.inf)
    if ref.any():
        tol = 1e-9 * (hi[ref] - lo[ref])
        tol = np.maximum(tol, 16 * np.finfo(float).eps * np.maximum(1.0, np.abs(hi[ref])))
        xr, fr = yield from _mapped(_bracket_min(lo[ref], v[lo_i[ref]], grid[loc[ref]], v[loc[ref]], hi[ref],
                                                 v[hi_i[ref]], tol), clean)
        rx[ref], rv[ref] = xr, np.where(np.isfinite(fr), fr, np.inf)
    # the best of (grid value, refined value) per candidate; equal extrema (to rounding, e.g.
    # repeated lobes) resolve to the smallest parameter, not to whichever rounding favoured
    seq = np.stack([v[loc], rv], axis=1).ravel()
    at = np.stack([grid[loc], rx], axis=1).ravel()
    best = float(np.min(seq))
    if not best < math.inf:
        return 0.0, float(sgn * math.inf)
    tie = np.flatnonzero(seq <= best + _TIE * abs(best))
    k = int(tie[np.argmin(at[tie])])
    return float(at[k]), float(sgn * seq[k])


def _trials_multi(u, a, b, tol, bt, nb: int) -> np.ndarray:
    """:func:`_trials` of rows from several independent batches (row r in batch ``bt[r]``):
    each row gets the points it would get in a call of its batch alone, the ladder entries
    beyond its batch's ladder length being repeats of the estimate u."""
    w = b - a
    ratio = w / np.maximum(tol, 1e-300)
    n = u.size
    lad = -math.log(_LADDER)
    if nb == 1 or n == 1:
        r = float(np.max(ratio))
        Jr = min(max(math.ceil(math.log(max(r, 1.0)) / lad), 1), 8)
        jm = Jr = int(Jr)
        steps = w[:, None] * _LADPOW[None, :jm]
    else:
        if n > 1 and bt[0] <= bt[-1] and not (bt[1:] < bt[:-1]).any():
            # rows grouped by batch (the solvers' order): the largest ratio per group
            cut = np.flatnonzero(bt[1:] != bt[:-1]) + 1
            gmax = np.maximum.reduceat(ratio, np.r_[0, cut]) if cut.size else np.array([np.max(ratio)])
            Jg = [int(min(max(math.ceil(math.log(max(r, 1.0)) / lad), 1), 8)) for r in gmax.tolist()]
            jm = max(Jg)
            Jr = np.repeat(np.array(Jg, dtype=np.intp), np.diff(np.r_[0, cut, n])) if min(Jg) < jm else None
        else:
            rmax = np.full(nb, -np.inf)
            np.maximum.at(rmax, bt, ratio)
            Jb = np.array([int(min(max(math.ceil(math.log(max(r, 1.0)) / lad), 1), 8)) if r > -math.inf else 1
                           for r in rmax.tolist()], dtype=np.intp)
            Jr = Jb[bt]
            jm = int(Jr.max())
            if int(Jr.min()) == jm:
                Jr = None
        steps = w[:, None] * _LADPOW[None, :jm]
        if Jr is not None:
            steps[_LADIDX[None, :jm] > Jr[:, None]] = 0.0  # u ± 0 = u: a repeat
    pts = np.empty((n, 2 * jm + 4))
    pts[:, 0] = u
    uc = u[:, None]
    np.subtract(uc, steps, out=pts[:, 1:jm + 1])
    np.add(uc, steps, out=pts[:, jm + 1:2 * jm + 1])
    np.add(a[:, None], w[:, None] * _QUARTERS[None, :], out=pts[:, 2 * jm + 1:])
    # np.clip(pts, a, b) (every value is finite)
    np.maximum(pts, a[:, None], out=pts)
    return np.minimum(pts, b[:, None], out=pts)


#: the ladder ratios r^j (j = 1…8) and their exponents
_LADPOW = _LADDER ** np.arange(1, 9)
_LADIDX = np.arange(1, 9)
_QUARTERS = np.array([0.25, 0.5, 0.75])


class _ExtremaPlan:
    """Several :func:`_extremum_steps` searches of functions given as rows of a value array:
    their dense grids (:attr:`grids`), the refinement rows after the dense sampling
    (:meth:`prepare`) and the results (:meth:`finish`), each exactly as its own search.

    ``specs`` holds ``(edges, maximize[, step[, row]])``; search i reads row ``row`` (default
    i) of the values and is refinement batch ``base + i``."""

    def __init__(self, specs, base: int = 0):
        self.specs = [(np.asarray(sp[0], dtype=float), sp[1], sp[2] if len(sp) > 2 else None,
                       sp[3] if len(sp) > 3 else i) for i, sp in enumerate(specs)]
        self.sgn = np.array([-1.0 if mx else 1.0 for _, mx, _, _ in self.specs])
        self.row = np.array([r for _, _, _, r in self.specs], dtype=np.intp)
        self.base = base
        self.samp = [_sampling(e, st or _default_step(e[-1] - e[0])) for e, _, st, _ in self.specs]
        offs, parts, total = [], {}, 0
        for ivs, grid, starts in self.samp:
            if ivs and id(grid) not in parts:
                parts[id(grid)] = (total, grid)
                total += grid.size
            offs.append(parts[id(grid)][0] if ivs else 0)
        self.offs, self.grids, self.size = offs, [g for _, g in parts.values()], total
        self.plan: list = []

    def prepare(self, V: np.ndarray, off: int = 0):
        """The refinement rows (lo, f(lo), x, f(x), hi, f(hi), tol, batch) from the values V at
        the dense grids (which start at column ``off``), or None.  All searches at once: their
        samples concatenated (each interval of each search an interval of the whole)."""
        act = [i for i, (ivs, _, _) in enumerate(self.samp) if ivs]
        self.act = act
        if not act:
            return None
        sizes = np.array([self.samp[i][1].size for i in act])
        base = np.r_[0, np.cumsum(sizes)[:-1]]
        gx = np.concatenate([self.samp[i][1] for i in act])
        cols = np.concatenate([off + self.offs[i] + np.arange(self.samp[i][1].size) for i in act])
        own = np.repeat(np.arange(len(act)), sizes)
        v = np.repeat(self.sgn[act], sizes) * V[np.repeat(self.row[act], sizes), cols]
        v = np.where(np.isnan(v), np.inf, v)
        starts = np.concatenate([self.samp[i][2] + bs for i, bs in zip(act, base)])
        loc = _candidates(gx, starts, v)
        loc = loc[np.lexsort((loc, v[loc], own[loc]))]  # per search, by value (stable)
        grp = own[loc]
        first = np.searchsorted(grp, np.arange(len(act)))
        rank = np.arange(loc.size) - first[grp]
        keep = rank < 4
        loc, grp, rank = loc[keep], grp[keep], rank[keep]
        end = np.r_[starts[1:], gx.size] - 1
        iv = np.searchsorted(starts, loc, side="right") - 1
        lo_i, hi_i = np.maximum(loc - 1, starts[iv]), np.minimum(loc + 1, end[iv])
        lo, hi = gx[lo_i], gx[hi_i]
        ref = hi > lo
        self.cand = (len(act), grp, rank, v[loc], gx[loc], ref)
        if not ref.any():
            return None
        tol = 1e-9 * (hi[ref] - lo[ref])
        tol = np.maximum(tol, 16 * np.finfo(float).eps * np.maximum(1.0, np.abs(hi[ref])))
        return [lo[ref], v[lo_i[ref]], gx[loc[ref]], v[loc[ref]], hi[ref], v[hi_i[ref]], tol,
                self.base + np.asarray(act)[grp[ref]]]

    def channels(self) -> tuple[np.ndarray, np.ndarray]:
        """Value row and sign of every batch (indexed from :attr:`base`)."""
        return self.row, self.sgn

    def finish(self, xr_all=None, fr_all=None, owner=None) -> list:
        """``(x, value)`` of every search, from the refined rows (``owner`` = their batches)."""
        out = [(0.0, float(sg * math.inf)) for sg in self.sgn]
        if not getattr(self, "act", None):
            return out
        m, grp, rank, vloc, xloc, ref = self.cand
        seq = np.full((m, 4, 2), np.inf)
        at = np.full((m, 4, 2), np.inf)
        seq[grp, rank, 0], at[grp, rank, 0], at[grp, rank, 1] = vloc, xloc, xloc
        if ref.any():
            # the refined rows in the order prepare gave them
            act = np.asarray(self.act)
            mine = np.zeros(max(int(owner.max()), self.base + int(act.max())) + 1, dtype=bool)
            mine[self.base + act] = True
            sel = np.flatnonzero(mine[owner])
            fr = fr_all[sel]
            at[grp[ref], rank[ref], 1] = xr_all[sel]
            seq[grp[ref], rank[ref], 1] = np.where(np.isfinite(fr), fr, np.inf)
        # the best of (grid value, refined value) per candidate; equal extrema (to rounding,
        # e.g. repeated lobes) resolve to the smallest parameter
        seq, at = seq.reshape(m, 8), at.reshape(m, 8)
        best = np.min(seq, axis=1)
        with np.errstate(invalid="ignore"):
            tie = seq <= (best + _TIE * np.abs(best))[:, None]
        j = np.argmin(np.where(tie, at, np.inf), axis=1)
        r = np.arange(m)
        xs, vs = at[r, j], seq[r, j]
        for q, i in enumerate(self.act):
            if best[q] < math.inf:
                out[i] = (float(xs[q]), float(self.sgn[i] * vs[q]))
        return out


def _channel_solvers(nrows: int, mins=None, roots=None, *, min_rounds: int = 60, root_rounds: int = 80):
    """Generator: independent batches of :func:`_bracket_min` and :func:`_bracket_root` problems,
    stepped together (one request per round), on functions given as the rows of the
    (nrows, n) value arrays it is sent (it yields the points).

    ``mins`` = (rows (lo, f(lo), x, f(x), hi, f(hi), tol, batch), value row of each batch,
    sign of each batch): the minimised value is ``sign·f`` (NaN → +inf); ``roots`` = (a, f(a),
    b, f(b), batch, value row of each batch), refined to ``b − a < 1e-14 + 1e-15·|x|``.  Every
    problem takes exactly the trial points it takes in its batch's own solver (the ladder
    length of a round is its batch's, see :func:`_trials_multi`), so it ends with exactly that
    result.  Returns ``((x, fx), roots)`` (None where not asked)."""
    xtol, rtol = 1e-14, 1e-15
    if mins is not None:
        a, fa, x, fx, b, fb = (np.array(t, dtype=float) for t in mins[0][:6])
        tol = np.asarray(mins[0][6], dtype=float)
        mb = np.asarray(mins[0][7], dtype=np.intp)
        done = ~(b - a > tol)
        mrow, msg = np.asarray(mins[1], dtype=np.intp), np.asarray(mins[2], dtype=float)
        nbm = int(mb.max()) + 1 if mb.size else 0
    else:
        nbm, done = 0, np.zeros(0, dtype=bool)
    if roots is not None:
        ra, rfa, rb, rfb = (np.array(t, dtype=float) for t in roots[:4])
        rbt = np.asarray(roots[4], dtype=np.intp)
        rrow = np.asarray(roots[5], dtype=np.intp)
        nbr = int(rbt.max()) + 1 if rbt.size else 0
    else:
        nbr = 0
    mround = rround = 0
    empty = np.zeros(0, dtype=np.intp)
    while True:
        mact = np.flatnonzero(~done) if mins is not None and mround < min_rounds else empty
        ract = (np.flatnonzero(rb - ra >= xtol + rtol * np.maximum(np.abs(ra), np.abs(rb)))
                if roots is not None and rround < root_rounds else empty)
        nm, nr = mact.size, ract.size
        if nm + nr == 0:
            break
        parts = []
        if nm:
            A, FA, X, FX, B, FB = a[mact], fa[mact], x[mact], fx[mact], b[mact], fb[mact]
            d1, d2, f1, f2 = X - A, B - X, FA - FX, FB - FX
            with np.errstate(all="ignore"):
                u = X + 0.5 * (d2 * d2 * f1 - d1 * d1 * f2) / (d2 * f1 + d1 * f2)
            u = np.where(np.isfinite(u) & (d1 > 0) & (d2 > 0), u, X)
            parts.append((u, A, B, tol[mact], mb[mact], mrow[mb[mact]]))
        if nr:
            RA, RFA, RB, RFB = ra[ract], rfa[ract], rb[ract], rfb[ract]
            with np.errstate(all="ignore"):
                ur = RA - RFA * (RB - RA) / (RFB - RFA)
            ur = np.where(np.isfinite(ur), ur, 0.5 * (RA + RB))
            parts.append((ur, RA, RB, np.full(nr, xtol), nbm + rbt[ract], rrow[rbt[ract]]))
        cols = [np.concatenate(t) for t in zip(*parts)] if len(parts) > 1 else list(parts[0])
        pts = _trials_multi(*cols[:5], nbm + nbr)
        V = np.asarray((yield pts.ravel()), dtype=float).reshape(nrows, -1)
        Y = V[cols[5][:, None], np.arange(pts.size).reshape(pts.shape)]
        if nm:
            v = msg[mb[mact]][:, None] * Y[:nm]
            v = np.where(np.isnan(v), np.inf, v)
            P = np.concatenate([X[:, None], A[:, None], B[:, None], pts[:nm]], axis=1)
            F = np.concatenate([FX[:, None], FA[:, None], FB[:, None], v], axis=1)
            j = np.argmin(F, axis=1)  # ties keep the current best (column 0)
            a[mact], fa[mact], x[mact], fx[mact], b[mact], fb[mact] = _neighbours(P, F, j)
            with np.errstate(invalid="ignore"):
                flat = np.maximum(fa[mact], fb[mact]) - fx[mact] <= _FLAT * np.abs(fx[mact])
            done[mact] = ~(b[mact] - a[mact] > tol[mact]) | flat
            mround += 1
        if nr:
            P = np.concatenate([RA[:, None], pts[nm:], RB[:, None]], axis=1)
            F = np.concatenate([RFA[:, None], Y[nm:], RFB[:, None]], axis=1)
            o = np.argsort(P, axis=1, kind="stable")
            P, F = np.take_along_axis(P, o, 1), np.take_along_axis(F, o, 1)
            flip = (F[:, :-1] > 0) != (F[:, 1:] > 0)  # the ends differ, so some adjacent pair does
            j = np.argmax(flip, axis=1)
            r = np.arange(nr)
            ra[ract], rfa[ract], rb[ract], rfb[ract] = P[r, j], F[r, j], P[r, j + 1], F[r, j + 1]
            rround += 1
    out_r = None
    if roots is not None:
        with np.errstate(invalid="ignore"):
            take_a = ~(np.abs(rfb) < np.abs(rfa))
        out_r = np.where(take_a, ra, rb)
    return ((x, fx) if mins is not None else None), out_r


def _extrema_steps(specs, nrows: int | None = None):
    """Generator: many :func:`_extremum_steps` searches of different functions run as one.

    ``specs`` holds ``(edges, maximize[, step[, row]])`` per search; the generator yields the
    parameter values it needs and is sent a (rows, n) array of the functions at them, search
    i using row ``row`` (default i).
    Each search gives exactly the result of its own :func:`_extremum_steps`.  Returns the
    list of ``(x, value)``."""
    plan = _ExtremaPlan(specs)
    nrows = nrows or (int(plan.row.max()) + 1 if len(plan.row) else 0)
    if not plan.grids:
        return [(0.0, float(sg * math.inf)) for sg in plan.sgn]
    allx = np.concatenate(plan.grids) if len(plan.grids) > 1 else plan.grids[0]
    V = np.asarray((yield allx), dtype=float).reshape(nrows, -1)
    cols = plan.prepare(V)
    if cols is None:
        return plan.finish()
    (xr, fr), _ = yield from _channel_solvers(nrows, (cols, *plan.channels()))
    return plan.finish(xr, fr, cols[7])


def extremum(f: Callable[[np.ndarray], np.ndarray], edges, *, maximize: bool = False,
             step: float | None = None, keep: int = 4) -> tuple[float, float]:
    """Global extremum of a vectorised ``f`` between breakpoints ``edges``.

    Dense sampling of every breakpoint interval (one call of f), then a safeguarded
    parabolic refinement (:func:`_bracket_min`) of the best ``keep`` local candidates,
    all at once (one call of f per round).  Returns ``(x, value)``.
    """
    return _run(f, _extremum_steps(edges, maximize=maximize, step=step, keep=keep))


_GAUSS20 = np.polynomial.legendre.leggauss(20)


def _integrate_steps(edges, *, rtol: float = 1e-11, atol: float = 0.0):
    """Generator form of :func:`integrate`."""
    xg, wg = _GAUSS20
    edges = np.asarray(edges, dtype=float)
    todo = np.stack([edges[:-1], edges[1:]], axis=1)
    todo = todo[todo[:, 1] > todo[:, 0]]

    def nodes(iv):
        mid, half = (iv[:, 0] + iv[:, 1]) / 2, (iv[:, 1] - iv[:, 0]) / 2
        return mid[:, None] + half[:, None] * xg[None, :], half

    pts, half = nodes(todo)
    whole = half * ((yield pts.ravel()).reshape(pts.shape) @ wg)
    total, scale = 0.0, max(abs(whole.sum()), 1e-300)
    span = edges[-1] - edges[0]
    for _ in range(40):
        if len(todo) == 0:
            break
        mid = (todo[:, 0] + todo[:, 1]) / 2
        left, right = np.stack([todo[:, 0], mid], 1), np.stack([mid, todo[:, 1]], 1)
        pl, hl = nodes(left)
        pr, hr = nodes(right)
        v = yield np.concatenate([pl.ravel(), pr.ravel()])
        ql = hl * (v[:pl.size].reshape(pl.shape) @ wg)
        qr = hr * (v[pl.size:].reshape(pr.shape) @ wg)
        ok = np.abs(ql + qr - whole) <= (rtol * scale + atol) * (todo[:, 1] - todo[:, 0]) / span + 1e-300
        total += float((ql + qr)[ok].sum())
        todo = np.concatenate([left[~ok], right[~ok]])
        whole = np.concatenate([ql[~ok], qr[~ok]])
    return total + float(whole.sum())


def integrate(f: Callable[[np.ndarray], np.ndarray], edges, *, rtol: float = 1e-11, atol: float = 0.0) -> float:
    """∫ f between breakpoints by adaptive 20-point Gauss–Legendre (vectorised: one call of f per pass).
    Error target ``rtol·|∫f| + atol``: give ``atol`` where the integral may cancel to ~0."""
    return _run(f, _integrate_steps(edges, rtol=rtol, atol=atol))


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
            lo = extremum(lambda x: c.radius(x)[0], edges)
            hi = extremum(lambda x: c.radius(x)[0], edges, maximize=True)
            memo[profile] = Extremes(lo[1], lo[0], hi[1], hi[0])
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
