"""What a pipeline stage returns (:class:`Artifact`, :class:`CamShapes`) and the exporters' entry points,
importing the exporters (:mod:`camfab.cad.export`, with :mod:`camfab.discretize` and :mod:`camfab.offset`)
on first use: ``camfab check`` and the other commands that write no CAD file never load them
(docs/decisions.md "Lazy imports").
"""
from __future__ import annotations

from collections.abc import Iterable
from typing import TYPE_CHECKING, Any

from ..records import dataclass

if TYPE_CHECKING:
    from ..discretize import ArcDiscretisation
    from ..geom2d import ArcChain

__all__ = ["Artifact", "CamShapes", "build_artifacts", "cam_shapes", "validate_tol"]


@dataclass(frozen=True)
class Artifact:
    """One file to write: name, bytes, and what was measured about it."""

    filename: str
    data: bytes
    kind: str
    entities: int | None = None
    deviation_mm: float | None = None
    note: str = ""


@dataclass(frozen=True)
class CamShapes:
    """Arc chains of every profile (and pitch curve) of a cam, each with its measured deviation (mm)."""

    profiles: tuple[ArcDiscretisation, ...]
    pitch: tuple[ArcChain, ...]
    curves: tuple  # exact ParametricCurve of each profile
    tol: float
    #: the two flanks of one groove cam's plate (camfab.cad.groove), not one plate per profile
    groove: bool = False

    @property
    def profile_deviation(self) -> tuple[float, ...]:
        """The measured deviation of every profile's arc chain from its exact curve (mm)."""
        return tuple(float(p.max_deviation) for p in self.profiles)


def build_artifacts(spec, geometry, formats: Iterable[str], *, tol: float, **options: Any) -> list[Artifact]:
    """:func:`camfab.cad.export.build_artifacts`."""
    from . import export

    return export.build_artifacts(spec, geometry, formats, tol=tol, **options)


def cam_shapes(geometry, *, tol: float, with_pitch: bool = True) -> CamShapes:
    """:func:`camfab.cad.export.cam_shapes`."""
    from . import export

    return export.cam_shapes(geometry, tol=tol, with_pitch=with_pitch)


def validate_tol(tol) -> float:
    """:func:`camfab.discretize.validate_tol`."""
    from ..discretize import validate_tol as validate

    return validate(tol)
