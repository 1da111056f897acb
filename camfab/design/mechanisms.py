"""The registry of cam families: (cam kind, follower type, follower motion) → mechanism class.

Every family is a :class:`~camfab.design.mechanism.Mechanism` subclass in a module of its own, imported on first
use; this table is the one place that says which design-file combination builds which family.  Adding a family
is one module plus one entry here (and its module in ``_MODULE_OF``): the design file's validation
(:data:`MECHANISMS` tells which combinations exist and which ``[follower]`` keys each needs), the geometry, every
check and every exporter then work through the
mechanism's contacts.

>>> from camfab.design.kinds import CamKind, FollowerMotion, FollowerType
>>> MECHANISMS[(CamKind.DISC, FollowerType.ROLLER, FollowerMotion.OSCILLATING)].__name__
'OscillatingRoller'
"""
from __future__ import annotations

import importlib
from collections.abc import Iterator, Mapping
from typing import TYPE_CHECKING, Any

from ..errors import Problem, SpecError
from .kinds import CamKind, FollowerMotion, FollowerType
from .mechanism import Mechanism
from .profile import CamGeometry

if TYPE_CHECKING:
    from .conjugate import (
        ConjugateOscillatingFlat,
        ConjugateOscillatingRoller,
        ConjugateTranslatingFlat,
        ConjugateTranslatingRoller,
        DesmodromicGeometry,
        FormClosed,
    )
    from .curved import OscillatingCurved, TranslatingCurved
    from .faces import OscillatingFlat, TranslatingFlat
    from .groove import GrooveOscillatingRoller, GrooveTranslatingRoller
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

#: the module of every family class named here; a family's module is imported when it is first asked for, so
#: ``camfab check`` of a roller cam does not import the conjugate, cylindrical, … families (docs/decisions.md,
#: "Start-up and export time")
_MODULE_OF = {
    **dict.fromkeys(("ConjugateOscillatingFlat", "ConjugateOscillatingRoller", "ConjugateTranslatingFlat",
                     "ConjugateTranslatingRoller", "DesmodromicGeometry", "FormClosed"), "conjugate"),
    **dict.fromkeys(("OscillatingCurved", "TranslatingCurved"), "curved"),
    **dict.fromkeys(("OscillatingFlat", "TranslatingFlat"), "faces"),
    **dict.fromkeys(("GrooveOscillatingRoller", "GrooveTranslatingRoller"), "groove"),
    **dict.fromkeys(("OscillatingRoller", "TranslatingRoller"), "rollers"),
    **dict.fromkeys(("ConstantDiameterCam", "ConstantWidthCam"), "symmetric"),
    "TranslatingCamRoller": "wedge",
}


def _family(name: str) -> type[Mechanism]:
    return getattr(importlib.import_module(f"{__package__}.{_MODULE_OF[name]}"), name)


def __getattr__(name: str) -> Any:
    """The family classes, imported from their modules on first use."""
    if name in _MODULE_OF:
        return _family(name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


class _Registry(Mapping):
    """(cam kind, follower type, follower motion) → family class, each class imported when first looked up."""

    def __init__(self, names: dict[tuple[CamKind, FollowerType, FollowerMotion], str]):
        self._names = names

    def __getitem__(self, key: tuple[CamKind, FollowerType, FollowerMotion]) -> type[Mechanism]:
        name = self._names[key]
        if name.startswith("cylindrical."):
            from .cylindrical import FAMILIES

            return FAMILIES[key]
        return _family(name)

    def __iter__(self) -> Iterator[tuple[CamKind, FollowerType, FollowerMotion]]:
        return iter(self._names)

    def __len__(self) -> int:
        return len(self._names)


_D, _CJ, _CW, _CD, _TC = (CamKind.DISC, CamKind.CONJUGATE, CamKind.CONSTANT_WIDTH, CamKind.CONSTANT_DIAMETER,
                          CamKind.TRANSLATING)
_RO, _FL, _KN, _CU = FollowerType.ROLLER, FollowerType.FLAT, FollowerType.KNIFE, FollowerType.CURVED
_T, _O = FollowerMotion.TRANSLATING, FollowerMotion.OSCILLATING
_CY = CamKind.CYLINDRICAL

#: every cam family by (cam kind, follower type, follower motion); a knife edge is a roller of radius 0
MECHANISMS: Mapping[tuple[CamKind, FollowerType, FollowerMotion], type[Mechanism]] = _Registry({
    (_D, _RO, _T): "TranslatingRoller",
    (_D, _KN, _T): "TranslatingRoller",
    (_D, _RO, _O): "OscillatingRoller",
    (_D, _KN, _O): "OscillatingRoller",
    (_D, _FL, _T): "TranslatingFlat",
    (_D, _FL, _O): "OscillatingFlat",
    (_D, _CU, _T): "TranslatingCurved",
    (_D, _CU, _O): "OscillatingCurved",
    (_CJ, _RO, _T): "ConjugateTranslatingRoller",
    (_CJ, _FL, _T): "ConjugateTranslatingFlat",
    (_CJ, _RO, _O): "ConjugateOscillatingRoller",
    (_CJ, _FL, _O): "ConjugateOscillatingFlat",
    (_CW, _FL, _T): "ConstantWidthCam",
    (_CD, _RO, _T): "ConstantDiameterCam",
    (_TC, _RO, _T): "TranslatingCamRoller",
    (CamKind.GROOVE, _RO, _T): "GrooveTranslatingRoller",
    (CamKind.GROOVE, _RO, _O): "GrooveOscillatingRoller",
    (_CY, _RO, _T): "cylindrical.translating",
    (_CY, _RO, _O): "cylindrical.oscillating",
})


def mechanism_class(cam_kind: str, follower: str, motion: str) -> type[Mechanism] | None:
    """The family registered for a design-file combination, or None."""
    try:
        key = (CamKind(cam_kind), FollowerType(follower), FollowerMotion(motion))
    except ValueError:
        return None
    return MECHANISMS.get(key)


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
