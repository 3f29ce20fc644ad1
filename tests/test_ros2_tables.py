"""A ROS 2 sqlite3 bag whose tables lose messages never passes with data unread (issue 26 item 2).

Rows whose ``topic_id`` the topics table lacks, rows deleted from the messages table, and PX4
topics recorded as a type fuzzoff cannot decode: each is OFB001 (exit 2, ``complete`` false)
with one line saying how many messages were not read and why, with or without metadata.yaml.
The bags are written by rosbags' writer and then edited with sqlite3, as the damage would be.
"""

from __future__ import annotations

import json
import sqlite3
from pathlib import Path
from typing import Any

import pytest

from fuzzoff.formats.rosbag2.writer import write_rosbag2
from tests.helpers import run_cli
from tests.test_ros2_bad_input import N, flight

Report = dict[str, Any]


@pytest.fixture
def bag(tmp_path: Path) -> Path:
    return write_rosbag2(tmp_path / "bag", flight())


def edit(bag: Path, *statements: str) -> None:
    with sqlite3.connect(bag / "bag.db3") as db:
        for statement in statements:
            db.execute(statement)


def without_metadata(bag: Path) -> Path:
    """The bag as a recorder that crashed leaves it: no metadata.yaml, its data file named
    ``<folder>_<n>.db3``."""
    (bag / "metadata.yaml").unlink()
    (bag / "bag.db3").rename(bag / "bag_0.db3")
    return bag


def lint(path: Path) -> tuple[int, Report, list[str]]:
    result = run_cli(["lint", str(path), "--format", "json"])
    (report,) = json.loads(result.stdout)["files"]
    assert "Traceback" not in result.stderr
    return result.returncode, report, result.stderr.splitlines()


def unread(path: Path) -> list[str]:
    """The OFB001 messages of a lint that must fail as incomplete, after the file's name; no
    OFB004 may say that every message was read."""
    code, report, lines = lint(path)
    assert code == 2 and report["complete"] is False, lines
    assert not any("every one was read" in line for line in lines), lines
    return [f["message"].split(": ", 1)[1] for f in report["findings"] if f["code"] == "OFB001"]


WHERE = {"with metadata.yaml": lambda bag: bag, "without": without_metadata}
GIVEN = {**WHERE, "the .db3 alone": lambda bag: bag / "bag.db3"}


@pytest.mark.parametrize("given", sorted(GIVEN))
def test_rows_of_a_topic_id_the_topics_table_lacks_are_not_read_and_said(
    bag: Path, given: str
) -> None:
    # Every row: the case (0 of 515 read, "every one was read", exit 0).
    edit(bag, "UPDATE messages SET topic_id = topic_id + 100")
    (message,) = unread(GIVEN[given](bag))
    assert message.startswith(
        f"{2 * N} message rows name a topic id the topics table lacks (101, 102): not read"
    )
    assert "not read at messages.topic_id" in message


@pytest.mark.parametrize("given", sorted(GIVEN))
def test_some_rows_of_a_missing_topic_are_counted(bag: Path, given: str) -> None:
    edit(bag, "UPDATE messages SET topic_id = 7 WHERE id % 10 = 0")
    (message,) = unread(GIVEN[given](bag))
    assert f"{2 * N // 10} message rows name a topic id the topics table lacks (7)" in message


@pytest.mark.parametrize("given", sorted(GIVEN))
def test_rows_deleted_from_the_middle_are_missing(bag: Path, given: str) -> None:
    edit(bag, "DELETE FROM messages WHERE id BETWEEN 101 AND 150")
    (message,) = unread(GIVEN[given](bag))
    assert f"50 of the {2 * N} message rows are missing from the database" in message


def test_rows_deleted_from_the_start_are_missing(bag: Path) -> None:
    edit(bag, "DELETE FROM messages WHERE id <= 30")
    messages = unread(bag)
    assert any(f"30 of the {2 * N} message rows are missing" in m for m in messages), messages


@pytest.mark.parametrize("rows", [1, 40])
def test_rows_deleted_from_the_end_are_not_passed_where_metadata_yaml_counts_them(
    bag: Path, rows: int
) -> None:
    # The ids cannot show a cut end; metadata.yaml's counts, from the same start, do.
    edit(bag, f"DELETE FROM messages WHERE id > {2 * N - rows}")
    (message,) = unread(bag)
    assert f"{rows} of the {2 * N} messages metadata.yaml lists on the PX4 topics" in message
    assert "are not in the data files" in message


def test_a_wrong_count_in_metadata_yaml_cannot_be_told_from_lost_messages(bag: Path) -> None:
    meta = bag / "metadata.yaml"
    meta.write_text(meta.read_text().replace(f"message_count: {N}", f"message_count: {N + 80}", 1))
    (message,) = unread(bag)
    assert "messages lost, or metadata.yaml's counts damaged: which cannot be told" in message


def test_metadata_yaml_of_another_bag_that_lists_more_messages_loses_none(bag: Path) -> None:
    meta = bag / "metadata.yaml"
    text = meta.read_text().replace(f"message_count: {N}", f"message_count: {N + 80}", 1)
    meta.write_text(
        text.replace("since_epoch: 1700000000000000000", "since_epoch: 1690000000000000000")
    )
    code, report, lines = lint(bag)
    assert code != 2 and report["complete"] is True
    assert any("the data files hold 800: every one was read" in line for line in lines), lines


UNKNOWN = "other_msgs/msg/Setpoint"


@pytest.mark.parametrize("given", sorted(GIVEN))
def test_a_px4_topic_of_a_type_fuzzoff_cannot_decode_is_not_read_and_counted(
    bag: Path, given: str
) -> None:
    edit(bag, f"UPDATE topics SET type = '{UNKNOWN}' WHERE name = '/fmu/in/trajectory_setpoint'")
    messages = unread(GIVEN[given](bag))
    expected = (
        f"topic /fmu/in/trajectory_setpoint has message type {UNKNOWN}, which fuzzoff cannot "
        f"decode as a PX4 topic: its {N} messages were not read"
    )
    assert any(m.startswith(expected) for m in messages), messages
    if given == "with metadata.yaml":  # which of the two is right cannot be told
        assert any("metadata.yaml does not list /fmu/in/trajectory_setpoint" in m for m in messages)
    else:
        assert len(messages) == 1


def test_an_unknown_type_both_metadata_yaml_and_the_database_name_is_counted(bag: Path) -> None:
    edit(bag, f"UPDATE topics SET type = '{UNKNOWN}' WHERE name = '/fmu/in/trajectory_setpoint'")
    meta = bag / "metadata.yaml"
    meta.write_text(meta.read_text().replace("px4_msgs/msg/TrajectorySetpoint", UNKNOWN))
    (message,) = unread(bag)
    assert f"which fuzzoff cannot decode as a PX4 topic: its {N} messages were not read" in message


def test_a_damaged_database_salvaged_row_by_row_counts_rows_of_no_topic(bag: Path) -> None:
    edit(bag, "UPDATE messages SET topic_id = 9 WHERE id > 600")
    db3 = bag / "bag.db3"
    data = db3.read_bytes()
    db3.write_bytes(data[: len(data) - 10])  # rosbags refuses it; salvaged with sqlite3
    messages = unread(db3)
    assert any(m.startswith(f"{2 * N - 600} message rows name a topic id") for m in messages), (
        messages
    )


def test_an_intact_bag_says_nothing(bag: Path) -> None:
    code, report, lines = lint(bag)
    assert lines == [] and report["complete"] is True and code != 2
