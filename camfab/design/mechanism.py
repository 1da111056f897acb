"""The mechanism model: what every cam family provides, and the validation helpers they share.

A **mechanism** is one cam family — a cam kind driving a follower of some type and motion — as a frozen
dataclass whose fields are its dimensions in mm and degrees (named as the design file's keys).  Each family
declares where it sits in the registry (:attr:`Mechanism.cam_kind`, :attr:`~Mechanism.follower`,
:attr:`~Mechanism.motion`), which ``[follower]`` keys it reads (:attr:`~Mechanism.required` and
:attr:`~Mechanism.optional`), and implements

* :meth:`~Mechanism.from_spec` — its dimensions from a validated design;
* :meth:`~Mechanism.validate` — problems of the dimensions alone (every problem, each naming its field);
* :meth:`~Mechanism.validate_motion` — problems that need the motion too (an arm that swings past the line of
  centres, a second cam that cannot be made …);
* :meth:`~Mechanism.contacts` — the exact profile(s): one :class:`~camfab.design.profile.Contact` per cam
  surface the followers envelope.

:meth:`Mechanism.geometry` validates and builds the :class:`~camfab.design.profile.CamGeometry` that every
check and exporter reads.  The registry of families is :mod:`camfab.design.mechanisms`: a new family is one
module with its mechanism (and contact, when no existing contact fits) plus one entry there.

Frame conventions shared by every family: cam centre at the origin; at cam angle 0 the follower lies along
+Y (above the cam); ``rotation = "cw"`` (default) or ``"ccw"`` is the sense in which the cam turns in that
view, the follower staying in place (so a ``ccw`` cam is the mirror image of the ``cw`` cam of the mirrored
mechanism).
"""
from __future__ import annotations

import math
from typing import Any, ClassVar

import numpy as np

from ..errors import Problem, SpecError
from ..records import dataclass, fields
from .kinds import CamKind, FollowerMotion, FollowerType, Rotation
from .profile import CamGeometry, Contact, MotionLike

__all__ = ["Mechanism", "lift_range", "finite_fields", "require_positive", "require_non_negative",
           "require_rotation"]


def lift_range(program: MotionLike, order: int = 0) -> tuple[float, float]:
    """min and max of the ``order``-th derivative of S over the cycle (exact peaks when the program has
    them, else a dense sample)."""
    peaks = getattr(program, "peaks", None)
    if peaks is not None:
        pk = peaks("exact")[order]
        return pk.min, pk.max
    v = program.evaluate(np.linspace(0.0, program.period, 20001), (order,))[0]
    return float(v.min()), float(v.max())


def finite_fields(obj: Any, problems: list[Problem], suffixes: tuple[str, ...] = ("_mm",)) -> bool:
    """Append a problem for every field named ``*_mm`` (and the other ``suffixes``, e.g. ``_deg``) that is
    given but not a finite number; True if none."""
    ok = True
    for f in fields(obj):
        v = getattr(obj, f.name)
        if not f.name.endswith(suffixes) or v is None:
            continue
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
            unit, what = ("mm", "a length") if f.name.endswith("_mm") else ("degrees", "an angle")
            problems.append(Problem(f"follower.{f.name}", v, f"must be a finite number ({unit})",
                                    f"give {f.name} as {what} in {unit}"))
            ok = False
    return ok


def require_positive(problems: list[Problem], name: str, value: float, what: str = "a length > 0 mm") -> None:
    """Append a problem when ``value`` is not > 0."""
    if value <= 0:
        problems.append(Problem(f"follower.{name}", value, f"must be {what}", f"give a positive {name}"))


def require_non_negative(problems: list[Problem], name: str, value: float) -> None:
    """Append a problem when ``value`` is negative."""
    if value < 0:
        problems.append(Problem(f"follower.{name}", value, "must be >= 0 mm", f"give {name} >= 0"))


def require_rotation(problems: list[Problem], rotation: str) -> None:
    """Append a problem when ``rotation`` is neither 'cw' nor 'ccw'."""
    if rotation not in tuple(Rotation):
        problems.append(Problem("cam.rotation", rotation, "rotation must be 'cw' or 'ccw'",
                                'use rotation = "cw" (default) or "ccw"'))


@dataclass(frozen=True)
class Mechanism:
    """Base of every cam family (see the module notes).

    Subclasses are frozen dataclasses; their fields are the dimensions, named as the design file's
    ``[follower]`` keys, plus ``rotation`` (or ``direction`` for a translating cam).
    """

    #: the registry key: ``[cam] kind``, ``[follower] type`` and ``[follower] motion``
    cam_kind: ClassVar[CamKind] = CamKind.DISC
    follower: ClassVar[FollowerType] = FollowerType.ROLLER
    motion: ClassVar[FollowerMotion] = FollowerMotion.TRANSLATING
    #: ``[follower]`` keys the family needs, and those it may take
    required: ClassVar[tuple[str, ...]] = ()
    optional: ClassVar[tuple[str, ...]] = ()

    @classmethod
    def from_spec(cls, spec: Any) -> Mechanism:  # pragma: no cover - abstract
        """The mechanism a validated :class:`~camfab.design.spec.DesignSpec` describes."""
        raise NotImplementedError

    def validate(self) -> list[Problem]:  # pragma: no cover - abstract
        """Every problem of the dimensions alone (empty: the family can be built for some motion)."""
        raise NotImplementedError

    def validate_motion(self, program: MotionLike, *, bore_mm: float | None = None) -> list[Problem]:
        """Problems that depend on the motion as well; a disc cam's program must span one revolution."""
        if self.cam_kind is not CamKind.TRANSLATING and abs(program.period - 2 * math.pi) > 1e-9:
            return [Problem("motion", program.period, "a disc cam's motion must span one revolution (2π rad)",
                            "make the segment angles sum to 360°")]
        return []

    def contacts(self, program: MotionLike) -> tuple[Contact, ...]:  # pragma: no cover - abstract
        """The exact profile(s) of the cam for ``program`` (no validation)."""
        raise NotImplementedError

    def default_program(self) -> MotionLike | None:
        """The law the family imposes when the design gives none (constant width/diameter), else None."""
        return None

    @property
    def sense(self) -> int:
        """σ: +1 for cw, −1 for ccw."""
        return 1 if getattr(self, "rotation", "cw") == "cw" else -1

    def geometry(self, program: MotionLike | None = None, *, bore_mm: float | None = None) -> CamGeometry:
        """Validate the mechanism with ``program`` and build its exact :class:`CamGeometry`.

        Raises
        ------
        SpecError
            Every problem found, together (field paths ``follower.*``, ``cam.*``, ``motion``).
        """
        if program is None and not self.validate():
            program = self.default_program()
            if program is None:
                raise SpecError(Problem("motion", None, f"a {type(self).__name__} needs a motion program",
                                        "pass a MotionProgram"))
        return self.geometry_class(self, program, bore_mm=bore_mm)  # type: ignore[arg-type]

    #: the geometry type of this family (form-closed pairs add their double-follower measures)
    geometry_class: ClassVar[type[CamGeometry]] = CamGeometry
