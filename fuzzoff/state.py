"""What the recording says about one vehicle at the current moment, shared by all checks.

The engine updates it with every event before the checks see that event. "In offboard" follows
rules.md: the recorded mode, except that a mode switch accepted by a command ack takes effect at
that ack (the last ack of a command wins: PX4 1.16/1.17 send two); where the recording has no
mode at all, the gate model's prediction is used and ``mode_source`` says so.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from fuzzoff.events import (
    MAV_CMD_DO_SET_MODE,
    NAV_STATE_OFFBOARD,
    VEHICLE_CMD_SET_NAV_STATE,
    Command,
    CommandAck,
    ControlMode,
    Event,
    FailsafeFlags,
    LegacyControlMode,
    Parameter,
    VehicleStatus,
)

DOUBLE_ACK_WINDOW_S = 0.1
"""A second ack for the same command within this window replaces the first (gate spec 4.3)."""


@dataclass(slots=True)
class _PendingSwitch:
    t: float
    to_offboard: bool
    before: int | None = None
    acked_at: float | None = None


@dataclass(slots=True)
class VehicleState:
    mode_recorded: bool = False
    """The recording carries the vehicle's mode (status topic, HEARTBEAT, MAVROS state)."""
    nav_state: int | None = None
    armed: bool | None = None
    predicted_offboard: bool = False
    """The gate model's verdict, used where the recording has no mode."""
    offboard_since: float | None = None
    params: dict[str, float] = field(default_factory=dict)
    control_mode: ControlMode | LegacyControlMode | None = None
    failsafe_flags: FailsafeFlags | None = None
    declared_flag: str | None = None
    """The first true field of the latest boolean ``OffboardControlMode`` (None: none/empty)."""
    in_offboard: bool = False
    """Recorded mode (acks applied), or the gate's prediction when no mode is recorded; kept as
    a plain attribute because every check asks on every message."""
    _pending: dict[int, _PendingSwitch] = field(default_factory=dict)

    def _now_in_offboard(self) -> bool:
        if self.mode_recorded:
            return self.nav_state == NAV_STATE_OFFBOARD
        return self.predicted_offboard

    @property
    def mode_source(self) -> str:
        return "recorded" if self.mode_recorded else "predicted by the gate model"

    def set_predicted(self, in_offboard: bool, t: float) -> None:
        """The gate model's verdict after an event; it drives ``in_offboard`` when no mode is
        recorded, so ``offboard_since`` follows it then."""
        if self.predicted_offboard == in_offboard:
            return
        self.predicted_offboard = in_offboard
        if not self.mode_recorded:
            self.in_offboard = in_offboard
            self.offboard_since = t if in_offboard else None

    def update(self, event: Event) -> None:
        was = self.in_offboard
        if isinstance(event, VehicleStatus):
            if event.nav_state is not None:
                self.nav_state = event.nav_state
            if event.armed is not None:
                self.armed = event.armed
        elif isinstance(event, ControlMode):
            self.control_mode = event
            self.declared_flag = event.first_flag()
        elif isinstance(event, LegacyControlMode):
            self.control_mode = event
            self.declared_flag = None
        elif isinstance(event, Parameter):
            self.params[event.name] = event.value
        elif isinstance(event, FailsafeFlags):
            self.failsafe_flags = event
        elif isinstance(event, Command) and event.is_mode_switch:
            self._pending[event.command] = _PendingSwitch(event.t, event.is_offboard_switch)
        elif isinstance(event, CommandAck) and event.command in (
            MAV_CMD_DO_SET_MODE,
            VEHICLE_CMD_SET_NAV_STATE,
        ):
            self._ack(event)
        now = self.in_offboard = self._now_in_offboard()
        if now and not was:
            self.offboard_since = event.t
        elif was and not now:
            self.offboard_since = None

    def _ack(self, ack: CommandAck) -> None:
        pending = self._pending.get(ack.command)
        if pending is None:
            return
        second = pending.acked_at is not None and ack.t - pending.acked_at <= DOUBLE_ACK_WINDOW_S
        if second:
            self.nav_state = pending.before  # the last ack decides: undo the first one
        else:
            pending.before = self.nav_state
        pending.acked_at = ack.t
        if ack.accepted and self.mode_recorded:
            if pending.to_offboard:
                self.nav_state = NAV_STATE_OFFBOARD
            elif self.nav_state == NAV_STATE_OFFBOARD:
                self.nav_state = None  # left offboard for a mode the status will name
