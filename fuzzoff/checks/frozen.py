"""OFB107: a command that moves the vehicle, held identical while the stream keeps coming.

A heuristic for a dead controller behind a library that re-sends the last setpoint (MAVSDK
does, at 20 Hz): the keep-alive stays healthy, so PX4 never fails safe and flies the command on.
Judged per topic, in offboard, on the external controller's messages; a gap longer than
``max_gap_s`` or any change in content restarts the count. Only a command that moves the vehicle
is reported (``_motion.held_motion``): a held position, a zero velocity or a hover is what a
stopped controller should leave. A motion that takes the vehicle ever further (``straight``) is
reported after ``freeze_s``, a bounded one (a circle, a turn on the spot) after ``turning_s``.
"""

from __future__ import annotations

import marshal
import math
from collections.abc import Callable
from dataclasses import fields
from itertools import chain, repeat
from operator import attrgetter, eq, itemgetter, le, ne, sub
from typing import Any

from fuzzoff.checks._external import external_only, from_external
from fuzzoff.checks._keepalive import mode_note
from fuzzoff.checks._motion import ROVER_TURNS, Hover, Motion, held_motion, rover_turns
from fuzzoff.checks.base import Check, CheckContext, StreamBatch
from fuzzoff.events import MAVLINK_SETPOINTS, PX4_SETPOINTS, Event, VehicleStatus, Where
from fuzzoff.gate import GateTransition
from fuzzoff.lean_dataclass import dataclass

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


_FIELDS: dict[type[Event], tuple[str, ...]] = {}
_READ: dict[str, Callable[[Event], Any]] = {}
_T = attrgetter("t")
_KIND = attrgetter("kind")


def _content_fields(cls: type[Event]) -> tuple[str, ...]:
    names = _FIELDS.get(cls)
    if names is None:
        names = _FIELDS[cls] = tuple(f.name for f in fields(cls) if f.name not in HEADER_FIELDS)
    return names


def _reader(name: str) -> Callable[[Event], Any]:
    read = _READ.get(name)
    if read is None:
        read = _READ[name] = attrgetter(name)
    return read


def _list_head(n: int) -> bytes:
    """How marshal (version 2) starts a list of ``n`` items."""
    return b"[" + n.to_bytes(4, "little")


_MARSHAL = 2
"""Version 2 writes no back-references (version 3+ does, so one value can be written two ways):
a list is its head followed by each item as if written alone."""
assert marshal.dumps([0.5, 0.5], _MARSHAL) == _list_head(2) + marshal.dumps(0.5, _MARSHAL) * 2


def all_alike(raws: list[Any]) -> bool:
    """Is every content in ``raws`` written exactly like the first (marshal: same types, same
    nesting, the same float bits, NaN included)? Then each has the first's ``repr``, and holds a
    NaN where and only where the first does: the same content for ``on_event`` in every way."""
    try:
        whole = marshal.dumps(raws, _MARSHAL)
        one = marshal.dumps(raws[0], _MARSHAL)
    except ValueError:  # a value marshal cannot write (a float subclass...): not proven
        return False
    return whole == _list_head(len(raws)) + one * len(raws)


def changing_field(events: list[Event], names: tuple[str, ...]) -> str | None:
    """A field (of ``names``) whose value differs between every two consecutive ``events`` and
    is never NaN or infinite in any of them, or None.

    Two values that differ and hold no NaN have different ``repr`` too, so such a field proves
    that no message has the content of the one before it, whether ``on_event`` compares the
    content as tuples or as text. A finite sum proves every term finite (an overflow, or a
    value that is not a number, only fails the proof)."""
    for name in names:
        column = list(map(_reader(name), events))
        if not all(map(ne, column[1:], column[:-1])):
            continue
        try:
            total = (
                sum(chain.from_iterable(column)) if isinstance(column[0], tuple) else sum(column)
            )
            if math.isfinite(total):
                return name
        except (TypeError, OverflowError):
            continue
    return None


def _itself(value: Any) -> Any:
    return value


def _clearly_differ(a: Any, b: Any) -> bool:
    """Do two values of one field differ without a NaN in either (so as text too)?"""
    try:
        if a == b:
            return False
        if isinstance(a, tuple) and isinstance(b, tuple):
            return math.isfinite(sum(a) + sum(b))
        return math.isfinite(a + b)
    except (TypeError, OverflowError):  # not numbers: not proven
        return False


@dataclass(slots=True)
class _Run:
    raw: Any
    """The content as read (first message of the run); equal tuples are equal content."""
    start: float
    last: float
    where: Where
    first: Event
    """The run's first message (every message of the run has its content)."""
    count: int = 1
    content: str | None = None
    """``repr`` of ``raw`` once needed: equal text means equal content, NaN included."""

    def text(self) -> str:
        if self.content is None:
            self.content = repr(self.raw)
        return self.content


@dataclass(slots=True)
class _Plan:
    """What a run of one kind's messages does to ``runs[kind]``: the first ``extend`` messages
    extend the run open before it; then (``new`` given) that run is closed and ``new`` is the
    open run after the last message (every run in between has one message: never reported)."""

    kind: str
    extend: int
    last: float
    """Time of the last message that extends the open run."""
    new: _Run | None


class SetpointFrozen(Check):
    codes = ("OFB107",)
    wants = (*PX4_SETPOINTS, *MAVLINK_SETPOINTS, VehicleStatus, GateTransition)

    def __init__(self, ctx: CheckContext) -> None:
        super().__init__(ctx)
        self.freeze = float(ctx.option("OFB107", "freeze_s"))
        self.turning = float(ctx.option("OFB107", "turning_s"))
        self.shortest = min(self.freeze, self.turning)
        """No run this short is reported, whatever its content."""
        self.hover = Hover(
            float(ctx.option("OFB107", "hover_thrust")), float(ctx.option("OFB107", "hover_band"))
        )
        self.max_gap = float(ctx.option("OFB107", "max_gap_s"))
        self.runs: dict[str, _Run] = {}
        self.setpoints = self.wants
        self.changing: dict[str, str | None] = {}
        """Per kind, how the last run was proven: the field that changed every time, or None
        (frozen content). Tried first on the next run."""
        self.quiet_single = self.shortest >= 0
        """A run of one message (duration 0) is never reported: the moving fast path needs it."""
        self.turns: dict[str, tuple[float, float]] = {}
        """Rover steering / yaw-rate kind -> (start, last) of its last closed run that turned
        the rover: a speed or throttle held under it drives a circle (``_rover_turning``)."""

    def on_event(self, event: Event) -> None:
        if not self.ctx.flying:  # out of offboard, or disarmed
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
        self.runs[kind] = _Run(raw, event.t, event.t, event.where, event, content=text)

    def on_batch(self, batch: StreamBatch) -> None:
        """Fast path, per kind: content frozen for the whole run, or changing with every message
        (``all_alike``, ``changing_field``); the first message is compared with the open run as
        ``on_event`` does. The open run is then closed at most once, at a known message. Any
        other run, rover placeholders and two kinds closing a run in one batch replay."""
        events = batch.of(self.setpoints)
        if not events:
            return
        if not self.ctx.flying:  # every message closes every run: the first one does
            for kind in list(self.runs):
                self._close(kind)
            return
        groups = self._external_by_kind(events)
        plans = []
        for kind, group in (groups or {}).items():
            plan = self._plan(kind, group)
            if plan is None:
                break
            plans.append(plan)
        if groups is None or len(plans) < len(groups) or self._closes(plans) > 1:
            self.replay(batch)
            return
        for plan in plans:
            self._apply(plan)

    def _external_by_kind(self, events: list[Event]) -> dict[str, list[Event]] | None:
        """The external controller's messages by kind; None if a rover kind needs its
        placeholder test."""
        kinds = set(map(_KIND, events))
        if any(kind.startswith("rover_") for kind in kinds):
            return None
        external = external_only(self.ctx, events)
        if len(kinds) == 1:
            return {external[0].kind: external} if external else {}
        groups: dict[str, list[Event]] = {}
        for event in external:
            groups.setdefault(event.kind, []).append(event)
        return groups

    def _plan(self, kind: str, events: list[Event]) -> _Plan | None:
        """What ``on_event`` would do with these messages (all of one kind), or None (replay)."""
        run = self.runs.get(kind)
        first = events[0]
        if run is not None and first.t - run.last > self.max_gap:
            run = None  # on_event starts a new run: as if none were open
        known = self.changing.get(kind, "")
        if known:
            plan = self._moving(kind, events, (known,), run)
            if plan is not None:
                return plan
        plan = self._frozen(kind, events, run)
        if plan is None:
            plan = self._moving(kind, events, _content_fields(type(first)), run)
        return plan

    def _continues(self, raw: Any, run: _Run | None, field: Callable[[Any], Any] | None) -> bool:
        """Does a message with content ``raw`` continue ``run`` (open within ``max_gap``)? As
        ``on_event`` decides, but without ``repr`` where ``field`` (of a content) proves a
        change."""
        if run is None:
            return False
        if raw == run.raw:
            return True
        if field is not None and _clearly_differ(field(raw), field(run.raw)):
            return False
        return _may_hold_nan(raw) and repr(raw) == run.text()

    def _moving(
        self, kind: str, events: list[Event], names: tuple[str, ...], run: _Run | None
    ) -> _Plan | None:
        """Every message after the first differs from the one before (``changing_field``): each
        starts a run of its own, which the next closes unreported (``quiet_single``)."""
        if not self.quiet_single:
            return None
        name = changing_field(events, names)
        if name is None:
            return None
        self.changing[kind] = name
        first, last = events[0], events[-1]
        get = _getter(type(first))
        raw = get(first)
        names_all = _content_fields(type(first))
        # the content is a tuple of the fields, or the one field's value itself
        field = itemgetter(names_all.index(name)) if len(names_all) > 1 else _itself
        same = self._continues(raw, run, field)
        if same and len(events) == 1:
            return _Plan(kind, 1, first.t, None)
        new_raw = raw if last is first else get(last)
        return _Plan(kind, int(same), first.t, _Run(new_raw, last.t, last.t, last.where, last))

    def _frozen(self, kind: str, events: list[Event], run: _Run | None) -> _Plan | None:
        """Every message has the same content (as tuples, or written alike: ``all_alike``) and
        follows the one before within ``max_gap``: one run throughout, the open one if its
        content is that too."""
        times = list(map(_T, events))
        if not all(map(le, map(sub, times[1:], times[:-1]), repeat(self.max_gap))):
            return None
        raws = list(map(_getter(type(events[0])), events))
        # == is an equivalence on contents (identity first), and so is being written alike
        if run is not None and (all(map(eq, raws, repeat(run.raw))) or all_alike([run.raw, *raws])):
            self.changing[kind] = None
            return _Plan(kind, len(events), times[-1], None)
        raw = raws[0]
        if not all(map(eq, raws, repeat(raw))) and not all_alike(raws):
            return None
        if self._continues(raw, run, None):
            return None  # the first continues the open run, the others may not: replay
        self.changing[kind] = None
        new = _Run(raw, times[0], times[-1], events[0].where, events[0], len(events))
        return _Plan(kind, 0, times[0], new)

    def _closes(self, plans: list[_Plan]) -> int:
        """How many plans close a run that is reported (order across kinds would matter)."""
        count = 0
        for plan in plans:
            run = self.runs.get(plan.kind)
            if plan.new is not None and run is not None:
                last = plan.last if plan.extend else run.last
                count += self._motion(run, last) is not None  # as _close decides
        return count

    def _apply(self, plan: _Plan) -> None:
        run = self.runs.get(plan.kind)
        if run is not None and plan.extend:
            run.last = plan.last
            run.count += plan.extend
        if plan.new is not None:
            self._close(plan.kind)
            self.runs[plan.kind] = plan.new

    def _motion(self, run: _Run, last: float) -> Motion | None:
        """The motion ``run`` commands when it is held longer than that motion's threshold
        until ``last``, else None (a hold is never reported)."""
        duration = last - run.start
        if duration <= self.shortest:
            return None
        motion = held_motion(run.first, self.ctx.profile.vehicle, self.hover)
        if motion is None:
            return None
        if motion.kind == "straight" and run.first.kind in ("rover_speed", "rover_throttle"):
            motion = self._rover_turning(run, motion)
        limit = self.freeze if motion.kind == "straight" else self.turning
        return motion if duration > limit else None

    def _rover_turning(self, run: _Run, motion: Motion) -> Motion:
        """A rover speed or throttle held while a steering or yaw-rate setpoint that turns the
        rover covers its first ``freeze_s`` (from the start, within ``max_gap_s``): a circle."""
        end = min(run.last, run.start + self.freeze) - self.max_gap
        for kind in ROVER_TURNS:
            open_run = self.runs.get(kind)
            spans = [self.turns[kind]] if kind in self.turns else []
            if open_run is not None and rover_turns(open_run.first):
                spans.append((open_run.start, open_run.last))
            if any(s <= run.start + self.max_gap and last >= end for s, last in spans):
                return Motion("turning", f"{motion.what} under a held turn")
        return motion

    def _close(self, kind: str) -> None:
        run = self.runs.pop(kind, None)
        if run is None:
            return
        if kind in ROVER_TURNS and rover_turns(run.first):
            self.turns[kind] = (run.start, run.last)
        motion = self._motion(run, run.last)
        if motion is None:
            return
        duration = run.last - run.start
        rate = (run.count - 1) / duration
        bounded = " (a bounded motion)" if motion.kind == "turning" else ""
        self.ctx.report(
            "OFB107",
            f"{run.where.topic or kind}: the same {motion.what}{bounded} for {duration:.2f} s "
            f"({run.count} identical messages, {rate:.1f} Hz) in offboard: a controller that "
            f"stopped while its library re-sends the last setpoint keeps the vehicle moving, "
            f"and PX4 sees a healthy stream{mode_note(self.ctx)}",
            run.start,
            run.where,
            end=run.last,
            short=f"the same {motion.what}{bounded} held for {duration:.1f} s while the stream "
            "goes on",
        )

    def finish(self, t_end: float) -> None:
        for kind in list(self.runs):
            self._close(kind)
