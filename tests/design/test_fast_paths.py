"""The fast evaluation paths agree exactly with the reference formulas.

``MotionProgram.evaluate`` evaluates few samples law by law and many samples segment by
segment; every path must give, value for value, what ``Segment.values`` gives (the
operation-for-operation definition), and every law's several-orders and single-point
evaluations what its reference evaluation ``law(u, nu)`` gives.  ``check`` runs its
extremum and range searches on one shared dense sample per contact, several searches refined
together; each must give exactly what the standalone searches (``extremum``, ``positive_ranges``)
give.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

import camfab.design.program as program_mod
from camfab.design.checks import check
from camfab.design.laws import LAWS, Piecewise, law_names
from camfab.design.mechanisms import OscillatingRoller, TranslatingFlat, TranslatingRoller
from camfab.design.profile import CamGeometry
from camfab.design.program import MotionProgram, Segment
from camfab.numeric import extremum, positive_ranges

PI = math.pi


def _every_law_program() -> MotionProgram:
    """Every law, rising and returning, generic polynomials and half-period laws."""
    half = {"semiharmonic_vf0", "semiharmonic_vi0", "semicycloidal_vf0", "semicycloidal_vi0", "poly5", "poly7"}
    rows = []
    for law in law_names():
        if law not in half and law != "dwell":  # a dwell does not move: it is the spacer between the others
            rows += [(law, 5.0, 8), ("dwell", 0, 2), (law, -5.0, 8), ("dwell", 0, 2)]
    rows += [("poly5", 3, 10), ("dwell", 0, 5), ("poly7", -3, 10), ("dwell", 0, 5)]
    # half-period laws with the matching constant velocity (end slopes 2L/β and (π/2)L/β)
    rows += [("semicycloidal_vi0", 1, 6), ("constant_velocity", 2, 6), ("semicycloidal_vf0", 1, 6),
             ("semiharmonic_vi0", -1, 6), ("constant_velocity", -PI / 2, 6), ("semiharmonic_vf0", -1, 6),
             ("cycloidal", -(2 - PI / 2), 6)]
    rows.append(("dwell", 0, 360 - sum(r[2] for r in rows)))
    return MotionProgram.from_segments(rows)


def _reference(prog: MotionProgram, x: np.ndarray, orders) -> np.ndarray:
    xr = np.mod(x, prog.period)
    idx = prog.segment_index(xr)
    out = np.empty((len(orders), x.size))
    for i in range(x.size):
        seg = prog.segments[idx[i]]
        u = np.array([(xr[i] - seg.start) / seg.span])
        for r, nu in enumerate(orders):
            out[r, i] = seg.values(u, nu)[0]
    return out


@pytest.mark.parametrize("grouped", [0, 10**9], ids=["by-segment", "grouped"])
def test_every_evaluation_path_is_bit_identical(monkeypatch, grouped):
    prog = _every_law_program()
    monkeypatch.setattr(program_mod, "_GROUPED_MAX", grouped)
    bp = prog.breakpoints
    x = np.r_[np.random.default_rng(3).uniform(-1.0, 7.0, 600), bp, np.nextafter(bp, -9.0), np.nextafter(bp, 9.0)]
    for xs in (x, x[:40], x[:1], np.r_[x[:20], np.nan, np.inf]):
        for orders in ((0, 1, 2, 3), (3, 0), (4,), (2,), (1, 1), (6, 0)):
            with np.errstate(invalid="ignore"):
                got = prog.evaluate(xs, orders)
                ref = _reference(prog, xs, orders)
            assert np.array_equal(got, ref, equal_nan=True)
            assert np.array_equal(np.signbit(got), np.signbit(ref))


def _law_points(law) -> np.ndarray:
    b = np.asarray(law.breaks)
    return np.r_[np.random.default_rng(5).uniform(0.0, 1.0, 300), 0.0, 1.0, b, np.nextafter(b, -1.0),
                 np.nextafter(b, 2.0)]


def _every_law():
    """Every standard law and every piece of a piecewise law."""
    for law in LAWS.values():
        yield law
        if isinstance(law, Piecewise):
            yield from law.pieces


@pytest.mark.parametrize("law", list(_every_law()), ids=repr)
def test_law_rows_and_points_equal_the_reference(law):
    u = _law_points(law)
    for orders in ((0, 1, 2, 3, 4), (3, 1), (0,), (5, 2)):
        rows = law.rows(u, orders)
        for r, nu in enumerate(orders):
            ref = law(u, nu)
            assert np.array_equal(rows[r], ref) and np.array_equal(np.signbit(rows[r]), np.signbit(ref))
    for nu in range(5):
        ref = law(u, nu)
        assert [law.scalar(float(t), nu) for t in u] == list(ref)
        assert [law.point(float(t), nu) for t in u[-8:]] == list(ref[-8:])
    for nu in range(4):
        cu, cf = law.extremum_candidates(nu)
        assert np.array_equal(cf, law(cu, nu))


@pytest.mark.parametrize("name", sorted(LAWS))
@pytest.mark.parametrize("lift", [7.5, -3.0])
def test_segment_rows_and_points_equal_values(name, lift):
    segs = [Segment(name, lift, 0.7, 1.0, 4.0), Segment("hermite7", 1.0, 0.3, 0.0, 2.0,
                                                         (2.0, -1.0, 0.5, 3.0, 0.25, -7.0, 1.5, 0.125))]
    for seg in segs:
        u = _law_points(seg.formula)
        rows = seg.rows(u.copy(), (0, 1, 2, 3, 4))
        for nu in range(5):
            ref = seg.values(u, nu)
            assert np.array_equal(rows[nu], ref)
            assert [seg.value_at(float(t), nu) for t in u[-6:]] == list(ref[-6:])


def test_exact_analyses_are_computed_once():
    prog = _every_law_program()
    assert prog.peaks("exact") is prog.peaks("exact")
    assert prog.junctions(internal=True) == prog.junctions(internal=True)


@pytest.fixture(params=["tr", "or", "tf"])
def geometry(request):
    rows = [("cycloidal", 10, 30), ("dwell", 0, 30), ("poly345", 10, 30), ("dwell", 0, 30),
            ("poly4567", -10, 30), ("dwell", 0, 30), ("cycloidal", -5, 30), ("dwell", 0, 30),
            ("poly345", 10, 30), ("dwell", 0, 30), ("poly4567", -15, 30), ("dwell", 0, 30)]
    if request.param == "tr":
        return CamGeometry(TranslatingRoller(12.0, 8.0, 5.0), MotionProgram.from_segments(rows))
    if request.param == "or":
        half = [(law, lift / 2, span) for law, lift, span in rows]
        return CamGeometry(OscillatingRoller(50.0, 8.0, 120.0, 90.0), MotionProgram.from_segments(half))
    return CamGeometry(TranslatingFlat(10.0), MotionProgram.from_segments(rows))


def test_merged_searches_equal_the_standalone_ones(geometry):
    """check()'s shared-sample searches give exactly the standalone results."""
    c = geometry.profiles[0]
    ev = c.evaluate_fixed  # check() reads frame-independent values from the unrotated sample
    rep = check(geometry, pressure_angle_limit_deg=10.0, tool_radius_mm=30.0)
    edges = c.breakpoints
    if c.kind == "roller":
        xa, pmax = extremum(lambda x: ev(x).pressure_angle, edges, maximize=True)
        xb, pmin = extremum(lambda x: ev(x).pressure_angle, edges)
        assert rep.pressure_angle.max == math.degrees(pmax)
        assert rep.pressure_angle.min == math.degrees(pmin)
        assert rep.pressure_angle.at_max == math.degrees(xa)
        lim = math.radians(10.0)
        ranges = positive_ranges(lambda x: ev(x).pressure_angle - lim, edges, closed=c.closed)
        found = [f for f in rep.findings if f.code == "PRESSURE_ANGLE_EXCEEDED" and f.limit > 0]
        assert [(f.from_deg, f.to_deg) for f in found] == [(math.degrees(lo), math.degrees(hi))
                                                           for lo, hi, _, _ in ranges]
        assert [f.value for f in found] == [math.degrees(gw + lim) for _, _, _, gw in ranges]
    else:
        xa, rmin = extremum(lambda x: ev(x).rho, edges)
        assert rep.curvature.min_convex == rmin
        assert rep.curvature.at_min_convex == math.degrees(xa)
        ranges = positive_ranges(lambda x: -ev(x).rho, edges, closed=c.closed)
        found = [f for f in rep.findings if f.code == "UNDERCUT"]
        assert [(f.from_deg, f.to_deg, f.value) for f in found] == [
            (math.degrees(lo), math.degrees(hi), -gw) for lo, hi, _, gw in ranges]
    assert rep.base_radius_mm == extremum(lambda x: np.hypot(*ev(x).point.T), edges)[1]
