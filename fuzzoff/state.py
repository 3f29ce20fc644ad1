"""What the recording says about one vehicle at the current moment, shared by all checks.

The engine updates it with every event before the checks see that event. "In offboard" follows
rules.md: the recorded mode, except that a mode switch accepted by a command ack takes effect at
that ack (the last ack of a command wins: PX4 1.16/1.17 send two). Where the recording has no
mode at all, the checks ask the gate model's prediction instead (``CheckContext.in_offboard``,
``flying`` and ``offboard_since`` choose; ``mode_source`` says which): this state holds only
what the recording says.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import field, fields
from operator import attrgetter

from fuzzoff.events import (
    KEEPALIVE_ROS,
    MAV_CMD_DO_SET_MODE,
    NAV_STATE_OFFBOARD,
    VEHICLE_CMD_SET_NAV_STATE,
    Command,
    CommandAck,
    ControlMode,
    Event,
    FailsafeFlags,
    LegacyControlMode,
    MavlinkTarget,
    Parameter,
    VehicleStatus,
    VtolPhase,
)
from fuzzoff.lean_dataclass import dataclass

STALE_STATUS_S = 0.05
"""A status that still shows the mode an accepted switch left, this soon after its ack, was
sent before the switch took effect (PX4's MAVLink HEARTBEAT can go out between Commander's
ack and its new vehicle_status: 7 ms later on 1.16.2 SITL), not a switch back."""

DOUBLE_ACK_WINDOW_S = 0.1
"""A second ack for the same command within this window replaces a first that was ACCEPTED
(gate.md#acks: PX4 1.16/1.17's receiver acks ACCEPTED, Commander's verdict follows)."""


@dataclass(slots=True)
class _PendingSwitch:
    t: float
    to_offboard: bool
    before: int | None = None
    acked_at: float | None = None
    first_accepted: bool = False


@dataclass(slots=True)
class VehicleState:
    mode_recorded: bool = False
    """The recording carries the vehicle's mode (status topic, HEARTBEAT, MAVROS state)."""
    nav_state: int | None = None
    status_nav_state: int | None = None
    """The nav_state of the newest recorded status, without the acks applied: what PX4 had
    switched to (its own flight tasks write the setpoint topics until that status)."""
    armed: bool | None = None
    vtol_phase: VtolPhase | None = None
    """A VTOL's phase as last recorded (None: not a VTOL, or no phase recorded)."""
    params: dict[str, float] = field(default_factory=dict)
    control_mode: ControlMode | LegacyControlMode | None = None
    failsafe_flags: FailsafeFlags | None = None
    declared_flag: str | None = None
    """The first true field of the latest boolean ``OffboardControlMode`` (None: none/empty)."""
    recorded_offboard: bool = False
    """The recorded mode (acks applied) is OFFBOARD; False where no mode is recorded. Kept as
    a plain attribute because the checks ask on every message."""
    recorded_offboard_since: float | None = None
    """When ``recorded_offboard`` last turned true (None while it is false)."""
    own_system: int | None = None
    """This vehicle's MAVLink system id (None where its name is not one: ROS namespaces)."""
    keepalive: Event | None = None
    """The current event when it counts as this vehicle's keep-alive (the docs' keep-alive: an
    OCM, or a MAVLink setpoint addressed to this vehicle or to all), else None. Set by
    ``update`` once per event so that the stream rules need not each work it out again; compare
    with ``is`` (a gate transition dispatched meanwhile is never the current event)."""
    _pending: dict[int, _PendingSwitch] = field(default_factory=dict)
    _left: tuple[float, int | None] | None = None
    """(ack time, the mode before) of the newest accepted switch that changed ``nav_state``."""

    def __copy__(self) -> VehicleState:
        """The shallow copy ``copy.copy`` makes (the dicts shared), built slot by slot: a run
        of stream messages takes one (``StreamBatch``), and copy's generic path for a slots
        class (``__reduce_ex__``, a state dict, a ``setattr`` per slot) cost ~10 µs of it."""
        new = object.__new__(VehicleState)
        for store, value in zip(_STATE_STORES, _STATE_VALUES(self), strict=True):
            store(new, value)
        return new

    @property
    def mode_source(self) -> str:
        return "recorded" if self.mode_recorded else "predicted by the gate model"

    def update(self, event: Event) -> None:
        updater = _UPDATER_BY_TYPE.get(type(event))
        if updater is None:
            updater = _UPDATER_BY_TYPE[type(event)] = _updater_for(type(event))
        self.keepalive = None
        if updater not in _MODE_UPDATERS:  # nothing the mode depends on moves (every setpoint)
            updater(self, event)
            return
        was = self.recorded_offboard
        updater(self, event)
        now = self.recorded_offboard = self.mode_recorded and self.nav_state == NAV_STATE_OFFBOARD
        if now and not was:
            self.recorded_offboard_since = event.t
        elif was and not now:
            self.recorded_offboard_since = None

    def counts_as_keepalive(self, event: Event) -> bool:
        """What ``update`` puts in ``keepalive`` for this event (runs of messages use it)."""
        if isinstance(event, MavlinkTarget):
            target = event.target_system
            return target == 0 or self.own_system is None or target == self.own_system
        return isinstance(event, (ControlMode, LegacyControlMode))

    def _status(self, event: Event) -> None:
        assert isinstance(event, VehicleStatus)
        left = self._left
        if left is not None and (event.t - left[0] > STALE_STATUS_S or event.nav_state != left[1]):
            self._left = left = None
        if event.nav_state is not None and left is None:
            self.nav_state = self.status_nav_state = event.nav_state
        if event.armed is not None:
            self.armed = event.armed
        if event.vtol_phase is not None:
            self.vtol_phase = event.vtol_phase

    def _control_mode(self, event: Event) -> None:
        assert isinstance(event, ControlMode)
        self.keepalive = event
        self.control_mode = event
        self.declared_flag = event.first_flag()

    def _legacy_control_mode(self, event: Event) -> None:
        assert isinstance(event, LegacyControlMode)
        self.keepalive = event
        self.control_mode = event
        self.declared_flag = None

    def _mavlink_setpoint(self, event: Event) -> None:
        assert isinstance(event, MavlinkTarget)
        target = event.target_system
        if target == 0 or self.own_system is None or target == self.own_system:
            self.keepalive = event

    def _parameter(self, event: Event) -> None:
        assert isinstance(event, Parameter)
        if math.isfinite(event.value):  # PX4 parameters are numbers; see GateModel too
            self.params[event.name] = event.value

    def _failsafe_flags(self, event: Event) -> None:
        assert isinstance(event, FailsafeFlags)
        self.failsafe_flags = event

    def _command(self, event: Event) -> None:
        assert isinstance(event, Command)
        if event.is_mode_switch:
            self._pending[event.command] = _PendingSwitch(event.t, event.is_offboard_switch)

    def _command_ack(self, event: Event) -> None:
        assert isinstance(event, CommandAck)
        if event.command in (MAV_CMD_DO_SET_MODE, VEHICLE_CMD_SET_NAV_STATE):
            self._ack(event)

    def _other(self, event: Event) -> None:
        """Setpoints, status texts...: nothing the shared state keeps."""

    def _ack(self, ack: CommandAck) -> None:
        pending = self._pending.get(ack.command)
        if pending is None:
            return
        second = (
            pending.acked_at is not None
            and pending.first_accepted
            and ack.t - pending.acked_at <= DOUBLE_ACK_WINDOW_S
        )
        if second:
            self.nav_state = pending.before  # the last ack decides: undo the first one
        else:
            pending.before = self.nav_state
            pending.first_accepted = ack.accepted  # the receiver's own ack is ACCEPTED
        pending.acked_at = ack.t
        self._left = None
        if ack.accepted and self.mode_recorded:
            before = self.nav_state
            if pending.to_offboard:
                self.nav_state = NAV_STATE_OFFBOARD
            elif self.nav_state == NAV_STATE_OFFBOARD:
                self.nav_state = None  # left offboard for a mode the status will name
            if self.nav_state != before:
                self._left = (ack.t, pending.before)


_UPDATERS: tuple[tuple[type, Callable[[VehicleState, Event], None]], ...] = (
    (VehicleStatus, VehicleState._status),
    (ControlMode, VehicleState._control_mode),
    (LegacyControlMode, VehicleState._legacy_control_mode),
    (Parameter, VehicleState._parameter),
    (FailsafeFlags, VehicleState._failsafe_flags),
    (Command, VehicleState._command),
    (CommandAck, VehicleState._command_ack),
    (MavlinkTarget, VehicleState._mavlink_setpoint),
)
"""In the order ``update`` used to test them with ``isinstance``; looked up once per event type
instead of walking the chain on every message (about 0.3 µs a setpoint on a tlog)."""


_MODE_UPDATERS = frozenset((VehicleState._status, VehicleState._command_ack))
"""The only updaters that move ``nav_state`` or ``armed``; after any other,
``recorded_offboard`` and ``recorded_offboard_since`` stay as they were."""


_UPDATER_BY_TYPE: dict[type, Callable[[VehicleState, Event], None]] = {}
"""Event type -> its entry of ``_UPDATERS`` (``_other`` for none), filled as types appear."""


def _updater_for(cls: type) -> Callable[[VehicleState, Event], None]:
    for base, updater in _UPDATERS:
        if issubclass(cls, base):
            return updater
    return VehicleState._other


assert {ControlMode, LegacyControlMode} == set(KEEPALIVE_ROS)  # _UPDATERS marks both keep-alive

_STATE_SLOTS: tuple[str, ...] = tuple(f.name for f in fields(VehicleState))
_STATE_VALUES = attrgetter(*_STATE_SLOTS)
_STATE_STORES: tuple[Callable[[VehicleState, object], None], ...] = tuple(
    getattr(VehicleState, name).__set__ for name in _STATE_SLOTS
)
"""``VehicleState.__copy__``'s slots, read at once and stored through their descriptors."""
assert set(_STATE_SLOTS) == set(VehicleState.__slots__)  # every slot is a field: all copied
