"""``offboard_control_mode`` flags as a small bit mask (cheap to build once per message).

Bits follow PX4's priority order (gate.md#control-mode): the lowest set bit is the "first true
flag" that selects the controller chain.
"""

from __future__ import annotations

from fuzzoff.events import ControlMode, LegacyControlMode

POSITION = 1
VELOCITY = 2
ACCELERATION = 4
ATTITUDE = 8
BODY_RATE = 16
THRUST_AND_TORQUE = 32
DIRECT_ACTUATOR = 64
ACTUATOR = 128

FLAG_NAMES: dict[int, str] = {
    POSITION: "position",
    VELOCITY: "velocity",
    ACCELERATION: "acceleration",
    ATTITUDE: "attitude",
    BODY_RATE: "body_rate",
    THRUST_AND_TORQUE: "thrust_and_torque",
    DIRECT_ACTUATOR: "direct_actuator",
    ACTUATOR: "actuator",
}

# Priority order of section 7: ``actuator`` (1.13/1.14) sits where ``thrust_and_torque`` is.
PRIORITY: tuple[int, ...] = (
    POSITION,
    VELOCITY,
    ACCELERATION,
    ATTITUDE,
    BODY_RATE,
    THRUST_AND_TORQUE,
    ACTUATOR,
    DIRECT_ACTUATOR,
)


def mask_of(event: ControlMode) -> int:
    """The flag mask of a boolean ``OffboardControlMode``."""
    return (
        (POSITION if event.position else 0)
        | (VELOCITY if event.velocity else 0)
        | (ACCELERATION if event.acceleration else 0)
        | (ATTITUDE if event.attitude else 0)
        | (BODY_RATE if event.body_rate else 0)
        | (THRUST_AND_TORQUE if event.thrust_and_torque else 0)
        | (DIRECT_ACTUATOR if event.direct_actuator else 0)
        | (ACTUATOR if event.actuator else 0)
    )


def legacy_mask(event: LegacyControlMode) -> int:
    """A legacy ``ignore_*`` control mode as the flags it leaves enabled (gate.md#control-mode,
    legacy)."""
    return (
        (0 if event.ignore_position else POSITION)
        | (0 if event.ignore_velocity else VELOCITY)
        | (0 if event.ignore_acceleration_force else ACCELERATION)
        | (0 if event.ignore_attitude else ATTITUDE)
        | (0 if event.ignore_bodyrate else BODY_RATE)
        | (0 if event.ignore_thrust else ACTUATOR)
    )


def first_flag(mask: int) -> int:
    """The first true flag in priority order (0 when none)."""
    for bit in PRIORITY:
        if mask & bit:
            return bit
    return 0


def names(mask: int) -> str:
    """``position+velocity`` style text for messages."""
    out = [FLAG_NAMES[bit] for bit in PRIORITY if mask & bit]
    return "+".join(out) if out else "no flag"
