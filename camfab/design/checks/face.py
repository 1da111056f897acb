"""The face rule: ``FACE_LENGTH`` (info) — how long a follower face must be to keep the contact on it.

A translating face (flat, or a mushroom's curved face) is measured either side of the stem axis (signed
contact position, positive to the right); an oscillating face from its vertex (the foot of the pivot's
perpendicular; along the arc for a finger follower's curved face)."""
from __future__ import annotations

from ...results import FaceLength, Finding, IssueCode, Severity
from ..profile import Contact
from .common import ContactSample, Limits, RuleResult

__all__ = ["face_rule"]


def face_rule(contact: Contact, limits: Limits, sample: ContactSample) -> RuleResult:
    """The face length needed (margin included) and where the contact runs along the face."""
    if not contact.has_face:
        return RuleResult()
    margin = limits.face_margin_mm
    (xa, pmin), (xb, pmax) = sample.extremes("face_position")
    a, b = sample.user(xa), sample.user(xb)
    out: tuple[Finding, ...]
    if not contact.oscillating:  # either side of the stem
        left, right = max(-pmin, 0.0) + margin, max(pmax, 0.0) + margin
        out = (Finding(IssueCode.FACE_LENGTH, Severity.INFO, a, a, left, None,
                       f"the face must reach {left:.6g} mm to the left of the stem axis (contact furthest left at "
                       f"{a:.6g}°; margin {margin:g} mm included)"),
               Finding(IssueCode.FACE_LENGTH, Severity.INFO, b, b, right, None,
                       f"the face must reach {right:.6g} mm to the right of the stem axis (contact furthest right at "
                       f"{b:.6g}°; margin {margin:g} mm included)"))
        return RuleResult(out, {"face_length": FaceLength(left, right, pmin, pmax)})
    along = ", measured along its arc" if contact.curved_face else ""
    out = (Finding(IssueCode.FACE_LENGTH, Severity.INFO, b, b, pmax + margin, None,
                   f"the face must be at least {pmax + margin:.6g} mm long from the vertex{along} (contact between "
                   f"{pmin:.6g} mm at {a:.6g}° and {pmax:.6g} mm at {b:.6g}°; margin {margin:g} mm included)"
                   + ("; the contact passes behind the vertex" if pmin < 0 else "")),)
    return RuleResult(out, {"face_length": FaceLength(None, None, pmin, pmax)})
