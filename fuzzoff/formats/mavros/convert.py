"""MAVROS topics -> the MAVLink setpoints MAVROS sends PX4 (formats.md section 6.1).

Pure conversion, no I/O: the ROS 1 and ROS 2 readers hand each decoded message of a MAVROS topic
(``/mavros/...`` or ``/<ns>/mavros/...``) to ``MavrosConverter.convert`` and get back the
normalised events, so the MAVLink rules judge what PX4 receives, not what the ROS program wrote:

* frames: ENU -> NED and FLU -> FRD, yaw re-expressed (``mavros_frames``);
* ``type_mask``: passed through for ``setpoint_raw/*``; fixed per topic otherwise
  (``TOPIC_MASKS``, the values MAVROS's plugins hard-code);
* what MAVROS drops (thrust outside [0, 1] on ``setpoint_attitude``, a thrust without
  ``thrust_scaling`` on ``setpoint_raw/attitude``) yields no event, as PX4 gets nothing.

Messages are any object with attribute access (rosbags' ROS 1 and ROS 2 classes both do).
The vehicle key is the namespace before ``/mavros`` (``""`` for plain ``/mavros``).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import field
from math import atan2 as _atan2
from math import cos as _cos
from math import sin as _sin
from typing import Any, NamedTuple

from fuzzoff.events import (
    Event,
    LandDetected,
    SetAttitudeTarget,
    SetPositionTargetGlobal,
    SetPositionTargetLocal,
    VehiclePosition,
    VehicleStatus,
    Where,
)
from fuzzoff.formats.mavros.frames import (
    AIRCRAFT_BASELINK_Q,
    BODY_FRAMES,
    FRAME_LOCAL_NED,
    enu_to_ned,
    flu_to_frd,
    orientation_enu_to_ned,
    pose_rotation,
    quat_mul,
    quat_yaw,
    yaw_enu_to_ned,
    yaw_flu_to_frd,
)
from fuzzoff.lean_dataclass import dataclass
from fuzzoff.modes import mavros_mode_to_nav_state
from fuzzoff.recording import POSITION_PERIOD_S, Aside
from fuzzoff.type_mask import (
    ACCELERATION_BITS,
    ATTITUDE_IGNORE,
    BODY_YAW_RATE_IGNORE,
    FORCE_SET,
    PITCH_RATE_IGNORE,
    POSITION_BITS,
    ROLL_RATE_IGNORE,
    VELOCITY_BITS,
    YAW_IGNORE,
    YAW_RATE_IGNORE,
)

# type_mask values MAVROS's plugins hard-code.
MASK_POSITION_YAW = YAW_RATE_IGNORE | ACCELERATION_BITS | VELOCITY_BITS  # 0x9F8: setpoint_position
MASK_VELOCITY_YAW_RATE = YAW_IGNORE | ACCELERATION_BITS | POSITION_BITS  # 0x5C7: setpoint_velocity
MASK_ACCEL = YAW_IGNORE | YAW_RATE_IGNORE | VELOCITY_BITS | POSITION_BITS  # 0xC3F: setpoint_accel
MASK_FORCE = FORCE_SET
MASK_ATTITUDE_THRUST = ROLL_RATE_IGNORE | PITCH_RATE_IGNORE | BODY_YAW_RATE_IGNORE  # attitude
MASK_RATES_THRUST = ATTITUDE_IGNORE  # setpoint_attitude/cmd_vel: ignore the attitude

LANDED_STATE_UNDEFINED = 0
LANDED_STATE_ON_GROUND = 1
"""``ExtendedState.landed_state`` values (MAVLink ``MAV_LANDED_STATE``)."""

MAVROS_TARGET_SYSTEM = 1
MAVROS_TARGET_COMPONENT = 1
"""MAVROS's default ``target_system_id`` / ``target_component_id``."""

_MSG = "mavros_msgs/msg/"
_GEO = "geometry_msgs/msg/"

TOPIC_TYPES: dict[str, str] = {
    "setpoint_raw/local": _MSG + "PositionTarget",
    "setpoint_raw/global": _MSG + "GlobalPositionTarget",
    "setpoint_raw/attitude": _MSG + "AttitudeTarget",
    "setpoint_position/local": _GEO + "PoseStamped",
    "setpoint_velocity/cmd_vel": _GEO + "TwistStamped",
    "setpoint_velocity/cmd_vel_unstamped": _GEO + "Twist",
    "setpoint_attitude/attitude": _GEO + "PoseStamped",
    "setpoint_attitude/cmd_vel": _GEO + "TwistStamped",
    "setpoint_attitude/thrust": _MSG + "Thrust",
    "setpoint_accel/accel": _GEO + "Vector3Stamped",
    "state": _MSG + "State",
    "extended_state": _MSG + "ExtendedState",
    "local_position/pose": _GEO + "PoseStamped",
}
"""MAVROS topic (after the ``mavros/`` namespace) -> the message type MAVROS subscribes with."""

TOPIC_KINDS: dict[str, str] = {
    "setpoint_raw/local": SetPositionTargetLocal.kind,
    "setpoint_raw/global": SetPositionTargetGlobal.kind,
    "setpoint_raw/attitude": SetAttitudeTarget.kind,
    "setpoint_position/local": SetPositionTargetLocal.kind,
    "setpoint_velocity/cmd_vel": SetPositionTargetLocal.kind,
    "setpoint_velocity/cmd_vel_unstamped": SetPositionTargetLocal.kind,
    "setpoint_attitude/attitude": SetAttitudeTarget.kind,
    "setpoint_attitude/cmd_vel": SetAttitudeTarget.kind,
    "setpoint_attitude/thrust": SetAttitudeTarget.kind,
    "setpoint_accel/accel": SetPositionTargetLocal.kind,
    "state": VehicleStatus.kind,
    "extended_state": LandDetected.kind,
    "local_position/pose": VehiclePosition.kind,
}
"""MAVROS topic -> the event kind it becomes (``RecordingInfo.kinds``)."""


class MavrosTopic(NamedTuple):
    namespace: str
    """What comes before ``/mavros`` (``""`` for ``/mavros``): the event's ``vehicle``."""
    name: str
    """The topic after ``mavros/``, e.g. ``setpoint_raw/local``."""


def split_topic(topic: str) -> MavrosTopic | None:
    """``/uav1/mavros/setpoint_raw/local`` -> (``/uav1``, ``setpoint_raw/local``); else None."""
    path = topic if topic.startswith("/") else "/" + topic
    at = path.rfind("/mavros/")
    if at < 0:
        return None
    return MavrosTopic(path[:at], path[at + len("/mavros/") :])


def mavros_topic(topic: str, msgtype: str) -> MavrosTopic | None:
    """The MAVROS topic this connection is, if fuzzoff converts it and the type is the right one.

    ``msgtype`` may be ROS 1 style (``pkg/Type``) or ROS 2 style (``pkg/msg/Type``).
    """
    split = split_topic(topic)
    if split is None:
        return None
    want = TOPIC_TYPES.get(split.name)
    if want is None or normalize_type(msgtype) != want:
        return None
    return split


def normalize_type(msgtype: str) -> str:
    """``pkg/Type`` -> ``pkg/msg/Type`` (rosbags already reports ROS 1 types this way)."""
    pkg, _, name = msgtype.rpartition("/")
    if pkg and "/" not in pkg:
        return f"{pkg}/msg/{name}"
    return msgtype


def stamp_to_time_boot_us(header: Any) -> int | None:
    """The MAVLink ``time_boot_ms`` MAVROS derives from ``header.stamp``, in microseconds.

    MAVROS sends the stamp in milliseconds truncated to 32 bits; a zero stamp (a program that
    never sets it) gives ``None``: the sender has no clock worth comparing.
    """
    stamp = header.stamp  # rosbags gives ROS 1 times the ROS 2 shape: sec, nanosec
    ns = int(stamp.sec) * 1_000_000_000 + int(stamp.nanosec)
    if ns <= 0:
        return None
    return ((ns // 1_000_000) & 0xFFFFFFFF) * 1000


def _vec(v: Any) -> tuple[float, float, float]:
    return (float(v.x), float(v.y), float(v.z))


def _quat(q: Any) -> tuple[float, float, float, float]:
    return (float(q.w), float(q.x), float(q.y), float(q.z))


@dataclass(frozen=True, slots=True)
class MavrosOptions:
    """MAVROS parameters that change what it sends (defaults: MAVROS's ``px4_config.yaml``)."""

    thrust_scaling: float | None = 1.0
    """``setpoint_raw/thrust_scaling``; ``None`` = unset: a non-zero thrust is dropped."""
    mav_frame: int = FRAME_LOCAL_NED
    """``setpoint_position`` / ``setpoint_velocity`` ``mav_frame`` parameter."""
    send_force: bool = False
    """``setpoint_accel/send_force``."""
    reverse_thrust: bool = False
    """``setpoint_attitude/reverse_thrust``: thrust may be in [-1, 0)."""


Handler = Callable[[Any, float, "int | None"], Event | None]
"""(message, recording time, index on its topic) -> the event, if MAVROS sends one (it sends at
most one MAVLink message per ROS message; a pair is sent on its second message)."""


@dataclass(slots=True)
class _Pending:
    """One side of the attitude/thrust pair MAVROS synchronises (message_filters)."""

    t: float
    msg: Any
    where: Where


@dataclass(slots=True)
class MavrosConverter:
    """Turns MAVROS topic messages into events; keeps the attitude + thrust pairing state.

    ``setpoint_attitude/attitude`` and ``cmd_vel`` are only sent together with a
    ``setpoint_attitude/thrust`` message (MAVROS pairs them with an approximate-time
    synchroniser, each message used once): the event is made when the second of a pair arrives.
    """

    options: MavrosOptions = field(default_factory=MavrosOptions)
    position_period_s: float = POSITION_PERIOD_S
    """``local_position/pose`` kept at most this often per vehicle (0: every one)."""
    aside: Aside = field(default_factory=Aside)
    """Where the thinned positions go (their time; the plots, when asked)."""
    _position_due: dict[str, float] = field(default_factory=dict)
    _body: dict[str, _Pending] = field(default_factory=dict)
    _thrust: dict[str, _Pending] = field(default_factory=dict)
    _handlers: dict[str, Handler | None] = field(default_factory=dict)
    _landed_state: dict[str, bool | None] = field(default_factory=dict)
    """The last land-detector verdict per vehicle (only changes become events)."""

    def convert(self, topic: str, msg: Any, t: float, index: int | None = None) -> list[Event]:
        """The events MAVROS produces for ``msg`` on ``topic`` at recording time ``t``."""
        handler = self.handler(topic)
        event = None if handler is None else handler(msg, t, index)
        return [] if event is None else [event]

    def handler(self, topic: str) -> Handler | None:
        """The conversion for one topic, looked up once (readers call it per connection)."""
        if topic in self._handlers:
            return self._handlers[topic]
        handler = self._make_handler(topic)
        self._handlers[topic] = handler
        return handler

    def _make_handler(self, topic: str) -> Handler | None:
        split = split_topic(topic)
        if split is None:
            return None
        ns, name = split
        if name == "state":
            return lambda msg, t, index: state_to_status(
                msg, t=t, vehicle=ns, where=Where(topic, index)
            )
        if name == "extended_state":
            return lambda msg, t, index: self._landed(msg, t, ns, Where(topic, index))
        if name == "local_position/pose":
            return lambda msg, t, index: self._position(msg, t, ns, Where(topic, index))
        if name in ("setpoint_attitude/attitude", "setpoint_attitude/cmd_vel"):

            def body(msg: Any, t: float, index: int | None) -> Event | None:
                self._body[ns] = _Pending(t, (name, msg), Where(topic, index))
                return self._pair(ns)

            return body
        if name == "setpoint_attitude/thrust":

            def thrust(msg: Any, t: float, index: int | None) -> Event | None:
                self._thrust[ns] = _Pending(t, msg, Where(topic, index))
                return self._pair(ns)

            return thrust
        make = _CONVERTERS.get(name)
        if make is None:
            return None
        options = self.options

        def setpoint(msg: Any, t: float, index: int | None) -> Event | None:
            return make(msg, options, t, ns, Where(topic, index))

        return setpoint

    def _landed(self, msg: Any, t: float, ns: str, where: Where) -> Event | None:
        """``extended_state`` (ExtendedState, MAVLink ``EXTENDED_SYS_STATE`` as MAVROS
        republishes it) -> ``LandDetected`` when its verdict changes, as the tlog reader gives
        it: ON_GROUND is landed; IN_AIR, TAKEOFF and LANDING are not; UNDEFINED is unknown."""
        state = int(msg.landed_state)
        landed = None if state == LANDED_STATE_UNDEFINED else state == LANDED_STATE_ON_GROUND
        if ns in self._landed_state and self._landed_state[ns] == landed:
            return None
        self._landed_state[ns] = landed
        return LandDetected(t=t, vehicle=ns, where=where, landed=landed)

    def _position(self, msg: Any, t: float, ns: str, where: Where) -> Event | None:
        """``local_position/pose``: where MAVROS says the vehicle is, ENU, from PX4's
        LOCAL_POSITION_NED (MAVROS turns NED into ENU; this turns it back)."""
        period = self.position_period_s
        if period:
            if t < self._position_due.get(ns, -math.inf):
                self.aside.read(t)
                if self.aside.plot is not None:
                    self.aside.plot.position(self._position_event(msg, t, ns, where))
                return None
            self._position_due[ns] = t + period - 1e-3
        return self._position_event(msg, t, ns, where)

    @staticmethod
    def _position_event(msg: Any, t: float, ns: str, where: Where) -> VehiclePosition:
        x, y, z = enu_to_ned(_vec(msg.pose.position))
        return VehiclePosition(
            t=t,
            vehicle=ns,
            where=where,
            sender_time_us=stamp_to_time_boot_us(msg.header),
            x=x,
            y=y,
            z=z,
        )

    def _pair(self, ns: str) -> Event | None:
        body, thrust = self._body.get(ns), self._thrust.get(ns)
        if body is None or thrust is None:
            return None
        del self._body[ns], self._thrust[ns]
        later = body if body.t >= thrust.t else thrust
        name, msg = body.msg
        return attitude_setpoint(
            name, msg, float(thrust.msg.thrust), self.options, later.t, ns, later.where
        )


def _local(
    t: float,
    ns: str,
    where: Where,
    header: Any | None,
    *,
    frame: int,
    mask: int,
    position: tuple[float, float, float] = (0.0, 0.0, 0.0),
    velocity: tuple[float, float, float] = (0.0, 0.0, 0.0),
    acceleration: tuple[float, float, float] = (0.0, 0.0, 0.0),
    yaw: float = 0.0,
    yaw_rate: float = 0.0,
) -> SetPositionTargetLocal:
    return SetPositionTargetLocal(
        t=t,
        vehicle=ns,
        where=where,
        sender_time_us=None if header is None else stamp_to_time_boot_us(header),
        target_system=MAVROS_TARGET_SYSTEM,
        target_component=MAVROS_TARGET_COMPONENT,
        type_mask=mask,
        transport="mavros",
        coordinate_frame=frame,
        position=position,
        velocity=velocity,
        acceleration=acceleration,
        yaw=yaw,
        yaw_rate=yaw_rate,
    )


def raw_local(
    msg: Any, options: MavrosOptions, t: float, ns: str, where: Where
) -> SetPositionTargetLocal:
    """``setpoint_raw/local`` (PositionTarget): frame and type_mask passed through.

    Body frames rotate FLU -> FRD (yaw changes sign), the others ENU -> NED (yaw becomes
    pi/2 - yaw); the yaw rate changes sign either way (MAVROS applies ENU -> NED to it).
    """
    frame = int(msg.coordinate_frame)
    p, v, a = msg.position, msg.velocity, msg.acceleration_or_force
    if frame in BODY_FRAMES:
        position, velocity = (p.x, -p.y, -p.z), (v.x, -v.y, -v.z)
        acceleration, yaw = (a.x, -a.y, -a.z), yaw_flu_to_frd(msg.yaw)
    else:  # inlined enu_to_ned and yaw_enu_to_ned: this is the hot path of a MAVROS bag
        position, velocity = (p.y, p.x, -p.z), (v.y, v.x, -v.z)
        yaw = msg.yaw
        acceleration, yaw = (a.y, a.x, -a.z), _atan2(_cos(yaw), _sin(yaw))
    stamp = msg.header.stamp  # inlined stamp_to_time_boot_us
    ns_stamp = int(stamp.sec) * 1_000_000_000 + int(stamp.nanosec)
    boot_us = ((ns_stamp // 1_000_000) & 0xFFFFFFFF) * 1000 if ns_stamp > 0 else None
    return SetPositionTargetLocal(
        t=t,
        vehicle=ns,
        where=where,
        sender_time_us=boot_us,
        target_system=MAVROS_TARGET_SYSTEM,
        target_component=MAVROS_TARGET_COMPONENT,
        type_mask=int(msg.type_mask),
        transport="mavros",
        coordinate_frame=frame,
        position=position,
        velocity=velocity,
        acceleration=acceleration,
        yaw=yaw,
        yaw_rate=-msg.yaw_rate,
    )


def raw_global(
    msg: Any, options: MavrosOptions, t: float, ns: str, where: Where
) -> SetPositionTargetGlobal:
    """``setpoint_raw/global`` (GlobalPositionTarget): lat/lon x 1e7, altitude as given."""
    return SetPositionTargetGlobal(
        t=t,
        vehicle=ns,
        where=where,
        sender_time_us=stamp_to_time_boot_us(msg.header),
        target_system=MAVROS_TARGET_SYSTEM,
        target_component=MAVROS_TARGET_COMPONENT,
        type_mask=int(msg.type_mask),
        transport="mavros",
        coordinate_frame=int(msg.coordinate_frame),
        lat_int=_to_int32(float(msg.latitude) * 1e7),
        lon_int=_to_int32(float(msg.longitude) * 1e7),
        alt=float(msg.altitude),
        velocity=enu_to_ned(_vec(msg.velocity)),
        acceleration=enu_to_ned(_vec(msg.acceleration_or_force)),
        yaw=yaw_enu_to_ned(float(msg.yaw)),
        yaw_rate=-float(msg.yaw_rate),
    )


def _to_int32(value: float) -> int:
    """C++'s double -> int32_t conversion (truncation toward zero; NaN/overflow give 0 here)."""
    if not math.isfinite(value) or abs(value) >= 2**31:
        return 0
    return int(value)


def raw_attitude(
    msg: Any, options: MavrosOptions, t: float, ns: str, where: Where
) -> SetAttitudeTarget | None:
    """``setpoint_raw/attitude`` (AttitudeTarget): thrust x ``thrust_scaling``, clamped to [0, 1].

    Dropped when the thrust is non-zero and ``thrust_scaling`` is unset (MAVROS logs an error).
    """
    thrust = float(msg.thrust)
    scaling = options.thrust_scaling
    if scaling is None:
        if thrust != 0.0:
            return None
        scaling = 1.0
    scaled = thrust * scaling
    rates = flu_to_frd(_vec(msg.body_rate))
    return SetAttitudeTarget(
        t=t,
        vehicle=ns,
        where=where,
        sender_time_us=stamp_to_time_boot_us(msg.header),
        target_system=MAVROS_TARGET_SYSTEM,
        target_component=MAVROS_TARGET_COMPONENT,
        type_mask=int(msg.type_mask),
        transport="mavros",
        q=orientation_enu_to_ned(_quat(msg.orientation)),
        body_roll_rate=rates[0],
        body_pitch_rate=rates[1],
        body_yaw_rate=rates[2],
        thrust=scaled if math.isnan(scaled) else min(1.0, max(0.0, scaled)),
    )


def position_local(
    msg: Any, options: MavrosOptions, t: float, ns: str, where: Where
) -> SetPositionTargetLocal:
    """``setpoint_position/local`` (PoseStamped): position + yaw, mask 0x9F8. The orientation
    goes through Eigen as MAVROS's does (``pose_rotation``: an all-zero one is the identity)."""
    pose = msg.pose
    q = pose_rotation(_quat(pose.orientation))
    if options.mav_frame in BODY_FRAMES:
        position = flu_to_frd(_vec(pose.position))
        yaw = quat_yaw(quat_mul(AIRCRAFT_BASELINK_Q, q))
    else:
        position = enu_to_ned(_vec(pose.position))
        yaw = quat_yaw(orientation_enu_to_ned(q))
    return _local(
        t,
        ns,
        where,
        msg.header,
        frame=options.mav_frame,
        mask=MASK_POSITION_YAW,
        position=position,
        yaw=yaw,
    )


def _velocity(
    header: Any | None,
    twist: Any,
    options: MavrosOptions,
    t: float,
    ns: str,
    where: Where,
) -> SetPositionTargetLocal:
    body = options.mav_frame in BODY_FRAMES
    linear = _vec(twist.linear)
    yaw_rate = float(twist.angular.z)
    return _local(
        t,
        ns,
        where,
        header,
        frame=options.mav_frame,
        mask=MASK_VELOCITY_YAW_RATE,
        velocity=flu_to_frd(linear) if body else enu_to_ned(linear),
        yaw_rate=-yaw_rate,
    )


def velocity_stamped(
    msg: Any, options: MavrosOptions, t: float, ns: str, where: Where
) -> SetPositionTargetLocal:
    """``setpoint_velocity/cmd_vel`` (TwistStamped): velocity + yaw rate, mask 0x5C7."""
    return _velocity(msg.header, msg.twist, options, t, ns, where)


def velocity_unstamped(
    msg: Any, options: MavrosOptions, t: float, ns: str, where: Where
) -> SetPositionTargetLocal:
    """``setpoint_velocity/cmd_vel_unstamped`` (Twist): as cmd_vel, stamped "now" by MAVROS."""
    return _velocity(None, msg, options, t, ns, where)


def accel(
    msg: Any, options: MavrosOptions, t: float, ns: str, where: Where
) -> SetPositionTargetLocal:
    """``setpoint_accel/accel`` (Vector3Stamped): acceleration only, LOCAL_NED, mask 0xC3F."""
    mask = MASK_ACCEL | (MASK_FORCE if options.send_force else 0)
    return _local(
        t,
        ns,
        where,
        msg.header,
        frame=FRAME_LOCAL_NED,
        mask=mask,
        acceleration=enu_to_ned(_vec(msg.vector)),
    )


def attitude_setpoint(
    name: str,
    msg: Any,
    thrust: float,
    options: MavrosOptions,
    t: float,
    ns: str,
    where: Where,
) -> SetAttitudeTarget | None:
    """``setpoint_attitude/attitude`` or ``cmd_vel`` paired with a ``thrust`` message.

    A thrust outside [0, 1] ([-1, 1] with ``reverse_thrust``) is dropped by MAVROS. The rates
    of ``cmd_vel`` go through MAVROS's ENU <-> NED swap (x and y exchanged, z negated), not
    FLU -> FRD: that is what MAVROS 1 and 2 do.
    """
    low = -1.0 if options.reverse_thrust else 0.0
    if not low <= thrust <= 1.0:
        return None
    common: dict[str, Any] = {
        "t": t,
        "vehicle": ns,
        "where": where,
        "sender_time_us": stamp_to_time_boot_us(msg.header),
        "target_system": MAVROS_TARGET_SYSTEM,
        "target_component": MAVROS_TARGET_COMPONENT,
        "transport": "mavros",
        "thrust": thrust,
    }
    if name == "setpoint_attitude/attitude":
        return SetAttitudeTarget(
            type_mask=MASK_ATTITUDE_THRUST,
            q=orientation_enu_to_ned(_quat(msg.pose.orientation)),
            **common,
        )
    rates = enu_to_ned(_vec(msg.twist.angular))
    return SetAttitudeTarget(
        type_mask=MASK_RATES_THRUST,
        q=(1.0, 0.0, 0.0, 0.0),
        body_roll_rate=rates[0],
        body_pitch_rate=rates[1],
        body_yaw_rate=rates[2],
        **common,
    )


def state_to_status(msg: Any, *, t: float, vehicle: str, where: Where) -> VehicleStatus:
    """``/mavros/state`` (State) -> ``VehicleStatus``: mode string mapped to ``nav_state``.

    While MAVROS is not connected to the autopilot the mode is unknown (``nav_state`` None).
    """
    mode = str(msg.mode)
    connected = bool(msg.connected)
    return VehicleStatus(
        t=t,
        vehicle=vehicle,
        where=where,
        nav_state=mavros_mode_to_nav_state(mode) if connected else None,
        mode=mode,
        armed=bool(msg.armed) if connected else None,
    )


Converter = Callable[[Any, MavrosOptions, float, str, Where], Event | None]

_CONVERTERS: dict[str, Converter] = {
    "setpoint_raw/local": raw_local,
    "setpoint_raw/global": raw_global,
    "setpoint_raw/attitude": raw_attitude,
    "setpoint_position/local": position_local,
    "setpoint_velocity/cmd_vel": velocity_stamped,
    "setpoint_velocity/cmd_vel_unstamped": velocity_unstamped,
    "setpoint_accel/accel": accel,
}
