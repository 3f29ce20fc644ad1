"""MAVLink .tlog: the writer and reader round-trip every kind; bad input is reported, not raised."""

from __future__ import annotations

import dataclasses
import itertools
import json
import math
import os
import struct
from pathlib import Path
from typing import Any

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

os.environ.setdefault("MAVLINK20", "1")

from pymavlink.dialects.v20 import common as mavlink

from fuzzoff.events import (
    Command,
    CommandAck,
    ControlMode,
    Event,
    Parameter,
    SetAttitudeTarget,
    SetPositionTargetGlobal,
    SetPositionTargetLocal,
    StatusText,
    VehicleInfo,
    VehicleStatus,
    Where,
)
from fuzzoff.formats import SourceError, open_source
from fuzzoff.formats.tlog.reader import TlogSource
from fuzzoff.formats.tlog.writer import DEFAULT_START_US, write_tlog
from fuzzoff.modes import custom_mode_to_nav_state, nav_state_name, nav_state_to_custom_mode
from tests.helpers import run_cli, run_cli_process

SENT: dict[str, Any] = {
    "source_system": 1,
    "source_component": 191,
    "target_system": 1,
    "target_component": 1,
}


def flight() -> list[Event]:
    """One of every kind the tlog reader emits (float values exact in float32)."""
    return [
        VehicleInfo(t=0.0, vehicle="1", px4_version="1.15.4"),
        VehicleInfo(t=0.25, vehicle="1", mav_type=2, vehicle_type="mc"),
        VehicleStatus(t=0.25, vehicle="1", nav_state=2, mode="POSCTL", armed=False),
        Parameter(t=0.5, vehicle="1", name="COM_OF_LOSS_T", value=1.0),
        Parameter(t=0.5, vehicle="1", name="COM_OBL_RC_ACT", value=3.0),
        Parameter(t=0.5, vehicle="1", name="COM_RC_OVERRIDE", value=-1.0),
        SetPositionTargetLocal(
            t=1.0,
            vehicle="1",
            sender_time_us=1_000_000,
            type_mask=0x09F8,
            coordinate_frame=1,
            position=(1.5, -2.0, -3.25),
            velocity=(0.5, 0.0, 0.0),
            acceleration=(0.0, 0.25, 0.0),
            yaw=1.5,
            yaw_rate=0.125,
            **SENT,
        ),
        SetPositionTargetGlobal(
            t=1.1,
            vehicle="1",
            sender_time_us=1_100_000,
            type_mask=0x0DF8,
            coordinate_frame=6,
            lat_int=473_977_418,
            lon_int=85_455_939,
            alt=12.5,
            **SENT,
        ),
        SetAttitudeTarget(
            t=1.2,
            vehicle="1",
            sender_time_us=1_200_000,
            type_mask=7,
            q=(1.0, 0.0, 0.0, 0.0),
            thrust=0.5,
            **SENT,
        ),
        Command(
            t=1.5,
            vehicle="1",
            command=176,
            params=(1.0, 6.0, 0.0, 0.0, 0.0, 0.0, 0.0),
            from_external=True,
            message="COMMAND_LONG",
            **SENT,
        ),
        CommandAck(
            t=1.52, vehicle="1", command=176, result=0, target_system=1, target_component=191
        ),
        VehicleStatus(t=2.0, vehicle="1", nav_state=14, mode="OFFBOARD", armed=True),
        StatusText(t=3.0, vehicle="1", severity=4, text="Failsafe activated"),
    ]


def read(path: Path) -> tuple[TlogSource, list[Event]]:
    source = open_source(path)
    assert isinstance(source, TlogSource)
    with source:
        source.probe()
        events = list(source.events())
    return source, events


def strip(event: Event) -> Event:
    """The event without the reader's file position (the writer cannot know it)."""
    return dataclasses.replace(event, where=Where(""))


def test_every_kind_round_trips(tmp_path: Path) -> None:
    events = flight()
    path = write_tlog(tmp_path / "flight.tlog", events)
    source, back = read(path)
    assert [strip(e) for e in back] == [strip(e) for e in events]
    assert not source.problems


def test_events_say_where_they_are(tmp_path: Path) -> None:
    path = write_tlog(tmp_path / "flight.tlog", flight())
    _, back = read(path)
    setpoint = next(e for e in back if isinstance(e, SetPositionTargetLocal))
    assert setpoint.where.topic == "SET_POSITION_TARGET_LOCAL_NED"
    assert setpoint.where.index == 0
    assert setpoint.where.offset is not None and setpoint.where.offset > 0
    data = path.read_bytes()
    assert data[setpoint.where.offset + 8] == 0xFD  # a record starts there


def test_mavlink1_packets_read_the_same(tmp_path: Path) -> None:
    events = flight()
    path = write_tlog(tmp_path / "v1.tlog", events, mavlink1=True)
    _, back = read(path)
    assert [strip(e) for e in back] == [strip(e) for e in events]


def test_probe_names_version_vehicle_kinds_and_count(tmp_path: Path) -> None:
    path = write_tlog(tmp_path / "flight.tlog", flight())
    source = open_source(path)
    with source:
        info = source.probe()
    assert info.px4_version == "1.15.4"
    assert info.vehicle_type == "mc"
    assert info.vehicles == ["1"]
    # one packet per event, but the VehicleInfo(mav_type) rides on the next HEARTBEAT; + GCS
    assert info.message_count == len(flight()) - 1 + 1
    assert {
        "vehicle_status",
        "vehicle_info",
        "set_position_target_local_ned",
        "set_position_target_global_int",
        "set_attitude_target",
        "command",
        "command_ack",
        "parameter",
        "status_text",
    } == info.kinds


def test_vehicles_are_told_apart_and_broadcast_goes_to_each(tmp_path: Path) -> None:
    events: list[Event] = [
        VehicleStatus(t=0.0, vehicle="1", nav_state=2, mode="POSCTL", armed=False),
        VehicleStatus(t=0.0, vehicle="2", nav_state=2, mode="POSCTL", armed=False),
        SetPositionTargetLocal(t=0.5, vehicle="2", target_system=2, target_component=1),
    ]
    path = write_tlog(tmp_path / "two.tlog", events)
    # a broadcast setpoint (target_system 0) from the companion of vehicle 1
    broadcast = _pack(
        mavlink.MAVLink_set_position_target_local_ned_message(
            0, 0, 0, 1, 0x09F8, 0, 0, -1, 0, 0, 0, 0, 0, 0, 0, 0
        ),
        (1, 191),
    )
    with path.open("ab") as fh:
        fh.write(struct.pack(">Q", DEFAULT_START_US + 600_000) + broadcast)
    source, back = read(path)
    assert source.probe().vehicles == ["1", "2"]
    setpoints = [e for e in back if isinstance(e, SetPositionTargetLocal)]
    assert [(e.vehicle, e.target_system) for e in setpoints] == [("2", 2), ("1", 0), ("2", 0)]
    assert setpoints[0].source_system == 2 and setpoints[0].source_component == 191


def _pack(msg: Any, sender: tuple[int, int]) -> bytes:
    class Capture:
        data = b""

        def write(self, data: bytes) -> None:
            Capture.data = bytes(data)

    link = mavlink.MAVLink(Capture(), srcSystem=sender[0], srcComponent=sender[1])
    link.send(msg)
    return Capture.data


def _tlog(path: Path, packets: list[tuple[float, bytes]]) -> Path:
    path.write_bytes(
        b"".join(struct.pack(">Q", DEFAULT_START_US + round(t * 1e6)) + p for t, p in packets)
    )
    return path


def test_set_mode_and_command_int_become_commands(tmp_path: Path) -> None:
    custom = nav_state_to_custom_mode(14)
    path = _tlog(
        tmp_path / "modes.tlog",
        [
            (0.0, _pack(mavlink.MAVLink_heartbeat_message(2, 12, 1, 0, 4, 3), (1, 1))),
            (0.5, _pack(mavlink.MAVLink_set_mode_message(1, 1, custom), (1, 240))),
            (
                0.75,
                _pack(
                    mavlink.MAVLink_command_int_message(1, 1, 0, 400, 0, 0, 1, 0, 0, 0, 7, 8, 9),
                    (255, 190),
                ),
            ),
        ],
    )
    _, back = read(path)
    commands = [e for e in back if isinstance(e, Command)]
    assert commands[0].command == 176 and commands[0].params[:3] == (1.0, 6.0, 0.0)
    assert commands[0].is_offboard_switch
    assert (commands[0].source_system, commands[0].source_component) == (1, 240)
    assert commands[0].t == 0.5
    assert commands[1].is_arm and commands[1].params[4:] == (7.0, 8.0, 9.0)


def test_heartbeat_mode_and_arming(tmp_path: Path) -> None:
    _, back = read(
        write_tlog(
            tmp_path / "hb.tlog",
            [VehicleStatus(t=0.0, vehicle="1", nav_state=14, mode="OFFBOARD", armed=True)],
        )
    )
    (status,) = [e for e in back if isinstance(e, VehicleStatus)]
    assert status.in_offboard and status.armed and status.mode == "OFFBOARD"


def _nan_free(value: int) -> bool:
    """An INT32 parameter travels as its bytes in PARAM_VALUE's float field. Integers whose
    bytes are a signalling NaN cannot be written through pymavlink's encoder: Python turns the
    float into a double and back, which sets the quiet bit (-4194305 arrives as -1)."""
    bits = value & 0xFFFFFFFF
    exponent, quiet, fraction = (bits >> 23) & 0xFF, bits & 0x400000, bits & 0x3FFFFF
    return not (exponent == 0xFF and not quiet and fraction)


def test_int32_parameter_is_decoded_from_its_bytes(tmp_path: Path) -> None:
    # PX4 sends COM_OBL_RC_ACT = 5 as the int32's bytes in the float field (param_type 6)
    (as_float,) = struct.unpack("<f", struct.pack("<i", 5))
    path = _tlog(
        tmp_path / "param.tlog",
        [
            (
                0.0,
                _pack(
                    mavlink.MAVLink_param_value_message(b"COM_OBL_RC_ACT", as_float, 6, 1, 0),
                    (1, 1),
                ),
            )
        ],
    )
    _, back = read(path)
    (param,) = back
    assert isinstance(param, Parameter) and param.value == 5.0


# -------------------------------------------------------------------------------- bad input


@pytest.fixture
def good(tmp_path: Path) -> Path:
    events: list[Event] = [VehicleInfo(t=0.0, vehicle="1", px4_version="1.15.4")]
    events += [
        SetPositionTargetLocal(t=0.1 * i, vehicle="1", type_mask=0x09F8, **SENT)
        for i in range(1, 60)
    ]
    return write_tlog(tmp_path / "good.tlog", events)


def _records(path: Path) -> list[int]:
    """Start offsets of the records, from the reader's own positions."""
    _, events = read(path)
    return [e.where.offset for e in events if e.where.offset is not None]


@pytest.mark.parametrize("fraction", [0.1, 0.5, 0.9, 0.999])
def test_truncated_file_keeps_what_came_before(good: Path, fraction: float) -> None:
    data = good.read_bytes()
    offsets = _records(good)
    cut = int(len(data) * fraction)
    if cut in offsets:
        cut += 1
    bad = good.with_name("cut.tlog")
    bad.write_bytes(data[:cut])
    source, events = read(bad)
    complete = [o for o in offsets if o < cut]
    last_start = complete[-1]
    assert len(events) == len(complete) - 1  # the one cut in the middle is lost
    (problem,) = source.problems
    assert problem.what.startswith(f"truncated at byte {cut}")
    assert problem.where == f"byte {last_start}"
    assert source.stats["truncated"] is True


def test_flipped_bytes_are_reported_and_reading_resumes(good: Path) -> None:
    data = bytearray(good.read_bytes())
    middle = len(data) // 2
    for i in range(middle, middle + 40):
        data[i] ^= 0xFF
    bad = good.with_name("flipped.tlog")
    bad.write_bytes(bytes(data))
    source, events = read(bad)
    assert 50 <= len(events) < 60  # a few lost, the rest kept
    assert events[-1].t == pytest.approx(5.9)
    (problem,) = source.problems
    assert problem.what.startswith("corrupt data")
    assert problem.where is not None
    start, end = (int(x) for x in problem.where.removeprefix("bytes ").split("-"))
    assert start <= middle and end >= middle + 40
    assert source.stats["bad_data"] == 1


def test_one_flipped_payload_byte_is_a_bad_crc(good: Path) -> None:
    offsets = _records(good)
    data = bytearray(good.read_bytes())
    data[offsets[10] + 8 + 12] ^= 0x01  # inside the payload of the 11th setpoint
    bad = good.with_name("bit.tlog")
    bad.write_bytes(bytes(data))
    source, events = read(bad)
    assert len(events) == len(offsets) - 1
    (problem,) = source.problems
    assert problem.where == f"bytes {offsets[10]}-{offsets[11]}"


def test_many_corrupt_regions_give_bounded_lines(good: Path) -> None:
    offsets = _records(good)
    data = bytearray(good.read_bytes())
    for start in offsets[1:50:2]:
        data[start + 8 + 12] ^= 0x01
    bad = good.with_name("many.tlog")
    bad.write_bytes(bytes(data))
    source, _ = read(bad)
    assert source.stats["bad_data"] == 25
    assert len(source.problems) == 11
    assert source.problems[-1].what == "15 more unreadable parts not listed"


def _unknown_record(payload_len: int, declared_len: int | None = None) -> bytes:
    """A MAVLink 2 packet of id 42424, which no dialect defines, with any CRC (none to check)."""
    declared = payload_len if declared_len is None else declared_len
    header = bytes([0xFD, declared, 0, 0, 0, 1, 1, 0xB8, 0xA5, 0x00])
    packet = header + bytes(range(7, 7 + payload_len)) + b"\xaa\xbb"
    return struct.pack(">Q", DEFAULT_START_US + 250_000) + packet


def test_unknown_message_ids_are_ordinary_traffic(good: Path) -> None:
    # PX4 sends ids newer than pymavlink's dialect (8, 380, 410, 411): counted, not a problem
    data = good.read_bytes()
    offsets = _records(good)
    bad = good.with_name("unknown.tlog")
    bad.write_bytes(data[: offsets[3]] + _unknown_record(2) + data[offsets[3] :])
    source, events = read(bad)
    assert len(events) == len(offsets)
    assert source.problems == []
    assert source.stats["unknown"] == {"UNKNOWN_42424": 1}
    assert source.stats["messages"]["UNKNOWN_42424"] == 1
    code, report, _ = _lint(bad)
    assert code == 0 and report["complete"] is True


@pytest.mark.parametrize("declared", [0, 1, 5, 40])
def test_an_unknown_id_whose_length_misses_the_next_record_is_corrupt(
    good: Path, declared: int
) -> None:
    # no CRC to check it with: its framing must hold, or the bytes are reported as corrupt
    data = good.read_bytes()
    offsets = _records(good)
    bad = good.with_name("badlength.tlog")
    bad.write_bytes(data[: offsets[3]] + _unknown_record(2, declared) + data[offsets[3] :])
    source, events = read(bad)
    assert source.stats["bad_data"] == 1
    (problem,) = source.problems
    assert "corrupt data (bad length)" in problem.what
    assert problem.where is not None and problem.where.startswith(f"bytes {offsets[3]}-")
    assert len(events) == len(offsets) - 1 or len(events) == len(offsets)
    assert "UNKNOWN_42424" not in source.stats["unknown"]


def test_an_unknown_id_at_the_end_must_end_the_file(good: Path) -> None:
    data = good.read_bytes()
    ends_well = good.with_name("ends.tlog")
    ends_well.write_bytes(data + _unknown_record(2))
    source, _ = read(ends_well)
    assert source.problems == [] and source.stats["unknown"] == {"UNKNOWN_42424": 1}
    overlong = good.with_name("overlong.tlog")
    overlong.write_bytes(data + _unknown_record(2) + b"\x00\x01\x02")
    source, _ = read(overlong)
    assert source.problems and "UNKNOWN_42424" not in source.stats["unknown"]


def test_unreadable_files_raise_one_clear_error(tmp_path: Path) -> None:
    foreign = tmp_path / "foreign.tlog"
    foreign.write_bytes(b"\x00" * 8 + b"\xfd" + b"not mavlink at all" * 10)
    with pytest.raises(SourceError, match="no MAVLink packet found"):
        read(foreign)
    stub = tmp_path / "stub.tlog"
    stub.write_bytes(write_tlog(tmp_path / "x.tlog", flight()).read_bytes()[:20])
    with pytest.raises(SourceError, match="truncated at byte 20: no complete packet"):
        read(stub)


# ------------------------------------------------------------------------------ through the CLI


def _lint(path: Path) -> tuple[int, dict[str, Any], str]:
    result = run_cli(["lint", str(path), "--format", "json"])
    return result.returncode, json.loads(result.stdout)["files"][0], result.stderr


@pytest.mark.parametrize(
    ("content", "what"),
    [
        (b"", "empty file"),
        (b"This is a text file, not a telemetry log.\n", "not a recording"),
        (b"\x00" * 8 + b"\xfe" + b"\x00" * 40, "no MAVLink packet found"),
    ],
)
def test_cli_unreadable_file_exit_2_one_line(tmp_path: Path, content: bytes, what: str) -> None:
    path = tmp_path / "bad.tlog"
    path.write_bytes(content)
    code, report, stderr = _lint(path)
    assert code == 2
    assert report["complete"] is False
    (line,) = stderr.strip().splitlines()
    assert str(path) in line and what in line
    assert "Traceback" not in stderr


def test_cli_truncated_keeps_findings_of_the_readable_part(tmp_path: Path) -> None:
    # 1 s of stream in POSCTL, then a switch 0.1 s after a 0.9 s gap -> findings before the cut
    events: list[Event] = [
        VehicleInfo(t=0.0, vehicle="1", px4_version="1.15.4"),
        VehicleInfo(t=0.0, vehicle="1", mav_type=2),
        VehicleStatus(t=0.0, vehicle="1", nav_state=2, armed=True),
    ]
    events += [
        SetPositionTargetLocal(t=0.1 + 0.1 * i, vehicle="1", type_mask=0x09F8, **SENT)
        for i in range(5)
    ]
    events.append(Command(t=0.55, vehicle="1", command=176, params=(1, 6, 0, 0, 0, 0, 0), **SENT))
    events.append(CommandAck(t=0.56, vehicle="1", command=176, result=0))
    events.append(VehicleStatus(t=0.6, vehicle="1", nav_state=14, armed=True))
    events += [
        SetPositionTargetLocal(t=2.0 + 0.1 * i, vehicle="1", type_mask=0x09F8, **SENT)
        for i in range(30)
    ]
    path = write_tlog(tmp_path / "flight.tlog", events)
    _, whole, _ = _lint(path)
    data = path.read_bytes()
    cut = path.with_name("cut.tlog")
    cut.write_bytes(data[: len(data) - 10])
    result = run_cli_process(["lint", str(cut), "--format", "json"])
    assert result.returncode == 2
    assert "Traceback" not in result.stderr
    (line,) = result.stderr.strip().splitlines()
    assert str(cut) in line and f"truncated at byte {len(data) - 10}" in line and "at byte" in line
    report = json.loads(result.stdout)["files"][0]
    assert report["complete"] is False
    codes = [f["code"] for f in report["findings"]]
    assert "OFB001" in codes
    whole_codes = [f["code"] for f in whole["findings"]]
    assert whole_codes, "the planted gap should give findings"
    for code in whole_codes:
        assert code in codes


def test_signed_packets_are_read(tmp_path: Path) -> None:
    class Capture:
        data = b""

        def write(self, data: bytes) -> None:
            Capture.data = bytes(data)

    link = mavlink.MAVLink(Capture(), srcSystem=1, srcComponent=191)
    link.signing.secret_key = bytes(range(32))
    link.signing.sign_outgoing = True
    link.signing.link_id = 1
    records = []
    for i in range(3):
        link.send(
            mavlink.MAVLink_set_position_target_local_ned_message(
                i, 1, 1, 1, 0x09F8, 0, 0, -1, 0, 0, 0, 0, 0, 0, 0, 0
            )
        )
        assert Capture.data[2] & 1  # the signed flag
        records.append((0.1 * i, Capture.data))
        link.send(mavlink.MAVLink_attitude_message(i, 0, 0, 0, 0, 0, 0))
        records.append((0.1 * i + 0.01, Capture.data))
    source, back = read(_tlog(tmp_path / "signed.tlog", records))
    assert [e.sender_time_us for e in back] == [0, 1000, 2000]
    assert not source.problems and source.stats["messages"]["ATTITUDE"] == 3


def test_cli_corrupt_middle_exit_2_and_names_the_bytes(good: Path) -> None:
    offsets = _records(good)
    data = bytearray(good.read_bytes())
    for i in range(offsets[20] + 3, offsets[20] + 30):
        data[i] ^= 0x5A
    bad = good.with_name("corrupt.tlog")
    bad.write_bytes(bytes(data))
    code, report, stderr = _lint(bad)
    assert code == 2 and report["complete"] is False
    (line,) = stderr.strip().splitlines()
    assert str(bad) in line and "corrupt data" in line and f"bytes {offsets[20]}-" in line
    assert report["stats"]["bad_data"] == 1
    assert report["stats"]["messages"]["SET_POSITION_TARGET_LOCAL_NED"] == len(offsets) - 2


def test_writer_refuses_or_skips_what_a_tlog_cannot_carry(tmp_path: Path) -> None:
    events: list[Event] = [
        ControlMode(t=0.0, position=True),
        VehicleStatus(t=0.5, vehicle="1", nav_state=2, armed=False),
    ]
    with pytest.raises(ValueError, match="ControlMode"):
        write_tlog(tmp_path / "x.tlog", events)
    _, back = read(write_tlog(tmp_path / "y.tlog", events, skip_unsupported=True))
    assert [e.kind for e in back] == ["vehicle_info", "vehicle_status"]


def test_a_corrupt_timestamp_is_skipped_but_a_real_pause_is_kept(good: Path) -> None:
    offsets = _records(good)
    data = bytearray(good.read_bytes())
    data[offsets[30] + 3] ^= 0x40  # the timestamp of one record jumps by days
    spiked = good.with_name("spike.tlog")
    spiked.write_bytes(bytes(data))
    source, events = read(spiked)
    assert len(events) == len(offsets) - 1
    assert all(b.t >= a.t for a, b in itertools.pairwise(events))
    (problem,) = source.problems
    assert "implausible timestamp" in problem.what
    assert problem.where == f"bytes {offsets[30]}-{offsets[31]}"

    paused: list[Event] = [
        SetPositionTargetLocal(t=t, vehicle="1", type_mask=0x09F8, **SENT)
        for t in (0.0, 0.1, 0.2, 600.0, 600.1)
    ]
    source, events = read(write_tlog(good.with_name("pause.tlog"), paused))
    assert [e.t for e in events] == [0.0, 0.1, 0.2, 600.0, 600.1]
    assert not source.problems


# ------------------------------------------------------------------------- round-trip property

_F32 = st.floats(width=32, allow_nan=False, allow_infinity=False)
_U8 = st.integers(0, 255)
_SENDER = st.tuples(st.integers(1, 255), st.integers(2, 255))  # never compid 1 (autopilot)
_NAV_STATES = [n for n in range(31) if custom_mode_to_nav_state(nav_state_to_custom_mode(n)) == n]


@st.composite
def _sent(draw: st.DrawFn) -> dict[str, Any]:
    target = draw(st.integers(1, 255))
    sysid, compid = draw(_SENDER)
    return {
        "vehicle": str(target),
        "target_system": target,
        "target_component": draw(_U8),
        "source_system": sysid,
        "source_component": compid,
    }


@st.composite
def _event(draw: st.DrawFn, t: float) -> Event:
    ms = draw(st.integers(0, 2**32 - 1)) * 1000
    vec = st.tuples(_F32, _F32, _F32)
    kind = draw(st.sampled_from(range(8)))
    if kind == 0:
        return SetPositionTargetLocal(
            t=t,
            sender_time_us=ms,
            type_mask=draw(st.integers(0, 0xFFFF)),
            coordinate_frame=draw(_U8),
            position=draw(vec),
            velocity=draw(vec),
            acceleration=draw(vec),
            yaw=draw(_F32),
            yaw_rate=draw(_F32),
            **draw(_sent()),
        )
    if kind == 1:
        return SetPositionTargetGlobal(
            t=t,
            sender_time_us=ms,
            type_mask=draw(st.integers(0, 0xFFFF)),
            coordinate_frame=draw(_U8),
            lat_int=draw(st.integers(-(2**31), 2**31 - 1)),
            lon_int=draw(st.integers(-(2**31), 2**31 - 1)),
            alt=draw(_F32),
            velocity=draw(vec),
            acceleration=draw(vec),
            yaw=draw(_F32),
            yaw_rate=draw(_F32),
            **draw(_sent()),
        )
    if kind == 2:
        return SetAttitudeTarget(
            t=t,
            sender_time_us=ms,
            type_mask=draw(_U8),
            q=draw(st.tuples(_F32, _F32, _F32, _F32)),
            body_roll_rate=draw(_F32),
            body_pitch_rate=draw(_F32),
            body_yaw_rate=draw(_F32),
            thrust=draw(_F32),
            **draw(_sent()),
        )
    if kind == 3:
        params = draw(st.tuples(*[_F32] * 7))
        return Command(
            t=t,
            command=draw(st.integers(0, 0xFFFF)),
            params=params,
            from_external=True,
            message="COMMAND_LONG",
            **draw(_sent()),
        )
    if kind == 4:
        return CommandAck(
            t=t,
            vehicle="1",
            command=draw(st.integers(0, 0xFFFF)),
            result=draw(_U8),
            target_system=draw(_U8),
            target_component=draw(_U8),
        )
    if kind == 5:
        name = draw(st.text("ABCDEFGHIJKLMNOPQRSTUVWXYZ_0123456789", min_size=1, max_size=16))
        value = draw(st.one_of(_F32, st.integers(-(2**31), 2**31 - 1).filter(_nan_free).map(float)))
        return Parameter(t=t, vehicle="1", name=name, value=value)
    if kind == 6:
        nav = draw(st.sampled_from(_NAV_STATES))
        return VehicleStatus(
            t=t, vehicle="1", nav_state=nav, mode=nav_state_name(nav), armed=draw(st.booleans())
        )
    if kind == 7 and draw(st.booleans()):
        version = ".".join(str(draw(st.integers(0, 255))) for _ in range(3))
        return VehicleInfo(t=t, vehicle="1", px4_version=version)
    text = draw(st.text(st.characters(min_codepoint=32, max_codepoint=126), max_size=50))
    return StatusText(t=t, vehicle="1", severity=draw(st.integers(0, 7)), text=text.rstrip())


@st.composite
def _stream(draw: st.DrawFn) -> list[Event]:
    steps = draw(st.lists(st.integers(0, 2000), max_size=25))
    start: list[Event] = [
        VehicleInfo(t=0.0, vehicle="1", mav_type=2, vehicle_type="mc"),
        VehicleStatus(t=0.0, vehicle="1", nav_state=2, mode="POSCTL", armed=False),
    ]
    ms = 0
    for step in steps:
        ms += step
        start.append(draw(_event(ms / 1000)))
    return start


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(_stream())
def test_round_trip_property(tmp_path_factory: pytest.TempPathFactory, events: list[Event]) -> None:
    path = write_tlog(tmp_path_factory.mktemp("rt") / "rt.tlog", events)
    source, back = read(path)
    assert not source.problems
    assert [strip(e) for e in back] == [strip(e) for e in events]


def test_a_reader_that_gives_up_midway_keeps_the_findings_before(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """A reader error raised while streaming ends the file there: one OFB001 line, and the
    findings on what was read (the 0.7 s gap at 8 s) stay."""
    from fuzzoff.engine import lint_file

    recording = Path(__file__).parent.parent / "corpora" / "tlog" / "stream_lost_in_offboard.tlog"
    original = TlogSource.events

    def give_up_at_10s(self: TlogSource) -> Any:
        for event in original(self):
            if event.t > 10.0:
                raise SourceError(self.path, "simulated damage", "offset 1234")
            yield event

    monkeypatch.setattr(TlogSource, "events", give_up_at_10s)
    report = lint_file(recording)
    codes = [f.code for f in report.findings]
    assert "OFB101" in codes and "OFB103" in codes
    assert report.complete is False
    assert report.problems == [f"{recording}: simulated damage at offset 1234"]


@pytest.mark.parametrize("value", [math.nan, math.inf, -math.inf])
def test_non_finite_command_and_parameter_values_are_linted(tmp_path: Path, value: float) -> None:
    # MAVLink carries them as any other float; PX4 would cast them to whole numbers (undefined
    # in C). fuzzoff lints on: such a DO_SET_MODE is not a switch to offboard, and such a
    # parameter is shown as recorded but not applied to the gate model.
    head = [e for e in flight() if not isinstance(e, Command | CommandAck | StatusText)]
    odd = [
        Parameter(t=0.6, vehicle="1", name=name, value=value)
        for name in ("COM_OF_LOSS_T", "MAV_COMP_ID", "MAV_SYS_ID", "NAV_RCL_ACT", "COM_OBL_RC_ACT")
    ]
    commands = [
        Command(t=1.5, vehicle="1", command=176, params=(value, 6.0, 0, 0, 0, 0, 0), **SENT),
        Command(t=1.6, vehicle="1", command=176, params=(1.0, value, value, 0, 0, 0, 0), **SENT),
        Command(t=1.7, vehicle="1", command=400, params=(value, value, 0, 0, 0, 0, 0), **SENT),
    ]
    events = sorted([*head, *odd, *commands], key=lambda e: e.t)
    path = write_tlog(tmp_path / "odd.tlog", events)
    with open_source(path) as source:
        read = [e for e in source.events() if isinstance(e, Command)]
    assert [e.is_offboard_switch or e.is_arm or e.is_disarm for e in read] == [False] * 3
    result = run_cli(["lint", str(path), "--format", "json"])
    assert result.returncode in (0, 1), result.stderr
    (report,) = json.loads(result.stdout)["files"]
    assert report["complete"] is True
