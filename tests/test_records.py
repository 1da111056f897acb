"""``camfab.records.dataclass``: the representation, equality, hash, frozen setters and ``__init__`` it gives a
frozen record behave as those the standard library's ``dataclass`` generates, for every record class in camfab
(docs/decisions.md, "Start-up: records' methods without compiled source" and "Start-up: the frozen records'
setters and ``__init__`` without compiled source")."""
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


#: what the dataclass decorator and class creation put in a class's namespace (the rest, methods and properties, a
#: twin takes over: a ``__post_init__`` may call them)
_MADE = {"__module__", "__qualname__", "__annotations__", "__doc__", "__dict__", "__weakref__", "__slots__",
         "__dataclass_params__", "__dataclass_fields__", "__match_args__", "__init__", "__repr__", "__eq__", "__hash__",
         "__setattr__", "__delattr__"}


def _twin(cls: type) -> type:
    """The same fields (and field options) through the standard library's ``dataclass``."""
    own = {m: getattr(cls.__dict__.get(m), "__module__", None) == "camfab.records" for m in ("__repr__", "__eq__")}
    twin = dataclasses.make_dataclass(
        cls.__name__, [(f.name, f.type, dataclasses.field(
            default=f.default, default_factory=f.default_factory, init=f.init, kw_only=f.kw_only, repr=f.repr,
            compare=f.compare, hash=f.hash)) for f in dataclasses.fields(cls)],
        frozen=True, repr=own["__repr__"], eq=own["__eq__"], slots="__slots__" in cls.__dict__,
        bases=tuple(b for b in cls.__bases__ if b is not object),
        namespace={k: v for k, v in vars(cls).items() if k not in _MADE and k not in cls.__dataclass_fields__})
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


#: the fixtures above (field options, eq=False, slots, a subclass, no fields)
FIXTURES = [_Options, _Identity, _Slotted, _Derived, _Nothing]


@pytest.mark.parametrize("cls", FIXTURES)
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


def _outcome(obj: object, name: str, delete: bool) -> tuple[str, str] | None:
    """What assigning 7 to (or deleting) ``obj.name`` raises: the exception's class name and message, or None."""
    try:
        if delete:
            delattr(obj, name)
        else:
            setattr(obj, name, 7)
    except Exception as exc:  # noqa: BLE001 (the kind and message are what is compared)
        return type(exc).__name__, str(exc)
    return None


@pytest.mark.parametrize("cls", RECORDS + FIXTURES,
                         ids=lambda c: f"{c.__module__}.{c.__qualname__}")
def test_frozen_setters_equal_the_standard_librarys(cls):
    """Assigning or deleting a field or another name, on the class and on a plain subclass: the same outcome and
    message as the standard library's compiled setters."""
    twin = _twin(cls)
    values = tuple(POOL[i % len(POOL)] for i in range(len(dataclasses.fields(cls))))
    names = [f.name for f in dataclasses.fields(cls)] + ["other"]
    pairs = [(cls, twin)]
    if "__slots__" not in cls.__dict__:
        pairs.append((type("Sub", (cls,), {}), type("Sub", (twin,), {})))
    for mine, theirs in pairs:
        for name in names:
            a, ta = _instance(mine, values), _instance(theirs, values)
            for delete in (False, True, True):  # assign, delete, delete what is gone
                assert _outcome(a, name, delete) == _outcome(ta, name, delete), (mine, name, delete)
                assert getattr(a, "__dict__", None) == getattr(ta, "__dict__", None)


def test_frozen_setters_are_closures_on_this_python():
    """On Python 3.11/3.12 the setters come from records (no compiled source), and the standard library's maker is
    back in place afterwards; elsewhere records leaves them to the standard library."""
    import sys

    import camfab.records as records
    from camfab.results import Finding

    assert (sys.version_info[:2] in ((3, 11), (3, 12))) == records.CLOSURE_METHODS
    if records.CLOSURE_METHODS:
        assert Finding.__setattr__.__module__ == "camfab.records"
        assert Finding.__setattr__.__qualname__ == "Finding.__setattr__"
        assert Finding.__delattr__.__qualname__ == "Finding.__delattr__"
    assert dataclasses._frozen_get_del_attr is not records._frozen_setters


def test_frozen_records_made_in_threads():
    """Records made in several threads at once are all frozen, and the standard library's maker is restored."""
    from concurrent.futures import ThreadPoolExecutor

    import camfab.records as records

    original = dataclasses._frozen_get_del_attr

    def make(i: int) -> type:
        @dataclass(frozen=True)
        class R:
            a: int
        return dataclasses.make_dataclass(f"M{i}", [("b", int)], frozen=True) if i % 2 else R

    with ThreadPoolExecutor(4) as pool:
        made = list(pool.map(make, range(40)))
    for cls in made:
        obj = cls(1)
        with pytest.raises(dataclasses.FrozenInstanceError):
            setattr(obj, dataclasses.fields(cls)[0].name, 2)
    assert dataclasses._frozen_get_del_attr is original and original is not records._frozen_setters


def _construct(cls: type, *args: object, **kwargs: object) -> tuple:
    """``cls(*args, **kwargs)``: ``("made", field values)``, or the exception's class name and message (the class's
    qualified name taken out)."""
    try:
        obj = cls(*args, **kwargs)
    except Exception as exc:  # noqa: BLE001 (the outcome is what is compared)
        return type(exc).__name__, str(exc).replace(cls.__init__.__qualname__, "__init__")
    return "made", [getattr(obj, f.name) for f in dataclasses.fields(cls) if hasattr(obj, f.name)]


def _same_init(cls: type, twin: type) -> None:
    """``cls.__init__`` behaves as ``twin``'s (the standard library's): signature, defaults, annotations, stored
    values (or a ``__post_init__``'s error), and the messages of missing, surplus, unknown and repeated
    arguments."""
    import inspect

    def shown(c: type) -> tuple:  # (Parameter equality compares defaults with ==: a NaN default is never equal)
        sig = inspect.signature(c)
        return sig.return_annotation, [(q.name, q.kind, q.annotation, repr(q.default)) for q in sig.parameters.values()]

    assert shown(cls) == shown(twin)
    mine, theirs = cls.__init__, twin.__init__
    assert (mine.__defaults__, mine.__kwdefaults__, mine.__annotations__) == \
        (theirs.__defaults__, theirs.__kwdefaults__, theirs.__annotations__)
    assert mine.__module__ == cls.__module__  # (the twin's is "types", where make_dataclass makes it)
    assert mine.__code__.co_qualname == theirs.__code__.co_qualname
    fs = [f for f in dataclasses.fields(cls) if f.init]
    values = tuple(POOL[(i * 7) % len(POOL)] for i in range(len(fs)))
    required = sum(f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING for f in fs)
    for args, kwargs in [(values, {}), ((), {f.name: v for f, v in zip(fs, values, strict=True)}),
                         (values[:max(required - 1, 0)], {}), ((*values, 1), {}), (values, {"__nope__": 1}),
                         (values, {fs[0].name: 1} if fs else {"x": 1}), ((), {})]:
        assert _construct(cls, *args, **kwargs) == _construct(twin, *args, **kwargs), (args, kwargs)


@pytest.mark.parametrize("cls", RECORDS + FIXTURES,
                         ids=lambda c: f"{c.__module__}.{c.__qualname__}")
def test_init_equals_the_standard_librarys(cls):
    if cls.__init__.__code__.co_filename != "<string>":
        pytest.skip("the class's own __init__")
    twin = _twin(cls)
    twin.__init__.__qualname__ = cls.__init__.__qualname__  # (the twin's class has a shorter qualified name)
    _same_init(cls, twin)


def _closure_made(cls: type) -> bool:
    return "__records_names__" in cls.__init__.__code__.co_freevars


def test_inits_are_made_without_source_on_this_python():
    """On Python 3.11/3.12 the usual record's ``__init__`` is records' (no compiled source); others are the
    standard library's."""
    import camfab.records as records

    made = [c for c in RECORDS if _closure_made(c)]
    if records.CLOSURE_METHODS:
        assert len(made) > 100
    else:
        assert not made


def test_init_special_cases_go_to_the_standard_library():
    """A default factory, ``__post_init__``, an InitVar, keyword-only fields, a field named self, a field with
    records' own prefix and a field without default after one with: the standard library's ``__init__``, same
    behaviour as a twin; 40 fields: records' (a larger template)."""
    import camfab.records as records

    @dataclass(frozen=True)
    class Factory:
        a: int
        b: list = field(default_factory=list)

    @dataclass(frozen=True)
    class Post:
        a: int

        def __post_init__(self) -> None:
            object.__setattr__(self, "a", self.a * 2)

    @dataclass(frozen=True)
    class Init:
        a: int
        scale: dataclasses.InitVar[int] = 1

        def __post_init__(self, scale: int) -> None:
            object.__setattr__(self, "a", self.a * scale)

    @dataclass(frozen=True, kw_only=True)
    class Keywords:
        a: int

    @dataclass(frozen=True)
    class Self:
        self: int

    @dataclass(frozen=True)
    class Prefixed:
        __records_0__: int

    for cls in (Factory, Post, Init, Keywords, Self, Prefixed):
        assert not _closure_made(cls)
    for cls in (Factory, Post, Keywords, Self, Prefixed):  # (an InitVar is no field: a twin cannot have it)
        _same_init(cls, _twin(cls))
    assert Factory(1).b == [] and Factory(1).b is not Factory(1).b and Post(2).a == 4 and Init(2, 3).a == 6
    assert Keywords(a=1).a == 1 and Self(5).self == 5 and Prefixed(3).__records_0__ == 3
    with pytest.raises(TypeError, match="non-default argument 'b' follows default argument"):
        @dataclass(frozen=True)
        class Order:
            a: int = 0
            b: int

    wide = dataclasses.make_dataclass("Wide", [(f"f{i}", "int") for i in range(40)], frozen=True)
    big = dataclass(frozen=True)(type("Big", (), {"__annotations__": {f"f{i}": "int" for i in range(40)}}))
    assert _closure_made(big) == records.CLOSURE_METHODS
    _same_init(big, wide)
    assert big(*range(40)).f39 == 39
