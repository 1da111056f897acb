"""``dataclass`` for camfab's records: the standard library's, with the methods of frozen classes made without
compiling source.

Why (measured 2026-11-27, Python 3.11): the standard ``dataclass`` writes each method as Python source and
compiles it.  A ``camfab check`` creates ~50 frozen classes, six compiled methods each; parsing and compiling
them was ~21 % of the whole process's instructions (valgrind), ~80 ms of a ~0.4 s check.  Here they are made
without source:

* ``__repr__``, ``__eq__``, ``__hash__``: closures over the class's fields (the standard library is asked not to
  make them);
* the frozen ``__setattr__`` / ``__delattr__`` and ``__init__``: while the standard library processes a frozen
  class, its private makers of these methods (``_frozen_get_del_attr`` and ``_init_fn``, Python 3.11 and 3.12)
  are replaced by :func:`_frozen_setters` and :func:`_frozen_init`.  The setters are closures; ``__init__`` is a
  template function compiled once per process whose parameters are renamed to the fields'
  (``CodeType.replace``).  ``_frozen_init`` makes only the usual record's ``__init__`` (fields with at most a
  plain default, no ``__post_init__``, no ``InitVar``, no keyword-only fields) and hands every other class to
  the standard library's maker.  On a Python whose makers differ (3.13 compiles a class's methods in one batch)
  nothing is replaced.

The methods behave exactly as the generated ones (``tests/test_records.py`` compares them with
``dataclasses.dataclass``'s own for every record class in camfab):

* ``__repr__``: ``QualName(a=…, b=…)`` over the fields with ``repr=True``, ``...`` for a recursive reference;
* ``__eq__``: the tuples of the fields with ``compare=True`` when both objects are of the same class, else
  ``NotImplemented``;
* ``__hash__``: the hash of the tuple of the fields with ``hash=True`` (or ``compare=True`` when ``hash`` is
  None);
* ``__setattr__`` / ``__delattr__``: ``FrozenInstanceError`` for the class itself or a field name, else
  ``super()``'s;
* ``__init__``: the same signature, defaults, annotations and argument errors, each field stored with
  ``object.__setattr__``.

A class that is not frozen goes to ``dataclasses.dataclass`` unchanged; one that orders, asks for
``unsafe_hash`` or defines any of the three comparison/representation methods itself keeps the standard library's
for those.  Type checkers see ``dataclasses.dataclass`` itself.  ``field``, ``fields`` and ``replace`` are the
standard library's, re-exported so that a module imports its records' toolkit in one line.
"""
from __future__ import annotations

import dataclasses
import reprlib
import threading
import types
from collections.abc import Callable
from operator import attrgetter
from typing import TYPE_CHECKING, Any

__all__ = ["dataclass", "field", "fields", "replace"]

_OWN = ("__repr__", "__eq__", "__hash__")


def _getter(names: tuple[str, ...]) -> Callable[[Any], tuple[Any, ...]]:
    """obj → the tuple of its attributes ``names``."""
    if len(names) == 1:
        one = attrgetter(names[0])
        return lambda obj: (one(obj),)
    if not names:
        return lambda obj: ()
    return attrgetter(*names)  # type: ignore[return-value]


def _methods(cls: type, *, repr: bool, eq: bool) -> type:  # noqa: A002 (dataclass's own keyword names)
    fields = dataclasses.fields(cls)
    if repr:
        shown = tuple(f.name for f in fields if f.repr)

        @reprlib.recursive_repr()
        def __repr__(self: Any) -> str:
            return self.__class__.__qualname__ + "(" + ", ".join(
                [f"{name}={getattr(self, name)!r}" for name in shown]) + ")"

        _put(cls, __repr__)
    if eq:
        compared = _getter(tuple(f.name for f in fields if f.compare))
        hashed = _getter(tuple(f.name for f in fields if (f.compare if f.hash is None else f.hash)))

        def __eq__(self: Any, other: Any) -> Any:
            if other.__class__ is self.__class__:
                return compared(self) == compared(other)
            return NotImplemented

        def __hash__(self: Any) -> int:
            return hash(hashed(self))

        _put(cls, __eq__)
        _put(cls, __hash__)
    return cls


def _put(cls: type, fn: Callable[..., Any]) -> None:
    fn.__qualname__ = f"{cls.__qualname__}.{fn.__name__}"
    setattr(cls, fn.__name__, fn)


def _frozen_setters(cls: type, fields: list[dataclasses.Field[Any]], globals: dict[str, Any]  # noqa: A002
                    ) -> tuple[Callable[..., None], Callable[..., None]]:
    """The frozen ``__setattr__`` and ``__delattr__`` the standard library's ``_frozen_get_del_attr`` compiles from
    source (Python 3.11 and 3.12), as closures: the same tests, the same messages, ``super(cls, self)`` after."""
    names = tuple(f.name for f in fields)

    def __setattr__(self: Any, name: str, value: Any) -> None:
        if type(self) is cls or name in names:
            raise dataclasses.FrozenInstanceError(f"cannot assign to field {name!r}")
        super(cls, self).__setattr__(name, value)  # type: ignore[misc, arg-type]

    def __delattr__(self: Any, name: str) -> None:
        if type(self) is cls or name in names:
            raise dataclasses.FrozenInstanceError(f"cannot delete field {name!r}")
        super(cls, self).__delattr__(name)  # type: ignore[misc, arg-type]

    return __setattr__, __delattr__


#: the template ``__init__``'s parameter count grows by doubling from this (a record with more fields gets a larger one)
_TEMPLATE_MIN = 32
_templates: dict[int, types.CodeType] = {}


def _template(size: int) -> types.CodeType:
    """The code of an ``__init__(self, p0, …, p{size-1})`` that stores its first ``count`` arguments under
    ``names`` with ``set`` (three closure cells) and returns; compiled once per size and process."""
    if size not in _templates:
        lines = ["def __records_outer__(__records_names__, __records_set__, __records_count__):",
                 " def __init__(self, " + ", ".join(f"__records_{i}__" for i in range(size)) + "):"]
        for i in range(size):
            lines += [f"  if __records_count__ == {i}: return",
                      f"  __records_set__(self, __records_names__[{i}], __records_{i}__)"]
        lines.append(" return __init__")
        made: dict[str, Any] = {}
        exec("\n".join(lines), {}, made)  # noqa: S102 (camfab's own text, no input in it)
        _templates[size] = made["__records_outer__"]((), object.__setattr__, 0).__code__
    return _templates[size]


def _frozen_init(fields: list[dataclasses.Field[Any]], std_fields: list[dataclasses.Field[Any]],
                 kw_only_fields: list[dataclasses.Field[Any]], frozen: bool, has_post_init: bool, self_name: str,
                 globals: dict[str, Any], slots: bool) -> Callable[..., None]:  # noqa: A002
    """The standard library's ``_init_fn`` (Python 3.11, 3.12) for the usual frozen record, without compiling source:
    every field an ordinary positional-or-keyword parameter with at most a plain default, no ``__post_init__``.  The
    template's parameters are renamed to the fields' (``CodeType.replace``), so binding, defaults, annotations,
    signature and every argument error are the compiled function's; it stores each argument with
    ``object.__setattr__`` as that function does.  Anything else goes to the standard library's maker."""
    n = len(fields)
    names = tuple(f.name for f in fields)
    plain = (frozen and not has_post_init and not kw_only_fields and self_name == "self" and len(std_fields) == n
             and all(f._field_type is dataclasses._FIELD and f.init  # type: ignore[attr-defined]
                     and f.default_factory is dataclasses.MISSING and not f.name.startswith("__records_")
                     for f in fields))
    defaults = tuple(f.default for f in fields if f.default is not dataclasses.MISSING)
    if not plain or any(f.default is dataclasses.MISSING for f in fields[n - len(defaults):]):
        return _COMPILED_INIT(fields, std_fields, kw_only_fields, frozen, has_post_init, self_name, globals, slots)
    size = _TEMPLATE_MIN
    while size < n:
        size *= 2
    template = _template(size)
    code = template.replace(co_argcount=n + 1, co_name="__init__", co_qualname="__create_fn__.<locals>.__init__",
                            co_varnames=("self", *names, *template.co_varnames[n + 1:]))
    cells = {"__records_names__": names, "__records_set__": object.__setattr__, "__records_count__": n}
    init = types.FunctionType(code, globals, "__init__", defaults or None,
                              tuple(types.CellType(cells[name]) for name in code.co_freevars))
    init.__annotations__ = {**{f.name: f.type for f in fields}, "return": None}
    return init


def _has_maker(name: str, parameters: tuple[str, ...]) -> bool:
    """Whether this Python's ``dataclasses`` has the private maker ``name`` with exactly these ``parameters``."""
    code = getattr(getattr(dataclasses, name, None), "__code__", None)
    return code is not None and code.co_varnames[:code.co_argcount] == parameters


#: whether records stand in for the standard library's makers of the frozen setters and ``__init__`` (Python 3.11 and
#: 3.12; 3.13 compiles a class's methods in one batch and keeps other makers: its records use the standard library's)
CLOSURE_METHODS = (_has_maker("_frozen_get_del_attr", ("cls", "fields", "globals"))
                   and _has_maker("_init_fn", ("fields", "std_fields", "kw_only_fields", "frozen", "has_post_init",
                                               "self_name", "globals", "slots")))
_COMPILED_INIT: Any = getattr(dataclasses, "_init_fn", None)
_SWAP = threading.Lock()


def _stdlib_frozen(c: type, kwargs: dict[str, Any]) -> type:
    """``dataclasses.dataclass(c, **kwargs)`` of a frozen class with :func:`_frozen_setters` and :func:`_frozen_init`
    standing in for the standard library's makers when this Python allows it (under a lock, restored after;
    another thread's dataclass made meanwhile would behave the same either way: both hand what they do not
    make to the standard library's maker or make what it makes)."""
    if not CLOSURE_METHODS:
        return dataclasses.dataclass(c, **kwargs)
    with _SWAP:
        setters, init = dataclasses._frozen_get_del_attr, dataclasses._init_fn  # type: ignore[attr-defined]
        dataclasses._frozen_get_del_attr, dataclasses._init_fn = _frozen_setters, _frozen_init  # type: ignore
        try:
            return dataclasses.dataclass(c, **kwargs)
        finally:
            dataclasses._frozen_get_del_attr, dataclasses._init_fn = setters, init  # type: ignore[attr-defined]


def _dataclass(cls: type | None = None, /, **kwargs: Any) -> Any:
    def wrap(c: type) -> type:
        if not kwargs.get("frozen"):
            return dataclasses.dataclass(c, **kwargs)
        if kwargs.get("order") or kwargs.get("unsafe_hash") or any(name in c.__dict__ for name in _OWN):
            return _stdlib_frozen(c, kwargs)
        repr_, eq = kwargs.get("repr", True), kwargs.get("eq", True)
        made = _stdlib_frozen(c, {**kwargs, "repr": False, "eq": False})
        return _methods(made, repr=repr_, eq=eq)

    return wrap if cls is None else wrap(cls)


from dataclasses import field, fields, replace  # noqa: E402 (the rest of the toolkit, for one import line)

if TYPE_CHECKING:
    from dataclasses import dataclass
else:
    dataclass = _dataclass
