"""Which setpoint messages each first true ``OffboardControlMode`` field declares (seed 000 table).

Each entry is a list of groups: every group must be published, any kind within a group will do
(thrust *and* torque; motors *or* servos). Rovers use the rover setpoints of the 000 "Ровер"
table, or the deprecated ``TrajectorySetpoint``.
"""

from __future__ import annotations

from fuzzoff.profiles import Profile

Groups = tuple[tuple[str, ...], ...]

_VEHICLE: dict[str, Groups] = {
    "position": (("trajectory",),),
    "velocity": (("trajectory",),),
    "acceleration": (("trajectory",),),
    "attitude": (("attitude",),),
    "body_rate": (("rates",),),
    "thrust_and_torque": (("thrust",), ("torque",)),
    "direct_actuator": (("actuator_motors", "actuator_servos"),),
    "actuator": (),
}

_ROVER: dict[str, Groups] = {
    "position": (("rover_position", "trajectory"),),
    "velocity": (("rover_speed", "trajectory"),),
    "attitude": (("rover_attitude", "trajectory"),),
    "body_rate": (("rover_rate", "trajectory"),),
    "thrust_and_torque": (("rover_throttle",), ("rover_steering",)),
    "direct_actuator": (("actuator_motors", "actuator_servos"),),
    "acceleration": (("trajectory",),),
    "actuator": (),
}


def declared_setpoints(first_flag: str, profile: Profile) -> Groups:
    """The setpoint kinds (``Event.kind``) the first true flag declares for this profile."""
    table = _ROVER if profile.is_rover and profile.at_least("1.16") else _VEHICLE
    return table.get(first_flag, ())


MESSAGE_NAMES: dict[str, str] = {
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
"""``Event.kind`` -> the px4_msgs message name users know."""
