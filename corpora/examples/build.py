"""Build the examples corpus from the PX4 runs kept in ``runs/`` (README.md says what each is).

``.venv/bin/python corpora/examples/build.py [--expected] [NAME...]`` writes each recording of
``RECORDINGS`` from three outputs of ``runs.py``: ``runs/RUN.client.json.gz`` (every message the
example client published, in PX4's clock), ``runs/RUN.ulg`` (PX4's own log of the flight) and
``runs/RUN.tlog`` (the HEARTBEATs MAVROS turns into ``/mavros/state``). Deterministic.

* ROS 2 (MCAP): the client's ``/fmu/in/*`` messages as it filled them, and PX4's answers as
  the uXRCE-DDS bridge would have carried them out of the ULog (``/fmu/out/vehicle_status``,
  ``vehicle_command_ack``, ``vehicle_local_position``, ``vehicle_land_detected``,
  ``failsafe_flags``): every publication (the bridges of these releases have no rate limit;
  ``vehicle_local_position`` as kept at 10 Hz), with the bridge's clock offset applied to the
  ``timestamp`` fields.
* MAVROS (ROS 1 bag, ROS 2 bag): the client's ``setpoint_position/local`` poses and MAVROS's
  ``state``, one per PX4 HEARTBEAT, derived as MAVROS's sys_status plugin derives it.

``--expected`` rewrites ``NAME.expected.json`` from today's ``fuzzoff lint`` (review the diff:
``tests/test_examples_corpus.py`` says what must hold on each recording).
"""

from __future__ import annotations

import argparse
import gzip
import json
import os
import shutil
import sys
from collections.abc import Iterator
from dataclasses import dataclass, field
from functools import cache
from pathlib import Path
from typing import Any

import numpy as np
from pyulog import ULog
from rosbags.typesys import Stores, get_types_from_msg, get_typestore

os.environ.setdefault("MAVLINK20", "1")

from pymavlink import mavutil

from fuzzoff import events as ev
from fuzzoff.formats.mavros.mavros_msgs import mavros_typedefs
from fuzzoff.formats.mcap.writer import write_mcap
from fuzzoff.formats.registry import BY_NAME
from fuzzoff.formats.ros2msgs.messages import RawMessage
from fuzzoff.formats.rosbag1.writer import Ros1Message, mavros_typestore, write_rosbag1
from fuzzoff.formats.rosbag2.writer import write_rosbag2

HERE = Path(__file__).resolve().parent
RUNS = HERE / "runs"
MSG = HERE / "msg"
EPOCH_US = 1_767_225_600_000_000
"""The tlogs' clock for PX4's boot (runs.py / px4link.py)."""

RECORDING_START_US = 1_772_618_400_000_000
"""2026-03-04 10:00:00 UTC: the ROS clock (``get_clock()->now()``) at each recording's start."""

PUBLISH_TO_BAG_US = 300
"""A message reaches ``ros2 bag record`` / ``rosbag record`` this long after it was published."""

BRIDGE_US = 1_000
"""A uORB message reaches the bag this long after PX4 published it (the bridge, DDS)."""

OUT_MESSAGES = {
    "vehicle_status": "VehicleStatus",
    "vehicle_command_ack": "VehicleCommandAck",
    "vehicle_local_position": "VehicleLocalPosition",
    "vehicle_land_detected": "VehicleLandDetected",
    "failsafe_flags": "FailsafeFlags",
}

CLIENT_IDS = (1, 191)
"""The driver's MAVLink ids for the client's own commands (runs.py); the ground station is 255."""

NAV_STATE_OFFBOARD, NAV_STATE_EXTERNAL1 = 14, 23
VEHICLE_TYPE_ROVER = 3


@dataclass(frozen=True)
class Recording:
    """One corpus file: which run it comes from and how it is written."""

    name: str
    run: str
    fmt: str
    """``mcap``, ``rosbag1`` (MAVROS) or ``rosbag2`` (MAVROS 2, sqlite3)."""
    external_mode: bool = False
    """OFFBOARD in the run stands for EXTERNAL1 (px4-ros2-interface-lib, README.md)."""
    rover: bool = False
    """The client drives a rover; the multicopter that answered is written as one."""
    args: tuple[str, ...] = ()

    @property
    def path(self) -> Path:
        return HERE / f"{self.name}{BY_NAME[self.fmt].written_suffix}"


RECORDINGS = [
    Recording("px4_ros_com_offboard_control", "px4_ros_com_offboard_control", "mcap"),
    Recording("px4_ros_com_offboard_control_py", "px4_ros_com_offboard_control_py", "mcap"),
    Recording("px4_ros_com_ten_minute_hold", "px4_ros_com_ten_minute_hold", "mcap"),
    Recording("px4_offboard_circle_after_takeoff", "px4_offboard_circle_after_takeoff", "mcap"),
    Recording("mavros_offb_node", "mavros_offb_node", "rosbag1"),
    Recording("mavros_offb_node_ros2", "mavros_offb_node", "rosbag2"),
    Recording("interface_lib_goto", "interface_lib_goto", "mcap", external_mode=True),
    Recording(
        "rover_speed_attitude",
        "rover_speed_attitude",
        "mcap",
        rover=True,
        args=("--vehicle", "rover-differential"),
    ),
    Recording("hazard_frozen_velocity", "hazard_frozen_velocity", "mcap"),
    Recording("hazard_stall_mid_air", "hazard_stall_mid_air", "mcap"),
    Recording("hazard_enu_z_from_ground", "hazard_enu_z_from_ground", "mcap"),
    Recording("hazard_enu_z_airborne", "hazard_enu_z_airborne", "mcap"),
    Recording(
        "hazard_nan_pattern_velocity_zero_position",
        "hazard_nan_pattern_velocity_zero_position",
        "mcap",
    ),
    Recording("hazard_switch_without_stream_flying", "hazard_switch_without_stream_flying", "mcap"),
    Recording("hazard_mavros_stall_mid_air", "hazard_mavros_stall_mid_air", "rosbag1"),
    Recording(
        "hazard_rover_trajectory_yaw",
        "hazard_rover_trajectory_yaw",
        "mcap",
        rover=True,
        args=("--vehicle", "rover-ackermann"),
    ),
]


# ---------------------------------------------------------------------------------------------
# A kept run


@dataclass
class Run:
    """``runs.py``'s outputs for one scenario, on the recording's clock."""

    name: str
    record: dict[str, Any]
    ulog: ULog
    start_us: int
    """PX4 time (µs) of the recording's t = 0."""
    end_us: int

    @property
    def release(self) -> str:
        return str(self.record["release"])

    @property
    def profile_release(self) -> str:
        """The px4_msgs folder of this release: ``1.16.2`` -> ``1.16``."""
        return ".".join(self.release.split(".")[:2])

    def t(self, px4_us: int) -> float:
        return (px4_us - self.start_us) / 1e6

    @property
    def namespace(self) -> str:
        """The ROS namespace of the client's PX4 topics (``""`` for none): PX4 must run its
        bridge in the same one for the example to fly (``/px4_offboard`` for px4-offboard)."""
        for pub in self.record["pubs"]:
            head, sep, _ = pub["topic"].partition("/fmu/")
            if sep:
                return str(head)
        return ""

    def ros_time_us(self, px4_us: int) -> int:
        """The companion's ROS clock at PX4 time ``px4_us`` (both run at the same rate)."""
        return RECORDING_START_US + px4_us - self.start_us


def load_run(name: str) -> Run:
    with gzip.open(RUNS / f"{name}.client.json.gz", "rt", encoding="utf-8") as fh:
        record = json.load(fh)
    marks = record["marks_us"]
    ulog = ULog(str(RUNS / f"{name}.ulg"))
    return Run(name, record, ulog, int(marks["record_start"]), int(marks["record_end"]))


def ulog_rows(ulog: ULog, topic: str) -> list[dict[str, Any]]:
    """The samples of ``topic`` (instance 0) as dicts, arrays gathered from ``name[i]``."""
    for data in ulog.data_list:
        if data.name == topic and data.multi_id == 0:
            break
    else:
        return []
    columns = data.data
    count = len(columns["timestamp"])
    rows: list[dict[str, Any]] = [{} for _ in range(count)]
    for key, values in columns.items():
        name, _, index = key.partition("[")
        for row, value in zip(rows, values.tolist(), strict=True):
            if index:
                row.setdefault(name, {})[int(index.rstrip("]"))] = value
            else:
                row[name] = value
    for row in rows:
        for name, value in row.items():
            if isinstance(value, dict):
                row[name] = [value[i] for i in sorted(value)]
    return rows


# ---------------------------------------------------------------------------------------------
# px4_msgs definitions and CDR encoding


@dataclass(frozen=True)
class MsgField:
    name: str
    base: str
    length: int | None


@cache
def definition(release: str, message: str) -> str:
    """``msg/RELEASE/MESSAGE.msg``: px4_msgs at the release's tag, wire fields only."""
    return (MSG / release / f"{message}.msg").read_text()


@cache
def store_for(release: str, message: str) -> Any:
    store = get_typestore(Stores.EMPTY)
    store.register(get_types_from_msg(definition(release, message), f"px4_msgs/msg/{message}"))
    return store


def msg_fields(release: str, message: str) -> list[MsgField]:
    out = []
    for line in definition(release, message).splitlines():
        if "=" in line:
            continue
        typ, name = line.split()[:2]
        base, _, rest = typ.partition("[")
        out.append(MsgField(name, base, int(rest.rstrip("]")) if rest else None))
    return out


def message_version(release: str, message: str) -> int:
    for line in definition(release, message).splitlines():
        if line.startswith("uint32 MESSAGE_VERSION"):
            return int(line.split("=")[1])
    return 0


def out_topic(release: str, message: str, name: str) -> str:
    version = message_version(release, message)
    return f"/fmu/out/{name}" + (f"_v{version}" if version else "")


def encode(release: str, message: str, values: dict[str, Any]) -> bytes:
    """CDR bytes of px4_msgs ``message`` from ``values`` (a missing field is zero), by rosbags."""
    store = store_for(release, message)
    typename = f"px4_msgs/msg/{message}"
    kwargs: dict[str, Any] = {}
    for f in msg_fields(release, message):
        dtype = np.dtype("bool" if f.base == "bool" else f.base)
        if f.length is not None:
            given = values.get(f.name, [0] * f.length)
            kwargs[f.name] = np.array(given, dtype=dtype)
        else:
            kwargs[f.name] = dtype.type(values.get(f.name, 0)).item()
    return bytes(store.serialize_cdr(store.types[typename](**kwargs), typename))


def raw_out(run: Run, topic: str, px4_us: int, values: dict[str, Any]) -> RawMessage:
    """A ``/fmu/out`` message: PX4's sample as the bridge sends it (timestamps on the agent's
    clock, as the bridge's time offset makes them), logged ``BRIDGE_US`` after PX4 published."""
    message = OUT_MESSAGES[topic]
    release = run.profile_release
    values = dict(values)
    for key in ("timestamp", "timestamp_sample"):
        if values.get(key):
            values[key] = run.ros_time_us(int(values[key]))
    return RawMessage(
        t=run.t(px4_us + BRIDGE_US),
        topic=run.namespace + out_topic(release, message, topic),
        msgtype=f"px4_msgs/msg/{message}",
        msgdef=definition(release, message),
        data=encode(release, message, values),
    )


# ---------------------------------------------------------------------------------------------
# The vehicle side of a ROS 2 recording


def vehicle_side(run: Run, recording: Recording) -> list[RawMessage]:
    out: list[RawMessage] = []
    topics = list(OUT_MESSAGES)
    if recording.rover:
        # a multicopter answered (README.md): its position and landing state are not a rover's
        topics = ["vehicle_status", "vehicle_command_ack", "failsafe_flags"]
    for topic in topics:
        rows = ulog_rows(run.ulog, topic)
        if topic == "vehicle_command_ack":
            rows = client_acks(run, rows)
        for row in rows:
            px4_us = int(row["timestamp"])
            if not run.start_us <= px4_us <= run.end_us:
                continue
            if topic == "vehicle_status":
                row = status_fields(row, recording)
            out.append(raw_out(run, topic, px4_us, row))
    return out


def status_fields(row: dict[str, Any], recording: Recording) -> dict[str, Any]:
    """PX4's vehicle_status with the SITL instance's system id as a real vehicle's (1: the id
    the examples address); EXTERNAL1 for the interface library's mode; a rover's type."""
    row = {**row, "system_id": 1}
    if recording.external_mode:
        for key in ("nav_state", "nav_state_user_intention"):
            if row.get(key) == NAV_STATE_OFFBOARD:
                row[key] = NAV_STATE_EXTERNAL1
    if recording.rover:
        row["vehicle_type"] = VEHICLE_TYPE_ROVER
    return row


def client_acks(run: Run, rows: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """Acks as a ROS 2 client gets them. Its commands reached PX4 over MAVLink here; over DDS
    they do not pass the MAVLink receiver, so the receiver's own first ack of a mode switch
    (1.16 and 1.17, gate spec 4.3) is left out, and Commander's ack is addressed to the
    example's source ids (1, 1) rather than the driver's."""
    out = []
    for i, row in enumerate(rows):
        ours = (row["target_system"], row["target_component"]) == CLIENT_IDS
        if ours and run.record["transport"] == "ros2":
            later = [
                r
                for r in rows[i + 1 :]
                if r["command"] == row["command"]
                and (r["target_system"], r["target_component"]) == CLIENT_IDS
                and r["timestamp"] - row["timestamp"] <= 50_000
            ]
            if row["command"] == ev.MAV_CMD_DO_SET_MODE and later:
                continue
            row = {**row, "target_system": 1, "target_component": 1}
        out.append(row)
    return out


# ---------------------------------------------------------------------------------------------
# The client side of a ROS 2 recording


def client_events(run: Run) -> tuple[list[ev.Event], list[RawMessage]]:
    """The client's ``/fmu/in`` messages: px4_msgs topics fuzzoff's writer knows as events,
    the others (goto, control-mode configuration, mode completed) as raw messages."""
    events: list[ev.Event] = []
    raw: list[RawMessage] = []
    release = run.profile_release
    for pub in run.record["pubs"]:
        px4_us, topic, f = int(pub["t_us"]), pub["topic"], pub["fields"]
        if not run.start_us <= px4_us <= run.end_us:
            continue
        t = run.t(px4_us + PUBLISH_TO_BAG_US)
        stamp = run.ros_time_us(px4_us) if f.get("timestamp") else 0
        vehicle = run.namespace
        if topic.endswith("/offboard_control_mode"):
            events.append(
                ev.ControlMode(
                    t=t,
                    vehicle=vehicle,
                    sender_time_us=stamp,
                    position=f["position"],
                    velocity=f["velocity"],
                    acceleration=f["acceleration"],
                    attitude=f["attitude"],
                    body_rate=f["body_rate"],
                )
            )
        elif topic.endswith("/trajectory_setpoint"):
            events.append(
                ev.TrajectorySetpoint(
                    t=t,
                    vehicle=vehicle,
                    sender_time_us=stamp,
                    position=vec3(f["position"]),
                    velocity=vec3(f["velocity"]),
                    acceleration=vec3(f["acceleration"]),
                    jerk=vec3(f["jerk"]),
                    yaw=float(f["yaw"]),
                    yawspeed=float(f["yawspeed"]),
                )
            )
        elif topic.endswith("/vehicle_command"):
            events.append(
                ev.Command(
                    t=t,
                    vehicle=vehicle,
                    sender_time_us=stamp,
                    command=int(f["command"]),
                    params=(float(f["param1"]), float(f["param2"]), 0.0, 0.0, 0.0, 0.0, 0.0),
                    target_system=f["target_system"],
                    target_component=f["target_component"],
                    source_system=f["source_system"],
                    source_component=f["source_component"],
                    from_external=f["from_external"],
                    transport="ros2",
                )
            )
        elif topic.endswith("/rover_speed_setpoint"):
            events.append(
                ev.RoverSpeedSetpoint(
                    t=t,
                    vehicle=vehicle,
                    sender_time_us=0,
                    speed_body_x=float(f["speed_body_x"]),
                    speed_body_y=float(f["speed_body_y"]),
                )
            )
        elif topic.endswith("/rover_attitude_setpoint"):
            events.append(
                ev.RoverAttitudeSetpoint(
                    t=t,
                    vehicle=vehicle,
                    sender_time_us=0,
                    yaw_setpoint=float(f["yaw_setpoint"]),
                )
            )
        elif topic.endswith(("/goto_setpoint", "/mode_completed")):
            message = "GotoSetpoint" if "goto" in topic else "ModeCompleted"
            raw.append(
                RawMessage(
                    t=t,
                    topic=topic,
                    msgtype=f"px4_msgs/msg/{message}",
                    msgdef=definition(release, message),
                    data=encode(release, message, f),
                )
            )
        else:
            raise ValueError(f"{run.name}: no ROS 2 form for {topic}")
    return events, raw


def vec3(values: list[float]) -> tuple[float, float, float]:
    return (float(values[0]), float(values[1]), float(values[2]))


def external_mode_config(run: Run) -> list[RawMessage]:
    """What the interface library publishes when its goto setpoint type becomes active (at
    registration): a VehicleControlMode on ``/fmu/in/config_control_setpoints`` with the mode's
    id and the controllers MulticopterGotoSetpointType enables, timestamp 0. Written at the
    recording's start (the library sends it once, before the recording began)."""
    flags = (
        "allocation",
        "rates",
        "attitude",
        "altitude",
        "acceleration",
        "velocity",
        "position",
        "climb_rate",
    )
    values: dict[str, Any] = {f"flag_control_{name}_enabled": True for name in flags}
    values["source_id"] = NAV_STATE_EXTERNAL1
    release = run.profile_release
    return [
        RawMessage(
            t=0.0,
            topic="/fmu/in/config_control_setpoints",
            msgtype="px4_msgs/msg/VehicleControlMode",
            msgdef=definition(release, "VehicleControlMode"),
            data=encode(release, "VehicleControlMode", values),
        )
    ]


def write_ros2(run: Run, recording: Recording) -> None:
    events, raw = client_events(run)
    raw += vehicle_side(run, recording)
    if recording.external_mode:
        raw += external_mode_config(run)
    write_mcap(
        recording.path,
        events,
        release=run.profile_release,
        extra=raw,
        start_ns=RECORDING_START_US * 1000,
    )


# ---------------------------------------------------------------------------------------------
# MAVROS


MAVROS_PX4_MODES = {
    1 << 16: "MANUAL",
    5 << 16: "ACRO",
    2 << 16: "ALTCTL",
    3 << 16: "POSCTL",
    6 << 16: "OFFBOARD",
    7 << 16: "STABILIZED",
    8 << 16: "RATTITUDE",
    **{
        4 << 16 | sub << 24: name
        for sub, name in (
            (4, "AUTO.MISSION"),
            (3, "AUTO.LOITER"),
            (5, "AUTO.RTL"),
            (6, "AUTO.LAND"),
            (7, "AUTO.RTGS"),
            (1, "AUTO.READY"),
            (2, "AUTO.TAKEOFF"),
            (8, "AUTO.FOLLOW_TARGET"),
            (9, "AUTO.PRECLAND"),
        )
    },
}
"""MAVROS's PX4 custom-mode table (``uas_stringify.cpp``): an exact ``custom_mode`` match."""


def mavros_mode(base_mode: int, custom_mode: int) -> str:
    """The ``State.mode`` string MAVROS gives a PX4 HEARTBEAT."""
    if not base_mode & 1:
        return f"MODE(0x{base_mode:2X})"
    return MAVROS_PX4_MODES.get(custom_mode, f"CMODE({custom_mode})")


@dataclass
class Heartbeat:
    px4_us: int
    base_mode: int
    custom_mode: int
    system_status: int


def heartbeats(run: Run) -> list[Heartbeat]:
    """PX4's HEARTBEATs as the driver received them (the tlog's clock is PX4's, px4link.py)."""
    conn: Any = mavutil.mavlink_connection(str(RUNS / f"{run.name}.tlog"))
    out = []
    system = int(run.record["px4_system"])
    while (msg := conn.recv_match(type="HEARTBEAT")) is not None:
        if msg.get_srcSystem() == system and msg.get_srcComponent() == 1:
            px4_us = round(msg._timestamp * 1e6) - EPOCH_US
            out.append(Heartbeat(px4_us, msg.base_mode, msg.custom_mode, msg.system_status))
    conn.close()
    return out


@dataclass
class MavrosItem:
    px4_us: int
    topic: str
    fields: dict[str, Any] = field(default_factory=dict)


def mavros_items(run: Run) -> list[MavrosItem]:
    """``setpoint_position/local`` as the example published it and ``state`` per HEARTBEAT
    (MAVROS stamps it with its clock on receipt)."""
    items = []
    for pub in run.record["pubs"]:
        px4_us = int(pub["t_us"])
        if pub["topic"] == "/mavros/setpoint_position/local" and (
            run.start_us <= px4_us <= run.end_us
        ):
            items.append(MavrosItem(px4_us + PUBLISH_TO_BAG_US, pub["topic"], pub["fields"]))
    for hb in heartbeats(run):
        if run.start_us <= hb.px4_us <= run.end_us:
            state = {
                "stamp_us": run.ros_time_us(hb.px4_us),
                "connected": True,
                "armed": bool(hb.base_mode & 128),
                "guided": bool(hb.base_mode & 8),
                "manual_input": bool(hb.base_mode & 64),
                "mode": mavros_mode(hb.base_mode, hb.custom_mode),
                "system_status": hb.system_status,
            }
            items.append(MavrosItem(hb.px4_us + PUBLISH_TO_BAG_US, "/mavros/state", state))
    items.sort(key=lambda item: item.px4_us)
    return items


def ros_messages(
    store: Any, items: list[MavrosItem], ros2: bool
) -> Iterator[tuple[MavrosItem, str, Any]]:
    """(item, type, rosbags message) for each item; the pose's orientation is what an unset
    message holds: all zero in ROS 1, the identity (w = 1) in ROS 2."""
    types = store.types
    time_cls = types["builtin_interfaces/msg/Time"]
    header_cls = types["std_msgs/msg/Header"]
    seq = 0
    for item in items:
        f = item.fields
        if item.topic.endswith("/state"):
            stamp_ns = f["stamp_us"] * 1000
            stamp = time_cls(sec=stamp_ns // 10**9, nanosec=stamp_ns % 10**9)
            header = (
                header_cls(seq=0, stamp=stamp, frame_id="")
                if not ros2
                else header_cls(stamp=stamp, frame_id="")
            )
            state = types["mavros_msgs/msg/State"](
                header=header,
                connected=f["connected"],
                armed=f["armed"],
                guided=f["guided"],
                manual_input=f["manual_input"],
                mode=f["mode"],
                system_status=f["system_status"],
            )
            yield item, "mavros_msgs/msg/State", state
            continue
        zero = time_cls(sec=0, nanosec=0)
        if ros2:
            header = header_cls(stamp=zero, frame_id="")
        else:
            header = header_cls(seq=seq, stamp=zero, frame_id="")
            seq += 1
        x, y, z = f["position"]
        pose = types["geometry_msgs/msg/Pose"](
            position=types["geometry_msgs/msg/Point"](x=x, y=y, z=z),
            orientation=types["geometry_msgs/msg/Quaternion"](
                x=0.0, y=0.0, z=0.0, w=1.0 if ros2 else 0.0
            ),
        )
        message = types["geometry_msgs/msg/PoseStamped"](header=header, pose=pose)
        yield item, "geometry_msgs/msg/PoseStamped", message


def write_mavros1(run: Run, recording: Recording) -> None:
    items = mavros_items(run)
    first = items[0].px4_us
    store = mavros_typestore()
    extra = [
        Ros1Message((item.px4_us - first) / 1e6, item.topic, msgtype, message)
        for item, msgtype, message in ros_messages(store, items, ros2=False)
    ]
    start_ns = run.ros_time_us(first) * 1000
    write_rosbag1(recording.path, [], extra=extra, start_ns=start_ns)


@cache
def ros2_mavros_store() -> Any:
    store = get_typestore(Stores.ROS2_HUMBLE)
    store.register(mavros_typedefs())
    return store


def write_mavros2(run: Run, recording: Recording) -> None:
    store = ros2_mavros_store()
    extra = []
    for item, msgtype, message in ros_messages(store, mavros_items(run), ros2=True):
        msgdef = store.generate_msgdef(msgtype, ros_version=2)[0]
        data = bytes(store.serialize_cdr(message, msgtype))
        extra.append(RawMessage(run.t(item.px4_us), item.topic, msgtype, msgdef, data))
    shutil.rmtree(recording.path, ignore_errors=True)
    write_rosbag2(
        recording.path,
        [],
        storage="sqlite3",
        extra=extra,
        start_ns=RECORDING_START_US * 1000,
    )


# ---------------------------------------------------------------------------------------------


def build(recording: Recording) -> Path:
    run = load_run(recording.run)
    if recording.fmt == "mcap":
        write_ros2(run, recording)
    elif recording.fmt == "rosbag1":
        write_mavros1(run, recording)
    else:
        write_mavros2(run, recording)
    return recording.path


def lint_args(recording: Recording) -> list[str]:
    """What a user gives: the release that answered (a ROS recording does not say it), and the
    rover type where the recording is a rover's."""
    release = load_run(recording.run).release
    return ["--px4", release, *recording.args]


def write_expected(recording: Recording) -> None:
    """NAME.expected.json from today's lint (tests/test_corpora.py replays it)."""
    from tests.helpers import run_cli

    args = lint_args(recording)
    result = run_cli(["lint", str(recording.path), "--format", "json", *args])
    data = json.loads(result.stdout)
    (report,) = data["files"]
    spec = {
        "recording": recording.path.name,
        "args": args,
        "exit_status": result.returncode,
        "complete": report["complete"],
        "profile": {key: report["profile"][key] for key in ("px4", "vehicle")},
        "findings": [
            {
                "code": f["code"],
                "severity": f["severity"],
                "time_s": None if f["time_s"] is None else round(f["time_s"], 3),
            }
            for f in report["findings"]
        ],
    }
    target = HERE / f"{recording.name}.expected.json"
    target.write_text(json.dumps(spec, indent=2) + "\n")


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("names", nargs="*", help="recordings to build (default: all)")
    parser.add_argument("--expected", action="store_true", help="rewrite NAME.expected.json")
    args = parser.parse_args(argv)
    chosen = [r for r in RECORDINGS if not args.names or r.name in args.names]
    for recording in chosen:
        if not (RUNS / f"{recording.run}.client.json.gz").exists():
            print(f"{recording.name}: run {recording.run} not kept, skipped")
            continue
        path = build(recording)
        size = (
            sum(p.stat().st_size for p in path.rglob("*")) if path.is_dir() else path.stat().st_size
        )
        print(f"{path.name}: {size} bytes")
        if args.expected:
            write_expected(recording)
    return 0


if __name__ == "__main__":
    sys.path.insert(0, str(HERE.parent.parent))
    raise SystemExit(main(sys.argv[1:]))
