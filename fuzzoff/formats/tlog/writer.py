"""Normalised events -> a MAVLink .tlog, packed by pymavlink (formats.md 7.4).

One pymavlink ``MAVLink`` encoder per sender (autopilot, companion, GCS) so each sender keeps
its own sequence numbers; every record is the 8-byte big-endian microsecond timestamp followed
by the packet, as QGroundControl and MAVProxy write them.

What becomes what (the inverse of ``fuzzoff.formats.tlog.reader``):

* setpoints -> SET_POSITION_TARGET_LOCAL_NED / _GLOBAL_INT / SET_ATTITUDE_TARGET from the
  event's ``source_system``/``source_component`` (default: the companion); ``thrust_body``
  is not written (the ``common`` dialect of pymavlink 2.4.50 has no such extension field);
* ``Command`` -> COMMAND_LONG from the event's sender (default: the companion);
* ``VehicleStatus`` -> a HEARTBEAT from the autopilot (``nav_state`` -> ``custom_mode``);
* ``VehicleInfo`` -> AUTOPILOT_VERSION for ``px4_version``; its ``mav_type`` becomes the
  ``type`` of the autopilot's HEARTBEATs from then on (one is written at once if no
  ``VehicleStatus`` follows at the same time);
* ``CommandAck``, ``Parameter``, ``StatusText`` -> COMMAND_ACK, PARAM_VALUE, STATUSTEXT;
* ``VehiclePosition`` -> LOCAL_POSITION_NED from the autopilot (velocities 0).

A GCS HEARTBEAT is written at time 0 so that the recording starts where the events' clock does.
"""

from __future__ import annotations

import os
import re
import struct
from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import Any

os.environ.setdefault("MAVLINK20", "1")  # formats.md 7.2: before any pymavlink import

from pymavlink.dialects.v20 import common as mavlink

from fuzzoff.events import (
    Command,
    CommandAck,
    Event,
    LandDetected,
    MavlinkTarget,
    Parameter,
    SetActuatorControlTarget,
    SetAttitudeTarget,
    SetPositionTargetGlobal,
    SetPositionTargetLocal,
    StatusText,
    VehicleInfo,
    VehiclePosition,
    VehicleStatus,
)
from fuzzoff.mavlink_ids import (
    MAV_AUTOPILOT_INVALID,
    MAV_AUTOPILOT_PX4,
    MAV_MODE_FLAG_CUSTOM_MODE_ENABLED,
    MAV_MODE_FLAG_SAFETY_ARMED,
    MAV_PARAM_TYPE_INT32,
    MAV_PARAM_TYPE_REAL32,
    MAV_STATE_ACTIVE,
    MAV_TYPE_GCS,
    MAV_TYPE_QUADROTOR,
)
from fuzzoff.modes import nav_state_to_custom_mode

Sender = tuple[int, int]

DEFAULT_START_US = 1_735_689_600_000_000
"""2025-01-01 00:00:00 UTC: the wall clock of the first record."""

FIRMWARE_VERSION_TYPE_OFFICIAL = 255

FLOAT_PARAMS = frozenset({"COM_OF_LOSS_T", "COM_OBC_LOSS_T", "COM_RC_LOSS_T", "COM_DL_LOSS_T"})
"""PX4 float parameters that may hold whole numbers; other whole values are written INT32."""

SUPPORTED: tuple[type[Event], ...] = (
    SetPositionTargetLocal,
    SetPositionTargetGlobal,
    SetAttitudeTarget,
    SetActuatorControlTarget,
    Command,
    CommandAck,
    Parameter,
    StatusText,
    VehicleInfo,
    VehicleStatus,
    VehiclePosition,
    LandDetected,
)
"""The event kinds a tlog carries (what ``fuzzoff.formats.tlog.reader`` emits)."""

_RELEASE = re.compile(r"^v?(\d+)\.(\d+)(?:\.(\d+))?")


class _Link:
    """A pymavlink encoder for one sender that hands back the packed bytes."""

    def __init__(self, sender: Sender, mavlink1: bool) -> None:
        self.packets: list[bytes] = []
        self.mav = mavlink.MAVLink(self, srcSystem=sender[0], srcComponent=sender[1])
        self.mavlink1 = mavlink1

    def write(self, data: bytes) -> None:  # file-like for MAVLink.send
        self.packets.append(bytes(data))

    def pack(self, msg: Any) -> bytes:
        self.mav.send(msg, force_mavlink1=self.mavlink1)
        return self.packets.pop()


def encode_px4_version(version: str) -> int:
    """AUTOPILOT_VERSION ``flight_sw_version``: major, minor, patch, type bytes (high to low)."""
    match = _RELEASE.match(version.strip())
    if match is None:
        raise ValueError(f"not a PX4 release: {version!r}")
    major, minor, patch = (int(g or 0) for g in match.groups())
    return (major << 24) | (minor << 16) | (patch << 8) | FIRMWARE_VERSION_TYPE_OFFICIAL


def _param_bytes(name: str, value: float) -> tuple[float, int]:
    """(param_value, param_type): whole numbers as INT32 bytes in the float (PX4's encoding)."""
    if name not in FLOAT_PARAMS and float(value).is_integer() and -(2**31) <= value < 2**31:
        (as_float,) = struct.unpack("<f", struct.pack("<i", int(value)))
        return as_float, MAV_PARAM_TYPE_INT32
    return float(value), MAV_PARAM_TYPE_REAL32


def _command_message(event: Command) -> Any:
    """The MAVLink message ``event.message`` names (COMMAND_LONG when it names none)."""
    p = event.params
    if event.message == "SET_MODE":  # DO_SET_MODE's base mode, main and sub mode
        base, main, sub = (int(v) for v in p[:3])
        custom = (main & 0xFF) << 16 | (sub & 0xFF) << 24
        return mavlink.MAVLink_set_mode_message(event.target_system, base, custom)
    if event.message == "COMMAND_INT":
        return mavlink.MAVLink_command_int_message(
            event.target_system,
            event.target_component,
            0,  # frame: MAV_FRAME_GLOBAL, unused by mode and arming commands
            event.command,
            0,
            0,
            *p[:4],
            int(p[4]),
            int(p[5]),
            p[6],
        )
    return mavlink.MAVLink_command_long_message(
        event.target_system, event.target_component, event.command, 0, *p
    )


class _Writer:
    def __init__(
        self,
        autopilot: Sender,
        companion: Sender,
        gcs: Sender,
        mavlink1: bool,
    ) -> None:
        self.autopilot = autopilot
        self.companion = companion
        self.gcs = gcs
        self.mavlink1 = mavlink1
        self.links: dict[Sender, _Link] = {}
        self.mav_type: dict[int, int] = {}
        self.last_status: dict[int, VehicleStatus] = {}

    def link(self, sender: Sender) -> _Link:
        link = self.links.get(sender)
        if link is None:
            link = self.links[sender] = _Link(sender, self.mavlink1)
        return link

    def vehicle_sysid(self, event: Event) -> int:
        return int(event.vehicle) if event.vehicle.isdigit() else self.autopilot[0]

    def autopilot_of(self, event: Event) -> Sender:
        return (self.vehicle_sysid(event), self.autopilot[1])

    def sender_of(self, event: Command | MavlinkTarget | SetActuatorControlTarget) -> Sender:
        if event.source_system is not None and event.source_component is not None:
            return (event.source_system, event.source_component)
        sysid = self.vehicle_sysid(event)
        offset = sysid - self.autopilot[0]
        return (self.companion[0] + offset, self.companion[1])

    def heartbeat(self, event: Event, status: VehicleStatus | None) -> bytes:
        sysid = self.vehicle_sysid(event)
        base_mode = MAV_MODE_FLAG_CUSTOM_MODE_ENABLED
        custom_mode = 0
        if status is not None:
            if status.armed:
                base_mode |= MAV_MODE_FLAG_SAFETY_ARMED
            if status.nav_state is not None:
                custom_mode = nav_state_to_custom_mode(status.nav_state)
        msg = mavlink.MAVLink_heartbeat_message(
            self.mav_type.get(sysid, MAV_TYPE_QUADROTOR),
            MAV_AUTOPILOT_PX4,
            base_mode,
            custom_mode,
            MAV_STATE_ACTIVE,
            3,
        )
        return self.link(self.autopilot_of(event)).pack(msg)

    def encode(self, event: Event, next_event: Event | None) -> list[bytes]:
        boot_ms = _boot_ms(event)
        if isinstance(event, SetPositionTargetLocal):
            msg: Any = mavlink.MAVLink_set_position_target_local_ned_message(
                boot_ms,
                event.target_system,
                event.target_component,
                event.coordinate_frame,
                event.type_mask,
                *event.position,
                *event.velocity,
                *event.acceleration,
                event.yaw,
                event.yaw_rate,
            )
            return [self.link(self.sender_of(event)).pack(msg)]
        if isinstance(event, SetPositionTargetGlobal):
            msg = mavlink.MAVLink_set_position_target_global_int_message(
                boot_ms,
                event.target_system,
                event.target_component,
                event.coordinate_frame,
                event.type_mask,
                event.lat_int,
                event.lon_int,
                event.alt,
                *event.velocity,
                *event.acceleration,
                event.yaw,
                event.yaw_rate,
            )
            return [self.link(self.sender_of(event)).pack(msg)]
        if isinstance(event, SetAttitudeTarget):
            msg = mavlink.MAVLink_set_attitude_target_message(
                boot_ms,
                event.target_system,
                event.target_component,
                event.type_mask,
                list(event.q),
                event.body_roll_rate,
                event.body_pitch_rate,
                event.body_yaw_rate,
                event.thrust,
            )
            return [self.link(self.sender_of(event)).pack(msg)]
        if isinstance(event, SetActuatorControlTarget):
            msg = mavlink.MAVLink_set_actuator_control_target_message(
                _boot_ms(event) * 1000,
                event.group_mlx,
                event.target_system,
                event.target_component,
                list(event.controls),
            )
            return [self.link(self.sender_of(event)).pack(msg)]
        if isinstance(event, Command):
            msg = _command_message(event)
            return [self.link(self.sender_of(event)).pack(msg)]
        if isinstance(event, VehicleStatus):
            self.last_status[self.vehicle_sysid(event)] = event
            return [self.heartbeat(event, event)]
        if isinstance(event, VehicleInfo):
            return self.vehicle_info(event, next_event)
        if isinstance(event, CommandAck):
            msg = mavlink.MAVLink_command_ack_message(
                event.command, event.result, 0, 0, event.target_system, event.target_component
            )
            return [self.link(self.autopilot_of(event)).pack(msg)]
        if isinstance(event, Parameter):
            value, ptype = _param_bytes(event.name, event.value)
            msg = mavlink.MAVLink_param_value_message(
                event.name.encode("ascii")[:16], value, ptype, 1, 0
            )
            return [self.link(self.autopilot_of(event)).pack(msg)]
        if isinstance(event, LandDetected):
            state = 0 if event.landed is None else 1 if event.landed else 2  # MAV_LANDED_STATE
            msg = mavlink.MAVLink_extended_sys_state_message(0, state)
            return [self.link(self.autopilot_of(event)).pack(msg)]
        if isinstance(event, StatusText):
            msg = mavlink.MAVLink_statustext_message(
                event.severity, event.text.encode("utf-8")[:50], 0, 0
            )
            return [self.link(self.autopilot_of(event)).pack(msg)]
        if isinstance(event, VehiclePosition):
            msg = mavlink.MAVLink_local_position_ned_message(
                _boot_ms(event), event.x, event.y, event.z, 0.0, 0.0, 0.0
            )
            return [self.link(self.autopilot_of(event)).pack(msg)]
        raise ValueError(f"a tlog cannot carry {type(event).__name__} events")

    def vehicle_info(self, event: VehicleInfo, next_event: Event | None) -> list[bytes]:
        out: list[bytes] = []
        sysid = self.vehicle_sysid(event)
        if event.px4_version is not None:
            msg = mavlink.MAVLink_autopilot_version_message(
                0,  # capabilities
                encode_px4_version(event.px4_version),
                0,
                0,
                0,
                [0] * 8,
                [0] * 8,
                [0] * 8,
                0,
                0,
                0,
                [0] * 18,
            )
            out.append(self.link(self.autopilot_of(event)).pack(msg))
        if event.mav_type is not None:
            self.mav_type[sysid] = event.mav_type
            follows = (
                isinstance(next_event, VehicleStatus)
                and next_event.vehicle == event.vehicle
                and next_event.t == event.t
            )
            if not follows:
                out.append(self.heartbeat(event, self.last_status.get(sysid)))
        return out


def _boot_ms(event: Event) -> int:
    if event.sender_time_us is not None:
        return int(event.sender_time_us // 1000) & 0xFFFFFFFF
    return round(event.t * 1000) & 0xFFFFFFFF


def encode_events(
    events: Sequence[Event],
    *,
    autopilot: Sender = (1, 1),
    companion: Sender = (1, 191),
    gcs: Sender = (255, 190),
    start_us: int = DEFAULT_START_US,
    mavlink1: bool = False,
    skip_unsupported: bool = False,
) -> Iterable[bytes]:
    """The tlog records (timestamp + packet) for ``events``, in order."""
    if skip_unsupported:
        events = [e for e in events if isinstance(e, SUPPORTED)]
    writer = _Writer(autopilot, companion, gcs, mavlink1)
    gcs_heartbeat = mavlink.MAVLink_heartbeat_message(
        MAV_TYPE_GCS, MAV_AUTOPILOT_INVALID, 0, 0, MAV_STATE_ACTIVE, 3
    )
    yield struct.pack(">Q", start_us) + writer.link(gcs).pack(gcs_heartbeat)
    for i, event in enumerate(events):
        stamp = struct.pack(">Q", start_us + max(0, round(event.t * 1e6)))
        following = events[i + 1] if i + 1 < len(events) else None
        for packet in writer.encode(event, following):
            yield stamp + packet


def write_tlog(
    path: str | Path,
    events: Iterable[Event],
    *,
    autopilot: Sender = (1, 1),
    companion: Sender = (1, 191),
    gcs: Sender = (255, 190),
    start_us: int = DEFAULT_START_US,
    mavlink1: bool = False,
    skip_unsupported: bool = False,
) -> Path:
    """Write ``events`` (in time order) as a tlog; returns the path.

    ``autopilot``/``companion``/``gcs`` are the (sysid, compid) of the default senders; an
    event's ``vehicle`` (a number) picks the autopilot's sysid. ``mavlink1`` writes MAVLink 1
    packets. Events a tlog cannot carry (ROS 2 and uORB topics) raise ``ValueError`` unless
    ``skip_unsupported``.
    """
    path = Path(path)
    records = encode_events(
        list(events),
        autopilot=autopilot,
        companion=companion,
        gcs=gcs,
        start_us=start_us,
        mavlink1=mavlink1,
        skip_unsupported=skip_unsupported,
    )
    with path.open("wb") as fh:
        for record in records:
            fh.write(record)
    return path
