"""The loft's sections of a grooved cylinder (``camfab.cad.cylinder.groove_sections``): every point lies in its
section's plane (normal to the 3D pitch curve), on the cylinder of its radius, and is the flank's crossing of that
plane found independently by Brent's method on the exact flank, to 1e-9 mm."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from scipy.optimize import brentq

from camfab.cad.cylinder import SECTION_RADII, _wrap, groove_sections
from camfab.design.cylindrical import pitch_3d
from camfab.design.mechanisms import geometry_from_spec
from camfab.formats import load_design

EXAMPLE = Path(__file__).parents[2] / "camfab" / "examples" / "cylindrical_translating.toml"


def test_section_points_are_the_exact_flank_crossings_of_their_planes():
    geom = geometry_from_spec(load_design(EXAMPLE))
    cyl = geom.cylinder
    radii = np.linspace(cyl.inner_radius_mm, cyl.outer_radius_mm + 1.0, SECTION_RADII)
    n = 48
    theta, sections = groove_sections(geom, n, radii)
    assert sections.shape == (n, 2, SECTION_RADII, 3)
    # the plane of section k: through the 3D pitch point, normal to the pitch curve's tangent (five-point stencil)
    h = 1e-3
    centre = pitch_3d(geom, theta)
    along = 8 * (pitch_3d(geom, theta + h) - pitch_3d(geom, theta - h)) - (pitch_3d(geom, theta + 2 * h)
                                                                          - pitch_3d(geom, theta - 2 * h))
    along /= np.linalg.norm(along, axis=1)[:, None]
    off_plane = np.einsum("kfjc,kc->kfj", sections - centre[:, None, None, :], along)
    assert np.abs(off_plane).max() < 1e-9
    assert np.allclose(np.hypot(sections[..., 0], sections[..., 1]), radii[None, None, :], rtol=0, atol=1e-9)
    for k in range(0, n, 7):
        for f, flank in enumerate((1, -1)):
            for j in (0, SECTION_RADII - 1):
                r = float(radii[j])
                contact = geom.at_radius(r, flank)

                def side(t, r=r, contact=contact, k=k):
                    p = _wrap(geom, r, contact.evaluate(np.array([t])).point)[0]
                    return float((p - centre[k]) @ along[k])

                ts = theta[k] + np.linspace(-0.3, 0.3, 601)
                s = (_wrap(geom, r, contact.evaluate(ts).point) - centre[k]) @ along[k]
                i = int(np.nonzero(np.sign(s[:-1]) != np.sign(s[1:]))[0][0])
                t = brentq(side, ts[i], ts[i + 1], xtol=1e-14, rtol=1e-15)
                exact = _wrap(geom, r, contact.evaluate(np.array([t])).point)[0]
                assert np.linalg.norm(sections[k, f, j] - exact) < 1e-9, (k, flank, r)
    assert math.isclose(float(theta[1] - theta[0]), geom.period / n)
