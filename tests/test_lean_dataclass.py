"""fuzzoff.lean_dataclass keeps the standard decorator's contract: the same ``repr``, equality
and hash (which fields, which rule for ``__hash__``), frozen assignment, copy and pickle, for
every way fuzzoff declares a dataclass."""

from __future__ import annotations

import copy
import dataclasses
import inspect
import math
import pickle
from collections.abc import Callable
from typing import Any

import pytest
from hypothesis import given
from hypothesis import strategies as st

from fuzzoff import lean_dataclass

Decorator = Callable[..., Any]
OPTIONS = [
    {"frozen": True, "slots": True},
    {"slots": True},
    {"slots": True, "eq": False},
    {"frozen": True},
    {},
    {"frozen": True, "slots": True, "kw_only": True},
]


def _plain(make: Decorator, options: dict[str, Any]) -> type:
    @make(**options)
    class Point:
        x: float
        y: Any = None
        label: str = dataclasses.field(default="", compare=False)
        secret: int = dataclasses.field(default=0, repr=False)
        tags: list[str] = dataclasses.field(default_factory=list, hash=False)

    return Point


def _explicit_eq(make: Decorator, options: dict[str, Any]) -> type:
    @make(**options)
    class ByName:
        name: str
        value: float = 0.0

        def __eq__(self, other: object) -> bool:
            return isinstance(other, ByName) and other.name == self.name

    return ByName


def _explicit_hash(make: Decorator, options: dict[str, Any]) -> type:
    @make(**options)
    class Hashed:
        name: str

        def __hash__(self) -> int:
            return 7

    return Hashed


def _child(make: Decorator, options: dict[str, Any]) -> type:
    @make(**options)
    class Base:
        a: int

    @make(**options)
    class Child(Base):
        b: float = 1.5

    return Child


def _derived(make: Decorator, options: dict[str, Any]) -> type:
    @make(**options)
    class Derived:
        a: Any
        items: list[Any] = dataclasses.field(default_factory=list)
        text: str = dataclasses.field(init=False, default="")
        seen: list[str] = dataclasses.field(init=False, default_factory=list)

        def __post_init__(self) -> None:
            object.__setattr__(self, "text", repr(self.a))

    return Derived


SHAPES = [_plain, _explicit_eq, _explicit_hash, _child, _derived]
CASES = [(shape, options) for shape in SHAPES for options in OPTIONS]
IDS = [f"{shape.__name__}-{'-'.join(options) or 'defaults'}" for shape, options in CASES]

VALUES = st.one_of(
    st.integers(),
    st.floats(allow_nan=True),
    st.text(max_size=5),
    st.tuples(st.floats(allow_nan=True), st.floats(allow_nan=True)),
    st.none(),
)


def _build(cls: type, values: list[Any]) -> Any:
    names = [f.name for f in dataclasses.fields(cls) if f.init]
    return cls(**dict(zip(names, values, strict=False)))


def _hash(obj: Any) -> int | str:
    try:
        return hash(obj)
    except TypeError as exc:
        return f"TypeError: {exc}"


@pytest.mark.parametrize(("shape", "options"), CASES, ids=IDS)
@given(
    first=st.lists(VALUES, min_size=5, max_size=5), second=st.lists(VALUES, min_size=5, max_size=5)
)
def test_repr_equality_and_hash_are_the_standard_ones(
    shape: Callable[[Decorator, dict[str, Any]], type],
    options: dict[str, Any],
    first: list[Any],
    second: list[Any],
) -> None:
    standard = shape(dataclasses.dataclass, options)
    lean = shape(lean_dataclass.dataclass, options)
    pairs = [
        (_build(standard, first), _build(lean, first)),
        (_build(standard, second), _build(lean, second)),
    ]
    (s1, l1), (s2, l2) = pairs
    assert repr(l1) == repr(s1) and repr(l2) == repr(s2)
    assert (l1 == l2) == (s1 == s2)
    assert (l1 == l1) == (s1 == s1)  # NaN: the same object is equal, as in a tuple
    assert (l1 != l2) == (s1 != s2)
    assert (l1 == "other") is False
    if options.get("eq", True):
        assert _hash(l1) == _hash(s1)  # fields' hash, an explicit one, or unhashable
    else:
        # identity, or unhashable where the class defines __eq__ (Python's own rule)
        assert type(_hash(l1)) is type(_hash(s1))


@pytest.mark.parametrize(("shape", "options"), CASES, ids=IDS)
def test_frozen_copy_and_pickle_behave_as_the_standard_ones(
    shape: Callable[[Decorator, dict[str, Any]], type], options: dict[str, Any]
) -> None:
    lean = shape(lean_dataclass.dataclass, options)
    obj = _build(lean, ["a", 2.5])
    assert dataclasses.is_dataclass(obj)
    assert copy.copy(obj) == obj or options.get("eq") is False
    assert repr(copy.deepcopy(obj)) == repr(obj)
    first = dataclasses.fields(lean)[0].name
    if options.get("frozen"):
        with pytest.raises(dataclasses.FrozenInstanceError):
            setattr(obj, first, 1)
    else:
        setattr(obj, first, 1)
        assert getattr(obj, first) == 1
    assert dataclasses.replace(obj).__class__ is lean


@pytest.mark.parametrize(("shape", "options"), CASES, ids=IDS)
def test_init_takes_the_standard_parameters_and_fills_every_field(
    shape: Callable[[Decorator, dict[str, Any]], type], options: dict[str, Any]
) -> None:
    standard = shape(dataclasses.dataclass, options)
    lean = shape(lean_dataclass.dataclass, options)

    def parameters(cls: type) -> list[tuple[str, Any, str]]:
        params = inspect.signature(cls.__init__).parameters.values()
        return [(p.name, p.kind, repr(p.default)) for p in params]

    assert parameters(lean) == parameters(standard)
    first, second = _build(lean, [1.0]), _build(lean, [1.0])
    assert repr(first) == repr(_build(standard, [1.0]))
    for f in dataclasses.fields(lean):
        if f.default_factory is not dataclasses.MISSING:  # a new object for each instance
            assert getattr(first, f.name) is not getattr(second, f.name)
    assert lean.__doc__ == standard.__doc__


def test_a_field_without_a_default_after_one_with_is_refused_as_by_the_standard() -> None:
    with pytest.raises(TypeError):

        @lean_dataclass.dataclass(slots=True)
        class Wrong:
            a: int = 0
            b: int  # type: ignore[misc]


def test_a_frozen_subclass_keeps_every_field_frozen() -> None:
    @lean_dataclass.dataclass(frozen=True, slots=True)
    class Base:
        a: int

    @lean_dataclass.dataclass(frozen=True, slots=True)
    class Child(Base):
        b: int = 2

    child = Child(1)
    for name in ("a", "b"):
        with pytest.raises(dataclasses.FrozenInstanceError):
            setattr(child, name, 5)
        with pytest.raises(dataclasses.FrozenInstanceError):
            delattr(child, name)
    assert (child.a, child.b) == (1, 2) and copy.copy(child) == child


def test_a_pickled_instance_comes_back_equal() -> None:
    back = pickle.loads(pickle.dumps(_Pickled(1.0, (math.nan, 2.0))))
    assert repr(back) == "_Pickled(x=1.0, y=(nan, 2.0))"
    assert back.x == 1.0 and back.y[1] == 2.0 and math.isnan(back.y[0])
    with pytest.raises(dataclasses.FrozenInstanceError):
        back.x = 2.0  # type: ignore[misc]


def test_a_recursive_repr_ends() -> None:
    node = _Node([])
    node.children.append(node)
    assert repr(node) == "_Node(children=[...])"


@lean_dataclass.dataclass(frozen=True, slots=True)
class _Pickled:
    x: float
    y: tuple[float, float]


@lean_dataclass.dataclass(slots=True)
class _Node:
    children: list[_Node]
