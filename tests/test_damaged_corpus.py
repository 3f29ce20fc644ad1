"""Any damage to any recording: lint never raises or hangs, and says what it could not read.

Hypothesis damages corpus recordings of every format (cut, flipped bits, runs of 0x00 / 0xFF, huge
length-like words, spliced-out ranges) and lints them as a user would (``fuzzoff lint``). A sweep
like this found a pyulog hang; a ROS 2 schema, a ULog parameter type and NaN command params
that raised; and a garbage topic name that broke a problem across lines.
"""

from __future__ import annotations

import json
import os
import re
import signal
import struct
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from tests.helpers import CORPORA, run_cli

RECORDINGS = [
    CORPORA / "tlog" / "good_offboard.tlog",
    CORPORA / "ulog" / "switch_rejected.ulg",
    CORPORA / "real" / "sample_log_small.ulg",
    CORPORA / "mcap" / "good_flight.mcap",
    CORPORA / "stream" / "ofb104_good.mcap",
    CORPORA / "rosbag2" / "two_vehicles" / "two_vehicles.db3",
    CORPORA / "rosbag1" / "offboard_good.bag",
]

UNPRINTABLE = re.compile(r"[\x00-\x1f\x7f-\x9f]")

SWEEP = int(os.environ.get("FUZZOFF_DAMAGE_EXAMPLES", "0"))
"""Set for a broad random sweep by hand, e.g. ``FUZZOFF_DAMAGE_EXAMPLES=2000 pytest
tests/test_damaged_corpus.py``; unset, each format gets the same 60 damaged copies every run."""

SECONDS = 60
"""Far above any of these files' lint time (well under a second): only a hang reaches it."""


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


def damage(size: int) -> st.SearchStrategy[Damage]:
    return st.tuples(
        st.sampled_from(["cut", "flip", "fill", "length", "splice"]),
        st.integers(0, size - 1),
        st.integers(1, size),
        st.integers(0, 255),
    )


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
        words = (0x7FFFFFFF, 0xFFFFFFFF, 0x80000000, 2**63 - 1)
        out[at : at + 8] = struct.pack("<Q", words[pattern % 4])
    else:
        del out[at : at + amount]
    return bytes(out)


@pytest.mark.parametrize("recording", RECORDINGS, ids=lambda p: p.name)
@settings(
    max_examples=SWEEP or 60,
    deadline=None,
    derandomize=not SWEEP,  # the same damage on every CI run
    suppress_health_check=[HealthCheck.too_slow],
)
@given(data=st.data())
def test_any_damage_is_one_line_per_problem_never_a_traceback(
    recording: Path, data: st.DataObject, tmp_path_factory: pytest.TempPathFactory
) -> None:
    original = recording.read_bytes()
    path = tmp_path_factory.mktemp("damaged") / recording.name
    path.write_bytes(damaged(original, *data.draw(damage(len(original)), label="damage")))
    with deadline(SECONDS):
        result = run_cli(["lint", str(path), "--format", "json"])
    (report,) = json.loads(result.stdout)["files"]
    unreadable = [f for f in report["findings"] if f["code"] == "OFB001"]
    lines = result.stderr.splitlines()
    assert len(lines) == len(unreadable)  # one line each, however odd the bytes
    for line in lines:
        assert line.startswith(f"fuzzoff: {path}: ") and not UNPRINTABLE.search(line)
    assert report["complete"] == (not unreadable) == (result.returncode != 2)
