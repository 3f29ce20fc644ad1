"""The indexed MCAP path (``formats/mcap/indexed``) reads what rosbags' own path reads.

A recording whose PX4 topics are a small share of its messages (camera and IMU beside them) is
read through the MCAP message indexes; everything else through rosbags. Both must give the same
events in the same order and the same problems, on good files and on damaged ones.
"""

from __future__ import annotations

import shutil
from collections.abc import Iterator
from pathlib import Path

import pytest
from mcap.reader import SeekingReader
from mcap.writer import CompressionType

from bench.ros2_data import generate
from fuzzoff.events import event_to_dict
from fuzzoff.formats import open_source
from fuzzoff.formats.mcap.writer import write_mcap
from fuzzoff.formats.ros2 import mcap_indexed
from fuzzoff.formats.ros2msgs.messages import RawMessage

ROOT = Path(__file__).resolve().parent.parent
CORPUS_MCAP = sorted(
    p
    for p in (ROOT / "corpora").rglob("*.mcap")
    if "truncated" not in p.name and ("damaged" not in p.parts or p.name == "chunked.mcap")
)
"""Every corpus MCAP file a summary can be read from and trusted (bag folders hold theirs;
corpora/damaged damages the summary or the bytes around it on purpose, but for its base)."""


def _read(path: Path) -> tuple[list[str], list[str]]:
    """Events as text (NaN compares equal there) and the problems, as a user sees them."""
    source = open_source(path)
    with source:
        source.probe()
        events = [repr(event_to_dict(e)) for e in source.events()]
    return events, [str(p) for p in source.problems]


def _rosbags_read(path: Path, monkeypatch: pytest.MonkeyPatch) -> tuple[list[str], list[str]]:
    with monkeypatch.context() as patch:
        patch.setattr(mcap_indexed, "SHARE", 0.0)
        return _read(path)


@pytest.fixture(scope="module")
def mixed(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """A small camera + IMU + PX4 recording as a bare MCAP file and as an mcap-storage bag."""
    folder = tmp_path_factory.mktemp("mixed")
    return {
        "mcap": generate(folder / "mixed.mcap", "mcap", 4000, mixed=True),
        "rosbag2-mcap": generate(folder / "mixed_bag", "rosbag2-mcap", 4000, mixed=True),
    }


def _data_file(path: Path) -> Path:
    return path if path.is_file() else next(path.glob("*.mcap"))


@pytest.fixture
def indexed_reads(monkeypatch: pytest.MonkeyPatch) -> list[Path]:
    """The files read through the indexes from here on."""
    calls: list[Path] = []
    real = mcap_indexed.messages

    def spy(plan: mcap_indexed.Plan) -> Iterator[tuple[int, int, bytes]]:
        calls.append(plan.path)
        return real(plan)

    monkeypatch.setattr(mcap_indexed, "messages", spy)
    return calls


@pytest.mark.parametrize("kind", ["mcap", "rosbag2-mcap"])
def test_mixed_recording_is_read_through_the_indexes(
    mixed: dict[str, Path], kind: str, indexed_reads: list[Path]
) -> None:
    events, problems = _read(mixed[kind])
    assert indexed_reads == [_data_file(mixed[kind])]
    assert problems == []
    assert any("trajectory_setpoint" in e for e in events)
    assert not any("/imu/data" in e or "/camera" in e for e in events)


@pytest.mark.parametrize("kind", ["mcap", "rosbag2-mcap"])
def test_indexed_events_are_rosbags_events(
    mixed: dict[str, Path], kind: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    indexed = _read(mixed[kind])
    assert len(indexed[0]) > 300
    assert _rosbags_read(mixed[kind], monkeypatch) == indexed


@pytest.mark.parametrize("path", CORPUS_MCAP, ids=lambda p: p.parent.name + "/" + p.name)
def test_corpus_reads_the_same_through_the_indexes(
    path: Path, monkeypatch: pytest.MonkeyPatch, indexed_reads: list[Path]
) -> None:
    """PX4-only corpus files normally take rosbags' path: forced through the indexes, they
    must read the same (whatever the layout the writers chose)."""
    with monkeypatch.context() as patch:
        patch.setattr(mcap_indexed, "SHARE", 2.0)
        forced = _read(path)
    assert indexed_reads == [path]
    assert forced[0]
    assert _rosbags_read(path, monkeypatch) == forced
    assert indexed_reads == [path]


@pytest.mark.parametrize("compression", list(CompressionType), ids=lambda c: c.name.lower())
def test_every_chunk_compression_reads_the_same(
    compression: CompressionType,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    indexed_reads: list[Path],
) -> None:
    """Small chunks (many overlapping in time) of each compression the mcap writer offers."""
    source = open_source(ROOT / "corpora" / "mcap" / "good_flight.mcap")
    with source:
        source.probe()
        events = list(source.events())
    end = max(e.t for e in events)
    filler = [
        RawMessage(
            k / 200, "/camera/image_raw", "sensor_msgs/msg/Image", "uint8[] data", b"\0" * 600
        )
        for k in range(int(end * 200))
    ]
    path = write_mcap(
        tmp_path / f"{compression.name}.mcap",
        events,
        extra=filler,
        chunk_size=8192,
        compression=compression,
    )
    assert len(_chunk_offsets(path)) > 20
    indexed = _read(path)
    assert indexed_reads == [path]
    assert indexed[1] == [] and len(indexed[0]) == len(events)
    assert _rosbags_read(path, monkeypatch) == indexed


def _chunk_offsets(path: Path) -> list[tuple[int, int]]:
    with path.open("rb") as fh:
        summary = SeekingReader(fh).get_summary()
    assert summary is not None
    return [(c.chunk_start_offset, c.chunk_length) for c in summary.chunk_indexes]


def test_flipped_bytes_in_a_chunk_read_as_rosbags_reads_them(
    mixed: dict[str, Path], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A CRC mismatch ends the indexed pass like rosbags' pass: the streaming reader skips the
    bad chunk, keeps the rest and reports it."""
    damaged = tmp_path / "damaged.mcap"
    shutil.copyfile(mixed["mcap"], damaged)
    start, length = _chunk_offsets(damaged)[1]
    data = bytearray(damaged.read_bytes())
    middle = start + length // 2
    data[middle : middle + 32] = bytes(b ^ 0xFF for b in data[middle : middle + 32])
    damaged.write_bytes(bytes(data))
    events, problems = _read(damaged)
    assert any("CRC mismatch" in p for p in problems)
    assert events
    assert _rosbags_read(damaged, monkeypatch) == (events, problems)


def test_a_message_index_pointing_elsewhere_loses_nothing(
    mixed: dict[str, Path], tmp_path: Path
) -> None:
    """An index that does not match its chunk stops the indexed pass; the streaming reader
    (which does not use the indexes) reads every message instead."""
    good_events, _ = _read(mixed["mcap"])
    damaged = tmp_path / "bad_index.mcap"
    shutil.copyfile(mixed["mcap"], damaged)
    with damaged.open("rb") as fh:
        summary = SeekingReader(fh).get_summary()
    assert summary is not None
    px4 = next(i for i, c in summary.channels.items() if c.topic.endswith("trajectory_setpoint"))
    first_index = next(c for c in summary.chunk_indexes if px4 in c.message_index_offsets)
    offset = first_index.message_index_offsets[px4]
    data = bytearray(damaged.read_bytes())
    # opcode (1) + record length (8) + channel id (2) + entries length (4), then the first
    # entry's log time (8) and place in the chunk (8): move the place by one byte
    place = offset + 1 + 8 + 2 + 4 + 8
    data[place] ^= 0x01
    damaged.write_bytes(bytes(data))
    events, _ = _read(damaged)
    assert events == good_events
