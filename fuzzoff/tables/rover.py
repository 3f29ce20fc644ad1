"""The docs' rover tables (seed 000 "Ровер": rover setpoints, actuator setpoints, deprecated
TrajectorySetpoint), looked up by profile. Rules OFB501-OFB506.

The rover setpoint topics exist from PX4 1.16; before that no page documents them, so
``rover_tables`` gives None and the ROS 2 rover rules do not apply.
"""

from __future__ import annotations

import math

from fuzzoff.events import (
    Event,
    RoverAttitudeSetpoint,
    RoverPositionSetpoint,
    RoverRateSetpoint,
    RoverSpeedSetpoint,
    RoverSteeringSetpoint,
    RoverThrottleSetpoint,
)
from fuzzoff.lean_dataclass import dataclass
from fuzzoff.profiles import Profile

POSITION = RoverPositionSetpoint.kind
SPEED = RoverSpeedSetpoint.kind
ATTITUDE = RoverAttitudeSetpoint.kind
RATE = RoverRateSetpoint.kind
THROTTLE = RoverThrottleSetpoint.kind
STEERING = RoverSteeringSetpoint.kind

ROVER_KINDS = (POSITION, SPEED, THROTTLE, ATTITUDE, RATE, STEERING)
"""In the order of the docs' table columns."""

TOPIC_NAMES = {
    POSITION: "RoverPositionSetpoint",
    SPEED: "RoverSpeedSetpoint",
    THROTTLE: "RoverThrottleSetpoint",
    ATTITUDE: "RoverAttitudeSetpoint",
    RATE: "RoverRateSetpoint",
    STEERING: "RoverSteeringSetpoint",
}


@dataclass(frozen=True, slots=True)
class RoverCombination:
    """One row of the docs' table of valid rover setpoint combinations."""

    name: str
    flag: str
    """The one ``OffboardControlMode`` flag to set (all others false)."""
    publish: frozenset[str]
    """Setpoints published with values (the docs' check marks)."""
    nan: frozenset[str] = frozenset()
    """Setpoints that must be published as NaN (the docs' crosses)."""


def _combo(
    name: str, flag: str, publish: set[str], nan: set[str] | None = None
) -> RoverCombination:
    return RoverCombination(name, flag, frozenset(publish), frozenset(nan or ()))


COMBINATIONS_000: tuple[RoverCombination, ...] = (
    _combo("Position", "position", {POSITION}),
    _combo("Speed + Attitude", "velocity", {SPEED, ATTITUDE}),
    _combo("Speed + Rate", "velocity", {SPEED, RATE}, {ATTITUDE}),
    _combo("Speed + Steering", "velocity", {SPEED, STEERING}, {ATTITUDE, RATE}),
    _combo("Throttle + Attitude", "attitude", {THROTTLE, ATTITUDE}),
    _combo("Throttle + Rate", "body_rate", {THROTTLE, RATE}),
    _combo("Throttle + Steering", "thrust_and_torque", {THROTTLE, STEERING}),
)

TRAJECTORY_FIELDS_000: dict[str, str] = {
    "position": "position",
    "velocity": "velocity",
    "attitude": "yaw",
}
"""Deprecated TrajectorySetpoint: control-mode flag -> the one active field."""


@dataclass(frozen=True, slots=True)
class RoverTables:
    combinations: tuple[RoverCombination, ...]
    trajectory_fields: dict[str, str]
    yaw_unsupported: frozenset[str]
    """Vehicle types that do not support the deprecated TrajectorySetpoint yaw."""
    direct_actuator_flag: str = "direct_actuator"


TABLES_000 = RoverTables(
    combinations=COMBINATIONS_000,
    trajectory_fields=TRAJECTORY_FIELDS_000,
    yaw_unsupported=frozenset({"rover-ackermann"}),
)


def rover_tables(profile: Profile) -> RoverTables | None:
    """Seed 000's tables where the rover setpoints exist (1.16+, ``Release.rover_setpoints``)."""
    return TABLES_000 if profile.release.rover_setpoints else None


def has_value(event: Event) -> bool:
    """Does a rover setpoint carry a value (True) or is it published as NaN (False)?"""
    values: tuple[float, ...]
    if isinstance(event, RoverPositionSetpoint):
        values = event.position_ned
    elif isinstance(event, RoverSpeedSetpoint):
        values = (event.speed_body_x, event.speed_body_y)
    elif isinstance(event, RoverAttitudeSetpoint):
        values = (event.yaw_setpoint,)
    elif isinstance(event, RoverRateSetpoint):
        values = (event.yaw_rate_setpoint,)
    elif isinstance(event, RoverThrottleSetpoint):
        values = (event.throttle_body_x, event.throttle_body_y)
    elif isinstance(event, RoverSteeringSetpoint):
        values = (event.normalized_steering_angle, event.normalized_speed_diff)
    else:
        return False
    return any(not math.isnan(v) for v in values)


def match(
    combinations: tuple[RoverCombination, ...], with_value: frozenset[str]
) -> RoverCombination | None:
    """The combination the setpoints published with values form, or None (OFB502).

    Either exactly one row's check marks, or one row's check marks plus some of its crosses:
    setpoints that should have been NaN carry values (that row is still the one meant; OFB504).
    """
    for row in combinations:
        if row.publish == with_value:
            return row
    for row in combinations:
        if row.publish < with_value and with_value - row.publish <= row.nan:
            return row
    return None


def names(kinds: frozenset[str] | set[str]) -> str:
    return ", ".join(TOPIC_NAMES[k] for k in ROVER_KINDS if k in kinds) or "none"
