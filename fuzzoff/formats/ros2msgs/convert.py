"""Decoded px4_msgs messages -> fuzzoff events (formats.md 2.2), one builder per message type.

A builder is made once per connection, knowing the field names of the definition in use, so the
release-dependent layouts (1.13 ``TrajectorySetpoint``, the 1.13/1.14 ``actuator`` flag, ...)
are resolved before the first message, not per message.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from fuzzoff import events as ev
from fuzzoff.events import Event, Origin, Where
from fuzzoff.formats.uorb import ARMING_STATE_ARMED, ESTIMATES, TOPICS
from fuzzoff.modes import nav_state_name

Builder = Callable[[Any, float, Where, int], Event]
"""(decoded message, t, where, sender_time_us) -> event."""


def _vec(value: Any) -> tuple[float, ...]:
    """A fixed array (rosbags: a numpy array) as a tuple of Python floats."""
    return tuple(value.tolist())


_v3: Any = _vec
"""float32[3] -> Vec3 (the definition fixes the length)."""
_v2: Any = _vec
_v4: Any = _vec


def _control_mode(fields: frozenset[str], vehicle: str, origin: Origin) -> Builder:
    if "actuator" in fields:

        def old(m: Any, t: float, where: Where, ts: int) -> Event:
            return ev.ControlMode(
                t=t,
                vehicle=vehicle,
                where=where,
                sender_time_us=ts,
                origin=origin,
                position=m.position,
                velocity=m.velocity,
                acceleration=m.acceleration,
                attitude=m.attitude,
                body_rate=m.body_rate,
                actuator=m.actuator,
                layout="actuator",
            )

        return old

    make = ev.ControlMode

    def new(m: Any, t: float, where: Where, ts: int) -> Event:
        return make(
            t=t,
            vehicle=vehicle,
            where=where,
            sender_time_us=ts,
            origin=origin,
            position=m.position,
            velocity=m.velocity,
            acceleration=m.acceleration,
            attitude=m.attitude,
            body_rate=m.body_rate,
            thrust_and_torque=m.thrust_and_torque,
            direct_actuator=m.direct_actuator,
        )

    return new


def _trajectory(fields: frozenset[str], vehicle: str, origin: Origin) -> Builder:
    if "x" in fields:  # 1.13 layout

        def old(m: Any, t: float, where: Where, ts: int) -> Event:
            return ev.TrajectorySetpoint(
                t=t,
                vehicle=vehicle,
                where=where,
                sender_time_us=ts,
                origin=origin,
                position=(m.x, m.y, m.z),
                velocity=(m.vx, m.vy, m.vz),
                acceleration=_v3(m.acceleration),
                jerk=_v3(m.jerk),
                yaw=m.yaw,
                yawspeed=m.yawspeed,
            )

        return old

    make = ev.TrajectorySetpoint

    def new(m: Any, t: float, where: Where, ts: int) -> Event:
        # tuple(x.tolist()) inline (= _v3): the hot path of every ROS 2 offboard recording
        return make(
            t=t,
            vehicle=vehicle,
            where=where,
            sender_time_us=ts,
            origin=origin,
            position=tuple(m.position.tolist()),
            velocity=tuple(m.velocity.tolist()),
            acceleration=tuple(m.acceleration.tolist()),
            jerk=tuple(m.jerk.tolist()),
            yaw=m.yaw,
            yawspeed=m.yawspeed,
        )

    return new


def _attitude(fields: frozenset[str], vehicle: str, origin: Origin) -> Builder:
    def build(m: Any, t: float, where: Where, ts: int) -> Event:
        return ev.AttitudeSetpoint(
            t=t,
            vehicle=vehicle,
            where=where,
            sender_time_us=ts,
            origin=origin,
            q_d=_v4(m.q_d),
            thrust_body=_v3(m.thrust_body),
            yaw_sp_move_rate=m.yaw_sp_move_rate,
        )

    return build


def _rates(fields: frozenset[str], vehicle: str, origin: Origin) -> Builder:
    def build(m: Any, t: float, where: Where, ts: int) -> Event:
        return ev.RatesSetpoint(
            t=t,
            vehicle=vehicle,
            where=where,
            sender_time_us=ts,
            origin=origin,
            roll=m.roll,
            pitch=m.pitch,
            yaw=m.yaw,
            thrust_body=_v3(m.thrust_body),
        )

    return build


def _xyz(cls: type[ev.ThrustSetpoint] | type[ev.TorqueSetpoint]) -> Any:
    def factory(fields: frozenset[str], vehicle: str, origin: Origin) -> Builder:
        def build(m: Any, t: float, where: Where, ts: int) -> Event:
            return cls(
                t=t,
                vehicle=vehicle,
                where=where,
                sender_time_us=ts,
                origin=origin,
                xyz=_v3(m.xyz),
            )

        return build

    return factory


def _motors(fields: frozenset[str], vehicle: str, origin: Origin) -> Builder:
    def build(m: Any, t: float, where: Where, ts: int) -> Event:
        return ev.ActuatorMotors(
            t=t,
            vehicle=vehicle,
            where=where,
            sender_time_us=ts,
            origin=origin,
            control=_vec(m.control),
            reversible_flags=m.reversible_flags,
        )

    return build


def _servos(fields: frozenset[str], vehicle: str, origin: Origin) -> Builder:
    def build(m: Any, t: float, where: Where, ts: int) -> Event:
        return ev.ActuatorServos(
            t=t,
            vehicle=vehicle,
            where=where,
            sender_time_us=ts,
            origin=origin,
            control=_vec(m.control),
        )

    return build


def _rover_position(fields: frozenset[str], vehicle: str, origin: Origin) -> Builder:
    nan2 = (ev.NAN, ev.NAN)

    def build(m: Any, t: float, where: Where, ts: int) -> Event:
        return ev.RoverPositionSetpoint(
            t=t,
            vehicle=vehicle,
            where=where,
            sender_time_us=ts,
            origin=origin,
            position_ned=_v2(m.position_ned),
            start_ned=_v2(m.start_ned) if "start_ned" in fields else nan2,
            cruising_speed=m.cruising_speed,
            arrival_speed=m.arrival_speed if "arrival_speed" in fields else ev.NAN,
            yaw=m.yaw,
        )

    return build


def _plain(cls: type[Event], names: tuple[str, ...]) -> Any:
    """A builder for messages whose event fields are float fields of the same name."""

    def factory(fields: frozenset[str], vehicle: str, origin: Origin) -> Builder:
        present = tuple(n for n in names if n in fields)

        def build(m: Any, t: float, where: Where, ts: int) -> Event:
            values = {n: getattr(m, n) for n in present}
            return cls(
                t=t, vehicle=vehicle, where=where, sender_time_us=ts, origin=origin, **values
            )

        return build

    return factory


def _steering(fields: frozenset[str], vehicle: str, origin: Origin) -> Builder:
    # 1.17+ has one field, normalized_steering_setpoint, kept in normalized_steering_angle.
    angle = "normalized_steering_angle" if "normalized_steering_angle" in fields else None
    angle = angle or "normalized_steering_setpoint"
    has_diff = "normalized_speed_diff" in fields

    def build(m: Any, t: float, where: Where, ts: int) -> Event:
        return ev.RoverSteeringSetpoint(
            t=t,
            vehicle=vehicle,
            where=where,
            sender_time_us=ts,
            origin=origin,
            normalized_steering_angle=getattr(m, angle),
            normalized_speed_diff=m.normalized_speed_diff if has_diff else ev.NAN,
        )

    return build


def _command(fields: frozenset[str], vehicle: str, origin: Origin) -> Builder:
    def build(m: Any, t: float, where: Where, ts: int) -> Event:
        return ev.Command(
            t=t,
            vehicle=vehicle,
            where=where,
            sender_time_us=ts,
            origin=origin,
            command=m.command,
            params=(m.param1, m.param2, m.param3, m.param4, m.param5, m.param6, m.param7),
            target_system=m.target_system,
            target_component=m.target_component,
            source_system=m.source_system,
            source_component=m.source_component,
            from_external=m.from_external,
            transport="ros2",
        )

    return build


def _ack(fields: frozenset[str], vehicle: str, origin: Origin) -> Builder:
    def build(m: Any, t: float, where: Where, ts: int) -> Event:
        return ev.CommandAck(
            t=t,
            vehicle=vehicle,
            where=where,
            sender_time_us=ts,
            origin=origin,
            command=m.command,
            result=m.result,
            target_system=m.target_system,
            target_component=m.target_component,
        )

    return build


def _status(fields: frozenset[str], vehicle: str, origin: Origin) -> Builder:
    has_intention = "nav_state_user_intention" in fields

    def build(m: Any, t: float, where: Where, ts: int) -> Event:
        return ev.VehicleStatus(
            t=t,
            vehicle=vehicle,
            where=where,
            sender_time_us=ts,
            origin=origin,
            nav_state=m.nav_state,
            mode=nav_state_name(m.nav_state),
            armed=m.arming_state == ARMING_STATE_ARMED,
            user_intention=m.nav_state_user_intention if has_intention else None,
            failsafe=m.failsafe,
            vehicle_type=m.vehicle_type,
            is_vtol=m.is_vtol,
            vtol_phase=(
                ev.vtol_phase_of(m.vehicle_type, getattr(m, "in_transition_mode", None))
                if m.is_vtol
                else None
            ),
        )

    return build


_FLAG_PREFIX = "flag_control_"
_FLAG_SUFFIX = "_enabled"


def _control_mode_status(fields: frozenset[str], vehicle: str, origin: Origin) -> Builder:
    flags = tuple(
        (name, name[len(_FLAG_PREFIX) : -len(_FLAG_SUFFIX)])
        for name in sorted(fields)
        if name.startswith(_FLAG_PREFIX) and name.endswith(_FLAG_SUFFIX)
    )

    def build(m: Any, t: float, where: Where, ts: int) -> Event:
        return ev.VehicleControlModeStatus(
            t=t,
            vehicle=vehicle,
            where=where,
            sender_time_us=ts,
            origin=origin,
            offboard_enabled=m.flag_control_offboard_enabled,
            enabled=frozenset(short for name, short in flags if getattr(m, name)),
        )

    return build


def _failsafe_flags(fields: frozenset[str], vehicle: str, origin: Origin) -> Builder:
    manual = "manual_control_signal_lost" if "manual_control_signal_lost" in fields else None
    invalid = tuple((name, f"{name}_invalid") for name in ESTIMATES if f"{name}_invalid" in fields)

    def build(m: Any, t: float, where: Where, ts: int) -> Event:
        return ev.FailsafeFlags(
            t=t,
            vehicle=vehicle,
            where=where,
            sender_time_us=ts,
            origin=origin,
            offboard_control_signal_lost=m.offboard_control_signal_lost,
            manual_control_signal_lost=getattr(m, manual) if manual else None,
            **{f"{name}_valid": not getattr(m, field) for name, field in invalid},
        )

    return build


def _local_position(fields: frozenset[str], vehicle: str, origin: Origin) -> Builder:
    """``VehicleLocalPosition``; a coordinate PX4 marks invalid is NaN (as from a ULog)."""
    nan = ev.NAN

    def build(m: Any, t: float, where: Where, ts: int) -> Event:
        xy = m.xy_valid
        return ev.VehiclePosition(
            t=t,
            vehicle=vehicle,
            where=where,
            sender_time_us=ts,
            origin=origin,
            x=m.x if xy else nan,
            y=m.y if xy else nan,
            z=m.z if m.z_valid else nan,
        )

    return build


def _land_detected(fields: frozenset[str], vehicle: str, origin: Origin) -> Builder:
    """``VehicleLandDetected``: landed as Commander judges a disarm, ``landed`` or
    ``maybe_landed`` (gate.md#seen-on-px4), as from a ULog."""

    def build(m: Any, t: float, where: Where, ts: int) -> Event:
        return ev.LandDetected(
            t=t,
            vehicle=vehicle,
            where=where,
            sender_time_us=ts,
            origin=origin,
            landed=bool(m.landed or m.maybe_landed),
        )

    return build


def _name(value: Any) -> str:
    """A ``char[25]`` name (rosbags: a numpy uint8 array) as text, up to its first NUL."""
    raw = bytes(value.tolist()) if hasattr(value, "tolist") else bytes(value)
    return raw.split(b"\0", 1)[0].decode("utf-8", "replace")


def _ext_request(fields: frozenset[str], vehicle: str, origin: Origin) -> Builder:
    def build(m: Any, t: float, where: Where, ts: int) -> Event:
        return ev.ExtComponentRequest(
            t=t,
            vehicle=vehicle,
            where=where,
            sender_time_us=ts,
            origin=origin,
            request_id=int(m.request_id),
            name=_name(m.name),
            api_version=int(m.px4_ros2_api_version),
            arming_check=bool(m.register_arming_check),
            mode=bool(m.register_mode),
            executor=bool(m.register_mode_executor),
        )

    return build


def _ext_reply(fields: frozenset[str], vehicle: str, origin: Origin) -> Builder:
    def build(m: Any, t: float, where: Where, ts: int) -> Event:
        return ev.ExtComponentReply(
            t=t,
            vehicle=vehicle,
            where=where,
            sender_time_us=ts,
            origin=origin,
            request_id=int(m.request_id),
            name=_name(m.name),
            api_version=int(m.px4_ros2_api_version),
            success=bool(m.success),
            arming_check_id=int(m.arming_check_id),
            mode_id=int(m.mode_id),
            executor_id=int(m.mode_executor_id),
        )

    return build


def _check_request(fields: frozenset[str], vehicle: str, origin: Origin) -> Builder:
    has_mask = "valid_registrations_mask" in fields

    def build(m: Any, t: float, where: Where, ts: int) -> Event:
        return ev.ArmingCheckRequest(
            t=t,
            vehicle=vehicle,
            where=where,
            sender_time_us=ts,
            origin=origin,
            request_id=int(m.request_id),
            registrations_mask=int(m.valid_registrations_mask) if has_mask else None,
        )

    return build


def _check_reply(fields: frozenset[str], vehicle: str, origin: Origin) -> Builder:
    def build(m: Any, t: float, where: Where, ts: int) -> Event:
        return ev.ArmingCheckReply(
            t=t,
            vehicle=vehicle,
            where=where,
            sender_time_us=ts,
            origin=origin,
            request_id=int(m.request_id),
            registration_id=int(m.registration_id),
            can_arm_and_run=bool(m.can_arm_and_run),
        )

    return build


def _unregister(fields: frozenset[str], vehicle: str, origin: Origin) -> Builder:
    def build(m: Any, t: float, where: Where, ts: int) -> Event:
        return ev.ExtComponentUnregister(
            t=t,
            vehicle=vehicle,
            where=where,
            sender_time_us=ts,
            origin=origin,
            name=_name(m.name),
            arming_check_id=int(m.arming_check_id),
            mode_id=int(m.mode_id),
            executor_id=int(m.mode_executor_id),
        )

    return build


def _setpoint_config(fields: frozenset[str], vehicle: str, origin: Origin) -> Builder:
    def build(m: Any, t: float, where: Where, ts: int) -> Event:
        return ev.SetpointConfig(
            t=t,
            vehicle=vehicle,
            where=where,
            sender_time_us=ts,
            origin=origin,
            setpoint_type=int(m.type),
            source_id=int(m.source_id),
            should_apply=bool(m.should_apply),
        )

    return build


def _setpoint_config_reply(fields: frozenset[str], vehicle: str, origin: Origin) -> Builder:
    def build(m: Any, t: float, where: Where, ts: int) -> Event:
        return ev.SetpointConfigReply(
            t=t,
            vehicle=vehicle,
            where=where,
            sender_time_us=ts,
            origin=origin,
            setpoint_type=int(m.type),
            source_id=int(m.source_id),
            result=int(m.result),
        )

    return build


BUILDERS: dict[str, Callable[[frozenset[str], str, Origin], Builder]] = {
    "OffboardControlMode": _control_mode,
    "TrajectorySetpoint": _trajectory,
    "VehicleAttitudeSetpoint": _attitude,
    "VehicleRatesSetpoint": _rates,
    "VehicleThrustSetpoint": _xyz(ev.ThrustSetpoint),
    "VehicleTorqueSetpoint": _xyz(ev.TorqueSetpoint),
    "ActuatorMotors": _motors,
    "ActuatorServos": _servos,
    "RoverPositionSetpoint": _rover_position,
    "RoverSpeedSetpoint": _plain(ev.RoverSpeedSetpoint, ("speed_body_x", "speed_body_y")),
    "RoverAttitudeSetpoint": _plain(ev.RoverAttitudeSetpoint, ("yaw_setpoint",)),
    "RoverRateSetpoint": _plain(ev.RoverRateSetpoint, ("yaw_rate_setpoint",)),
    "RoverThrottleSetpoint": _plain(
        ev.RoverThrottleSetpoint, ("throttle_body_x", "throttle_body_y")
    ),
    "RoverSteeringSetpoint": _steering,
    "VehicleCommand": _command,
    "VehicleCommandAck": _ack,
    "VehicleStatus": _status,
    "VehicleControlMode": _control_mode_status,
    "FailsafeFlags": _failsafe_flags,
    "VehicleLocalPosition": _local_position,
    "VehicleLandDetected": _land_detected,
    "RegisterExtComponentRequest": _ext_request,
    "RegisterExtComponentReply": _ext_reply,
    "ArmingCheckRequest": _check_request,
    "ArmingCheckReply": _check_reply,
    "UnregisterExtComponent": _unregister,
    "SetpointConfig": _setpoint_config,
    "SetpointConfigReply": _setpoint_config_reply,
}
"""px4_msgs message name -> builder factory (fields of the definition, vehicle, origin)."""

KIND_OF: dict[str, str] = {
    topic.message: topic.kind for topic in TOPICS.values() if topic.message is not None
}
