"""A reproducer's stream: the events a property was checked on, as JSON (``NAME.stream.json``).

A recording is what a writer made of a stream, and a reader gives back what it can of it. A
property about the writers and readers (``round-trip``, ``truncation``) can only be checked
again on the stream itself, and the others are checked again exactly only on the events they
failed on (a reader gives its own topics, float32 values, its own order at one instant). So a
reproducer keeps the stream, one event a line, and ``fuzzoff replay`` checks the property on it
without fuzzoff's generator.

The file holds ``Scenario.to_json()``: ``px4``, ``vehicle``, ``transport``, ``params`` and
``events`` (each ``{"kind": ..., field: value}`` as ``events.event_to_dict`` gives it; NaN as
``"nan"``). Reading it back checks every field against the event type's annotation, so a
damaged or hand-edited file is one line naming the event and the field, not a traceback later.
"""

from __future__ import annotations

import json
import math
import types
import typing
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from fuzzoff.events import EVENT_BY_KIND, Event, event_from_dict
from fuzzoff.fuzz.scenario import Scenario

SUFFIX = ".stream.json"


class StreamFileError(ValueError):
    """The stream file cannot be used (the message names the event and the field)."""


def write(scenario: Scenario, path: Path) -> Path:
    """``scenario`` as ``path``: the header keys, then the events one per line (diffable)."""
    data = scenario.to_json()
    events = data.pop("events")
    head = json.dumps(data)[:-1]
    lines = ",\n".join("  " + json.dumps(e) for e in events)
    path.write_text(f'{head}, "events": [\n{lines}\n]}}\n')
    return path


def read_events(path: Path) -> tuple[Event, ...]:
    """The events of the stream file at ``path`` (``StreamFileError`` when they cannot be)."""
    try:
        data = json.loads(path.read_text())
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise StreamFileError(f"not a readable stream file: {exc}") from None
    if not isinstance(data, dict) or not isinstance(data.get("events"), list):
        raise StreamFileError("expected an object with a list of 'events'")
    return tuple(_event(i, e) for i, e in enumerate(data["events"]))


def _event(i: int, data: Any) -> Event:
    where = f"events[{i}]"
    if not isinstance(data, dict):
        raise StreamFileError(f"{where}: expected an object with 'kind' and 't'")
    kind = data.get("kind")
    cls = EVENT_BY_KIND.get(kind) if isinstance(kind, str) else None
    if cls is None:
        raise StreamFileError(f"{where}.kind: {kind!r} is not an event kind")
    hints = _hints(cls)
    for key, value in data.items():
        if key == "kind":
            continue
        if key not in hints:
            raise StreamFileError(f"{where}: {cls.kind} has no field {key!r}")
        if not _fits(value, hints[key]):
            raise StreamFileError(f"{where}.{key}: {value!r} is not a {_name(hints[key])}")
    if not (_number(data.get("t")) and math.isfinite(data["t"])):
        raise StreamFileError(f"{where}.t: {data.get('t')!r} is not a time in seconds")
    try:
        return event_from_dict(data)
    except (TypeError, ValueError) as exc:  # a required field missing
        raise StreamFileError(f"{where}: {exc}") from None


_HINTS: dict[str, dict[str, Any]] = {}


def _hints(cls: type[Event]) -> dict[str, Any]:
    """The fields of ``cls`` and their annotations (``kind`` is the class's, not a field)."""
    if cls.kind not in _HINTS:
        hints = typing.get_type_hints(cls)
        _HINTS[cls.kind] = {k: v for k, v in hints.items() if k != "kind"}
    return _HINTS[cls.kind]


def _fits(value: Any, hint: Any) -> bool:
    """Does a JSON value fit a field annotated ``hint`` (as ``event_from_dict`` builds it)?"""
    origin = typing.get_origin(hint)
    args = typing.get_args(hint)
    if origin in (typing.Union, types.UnionType):
        return any(_fits(value, a) for a in args)
    if hint is type(None):
        return value is None
    if hint is float:
        return _number(value) or value == "nan"
    if hint is bool:
        return isinstance(value, bool)
    if hint is int:
        return isinstance(value, int) and not isinstance(value, bool)
    if hint is str:
        return isinstance(value, str)
    if origin is typing.Literal:
        return value in args
    if origin is frozenset:
        return isinstance(value, list) and all(isinstance(v, str) for v in value)
    if origin is tuple:
        if not isinstance(value, list):
            return False
        if len(args) == 2 and args[1] is Ellipsis:
            return all(_fits(v, args[0]) for v in value)
        return len(value) == len(args) and all(
            _fits(v, a) for v, a in zip(value, args, strict=True)
        )
    if getattr(hint, "__name__", "") == "Where":
        return isinstance(value, str) or (
            isinstance(value, dict)
            and isinstance(value.get("topic"), str)
            and all(v is None or _fits(v, int) for k, v in value.items() if k != "topic")
            and set(value) <= {"topic", "index", "offset"}
        )
    return False


def _number(value: Any) -> bool:
    """A number JSON can carry (``json`` reads ``Infinity`` too: a stream may hold one)."""
    return isinstance(value, (int, float)) and not isinstance(value, bool) and not math.isnan(value)


def _name(hint: Any) -> str:
    names: Sequence[Any] = (
        typing.get_args(hint)
        if typing.get_origin(hint)
        in (
            typing.Union,
            types.UnionType,
        )
        else (hint,)
    )
    return " or ".join(
        "null" if a is type(None) else getattr(a, "__name__", None) or str(a) for a in names
    )
