"""MAVLink telemetry logs (.tlog) -> normalised events (formats.md 7, docs/tlog.md).

Who is who: a sender is its (sysid, compid). The autopilot is compid 1
(``MAV_COMP_ID_AUTOPILOT1``) or any sender whose HEARTBEAT says ``autopilot`` 12 (PX4); every
other sender (MAVROS 1/191 or 1/240, MAVSDK, QGC 255/190) is a companion or a GCS. The vehicle
is the autopilot's sysid as text. Setpoints and commands belong to the vehicle their
``target_system`` names; 0 (broadcast) means every autopilot in the log (usually one).
"""

from __future__ import annotations

import math
import struct
from collections.abc import Callable, Iterable, Iterator
from pathlib import Path
from typing import Any, BinaryIO

from fuzzoff.events import (
    MAV_VTOL_STATE_PHASE,
    NOWHERE,
    Command,
    CommandAck,
    CommandMessage,
    Event,
    FailsafeFlags,
    LandDetected,
    ManualControl,
    Parameter,
    SetActuatorControlTarget,
    SetAttitudeTarget,
    SetPositionTargetGlobal,
    SetPositionTargetLocal,
    StatusText,
    VehicleInfo,
    VehiclePosition,
    VehicleStatus,
    VtolPhase,
    Where,
)
from fuzzoff.findings import RecordingStats
from fuzzoff.formats.tlog.frames import RESYNC_LIMIT, Framer, FrameStats, message_name
from fuzzoff.mavlink_ids import (
    MAV_AUTOPILOT_PX4,
    MAV_CMD_DO_SET_MODE,
    MAV_COMP_ID_AUTOPILOT1,
    MAV_LANDED_STATE_ON_GROUND,
    MAV_LANDED_STATE_UNDEFINED,
    MAV_MODE_FLAG_CUSTOM_MODE_ENABLED,
    MAV_MODE_FLAG_SAFETY_ARMED,
    MAV_SYS_STATUS_SENSOR_RC_RECEIVER,
    MAV_TYPE_GCS,
)
from fuzzoff.modes import custom_mode_to_nav_state, nav_state_name, split_custom_mode
from fuzzoff.profiles import MAV_TYPE_VEHICLE, ROVER_ASSUMED
from fuzzoff.recording import (
    POSITION_PERIOD_S,
    RecordingInfo,
    Source,
    SourceError,
    SourceProblem,
)

HEARTBEAT = 0
SYS_STATUS = 1
SET_MODE = 11
PARAM_VALUE = 22
RC_CHANNELS = 65
MANUAL_CONTROL = 69
COMMAND_INT = 75
COMMAND_LONG = 76
COMMAND_ACK = 77
SET_ATTITUDE_TARGET = 82
SET_POSITION_TARGET_LOCAL_NED = 84
SET_POSITION_TARGET_GLOBAL_INT = 86
SET_ACTUATOR_CONTROL_TARGET = 139
AUTOPILOT_VERSION = 148
EXTENDED_SYS_STATE = 245
STATUSTEXT = 253
LOCAL_POSITION_NED = 32

WANTED = frozenset(
    {
        HEARTBEAT,
        SET_MODE,
        PARAM_VALUE,
        COMMAND_INT,
        COMMAND_LONG,
        COMMAND_ACK,
        SET_ATTITUDE_TARGET,
        SET_POSITION_TARGET_LOCAL_NED,
        SET_POSITION_TARGET_GLOBAL_INT,
        SET_ACTUATOR_CONTROL_TARGET,
        AUTOPILOT_VERSION,
        STATUSTEXT,
        SYS_STATUS,
        RC_CHANNELS,
        MANUAL_CONTROL,
        EXTENDED_SYS_STATE,
        LOCAL_POSITION_NED,
    }
)
"""The only message ids decoded; the rest are framed and CRC-checked, not decoded."""

THINNED = {LOCAL_POSITION_NED: round(POSITION_PERIOD_S * 1e6)}
"""Decoded at most once per period per vehicle in a plain lint (``POSITION_PERIOD_S``)."""

PROBE_WANTED = frozenset({HEARTBEAT, AUTOPILOT_VERSION, COMMAND_LONG, COMMAND_INT, SET_MODE})
"""The probe's decodes: who is who, the release, and who sends commands (rare messages)."""
KEEPALIVE_IDS = frozenset(
    {SET_POSITION_TARGET_LOCAL_NED, SET_POSITION_TARGET_GLOBAL_INT, SET_ATTITUDE_TARGET}
)
SENT_STREAM_IDS = KEEPALIVE_IDS | {SET_ACTUATOR_CONTROL_TARGET}
"""Setpoint messages a companion sends: a log holding any of them holds the sent stream."""

INT_PARAM_TYPES = frozenset({1, 2, 3, 4, 5, 6})
"""MAV_PARAM_TYPE UINT8..INT32: the float's four bytes hold the integer (PX4's encoding)."""

MAX_PROBLEM_LINES = 10
"""Corrupt regions reported one by one; the rest are summed up in one more line."""

_KIND_OF_ID: dict[int, tuple[str, ...]] = {
    SET_POSITION_TARGET_LOCAL_NED: (SetPositionTargetLocal.kind,),
    SET_POSITION_TARGET_GLOBAL_INT: (SetPositionTargetGlobal.kind,),
    SET_ATTITUDE_TARGET: (SetAttitudeTarget.kind,),
    SET_ACTUATOR_CONTROL_TARGET: (SetActuatorControlTarget.kind,),
    COMMAND_LONG: (Command.kind,),
    COMMAND_INT: (Command.kind,),
    SET_MODE: (Command.kind,),
    COMMAND_ACK: (CommandAck.kind,),
    PARAM_VALUE: (Parameter.kind,),
    AUTOPILOT_VERSION: (VehicleInfo.kind,),
    STATUSTEXT: (StatusText.kind,),
    EXTENDED_SYS_STATE: (LandDetected.kind,),
    MANUAL_CONTROL: (ManualControl.kind,),
}


STICK_UNUSED = 32767
"""MANUAL_CONTROL's INT16_MAX: the axis is not used."""


def _stick(value: int, scale: float = 1000.0, offset: float = 0.0) -> float:
    return math.nan if value == STICK_UNUSED else value / scale - offset


def _sticks(m: Any, t: float, vehicle: str, where: Where) -> ManualControl:
    """MANUAL_CONTROL as PX4's receiver scales it: x pitch, y roll, r yaw in [-1, 1] from
    thousandths; z throttle 0..1000 -> [-1, 1] (PX4 keeps throttle centred)."""
    return ManualControl(
        t=t,
        vehicle=vehicle,
        where=where,
        pitch=_stick(m.x),
        roll=_stick(m.y),
        yaw=_stick(m.r),
        throttle=_stick(m.z, 500.0, 1.0),
    )


def decode_px4_version(flight_sw_version: int) -> str:
    """AUTOPILOT_VERSION ``flight_sw_version`` bytes (major, minor, patch, type) -> "1.15.4"."""
    v = flight_sw_version
    return f"{(v >> 24) & 0xFF}.{(v >> 16) & 0xFF}.{(v >> 8) & 0xFF}"


def param_value(value: float, param_type: int) -> float:
    """PARAM_VALUE's value: integer types carry the integer's bytes in the float."""
    if param_type in INT_PARAM_TYPES:
        (as_int,) = struct.unpack("<i", struct.pack("<f", value))
        if param_type in (1, 3, 5):  # unsigned
            as_int &= {1: 0xFF, 3: 0xFFFF, 5: 0xFFFFFFFF}[param_type]
        return float(as_int)
    return float(value)


ROVER_KIND_UNSAID = (
    f"a rover (HEARTBEAT type 10, MAV_TYPE_GROUND_ROVER) but not which kind (assumed"
    f" {ROVER_ASSUMED}; set --vehicle rover-ackermann, rover-differential or rover-mecanum)"
)
"""PX4 sends type 10 for its Ackermann, differential and mecanum rovers alike."""


def _text(raw: Any) -> str:
    if isinstance(raw, bytes):
        return raw.split(b"\x00", 1)[0].decode("utf-8", errors="replace")
    return str(raw).split("\x00", 1)[0]


class TlogSource(Source):
    """A .tlog read with pymavlink (dialect ``development``, PX4's), one sequential pass per
    call. Packets of ids the dialect does not know are ordinary traffic, counted in the stats."""

    format = "tlog"

    def __init__(self, path: Path) -> None:
        super().__init__(path)
        self._fh: BinaryIO | None = None
        self._size = 0
        self._info: RecordingInfo | None = None
        self._autopilots: set[tuple[int, int]] = set()
        self._fatal = False
        self._framer: Framer | None = None

    # -- Source API -----------------------------------------------------------------------

    def open(self) -> None:
        try:
            self._fh = self.path.open("rb")
            self._size = self._fh.seek(0, 2)
            self._fh.seek(0)
        except OSError as exc:
            raise SourceError(self.path, f"cannot open: {exc.strerror or exc}") from None
        if self._size == 0:
            raise SourceError(self.path, "empty file")

    def close(self) -> None:
        if self._fh is not None:
            self._fh.close()
            self._fh = None

    def progress(self) -> float | None:
        if self._framer is None or not self._size:
            return None
        return min(1.0, self._framer.consumed / self._size)

    def probe(self) -> RecordingInfo:
        """One framing pass decoding only HEARTBEAT and AUTOPILOT_VERSION."""
        if self._info is not None:
            return self._info
        info = RecordingInfo(str(self.path), self.format)
        framer = Framer(self._file(), self._size, PROBE_WANTED, verify=False)
        framer.on_chunk = self.on_progress
        autopilots = self._autopilots
        ground_stations: set[tuple[int, int]] = set()
        commanders: set[tuple[int, int]] = set()
        for _offset, _ts, msgid, msg in framer.records():
            sender = (msg.get_srcSystem(), msg.get_srcComponent())
            if msgid == HEARTBEAT:
                if msg.type == MAV_TYPE_GCS:
                    ground_stations.add(sender)
                if sender[1] == MAV_COMP_ID_AUTOPILOT1 or (
                    msg.autopilot == MAV_AUTOPILOT_PX4 and msg.type != MAV_TYPE_GCS
                ):
                    autopilots.add(sender)
                if sender in autopilots and info.vehicle_type is None:
                    info.vehicle_type = MAV_TYPE_VEHICLE.get(msg.type)
                    if info.vehicle_type == ROVER_ASSUMED:
                        info.vehicle_assumed = ROVER_KIND_UNSAID
            elif msgid == AUTOPILOT_VERSION and sender[1] == MAV_COMP_ID_AUTOPILOT1:
                autopilots.add(sender)
                if info.px4_version is None:
                    info.px4_version = decode_px4_version(msg.flight_sw_version)
            elif msgid != AUTOPILOT_VERSION and sender[1] != MAV_COMP_ID_AUTOPILOT1:
                commanders.add(sender)
        stats = framer.stats
        if stats.packets == 0:
            self._fatal = True
            if stats.truncated_at == 0:
                raise SourceError(
                    self.path, f"truncated at byte {stats.size}: no complete packet", "byte 0"
                )
            raise SourceError(self.path, "no MAVLink packet found: not a tlog", "byte 0")
        info.vehicles = sorted({str(s) for s, _ in self._autopilots}, key=_vehicle_sort)
        if not self._autopilots:
            info.notes.append(
                "no autopilot in the log (no HEARTBEAT or AUTOPILOT_VERSION from component 1 "
                "or from PX4): no recorded mode; broadcast setpoints are taken for vehicle 1"
            )
        if info.px4_version is None:
            info.notes.append("no AUTOPILOT_VERSION in the log: PX4 version unknown")
        companions = commanders - autopilots - ground_stations
        if not any(stats.by_id.get(i) for i in SENT_STREAM_IDS) and not companions:
            info.stream_recorded = False
            info.stream_missing = (
                "holds no setpoint and no command from a companion: a ground station's log "
                "(PX4 does not forward the messages addressed to itself)"
            )
            info.notes.append(
                "no setpoint and no command from a companion in the log (a ground station's "
                "log?): the stream sent to the vehicle is not in this recording"
            )
        info.message_count = stats.packets
        for msgid, kinds in _KIND_OF_ID.items():
            if stats.by_id.get(msgid):
                info.kinds.update(kinds)
        if stats.by_id.get(HEARTBEAT) and self._autopilots:
            info.kinds.update((VehicleStatus.kind, VehicleInfo.kind))
        self._info = info
        return info

    def events(self) -> Iterator[Event]:
        if self._fatal:
            return  # the probe already raised the one SourceError for this file
        self.probe()
        framer = Framer(self._file(), self._size, WANTED, verify=True, thinned=THINNED)
        self._framer = framer
        framer.on_chunk = self.on_progress
        decoder = _Decoder(self._autopilots, self._vehicles())
        plot = self.aside.plot
        if plot is not None:

            def aside(ts: int, msg: Any) -> None:
                first = framer.stats.first_ts or ts
                if decoder.from_autopilot(msg):
                    plot.position(_position_event(msg, (ts - first) / 1e6))

            framer.on_thinned = aside
        first_ts: int | None = None
        try:
            for offset, ts, msgid, msg in framer.records():
                if first_ts is None:
                    first_ts = framer.stats.first_ts or ts
                    self.set_start(first_ts / 1e6)
                t = (ts - first_ts) / 1e6
                yield from decoder.decode(msgid, msg, t, offset)
        finally:
            last_ts = framer.stats.last_ts
            if first_ts is not None and last_ts is not None:  # every packet, event or not
                self.aside.read((last_ts - first_ts) / 1e6)
            self._report(framer.stats, first_ts)
            self.stats.update(self._stats(framer.stats, decoder))

    # -- helpers --------------------------------------------------------------------------

    def _file(self) -> BinaryIO:
        if self._fh is None:
            self.open()
        assert self._fh is not None
        self._fh.seek(0)
        return self._fh

    def _vehicles(self) -> list[int]:
        return sorted({sysid for sysid, _ in self._autopilots})

    def _report(self, stats: FrameStats, first_ts: int | None) -> None:
        """Turn the framer's findings into problems: bounded lines, then a count."""

        def t_of(ts: int | None) -> float | None:
            if ts is None or first_ts is None:
                return None
            return round((ts - first_ts) / 1e6, 6)

        lines: list[SourceProblem] = []
        regions = stats.regions
        if stats.stopped_at is not None:  # the last region: where the search gave up
            last = regions[-1]
            regions = regions[:-1]
            lines.append(
                SourceProblem(
                    f"no MAVLink packet in the {RESYNC_LIMIT >> 20} MiB after byte {last.start}: "
                    f"reading stopped, the last {stats.size - stats.stopped_at} bytes were "
                    "not read",
                    f"byte {stats.stopped_at}",
                    t_of(last.ts_us),
                )
            )
        for region in regions:
            size = region.end - region.start
            lines.append(
                SourceProblem(
                    f"corrupt data ({region.why}), {size} bytes skipped",
                    f"bytes {region.start}-{region.end}",
                    t_of(region.ts_us),
                )
            )
        if len(lines) > MAX_PROBLEM_LINES:
            rest = lines[MAX_PROBLEM_LINES:]
            lines = lines[:MAX_PROBLEM_LINES]
            lines.append(SourceProblem(f"{len(rest)} more unreadable parts not listed"))
        if stats.truncated_at is not None:
            lines.append(
                SourceProblem(
                    f"truncated at byte {stats.size}: the last packet is incomplete",
                    f"byte {stats.truncated_at}",
                    t_of(stats.last_ts),
                )
            )
        self.problems.extend(lines)

    def _stats(self, stats: FrameStats, decoder: _Decoder) -> RecordingStats:
        return {
            "packets": stats.packets,
            "bad_data": len(stats.regions),
            "bad_data_bytes": sum(r.end - r.start for r in stats.regions),
            "unknown": {f"UNKNOWN_{msgid}": count for msgid, count in sorted(stats.unknown.items())}
            | ({"other": stats.unknown_other} if stats.unknown_other else {}),
            "truncated": stats.truncated_at is not None,
            "messages": {message_name(m): c for m, c in sorted(stats.by_id.items())},
            "ignored": dict(decoder.ignored),
        }


def _vehicle_sort(name: str) -> tuple[int, str]:
    return (int(name), name) if name.isdigit() else (1 << 30, name)


class _Decoder:
    """pymavlink messages -> events, knowing who the autopilots are."""

    def __init__(self, autopilots: set[tuple[int, int]], vehicles: list[int]) -> None:
        self.autopilots = autopilots
        self.vehicles = vehicles or [1]
        self.index: dict[int, int] = {}
        self.mav_type: dict[int, int] = {}
        self.ignored: dict[str, int] = {}
        self.target_names: dict[int, tuple[str, ...]] = {}
        self.handlers: dict[int, Callable[[Any, float, Where], Iterable[Event]]] = {
            SET_POSITION_TARGET_LOCAL_NED: self._local,
            SET_POSITION_TARGET_GLOBAL_INT: self._global,
            SET_ATTITUDE_TARGET: self._attitude,
            SET_ACTUATOR_CONTROL_TARGET: self._actuator_control,
            COMMAND_LONG: self._command_long,
            COMMAND_INT: self._command_int,
            SET_MODE: self._set_mode,
            HEARTBEAT: self._heartbeat,
            COMMAND_ACK: self._ack,
            PARAM_VALUE: self._param,
            AUTOPILOT_VERSION: self._version,
            STATUSTEXT: self._statustext,
            SYS_STATUS: self._sys_status,
            RC_CHANNELS: self._rc_channels,
            MANUAL_CONTROL: self._manual_control,
            LOCAL_POSITION_NED: self._position,
            EXTENDED_SYS_STATE: self._extended_sys_state,
        }
        self.landed: dict[int, bool | None] = {}
        self.vtol_phase: dict[int, VtolPhase | None] = {}
        """The newest ``EXTENDED_SYS_STATE.vtol_state`` per system, given to its HEARTBEAT's
        status (PX4 sends both about once a second)."""
        """Vehicle sysid -> on the ground, as last said (events only on a change)."""
        self.manual: dict[int, bool] = {}
        """Vehicle sysid -> manual control present, as last said (events only on a change)."""
        self.sys_status: set[int] = set()
        """Vehicles whose SYS_STATUS was seen: PX4's own verdict on manual control wins."""

    def decode(self, msgid: int, msg: Any, t: float, offset: int) -> Iterable[Event]:
        i = self.index.get(msgid, 0)
        self.index[msgid] = i + 1
        return self.handlers[msgid](msg, t, Where(message_name(msgid), i, offset))

    def _ignore(self, msg: Any, why: str) -> Iterable[Event]:
        key = f"{msg.get_type()} {why}"
        self.ignored[key] = self.ignored.get(key, 0) + 1
        return ()

    def from_autopilot(self, msg: Any) -> bool:
        """Is ``msg`` from a vehicle's autopilot (whose messages become events)?"""
        return self._from_autopilot(msg)

    def _from_autopilot(self, msg: Any) -> bool:
        compid = msg.get_srcComponent()
        return compid == MAV_COMP_ID_AUTOPILOT1 or (msg.get_srcSystem(), compid) in self.autopilots

    def _targets(self, target_system: int) -> tuple[str, ...]:
        """The vehicles a message addressed to ``target_system`` is for (0: every autopilot)."""
        names = self.target_names.get(target_system)
        if names is None:
            if target_system == 0:
                names = tuple(str(v) for v in self.vehicles)
            else:
                names = (str(target_system),)
            self.target_names[target_system] = names
        return names

    # -- sent to the vehicle --------------------------------------------------------------

    def _local(self, m: Any, t: float, where: Where) -> Iterable[Event]:
        if self._from_autopilot(m):
            return self._ignore(m, "from the autopilot")
        return [
            SetPositionTargetLocal(
                t=t,
                vehicle=v,
                where=where,
                sender_time_us=m.time_boot_ms * 1000,
                target_system=m.target_system,
                target_component=m.target_component,
                source_system=m.get_srcSystem(),
                source_component=m.get_srcComponent(),
                type_mask=m.type_mask,
                coordinate_frame=m.coordinate_frame,
                position=(m.x, m.y, m.z),
                velocity=(m.vx, m.vy, m.vz),
                acceleration=(m.afx, m.afy, m.afz),
                yaw=m.yaw,
                yaw_rate=m.yaw_rate,
            )
            for v in self._targets(m.target_system)
        ]

    def _global(self, m: Any, t: float, where: Where) -> Iterable[Event]:
        if self._from_autopilot(m):
            return self._ignore(m, "from the autopilot")
        return [
            SetPositionTargetGlobal(
                t=t,
                vehicle=v,
                where=where,
                sender_time_us=m.time_boot_ms * 1000,
                target_system=m.target_system,
                target_component=m.target_component,
                source_system=m.get_srcSystem(),
                source_component=m.get_srcComponent(),
                type_mask=m.type_mask,
                coordinate_frame=m.coordinate_frame,
                lat_int=m.lat_int,
                lon_int=m.lon_int,
                alt=m.alt,
                velocity=(m.vx, m.vy, m.vz),
                acceleration=(m.afx, m.afy, m.afz),
                yaw=m.yaw,
                yaw_rate=m.yaw_rate,
            )
            for v in self._targets(m.target_system)
        ]

    def _attitude(self, m: Any, t: float, where: Where) -> Iterable[Event]:
        if self._from_autopilot(m):
            return self._ignore(m, "from the autopilot")
        thrust_body = getattr(m, "thrust_body", None)  # not in pymavlink 2.4.50's dialects
        return [
            SetAttitudeTarget(
                t=t,
                vehicle=v,
                where=where,
                sender_time_us=m.time_boot_ms * 1000,
                target_system=m.target_system,
                target_component=m.target_component,
                source_system=m.get_srcSystem(),
                source_component=m.get_srcComponent(),
                type_mask=m.type_mask,
                q=(m.q[0], m.q[1], m.q[2], m.q[3]),
                body_roll_rate=m.body_roll_rate,
                body_pitch_rate=m.body_pitch_rate,
                body_yaw_rate=m.body_yaw_rate,
                thrust=m.thrust,
                thrust_body=tuple(thrust_body) if thrust_body and any(thrust_body) else None,
            )
            for v in self._targets(m.target_system)
        ]

    def _actuator_control(self, m: Any, t: float, where: Where) -> Iterable[Event]:
        if self._from_autopilot(m):
            return self._ignore(m, "from the autopilot")
        return [
            SetActuatorControlTarget(
                t=t,
                vehicle=v,
                where=where,
                sender_time_us=m.time_usec,
                group_mlx=m.group_mlx,
                controls=tuple(m.controls),
                target_system=m.target_system,
                target_component=m.target_component,
                source_system=m.get_srcSystem(),
                source_component=m.get_srcComponent(),
            )
            for v in self._targets(m.target_system)
        ]

    def _command(
        self,
        m: Any,
        t: float,
        where: Where,
        command: int,
        params: tuple[float, float, float, float, float, float, float],
        target_component: int,
        message: CommandMessage,
    ) -> Iterable[Event]:
        if self._from_autopilot(m):
            return self._ignore(m, "from the autopilot")
        return [
            Command(
                t=t,
                vehicle=v,
                where=where,
                command=command,
                params=params,
                target_system=m.target_system,
                target_component=target_component,
                source_system=m.get_srcSystem(),
                source_component=m.get_srcComponent(),
                from_external=True,
                message=message,
            )
            for v in self._targets(m.target_system)
        ]

    def _command_long(self, m: Any, t: float, where: Where) -> Iterable[Event]:
        params = (m.param1, m.param2, m.param3, m.param4, m.param5, m.param6, m.param7)
        return self._command(m, t, where, m.command, params, m.target_component, "COMMAND_LONG")

    def _command_int(self, m: Any, t: float, where: Where) -> Iterable[Event]:
        params = (m.param1, m.param2, m.param3, m.param4, float(m.x), float(m.y), m.z)
        return self._command(m, t, where, m.command, params, m.target_component, "COMMAND_INT")

    def _set_mode(self, m: Any, t: float, where: Where) -> Iterable[Event]:
        """SET_MODE (#11, MAVROS set_mode) -> DO_SET_MODE as PX4 handles it."""
        main, sub = split_custom_mode(m.custom_mode)
        params = (float(m.base_mode), float(main), float(sub), 0.0, 0.0, 0.0, 0.0)
        return self._command(m, t, where, MAV_CMD_DO_SET_MODE, params, 0, "SET_MODE")

    # -- from the vehicle -----------------------------------------------------------------

    def _heartbeat(self, m: Any, t: float, where: Where) -> Iterable[Event]:
        if not self._from_autopilot(m):
            return self._ignore(m, "not from an autopilot")
        sysid = m.get_srcSystem()
        vehicle = str(sysid)
        out: list[Event] = []
        if self.mav_type.get(sysid) != m.type:
            self.mav_type[sysid] = m.type
            out.append(
                VehicleInfo(
                    t=t,
                    vehicle=vehicle,
                    where=where,
                    mav_type=m.type,
                    vehicle_type=MAV_TYPE_VEHICLE.get(m.type),
                )
            )
        nav_state = None
        if m.base_mode & MAV_MODE_FLAG_CUSTOM_MODE_ENABLED:
            nav_state = custom_mode_to_nav_state(m.custom_mode)
        out.append(
            VehicleStatus(
                t=t,
                vehicle=vehicle,
                where=where,
                nav_state=nav_state,
                mode=nav_state_name(nav_state),
                armed=bool(m.base_mode & MAV_MODE_FLAG_SAFETY_ARMED),
                vtol_phase=self.vtol_phase.get(sysid),
            )
        )
        return out

    def _ack(self, m: Any, t: float, where: Where) -> Iterable[Event]:
        if not self._from_autopilot(m):
            return self._ignore(m, "not from an autopilot")
        ack = CommandAck(
            t=t,
            vehicle=str(m.get_srcSystem()),
            where=where,
            command=m.command,
            result=m.result,
            target_system=m.target_system,
            target_component=m.target_component,
        )
        return (ack,)

    def _param(self, m: Any, t: float, where: Where) -> Iterable[Event]:
        if not self._from_autopilot(m):
            return self._ignore(m, "not from an autopilot")
        param = Parameter(
            t=t,
            vehicle=str(m.get_srcSystem()),
            where=where,
            name=_text(m.param_id),
            value=param_value(m.param_value, m.param_type),
        )
        return (param,)

    def _version(self, m: Any, t: float, where: Where) -> Iterable[Event]:
        if not self._from_autopilot(m):
            return self._ignore(m, "not from an autopilot")
        info = VehicleInfo(
            t=t,
            vehicle=str(m.get_srcSystem()),
            where=where,
            px4_version=decode_px4_version(m.flight_sw_version),
        )
        return (info,)

    # -- manual control (RC or joystick) ------------------------------------------------------

    def _manual(self, sysid: int, present: bool, t: float, where: Where) -> Iterable[Event]:
        """A ``FailsafeFlags`` with only ``manual_control_signal_lost``, when it changes."""
        if self.manual.get(sysid) == present:
            return ()
        self.manual[sysid] = present
        flags = FailsafeFlags(
            t=t, vehicle=str(sysid), where=where, manual_control_signal_lost=not present
        )
        return (flags,)

    def _sys_status(self, m: Any, t: float, where: Where) -> Iterable[Event]:
        """PX4's verdict: the RC receiver bit present and healthy while it has manual control."""
        if not self._from_autopilot(m):
            return self._ignore(m, "not from an autopilot")
        sysid = m.get_srcSystem()
        self.sys_status.add(sysid)
        bit = MAV_SYS_STATUS_SENSOR_RC_RECEIVER
        present = bool(m.onboard_control_sensors_present & m.onboard_control_sensors_health & bit)
        return self._manual(sysid, present, t, where)

    def _rc_channels(self, m: Any, t: float, where: Where) -> Iterable[Event]:
        """PX4 sends RC_CHANNELS while an RC receiver delivers: present, where no SYS_STATUS
        says otherwise."""
        if not self._from_autopilot(m):
            return self._ignore(m, "not from an autopilot")
        sysid = m.get_srcSystem()
        if sysid in self.sys_status:
            return ()
        return self._manual(sysid, True, t, where)

    def _manual_control(self, m: Any, t: float, where: Where) -> Iterable[Event]:
        """A joystick on the ground station (MANUAL_CONTROL to the vehicle): present, where no
        SYS_STATUS says otherwise."""
        if self._from_autopilot(m):
            return self._ignore(m, "from the autopilot")
        out: list[Event] = []
        for vehicle in self._targets(m.target):
            sysid = int(vehicle)
            if sysid not in self.sys_status:
                out.extend(self._manual(sysid, True, t, where))
            out.append(_sticks(m, t, vehicle, where))
        return out

    def _position(self, m: Any, t: float, where: Where) -> Iterable[Event]:
        if not self._from_autopilot(m):
            return self._ignore(m, "not from an autopilot")
        return (_position_event(m, t, where),)

    def _extended_sys_state(self, m: Any, t: float, where: Where) -> Iterable[Event]:
        """PX4's ``landed_state``: ON_GROUND while its land detector says landed; IN_AIR,
        TAKEOFF and LANDING otherwise (``maybe_landed`` shows as in the air here)."""
        if not self._from_autopilot(m):
            return self._ignore(m, "not from an autopilot")
        sysid = m.get_srcSystem()
        self.vtol_phase[sysid] = MAV_VTOL_STATE_PHASE.get(getattr(m, "vtol_state", 0))
        state = m.landed_state
        landed = (
            None if state == MAV_LANDED_STATE_UNDEFINED else state == MAV_LANDED_STATE_ON_GROUND
        )
        if sysid in self.landed and self.landed[sysid] == landed:
            return ()
        self.landed[sysid] = landed
        return (LandDetected(t=t, vehicle=str(sysid), where=where, landed=landed),)

    def _statustext(self, m: Any, t: float, where: Where) -> Iterable[Event]:
        if not self._from_autopilot(m):
            return self._ignore(m, "not from an autopilot")
        text = StatusText(
            t=t,
            vehicle=str(m.get_srcSystem()),
            where=where,
            severity=m.severity,
            text=_text(m.text),
        )
        return (text,)


def _position_event(m: Any, t: float, where: Where = NOWHERE) -> VehiclePosition:
    """LOCAL_POSITION_NED as the vehicle's position (NED metres)."""
    return VehiclePosition(t=t, vehicle=str(m.get_srcSystem()), where=where, x=m.x, y=m.y, z=m.z)
