"""The grooved (or ribbed) cylinder's triangles from its exact surfaces (its STL, without OpenCascade, cadquery or
trimesh).

The part (:mod:`camfab.cad.cylinder`, :mod:`camfab.cad.rib`): a groove's, the cylinder of outer radius
R_o = R + depth/2, length L along +Z from z = 0, an optional bore, minus the groove; a rib's, the root cylinder
(R_i = R − height/2) with the rib up to R_o.  Each surface is sampled on its own exact parametrisation, angles as
developed angles u = x/r (a point of the developed cylinder r at x has the polar angle 90° + σ·u):

* each flank (+z and −z), by (cam angle, radius): the developed flank on the cylinder r
  (``geometry.at_radius(r, flank)``), wrapped, on equally spaced radii from R_i to R_o (:func:`radial_rows`), at
  a rib's mesh cam angles θ, at a groove's flank's bottom-point cam angles (next);
* a groove's bottom, flat across: in the plane normal to the 3D pitch curve at each θ, the straight segment
  between the two flanks' points on R_i that lie in that plane (:func:`bottom_angles`; the STEP's sections,
  :func:`~camfab.cad.cylinder.groove_sections`, to 2e-13 mm), split into strips across (their :func:`twist`);
  a rib's top, the band of R_o between its flanks' top edges (:func:`zipper`);
* the sides' cylinder (a groove's R_o, a rib's R_i) as two bands: from z = 0 (a circle of equal steps) to the −z
  flank's edge on it, and from the +z flank's edge to z = L, each zipped between its two edges by developed angle;
* the end faces (the annulus between the sides' circle and the bore's, zipped, or a fan to the axis) and the bore.

Every vertex is a point of the exact part (to rounding).  The cam angles θ come from a bound: each flank edge's
chord error κ·h²/8 (κ its 3D curvature, on a dense grid) at most :data:`ALONG`·tol and its angular step on R_o at
most the one whose sagitta on R_o is tol/2; the radii from the flank's second difference across the depth (chord
error :data:`ACROSS`·tol) and each cell's twist (:data:`TWIST`·tol), the bottom's strips from its twist; the
circles' steps from their sagitta (tol/2).  The mesh is then **measured**, and its deviation (:func:`part_mesh`,
the STL's ``deviation_mm``) is that measurement: on the flanks and a groove's bottom, each cell's edge and diagonal
midpoints and both facets' centroids against a point of the exact surface (the flank's on the probe's radius, at
its interpolated cam angle moved by a Newton step along the track towards the probe; the bottom's at its
interpolated plane angle and place across), an upper bound of each probe's distance from the surface; on the
cylinders, each facet's largest depth inside its circle, exact; the end faces are planar (0).  A measurement above
tol doubles the sampling (up to :data:`REFINE` times), then the export is refused; so is a mesh over
:data:`MAX_TRIANGLES`.
"""
from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..design.cylindrical import wrap
from ..errors import ExportError
from ..textsafe import plain

__all__ = ["MAX_TRIANGLES", "part_mesh", "part_triangles", "part_stl", "zipper", "track_angles",
           "radial_rows", "circle_steps", "flank_rows", "cylinder_depth"]

#: the most triangles a grooved cylinder's mesh may have (50 bytes each in the STL: 100 MB)
MAX_TRIANGLES = 2_000_000
#: points of the dense grid of cam angles the sampling's bound is read on
DENSE = 2048
#: refinements (all directions doubled) after a measurement above the tolerance, before refusing
REFINE = 2
#: the shares of the tolerance the sampling's bounds aim at: along the track, across the depth, each cell's twist
ALONG, ACROSS, TWIST = 0.25, 0.25, 0.4
#: Newton steps at most finding the bottom's segments across (:func:`bottom_angles`)
PAIRING_STEPS = 20
#: the probes of each grid cell (corners a = (i, j), b = (i+1, j), c = (i+1, j+1), d = (i, j+1); facets abc, acd):
#: its four edges' and its diagonal's midpoints and both facets' centroids, as weights of the corners
_PROBES = np.array([[0.5, 0.5, 0, 0], [0.5, 0, 0, 0.5], [0, 0, 0.5, 0.5], [0.5, 0, 0.5, 0], [1 / 3, 1 / 3, 1 / 3, 0],
                    [1 / 3, 0, 1 / 3, 1 / 3]])


def _refuse(what: str, tol: float) -> ExportError:
    return ExportError(f"the cylinder's STL: {what} with the {tol:g} mm tolerance. Give a larger "
                       "[manufacturing] tolerance_mm")


def flank_at(geometry: Any, flank: int, t: np.ndarray, r: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The exact flank ``flank`` at the pairs (cam angle t, radius r) (``(p,)`` each): its developed angle u
    (x/r), its 3D point and the 3D point's derivative along t, ``(p,)``, ``(p, 3)``, ``(p, 3)``.  One evaluation
    of the developed flank for all the pairs (``DevelopedContact.on_radii``: the points bit for bit those of
    each radius's own evaluation) for a cylindrical roller, one per radius for a conical roller (whose section's
    second derivatives take one radius)."""
    from ..design.cylindrical import RollerShape

    t, r = np.asarray(t, dtype=float), np.asarray(r, dtype=float)
    x, d1 = np.empty((len(t), 2)), np.empty((len(t), 2))
    conical = geometry.cylinder.roller is RollerShape.CONICAL
    for at in [np.nonzero(r == v)[0] for v in np.unique(r)] if conical else [np.arange(len(r))] if len(r) else []:
        contact = geometry.at_radius(float(r[at[0]]), flank)
        e = contact.evaluate(t[at]) if conical else contact.on_radii(t[at], r[at])
        x[at], d1[at] = e.point, e.point_d1
    sense = geometry.mechanism.sense
    u = x[:, 0] / r
    a = 0.5 * math.pi + sense * u
    vel = np.column_stack([-sense * d1[:, 0] * np.sin(a), sense * d1[:, 0] * np.cos(a), d1[:, 1]])
    return u, wrap(sense, r, u, x[:, 1]), vel


def flank_rows(geometry: Any, flank: int, radii: np.ndarray, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The flank ``flank`` on each radius at the cam angles t (``(n,)``, or ``(len(radii), n)``: a row's own):
    developed angles ``(len(radii), n)`` and 3D points ``(len(radii), n, 3)``."""
    k, n = len(radii), t.shape[-1]
    u, p, _ = flank_at(geometry, flank, np.broadcast_to(t, (k, n)).ravel(),
                       np.repeat(np.asarray(radii, dtype=float), n))
    return u.reshape(k, n), p.reshape(k, n, 3)


def bottom_angles(geometry: Any, theta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The cam angles ``(n,)`` of the +z and the −z flank's points on the groove bottom that lie in the planes
    normal to the 3D pitch curve at the cam angles ``theta`` (the bottom's segments across, as the STEP's
    sections, :func:`~camfab.cad.cylinder.groove_sections`): Newton from theta along each flank's bottom edge."""
    from ..design.cylindrical import pitch_3d

    cyl, sense = geometry.cylinder, geometry.mechanism.sense
    R, r = cyl.radius_mm, np.full(len(theta), cyl.inner_radius_mm)
    C, T = geometry.at_radius(R).pitch(theta)
    a = 0.5 * math.pi + sense * C[:, 0] / R
    along = np.column_stack([-sense * np.sin(a) * T[:, 0], sense * np.cos(a) * T[:, 0], T[:, 1]])
    along /= np.linalg.norm(along, axis=1)[:, None]
    p0 = pitch_3d(geometry, theta)
    out = []
    for flank in (1, -1):
        t = np.array(theta, dtype=float)
        for _ in range(PAIRING_STEPS):
            _, p, v = flank_at(geometry, flank, t, r)
            step = np.einsum("ij,ij->i", p - p0, along) / np.einsum("ij,ij->i", v, along)
            t -= step
            if np.all(np.abs(step) < 1e-13):
                break
        else:
            raise ExportError("a flank of the groove does not meet the pitch curve's normal planes on the groove "
                              "bottom (Newton did not converge): check the design for a corner of the pitch curve (a "
                              "jump of the follower's velocity) or an undercut")
        out.append(t)
    return out[0], out[1]


def _curvature(p: np.ndarray, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """Speed |P′| and curvature of closed curves ``(..., n, 3)`` sampled at equal steps dt (central
    differences, periodic)."""
    d1 = (np.roll(p, -1, axis=-2) - np.roll(p, 1, axis=-2)) / (2 * dt)
    d2 = (np.roll(p, -1, axis=-2) - 2 * p + np.roll(p, 1, axis=-2)) / dt ** 2
    speed = np.linalg.norm(d1, axis=-1)
    return speed, np.linalg.norm(np.cross(d1, d2), axis=-1) / np.maximum(speed, 1e-300) ** 3


def circle_steps(r: float, tol: float) -> float:
    """The largest angle (rad) whose chord on the circle r lies within ``tol`` of it (sagitta r·(1 − cos(α/2)))."""
    return 2.0 * math.acos(max(1.0 - tol / r, -1.0))


def track_angles(geometry: Any, tol: float, scale: float = 1.0) -> np.ndarray:
    """The cam angles ``(n,)`` in [0, period) shared by both flanks on every radius: their density the larger of
    each flank edge's (groove bottom, outer radius) chord-error bound (κ·h²/8 ≤ :data:`ALONG`·tol, κ its 3D
    curvature) and its angular step on the outer radius (sagitta ≤ tol/2), read on a dense grid, times
    ``scale``."""
    cyl, period = geometry.cylinder, geometry.period
    radii = np.array([cyl.inner_radius_mm, cyl.outer_radius_mm])
    t = np.linspace(0.0, period, DENSE, endpoint=False)
    dt = period / DENSE
    density = np.zeros(DENSE)
    alpha = circle_steps(cyl.outer_radius_mm, tol / 2)
    for flank in (1, -1):
        u, p = flank_rows(geometry, flank, radii, t)
        speed, kappa = _curvature(p, dt)
        density = np.maximum(density, (speed * np.sqrt(kappa / (8 * ALONG * tol))).max(axis=0))  # |P′| / h
        du = (np.roll(u[1], -1) - np.roll(u[1], 1) + np.where(np.arange(DENSE) % (DENSE - 1) == 0, 2 * math.pi, 0.0))
        density = np.maximum(density, np.abs(du) / (2 * dt) / alpha)
    density *= scale
    cum = np.concatenate([[0.0], np.cumsum(0.5 * (density + np.roll(density, -1)) * dt)])  # trapezoids, periodic
    n = max(64, int(math.ceil(cum[-1])))
    if n > MAX_TRIANGLES:
        raise _refuse(f"{n} cam angles along the track would exceed the cap of {MAX_TRIANGLES} triangles", tol)
    return np.interp(np.arange(n) * cum[-1] / n, cum, np.append(t, period))


def twist(a0: np.ndarray, a1: np.ndarray, b0: np.ndarray, b1: np.ndarray) -> np.ndarray:
    """Each quad's (a0, a1 along one edge, b0, b1 along the other, ``(n, 3)`` each) departure from a plane along
    its normal: a quarter of the normal part of (b1 − b0) − (a1 − a0), the largest distance of the bilinear
    patch from the two triangles either diagonal makes."""
    normal = np.cross(a1 - a0 + b1 - b0, b0 - a0 + b1 - a1)
    normal /= np.maximum(np.linalg.norm(normal, axis=-1, keepdims=True), 1e-300)
    return 0.25 * np.abs(np.einsum("ij,ij->i", b1 - b0 - a1 + a0, normal))


def _across(p: np.ndarray) -> float:
    """A quad grid's (rows ``(2, n, 3)``, periodic along n) largest :func:`twist`."""
    return float(twist(p[0], np.roll(p[0], -1, axis=0), p[1], np.roll(p[1], -1, axis=0)).max())


def radial_rows(geometry: Any, tol: float, t: np.ndarray, scale: float = 1.0) -> np.ndarray:
    """The flanks' radii ``(k + 1,)`` from the groove bottom to the outer radius, equally spaced: k strips, so
    that the chord error across the depth, read from the second difference of the flank over the bottom,
    middle and outer radii (each strip's ≈ that over the whole depth / (2k²)), is at most :data:`ACROSS`·tol and
    each cell's :func:`twist` (≈ that of the cell across the whole depth / k) at most :data:`TWIST`·tol (k times
    ``scale``)."""
    cyl = geometry.cylinder
    radii = np.array([cyl.inner_radius_mm, 0.5 * (cyl.inner_radius_mm + cyl.outer_radius_mm), cyl.outer_radius_mm])
    k = 1.0
    for flank in (1, -1):
        _, p = flank_rows(geometry, flank, radii, t)
        bend = float(np.linalg.norm(p[0] - 2 * p[1] + p[2], axis=-1).max())
        k = max(k, math.sqrt(bend / (2 * ACROSS * tol)), _across(p[::2]) / (TWIST * tol))
    return np.linspace(cyl.inner_radius_mm, cyl.outer_radius_mm, int(math.ceil(scale * k)) + 1)


def zipper(ua: np.ndarray, ub: np.ndarray) -> np.ndarray:
    """Triangles ``(n + m, 3)`` of the band between two closed edges, A (``ua``, n developed angles, increasing
    over one turn) and B (``ub``, m), by indices (A's 0..n−1, B's n..n+m−1): walking both edges by angle, each
    step advances the one whose next vertex comes first, (a_i, a_i+1, b_j) or (a_i, b_j+1, b_j), all wound alike
    (counter-clockwise with A below B in (u, edge) coordinates).  Each triangle spans at most the larger of the
    two edges' steps in angle."""
    n, m = len(ua), len(ub)
    turn = 2 * math.pi
    ubs = np.mod(ub - ua[0], turn)
    key = np.where(ubs == 0.0, turn, ubs)
    j0 = int(np.argmax(key))  # B's last vertex at or before a_0
    order_b = (j0 + np.arange(m)) % m
    rel_b = ubs[order_b]
    rel_b[0] = key[j0] - turn
    keys = np.concatenate([ua[1:] - ua[0], [turn], rel_b[1:], [rel_b[0] + turn]])
    step_b = np.concatenate([np.zeros(n, dtype=bool), np.ones(m, dtype=bool)])[np.argsort(keys, kind="stable")]
    i = np.cumsum(~step_b) - (~step_b)  # A's vertex before each step
    j = np.cumsum(step_b) - step_b
    a0, a1 = i % n, (i + 1) % n
    b0, b1 = n + order_b[j % m], n + order_b[(j + 1) % m]
    return np.where(step_b[:, None], np.stack([a0, b1, b0], axis=1), np.stack([a0, a1, b0], axis=1))


def _cells(n: int, rows: np.ndarray) -> np.ndarray:
    """The corners (a, b, c, d) ``(cells, 4)`` of the periodic grid of rows of n vertices (row j's vertex i is
    ``rows[j] + i``), row by row."""
    i, j = np.meshgrid(np.arange(n), np.arange(len(rows) - 1))
    a, b = rows[j] + i, rows[j] + (i + 1) % n
    return np.stack([a, b, b - rows[j] + rows[j + 1], a - rows[j] + rows[j + 1]], axis=-1).reshape(-1, 4)


def _split(cells: np.ndarray) -> np.ndarray:
    """The cells' facets abc and acd ``(2·cells, 3)``."""
    return np.concatenate([cells[:, [0, 1, 2]], cells[:, [0, 2, 3]]])


def cylinder_depth(tri: np.ndarray, r: float) -> np.ndarray:
    """Each facet's (vertices on the cylinder r about Z) largest depth inside that cylinder: r minus its nearest
    distance to the axis (the origin's distance to its edges seen along Z; r if it surrounds the axis)."""
    p = tri[..., :2]
    e = np.roll(p, -1, axis=1) - p
    s = np.clip(-np.einsum("ijk,ijk->ij", p, e) / np.maximum(np.einsum("ijk,ijk->ij", e, e), 1e-300), 0.0, 1.0)
    near = np.linalg.norm(p + s[..., None] * e, axis=-1).min(axis=1)
    side = e[..., 0] * p[..., 1] - e[..., 1] * p[..., 0]  # the axis on the same side of every edge: inside
    return np.where(np.all(side > 0, axis=1) | np.all(side < 0, axis=1), r, r - near)


def _orient(verts: np.ndarray, faces: np.ndarray, direction: np.ndarray | float) -> np.ndarray:
    """``faces`` wound so that their normals (summed, area-weighted) point along ``direction``: a vector, or
    +1 (−1) away from (towards) the axis."""
    p = verts[faces]
    normal = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    if not isinstance(direction, np.ndarray):
        direction = direction * p.mean(axis=1) * np.array([1.0, 1.0, 0.0])
    return faces if float(np.sum(normal * direction)) > 0 else faces[:, ::-1]


def _next(i: np.ndarray, n: int, period: float) -> tuple[np.ndarray, np.ndarray]:
    """The columns after columns i of a periodic grid of n columns, and what to add to their cam angles (a
    period across the turn's end)."""
    return (i + 1) % n, np.where(i == n - 1, period, 0.0)


def _flank_error(geometry: Any, flank: int, t: np.ndarray, radii: np.ndarray, verts: np.ndarray,
                 cells: np.ndarray) -> float:
    """Largest distance from the flank's probes (:data:`_PROBES`, its cells row by row over the cam angles
    ``t`` ``(rows, n)``) to the exact flank: to its point on the probe's interpolated radius, at the interpolated
    cam angle moved by one Newton step along the track towards the probe's foot (a point of the surface: its
    distance bounds the probe's from the surface)."""
    n = t.shape[1]
    i, j = np.tile(np.arange(n), len(radii) - 1), np.repeat(np.arange(len(radii) - 1), n)
    after, on = _next(i, n, geometry.period)
    tp = (_PROBES @ np.stack([t[j, i], t[j, after] + on, t[j + 1, after] + on, t[j + 1, i]])).ravel()
    rp = (_PROBES @ np.stack([radii[j], radii[j], radii[j + 1], radii[j + 1]])).ravel()
    q = np.einsum("pk,ckx->pcx", _PROBES, verts[cells]).reshape(-1, 3)
    _, e, v = flank_at(geometry, flank, tp, rp)
    tp = tp + np.einsum("ij,ij->i", q - e, v) / np.einsum("ij,ij->i", v, v)
    return float(np.linalg.norm(flank_at(geometry, flank, tp, rp)[1] - q, axis=-1).max())


def _bottom_error(geometry: Any, t: np.ndarray, strips: int, verts: np.ndarray, cells: np.ndarray) -> float:
    """Largest distance from the bottom's probes (its cells row by row across, over the planes' cam angles t
    ``(n,)``) to the exact bottom at their interpolated (plane's cam angle, place across): the point that far
    along the segment between the flanks' bottom points in that plane (:func:`bottom_angles`)."""
    n = len(t)
    after, on = _next(np.arange(n), n, geometry.period)
    tau = _PROBES @ np.stack([t, t[after] + on, t[after] + on, t])  # (probes, n): the same in every strip
    r = np.full(tau.size, geometry.cylinder.inner_radius_mm)
    plus, minus = (flank_at(geometry, f, tf, r)[1].reshape(*tau.shape, 1, 3)
                   for f, tf in zip((1, -1), bottom_angles(geometry, tau.ravel()), strict=True))
    j = np.arange(strips)[:, None]
    s = (_PROBES @ np.stack([j, j, j + 1, j + 1]).reshape(4, -1) / strips).reshape(len(_PROBES), strips, 1, 1)
    exact = (1 - s) * plus.transpose(0, 2, 1, 3) + s * minus.transpose(0, 2, 1, 3)
    q = np.einsum("pk,ckx->pcx", _PROBES, verts[cells]).reshape(len(_PROBES), strips, n, 3)
    return float(np.linalg.norm(exact - q, axis=-1).max())


def _build(geometry: Any, tol: float, bore_mm: float, scale: float) -> tuple[np.ndarray, np.ndarray, float]:
    """One mesh (vertices, faces, measured deviation) with the sampling's densities times ``scale``."""
    cyl, sense = geometry.cylinder, geometry.mechanism.sense
    rib = cyl.rib_width_mm is not None
    r_in, r_out, length = cyl.inner_radius_mm, cyl.outer_radius_mm, cyl.length_mm
    r_side, r_bore = r_in if rib else r_out, 0.5 * bore_mm  # the sides' cylinder: a rib's root, a groove's outside
    if r_bore >= r_in:
        raise ExportError(f"the bore ([manufacturing] bore_mm = {bore_mm:g}) reaches the "
                          f"{'rib root' if rib else 'groove bottom'} (radius {r_in:g} mm): make it smaller")
    t = track_angles(geometry, tol, scale)
    radii = radial_rows(geometry, tol, t, scale)
    n, k = len(t), len(radii)
    outer = max(int(math.ceil(scale * 2 * math.pi / circle_steps(r_side, tol / 2))), 16)
    inner = max(int(math.ceil(scale * 2 * math.pi / circle_steps(r_bore, tol / 2))), 16) if r_bore > 0 else 0
    estimate = 4 * n * k + 2 * (n + outer) + 2 * (outer + max(inner, 1)) + 2 * inner + 2 * n
    if estimate > MAX_TRIANGLES:
        raise _refuse(f"{estimate} triangles ({n} cam angles, {k} radii) would exceed the cap of {MAX_TRIANGLES} "
                      "triangles", tol)
    # each flank's cam angles on every radius: a groove's, its bottom points' in the planes normal to the pitch
    # curve at t (the flat bottom's segments across); a rib's, t
    params = [np.broadcast_to(b, (k, n)) for b in ((t, t) if rib else bottom_angles(geometry, t))]
    rows = [flank_rows(geometry, f, radii, tf) for f, tf in zip((1, -1), params, strict=True)]  # +z, −z flank
    for u, _ in rows:
        if not np.all(np.diff(u, axis=1) > 0) or np.any(u[:, -1] - u[:, 0] >= 2 * math.pi):
            raise ExportError(f"a flank of the {'rib' if rib else 'groove'} turns back along the track (an "
                              "undercut): check the design")
    strips = 0 if rib else max(1, int(math.ceil(scale * _across(np.stack([rows[0][1][0], rows[1][1][0]]))
                                                / (TWIST * tol))))
    if estimate + 2 * n * strips > MAX_TRIANGLES:
        raise _refuse(f"{estimate + 2 * n * strips} triangles ({n} cam angles, {k} radii, {strips} strips across "
                      f"the bottom) would exceed the cap of {MAX_TRIANGLES} triangles", tol)
    across = np.arange(1, max(strips, 1))[:, None, None] / max(strips, 1)
    ring = 2 * math.pi * np.arange(outer) / outer
    hole = 2 * math.pi * np.arange(inner) / inner if r_bore > 0 else np.zeros(0)
    pts = [rows[0][1].reshape(-1, 3), rows[1][1].reshape(-1, 3),
           ((1 - across) * rows[0][1][0] + across * rows[1][1][0]).reshape(-1, 3),  # inside the bottom, +z to −z
           wrap(sense, r_side, ring, 0.0), wrap(sense, r_side, ring, length)]
    pts += ([wrap(sense, r_bore, hole, 0.0), wrap(sense, r_bore, hole, length)] if r_bore > 0 else
            [np.zeros((1, 3)), np.array([[0.0, 0.0, length]])])  # the bore's circles or the axis's ends
    plus, minus, inside, low, high, bore_low, bore_high = np.cumsum([0] + [len(p) for p in pts])[:7]
    verts = np.concatenate(pts)
    grids = [_cells(n, plus + n * np.arange(k)), _cells(n, minus + n * np.arange(k))]  # +z flank, −z flank

    def band(edge_a: int, ua: np.ndarray, edge_b: int, ub: np.ndarray) -> np.ndarray:
        local = zipper(ua, ub)
        return np.where(local < len(ua), edge_a + local, edge_b + local - len(ua))

    up, top = np.array([0.0, 0.0, 1.0]), (k - 1) * n
    edge = 0 if rib else k - 1  # the flanks' row on the sides' cylinder
    sides = [band(plus + edge * n, rows[0][0][edge], high, ring), band(minus + edge * n, rows[1][0][edge], low, ring)]
    pieces: list[tuple[np.ndarray, np.ndarray | float]] = [
        (_split(grids[0]), up if rib else -up), (_split(grids[1]), -up if rib else up), (sides[0], 1.0),
        (sides[1], 1.0)]
    if rib:  # the rib's top, between its flanks' top edges
        pieces.append((band(minus + top, rows[1][0][-1], plus + top, rows[0][0][-1]), 1.0))
    else:  # the groove's flat bottom, across from its +z flank to its −z flank
        grids.append(_cells(n, np.concatenate([[plus], inside + n * np.arange(strips - 1), [minus]])))
        pieces.append((_split(grids[2]), 1.0))
    depth = [float(cylinder_depth(verts[np.concatenate(sides)], r_side).max()),
             float(cylinder_depth(verts[pieces[-1][0]], r_out).max()) if rib else
             _bottom_error(geometry, t, strips, verts, grids[2])]
    if r_bore > 0:
        pieces += [(band(low, ring, bore_low, hole), -up), (band(high, ring, bore_high, hole), up),
                   (_split(_cells(inner, np.array([bore_low, bore_high]))), -1.0)]
        depth.append(float(cylinder_depth(verts[pieces[-1][0]], r_bore).max()))
    else:
        cell = np.arange(outer)
        pieces += [(np.stack([np.full(outer, centre), start + cell, start + (cell + 1) % outer], 1), d)
                   for centre, start, d in ((bore_low, low, -up), (bore_high, high, up))]
    faces = np.concatenate([_orient(verts, f, d) for f, d in pieces])
    dev = max(_flank_error(geometry, 1, params[0], radii, verts, grids[0]),
              _flank_error(geometry, -1, params[1], radii, verts, grids[1]), *depth)
    return verts, faces, dev


def part_mesh(geometry: Any, *, tol: float, bore_mm: float = 0.0) -> tuple[np.ndarray, np.ndarray, float]:
    """The grooved (or ribbed) cylinder's watertight mesh (see the module notes): vertices ``(v, 3)``, faces ``(m, 3)``
    (counter-clockwise seen from outside) and its measured deviation from the exact part (mm, ≤ ``tol``);
    refined up to :data:`REFINE` times while the measurement exceeds ``tol``, then refused (ExportError)."""
    if not (math.isfinite(tol) and tol > 0):
        raise ExportError(f"the cylinder's STL needs a positive tolerance, not {tol!r}: check "
                          "[manufacturing] tolerance_mm")
    scale = 1.0
    for _ in range(REFINE + 1):
        verts, faces, dev = _build(geometry, tol, bore_mm, scale)
        if dev <= tol:
            return verts, faces, dev
        scale *= 2.0
    raise _refuse(f"the mesh stays {dev:.3g} mm from the exact surfaces after {REFINE} refinements", tol)


def closed(faces: np.ndarray) -> bool:
    """Whether the faces (vertex indices) form closed surfaces with a consistent winding: every directed edge
    once and its reverse once (:func:`camfab.cad.stl.is_closed_surface` by indices)."""
    heads, tails = faces.astype(np.int64), np.roll(faces, -1, axis=1).astype(np.int64)
    n = int(faces.max()) + 1
    edges = np.sort((heads * n + tails).ravel())
    reverse = np.sort((tails * n + heads).ravel())
    return bool(faces.size) and bool(np.all(edges[1:] != edges[:-1])) and bool(np.array_equal(edges, reverse))


def part_triangles(geometry: Any, *, tol: float, bore_mm: float = 0.0) -> tuple[np.ndarray, float]:
    """The grooved (or ribbed) cylinder's triangles ``(m, 3, 3)`` (:func:`part_mesh`), checked closed and consistently
    wound (:func:`closed`) with a positive volume, and the mesh's measured deviation (mm)."""
    verts, faces, dev = part_mesh(geometry, tol=tol, bore_mm=bore_mm)
    tri = verts[faces]
    volume = float(np.einsum("ij,ij->", tri[:, 0], np.cross(tri[:, 1], tri[:, 2]))) / 6.0
    if not closed(faces) or not volume > 0:
        raise ExportError("the cylinder's mesh is not a closed, outward-facing surface: check the design "
                          "for an undercut or give another [manufacturing] tolerance_mm")
    return tri, dev


def part_stl(geometry: Any, *, tol: float, name: str = "cam", bore_mm: float = 0.0) -> tuple[bytes, float]:
    """Binary STL of the grooved (or ribbed) cylinder (:func:`part_triangles`) and its measured deviation (mm)."""
    from .stl import stl_bytes

    tri, dev = part_triangles(geometry, tol=tol, bore_mm=bore_mm)
    what = "ribbed" if geometry.cylinder.rib_width_mm is not None else "grooved"
    return stl_bytes(tri, f"camfab {plain(name)} units=mm tol={tol:g} {what} cylinder"), dev
