"""Sequential read of a ROS 1 bag whose index is missing or cut off (formats.md 6 and 9.2).

Why this exists: ``rosbags.rosbag1.Reader`` seeks to the index at the end of the bag before it
yields anything, and has no reindex mode, so a bag from a killed ``rosbag record``
(``.bag.active``, ``index_pos`` 0) or a bag cut short (the index is gone) gives the user no
events at all. A ROS 1 bag is a sequence of records (header, data); the chunks carry the
connection and message records in recording order, which is all fuzzoff needs. This module walks
them in file order, parsing each record header with rosbags' own ``Header`` class and
decompressing with the same codecs rosbags uses; it stops at the first record that does not
read and reports where. Every length field is checked against the bytes left in the file before
anything is read, so a corrupt length cannot ask for gigabytes.
"""

from __future__ import annotations

import bz2
import os
import struct
from collections.abc import Iterator
from io import BytesIO
from pathlib import Path
from typing import BinaryIO

import lz4.frame  # type: ignore[import-untyped]
from rosbags.interfaces import (
    Connection,
    ConnectionExtRosbag1,
    MessageDefinition,
    MessageDefinitionFormat,
)
from rosbags.rosbag1.reader import (
    Header,
    ReaderError,
    RecordType,
    normalize,
    read_bytes,
    read_uint32,
)
from rosbags.typesys.msg import normalize_msgtype

MAGIC = b"#ROSBAG V2.0\n"


def bag_header_index_pos(path: Path) -> int | None:
    """The bag header's ``index_pos`` (0 = never indexed), or None if the header is unreadable."""
    try:
        with path.open("rb") as bio:
            if bio.readline() != MAGIC:
                return None
            _check_length(bio, os.fstat(bio.fileno()).st_size)
            return Header.read(bio, RecordType.BAGHEADER).get_uint64("index_pos")
    except (OSError, ReaderError, ValueError):
        return None


def _check_length(bio: BinaryIO, size: int) -> None:
    """Peek the next uint32 length and refuse one that runs past the end of the data."""
    pos = bio.tell()
    raw = bio.read(4)
    if len(raw) != 4:
        raise ReaderError("record cut off")
    (length,) = struct.unpack("<I", raw)
    bio.seek(pos)
    if pos + 4 + length > size:
        raise ReaderError(f"record length {length} runs past the end")


def _decompress(compression: str, data: bytes) -> bytes:
    if compression == "none":
        return data
    if compression == "bz2":
        return bz2.decompress(data)
    if compression == "lz4":
        out: bytes = lz4.frame.decompress(data)
        return out
    raise ReaderError(f"compression {compression!r} is not supported")


class SalvageReader:
    """Connection and message records of a bag, in file order, without its index."""

    def __init__(self, path: Path) -> None:
        self.path = path
        self._bio: BinaryIO | None = None
        self._size = 0
        self._pos = 0
        self._by_id: dict[int, Connection] = {}
        self.stopped: tuple[str, int] | None = None
        """Why and at which byte reading stopped early (None: the records ran to the end)."""

    @property
    def connections(self) -> list[Connection]:
        return list(self._by_id.values())

    def open(self) -> None:
        self._bio = bio = self.path.open("rb")
        self._size = os.fstat(bio.fileno()).st_size
        if bio.readline() != MAGIC:
            raise ReaderError("no `#ROSBAG V2.0` header")
        _check_length(bio, self._size)
        Header.read(bio, RecordType.BAGHEADER)
        self._skip_data(bio, self._size)
        self._pos = bio.tell()
        self._scan_connections()

    def _scan_connections(self) -> None:
        """Collect the connections first (cheap: chunk data is skipped unless it holds them)."""
        for _ in self._records(connections_only=True):
            pass
        self.stopped = None

    def close(self) -> None:
        if self._bio is not None:
            self._bio.close()
            self._bio = None

    def progress(self) -> float:
        return self._pos / self._size if self._size else 1.0

    def messages(self) -> Iterator[tuple[Connection, int, bytes]]:
        """(connection, time ns, raw message) for every message record that reads."""
        yield from self._records(connections_only=False)

    def _records(self, *, connections_only: bool) -> Iterator[tuple[Connection, int, bytes]]:
        bio = self._bio
        assert bio is not None
        bio.seek(self._pos)
        while bio.tell() < self._size:
            start = bio.tell()
            try:
                _check_length(bio, self._size)
                header = Header.read(bio)
                op = header.get_uint8("op")
                if op == RecordType.CHUNK:
                    data, complete = self._chunk_data(bio)
                    chunk = _decompress(header.get_string("compression"), data)
                    yield from self._chunk_records(chunk, connections_only)
                    if not complete:
                        raise ReaderError("chunk cut off")
                elif op == RecordType.CONNECTION:
                    self._connection(header, bio, self._size)
                else:
                    self._skip_data(bio, self._size)
            except (ReaderError, ValueError, OSError, RuntimeError, EOFError) as exc:
                self.stopped = (str(exc) or type(exc).__name__, start)
                return
            finally:
                if not connections_only:
                    self._pos = bio.tell()

    def _chunk_data(self, bio: BinaryIO) -> tuple[bytes, bool]:
        """The chunk's data; a chunk cut by the end of the file gives what is there."""
        length = read_uint32(bio)
        available = self._size - bio.tell()
        data = bio.read(min(length, available))
        return data, length <= available

    def _chunk_records(
        self, chunk: bytes, connections_only: bool
    ) -> Iterator[tuple[Connection, int, bytes]]:
        bio = BytesIO(chunk)
        size = len(chunk)
        while bio.tell() < size:
            try:
                _check_length(bio, size)
                header = Header.read(bio)
                op = header.get_uint8("op")
                if op == RecordType.CONNECTION:
                    self._connection(header, bio, size)
                    continue
                if op != RecordType.MSGDATA or connections_only:
                    self._skip_data(bio, size)
                    continue
                _check_length(bio, size)
                data = read_bytes(bio, read_uint32(bio))
                conn = self._by_id.get(header.get_uint32("conn"))
            except ReaderError:
                return  # the rest of a cut chunk
            if conn is not None:
                yield conn, header.get_time("time"), data

    def _connection(self, header: Header, bio: BinaryIO, size: int) -> None:
        conn_id = header.get_uint32("conn")
        topic = normalize(header.get_string("topic"))
        _check_length(bio, size)
        body = Header.read(bio)
        latching = body.get_string("latching") if "latching" in body else ""
        self._by_id[conn_id] = Connection(
            conn_id,
            topic,
            normalize_msgtype(body.get_string("type")),
            MessageDefinition(MessageDefinitionFormat.MSG, body.get_string("message_definition")),
            body.get_string("md5sum"),
            0,
            ConnectionExtRosbag1(
                body.get_string("callerid") if "callerid" in body else None,
                int(latching) if latching.isdigit() else None,
            ),
            None,
        )

    @staticmethod
    def _skip_data(bio: BinaryIO, size: int) -> None:
        _check_length(bio, size)
        bio.seek(read_uint32(bio), os.SEEK_CUR)
