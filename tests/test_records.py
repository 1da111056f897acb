"""``camfab.records.dataclass``: the representation, equality and hash it gives a frozen record are those the
standard library's ``dataclass`` generates, for every record class in camfab (docs/decisions.md, "Records'
methods without compiled source")."""
from __future__ import annotations

import dataclasses
import importlib
import itertools
import pkgutil

import pytest

import camfab
from camfab.records import dataclass, field

NAN = float("nan")
#: field values: hashable, unequal to one another, a NaN (equal to itself only as the same object), -0.0 == 0
POOL = (0, 1, -0.0, 2.5, NAN, "x", "a'b\n", (1, "y"), None, frozenset({3}))


def _record_classes() -> list[type]:
    """Every class in camfab whose methods ``camfab.records`` made (modules needing a missing optional library are
    skipped)."""
    found = {}
    for info in pkgutil.walk_packages(camfab.__path__, "camfab."):
        try:
            module = importlib.import_module(info.name)
        except ImportError:
            continue
        for obj in vars(module).values():
            if (isinstance(obj, type) and dataclasses.is_dataclass(obj) and obj.__module__ == info.name
                    and any(getattr(obj.__dict__.get(m), "__module__", None) == "camfab.records"
                            for m in ("__repr__", "__eq__"))):
                found[f"{obj.__module__}.{obj.__qualname__}"] = obj
    return [found[k] for k in sorted(found)]


RECORDS = _record_classes()


def _twin(cls: type) -> type:
    """The same fields (and field options) through the standard library's ``dataclass``."""
    own = {m: getattr(cls.__dict__.get(m), "__module__", None) == "camfab.records" for m in ("__repr__", "__eq__")}
    twin = dataclasses.make_dataclass(
        cls.__name__, [(f.name, f.type, dataclasses.field(repr=f.repr, compare=f.compare, hash=f.hash))
                       for f in dataclasses.fields(cls)], frozen=True, repr=own["__repr__"], eq=own["__eq__"],
        bases=tuple(b for b in cls.__bases__ if b is not object))
    twin.__qualname__ = cls.__qualname__
    return twin


def _instance(cls: type, values: tuple) -> object:
    obj = object.__new__(cls)
    for f, v in zip(dataclasses.fields(cls), values, strict=True):
        object.__setattr__(obj, f.name, v)
    return obj


def test_camfab_records_use_it():
    """The package's frozen classes do come through records (the check's ~60 and the rest)."""
    assert len(RECORDS) > 100
    from camfab.results import CheckReport, Finding
    assert Finding in RECORDS and CheckReport in RECORDS


@pytest.mark.parametrize("cls", RECORDS, ids=lambda c: f"{c.__module__}.{c.__qualname__}")
def test_methods_equal_the_standard_librarys(cls):
    twin = _twin(cls)
    n = len(dataclasses.fields(cls))
    rows = [tuple(POOL[(i * 3 + k) % len(POOL)] for i in range(n)) for k in range(len(POOL))]
    rows.append(tuple(POOL[0] for _ in range(n)))
    objs = [(_instance(cls, r), _instance(twin, r)) for r in rows]
    for (a, ta), (b, tb) in itertools.product(objs, repeat=2):
        assert repr(a) == repr(ta)
        assert (a == b) == (ta == tb) and (a != b) == (ta != tb)
        assert a.__eq__(ta) is NotImplemented and ta.__eq__(a) is NotImplemented
    if cls.__hash__ is not None and cls.__dict__.get("__hash__") is not None:
        for a, ta in objs:
            assert hash(a) == hash(ta)


@dataclass(frozen=True)
class _Options:
    a: int
    hidden: float = field(default=0.0, repr=False)
    ignored: str = field(default="", compare=False)
    unhashed: tuple = field(default=(), hash=False)
    loop: object = None


@dataclass(frozen=True, eq=False)
class _Identity:
    a: int


@dataclass(frozen=True, slots=True)
class _Slotted:
    a: int
    b: str = "s"


@dataclass(frozen=True)
class _Derived(_Options):
    extra: int = 0


@dataclass(frozen=True)
class _Nothing:
    pass


@pytest.mark.parametrize("cls", [_Options, _Identity, _Slotted, _Derived, _Nothing])
def test_field_options_slots_inheritance_and_no_fields(cls):
    """repr=False, compare=False, hash=False, eq=False, slots and a subclass, against the standard library."""
    eq = cls is not _Identity
    twin = _twin(cls)
    n = len(dataclasses.fields(cls))
    for values in itertools.islice(itertools.product(POOL[:4], repeat=n), 60):
        a, ta = _instance(cls, values), _instance(twin, values)
        b, tb = _instance(cls, values[::-1]), _instance(twin, values[::-1])
        assert repr(a) == repr(ta)
        assert (a == b) == (ta == tb)
        assert (a == _instance(cls, values)) == (ta == _instance(twin, values))
        if eq:
            assert hash(a) == hash(ta)
        else:
            assert hash(a) == object.__hash__(a)


def test_recursive_repr_and_frozen():
    a = _Options(1)
    object.__setattr__(a, "loop", a)
    assert repr(a) == "_Options(a=1, ignored='', unhashed=(), loop=...)"
    with pytest.raises(dataclasses.FrozenInstanceError):
        a.a = 2  # type: ignore[misc]


def test_classes_that_want_more_go_to_the_standard_library():
    """Not frozen, ordered, unsafe_hash, or a method of the class's own: records changes nothing."""
    @dataclass
    class Plain:
        a: int

    @dataclass(frozen=True, order=True)
    class Ordered:
        a: int

    @dataclass(frozen=True)
    class Own:
        a: int

        def __repr__(self) -> str:
            return "own"

    for cls in (Plain, Ordered, Own):
        assert cls.__eq__.__module__ != "camfab.records"
    assert repr(Own(1)) == "own" and Ordered(1) < Ordered(2) and Plain(1) == Plain(1)


def test_camfab_modules_take_dataclass_from_records():
    """A new module's records get the same start-up saving: no camfab module but records uses the standard
    library's decorator directly."""
    from pathlib import Path

    root = Path(camfab.__file__).parent
    direct = []
    for path in sorted(root.rglob("*.py")):
        if path.name == "records.py":
            continue
        for n, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
            names = line.split("from dataclasses import", 1)[1] if line.lstrip().startswith("from dataclasses import") \
                else ""
            if "dataclass" in [x.strip() for x in names.split(",")] or "@dataclasses.dataclass" in line:
                direct.append(f"{path.relative_to(root.parent)}:{n}")
    assert not direct, f"use `from camfab.records import dataclass` (docs/decisions.md): {direct}"
