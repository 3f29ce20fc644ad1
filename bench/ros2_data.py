"""Generated ROS 2 recordings for ``bench_ros2`` (MCAP, rosbag2 sqlite3, rosbag2 mcap).

PX4 topics: ``OffboardControlMode`` and ``TrajectorySetpoint`` at 50 Hz each, ``VehicleStatus``
at 2 Hz, one accepted switch to offboard at 2 s (px4_msgs main). The mixed recordings have
the two PX4 topics at 20 Hz beside ``sensor_msgs/Imu`` at 400 Hz and 20 kB
``sensor_msgs/Image`` frames at 30 Hz: PX4 topics are 9 % of the messages. Payloads are
encoded once per topic and only their ``timestamp`` bytes change (fast to generate; the
content is not what is measured); every camera frame has its own noise.
"""

from __future__ import annotations

import random
import shutil
import struct
from pathlib import Path

from rosbags.typesys import Stores, get_typestore

from fuzzoff.events import Command, CommandAck, ControlMode, TrajectorySetpoint, VehicleStatus
from fuzzoff.formats.mcap.writer import write_mcap
from fuzzoff.formats.ros2msgs.messages import RawMessage, encode, to_message
from fuzzoff.formats.rosbag2.writer import write_rosbag2

PX4_RATE = 50.0
MIXED_PX4_RATE = 20.0
STATUS_PERIOD = 0.5
IMU_RATE = 400.0
CAMERA_RATE = 30.0
IMAGE_BYTES = 20_000


def _with_stamp(template: bytes, stamp_us: int) -> bytes:
    # CDR: 4-byte encapsulation header, then the uint64 timestamp every px4_msgs type starts with.
    return template[:4] + struct.pack("<Q", stamp_us) + template[12:]


def _px4(duration: float, rate: float) -> tuple[list[RawMessage], list[object]]:
    """PX4 topics as raw messages (templated) plus the few events written normally."""
    ocm = to_message(ControlMode(t=0.0, position=True), "main")
    tsp = to_message(TrajectorySetpoint(t=0.0, position=(0.0, 0.0, -2.0), yaw=0.0), "main")
    raw: list[RawMessage] = []
    for msg in (ocm, tsp):
        template = encode(msg)
        text = _definition(msg.message)
        offset = 0.0 if msg is ocm else 0.002
        for k in range(int(duration * rate)):
            t = k / rate + offset
            data = _with_stamp(template, round(t * 1e6))
            raw.append(RawMessage(t, msg.topic, msg.typename, text, data))
    events: list[object] = [
        Command(t=2.0, command=176, params=(1, 6, 0, 0, 0, 0, 0), target_system=1),
        CommandAck(t=2.01, command=176, result=0),
    ]
    k = 0
    while (t := k * STATUS_PERIOD) < duration:
        nav = 14 if t >= 2.02 else 2
        events.append(VehicleStatus(t=t, nav_state=nav, armed=True, vehicle_type=1))
        k += 1
    return raw, events


def _definition(message: str) -> str:
    from fuzzoff.formats import px4_msgs

    text = px4_msgs.definition("main", message)
    assert text is not None
    return text


def _sensors(duration: float) -> list[RawMessage]:
    store = get_typestore(Stores.ROS2_HUMBLE)
    types = store.types
    stamp = types["builtin_interfaces/msg/Time"](sec=0, nanosec=0)
    header = types["std_msgs/msg/Header"](stamp=stamp, frame_id="imu")
    vec = types["geometry_msgs/msg/Vector3"](x=0.0, y=0.0, z=9.81)
    quat = types["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=0.0, w=1.0)
    import numpy as np

    cov = np.zeros(9, dtype=np.float64)
    imu = types["sensor_msgs/msg/Imu"](
        header=header,
        orientation=quat,
        orientation_covariance=cov,
        angular_velocity=vec,
        angular_velocity_covariance=cov,
        linear_acceleration=vec,
        linear_acceleration_covariance=cov,
    )
    imu_type = "sensor_msgs/msg/Imu"
    imu_data = bytes(store.serialize_cdr(imu, imu_type))
    imu_def, _ = store.generate_msgdef(imu_type, ros_version=2)
    rng = random.Random(0)
    pixels = np.frombuffer(rng.randbytes(IMAGE_BYTES), dtype=np.uint8)
    image = types["sensor_msgs/msg/Image"](
        header=header,
        height=100,
        width=200,
        encoding="mono8",
        is_bigendian=0,
        step=200,
        data=pixels,
    )
    image_type = "sensor_msgs/msg/Image"
    image_data = bytes(store.serialize_cdr(image, image_type))
    image_def, _ = store.generate_msgdef(image_type, ros_version=2)
    out = [
        RawMessage(k / IMU_RATE + 0.0007, "/imu/data", imu_type, imu_def, imu_data)
        for k in range(int(duration * IMU_RATE))
    ]
    # Every frame its own noise (data is the last field), so compression cannot fold them.
    head = image_data[:-IMAGE_BYTES]
    out += [
        RawMessage(
            k / CAMERA_RATE + 0.0013,
            "/camera/image_raw",
            image_type,
            image_def,
            head + rng.randbytes(IMAGE_BYTES),
        )
        for k in range(int(duration * CAMERA_RATE))
    ]
    return out


def generate(path: Path, kind: str, messages: int, *, mixed: bool = False) -> Path:
    """Write (once) a recording of about ``messages`` messages; returns its path."""
    done = path.with_name(path.name + ".done")
    if done.exists() and path.exists():
        return path
    if path.is_dir():
        shutil.rmtree(path)
    elif path.exists():
        path.unlink()
    rate = MIXED_PX4_RATE if mixed else PX4_RATE
    per_second = 2 * rate + 1 / STATUS_PERIOD
    if mixed:
        per_second += IMU_RATE + CAMERA_RATE
    duration = messages / per_second
    raw, events = _px4(duration, rate)
    if mixed:
        raw += _sensors(duration)
    path.parent.mkdir(parents=True, exist_ok=True)
    if kind == "mcap":
        write_mcap(path, events, extra=raw)  # type: ignore[arg-type]
    else:
        storage = "mcap" if kind == "rosbag2-mcap" else "sqlite3"
        write_rosbag2(path, events, storage=storage, extra=raw)  # type: ignore[arg-type]
    done.touch()
    return path
