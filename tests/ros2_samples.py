"""Event streams for the ROS 2 tests: one event of every kind a px4_msgs release can carry."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

from fuzzoff import events as ev
from fuzzoff import releases
from fuzzoff.events import Event, event_to_dict
from fuzzoff.formats import open_source
from fuzzoff.recording import Source

NAN = math.nan
RELEASES = ("1.13", "1.14", "1.15", "1.16", "1.17", "main")


def every_kind(release: str, vehicle: str = "") -> list[Event]:
    """One of each event kind the release defines, with distinct non-default values."""
    old = release in ("1.13", "1.14")
    n_motors = 8 if release == "1.13" else 12
    n_servos = 15 if release == "main" else 8
    out: list[Event] = [
        ev.VehicleStatus(
            t=0.0,
            vehicle=vehicle,
            sender_time_us=10,
            nav_state=2,
            mode="POSCTL",
            armed=True,
            user_intention=None if release == "1.13" else 2,
            failsafe=False,
            vehicle_type=1,
            is_vtol=False,
        ),
        ev.ControlMode(
            t=0.1,
            vehicle=vehicle,
            sender_time_us=100_000,
            position=True,
            body_rate=True,
            actuator=old,
            thrust_and_torque=not old,
            direct_actuator=not old,
            layout="actuator" if old else "thrust_and_torque",
        ),
        ev.TrajectorySetpoint(
            t=0.2,
            vehicle=vehicle,
            sender_time_us=200_000,
            position=(1.0, 2.0, -3.0),
            velocity=(0.5, NAN, 0.25),
            acceleration=(NAN, NAN, NAN),
            jerk=(0.0, 0.0, 0.0),
            yaw=0.5,
            yawspeed=NAN,
        ),
        ev.AttitudeSetpoint(
            t=0.3,
            vehicle=vehicle,
            sender_time_us=300_000,
            q_d=(1.0, 0.0, 0.0, 0.0),
            thrust_body=(0.0, 0.0, -0.5),
            yaw_sp_move_rate=0.25,
        ),
        ev.RatesSetpoint(
            t=0.4,
            vehicle=vehicle,
            sender_time_us=400_000,
            roll=0.5,
            pitch=-0.5,
            yaw=0.125,
            thrust_body=(0.0, 0.0, -0.75),
        ),
        ev.ThrustSetpoint(t=0.5, vehicle=vehicle, sender_time_us=500_000, xyz=(0.0, 0.0, -0.5)),
        ev.TorqueSetpoint(t=0.6, vehicle=vehicle, sender_time_us=600_000, xyz=(0.25, 0.0, 0.0)),
        ev.ActuatorMotors(
            t=0.7,
            vehicle=vehicle,
            sender_time_us=700_000,
            control=tuple(0.125 * i for i in range(4)) + (NAN,) * (n_motors - 4),
            reversible_flags=3,
        ),
        ev.ActuatorServos(
            t=0.8,
            vehicle=vehicle,
            sender_time_us=800_000,
            control=tuple(-0.5 for _ in range(n_servos)),
        ),
        ev.Command(
            t=0.9,
            vehicle=vehicle,
            sender_time_us=900_000,
            command=176,
            params=(1.0, 6.0, 0.0, 0.0, 0.0, 0.0, 0.0),
            target_system=1,
            target_component=1,
            source_system=1,
            source_component=1,
            from_external=True,
            transport="ros2",
        ),
        ev.CommandAck(
            t=1.0,
            vehicle=vehicle,
            sender_time_us=1_000_000,
            command=176,
            result=0,
            target_system=1,
            target_component=1,
        ),
        ev.VehicleControlModeStatus(
            t=1.1,
            vehicle=vehicle,
            sender_time_us=1_100_000,
            offboard_enabled=True,
            enabled=frozenset({"offboard", "position", "velocity", "altitude"}),
        ),
    ]
    if release in ("1.16", "1.17", "main"):
        new = release != "1.16"
        out += [
            ev.RoverPositionSetpoint(
                t=1.2,
                vehicle=vehicle,
                sender_time_us=1_200_000,
                position_ned=(3.0, 4.0),
                start_ned=(0.0, 0.0) if new else (NAN, NAN),
                cruising_speed=1.5,
                arrival_speed=0.5 if new else NAN,
                yaw=NAN,
            ),
            ev.RoverAttitudeSetpoint(
                t=1.3, vehicle=vehicle, sender_time_us=1_300_000, yaw_setpoint=1.0
            ),
            ev.RoverRateSetpoint(
                t=1.4, vehicle=vehicle, sender_time_us=1_400_000, yaw_rate_setpoint=0.5
            ),
            ev.RoverThrottleSetpoint(
                t=1.5,
                vehicle=vehicle,
                sender_time_us=1_500_000,
                throttle_body_x=0.5,
                throttle_body_y=0.0,
            ),
            ev.RoverSteeringSetpoint(
                t=1.6,
                vehicle=vehicle,
                sender_time_us=1_600_000,
                normalized_steering_angle=0.25,
                normalized_speed_diff=NAN if new else 0.125,
            ),
        ]
        if new:
            out.append(
                ev.RoverSpeedSetpoint(
                    t=1.7,
                    vehicle=vehicle,
                    sender_time_us=1_700_000,
                    speed_body_x=1.0,
                    speed_body_y=0.0,
                )
            )
    return out


def comparable(event: Event) -> dict[str, Any]:
    """A dict for equality: NaN as a marker, times rounded to the microsecond, no index."""
    data = event_to_dict(event)
    data["where"] = data["where"]["topic"]
    data["t"] = round(data["t"], 6)

    def norm(value: Any) -> Any:
        if isinstance(value, float):
            return "nan" if math.isnan(value) else round(value, 6)
        if isinstance(value, list):
            return [norm(v) for v in value]
        return value

    return {k: norm(v) for k, v in data.items()}


def read_all(path: Path, px4: str | None = None) -> tuple[Source, list[Event]]:
    """Open, probe and read a recording the way the engine does."""
    source = open_source(path)
    if px4 is not None:
        source.px4_hint = releases.named(px4)  # as the engine sets it from --px4
    source.open()
    source.probe()
    events = list(source.events())
    source.close()
    return source, events
