"""``dataclass`` at a lower import cost: the standard one, with ``__init__`` compiled once per
class and ``__repr__``, ``__eq__``, ``__hash__`` and the frozen ``__setattr__`` shared instead of
compiled for each class (issue 31).

The standard decorator writes the source of every method it adds and compiles it, class by
class; on Python 3.11 that is most of what a class costs to define, and a lint defines about
seventy dataclasses before it reads a byte (some 14 ms of a ten-minute ULog's 0.36 s lint
were these compiles). Here ``dataclasses.dataclass`` still collects the fields (defaults,
factories, ``field(...)`` options, inheritance, keyword-only) and makes the slots; this module
adds what it would have compiled:

* ``__init__``: one function per class, as the standard one (same parameters, defaults,
  keyword-only layout, factories, ``init=False`` fields, ``__post_init__``), storing through
  the slots' descriptors as ``events._fast_init`` does, so a frozen class needs no
  ``object.__setattr__`` per field;
* ``__repr__``, ``__eq__``, ``__hash__``: closures over the field names, with the standard
  rules for which fields take part (``repr=``, ``compare=``, ``hash=``) and for when
  ``__hash__`` is added, kept or set to None;
* for a frozen class, ``__setattr__``/``__delattr__`` that raise ``FrozenInstanceError`` and,
  with slots, the state for copy and pickle.

``tests/test_lean_dataclass.py`` holds all of it to the standard decorator's behaviour. What
differs: ``__dataclass_params__`` says ``init=False, repr=False, eq=False, frozen=False`` for
every class made here, since the standard decorator did not add those methods; nothing in
fuzzoff reads it. ``InitVar`` fields are refused (no class of fuzzoff has one).
"""

from __future__ import annotations

import dataclasses
import inspect
import reprlib
import types
from collections.abc import Callable
from dataclasses import MISSING, Field, FrozenInstanceError, field
from operator import attrgetter
from typing import Any, TypeVar, dataclass_transform, overload

_T = TypeVar("_T", bound=type)


class _Factory:
    """The default of a parameter whose field has a ``default_factory`` (as the standard
    ``__init__``'s ``_HAS_DEFAULT_FACTORY``): the factory runs when the caller gave none."""

    def __repr__(self) -> str:
        return "<factory>"


_FACTORY = _Factory()

_INIT_VAR = getattr(dataclasses, "_FIELD_INITVAR", None)
"""How the standard decorator marks an ``InitVar`` pseudo-field (not public: None if gone)."""


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
        undocumented = own.get("__doc__") is None
        explicit_repr = "__repr__" in own
        explicit_eq = "__eq__" in own
        class_hash = own.get("__hash__", MISSING)
        explicit_hash = not (class_hash is MISSING or (class_hash is None and explicit_eq))
        made: Any = dataclasses.dataclass(
            original, slots=slots, kw_only=kw_only, init=False, repr=False, eq=False
        )
        pseudo = made.__dataclass_fields__.values()
        if _INIT_VAR is not None and any(f._field_type is _INIT_VAR for f in pseudo):
            raise TypeError(f"{made.__qualname__}: InitVar fields are not supported here")
        every = dataclasses.fields(made)
        made.__init__ = _init_of(made, every, slots=slots)
        if undocumented:  # as the standard decorator, from the signature it now has
            text = str(inspect.signature(made)).replace(" -> None", "")
            made.__doc__ = made.__name__ + text
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
        if frozen:
            _freeze(made, tuple(f.name for f in every), slots=slots)
        result: _T = made
        return result

    return wrap if cls is None else wrap(cls)


def _init_of(cls: type, every: tuple[Field[Any], ...], *, slots: bool) -> Any:
    """The standard ``__init__`` of ``cls`` (parameters, defaults, factories, ``init=False``
    fields, ``__post_init__``), compiled once; it stores through each slot's descriptor
    (``object.__setattr__`` without slots), which a frozen class's ``__setattr__`` does not see."""
    namespace: dict[str, Any] = {"_fz_factory": _FACTORY, "_fz_setattr": object.__setattr__}
    positional: list[str] = []
    keyword: list[str] = []
    body: list[str] = []
    for f in every:
        name = f.name
        if f.init:
            if f.default is not MISSING:
                namespace[f"_fz_default_{name}"] = f.default
                param, value = f"{name}=_fz_default_{name}", name
            elif f.default_factory is not MISSING:
                namespace[f"_fz_make_{name}"] = f.default_factory
                param = f"{name}=_fz_factory"
                value = f"_fz_make_{name}() if {name} is _fz_factory else {name}"
            else:
                param, value = name, name
            (keyword if f.kw_only is True else positional).append(param)
        elif f.default_factory is not MISSING:
            namespace[f"_fz_make_{name}"] = f.default_factory
            value = f"_fz_make_{name}()"
        elif f.default is not MISSING:
            namespace[f"_fz_default_{name}"] = f.default
            value = f"_fz_default_{name}"
        else:
            continue  # no value: the standard __init__ leaves it unset too
        if slots:
            descriptor = inspect.getattr_static(cls, name)
            assert isinstance(descriptor, types.MemberDescriptorType), (cls, name)
            namespace[f"_fz_set_{name}"] = descriptor.__set__
            body.append(f"    _fz_set_{name}(self, {value})\n")
        else:
            body.append(f"    _fz_setattr(self, {name!r}, {value})\n")
    if hasattr(cls, "__post_init__"):
        body.append("    self.__post_init__()\n")
    params = ["self", *positional, *(["*", *keyword] if keyword else [])]
    lines = "".join(body) or "    pass\n"
    source = f"def __init__({', '.join(params)}):\n" + lines
    try:
        exec(source, namespace)  # generated from the dataclass fields above, nothing else
    except SyntaxError as exc:  # a field without a default after one with: as the standard
        raise TypeError(f"{cls.__qualname__}: {exc.msg}") from None
    init = namespace["__init__"]
    init.__annotations__ = {f.name: f.type for f in every if f.init} | {"return": None}
    return _named(init, cls, "__init__")


def _freeze(cls: Any, names: tuple[str, ...], *, slots: bool) -> None:
    """The frozen class's assignment and deletion (``FrozenInstanceError`` for its fields and
    on its own instances, as the standard ones) and, with slots, its copy and pickle state."""
    fields_of = frozenset(names)

    def __setattr__(self: Any, name: str, value: object) -> None:
        if type(self) is cls or name in fields_of:
            raise FrozenInstanceError(f"cannot assign to field {name!r}")
        super(cls, self).__setattr__(name, value)

    def __delattr__(self: Any, name: str) -> None:
        if type(self) is cls or name in fields_of:
            raise FrozenInstanceError(f"cannot delete field {name!r}")
        super(cls, self).__delattr__(name)

    cls.__setattr__ = _named(__setattr__, cls, "__setattr__")
    cls.__delattr__ = _named(__delattr__, cls, "__delattr__")
    if not slots:
        return
    values = _values(list(names))

    def __getstate__(self: Any) -> list[Any]:
        return list(values(self))

    def __setstate__(self: Any, state: list[Any]) -> None:
        for name, value in zip(names, state, strict=False):
            object.__setattr__(self, name, value)

    cls.__getstate__ = _named(__getstate__, cls, "__getstate__")
    cls.__setstate__ = _named(__setstate__, cls, "__setstate__")


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
