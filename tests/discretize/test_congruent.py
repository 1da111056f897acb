"""Congruent spans share one arc-count search: a mirrored rise and return, measured within tol independently."""
from __future__ import annotations

import pytest

import camfab.discretize.arcspline as spline
import camfab.discretize.congruent as congruent
from camfab.design.assemble import geometry_from_spec
from camfab.design.spec import design_from_dict
from camfab.discretize import arcs
from camfab.offset.cutter import profile_curve

from .test_discretize import Dense, assert_chain_consistent, check_arcs, tangent_jumps


def symmetric_cam(rise: str = "cycloidal", ret: str = "cycloidal"):
    """Issue 15's roller cam (Rb 50, Rr 5): a rise of 25 mm over 120°, dwell 60°, a return over 120°, dwell 60°."""
    return profile_curve(geometry_from_spec(design_from_dict({
        "name": "mirror", "cam": {"kind": "disc", "rotation": "cw", "omega_rad_s": 1.0},
        "follower": {"type": "roller", "motion": "translating", "base_radius_mm": 50.0, "roller_radius_mm": 5.0,
                     "offset_mm": 0.0},
        "motion": [{"law": rise, "lift": 25.0, "angle_deg": 120.0}, {"law": "dwell", "lift": 0.0, "angle_deg": 60.0},
                   {"law": ret, "lift": -25.0, "angle_deg": 120.0}, {"law": "dwell", "lift": 0.0, "angle_deg": 60.0}],
    })).profiles[0])


def _spy(monkeypatch):
    calls = []
    fit_span = spline._fit_span

    def spy(sur, span, target, search=None):
        calls.append(span.label)
        return fit_span(sur, span, target, search)

    monkeypatch.setattr(spline, "_fit_span", spy)
    return calls


@pytest.mark.parametrize("tol", [1e-3, 1e-4])
def test_mirrored_return_takes_the_rise_arcs(monkeypatch, tol):
    """The return mirrors the rise: one search, and the same number of arcs on both, within tol (checked on dense
    exact samples, not by the fit's own measurement)."""
    curve = symmetric_cam()
    calls = _spy(monkeypatch)
    res = arcs(curve, tol=tol)
    assert len(calls) == 1
    assert check_arcs(res, Dense(curve)) <= tol
    assert_chain_consistent(res)
    assert tangent_jumps(res).max() < 1e-7


def test_different_return_is_searched_on_its_own(monkeypatch):
    """A return by another law is not congruent to the rise: both spans are searched."""
    calls = _spy(monkeypatch)
    res = arcs(symmetric_cam(ret="poly345"), tol=1e-3)
    assert len(calls) == 2
    assert res.max_deviation <= 1e-3


def test_wrongly_carried_arcs_are_refitted(monkeypatch):
    """Arcs carried to a span that is not congruent (the comparison made blind) measure above tol: that span is
    fitted on its own, and the result is within tol (measured independently)."""
    monkeypatch.setattr(congruent, "CURVATURE_TOL", 1e9)
    monkeypatch.setattr(congruent, "SIGNATURE_TOL", 1e9)
    curve = symmetric_cam(ret="poly345")
    calls = _spy(monkeypatch)
    res = arcs(curve, tol=1e-3)
    assert len(calls) == 2  # the rise searched, the carried return refitted
    assert check_arcs(res, Dense(curve)) <= 1e-3
