"""Property-based fuzzing of the input edge (issue "trust at the edges"): every design either computes or is refused
with field paths — never a traceback, never over a memory cap.

Three generators, each bounded for CI:

* **mutated designs**: a built-in example's TOML structure with 1–4 random edits (a value replaced by a hostile
  one — negative, zero, NaN, ±inf, 1e300, 1e-300, a long string, a list, a table, a bool —, a key deleted or
  added, a segment duplicated, dropped or re-spanned) goes through :func:`camfab.design_from_dict` and, when
  accepted, through ``Cam.check()``;
* **knot tables**: random inline ``[motion_table]`` rows (sorted or not, close or far apart, finite or not, in
  random units and degree);
* **TOML text**: random text and random damage to an example's file, read by :func:`camfab.load_design`.

An outcome is admissible when it is a check report (any verdict), or a :class:`~camfab.errors.SpecError` whose
every problem has a field path, or another deliberate :class:`~camfab.errors.CamfabError` (a geometry refusal)
that is not a bug class (:class:`~camfab.errors.ApiError`, :class:`~camfab.errors.InternalError`).  Anything
else — ``ValueError``, ``ZeroDivisionError``, ``RecursionError``, ``MemoryError`` — fails the test.

Memory: each example runs under a soft address-space limit of the process's current size plus
:data:`BUDGET` (``RLIMIT_AS``), so an allocation that grows with the input surfaces as a ``MemoryError``, a
failure, instead of taking the machine down.
"""
from __future__ import annotations

import contextlib
import copy
import math
import os
import resource
import tomllib
from pathlib import Path
from typing import Any

import pytest
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st

import camfab
from camfab.errors import ApiError, CamfabError, InternalError, SpecError

EXAMPLES = Path(camfab.__file__).resolve().parent / "examples"
BASES = {p.stem: tomllib.loads(p.read_text()) for p in sorted(EXAMPLES.glob("*.toml"))
         if "motion_table" not in tomllib.loads(p.read_text())}
BUDGET = 2 << 30  # bytes of address space each example may add
EXAMPLES_PER_TEST = int(os.environ.get("CAMFAB_FUZZ_EXAMPLES", "200"))  # more for a deeper local run
SETTINGS = settings(max_examples=EXAMPLES_PER_TEST, deadline=None, derandomize=True, database=None,
                    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])

pytestmark = pytest.mark.slow


@contextlib.contextmanager
def memory_cap(budget: int = BUDGET):
    """Lower the soft RLIMIT_AS to the current size + ``budget`` for the block, then restore it."""
    with open("/proc/self/statm") as f:
        pages = int(f.read().split()[0])
    size = pages * resource.getpagesize()
    soft, hard = resource.getrlimit(resource.RLIMIT_AS)
    cap = size + budget
    if hard != resource.RLIM_INFINITY:
        cap = min(cap, hard)
    resource.setrlimit(resource.RLIMIT_AS, (cap, hard))
    try:
        yield
    finally:
        resource.setrlimit(resource.RLIMIT_AS, (soft, hard))


def admissible(data: Any) -> str:
    """Validate ``data`` and check it; returns the outcome's kind, raises AssertionError on a bug."""
    with memory_cap():
        try:
            spec = camfab.design_from_dict(data)
            cam = camfab.Cam(spec)
            report = cam.check()
        except SpecError as exc:
            assert exc.problems, "a SpecError without problems"
            for p in exc.problems:
                assert p.path, f"a problem without a field path: {p}"
                assert p.rule, f"a problem without a rule: {p}"
                assert len(str(p)) < 2000, f"an unbounded message ({len(str(p))} characters)"
            return "refused"
        except (ApiError, InternalError):
            raise
        except CamfabError as exc:
            assert str(exc), "a refusal without a message"
            return "refused-geometry"
    assert report.verdict is not None
    return str(report.verdict)


# ---------------------------------------------------------------------------
# mutated designs
HOSTILE = st.one_of(
    st.sampled_from([-1.0, 0.0, -0.0, 1e-300, 1e300, -1e300, math.nan, math.inf, -math.inf, 1e-9, 1e9,
                     0, -7, 10**30, True, False, "", "x" * 5000, "\x1b[31m", "../../x", "=1+1", [], {},
                     [1, 2, 3], {"a": 1}, None, 359.999999, 360.0, 720.0]),
    st.floats(allow_nan=True, allow_infinity=True),
    st.integers(-10**6, 10**6),
    st.text(max_size=40),
)


def _paths(node: Any, prefix: tuple = ()) -> list[tuple]:
    """Every path to a value (table key or list index) in the design structure."""
    out = []
    if isinstance(node, dict):
        for k, v in node.items():
            out.append((*prefix, k))
            out += _paths(v, (*prefix, k))
    elif isinstance(node, list):
        for i, v in enumerate(node):
            out.append((*prefix, i))
            out += _paths(v, (*prefix, i))
    return out


def _parent(root: Any, path: tuple) -> Any:
    node = root
    for k in path[:-1]:
        node = node[k]
    return node


@st.composite
def mutated_designs(draw) -> dict:
    base = copy.deepcopy(BASES[draw(st.sampled_from(sorted(BASES)))])
    for _ in range(draw(st.integers(1, 4))):
        paths = _paths(base)
        op = draw(st.sampled_from(["replace", "scale", "scale", "scale", "delete", "add", "segments"]))
        if op == "segments" and isinstance(base.get("motion"), list) and base["motion"]:
            seg = base["motion"]
            kind = draw(st.sampled_from(["dup", "drop", "respan", "many"]))
            i = draw(st.integers(0, len(seg) - 1))
            if kind == "dup":
                seg.insert(i, copy.deepcopy(seg[i]))
            elif kind == "drop":
                del seg[i]
            elif kind == "respan" and isinstance(seg[i], dict):
                seg[i]["angle_deg"] = draw(st.floats(-10.0, 400.0, allow_nan=False))
            elif isinstance(seg[i], dict):  # many tiny segments in place of one
                n = draw(st.integers(2, 200))
                span = seg[i].get("angle_deg", 10.0)
                span = float(span) if isinstance(span, (int, float)) else 10.0
                lift = seg[i].get("lift", 0.0)
                law = seg[i].get("law", "dwell")
                seg[i:i + 1] = [{"law": law, "lift": lift / n if isinstance(lift, (int, float)) else lift,
                                 "angle_deg": span / n} for _ in range(n)]
            continue
        if not paths:
            continue
        path = draw(st.sampled_from(paths))
        parent = _parent(base, path)
        if op == "replace":
            parent[path[-1]] = draw(HOSTILE)
        elif op == "scale":  # a plausible value, far from the example's: the design still reaches the checks
            old = parent[path[-1]]
            if isinstance(old, (int, float)) and not isinstance(old, bool):
                parent[path[-1]] = old * draw(st.sampled_from([-1.0, 1e-6, 1e-3, 0.1, 0.5, 0.99, 1.01, 2.0, 10.0,
                                                               1e3, 1e6]))
        elif op == "delete":
            del parent[path[-1]]
        elif isinstance(parent, dict):
            parent[draw(st.sampled_from(["extra", "Name", "lift ", "rpm"]))] = draw(HOSTILE)
    return base


@pytest.mark.parametrize("name", sorted(BASES))
def test_every_base_design_checks(name):
    """The unmutated bases compute (the fuzz starts from valid designs)."""
    assert admissible(copy.deepcopy(BASES[name])) not in ("refused", "refused-geometry")


@SETTINGS
@given(mutated_designs())
def test_mutated_designs_compute_or_are_refused_with_field_paths(data):
    event(admissible(data))


# ---------------------------------------------------------------------------
# knot tables
FINITE = st.floats(-1e3, 1e3, allow_nan=False)
ANY_FLOAT = st.one_of(FINITE, st.sampled_from([math.nan, math.inf, -math.inf, 1e300, -1e300, 1e-300]))


@st.composite
def knot_designs(draw) -> dict:
    degree = draw(st.sampled_from([5, 7, 6, "5"]))
    ncol = draw(st.sampled_from([4, 5, 3, 6]))
    n = draw(st.integers(0, 60))
    gaps = draw(st.lists(st.sampled_from([1e-12, 1e-9, 1e-6, 1e-3, 0.1, 1.0, 10.0, 90.0]), min_size=n, max_size=n))
    angles = []
    x = draw(st.sampled_from([0.0, 5.0, -10.0]))
    for g in gaps:
        angles.append(x)
        x += g
    value = ANY_FLOAT if draw(st.booleans()) else FINITE
    rows = [[a, *[draw(value) for _ in range(ncol - 1)]] for a in angles]
    if draw(st.booleans()):  # a closed, plausible lift: S >= 0, equal at both ends
        for r in rows:
            r[1] = abs(r[1]) if math.isfinite(r[1]) else r[1]
        if rows:
            rows[-1] = [360.0 + rows[0][0], *rows[0][1:]]
    table: dict[str, Any] = {"rows": rows, "degree": degree}
    if draw(st.booleans()):
        table["units"] = draw(st.sampled_from([
            {"angle": "deg", "s": "mm", "v": "mm/rad", "a": "mm/rad2", "j": "mm/rad3"},
            {"angle": "deg", "s": "m", "v": "m/s", "a": "m/s2"},
            {"angle": "rad", "s": "mm"},
            {"angle": "furlong"},
        ]))
        table["speed_rpm"] = draw(st.sampled_from([1500, 0, -1, 1e300]))
    return {
        "name": "fuzz-knots",
        "cam": {"kind": "disc", "rotation": "cw"},
        "follower": {"type": "roller", "motion": "translating", "base_radius_mm": 40.0, "roller_radius_mm": 8.0},
        "motion_table": table,
    }


@st.composite
def plausible_knot_designs(draw) -> dict:
    """A closed smooth lift S = c0 + a cos θ + b sin 2θ sampled at 4–40 knots over the cycle, exact S′ S″ (S‴),
    with a few knots doubled at a tiny gap (1e-12 … 1e-3°) and one value possibly nudged."""
    a, b = draw(st.floats(0.001, 20.0)), draw(st.floats(-5.0, 5.0))
    c0 = abs(a) + abs(b) + draw(st.sampled_from([0.0, 1e-9, 1.0]))
    n = draw(st.integers(4, 40))
    angles = sorted(set([0.0, *(draw(st.floats(0.5, 359.5)) for _ in range(n - 2)), 360.0]))
    for _ in range(draw(st.integers(0, 3))):
        i = draw(st.integers(0, len(angles) - 2))
        angles.insert(i + 1, angles[i] + draw(st.sampled_from([1e-12, 1e-9, 1e-6, 1e-3])))
    angles = sorted(set(angles))
    degree = draw(st.sampled_from([5, 7]))

    def row(deg: float) -> list[float]:
        t = math.radians(deg)
        r = [deg, c0 + a * math.cos(t) + b * math.sin(2 * t), -a * math.sin(t) + 2 * b * math.cos(2 * t),
             -a * math.cos(t) - 4 * b * math.sin(2 * t)]
        return r + [a * math.sin(t) - 8 * b * math.cos(2 * t)] if degree == 7 else r

    rows = [row(x) for x in angles]
    if draw(st.booleans()):
        i, j = draw(st.integers(0, len(rows) - 1)), draw(st.integers(1, len(rows[0]) - 1))
        rows[i][j] += draw(st.sampled_from([1e-9, 1e-3, 1.0, -1.0, 1e6]))
    return {
        "name": "fuzz-knots",
        "cam": {"kind": "disc", "rotation": "cw"},
        "follower": {"type": "roller", "motion": "translating",
                     "base_radius_mm": draw(st.sampled_from([5.0, 40.0, 400.0])),
                     "roller_radius_mm": draw(st.sampled_from([0.01, 2.0, 8.0]))},
        "motion_table": {"rows": rows, "degree": degree,
                         "units": {"angle": "deg", "s": "mm", "v": "mm/rad", "a": "mm/rad2", "j": "mm/rad3"}},
    }


@SETTINGS
@given(plausible_knot_designs())
def test_plausible_knot_tables_compute_or_are_refused_with_field_paths(data):
    event(admissible(data))


@SETTINGS
@given(knot_designs())
def test_knot_tables_compute_or_are_refused_with_field_paths(data):
    event(admissible(data))


# ---------------------------------------------------------------------------
# TOML text
EXAMPLE_TEXT = {p.stem: p.read_text() for p in sorted(EXAMPLES.glob("*.toml"))}


@st.composite
def damaged_toml(draw) -> str:
    if draw(st.booleans()):
        return draw(st.text(max_size=300))
    text = EXAMPLE_TEXT[draw(st.sampled_from(sorted(EXAMPLE_TEXT)))]
    for _ in range(draw(st.integers(1, 3))):
        i = draw(st.integers(0, len(text)))
        edit = draw(st.sampled_from(["cut", "insert", "brackets"]))
        if edit == "cut":
            text = text[:i] + text[i + draw(st.integers(1, 40)):]
        elif edit == "insert":
            text = text[:i] + draw(st.sampled_from(["[", "]", "=", '"', "\n", "[[motion]]\n", "nan", "-",
                                                   "\x00", "1e999", "{", "}"])) + text[i:]
        else:
            k = draw(st.integers(1, 3000))
            text = text + "\nz = " + "[" * k + "]" * k + "\n"
    return text


@SETTINGS
@given(damaged_toml())
def test_toml_text_loads_or_is_refused(tmp_path_factory, text):
    path = tmp_path_factory.mktemp("fuzz") / "design.toml"
    path.write_text(text, encoding="utf-8", errors="surrogatepass")
    with memory_cap():
        try:
            spec = camfab.load_design(path)
        except SpecError as exc:
            assert exc.problems and all(p.path for p in exc.problems), str(exc)
            return
        except (ApiError, InternalError):
            raise
        except CamfabError as exc:
            assert str(exc)
            return
    assert spec.name is not None


@pytest.mark.parametrize("speed", [1e300, 1e7, float("inf")])
def test_a_knot_table_speed_beyond_the_bound_is_refused_by_name(speed):
    """Hypothesis found speed_rpm = 1e300 with a table in time units overflowing ω² (OverflowError, not a problem
    naming the field): the table's speed has the bound of [cam] speed_rpm."""
    from camfab.design.spec import design_from_dict
    from camfab.errors import SpecError
    rows = [[0.0, 0.0, 0.0, 0.0], [180.0, 0.01, 0.0, 0.0], [360.0, 0.0, 0.0, 0.0]]
    data = {"name": "k", "cam": {"kind": "disc"},
            "follower": {"type": "roller", "motion": "translating", "base_radius_mm": 40.0, "roller_radius_mm": 8.0},
            "motion_table": {"rows": rows, "units": {"angle": "deg", "s": "m", "v": "m/s", "a": "m/s2"},
                             "speed_rpm": speed}}
    with pytest.raises(SpecError) as e:
        design_from_dict(data)
    assert "motion_table.speed_rpm" in {p.path for p in e.value.problems}
