"""OFB107: identical setpoint content for longer than a threshold while the stream keeps coming.

A heuristic for a dead controller behind a library that re-sends the last setpoint (MAVSDK
does, at 20 Hz): the keep-alive stays healthy, so PX4 never fails safe. Judged per topic, in
offboard, on the external controller's messages; a gap longer than ``max_gap_s`` or any change
in content restarts the count.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field, fields
from operator import attrgetter
from typing import Any

from fuzzoff.checks._external import from_external, mode_note
from fuzzoff.checks.base import Check, CheckContext
from fuzzoff.events import MAVLINK_SETPOINTS, PX4_SETPOINTS, Event, VehicleStatus, Where
from fuzzoff.gate import GateTransition

HEADER_FIELDS = frozenset({"t", "vehicle", "where", "sender_time_us", "origin"})
"""Fields that change with every message and say nothing about the setpoint."""

_CONTENT: dict[type[Event], Callable[[Event], Any]] = {}


def content_of(event: Event) -> str:
    """The setpoint's content as comparable text (``repr`` keeps NaN equal to NaN)."""
    getter = _CONTENT.get(type(event))
    if getter is None:
        names = [f.name for f in fields(event) if f.name not in HEADER_FIELDS]
        getter = _CONTENT[type(event)] = attrgetter(*names)
    return repr(getter(event))


def _floats(value: Any) -> list[float]:
    if isinstance(value, float):
        return [value]
    if isinstance(value, tuple):
        return [x for item in value for x in _floats(item)]
    return []


def is_placeholder(event: Event) -> bool:
    """Every float of the content is NaN: a setpoint published as NaN on purpose (seed 000:
    a rover combination needs the setpoints above it published as NaN), not a frozen one."""
    getter = _CONTENT.get(type(event))
    if getter is None:
        content_of(event)
        getter = _CONTENT[type(event)]
    values = _floats(getter(event))
    return bool(values) and all(math.isnan(v) for v in values)


SAMPLE_S = 0.1
"""Content is compared at most this often within a run (a live controller changes its setpoint
continuously, so 10 Hz samples show it; comparing every message of a 50 Hz stream costs 5x)."""


@dataclass(slots=True)
class _Run:
    content: str
    start: float
    last: float
    """The last message proven identical."""
    where: Where
    count: int = 1
    compared: float = 0.0
    pending: list[tuple[float, Any]] = field(default_factory=list)
    """Messages since the last comparison (at most ``SAMPLE_S`` of them): their raw content,
    compared only when the run ends, so its end stays exact."""

    def settle(self) -> None:
        """Extend the run over the pending messages that match it, up to the first that does not."""
        for t, raw in self.pending:
            if repr(raw) != self.content:
                break
            self.last = t
            self.count += 1
        self.pending.clear()


class SetpointFrozen(Check):
    codes = ("OFB107",)
    wants = (*PX4_SETPOINTS, *MAVLINK_SETPOINTS, VehicleStatus, GateTransition)

    def __init__(self, ctx: CheckContext) -> None:
        super().__init__(ctx)
        self.freeze = float(ctx.option("OFB107", "freeze_s"))
        self.max_gap = float(ctx.option("OFB107", "max_gap_s"))
        self.runs: dict[str, _Run] = {}

    def on_event(self, event: Event) -> None:
        if not self.ctx.state.in_offboard or self.ctx.state.armed is False:
            for kind in list(self.runs):
                self._close(kind)
            return
        if isinstance(event, (VehicleStatus, GateTransition)) or not from_external(self.ctx, event):
            return
        if event.kind.startswith("rover_") and is_placeholder(event):
            self._close(event.kind)
            return
        run = self.runs.get(event.kind)
        last_seen = run.pending[-1][0] if run is not None and run.pending else None
        if run is not None and event.t - (last_seen or run.last) <= self.max_gap:
            if event.t - run.compared < SAMPLE_S:
                run.pending.append((event.t, _CONTENT[type(event)](event)))
                return
            content = content_of(event)
            if run.content == content:
                run.count += len(run.pending) + 1
                run.pending.clear()
                run.last = run.compared = event.t
                return
            if run.pending:
                self._restart_within(run, event, content)
                return
        else:
            content = content_of(event)
        self._close(event.kind)
        self.runs[event.kind] = _Run(content, event.t, event.t, event.where, compared=event.t)

    def _restart_within(self, run: _Run, event: Event, content: str) -> None:
        """The content changed somewhere among the uncompared messages: end the run at the last
        one that matches and start the next run at the first one that does not (exact edges)."""
        pending, run.pending = run.pending, []
        matched = 0
        for t, raw in pending:
            if repr(raw) != run.content:
                break
            run.last, matched = t, matched + 1
        run.count += matched
        self.runs[event.kind] = run
        self._close(event.kind)
        rest = pending[matched:]
        if not rest:  # every pending message matched: the change is this message
            self.runs[event.kind] = _Run(content, event.t, event.t, event.where, compared=event.t)
            return
        t0, raw0 = rest[0]
        new = _Run(repr(raw0), t0, t0, event.where, compared=event.t)
        for t, raw in [*rest[1:], (event.t, None)]:
            text = content if raw is None else repr(raw)
            if text != new.content:
                self.runs[event.kind] = new
                self._close(event.kind)
                new = _Run(text, t, t, event.where, compared=event.t)
            else:
                new.last, new.count = t, new.count + 1
        self.runs[event.kind] = new

    def _close(self, kind: str) -> None:
        run = self.runs.pop(kind, None)
        if run is None:
            return
        run.settle()
        if run.last - run.start <= self.freeze:
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
