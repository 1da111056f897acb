"""Follower vibration: the elastic follower train as one mass on a spring, in its periodic steady state.

The kinetostatics of :mod:`camfab.design.dynamics` takes the follower as rigid.  A real train (tappet,
push rod, rocker, valve) is elastic: it rings, lags and overshoots the cam's motion, and its contact
force swings with the vibration.  This module adds the classic single-mass model (Koster; Norton,
*Cam Design and Manufacturing Handbook*, ch. 10) in the follower's generalised coordinate q (m, or
rad for an arm), in the units of :class:`~camfab.design.dynamics.Loads`.

Model
-----
The cam drives the input end of the train along the kinematic motion s(t) = q(S(x(t))) (x = ω·t, or
v·t for a translating cam).  The moving mass m sits at the output, at w(t), measured from its static
position on the base circle (S = 0).  Between them, the train: a spring k and a damper c (ζ its
damping ratio).  The return spring (rate k_s, preload F₀ at that static position), the absolute
damper c_a of ``[dynamics]`` and the constant load F_ext act on the mass::

    m·ẅ + c_a·ẇ + k_s·w + F₀ + F_ext = F_c
    F_c = F₀ + F_ext − k·u − c·u̇          (the contact force; u = w − s, the train's deflection)

so the deflection obeys the single-degree-of-freedom equation driven by the motion's part of the
kinetostatic force G̃ = m·s̈ + c_a·ṡ + k_s·s (G = G̃ + F₀ + F_ext is the rigid follower's)::

    m·ü + (c + c_a)·u̇ + (k + k_s)·u = −G̃(t)

with ω_n = √((k + k_s)/m) (the cam held still) and c = 2ζ·√((k + k_s)·m).  The contact force in
newtons is N = F_c/D, D the lever of :mod:`~camfab.design.dynamics` (kinematic: the pressure angle and
friction direction of the rigid follower).  The follower separates where F_c < 0; past that the
linear model no longer holds (the mass flies free): the first separation is what it reports.
Rigid limit k → ∞: u → 0 and F_c → G.  Energy: over a steady cycle the cam's work ∮F_c·ṡ dt equals
the damping's ∮(c·u̇² + c_a·ẇ²) dt (tested).

Periodic steady state (harmonic balance)
----------------------------------------
G̃ is periodic; the response of the linear system to its harmonic j (frequency jΩ, Ω = 2π/T) is
that harmonic times H(jΩ) = 1/(k + k_s − m(jΩ)² + i·jΩ(c + c_a)) — no transient, no cycles to integrate.
The response is computed at ``n`` equal steps of one cycle (FFT); G̃'s first n/2 harmonics come from
a sample :data:`OVERSAMPLE` times finer, so little of the harmonics above folds onto them.  The error
falls as 1/n² (3·10⁻⁸ of the deflection through a cycloidal rise at n = 4096); ``solve_ivp`` over many
cycles agrees (tests).  G̃ = r²·A₂ + r·A₁ + A₀
at the rate r (ω or v), so a new speed costs one inverse FFT: the separation speed is scanned on a
geometric ladder of speeds and refined by root finding.
"""
from __future__ import annotations

import math

import numpy as np

from .. import numeric
from ..errors import InputError
from ..records import dataclass
from ..results import Extreme, Finding, IssueCode, JumpSpeed, Maximum, Severity
from ..units import RPM
from .dynamics import ContactDynamics, Loads
from .profile import Contact
from .vibration_results import Harmonic, VibrationReport, VibrationSummary

__all__ = ["Train", "VibrationSample", "FollowerTrain", "analyse_vibration", "dwell_runs", "SEARCH_FACTOR",
           "SCAN_RATIO", "RESONANCE_BAND", "SIGNIFICANT_FRACTION", "SAMPLES"]

#: samples per cycle (a power of two: the FFT)
SAMPLES = 4096
#: the motion is sampled this many times finer for its harmonics (aliasing from above n/2 falls by its square)
OVERSAMPLE = 8
#: the separation speed is searched up to this multiple of the design speed …
SEARCH_FACTOR = 10.0
#: … from 1 % of it, on a geometric ladder of this ratio (a separation band narrower is missed)
SCAN_RATIO = 1.01
#: a harmonic within this fraction of the natural frequency is near resonance …
RESONANCE_BAND = 0.1
#: … and significant when its kinematic acceleration amplitude is at least this fraction of the largest
SIGNIFICANT_FRACTION = 0.05


@dataclass(frozen=True)
class Train:
    """The follower train's elasticity: its stiffness k (N/m, or N·m/rad for an arm; > 0) and the damping
    ratio ζ of its damper (≥ 0, the train alone: c = 2ζ√((k + k_s)·m))."""

    stiffness: float
    damping_ratio: float = 0.05


@dataclass(frozen=True)
class VibrationSample:
    """The steady state over one cycle at ``n`` equal steps (arrays (n,); q in m or rad, forces in N or N·m).

    ``x``: the cam parameter (rad, or mm of travel); ``s``: the kinematic follower; ``w``: the elastic
    follower (from its static position on the base circle); ``force``: the generalised contact force F_c;
    ``contact_force``: N = F_c/D (newtons; NaN where the follower is wedged, D ≤ 0); ``kinematic_force``:
    the rigid follower's G/D; ``deflection_rate``: u̇ = ẇ − ṡ (per second); ``rate``: ω or v."""

    x: np.ndarray
    s: np.ndarray
    w: np.ndarray
    deflection_rate: np.ndarray
    force: np.ndarray
    contact_force: np.ndarray
    kinematic_force: np.ndarray
    rate: float


class FollowerTrain:
    """One contact's elastic follower train (see the module docstring).

    Parameters
    ----------
    contact : Contact
        A spring-loaded single contact (rotating or translating cam).
    loads : Loads
        m, k_s, F₀, c_a and F_ext (SI units of the follower's coordinate).
    train : Train
    n : int
        Samples per cycle (even).
    """

    def __init__(self, contact: Contact, loads: Loads, train: Train, *, n: int = SAMPLES):
        if not (loads.inertia > 0 and train.stiffness > 0 and train.damping_ratio >= 0 and loads.spring_rate >= 0
                and loads.damping >= 0):
            raise InputError(f"the follower train needs m > 0, k > 0, ζ ≥ 0, k_s ≥ 0 and c_a ≥ 0 (m = "
                             f"{loads.inertia!r}, k = {train.stiffness!r}, ζ = {train.damping_ratio!r}, k_s = "
                             f"{loads.spring_rate!r}, c_a = {loads.damping!r})")
        if n < 16 or n % 2:
            raise InputError(f"n = {n}: give an even number of samples per cycle, at least 16")
        self.contact, self.loads, self.train, self.n = contact, loads, train, int(n)
        dyn = ContactDynamics(contact, loads, 1.0)
        self.q_per_s = qs = dyn.q_per_s
        self.period = contact.period
        self.x = np.arange(self.n) * (self.period / self.n)
        # the motion sampled OVERSAMPLE times finer: its first n/2 harmonics nearly free of aliasing
        fine = np.arange(self.n * OVERSAMPLE) * (self.period / (self.n * OVERSAMPLE))
        Sf = np.asarray(contact.motion.evaluate(fine, (0, 1, 2)), dtype=float)
        S = self.S = Sf[:, ::OVERSAMPLE]
        self.s = qs * S[0]
        self.lever = dyn.evaluate(self.x).lever  # D does not depend on the speed
        m, ks, ca = loads.inertia, loads.spring_rate, loads.damping
        # G̃ = r²·A₂ + r·A₁ + A₀ (per unit of x: S′ per rad or mm), as the DFT of n samples would give it
        keep = self.n // 2 + 1
        spec = np.fft.rfft(np.stack([m * qs * Sf[2], ca * qs * Sf[1], ks * qs * Sf[0]]), axis=1)[:, :keep]
        self._A = spec / OVERSAMPLE
        self._S = np.fft.rfft(qs * Sf[0])[:keep] / OVERSAMPLE
        self.constant = loads.preload + loads.external  # F₀ + F_ext: the contact load at rest on the base circle
        self.stiffness = k = train.stiffness
        self.total_stiffness = k + ks
        self.omega_n = math.sqrt(self.total_stiffness / m)
        self.damper = 2.0 * train.damping_ratio * math.sqrt(self.total_stiffness * m)
        self.orders = np.arange(self.n // 2 + 1)
        # the harmonics a speed scan needs: beyond the last one with a part of G̃ above 1e-13 of that part's
        # largest, the contact force changes by less than the rounding of the FFT
        mags = np.abs(self._A) / np.maximum(np.abs(self._A).max(axis=1, keepdims=True), 1e-300)
        big = np.flatnonzero((mags > 1e-13).any(axis=0))
        self._scan = int(big[-1]) + 1 if big.size else 1

    # ---- frequencies ----------------------------------------------------------------------------
    @property
    def natural_frequency_hz(self) -> float:
        return self.omega_n / (2 * math.pi)

    def fundamental(self, rate: float) -> float:
        """Ω (rad/s): the cycle's angular frequency at the rate r (ω in rad/s, or v in mm/s)."""
        return 2 * math.pi * rate / self.period

    def _spectra(self, rates: np.ndarray, top: int | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Per rate (rows) and harmonic (the first ``top``, default all): (the harmonic's ω_j, U_j the
        deflection's DFT, F_j the contact force's DFT without its constant)."""
        r = rates[:, None]
        top = self.orders.size if top is None else top
        wj = (2 * math.pi / self.period) * r * self.orders[None, :top]
        L = self.loads
        den = self.total_stiffness - L.inertia * wj * wj + 1j * wj * (self.damper + L.damping)
        if np.any(den == 0):
            raise InputError("a harmonic of the motion sits exactly on the undamped natural frequency: there is no "
                             "periodic steady state; give the train some damping")
        A = self._A[:, :top]
        G = r * r * A[0] + r * A[1] + A[2]
        U = -G / den
        F = -(self.stiffness + 1j * wj * self.damper) * U
        if top == self.orders.size:  # the Nyquist term of a real signal is real
            U[:, -1], F[:, -1] = U[:, -1].real, F[:, -1].real
        return wj, U, F

    # ---- the steady state ---------------------------------------------------------------------
    def response(self, rate: float) -> VibrationSample:
        """The periodic steady state at the rate r (ω in rad/s, or v in mm/s)."""
        if not rate > 0:
            raise InputError(f"speed = {rate!r}: must be > 0")
        wj, U, F = self._spectra(np.array([float(rate)]))
        u = np.fft.irfft(U[0], self.n)
        du = np.fft.irfft(1j * wj[0] * U[0], self.n)
        force = np.fft.irfft(F[0], self.n) + self.constant
        D = self.lever
        with np.errstate(divide="ignore", invalid="ignore"):
            N = np.where(D > 0, force / D, np.nan)
            L, qs, S = self.loads, self.q_per_s, self.S
            G = (L.inertia * qs * S[2] * rate * rate + L.damping * qs * S[1] * rate + L.spring_rate * self.s
                 + self.constant)
            Nk = np.where(D > 0, G / D, np.nan)
        return VibrationSample(self.x, self.s, self.s + u, du, force, N, Nk, float(rate))

    def min_force(self, rates) -> np.ndarray:
        """The smallest generalised contact force F_c over the cycle at each rate (vectorised)."""
        rates = np.atleast_1d(np.asarray(rates, dtype=float))
        out = np.empty(rates.size)
        for lo in range(0, rates.size, 64):  # 64 speeds per inverse FFT: memory stays small
            _, _, F = self._spectra(rates[lo:lo + 64], self._scan)
            out[lo:lo + 64] = np.fft.irfft(F, self.n, axis=1).min(axis=1) + self.constant
        return out

    def separation_rate(self, rate: float, factor: float = SEARCH_FACTOR) -> tuple[float, float | None]:
        """(the lowest rate at which F_c first reaches 0, the parameter x where) — searched from rest to
        ``factor``·``rate``; (0, x) when the follower is not held at rest, (inf, None) when it never leaves."""
        at_rest = self.constant + (self.stiffness / self.total_stiffness) * self.loads.spring_rate * self.s
        if at_rest.min() <= 0:
            return 0.0, float(self.x[int(np.argmin(at_rest))])
        steps = int(math.ceil(math.log(100.0 * factor) / math.log(SCAN_RATIO)))
        ladder = rate * 0.01 * SCAN_RATIO ** np.arange(steps + 1)
        fmin = self.min_force(ladder)
        below = np.flatnonzero(fmin <= 0)
        if below.size == 0:
            return math.inf, None
        k = int(below[0])
        if k == 0:  # separates already at 1 % of the speed: between rest and there
            lo, flo = 0.0, float(at_rest.min())
        else:
            lo, flo = float(ladder[k - 1]), float(fmin[k - 1])
        if fmin[k] == 0:
            r = float(ladder[k])
        else:
            r = numeric.root(lambda z: self.min_force(np.maximum(z, 1e-300)), lo, float(ladder[k]), fa=flo,
                             fb=float(fmin[k]))
        resp = self.response(r)
        return r, float(self.x[int(np.argmin(resp.force))])

    def harmonics(self, rate: float, count: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The first ``count`` harmonics of the follower acceleration at the rate r: (orders 1…count, the
        kinematic amplitude, the elastic follower's), in q units/s² (m or rad)."""
        wj, U, _ = self._spectra(np.array([float(rate)]))
        j = np.arange(1, min(count, self.n // 2 - 1) + 1)
        scale = 2.0 / self.n  # a one-sided amplitude
        kin = scale * np.abs(self._S[j]) * wj[0, j] ** 2
        dyn = scale * np.abs(self._S[j] + U[0, j]) * wj[0, j] ** 2
        return j, kin, dyn


def dwell_runs(S: np.ndarray, tol: float = 1e-9) -> list[tuple[int, int]]:
    """Index runs [i, j) of a periodic sample where the motion dwells (S′ and S″ vanish), each at least
    three samples long; a run through the end of the cycle wraps (j > n, indices mod n)."""
    flat = (np.abs(S[1]) <= tol * max(float(np.abs(S[1]).max()), 1e-300)) & \
        (np.abs(S[2]) <= tol * max(float(np.abs(S[2]).max()), 1e-300))
    if flat.all() or not flat.any():
        return []
    return [(a, b) for a, b in _runs(flat) if b - a >= 3]


def _refined_min(x: np.ndarray, f: np.ndarray, period: float) -> tuple[float, float]:
    """The smallest value of a periodic sample, refined by the parabola through its neighbours, and where."""
    i = int(np.nanargmin(f))
    a, b, c = f[i - 1], f[i], f[(i + 1) % f.size]
    den = a - 2 * b + c
    if not (np.isfinite(den) and den > 0):
        return float(b), float(x[i])
    t = 0.5 * (a - c) / den
    h = period / f.size
    return float(b - 0.25 * (a - c) * t), float((x[i] + t * h) % period)


def analyse_vibration(contact: Contact, loads: Loads, train: Train, speed: float, *, harmonics: int = 12,
                      n: int = SAMPLES) -> VibrationReport:
    """The follower vibration at the design speed: deviation, residual vibration in dwells, contact
    force, separation speed, harmonics, and the findings ``FOLLOWER_SEPARATES_VIBRATION`` (error) and
    ``VIBRATION_RESONANCE`` (warning).  ``speed``: ω (rad/s), or v (mm/s) for a translating cam."""
    model = FollowerTrain(contact, loads, train, n=n)
    resp = model.response(speed)
    axis = contact.axis
    user = np.degrees if axis.rotating else (lambda v: v)
    lift = 180.0 / math.pi if contact.oscillating else 1e3  # q unit → lift unit (deg or mm)
    x, P = resp.x, model.period
    dev = np.abs(resp.w - resp.s)
    i = int(np.argmax(dev))
    deviation = Maximum(float(dev[i] * lift), float(user(x[i])))
    residual = _residual(model, resp, lift, user)
    N = resp.contact_force
    lo, at_lo = _refined_min(x, N, P)
    hi, at_hi = _refined_min(x, -N, P)
    force = Extreme(lo, float(user(at_lo)), -hi, float(user(at_hi)))
    r_sep, at_sep = model.separation_rate(speed)
    closed = axis.rotating
    unit = "rpm" if closed else "mm/s"
    sep = JumpSpeed(None, unit, None) if not math.isfinite(r_sep) else \
        JumpSpeed(r_sep / RPM if closed else r_sep, unit, float(user(at_sep)) if at_sep is not None else None)
    cycle_hz = model.fundamental(speed) / (2 * math.pi)
    orders, kin, dyn = model.harmonics(speed, harmonics)
    table = tuple(Harmonic(int(j), float(j * cycle_hz), float(a * lift), float(b * lift))
                  for j, a, b in zip(orders, kin, dyn, strict=True))
    near = max(1, round(model.natural_frequency_hz / cycle_hz))
    summary = VibrationSummary(model.natural_frequency_hz, cycle_hz, train.damping_ratio, axis.lift_unit.value,
                               deviation, residual, force, sep, near, table)
    findings = _separation(resp, model, user, axis.x_unit, speed, sep) + \
        _resonance(model, speed, cycle_hz)
    return VibrationReport(summary, tuple(findings))


def _residual(model: FollowerTrain, resp: VibrationSample, lift: float, user) -> Maximum | None:
    """The largest vibration about the static position in a dwell (lift units), and the dwell's start."""
    runs = dwell_runs(model.S)
    if not runs:
        return None
    best, at = -1.0, 0.0
    n, u = model.n, resp.w - resp.s
    for a, b in runs:
        idx = np.arange(a, b) % n
        s_dw = resp.s[idx[0]]  # the static deflection there: −k_s·s/(k + k_s)
        amp = float(np.max(np.abs(u[idx] + model.loads.spring_rate * s_dw / model.total_stiffness)))
        if amp > best:
            best, at = amp, float(resp.x[idx[0]])
    return Maximum(best * lift, float(user(at)))


def _separation(resp: VibrationSample, model: FollowerTrain, user, unit: str, speed: float,
                sep: JumpSpeed) -> list[Finding]:
    """FOLLOWER_SEPARATES_VIBRATION: the ranges where F_c < 0 at the design speed."""
    neg = resp.force < 0
    if not neg.any():
        return []
    n, F = model.n, resp.force
    h = model.period / n
    fix = "raise the spring preload or rate, stiffen the train, or run slower"
    if sep.value is not None:
        fix = f"the follower first leaves the cam at {sep.value:.6g} {sep.unit}; " + fix
    speed_txt = f"{speed / RPM:.6g} rpm" if model.contact.axis.rotating else f"{speed:.6g} mm/s"
    out = []
    for a, b in _runs(neg):
        idx = np.arange(a, b) % n
        worst = float(np.nanmin(resp.contact_force[idx])) if np.isfinite(resp.contact_force[idx]).any() else \
            float(F[idx].min())
        if b - a >= n:  # never in contact
            lo, hi = 0.0, float(user(model.period))
        else:  # the zero crossings, linear between the samples
            f0, f1 = F[(a - 1) % n], F[a % n]
            g0, g1 = F[(b - 1) % n], F[b % n]
            lo = float(user(((a - 1) + f0 / (f0 - f1)) * h % model.period))
            hi = float(user(((b - 1) + g0 / (g0 - g1)) * h % model.period))
        out.append(Finding(IssueCode.FOLLOWER_SEPARATES_VIBRATION, Severity.ERROR, lo, hi, worst, 0.0,
                           f"with the train's vibration the follower leaves the cam from {lo:.2f} to {hi:.2f} "
                           f"{unit} at {speed_txt} (contact force down to {worst:.6g} N); {fix}"))
    return out


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """Index runs [i, j) where a periodic mask holds (a run through the end wraps: j > n)."""
    if mask.all():
        return [(0, mask.size)]
    shift = int(np.flatnonzero(~mask)[0])
    f = np.roll(mask, -shift)
    edges = np.flatnonzero(np.diff(np.concatenate([[0], f.astype(int), [0]])))
    return [(int(a) + shift, int(b) + shift) for a, b in zip(edges[::2], edges[1::2], strict=True)]


def _resonance(model: FollowerTrain, speed: float, cycle_hz: float) -> list[Finding]:
    """VIBRATION_RESONANCE: a significant harmonic of the follower acceleration within
    :data:`RESONANCE_BAND` of the natural frequency."""
    fn = model.natural_frequency_hz
    top = int(math.floor(fn * (1 + RESONANCE_BAND) / cycle_hz))
    if top < 1:
        return []
    orders, kin, _ = model.harmonics(speed, top)
    big = kin.max() if kin.size else 0.0
    near = np.abs(orders * cycle_hz - fn) <= RESONANCE_BAND * fn
    hits = np.flatnonzero(near & (kin >= SIGNIFICANT_FRACTION * big))
    return [Finding(IssueCode.VIBRATION_RESONANCE, Severity.WARNING, None, None, float(orders[j] * cycle_hz), fn,
                    f"harmonic {int(orders[j])} of the follower acceleration ({orders[j] * cycle_hz:.6g} Hz, "
                    f"{100 * kin[j] / big:.3g} % of the largest) lies within {100 * RESONANCE_BAND:g} % of the "
                    f"train's natural frequency {fn:.6g} Hz: the train resonates; stiffen or lighten the train, "
                    "change the speed, or use a smoother motion law") for j in hits]
