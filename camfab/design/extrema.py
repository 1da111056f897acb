"""Peaks of S, S′, S″, S‴ over a program's cycle, and the continuity at its junctions.

Exact peaks take, on every piece of every segment (a piece lies between junctions and
internal law breaks), the piece's end values (one-sided: one ulp inside at an internal
break, so a jump reports the value on each side) and the values at the interior zeros of
the next derivative.  A standard law's candidates do not depend on the segment's lift or
span and are found once per law (:meth:`Law.extremum_candidates`); a polynomial segment's
come from the exact roots of its derivative.  Sampled peaks reproduce CAM-DAS: a fixed step
from 0 to the period inclusive, a sample on a junction counted on both sides.
"""
from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

from ..records import dataclass
from .segment import Segment

if TYPE_CHECKING:
    from .program import MotionProgram

__all__ = ["Peak", "Junction", "segment_candidates", "polynomial_roots", "exact_peaks", "sampled_peaks", "junctions"]


@dataclass(frozen=True)
class Peak:
    """Extremes of one quantity over the cycle (x in the program's unit)."""

    max: float
    min: float
    at_max: float
    at_min: float


@dataclass(frozen=True)
class Junction:
    """Continuity at a breakpoint.

    ``order`` is the highest derivative order k such that S…S⁽ᵏ⁾ are all
    continuous (−1 if S itself jumps); ``jumps`` holds |right − left| for
    S, S′, S″, S‴.
    """

    at: float
    order: int
    jumps: tuple[float, float, float, float]
    segment: int | None  # index of the segment starting here; None for internal breaks

    @property
    def continuity(self) -> str:
        return f"C{self.order}" if self.order >= 0 else "discontinuous"


def polynomial_roots(coeffs: Sequence[np.ndarray]) -> list[np.ndarray]:
    """``numpy.polynomial.polynomial.polyroots`` of each ascending coefficient array, bit for bit, with one
    eigenvalue call per degree instead of one per polynomial (the same companion matrices, which LAPACK's
    ``geev`` solves one by one either way): the exact peaks of a 20-knot table took 11.7 ms with a call per
    segment and derivative, 6.2 ms so (measured 2026-11-27)."""
    out: list[np.ndarray] = [np.array([])] * len(coeffs)
    trimmed = [np.trim_zeros(np.asarray(c, dtype=float), "b") for c in coeffs]
    by_degree: dict[int, list[int]] = {}
    for i, c in enumerate(trimmed):
        if len(c) == 2:
            out[i] = np.array([-c[0] / c[1]])
        elif len(c) > 2:
            by_degree.setdefault(len(c) - 1, []).append(i)
    for n, idx in by_degree.items():
        c = np.stack([trimmed[i] for i in idx])
        mat = np.zeros((len(idx), n, n))
        mat[:, np.arange(1, n), np.arange(n - 1)] = 1.0
        mat[:, :, -1] -= c[:, :-1] / c[:, -1:]
        roots = np.linalg.eigvals(mat)
        roots.sort(axis=-1)
        for i, r in zip(idx, roots, strict=True):
            out[i] = r
    return out


def _real_inside(r: np.ndarray) -> list[float]:
    """The real roots strictly inside (0, 1) (imaginary part below 1e-9)."""
    return [float(z.real) for z in np.atleast_1d(r) if abs(z.imag) < 1e-9 and 0.0 < z.real < 1.0]


def _polynomial_roots(seg: Segment, nu: int) -> list[float]:
    """Real zeros of a polynomial segment's S⁽ᵛ⁺¹⁾ strictly inside (0, 1)."""
    return _real_inside(polynomial_roots([seg.formula.coefficients(nu + 1)])[0])  # type: ignore[attr-defined]


def segment_candidates(seg: Segment, nu: int, roots: list[float] | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Local coordinates u and values of S⁽ᵛ⁾ at every extremum candidate of a segment (a polynomial
    segment's ``roots``, the real zeros of S⁽ᵛ⁺¹⁾ inside (0, 1), when already known)."""
    if seg.coeffs is None:
        # the law's candidates u and f⁽ᵛ⁾ there; the values as Segment.values computes them
        u, f = seg.formula.extremum_candidates(nu)
        out = seg.lift * f
        if nu == 0:
            out = out + seg.s0
        return u, out / seg.span**nu
    if roots is None:
        roots = _polynomial_roots(seg, nu)
    u = np.asarray([0.0, 1.0, *roots], dtype=float)
    return u, seg.values(u, nu)


def _pick(xs: np.ndarray, vals: np.ndarray) -> Peak:
    """Max and min of ``vals``, each at the first ``x`` (in order) within 1e-12 of it, relative to the
    values' own size (no absolute floor: a lift of 1e-12 mm has peaks of its own size, not 0)."""
    order = np.argsort(xs, kind="stable")
    xs, vals = xs[order], vals[order]
    span = float(vals.max() - vals.min())
    tol = 1e-12 * max(span, abs(float(vals.max())), abs(float(vals.min())))
    imax = int(np.flatnonzero(vals >= vals.max() - tol)[0])
    imin = int(np.flatnonzero(vals <= vals.min() + tol)[0])
    return Peak(float(vals[imax]), float(vals[imin]), float(xs[imax]), float(xs[imin]))


def exact_peaks(prog: MotionProgram) -> tuple[Peak, Peak, Peak, Peak]:
    """Analytic extremes of S, S′, S″, S‴ (see the module docstring)."""
    out = []
    for nu in range(4):
        xs, vals = [], []
        polys = [seg for seg in prog.segments if seg.coeffs is not None]
        found = polynomial_roots([seg.formula.coefficients(nu + 1) for seg in polys])  # type: ignore[attr-defined]
        roots = {id(seg): _real_inside(r) for seg, r in zip(polys, found, strict=True)}
        for seg in prog.segments:
            u, v = segment_candidates(seg, nu, roots.get(id(seg)))
            xs.append(seg.start + u * seg.span)
            vals.append(v)
        out.append(_pick(np.concatenate(xs), np.concatenate(vals)))
    return tuple(out)  # type: ignore[return-value]


def sampled_peaks(prog: MotionProgram, step: float) -> tuple[Peak, Peak, Peak, Peak]:
    """Extremes of S, S′, S″, S‴ at ``0, step, 2·step … period``; a sample on a junction
    counts on both sides."""
    n = int(round(prog.period / step))
    grid = np.arange(n + 1) * step
    xs, vals = [], []
    eps = 1e-9 * step
    for seg in prog.segments:
        sel = grid[(grid >= seg.start - eps) & (grid <= seg.end + eps)]
        u = np.clip((sel - seg.start) / seg.span, 0.0, 1.0)
        xs.append(sel)
        vals.append(np.array([seg.values(u, k) for k in range(4)]))
    x = np.concatenate(xs)
    v = np.concatenate(vals, axis=1)
    return tuple(_pick(x, v[k]) for k in range(4))  # type: ignore[return-value]


def _junction(at: float, left: np.ndarray, right: np.ndarray, scale: list[float], unit: float, tol: float,
              seg: int | None) -> Junction:
    jumps = np.abs(right - left)
    order = 3
    for j in range(4):
        if jumps[j] > tol * scale[j] + 1e-12 * unit:
            order = j - 1
            break
    return Junction(at, order, tuple(float(v) for v in jumps), seg)  # type: ignore[arg-type]


def junctions(prog: MotionProgram, tol: float, internal: bool) -> list[Junction]:
    """Continuity at every segment junction (360°→0° included) and, with ``internal``, at
    the internal breaks of piecewise laws; sorted by position.

    A jump counts as a discontinuity when it exceeds ``tol`` times the peak magnitude of
    that derivative over the cycle (at least 1e-2·u), plus 1e-12·u, where u = min(1, H) is the
    motion's size (H the largest |S|, mm or degrees): a motion smaller than 1 mm (1°) is judged
    relative to its own size, so a lift of 1e-12 mm jumps where a lift of 1 mm does.
    """
    peaks = prog.peaks("exact")
    u = min(1.0, max(abs(peaks[0].max), abs(peaks[0].min)))
    scale = [max(abs(p.max), abs(p.min), 1e-2 * u) for p in peaks]
    out = []
    for k, seg in enumerate(prog.segments):
        left = prog.segments[k - 1].end_values(True)
        right = seg.end_values(False)
        out.append(_junction(seg.start, left, right, scale, u, tol, k))
        if internal:
            for ub in seg.breaks:
                lo, hi = np.nextafter(ub, -1.0), np.nextafter(ub, 2.0)
                left = np.array([seg.value_at(float(lo), j) for j in range(4)])
                right = np.array([seg.value_at(float(hi), j) for j in range(4)])
                out.append(_junction(seg.start + ub * seg.span, left, right, scale, u, tol, None))
    return sorted(out, key=lambda j: j.at)
