"""What ``OffboardControlMode`` declares, per profile, as the docs state it (rules OFB3xx, OFB8xx).

The first true field of ``OffboardControlMode`` selects a required estimate and the setpoint
messages that may and must be published (seed 000 "The OffboardControlMode PX4 message" for
1.15+, seed 002 "ROS 2 消息" for 1.13-1.14 with its single ``actuator`` field; rover table of
seed 000 "Ровер" from 1.16). The legacy ``ignore_*`` semantics follow seed 003 and
gate.md#control-mode (legacy). Everything version-dependent about the declaration lives here.
"""

from __future__ import annotations

import functools

from fuzzoff.events import FailsafeFlags, LegacyControlMode, SetPositionTargetLocal
from fuzzoff.lean_dataclass import dataclass
from fuzzoff.profiles import Profile
from fuzzoff.type_mask import (
    ACCELERATION_BITS,
    POSITION_BITS,
    VELOCITY_BITS,
    YAW_IGNORE,
    YAW_RATE_IGNORE,
    Z_IGNORE,
)


@dataclass(frozen=True, slots=True)
class FlagRow:
    """One row of the docs' table: what the first true field requires."""

    flag: str
    estimate: str | None
    """Required estimate (``position``, ``velocity``, ``attitude``, ``angular velocity``)."""
    allowed: frozenset[str]
    """Setpoint event kinds this declaration selects (publishing others collides, OFB302)."""
    required: tuple[frozenset[str], ...]
    """Alternatives; the declaration is served when every kind of one alternative is published."""


TRAJECTORY = frozenset({"trajectory"})
THRUST_TORQUE = frozenset({"thrust", "torque"})
ACTUATORS = frozenset({"actuator_motors", "actuator_servos"})

ROVER_SETPOINT_KINDS = frozenset(
    {
        "rover_position",
        "rover_speed",
        "rover_attitude",
        "rover_rate",
        "rover_throttle",
        "rover_steering",
    }
)


def _row(
    flag: str,
    estimate: str | None,
    allowed: frozenset[str],
    *required: frozenset[str],
) -> FlagRow:
    return FlagRow(flag, estimate, allowed, tuple(required) or (allowed,))


_MOTORS_OR_SERVOS = (frozenset({"actuator_motors"}), frozenset({"actuator_servos"}))

# Seed 000 (main / v1.16+ page), also used for 1.15-1.17 (same seven fields).
TABLE_000: dict[str, FlagRow] = {
    "position": _row("position", "position", TRAJECTORY),
    "velocity": _row("velocity", "velocity", TRAJECTORY),
    "acceleration": _row("acceleration", "attitude", TRAJECTORY),
    "attitude": _row("attitude", "attitude", frozenset({"attitude"})),
    "body_rate": _row("body_rate", "angular velocity", frozenset({"rates"})),
    "thrust_and_torque": _row("thrust_and_torque", None, THRUST_TORQUE, THRUST_TORQUE),
    "direct_actuator": _row("direct_actuator", None, ACTUATORS, *_MOTORS_OR_SERVOS),
}

# Seed 002 (v1.13-v1.14 page): acceleration needs a velocity estimate, attitude and body_rate
# need none, and one ``actuator`` field covers thrust/torque and direct motors and servos.
TABLE_002: dict[str, FlagRow] = {
    "position": _row("position", "position", TRAJECTORY),
    "velocity": _row("velocity", "velocity", TRAJECTORY),
    "acceleration": _row("acceleration", "velocity", TRAJECTORY),
    "attitude": _row("attitude", None, frozenset({"attitude"})),
    "body_rate": _row("body_rate", None, frozenset({"rates"})),
    "actuator": _row(
        "actuator", None, THRUST_TORQUE | ACTUATORS, THRUST_TORQUE, *_MOTORS_OR_SERVOS
    ),
}

# The 1.15 docs still asked for a velocity estimate with ``acceleration`` (gate.md#docs-vs-code).
TABLE_115: dict[str, FlagRow] = {
    **TABLE_000,
    "acceleration": _row("acceleration", "velocity", TRAJECTORY),
}

# Seed 000 "Ровер" (1.16+): the control flag of each valid combination selects these rover
# setpoints (published values and the ones published as NaN); the deprecated
# TrajectorySetpoint stays selectable by position, velocity and attitude (OFB501 warns).
ROVER_TABLE: dict[str, FlagRow] = {
    "position": _row(
        "position",
        "position",
        frozenset({"rover_position", "trajectory"}),
        frozenset({"rover_position"}),
        TRAJECTORY,
    ),
    "velocity": _row(
        "velocity",
        "velocity",
        frozenset({"rover_speed", "rover_attitude", "rover_rate", "rover_steering", "trajectory"}),
        frozenset({"rover_speed"}),
        TRAJECTORY,
    ),
    "attitude": _row(
        "attitude",
        "attitude",
        frozenset({"rover_throttle", "rover_attitude", "trajectory"}),
        frozenset({"rover_throttle", "rover_attitude"}),
        TRAJECTORY,
    ),
    "body_rate": _row(
        "body_rate",
        "angular velocity",
        frozenset({"rover_throttle", "rover_rate", "trajectory"}),
        frozenset({"rover_throttle", "rover_rate"}),
        TRAJECTORY,
    ),
    "thrust_and_torque": _row(
        "thrust_and_torque",
        None,
        frozenset({"rover_throttle", "rover_steering"}),
        frozenset({"rover_throttle", "rover_steering"}),
    ),
    "direct_actuator": _row("direct_actuator", None, ACTUATORS, *_MOTORS_OR_SERVOS),
}

ESTIMATE_FIELD: dict[str, str] = {
    "position": "local_position_valid",
    "velocity": "local_velocity_valid",
    "attitude": "attitude_valid",
    "angular velocity": "angular_velocity_valid",
}
"""Required estimate -> the ``FailsafeFlags`` field that says whether it is valid."""

SETPOINT_NAMES: dict[str, str] = {
    "trajectory": "TrajectorySetpoint",
    "attitude": "VehicleAttitudeSetpoint",
    "rates": "VehicleRatesSetpoint",
    "thrust": "VehicleThrustSetpoint",
    "torque": "VehicleTorqueSetpoint",
    "actuator_motors": "ActuatorMotors",
    "actuator_servos": "ActuatorServos",
    "rover_position": "RoverPositionSetpoint",
    "rover_speed": "RoverSpeedSetpoint",
    "rover_attitude": "RoverAttitudeSetpoint",
    "rover_rate": "RoverRateSetpoint",
    "rover_throttle": "RoverThrottleSetpoint",
    "rover_steering": "RoverSteeringSetpoint",
}
"""Event kind -> the px4_msgs message name, for messages."""

SETPOINT_KINDS = frozenset(SETPOINT_NAMES)


@functools.cache
def table_for(profile: Profile) -> dict[str, FlagRow]:
    """The docs' table that applies to this profile (empty before 1.13: no boolean fields)."""
    release = profile.release
    if release.docs_page is None:
        return {}
    if profile.is_rover and release.rover_setpoints:
        return ROVER_TABLE
    if release.docs_page == "002":
        return TABLE_002
    if release.docs_acceleration_needs_velocity:
        return TABLE_115
    return TABLE_000


def row_for(profile: Profile, first_flag: str | None) -> FlagRow | None:
    """The row the first true field selects, or None (no field true, or not in this table)."""
    if first_flag is None:
        return None
    return table_for(profile).get(first_flag)


def estimate_valid(flags: FailsafeFlags, estimate: str) -> bool | None:
    """Whether the recording shows ``estimate`` valid (None: that validity is not recorded)."""
    value: bool | None = getattr(flags, ESTIMATE_FIELD[estimate])
    return value


def describe_required(row: FlagRow) -> str:
    """``TrajectorySetpoint`` / ``VehicleThrustSetpoint and VehicleTorqueSetpoint`` / ..."""
    options = [" and ".join(SETPOINT_NAMES[k] for k in sorted(alt)) for alt in row.required]
    return " or ".join(options)


# ---------------------------------------------------------------------------------------------
# Legacy (v1.5-v1.11) ``ignore_*`` semantics: seed 003, gate.md#control-mode (legacy)


@dataclass(frozen=True, slots=True)
class LegacyControllers:
    """The controllers a legacy ``offboard_control_mode`` enables (not in a VTOL transition)."""

    position: bool
    velocity: bool
    acceleration: bool
    attitude: bool
    rates: bool


def legacy_controllers(mode: LegacyControlMode) -> LegacyControllers:
    """Enabling acceleration/force disables position and velocity control (seed 003)."""
    pos = not mode.ignore_position
    vel = not mode.ignore_velocity
    acc = not mode.ignore_acceleration_force
    return LegacyControllers(
        position=pos and not acc,
        velocity=(vel or pos) and not acc,
        acceleration=acc,
        attitude=not mode.ignore_attitude or pos or vel or acc,
        rates=not mode.ignore_bodyrate or not mode.ignore_attitude or pos or vel or acc,
    )


def legacy_disabled_by_acceleration(mode: LegacyControlMode) -> tuple[str, ...]:
    """The controls the message asks for (not ignored) that acceleration/force disables."""
    if mode.ignore_acceleration_force:
        return ()
    wanted = []
    if not mode.ignore_position:
        wanted.append("position")
    if not mode.ignore_velocity:
        wanted.append("velocity")
    return tuple(wanted)


def legacy_mode_from_mask(sp: SetPositionTargetLocal) -> LegacyControlMode:
    """The ``offboard_control_mode`` a legacy receiver publishes for this message
    (gate.md#receiver): a group is ignored when ANY of its ignore bits is set."""
    mask = sp.type_mask
    return LegacyControlMode(
        t=sp.t,
        vehicle=sp.vehicle,
        where=sp.where,
        origin="model",
        ignore_position=bool(mask & POSITION_BITS),
        ignore_alt_hold=bool(mask & Z_IGNORE),
        ignore_velocity=bool(mask & VELOCITY_BITS),
        ignore_acceleration_force=bool(mask & ACCELERATION_BITS),
        ignore_attitude=bool(mask & YAW_IGNORE),
        ignore_bodyrate=bool(mask & YAW_RATE_IGNORE),
    )
