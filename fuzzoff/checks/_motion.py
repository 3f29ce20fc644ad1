"""What a setpoint makes the vehicle do while it is held unchanged (OFB107).

A held position, a zero velocity or a hover keeps the vehicle where it is: that is what a stopped
controller should leave behind, and a library that re-sends it is harmless. A command that moves
the vehicle is not: re-sent after the controller behind it died, it flies the vehicle on.
``held_motion`` tells the two apart and names the motion:

* ``STRAIGHT``: the longer it is held, the further the vehicle goes (or the more it tilts,
  tumbles or climbs): a non-zero velocity or acceleration in the local frame, a tilt, a roll or
  pitch rate or torque, a thrust away from hover, a rover speed or throttle;
* ``TURNING``: the motion stays bounded: a body-frame velocity with a yaw rate (a circle: PX4
  turns the body velocity with the heading), a yaw rate alone (a turn on the spot), a banked
  fixed-wing (an orbit), a rover's speed or throttle held under a steering or yaw-rate setpoint
  that turns it (``rover_turns``: on another topic, so the check pairs them; an Ackermann rover
  on 0.3 throttle and 0.3 steering drove a 5 m circle on PX4 1.17.0 and 1.18).

Direct actuator outputs cannot be judged without the vehicle's mixer: never a motion here.
"""

from __future__ import annotations

import math
from typing import Literal

from fuzzoff import type_mask as tmask
from fuzzoff.events import (
    AttitudeSetpoint,
    Event,
    RatesSetpoint,
    RoverRateSetpoint,
    RoverSpeedSetpoint,
    RoverSteeringSetpoint,
    RoverThrottleSetpoint,
    SetAttitudeTarget,
    SetPositionTargetGlobal,
    SetPositionTargetLocal,
    ThrustSetpoint,
    TorqueSetpoint,
    TrajectorySetpoint,
)
from fuzzoff.lean_dataclass import dataclass
from fuzzoff.mavlink_ids import MAV_FRAME_BODY_NED, MAV_FRAME_LOCAL_NED
from fuzzoff.tables import mavlink as tm

MotionKind = Literal["straight", "turning"]

SPEED_EPS = 0.01
"""m/s (or m/s², normalised thrust or torque, rover speed or throttle) under which a command
counts as zero: a controller's "stop" is 0.0, or float noise around it."""
RATE_EPS = math.radians(0.5)
"""rad/s under which a rate counts as zero."""
TILT_RAD = math.radians(2.0)
"""A commanded attitude tilted less than this from level counts as level (a hover)."""


@dataclass(frozen=True, slots=True)
class Motion:
    kind: MotionKind
    what: str
    """The command, in the words of the finding (``velocity 2.00 m/s``)."""


@dataclass(frozen=True, slots=True)
class Hover:
    """The thrust band that counts as a hover (multicopter and VTOL)."""

    thrust: float = 0.5
    band: float = 0.2

    def away(self, thrust: float) -> bool:
        return math.isfinite(thrust) and abs(abs(thrust) - self.thrust) > self.band


def _nonzero(value: float, eps: float = SPEED_EPS) -> bool:
    return math.isfinite(value) and abs(value) > eps


def _norm(values: tuple[float, ...] | list[float]) -> float:
    return math.sqrt(sum(v * v for v in values))


Used = tuple[tuple[bool, bool, bool], tuple[bool, bool, bool], tuple[bool, bool, bool]]
"""Per group (position, velocity, acceleration), per axis: is the component used?"""

ALL_USED: Used = ((True, True, True), (True, True, True), (True, True, True))


def _used(mask: int) -> Used:
    """What a SET_POSITION_TARGET_* type_mask uses (a component is used when its bit is clear)."""

    def group(g: int) -> tuple[bool, bool, bool]:
        return (not mask & (1 << 3 * g), not mask & (2 << 3 * g), not mask & (4 << 3 * g))

    return group(0), group(1), group(2)


def _axes(
    position: tuple[float, ...],
    velocity: tuple[float, ...],
    acceleration: tuple[float, ...],
    used: Used = ALL_USED,
) -> Motion | None:
    """Per axis as PX4's position controller runs it: a finite position holds the axis; else a
    finite velocity moves it when non-zero; else a finite acceleration does. ``used`` masks
    the position, velocity and acceleration components a MAVLink type_mask ignores."""
    vel: list[float] = []
    acc: list[float] = []
    for i in range(3):
        if used[0][i] and math.isfinite(position[i]):
            continue
        if used[1][i] and math.isfinite(velocity[i]):
            if _nonzero(velocity[i]):
                vel.append(velocity[i])
            continue
        if used[2][i] and _nonzero(acceleration[i]):
            acc.append(acceleration[i])
    if vel:
        return Motion("straight", f"velocity {_norm(vel):.2f} m/s")
    if acc:
        return Motion("straight", f"acceleration {_norm(acc):.2f} m/s²")
    return None


def _turn(yaw_rate: float) -> Motion | None:
    if _nonzero(yaw_rate, RATE_EPS):
        return Motion("turning", f"yaw rate {math.degrees(yaw_rate):.1f} deg/s")
    return None


def _tilt(q: tuple[float, float, float, float]) -> tuple[float, float]:
    """(tilt from level, roll) in radians of a (w, x, y, z) quaternion; NaN for NaN."""
    n = _norm(q)
    if not math.isfinite(n) or n == 0.0:
        return math.nan, math.nan
    w, x, y, z = (c / n for c in q)
    cos_tilt = max(-1.0, min(1.0, 1.0 - 2.0 * (x * x + y * y)))
    roll = math.atan2(2 * (w * x + y * z), 1 - 2 * (x * x + y * y))
    return math.acos(cos_tilt), roll


def _attitude(
    q: tuple[float, float, float, float], thrust: float, vehicle: str, hover: Hover
) -> Motion | None:
    tilt, roll = _tilt(q)
    if vehicle == "fw":
        if math.isfinite(tilt) and tilt > TILT_RAD and abs(abs(roll) - tilt) <= TILT_RAD:
            return Motion("turning", f"bank {math.degrees(abs(roll)):.0f} deg")
        return Motion("straight", "an attitude and throttle (a fixed-wing flies on)")
    if math.isfinite(tilt) and tilt > TILT_RAD:
        return Motion("straight", f"tilt {math.degrees(tilt):.0f} deg")
    if hover.away(thrust):
        return Motion("straight", f"thrust {abs(thrust):.2f}, away from hover {hover.thrust:g}")
    return None


def _rates(
    roll: float, pitch: float, yaw: float, thrust: float, vehicle: str, hover: Hover
) -> Motion | None:
    if _nonzero(roll, RATE_EPS) or _nonzero(pitch, RATE_EPS):
        rate = math.degrees(_norm([r for r in (roll, pitch) if math.isfinite(r)]))
        return Motion("straight", f"roll and pitch rate {rate:.1f} deg/s")
    if vehicle == "fw":
        return Motion("straight", "body rates and throttle (a fixed-wing flies on)")
    if hover.away(thrust):
        return Motion("straight", f"thrust {abs(thrust):.2f}, away from hover {hover.thrust:g}")
    return _turn(yaw)


def _local(event: SetPositionTargetLocal) -> Motion | None:
    mask = event.type_mask
    if mask & tmask.FORCE_SET:
        return None  # PX4 drops force setpoints (OFB602)
    yaw_rate = event.yaw_rate if not mask & tmask.YAW_RATE_IGNORE else math.nan
    if event.coordinate_frame == MAV_FRAME_BODY_NED:
        kept = tm.body_ned_groups(mask)
        if "velocity" in kept and _nonzero(event.velocity[2]):
            return Motion("straight", f"vertical velocity {abs(event.velocity[2]):.2f} m/s")
        if "velocity" in kept and _norm(event.velocity[:2]) > SPEED_EPS:
            speed = f"body velocity {_norm(event.velocity[:2]):.2f} m/s"
            if _nonzero(yaw_rate, RATE_EPS):
                turn = f"{speed} with yaw rate {math.degrees(yaw_rate):.0f} deg/s"
                return Motion("turning", turn)
            return Motion("straight", speed)
        if "acceleration" in kept and _norm(event.acceleration) > SPEED_EPS:
            return Motion("straight", f"body acceleration {_norm(event.acceleration):.2f} m/s²")
        return _turn(yaw_rate)
    if event.coordinate_frame != MAV_FRAME_LOCAL_NED:
        return None  # dropped by PX4's receiver (OFB601)
    motion = _axes(event.position, event.velocity, event.acceleration, _used(mask))
    return motion or _turn(yaw_rate)


def _global(event: SetPositionTargetGlobal) -> Motion | None:
    mask = event.type_mask
    if mask & tmask.FORCE_SET:
        return None
    held = (0.0, 0.0, event.alt)  # lat/lon/alt as a position: finite whenever used
    motion = _axes(held, event.velocity, event.acceleration, _used(mask))
    yaw_rate = event.yaw_rate if not mask & tmask.YAW_RATE_IGNORE else math.nan
    return motion or _turn(yaw_rate)


def _attitude_target(event: SetAttitudeTarget, vehicle: str, hover: Hover) -> Motion | None:
    mask = event.type_mask
    if mask & tmask.THRUST_BODY_SET and event.thrust_body is not None:
        thrust = event.thrust_body[0] if vehicle == "fw" else event.thrust_body[2]
    elif not mask & tmask.THROTTLE_IGNORE:
        thrust = event.thrust
    else:
        thrust = math.nan
    if tm.attitude_used(mask):
        return _attitude(event.q, thrust, vehicle, hover)
    roll = event.body_roll_rate if not mask & tmask.ROLL_RATE_IGNORE else math.nan
    pitch = event.body_pitch_rate if not mask & tmask.PITCH_RATE_IGNORE else math.nan
    yaw = event.body_yaw_rate if not mask & tmask.BODY_YAW_RATE_IGNORE else math.nan
    return _rates(roll, pitch, yaw, thrust, vehicle, hover)


def held_motion(event: Event, vehicle: str, hover: Hover) -> Motion | None:
    """The motion ``event`` commands while it is held, or None for a hold (or a command this
    module cannot judge). ``vehicle`` is the profile's vehicle type."""
    if isinstance(event, TrajectorySetpoint):
        motion = _axes(event.position, event.velocity, event.acceleration)
        if motion is None and not math.isfinite(event.yaw):
            motion = _turn(event.yawspeed)
        return motion
    if isinstance(event, SetPositionTargetLocal):
        return _local(event)
    if isinstance(event, SetPositionTargetGlobal):
        return _global(event)
    if isinstance(event, SetAttitudeTarget):
        return _attitude_target(event, vehicle, hover)
    if isinstance(event, AttitudeSetpoint):
        thrust = event.thrust_body[0] if vehicle == "fw" else event.thrust_body[2]
        return _attitude(event.q_d, thrust, vehicle, hover)
    if isinstance(event, RatesSetpoint):
        return _rates(event.roll, event.pitch, event.yaw, event.thrust_body[2], vehicle, hover)
    if isinstance(event, ThrustSetpoint):
        if vehicle == "fw":
            if _nonzero(event.xyz[0]):
                return Motion("straight", f"thrust {event.xyz[0]:.2f}")
            return None
        if hover.away(event.xyz[2]):
            return Motion("straight", f"thrust {abs(event.xyz[2]):.2f}, away from hover")
        return None
    if isinstance(event, TorqueSetpoint):
        if _norm(event.xyz[:2]) > SPEED_EPS:
            return Motion("straight", f"roll and pitch torque {_norm(event.xyz[:2]):.2f}")
        if _nonzero(event.xyz[2]):
            return Motion("turning", f"yaw torque {event.xyz[2]:.2f}")
        return None
    if isinstance(event, RoverSpeedSetpoint):
        speed = _norm([v for v in (event.speed_body_x, event.speed_body_y) if math.isfinite(v)])
        return Motion("straight", f"rover speed {speed:.2f} m/s") if speed > SPEED_EPS else None
    if isinstance(event, RoverThrottleSetpoint):
        values = [v for v in (event.throttle_body_x, event.throttle_body_y) if math.isfinite(v)]
        throttle = _norm(values)
        if throttle > SPEED_EPS:
            return Motion("straight", f"rover throttle {throttle:.2f}")
        return None
    if isinstance(event, RoverRateSetpoint):
        return _turn(event.yaw_rate_setpoint)
    return None


ROVER_TURNS = ("rover_steering", "rover_rate")
"""The rover setpoints that turn a rover driven by a held speed or throttle."""


def rover_turns(event: Event) -> bool:
    """Does this rover steering or yaw-rate setpoint turn the rover (a value, not zero)?
    A speed or throttle held under it drives a circle: a bounded motion."""
    if isinstance(event, RoverSteeringSetpoint):
        values = (event.normalized_steering_angle, event.normalized_speed_diff)
        return any(math.isfinite(v) and _nonzero(v) for v in values)
    if isinstance(event, RoverRateSetpoint):
        return math.isfinite(event.yaw_rate_setpoint) and _nonzero(event.yaw_rate_setpoint)
    return False
