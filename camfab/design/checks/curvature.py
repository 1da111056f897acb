"""The curvature rule: undercut, cusp and concave stretches tighter than the cutter.

* ``UNDERCUT`` (error) — rollers and curved faces: the pitch curve (the roller centre's path, the
  face's centre of curvature's) is convex with radius 0 < ρ_p < R_r (the roller or face cannot
  follow it: judged on the pitch curve, whose radius is the profile's plus R_r);
  flat faces: ρ < 0 (the profile crosses itself between two cusps).
* ``CUSP`` (error) — the limit case: ρ_p = R_r (roller) or ρ = 0 (flat face) within
  :data:`~.common.CUSP_TOL_MM`: the profile has a sharp point.
* ``CONCAVE_RADIUS_BELOW_ROLLER`` (warning) — a concave stretch whose radius is smaller than the
  roller or the cutter (the larger).  On a true roller envelope the concave radius is
  |ρ_p| + R_r > R_r, so it fires only for a cutter larger than the roller: it names the stretches
  such a cutter cannot finish, and the largest tool that fits.
"""
from __future__ import annotations

import numpy as np

from ...results import Curvature, Finding, IssueCode, Severity
from ..kinds import ContactKind
from ..profile import Contact
from .common import CUSP_TOL_MM, ContactSample, Limits, RuleResult, Words, span_text, words

__all__ = ["curvature_rule"]


def curvature_rule(contact: Contact, limits: Limits, sample: ContactSample) -> RuleResult:
    """Undercut, cusp and concave-radius findings, and the radius-of-curvature summary."""
    if contact.kind is ContactKind.ROLLER:
        return _roller(contact, limits, sample)
    return _face(sample)


def _cusp(sample: ContactSample, x: float, value: float, limit: float, why: str, size: str = "roller") -> Finding:
    a = sample.user(x)
    return Finding(IssueCode.CUSP, Severity.ERROR, a, a, value, limit,
                   f"cusp at {a:.6g}{sample.unit}: {why}, so the profile has a sharp point with very high contact "
                   f"stress. Enlarge the base circle (or use a smaller {size})")


def _roller(contact: Contact, limits: Limits, sample: ContactSample) -> RuleResult:
    """Rollers (knife edges: radius 0) and curved faces: judged on the pitch-curve curvature κ_p (a curved
    face's pitch curve is the path of its centre of curvature)."""
    rr, say = contact.roller_radius, words(contact)
    lim = max(rr, limits.tool_radius_mm or 0.0)
    (xb, kmin), (xa, kmax) = sample.extremes("curvature_pitch")
    convex, concave = kmax > 0, kmin < 0
    summary = _roller_summary(sample, rr, (xb, kmin), (xa, kmax))
    undercut = rr > 0 and convex and rr - 1.0 / kmax > CUSP_TOL_MM
    tight = lim > 0 and concave and 1.0 / -kmin + rr < lim
    wanted = ([lambda s: rr * s.curvature_pitch - 1.0] if undercut else []) + (
        [lambda s: np.where(s.curvature_pitch < 0, -lim * s.curvature - 1.0, -1.0)] if tight else [])
    found = sample.ranges(*wanted) if wanted else []
    out: list[Finding] = []
    if undercut:
        out += _undercuts(sample, found.pop(0), rr, say)
    elif rr > 0 and convex and rr - 1.0 / kmax >= -CUSP_TOL_MM:
        why = ("the radius of the path of the face's centre of curvature equals the face radius" if contact.curved_face
               else "the pitch-curve radius equals the roller radius")
        out.append(_cusp(sample, xa, 1.0 / kmax, rr, why, say.size))
    if tight:
        out += _too_tight(sample, found.pop(0), lim, 1.0 / -kmin + rr)
    return RuleResult(tuple(out), {"curvature": summary})


def _roller_summary(sample: ContactSample, rr: float, lowest: tuple[float, float],
                    highest: tuple[float, float]) -> Curvature:
    """The curvature summary of a roller or curved face from the extremes (x, κ_p) of the pitch curvature."""
    (xb, kmin), (xa, kmax) = lowest, highest
    convex, concave = kmax > 0, kmin < 0
    return Curvature(1.0 / kmax - rr if convex else None, sample.user(xa) if convex else None,
                     1.0 / -kmin + rr if concave else None, sample.user(xb) if concave else None,
                     1.0 / kmax if convex else None, None)


def _too_tight(sample: ContactSample, ranges, lim: float, fits: float) -> list[Finding]:
    """CONCAVE_RADIUS_BELOW_ROLLER from the ranges where a concave stretch is tighter than the cutter or roller
    radius ``lim``; ``fits`` is the smallest concave radius (the largest tool radius that fits)."""
    return [Finding(IssueCode.CONCAVE_RADIUS_BELOW_ROLLER, Severity.WARNING, sample.user(lo), sample.user(hi),
                    lim / (1.0 + gw), lim,
                    f"concave stretch {span_text(sample, lo, hi)} with radius down to {fits:.6g} mm, tighter than "
                    f"the {lim:.6g} mm cutter; the largest tool radius that fits is {fits:.6g} mm")
            for lo, hi, _, gw in ranges]


def _undercuts(sample: ContactSample, ranges, rr: float, say: Words) -> list[Finding]:
    """UNDERCUT from the ranges where R_r·κ_p − 1 > 0 (the worst value gives the smallest ρ_p).  As for a
    roller, the advice for a curved face is a smaller face radius or a larger base circle (a larger face
    radius, towards the flat face, sharpens the profile: tested)."""
    out = []
    for lo, hi, xw, gw in ranges:
        rp = rr / (1.0 + gw)
        out.append(Finding(IssueCode.UNDERCUT, Severity.ERROR, sample.user(lo), sample.user(hi), rp, rr,
                           f"undercut {span_text(sample, lo, hi)}: the pitch curve is convex with radius down to "
                           f"{rp:.6g} mm (at {sample.user(xw):.6g}{sample.unit}), smaller than the {say.size} "
                           f"({rr:.6g} mm); the {say.surface} cannot follow the law there. Enlarge the base circle or "
                           f"use a smaller {say.size}"))
    return out


def _face(sample: ContactSample) -> RuleResult:
    """Flat faces: judged on the profile radius ρ."""
    (xa, rmin), (_, rmax) = sample.extremes("rho")
    summary = Curvature(rmin, sample.user(xa), None, None, None, rmax)
    out: list[Finding] = []
    if rmin < -CUSP_TOL_MM:
        for lo, hi, xw, gw in sample.ranges(lambda s: -s.rho)[0]:
            out.append(Finding(IssueCode.UNDERCUT, Severity.ERROR, sample.user(lo), sample.user(hi), -gw, 0.0,
                               f"undercut {span_text(sample, lo, hi)}: the radius of curvature is negative (down to "
                               f"{-gw:.6g} mm at {sample.user(xw):.6g}{sample.unit}); the profile crosses itself "
                               "between two cusps and the face cannot follow the law. Enlarge the base circle"))
    elif rmin <= CUSP_TOL_MM:
        out.append(_cusp(sample, xa, rmin, 0.0, "the radius of curvature reaches 0"))
    return RuleResult(tuple(out), {"curvature": summary})
