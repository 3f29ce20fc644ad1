"""A ROS 2 node driving a PX4 rover offboard with the rover setpoints (PX4 1.16+).

As the px4_ros_com example (``example.py``) but for a rover: every 100 ms it publishes an
``OffboardControlMode`` with the plan's flags and each of the plan's setpoint messages (the rover
setpoints of PX4's docs, "Rover Setpoints", or the deprecated ``TrajectorySetpoint``) with the
plan's values, every other field zero as a C++ message starts; on its 11th tick it sends
DO_SET_MODE (OFFBOARD) and ARM as the example does. ``RoverPlan.stop_after_arm_s``: the node
stops publishing that long after the arm (a stream loss while driving).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import field
from typing import Any

from fuzzoff.lean_dataclass import dataclass
from fuzzoff.sitl.ros2.example import (
    PX4_CUSTOM_MAIN_MODE_OFFBOARD,
    SETPOINTS_BEFORE_SWITCH,
    VEHICLE_CMD_COMPONENT_ARM_DISARM,
    VEHICLE_CMD_DO_SET_MODE,
    Sink,
    now_us,
    send_vehicle_command,
)

NAN = math.nan
FLAGS = ("position", "velocity", "acceleration", "attitude", "body_rate")
"""The ``OffboardControlMode`` flags every release has (1.15+ adds ``thrust_and_torque`` and
``direct_actuator``, set only when the plan names them)."""
ROVER_MESSAGES = (
    "RoverPositionSetpoint",
    "RoverSpeedSetpoint",
    "RoverAttitudeSetpoint",
    "RoverRateSetpoint",
    "RoverThrottleSetpoint",
    "RoverSteeringSetpoint",
)


@dataclass(frozen=True, slots=True)
class RoverPlan:
    flags: tuple[str, ...]
    """The ``OffboardControlMode`` flags set true (every other one false)."""
    setpoints: tuple[tuple[str, Mapping[str, Any]], ...]
    """(message, its fields' values) published each tick after the control mode."""
    stop_after_arm_s: float | None = None
    setpoints_before_switch: int = SETPOINTS_BEFORE_SWITCH
    messages: tuple[str, ...] = field(init=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "messages", tuple(m for m, _ in self.setpoints))


class RoverNode:
    """One rover node: ``tick()`` is its 100 ms timer callback (``example.OffboardControl``'s
    interface: ``armed_at``, ``notes``)."""

    def __init__(self, sinks: Mapping[str, Sink], plan: RoverPlan) -> None:
        self.sinks = sinks
        self.plan = plan
        self.counter = 0
        self.armed_at: float | None = None
        self.stopped = False
        self.notes: list[tuple[float, str]] = []

    def tick(self, now: float) -> None:
        if self.stopped:
            return
        stop = self.plan.stop_after_arm_s
        if stop is not None and self.armed_at is not None and now - self.armed_at >= stop:
            self.stopped = True
            self.notes.append((now, "the node stops publishing"))
            return
        if self.counter == self.plan.setpoints_before_switch:
            self._command(VEHICLE_CMD_DO_SET_MODE, 1.0, PX4_CUSTOM_MAIN_MODE_OFFBOARD)
            self._command(VEHICLE_CMD_COMPONENT_ARM_DISARM, 1.0)
            self.armed_at = now
            self.notes.append((now, "DO_SET_MODE offboard and ARM sent"))
        flags = {f: f in self.plan.flags for f in FLAGS}
        flags.update({f: True for f in self.plan.flags})
        self.sinks["OffboardControlMode"].publish(timestamp=now_us(), **flags)
        for message, values in self.plan.setpoints:
            self.sinks[message].publish(timestamp=now_us(), **values)
        if self.counter <= self.plan.setpoints_before_switch:
            self.counter += 1

    def _command(self, command: int, param1: float = 0.0, param2: float = 0.0) -> None:
        send_vehicle_command(self.sinks["VehicleCommand"], command, param1, param2)


POSITION_10M_NORTH: Mapping[str, Any] = {
    "position_ned": [10.0, 0.0],
    "start_ned": [NAN, NAN],
    "cruising_speed": NAN,
    "arrival_speed": NAN,
    "yaw": NAN,
}
"""10 m north of the start; NaN: PX4's defaults (from the current position, its cruise speed,
stop on arrival, heading along the path)."""
SPEED_1 = {"speed_body_x": 1.0, "speed_body_y": 0.0}
SPEED_ALONE_2 = {"speed_body_x": 2.0, "speed_body_y": 0.0}
STEER_RIGHT = {"normalized_steering_setpoint": 0.3}
THROTTLE_30 = {"throttle_body_x": 0.3, "throttle_body_y": 0.0}
ATTITUDE_EAST = {"yaw_setpoint": math.pi / 2}
ATTITUDE_NAN = {"yaw_setpoint": NAN}
RATE_NAN = {"yaw_rate_setpoint": NAN}
TRAJECTORY_10M_NORTH: Mapping[str, Any] = {
    "position": [10.0, 0.0, 0.0],
    "velocity": [NAN, NAN, NAN],
    "acceleration": [NAN, NAN, NAN],
    "jerk": [NAN, NAN, NAN],
    "yaw": NAN,
    "yawspeed": NAN,
}
