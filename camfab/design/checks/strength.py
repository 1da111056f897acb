"""The contact-stress rule: Hertz stress along the cycle against the allowable contact stress
(``CONTACT_STRESS_ABOVE_LIMIT``, error), the roller's rating life and the cam track's life estimate
(:mod:`camfab.design.strength`).

It needs the contact force, so it runs only when the caller passes the strength inputs
(:attr:`~.common.Limits.strength`: ``camfab check`` does for a design with ``[dynamics]`` or
``[strength]``).  A knife edge, or a design without ``[dynamics]``, gets a ``contact_stress`` summary
whose notes say why nothing was computed, and no finding.
"""
from __future__ import annotations

from ...errors import InputError
from ..profile import CamGeometry
from .common import ContactSample, Limits, RuleResult

__all__ = ["contact_stress_rule"]


def contact_stress_rule(geometry: CamGeometry, limits: Limits, samples: list[ContactSample]) -> RuleResult:
    """Contact-stress findings and the ``contact_stress`` summary (nothing without strength inputs)."""
    inp = limits.strength
    if inp is None:
        return RuleResult()
    from ..strength import ContactStressSummary, analyse_strength  # imported by the designs that ask for it

    try:
        summary, findings = analyse_strength(geometry, inp)
    except InputError as exc:  # no contact force, or a knife edge: stated, not checked
        summary = ContactStressSummary(None, None, inp.allowable_mpa, None, inp.cam.name, inp.follower.name,
                                       inp.width_mm, notes=(*inp.notes, str(exc)))
        findings = ()
    return RuleResult(findings, {"contact_stress": summary})
