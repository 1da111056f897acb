"""The plate DXF written without ezdxf (camfab.cad.dxfwrite) is ezdxf's file byte for byte: every built-in
example's plate in every flavour, with and without tool paths, and generated contents with hostile names; the
cylindrical cam's developed DXF likewise; and ``camfab export --dxf`` no longer imports ezdxf."""
from __future__ import annotations

import dataclasses
import functools
import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import camfab.cad.dxf as dxf_mod
from camfab.cad.dxf import FLAVOURS, LAYERS, DxfContent, build_document, dumps, write_deterministic
from camfab.cad.plate import bore_loop, circle_loop
from camfab.geom2d import ArcChain
from tests.conftest import EXAMPLES

ezdxf = pytest.importorskip("ezdxf")

ROOT = Path(__file__).resolve().parents[2]
if ezdxf.__version__ != "1.4.5":  # the writer's format (camfab.cad.dxfwrite.EZDXF_VERSION); dumps uses ezdxf then
    pytest.skip(f"ezdxf {ezdxf.__version__} installed, the writer reproduces 1.4.5: regenerate "
                "camfab/cad/dxf_skeleton.py with tools/dxf_skeleton.py and compare", allow_module_level=True)
PLATE_EXAMPLES = sorted(p.stem for p in EXAMPLES.glob("*.toml") if not p.stem.startswith("cylindrical"))


def _ezdxf_text(content: DxfContent, flavour: str) -> str:
    return write_deterministic(build_document(content, flavour=flavour))


def _direct(content: DxfContent, flavour: str) -> str:
    """The direct writer's text (checked to be what dumps uses for ``content``)."""
    from camfab.cad import dxfwrite

    assert dxfwrite.writes(content)
    text = dxfwrite.write(content, flavour)
    assert dumps(content, flavour=flavour) == text
    return text


@functools.cache
def _example_content(name: str, tool_paths: bool) -> DxfContent:
    """The DxfContent ``camfab export NAME --dxf [--tool-path]`` writes (caught at dxf.dumps)."""
    import tempfile

    from camfab.cli import main

    got: list[DxfContent] = []
    real = dxf_mod.dumps

    def catch(content, *, flavour="lwpolyline"):
        got.append(content)
        return real(content, flavour=flavour)

    with pytest.MonkeyPatch.context() as mp, tempfile.TemporaryDirectory() as out:
        mp.setattr(dxf_mod, "dumps", catch)
        args = ["export", str(EXAMPLES / f"{name}.toml"), "--dxf", "--force", "-o", out]
        main([*args, "--tool-path"] if tool_paths else args)
    (content,) = got
    return content


def test_every_plate_example_is_found():
    assert len(PLATE_EXAMPLES) >= 14 and "groove_translating" in PLATE_EXAMPLES


@pytest.mark.parametrize("flavour", FLAVOURS)
@pytest.mark.parametrize("name", PLATE_EXAMPLES)
def test_examples_byte_identical_to_ezdxf(name, flavour):
    with_tools = _example_content(name, True)
    for content in (with_tools, dataclasses.replace(with_tools, tool_paths=())):
        assert _direct(content, flavour) == _ezdxf_text(content, flavour)


def test_examples_exercise_tool_paths_groove_and_conjugates():
    """The examples above cover what varies: tool paths, a groove's PLATE layer, a second profile."""
    contents = [_example_content(n, True) for n in PLATE_EXAMPLES]
    assert any(c.tool_paths for c in contents)
    assert any(c.plate_outline is not None for c in contents)
    assert any(len(c.profiles) > 1 for c in contents)


def test_export_content_without_tool_paths_is_the_same_less_the_paths():
    """The 'without tool paths' case above is what the export makes without --tool-path."""
    for name in ("ejemplo9rt", "groove_translating"):
        less = dataclasses.replace(_example_content(name, True), tool_paths=())
        assert _ezdxf_text(_example_content(name, False), "r12") == _ezdxf_text(less, "r12")


# ---- generated contents -------------------------------------------------------------------------------------
_coord = st.one_of(st.floats(-500, 500, allow_nan=False, allow_infinity=False),
                   st.sampled_from([0.0, -0.0, 1e-9, -1e-12, 123456.789, 0.1 + 0.2]))
_bulge = st.one_of(st.just(0.0), st.just(-0.0), st.sampled_from([1e-16, -1e-14, 1.0, -1.0, 0.4142135623730951]),
                   st.floats(-3, 3, allow_nan=False, allow_infinity=False))


@st.composite
def _chains(draw):
    n = draw(st.integers(2, 9))
    pts = draw(st.lists(st.tuples(_coord, _coord), min_size=n, max_size=n, unique=True))
    pts = np.asarray(pts, dtype=float)
    if np.min(np.hypot(*(pts[:, None] - pts[None]).transpose(2, 0, 1))[~np.eye(n, dtype=bool)]) < 1e-6:
        pts = pts + np.arange(n)[:, None] * 7.0  # keep the vertices apart (an arc needs a chord)
    bulges = draw(st.lists(_bulge, min_size=n, max_size=n))
    with np.errstate(all="ignore"):  # a bulge of 1e-16 has a centre far out (unused: written as a line or bulge)
        return ArcChain.from_bulges(pts, np.asarray(bulges), closed=draw(st.booleans()))


_HOSTILE = ["", "cam", "a\nb", "  0\nEOF\n", "\r\n  9\n$HANDSEED\n  5\nFFFF", "\x00\x01\x1b\x7f\x85", "^J^M ^^",
            "Ñandú ✓ 凸轮 \U0001f600", "\u2028\u2029", "x" * 5000, "%%d \\U+0041 {}", "name\twith\ttabs"]
_name = st.one_of(st.sampled_from(_HOSTILE), st.text(max_size=60))
_radius = st.one_of(st.none(), st.just(0.0), st.floats(0.001, 400, allow_nan=False))


@st.composite
def _contents(draw):
    chains = st.lists(_chains(), max_size=3)
    return DxfContent(
        profiles=tuple(draw(chains)), pitch_curves=tuple(draw(chains)), base_radius=draw(_radius),
        prime_radius=draw(_radius), bore=draw(st.one_of(st.none(), _chains(), st.just(bore_loop(12.0, True)))),
        tool_paths=tuple(draw(chains)), tol_mm=draw(st.sampled_from([0.001, 1e-4, 0.05, 2.5e-6, 1])),
        deviation_mm=draw(st.one_of(st.none(), st.floats(0, 1, allow_nan=False), st.just(-0.0))),
        name=draw(_name),
        extra_circles=tuple(draw(st.lists(st.tuples(st.sampled_from(sorted(LAYERS)), _radius.map(lambda r: r or 0.0)),
                                          max_size=3))),
        plate_outline=draw(st.one_of(st.none(), st.just(circle_loop(55.5)), _chains())))


@settings(max_examples=120, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(content=_contents(), flavour=st.sampled_from(FLAVOURS))
def test_generated_contents_byte_identical_to_ezdxf(content, flavour):
    with np.errstate(all="ignore"):
        assert _direct(content, flavour) == _ezdxf_text(content, flavour)


def test_straight_and_open_pieces_in_every_flavour():
    """Open chains (an LWPOLYLINE's flag 0, a SPLINE ending on the last end) and pure lines."""
    open_arc = ArcChain.from_bulges([[0.0, 0.0], [10.0, 0.0], [10.0, 10.0]], [0.5, -0.25, 0.0], closed=False)
    square = ArcChain.from_polyline([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    content = DxfContent((square, open_arc), (open_arc,), tool_paths=(square,), name="o",
                         plate_outline=circle_loop(math.pi))
    for flavour in FLAVOURS:
        assert _direct(content, flavour) == _ezdxf_text(content, flavour)


def test_skeleton_is_what_installed_ezdxf_makes():
    """camfab/cad/dxf_skeleton.py is tools/dxf_skeleton.py's output for the ezdxf installed (regenerate it after
    an ezdxf upgrade)."""
    import importlib.util

    from camfab.cad import dxf_skeleton

    spec = importlib.util.spec_from_file_location("dxf_skeleton_tool", ROOT / "tools" / "dxf_skeleton.py")
    tool = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(tool)
    assert ezdxf.__version__ == dxf_skeleton.EZDXF_VERSION
    assert tool.module_text() == (ROOT / "camfab" / "cad" / "dxf_skeleton.py").read_text(encoding="utf-8")


def test_extra_circle_on_a_layer_of_the_callers_goes_through_ezdxf(monkeypatch):
    """The one content the direct writer leaves to ezdxf: an extra circle on a layer not camfab's (ezdxf checks
    the name).  A valid name gives ezdxf's bytes, an invalid one ezdxf's error, as before."""
    import camfab.cad.dxfwrite as dxfwrite

    ours = DxfContent((circle_loop(10.0),), extra_circles=(("BASE_CIRCLE", 4.0),))
    theirs = DxfContent((circle_loop(10.0),), extra_circles=(("HOLES", 4.0),))
    assert dxfwrite.writes(ours) and not dxfwrite.writes(theirs)

    def refuse(content, flavour):
        raise AssertionError("the direct writer was used")

    monkeypatch.setattr(dxfwrite, "write", refuse)
    for flavour in FLAVOURS:
        assert dumps(theirs, flavour=flavour) == _ezdxf_text(theirs, flavour)
    with pytest.raises(ezdxf.DXFValueError):
        dumps(DxfContent((circle_loop(10.0),), extra_circles=(("A;B", 4.0),)))
    with pytest.raises(AssertionError, match="direct writer"):
        dumps(ours)


def test_installed_ezdxf_version_read_without_importing_it():
    from camfab.cad.dxfwrite import installed_ezdxf_version, same_ezdxf

    assert installed_ezdxf_version() == ezdxf.__version__
    assert same_ezdxf() == (ezdxf.__version__ == "1.4.5")


def test_another_ezdxf_version_writes_through_ezdxf(monkeypatch):
    """With an ezdxf other than the writer's installed, the plate and developed DXFs are that ezdxf's own bytes."""
    import camfab.cad.dxfwrite as dxfwrite
    from camfab.cad import cylinder

    def refuse(*args):
        raise AssertionError("the direct writer was used")

    monkeypatch.setattr(dxfwrite, "same_ezdxf", lambda: False)
    monkeypatch.setattr(cylinder, "same_ezdxf", lambda: False)
    monkeypatch.setattr(dxfwrite, "write", refuse)
    monkeypatch.setattr(cylinder, "developed", refuse)
    content = _example_content("groove_translating", True)
    for flavour in FLAVOURS:
        assert dumps(content, flavour=flavour) == _ezdxf_text(content, flavour)
    chain = ArcChain.from_bulges([[0.0, 0.0], [5.0, 1.0], [9.0, 0.0]], [0.2, 0.0, 0.0], closed=False,
                                 max_deviation=1e-3)
    monkeypatch.setattr(cylinder, "developed_curves", lambda geometry, tol: (chain, chain, chain))
    geometry = type("G", (), {"cylinder": type("C", (), {"radius_mm": 30.0, "length_mm": 60.0})()})()
    text, dev = cylinder.developed_dxf(geometry, tol=0.01, name="b")
    assert text == _developed_ezdxf("b", 0.01, dev, (chain, chain, chain), 2 * math.pi * 30.0, 60.0)


def test_bad_flavour_refused_before_writing():
    with pytest.raises(ValueError, match="lwpolyline, r12, spline"):
        dumps(DxfContent(()), flavour="r14")


# ---- the command --------------------------------------------------------------------------------------------
@pytest.mark.parametrize("name", ["ejemplo9rt", "groove_translating", "ejemplo8da_conjugate"])
def test_export_dxf_imports_no_ezdxf_and_writes_ezdxf_bytes(tmp_path, name):
    """A disc, a groove and a conjugate pair: the plate DXF of the command is the ezdxf path's bytes."""
    from tests.test_lazy_imports import _run

    out = tmp_path / "out"
    last = _run(tmp_path, "export", str(EXAMPLES / f"{name}.toml"), "--dxf", "--force", "-o", str(out))
    assert last["code"] in (0, None)
    assert "ezdxf" not in last["modules"]
    (written,) = out.glob("*.dxf")
    assert written.read_bytes() == _ezdxf_text(_example_content(name, False), "lwpolyline").encode("utf-8")


# ---- the cylindrical cam's developed DXF ----------------------------------------------------------------------
def _developed_ezdxf(name, tol, dev, curves, width, length):
    from camfab.cad.cylinder import developed_document

    return write_deterministic(developed_document(name, tol, dev, curves, width, length))


@pytest.mark.parametrize("tol", [0.01, 0.003])
def test_cylinder_example_developed_dxf_byte_identical(tol):
    from camfab.cad.cylinder import developed_curves, developed_dxf
    from camfab.design.mechanisms import geometry_from_spec
    from camfab.formats import load_design

    geom = geometry_from_spec(load_design(EXAMPLES / "cylindrical_translating.toml"))
    text, dev = developed_dxf(geom, tol=tol, name="barrel ^ \n")
    curves = developed_curves(geom, tol)
    cyl = geom.cylinder
    assert text == _developed_ezdxf("barrel ^ \n", tol, dev, curves, 2 * math.pi * cyl.radius_mm, cyl.length_mm)


@st.composite
def _open_chains(draw):
    chain = draw(_chains())
    return dataclasses.replace(chain, closed=False)


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(curves=st.tuples(_open_chains(), _open_chains(), _open_chains()), name=_name,
       tol=st.sampled_from([0.01, 1e-4, 2]), dev=st.floats(0, 1, allow_nan=False),
       width=st.floats(1, 3000, allow_nan=False), length=st.one_of(st.integers(1, 500), st.floats(1, 500)))
def test_generated_developed_dxf_byte_identical(curves, name, tol, dev, width, length):
    from camfab.cad.dxfwrite import developed

    with np.errstate(all="ignore"):
        assert developed(name, tol, dev, curves, width, length) == _developed_ezdxf(name, tol, dev, curves, width,
                                                                                    length)


def test_export_dxf_of_a_cylindrical_cam_imports_no_ezdxf(tmp_path):
    from tests.test_lazy_imports import _run

    out = tmp_path / "out"
    last = _run(tmp_path, "export", str(EXAMPLES / "cylindrical_translating.toml"), "--dxf", "--force", "-o", str(out))
    assert last["code"] in (0, None)
    assert "ezdxf" not in last["modules"]
    (written,) = out.glob("*.dxf")
    assert written.read_bytes().startswith(b"  0\nSECTION\n  2\nHEADER\n") and b"OUTLINE" in written.read_bytes()
