"""Form closure is a class attribute of each family's geometry (``CamGeometry.form_closed``), the same as its
cam kind's (``CamKind.form_closed``), so the check and the force model ask the geometry instead of looking for
the families' modules; a disc groove's flanks are its force model's pair (``flank_pair``)."""
from __future__ import annotations

import tomllib

import pytest

from camfab.design.assemble import check_design, geometry_from_spec
from camfab.design.dynamics import Loads, analyse_dynamics, pair_of
from camfab.design.kinds import CamKind
from camfab.design.mechanisms import MECHANISMS
from camfab.design.spec import design_from_dict
from camfab.errors import InputError, SpecError
from camfab.formats import load_design
from camfab.units import RPM

from ..conftest import EXAMPLES

#: the kinds whose cams drive the follower both ways (no return spring)
FORM_CLOSED = {CamKind.CONJUGATE, CamKind.CONSTANT_WIDTH, CamKind.CONSTANT_DIAMETER, CamKind.GROOVE,
               CamKind.CYLINDRICAL}


@pytest.mark.parametrize("key", list(MECHANISMS), ids=lambda k: "-".join(k))
def test_every_family_geometry_says_whether_it_is_form_closed(key):
    kind = key[0]
    cls = MECHANISMS[key]
    assert cls.cam_kind is kind
    assert cls.geometry_class.form_closed is (kind in FORM_CLOSED) is kind.form_closed
    assert cls.geometry_class.flank_pair is (kind is CamKind.GROOVE)


@pytest.mark.parametrize("example", ["ejemplo9rt", "ejemplo8da_conjugate", "constant_width", "constant_diameter",
                                     "groove_translating", "cylindrical_translating", "wedge_translating"])
def test_example_geometries_carry_their_kinds_closure(example):
    spec = load_design(EXAMPLES / f"{example}.toml")
    geom = geometry_from_spec(spec)
    assert geom.form_closed is spec.cam.kind.form_closed
    assert (check_design(spec).cylinder is not None) is (spec.cam.kind is CamKind.CYLINDRICAL)


@pytest.mark.parametrize("example", ["ejemplo8da_conjugate", "constant_width", "groove_translating"])
def test_force_model_default_follows_the_geometry(example):
    """``analyse_dynamics`` without ``form_closed`` takes the geometry's: the same report as given explicitly."""
    geom = geometry_from_spec(load_design(EXAMPLES / f"{example}.toml"))
    loads, speed = Loads(1.5, 0.0, 0.0), 200 * RPM  # inertia alone: the load reverses
    default = analyse_dynamics(geom, loads, speed)
    assert default.summary.form_closed
    assert default == analyse_dynamics(geom, loads, speed, form_closed=True)
    reversals = [f.message for f in default.findings if f.code == "LOAD_REVERSAL"]
    assert reversals and all(("flank" in m) is geom.flank_pair for m in reversals)


def test_cylindrical_cam_has_no_force_model():
    """A cylindrical cam's [dynamics] is refused with its field path (it has six developed contacts and no force
    model), and the force model refuses its geometry."""
    data = tomllib.loads((EXAMPLES / "cylindrical_translating.toml").read_text())
    with pytest.raises(SpecError) as e:
        design_from_dict({**data, "dynamics": {"mass_kg": 1.0}})
    assert [p.path for p in e.value.problems] == ["dynamics"]
    geom = geometry_from_spec(design_from_dict(data))
    with pytest.raises(InputError, match="no force model"):
        pair_of(geom, Loads(1.0, 0.0, 0.0), 60 * RPM)
