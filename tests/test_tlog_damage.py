"""A tlog whose good start is followed by a long stretch of garbage (issue 19 item 6): the search
for the next packet stops after a bounded stretch and says where, and the progress shown on a
terminal moves through the garbage instead of standing still for minutes."""

from __future__ import annotations

import json
from pathlib import Path

from fuzzoff.engine import lint_file
from fuzzoff.formats.tlog.frames import RESYNC_LIMIT
from tests.helpers import CORPORA, run_cli

GOOD = CORPORA / "tlog" / "good_offboard.tlog"


def garbage_after_a_good_start(path: Path, garbage: int) -> int:
    """The first 2 kB of a good tlog, then ``garbage`` zero bytes (a sparse file: no disk
    used); returns where the garbage starts."""
    head = GOOD.read_bytes()[:2048]
    with path.open("wb") as fh:
        fh.write(head)
        fh.truncate(len(head) + garbage)
    return len(head)


def test_the_search_for_a_packet_stops_and_says_where(tmp_path: Path) -> None:
    path = tmp_path / "disk.tlog"
    size = 3 * RESYNC_LIMIT
    garbage_after_a_good_start(path, size)
    result = run_cli(["lint", str(path), "--format", "json"])
    assert result.returncode == 2
    lines = result.stderr.splitlines()
    (stop,) = [line for line in lines if "reading stopped" in line]
    assert f"no MAVLink packet in the {RESYNC_LIMIT >> 20} MiB after byte" in stop
    stopped_at = int(stop.rsplit(" at byte ", 1)[1])
    assert RESYNC_LIMIT < stopped_at < RESYNC_LIMIT + (2 << 20)  # not the whole file
    assert f"the last {path.stat().st_size - stopped_at} bytes were not read" in stop
    (report,) = json.loads(result.stdout)["files"]
    assert report["complete"] is False


def test_progress_moves_through_garbage(tmp_path: Path) -> None:
    path = tmp_path / "noise.tlog"
    garbage_after_a_good_start(path, 8 << 20)
    shown: list[float] = []
    lint_file(path, progress=shown.append)
    during = [f for f in shown if 0.0 < f < 1.0]
    assert len(during) >= 4  # a chunk at a time, though the garbage yields no event
    assert during == sorted(during) and during[-1] > 0.5
