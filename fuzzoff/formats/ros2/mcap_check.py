"""What an MCAP file gets wrong where its readers do not look (formats.md 4.1, issue 19).

rosbags reads an MCAP through its summary (the footer's summary offset, the chunk indexes, the
statistics) and never reads the chunks' own headers, the message indexes or the record lengths
between them. A chunk index whose times lie made it skip that chunk, and a record length no
writer produces went unseen. Two checks, with mcap's own record classes, reading no chunk's
data (one seek per chunk and per top-level record header):

* ``summary_damage``: the footer's offsets, the summary CRC (where the writer set one), the
  summary's records, and every chunk index against its chunk's header. When it finds damage,
  the summary cannot be trusted and the file is read front to back instead (``McapStream``);
* ``framing_damage``: the data section's top-level records, by their opcode and length, must
  lead from the header to the DataEnd record. Damage there is read around through the summary.
"""

from __future__ import annotations

import io
import zlib
from pathlib import Path
from typing import BinaryIO

from mcap.data_stream import ReadDataStream
from mcap.opcode import Opcode
from mcap.records import Channel, ChunkIndex, Footer
from mcap.stream_reader import StreamReader

from fuzzoff.lean_dataclass import dataclass

MAGIC = b"\x89MCAP0\r\n"
FOOTER_RECORD = 1 + 8 + 20
"""Opcode, length and the three footer fields."""
CHUNK_HEADER = 8 + 8 + 8 + 4 + 4 + 8
"""The fixed part of a chunk record: times, sizes, CRC, the compression's length, data length."""
KNOWN_OPCODES = frozenset(int(op) for op in Opcode)


@dataclass(frozen=True, slots=True)
class Damage:
    what: str
    offset: int
    kind: str = "summary"
    """``summary``; or, in the data section, ``type`` (a record of a type that has no place
    there: whatever it held is not read front to back) or ``length`` (a length or an end that
    the streaming reader also stops at)."""

    def line(self) -> str:
        return f"{self.what} at byte {self.offset}"


def summary_damage(path: Path) -> Damage | None:
    """What the summary section or the footer gets wrong, or None (also when the file has no
    summary, or no footer at its end: rosbags refuses such a file and the stream reader says
    why)."""
    size = path.stat().st_size
    with path.open("rb") as fh:
        found = _footer(fh, size)
        if found is None:
            return None
        footer, footer_at = found
        if footer.summary_start == 0:
            return None
        if not len(MAGIC) < footer.summary_start <= footer_at:
            what = f"the footer's summary offset ({footer.summary_start}) is past the end"
            return Damage(what, footer_at)
        if footer.summary_offset_start and not (
            footer.summary_start <= footer.summary_offset_start <= footer_at
        ):
            offset = footer.summary_offset_start
            what = f"the footer's offset of the summary offsets ({offset}) is past the end"
            return Damage(what, footer_at)
        if footer.summary_crc:
            fh.seek(footer.summary_start)
            covered = fh.read(footer_at + 1 + 8 + 8 + 8 - footer.summary_start)
            if zlib.crc32(covered) != footer.summary_crc:
                return Damage(
                    "summary CRC mismatch (its records were altered)", footer.summary_start
                )
        fh.seek(footer.summary_start)
        indexes: list[ChunkIndex] = []
        channels: set[int] = set()
        try:
            for record in StreamReader(fh, skip_magic=True, record_size_limit=size).records:
                if isinstance(record, ChunkIndex):
                    indexes.append(record)
                elif isinstance(record, Channel):
                    channels.add(record.id)
        except Exception as exc:  # mcap's errors, struct and decode errors on damaged records
            what = f"summary section unreadable ({type(exc).__name__})"
            return Damage(what, footer.summary_start)
        named = {c for index in indexes for c in index.message_index_offsets}
        if channels and not named <= channels:  # rosbags would not read an undefined channel
            lacking = min(named - channels)
            what = f"the summary lacks the channel {lacking} its chunk indexes name"
            return Damage(what, footer.summary_start)
        for index in indexes:
            wrong = _index_disagrees(fh, index, footer.summary_start)
            if wrong is not None:
                what = (
                    f"the summary's index of the chunk at byte {index.chunk_start_offset} {wrong}"
                )
                return Damage(what, footer.summary_start)
    return None


def _index_disagrees(fh: BinaryIO, index: ChunkIndex, data_end: int) -> str | None:
    """How a chunk index differs from the chunk's own header, or None."""
    if not len(MAGIC) <= index.chunk_start_offset < data_end:
        return "points outside the data section"
    if index.chunk_start_offset + index.chunk_length + index.message_index_length > data_end:
        return "runs past the data section"
    fh.seek(index.chunk_start_offset)
    head = fh.read(9 + CHUNK_HEADER + len(index.compression.encode()))
    if len(head) < 9 + CHUNK_HEADER:
        return "points past the end"
    stream = ReadDataStream(io.BytesIO(head))
    stream.read1()  # the record's type and length: ``framing_damage`` judges them (a chunk
    stream.read8()  # whose type byte was hit is still there, where its index says)
    if (stream.read8(), stream.read8()) != (index.message_start_time, index.message_end_time):
        return "disagrees with it on its message times"
    if stream.read8() != index.uncompressed_size:
        return "disagrees with it on its size"
    stream.read4()  # the CRC: checked when the chunk is read
    try:
        compression = stream.read_prefixed_string()
    except (UnicodeDecodeError, ValueError):
        compression = None
    if compression != index.compression:
        return "disagrees with it on its compression"
    if stream.read8() != index.compressed_size:
        return "disagrees with it on its compressed size"
    if index.chunk_length != stream.count + index.compressed_size:
        return "disagrees with it on its length"
    return _message_indexes_disagree(fh, index)


def _message_indexes_disagree(fh: BinaryIO, index: ChunkIndex) -> str | None:
    """Each channel's offset must lead to that channel's MessageIndex record after the chunk:
    rosbags counts a chunk's messages per channel from these offsets, and skips the chunk for
    a channel it finds none of."""
    first = index.chunk_start_offset + index.chunk_length
    last = first + index.message_index_length
    for channel_id, offset in index.message_index_offsets.items():
        if not first <= offset < last:
            return "points to message indexes outside its own"
        fh.seek(offset)
        head = fh.read(9 + 2)
        if len(head) < 11:
            return "points to message indexes past the end"
        stream = ReadDataStream(io.BytesIO(head))
        if stream.read1() != Opcode.MESSAGE_INDEX:
            return "points to no message index"
        stream.read8()
        if stream.read2() != channel_id:
            return "disagrees with its message indexes on their channels"
    return None


def framing_damage(path: Path) -> Damage | None:
    """The first top-level record of the data section whose header no writer produces (an
    impossible type or length), or a data section that does not end in its DataEnd record;
    None for a file without a footer (rosbags refuses it; the stream reader says why)."""
    with path.open("rb") as fh:
        found = _footer(fh, path.stat().st_size)
        if found is None:
            return None
        footer, footer_at = found
        end = footer.summary_start if len(MAGIC) < footer.summary_start <= footer_at else footer_at
        at = len(MAGIC)
        fh.seek(at)
        while at + 9 <= end:
            header = fh.read(9)
            stream = ReadDataStream(io.BytesIO(header))
            opcode, length = stream.read1(), stream.read8()
            if _misplaced(opcode):
                return Damage(f"a record of type {opcode:#04x} in the data section", at, "type")
            if length > end - at - 9:
                what = f"a record claims {length} bytes, more than the file holds"
                return Damage(what, at, "length")
            if opcode == Opcode.CHUNK and length < CHUNK_HEADER:
                what = f"a chunk record of {length} bytes, too short for a chunk"
                return Damage(what, at, "length")
            if opcode == Opcode.DATA_END:
                if at + 9 + length == end:
                    return None
                return Damage("the data section ends early", at, "length")
            at += 9 + length
            fh.seek(at)
        return Damage("the data section has no DataEnd record", at, "length")


def _footer(fh: BinaryIO, size: int) -> tuple[Footer, int] | None:
    """The file's footer record and where it starts, or None when the file does not end in
    one (then rosbags refuses the file and the stream reader says why)."""
    footer_at = size - len(MAGIC) - FOOTER_RECORD
    fh.seek(max(footer_at, 0))
    tail = fh.read()
    if footer_at < len(MAGIC) or not tail.endswith(MAGIC) or tail[0] != Opcode.FOOTER:
        return None
    return Footer.read(ReadDataStream(io.BytesIO(tail[9:]))), footer_at


def _misplaced(opcode: int) -> bool:
    """A record type that has no place in the data section: 0, a summary record, or one of the
    types MCAP reserves for itself and does not define (private records use 0x80 and up)."""
    if opcode in KNOWN_OPCODES:
        return opcode not in _DATA_SECTION
    return opcode < 0x80


_DATA_SECTION = frozenset(
    {
        Opcode.HEADER,
        Opcode.SCHEMA,
        Opcode.CHANNEL,
        Opcode.MESSAGE,
        Opcode.CHUNK,
        Opcode.MESSAGE_INDEX,
        Opcode.ATTACHMENT,
        Opcode.METADATA,
        Opcode.DATA_END,
    }
)
"""The records the MCAP spec allows in the data section (private ones, 0x80 and up, too)."""
