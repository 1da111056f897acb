"""What every check rule shares: the limits a cam is judged against, a rule's result, and the
dense sample of a contact that all the rules of that contact read.

A rule is a plain function — of a contact ``(contact, limits, sample)`` or of the whole cam
``(geometry, limits, samples)`` — that returns its findings and the report fields it fills.
"""
from __future__ import annotations

import functools
import math
from collections.abc import Callable
from typing import Any

import numpy as np

from ... import numeric
from ...errors import GeometryError
from ...records import dataclass, field
from ...results import Finding
from ..kinds import ContactKind
from ..profile import Contact, ProfileSample

__all__ = ["Limits", "RuleResult", "ContactSample", "QUANTITIES", "CUSP_TOL_MM", "DEFAULT_PRESSURE_LIMIT_DEG",
           "Words", "words", "radius", "span_text", "where"]

#: a radius margin within this many mm of its limit is a cusp (not an undercut)
CUSP_TOL_MM = 1e-7
#: pressure-angle limits (degrees) by follower motion (CAM-DAS, after Norton)
DEFAULT_PRESSURE_LIMIT_DEG = {"translating": 30.0, "oscillating": 35.0}

#: a quantity of a profile sample: (n,) values from a :class:`ProfileSample` of n parameters
Quantity = Callable[[ProfileSample], np.ndarray | None]


@dataclass(frozen=True)
class Limits:
    """What the checks judge a cam against.

    Attributes
    ----------
    pressure_angle_deg : float, optional
        Limit on |δ| (degrees); default 30 (translating followers and cams) or 35 (oscillating).
    tool_radius_mm : float, optional
        Cutter radius: concave stretches tighter than it are reported.
    face_margin_mm : float
        Safety margin added to each required flat-face length (mm).
    allow_acceleration_jump : bool
        Accept acceleration jumps (constant-width / constant-diameter cams).
    speed : float
        ω in rad/s (mm/s for a translating cam): the motion peaks are given in time units.
    strength : camfab.design.strength.StrengthInput, optional
        The contact-stress inputs (force model, materials, width); None: no contact-stress check.
    """

    pressure_angle_deg: float | None = None
    tool_radius_mm: float | None = None
    face_margin_mm: float = 0.0
    allow_acceleration_jump: bool = False
    speed: float = 1.0
    strength: Any = None


@dataclass(frozen=True)
class RuleResult:
    """A rule's findings and the :class:`~camfab.results.CheckReport` fields it fills (by field
    name; a field filled by several profiles is merged with its ``merged`` method)."""

    findings: tuple[Finding, ...] = ()
    fields: dict[str, Any] = field(default_factory=dict)


@dataclass(frozen=True)
class Words:
    """How the findings of a circle-touching contact name its follower.

    Attributes
    ----------
    surface : str
        What touches the cam: "roller" or "face".
    size : str
        What its radius R is called: "roller" (as in "smaller than the roller (7 mm)") or "face radius".
    """

    surface: str
    size: str


def words(contact: Contact) -> Words:
    """The words for a roller (knife edge: radius 0) or a curved face (:attr:`Contact.curved_face`)."""
    return Words("face", "face radius") if contact.curved_face else Words("roller", "roller")


def radius(s: ProfileSample) -> np.ndarray:
    """Distance of the contact point from the cam centre (mm)."""
    return np.hypot(s.point[:, 0], s.point[:, 1])


#: the frame-independent quantities whose extremes the rules read, by name, with the contacts they
#: apply to; a contact's applicable ones are all searched together on the first request
QUANTITIES: dict[str, tuple[Quantity, Callable[[Contact], bool]]] = {
    "curvature_pitch": (lambda s: s.curvature_pitch, lambda c: c.kind is ContactKind.ROLLER),
    "rho": (lambda s: s.rho, lambda c: c.kind is not ContactKind.ROLLER),
    "pressure_angle": (lambda s: s.pressure_angle, lambda c: c.kind is ContactKind.ROLLER),
    "face_position": (lambda s: s.face_position, lambda c: c.has_face),
    "radius": (radius, lambda c: c.closed),
}


class ContactSample:
    """One contact evaluated once on the dense grid of its breakpoints (fixed frame), shared by every
    rule of that contact: a search given these values does not sample the contact again.

    The checked quantities (curvatures, pressure angle, face position, |point|, point × point′) do
    not depend on the frame, so the fixed-frame sample (no rotation into the cam frame) serves.
    The extremes of the :data:`QUANTITIES` that apply to the contact are searched together (one
    evaluation per round for all of them) when a rule first asks for one, and kept.
    """

    def __init__(self, contact: Contact):
        self.contact = contact
        self.edges = contact.breakpoints
        _refuse_unresolved(contact, self.edges)
        self.grid = numeric.dense_grid(self.edges)
        self._extremes: dict[str, tuple[numeric.Optimum, numeric.Optimum]] | None = None

    @functools.cached_property
    def dense(self) -> ProfileSample:
        """The contact at every sample of :attr:`grid`."""
        return self.contact.evaluate_fixed(self.grid.x)

    def _rows(self, quantities: tuple[Quantity, ...]) -> Callable[[np.ndarray], np.ndarray]:
        def f(x: np.ndarray) -> np.ndarray:
            s = self.contact.evaluate_fixed(x)
            return np.stack([np.asarray(q(s), dtype=float) for q in quantities])
        return f

    def extrema(self, quantities: tuple[Quantity, ...], maximize: tuple[bool, ...],
                rows: tuple[int, ...]) -> list[numeric.Optimum]:
        """Exact extrema over the contact's period: search i looks at ``quantities[rows[i]]``."""
        values = np.stack([np.asarray(q(self.dense), dtype=float) for q in quantities])
        return numeric.extrema(self._rows(quantities), self.edges, maximize, rows=rows, values=values)

    def extremes(self, name: str) -> tuple[numeric.Optimum, numeric.Optimum]:
        """``(minimum, maximum)`` of the quantity ``name`` of :data:`QUANTITIES`."""
        if self._extremes is None:
            names = [n for n, (_, applies) in QUANTITIES.items() if applies(self.contact)]
            found = self.extrema(tuple(QUANTITIES[n][0] for n in names), (False, True) * len(names),
                                 tuple(k for k in range(len(names)) for _ in (0, 1)))
            self._extremes = {n: (found[2 * k], found[2 * k + 1]) for k, n in enumerate(names)}
        if name not in self._extremes:
            lo, hi = self.extrema((QUANTITIES[name][0],), (False, True), (0, 0))
            self._extremes[name] = (lo, hi)
        return self._extremes[name]

    def ranges(self, *quantities: Quantity) -> list[list[numeric.Range]]:
        """Where each quantity is > 0 (all searched together), with its largest value per range."""
        values = np.stack([np.asarray(q(self.dense), dtype=float) for q in quantities])
        return numeric.positive_ranges(self._rows(quantities), self.edges, closed=self.contact.closed,
                                       values=values)

    def user(self, x: float) -> float:
        """A parameter in user units: degrees of cam angle, or mm of travel."""
        return math.degrees(x) if self.contact.axis.rotating else float(x)

    @property
    def unit(self) -> str:
        """``"°"`` or ``" mm"``, to follow a number in a message."""
        return self.contact.axis.x_symbol


def span_text(sample: ContactSample, lo: float, hi: float) -> str:
    """``"at A°"`` or ``"from A° to B°"`` (user units) for a range of parameters; six significant digits, more
    where a narrow range needs them to show its two ends apart (``from 90° to 90.000001°``, not ``to 90°``)."""
    a, b, u = sample.user(lo), sample.user(hi), sample.unit
    if abs(b - a) < 1e-9:
        return f"at {a:.6g}{u}"
    digits = next(d for d in (6, 9, 12, 17) if f"{a:.{d}g}" != f"{b:.{d}g}" or d == 17)
    return f"from {a:.{digits}g}{u} to {b:.{digits}g}{u}"


def _user(contact: Contact, x: float) -> float:
    return math.degrees(x) if contact.axis.rotating else float(x)


def where(contact: Contact, lo: float, hi: float) -> str:
    """The motion segment holding ``[lo, hi]`` (parameters; its middle decides) by its field path, law, lift
    and span, for a refusal: ``"motion[2] (cycloidal, lift 10 mm over 0.01°, from 0° to 0.01°)"``, a knot
    table's segment by the row it starts at (``"motion_table.rows[1] (hermite5, …)"``); a motion without
    segments (a conjugate partner's) as ``"from A° to B°"``."""
    u = contact.axis.x_symbol
    segments = getattr(contact.motion, "segments", None)
    if not segments:
        return f"from {_user(contact, lo):.12g}{u} to {_user(contact, hi):.12g}{u}"
    mid = float(np.mod(0.5 * (lo + hi), contact.period))
    k = max(int(np.searchsorted([s.start for s in segments], mid, side="right")) - 1, 0)
    seg = segments[k]
    path = f"motion_table.rows[{k}]" if seg.law.startswith("hermite") else f"motion[{k}]"
    return (f"{path} ({seg.law}, lift {seg.lift:.6g} {contact.axis.lift_unit.value} over {_user(contact, seg.span):.6g}"
            f"{u}, from {_user(contact, seg.start):.12g}{u} to {_user(contact, seg.end):.12g}{u})")


def _refuse_unresolved(contact: Contact, edges: np.ndarray) -> None:
    """A stretch between breakpoints narrower than double precision resolves (:func:`numeric.resolution`)
    cannot be checked: refused (exit 2) rather than passed unseen."""
    narrow = numeric.unresolved(edges)
    if narrow.size:
        a, b = float(edges[narrow[0]]), float(edges[narrow[0] + 1])
        u = contact.axis.x_symbol
        raise GeometryError(
            f"{where(contact, a, b)}: a stretch {_user(contact, b - a):.3g}{u} wide, narrower than the "
            f"{_user(contact, numeric.resolution(edges)):.3g}{u} that double precision resolves at this cam size, "
            "so the checks cannot see into it. Widen it or merge it with its neighbour")
