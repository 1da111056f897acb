"""Contact stress and life: Hertz line contact along the cycle, the roller bearing's rating life
(ISO 281) and an estimate of the cam surface's contact-fatigue life.

Hertz line contact (two cylinders, or a cylinder on a plane; Johnson, *Contact Mechanics*, §4.3)
-------------------------------------------------------------------------------------------------
A force N (newtons) pressed over a face width b (mm) between bodies of radii R₁, R₂::

    1/E* = (1 − ν₁²)/E₁ + (1 − ν₂²)/E₂         1/R* = 1/R₁ + 1/R₂
    p_max = √(N·E*/(π·b·R*))                    a = √(4·N·R*/(π·b·E*))   (half-width of the contact)

R₁ is the cam profile's signed radius of curvature ρ (positive = convex, ``docs/decisions.md``:
1/R₁ = κ, negative on a concave stretch: the textbook's "minus" of a concave contact comes with the
sign), R₂ the follower's: the roller radius, a curved face's radius, ∞ for a flat face.  So
``1/R* = κ + 1/R₂``.  On a true roller envelope a concave stretch has |ρ| > R_r, so 1/R* > 0; a flat face
on a concave stretch (an undercut) or a cusp has 1/R* ≤ 0 or ∞: the stress is infinite there.  A knife
edge (R₂ = 0) has no finite contact stress: refused (:func:`follower_radius`).  Where the follower
leaves the cam (N < 0) the stress is 0.

N is the contact force of :mod:`camfab.design.dynamics` (follower 1's and follower 2's on a
form-closed cam, each on its own profile, follower 2 at φ + shift).  Every extreme is exact
(:func:`camfab.numeric.search`, refined between the motion's breakpoints).

Roller life (ISO 281:2007, basic rating life)
---------------------------------------------
``L10 = (C/P)^p`` million revolutions of the roller (p = 10/3 for roller bearings, 3 for ball bearings),
with P the equivalent load of the varying contact force, weighted by the revolutions the roller makes
(ISO 281 / bearing makers' mean load for a varying load)::

    P = (∮ N^p · ds / ∮ ds)^(1/p)

s the arc length along the cam profile (the contact rolls without slip, so the roller turns by ds/R_r):
per cam cycle the roller turns ∮ds / (2π·R_r) times (the turning of the contact normal and of an arm
cancel over a closed cycle).  L10 is then given in cam cycles and hours at the design speed.

Cam surface life (estimate)
---------------------------
Each point of the cam track is loaded once per cam cycle (twice on a constant-width or -diameter cam,
whose one profile carries both followers), the worst point at p_max.  Its life follows the
material's S–N line ``N = N_L·(σ_Hlim/p_max)^m`` (ISO 6336-2's life factor: m = 13.2, N_L = 5·10⁷ for
steels), unlimited below σ_Hlim.  An estimate: lubrication, sliding and surface finish are not in it.
"""
from __future__ import annotations

import math
from typing import Any

import numpy as np

from .. import numeric
from ..errors import InputError
from ..records import dataclass
from ..results import Finding, IssueCode, Severity
from .dynamics import ContactDynamics, DynamicsSample, GrooveDynamics, PairDynamics
from .kinds import ContactKind
from .materials import Material
from .profile import CamGeometry, Contact

__all__ = ["effective_modulus", "hertz_line", "relative_curvature", "follower_radius", "StrengthInput",
           "StressModel", "StressSample", "RollerLife", "CamLife", "ContactStressSummary", "analyse_strength",
           "rating_life", "cam_life", "BALL", "ROLLER"]

#: ISO 281 life exponents
ROLLER = 10.0 / 3.0
BALL = 3.0


def effective_modulus(e1: float, nu1: float, e2: float, nu2: float) -> float:
    """E* (MPa): ``1/E* = (1 − ν₁²)/E₁ + (1 − ν₂²)/E₂``."""
    return 1.0 / ((1.0 - nu1 * nu1) / e1 + (1.0 - nu2 * nu2) / e2)


def hertz_line(force, e_star: float, width: float, curvature) -> tuple[np.ndarray, np.ndarray]:
    """``(p_max (MPa), half-width a (mm))`` of a line contact: force N (newtons, < 0 counts as 0), E* (MPa),
    face width b (mm) and the relative curvature ``1/R* = 1/R₁ + 1/R₂`` (1/mm; ≤ 0 or ∞: p = ∞ where
    loaded)."""
    N = np.maximum(np.asarray(force, dtype=float), 0.0)
    k = np.asarray(curvature, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        p = np.sqrt(N * (e_star / (math.pi * width)) * k)
        a = np.sqrt(N * (4.0 / (math.pi * width * e_star)) / k)
    bad = ~(k > 0) | ~np.isfinite(k)
    p = np.where(bad, np.where(N > 0, np.inf, 0.0), p)
    a = np.where(bad & (N > 0), np.where(k > 0, 0.0, np.inf), np.where(N > 0, a, 0.0))
    return p, a


def relative_curvature(kappa, follower_radius_mm: float) -> np.ndarray:
    """``1/R* = κ + 1/R₂`` (1/mm): κ the profile's signed curvature (positive convex), R₂ the follower's radius
    (∞ for a flat face)."""
    return np.asarray(kappa, dtype=float) + (0.0 if math.isinf(follower_radius_mm) else 1.0 / follower_radius_mm)


def follower_radius(contact: Contact) -> float:
    """R₂ (mm) of a contact's follower: the roller or curved-face radius, ∞ for a flat face.

    Raises
    ------
    InputError
        A knife edge: its contact stress is infinite (a line of zero radius), not a number to check.
    """
    if contact.kind is ContactKind.FLAT:
        return math.inf
    if contact.roller_radius <= 0.0:
        raise InputError("contact stress of a knife-edge follower: undefined (a zero-radius edge gives an "
                         "infinite Hertz stress and wears at once); use a roller or a face to have it checked")
    return float(contact.roller_radius)


@dataclass(frozen=True)
class StrengthInput:
    """What the contact-stress check needs beyond the geometry.

    Attributes
    ----------
    dynamics : ContactDynamics or PairDynamics or None
        The force model at the design speed; None: no contact force known (nothing computed, stated).
    cam, follower : Material
        Follower 2 of a form-closed cam is of the follower's material too.
    width_mm : float
        Face width b of the line contact (mm).
    allowable_mpa : float
        The contact stress judged against (MPa).
    dynamic_rating_n : float, optional
        C of the roller's bearing (N); None: no roller life.
    life_exponent : float
        p of ISO 281: 10/3 roller bearings, 3 ball bearings.
    notes : tuple of str
        Assumptions stated with the result (a material assumed, the width taken from the plate …).
    roller_radius_mm : float, optional
        R₂ of both contacts where the contacts carry another radius: a groove cam's flanks are contacts of the
        groove half-width R_r + b/2, its roller is R_r.
    """

    dynamics: ContactDynamics | PairDynamics | None
    cam: Material
    follower: Material
    width_mm: float
    allowable_mpa: float
    dynamic_rating_n: float | None = None
    life_exponent: float = ROLLER
    notes: tuple[str, ...] = ()
    roller_radius_mm: float | None = None


@dataclass(frozen=True)
class StressSample:
    """Contact stress at n parameters: follower 1's (and a form-closed follower 2's) p_max (MPa)."""

    phi: np.ndarray
    stress: np.ndarray
    force: np.ndarray
    stress_2: np.ndarray | None = None
    force_2: np.ndarray | None = None


class StressModel:
    """p_max(φ) along the cycle from one force evaluation (:meth:`evaluate`)."""

    def __init__(self, dynamics: ContactDynamics | PairDynamics, e_star: float, width_mm: float,
                 roller_radius_mm: float | None = None):
        self.dynamics, self.e_star, self.width = dynamics, float(e_star), float(width_mm)
        self.pair = isinstance(dynamics, PairDynamics)
        first = dynamics.first.contact if isinstance(dynamics, PairDynamics) else dynamics.contact
        self.radius = follower_radius(first) if roller_radius_mm is None else float(roller_radius_mm)
        self.radius_2 = None if not isinstance(dynamics, PairDynamics) else \
            follower_radius(dynamics.second.contact) if roller_radius_mm is None else float(roller_radius_mm)

    def evaluate(self, x) -> StressSample:
        """The stress at parameters x (radians, or mm of travel)."""
        return self.of_sample(self.dynamics.evaluate(x))

    def of_sample(self, sm: DynamicsSample) -> StressSample:
        """The stress from a force sample of :attr:`dynamics` (no second evaluation)."""
        p, _ = hertz_line(sm.contact_force, self.e_star, self.width, relative_curvature(sm.curvature, self.radius))
        if not self.pair:
            return StressSample(sm.phi, p, sm.contact_force)
        p2, _ = hertz_line(sm.contact_force_2, self.e_star, self.width,
                           relative_curvature(sm.curvature_2, self.radius_2))  # type: ignore[arg-type]
        return StressSample(sm.phi, p, sm.contact_force, p2, sm.contact_force_2)


@dataclass(frozen=True)
class RollerLife:
    """ISO 281 basic rating life of the roller bearing (the shorter of a form-closed cam's two)."""

    l10_million_revolutions: float | None
    cam_cycles: float | None
    hours: float | None
    equivalent_load_n: float
    dynamic_rating_n: float
    exponent: float
    roller_revolutions_per_cycle: float
    follower: int = 1

    def to_dict(self) -> dict[str, Any]:
        return {"l10_million_revolutions": self.l10_million_revolutions, "l10_cam_revolutions": self.cam_cycles,
                "l10_hours": self.hours, "equivalent_load_n": self.equivalent_load_n,
                "dynamic_rating_n": self.dynamic_rating_n, "exponent": self.exponent,
                "roller_revolutions_per_cam_revolution": self.roller_revolutions_per_cycle,
                "follower": self.follower}


@dataclass(frozen=True)
class CamLife:
    """Estimated contact-fatigue life of the cam track (None: unlimited, below the fatigue limit)."""

    cam_cycles: float | None
    hours: float | None
    fatigue_limit_mpa: float
    exponent: float
    knee_cycles: float

    def to_dict(self) -> dict[str, Any]:
        return {"cam_revolutions": self.cam_cycles, "hours": self.hours, "fatigue_limit_mpa": self.fatigue_limit_mpa,
                "exponent": self.exponent, "knee_cycles": self.knee_cycles}


@dataclass(frozen=True)
class ContactStressSummary:
    """The ``contact_stress`` object of ``check --json`` (MPa; angles in user units).

    ``max_mpa`` is the largest over both followers of a form-closed cam (``follower`` says whose);
    None with ``notes`` saying why when it is not computed (no contact force, a knife edge) or is
    infinite (a cusp or an undercut of a flat face)."""

    max_mpa: float | None
    at: float | None
    allowable_mpa: float | None
    safety_factor: float | None
    cam_material: str | None = None
    follower_material: str | None = None
    width_mm: float | None = None
    follower: int = 1
    second: tuple[float, float] | None = None
    roller_life: RollerLife | None = None
    cam_life: CamLife | None = None
    notes: tuple[str, ...] = ()

    def to_dict(self) -> dict[str, Any]:
        return {"max_mpa": self.max_mpa, "at_deg": self.at, "allowable_mpa": self.allowable_mpa,
                "safety_factor": self.safety_factor, "follower": self.follower, "cam_material": self.cam_material,
                "follower_material": self.follower_material, "face_width_mm": self.width_mm,
                "second_follower": None if self.second is None else
                {"max_mpa": self.second[0], "at_deg": self.second[1]},
                "roller_life": None if self.roller_life is None else self.roller_life.to_dict(),
                "cam_life": None if self.cam_life is None else self.cam_life.to_dict(),
                "notes": list(self.notes)}


def rating_life(dynamic_rating_n: float, load_n: float, exponent: float = ROLLER) -> float:
    """ISO 281 basic rating life L10 = (C/P)^p in millions of revolutions (∞ for P = 0)."""
    if load_n <= 0:
        return math.inf
    return (dynamic_rating_n / load_n) ** exponent


def cam_life(p_max: float, material: Material, contacts_per_cycle: int = 1) -> float:
    """Cam cycles to contact fatigue of the worst track point: ``N_L·(σ_Hlim/p)^m / contacts_per_cycle``
    (∞ at or below σ_Hlim, or without a fatigue limit)."""
    lim = material.fatigue_limit_mpa
    if lim is None or not p_max > lim:
        return math.inf
    return material.fatigue_cycles * (lim / p_max) ** material.fatigue_exponent / contacts_per_cycle


def _edges(geometry: CamGeometry, pair: PairDynamics | None) -> np.ndarray:
    """The breakpoints of the forces: a single profile touched twice has them shifted half a turn too."""
    c = geometry.profiles[0]
    if pair is not None and len(geometry.profiles) == 1:
        return np.unique(np.concatenate([c.breakpoints, np.mod(c.breakpoints - pair.shift, c.period)]))
    return geometry.breakpoints


def _user(c: Contact, x: float) -> float:
    return math.degrees(x) if c.axis.rotating else float(x)


def analyse_strength(geometry: CamGeometry, inp: StrengthInput) -> tuple[ContactStressSummary, tuple[Finding, ...]]:
    """Contact stress along the cycle (exact peak, ``CONTACT_STRESS_ABOVE_LIMIT`` ranges), the roller's
    rating life and the cam track's fatigue-life estimate.

    Raises
    ------
    InputError
        No force model (``inp.dynamics`` None), or a knife edge (:func:`follower_radius`).
    """
    if inp.dynamics is None:
        raise InputError("contact stress needs the contact force: add a [dynamics] section (mass, spring, speed)")
    model = StressModel(inp.dynamics, effective_modulus(inp.cam.e_mpa, inp.cam.poisson, inp.follower.e_mpa,
                                                        inp.follower.poisson), inp.width_mm, inp.roller_radius_mm)
    pair = inp.dynamics if isinstance(inp.dynamics, PairDynamics) else None
    c = geometry.profiles[0]
    edges = _edges(geometry, pair)
    lim = inp.allowable_mpa
    peaks, infinite_at, ranges = _search(model, c, edges, lim)
    follower = 1 + int(np.argmax([v for v, _ in peaks]))
    pmax, at = peaks[follower - 1]
    notes = list(inp.notes)
    findings = tuple(_finding(c, lo, hi, xw, gw + lim, lim, j + 1, pair is not None)
                     for j, rs in enumerate(ranges) for lo, hi, xw, gw in rs)
    second = peaks[1] if pair is not None else None
    if infinite_at is not None:
        notes.append(f"the contact stress is infinite at {infinite_at:.6g} {c.axis.x_unit} (a cusp or a flat face on "
                     "a concave stretch: see the curvature findings; or an infinite force: a self-locking follower)")
        return ContactStressSummary(None, infinite_at, lim, 0.0, inp.cam.name, inp.follower.name, inp.width_mm,
                                    follower, second, None, None, tuple(notes)), findings
    cycle_s = (2 * math.pi if c.closed else c.period) / inp.dynamics.speed
    life = _roller_life(model, inp, edges, cycle_s, notes)
    cam = _cam_life(pmax, inp.cam, 2 if pair is not None and len(geometry.profiles) == 1 else 1, cycle_s, notes)
    safety = lim / pmax if pmax > 0 else None
    return ContactStressSummary(pmax, at, lim, safety, inp.cam.name, inp.follower.name, inp.width_mm, follower,
                                second, life, cam, tuple(notes)), findings


def _search(model: StressModel, c: Contact, edges: np.ndarray,
            lim: float) -> tuple[list[tuple[float, float]], float | None, list[list[numeric.Range]]]:
    """Each follower's exact peak ``(p, at)`` (user units), where the stress is first infinite (None: nowhere),
    and the ranges above ``lim`` — all searched together.  An infinite stress (a cusp, a flat face on a
    concave stretch) is seen on the dense sample but not searched: the curvature rule reports those stretches."""
    k = 2 if model.pair else 1

    def raw(x: np.ndarray) -> np.ndarray:
        sm = model.evaluate(x)
        ps = [sm.stress] + ([sm.stress_2] if sm.stress_2 is not None else [])
        return np.stack(ps + [p - lim for p in ps])

    def rows(x: np.ndarray) -> np.ndarray:
        v = raw(x)
        return np.where(np.isinf(v), np.nan, v)

    grid = numeric.dense_grid(edges)
    dense = raw(grid.x)
    found, ranges = numeric.search(rows, edges, extrema=[(j, True) for j in range(k)], ranges=range(k, 2 * k),
                                   closed=c.closed, values=np.where(np.isinf(dense), np.nan, dense))
    infinite = np.isinf(dense[:k]).any(axis=0)
    at_inf = _user(c, float(grid.x[np.argmax(infinite)])) if infinite.any() else None
    return [(float(v), _user(c, at)) for at, v in found], at_inf, ranges


def _cam_life(pmax: float, material: Material, contacts: int, cycle_s: float, notes: list[str]) -> CamLife | None:
    """The cam track's :class:`CamLife` (None without a fatigue limit; the notes say so, or that it is unlimited)."""
    if material.fatigue_limit_mpa is None:
        notes.append(f"no cam-life estimate: {material.name} has no contact-fatigue limit in the table")
        return None
    n = cam_life(pmax, material, contacts)
    if math.isinf(n):
        notes.append(f"cam track life unlimited: the peak stress is below the {material.name} contact-fatigue "
                     f"limit {material.fatigue_limit_mpa:g} MPa")
        return CamLife(None, None, material.fatigue_limit_mpa, material.fatigue_exponent, material.fatigue_cycles)
    return CamLife(n, n * cycle_s / 3600.0, material.fatigue_limit_mpa, material.fatigue_exponent,
                   material.fatigue_cycles)


def _finding(c: Contact, lo: float, hi: float, xw: float, worst: float, lim: float, follower: int,
             pair: bool) -> Finding:
    unit = c.axis.x_symbol
    a, b = _user(c, lo), _user(c, hi)
    span = f"at {a:.6g}{unit}" if abs(b - a) < 1e-9 else f"from {a:.6g}{unit} to {b:.6g}{unit}"
    who = f"follower {follower}: " if pair else ""
    return Finding(IssueCode.CONTACT_STRESS_ABOVE_LIMIT, Severity.ERROR, a, b, float(worst), float(lim),
                   f"{who}contact stress up to {worst:.6g} MPa (at {_user(c, xw):.6g}{unit}) above the allowable "
                   f"{lim:.6g} MPa {span} (safety factor {lim / worst:.3g}): widen the cam or the roller (p ~ 1/sqrt "
                   "of the width), enlarge the base circle or the roller, lower the contact force, or choose a "
                   "harder material")


def _roller_life(model: StressModel, inp: StrengthInput, edges: np.ndarray, cycle_s: float,
                 notes: list[str]) -> RollerLife | None:
    """ISO 281 L10 of the roller bearing from the contact-force history (the shorter of two followers')."""
    if math.isinf(model.radius) or model.dynamics.contact.has_face:
        return None  # a face slides on the cam: no roller
    if inp.dynamic_rating_n is None:
        notes.append("roller life not computed: give the bearing's dynamic rating ([strength] "
                     "roller_dynamic_rating_n)")
        return None
    dyn = model.dynamics
    if isinstance(dyn, GrooveDynamics):
        notes.append("groove cam: one roller, loaded by the inner flank where the follower force is positive and by "
                     "the outer flank where it is negative; its turns counted where a flank carries it")
        return _groove_roller(dyn, inp, edges, cycle_s, model.radius)
    sides = [(dyn.first.contact, dyn.shift if k == 2 else 0.0, k) for k in (1, 2)] \
        if isinstance(dyn, PairDynamics) else [(dyn.contact, 0.0, 1)]
    out = [_one_roller(dyn, contact, shift, who, inp, edges, cycle_s) for contact, shift, who in sides]
    return min(out, key=lambda r: math.inf if r.cam_cycles is None else r.cam_cycles)


def _groove_roller(dyn: GrooveDynamics, inp: StrengthInput, edges: np.ndarray, cycle_s: float,
                   radius: float) -> RollerLife:
    """A groove's one roller: P = (Σ∫N^p ds / Σ∫ds)^(1/p) over the stretches where each flank carries it (s along
    that flank: the inner where G > 0, the outer where G < 0), its turns Σ∫ds/(2π·R_r); the integrals split at
    the load reversals (the roots of G)."""
    p = inp.life_exponent
    inner, outer = dyn.first.contact, dyn.second.contact

    def required(x: np.ndarray) -> np.ndarray:
        g = dyn.first.required(np.asarray(inner.motion.evaluate(x, (0, 1, 2)), dtype=float))
        return np.stack([g, -g])

    cuts = [r[k] for rs in numeric.positive_ranges(required, edges, closed=inner.closed) for r in rs for k in (0, 1)]
    split = np.unique(np.concatenate([edges, np.clip(cuts, edges[0], edges[-1])]))

    def rows(x: np.ndarray) -> np.ndarray:
        sm = dyn.evaluate(x)
        d1, d2 = (np.hypot(*c.evaluate(x).point_d1.T) for c in (inner, outer))
        n1, n2 = np.maximum(sm.contact_force, 0.0), np.maximum(sm.contact_force_2, 0.0)  # type: ignore[arg-type]
        return np.stack([n1 ** p * d1 + n2 ** p * d2, d1 * (sm.required > 0) + d2 * (sm.required < 0)])

    load_ds = numeric.integrate(lambda x: rows(x)[0], split, rtol=1e-9)
    length = numeric.integrate(lambda x: rows(x)[1], split, rtol=1e-9)
    P = (load_ds / length) ** (1.0 / p) if length > 0 else 0.0
    turns = length / (2 * math.pi * radius)
    L = rating_life(inp.dynamic_rating_n or 0.0, P, p)
    cycles = None if math.isinf(L) or turns <= 0 else L * 1e6 / turns
    return RollerLife(None if math.isinf(L) else L, cycles, None if cycles is None else cycles * cycle_s / 3600,
                      P, inp.dynamic_rating_n or 0.0, p, turns, 1)


def _one_roller(dyn: ContactDynamics | PairDynamics, contact: Contact, shift: float, who: int, inp: StrengthInput,
                edges: np.ndarray, cycle_s: float) -> RollerLife:
    """One roller's L10: P = (∮N^p ds / ∮ds)^(1/p) over the cam cycle (s along the profile, at φ + shift)."""
    p = inp.life_exponent
    if isinstance(dyn, PairDynamics) and who == 2:
        contact = dyn.second.contact

    def rows(x: np.ndarray) -> np.ndarray:
        ds = np.hypot(*contact.evaluate(x + shift).point_d1.T)
        sm = dyn.evaluate(x)
        n = sm.contact_force_2 if who == 2 else sm.contact_force
        return np.stack([np.maximum(n, 0.0) ** p * ds, ds])  # type: ignore[arg-type]

    load_ds = numeric.integrate(lambda x: rows(x)[0], edges, rtol=1e-9)
    length = numeric.integrate(lambda x: rows(x)[1], edges, rtol=1e-9)
    P = (load_ds / length) ** (1.0 / p)
    turns = length / (2 * math.pi * contact.roller_radius)
    L = rating_life(inp.dynamic_rating_n or 0.0, P, p)
    cycles = None if math.isinf(L) else L * 1e6 / turns
    return RollerLife(None if math.isinf(L) else L, cycles, None if cycles is None else cycles * cycle_s / 3600,
                      P, inp.dynamic_rating_n or 0.0, p, turns, who)
