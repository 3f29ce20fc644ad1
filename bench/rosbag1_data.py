"""Synthetic ROS 1 bags for the rosbag1 benchmark, fast to make at a million messages.

Each message is serialised by rosbags once (a few hundred variants per topic) and the bytes are
reused; only the record time changes. The stream is a MAVROS offboard flight: 50 Hz
``setpoint_raw/local`` and a 1 Hz ``/mavros/state`` (POSCTL, then OFFBOARD after 2 s of
setpoints). The mixed bag has 20 Hz setpoints beside a 200 Hz IMU and a 2 Hz 16 kB camera
image, so that the MAVROS topics are under 10 % of the messages (about 9.5 %).
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np
from rosbags.rosbag1 import Writer

from fuzzoff.formats.rosbag1.writer import DEFAULT_START_NS, mavros_typestore

VARIANTS = 256
SETPOINT_PERIOD_NS = 20_000_000
MIXED_SETPOINT_PERIOD_NS = 50_000_000
IMU_PERIOD_NS = 5_000_000
IMAGE_PERIOD_NS = 500_000_000
STATE_PERIOD_NS = 1_000_000_000


def _setpoints(store: Any) -> list[bytes]:
    t = store.types
    out = []
    for i in range(VARIANTS):
        msg = t["mavros_msgs/msg/PositionTarget"](
            header=t["std_msgs/msg/Header"](
                seq=i, stamp=t["builtin_interfaces/msg/Time"](sec=i, nanosec=0), frame_id=""
            ),
            coordinate_frame=1,
            type_mask=0x09F8,
            position=t["geometry_msgs/msg/Point"](x=0.01 * i, y=0.0, z=2.5),
            velocity=t["geometry_msgs/msg/Vector3"](x=0.0, y=0.0, z=0.0),
            acceleration_or_force=t["geometry_msgs/msg/Vector3"](x=0.0, y=0.0, z=0.0),
            yaw=0.0,
            yaw_rate=0.0,
        )
        out.append(store.serialize_ros1(msg, "mavros_msgs/msg/PositionTarget"))
    return out


def _state(store: Any, mode: str) -> bytes:
    t = store.types
    msg = t["mavros_msgs/msg/State"](
        header=t["std_msgs/msg/Header"](
            seq=0, stamp=t["builtin_interfaces/msg/Time"](sec=0, nanosec=0), frame_id=""
        ),
        connected=True,
        armed=True,
        guided=True,
        manual_input=False,
        mode=mode,
        system_status=4,
    )
    return bytes(store.serialize_ros1(msg, "mavros_msgs/msg/State"))


def _imu(store: Any) -> list[bytes]:
    t = store.types
    vec = t["geometry_msgs/msg/Vector3"]
    out = []
    for i in range(VARIANTS):
        msg = t["sensor_msgs/msg/Imu"](
            header=t["std_msgs/msg/Header"](
                seq=i, stamp=t["builtin_interfaces/msg/Time"](sec=i, nanosec=0), frame_id="imu"
            ),
            orientation=t["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=0.0, w=1.0),
            orientation_covariance=np.zeros(9),
            angular_velocity=vec(x=0.001 * i, y=0.0, z=0.0),
            angular_velocity_covariance=np.zeros(9),
            linear_acceleration=vec(x=0.0, y=0.0, z=9.81),
            linear_acceleration_covariance=np.zeros(9),
        )
        out.append(store.serialize_ros1(msg, "sensor_msgs/msg/Imu"))
    return out


def _image(store: Any) -> bytes:

    t = store.types
    msg = t["sensor_msgs/msg/Image"](
        header=t["std_msgs/msg/Header"](
            seq=0, stamp=t["builtin_interfaces/msg/Time"](sec=0, nanosec=0), frame_id="cam"
        ),
        height=64,
        width=256,
        encoding="mono8",
        is_bigendian=0,
        step=256,
        data=np.zeros(64 * 256, dtype=np.uint8),
    )
    return bytes(store.serialize_ros1(msg, "sensor_msgs/msg/Image"))


def generate(path: Path, messages: int, mixed: bool = False) -> Path:
    """A bag of about ``messages`` messages at ``path`` (reused if it exists)."""
    if path.exists():
        return path
    path.parent.mkdir(parents=True, exist_ok=True)
    store = mavros_typestore()
    setpoints = _setpoints(store)
    posctl, offboard = _state(store, "POSCTL"), _state(store, "OFFBOARD")
    tmp = path.with_name(f".{path.name}.{os.getpid()}.partial")
    tmp.unlink(missing_ok=True)
    with Writer(tmp) as writer:
        sp = writer.add_connection(
            "/mavros/setpoint_raw/local", "mavros_msgs/msg/PositionTarget", typestore=store
        )
        st = writer.add_connection(
            "/mavros/state", "mavros_msgs/msg/State", typestore=store, latching=1
        )
        imu_conn = img_conn = None
        imu: list[bytes] = []
        image = b""
        if mixed:
            imu_conn = writer.add_connection("/imu/data", "sensor_msgs/msg/Imu", typestore=store)
            img_conn = writer.add_connection(
                "/camera/image_raw", "sensor_msgs/msg/Image", typestore=store
            )
            imu, image = _imu(store), _image(store)
        step = IMU_PERIOD_NS if mixed else SETPOINT_PERIOD_NS
        period = MIXED_SETPOINT_PERIOD_NS if mixed else SETPOINT_PERIOD_NS
        count = 0
        tick = 0
        while count < messages:
            now = DEFAULT_START_NS + tick * step
            since = tick * step
            if since % STATE_PERIOD_NS == 0:
                mode = offboard if since >= 3 * STATE_PERIOD_NS else posctl
                writer.write(st, now, mode)
                count += 1
            if since >= STATE_PERIOD_NS and since % period == 0:
                writer.write(sp, now, setpoints[tick % VARIANTS])
                count += 1
            if imu_conn is not None and img_conn is not None:
                writer.write(imu_conn, now, imu[tick % VARIANTS])
                count += 1
                if since % IMAGE_PERIOD_NS == 0:
                    writer.write(img_conn, now, image)
                    count += 1
            tick += 1
    tmp.rename(path)
    return path
