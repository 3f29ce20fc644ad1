"""Damaged MCAP files and ROS 2 bags: one clear line per problem, what was readable kept, exit 2."""

from __future__ import annotations

import json
import shutil
import sqlite3
import struct
from pathlib import Path

import pytest
from mcap.reader import make_reader

from fuzzoff import events as ev
from fuzzoff.formats.mcap.writer import write_mcap
from fuzzoff.formats.ros2msgs.messages import RawMessage
from fuzzoff.formats.rosbag2.writer import write_rosbag2
from tests.helpers import run_cli
from tests.ros2_samples import read_all

N = 400


def flight() -> list[ev.Event]:
    """20 s of keep-alive and setpoints at 20 Hz."""
    out: list[ev.Event] = []
    for i in range(N):
        t = i * 0.05
        out.append(ev.ControlMode(t=t, position=True, sender_time_us=1_000_000 + i * 50_000))
        out.append(
            ev.TrajectorySetpoint(
                t=t + 0.001, position=(0.0, 0.0, -2.0), sender_time_us=1_000_000 + i * 50_000
            )
        )
    return out


def lint(path: Path) -> tuple[int, dict, str]:  # type: ignore[type-arg]
    result = run_cli(["lint", str(path), "--format", "json"])
    (report,) = json.loads(result.stdout)["files"]
    return result.returncode, report, result.stderr


def assert_clean_failure(path: Path, needle: str) -> list[str]:
    code, report, stderr = lint(path)
    assert code == 2
    assert report["complete"] is False
    assert "Traceback" not in stderr
    lines = [line for line in stderr.splitlines() if line.strip()]
    assert lines and all(line.startswith(f"fuzzoff: {path}") for line in lines)
    assert any(needle in line for line in lines), lines
    assert any(f["code"] == "OFB001" for f in report["findings"])
    return lines


def assert_read_around(path: Path, needle: str) -> str:
    """A malformed part read around with nothing lost: one OFB004 line, the file complete."""
    code, report, stderr = lint(path)
    assert code != 2
    assert report["complete"] is True
    (line,) = stderr.splitlines()
    assert line.startswith(f"fuzzoff: {path}: ") and needle in line, line
    assert [f["severity"] for f in report["findings"] if f["code"] == "OFB004"] == ["info"]
    return line


def flip(path: Path, offset: int, count: int = 64) -> None:
    data = bytearray(path.read_bytes())
    for k in range(offset, min(offset + count, len(data))):
        data[k] ^= 0xFF
    path.write_bytes(bytes(data))


@pytest.fixture
def mcap_file(tmp_path: Path) -> Path:
    return write_mcap(tmp_path / "flight.mcap", flight(), chunk_size=4096)


def test_truncated_mcap_keeps_the_first_half(mcap_file: Path) -> None:
    data = mcap_file.read_bytes()
    mcap_file.write_bytes(data[: len(data) // 2])
    assert_clean_failure(mcap_file, "truncated")
    _source, events = read_all(mcap_file)
    assert N // 4 < len(events) < 2 * N
    assert [e.t for e in events] == sorted(e.t for e in events)


def test_flipped_bytes_in_a_chunk_skip_that_chunk_only(mcap_file: Path) -> None:
    with mcap_file.open("rb") as fh:
        summary = make_reader(fh).get_summary()
    assert summary is not None
    chunks = summary.chunk_indexes
    middle = chunks[len(chunks) // 2]
    flip(mcap_file, middle.chunk_start_offset + middle.chunk_length // 2, 16)
    assert_clean_failure(mcap_file, "chunk")
    _, events = read_all(mcap_file)
    assert 2 * N * 0.5 < len(events) < 2 * N
    assert events[-1].t == pytest.approx((N - 1) * 0.05 + 0.001)


def test_missing_footer_keeps_every_chunk(mcap_file: Path) -> None:
    with mcap_file.open("rb") as fh:
        summary = make_reader(fh).get_summary()
    assert summary is not None
    last = summary.chunk_indexes[-1]
    data = mcap_file.read_bytes()
    end = last.chunk_start_offset + last.chunk_length
    mcap_file.write_bytes(data[:end])
    assert_clean_failure(mcap_file, "no valid footer")
    source, events = read_all(mcap_file)
    assert len(events) == 2 * N
    assert source.probe().kinds == {"control_mode", "trajectory"}


def test_not_an_mcap_behind_the_name(tmp_path: Path) -> None:
    path = tmp_path / "fake.mcap"
    path.write_bytes(b"hello, this is text, not a recording\n" * 4)
    assert_clean_failure(path, "not a recording")


@pytest.fixture
def bag(tmp_path: Path) -> Path:
    return write_rosbag2(tmp_path / "bag", flight())


def test_missing_metadata_reads_the_data_files(bag: Path) -> None:
    (bag / "metadata.yaml").unlink()
    source, events = read_all(bag)
    (problem,) = source.problems
    assert "metadata.yaml is missing" in problem.what
    assert len(events) == 2 * N


def test_malformed_metadata_reads_the_db3(bag: Path) -> None:
    (bag / "metadata.yaml").write_text("rosbag2_bagfile_information: [unclosed\n  : :\n")
    assert_read_around(bag, "metadata.yaml is not readable YAML")
    _, events = read_all(bag)
    assert len(events) == 2 * N


@pytest.mark.parametrize(
    ("key", "value"),
    [
        ("name", "[]"),
        ("name", "{}"),
        ("type", "null"),
        ("type", "[1, 2]"),
        ("message_count", "'x'"),
        ("message_count", "-5"),
        ("message_count", "true"),
    ],
)
def test_malformed_metadata_topic_reads_the_db3(bag: Path, key: str, value: str) -> None:
    # YAML that parses, but a topic's name, type or count is a list, a mapping, null or
    # negative: rosbags passes the value through as the connection's.
    meta = bag / "metadata.yaml"
    text = meta.read_text()
    topics = text[text.index("topics_with_message_count:") :]
    line = next(line for line in topics.splitlines() if line.strip(" -").startswith(f"{key}: "))
    meta.write_text(text.replace(line, line.split(":")[0] + ": " + value, 1))
    assert_read_around(bag, "metadata.yaml: a topic's name, type or message count is malformed")
    _, events = read_all(bag)
    assert len(events) == 2 * N


def test_metadata_file_list_that_is_not_text_reads_the_folder(bag: Path) -> None:
    meta = bag / "metadata.yaml"
    db3 = next(bag.glob("*.db3"))
    meta.write_text(meta.read_text().replace(f"  - {db3.name}\n", f"  - [{db3.name}]\n"))
    assert_read_around(bag, "relative_file_paths is not a list of file names")
    _, events = read_all(bag)
    assert len(events) == 2 * N


def test_metadata_of_another_bag_is_not_silent(bag: Path) -> None:
    # The database's topics are not the ones metadata.yaml lists (say, a metadata.yaml copied
    # from another recording): rosbags then yields none of their messages, and says nothing.
    # fuzzoff says so, and reads the database's own topics; which of the two is damaged
    # cannot be told, so the file is not vouched for (OFB001).
    db3 = next(bag.glob("*.db3"))
    with sqlite3.connect(db3) as db:
        db.execute("UPDATE topics SET name = name || '_renamed'")
    assert_clean_failure(
        bag, "metadata.yaml does not list /fmu/in/offboard_control_mode_renamed, /fmu/in/tra"
    )


def test_topic_row_that_is_not_text_is_reported(bag: Path) -> None:
    db3 = next(bag.glob("*.db3"))
    with sqlite3.connect(db3) as db:
        db.execute("UPDATE topics SET type = x'00ff' WHERE name LIKE '%trajectory%'")
    assert_clean_failure(db3, "a topic's name or type is not text; its messages were skipped")
    _, events = read_all(db3)
    assert [e.kind for e in events] == ["control_mode"] * N  # the other topic is read


def test_damaged_schema_text_is_reported(bag: Path) -> None:
    # Two bytes of a CREATE statement in sqlite_master overwritten: SQLite's error message
    # quotes them, and Python's sqlite3 then raises UnicodeDecodeError instead of its own error.
    db3 = next(bag.glob("*.db3"))
    data = db3.read_bytes()
    at = data.index(b"CREATE INDEX") + 2
    db3.write_bytes(data[:at] + b"\xff\xff" + data[at + 2 :])
    assert_clean_failure(db3, "damaged text in its schema")


def test_a_row_whose_data_is_not_a_blob_is_counted_as_undecodable(bag: Path) -> None:
    db3 = next(bag.glob("*.db3"))
    with sqlite3.connect(db3) as db:
        db.execute("UPDATE messages SET data = 7 WHERE id = 5")
    source, events = read_all(db3)
    assert len(events) == 2 * N - 1  # the rest is read on
    (problem,) = source.problems
    assert "payload is not bytes but int; 1 of" in problem.what


def test_db3_given_directly_needs_no_metadata(bag: Path) -> None:
    db3 = next(bag.glob("*.db3"))
    _code, report, _stderr = lint(db3)
    assert report["complete"] is True
    assert report["format"] == "rosbag2-sqlite3"
    _, events = read_all(db3)
    assert len(events) == 2 * N


def test_cut_db3_is_salvaged_row_by_row(bag: Path) -> None:
    db3 = next(bag.glob("*.db3"))
    data = db3.read_bytes()
    db3.write_bytes(data[: len(data) // 2])
    assert_clean_failure(bag, "database damaged")
    _, events = read_all(bag)
    assert N // 2 < len(events) < 2 * N
    assert [e.t for e in events] == sorted(e.t for e in events)


def test_db3_that_is_not_a_database(bag: Path) -> None:
    db3 = next(bag.glob("*.db3"))
    db3.write_bytes(b"\x00" * 4096)
    lines = assert_clean_failure(bag, "bag.db3")
    assert len(lines) <= 2


def test_cut_mcap_storage_in_a_bag_is_streamed(tmp_path: Path) -> None:
    # rosbags writes 1 MiB chunks: camera-sized messages make several.
    camera = [
        RawMessage(i * 0.1, "/camera", "acme_msgs/msg/Blob", "uint8[] d\n", bytes(16_000))
        for i in range(200)
    ]
    bag = write_rosbag2(tmp_path / "bag", flight(), storage="mcap", extra=camera)
    data_file = next(bag.glob("*.mcap"))
    data = data_file.read_bytes()
    data_file.write_bytes(data[: len(data) * 3 // 4])
    assert_clean_failure(bag, "no valid footer")
    _, events = read_all(bag)
    assert len(events) > N // 2


def test_px4_topic_of_unknown_type_is_reported_not_guessed(tmp_path: Path) -> None:
    foreign = [
        RawMessage(
            0.5,
            "/fmu/in/vehicle_command",
            "acme_msgs/msg/Command",
            "int32 x\n",
            b"\0\1\0\0\5\0\0\0",
        )
    ]
    for path in (
        write_mcap(tmp_path / "f.mcap", flight(), extra=foreign),
        write_rosbag2(tmp_path / "bag", flight(), extra=foreign),
    ):
        assert_clean_failure(path, "acme_msgs/msg/Command")
        _, events = read_all(path)
        assert len(events) == 2 * N


def test_foreign_topics_are_ignored_quietly(tmp_path: Path) -> None:
    camera = [
        RawMessage(i * 0.5, "/camera/raw", "acme_msgs/msg/Blob", "uint8[] d\n", b"\0\1\0\0\0\0\0\0")
        for i in range(5)
    ]
    path = write_mcap(tmp_path / "f.mcap", flight(), extra=camera)
    _code, report, _ = lint(path)
    assert report["complete"] is True
    source, events = read_all(path)
    assert len(events) == 2 * N
    assert source.probe().message_count == 2 * N + 5
    assert source.stats["messages"] == 2 * N  # the camera topic was never read


def test_wrong_release_payload_is_a_problem_not_a_guess(tmp_path: Path) -> None:
    # 1.14 definitions embedded, 1.13 payloads: TrajectorySetpoint is longer in 1.13.
    path = write_mcap(tmp_path / "f.mcap", flight(), release="1.14", payload_release="1.13")
    lines = assert_clean_failure(path, "TrajectorySetpoint")
    assert any("embedded definition" in line for line in lines)


def test_damaged_copy_leaves_the_original_untouched(bag: Path, tmp_path: Path) -> None:
    copy = tmp_path / "copy"
    shutil.copytree(bag, copy)
    db3 = next(copy.glob("*.db3"))
    db3.write_bytes(db3.read_bytes()[:8192])
    before = db3.read_bytes()
    lint(copy)
    assert db3.read_bytes() == before


_WITH_NOTE = (
    "uint64 timestamp\nbool position\nbool velocity\nbool acceleration\nbool attitude\n"
    "bool body_rate\nbool thrust_and_torque\nbool direct_actuator\nstring note\n"
)
"""OffboardControlMode as a custom px4_msgs build defines it: an extra string field."""


def _noted_ocm(k: int, length: int | None = None) -> bytes:
    """CDR of ``_WITH_NOTE`` at 20 Hz, its string length field ``length`` when given."""
    text = b"ok\x00"
    body = struct.pack("<Q", 5_000_000 + k * 50_000) + bytes([1, 0, 0, 0, 0, 0, 0, 0])
    body += struct.pack("<I", len(text) if length is None else length) + text
    return b"\x00\x01\x00\x00" + body


@pytest.mark.parametrize("bad", [[30], [30, 45]])
def test_a_corrupt_string_length_loses_that_message_only(tmp_path: Path, bad: list[int]) -> None:
    """rosbags raises its own error for a length past the end: each such message is counted
    and named, the others are read (a keep-alive of 20 Hz with none missing around them)."""
    raws = [
        RawMessage(
            t=0.05 * k,
            topic="/fmu/in/offboard_control_mode",
            msgtype="px4_msgs/msg/OffboardControlMode",
            msgdef=_WITH_NOTE,
            data=_noted_ocm(k, 0x7FFFFFF0 if k in bad else None),
        )
        for k in range(60)
    ]
    path = write_mcap(tmp_path / "noted.mcap", [], extra=raws)
    lines = assert_clean_failure(path, f"{len(bad)} of 60 messages not decoded")
    assert any("Invalid string length" in line for line in lines)
    _, report, _ = lint(path)
    assert report["stats"]["kinds"] == {"control_mode": 60 - len(bad)}


def test_a_huge_fixed_array_in_a_definition_is_refused_before_decoding(tmp_path: Path) -> None:
    """``string[100000]`` would make rosbags generate code per element (gigabytes): the
    embedded definition is refused with a note, and the bundled ones are tried instead."""
    raws = [
        RawMessage(
            t=0.05 * k,
            topic="/fmu/in/offboard_control_mode",
            msgtype="px4_msgs/msg/OffboardControlMode",
            msgdef="uint64 timestamp\nstring[100000] s\n",
            data=b"\x00\x01\x00\x00" + bytes(72),
        )
        for k in range(40)
    ]
    path = write_mcap(tmp_path / "huge.mcap", [], extra=raws)
    assert_clean_failure(path, "40 of 40 messages not decoded")
    _, report, _ = lint(path)
    (note,) = [n for n in report["stats"]["notes"] if "embedded definition not usable" in n]
    assert "100000 string or message array elements in OffboardControlMode" in note


@pytest.mark.parametrize("bag", ["stream_lost_mcap", "good_flight_sqlite3"])
def test_a_topic_metadata_yaml_leaves_out_is_read_from_the_data_files(
    tmp_path: Path, bag: str
) -> None:
    """An edited or half-written metadata.yaml without the keep-alive topic: reading through
    it would report a lost stream that was recorded. The data files are read instead, and
    the findings are those of the intact bag, beside one line saying why."""
    intact = Path(__file__).parent.parent / "corpora" / "rosbag2" / bag
    damaged = tmp_path / bag
    shutil.copytree(intact, damaged)
    meta = damaged / "metadata.yaml"
    entries = meta.read_text().split("  - message_count: ")
    kept = [e for e in entries[1:] if "name: /fmu/in/offboard_control_mode\n" not in e]
    assert len(kept) == len(entries) - 2  # the one entry left out
    meta.write_text("  - message_count: ".join([entries[0], *kept]))
    assert_clean_failure(damaged, "metadata.yaml does not list /fmu/in/offboard_control_mode")

    def judged(path: Path) -> list[tuple[str, float | None]]:
        _, report, _ = lint(path)
        return [(f["code"], f["time_s"]) for f in report["findings"] if f["code"] != "OFB001"]

    assert judged(damaged) == judged(intact)
