"""The damage campaign: any damage to a recording of any format is said, never lost in silence.

Hypothesis damages a corpus recording of every format and every reader (cuts, flipped bits, runs
of 0x00 / 0xFF, length-like words set to 0 or their largest values, ranges removed or
duplicated, garbage appended; in a ROS 2 bag folder, its data file or its ``metadata.yaml``)
and lints the copy as a user would (``fuzzoff lint``, in this process). For every copy:

* no exception and no hang (``SECONDS``), the process's peak memory under ``MEMORY_BYTES``;
  exit status 0, 1 or 2;
* one clean stderr line per OFB001 and OFB004 finding, naming the file;
* ``complete`` is false exactly when an OFB001 was reported, and then the exit status is 2;
* whenever the reader's events differ from the undamaged recording's, the file is reported
  incomplete, unless the difference is one the format cannot show: in formats without
  checksums (``LENIENT``), the values inside as many messages as the damage touched.

Each damaged copy is given a name Hypothesis draws too (its own, in upper case, with ``.active``
after it, with another format's extension, or none): a recording is read by its content, so the
name changes nothing the campaign checks (issue 26 item 3).

A ROS 2 database's tables are damaged as well as its bytes (issue 26 item 2): message rows whose
topic id the topics table lacks, a PX4 topic recorded as a type fuzzoff cannot decode, and rows
deleted. Every such copy loses messages, so its lint must say which (OFB001, exit 2).

Failures it found stay as corpus cases (corpora/damaged/build.py). ``FUZZOFF_DAMAGE_EXAMPLES=2000
pytest tests/test_damaged_corpus.py`` runs a broad random sweep by hand; unset, each recording
gets the same ``EXAMPLES`` damaged copies on every run.
"""

from __future__ import annotations

import json
import os
import re
import resource
import shutil
import signal
import sqlite3
import struct
from collections import Counter
from collections.abc import Iterator
from contextlib import contextmanager, suppress
from dataclasses import dataclass
from functools import cache
from pathlib import Path
from typing import Any

import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

from fuzzoff.formats import SourceError, open_source
from tests.helpers import CORPORA, run_cli


@dataclass(frozen=True)
class Case:
    recording: Path
    """What is linted: a file, or a ROS 2 bag folder (one of whose files is damaged)."""
    lenient: bool
    """No checksum covers the messages' payloads (or a tlog record's timestamp, outside the
    packet's CRC): a flipped value can only be seen as such."""
    endless: bool = False
    """Nothing marks the end of the file (no footer, index or size) and nothing numbers the
    records: cut between two records it is a shorter recording, and whole records removed or
    repeated (a splice that lands on a record boundary) leave no trace."""


CASES = {
    "tlog": Case(CORPORA / "tlog" / "good_offboard.tlog", lenient=True, endless=True),
    "ulog": Case(CORPORA / "ulog" / "switch_rejected.ulg", lenient=True, endless=True),
    "ulog-real": Case(CORPORA / "real" / "sample_log_small.ulg", lenient=True, endless=True),
    "tlog-px4": Case(CORPORA / "sitl" / "clean_offboard-1.16.2.tlog", lenient=True, endless=True),
    "ulog-px4": Case(
        CORPORA / "sitl" / "disarmed_switch_no_stream-1.18.0-alpha1.ulg", lenient=True, endless=True
    ),
    "mcap": Case(CORPORA / "damaged" / "chunked.mcap", lenient=False),
    "mcap-one-chunk": Case(CORPORA / "stream" / "ofb104_good.mcap", lenient=False),
    "rosbag2-sqlite3": Case(CORPORA / "rosbag2" / "two_vehicles", lenient=True),
    "rosbag2-mcap": Case(CORPORA / "rosbag2" / "stream_lost_mcap", lenient=True),
    "rosbag1": Case(CORPORA / "damaged" / "chunked.bag", lenient=True),
}

EXAMPLES = 50
SWEEP = int(os.environ.get("FUZZOFF_DAMAGE_EXAMPLES", "0"))
SECONDS = 60
"""Far above any of these files' lint time (well under a second): only a hang reaches it."""
MEMORY_BYTES = 1 << 30
"""A length field read as a size must never be allocated: this process stays under 1 GB."""

UNPRINTABLE = re.compile(r"[\x00-\x1f\x7f-\x9f\u202a-\u202e\u2066-\u2069]")
LINE_LIMIT = 600
"""Longest stderr line after the path: names from the file are cut."""


class Hang(Exception):
    pass


@contextmanager
def deadline(seconds: int) -> Iterator[None]:
    def expire(_signum: int, _frame: object) -> None:
        raise Hang(f"lint still running after {seconds} s")

    previous = signal.signal(signal.SIGALRM, expire)
    signal.alarm(seconds)
    try:
        yield
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, previous)


Damage = tuple[str, int, int, int]
"""(how, where, how much, which pattern): small enough to read in a failing example."""

HOW = ["cut", "flip", "fill", "length", "splice", "duplicate", "append"]


def damage(size: int) -> st.SearchStrategy[Damage]:
    """Anywhere, but the first and last 512 bytes (headers, indexes, footers) more often."""
    where = st.one_of(
        st.integers(0, size - 1),
        st.integers(0, min(size, 512) - 1),
        st.integers(max(0, size - 512), size - 1),
    )
    return st.tuples(st.sampled_from(HOW), where, st.integers(1, size), st.integers(0, 255))


WORDS = (1, 2, 4, 8)
"""The widths of a length field: tlog 1, ULog 2, ROS 1 4, MCAP 8 bytes."""


def length_word(pattern: int) -> bytes:
    """A length-like word: 0, all ones, only the top bit, or all but the top bit."""
    width = WORDS[pattern % 4]
    bits = 8 * width
    value = (0, (1 << bits) - 1, 1 << (bits - 1), (1 << (bits - 1)) - 1)[pattern // 4 % 4]
    return value.to_bytes(width, "little")


def damaged(data: bytes, how: str, at: int, amount: int, pattern: int) -> bytes:
    out = bytearray(data)
    if how == "cut":
        return bytes(out[:at])
    if how == "flip":  # a few bits flipped around ``at``
        for k in range(1 + pattern % 8):
            spot = (at + k * amount) % len(out)
            out[spot] ^= 1 << (pattern + k) % 8
    elif how == "fill":
        out[at : at + amount % 64 + 1] = (b"\xff" if pattern % 2 else b"\x00") * (amount % 64 + 1)
    elif how == "length":
        word = length_word(pattern)
        out[at : at + len(word)] = word
    elif how == "splice":
        del out[at : at + amount]
    elif how == "duplicate":
        out[at + amount : at + amount] = out[at : at + amount]
    else:  # append
        out += bytes((pattern + k * 37) % 256 for k in range(amount % 512 + 1))
    return bytes(out)


SMALLEST_RECORD = 10
"""Bytes of the smallest record of the endless formats (a ULog data record, a tlog packet)."""


def spots(case: Case, how: str, amount: int, pattern: int) -> int:
    """How many messages the damage can change in a way the format cannot show: values inside
    messages without a checksum; whole records of a format that does not number them."""
    if case.lenient and how == "flip":
        return 1 + pattern % 8
    if case.lenient and how == "fill":
        return 2 + (amount % 64 + 1) // 16
    if case.lenient and how == "length":
        return 1
    if case.endless and how in ("splice", "duplicate"):
        return 1 + amount // SMALLEST_RECORD
    return 0


def events(recording: Path) -> list[tuple[str, str, int | None, str]] | None:
    """The reader's events as (type, topic, index, everything), or None if it read none."""
    try:
        with open_source(recording) as source:
            source.probe()
            out = []
            for e in source.events():
                where = e.where
                key = (type(e).__name__, where.topic, where.index)
                out.append((*key, repr(e).replace(f"offset={where.offset}", "")))
            return out
    except SourceError:
        return None


@cache
def undamaged(name: str) -> list[tuple[str, str, int | None, str]] | None:
    return events(CASES[name].recording)


def differs_beyond(
    before: list[tuple[str, str, int | None, str]] | None,
    after: list[tuple[str, str, int | None, str]] | None,
    allowed: int,
) -> bool:
    """Do the events differ by more than ``allowed`` messages (0: at all)? Counted per event
    type and topic: a message whose values changed, or that now reads as another (or no)
    event, moves at most two of those counts (a tlog HEARTBEAT is two events); its place
    in its topic does not count, since every later one's moves with it."""
    if before == after:
        return False
    if allowed == 0 or before is None or after is None:
        return True
    kinds = Counter(e[:2] for e in before)
    kinds_after = Counter(e[:2] for e in after)
    moved = (kinds - kinds_after).total() + (kinds_after - kinds).total()
    return moved > 2 * allowed


def cut_short(
    before: list[tuple[str, str, int | None, str]] | None,
    after: list[tuple[str, str, int | None, str]] | None,
) -> bool:
    """Is every topic's event list of ``after`` the start of ``before``'s?"""
    if before is None or after is None:
        return after is None or not after

    def by_topic(events: list[tuple[str, str, int | None, str]]) -> dict[str, list[str]]:
        topics: dict[str, list[str]] = {}
        for event in events:
            topics.setdefault(event[1], []).append(event[3])
        return topics

    whole, cut = by_topic(before), by_topic(after)
    return all(whole.get(topic, [])[: len(events)] == events for topic, events in cut.items())


NAMES = ("its own", "upper case", ".active", "another format's extension", "none")
OTHER_EXTENSION = {
    ".tlog": ".ulg",
    ".ulg": ".mcap",
    ".mcap": ".db3",
    ".bag": ".tlog",
    ".db3": ".bag",
}


def renamed(path: Path, how: str) -> Path:
    """``path`` under the name ``how`` says (a name in ``NAMES``)."""
    if how == "upper case":
        return path.with_name(path.name.upper())
    if how == ".active":
        return path.with_name(path.name + ".active")
    if how == "another format's extension":
        return path.with_suffix(OTHER_EXTENSION[path.suffix])
    if how == "none":
        return path.with_suffix("")
    return path


def rename_data_file(folder: Path, data: Path, how: str) -> Path:
    """A bag's data file renamed, and metadata.yaml's list of files with it (where it can
    still be read as text): a bag renamed by hand."""
    new = renamed(data, how)
    if new == data:
        return data
    data.rename(new)
    meta = folder / "metadata.yaml"
    with suppress(OSError, UnicodeDecodeError):
        meta.write_text(meta.read_text(encoding="utf-8").replace(data.name, new.name))
    return new


def copy_damaged(
    name: str, tmp: Path, choose: int, hit: Damage, how: str = "its own"
) -> tuple[Path, bool]:
    """The damaged copy, under the name ``how`` says: the recording to lint, and whether its
    metadata.yaml was damaged."""
    source = CASES[name].recording
    if source.is_dir():
        folder = tmp / source.name
        shutil.copytree(source, folder)
        files = sorted(folder.iterdir())
        target = files[choose % len(files)]
        recording = folder
    else:
        target = recording = tmp / renamed(source, how).name
        shutil.copyfile(source, target)
    target.write_bytes(damaged(target.read_bytes(), *hit))
    if source.is_dir():
        for data in sorted(folder.iterdir()):
            if data.name != "metadata.yaml":
                rename_data_file(folder, data, how)
    return recording, target.name == "metadata.yaml"


@pytest.mark.parametrize("name", sorted(CASES))
@settings(
    max_examples=SWEEP or EXAMPLES,
    deadline=None,
    derandomize=not SWEEP,  # the same damage on every CI run
    database=None,
    suppress_health_check=[HealthCheck.too_slow],
)
@given(data=st.data())
def test_any_damage_is_said_never_lost_in_silence(
    name: str, data: st.DataObject, tmp_path_factory: pytest.TempPathFactory
) -> None:
    case = CASES[name]
    source = case.recording
    choose = data.draw(st.integers(0, 7), label="file") if source.is_dir() else 0
    files = sorted(source.iterdir()) if source.is_dir() else [source]
    size = files[choose % len(files)].stat().st_size
    hit = data.draw(damage(size), label="damage")
    how = data.draw(st.sampled_from(NAMES), label="name")
    tmp = tmp_path_factory.mktemp("damaged")
    recording, metadata = copy_damaged(name, tmp, choose, hit, how)

    with deadline(SECONDS):
        report, lines, _ = lint_as_a_user_would(recording)
        after = events(recording)
    allowed = 0 if metadata else spots(case, hit[0], hit[2], hit[3])
    before = undamaged(name)
    if case.endless and hit[0] == "cut" and cut_short(before, after):
        return  # a cut between two records: no reader can tell
    if differs_beyond(before, after, allowed):
        assert not report["complete"], f"events changed in silence: {lines}"


def lint_as_a_user_would(recording: Path) -> tuple[dict[str, Any], list[str], int]:
    """``fuzzoff lint RECORDING --format json``: its report, stderr lines and exit status,
    checked for what every lint of a damaged file must hold (no exception, no more than 1 GB,
    one clean line per OFB001 and OFB004, incomplete exactly when OFB001, then exit 2)."""
    result = run_cli(["lint", str(recording), "--format", "json"])
    assert resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024 < MEMORY_BYTES
    assert result.returncode in (0, 1, 2)
    (report,) = json.loads(result.stdout)["files"]
    said = [f for f in report["findings"] if f["code"] in ("OFB001", "OFB004")]
    unreadable = [f for f in said if f["code"] == "OFB001"]
    lines = result.stderr.splitlines()
    assert len(lines) == len(said)  # one line each, however odd the bytes
    for line in lines:
        assert line.startswith(f"fuzzoff: {recording}: ") and not UNPRINTABLE.search(line)
        assert len(line) - len(str(recording)) < LINE_LIMIT
    assert report["complete"] == (not unreadable) == (result.returncode != 2)
    return report, lines, result.returncode


# -- a ROS 2 database's tables (issue 26 item 2) ---------------------------------------------

TABLES_BAG = CORPORA / "rosbag2" / "two_vehicles"
TableDamage = tuple[str, int, int, bool]
"""(how, first row id or topic id, how many rows, metadata.yaml kept)."""


def table_damage(rows: int, topics: int) -> st.SearchStrategy[TableDamage]:
    return st.one_of(
        st.tuples(
            st.sampled_from(["dangling topic ids", "missing rows"]),
            st.integers(1, rows),
            st.integers(1, rows),
            st.booleans(),
        ),
        st.tuples(st.just("unknown type"), st.integers(1, topics), st.just(0), st.booleans()),
    )


def damage_tables(db3: Path, hit: TableDamage) -> None:
    how, first, amount, _ = hit
    with sqlite3.connect(db3) as db:
        if how == "dangling topic ids":  # a topic id no topic has, as a flipped bit leaves
            db.execute(
                "UPDATE messages SET topic_id = topic_id + 1000 WHERE id BETWEEN ? AND ?",
                (first, first + amount - 1),
            )
        elif how == "missing rows":
            db.execute("DELETE FROM messages WHERE id BETWEEN ? AND ?", (first, first + amount - 1))
        else:
            db.execute("UPDATE topics SET type = 'fuzzoff_test/msg/Unknown' WHERE id = ?", (first,))


@cache
def table_counts() -> tuple[int, int]:
    with sqlite3.connect(f"file:{TABLES_BAG / 'two_vehicles.db3'}?mode=ro", uri=True) as db:
        rows = db.execute("SELECT MAX(id) FROM messages").fetchone()[0]
        topics = db.execute("SELECT MAX(id) FROM topics").fetchone()[0]
    return int(rows), int(topics)


@settings(
    max_examples=SWEEP or EXAMPLES,
    deadline=None,
    derandomize=not SWEEP,
    database=None,
    suppress_health_check=[HealthCheck.too_slow],
)
@given(data=st.data())
def test_a_database_whose_tables_lose_messages_never_passes(
    data: st.DataObject, tmp_path_factory: pytest.TempPathFactory
) -> None:
    rows, topics = table_counts()
    hit = data.draw(table_damage(rows, topics), label="damage")
    how, first, amount, kept = hit
    # Rows cut from the end leave no trace without metadata.yaml's counts (nor do the ids:
    # rosbag2 numbers rows from 1): no reader can tell, as with a cut between two records.
    assume(kept or how != "missing rows" or first + amount - 1 < rows)
    name = data.draw(st.sampled_from(NAMES), label="name")
    bag = tmp_path_factory.mktemp("tables") / TABLES_BAG.name
    shutil.copytree(TABLES_BAG, bag)
    damage_tables(bag / "two_vehicles.db3", hit)
    data_file = rename_data_file(bag, bag / "two_vehicles.db3", name)
    recording = bag
    if not kept:  # what is linted is then the database itself
        (bag / "metadata.yaml").unlink()
        recording = data_file

    with deadline(SECONDS):
        report, lines, code = lint_as_a_user_would(recording)
        after = events(recording)
    before = events(TABLES_BAG)
    assert before is not None and (after is None or len(after) < len(before))
    assert code == 2 and not report["complete"], lines
    assert not any("every one was read" in line for line in lines), lines


def test_the_length_damage_writes_the_words_it_names() -> None:
    zero = damaged(b"\x11" * 16, "length", 4, 1, 4 * 0 + 3)  # 8 bytes of 0
    ones = damaged(b"\x11" * 16, "length", 4, 1, 4 * 1 + 2)  # 4 bytes of 0xff
    top = damaged(b"\x11" * 16, "length", 4, 1, 4 * 2 + 1)  # 2 bytes: 0x8000
    most = damaged(b"\x11" * 16, "length", 4, 1, 4 * 3 + 3)  # 8 bytes: 2**63 - 1
    assert zero[4:12] == bytes(8)
    assert ones[4:8] == b"\xff" * 4
    assert struct.unpack_from("<H", top, 4)[0] == 0x8000
    assert struct.unpack_from("<Q", most, 4)[0] == 2**63 - 1
