"""``dataclass`` at a lower import cost: the standard one, with ``__repr__``, ``__eq__`` and
``__hash__`` shared instead of compiled for each class (issue 31).

The standard decorator writes the source of every method it adds and compiles it, class by
class; on Python 3.11 that is most of what a class costs to define, and a lint defines about
seventy dataclasses before it reads a byte (some 70 M instructions, a fifth of fuzzoff's own
start-up on a ULog lint). Here ``dataclasses.dataclass`` still does everything else (fields,
defaults and factories, ``__init__``, ``__post_init__``, slots, frozen assignment, copy and
pickle), and the three comparison and display methods are closures over the field names:
the same results as the generated ones, same rules for which fields take part (``repr=``,
``compare=``, ``hash=`` of ``field``) and for when ``__hash__`` is added, kept or set to None.
``tests/test_lean_dataclass.py`` holds them to the standard decorator's.

What differs: ``__dataclass_params__`` says ``repr=False, eq=False`` for every class made
here, since the standard decorator did not add those methods; nothing in fuzzoff reads it.
"""

from __future__ import annotations

import dataclasses
import reprlib
from collections.abc import Callable
from dataclasses import Field, field
from operator import attrgetter
from typing import Any, TypeVar, dataclass_transform, overload

_T = TypeVar("_T", bound=type)


@overload
def dataclass(cls: _T, /) -> _T: ...


@overload
def dataclass(
    *, frozen: bool = False, slots: bool = False, eq: bool = True, kw_only: bool = False
) -> Callable[[_T], _T]: ...


@dataclass_transform(field_specifiers=(field, Field))
def dataclass(
    cls: _T | None = None,
    /,
    *,
    frozen: bool = False,
    slots: bool = False,
    eq: bool = True,
    kw_only: bool = False,
) -> _T | Callable[[_T], _T]:
    """``dataclasses.dataclass`` with these arguments (``repr`` and ``order`` are not offered:
    no class of fuzzoff turns off its ``repr`` or orders its instances)."""

    def wrap(original: _T) -> _T:
        own = original.__dict__
        explicit_repr = "__repr__" in own
        explicit_eq = "__eq__" in own
        class_hash = own.get("__hash__", dataclasses.MISSING)
        explicit_hash = not (
            class_hash is dataclasses.MISSING or (class_hash is None and explicit_eq)
        )
        made: Any = dataclasses.dataclass(
            original, frozen=frozen, slots=slots, kw_only=kw_only, repr=False, eq=False
        )
        every = dataclasses.fields(made)
        if not explicit_repr:
            made.__repr__ = _repr_of(made, tuple(f.name for f in every if f.repr))
        if eq and not explicit_eq:
            made.__eq__ = _eq_of(made, _values([f.name for f in every if f.compare]))
        if eq and not explicit_hash:
            # dataclasses' rule without unsafe_hash: frozen and eq adds a hash of the
            # compared fields (or those with hash=True); eq alone makes it unhashable.
            if frozen:
                hashed = [f.name for f in every if (f.compare if f.hash is None else f.hash)]
                made.__hash__ = _hash_of(made, _values(hashed))
            else:
                made.__hash__ = None
        result: _T = made
        return result

    return wrap if cls is None else wrap(cls)


def _values(names: list[str]) -> Callable[[Any], tuple[Any, ...]]:
    """The fields' values in order, as a tuple (what the generated methods compare)."""
    if len(names) > 1:
        return attrgetter(*names)
    if names:
        one = attrgetter(names[0])
        return lambda obj: (one(obj),)
    return lambda obj: ()


def _named(method: Any, cls: type, name: str) -> Any:
    method.__name__ = name
    method.__qualname__ = f"{cls.__qualname__}.{name}"
    return method


def _repr_of(cls: type, names: tuple[str, ...]) -> Any:
    @reprlib.recursive_repr()
    def __repr__(self: Any) -> str:
        body = ", ".join(f"{name}={getattr(self, name)!r}" for name in names)
        return f"{self.__class__.__qualname__}({body})"

    return _named(__repr__, cls, "__repr__")


def _eq_of(cls: type, values: Callable[[Any], tuple[Any, ...]]) -> Any:
    def __eq__(self: Any, other: object) -> Any:
        if other.__class__ is self.__class__:
            return values(self) == values(other)
        return NotImplemented

    return _named(__eq__, cls, "__eq__")


def _hash_of(cls: type, values: Callable[[Any], tuple[Any, ...]]) -> Any:
    def __hash__(self: Any) -> int:
        return hash(values(self))

    return _named(__hash__, cls, "__hash__")
