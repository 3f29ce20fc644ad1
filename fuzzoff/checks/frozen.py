"""OFB107: identical setpoint content for longer than a threshold while the stream keeps coming.

A heuristic for a dead controller behind a library that re-sends the last setpoint (MAVSDK
does, at 20 Hz): the keep-alive stays healthy, so PX4 never fails safe. Judged per topic, in
offboard, on the external controller's messages; a gap longer than ``max_gap_s`` or any change
in content restarts the count.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, fields
from operator import attrgetter
from typing import Any

from fuzzoff.checks._external import from_external
from fuzzoff.checks._keepalive import mode_note
from fuzzoff.checks.base import Check, CheckContext
from fuzzoff.events import MAVLINK_SETPOINTS, PX4_SETPOINTS, Event, VehicleStatus, Where
from fuzzoff.gate import GateTransition

HEADER_FIELDS = frozenset({"t", "vehicle", "where", "sender_time_us", "origin"})
"""Fields that change with every message and say nothing about the setpoint."""

_CONTENT: dict[type[Event], Callable[[Event], Any]] = {}


def _getter(cls: type[Event]) -> Callable[[Event], Any]:
    """Reads a setpoint's content fields (everything but the header) as a tuple."""
    getter = _CONTENT.get(cls)
    if getter is None:
        names = [f.name for f in fields(cls) if f.name not in HEADER_FIELDS]
        getter = _CONTENT[cls] = attrgetter(*names)
    return getter


def content_of(event: Event) -> str:
    """The setpoint's content as comparable text (``repr`` keeps NaN equal to NaN)."""
    return repr(_getter(type(event))(event))


def _floats(value: Any) -> list[float]:
    if isinstance(value, float):
        return [value]
    if isinstance(value, tuple):
        return [x for item in value for x in _floats(item)]
    return []


def is_placeholder(event: Event) -> bool:
    """Every float of the content is NaN: a setpoint published as NaN on purpose (seed 000:
    a rover combination needs the setpoints above it published as NaN), not a frozen one."""
    values = _floats(_getter(type(event))(event))
    return bool(values) and all(math.isnan(v) for v in values)


def _may_hold_nan(value: Any) -> bool:
    """Could ``value`` (content as read: a value or nested tuples) hold a NaN?

    Content that differs as a tuple can still be the same content only through NaN (NaN !=
    NaN; every other value the events carry has a ``repr`` that tells unequal values apart),
    so without a NaN the ``repr`` comparison is skipped: ~1 µs here against ~3.7 µs for the
    ``repr`` of a ``SET_POSITION_TARGET_LOCAL_NED``, on every message whose content changes.
    """
    if value.__class__ is not tuple:
        return bool(value != value)
    for item in value:
        if item.__class__ is tuple:  # a vector: one level down, without a call per vector
            for x in item:
                if x != x or x.__class__ is tuple:
                    return True  # NaN, or deeper than events nest: let ``repr`` decide
        elif item != item:
            return True
    return False


@dataclass(slots=True)
class _Run:
    raw: Any
    """The content as read (first message of the run); equal tuples are equal content."""
    start: float
    last: float
    where: Where
    count: int = 1
    content: str | None = None
    """``repr`` of ``raw`` once needed: equal text means equal content, NaN included."""

    def text(self) -> str:
        if self.content is None:
            self.content = repr(self.raw)
        return self.content


class SetpointFrozen(Check):
    codes = ("OFB107",)
    wants = (*PX4_SETPOINTS, *MAVLINK_SETPOINTS, VehicleStatus, GateTransition)

    def __init__(self, ctx: CheckContext) -> None:
        super().__init__(ctx)
        self.freeze = float(ctx.option("OFB107", "freeze_s"))
        self.max_gap = float(ctx.option("OFB107", "max_gap_s"))
        self.runs: dict[str, _Run] = {}

    def on_event(self, event: Event) -> None:
        if not self.ctx.state.flying:  # out of offboard, or disarmed
            if self.runs:
                for kind in list(self.runs):
                    self._close(kind)
            return
        if isinstance(event, (VehicleStatus, GateTransition)) or not from_external(self.ctx, event):
            return
        kind = event.kind
        if kind.startswith("rover_") and is_placeholder(event):
            self._close(kind)
            return
        raw = _getter(type(event))(event)
        run = self.runs.get(kind)
        text = None
        if run is not None and event.t - run.last <= self.max_gap:
            # identical content without NaN compares equal as a tuple, which is cheap; text is
            # needed only when it does not and a NaN could be the reason (NaN != NaN)
            if raw == run.raw:
                same = True
            elif _may_hold_nan(raw):
                text = repr(raw)
                same = text == run.text()
            else:
                same = False
            if same:
                run.last = event.t
                run.count += 1
                return
        self._close(kind)
        self.runs[kind] = _Run(raw, event.t, event.t, event.where, content=text)

    def _close(self, kind: str) -> None:
        run = self.runs.pop(kind, None)
        if run is None or run.last - run.start <= self.freeze:
            return
        duration = run.last - run.start
        rate = (run.count - 1) / duration
        self.ctx.report(
            "OFB107",
            f"{run.where.topic or kind}: identical setpoint content for {duration:.2f} s "
            f"({run.count} messages, {rate:.1f} Hz) in offboard: a controller that stopped "
            f"while its library re-sends the last setpoint looks alive to PX4"
            f"{mode_note(self.ctx)}",
            run.start,
            run.where,
            end=run.last,
        )

    def finish(self, t_end: float) -> None:
        for kind in list(self.runs):
            self._close(kind)
