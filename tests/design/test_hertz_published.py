"""Hertz line contact against a published worked example with printed numbers.

Source: A. P. Boresi and R. J. Schmidt, *Advanced Mechanics of Materials* (Wiley), chapter 17 "Contact stresses",
the worked example on two parallel cylinders on p. 621 (Ex. 3 of chapter 17 in the FOSSEE Python Textbook
Companion for this book, which carries the book's printed answers: https://tbc-python.fossee.in/convert-notebook/
Advanced_Mechanics_of_Materials_by_A._P._Boresi_and_R._J._Schmidt/Chapter17.ipynb, "Ex3-pg621").
Data: two steel cylinders, E = 200 GPa, ν = 0.29, both of radius R = 40 mm, contact length h = 20 mm,
load P = 24.1 kN.  Printed results: σ_max = −1445 MPa (the surface pressure p_max, compressive),
τ_max = 433 MPa, τ_oct,max = 361 MPa.

Boresi's convention: b is the HALF-width of the contact band (width 2b), the load P is the total force on the length
h (not per unit length), and with ``A + B = (1/R₁ + 1/R₂)/2`` and ``Δ = [(1 − ν₁²)/E₁ + (1 − ν₂²)/E₂]/(A + B)``::

    b = √(2·P·Δ/(π·h))        σ_max = −b/Δ   (= −p_max)

camfab's ``hertz_line`` takes the same total force and face width and returns ``(p_max, a)`` with a the half-width:
``a ≡ b`` and ``p_max ≡ b/Δ`` (Δ = 2/(E*·(1/R*)) ties the two notations).  Exactly, b/Δ = 1447.0 MPa; the book
prints 1445 MPa, rounded through its intermediate b — hence the tolerance of 3 MPa (0.2 %).  τ_max and τ_oct are
the book's fixed multiples of b/Δ (0.30 and 0.25 for ν ≈ 0.3), not computed by camfab."""
from __future__ import annotations

import math

import numpy as np
import pytest

from camfab.design.dynamics import ContactDynamics, Loads
from camfab.design.materials import Material
from camfab.design.profile import CamGeometry
from camfab.design.program import MotionProgram
from camfab.design.rollers import TranslatingRoller
from camfab.design.strength import (
    StrengthInput,
    StressModel,
    analyse_strength,
    effective_modulus,
    hertz_line,
    relative_curvature,
)
from camfab.units import RPM

#: Boresi & Schmidt's example (chapter 17, p. 621): E (MPa), ν, R₁ = R₂ (mm), h (mm), P (N); printed σ_max (MPa)
E, NU, R, H, P = 200e3, 0.29, 40.0, 20.0, 24.1e3
PRINTED_P_MAX = 1445.0
PRINTED_TOL = 3.0
BORESI_STEEL = Material("Boresi steel", E, NU, 1445.0 * 1.5)


def _boresi_b_and_delta() -> tuple[float, float]:
    """The book's own formulas (its notation), to show the conventions line up."""
    a_plus_b = 0.5 * (1 / R + 1 / R)
    delta = (2 * (1 - NU * NU) / E) / a_plus_b
    return math.sqrt(2 * P * delta / (math.pi * H)), delta


def test_boresi_two_cylinders():
    """camfab's ``hertz_line`` (the function the contact-stress rule calls) on the book's data gives the printed
    p_max within its rounding, and its half-width is the book's b."""
    e_star = effective_modulus(E, NU, E, NU)
    p, a = hertz_line(P, e_star, H, relative_curvature(1 / R, R))
    assert float(p) == pytest.approx(PRINTED_P_MAX, abs=PRINTED_TOL)
    b, delta = _boresi_b_and_delta()
    assert float(a) == pytest.approx(b, rel=1e-12)  # same half-width convention
    assert float(p) == pytest.approx(b / delta, rel=1e-12)  # |σ_max| = b/Δ
    assert float(a) == pytest.approx(0.530, abs=5e-4)
    assert float(p) == pytest.approx(2 * P / (math.pi * float(a) * H), rel=1e-12)  # p_max = 2P/(π·b·h)


def test_boresi_cylinders_as_a_cam_dwell():
    """The same contact inside a mechanism: a translating roller of radius 40 mm on a disc cam whose base circle
    (the profile in the dwell) has radius 40 mm, face width 20 mm, pressed by a spring preload of 24.1 kN and no
    spring rate.  In the dwell S = S' = S'' = 0 and the pressure angle is 0, so the contact force is exactly the
    preload and the profile's radius of curvature is the base radius: camfab's contact stress there (the model
    :func:`analyse_strength` searches) is the book's p_max; over the whole cycle the peak is no lower."""
    program = MotionProgram.from_segments([("dwell", 0, 90), ("cycloidal", 5, 90), ("dwell", 0, 90),
                                           ("cycloidal", -5, 90)])
    geom = CamGeometry(TranslatingRoller(R, R), program)
    contact = geom.profiles[0]
    dwell = np.radians([10.0, 45.0, 80.0])
    fixed = contact.evaluate_fixed(dwell)
    np.testing.assert_allclose(fixed.rho, R, rtol=1e-12)
    dyn = ContactDynamics(contact, Loads(0.2, 0.0, P), 100 * RPM)
    np.testing.assert_allclose(dyn.evaluate(dwell).contact_force, P, rtol=1e-12)
    e_star = effective_modulus(E, NU, E, NU)
    stress = StressModel(dyn, e_star, H).evaluate(dwell).stress
    np.testing.assert_allclose(stress, PRINTED_P_MAX, atol=PRINTED_TOL)
    summary, _ = analyse_strength(geom, StrengthInput(dyn, BORESI_STEEL, BORESI_STEEL, H, BORESI_STEEL.allowable_mpa))
    assert summary.max_mpa is not None and summary.max_mpa >= float(stress[0]) * (1 - 1e-12)
