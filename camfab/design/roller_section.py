"""The exact section of a cylindrical cam's roller by a cylinder of radius r, and the groove flank it envelopes.

Section (``docs/decisions.md``, "Cylindrical cams: the exact roller section")
-----------------------------------------------------------------------------
The roller's axis is parallel to the radial line of the follower at cam angle 0 (a translating follower's
passes through the cam axis; an oscillating follower's lies the arm's shift ``e`` aside, along the developed
x).  In the roller's plane (X̂ along the developed x, ẑ along the cam axis) a point of the enlarged roller (its
radius plus half the backlash, ``a = c·ρ + h``, ρ the distance along its axis from the point nearest the cam
axis) at the angle t is ``(e + a·cos t, a·sin t)``: ``c = 0, h = R_r + b/2`` for a cylindrical roller,
``c = R_r/R, h = b/2`` for a conical one (apex on the cam axis).  It lies on the cylinder r at the polar offset
β from the radial line, ``r·sin β = e + a·cos t`` with ``ρ = r·cos β``, so

    β(t, e) = atan(c·cos t) + asin((e + h·cos t) / (r·√(1 + c²cos²t))),   v(t, e) = (c·r·cos β + h)·sin t,

and its developed point is ``B(θ) + σ(t, e)`` with ``B = (r·θ, z(θ))`` and ``σ = (r·β, v)``: a circle of radius
h stretched along x (by ``r·asin(h/r) − h ≈ h³/(6r²)`` at its sides) for a cylindrical roller.

Envelope
--------
The flank on the cylinder r is the envelope of the sections over the cam angle (the swept region's boundary
on the cylinder is the boundary of the union of its sections, and the development is an isometry): the point
of parameter t* where ``g = σ_t × P_θ = 0`` with ``P_θ = B′ + σ_e·e′`` the velocity of the section's point.
t* is found by Newton's method from the circle's solution (the roller's outward normal along ``±J(P̂_θ)``).
With ``t*′ = −g_θ/g_t`` the flank's derivative is ``F′ = P_θ + σ_t·t*′`` and its curvature ``κ = σ·ψ′/λ``
(ψ the direction of σ_t, λ = F′ along the flank's tangent, σ the flank's sign), as the circular offset's
``κ_p/(1 − R_r·κ_p)``.  σ_t and σ_e come from complex steps (exact), the second derivatives from central
differences of those (relative error ~1e-10).  The pressure angle is the angle, in the roller's plane, from
the follower's direction of increasing lift to the roller's normal at the contact, ``(cos t*, sin t*)``.
"""
from __future__ import annotations

import numpy as np

from ..errors import GeometryError
from ..geom2d import J, cross, dot, pair
from ..records import dataclass

__all__ = ["RollerSection", "Envelope", "envelope"]

_CSTEP = 1e-30
_DT = 1e-5


@dataclass(frozen=True, slots=True)
class RollerSection:
    """The (enlarged) roller cut by the cylinder of radius ``r``: ``c`` the cone's slope (0 for a cylindrical
    roller), ``h`` its radius at the axis's foot (module notes)."""

    r: float
    c: float
    h: float

    def sigma(self, t, e):
        """Developed offset ``(r·β, v)`` of the section's point t from ``(r·θ, z)``; complex-safe, (n, 2)."""
        r, c, h = self.r, self.c, self.h
        ct = np.cos(t)
        beta = np.arctan(c * ct) + np.arcsin((e + h * ct) / (r * np.sqrt(1.0 + (c * ct) ** 2)))
        return pair(r * beta, (c * r * np.cos(beta) + h) * np.sin(t))

    def d_t(self, t, e):
        """∂σ/∂t (complex step)."""
        return self.sigma(t + 1j * _CSTEP, e).imag / _CSTEP

    def d_e(self, t, e):
        """∂σ/∂e (complex step)."""
        return self.sigma(t, e + 1j * _CSTEP).imag / _CSTEP

    def second(self, t, e) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """σ_tt, σ_te, σ_ee by central differences of the complex-step derivatives."""
        de = _DT * max(self.r, 1.0)
        s_tt = (self.d_t(t + _DT, e) - self.d_t(t - _DT, e)) / (2 * _DT)
        s_te = (self.d_e(t + _DT, e) - self.d_e(t - _DT, e)) / (2 * _DT)
        s_ee = (self.d_e(t, e + de) - self.d_e(t, e - de)) / (2 * de)
        return s_tt, s_te, s_ee

    def derivatives(self, t, e) -> tuple[np.ndarray, ...]:
        """σ_t, σ_e, σ_tt, σ_te, σ_ee, each (n, 2): in closed form for a cylindrical roller (c = 0: x = r·asin q,
        q = (e + h·cos t)/r, z = h·sin t), else :meth:`d_t`, :meth:`d_e` and :meth:`second`."""
        if self.c != 0.0:
            return (self.d_t(t, e), self.d_e(t, e), *self.second(t, e))
        r, h = self.r, self.h
        ct, st = np.cos(t), np.sin(t)
        q = (e + h * ct) / r
        k = np.sqrt(1.0 - q * q)
        g = q / k**3
        qt = -h * st / r
        zero = 0.0 * q
        return (pair(r * qt / k, h * ct), pair(1.0 / k, zero),
                pair(-h * ct / k + r * qt * qt * g, -h * st), pair(qt * g, zero),
                pair(g / r, zero))


@dataclass(frozen=True, slots=True)
class Envelope:
    """One flank on the developed cylinder at n cam angles: the contact parameter t*, the point, its
    derivative per radian, the unit outward normal (from the cam into the groove) and unit tangent, the
    signed curvature and the roller's normal in its plane, each (n,) or (n, 2)."""

    t: np.ndarray
    point: np.ndarray
    point_d1: np.ndarray
    normal: np.ndarray
    tangent: np.ndarray
    curvature: np.ndarray
    roller_normal: np.ndarray


def _solve(sec: RollerSection, sense: int, Bp: np.ndarray, e: np.ndarray, e1: np.ndarray) -> np.ndarray:
    """t* of the flank ``sense`` (+1 the +z side): Newton on g = σ_t × P_θ from the circle's root."""
    P = Bp + sec.d_e(0.0 * e, e) * e1[:, None]
    u = P / np.hypot(P[:, 0], P[:, 1])[:, None]
    t = np.arctan2(sense * u[:, 0], -sense * u[:, 1])
    for _ in range(40):
        s_t, s_e, s_tt, s_te, _ = sec.derivatives(t, e)
        P = Bp + s_e * e1[:, None]
        g = cross(s_t, P)
        gt = cross(s_tt, P) + cross(s_t, s_te * e1[:, None])
        step = g / gt
        t = t - step
        if np.all(np.abs(step) < 1e-13):
            return t
    raise GeometryError("the groove flank's contact on the roller section did not converge (Newton); the roller is "
                        "too large for the cylinder radius. Use a smaller roller or a larger [cylinder] radius_mm")


def envelope(sec: RollerSection, sense: int, B, Bp, Bpp, e, e1, e2) -> Envelope:
    """The flank ``sense`` enveloped by the section moving with ``B(θ) = (r·θ, z)`` (B, B′, B″ (n, 2)) and the
    arm's shift e, e′, e″ (n,) (module notes)."""
    e, e1, e2 = (np.asarray(a, dtype=float) for a in (e, e1, e2))
    t = _solve(sec, sense, Bp, e, e1)
    s_t, s_e, s_tt, s_te, s_ee = sec.derivatives(t, e)
    E1 = e1[:, None]
    P = Bp + s_e * E1
    Ptt = Bpp + s_ee * E1**2 + s_e * e2[:, None]
    gt = cross(s_tt, P) + cross(s_t, s_te * E1)
    gth = cross(s_te * E1, P) + cross(s_t, Ptt)
    t1 = -gth / gt
    d1 = P + s_t * t1[:, None]
    speed = np.hypot(s_t[:, 0], s_t[:, 1])
    normal = J(s_t) / speed[:, None]
    tangent = sense * J(normal)
    lam = dot(d1, tangent)
    psi1 = cross(s_t, s_tt * t1[:, None] + s_te * E1) / speed**2
    with np.errstate(divide="ignore", invalid="ignore"):
        k = sense * psi1 / lam
    point = B + sec.sigma(t, e)
    return Envelope(t, point, d1, normal, tangent, k, pair(np.cos(t), np.sin(t)))
