"""``--force`` on a roller follower whose velocity jumps: the files carry the profile a roller really makes.

The most common unacceptable design puts a constant-velocity rise beside a dwell: the roller centre's path has a
corner there.  The written profile is checked here against the physics, independently of how camfab builds it:
dense exact roller positions along the pitch curve (the corners' one-sided limits included) must never overlap
the part (every centre at least R_r − tol from the profile, and outside it), and every point of the profile must
be touched by some roller position (within R_r + tol of a centre) — together: the profile lies within ``tol`` of
the boundary of the region the roller sweeps.  The G-code's tool centre obeys the same two rules with the
cutter radius against that written profile.
"""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.spatial import cKDTree

import camfab
from camfab.cli import main
from camfab.discretize import Chain
from camfab.errors import GeometryError
from camfab.offset.corners import profile_corners
from camfab.offset.cutter import offset_curve, profile_curve
from tests.conftest import EXAMPLES, cv_jump

ezdxf = pytest.importorskip("ezdxf")
shapely = pytest.importorskip("shapely")



def _design(tmp_path, rotation="cw", roller=8.0, offset=0.0, tool=6.0):
    d = tmp_path / f"cv_{rotation}_{roller}_{offset}_{tool}.toml"
    d.write_text(cv_jump("roller", roller, rotation, offset, tool))
    return d


def _profile_chain(path) -> Chain:
    doc = ezdxf.readfile(path)
    (pl,) = doc.modelspace().query("LWPOLYLINE[layer=='PROFILE']")
    return Chain.from_bulges(np.array(list(pl.get_points("xyb"))), closed=True)


def _roller_centres(contact, n=100_000) -> np.ndarray:
    """Exact pitch points: a dense grid plus both one-sided limits at every breakpoint."""
    bp = contact.breakpoints
    t = np.concatenate([np.linspace(0.0, contact.period, n), bp, bp - 1e-12])
    return contact.evaluate(np.mod(t, contact.period)).pitch


def _envelope_errors(chain: Chain, centres: np.ndarray, radius: float) -> tuple[float, float, bool]:
    """``(overlap, untouched, centres_outside)``: how far the closest centre comes inside ``radius`` of the
    chain, how far the worst chain point lies beyond ``radius`` from every centre, and whether every centre
    lies outside the part."""
    d_centre, _ = chain.distance(centres)
    pts = chain.sample(65)[0][:, :-1].reshape(-1, 2)  # each entity's end is the next one's start
    d_point, _ = cKDTree(centres).query(pts)
    poly = shapely.Polygon(pts)
    assert poly.is_valid  # a simple closed outline: nothing folds over
    outside = not shapely.contains_xy(poly, centres[:, 0], centres[:, 1]).any()
    return radius - float(d_centre.min()), float(d_point.max()) - radius, outside


@pytest.mark.parametrize("rotation, offset", [("cw", 0.0), ("ccw", 0.0), ("cw", 6.0)])
def test_force_writes_the_profile_a_roller_makes(tmp_path, capsys, rotation, offset):
    d = _design(tmp_path, rotation=rotation, offset=offset)
    out = tmp_path / "out"
    assert main(["export", str(d), "--dxf", "--force", "-o", str(out)]) == 1  # written, still unacceptable
    assert "verdict unacceptable" in capsys.readouterr().out
    chain = _profile_chain(out / "cv_jump.dxf")
    contact = camfab.load(str(d)).geometry.profiles[0]
    overlap, untouched, outside = _envelope_errors(chain, _roller_centres(contact), 8.0)
    assert overlap <= 0.01 and untouched <= 0.01 and outside
    # the four corners: two concave ones filled by an arc of the roller radius about the corner,
    # two convex ones cut back to where the two sides cross
    corners = profile_corners(contact)
    assert sorted(round(math.degrees(c.at)) for c in corners) == [0, 120, 180, 300]
    assert sum(c.convex for c in corners) == 2
    pts = chain.sample(64)[0].reshape(-1, 2)
    for c in corners:
        if c.convex:
            assert np.min(np.hypot(*(pts - c.point).T)) <= 0.01
            continue
        # the profile between the two one-sided contact points is the roller circle about the corner
        a, b = c.centre - 8.0 * c.n_left, c.centre - 8.0 * c.n_right
        near = pts[np.hypot(*(pts - 0.5 * (a + b)).T) < 0.3 * np.hypot(*(a - b))]
        assert near.size and np.abs(np.hypot(*(near - c.centre).T) - 8.0).max() <= 0.01


def test_without_the_arc_the_roller_would_leave_a_step(tmp_path):
    """The envelope formula alone jumps by 2·R_r·sin(turn/2) at the concave corners (0.79 mm here): what the
    arc replaces."""
    contact = camfab.load(str(_design(tmp_path))).geometry.profiles[0]
    (c,) = [c for c in profile_corners(contact) if not c.convex and round(math.degrees(c.at)) == 0]
    raw = contact.evaluate(np.array([contact.period - 1e-9, 0.0])).point
    assert np.hypot(*(raw[1] - raw[0])) == pytest.approx(2 * 8.0 * math.sin(abs(c.turn) / 2), rel=1e-4)
    assert np.hypot(*(raw[1] - raw[0])) > 0.7


def test_force_gcode_cuts_that_profile_without_gouging(tmp_path):
    from camfab.gcode.parse import backplot, sample

    d = _design(tmp_path)
    out = tmp_path / "out"  # the reference profile, written 100 times finer than the program
    assert main(["export", str(d), "--dxf", "--force", "--tol", "1e-4", "-o", str(out)]) == 1
    nc = tmp_path / "cv.nc"
    assert main(["gcode", str(d), "--force", "-o", str(nc)]) == 1
    chain = _profile_chain(out / "cv_jump.dxf")
    moves = [m for m in backplot(nc.read_text()) if m.kind in ("line", "arc")]
    s = sample(moves, step=0.01)
    deep = s.points[:, 2] < -0.5
    tool = s.points[deep, :2]
    d_tool, _ = chain.distance(tool)
    assert d_tool.min() >= 3.0 - 0.01 - 1e-4  # never into the part
    pts = chain.sample(64)[0].reshape(-1, 2)
    reach, _ = cKDTree(tool).query(pts)
    assert reach.max() <= 3.0 + 0.01 + 1e-4  # everything cut
    assert main(["verify", str(nc), "--design", str(d)]) == 0


def test_a_cutter_as_large_as_the_roller_is_refused(tmp_path, capsys):
    d = _design(tmp_path, tool=16.0)
    assert main(["gcode", str(d), "--force", "-o", str(tmp_path / "x.nc")]) == 2
    err = capsys.readouterr().err
    assert "roller radius 8 mm" in err and "gouge" in err and "Traceback" not in err
    assert not (tmp_path / "x.nc").exists()
    contact = camfab.load(str(d)).geometry.profiles[0]
    with pytest.raises(GeometryError, match="smaller tool"):
        offset_curve(contact, 8.0)


def test_the_cornered_curve_is_continuous_and_its_offset_parallel(tmp_path):
    from camfab.discretize.curve import discontinuities, points_at

    contact = camfab.load(str(_design(tmp_path))).geometry.profiles[0]
    prof, off = profile_curve(contact), offset_curve(contact, 3.0)
    assert discontinuities(prof, 1e-6) == [] and discontinuities(off, 1e-6) == []
    p = points_at(prof, np.union1d(np.linspace(0, prof.period, 40_001), prof.breakpoints))
    q = points_at(off, np.union1d(np.linspace(0, off.period, 40_001), off.breakpoints))
    # the offset lies 3 mm from the profile everywhere, and the profile 3 mm from the offset (nearest dense
    # samples, 8 µm apart, the corners among them: within 3e-6 mm of the true distance at 3 mm)
    assert np.abs(cKDTree(p).query(q)[0] - 3.0).max() < 1e-5
    assert np.abs(cKDTree(q).query(p)[0] - 3.0).max() < 1e-5
    # the analytic derivative matches finite differences away from the breakpoints
    t = np.linspace(0, prof.period, 3001)[1:-1]
    t = t[np.min(np.abs(t[:, None] - prof.breakpoints[None, :]), axis=1) > 1e-4]
    h = 1e-7
    fd = (points_at(prof, t + h) - points_at(prof, t - h)) / (2 * h)
    np.testing.assert_allclose(prof.derivative(t), fd, atol=1e-4)


@pytest.mark.parametrize("name", ["ejemplo9rt", "ejemplo1rt", "ejemplo11ro", "ejemplo12po_roller"])
def test_designs_without_a_velocity_jump_have_no_corner(name):
    cam = camfab.load(str(EXAMPLES / f"{name}.toml"))
    for contact in cam.geometry.profiles:
        assert profile_corners(contact) == []


def test_force_on_a_flat_face_writes_the_face_stretch(tmp_path):
    """A flat face's contact point jumps along the face where the velocity jumps: forced, the profile gets the
    face's straight stretch (where it jumps forward) or a cut-back corner (where it jumps back).  Checked with
    the face positions themselves: no position of the face cuts into the written part, and every point of it
    lies on some position of the face (within tol)."""
    d = tmp_path / "flat.toml"
    d.write_text(cv_jump("flat").replace("offset_mm = 0.0\n", ""))
    out = tmp_path / "out"
    assert main(["export", str(d), "--dxf", "--force", "-o", str(out)]) == 1
    contact = camfab.load(str(d)).geometry.profiles[0]
    assert [c.fill for c in sorted(profile_corners(contact), key=lambda c: c.at)] == ["line", "cut", "cut", "line"]
    pts = _profile_chain(out / "cv_jump.dxf").sample(201)[0].reshape(-1, 2)
    bp = contact.breakpoints
    phi = np.concatenate([np.linspace(0.0, contact.period, 20_000), bp, bp - 1e-12]) % contact.period
    s = contact.evaluate(phi)
    inside, touch = -np.inf, np.full(pts.shape[0], np.inf)
    for k in range(0, phi.size, 2000):  # (x − P(φ))·n(φ): > 0 where the face at φ would cut x away
        h = np.einsum("fpi,fi->fp", pts[None, :, :] - s.point[k:k + 2000, None, :], s.normal[k:k + 2000])
        inside = max(inside, float(h.max()))
        touch = np.minimum(touch, np.abs(h).min(axis=0))
    assert inside <= 0.01 and touch.max() <= 0.01


def test_force_on_a_translating_cam_writes_the_roller_profile(tmp_path):
    """The plate of a translating cam: the same corners on its top edge (travel 100, 150: cut back; 250: an arc
    of the roller's radius), within tol of the region the roller sweeps; G-code verified."""
    text = (EXAMPLES / "wedge_translating.toml").read_text().replace('law = "cycloidal"', 'law = "constant_velocity"')
    text = text.replace("lift = 20.0", "lift = 5.0").replace("lift = -20.0", "lift = -5.0")
    d = tmp_path / "wedge.toml"
    d.write_text(text)
    out = tmp_path / "out"
    assert main(["export", str(d), "--dxf", "--force", "--tol", "1e-3", "-o", str(out)]) == 1
    contact = camfab.load(str(d)).geometry.profiles[0]
    corners = sorted(profile_corners(contact), key=lambda c: c.at)
    assert [(round(c.at), c.fill) for c in corners] == [(100, "cut"), (150, "cut"), (250, "arc")]
    chain = _profile_chain(out / "WedgeCam.dxf")
    bp = contact.breakpoints
    t = np.clip(np.concatenate([np.linspace(0.0, contact.period, 100_000), bp, bp - 1e-9]), 0.0,
                np.nextafter(contact.period, 0.0))
    centres = contact.evaluate(t).pitch
    assert chain.distance(centres)[0].min() >= 8.0 - 1e-3  # no roller position overlaps the plate
    pts = chain.sample(65)[0][:, :-1].reshape(-1, 2)
    top = pts[pts[:, 1] > 20.0 + 1e-6]  # the top edge (the plate's S = 0 line is 20 mm up)
    assert cKDTree(centres).query(top)[0].max() <= 8.0 + 1e-3  # every point of it touched by the roller
    nc = tmp_path / "w.nc"
    assert main(["gcode", str(d), "--force", "-o", str(nc)]) == 1
    assert main(["verify", str(nc), "--design", str(d)]) == 0
