"""ROS 1 bags: events -> bag -> events round trip, and damaged bags through the CLI."""

from __future__ import annotations

import json
import math
import struct
from dataclasses import fields, replace
from pathlib import Path
from typing import Any

import pytest
from rosbags.rosbag1 import Writer

from fuzzoff.events import (
    NOWHERE,
    Command,
    Event,
    SetAttitudeTarget,
    SetPositionTargetGlobal,
    SetPositionTargetLocal,
    VehicleStatus,
)
from fuzzoff.formats import detect_format, open_source
from fuzzoff.formats.rosbag1.reader import Rosbag1Source
from fuzzoff.formats.rosbag1.writer import _Builder, mavros_typestore, write_rosbag1
from tests.helpers import run_cli, run_cli_process

MAVROS: dict[str, Any] = {"target_system": 1, "target_component": 1, "transport": "mavros"}


def flight(n: int = 60, start: float = 0.0) -> list[Event]:
    """Setpoints at 20 Hz; the state shows OFFBOARD after 1.5 s of them."""
    events: list[Event] = [VehicleStatus(t=start, nav_state=2, mode="POSCTL", armed=True)]
    for i in range(n):
        t = start + 0.05 * (i + 1)
        events.append(
            SetPositionTargetLocal(
                t=t, type_mask=0x09F8, position=(1.0, -2.0, -3.0 - i / 100), yaw=0.25, **MAVROS
            )
        )
        if i == 30:
            events.append(VehicleStatus(t=t + 0.001, nav_state=14, mode="OFFBOARD", armed=True))
    return events


def read(path: Path) -> tuple[list[Event], Rosbag1Source]:
    source = open_source(path)
    assert isinstance(source, Rosbag1Source)
    with source:
        source.probe()
        return list(source.events()), source


def assert_same(a: Event, b: Event) -> None:
    assert type(a) is type(b)
    for f in fields(a):
        x, y = getattr(a, f.name), getattr(b, f.name)
        if f.name == "where":
            continue
        if isinstance(x, tuple) and f.name == "q":  # the same rotation, sign may differ
            sign = 1.0 if sum(p * q for p, q in zip(x, y, strict=True)) >= 0 else -1.0
            assert all(abs(p - sign * q) < 1e-6 for p, q in zip(x, y, strict=True)), f.name
        elif isinstance(x, tuple):
            assert all(abs(p - q) < 1e-6 for p, q in zip(x, y, strict=True)), (f.name, x, y)
        elif isinstance(x, float):
            assert math.isclose(x, y, abs_tol=1e-6) or (math.isnan(x) and math.isnan(y)), f.name
        else:
            assert x == y, (f.name, x, y)


def test_round_trip_every_kind_mavros_carries(tmp_path: Path) -> None:
    events: list[Event] = [
        VehicleStatus(t=0.25, nav_state=2, mode="POSCTL", armed=False),
        SetPositionTargetLocal(
            t=0.3,
            type_mask=0x0DC0,
            coordinate_frame=1,
            position=(1.5, -2.0, -3.0),
            velocity=(0.5, 0.25, -1.0),
            acceleration=(0.0, 0.1, 0.2),
            yaw=-2.5,
            yaw_rate=0.3,
            sender_time_us=4_000_000,
            **MAVROS,
        ),
        SetPositionTargetLocal(
            t=0.35,
            type_mask=0x05C7,
            coordinate_frame=9,
            velocity=(1.0, 2.0, 3.0),
            yaw=1.0,
            yaw_rate=-0.5,
            **MAVROS,
        ),
        SetPositionTargetGlobal(
            t=0.4,
            type_mask=0x0FF8,
            coordinate_frame=6,
            lat_int=-337654321,
            lon_int=1512345678,
            alt=55.5,
            velocity=(1.0, 0.0, -0.5),
            yaw=3.0,
            yaw_rate=0.1,
            **MAVROS,
        ),
        SetAttitudeTarget(
            t=0.45,
            type_mask=7,
            q=(0.8, 0.2, -0.4, 0.4),
            body_roll_rate=0.1,
            body_pitch_rate=-0.2,
            body_yaw_rate=0.3,
            thrust=0.55,
            **MAVROS,
        ),
        VehicleStatus(t=0.5, vehicle="/uav2", nav_state=14, mode="OFFBOARD", armed=True),
        Command(t=0.6, command=176),  # no MAVROS topic: left out
    ]
    path = write_rosbag1(tmp_path / "all.bag", events)
    assert detect_format(path) == "rosbag1"
    back, source = read(path)
    assert not source.problems
    expected = [e for e in events if not isinstance(e, Command)]
    assert len(back) == len(expected)
    for want, got in zip(expected, back, strict=True):
        assert_same(want, got)
    assert back[-1].where.topic == "/uav2/mavros/state"
    assert back[1].where.topic == "/mavros/setpoint_raw/local" and back[1].where.index == 0


def test_round_trip_keeps_the_clock_and_namespace(tmp_path: Path) -> None:
    events = [replace(e, vehicle="/uav1") for e in flight(20, start=2.0)]
    back, _ = read(write_rosbag1(tmp_path / "ns.bag", events))
    assert [round(e.t, 6) for e in back] == [round(e.t, 6) for e in events]
    assert {e.vehicle for e in back} == {"/uav1"}
    assert all(e.where != NOWHERE for e in back)


def test_probe_says_what_the_bag_can_produce(tmp_path: Path) -> None:
    source = open_source(write_rosbag1(tmp_path / "f.bag", flight(10)))
    with source:
        info = source.probe()
    assert info.format == "rosbag1"
    assert info.kinds == {"vehicle_status", "set_position_target_local_ned"}
    assert info.vehicles == [""] and info.message_count == 11 and info.px4_version is None


def test_lint_a_good_bag(tmp_path: Path) -> None:
    path = write_rosbag1(tmp_path / "good.bag", flight())
    result = run_cli(["lint", str(path), "--format", "json", "--px4", "1.15", "--vehicle", "mc"])
    data = json.loads(result.stdout)
    (report,) = data["files"]
    assert report["format"] == "rosbag1" and report["complete"] is True
    assert not [f for f in report["findings"] if f["code"] == "OFB001"]
    assert result.stderr == ""


def test_other_topics_and_types_are_ignored(tmp_path: Path) -> None:
    """A camera topic, a MAVROS name with a foreign type and an unknown package type."""
    path = tmp_path / "mixed.bag"
    store = mavros_typestore()
    types = store.types
    with Writer(path) as writer:
        img = writer.add_connection("/camera/info", "std_msgs/msg/String", typestore=store)
        wrong = writer.add_connection(
            "/mavros/setpoint_raw/local", "std_msgs/msg/String", typestore=store
        )
        unknown = writer.add_connection(
            "/my/custom", "my_pkg/msg/Thing", msgdef="int32 a\n", md5sum="0" * 32
        )
        raw = store.serialize_ros1(types["std_msgs/msg/String"](data="x"), "std_msgs/msg/String")
        for i in range(5):
            writer.write(img, 10**9 + i, raw)
            writer.write(wrong, 10**9 + i, raw)
            writer.write(unknown, 10**9 + i, b"\x01\x00\x00\x00")
    events, source = read(path)
    assert events == [] and not source.problems
    result = run_cli(["lint", str(path), "--format", "json"])
    assert json.loads(result.stdout)["files"][0]["complete"] is True


def test_broken_embedded_definition_falls_back_to_shipped_one(tmp_path: Path) -> None:
    store = mavros_typestore()
    good = tmp_path / "good.bag"
    write_rosbag1(good, flight(3))
    path = tmp_path / "baddef.bag"
    with Writer(path) as writer:
        conn = writer.add_connection(
            "/mavros/setpoint_raw/local",
            "mavros_msgs/msg/PositionTarget",
            msgdef="this is ::: not a message definition",
            md5sum="0" * 32,
        )
        events, _ = read(good)
        builder_topic = [e for e in events if isinstance(e, SetPositionTargetLocal)]
        builder = _Builder(store)
        for e in builder_topic:
            raw = store.serialize_ros1(builder.build(e), "mavros_msgs/msg/PositionTarget")
            writer.write(conn, 10**9 + round(e.t * 1e9), raw)
    back, source = read(path)
    assert len(back) == 3 and not source.problems
    assert_same(replace(back[0], t=builder_topic[0].t), builder_topic[0])


# -- damaged bags ------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def good_bag(tmp_path_factory: pytest.TempPathFactory) -> bytes:
    path = tmp_path_factory.mktemp("bags") / "good.bag"
    write_rosbag1(path, flight(300), chunk_threshold=2048)
    return path.read_bytes()


def index_pos(data: bytes) -> tuple[int, int]:
    """(offset of the header's index_pos value, its value) in a bag written by rosbags."""
    at = data.index(b"index_pos=") + len(b"index_pos=")
    return at, struct.unpack("<Q", data[at : at + 8])[0]


def damaged(name: str, data: bytes) -> bytes:
    if name == "truncated":
        return data[: len(data) // 2]
    if name == "unindexed":  # what a killed `rosbag record` leaves: index_pos 0, no index
        at, pos = index_pos(data)
        return data[:at] + bytes(8) + data[at + 8 : pos]
    if name == "flipped":
        mid = len(data) // 2
        return data[:mid] + bytes(b ^ 0xFF for b in data[mid : mid + 64]) + data[mid + 64 :]
    if name == "foreign":
        return b"%PDF-1.4 not a bag at all\n" * 20
    if name == "bad-header":
        return b"#ROSBAG V2.0\n" + b"\xff" * 64
    if name == "huge-length":
        first_chunk = data.index(b"op=\x05")
        # the chunk's data length follows its header; make it claim 4 GB
        hdr_len = struct.unpack("<I", data[first_chunk - 8 : first_chunk - 4])[0]
        length_at = first_chunk - 4 + hdr_len
        return data[:length_at] + b"\xff\xff\xff\xff" + data[length_at + 4 :]
    raise AssertionError(name)


BAD = ["truncated", "unindexed", "flipped", "foreign", "bad-header", "huge-length"]


@pytest.mark.parametrize("name", BAD)
def test_damaged_bag_is_one_line_and_exit_2(name: str, good_bag: bytes, tmp_path: Path) -> None:
    path = tmp_path / f"{name}.bag"
    path.write_bytes(damaged(name, good_bag))
    result = run_cli(["lint", str(path), "--format", "json"])
    assert result.returncode == 2
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and str(path) in lines[0] and "Traceback" not in result.stderr
    (report,) = json.loads(result.stdout)["files"]
    assert report["complete"] is False
    assert [f for f in report["findings"] if f["code"] == "OFB001"]


def test_truncated_bag_keeps_the_events_before_the_cut(good_bag: bytes, tmp_path: Path) -> None:
    path = tmp_path / "cut.bag"
    path.write_bytes(damaged("truncated", good_bag))
    events, source = read(path)
    setpoints = [e for e in events if isinstance(e, SetPositionTargetLocal)]
    assert 100 < len(setpoints) < 300
    assert [e.t for e in events] == sorted(e.t for e in events)
    (problem,) = source.problems
    assert problem.what.startswith(f"truncated at byte {len(good_bag) // 2}")


def test_unindexed_bag_is_read_and_says_reindex(good_bag: bytes, tmp_path: Path) -> None:
    path = tmp_path / "x.bag.active"
    path.write_bytes(damaged("unindexed", good_bag))
    events, source = read(path)
    assert len(events) == 302  # every message: the chunks are all there
    (problem,) = source.problems
    assert "not indexed" in problem.what and "rosbag reindex" in problem.what


def _record_data_at(data: bytes, op: bytes, nth: int) -> int:
    """Where the data of the ``nth`` record with this op code starts (rosbags writes ``op``
    as the first field of a record header)."""
    at = -1
    for _ in range(nth + 1):
        at = data.index(b"op=" + op, at + 1)
    header_length = struct.unpack("<I", data[at - 8 : at - 4])[0]
    return at - 4 + header_length + 4


def test_a_damaged_chunk_info_record_falls_back_to_reading_in_file_order(
    good_bag: bytes, tmp_path: Path
) -> None:
    """CHUNK_INFO's version byte (the index section at the end) changed: the chunks are
    intact, so every message is still read, and the index is named as damaged."""
    data = bytearray(good_bag)
    info = data.rindex(b"op=\x06")
    version = data.index(b"ver=", info - 40) + 4
    data[version] = 2
    path = tmp_path / "chunk_info.bag"
    path.write_bytes(bytes(data))
    events, source = read(path)
    assert len(events) == 302
    (problem,) = source.problems
    assert problem.what.startswith("index damaged at byte")


def test_one_bad_offset_in_the_index_loses_at_most_its_message(
    good_bag: bytes, tmp_path: Path
) -> None:
    """An IDX_DATA entry three bytes off, in the fifth chunk: the indexed read stops there,
    and the rest is read in file order from after the last message read."""
    data = bytearray(good_bag)
    entries = _record_data_at(bytes(data), b"\x04", 4)
    offset_at = entries + 8  # the first entry: time (8 bytes), then the offset
    struct.pack_into("<I", data, offset_at, struct.unpack_from("<I", data, offset_at)[0] + 3)
    path = tmp_path / "bad_offset.bag"
    path.write_bytes(bytes(data))
    events, source = read(path)
    assert 300 <= len(events) <= 302
    assert [e.t for e in events] == sorted(e.t for e in events)
    (problem,) = source.problems
    assert problem.what.startswith("the indexed read stopped")
    assert "later messages read in file order" in problem.what


def test_damaged_bag_as_a_process_prints_no_traceback(good_bag: bytes, tmp_path: Path) -> None:
    path = tmp_path / "cut.bag"
    path.write_bytes(damaged("flipped", good_bag))
    result = run_cli_process(["lint", str(path), "--no-progress"])
    assert result.returncode == 2
    assert "Traceback" not in result.stderr
    assert len(result.stderr.strip().splitlines()) == 1


def test_chunkwise_reader_gives_what_rosbags_gives(tmp_path: Path) -> None:
    """Same messages, same order as rosbags' whole-index reader, on a many-chunk mixed bag."""
    from rosbags.rosbag1 import Reader

    from fuzzoff.formats.rosbag1.chunkwise import ChunkwiseReader

    path = tmp_path / "mixed.bag"
    store = mavros_typestore()
    raw = store.serialize_ros1(
        store.types["std_msgs/msg/String"](data="x" * 200), "std_msgs/msg/String"
    )
    events = flight(200)
    write_rosbag1(path, events)
    with Reader(path) as source, Writer(tmp_path / "m2.bag") as writer:
        writer.chunk_threshold = 4096
        conns = {}
        noise = writer.add_connection("/camera/info", "std_msgs/msg/String", typestore=store)
        for conn, t, data in source.messages():
            if conn.topic not in conns:
                conns[conn.topic] = writer.add_connection(
                    conn.topic, conn.msgtype, msgdef=conn.msgdef.data, md5sum=conn.digest
                )
            writer.write(conns[conn.topic], t, data)
            for k in range(3):
                writer.write(noise, t + k, raw)
    with Reader(tmp_path / "m2.bag") as whole, ChunkwiseReader(tmp_path / "m2.bag") as chunked:
        assert len(chunked.chunk_infos) > 10
        wanted = [c for c in whole.connections if c.topic.startswith("/mavros")]
        want = [(c.topic, t, bytes(d)) for c, t, d in whole.messages(connections=wanted)]
        ids = {c.id for c in wanted}
        mine = [c for c in chunked.connections if c.id in ids]
        got = [(c.topic, t, bytes(d)) for c, t, d in chunked.messages(connections=mine)]
        assert got == want and len(got) == len(events)
        assert sum(c.msgcount for c in mine) == len(events)
