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
import struct
from collections import Counter
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from functools import cache
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
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


def copy_damaged(name: str, tmp: Path, choose: int, hit: Damage) -> tuple[Path, bool]:
    """The damaged copy: the recording to lint, and whether its metadata.yaml was damaged."""
    source = CASES[name].recording
    if source.is_dir():
        folder = tmp / source.name
        shutil.copytree(source, folder)
        files = sorted(folder.iterdir())
        target = files[choose % len(files)]
        recording = folder
    else:
        target = recording = tmp / source.name
        shutil.copyfile(source, target)
    target.write_bytes(damaged(target.read_bytes(), *hit))
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
    tmp = tmp_path_factory.mktemp("damaged")
    recording, metadata = copy_damaged(name, tmp, choose, hit)

    with deadline(SECONDS):
        result = run_cli(["lint", str(recording), "--format", "json"])
        after = events(recording)
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
    allowed = 0 if metadata else spots(case, hit[0], hit[2], hit[3])
    before = undamaged(name)
    if case.endless and hit[0] == "cut" and cut_short(before, after):
        return  # a cut between two records: no reader can tell
    if differs_beyond(before, after, allowed):
        assert not report["complete"], f"events changed in silence: {lines}"


def test_the_length_damage_writes_the_words_it_names() -> None:
    zero = damaged(b"\x11" * 16, "length", 4, 1, 4 * 0 + 3)  # 8 bytes of 0
    ones = damaged(b"\x11" * 16, "length", 4, 1, 4 * 1 + 2)  # 4 bytes of 0xff
    top = damaged(b"\x11" * 16, "length", 4, 1, 4 * 2 + 1)  # 2 bytes: 0x8000
    most = damaged(b"\x11" * 16, "length", 4, 1, 4 * 3 + 3)  # 8 bytes: 2**63 - 1
    assert zero[4:12] == bytes(8)
    assert ones[4:8] == b"\xff" * 4
    assert struct.unpack_from("<H", top, 4)[0] == 0x8000
    assert struct.unpack_from("<Q", most, 4)[0] == 2**63 - 1
