"""The pressure-angle rule: ``PRESSURE_ANGLE_EXCEEDED`` (error) where |δ| is above the limit
(default 30° for translating followers and translating cams, 35° for oscillating followers; a flat
face has no pressure angle to check)."""
from __future__ import annotations

import math

from ...results import Finding, IssueCode, PressureAngle, Severity
from ..kinds import ContactKind
from ..profile import Contact
from .common import DEFAULT_PRESSURE_LIMIT_DEG, ContactSample, Limits, RuleResult, span_text, words

__all__ = ["pressure_angle_rule"]

#: a pressure angle within this many radians of its limit is not above it
_PA_TOL_RAD = 1e-10


def pressure_angle_rule(contact: Contact, limits: Limits, sample: ContactSample) -> RuleResult:
    """Pressure-angle extremes and the ranges beyond ± the limit (rollers, knife edges and curved faces)."""
    if contact.kind is not ContactKind.ROLLER:
        return RuleResult()
    lim_deg = limits.pressure_angle_deg
    if lim_deg is None:
        lim_deg = DEFAULT_PRESSURE_LIMIT_DEG["oscillating" if contact.oscillating else "translating"]
    lim = math.radians(lim_deg)
    (xb, dmin), (xa, dmax) = sample.extremes("pressure_angle")
    summary = PressureAngle(math.degrees(dmin), sample.user(xb), math.degrees(dmax), sample.user(xa), lim_deg)
    over = [sign for sign, worst in ((1.0, dmax), (-1.0, dmin)) if sign * worst - lim > _PA_TOL_RAD]
    found = sample.ranges(*[lambda s, sign=sign: sign * s.pressure_angle - lim for sign in over]) if over else []
    out = []
    for sign, ranges in zip(over, found, strict=True):
        for lo, hi, xw, gw in ranges:
            val = sign * math.degrees(gw + lim)
            out.append(Finding(IssueCode.PRESSURE_ANGLE_EXCEEDED, Severity.ERROR, sample.user(lo), sample.user(hi),
                               val, sign * lim_deg,
                               f"pressure angle {val:.4g}° (at {sample.user(xw):.6g}{sample.unit}) exceeds "
                               f"±{lim_deg:.4g}° {span_text(sample, lo, hi)}: high side load, risk of jamming. "
                               + _remedy(contact)))
    return RuleResult(tuple(out), {"pressure_angle": summary})


def _remedy(contact: Contact) -> str:
    """What lowers the pressure angle: for a roller or a mushroom (whose face centre is a roller's centre) a
    larger base circle, offset, law or radius; a finger follower's depends on where its pivot and face sit."""
    if contact.curved_face and contact.oscillating:
        return "Enlarge the base circle, move the pivot, or change the face offset, the face radius or the law"
    return f"Enlarge the base circle, change the offset or the law, or use a larger {words(contact).size}"
