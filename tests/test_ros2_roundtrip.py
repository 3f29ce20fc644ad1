"""Events -> MCAP / rosbag2 (both storages, Humble-style) -> fuzzoff's readers -> same events."""

from __future__ import annotations

from pathlib import Path

import pytest

from fuzzoff.formats.mcap.writer import write_mcap
from fuzzoff.formats.rosbag2.writer import write_rosbag2
from tests.ros2_samples import RELEASES, comparable, every_kind, read_all

KINDS = ("mcap", "rosbag2-sqlite3", "rosbag2-mcap", "rosbag2-humble")


def _write(kind: str, path: Path, events: list, release: str) -> Path:  # type: ignore[type-arg]
    if kind == "mcap":
        return write_mcap(path / "flight.mcap", events, release=release)
    if kind == "rosbag2-humble":
        return write_rosbag2(path / "bag", events, release=release, definitions=False)
    storage = "mcap" if kind == "rosbag2-mcap" else "sqlite3"
    return write_rosbag2(path / "bag", events, storage=storage, release=release)  # type: ignore[arg-type]


@pytest.mark.parametrize("release", RELEASES)
@pytest.mark.parametrize("kind", KINDS)
def test_every_event_kind_survives_the_round_trip(tmp_path: Path, kind: str, release: str) -> None:
    events = every_kind(release, vehicle="/px4_1")
    source, read = read_all(_write(kind, tmp_path, events, release))
    assert source.problems == []
    assert [comparable(e) | {"where": ""} for e in read] == [
        comparable(e) | {"where": ""} for e in events
    ]
    assert all(e.where.topic.startswith("/px4_1/fmu/") for e in read)


@pytest.mark.parametrize("kind", KINDS)
def test_release_is_detected_from_the_recording(tmp_path: Path, kind: str) -> None:
    source, _ = read_all(_write(kind, tmp_path, every_kind("1.15"), "1.15"))
    info = source.probe()
    assert info.px4_version == "1.15"
    assert "vehicle_status" in info.kinds and "control_mode" in info.kinds


def test_events_carry_topic_index_and_sender_time(tmp_path: Path) -> None:
    events = every_kind("main")
    _, read = read_all(write_mcap(tmp_path / "f.mcap", events))
    control = next(e for e in read if e.kind == "control_mode")
    assert control.where.topic == "/fmu/in/offboard_control_mode"
    assert control.where.index == 0
    assert control.sender_time_us == 100_000
    assert control.origin == "sent"
    status = next(e for e in read if e.kind == "vehicle_status")
    assert status.where.topic == "/fmu/out/vehicle_status_v4"
    assert status.origin == "vehicle"
