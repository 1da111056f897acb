"""``Contact.evaluate_fields``: only the fields asked for, bit for bit those of the whole sample, in bounded memory."""
from __future__ import annotations

import tracemalloc
from pathlib import Path

import numpy as np
import pytest

import camfab
from camfab.design.mechanisms import geometry_from_spec
from camfab.design.profile import CHUNK, ProfileSample
from camfab.errors import ApiError
from camfab.formats.design_files import load_design

EXAMPLES = Path(camfab.__file__).resolve().parent / "examples"
FIELDS = tuple(ProfileSample.__dataclass_fields__)
#: every contact family of the examples: rollers, faces, curved faces, conjugate pairs, groove flanks, wedge, cylinder
NAMES = ("ejemplo9rt", "ejemplo11ro", "ejemplo1rt", "ejemplo8da_conjugate", "groove_translating", "finger_follower",
         "valve_mushroom", "wedge_translating", "cylindrical_translating", "ejemplo10ex")


def _contacts(name):
    return geometry_from_spec(load_design(EXAMPLES / f"{name}.toml")).profiles


@pytest.mark.parametrize("name", NAMES)
def test_fields_bit_identical_to_the_whole_sample(name):
    for contact in _contacts(name):
        for n in (7, CHUNK + 3):
            phi = np.linspace(-0.3, 1.1 * contact.period, n)
            whole = contact.evaluate(phi)
            got = contact.evaluate_fields(phi, FIELDS)
            for f in FIELDS:
                a, b = getattr(whole, f), got[f]
                if a is None:
                    assert b is None, (name, f)
                    continue
                assert b.shape == a.shape, (name, n, f)
                assert np.array_equal(a, b, equal_nan=True), (name, n, f)
            # subsets (the points alone take a shorter path for rollers): the same values, nothing else returned
            for subset in (("point",), ("point_d1",), ("point", "point_d1"), ("point", "rho")):
                part = contact.evaluate_fields(phi, subset)
                assert set(part) == set(subset)
                for f in subset:
                    assert np.array_equal(part[f], getattr(whole, f), equal_nan=True), (name, n, subset, f)


def test_unknown_field_is_refused():
    contact = _contacts("ejemplo9rt")[0]
    with pytest.raises(ApiError, match="unknown profile field"):
        contact.evaluate_fields(np.zeros(3), ("point", "radius"))


def test_points_only_need_bounded_working_memory():
    """The whole sample is 16 arrays; the points alone are 2 arrays plus one chunk's working sample, whatever
    the angle count (the working memory above the output does not grow with it)."""
    contact = _contacts("ejemplo9rt")[0]

    def peak(fn):
        tracemalloc.start()
        fn()
        _, p = tracemalloc.get_traced_memory()
        tracemalloc.stop()
        return p

    work = []
    for n in (20 * CHUNK, 40 * CHUNK):
        phi = np.linspace(0.0, contact.period, n)
        whole = peak(lambda phi=phi: contact.evaluate(phi))
        points = peak(lambda phi=phi: contact.evaluate_fields(phi, ("point",)))
        assert whole > 14 * n * 8  # the sample's rows
        assert points < 0.35 * whole
        work.append(points - 2 * n * 8)
    assert work[1] < 1.1 * work[0] + 8 * CHUNK * 8, work
