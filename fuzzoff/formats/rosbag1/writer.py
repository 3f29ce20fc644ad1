"""Normalised events -> a ROS 1 bag of MAVROS topics, written by ``rosbags.rosbag1.Writer``.

The inverse of ``fuzzoff.formats.mavros.convert``: each MAVLink setpoint event becomes the MAVROS
message that makes MAVROS send exactly that setpoint, on the ``setpoint_raw/*`` topics (the only
ones that carry every field and the ``type_mask`` through unchanged):

* ``SetPositionTargetLocal`` -> ``setpoint_raw/local`` (PositionTarget): NED -> ENU, or FRD ->
  FLU in body frames; yaw back to ENU (pi/2 - yaw) or FLU (-yaw); yaw rate negated;
* ``SetPositionTargetGlobal`` -> ``setpoint_raw/global`` (GlobalPositionTarget);
* ``SetAttitudeTarget`` -> ``setpoint_raw/attitude`` (AttitudeTarget), thrust as is (MAVROS's
  default ``thrust_scaling`` 1.0; thrust outside [0, 1] cannot round-trip, MAVROS clamps it);
* ``VehicleStatus`` -> ``state`` (State) with the MAVROS mode string of ``nav_state``;
* ``LandDetected`` -> ``extended_state`` (ExtendedState): ON_GROUND, IN_AIR or UNDEFINED.

Other events have no MAVROS topic and are left out. The topic namespace is the event's
``vehicle`` when it is a ROS namespace (``/uav1`` -> ``/uav1/mavros``), else ``namespace``.
``header.stamp`` carries ``sender_time_us`` (zero when None, which reads back as None).
A ``/fuzzoff/origin`` message at time 0 keeps the events' clock when the first event is later.

``extra`` messages are written as given, on their own topics: a message a real node published
that the inverse conversion does not produce (``setpoint_position/local`` as the PX4 docs'
``offb_node`` publishes it, ``state`` with MAVROS's own stamp and flags). They are rosbags
message objects of ``mavros_typestore()``'s types.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from pathlib import Path
from typing import Any

from rosbags.rosbag1 import Writer
from rosbags.typesys import Stores, get_typestore

from fuzzoff.events import (
    Event,
    LandDetected,
    SetAttitudeTarget,
    SetPositionTargetGlobal,
    SetPositionTargetLocal,
    VehicleStatus,
)
from fuzzoff.formats.mavros.frames import (
    BODY_FRAMES,
    enu_to_ned,
    flu_to_frd,
    orientation_ned_to_enu,
    wrap_pi,
)
from fuzzoff.formats.mavros.mavros_msgs import mavros_typedefs
from fuzzoff.lean_dataclass import dataclass
from fuzzoff.modes import mavros_mode_to_nav_state, nav_state_to_mavros_mode

DEFAULT_START_NS = 1_735_689_600 * 1_000_000_000
"""2025-01-01 00:00:00 UTC: the bag time of ``t = 0``."""

ORIGIN_TOPIC = "/fuzzoff/origin"

_TOPICS: dict[type[Event], tuple[str, str]] = {
    SetPositionTargetLocal: ("setpoint_raw/local", "mavros_msgs/msg/PositionTarget"),
    SetPositionTargetGlobal: ("setpoint_raw/global", "mavros_msgs/msg/GlobalPositionTarget"),
    SetAttitudeTarget: ("setpoint_raw/attitude", "mavros_msgs/msg/AttitudeTarget"),
    VehicleStatus: ("state", "mavros_msgs/msg/State"),
    LandDetected: ("extended_state", "mavros_msgs/msg/ExtendedState"),
}


@dataclass(frozen=True, slots=True)
class Ros1Message:
    """A message written as it is: ``t`` in seconds of the events' clock, the topic, the ROS
    type name (``geometry_msgs/msg/PoseStamped``) and a rosbags message object of that type."""

    t: float
    topic: str
    msgtype: str
    message: Any


def mavros_typestore() -> Any:
    """ROS 1 Noetic's standard types plus the shipped mavros_msgs."""
    store = get_typestore(Stores.ROS1_NOETIC)
    store.register(mavros_typedefs())
    return store


class _Builder:
    """Builds rosbags message objects from events (one typestore, its classes looked up once)."""

    def __init__(self, store: Any) -> None:
        types = store.types
        self.header = types["std_msgs/msg/Header"]
        self.time = types["builtin_interfaces/msg/Time"]
        self.point = types["geometry_msgs/msg/Point"]
        self.vector = types["geometry_msgs/msg/Vector3"]
        self.quat = types["geometry_msgs/msg/Quaternion"]
        self.local = types["mavros_msgs/msg/PositionTarget"]
        self.glob = types["mavros_msgs/msg/GlobalPositionTarget"]
        self.att = types["mavros_msgs/msg/AttitudeTarget"]
        self.state = types["mavros_msgs/msg/State"]
        self.extended = types["mavros_msgs/msg/ExtendedState"]
        self.seq = 0

    def _header(self, sender_time_us: int | None) -> Any:
        ns = 0 if sender_time_us is None else sender_time_us * 1000
        self.seq += 1
        stamp = self.time(sec=ns // 1_000_000_000, nanosec=ns % 1_000_000_000)
        return self.header(seq=self.seq, stamp=stamp, frame_id="")

    def _v(self, v: tuple[float, float, float]) -> Any:
        return self.vector(x=v[0], y=v[1], z=v[2])

    def build(self, event: Event) -> Any:
        if isinstance(event, SetPositionTargetLocal):
            return self._local(event)
        if isinstance(event, SetPositionTargetGlobal):
            return self._global(event)
        if isinstance(event, SetAttitudeTarget):
            return self._attitude(event)
        if isinstance(event, LandDetected):
            return self._extended(event)
        assert isinstance(event, VehicleStatus)
        return self._status(event)

    def _local(self, e: SetPositionTargetLocal) -> Any:
        body = e.coordinate_frame in BODY_FRAMES
        to_ros = flu_to_frd if body else enu_to_ned  # both are their own inverse
        position = to_ros(e.position)
        return self.local(
            header=self._header(e.sender_time_us),
            coordinate_frame=e.coordinate_frame,
            type_mask=e.type_mask,
            position=self.point(x=position[0], y=position[1], z=position[2]),
            velocity=self._v(to_ros(e.velocity)),
            acceleration_or_force=self._v(to_ros(e.acceleration)),
            yaw=_yaw_to_ros(e.yaw, body),
            yaw_rate=-e.yaw_rate,
        )

    def _global(self, e: SetPositionTargetGlobal) -> Any:
        return self.glob(
            header=self._header(e.sender_time_us),
            coordinate_frame=e.coordinate_frame,
            type_mask=e.type_mask,
            latitude=_degrees(e.lat_int),
            longitude=_degrees(e.lon_int),
            altitude=e.alt,
            velocity=self._v(enu_to_ned(e.velocity)),
            acceleration_or_force=self._v(enu_to_ned(e.acceleration)),
            yaw=_yaw_to_ros(e.yaw, body=False),
            yaw_rate=-e.yaw_rate,
        )

    def _attitude(self, e: SetAttitudeTarget) -> Any:
        w, x, y, z = orientation_ned_to_enu(e.q)
        rates = flu_to_frd((e.body_roll_rate, e.body_pitch_rate, e.body_yaw_rate))
        return self.att(
            header=self._header(e.sender_time_us),
            type_mask=e.type_mask,
            orientation=self.quat(x=x, y=y, z=z, w=w),
            body_rate=self._v(rates),
            thrust=e.thrust,
        )

    def _status(self, e: VehicleStatus) -> Any:
        connected = e.nav_state is not None
        mode = e.mode
        if e.nav_state is not None and mavros_mode_to_nav_state(mode) != e.nav_state:
            mode = nav_state_to_mavros_mode(e.nav_state)
        return self.state(
            header=self._header(None),
            connected=connected,
            armed=bool(e.armed),
            guided=e.nav_state == 14,
            manual_input=False,
            mode=mode if connected else "",
            system_status=4 if e.armed else 3,  # MAV_STATE_ACTIVE / STANDBY
        )

    def _extended(self, e: LandDetected) -> Any:
        state = 0 if e.landed is None else 1 if e.landed else 2  # MAV_LANDED_STATE
        return self.extended(header=self._header(None), vtol_state=0, landed_state=state)


def _degrees(value_1e7: int) -> float:
    """1e-7 degrees -> degrees, half a step away from zero: MAVROS's truncation gives it back."""
    return (value_1e7 + math.copysign(0.5, value_1e7)) / 1e7


def _yaw_to_ros(yaw: float, body: bool) -> float:
    """NED yaw -> ENU (pi/2 - yaw) or FRD -> FLU (-yaw), wrapped as MAVROS would give it back."""
    if math.isnan(yaw):
        return yaw
    return wrap_pi(-yaw if body else math.pi / 2 - yaw)


def topic_for(event: Event, namespace: str) -> tuple[str, str] | None:
    """(topic, message type) the event is written on, or None if MAVROS has none for it."""
    entry = _TOPICS.get(type(event))
    if entry is None:
        return None
    ns = namespace
    if event.vehicle.startswith("/"):
        ns = event.vehicle.rstrip("/") + "/mavros"
    return f"{ns.rstrip('/')}/{entry[0]}", entry[1]


def write_rosbag1(
    path: str | Path,
    events: Iterable[Event],
    namespace: str = "/mavros",
    *,
    start_ns: int = DEFAULT_START_NS,
    chunk_threshold: int | None = None,
    extra: Iterable[Ros1Message] = (),
) -> Path:
    """Write the MAVROS-expressible ``events`` (in time order) and the ``extra`` messages as a
    ROS 1 bag, in time order; returns the path."""
    path = Path(path)
    if path.exists():
        path.unlink()  # rosbags refuses to overwrite
    store = mavros_typestore()
    builder = _Builder(store)
    writer = Writer(path)
    if chunk_threshold is not None:
        writer.chunk_threshold = chunk_threshold
    connections: dict[str, Any] = {}
    items: list[tuple[float, str, str, Any]] = []
    for event in events:
        target = topic_for(event, namespace)
        if target is not None:
            items.append((event.t, target[0], target[1], event))
    items.extend((m.t, m.topic, m.msgtype, m.message) for m in extra)
    items.sort(key=lambda item: item[0])  # stable: events keep their order at equal times
    with writer:
        if items and items[0][0] > 0:
            origin = writer.add_connection(ORIGIN_TOPIC, "std_msgs/msg/Empty", typestore=store)
            empty = store.types["std_msgs/msg/Empty"]()
            writer.write(origin, start_ns, store.serialize_ros1(empty, "std_msgs/msg/Empty"))
        for t, topic, msgtype, item in items:
            conn = connections.get(topic)
            if conn is None:
                conn = connections[topic] = writer.add_connection(
                    topic, msgtype, typestore=store, latching=1 if topic.endswith("/state") else 0
                )
            message = builder.build(item) if isinstance(item, Event) else item
            raw = store.serialize_ros1(message, msgtype)
            writer.write(conn, start_ns + round(t * 1e9), raw)
    return path
