"""Events -> px4_msgs messages of a chosen release (the inverse of ``ros2msgs.convert``).

Shared by the MCAP and rosbag2 writers. A message is a plain dict holding every wire field of
the release's bundled definition (fields the event does not carry get zero / NaN defaults), the
topic PX4 uses for it in that release (``_vN`` suffix, v1.13 ``/fmu/<name>/in`` naming) and its
log time.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Iterator
from typing import Any

import numpy as np
from rosbags.interfaces import Nodetype

from fuzzoff import events as ev
from fuzzoff.formats import px4_msgs
from fuzzoff.formats.ros2msgs.topics import topic_for
from fuzzoff.formats.uorb import ARMING_STATE_ARMED, ARMING_STATE_DISARMED, ESTIMATES
from fuzzoff.lean_dataclass import dataclass

START_NS = 1_700_000_000_000_000_000
"""Recording start (log time of t = 0) used by the writers unless told otherwise."""

_MESSAGE_OF: dict[type[ev.Event], str] = {
    ev.ControlMode: "OffboardControlMode",
    ev.TrajectorySetpoint: "TrajectorySetpoint",
    ev.AttitudeSetpoint: "VehicleAttitudeSetpoint",
    ev.RatesSetpoint: "VehicleRatesSetpoint",
    ev.ThrustSetpoint: "VehicleThrustSetpoint",
    ev.TorqueSetpoint: "VehicleTorqueSetpoint",
    ev.ActuatorMotors: "ActuatorMotors",
    ev.ActuatorServos: "ActuatorServos",
    ev.RoverPositionSetpoint: "RoverPositionSetpoint",
    ev.RoverSpeedSetpoint: "RoverSpeedSetpoint",
    ev.RoverAttitudeSetpoint: "RoverAttitudeSetpoint",
    ev.RoverRateSetpoint: "RoverRateSetpoint",
    ev.RoverThrottleSetpoint: "RoverThrottleSetpoint",
    ev.RoverSteeringSetpoint: "RoverSteeringSetpoint",
    ev.Command: "VehicleCommand",
    ev.CommandAck: "VehicleCommandAck",
    ev.VehicleStatus: "VehicleStatus",
    ev.VehicleControlModeStatus: "VehicleControlMode",
    ev.FailsafeFlags: "FailsafeFlags",
    ev.VehiclePosition: "VehicleLocalPosition",
    ev.LandDetected: "VehicleLandDetected",
    ev.ExtComponentRequest: "RegisterExtComponentRequest",
    ev.ExtComponentReply: "RegisterExtComponentReply",
    ev.ArmingCheckRequest: "ArmingCheckRequest",
    ev.ArmingCheckReply: "ArmingCheckReply",
    ev.ExtComponentUnregister: "UnregisterExtComponent",
    ev.SetpointConfig: "SetpointConfig",
    ev.SetpointConfigReply: "SetpointConfigReply",
}

_NUMPY = {
    "bool": np.bool_,
    "char": np.uint8,
    "byte": np.uint8,
    "uint8": np.uint8,
    "int8": np.int8,
    "uint16": np.uint16,
    "int16": np.int16,
    "uint32": np.uint32,
    "int32": np.int32,
    "uint64": np.uint64,
    "int64": np.int64,
    "float32": np.float32,
    "float64": np.float64,
}


@dataclass(frozen=True, slots=True)
class Field:
    name: str
    base: str
    length: int | None


@dataclass(frozen=True, slots=True)
class Px4Message:
    """One message to write."""

    topic: str
    message: str
    release: str
    log_time_ns: int
    values: dict[str, Any]

    @property
    def typename(self) -> str:
        return px4_msgs.type_name(self.message)


class UnsupportedEvent(ValueError):
    """An event the ROS 2 formats cannot carry (a MAVLink setpoint, a ULog-only kind)."""


def fields_of(release: str, message: str) -> list[Field]:
    """The wire fields of a bundled definition, in order."""
    text = px4_msgs.definition(release, message)
    if text is None:
        raise UnsupportedEvent(f"px4_msgs {release} has no {message}")
    out = []
    for line in px4_msgs.own_part(text).splitlines():
        line = line.split("#", 1)[0].strip()
        if not line or "=" in line:
            continue
        typ, name = line.split()[:2]
        base, _, rest = typ.partition("[")
        out.append(Field(name, base, int(rest.rstrip("]")) if rest else None))
    return out


def _default(f: Field) -> Any:
    zero: Any = False if f.base == "bool" else (0.0 if f.base.startswith("float") else 0)
    return [zero] * f.length if f.length else zero


def _fit(values: tuple[float, ...], length: int) -> list[float]:
    return [*values[:length], *([math.nan] * (length - len(values)))]


def _event_values(event: ev.Event, message: str, names: set[str]) -> dict[str, Any]:
    """The fields this event sets (only those the release's definition has are kept)."""
    v: dict[str, Any] = {}
    if isinstance(event, ev.ControlMode):
        for flag in ("position", "velocity", "acceleration", "attitude", "body_rate"):
            v[flag] = getattr(event, flag)
        v["actuator"] = event.actuator
        v["thrust_and_torque"] = event.thrust_and_torque
        v["direct_actuator"] = event.direct_actuator
    elif isinstance(event, ev.TrajectorySetpoint):
        if "x" in names:
            v.update(zip(("x", "y", "z"), event.position, strict=True))
            v.update(zip(("vx", "vy", "vz"), event.velocity, strict=True))
            v["thrust"] = [math.nan] * 3
        else:
            v["position"], v["velocity"] = list(event.position), list(event.velocity)
        v["acceleration"], v["jerk"] = list(event.acceleration), list(event.jerk)
        v["yaw"], v["yawspeed"] = event.yaw, event.yawspeed
    elif isinstance(event, ev.AttitudeSetpoint):
        v["q_d"], v["thrust_body"] = list(event.q_d), list(event.thrust_body)
        v["yaw_sp_move_rate"] = event.yaw_sp_move_rate
    elif isinstance(event, ev.RatesSetpoint):
        v.update(roll=event.roll, pitch=event.pitch, yaw=event.yaw)
        v["thrust_body"] = list(event.thrust_body)
    elif isinstance(event, ev.ThrustSetpoint | ev.TorqueSetpoint):
        v["xyz"] = list(event.xyz)
    elif isinstance(event, ev.ActuatorMotors | ev.ActuatorServos):
        v["control"] = event.control
        if isinstance(event, ev.ActuatorMotors):
            v["reversible_flags"] = event.reversible_flags
    elif isinstance(event, ev.RoverPositionSetpoint):
        v["position_ned"], v["start_ned"] = list(event.position_ned), list(event.start_ned)
        v.update(cruising_speed=event.cruising_speed, arrival_speed=event.arrival_speed)
        v["yaw"] = event.yaw
    elif isinstance(event, ev.RoverSteeringSetpoint):
        v["normalized_steering_angle"] = event.normalized_steering_angle
        v["normalized_steering_setpoint"] = event.normalized_steering_angle
        v["normalized_speed_diff"] = event.normalized_speed_diff
    elif isinstance(
        event,
        ev.RoverSpeedSetpoint
        | ev.RoverAttitudeSetpoint
        | ev.RoverRateSetpoint
        | ev.RoverThrottleSetpoint,
    ):
        v.update({n: getattr(event, n) for n in names if hasattr(event, n) and n != "timestamp"})
    elif isinstance(event, ev.Command):
        v.update({f"param{i + 1}": p for i, p in enumerate(event.params)})
        v.update(command=event.command, target_system=event.target_system)
        v.update(target_component=event.target_component)
        v["source_system"] = event.source_system or 0
        v["source_component"] = event.source_component or 0
        v["from_external"] = True if event.from_external is None else event.from_external
    elif isinstance(event, ev.CommandAck):
        v.update(command=event.command, result=event.result, target_system=event.target_system)
        v["target_component"] = event.target_component
    elif isinstance(event, ev.VehicleStatus):
        nav = event.nav_state or 0
        v["nav_state"] = nav
        v["arming_state"] = ARMING_STATE_ARMED if event.armed else ARMING_STATE_DISARMED
        v["nav_state_user_intention"] = (
            nav if event.user_intention is None else event.user_intention
        )
        v["failsafe"] = bool(event.failsafe)
        v["vehicle_type"] = event.vehicle_type or 0
        v["is_vtol"] = bool(event.is_vtol)
        v.update(system_id=1, component_id=1, nav_state_timestamp=0)
    elif isinstance(event, ev.VehicleControlModeStatus):
        for name in names:
            if name.startswith("flag_control_") and name.endswith("_enabled"):
                v[name] = name[len("flag_control_") : -len("_enabled")] in event.enabled
        v["flag_control_offboard_enabled"] = event.offboard_enabled
    elif isinstance(event, ev.FailsafeFlags):
        v["offboard_control_signal_lost"] = bool(event.offboard_control_signal_lost)
        v["manual_control_signal_lost"] = bool(event.manual_control_signal_lost)
        for name in ESTIMATES:
            valid = getattr(event, f"{name}_valid")
            v[f"{name}_invalid"] = valid is False
    elif isinstance(event, ev.LandDetected):
        v["landed"] = v["maybe_landed"] = bool(event.landed)
    elif isinstance(event, ev.ExtComponentRequest | ev.ExtComponentReply):
        v.update(request_id=event.request_id, name=_name_bytes(event.name))
        v["px4_ros2_api_version"] = event.api_version
        if isinstance(event, ev.ExtComponentRequest):
            v.update(register_arming_check=event.arming_check, register_mode=event.mode)
            v["register_mode_executor"] = event.executor
        else:
            v.update(success=event.success, arming_check_id=event.arming_check_id)
            v.update(mode_id=event.mode_id, mode_executor_id=event.executor_id)
    elif isinstance(event, ev.ArmingCheckRequest):
        v["request_id"] = event.request_id
        v["valid_registrations_mask"] = event.registrations_mask or 0
    elif isinstance(event, ev.ArmingCheckReply):
        v.update(request_id=event.request_id, registration_id=event.registration_id)
        v["can_arm_and_run"] = event.can_arm_and_run
    elif isinstance(event, ev.ExtComponentUnregister):
        v.update(name=_name_bytes(event.name), arming_check_id=event.arming_check_id)
        v.update(mode_id=event.mode_id, mode_executor_id=event.executor_id)
    elif isinstance(event, ev.SetpointConfig | ev.SetpointConfigReply):
        v.update(type=event.setpoint_type, source_id=event.source_id)
        if isinstance(event, ev.SetpointConfig):
            v["should_apply"] = event.should_apply
        else:
            v["result"] = event.result
    elif isinstance(event, ev.VehiclePosition):
        xy, z = math.isfinite(event.x) and math.isfinite(event.y), math.isfinite(event.z)
        v.update(x=event.x if xy else 0.0, y=event.y if xy else 0.0, z=event.z if z else 0.0)
        v.update(xy_valid=xy, z_valid=z, v_xy_valid=xy, v_z_valid=z)
    return v


def _name_bytes(name: str) -> list[int]:
    """A name as the ``char[25]`` field holds it: UTF-8, NUL-padded (cut to 24 bytes)."""
    raw = name.encode("utf-8")[:24]
    return [*raw, *([0] * (25 - len(raw)))]


def complete(given: dict[str, Any], release: str, message: str) -> dict[str, Any]:
    """Every wire field of ``release``'s ``message``: ``given`` values, else zero / NaN."""
    values: dict[str, Any] = {}
    for f in fields_of(release, message):
        value = given.get(f.name, _default(f))
        if f.base not in _NUMPY:
            values[f.name] = None  # a nested px4_msgs type: its zero value (rosbags_message)
            continue
        if f.length is not None:
            value = _fit(tuple(value), f.length) if f.base.startswith("float") else list(value)
        values[f.name] = value
    return values


def to_message(event: ev.Event, release: str, start_ns: int = START_NS) -> Px4Message:
    """The px4_msgs ``release`` message for ``event``; ``UnsupportedEvent`` if there is none."""
    message = _MESSAGE_OF.get(type(event))
    if message is None:
        raise UnsupportedEvent(f"{type(event).__name__} has no ROS 2 PX4 topic")
    names = {f.name for f in fields_of(release, message)}
    given = _event_values(event, message, names)
    timestamp = event.sender_time_us
    if timestamp is None:
        timestamp = round(event.t * 1e6)
    values = complete(given, release, message)
    values["timestamp"] = timestamp
    if "timestamp_sample" in names:
        values["timestamp_sample"] = timestamp
    text = px4_msgs.definition(release, message)
    assert text is not None
    topic = topic_for(
        message, event.vehicle, px4_msgs.message_version(text), legacy=release == "1.13"
    )
    return Px4Message(topic, message, release, start_ns + round(event.t * 1e9), values)


def to_messages(
    events: Iterable[ev.Event], release: str, start_ns: int = START_NS
) -> Iterator[Px4Message]:
    """Messages for every event a ROS 2 recording can carry, in time order."""
    for event in sorted(events, key=lambda e: e.t):
        yield to_message(event, release, start_ns)


def rosbags_message(store: Any, msg: Px4Message) -> Any:
    """The rosbags message object for ``msg`` (arrays as numpy arrays of the field's type)."""
    cls = store.types[msg.typename]
    kwargs = {}
    for f in fields_of(msg.release, msg.message):
        value = msg.values[f.name]
        if f.base not in _NUMPY:
            nested = _zero(store, px4_msgs.type_name(f.base))
            kwargs[f.name] = [nested] * f.length if f.length else nested
            continue
        if f.length is not None:
            value = np.array(value, dtype=_NUMPY[f.base])
        kwargs[f.name] = value
    return cls(**kwargs)


def _zero(store: Any, typename: str) -> Any:
    """A message of a nested type with every field zero (``ArmingCheckReply.events``)."""
    cls = store.types[typename]
    kwargs: dict[str, Any] = {}
    for name, (nodetype, details) in store.fielddefs[typename][1]:
        if nodetype == Nodetype.ARRAY:
            (_, (base, _)), count = details
            kwargs[name] = np.zeros(count, dtype=_NUMPY[base])
        else:
            kwargs[name] = _NUMPY[details[0]](0)
    return cls(**kwargs)


@dataclass(frozen=True, slots=True)
class RawMessage:
    """A message of any type, already CDR-encoded (camera, IMU, foreign topics in tests)."""

    t: float
    topic: str
    msgtype: str
    msgdef: str
    data: bytes


def merged(
    messages: Iterable[Px4Message], raw: Iterable[RawMessage], start_ns: int = START_NS
) -> Iterator[Px4Message | RawMessage]:
    """PX4 and raw messages in log-time order."""
    import heapq

    def key(item: Px4Message | RawMessage) -> int:
        if isinstance(item, RawMessage):
            return start_ns + round(item.t * 1e9)
        return item.log_time_ns

    ordered: list[Px4Message | RawMessage] = sorted(raw, key=key)
    yield from heapq.merge(messages, ordered, key=key)


def log_time(item: Px4Message | RawMessage, start_ns: int = START_NS) -> int:
    if isinstance(item, RawMessage):
        return start_ns + round(item.t * 1e9)
    return item.log_time_ns


def encode(msg: Px4Message, release: str | None = None) -> bytes:
    """CDR bytes of ``msg`` under ``release``'s definition (default: its own) via rosbags."""
    release = release or msg.release
    text = px4_msgs.definition(release, msg.message)
    if text is None:
        raise UnsupportedEvent(f"px4_msgs {release} has no {msg.message}")
    store = px4_msgs.typestore_for(msg.typename, text)
    relaid = Px4Message(
        msg.topic, msg.message, release, msg.log_time_ns, complete(msg.values, release, msg.message)
    )
    return bytes(store.serialize_cdr(rosbags_message(store, relaid), msg.typename))


def payload_for(payload_release: str | dict[str, str] | None, message: str) -> str | None:
    """The release whose layout encodes ``message`` (None: the declared one)."""
    if isinstance(payload_release, dict):
        return payload_release.get(message)
    return payload_release
