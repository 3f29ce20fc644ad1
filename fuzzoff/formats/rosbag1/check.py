"""What a ROS 1 bag gets wrong where rosbags does not look (formats.md 6, issue 19).

rosbags reads a bag through its index: the bag header's ``index_pos``, the connection and
chunk-info records there, then each chunk at the position its chunk info gives. The bag
header's own data length, the lengths of the records between the chunks and anything after the
index are never read, so a damaged one went unseen; and a chunk info whose message counts were
damaged made it skip that chunk. ``walk`` steps over the bag's top-level records by their
lengths, parsing each record header with rosbags' ``Header`` and reading no chunk's data (one
header per chunk and per index record), and keeps the message counts each chunk's own index
records give, for the chunk infos to be checked against (``chunk_infos_disagree``).
"""

from __future__ import annotations

import os
from collections import Counter
from dataclasses import field
from pathlib import Path
from typing import Any, BinaryIO

from rosbags.rosbag1.reader import Header, ReaderError, RecordType, read_uint32

from fuzzoff.lean_dataclass import dataclass

MAGIC = b"#ROSBAG V2.0\n"
BEFORE_INDEX = frozenset({RecordType.CHUNK, RecordType.IDXDATA, RecordType.CONNECTION})
IN_INDEX = frozenset({RecordType.CONNECTION, RecordType.CHUNK_INFO})


@dataclass(slots=True)
class Walk:
    damage: tuple[str, int] | None = None
    """What is wrong with the first damaged record's framing, and at which byte."""
    in_index: bool = False
    """The damage is in the index: then the index cannot say where the messages are."""
    counts: dict[int, Counter[int]] = field(default_factory=dict)
    """Chunk position -> connection id -> messages, from the chunk's own index records."""


def walk(path: Path) -> Walk:
    """The bag's framing, read without its data (an empty walk for what is not a bag)."""
    found = Walk()
    with path.open("rb") as bio:
        size = os.fstat(bio.fileno()).st_size
        if bio.readline() != MAGIC:
            return found  # not a bag: the reader says so
        try:
            header = Header.read(bio, RecordType.BAGHEADER)
            index_pos = header.get_uint64("index_pos")
            records = header.get_uint32("conn_count") + header.get_uint32("chunk_count")
        except (ReaderError, ValueError, KeyError):
            return found  # the reader refuses the bag and says why
        at = bio.tell()
        length = _length(bio, size)
        if length is None:
            found.damage = f"the bag header's data length runs past the end (byte {size})", at
            return found
        bio.seek(length, os.SEEK_CUR)
        if bio.tell() > index_pos:
            found.damage = "the bag header's data length runs into the index", at
            return found
        chunk = -1
        while bio.tell() < index_pos:
            at = bio.tell()
            head = _record(bio, index_pos, BEFORE_INDEX, found)
            if head is None:
                return found
            op = head.get_uint8("op")
            if op == RecordType.CHUNK:
                chunk = at
                found.counts[chunk] = Counter()
            elif op == RecordType.IDXDATA and chunk >= 0:
                found.counts[chunk][head.get_uint32("conn")] += head.get_uint32("count")
        for _ in range(records):
            if _record(bio, size, IN_INDEX, found) is None:
                found.in_index = True
                return found
        if bio.tell() < size:
            at = bio.tell()
            if _record(bio, size, IN_INDEX, Walk()) is not None:
                # an index record the header's counts leave out: rosbags stops before it,
                # and the messages of the chunk it names are lost (a flipped chunk_count)
                found.damage = "the bag header counts fewer index records than the index holds", at
                found.in_index = True
                return found
            what = f"{size - at} bytes after the bag's index, not part of the bag"
            found.damage = what, at
    return found


def chunk_infos_disagree(found: Walk, chunk_infos: list[Any]) -> str | None:
    """How the index's chunk infos (rosbags' ``ChunkInfo``: ``pos``, ``connection_counts``)
    differ from the chunks' own index records, or None."""
    if found.damage is not None:
        return None  # the walk stopped early: its counts are not whole
    for info in chunk_infos:
        counts = found.counts.get(info.pos)
        if counts is None:
            return f"the index names a chunk at byte {info.pos}, where none starts"
        if dict(counts) != dict(info.connection_counts):
            return f"the index disagrees with the chunk at byte {info.pos} on its messages"
    return None


def _length(bio: BinaryIO, end: int) -> int | None:
    """The next uint32 length, if what it claims fits before ``end``."""
    raw = bio.read(4)
    if len(raw) < 4:
        return None
    bio.seek(-4, os.SEEK_CUR)
    length = read_uint32(bio)
    return length if bio.tell() + length <= end else None


def _record(bio: BinaryIO, end: int, allowed: frozenset[int], found: Walk) -> Header | None:
    """Step over one record (header and data) that must end by ``end``; its header, or None
    and the damage noted in ``found``."""
    at = bio.tell()
    if _length(bio, end) is None:
        found.damage = "a record header whose length runs past where it must end", at
        return None
    bio.seek(-4, os.SEEK_CUR)
    try:
        head = Header.read(bio)
        op = head.get_uint8("op")
    except (ReaderError, ValueError, KeyError):
        found.damage = "an unreadable record header", at
        return None
    if op not in allowed:
        found.damage = f"a record of type {op:#04x} where none belongs", at
        return None
    length = _length(bio, end)
    if length is None:
        found.damage = "a record whose data length runs past where it must end", at
        return None
    bio.seek(length, os.SEEK_CUR)
    return head
