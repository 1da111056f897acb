"""The registry of cam families: (cam kind, follower type, follower motion) → mechanism class.

Every family is a :class:`~camfab.design.mechanism.Mechanism` subclass in a module of its own; this table is
the one place that says which design-file combination builds which family.  Adding a family is one module plus
one entry here: the design file's validation (:data:`MECHANISMS` tells which combinations exist and which
``[follower]`` keys each needs), the geometry, every check and every exporter then work through the
mechanism's contacts.

>>> from camfab.design.kinds import CamKind, FollowerMotion, FollowerType
>>> MECHANISMS[(CamKind.DISC, FollowerType.ROLLER, FollowerMotion.OSCILLATING)].__name__
'OscillatingRoller'
"""
from __future__ import annotations

from typing import Any

from ..errors import Problem, SpecError
from .conjugate import (
    ConjugateOscillatingFlat,
    ConjugateOscillatingRoller,
    ConjugateTranslatingFlat,
    ConjugateTranslatingRoller,
    DesmodromicGeometry,
    FormClosed,
)
from .curved import OscillatingCurved, TranslatingCurved
from .cylindrical import FAMILIES as CYLINDRICAL_FAMILIES
from .faces import OscillatingFlat, TranslatingFlat
from .groove import GrooveOscillatingRoller, GrooveTranslatingRoller
from .kinds import CamKind, FollowerMotion, FollowerType
from .mechanism import Mechanism
from .profile import CamGeometry
from .rollers import OscillatingRoller, TranslatingRoller
from .symmetric import ConstantDiameterCam, ConstantWidthCam
from .wedge import TranslatingCamRoller

__all__ = [
    "MECHANISMS",
    "mechanism_class",
    "mechanism_from_spec",
    "geometry_from_spec",
    "Mechanism",
    "FormClosed",
    "TranslatingRoller",
    "OscillatingRoller",
    "TranslatingFlat",
    "OscillatingFlat",
    "TranslatingCurved",
    "OscillatingCurved",
    "TranslatingCamRoller",
    "ConjugateTranslatingFlat",
    "ConjugateTranslatingRoller",
    "ConjugateOscillatingFlat",
    "ConjugateOscillatingRoller",
    "ConstantWidthCam",
    "ConstantDiameterCam",
    "DesmodromicGeometry",
    "GrooveTranslatingRoller",
    "GrooveOscillatingRoller",
]

_D, _CJ, _CW, _CD, _TC = (CamKind.DISC, CamKind.CONJUGATE, CamKind.CONSTANT_WIDTH, CamKind.CONSTANT_DIAMETER,
                          CamKind.TRANSLATING)
_RO, _FL, _KN, _CU = FollowerType.ROLLER, FollowerType.FLAT, FollowerType.KNIFE, FollowerType.CURVED
_T, _O = FollowerMotion.TRANSLATING, FollowerMotion.OSCILLATING

#: every cam family by (cam kind, follower type, follower motion); a knife edge is a roller of radius 0
MECHANISMS: dict[tuple[CamKind, FollowerType, FollowerMotion], type[Mechanism]] = {
    (_D, _RO, _T): TranslatingRoller,
    (_D, _KN, _T): TranslatingRoller,
    (_D, _RO, _O): OscillatingRoller,
    (_D, _KN, _O): OscillatingRoller,
    (_D, _FL, _T): TranslatingFlat,
    (_D, _FL, _O): OscillatingFlat,
    (_D, _CU, _T): TranslatingCurved,
    (_D, _CU, _O): OscillatingCurved,
    (_CJ, _RO, _T): ConjugateTranslatingRoller,
    (_CJ, _FL, _T): ConjugateTranslatingFlat,
    (_CJ, _RO, _O): ConjugateOscillatingRoller,
    (_CJ, _FL, _O): ConjugateOscillatingFlat,
    (_CW, _FL, _T): ConstantWidthCam,
    (_CD, _RO, _T): ConstantDiameterCam,
    (_TC, _RO, _T): TranslatingCamRoller,
    (CamKind.GROOVE, _RO, _T): GrooveTranslatingRoller,
    (CamKind.GROOVE, _RO, _O): GrooveOscillatingRoller,
    **CYLINDRICAL_FAMILIES,
}


def mechanism_class(cam_kind: str, follower: str, motion: str) -> type[Mechanism] | None:
    """The family registered for a design-file combination, or None."""
    try:
        return MECHANISMS.get((CamKind(cam_kind), FollowerType(follower), FollowerMotion(motion)))
    except ValueError:
        return None


def mechanism_from_spec(spec: Any) -> Mechanism:
    """The mechanism described by a validated design's ``[cam]`` and ``[follower]``.

    Raises
    ------
    SpecError
        The combination of cam kind, follower type and motion has no family.
    """
    cls = mechanism_class(spec.cam.kind, spec.follower.type, spec.follower.motion)
    if cls is None:
        raise SpecError(Problem("follower.type", spec.follower.type,
                                f"no {spec.cam.kind} cam drives a {spec.follower.motion} {spec.follower.type} follower",
                                "use one of: " + ", ".join(sorted({f"{k.value} cam + {m.value} {t.value}"
                                                                   for k, t, m in MECHANISMS}))), spec.source)
    return cls.from_spec(spec)


def geometry_from_spec(spec: Any) -> CamGeometry:
    """The exact :class:`CamGeometry` of a validated design; every geometry problem raised as one
    :class:`SpecError` naming the design file."""
    mech = mechanism_from_spec(spec)
    try:
        return mech.geometry(spec.program(), bore_mm=spec.manufacturing.bore_mm or None)
    except SpecError as exc:
        raise SpecError(exc.problems, spec.source) from None
