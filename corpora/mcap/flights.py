"""PX4 ROS 2 offboard flights as events, shared by the MCAP and rosbag2 corpus builders.

A flight: armed in POSCTL, ``OffboardControlMode`` (position) at 20 Hz from t = 0,
``VehicleCommand`` DO_SET_MODE offboard at ``switch_at`` and its ack 10 ms later,
``TrajectorySetpoint`` at 20 Hz while in offboard, NAV_LAND at ``land_at``; ``VehicleStatus`` at
2 Hz and on every change, as PX4's uXRCE-DDS bridge publishes it.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field

from fuzzoff.events import (
    Command,
    CommandAck,
    ControlMode,
    Event,
    TrajectorySetpoint,
    VehicleStatus,
)

POSCTL, OFFBOARD, AUTO_LAND = 2, 14, 18
DO_SET_MODE, NAV_LAND = 176, 21
ROTARY_WING = 1
PERIOD = 0.05


@dataclass
class Flight:
    vehicle: str = ""
    switch_at: float = 2.0
    land_at: float = 12.0
    end: float = 14.0
    ack_result: int = 0
    gaps: list[tuple[float, float]] = field(default_factory=list)
    """(from, to): the program stalls, no OffboardControlMode nor setpoint in between."""
    ocm_gaps: list[tuple[float, float]] = field(default_factory=list)
    """(from, to): only OffboardControlMode pauses; the setpoints go on."""
    lost_mode_at: float | None = None
    """Where PX4's failsafe took the vehicle out of offboard (POSCTL) after a loss."""
    resume_mode_at: float | None = None
    """Back in offboard (the stream came back and the program switched again)."""

    def mode_at(self, t: float) -> int:
        if self.ack_result != 0 or t < self.switch_at + 0.02:
            return POSCTL
        if t >= self.land_at + 0.02:
            return AUTO_LAND
        lost = self.lost_mode_at is not None and self.lost_mode_at <= t
        if lost and (self.resume_mode_at is None or t < self.resume_mode_at):
            return POSCTL
        return OFFBOARD

    def in_gap(self, t: float) -> bool:
        return any(a <= t < b for a, b in self.gaps)

    def events(self) -> list[Event]:
        ns = self.vehicle
        out: list[Event] = []
        k = 0
        while (t := round(k * PERIOD, 6)) < self.end:
            k += 1
            if self.in_gap(t):
                continue
            stamp = round(t * 1e6) + 5_000_000
            if not any(a <= t < b for a, b in self.ocm_gaps):
                out.append(ControlMode(t=t, vehicle=ns, sender_time_us=stamp, position=True))
            if self.mode_at(t) == OFFBOARD:
                out.append(
                    TrajectorySetpoint(
                        t=round(t + 0.002, 6),
                        vehicle=ns,
                        sender_time_us=stamp + 2000,
                        position=(0.0, 0.0, -2.0 - 0.01 * k),
                        yaw=0.0,
                    )
                )
        out += self._command(self.switch_at, DO_SET_MODE, (1.0, 6.0), self.ack_result)
        out += self._command(self.land_at, NAV_LAND, (0.0, 0.0), 0)
        out += self._status()
        return sorted(out, key=lambda e: e.t)

    def _command(
        self, t: float, command: int, params: tuple[float, float], result: int
    ) -> list[Event]:
        ns = self.vehicle
        return [
            Command(
                t=t,
                vehicle=ns,
                sender_time_us=round(t * 1e6) + 5_000_000,
                command=command,
                params=(*params, 0.0, 0.0, 0.0, 0.0, 0.0),
                target_system=1,
                target_component=1,
                source_system=1,
                source_component=1,
                from_external=True,
                transport="ros2",
            ),
            CommandAck(
                t=round(t + 0.01, 6),
                vehicle=ns,
                sender_time_us=round(t * 1e6) + 5_010_000,
                command=command,
                result=result,
                target_system=1,
                target_component=1,
            ),
        ]

    def _status(self) -> list[Event]:
        times = {round(i * 0.5, 6) for i in range(int(self.end / 0.5) + 1)}
        changes: Iterable[float | None] = (
            self.switch_at + 0.02,
            self.land_at + 0.02,
            self.lost_mode_at,
            self.resume_mode_at,
        )
        times |= {round(c, 6) for c in changes if c is not None and c < self.end}
        out: list[Event] = []
        for t in sorted(times):
            nav = self.mode_at(t)
            out.append(
                VehicleStatus(
                    t=t,
                    vehicle=self.vehicle,
                    sender_time_us=round(t * 1e6) + 5_000_000,
                    nav_state=nav,
                    armed=True,
                    user_intention=nav,
                    failsafe=False,
                    vehicle_type=ROTARY_WING,
                    is_vtol=False,
                )
            )
        return out
