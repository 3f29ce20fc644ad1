"""ROS 2 bags and MCAP files damaged where their readers did not look (issue 19 items 2-4).

Where data was not read: OFB001, exit 2. Where the file is malformed but every message was read
around the damage (a summary, a record length, a metadata.yaml the data files contradict):
OFB004 (info), the file complete, and the line says what is wrong and what was read instead.
"""

from __future__ import annotations

import io
import json
import shutil
import sqlite3
import struct
from pathlib import Path

import pytest
from mcap.reader import SeekingReader

from fuzzoff.events import ControlMode
from fuzzoff.formats import open_source
from fuzzoff.formats.mcap.writer import write_mcap
from tests.helpers import CORPORA, run_cli
from tests.test_ros2_bad_input import flight

BAGS = CORPORA / "rosbag2"


def lint(path: Path, command: str = "lint") -> tuple[int, dict, list[str]]:  # type: ignore[type-arg]
    """Exit status, the file's JSON report and the stderr lines of ``fuzzoff COMMAND PATH``."""
    result = run_cli([command, str(path), "--format", "json"])
    (report,) = json.loads(result.stdout)["files"]
    return result.returncode, report, result.stderr.splitlines()


def judged(report: dict) -> list[tuple[str, float | None]]:  # type: ignore[type-arg]
    return [(f["code"], f["time_s"]) for f in report["findings"] if f["code"] != "OFB004"]


# -- item 2: SQLite keeps any type in any column ----------------------------------------------


@pytest.fixture
def sqlite_bag(tmp_path: Path) -> Path:
    bag = tmp_path / "two_vehicles"
    shutil.copytree(BAGS / "two_vehicles", bag)
    return bag


def test_a_text_timestamp_is_one_line_and_that_message_only(sqlite_bag: Path) -> None:
    with sqlite3.connect(sqlite_bag / "two_vehicles.db3") as db:
        db.execute("UPDATE messages SET timestamp = 'abc' WHERE id = 50")
    code, report, lines = lint(sqlite_bag)
    assert code == 2 and report["complete"] is False
    (line,) = lines
    assert (
        "1 message whose timestamp is not an integer was not read (the first: text 'abc')" in line
    )
    assert line.endswith("at messages.timestamp")
    _, intact, _ = lint(BAGS / "two_vehicles")
    assert [f for f in judged(report) if f[0] != "OFB001"] == judged(intact)


def test_every_timestamp_text_is_one_line_not_a_traceback(sqlite_bag: Path) -> None:
    # rosbags raised TypeError and the salvage probe ValueError: exit 1 and no JSON.
    with sqlite3.connect(sqlite_bag / "two_vehicles.db3") as db:
        db.execute("UPDATE messages SET timestamp = 'abc'")
    code, report, lines = lint(sqlite_bag)
    assert code == 2 and report["complete"] is False
    assert any("1016 messages whose timestamp is not an integer were not read" in x for x in lines)


# -- item 4: metadata.yaml against the data files -----------------------------------------------


def _folder(meta: Path) -> None:
    meta.unlink()
    meta.mkdir()


def _missing(meta: Path) -> None:
    meta.unlink()


def _cut(meta: Path) -> None:
    meta.write_text(meta.read_text()[:600])


def _replace(old: str, new: str):  # type: ignore[no-untyped-def]
    def edit(meta: Path) -> None:
        text = meta.read_text()
        assert old in text
        meta.write_text(text.replace(old, new))

    return edit


METADATA = {
    "a folder": (_folder, "metadata.yaml is not a file (a folder); the data files were read"),
    "missing": (_missing, "metadata.yaml is missing; the data files were read instead"),
    "cut short": (_cut, "metadata.yaml lacks version (cut short?)"),
    "version 99": (_replace("  version: 9\n", "  version: 99\n"), "says version 99"),
    "unknown storage": (
        _replace("storage_identifier: mcap", "storage_identifier: rosbag_v99"),
        "names the storage 'rosbag_v99', which rosbag2 does not have",
    ),
    "another storage": (
        _replace("storage_identifier: mcap", "storage_identifier: sqlite3"),
        "names the storage 'sqlite3', but the data files are .mcap",
    ),
    "false compression": (
        _replace("compression_mode: ''", "compression_mode: file"),
        "names the compression ''; rosbag2 compresses with zstd",
    ),
    "false zstd": (
        _replace(
            "compression_format: ''\n  compression_mode: ''",
            "compression_format: zstd\n  compression_mode: file",
        ),
        "says the data files are zstd-compressed, but they are not",
    ),
    "another bag's": (  # its start 208 days earlier: every time was 208 days late
        _replace("since_epoch: 1700000000000000000", "since_epoch: 1682000000000000000"),
        "metadata.yaml's starting time is 208.3 days before the first message in the data "
        "files; the data files' times were used",
    ),
}


@pytest.mark.parametrize("damage", sorted(METADATA))
def test_what_metadata_yaml_gets_wrong_is_said_and_the_data_files_decide(
    damage: str, tmp_path: Path
) -> None:
    edit, says = METADATA[damage]
    intact = BAGS / "stream_lost_mcap"
    bag = tmp_path / intact.name
    shutil.copytree(intact, bag)
    edit(bag / "metadata.yaml")
    if damage == "missing":  # a recorder that crashed names its files <bag>_<n>
        (bag / "stream_lost_mcap.mcap").rename(bag / "stream_lost_mcap_0.mcap")

    code, report, lines = lint(bag)
    intact_code, intact_report, _ = lint(intact)
    (line,) = lines
    assert line.startswith(f"fuzzoff: {bag}: ") and says in line
    assert code == intact_code != 2
    assert report["complete"] is True
    assert report["format"] == "rosbag2-mcap"
    assert judged(report) == judged(intact_report)  # the same times: the data files' own
    gate_code, _, gate_lines = lint(bag, "gate")
    assert gate_lines == lines
    assert gate_code == lint(intact, "gate")[0]  # lint and gate agree on the file


def test_a_zero_length_mcap_in_a_bag_is_empty(tmp_path: Path) -> None:
    bag = tmp_path / "stream_lost_mcap"
    shutil.copytree(BAGS / "stream_lost_mcap", bag)
    (bag / "stream_lost_mcap.mcap").write_bytes(b"")
    code, _, lines = lint(bag)
    assert code == 2
    (line,) = lines
    assert line.endswith("empty file (0 bytes) at stream_lost_mcap.mcap")


# -- item 3 and the MCAP summary: read around, and said -----------------------------------------


@pytest.fixture
def chunked(tmp_path: Path) -> Path:
    return write_mcap(tmp_path / "flight.mcap", flight(), chunk_size=4096)


def summary_of(data: bytes):  # type: ignore[no-untyped-def]
    summary = SeekingReader(io.BytesIO(data)).get_summary()
    assert summary is not None
    return summary


def control_modes(path: Path) -> int:
    with open_source(path) as source:
        return sum(isinstance(e, ControlMode) for e in source.events())


def test_a_zeroed_range_in_the_summary_is_read_around(chunked: Path) -> None:
    data = chunked.read_bytes()
    footer = len(data) - 8 - 29
    (summary_start,) = struct.unpack_from("<Q", data, footer + 9)
    chunked.write_bytes(data[: summary_start + 40] + bytes(64) + data[summary_start + 104 :])
    line = lint(chunked)[2][0]
    assert "summary CRC mismatch" in line and "read front to back without the summary" in line
    assert control_modes(chunked) == 400


def test_a_chunk_a_damaged_index_hides_is_read(chunked: Path) -> None:
    # A chunk index whose times do not cover its chunk: rosbags skipped the chunk, and only
    # "N of M messages ... are not in the data" said that something, somewhere, was missing.
    data = chunked.read_bytes()
    summary = summary_of(data)
    third = sorted(summary.chunk_indexes, key=lambda c: c.chunk_start_offset)[2]
    footer = len(data) - 8 - 29
    data = data[: footer + 25] + bytes(4) + data[footer + 29 :]  # no summary CRC given
    times = struct.pack("<QQ", third.message_start_time, third.message_end_time)
    at = data.index(times)
    chunked.write_bytes(data[:at] + struct.pack("<QQ", 0, 0) + data[at + 16 :])
    code, report, (line,) = lint(chunked)
    assert f"the summary's index of the chunk at byte {third.chunk_start_offset}" in line
    assert report["complete"] is True and code != 2
    assert control_modes(chunked) == 400


def test_channels_a_skipped_chunk_defined_are_read_or_counted(chunked: Path) -> None:
    data = chunked.read_bytes()
    summary = summary_of(data)
    first = min(summary.chunk_indexes, key=lambda c: c.chunk_start_offset)
    bad = first.chunk_start_offset + first.chunk_length // 2
    damaged = data[:bad] + bytes([data[bad] ^ 0xFF]) + data[bad + 1 :]  # its CRC fails
    chunked.write_bytes(damaged)
    # With the summary, the channels defined in the skipped chunk decode in the later ones.
    code, _, lines = lint(chunked)
    assert code == 2 and len(lines) == 1 and "chunk CRC mismatch" in lines[0]
    with_summary = control_modes(chunked)
    # Without one (cut where the summary starts: a recorder that died while closing the
    # file), what cannot be decoded is counted, not dropped in silence.
    (summary_start,) = struct.unpack_from("<Q", data, len(data) - 8 - 29 + 9)
    chunked.write_bytes(damaged[:summary_start])
    code, _, lines = lint(chunked)
    assert code == 2
    (orphans,) = [x for x in lines if "on channels that no readable record defines" in x]
    counted = int(orphans.split(f"{chunked}: ", 1)[1].split()[0])
    assert control_modes(chunked) + counted // 2 <= with_summary < 400


def test_ofb004_is_a_rule_like_any_other() -> None:
    path = CORPORA / "damaged" / "mcap_trailing_garbage.mcap"
    said = run_cli(["lint", str(path), "--format", "json"])
    assert said.returncode == 0 and "bytes after the end of the MCAP file" in said.stderr
    quiet = run_cli(["lint", str(path), "--format", "json", "--ignore", "OFB004"])
    assert quiet.returncode == 0 and quiet.stderr == ""
    (report,) = json.loads(quiet.stdout)["files"]
    assert "OFB004" not in [f["code"] for f in report["findings"]]
    strict = run_cli(["lint", str(path), "--format", "json", "--fail-on", "info"])
    assert strict.returncode == 1  # an info finding at the info fail level


def test_a_topic_name_flipped_in_the_database_is_not_vouched_for(sqlite_bag: Path) -> None:
    # One bit of a topic's name in the database's topics table (the campaign's case): the data
    # then hold a topic metadata.yaml does not list. Which of the two is damaged cannot be
    # told (a metadata.yaml from another bag reads the same), so the file is incomplete.
    db3 = sqlite_bag / "two_vehicles.db3"
    data = db3.read_bytes()
    at = data.rindex(b"/px4_1/fmu/out/vehicle_status") + len("/px4_1/fm")
    db3.write_bytes(data[:at] + bytes([data[at] ^ 0x40]) + data[at + 1 :])  # 'u' -> '5'
    code, report, (line,) = lint(sqlite_bag)
    assert code == 2 and report["complete"] is False
    assert "metadata.yaml does not list /px4_1/fm5/out/vehicle_status" in line
    assert "one of them is damaged or from another recording" in line
