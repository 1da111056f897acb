"""Discretisation of exact closed curves: polylines and G1 arc chains within ``tol``.

Every deviation asserted here is measured by an independent checker written in
this file (dense exact-curve samples, exact point-to-segment and point-to-arc
distances from the public result fields, both directions), not by the
module's own measurement.
"""
from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st
from scipy.spatial import cKDTree

from camfab.design.program import MotionProgram
from camfab.discretize import (
    ArcDiscretisation,
    Chain,
    CurveError,
    Discretisation,
    ParametricCurve,
    ToleranceError,
    arcs,
    curvature_at,
    max_deviation,
    measure_deviation,
    polyline,
    validate_tol,
)
from camfab.errors import CamfabError
from camfab.geom2d import cross, dot
from camfab.tolerances import MAX_EXPORT_TOL_MM, MIN_EXPORT_TOL_MM

TOLS = (1e-2, 1e-3, 1e-4, 1e-5)
DENSE = 200_000


# ---------------------------------------------------------------------------------------
# exact test curves
# ---------------------------------------------------------------------------------------
def circle(derivative: bool = True) -> ParametricCurve:
    c, r = np.array([3.0, -2.0]), 30.0
    return ParametricCurve(
        lambda t: c + r * np.column_stack([np.cos(t), np.sin(t)]),
        [0.0, 2 * math.pi],
        derivative=(lambda t: r * np.column_stack([-np.sin(t), np.cos(t)])) if derivative else None)


def ellipse() -> ParametricCurve:
    a, b = 50.0, 20.0
    return ParametricCurve(lambda t: np.column_stack([a * np.cos(t), b * np.sin(t)]), [0.0],
                           derivative=lambda t: np.column_stack([-a * np.sin(t), b * np.cos(t)]))


def polar(r, dr, breakpoints, derivative=True) -> ParametricCurve:
    """``P(φ) = r(φ)·(sin φ, cos φ)``: the cam frame (follower along +Y at φ = 0)."""
    def point(t):
        rr = r(t)
        return np.column_stack([rr * np.sin(t), rr * np.cos(t)])

    def deriv(t):
        rr, d = r(t), dr(t)
        return np.column_stack([d * np.sin(t) + rr * np.cos(t), d * np.cos(t) - rr * np.sin(t)])

    return ParametricCurve(point, breakpoints, derivative=deriv if derivative else None)


def limacon() -> ParametricCurve:
    return polar(lambda t: 40.0 + 8.0 * np.cos(t), lambda t: -8.0 * np.sin(t), [0.0])


def kinked() -> ParametricCurve:
    """r = 35 + 6·|sin φ|: the tangent turns abruptly at φ = 0 and φ = π."""
    return polar(lambda t: 35.0 + 6.0 * np.abs(np.sin(t)),
                 lambda t: 6.0 * np.cos(t) * np.sign(np.sin(t)), [0.0, math.pi, 2 * math.pi])


def cam(rows, base: float = 40.0, derivative: bool = True) -> ParametricCurve:
    prog = MotionProgram.from_segments(rows)
    return polar(lambda t: base + prog.evaluate(t, (0,))[0], lambda t: prog.evaluate(t, (1,))[0],
                 prog.breakpoints, derivative)


CAM4 = [("cycloidal", 10, 90), ("dwell", 0, 90), ("poly345", -10, 90), ("dwell", 0, 90)]
#: constant velocity against dwells: the profile has true tangent kinks at 0°, 90°, 180°, 270°
CAM_CV = [("constant_velocity", 8, 90), ("dwell", 0, 90), ("constant_velocity", -8, 90), ("dwell", 0, 90)]

CURVES = {
    "circle": circle,
    "ellipse": ellipse,
    "limacon": limacon,
    "cam4": lambda: cam(CAM4),
    "kinked": kinked,
}
#: true tangent kinks of each curve (parameters)
KINKS = {"kinked": (0.0, math.pi), "cam_cv": tuple(np.radians([0.0, 90.0, 180.0, 270.0]))}


# ---------------------------------------------------------------------------------------
# independent checker
# ---------------------------------------------------------------------------------------
def seg_dist(q, a, b):
    ab = b - a
    tt = np.clip(np.einsum("...i,...i", q - a, ab) / np.maximum(np.einsum("...i,...i", ab, ab), 1e-300), 0, 1)
    return np.linalg.norm(q - (a + tt[..., None] * ab), axis=-1)


def arc_dist(q, s, e, c, r, sweep):
    """Distance from q to the arc of centre c, radius r from s sweeping ``sweep`` (lines: sweep 0)."""
    line = sweep == 0
    cc = np.where(line[..., None], 0.0, c)
    v = q - cc
    a0 = np.arctan2(s[..., 1] - cc[..., 1], s[..., 0] - cc[..., 0])
    ang = np.mod((np.arctan2(v[..., 1], v[..., 0]) - a0) * np.sign(sweep), 2 * math.pi)
    inside = ang <= np.abs(sweep)
    radial = np.abs(np.linalg.norm(v, axis=-1) - np.where(line, 0.0, r))
    ends = np.minimum(np.linalg.norm(q - s, axis=-1), np.linalg.norm(q - e, axis=-1))
    return np.where(line, seg_dist(q, s, e), np.where(inside, radial, ends))


def arc_samples(res: ArcDiscretisation, m: int = 40):
    f = np.linspace(0.0, 1.0, m)
    line = res.is_line[:, None]
    a0 = np.arctan2(res.starts[:, 1] - res.centres[:, 1], res.starts[:, 0] - res.centres[:, 0])
    ang = a0[:, None] + res.sweeps[:, None] * f
    on_arc = res.centres[:, None] + res.radii[:, None, None] * np.stack([np.cos(ang), np.sin(ang)], -1)
    on_line = res.starts[:, None] + f[None, :, None] * (res.ends - res.starts)[:, None]
    return np.where(line[..., None], on_line, on_arc)


class Dense:
    """The exact curve at DENSE parameters (+ breakpoints) as a fine polyline."""

    def __init__(self, curve: ParametricCurve, n: int = DENSE):
        t = np.unique(np.concatenate([np.linspace(0, curve.period, n), curve.breakpoints]))
        self.t = t
        self.p = curve.point(t)
        self.tree = cKDTree(self.p)

    def to_curve(self, x):
        _, j = self.tree.query(x)
        j0, j1 = np.maximum(j - 1, 0), np.minimum(j + 1, self.p.shape[0] - 1)
        return np.minimum(seg_dist(x, self.p[j0], self.p[j]), seg_dist(x, self.p[j], self.p[j1]))


def nearest_entity(q, sites, owner, reach: float, dist) -> np.ndarray:
    """Each point's distance to the nearest entity, exactly: ``sites`` are points of the entities (``owner``: whose),
    every point of an entity lies within ``reach`` of one of its own sites, and ``dist(q, idx)`` is the distance
    from points ``q`` ``(n, 2)`` to the entities ``idx`` ``(n, k)``.  The entities of the 6 nearest sites give an
    upper bound d; where an entity outside them could still be nearer (d > 6th site's distance − reach: a long
    segment among short ones), every entity with a site within d + reach is measured."""
    tree = cKDTree(sites)
    k = min(6, len(sites))
    dk, near = tree.query(q, k=k)
    dk, near = dk.reshape(len(q), k), near.reshape(len(q), k)
    d = dist(q[:, None], owner[near]).min(axis=1)
    unsure = np.flatnonzero(d > dk[:, -1] - reach) if k < len(sites) else np.array([], dtype=int)
    if unsure.size:
        balls = tree.query_ball_point(q[unsure], d[unsure] + reach)
        counts = np.fromiter((len(b) for b in balls), int, len(balls))
        who = np.repeat(unsure, counts)
        pair = dist(q[who][:, None], owner[np.concatenate(balls).astype(int)][:, None])[:, 0]
        np.minimum.at(d, who, pair)
    return d


def check_polyline(res: Discretisation, dense: Dense) -> float:
    a, b = res.points[:-1], res.points[1:]
    mids = 0.5 * (a + b)
    reach = 0.5 * float(np.hypot(*(b - a).T).max())  # a segment's points lie within half its length of its middle
    d1 = nearest_entity(dense.p, mids, np.arange(len(mids)), reach, lambda q, i: seg_dist(q, a[i], b[i])).max()
    f = np.linspace(0, 1, 40)[None, :, None]
    xs = (a[:, None] + f * (b - a)[:, None]).reshape(-1, 2)
    return max(d1, dense.to_curve(xs).max())


def check_arcs(res: ArcDiscretisation, dense: Dense) -> float:
    xs = arc_samples(res)
    owner = np.repeat(np.arange(res.n_entities), xs.shape[1])
    reach = 0.5 * float(np.hypot(*np.diff(xs, axis=1).reshape(-1, 2).T).max())  # half the largest sample step

    def dist(q, i):
        return arc_dist(q, res.starts[i], res.ends[i], res.centres[i], res.radii[i], res.sweeps[i])

    d1 = nearest_entity(dense.p, xs.reshape(-1, 2), owner, reach, dist).max()
    return max(d1, dense.to_curve(xs.reshape(-1, 2)).max())


_DENSE_CACHE: dict = {}


def dense_of(name: str, curve: ParametricCurve) -> Dense:
    if name not in _DENSE_CACHE:
        _DENSE_CACHE[name] = Dense(curve)
    return _DENSE_CACHE[name]


# ---------------------------------------------------------------------------------------
# tolerance guarantee
# ---------------------------------------------------------------------------------------
@pytest.mark.parametrize("tol", TOLS)
@pytest.mark.parametrize("name", sorted(CURVES))
def test_polyline_within_tol(name, tol):
    curve = CURVES[name]()
    res = polyline(curve, tol=tol)
    measured = check_polyline(res, dense_of(name, curve))
    assert measured <= tol
    assert res.max_deviation <= tol
    # the reported deviation is a measurement, not the tolerance echoed back
    assert res.max_deviation == pytest.approx(measured, rel=0.02, abs=2e-8)
    assert np.isin(curve.breakpoints, res.params).all()
    assert res.params[0] == 0.0 and res.params[-1] == curve.period
    np.testing.assert_array_equal(res.points[-1], res.points[0])
    np.testing.assert_allclose(res.points[:-1], curve.point(res.params[:-1]), atol=1e-12)


@pytest.mark.parametrize("tol", TOLS)
@pytest.mark.parametrize("name", sorted(CURVES))
def test_arcs_within_tol(name, tol):
    curve = CURVES[name]()
    res = arcs(curve, tol=tol)
    measured = check_arcs(res, dense_of(name, curve))
    assert measured <= tol
    assert res.max_deviation <= tol
    assert res.max_deviation == pytest.approx(measured, rel=0.02, abs=2e-8)
    # every true kink (tangent jump) among the breakpoints is a vertex of the chain; arcs may run
    # across G1 breakpoints
    kinks = [t for t in curve.breakpoints[:-1] if kink_angle(curve, t) > 1e-3]
    if kinks:
        kink_points = curve.point(np.array(kinks))
        gaps = np.linalg.norm(kink_points[:, None] - res.starts[None], axis=-1).min(axis=1)
        assert gaps.max() < 1e-9
    assert_chain_consistent(res)


def kink_angle(curve: ParametricCurve, t: float) -> float:
    """Angle between the one-sided tangents of the exact curve at ``t`` (finite differences)."""
    h = 1e-7 * curve.period
    p = curve.point(np.mod(np.array([t - 2 * h, t - h, t, t + h, t + 2 * h]), curve.period))
    a, b = 3 * p[2] - 4 * p[1] + p[0], -3 * p[2] + 4 * p[3] - p[4]
    return abs(math.atan2(a[0] * b[1] - a[1] * b[0], a @ b))


def assert_chain_consistent(res: ArcDiscretisation):
    np.testing.assert_array_equal(res.ends, np.roll(res.starts, -1, axis=0))
    arc = ~res.is_line
    assert np.all(np.abs(res.sweeps) < math.pi)
    np.testing.assert_allclose(np.tan(res.sweeps / 4), res.bulges)
    np.testing.assert_allclose(np.linalg.norm(res.starts[arc] - res.centres[arc], axis=1), res.radii[arc],
                               rtol=1e-9)
    np.testing.assert_allclose(np.linalg.norm(res.ends[arc] - res.centres[arc], axis=1), res.radii[arc],
                               rtol=1e-9)
    assert np.all(np.isinf(res.radii[res.is_line])) and np.all(np.isnan(res.centres[res.is_line]))


# ---------------------------------------------------------------------------------------
# G1 continuity
# ---------------------------------------------------------------------------------------
def tangent_jumps(res: ArcDiscretisation) -> np.ndarray:
    """Angle between each entity's end tangent and the next entity's start tangent."""
    a, b = res.end_tangents, np.roll(res.tangents, -1, axis=0)
    return np.abs(np.arctan2(a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0], (a * b).sum(axis=1)))


@pytest.mark.parametrize("name", ["ellipse", "limacon", "cam4", "kinked", "cam_cv"])
def test_arcs_are_g1_away_from_kinks(name):
    curve = cam(CAM_CV) if name == "cam_cv" else CURVES[name]()
    res = arcs(curve, tol=1e-3)
    jumps = tangent_jumps(res)
    # the joint after entity i is the start of entity i + 1
    joint = np.roll(res.starts, -1, axis=0)
    kinks = KINKS.get(name, ())
    at_kink = np.zeros(len(jumps), bool)
    for k in kinks:
        at_kink |= np.linalg.norm(joint - curve.point(np.array([k]))[0], axis=1) < 1e-9
    assert at_kink.sum() == len(kinks)
    assert jumps[~at_kink].max() < 1e-7
    if kinks:
        # the chain keeps the true kinks: one-sided tangents of the exact curve
        assert jumps[at_kink].min() > 0.05


def test_kinked_cam_within_tol():
    curve = cam(CAM_CV)
    dense = Dense(curve)
    for tol in (1e-3, 1e-5):
        assert check_arcs(arcs(curve, tol=tol), dense) <= tol
        assert check_polyline(polyline(curve, tol=tol), dense) <= tol


# ---------------------------------------------------------------------------------------
# entity counts
# ---------------------------------------------------------------------------------------
def test_circle_needs_very_few_arcs():
    curve = circle()
    res = arcs(curve, tol=1e-5)
    assert res.n_entities <= 4
    assert res.max_deviation < 1e-9
    np.testing.assert_allclose(res.radii, 30.0, rtol=1e-12)
    np.testing.assert_allclose(res.centres, np.broadcast_to([3.0, -2.0], res.centres.shape), atol=1e-9)
    assert res.sweeps.sum() == pytest.approx(2 * math.pi)


@pytest.mark.parametrize("tol", [1e-3, 1e-4])
def test_arcs_need_far_fewer_entities(tol):
    curve = cam(CAM4)
    n_line = polyline(curve, tol=tol).n_entities
    n_arc = arcs(curve, tol=tol).n_entities
    assert n_arc * 8 <= n_line, (n_arc, n_line)
    if tol == 1e-3:
        assert n_arc <= 72


# ---------------------------------------------------------------------------------------
# derivative-free curves, determinism, validation
# ---------------------------------------------------------------------------------------
def test_finite_difference_tangents():
    curve = cam(CAM4, derivative=False)
    dense = Dense(curve)
    for tol in (1e-3, 1e-5):
        res = arcs(curve, tol=tol)
        assert check_arcs(res, dense) <= tol
        assert tangent_jumps(res).max() < 1e-7
    assert arcs(circle(derivative=False), tol=1e-4).n_entities <= 4


def test_deterministic():
    for fn in (polyline, arcs):
        r1, r2 = fn(cam(CAM4), tol=1e-4), fn(cam(CAM4), tol=1e-4)
        for f in r1.__dataclass_fields__:
            a, b = getattr(r1, f), getattr(r2, f)
            if isinstance(a, np.ndarray):
                np.testing.assert_array_equal(a, b)
            else:
                assert a == b


@pytest.mark.parametrize("bad", [0.0, -1e-3, 1e-7, 0.2, float("nan"), float("inf"), "x", None])
@pytest.mark.parametrize("fn", [polyline, arcs, validate_tol])
def test_invalid_tol(fn, bad):
    with pytest.raises(ValueError, match=r"tol must be in \[1e-06, 0\.1\]"):
        fn(circle(), tol=bad) if fn is not validate_tol else fn(bad)


def test_tol_is_keyword_only_and_limits_accepted():
    with pytest.raises(TypeError):
        polyline(circle(), 1e-3)  # noqa
    assert validate_tol(MIN_EXPORT_TOL_MM) == MIN_EXPORT_TOL_MM
    assert validate_tol(MAX_EXPORT_TOL_MM) == MAX_EXPORT_TOL_MM
    assert polyline(circle(), tol=MAX_EXPORT_TOL_MM).max_deviation <= MAX_EXPORT_TOL_MM


def test_curve_validation():
    c = ParametricCurve(lambda t: np.column_stack([np.cos(t), np.sin(t)]), [math.pi, 0.5])
    np.testing.assert_array_equal(c.breakpoints, [0.0, 0.5, math.pi, 2 * math.pi])
    with pytest.raises(ValueError, match="breakpoints"):
        ParametricCurve(lambda t: t, [7.0])
    with pytest.raises(ValueError, match="not closed"):
        polyline(ParametricCurve(lambda t: np.column_stack([t, 0 * t]), [0.0]), tol=1e-3)
    with pytest.raises(ValueError, match=r"\(n, 2\)"):
        polyline(ParametricCurve(lambda t: np.cos(t), [0.0]), tol=1e-3)
    # every deliberate error is a CamfabError (and still a ValueError)
    with pytest.raises(CurveError, match="pass closed=False"):
        arcs(ParametricCurve(lambda t: np.column_stack([t, 0 * t]), [0.0]), tol=1e-3)
    with pytest.raises(ToleranceError, match="give a tolerance in that range"):
        validate_tol(1.0)
    assert issubclass(CurveError, CamfabError) and issubclass(ToleranceError, CamfabError)


def test_curvature():
    r = 30.0
    np.testing.assert_allclose(curvature_at(circle(), np.linspace(0, 2 * math.pi, 9)), 1 / r, rtol=1e-7)
    a, b = 50.0, 20.0
    t = np.linspace(0, 2 * math.pi, 17)
    exact = a * b / (a * a * np.sin(t) ** 2 + b * b * np.cos(t) ** 2) ** 1.5
    np.testing.assert_allclose(curvature_at(ellipse(), t), exact, rtol=1e-6)
    np.testing.assert_allclose(curvature_at(circle(derivative=False), np.array([0.3, 2.0])), 1 / r, rtol=1e-5)


# ---------------------------------------------------------------------------------------
# open curves: the ends are vertices, nothing wraps around
# ---------------------------------------------------------------------------------------
def half_ellipse() -> ParametricCurve:
    a, b = 50.0, 20.0
    return ParametricCurve(lambda t: np.column_stack([a * np.cos(t), b * np.sin(t)]), [0.0], period=math.pi,
                           derivative=lambda t: np.column_stack([-a * np.sin(t), b * np.cos(t)]), closed=False)


def open_kinked() -> ParametricCurve:
    """y = 5·|sin x| on [0, 7]: kinks at π and 2π, the ends far apart."""
    def derivative(t):
        return np.column_stack([np.ones_like(t), 5.0 * np.cos(t) * np.sign(np.sin(t))])

    return ParametricCurve(lambda t: np.column_stack([t, 5.0 * np.abs(np.sin(t))]), [math.pi, 2 * math.pi],
                           period=7.0, closed=False, derivative=derivative)


def open_cam() -> ParametricCurve:
    """Three quarters of the CAM4 profile: a rise, a dwell, a return, ending before the last dwell."""
    c = cam(CAM4)
    return ParametricCurve(c.point, c.breakpoints[c.breakpoints <= 1.5 * math.pi], period=1.5 * math.pi,
                           derivative=c.derivative, closed=False)


OPEN = {"half_ellipse": half_ellipse, "open_kinked": open_kinked, "open_cam": open_cam}


@pytest.mark.parametrize("tol", [1e-2, 1e-4])
@pytest.mark.parametrize("name", sorted(OPEN))
def test_open_curves_within_tol(name, tol):
    curve = OPEN[name]()
    dense = Dense(curve)
    ends = curve.point(np.array([0.0, curve.period]))
    res_l = polyline(curve, tol=tol)
    assert not res_l.closed and res_l.max_deviation <= tol
    assert check_polyline(res_l, dense) <= tol
    np.testing.assert_array_equal(res_l.points[[0, -1]], ends)
    res_a = arcs(curve, tol=tol)
    assert not res_a.closed and res_a.max_deviation <= tol
    assert check_arcs(res_a, dense) <= tol
    assert res_a.max_deviation == pytest.approx(check_arcs(res_a, dense), rel=0.02, abs=2e-8)
    np.testing.assert_array_equal(np.vstack([res_a.starts[0], res_a.ends[-1]]), ends)
    np.testing.assert_array_equal(res_a.ends[:-1], res_a.starts[1:])  # no closing entity
    jumps = np.abs(np.arctan2(cross(res_a.end_tangents[:-1], res_a.tangents[1:]),
                              dot(res_a.end_tangents[:-1], res_a.tangents[1:])))
    assert (jumps > 1e-3).sum() == (2 if name == "open_kinked" else 0)
    assert res_a.n_entities < res_l.n_entities


def test_measure_open_chain_sees_its_ends():
    curve = half_ellipse()
    res = polyline(curve, tol=1e-3)
    assert measure_deviation(res.points, curve).max == pytest.approx(res.max_deviation, rel=1e-9)
    # dropping the last segment leaves the curve's end uncovered: the curve-to-entities distance sees it
    short = res.points[:-1]
    gap = float(np.hypot(*(res.points[-1] - res.points[-2])))
    dev = measure_deviation(short, curve)
    assert dev.curve_to_entities == pytest.approx(gap, rel=1e-3)
    assert dev.at_param == pytest.approx(math.pi, abs=1e-9)
    # the chain measured as an ArcChain keeps its own closure
    assert measure_deviation(arcs(curve, tol=1e-3), curve).max <= 1e-3


# ---------------------------------------------------------------------------------------
# measuring read-back geometry
# ---------------------------------------------------------------------------------------
def test_measure_read_back_lwpolyline_and_gcode_arcs():
    curve = cam(CAM4)
    res = arcs(curve, tol=1e-4)
    from_bulges = max_deviation(res.lwpolyline, curve)
    assert from_bulges == pytest.approx(res.max_deviation, rel=1e-6)
    line = res.is_line
    g = Chain.from_arcs(res.starts, res.ends, np.where(line[:, None], np.nan, res.centres), res.sweeps > 0)
    assert max_deviation(g, curve) == pytest.approx(res.max_deviation, rel=1e-6)
    # G-code rounding to 4 decimals (0.1 µm) stays visible but small
    rounded = np.column_stack([np.round(res.starts, 4), res.bulges])
    assert max_deviation(rounded, curve) <= res.max_deviation + 1e-4


def test_measure_detects_a_defect():
    curve = cam(CAM4)
    res = polyline(curve, tol=1e-3)
    pts = res.points.copy()
    i = len(pts) // 3
    n = pts[i] / np.linalg.norm(pts[i])
    pts[i] += 0.02 * n                      # one vertex pushed 20 µm outwards
    pts[-1] = pts[0]
    dev = measure_deviation(pts, curve)
    assert dev.max == pytest.approx(0.02, rel=0.05)
    assert dev.entities_to_curve == pytest.approx(0.02, rel=0.05)
    assert np.linalg.norm(dev.at_point - res.points[i]) < 0.5
    # dropping vertices leaves the curve far from the chord: the other direction
    coarse = res.points[::8]
    dev2 = measure_deviation(coarse, curve)
    assert dev2.curve_to_entities == pytest.approx(check_polyline(
        Discretisation(np.zeros(len(coarse)), np.vstack([coarse, coarse[:1]]), 0.0, 1e-3),
        Dense(curve)), rel=1e-3)


def test_measure_matches_independent_checker_on_a_coarse_chain():
    curve = ellipse()
    dense = dense_of("ellipse", curve)
    pts = curve.point(np.linspace(0, 2 * math.pi, 41))
    pts[-1] = pts[0]
    res = Discretisation(np.linspace(0, 2 * math.pi, 41), pts, 0.0, 0.1)
    assert max_deviation(pts, curve) == pytest.approx(check_polyline(res, dense), rel=1e-6)


# ---------------------------------------------------------------------------------------
# property-based: random cam-like curves
# ---------------------------------------------------------------------------------------
RISE_LAWS = ["cycloidal", "poly345", "poly4567", "simple_harmonic", "modified_sine", "modified_trapezoid"]


@st.composite
def cam_programs(draw):
    n_rise = draw(st.integers(1, 2))
    lifts = [draw(st.floats(2.0, 12.0)) for _ in range(n_rise)]
    n_seg = 2 * n_rise + 2          # rises, one return, dwells after each motion
    angles = [draw(st.integers(25, 90)) for _ in range(n_seg - 1)]
    last = 360 - sum(angles)
    if last < 20:
        scale = (360 - 20 * n_seg) / sum(a - 20 for a in angles)
        angles = [20 + math.floor((a - 20) * scale) for a in angles]
        last = 360 - sum(angles)
    laws = [draw(st.sampled_from(RISE_LAWS)) for _ in range(n_rise + 1)]
    moves = [(laws[i], lifts[i]) for i in range(n_rise)] + [(laws[-1], -sum(lifts))]
    rows = []
    for (law, lift), a_move, a_dwell in zip(moves, angles[0::2], angles[1::2] + [last], strict=True):
        rows += [(law, lift, a_move), ("dwell", 0, a_dwell)]
    base = draw(st.floats(25.0, 60.0))
    tol = draw(st.sampled_from([1e-2, 1e-3, 1e-4]))
    return rows, base, tol


@settings(max_examples=20, deadline=None)
@given(cam_programs())
# a long dwell segment among short ones: the checker's 6 nearest midpoints missed it (0.083 mm "found", 4e-6 true)
@example(([("cycloidal", 2.125, 25), ("dwell", 0, 25), ("cycloidal", 8.625, 25), ("dwell", 0, 25),
           ("simple_harmonic", -10.75, 65), ("dwell", 0, 195)], 41.0, 1e-4))
def test_random_cams_within_tol(case):
    rows, base, tol = case
    assert sum(r[2] for r in rows) == 360
    curve = cam(rows, base)
    dense = Dense(curve, 40_000)
    res_l = polyline(curve, tol=tol)
    res_a = arcs(curve, tol=tol)
    assert check_polyline(res_l, dense) <= tol
    assert check_arcs(res_a, dense) <= tol
    assert tangent_jumps(res_a).max() < 1e-7
    assert res_a.n_entities < res_l.n_entities
