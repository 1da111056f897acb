"""Segment programs: a closed chain of motion-law segments, evaluated exactly.

A :class:`MotionProgram` maps the cam's independent variable ``x`` (radians of
cam angle for rotating cams, mm of travel for translating cams) to the follower
coordinate ``S`` and its derivatives ``S′, S″, S‴`` per unit of ``x``.  It is
periodic with period :attr:`MotionProgram.period` (2π or the cam length), and its
:attr:`MotionProgram.axis` says which of the two x is and whether S is in mm or degrees.

Build one with :func:`build_program` (validating, reports every problem at
once) or :meth:`MotionProgram.from_segments` (the same, with degrees for
convenience).  The parts live in their own modules: the laws
(:mod:`~camfab.design.laws`), one segment (:mod:`~camfab.design.segment`), the evaluation
paths (:mod:`~camfab.design.evaluation`), peaks and junctions
(:mod:`~camfab.design.extrema`) and the validation of the inputs
(:mod:`~camfab.design.resolve`); their public names are importable from here too.
"""
from __future__ import annotations

import math
from collections.abc import Iterable, Sequence

import numpy as np

from ..errors import InputError
from ..records import dataclass, field
from ..sets import sorted_unique
from ..tolerances import CONTINUITY_REL_TOL
from .evaluation import Grouped, by_segment
from .extrema import Junction, Peak, exact_peaks, junctions, sampled_peaks
from .kinds import ROTATING_MM, TRANSLATING_MM, Axis, LiftUnit
from .resolve import SegmentInput, resolve_segments
from .segment import Segment, hermite_coefficients, solve_generic

__all__ = [
    "SegmentInput",
    "Segment",
    "MotionProgram",
    "Peak",
    "Junction",
    "build_program",
    "solve_generic",
    "hermite_coefficients",
]

TWO_PI = 2.0 * math.pi
#: at most this many samples per segment (on average) are evaluated law by law
#: (:class:`~camfab.design.evaluation.Grouped`), more segment by segment
_GROUPED_MAX = 256


@dataclass(frozen=True)
class MotionProgram:
    """A closed chain of resolved segments.  See the module docstring."""

    segments: tuple[Segment, ...]
    period: float = TWO_PI
    #: what x is (cam angle or travel) and the unit of S (mm or degrees)
    axis: Axis = ROTATING_MM
    _starts: np.ndarray = field(init=False, repr=False, compare=False)
    _grouped: Grouped = field(init=False, repr=False, compare=False)
    _memo: dict = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "_starts", np.array([s.start for s in self.segments]))
        object.__setattr__(self, "_grouped", Grouped(self.segments))
        object.__setattr__(self, "_memo", {})  # results of the analyses (the program is immutable)

    # ---- construction -------------------------------------------------
    @classmethod
    def from_segments(cls, rows: Iterable[Sequence], *, unit: str = "deg",
                      period: float | None = None, lift_unit: str = "mm") -> MotionProgram:
        """Build from ``(law, lift, span[, shape[, ends]])`` rows; span in degrees by default (``ends``: a generic
        polynomial's joint values S′, S″, S‴ per radian, see :class:`SegmentInput`).

        ``unit="rad"`` takes spans in radians; ``unit="mm"`` builds a
        translating-cam program whose period is the sum of the spans (or
        ``period``).  A span of ``None`` is solved (half-period laws).  ``lift_unit``: "mm", or
        "deg" for an oscillating follower.
        """
        scale = {"deg": math.pi / 180.0, "rad": 1.0, "mm": 1.0}[unit]
        inputs = []
        for row in rows:
            law, lift, span, *rest = row
            inputs.append(SegmentInput(law, float(lift), None if span is None else float(span) * scale,
                                       rest[0] if rest else None, *rest[1:2]))
        if period is None:
            period = TWO_PI if unit != "mm" else sum(i.span or 0.0 for i in inputs)
        return build_program(inputs, period=period, unit=unit, lift_unit=lift_unit)

    # ---- evaluation ---------------------------------------------------
    @property
    def junctions_x(self) -> np.ndarray:
        """Segment junctions in x, from 0 to :attr:`period` inclusive."""
        return np.append(self._starts, self.period)

    @property
    def breakpoints(self) -> np.ndarray:
        """Every point where a formula changes: junctions and internal law breaks."""
        pts = [self.junctions_x]
        for s in self.segments:
            if s.breaks:
                pts.append(s.start + s.span * np.asarray(s.breaks))
        return sorted_unique(np.concatenate(pts))

    def segment_index(self, x: np.ndarray) -> np.ndarray:
        """Index of the segment containing each ``x`` (already reduced to [0, period))."""
        idx = np.searchsorted(self._starts, x, side="right") - 1
        return np.maximum(idx, 0)  # ≤ n − 1 already: NaN sorts last

    def evaluate(self, x, orders: Sequence[int] = (0, 1, 2, 3)) -> np.ndarray:
        """S and its derivatives at ``x``.

        Parameters
        ----------
        x : (n,) float array or float
            Cam angle in radians (or travel in mm); any real value, the program
            is periodic.  A point on a junction takes the segment that starts there.
        orders : sequence of int
            Which derivatives to return (0 = S … 3 = S‴; higher ones are available too).

        Returns
        -------
        (len(orders), n) float array
            Derivatives per unit of x (per radian or per mm).
        """
        xa = np.atleast_1d(np.asarray(x, dtype=float))
        xr = np.mod(xa, self.period)
        idx = self.segment_index(xr)
        out = np.empty((len(orders), xr.size))
        if xr.size <= _GROUPED_MAX * len(self.segments):
            self._grouped.evaluate(xr, idx, orders, out)
        else:
            by_segment(self.segments, xr, idx, orders, out)
        return out

    def __call__(self, x, nu: int = 0) -> np.ndarray:
        """The ``nu``-th derivative of S at ``x`` (vectorised, periodic)."""
        return self.evaluate(x, (nu,))[0]

    # ---- analysis -----------------------------------------------------
    def junctions(self, *, rel_tol: float | None = None, internal: bool = False) -> list[Junction]:
        """Continuity at every segment junction (360°→0° included, listed first).

        A jump counts as a discontinuity when it exceeds ``rel_tol`` times the
        peak magnitude of that derivative over the cycle (at least 1e-9 in
        absolute terms).  With ``internal=True`` the internal breakpoints of
        piecewise laws are included.
        """
        tol = CONTINUITY_REL_TOL if rel_tol is None else rel_tol
        key = ("junctions", tol, internal)
        if key not in self._memo:
            self._memo[key] = junctions(self, tol, internal)
        return list(self._memo[key])

    def peaks(self, mode: str = "exact", *, step: float | None = None) -> tuple[Peak, Peak, Peak, Peak]:
        """Extremes of S, S′, S″, S‴ over the cycle (per unit x).

        ``mode="exact"`` finds the analytic extrema: piece end values (one-sided
        at junctions, so a jerk jump reports the value on the segment side) and
        interior zeros of the next derivative, located to ~1e-12 in u.
        ``mode="camdas"`` reproduces CAM-DAS: samples every ``step`` (default
        1°, or 1 mm for translating cams) from 0 to the period inclusive, a
        sample on a junction counted on both sides.
        """
        if mode == "exact":  # computed once (the program is immutable; Peak is frozen)
            if "peaks" not in self._memo:
                self._memo["peaks"] = exact_peaks(self)
            return self._memo["peaks"]  # type: ignore[return-value]
        if mode == "camdas":
            if step is None:
                step = math.pi / 180.0 if self.axis.rotating else 1.0
            return sampled_peaks(self, step)
        raise InputError(f"'{mode}' is not a valid peaks mode, must be one of: exact, camdas")


def build_program(inputs: Sequence[SegmentInput], *, period: float = TWO_PI, unit: str = "rad",
                  path: str = "motion", source: str | None = None, lift_unit: str = "mm") -> MotionProgram:
    """Validate segment inputs and resolve them into a :class:`MotionProgram`.

    Every rule of the CAM-DAS data entry (see :mod:`~camfab.design.resolve`) is checked and
    **all** problems are reported together in one :class:`~camfab.errors.SpecError`, each
    naming its field path (``motion[3].angle_deg``), the value, the rule and a fix.

    Parameters
    ----------
    inputs : sequence of SegmentInput
    period : float
        2π, or the cam length in mm.
    unit : {"rad", "deg", "mm"}
        The unit the user gave the spans in (``"mm"``: a translating cam).
    path, source : str
        Field path prefix and file named in the problems.
    lift_unit : {"mm", "deg"}
        "deg" for an oscillating follower.
    """
    segments = resolve_segments(inputs, period=period, unit=unit, path=path, source=source)
    axis = (TRANSLATING_MM if unit == "mm" else ROTATING_MM).with_lift(LiftUnit(lift_unit))
    return MotionProgram(segments, period, axis)
