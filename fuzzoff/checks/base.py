"""The check protocol: a small state machine that sees one vehicle's events in order.

A check subclasses ``Check``, names the rule codes it can report (``codes``) and the event
types it wants (``wants``; ``GateTransition`` included for checks driven by the gate model),
and reports through ``self.ctx.report``. Subclassing registers it; a module in this package
is imported automatically, so adding a rule needs no edit elsewhere.

The stream messages (keep-alives and setpoints, ``STREAM_TYPES``) reach every check one way:
as runs, a ``StreamBatch`` at a time, through ``on_batch``; every other event reaches
``on_event`` at once, after the runs before it. A run never spans anything that changes what
the checks read (see ``StreamBatch``). ``Check.on_batch`` replays the run through ``on_event``,
message by message; a check on the hot path overrides it to judge the run with a tight loop or
in one step.
"""

from __future__ import annotations

import copy
from collections.abc import Callable
from dataclasses import field
from operator import attrgetter
from typing import Any, ClassVar

from fuzzoff.catalog import get_rule, sent_stream_rules
from fuzzoff.config import Settings
from fuzzoff.events import (
    KEEPALIVE_ROS,
    KEEPALIVE_TYPES,
    MAVLINK_SETPOINTS,
    NAV_STATE_OFFBOARD,
    PX4_SETPOINTS,
    ControlMode,
    Event,
    LegacyControlMode,
    Where,
)
from fuzzoff.findings import Finding, Severity
from fuzzoff.gate import GateView
from fuzzoff.lean_dataclass import dataclass
from fuzzoff.profiles import Profile
from fuzzoff.recording import RecordingInfo
from fuzzoff.state import VehicleState
from fuzzoff.tables.control_mode import FlagRow, row_for

REGISTRY: list[type[Check]] = []


@dataclass(slots=True)
class CheckContext:
    """Everything a check may read, and where it reports. One per vehicle per recording."""

    profile: Profile
    settings: Settings
    info: RecordingInfo
    vehicle: str
    state: VehicleState
    gate: GateView
    """The gate model's prediction, read-only (during ``on_batch``: as the run saw it)."""
    findings: list[Finding] = field(default_factory=list)
    not_checkable: dict[str, str] = field(default_factory=dict)
    """code -> what the recording would need (one OFB002 finding lists them all)."""
    stream_recorded: bool = True
    """False: the recording holds no sent stream, and the ``sent_stream`` rules are off."""
    offboard_used: bool = False
    """The vehicle was in OFFBOARD (or an external mode) or asked to switch there, as far as
    the events so far show (kept by ``whole_file.OffboardUse`` while OFB005 is enabled)."""
    first_keepalive: float | None = None
    """When this vehicle's first keep-alive came (kept with ``offboard_used``)."""
    _rows: dict[str | None, FlagRow | None] = field(default_factory=dict)

    def row_for(self, first_flag: str | None) -> FlagRow | None:
        """``tables.control_mode.row_for`` for this profile, remembered per flag: the content
        rules ask on every setpoint, and the table lookup compares version strings (~1 µs)."""
        try:
            return self._rows[first_flag]
        except KeyError:
            row = self._rows[first_flag] = row_for(self.profile, first_flag)
            return row

    def enabled(self, code: str) -> bool:
        if not self.stream_recorded and code in sent_stream_rules():
            return False
        try:
            rule = get_rule(code)
        except KeyError:  # a check without a catalog page never reports (a test catches it)
            return False
        return self.settings.enabled(code) and rule.applies_to(
            self.profile.px4, self.profile.vehicle
        )

    def option(self, code: str, name: str) -> Any:
        return self.settings.option(code, name)

    def report(
        self,
        code: str,
        message: str,
        t: float | None,
        where: Where | None = None,
        *,
        severity: Severity | None = None,
        end: float | None = None,
        short: str = "",
    ) -> None:
        """Record a finding. ``severity`` lowers or raises the catalog default for this case
        (e.g. a docs rule the profile's PX4 tolerates); the user's override wins over both.
        ``short`` is the key fact for a terminal line (else the message's first statement)."""
        if not self.enabled(code):
            return
        rule = get_rule(code)
        level = self.settings.severity_of(code, severity if severity is not None else rule.severity)
        self.findings.append(
            Finding(
                code=code,
                name=rule.name,
                severity=level,
                message=message,
                time_s=t,
                where=where,
                vehicle=self.vehicle,
                end_s=end,
                summary=short,
            )
        )

    def cannot_check(self, code: str, needs: str) -> None:
        """Say once that ``code`` cannot be judged here and what the recording would need."""
        if self.enabled(code):
            self.not_checkable.setdefault(code, needs)

    @property
    def in_offboard(self) -> bool:
        """In OFFBOARD: as recorded (acks applied), else as the gate model predicts
        (``state.mode_source`` says which)."""
        state = self.state
        if state.mode_recorded:
            return state.recorded_offboard
        return self.gate.in_offboard

    @property
    def flying(self) -> bool:
        """``in_offboard`` and not known to be disarmed (a disarmed vehicle parked in OFFBOARD
        is idle): what most stream rules ask."""
        return self.in_offboard and self.state.armed is not False

    @property
    def offboard_since(self) -> float | None:
        """When ``in_offboard`` last turned true (None while it is false)."""
        state = self.state
        if state.mode_recorded:
            return state.recorded_offboard_since
        return self.gate.offboard_since

    def offboard_selected(self) -> bool:
        """OFFBOARD is the selected mode (what makes an arm an offboard request): as recorded,
        else as the gate model has the user's intention."""
        if self.state.mode_recorded:
            return self.state.nav_state == NAV_STATE_OFFBOARD
        return self.gate.user_intention == NAV_STATE_OFFBOARD

    def has(self, *kinds: str) -> bool:
        """Does the recording carry any of these event kinds at all?"""
        return any(kind in self.info.kinds for kind in kinds)


STREAM_TYPES: frozenset[type[Event]] = frozenset((*KEEPALIVE_TYPES, *PX4_SETPOINTS))
"""The high-rate messages the engine may group into runs: keep-alives and setpoints."""

assert not any(a is not b and issubclass(a, b) for a in STREAM_TYPES for b in STREAM_TYPES)

_ROS_KEEPALIVES: frozenset[type[Event]] = frozenset(KEEPALIVE_ROS)
_MAVLINK_KEEPALIVES: frozenset[type[Event]] = frozenset(MAVLINK_SETPOINTS)
_TARGET_SYSTEM = attrgetter("target_system")

_HELD: dict[
    tuple[frozenset[type[Event]], tuple[type[Event], ...]], frozenset[type[Event]] | bool
] = {}
"""(classes of a run, types asked) -> True (all of the run), False (none), or the classes
wanted: ``StreamBatch.of``'s answer for a run's classes, worked out once per process (a few
dozen pairs occur; the ten-minute real ULog asks 35k times, mostly of one- and two-message
runs)."""


def _held(
    present: frozenset[type[Event]], types: tuple[type[Event], ...]
) -> frozenset[type[Event]] | bool:
    key = (present, types)
    held = _HELD.get(key)
    if held is None:
        wanted = frozenset(cls for cls in present if issubclass(cls, types))
        held = True if len(wanted) == len(present) else (wanted if wanted else False)
        _HELD[key] = held
    return held


class StreamBatch:
    """A run of consecutive stream messages of one vehicle, in time order.

    Within a run nothing changes what a check reads: no other event of the vehicle, no gate
    transition and no change of the declared control mode (first true OCM flag) falls inside
    it; only the messages themselves do (which one is the latest keep-alive or setpoint).
    ``state`` and ``gate`` are a copy of the shared state and a snapshot of the gate model as
    every message of the run saw them: the engine may close a run only after its next message
    has moved the live ones on (a gate transition it caused). While a check's ``on_batch``
    runs, the engine points ``ctx.state`` and ``ctx.gate`` at these copies, so code shared
    with ``on_event`` (``ctx.in_offboard``, ``ctx.flying``) reads the right values.

    ``on_batch`` must report exactly what ``on_event`` would for the same messages one at a
    time; ``Check.replay`` (the default ``on_batch``) does that, and a check's own fast path
    proves the common case
    (nothing to report, only counters and times move) and replays the rest.
    ``tests/test_batching.py`` and the ``runs`` fuzz property compare the two.
    """

    __slots__ = (
        "_classes",
        "_keepalives",
        "_of",
        "events",
        "gate",
        "memo",
        "mode_at_start",
        "state",
    )

    def __init__(self, state: VehicleState, gate: GateView) -> None:
        self.events: list[Event] = []
        self.state = copy.copy(state)
        self.gate = gate.snapshot()
        self.mode_at_start = state.control_mode
        """The declaration the run's first message saw: ``replay`` moves ``state.control_mode``
        through the run's own declarations and puts this back for the next check."""
        self._keepalives: list[Event] | None = None
        self._of: dict[tuple[type[Event], ...], list[Event]] = {}
        self._classes: frozenset[type[Event]] | None = None
        self.memo: dict[object, Any] = {}
        """What several checks derive from the run (e.g. the keep-alive times and gaps), kept
        with the run so that it is worked out once and goes when the run goes. Keyed by the
        function that derives it."""

    def classes(self) -> frozenset[type[Event]]:
        """The classes of the run's messages (exact ``STREAM_TYPES`` classes), worked out once."""
        if self._classes is None:
            self._classes = frozenset(map(type, self.events))
        return self._classes

    def of(self, types: tuple[type[Event], ...]) -> list[Event]:
        """The run's messages that are instances of ``types``, worked out once per run and tuple
        (several checks ask for the same). Found by exact class: a run holds only
        ``STREAM_TYPES`` classes, none a subclass of another, so the classes it holds tell
        at once whether all, none or which of its messages are wanted (an ``isinstance`` test
        per message walks the tuple: ~0.4 µs for the sixteen setpoint types). The list may be
        ``events`` itself: do not change it."""
        found = self._of.get(types)
        if found is None:
            present = self.classes()
            held = _held(present, types)
            if held is True:
                found = self.events
            elif held is False:
                found = []
            else:
                found = [e for e in self.events if type(e) in held]
            self._of[types] = found
        return found

    def keepalives(self) -> list[Event]:
        """The run's messages that count as keep-alive (``VehicleState.keepalive`` rules)."""
        if self._keepalives is None:
            self._keepalives = self._find_keepalives()
        return self._keepalives

    def _find_keepalives(self) -> list[Event]:
        """Decided for the whole run where its classes and targets allow (every OCM counts;
        a MAVLink setpoint counts when addressed to all or to this vehicle), else per message."""
        present = self.classes()
        events = self.events
        if present <= _ROS_KEEPALIVES:
            return events
        own = self.state.own_system
        if present <= _MAVLINK_KEEPALIVES and (
            own is None or set(map(_TARGET_SYSTEM, events)) <= {0, own}
        ):
            return events
        counts = self.state.counts_as_keepalive
        return [e for e in events if counts(e)]


class Check:
    codes: ClassVar[tuple[str, ...]] = ()
    wants: ClassVar[tuple[type[Event], ...]] = ()

    def __init_subclass__(cls, **kwargs: Any) -> None:
        super().__init_subclass__(**kwargs)
        if cls.codes:
            REGISTRY.append(cls)

    def __init__(self, ctx: CheckContext) -> None:
        self.ctx = ctx
        self.subscriptions: tuple[type[Event], ...] = self.wants
        """What the engine sends this instance; a check that finds in ``__init__`` that the
        recording cannot show its rule sets it to ``()`` and costs nothing per message."""

    @classmethod
    def wanted(cls, ctx: CheckContext) -> bool:
        """Instantiate only if one of its codes is enabled and applies to the profile."""
        return any(ctx.enabled(code) for code in cls.codes)

    def on_event(self, event: Event) -> None:
        """Called for every event whose type is in ``wants``, in time order."""

    def on_batch(self, batch: StreamBatch) -> None:
        """The stream messages of a run (see ``StreamBatch``); ``on_event`` sees only the other
        events it wants. The run holds every stream message; the check picks the ones it wants.
        Here: each one it wants, through ``on_event`` (``replay``). An override must report
        exactly what this would."""
        if batch.of(self.subscriptions):
            self.replay(batch)

    def replay(self, batch: StreamBatch, start: int = 0) -> None:
        """``on_event`` for the run's messages from ``start`` on that this check wants, with
        the per-message parts of the state (``keepalive``, ``control_mode``) set as
        ``VehicleState.update`` sets them: the exact fallback of an ``on_batch``. Several checks
        may replay one run: each finds ``control_mode`` as the run began, and leaves it so."""
        state = self.ctx.state
        wants = self.subscriptions
        counts = state.counts_as_keepalive
        on_event = self.on_event
        events = batch.events
        declarations = (ControlMode, LegacyControlMode)
        state.control_mode = next(
            (e for e in reversed(events[:start]) if isinstance(e, declarations)),
            batch.mode_at_start,
        )
        for i in range(start, len(events)):
            event = events[i]
            if isinstance(event, declarations):
                state.control_mode = event
            if isinstance(event, wants):
                state.keepalive = event if counts(event) else None
                on_event(event)
        state.keepalive = None
        state.control_mode = batch.mode_at_start

    def finish(self, t_end: float) -> None:
        """Called once after the last event (``t_end`` = the recording's last time)."""


Handler = Callable[[Event], None]
