"""The profile a follower really makes where its velocity jumps (a design written under ``--force``).

Where the follower's velocity jumps, the envelope formula of the profile jumps too.  The part a cutter makes, and
the follower then runs on, is what no follower position overlaps.  At such a junction (cam angle ``φc``):

* **roller** (and curved face, a circle of radius R about its centre): the roller centre's path (the pitch curve)
  keeps its point ``C`` but turns, its outward normal going from ``n_L`` to ``n_R``, and ``P = C − R·n`` jumps
  from ``C − R·n_L`` to ``C − R·n_R``.  Where the pitch curve turns away from the cam (a constant-velocity rise
  leaving a dwell) the two ends leave a gap, which the roller fills by rolling about ``C``: the profile gets the
  **arc of radius R about C** between them, tangent to both sides;
* **flat face**: the face line at ``φc`` is the same on both sides and the contact point jumps along it; where it
  jumps forward the profile gets the **straight stretch of the face line** between the two contact points;
* where the two ends overlap instead (the pitch curve turns towards the cam, the contact point jumps back), each
  side is **cut back** to the point ``K`` where they cross: a sharp corner.

An outward offset by ``d`` (a cutter's centre path) follows: an arc's radius becomes ``R − d`` (a cutter as
large as the roller cannot cut it), a face stretch moves out by ``d``, and ``K`` gets the round join of radius
``d`` a cutter makes going round a corner.

:func:`profile_corners` finds the corners (none for a design without a velocity jump, which then keeps its
plain curve); :func:`cornered_curve` builds the closed curve, parametrised piece by piece: the cam angle on the
sides (minus the cut-back stretches), and an added stretch for each arc or face stretch.
"""
from __future__ import annotations

import math

import numpy as np

from ..design.kinds import ContactKind
from ..discretize import ParametricCurve
from ..errors import GeometryError
from ..geom2d import J, cross, dot, rotate, unit
from ..records import dataclass

__all__ = ["ProfileCorner", "profile_corners", "cornered_curve", "corner_note", "CORNER_GAP_MM"]

#: a jump of the envelope below this (mm) is no corner (a thousandth of the hundredth of the smallest accepted
#: tolerance: the continuity the discretisation asks of a curve)
CORNER_GAP_MM = 1e-9
_NEWTON_ITERS = 30
#: samples of each side when the crossing of a cut-back corner is searched on polylines
_SIDE_SAMPLES = 257
#: piece kinds of a cornered curve
_SIDE, _ARC, _LINE = 0, 1, 2


@dataclass(frozen=True)
class ProfileCorner:
    """One corner of a profile at a velocity jump and what the follower makes of it.

    ``at``: the parameter (cam angle, rad) of the junction; ``fill``: ``"arc"`` (rollers: radius R about
    ``centre``, the pitch point), ``"line"`` (flat faces: the face from ``p_left`` to ``p_right``) or ``"cut"``
    (the sides cut back to ``(t_left, t_right)``, crossing at ``point``); ``p_left``, ``p_right``: the two
    one-sided contact points; ``n_left``, ``n_right``: the unit outward normals there; ``turn``: the signed
    angle from ``n_left`` to ``n_right``.
    """

    at: float
    fill: str
    p_left: np.ndarray
    p_right: np.ndarray
    n_left: np.ndarray
    n_right: np.ndarray
    turn: float
    t_left: float
    t_right: float
    centre: np.ndarray | None = None
    point: np.ndarray | None = None

    @property
    def convex(self) -> bool:
        """The sides overlap and are cut back to a sharp corner."""
        return self.fill == "cut"


def _user_deg(contact, t: float) -> str:
    return f"{float(contact.axis.to_user(t)):.6g}{contact.axis.x_symbol}"


def _circle(contact) -> bool:
    """A follower whose profile is the envelope of a circle about its pitch point (roller, curved face)."""
    return contact.kind is ContactKind.ROLLER and float(contact.roller_radius) > 0


def profile_corners(contact) -> list[ProfileCorner]:
    """The junctions of a profile where its envelope jumps by more than :data:`CORNER_GAP_MM`, with what the
    follower makes there; empty for a profile without a jump and for a knife edge (its profile is its path: a
    corner, no jump).

    Raises
    ------
    GeometryError
        When the two sides of an overlapping corner do not cross within the pieces beside it, or are cut back
        past the next corner (the jumps are too close for the follower).
    """
    if not (_circle(contact) or contact.kind is ContactKind.FLAT):
        return []
    bp = np.asarray(contact.breakpoints, dtype=float)
    first = 0 if contact.closed else 1  # an open profile (a translating cam) has no junction at its ends
    at = bp[first:-1]  # (0 = the period of a closed profile and) every inner breakpoint
    prev = np.arange(first, bp.size - 1) - 1  # the piece before each (wrapping for 0)
    delta = np.maximum(1e-7 * np.diff(bp)[prev], 8 * np.spacing(np.maximum(bp[1:], 1.0)[prev]))
    before = np.where(at == 0.0, contact.period, at)
    right = contact.evaluate(at)
    s1, s2 = contact.evaluate(before - delta), contact.evaluate(before - 2 * delta)
    p_left = 2 * s1.point - s2.point  # the limits from the left, O(δ²)
    v_left = 2 * s1.point_d1 - s2.point_d1
    n_left = unit(2 * s1.normal - s2.normal)
    jump = right.point - p_left
    idx = np.flatnonzero(np.hypot(*jump.T) > CORNER_GAP_MM)
    if idx.size == 0:
        return []
    if _circle(contact):  # the normals from the pitch point: exact for a circle about it
        n_left[idx] = unit(right.pitch[idx] - p_left[idx])
    along = unit(v_left[idx] + right.point_d1[idx])  # the direction the profile runs at the corner
    ahead = dot(jump[idx], along) > 0  # the right side starts ahead of the left side's end: a gap to fill
    out = []
    for j, i in enumerate(idx.tolist()):
        t = float(at[i])
        n_l, n_r = n_left[i], right.normal[i]
        turn = float(np.arctan2(cross(n_l, n_r), dot(n_l, n_r)))
        common = dict(p_left=p_left[i], p_right=right.point[i], n_left=n_l, n_right=n_r, turn=turn)
        if ahead[j]:
            fill = "arc" if _circle(contact) else "line"
            centre = right.pitch[i] if fill == "arc" else None
            out.append(ProfileCorner(t, fill, t_left=t, t_right=t, centre=centre, **common))
            continue
        t1, t2, k = _crossing(contact, t, bp, p_left[i], v_left[i], right.point[i], right.point_d1[i])
        if not (t1 < t < t2):
            raise GeometryError(f"the two sides of the profile at the velocity jump at {_user_deg(contact, t)} do "
                                "not cross near it, so no follower could make this profile: match the velocities "
                                "there")
        out.append(ProfileCorner(t, "cut", t_left=t1, t_right=t2, point=k, **common))
    _refuse_overlapping(contact, out)
    return out


def _refuse_overlapping(contact, corners: list[ProfileCorner]) -> None:
    period = contact.period
    ats = np.array([c.at for c in corners])
    for c in corners:
        if not c.convex:
            continue
        rel = (ats - c.at + 0.5 * period) % period - 0.5 * period
        rel = rel[rel != 0.0]
        if np.any((rel > c.t_left - c.at) & (rel < c.t_right - c.at)):
            raise GeometryError(f"the profile at the velocity jump at {_user_deg(contact, c.at)} is cut back past "
                                f"the next velocity jump ({_user_deg(contact, c.t_left % period)} to "
                                f"{_user_deg(contact, c.t_right % period)}): the jumps are too close for the "
                                "follower; match the velocities there")


def _crossing(contact, t: float, bp: np.ndarray, p_l, v_l, p_r, v_r) -> tuple[float, float, np.ndarray]:
    """Where the side before ``t`` (ending at ``p_l`` with derivative ``v_l``) crosses the side after it:
    ``(t1 < t, t2 > t, point)``, by Newton on ``P(t1) = P(t2)`` from the crossing of the two tangents, or,
    when they are parallel (a flat face) or Newton fails, from the crossing of the two sides sampled over the
    pieces beside the corner.  ``(t, t, p_r)`` when there is none."""
    m = np.column_stack([v_l, -v_r])
    if abs(float(np.linalg.det(m))) > 1e-9 * float(np.hypot(*v_l) * np.hypot(*v_r)):
        a, b = np.linalg.solve(m, p_r - p_l)
        found = _newton(contact, t, t + min(float(a), 0.0), t + max(float(b), 0.0), p_r)
        if found[0] < t < found[1]:
            return found
    i = int(np.searchsorted(bp, t))
    lo = bp[i - 1] if i > 0 else bp[-2] - contact.period  # (only a closed profile has a corner at 0)
    hi = bp[i + 1]
    guess = _sampled_crossing(contact, t, lo, hi)
    if guess is None:
        return t, t, p_r
    return _newton(contact, t, guess[0], guess[1], p_r)


def _sampled_crossing(contact, t: float, lo: float, hi: float) -> tuple[float, float] | None:
    """The crossing nearest the corner of the two sides sampled as polylines on ``[lo, t)`` and ``(t, hi]``."""
    period = contact.period
    ta = t - (t - lo) * np.linspace(1.0, 1e-6, _SIDE_SAMPLES)
    tb = t + (hi - t) * np.linspace(1e-6, 1.0, _SIDE_SAMPLES)
    a = contact.evaluate(np.mod(ta, period)).point
    b = contact.evaluate(np.mod(tb, period)).point
    a0, da = a[:-1, None], np.diff(a, axis=0)[:, None]
    b0, db = b[None, :-1], np.diff(b, axis=0)[None, :]
    den = cross(da, db)
    with np.errstate(divide="ignore", invalid="ignore"):
        s = cross(b0 - a0, db) / den
        u = cross(b0 - a0, da) / den
    hit = (s >= 0) & (s <= 1) & (u >= 0) & (u <= 1) & (den != 0)
    if not hit.any():
        return None
    i, j = np.nonzero(hit)
    t1 = ta[i] + s[i, j] * (ta[i + 1] - ta[i])
    t2 = tb[j] + u[i, j] * (tb[j + 1] - tb[j])
    best = int(np.argmin(t2 - t1))
    return float(t1[best]), float(t2[best])


def _newton(contact, t: float, t1: float, t2: float, p_r) -> tuple[float, float, np.ndarray]:
    """Newton on ``P(t1) = P(t2)`` with ``t1 < t < t2`` (a step that would cross ``t`` is halved)."""
    period = contact.period
    scale = max(1.0, float(np.abs(p_r).max()))
    for _ in range(_NEWTON_ITERS):
        s = contact.evaluate(np.array([t1 % period, t2 % period]))
        f = s.point[0] - s.point[1]
        if float(np.hypot(*f)) <= 1e-13 * scale:
            return t1, t2, 0.5 * (s.point[0] + s.point[1])
        try:
            da, db = np.linalg.solve(np.column_stack([s.point_d1[0], -s.point_d1[1]]), -f)
        except np.linalg.LinAlgError:
            break
        t1 = t1 + da if t1 + da < t else 0.5 * (t1 + t)
        t2 = t2 + db if t2 + db > t else 0.5 * (t2 + t)
    return t, t, p_r


@dataclass(frozen=True)
class _Layout:
    """The pieces of a cornered curve in order: ``kind`` :data:`_SIDE` (a stretch of the contact from parameter
    ``t0``, unit speed), :data:`_ARC` (``centre``, ``radius``, unit start direction ``vec`` from the centre,
    signed ``sweep``) or :data:`_LINE` (from ``centre`` along ``vec``, whole); ``tau`` the starts of the pieces
    in the new parameter, then its period."""

    kind: np.ndarray
    tau: np.ndarray
    t0: np.ndarray
    centre: np.ndarray
    radius: np.ndarray
    vec: np.ndarray
    sweep: np.ndarray


def _fill(contact, c: ProfileCorner, d: float) -> tuple[int, np.ndarray, float, np.ndarray, float, float] | None:
    """The piece a corner adds to the curve offset by ``d``: ``(kind, centre, radius, vec, sweep, length)``
    (``length``: its arc length), or None (a cut-back corner of the profile itself: a sharp vertex)."""
    if c.fill == "arc":
        r = float(contact.roller_radius) - d
        assert c.centre is not None
        return _ARC, c.centre, r, -c.n_left, c.turn, r * abs(c.turn)
    if c.fill == "line":
        a, b = c.p_left + d * c.n_left, c.p_right + d * c.n_right
        return _LINE, a, 0.0, b - a, 0.0, float(np.hypot(*(b - a)))
    if d > 0:
        assert c.point is not None
        s = contact.evaluate(np.array([c.t_left % contact.period, c.t_right % contact.period]))
        n1, n2 = s.normal[0], s.normal[1]
        sweep = float(np.arctan2(cross(n1, n2), dot(n1, n2)))
        return _ARC, np.asarray(c.point, dtype=float), d, n1, sweep, d * abs(sweep)
    return None


def cornered_curve(contact, corners: list[ProfileCorner], distance: float = 0.0) -> ParametricCurve:
    """The profile of ``contact`` (``distance = 0``) or its outward offset by ``distance`` (a cutter's centre
    path), made as the follower makes it at ``corners`` (see the module notes): closed for a disc cam, from
    travel 0 to the cam length for a translating cam.

    Raises
    ------
    GeometryError
        A cutter (``distance``) at least as large as the roller: it cannot cut the roller-radius arcs.
    """
    d = float(distance)
    arcs = [c for c in corners if c.fill == "arc"]
    if arcs and d >= float(contact.roller_radius):
        raise GeometryError(f"the cutter radius {d:g} mm is not smaller than the roller radius "
                            f"{float(contact.roller_radius):g} mm: at the velocity jump at "
                            f"{_user_deg(contact, arcs[0].at)} the profile has a concave arc of the roller's radius, "
                            "which it would gouge; choose a smaller tool")
    period = contact.period
    order = sorted(corners, key=lambda c: c.at)
    rows: list[tuple] = []  # (kind, t0, length in the new parameter, centre, radius, vec, sweep)
    # the sides between corners, each corner's piece between them; a closed profile starts just after its first
    # corner and ends with that corner's piece (so the curve closes on the side values, not on a wrapped one),
    # an open one starts at travel 0 and ends at the cam length
    sides = [(c.t_right, nxt.t_left) for c, nxt in zip(order, order[1:], strict=False)]
    if contact.closed:
        sides.append((order[-1].t_right, order[0].t_left + period))
        fills = order[1:] + order[:1]
    else:
        sides = [(0.0, order[0].t_left)] + sides + [(order[-1].t_right, period)]
        fills = order
    speed = np.hypot(*contact.evaluate(np.array([c.at for c in fills])).point_d1.T)
    for i, (a, b) in enumerate(sides):
        rows.append((_SIDE, a, b - a, np.zeros(2), 0.0, np.zeros(2), 0.0))
        if i == len(fills):
            break
        piece = _fill(contact, fills[i], d)
        if piece is not None and piece[5] > 0:
            kind, centre, radius, vec, sweep, length = piece
            v = max(float(speed[i]), 1e-300)
            rows.append((kind, 0.0, max(length / v, 1e-9 * period), centre, radius, vec, sweep))
    tau = np.concatenate([[0.0], np.cumsum([r[2] for r in rows])])
    lay = _Layout(np.array([r[0] for r in rows]), tau, np.array([r[1] for r in rows]),
                  np.array([r[3] for r in rows]), np.array([r[4] for r in rows]), np.array([r[5] for r in rows]),
                  np.array([r[6] for r in rows]))
    # breakpoints: the ends of every piece and the contact's own breakpoints inside the sides
    bp = np.asarray(contact.breakpoints, dtype=float)[:-1]
    inner = []
    for k in np.flatnonzero(lay.kind == _SIDE).tolist():
        rel = (bp - lay.t0[k]) % period
        inner.append(lay.tau[k] + rel[(rel > 0) & (rel < lay.tau[k + 1] - lay.tau[k])])
    breakpoints = np.unique(np.concatenate([tau] + inner))

    def evaluate(t, first: bool) -> np.ndarray:
        """``P`` (``first`` false) or ``dP/dτ`` at the new parameters ``t``."""
        t = np.asarray(t, dtype=float)
        k = np.clip(np.searchsorted(lay.tau, t, side="right") - 1, 0, lay.kind.size - 1)
        u = t - lay.tau[k]
        w = lay.tau[k + 1] - lay.tau[k]
        out = np.empty((u.size, 2))
        side = lay.kind[k] == _SIDE
        if side.any():
            x = lay.t0[k[side]] + u[side]  # an open profile ends on its left limit (the motion wraps at its end)
            s = contact.evaluate(x % period if contact.closed else np.minimum(x, np.nextafter(period, 0.0)))
            if first:
                out[side] = s.point_d1 * (1.0 + d * s.curvature)[:, None] if d else s.point_d1
            else:
                out[side] = s.point + d * s.normal if d else s.point
        arc = lay.kind[k] == _ARC
        if arc.any():
            ka = k[arc]
            direction = rotate(lay.vec[ka], lay.sweep[ka] * u[arc] / w[arc])
            if first:
                out[arc] = (lay.radius[ka] * lay.sweep[ka] / w[arc])[:, None] * J(direction)
            else:
                out[arc] = lay.centre[ka] + lay.radius[ka, None] * direction
        line = lay.kind[k] == _LINE
        if line.any():
            kl = k[line]
            out[line] = lay.vec[kl] / w[line, None] if first else \
                lay.centre[kl] + lay.vec[kl] * (u[line] / w[line])[:, None]
        return out

    return ParametricCurve(lambda t: evaluate(t, False), breakpoints, float(tau[-1]),
                           lambda t: evaluate(t, True), contact.closed)


def corner_note(contact, corners: list[ProfileCorner]) -> str:
    """One line for a log: where the corners are and what the follower makes of them."""
    words = {"arc": "an arc of the roller's radius", "line": "a stretch of the face", "cut": "cut back to a corner"}
    parts = [f"{_user_deg(contact, c.at)} ({words[c.fill]}, {math.degrees(abs(c.turn)):.3g}° turn)"
             for c in corners[:5]]
    more = f" and {len(corners) - 5} more" if len(corners) > 5 else ""
    return ", ".join(parts) + more
