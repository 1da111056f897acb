"""Arcs above a radius limit become chords within the tolerance (docs/decisions.md, "Arc radius limit").

The sagitta formula against the exact ``r - sqrt(r² - c²/4)`` and ``c²/(8r)``; the chords against the arc they
replace (every chord point within the sagitta of the circle, the arc's middle within it of the chord, the ends
kept bit for bit); and the wedge cam's profile, whose fit holds an arc of radius ~2.2e7 mm, limited to
5000 mm and measured again, independently, on the exact curve.
"""
from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from camfab import pipeline
from camfab.discretize import arcs_within_radius, measure_deviation
from camfab.geom2d import ArcChain, chord_large_arcs, chord_sagitta
from camfab.tolerances import MAX_ARC_RADIUS_MM


@pytest.mark.parametrize("r,c", [(10.0, 3.0), (57850.0, 40.0), (22_497_266.0, 150.0)])
def test_sagitta_is_exact(r, c):
    sweep = 2 * math.asin(c / (2 * r))
    exact = r - math.sqrt(r * r - c * c / 4)  # cancels for huge r: compare loosely there
    assert chord_sagitta(r, sweep) == pytest.approx(c * c / (8 * r), rel=(c / r) ** 2)  # the series' next term
    assert chord_sagitta(r, sweep) == pytest.approx(exact, rel=1e-6 if r < 1e5 else 1e-2)


def _arc_chain(r: float, sweep: float) -> ArcChain:
    """A closed chain: an arc of radius r about (0, -r) from (-a, y0) to (a, y0) over the top, closed by a line."""
    half = sweep / 2
    p0 = np.array([-r * math.sin(half), -r + r * math.cos(half)])
    p1 = np.array([r * math.sin(half), p0[1]])
    return ArcChain.from_bulges(np.array([p0, p1]), np.array([-math.tan(sweep / 4), 0.0]))


@pytest.mark.parametrize("r,length,sag", [(6000.0, 80.0, 1e-4), (57850.0, 60.0, 5e-5), (2.2e7, 300.0, 1e-5)])
def test_chords_stay_within_their_sagitta(r, length, sag):
    chain = _arc_chain(r, length / r)
    out, used = chord_large_arcs(chain, MAX_ARC_RADIUS_MM, sag)
    assert 0 < used <= sag
    assert out.is_line.all() and out.closed
    assert np.array_equal(out.starts[0], chain.starts[0]) and np.array_equal(out.ends[-2], chain.ends[0])
    assert np.array_equal(out.ends[:-1], out.starts[1:])  # still joined, bit for bit
    centre = chain.centres[0]
    # every chord within the sagitta of the circle (its middle is the farthest point), and the circle between
    # two chord vertices within it of the chord (the vertices are on the circle)
    mids = 0.5 * (out.starts[:-1] + out.ends[:-1])
    gap = r - np.hypot(*(mids - centre).T)
    assert np.all(gap >= -1e-9) and gap.max() <= sag * (1 + 1e-6)
    assert np.allclose(np.hypot(*(out.starts[:-1] - centre).T), r, rtol=0, atol=1e-8)
    n = out.n_entities - 1
    assert n == max(1, math.ceil(abs(chain.sweeps[0]) / (4 * math.asin(math.sqrt(sag / (2 * r))))))


def test_small_arcs_are_kept():
    chain = _arc_chain(100.0, 1.0)
    out, used = chord_large_arcs(chain, MAX_ARC_RADIUS_MM, 1e-4)
    assert out is chain and used == 0.0


def test_wedge_profile_limited_within_tolerance():
    cam = pipeline.load("wedge_translating")
    tol = cam.tolerance()
    curve = cam.shapes().curves[0]
    # the wedge's fit as the fitter once made it (tests/cad/data): its near-straight stretch a huge arc
    data = json.loads((Path(__file__).parents[1] / "cad" / "data" / "wedge_fit_67222e9.json").read_text())
    fit = ArcChain.from_bulges(data["starts"], data["bulges"], closed=True)
    fit = fit.with_deviation(float(measure_deviation(fit, curve).max))
    assert fit.radii[~fit.is_line].max() > 1e6 and fit.max_deviation <= tol
    out = arcs_within_radius(fit, curve, tol=tol, max_radius_mm=MAX_ARC_RADIUS_MM)
    assert np.all(out.radii[~out.is_line] <= MAX_ARC_RADIUS_MM)
    dev = float(measure_deviation(out, curve, samples=60000).max)
    assert dev <= tol and out.max_deviation == pytest.approx(dev, rel=1e-3)
    # the chords alone (no refit): the entities the limit leaves alone are the fit's own, bit for bit
    chords, used = chord_large_arcs(fit, MAX_ARC_RADIUS_MM, tol - fit.max_deviation)
    assert 0 < used <= tol - fit.max_deviation
    kept = [i for i in range(fit.n_entities) if fit.is_line[i] or fit.radii[i] <= MAX_ARC_RADIUS_MM]
    keys = {(tuple(s), tuple(e)) for s, e in zip(chords.starts, chords.ends, strict=True)}
    assert all((tuple(fit.starts[i]), tuple(fit.ends[i])) in keys for i in kept)
    assert float(measure_deviation(chords, curve, samples=60000).max) <= tol
