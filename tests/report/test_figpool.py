"""The report's kept figures (camfab/report/figpool.py): a figure drawn again for another design gives the same
SVG bytes as a new figure of that design, whatever was drawn in it before (a closed roller cam, a translating
wedge, a flat face with dynamics, a conjugate pair, a constant-width cam, in an order that changes the kind at
every step); outside the block every call makes a new figure."""
from __future__ import annotations

import pytest

import camfab

pytest.importorskip("matplotlib")

from camfab.report.figpool import reusing_figures  # noqa: E402
from camfab.report.plots import figure_bytes, report_figures  # noqa: E402

ORDER = ["ejemplo9rt", "wedge_translating", "valve_mushroom", "ejemplo8da_conjugate", "constant_width",
         "finger_follower", "ejemplo9rt"]


def _svgs(figures) -> dict[str, bytes]:
    return {name: figure_bytes(fig, "svg") for name, fig in figures.items()}


@pytest.mark.slow
def test_a_kept_figure_draws_what_a_new_one_draws():
    cams = {e: camfab.load(e) for e in dict.fromkeys(ORDER)}
    args = {e: (c.spec, c.geometry, c.check()) for e, c in cams.items()}
    new = {e: _svgs(report_figures(*args[e])) for e in cams}
    kept: dict[str, int] = {}
    reused = 0
    for e in ORDER:
        with reusing_figures():
            figures = report_figures(*args[e])
            reused += sum(kept.get(name) == id(fig) for name, fig in figures.items())
            kept.update({name: id(fig) for name, fig in figures.items()})
            assert _svgs(figures) == new[e], e
    assert reused >= 10  # the figures were drawn again, not made anew


def test_outside_the_block_every_figure_is_new():
    cam = camfab.load("ejemplo9rt")
    args = (cam.spec, cam.geometry, cam.check())
    with reusing_figures():
        report_figures(*args)
    first, second = report_figures(*args), report_figures(*args)
    assert all(first[n] is not second[n] for n in first)
