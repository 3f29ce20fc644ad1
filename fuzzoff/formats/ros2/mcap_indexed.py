"""MCAP read through its message indexes, for recordings where the PX4 topics are a small share.

Both libraries read a chunk by parsing every record in it (rosbags' ``msgsrc``, mcap's
``breakup_chunk``). Where camera and IMU topics share the chunks with the PX4 topics, that
parsing is most of the reading time. An indexed MCAP lists, per chunk and channel, where each
message sits in the chunk (the MessageIndex records after the chunk, formats.md 4.1). This reader
reads, decompresses and CRC-checks every chunk that holds a chosen channel, as rosbags does, then
parses only the chosen messages, with mcap's record classes.

Messages come out in rosbags' order (log time, then chunk, then place in the chunk), so both
paths give the same events; ``tests/test_mcap_indexed.py`` compares them. Damage raises, as
rosbags does, and the caller's salvage path takes over.
"""

from __future__ import annotations

import heapq
import io
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import BinaryIO

from mcap.data_stream import ReadDataStream
from mcap.exceptions import McapError
from mcap.opcode import Opcode
from mcap.reader import SeekingReader
from mcap.records import Chunk, ChunkIndex, Message, MessageIndex
from mcap.stream_reader import get_chunk_data_stream

from fuzzoff.formats.ros2.mcap_stream import MAX_CHUNK_INFLATION
from fuzzoff.lean_dataclass import dataclass

SHARE = 0.5
"""The indexes are used when the chosen channels hold less than this share of the messages;
above it, parsing whole chunks costs about the same and the library's own path is kept."""

MESSAGE_HEADER = 22
"""Bytes of a Message record before its data: channel id, sequence, log and publish time."""

Wanted = Callable[[str, str], bool]
"""(topic, message type) -> is the channel to be read."""


class IndexMismatch(McapError):
    """The indexes do not describe the chunk (a damaged file)."""


@dataclass(frozen=True)
class Plan:
    """What to read: the chosen channels (id -> topic, message type) and the chunks holding
    any of them, in file order."""

    path: Path
    channels: dict[int, tuple[str, str]]
    chunks: list[ChunkIndex]


def plan(path: Path, wanted: Wanted) -> Plan | None:
    """The reading plan, or None when the file lacks what this path needs (a summary with
    statistics and chunk indexes, every chunk with its message indexes) or when the chosen
    channels are not a small share of the messages."""
    try:
        with path.open("rb") as fh:
            summary = SeekingReader(fh, record_size_limit=path.stat().st_size).get_summary()
    except Exception:  # no usable summary: the caller's path reports what is wrong
        return None
    if summary is None or summary.statistics is None or not summary.chunk_indexes:
        return None
    if any(not index.message_index_offsets for index in summary.chunk_indexes):
        return None
    channels: dict[int, tuple[str, str]] = {}
    for channel_id, channel in summary.channels.items():
        schema = summary.schemas.get(channel.schema_id)
        msgtype = schema.name if schema is not None else ""
        if wanted(channel.topic, msgtype):
            channels[channel_id] = (channel.topic, msgtype)
    statistics = summary.statistics
    chosen = sum(statistics.channel_message_counts.get(c, 0) for c in channels)
    if not channels or chosen >= SHARE * statistics.message_count:
        return None
    chunks = [
        index
        for index in summary.chunk_indexes
        if any(c in index.message_index_offsets for c in channels)
    ]
    chunks.sort(key=lambda index: index.chunk_start_offset)
    return Plan(path, channels, chunks)


def messages(plan: Plan) -> Iterator[tuple[int, int, bytes]]:
    """(channel id, log time in ns, CDR payload) of the chosen channels, in rosbags' order.

    Chunks are merged as rosbags merges them: each chunk is read when the merge reaches its
    start time, so only chunks that overlap in time are held at once."""
    size = plan.path.stat().st_size
    with plan.path.open("rb") as fh:
        sources = [_chunk(fh, size, index, plan.channels) for index in plan.chunks]
        for log_time, _, _, channel_id, data in heapq.merge(*sources):
            if channel_id >= 0:
                yield channel_id, log_time, data


def _chunk(
    fh: BinaryIO, size: int, index: ChunkIndex, channels: dict[int, tuple[str, str]]
) -> Iterator[tuple[int, int, int, int, bytes]]:
    """One chunk's chosen messages as (log time, chunk offset, place, channel id, data),
    sorted; first a marker at the chunk's start time, so the merge opens it only then."""
    yield (index.message_start_time, -1, 0, -1, b"")
    data = _chunk_data(fh, size, index)
    places: list[tuple[int, int]] = []
    for channel_id in channels:
        offset = index.message_index_offsets.get(channel_id)
        if offset is not None:
            places.extend((place, channel_id) for _, place in _message_index(fh, offset))
    view = io.BytesIO(data)
    stream = ReadDataStream(view)
    found: list[tuple[int, int, int, int, bytes]] = []
    for place, channel_id in places:
        view.seek(place)
        if stream.read1() != Opcode.MESSAGE:
            raise IndexMismatch(f"message index points at a record that is not a message ({place})")
        length = stream.read8()
        if length < MESSAGE_HEADER or place + 9 + length > len(data):
            raise IndexMismatch(f"message record at {place} has an impossible length")
        message = Message.read(stream, length)
        if message.channel_id != channel_id:
            raise IndexMismatch(f"message index and message disagree on the channel ({place})")
        found.append((message.log_time, index.chunk_start_offset, place, channel_id, message.data))
    found.sort()
    yield from found


def _chunk_data(fh: BinaryIO, size: int, index: ChunkIndex) -> bytes:
    """The chunk's records, decompressed and CRC-checked by mcap (raises on damage)."""
    if index.chunk_length > size:
        raise IndexMismatch(f"chunk at byte {index.chunk_start_offset} is longer than the file")
    fh.seek(index.chunk_start_offset)
    stream = ReadDataStream(fh)
    if stream.read1() != Opcode.CHUNK:
        raise IndexMismatch(f"no chunk at byte {index.chunk_start_offset}")
    stream.read8()
    chunk = Chunk.read(stream)
    if chunk.uncompressed_size > MAX_CHUNK_INFLATION:
        raise IndexMismatch(f"chunk at byte {index.chunk_start_offset} claims an impossible size")
    records, length = get_chunk_data_stream(chunk, validate_crc=True)
    return records.read(length)


def _message_index(fh: BinaryIO, offset: int) -> list[tuple[int, int]]:
    fh.seek(offset)
    stream = ReadDataStream(fh)
    if stream.read1() != Opcode.MESSAGE_INDEX:
        raise IndexMismatch(f"no message index at byte {offset}")
    stream.read8()
    records: list[tuple[int, int]] = MessageIndex.read(stream).records
    return records
