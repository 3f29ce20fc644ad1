"""The behaviour of px4_ros_com's ``offboard_control`` example (C++ and Python alike).

What the example does, reproduced from its source (px4_ros_com ``src/examples/offboard``):
every 100 ms it publishes an ``OffboardControlMode`` (position only) and a
``TrajectorySetpoint`` (position 0, 0, -5 m NED, yaw -3.14, every other field zero); on its
11th tick, before those two, it publishes ``VehicleCommand`` DO_SET_MODE (param1 1, param2 6:
PX4's OFFBOARD) and then ARM (param1 1), both addressed to system 1, component 1, from
system 1, component 1, ``from_external`` true. Timestamps are the node's clock in µs (ROS time:
the host's system clock). It never stops by itself.

``Plan.stop_after_arm_s`` makes it a hazard: the node stops publishing that long after the arm
(a crashed or stalled node), with PX4 in OFFBOARD in the air. ``Plan.land_after_arm_s``: the
node asks PX4 to land (NAV_LAND) and, as the example's timer never stops, streams on.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Any, Protocol

from fuzzoff.lean_dataclass import dataclass

VEHICLE_CMD_NAV_LAND = 21
VEHICLE_CMD_DO_SET_MODE = 176
VEHICLE_CMD_COMPONENT_ARM_DISARM = 400
PX4_CUSTOM_MAIN_MODE_OFFBOARD = 6.0
TICK_S = 0.1
SETPOINTS_BEFORE_SWITCH = 10


class Sink(Protocol):
    def publish(self, **values: Any) -> None: ...


@dataclass(frozen=True, slots=True)
class Plan:
    position: tuple[float, float, float] = (0.0, 0.0, -5.0)
    yaw: float = -3.14
    stop_after_arm_s: float | None = None
    """The node stops publishing this long after its arm command (None: it never stops)."""
    land_after_arm_s: float | None = None
    """The node sends NAV_LAND this long after its arm command and streams on."""
    setpoints_before_switch: int = SETPOINTS_BEFORE_SWITCH
    arm_from_new_publisher: bool = False
    """The ARM goes out through a VehicleCommand publisher the node creates for it (a node that
    makes its publishers when it needs them): a reader on the same host matches the new writer
    at once, PX4's agent some 100 ms later, and PX4 never gets the ARM."""


DEFAULT_PLAN = Plan()
"""The official example's flight: hover at 5 m, never stop."""


def now_us() -> int:
    """The node's clock (ROS time is the system clock), in µs as px4_msgs timestamps."""
    return time.time_ns() // 1000


class OffboardControl:
    """One node: ``tick()`` is its 100 ms timer callback."""

    def __init__(
        self,
        sinks: dict[str, Sink],
        plan: Plan = DEFAULT_PLAN,
        new_sink: Callable[[str], Sink] | None = None,
    ) -> None:
        """``new_sink(message)``: a new publisher (``Plan.arm_from_new_publisher``)."""
        self.new_sink = new_sink
        self.mode = sinks["OffboardControlMode"]
        self.setpoint = sinks["TrajectorySetpoint"]
        self.command = sinks["VehicleCommand"]
        self.plan = plan
        self.counter = 0
        self.armed_at: float | None = None
        self.stopped = False
        self.landing = False
        self.notes: list[tuple[float, str]] = []

    def tick(self, now: float) -> None:
        """``now``: the monotonic clock, for the plan's stop only."""
        if self.stopped:
            return
        if self._due(self.plan.stop_after_arm_s, now):
            self.stopped = True
            self.notes.append((now, "the node stops publishing"))
            return
        if self._due(self.plan.land_after_arm_s, now) and not self.landing:
            self.landing = True
            self._vehicle_command(VEHICLE_CMD_NAV_LAND)
            self.notes.append((now, "NAV_LAND sent; the stream goes on"))
        switch_at = self.plan.setpoints_before_switch
        if self.counter == switch_at:
            self._vehicle_command(VEHICLE_CMD_DO_SET_MODE, 1.0, PX4_CUSTOM_MAIN_MODE_OFFBOARD)
            sink = self.command
            if self.plan.arm_from_new_publisher and self.new_sink is not None:
                sink = self.new_sink("VehicleCommand")
            self._vehicle_command(VEHICLE_CMD_COMPONENT_ARM_DISARM, 1.0, sink=sink)
            self.armed_at = now
            self.notes.append((now, "DO_SET_MODE offboard and ARM sent"))
        self.mode.publish(
            timestamp=now_us(),
            position=True,
            velocity=False,
            acceleration=False,
            attitude=False,
            body_rate=False,
        )
        self.setpoint.publish(
            timestamp=now_us(), position=list(self.plan.position), yaw=self.plan.yaw
        )
        if self.counter < switch_at + 1:
            self.counter += 1

    def _due(self, after_arm_s: float | None, now: float) -> bool:
        return (
            after_arm_s is not None
            and self.armed_at is not None
            and now - self.armed_at >= after_arm_s
        )

    def _vehicle_command(
        self, command: int, param1: float = 0.0, param2: float = 0.0, sink: Sink | None = None
    ) -> None:
        send_vehicle_command(sink or self.command, command, param1, param2)


def send_vehicle_command(
    sink: Sink, command: int, param1: float = 0.0, param2: float = 0.0
) -> None:
    """A ``VehicleCommand`` as the example sends it: to system 1, from an external component."""
    sink.publish(
        timestamp=now_us(),
        param1=param1,
        param2=param2,
        command=command,
        target_system=1,
        target_component=1,
        source_system=1,
        source_component=1,
        from_external=True,
    )
