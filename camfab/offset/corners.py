"""The profile a roller really makes where its centre's path has a corner (a velocity jump, under ``--force``).

Where the follower's velocity jumps, the pitch curve (the roller centre's path) keeps its point ``C`` but turns
abruptly: its outward normal goes from ``n_L`` to ``n_R``.  The envelope formula ``P = C − R_r·n`` then jumps
from ``C − R_r·n_L`` to ``C − R_r·n_R``.  The part a cutter makes, and the roller then rolls on, is what no
roller position overlaps:

* a **concave corner** of the pitch curve (it turns away from the cam, e.g. where a constant-velocity rise
  leaves a dwell) leaves a gap, which the roller fills by rolling about ``C``: the profile gets the **arc of
  radius R_r centred at C** from ``C − R_r·n_L`` to ``C − R_r·n_R`` (tangent to both sides);
* a **convex corner** (it turns towards the cam, where a rise meets the dwell after it) makes the two sides
  overlap: each is cut back to the point ``K`` where they cross, a sharp corner of the profile.

An outward offset by ``d`` (a cutter's centre path) follows: the arc's radius becomes ``R_r − d`` (a cutter
as large as the roller cannot cut it), and ``K`` gets the round join of radius ``d`` a cutter makes going
round a corner.

:func:`roller_corners` finds the corners (none for a design without a velocity jump, so nothing changes then);
:func:`cornered_curve` builds the closed curve, parametrised piece by piece: the cam angle on the sides (minus
the cut-back stretches), and an added stretch for each arc.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..design.kinds import ContactKind
from ..discretize import ParametricCurve
from ..errors import GeometryError
from ..geom2d import J, cross, dot, rotate, unit

__all__ = ["RollerCorner", "roller_corners", "cornered_curve", "corner_note", "CORNER_GAP_MM"]

#: a jump of the roller envelope below this (mm) is no corner (it is far below every accepted tolerance's
#: hundredth, the continuity the discretisation asks of a curve)
CORNER_GAP_MM = 1e-9
_NEWTON_ITERS = 30


@dataclass(frozen=True)
class RollerCorner:
    """One corner of a roller's pitch curve and what the roller makes of it.

    ``at``: the parameter (cam angle, rad) of the corner; ``centre``: the pitch point C; ``n_left``,
    ``n_right``: the unit outward normals either side; ``turn``: the signed angle from ``n_left`` to
    ``n_right``; ``convex``: the sides overlap and are cut back to ``(t_left, t_right)``, whose common point is
    ``point`` (``K``); for a concave corner ``t_left == t_right == at`` and ``point`` is None.
    """

    at: float
    centre: np.ndarray
    n_left: np.ndarray
    n_right: np.ndarray
    turn: float
    convex: bool
    t_left: float
    t_right: float
    point: np.ndarray | None


def _user_deg(contact, t: float) -> str:
    return f"{float(contact.axis.to_user(t)):.6g}{contact.axis.x_symbol}"


def _orientation(contact) -> float:
    """+1 when the profile runs counter-clockwise with its parameter, −1 clockwise (shoelace of samples)."""
    t = np.linspace(0.0, contact.period, 4097)[:-1]
    p = contact.evaluate(t).point
    return 1.0 if float(cross(p, np.roll(p, -1, axis=0)).sum()) > 0 else -1.0


def roller_corners(contact) -> list[RollerCorner]:
    """The corners of a closed roller contact's pitch curve where its envelope jumps by more than
    :data:`CORNER_GAP_MM`; empty for anything else (flat or curved faces, knife edges, translating cams).

    Raises
    ------
    GeometryError
        When the two sides of a convex corner do not cross within the stretch to the next corner (the roller
        could not make the profile there).
    """
    rr = float(contact.roller_radius)
    if not contact.closed or rr <= 0 or contact.has_face or contact.kind is not ContactKind.ROLLER:
        return []
    bp = np.asarray(contact.breakpoints, dtype=float)
    at = bp[:-1]  # 0 (= the period) and every inner breakpoint
    left_w = np.diff(bp)[np.arange(at.size) - 1]  # the piece before each (wrapping for 0)
    delta = np.maximum(1e-7 * left_w, 8 * np.spacing(np.maximum(np.abs(bp[1:]), 1.0)[np.arange(at.size) - 1]))
    before = np.where(at == 0.0, contact.period, at)
    right = contact.evaluate(at)
    s1, s2 = contact.evaluate(before - delta), contact.evaluate(before - 2 * delta)
    p_left = 2 * s1.point - s2.point  # the limit from the left, O(δ²)
    v_left = 2 * s1.point_d1 - s2.point_d1
    gap = np.hypot(*(right.point - p_left).T)
    idx = np.flatnonzero(gap > CORNER_GAP_MM)
    if idx.size == 0:
        return []
    c = right.pitch[idx]
    n_l = unit(c - p_left[idx])
    n_r = right.normal[idx]
    turn = np.arctan2(cross(n_l, n_r), dot(n_l, n_r))
    convex = _orientation(contact) * turn > 0
    out = []
    corners_at = at[idx]
    for j, i in enumerate(idx.tolist()):
        t = float(at[i])
        if not convex[j]:
            out.append(RollerCorner(t, c[j], n_l[j], n_r[j], float(turn[j]), False, t, t, None))
            continue
        t1, t2, k = _crossing(contact, t, p_left[i], v_left[i], right.point[i], right.point_d1[i])
        if not (t1 < t < t2):
            raise GeometryError(f"the two sides of the roller profile at the velocity jump at {_user_deg(contact, t)} "
                                "do not cross near it, so no roller could make this profile: match the velocities "
                                "there")
        others = (corners_at - t + 0.5 * contact.period) % contact.period - 0.5 * contact.period
        others = others[others != 0.0]
        if np.any((others > t1 - t) & (others < t2 - t)):
            raise GeometryError(f"the roller profile at the velocity jump at {_user_deg(contact, t)} is cut back "
                                f"past the next velocity jump ({_user_deg(contact, t1 % contact.period)} to "
                                f"{_user_deg(contact, t2 % contact.period)}): the jumps are too close for the "
                                "roller; match the velocities there")
        out.append(RollerCorner(t, c[j], n_l[j], n_r[j], float(turn[j]), True, t1, t2, k))
    return out


def _crossing(contact, t: float, p_l, v_l, p_r, v_r) -> tuple[float, float, np.ndarray]:
    """Where the side before ``t`` (ending at ``p_l`` with derivative ``v_l``) crosses the side after it:
    ``(t1 < t, t2 > t, point)`` by Newton on ``P(t1) = P(t2)`` from the crossing of the two tangents."""
    period = contact.period
    m = np.column_stack([v_l, -v_r])
    try:
        a, b = np.linalg.solve(m, p_r - p_l)
    except np.linalg.LinAlgError:
        return t, t, p_r
    t1, t2 = t + min(float(a), 0.0), t + max(float(b), 0.0)
    scale = max(1.0, float(np.abs(p_r).max()))
    for _ in range(_NEWTON_ITERS):
        s = contact.evaluate(np.array([t1 % period, t2 % period]))
        f = s.point[0] - s.point[1]
        if float(np.hypot(*f)) <= 1e-13 * scale:
            return t1, t2, 0.5 * (s.point[0] + s.point[1])
        jac = np.column_stack([s.point_d1[0], -s.point_d1[1]])
        try:
            da, db = np.linalg.solve(jac, -f)
        except np.linalg.LinAlgError:
            break
        # stay on each side of the corner (halve a step that would cross it)
        t1 = t1 + da if t1 + da < t else 0.5 * (t1 + t)
        t2 = t2 + db if t2 + db > t else 0.5 * (t2 + t)
    return t, t, p_r


@dataclass(frozen=True)
class _Layout:
    """The pieces of a cornered curve in order: ``kind`` 0 = a stretch of the contact (parameter ``t0`` at its
    start, unit speed in the parameter), 1 = an arc (``centre``, ``radius``, start direction ``start`` from the
    centre, signed ``sweep``); ``tau`` the starts of the pieces in the new parameter, then its period."""

    kind: np.ndarray
    tau: np.ndarray
    t0: np.ndarray
    centre: np.ndarray
    radius: np.ndarray
    start: np.ndarray
    sweep: np.ndarray


def cornered_curve(contact, corners: list[RollerCorner], distance: float = 0.0) -> ParametricCurve:
    """The closed profile of ``contact`` (``distance = 0``) or its outward offset by ``distance`` (a cutter's
    centre path), made as a roller makes it at ``corners`` (see the module notes).

    Raises
    ------
    GeometryError
        A cutter (``distance``) at least as large as the roller: it cannot cut the roller-radius arcs.
    """
    rr = float(contact.roller_radius)
    d = float(distance)
    concave = [c for c in corners if not c.convex]
    if concave and d >= rr:
        raise GeometryError(f"the cutter radius {d:g} mm is not smaller than the roller radius {rr:g} mm: at the "
                            f"velocity jump at {_user_deg(contact, concave[0].at)} the profile has a concave arc of "
                            "the roller's radius, which it would gouge; choose a smaller tool")
    period = contact.period
    # the stretches of the contact between corners (from just after the first one), each followed by the next
    # corner's arc (concave, or convex with a cutter's round join)
    order = sorted(corners, key=lambda c: c.at)
    kinds: list[int] = []
    t0s: list[float] = []
    lens: list[float] = []
    arcs: list[tuple] = []
    speed = np.hypot(*contact.evaluate(np.array([c.at for c in order])).point_d1.T)
    for i, c in enumerate(order):
        nxt = order[(i + 1) % len(order)]
        end = nxt.t_left + (period if i == len(order) - 1 or nxt.t_left <= c.t_right else 0.0)
        kinds.append(0)
        t0s.append(c.t_right)
        lens.append(end - c.t_right)
        arcs.append((np.zeros(2), 0.0, np.zeros(2), 0.0))
        # then the corner nxt
        v = max(float(speed[(i + 1) % len(order)]), 1e-300)
        if not nxt.convex:
            r = rr - d
            if r * abs(nxt.turn) > 0:
                kinds.append(1)
                t0s.append(0.0)
                lens.append(max(rr * abs(nxt.turn) / v, 1e-9 * period))
                arcs.append((nxt.centre, r, -nxt.n_left, nxt.turn))
        elif d > 0:
            s = contact.evaluate(np.array([nxt.t_left % period, nxt.t_right % period]))
            n1, n2 = s.normal[0], s.normal[1]
            sweep = float(np.arctan2(cross(n1, n2), dot(n1, n2)))
            kinds.append(1)
            t0s.append(0.0)
            lens.append(max(d * abs(sweep) / v, 1e-9 * period))
            arcs.append((np.asarray(nxt.point, dtype=float), d, n1, sweep))
    tau = np.concatenate([[0.0], np.cumsum(lens)])
    lay = _Layout(np.array(kinds), tau, np.array(t0s), np.array([a[0] for a in arcs]), np.array([a[1] for a in arcs]),
                  np.array([a[2] for a in arcs]), np.array([a[3] for a in arcs]))
    # breakpoints: the ends of every piece and the contact's own breakpoints inside the stretches
    bp = np.asarray(contact.breakpoints, dtype=float)[:-1]
    inner = []
    for k in np.flatnonzero(lay.kind == 0).tolist():
        a = lay.t0[k]
        rel = (bp - a) % period
        rel = rel[(rel > 0) & (rel < lay.tau[k + 1] - lay.tau[k])]
        inner.append(lay.tau[k] + rel)
    breakpoints = np.unique(np.concatenate([tau] + inner))

    def evaluate(t, first: bool) -> np.ndarray:
        """``P`` (``first`` false) or ``dP/dτ`` at the new parameters ``t``."""
        t = np.asarray(t, dtype=float)
        k = np.clip(np.searchsorted(lay.tau, t, side="right") - 1, 0, lay.kind.size - 1)
        u = t - lay.tau[k]
        out = np.empty((u.size, 2))
        law = lay.kind[k] == 0
        if law.any():
            s = contact.evaluate((lay.t0[k[law]] + u[law]) % period)
            if first:
                out[law] = s.point_d1 * (1.0 + d * s.curvature)[:, None] if d else s.point_d1
            else:
                out[law] = s.point + d * s.normal if d else s.point
        ka = k[~law]
        if ka.size:
            w = lay.tau[ka + 1] - lay.tau[ka]
            direction = rotate(lay.start[ka], lay.sweep[ka] * u[~law] / w)
            if first:
                out[~law] = (lay.radius[ka] * lay.sweep[ka] / w)[:, None] * J(direction)
            else:
                out[~law] = lay.centre[ka] + lay.radius[ka, None] * direction
        return out

    return ParametricCurve(lambda t: evaluate(t, False), breakpoints, float(tau[-1]),
                           lambda t: evaluate(t, True), True)


def corner_note(contact, corners: list[RollerCorner]) -> str:
    """One line for a log: where the corners are and what the roller makes of them."""
    parts = [f"{_user_deg(contact, c.at)} ({'cut back to a corner' if c.convex else 'roller-radius arc'}, "
             f"{math.degrees(abs(c.turn)):.3g}° turn)" for c in corners[:5]]
    more = f" and {len(corners) - 5} more" if len(corners) > 5 else ""
    return ", ".join(parts) + more
