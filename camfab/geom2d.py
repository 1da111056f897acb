"""Plane geometry: vector operations on ``(..., 2)`` arrays, arc and bulge conversions, and :class:`ArcChain`.

Millimetres in the XY plane; angles in radians, counter-clockwise positive.  A *signed sweep* is
negative for a clockwise arc; a *bulge* is ``tan(sweep / 4)`` (the DXF LWPOLYLINE convention), so it
has the sign of the sweep, is 0 for a straight line and 1 for a counter-clockwise half circle.

:class:`ArcChain` is the one value that carries lines and arcs from a discretisation to the writers:
the DXF, STEP and STL exporters and the G-code contour all read it.

``ezdxf.math`` has the same scalar bulge conversions (``bulge_center``, ``bulge_to_arc``), but they
round differently from the formulas here, which the written files depend on bit for bit, and they are
no faster (``benchmarks/bench_geom2d.py``: 1.8 µs per ``bulge_center`` call, 1.7 µs per
:func:`bulge_centre`; a whole chain's centres come vectorised from :meth:`ArcChain.from_bulges` at 0.18 µs
per arc on a 518-arc profile, 0.5–0.7 µs on ~100 arcs), so they serve the tests as an independent reference.
"""
from __future__ import annotations

import math
from collections.abc import Iterator, Sequence

import numpy as np

from .errors import GeometryError
from .records import dataclass, replace

__all__ = [
    "TWO_PI",
    "FULL_CIRCLE_TOL_MM",
    "J",
    "pair",
    "cross",
    "dot",
    "rotate",
    "rotate_cs",
    "unit",
    "arc_sweep",
    "bulge_centre",
    "bulge_midpoint",
    "ArcChain",
    "chord_sagitta",
    "chord_large_arcs",
]

#: a full turn in radians
TWO_PI = 2.0 * math.pi
#: an arc whose start and end are closer than this (mm) is a full circle (:func:`arc_sweep`)
FULL_CIRCLE_TOL_MM = 1e-9


# --------------------------------------------------------------------------------------
# vector operations on (..., 2) arrays
# --------------------------------------------------------------------------------------
def pair(a, b) -> np.ndarray:
    """``np.stack([a, b], axis=-1)`` of two arrays of one shape, the same array without ``np.stack``'s generic
    checks (~3 µs instead of ~9 µs; a cylindrical cam's check makes ~1 000 of them in its Newton loops).
    Arrays of different shapes go to ``np.stack``, which refuses them as before."""
    a, b = np.asarray(a), np.asarray(b)
    if a.shape != b.shape:
        return np.stack([a, b], axis=-1)
    out = np.empty(a.shape + (2,), dtype=np.result_type(a, b))
    out[..., 0] = a
    out[..., 1] = b
    return out


def J(v: np.ndarray) -> np.ndarray:
    """``v`` turned by +90° (the rotation J: ``(x, y) -> (-y, x)``); shape ``(..., 2)`` kept."""
    return pair(-v[..., 1], v[..., 0])


def cross(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """z component of ``u × v`` for ``(..., 2)`` arrays (broadcasting): ``(...)``."""
    return u[..., 0] * v[..., 1] - u[..., 1] * v[..., 0]


def dot(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """``u · v`` for ``(..., 2)`` arrays (broadcasting): ``(...)``."""
    return u[..., 0] * v[..., 0] + u[..., 1] * v[..., 1]


def rotate(v: np.ndarray, angle) -> np.ndarray:
    """``v`` ``(..., 2)`` turned counter-clockwise by ``angle`` (radians, broadcast over ``...``)."""
    return rotate_cs(v, np.cos(angle), np.sin(angle))


def rotate_cs(v: np.ndarray, c, s) -> np.ndarray:
    """``v`` ``(..., 2)`` turned counter-clockwise by the angle whose cosine and sine are ``c``, ``s``
    (broadcast over ``...``; for callers that already have them)."""
    return pair(c * v[..., 0] - s * v[..., 1], s * v[..., 0] + c * v[..., 1])


def unit(v: np.ndarray) -> np.ndarray:
    """``v`` ``(..., 2)`` scaled to length 1 (zero vectors stay zero)."""
    n = np.hypot(v[..., 0], v[..., 1])
    return v / np.where(n > 0, n, 1.0)[..., None]


# --------------------------------------------------------------------------------------
# arcs and bulges (scalar: one entity)
# --------------------------------------------------------------------------------------
def arc_sweep(start: Sequence[float] | np.ndarray, end: Sequence[float] | np.ndarray,
              center: Sequence[float] | np.ndarray, clockwise: bool) -> float:
    """Signed sweep of an arc from ``start`` to ``end`` about ``center``.

    Parameters
    ----------
    start, end, center : sequence of float
        Points ``(x, y)`` in mm.
    clockwise : bool
        Direction of travel (G2 when true).

    Returns
    -------
    float
        Sweep in radians, in ``(0, 2π]`` for counter-clockwise arcs and ``[-2π, 0)`` for clockwise
        ones.  Start and end within :data:`FULL_CIRCLE_TOL_MM` give a full circle.
    """
    sx, sy = float(start[0]), float(start[1])
    ex, ey = float(end[0]), float(end[1])
    cx, cy = float(center[0]), float(center[1])
    if math.hypot(ex - sx, ey - sy) <= FULL_CIRCLE_TOL_MM:
        return -TWO_PI if clockwise else TWO_PI
    a0 = math.atan2(sy - cy, sx - cx)
    a1 = math.atan2(ey - cy, ex - cx)
    if clockwise:
        return -((a0 - a1) % TWO_PI)
    return (a1 - a0) % TWO_PI


def bulge_centre(p0: np.ndarray, p1: np.ndarray, bulge: float) -> np.ndarray:
    """Centre ``(2,)`` of the arc from ``p0`` to ``p1`` (``(2,)`` mm) with this non-zero bulge.

    The centre lies on the chord's perpendicular bisector at ``(c/2) / tan(sweep/2)`` from the
    chord's middle (``c`` the chord length), to the left of the chord for a counter-clockwise arc
    of less than a half turn.  (Scalar float arithmetic: 4× faster than numpy on two numbers.)
    """
    x0, y0, x1, y1 = float(p0[0]), float(p0[1]), float(p1[0]), float(p1[1])
    dx, dy = x1 - x0, y1 - y0
    c = math.hypot(dx, dy)
    h = c / 2 / math.tan(4 * math.atan(bulge) / 2)
    return np.array([(x0 + x1) / 2 + (-dy / c) * h, (y0 + y1) / 2 + (dx / c) * h])


def bulge_midpoint(p0: np.ndarray, p1: np.ndarray, bulge: float) -> np.ndarray:
    """The point ``(2,)`` halfway along the arc from ``p0`` to ``p1`` with this bulge.

    It lies ``bulge · c / 2`` (the sagitta) from the chord's middle, to the right of the chord for a
    counter-clockwise arc.
    """
    x0, y0, x1, y1 = float(p0[0]), float(p0[1]), float(p1[0]), float(p1[1])
    dx, dy = x1 - x0, y1 - y0
    c = math.hypot(dx, dy)
    return np.array([(x0 + x1) / 2 + (dy / c) * bulge * c / 2, (y0 + y1) / 2 + (-dx / c) * bulge * c / 2])


def _bulge_centres(starts: np.ndarray, ends: np.ndarray, bulges: np.ndarray) -> np.ndarray:
    """Vectorised :func:`bulge_centre`: ``(n, 2)`` centres, NaN rows for lines (bulge 0)."""
    arc = bulges != 0
    d = ends - starts
    c = np.hypot(d[:, 0], d[:, 1])
    safe_c = np.where(c > 0, c, 1.0)
    half = np.where(arc, 2.0 * np.arctan(bulges), 1.0)
    h = np.where(arc, 0.5 * c / np.tan(half), 0.0)
    centres = 0.5 * (starts + ends) + J(d) / safe_c[:, None] * h[:, None]
    return np.where(arc[:, None], centres, np.nan)


# --------------------------------------------------------------------------------------
# the arc-chain value
# --------------------------------------------------------------------------------------
@dataclass(frozen=True, eq=False)
class ArcChain:
    """An ordered chain of straight lines and circular arcs: what discretisations produce and writers read.

    Entity ``i`` runs from ``starts[i]`` to ``ends[i]``; a closed chain's entities join up
    (``ends[i] == starts[i + 1]``, the last ending on the first start), an open chain ends at
    ``ends[-1]``.  Writers keep the numbers as given: a DXF LWPOLYLINE takes the start points and
    bulges, R12 arcs, splines, STEP wires and STL facets the arcs those define (vertices and bulges),
    G-code the start, end and centre of every entity and the sign of its sweep.

    Attributes
    ----------
    starts, ends : (n, 2) float ndarray, mm
        Entity end points.
    centres : (n, 2) float ndarray, mm
        Arc centres; NaN rows for lines.
    sweeps : (n,) float ndarray, rad
        Signed sweeps, > 0 counter-clockwise, 0 for lines.
    bulges : (n,) float ndarray
        ``tan(sweep / 4)`` of every entity (0 for lines).
    closed : bool
        Whether the last entity returns to the first start.
    max_deviation : float or None, mm
        The measured two-way maximum distance from the exact curve the chain stands for (None when
        the chain is exact or was not measured).
    """

    starts: np.ndarray
    ends: np.ndarray
    centres: np.ndarray
    sweeps: np.ndarray
    bulges: np.ndarray
    closed: bool = True
    max_deviation: float | None = None

    def __post_init__(self) -> None:
        n = len(self.bulges)
        shapes = {"starts": (n, 2), "ends": (n, 2), "centres": (n, 2), "sweeps": (n,), "bulges": (n,)}
        for name, shape in shapes.items():
            if np.shape(getattr(self, name)) != shape:
                raise GeometryError(f"ArcChain.{name} has shape {np.shape(getattr(self, name))}, expected "
                                    f"{shape} for {n} entities; give one row per entity")

    # ---- constructors ---------------------------------------------------------------
    @classmethod
    def from_bulges(cls, points, bulges, *, closed: bool = True,
                    max_deviation: float | None = None) -> ArcChain:
        """The chain of a (LW)POLYLINE: ``points`` ``(m, 2)`` and the bulge of the entity leaving each.

        A closed chain has ``m`` entities (vertex ``m - 1`` back to vertex 0); an open one ``m - 1``
        (the last bulge, if given, is ignored).
        """
        p = np.asarray(points, dtype=float).reshape(-1, 2)
        b = np.asarray(bulges, dtype=float).reshape(-1)
        if b.size != p.shape[0]:
            raise GeometryError(f"{b.size} bulges for {p.shape[0]} vertices; give one bulge per vertex")
        starts, ends = (p, np.roll(p, -1, axis=0)) if closed else (p[:-1], p[1:])
        b = b if closed else b[:-1]
        return cls(starts, ends, _bulge_centres(starts, ends, b), 4.0 * np.arctan(b), b, closed,
                   max_deviation)

    @classmethod
    def from_polyline(cls, points, *, closed: bool = True,
                      max_deviation: float | None = None) -> ArcChain:
        """Straight lines through ``points`` ``(m, 2)``; a closed chain drops a repeated last vertex."""
        p = np.asarray(points, dtype=float).reshape(-1, 2)
        if closed and p.shape[0] > 1 and np.array_equal(p[0], p[-1]):
            p = p[:-1]
        return cls.from_bulges(p, np.zeros(p.shape[0]), closed=closed, max_deviation=max_deviation)

    def with_deviation(self, max_deviation: float | None) -> ArcChain:
        """The same chain with another measured deviation."""
        return replace(self, max_deviation=max_deviation)

    # ---- derived values ----------------------------------------------------------------
    @property
    def n_entities(self) -> int:
        """Number of entities (arcs and lines)."""
        return int(len(self.bulges))

    @property
    def is_line(self) -> np.ndarray:
        """``(n,)`` bool: the entities that are straight lines."""
        return self.sweeps == 0

    @property
    def radii(self) -> np.ndarray:
        """``(n,)`` arc radii in mm (``inf`` for lines)."""
        return np.where(self.is_line, np.inf, np.hypot(*(self.starts - self.centres).T))

    @property
    def points(self) -> np.ndarray:
        """The vertices ``(m, 2)``: the entity starts, and for an open chain its last end."""
        return self.starts if self.closed else np.vstack([self.starts, self.ends[-1:]])

    @property
    def lwpolyline(self) -> np.ndarray:
        """``(m, 3)`` rows ``(x, y, bulge)`` of a DXF LWPOLYLINE (an open chain's last bulge is 0)."""
        bulges = self.bulges if self.closed else np.append(self.bulges, 0.0)
        return np.column_stack([self.points, bulges])

    def segments(self) -> Iterator[tuple[np.ndarray, np.ndarray, float]]:
        """Yield ``(p0, p1, bulge)`` for every entity in order."""
        for i in range(self.n_entities):
            yield self.starts[i], self.ends[i], float(self.bulges[i])

    # ---- geometry of closed chains (the bulge model: vertices and bulges) ----------------
    def _require_closed(self, what: str) -> None:
        if not self.closed:
            raise GeometryError(f"the {what} of an open arc chain is not defined; close the chain first")

    def area(self) -> float:
        """Exact signed area (mm², > 0 for a counter-clockwise closed chain), arcs included."""
        self._require_closed("area")
        p, q = self.starts, np.roll(self.starts, -1, axis=0)
        poly = 0.5 * float(np.sum(p[:, 0] * q[:, 1] - q[:, 0] * p[:, 1]))
        c = np.hypot(*(q - p).T)
        th = 4 * np.arctan(np.abs(self.bulges))
        with np.errstate(divide="ignore", invalid="ignore"):
            r = np.where(th > 0, c / (2 * np.sin(th / 2)), 0.0)
        return poly + float(np.sum(np.sign(self.bulges) * r**2 / 2 * (th - np.sin(th))))

    def flatten(self, tol: float) -> np.ndarray:
        """Vertices ``(m, 2)`` of a polyline whose chords lie within ``tol`` mm (sagitta) of every arc.

        Every vertex is on the chain; a closed chain's first vertex is not repeated at the end, an
        open chain's last end is included.
        """
        return self.flatten_sagitta(tol)[0]

    def flatten_sagitta(self, tol: float) -> tuple[np.ndarray, float]:
        """:meth:`flatten`'s vertices and its largest sagitta: the largest distance (mm, ``<= tol``; 0 for a chain
        of lines) between one of its chords and the arc it stands for, ``2 r sin²(φ/4)`` for a chord of angle φ
        on an arc of radius r.  Both ways, the polyline is within that distance of the chain."""
        out = []
        sagitta = 0.0
        for p0, p1, b in self.segments():
            out.append(p0[None, :])
            if abs(b) < 1e-15:
                continue
            th = 4 * math.atan(b)
            c = math.hypot(*(p1 - p0))
            r = c / (2 * math.sin(abs(th) / 2))
            n = max(1, math.ceil(abs(th) / (2 * math.acos(max(-1.0, 1 - tol / r)))))
            sagitta = max(sagitta, 2.0 * r * math.sin(abs(th) / (4 * n)) ** 2)
            centre = bulge_centre(p0, p1, b)
            a0 = math.atan2(*(p0 - centre)[::-1])
            ang = a0 + th * np.arange(1, n) / n
            out.append(centre + r * np.column_stack([np.cos(ang), np.sin(ang)]))
        if not self.closed:
            out.append(self.ends[-1:])
        return np.concatenate(out), sagitta

    def offset_g1(self, distance: float, *, angle_tol: float = 1e-9) -> ArcChain | None:
        """The closed chain offset outward by ``distance`` mm (inward if negative), exactly, or None.

        For a tangent-continuous chain the offset of every arc is the concentric arc with the
        same sweep and of every line the parallel line, so the offset chain is the vertices moved
        along their common normal with the bulges unchanged.  Returns None when the chain has a
        corner (tangent jump above ``angle_tol`` rad) or an arc would shrink to radius ≤ 0.
        """
        self._require_closed("G1 offset")
        p, q = self.starts, np.roll(self.starts, -1, axis=0)
        d = q - p
        chord = np.hypot(d[:, 0], d[:, 1])
        th = 4 * np.arctan(self.bulges)
        u = d / chord[:, None]
        t0 = rotate(u, -th / 2)  # start tangent = chord turned back by half the sweep
        t_in = np.roll(rotate(u, th / 2), 1, axis=0)  # end tangent (chord turned on), arriving at each vertex
        if np.any(np.abs(cross(t_in, t0)) > angle_tol) or np.any(dot(t_in, t0) <= 0):
            return None
        ccw = self.area() > 0
        sign = 1.0 if ccw else -1.0  # outward = right of the direction of travel on a ccw chain
        normal = sign * -J(t0)
        with np.errstate(divide="ignore", invalid="ignore"):
            radius = np.where(th != 0, chord / (2 * np.abs(np.sin(th / 2))), np.inf)
        # an arc turning the chain's way (convex) grows by the distance, the other way shrinks
        grow = np.where(np.sign(th) == sign, 1.0, -1.0)
        if np.any((th != 0) & (radius + grow * distance <= 0)):
            return None
        return ArcChain.from_bulges(p + distance * normal, self.bulges.copy())

    def reversed(self) -> ArcChain:
        """The same chain traversed the other way (sweeps and bulges change sign)."""
        return ArcChain(self.ends[::-1].copy(), self.starts[::-1].copy(), self.centres[::-1].copy(),
                        -self.sweeps[::-1], -self.bulges[::-1], self.closed, self.max_deviation)


# --------------------------------------------------------------------------------------
# arcs too large for a controller or a CAD kernel
# --------------------------------------------------------------------------------------
def chord_sagitta(radius, sweep):
    """Largest distance (mm) between an arc of ``radius`` and ``sweep`` (rad) and its chord: the sagitta
    ``r (1 - cos(sweep / 2)) = 2 r sin²(sweep / 4)`` (≈ ``c² / (8 r)`` for a chord ``c``), written without the
    cancellation of ``1 - cos`` so that it stays exact for radii of 10⁷ mm; broadcasts."""
    return 2.0 * np.asarray(radius, dtype=float) * np.sin(np.abs(np.asarray(sweep, dtype=float)) / 4.0) ** 2


def chord_large_arcs(chain: ArcChain, max_radius_mm: float, max_sagitta_mm: float) -> tuple[ArcChain, float]:
    """Replace every arc of radius above ``max_radius_mm`` by equal chords, each within ``max_sagitta_mm`` of it.

    An arc of radius ``r`` and sweep ``θ`` becomes ``n = ceil(|θ| / α)`` lines through points of the arc, with
    ``α = 4 asin(sqrt(s / (2 r)))`` the largest sweep whose chord has sagitta ``s`` (see :func:`chord_sagitta`).
    The end points of every entity are kept bit for bit (so a closed chain stays closed), lines and smaller
    arcs are untouched.  Each chord lies within its sagitta of the arc and the arc within the sagitta of the
    chords, so the two-way distance from any curve grows by at most the returned sagitta (the triangle
    inequality); the tangent turns by half a chord's sweep at each new vertex (``c / (2 r)`` rad, below
    ``sqrt(2 s / r)``).

    Parameters
    ----------
    chain : ArcChain
    max_radius_mm : float
        Arcs with a larger radius become lines.
    max_sagitta_mm : float
        Largest distance (mm) allowed between an arc and its chords (> 0).

    Returns
    -------
    (ArcChain, float)
        The chain (the same object when no arc is that large; otherwise ``max_deviation`` is the old one plus
        the sagitta, an upper bound: measure again where the exact curve is known) and the largest sagitta
        of the chords written (0 when none), mm.
    """
    if not (max_sagitta_mm > 0 and max_radius_mm > 0):
        raise GeometryError(f"chord_large_arcs needs a positive radius limit and sagitta, got {max_radius_mm!r} "
                            f"and {max_sagitta_mm!r} mm")
    radii = chain.radii
    big = ~chain.is_line & (radii > max_radius_mm)
    if not big.any():
        return chain, 0.0
    th = np.abs(chain.sweeps)
    alpha = 4.0 * np.arcsin(np.sqrt(np.minimum(max_sagitta_mm / (2.0 * np.where(big, radii, 1.0)), 0.5)))
    n = np.where(big, np.maximum(1, np.ceil(th / alpha - 1e-12)), 1).astype(int)
    sag = float(np.max(chord_sagitta(np.where(big, radii, 0.0), th / n)))
    starts, ends, centres, sweeps, bulges = [], [], [], [], []
    for i in range(chain.n_entities):
        if not big[i]:
            starts.append(chain.starts[i:i + 1])
            ends.append(chain.ends[i:i + 1])
            centres.append(chain.centres[i:i + 1])
            sweeps.append(chain.sweeps[i:i + 1])
            bulges.append(chain.bulges[i:i + 1])
            continue
        c, r, k = chain.centres[i], radii[i], n[i]
        a0 = math.atan2(chain.starts[i, 1] - c[1], chain.starts[i, 0] - c[0])
        ang = a0 + chain.sweeps[i] * np.arange(1, k) / k
        mid = c + r * np.column_stack([np.cos(ang), np.sin(ang)])
        pts = np.vstack([chain.starts[i:i + 1], mid, chain.ends[i:i + 1]])
        starts.append(pts[:-1])
        ends.append(pts[1:])
        centres.append(np.full((k, 2), np.nan))
        sweeps.append(np.zeros(k))
        bulges.append(np.zeros(k))
    dev = None if chain.max_deviation is None else chain.max_deviation + sag
    out = ArcChain(np.concatenate(starts), np.concatenate(ends), np.concatenate(centres), np.concatenate(sweeps),
                   np.concatenate(bulges), chain.closed, dev)
    return out, sag
