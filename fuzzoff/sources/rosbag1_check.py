"""What a ROS 1 bag gets wrong where rosbags does not look (formats.md 6, issue 19).

rosbags reads a bag through its index: the bag header's ``index_pos``, the connection and
chunk-info records there, then each chunk at the position its chunk info gives. The bag
header's own data length, the lengths of the records between the chunks and anything after the
index are never read, so a damaged one went unseen. ``framing_damage`` walks the bag's
top-level records by their lengths, parsing each record header with rosbags' ``Header`` and
reading no chunk's data (one header per chunk and per index record).
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import BinaryIO

from rosbags.rosbag1.reader import Header, ReaderError, RecordType, read_uint32

MAGIC = b"#ROSBAG V2.0\n"
BEFORE_INDEX = frozenset({RecordType.CHUNK, RecordType.IDXDATA, RecordType.CONNECTION})
IN_INDEX = frozenset({RecordType.CONNECTION, RecordType.CHUNK_INFO})


Damage = tuple[str, int, bool]
"""What is wrong, at which byte, and whether it is in the index (then the index cannot be
trusted: its records say where the messages are)."""


def framing_damage(path: Path) -> Damage | None:
    """The first record whose framing is damaged, or None."""
    with path.open("rb") as bio:
        size = os.fstat(bio.fileno()).st_size
        if bio.readline() != MAGIC:
            return None  # not a bag: the reader says so
        try:
            header = Header.read(bio, RecordType.BAGHEADER)
            index_pos = header.get_uint64("index_pos")
            records = header.get_uint32("conn_count") + header.get_uint32("chunk_count")
        except (ReaderError, ValueError, KeyError):
            return None  # the reader refuses the bag and says why
        at = bio.tell()
        length = _length(bio, size)
        if length is None:
            return f"the bag header's data length runs past the end (byte {size})", at, False
        bio.seek(length, os.SEEK_CUR)
        if bio.tell() > index_pos:
            return "the bag header's data length runs into the index", at, False
        while bio.tell() < index_pos:
            wrong = _record(bio, index_pos, BEFORE_INDEX)
            if wrong is not None:
                return (*wrong, False)
        for _ in range(records):
            wrong = _record(bio, size, IN_INDEX)
            if wrong is not None:
                return (*wrong, True)
        if bio.tell() < size:
            what = f"{size - bio.tell()} bytes after the bag's index, not part of the bag"
            return what, bio.tell(), False
    return None


def _length(bio: BinaryIO, end: int) -> int | None:
    """The next uint32 length, if what it claims fits before ``end``."""
    raw = bio.read(4)
    if len(raw) < 4:
        return None
    bio.seek(-4, os.SEEK_CUR)
    length = read_uint32(bio)
    return length if bio.tell() + length <= end else None


def _record(bio: BinaryIO, end: int, allowed: frozenset[int]) -> tuple[str, int] | None:
    """Step over one record (header and data) that must end by ``end``."""
    at = bio.tell()
    header_length = _length(bio, end)
    if header_length is None:
        return "a record header whose length runs past where it must end", at
    bio.seek(-4, os.SEEK_CUR)
    try:
        op = Header.read(bio).get_uint8("op")
    except (ReaderError, ValueError, KeyError):
        return "an unreadable record header", at
    if op not in allowed:
        return f"a record of type {op:#04x} where none belongs", at
    length = _length(bio, end)
    if length is None:
        return "a record whose data length runs past where it must end", at
    bio.seek(length, os.SEEK_CUR)
    return None
