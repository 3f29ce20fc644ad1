"""ULog damage pyulog reads past in silence: a record too short for its type, a format record
whose text a flipped byte changed. Each is one OFB001 line naming the byte, exit 2, and the rest
of the flight still read (issue 19 item 1)."""

from __future__ import annotations

import json
import struct
from pathlib import Path

import pytest
from pyulog import ULog

from fuzzoff.events import ControlMode, Event, TrajectorySetpoint, VehicleStatus
from fuzzoff.formats import open_source
from fuzzoff.formats.ulog.writer import write_ulog
from tests.helpers import CORPORA, run_cli
from tests.test_ulog import offboard_with_rejection

REAL = CORPORA / "real" / "sample_px4_events.ulg"


def events(path: Path) -> list[Event]:
    with open_source(path) as source:
        return list(source.events())


def data_record(data: bytes, path: Path, topic: str, row: int) -> int:
    """Where the data record of ``topic``'s row ``row`` starts: found by its timestamp (the first
    field of every uORB message), as pyulog reads it, after the 2-byte size, the type ``D`` and
    the 2-byte message id."""
    (dataset,) = ULog(str(path), [topic]).data_list
    stamp = struct.pack("<Q", int(dataset.data["timestamp"][row]))
    at = data.index(stamp) - 5
    assert data[at + 2 : at + 3] == b"D"
    return at


def test_a_data_record_whose_size_reads_0_is_reported_and_the_flight_read_on(
    tmp_path: Path,
) -> None:
    # A real PX4 log (1.15.0-dev): pyulog stopped at such a record as if the file ended there,
    # and lint said nothing (85 % of this flight dropped, exit 0, complete: true).
    data = REAL.read_bytes()
    (status,) = ULog(str(REAL), ["vehicle_status"]).data_list
    row = len(status.data["timestamp"]) // 7
    at = data_record(data, REAL, "vehicle_status", row)
    path = tmp_path / "size0.ulg"
    path.write_bytes(data[:at] + b"\x00\x00" + data[at + 2 :])

    result = run_cli(["lint", str(path), "--format", "json"])
    assert result.returncode == 2
    (line,) = result.stderr.splitlines()
    assert line.startswith(f"fuzzoff: {path}: corrupt data: damaged records were skipped")
    assert f"at byte {at + 3}" in line  # the end of the 3-byte header that says 0
    (report,) = json.loads(result.stdout)["files"]
    assert report["complete"] is False
    whole = [e for e in events(REAL) if isinstance(e, VehicleStatus)]
    damaged = [e for e in events(path) if isinstance(e, VehicleStatus)]
    assert damaged[-1].t == whole[-1].t  # read on to the end of the flight
    assert len(damaged) > row + len(whole) // 2  # most of what follows the damage


@pytest.fixture(scope="module")
def offboard_log(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return write_ulog(tmp_path_factory.mktemp("ulog") / "flight.ulg", offboard_with_rejection())


FLIPS = {
    "timestamp": (b"trajectory_setpoint:uint64_t timestamp;", b"timestamp", b"timestamq"),
    "not a name": (b"float[3] position;", b"position", b"posi#ion"),
    "one letter": (b"float[3] position;", b"position", b"posiuion"),
    "upper case": (b"float[3] position;", b"position", b"positioN"),
}


@pytest.mark.parametrize("flip", sorted(FLIPS))
def test_a_flipped_byte_in_a_format_record_sets_that_topic_aside(
    flip: str, offboard_log: Path, tmp_path: Path
) -> None:
    data = offboard_log.read_bytes()
    start, old, new = FLIPS[flip]
    record = data.index(b"trajectory_setpoint:") - 3  # the format record's 3-byte header
    at = data.index(start, record)
    assert len(old) == len(new)
    damaged = data[:at] + data[at:].replace(old, new, 1)
    path = tmp_path / "flip.ulg"
    path.write_bytes(damaged)

    result = run_cli(["lint", str(path), "--format", "json"])
    assert result.returncode == 2
    (line,) = result.stderr.splitlines()
    assert "damaged format record of 'trajectory_setpoint'" in line
    assert "were not read" in line and line.endswith(f" at byte {record}")
    (report,) = json.loads(result.stdout)["files"]
    assert report["complete"] is False
    codes = [f["code"] for f in report["findings"]]
    assert "OFB201" in codes  # the rejected switch: from the topics that were read
    read = events(path)
    assert not [e for e in read if isinstance(e, TrajectorySetpoint)]
    assert [e for e in read if isinstance(e, ControlMode)]


def test_a_damaged_format_no_read_topic_uses_is_said_and_costs_nothing(tmp_path: Path) -> None:
    data = REAL.read_bytes()
    record = data.index(b"sensor_combined:") - 3
    at = data.index(b" gyro_rad;", record)
    path = tmp_path / "other.ulg"
    path.write_bytes(data[:at] + b" gyro#rad;" + data[at + 10 :])

    result = run_cli(["lint", str(path), "--format", "json"])
    whole = run_cli(["lint", str(REAL), "--format", "json"])
    assert result.returncode == whole.returncode != 2
    (line,) = result.stderr.splitlines()
    assert "damaged format record of 'sensor_combined'" in line
    assert "no topic fuzzoff reads depends on it" in line and line.endswith(f"at byte {record}")
    (report,) = json.loads(result.stdout)["files"]
    (before,) = json.loads(whole.stdout)["files"]
    assert report["complete"] is True
    ofb004 = [f for f in report["findings"] if f["code"] == "OFB004"]
    assert [f["severity"] for f in ofb004] == ["info"]
    assert [f for f in report["findings"] if f["code"] != "OFB004"] == before["findings"]
    assert list(map(repr, events(path))) == list(map(repr, events(REAL)))


def test_a_long_garbage_name_is_cut_in_the_line(offboard_log: Path, tmp_path: Path) -> None:
    # The subscription record names a topic with no format: 300 bytes of garbage as its name.
    data = offboard_log.read_bytes()
    name = b"trajectory_setpoint"
    at = data.index(name, data.index(name + b":") + 1)  # in the subscription record
    size_at = at - 3 - 3  # its header: size, 'A', then multi id and message id
    (size,) = struct.unpack_from("<H", data, size_at)
    garbage = b"x" * 300
    record = struct.pack("<H", size + len(garbage) - len(name)) + data[size_at + 2 : at]
    path = tmp_path / "long.ulg"
    path.write_bytes(data[:size_at] + record + garbage + data[at + len(name) :])

    result = run_cli(["lint", str(path), "--format", "json"])
    assert result.returncode == 2
    (line,) = result.stderr.splitlines()
    assert "no message format for topic " + "x" * 39 + "…" in line
    assert len(line) < 300
