"""``dataclass`` for camfab's records: the standard library's, with ``__repr__``, ``__eq__`` and ``__hash__``
of frozen classes made by closures instead of compiled source.

Why (measured 2026-11-27, Python 3.11): the standard ``dataclass`` writes each method as Python source and
compiles it.  A ``camfab check`` creates ~60 frozen classes, six compiled methods each; parsing and compiling
them was ~21 % of the whole process's instructions (valgrind), ~80 ms of a ~0.4 s check.  The three methods
that need no source, the representation, equality and hash, are made here from the class's fields, which
cut a check's instructions by ~7 %.  ``__init__`` and the frozen ``__setattr__`` / ``__delattr__`` are still
the standard library's.

The methods behave exactly as the generated ones (``tests/test_records.py`` compares them with
``dataclasses.dataclass``'s own for every record class in camfab):

* ``__repr__``: ``QualName(a=…, b=…)`` over the fields with ``repr=True``, ``...`` for a recursive reference;
* ``__eq__``: the tuples of the fields with ``compare=True`` when both objects are of the same class, else
  ``NotImplemented``;
* ``__hash__``: the hash of the tuple of the fields with ``hash=True`` (or ``compare=True`` when ``hash`` is
  None).

A class that is not frozen, orders, asks for ``unsafe_hash`` or defines any of the three methods itself goes to
``dataclasses.dataclass`` unchanged.  Type checkers see ``dataclasses.dataclass`` itself.  ``field``, ``fields``
and ``replace`` are the standard library's, re-exported so that a module imports its records' toolkit in one line.
"""
from __future__ import annotations

import dataclasses
import reprlib
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


def _dataclass(cls: type | None = None, /, **kwargs: Any) -> Any:
    def wrap(c: type) -> type:
        if (not kwargs.get("frozen") or kwargs.get("order") or kwargs.get("unsafe_hash")
                or any(name in c.__dict__ for name in _OWN)):
            return dataclasses.dataclass(c, **kwargs)
        repr_, eq = kwargs.get("repr", True), kwargs.get("eq", True)
        made: type = dataclasses.dataclass(c, **{**kwargs, "repr": False, "eq": False})
        return _methods(made, repr=repr_, eq=eq)

    return wrap if cls is None else wrap(cls)


from dataclasses import field, fields, replace  # noqa: E402 (the rest of the toolkit, for one import line)

if TYPE_CHECKING:
    from dataclasses import dataclass
else:
    dataclass = _dataclass
