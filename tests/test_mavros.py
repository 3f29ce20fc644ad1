"""MAVROS topic -> MAVLink setpoint conversion, against hand-computed values (formats.md 6.1)."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import pytest
from rosbags.typesys import Stores, get_typestore

from fuzzoff.events import (
    SetAttitudeTarget,
    SetPositionTargetGlobal,
    SetPositionTargetLocal,
    VehicleStatus,
)
from fuzzoff.formats import open_source
from fuzzoff.formats.mavros.convert import (
    MavrosConverter,
    MavrosOptions,
    mavros_topic,
    split_topic,
)
from fuzzoff.formats.mavros.frames import (
    AIRCRAFT_BASELINK_Q,
    orientation_enu_to_ned,
    quat_from_rpy,
    quat_mul,
    quat_yaw,
    yaw_enu_to_ned,
    yaw_flu_to_frd,
)
from fuzzoff.formats.mavros.mavros_msgs import mavros_typedefs
from fuzzoff.formats.rosbag1.writer import mavros_typestore
from tests.helpers import CORPORA

ROS1 = mavros_typestore()
T = ROS1.types
S = math.sqrt(0.5)
ONE = (1.0, 0.0, 0.0, 0.0)
"""The identity quaternion (w, x, y, z)."""


def header(sec: int = 0, nsec: int = 0) -> Any:
    return T["std_msgs/msg/Header"](
        seq=0, stamp=T["builtin_interfaces/msg/Time"](sec=sec, nanosec=nsec), frame_id=""
    )


def vec(x: float, y: float, z: float) -> Any:
    return T["geometry_msgs/msg/Vector3"](x=x, y=y, z=z)


def quat(w: float, x: float, y: float, z: float) -> Any:
    return T["geometry_msgs/msg/Quaternion"](x=x, y=y, z=z, w=w)


def pose(p: tuple[float, float, float], q: tuple[float, float, float, float]) -> Any:
    return T["geometry_msgs/msg/PoseStamped"](
        header=header(1),
        pose=T["geometry_msgs/msg/Pose"](
            position=T["geometry_msgs/msg/Point"](x=p[0], y=p[1], z=p[2]), orientation=quat(*q)
        ),
    )


def twist(linear: tuple[float, ...], angular: tuple[float, ...]) -> Any:
    return T["geometry_msgs/msg/Twist"](linear=vec(*linear), angular=vec(*angular))


def position_target(frame: int, **kw: Any) -> Any:
    fields: dict[str, Any] = {
        "header": header(12, 345_678_900),
        "coordinate_frame": frame,
        "type_mask": 0,
        "position": T["geometry_msgs/msg/Point"](x=0.0, y=0.0, z=0.0),
        "velocity": vec(0, 0, 0),
        "acceleration_or_force": vec(0, 0, 0),
        "yaw": 0.0,
        "yaw_rate": 0.0,
    }
    fields.update(kw)
    return T["mavros_msgs/msg/PositionTarget"](**fields)


def one(topic: str, msg: Any, converter: MavrosConverter | None = None) -> Any:
    events = (converter or MavrosConverter()).convert(topic, msg, 1.5, 7)
    assert len(events) == 1
    return events[0]


def close(a: tuple[float, ...], b: tuple[float, ...], tol: float = 1e-9) -> bool:
    return len(a) == len(b) and all(abs(x - y) <= tol for x, y in zip(a, b, strict=True))


def same_rotation(a: tuple[float, ...], b: tuple[float, ...]) -> bool:
    return close(a, b, 1e-9) or close(a, tuple(-x for x in b), 1e-9)


def test_raw_local_enu_becomes_ned_with_mask_and_frame_passed_through() -> None:
    msg = position_target(
        1,
        type_mask=0x0DF8 & ~0x400,
        position=T["geometry_msgs/msg/Point"](x=1.0, y=2.0, z=3.0),
        velocity=vec(0.5, -1.0, 0.25),
        acceleration_or_force=vec(0.0, 0.0, 9.0),
        yaw=0.0,
        yaw_rate=0.25,
    )
    e = one("/mavros/setpoint_raw/local", msg)
    assert isinstance(e, SetPositionTargetLocal)
    assert e.position == (2.0, 1.0, -3.0)
    assert e.velocity == (-1.0, 0.5, -0.25)
    assert e.acceleration == (0.0, 0.0, -9.0)
    assert e.yaw == pytest.approx(math.pi / 2)  # facing east: ENU 0, NED +90 deg
    assert e.yaw_rate == -0.25
    assert e.type_mask == 0x09F8
    assert e.coordinate_frame == 1
    assert (e.target_system, e.target_component, e.transport) == (1, 1, "mavros")
    assert e.sender_time_us == 12_345_000  # time_boot_ms = stamp in ms
    assert (e.t, e.vehicle, e.where.topic, e.where.index) == (
        1.5,
        "",
        "/mavros/setpoint_raw/local",
        7,
    )


@pytest.mark.parametrize(
    ("yaw_enu", "yaw_ned"),
    [
        (math.pi / 2, 0.0),
        (math.pi, -math.pi / 2),
        (-math.pi / 2, math.pi),
        (0.3, math.pi / 2 - 0.3),
    ],
)
def test_raw_local_yaw_is_pi_half_minus_enu_yaw_wrapped(yaw_enu: float, yaw_ned: float) -> None:
    e = one("/mavros/setpoint_raw/local", position_target(1, yaw=yaw_enu))
    assert -math.pi <= e.yaw <= math.pi
    assert abs(math.remainder(e.yaw - yaw_ned, 2 * math.pi)) < 1e-6


def test_raw_local_body_frame_is_flu_to_frd() -> None:
    msg = position_target(8, type_mask=0x05C7, velocity=vec(1.0, 2.0, 3.0), yaw=0.4, yaw_rate=0.1)
    e = one("/mavros/setpoint_raw/local", msg)
    assert e.velocity == (1.0, -2.0, -3.0)
    assert e.yaw == pytest.approx(-0.4, abs=1e-6)
    assert e.yaw_rate == pytest.approx(-0.1, abs=1e-6)
    assert e.coordinate_frame == 8


def test_raw_global_scales_lat_lon_and_rotates_velocity() -> None:
    msg = T["mavros_msgs/msg/GlobalPositionTarget"](
        header=header(),
        coordinate_frame=6,
        type_mask=0x0FF8,
        latitude=47.397742,
        longitude=-8.545594,
        altitude=488.5,
        velocity=vec(1.0, 2.0, 3.0),
        acceleration_or_force=vec(0, 0, 0),
        yaw=math.pi / 2,
        yaw_rate=0.0,
    )
    e = one("/uav1/mavros/setpoint_raw/global", msg)
    assert isinstance(e, SetPositionTargetGlobal)
    assert abs(e.lat_int - 473977420) <= 1 and abs(e.lon_int + 85455940) <= 1
    assert e.alt == 488.5
    assert e.velocity == (2.0, 1.0, -3.0)
    assert e.yaw == pytest.approx(0.0, abs=1e-6)
    assert (e.coordinate_frame, e.type_mask, e.vehicle) == (6, 0x0FF8, "/uav1")
    assert e.sender_time_us is None  # zero stamp: no sender clock


def attitude_target(q: tuple[float, ...], thrust: float, mask: int = 0) -> Any:
    return T["mavros_msgs/msg/AttitudeTarget"](
        header=header(),
        type_mask=mask,
        orientation=quat(*q),
        body_rate=vec(0.1, 0.2, 0.3),
        thrust=thrust,
    )


def test_raw_attitude_level_east_is_ned_yaw_90_and_rates_frd() -> None:
    e = one("/mavros/setpoint_raw/attitude", attitude_target((1, 0, 0, 0), 0.7, 7))
    assert isinstance(e, SetAttitudeTarget)
    assert same_rotation(e.q, (S, 0.0, 0.0, S))
    assert (e.body_roll_rate, e.body_pitch_rate, e.body_yaw_rate) == (0.1, -0.2, -0.3)
    assert e.thrust == pytest.approx(0.7) and e.type_mask == 7


def test_raw_attitude_nose_up_pitch_keeps_its_sign_in_frd() -> None:
    # ENU base_link pitched 30 deg nose-up facing north (yaw 90): FLU pitch about +y is nose-down,
    # so nose-up is a negative rotation about y; in NED/FRD nose-up is positive pitch.
    half = math.radians(-30) / 2
    q_pitch = (math.cos(half), 0.0, math.sin(half), 0.0)
    q_yaw = (math.cos(math.pi / 4), 0.0, 0.0, math.sin(math.pi / 4))
    e = one("/mavros/setpoint_raw/attitude", attitude_target(quat_mul(q_yaw, q_pitch), 0.5))
    w, x, y, z = e.q
    pitch = math.asin(max(-1.0, min(1.0, 2 * (w * y - z * x))))
    assert pitch == pytest.approx(math.radians(30), abs=1e-9)
    assert abs(math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))) < 1e-9  # north


def test_raw_attitude_thrust_scaled_clamped_or_dropped() -> None:
    assert one("/mavros/setpoint_raw/attitude", attitude_target((1, 0, 0, 0), 1.5)).thrust == 1.0
    half = MavrosConverter(MavrosOptions(thrust_scaling=0.5))
    assert one(
        "/mavros/setpoint_raw/attitude", attitude_target((1, 0, 0, 0), 0.8), half
    ).thrust == (pytest.approx(0.4))
    unset = MavrosConverter(MavrosOptions(thrust_scaling=None))
    assert (
        unset.convert("/mavros/setpoint_raw/attitude", attitude_target((1, 0, 0, 0), 0.5), 0) == []
    )
    assert (
        len(unset.convert("/mavros/setpoint_raw/attitude", attitude_target((1, 0, 0, 0), 0), 0))
        == 1
    )


def test_setpoint_position_local_sets_position_and_yaw_mask() -> None:
    e = one("/mavros/setpoint_position/local", pose((1.0, 2.0, 3.0), (S, 0.0, 0.0, S)))
    assert e.type_mask == 0x09F8
    assert e.position == (2.0, 1.0, -3.0)
    assert e.yaw == pytest.approx(0.0, abs=1e-9)  # ENU yaw 90 deg = north = NED yaw 0
    assert e.velocity == (0.0, 0.0, 0.0) and e.coordinate_frame == 1
    assert e.sender_time_us == 1_000_000


def test_local_position_pose_is_the_vehicle_position_in_ned_once_a_second() -> None:
    # MAVROS publishes PX4's LOCAL_POSITION_NED in ENU; OFB404 reads it back in NED
    converter = MavrosConverter()
    first = converter.convert("/uav1/mavros/local_position/pose", pose((1.0, 2.0, -1.78), ONE), 3.0)
    (e,) = first
    assert (e.kind, e.vehicle, (e.x, e.y, e.z)) == ("vehicle_position", "/uav1", (2.0, 1.0, 1.78))
    later = [
        converter.convert("/uav1/mavros/local_position/pose", pose((0, 0, 0), ONE), t)
        for t in (3.5, 4.0)
    ]
    assert [len(events) for events in later] == [0, 1]
    every = MavrosConverter(position_period_s=0.0)  # the HTML report's plots
    assert every.convert("/mavros/local_position/pose", pose((0, 0, 0), ONE), 3.5)


def _local_setpoints(path: Path) -> list[Any]:
    with open_source(path) as source:
        source.probe()
        return [e for e in source.events() if e.kind == "set_position_target_local_ned"]


def test_an_unset_orientation_is_sent_as_mavros_sends_it() -> None:
    # the PX4 docs' offb_node never sets the pose's orientation: all zero in ROS 1. MAVROS
    # turns it into an Eigen transform, whose rotation is the identity: yaw pi/2 in NED, as the
    # SET_POSITION_TARGET_LOCAL_NED PX4 received in the same example's run shows
    bag = _local_setpoints(CORPORA / "examples" / "mavros_offb_node.bag")
    received = _local_setpoints(CORPORA / "examples" / "runs" / "mavros_offb_node.tlog")
    assert {round(e.yaw, 6) for e in bag} == {round(e.yaw, 6) for e in received} == {1.570796}
    assert {e.position for e in bag} == {e.position for e in received}


def test_a_pose_orientation_of_another_length_is_the_rotation_nearest_eigens_matrix() -> None:
    # a yaw of 2.9 rad in ENU scaled to length 0.3: Eigen's matrix is 0.91 I + 0.09 R, whose
    # rotation factor turns by atan2(0.09 sin 2.9, 0.91 + 0.09 cos 2.9) about the same axis
    half = 2.9 / 2
    scaled = (0.3 * math.cos(half), 0.0, 0.0, 0.3 * math.sin(half))
    e = one("/mavros/setpoint_position/local", pose((0.0, 0.0, 2.0), scaled))
    turned = math.atan2(0.09 * math.sin(2.9), 0.91 + 0.09 * math.cos(2.9))
    assert e.yaw == pytest.approx(math.pi / 2 - turned, abs=1e-9)
    unit = one("/mavros/setpoint_position/local", pose((0.0, 0.0, 2.0), (S, 0.0, 0.0, S)))
    assert unit.yaw == pytest.approx(0.0, abs=1e-9)  # a unit quaternion is used as it is


def test_setpoint_velocity_stamped_and_unstamped() -> None:
    stamped = T["geometry_msgs/msg/TwistStamped"](
        header=header(2), twist=twist((1.0, 0.0, 0.5), (0.0, 0.0, 0.5))
    )
    e = one("/mavros/setpoint_velocity/cmd_vel", stamped)
    assert e.type_mask == 0x05C7
    assert e.velocity == (0.0, 1.0, -0.5)  # east -> NED y
    assert e.yaw_rate == -0.5
    assert e.sender_time_us == 2_000_000
    u = one("/mavros/setpoint_velocity/cmd_vel_unstamped", twist((1.0, 0.0, 0.0), (0, 0, 0)))
    assert u.type_mask == 0x05C7 and u.velocity == (0.0, 1.0, -0.0) and u.sender_time_us is None


def test_setpoint_velocity_body_frame_option() -> None:
    body = MavrosConverter(MavrosOptions(mav_frame=8))
    msg = T["geometry_msgs/msg/TwistStamped"](header=header(), twist=twist((1, 2, 3), (0, 0, 1)))
    e = one("/mavros/setpoint_velocity/cmd_vel", msg, body)
    assert (e.velocity, e.coordinate_frame, e.yaw_rate) == ((1.0, -2.0, -3.0), 8, -1.0)


def test_setpoint_accel_is_acceleration_only() -> None:
    msg = T["geometry_msgs/msg/Vector3Stamped"](header=header(), vector=vec(1.0, 0.0, 2.0))
    e = one("/mavros/setpoint_accel/accel", msg)
    assert (e.type_mask, e.coordinate_frame, e.acceleration) == (0x0C3F, 1, (0.0, 1.0, -2.0))
    force = MavrosConverter(MavrosOptions(send_force=True))
    assert one("/mavros/setpoint_accel/accel", msg, force).type_mask == 0x0E3F


def thrust(value: float) -> Any:
    return T["mavros_msgs/msg/Thrust"](header=header(), thrust=value)


def test_setpoint_attitude_needs_its_thrust_partner() -> None:
    conv = MavrosConverter()
    assert (
        conv.convert("/mavros/setpoint_attitude/attitude", pose((0, 0, 0), (1, 0, 0, 0)), 1.0) == []
    )
    (e,) = conv.convert("/mavros/setpoint_attitude/thrust", thrust(0.6), 1.01)
    assert isinstance(e, SetAttitudeTarget)
    assert e.type_mask == 7 and e.thrust == pytest.approx(0.6) and e.t == 1.01
    assert same_rotation(e.q, (S, 0.0, 0.0, S))
    assert conv.convert("/mavros/setpoint_attitude/thrust", thrust(0.6), 1.02) == []


def test_setpoint_attitude_out_of_range_thrust_is_dropped() -> None:
    conv = MavrosConverter()
    conv.convert("/mavros/setpoint_attitude/thrust", thrust(1.2), 1.0)
    assert (
        conv.convert("/mavros/setpoint_attitude/attitude", pose((0, 0, 0), (1, 0, 0, 0)), 1.0) == []
    )


def test_setpoint_attitude_cmd_vel_rates_take_the_enu_ned_swap() -> None:
    conv = MavrosConverter()
    msg = T["geometry_msgs/msg/TwistStamped"](
        header=header(), twist=twist((0, 0, 0), (0.1, 0.2, 0.3))
    )
    conv.convert("/mavros/setpoint_attitude/thrust", thrust(0.5), 1.0)
    (e,) = conv.convert("/mavros/setpoint_attitude/cmd_vel", msg, 1.0)
    assert isinstance(e, SetAttitudeTarget)
    assert e.type_mask == 128 and e.q == (1.0, 0.0, 0.0, 0.0)
    assert (e.body_roll_rate, e.body_pitch_rate, e.body_yaw_rate) == (0.2, 0.1, -0.3)


def state(mode: str, armed: bool, connected: bool = True) -> Any:
    return T["mavros_msgs/msg/State"](
        header=header(),
        connected=connected,
        armed=armed,
        guided=True,
        manual_input=False,
        mode=mode,
        system_status=4,
    )


def test_state_maps_mode_string_to_nav_state() -> None:
    e = one("/drone_2/mavros/state", state("OFFBOARD", True))
    assert isinstance(e, VehicleStatus)
    assert (e.nav_state, e.armed, e.mode, e.vehicle, e.origin) == (
        14,
        True,
        "OFFBOARD",
        "/drone_2",
        "vehicle",
    )
    assert one("/mavros/state", state("AUTO.LOITER", False)).nav_state == 4
    lost = one("/mavros/state", state("", False, connected=False))
    assert lost.nav_state is None and lost.armed is None


def test_topic_names_and_types() -> None:
    assert split_topic("/uav1/mavros/setpoint_raw/local") == ("/uav1", "setpoint_raw/local")
    assert split_topic("/mavros/state") == ("", "state")
    assert split_topic("/camera/image") is None
    assert mavros_topic("/mavros/setpoint_raw/local", "mavros_msgs/PositionTarget")
    assert mavros_topic("/mavros/setpoint_raw/local", "std_msgs/msg/String") is None
    assert mavros_topic("/mavros/imu/data", "sensor_msgs/msg/Imu") is None
    assert MavrosConverter().convert("/mavros/unknown_plugin/x", object(), 0.0) == []


def test_shipped_definitions_decode_ros2_cdr() -> None:
    store = get_typestore(Stores.ROS2_HUMBLE)
    store.register(mavros_typedefs())
    types = store.types
    msg = types["mavros_msgs/msg/PositionTarget"](
        header=types["std_msgs/msg/Header"](
            stamp=types["builtin_interfaces/msg/Time"](sec=3, nanosec=0), frame_id="map"
        ),
        coordinate_frame=1,
        type_mask=0x09F8,
        position=types["geometry_msgs/msg/Point"](x=1.0, y=0.0, z=2.0),
        velocity=types["geometry_msgs/msg/Vector3"](x=0.0, y=0.0, z=0.0),
        acceleration_or_force=types["geometry_msgs/msg/Vector3"](x=0.0, y=0.0, z=0.0),
        yaw=0.0,
        yaw_rate=0.0,
    )
    raw = store.serialize_cdr(msg, "mavros_msgs/msg/PositionTarget")
    decoded = store.deserialize_cdr(raw, "mavros_msgs/msg/PositionTarget")
    e = one("/mavros/setpoint_raw/local", decoded)
    assert e.position == (0.0, 1.0, -2.0) and e.sender_time_us == 3_000_000
    assert set(mavros_typedefs()) >= {
        f"mavros_msgs/msg/{n}"
        for n in ("PositionTarget", "GlobalPositionTarget", "AttitudeTarget", "State", "Thrust")
    }


@pytest.mark.parametrize("yaw", [0.0, 0.3, math.pi / 2, -2.0, 3.0, math.pi, -math.pi, 7.0])
def test_closed_form_yaw_matches_mavros_quaternion_path(yaw: float) -> None:
    """MAVROS rotates a yaw-only quaternion and reads the yaw back; the closed form agrees."""
    via_enu = quat_yaw(orientation_enu_to_ned(quat_from_rpy(0.0, 0.0, yaw)))
    via_body = quat_yaw(quat_mul(AIRCRAFT_BASELINK_Q, quat_from_rpy(0.0, 0.0, yaw)))
    assert abs(math.remainder(yaw_enu_to_ned(yaw) - via_enu, 2 * math.pi)) < 1e-12
    assert abs(math.remainder(yaw_flu_to_frd(yaw) - via_body, 2 * math.pi)) < 1e-12
