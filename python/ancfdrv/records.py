"""Records: the standard library's dataclasses without compiling their methods at import.

``dataclasses.dataclass`` writes a class's ``__init__``, ``__repr__`` and ``__eq__`` (and a
frozen class's ``__setattr__``, ``__delattr__`` and ``__hash__``) as Python source and
compiles each with ``exec`` when the class is defined: about 0.6 M instructions a method.
The package defines some 75 such classes, 64 of them on the path of every ``ancf run``,
which compiled their 163 methods each time (issue 38: a small call costs what it
computes); made as records, the accuracy-matched boom's ``ancf run`` takes 5.9 % fewer
instructions (1263 -> 1189 M, callgrind).

:func:`record` takes the same arguments where the package uses them (``eq``, ``repr``,
``frozen``) and gives the same class: its fields are registered by ``dataclasses`` itself
(``dataclasses.fields``, ``replace``, ``asdict``, ``is_dataclass`` and pickling work as
before). Its ``__init__`` is the standard library's, compiled the first time an instance
is made (a small command makes instances of some 20 of the records it imports), so that
making instances costs what it did; ``__repr__``, ``__eq__``, ``__hash__`` and a frozen
record's ``__setattr__`` / ``__delattr__`` are closures over its fields written once here.
The behaviour is the standard library's: positional or keyword arguments in field order,
defaults and default factories, ``__post_init__``, ``repr=False`` / ``compare=False``
fields left out of the repr and the comparison, ``eq`` comparing instances of the same
class field by field, a hash for frozen classes with ``eq`` and none for mutable ones,
``FrozenInstanceError`` on assignment to a frozen instance (tests/test_records.py checks
each against ``dataclasses.dataclass``).
"""
from __future__ import annotations

import dataclasses
from dataclasses import MISSING, FrozenInstanceError
from typing import Any, Callable, TypeVar

T = TypeVar("T", bound=type)



def record(cls: T | None = None, /, *, eq: bool = True, repr: bool = True,  # noqa: A002
           frozen: bool = False) -> T | Callable[[T], T]:
    """``dataclasses.dataclass(cls, eq=eq, repr=repr, frozen=frozen)`` with its methods
    made without compiling source (the module's notes). Used bare (``@record``) or with
    arguments (``@record(frozen=True)``)."""

    def wrap(c: T) -> T:
        c = dataclasses.dataclass(c, init=False, repr=False, eq=False)
        _give_methods(c, eq=eq, show=repr, frozen=frozen)
        return c

    return wrap if cls is None else wrap(cls)


def _give_methods(cls: type, *, eq: bool, show: bool, frozen: bool) -> None:
    """Sets the record's __init__ and, as asked, __repr__, __eq__, __hash__ and the frozen
    __setattr__ / __delattr__ (those the class body defines itself are kept)."""
    fields = dataclasses.fields(cls)
    _set(cls, "__init__", _init(cls, fields, frozen))
    if show:
        _set(cls, "__repr__", _repr(tuple(f.name for f in fields if f.repr)))
    if eq:
        _set(cls, "__eq__", _eq(tuple(f.name for f in fields if f.compare)))
        if "__hash__" not in cls.__dict__ or cls.__dict__["__hash__"] is None:
            # the standard library's rule: eq with frozen hashes the compared fields,
            # eq without frozen makes the class unhashable
            cls.__hash__ = (_hash(tuple(f.name for f in fields
                                        if (f.compare if f.hash is None else f.hash)))
                            if frozen else None)
    if frozen:
        names = frozenset(f.name for f in fields)
        _set(cls, "__setattr__", _frozen_setattr(cls, names))
        _set(cls, "__delattr__", _frozen_delattr(cls, names))


def _set(cls: type, name: str, function: Callable) -> None:
    """Sets a method unless the class body defines it (as dataclasses does)."""
    if name in cls.__dict__:
        return
    function.__qualname__ = f"{cls.__qualname__}.{name}"
    function.__name__ = name
    setattr(cls, name, function)


def _init(cls: type, fields: tuple, frozen: bool) -> Callable:
    """The record's __init__, compiled the first time an instance is made (most records
    of a run are never made: a small command makes some 20 of the 64 it imports) and then
    set on the class: the standard library's __init__, the init fields in order as
    parameters with their defaults, a default factory called when its field is not
    given, the fields left out of __init__ that have a factory set from it, then
    __post_init__. A frozen record's fields are set with object.__setattr__."""
    def __init__(self: Any, *args: Any, **kwargs: Any) -> None:
        compiled = _compiled_init(cls, fields, frozen)
        compiled.__qualname__ = f"{cls.__qualname__}.__init__"
        cls.__init__ = compiled
        compiled(self, *args, **kwargs)

    return __init__


class _Factory:
    """The default of a parameter whose field has a default factory."""

    def __repr__(self) -> str:
        return "<factory>"


_FACTORY_DEFAULT = _Factory()


def _compiled_init(cls: type, fields: tuple, frozen: bool) -> Callable:
    """The source of the standard library's __init__ for these fields, compiled."""
    scope: dict[str, Any] = {"_FACTORY_DEFAULT": _FACTORY_DEFAULT,
                             "_set_field": object.__setattr__}
    parameters, lines = [], []
    for index, f in enumerate(fields):
        if f.init:
            if f.default is not MISSING:
                scope[f"_default_{index}"] = f.default
                parameters.append(f"{f.name}=_default_{index}")
                value = f.name
            elif f.default_factory is not MISSING:
                scope[f"_factory_{index}"] = f.default_factory
                parameters.append(f"{f.name}=_FACTORY_DEFAULT")
                value = f"_factory_{index}() if {f.name} is _FACTORY_DEFAULT else {f.name}"
            else:
                parameters.append(f.name)
                value = f.name
        elif f.default_factory is not MISSING:
            scope[f"_factory_{index}"] = f.default_factory
            value = f"_factory_{index}()"
        else:
            continue
        lines.append(f"    _set_field(__record_self__, {f.name!r}, {value})" if frozen
                     else f"    __record_self__.{f.name} = {value}")
    if hasattr(cls, "__post_init__"):
        lines.append("    __record_self__.__post_init__()")
    source = (f"def __init__(__record_self__{''.join(', ' + p for p in parameters)}):\n"
              + ("\n".join(lines) or "    pass") + "\n")
    exec(source, scope)  # noqa: S102 - source made here from the class's field names
    return scope["__init__"]


def _repr(names: tuple[str, ...]) -> Callable:
    """__repr__: the class's qualified name and the shown fields."""

    def __repr__(self: Any) -> str:
        shown = ", ".join(f"{name}={getattr(self, name)!r}" for name in names)
        return f"{type(self).__qualname__}({shown})"

    return __repr__


def _eq(names: tuple[str, ...]) -> Callable:
    """__eq__: instances of the same class, field by field (as tuples)."""

    def __eq__(self: Any, other: Any) -> Any:
        if other.__class__ is not self.__class__:
            return NotImplemented
        return (tuple(getattr(self, n) for n in names)
                == tuple(getattr(other, n) for n in names))

    return __eq__


def _hash(names: tuple[str, ...]) -> Callable:
    """__hash__ of a frozen record: the hash of its hashed fields' tuple."""

    def __hash__(self: Any) -> int:
        return hash(tuple(getattr(self, n) for n in names))

    return __hash__


def _frozen_setattr(cls: type, names: frozenset) -> Callable:
    """__setattr__ of a frozen record: no assignment to its fields."""

    def __setattr__(self: Any, name: str, value: Any) -> None:
        if type(self) is cls or name in names:
            raise FrozenInstanceError(f"cannot assign to field {name!r}")
        super(cls, self).__setattr__(name, value)

    return __setattr__


def _frozen_delattr(cls: type, names: frozenset) -> Callable:
    """__delattr__ of a frozen record: no deletion of its fields."""

    def __delattr__(self: Any, name: str) -> None:
        if type(self) is cls or name in names:
            raise FrozenInstanceError(f"cannot delete field {name!r}")
        super(cls, self).__delattr__(name)

    return __delattr__


__all__ = ["record"]
