"""What the stream rules share: which events are keep-alive, what a gap proves, PX4's timeout."""

from __future__ import annotations

import math
from operator import attrgetter, sub

from fuzzoff.checks.base import CheckContext, StreamBatch
from fuzzoff.events import (
    KEEPALIVE_TYPES,
    ControlMode,
    Dropout,
    Event,
    VehicleStatus,
)
from fuzzoff.lean_dataclass import dataclass

KEEPALIVE_EVENTS: tuple[type[Event], ...] = (*KEEPALIVE_TYPES, Dropout)
"""What a stream rule subscribes to: the keep-alive kinds, and logger dropouts (ULog)."""


_TIME = attrgetter("t")


@dataclass(frozen=True, slots=True)
class KeepaliveRun:
    """A run's keep-alive messages with their times and the gaps between them, worked out once
    per run for every stream rule (``keepalive_run``); each rule adds the gap from its own
    ``last``. The gaps are ``later.t - earlier.t``, the very subtraction ``on_event`` makes."""

    events: list[Event]
    times: list[float]
    gaps: list[float]
    """The gaps between consecutive keep-alives of the run, smallest first (one fewer than
    ``times``): sorting is cheaper than ``min`` and ``max`` and gives both."""

    @property
    def widest(self) -> float:
        """The largest gap, -inf for none."""
        return self.gaps[-1] if self.gaps else -math.inf

    @property
    def narrowest(self) -> float:
        """The smallest gap, +inf for none."""
        return self.gaps[0] if self.gaps else math.inf

    def worst_gap(self, last: float | None) -> float:
        """The longest interval between consecutive keep-alives of the run and from ``last``
        (when given) to the first; 0 for fewer than two times."""
        widest = self.widest
        if last is not None:
            first = self.times[0] - last
            return first if first > widest else widest
        return 0.0 if widest == -math.inf else widest


def keepalive_run(batch: StreamBatch) -> KeepaliveRun:
    """The run's ``KeepaliveRun`` (non-empty runs only: callers test ``batch.keepalives()``),
    worked out once per run (``StreamBatch.memo``)."""
    found: KeepaliveRun | None = batch.memo.get(keepalive_run)
    if found is None:
        events = batch.keepalives()
        times = list(map(_TIME, events))
        gaps = sorted(map(sub, times[1:], times))
        found = batch.memo[keepalive_run] = KeepaliveRun(events, times, gaps)
    return found


_OTHER_KEEPALIVES = frozenset(KEEPALIVE_TYPES) - {ControlMode}
_OCM: tuple[type[Event], ...] = (ControlMode,)


def control_modes(batch: StreamBatch) -> list[Event]:
    """The run's OffboardControlMode messages, ``batch.of((ControlMode,))``: the run's
    keep-alives themselves when no other keep-alive kind is in the run (ROS 2; every OCM
    counts, ``VehicleState.counts_as_keepalive``), so the ``keepalive_run`` figures are
    theirs too. Do not change the list."""
    present = batch.classes()
    if ControlMode in present and present.isdisjoint(_OTHER_KEEPALIVES):
        return batch.keepalives()
    return batch.of(_OCM)


def logging_interval(ctx: CheckContext, event: Event) -> float:
    """The logger's interval for this kind in a subsampled recording (ULog), else 0."""
    return ctx.info.sampled_intervals.get(event.kind, 0.0)


TIME_EPSILON_S = 1e-6
"""Recording clocks are integers (µs, ns); differences of their float seconds are not exact."""

PROOF_SLACK_S = 2 * TIME_EPSILON_S
"""``gap + PROOF_SLACK_S < limit`` (with ``limit > PROOF_SLACK_S``) proves that
``proven_gap(ctx, event, gap) < limit`` whatever the logging interval (it only lowers the
gap), float rounding included: the stream rules test it first and skip ``proven_gap`` for the
usual short gap between two keep-alive messages (about 0.25 µs a call, two calls a message)."""


def proven_gap(ctx: CheckContext, event: Event, gap: float) -> float:
    """The gap the recording proves: in a subsampled log a logged gap may hide one interval."""
    return max(0.0, gap - logging_interval(ctx, event)) + TIME_EPSILON_S


def loss_timeout(ctx: CheckContext) -> float:
    """The gap after which the profile's PX4 declares the offboard signal lost (gate.md#signal):
    the gate model's own value (legacy's fixed 500 ms, else the effective COM_OF_LOSS_T)."""
    return ctx.gate.loss_timeout


def as_received(ctx: CheckContext) -> bool:
    """Is the recording's keep-alive what PX4 accepted, not what was sent? A ULog holds PX4's
    own ``offboard_control_mode``: a setpoint its receiver dropped (a coordinate_frame or a
    type_mask it does not take, another target) or a message it ignores never reaches it."""
    return ctx.info.format == "ulog"


RECEIVED_NOTE = (
    "this log holds the keep-alive PX4 accepted (offboard_control_mode): setpoints its receiver "
    "dropped (a coordinate_frame, type_mask or target it does not take) and messages it ignores "
    "are no keep-alive and leave no trace in it; the companion's side of the link (its tlog, or "
    "the /fmu/in topics) shows what was sent"
)
"""Said where a ULog shows no keep-alive before a request (OFB102) or a gap PX4 acts on
(OFB101)."""


def px4_label(ctx: CheckContext) -> str:
    """``PX4 1.15`` (or ``PX4 legacy``) for "docs: …; PX4 1.15 would: …" messages."""
    return f"PX4 {ctx.profile.px4}"


def mode_note(ctx: CheckContext) -> str:
    """Appended to messages that depend on the mode when the recording has none."""
    return "" if ctx.state.mode_recorded else " (mode predicted by the gate model)"


class RecordedSwitches:
    """Tells a user's switch to OFFBOARD from PX4's automatic return, on the recorded mode alone.

    Where no commands are recorded (MAVROS bags: services are not recorded) the recorded entry
    into OFFBOARD is the request. But PX4 enters OFFBOARD by itself twice:

    * after a loss failsafe it returns when the stream resumes (gate.md#loss, #docs-vs-code): an
      entry
      that follows an exit made while the keep-alive was older than the loss timeout (less the
      10 Hz evaluation slack) is that return;
    * when it disarms after a landing (an auto land, a Return), its mode goes back to the
      user's intention from before, OFFBOARD (SITL 1.16.2 and 1.17.0: AUTO_LAND armed, then
      OFFBOARD disarmed): an entry shown disarmed right after a status that showed the vehicle
      armed is that, with or without a stream. A user's switch cannot disarm the vehicle.
    """

    SLACK_S = 0.15

    def __init__(self, ctx: CheckContext) -> None:
        self.ctx = ctx
        self.was_offboard: bool | None = None
        self.was_armed: bool | None = None
        self.left_by_failsafe = False

    def entered_by_request(self, event: VehicleStatus, last_keepalive: float | None) -> bool:
        """Feed every recorded status; True when it is the user's switch to OFFBOARD."""
        if event.nav_state is None:
            return False
        was, now = self.was_offboard, event.in_offboard
        self.was_offboard = now
        was_armed, self.was_armed = self.was_armed, event.armed
        if was is False and now and was_armed and event.armed is False:
            self.left_by_failsafe = False
            return False  # disarmed after a landing: PX4 went back to the user's intention
        if was and not now:
            age = None if last_keepalive is None else event.t - last_keepalive
            self.left_by_failsafe = age is None or age >= loss_timeout(self.ctx) - self.SLACK_S
            return False
        if was is False and now:
            automatic, self.left_by_failsafe = self.left_by_failsafe, False
            return not automatic and "command" not in self.ctx.info.kinds
        return False
