"""rosbags' ROS 1 reader, holding one chunk's index at a time (formats.md section 9).

Why: ``rosbags.rosbag1.Reader.open`` reads the index entry of every message in the bag into
memory before it yields anything (about 150 bytes per message: 150 MB for a million), so memory
grows with the bag. The bag keeps each chunk's index records right after the chunk, so this
subclass reads only the bag's connection and chunk-info records on ``open`` and, while
iterating, one chunk's index at a time. Chunks holding none of the wanted connections are not
read at all, and the index records of unwanted connections are skipped. The record parsing
and message extraction are rosbags' own (``Header``, ``read_connection``, ``read_chunk_info``,
``read_chunk``, ``read_index_data``, ``messages``).

Order: chunks by start time, messages within a chunk by time. Bags written by ``rosbag record``
are in receive order, so this is the same order rosbags gives; chunks whose times overlap
(bags re-written by tools) may interleave differently.
"""

from __future__ import annotations

import os
from collections import Counter, defaultdict
from collections.abc import Collection, Generator

from rosbags.interfaces import Connection
from rosbags.rosbag1 import Reader, ReaderError
from rosbags.rosbag1.reader import Header, IndexData, RecordType, read_uint32

MAGIC = b"#ROSBAG V2.0\n"


class ChunkwiseReader(Reader):
    """A ``rosbags.rosbag1.Reader`` whose memory does not grow with the number of messages."""

    def open(self) -> None:
        self.bio = bio = self.path.open("rb")
        try:
            self._size = os.fstat(bio.fileno()).st_size
            magic = bio.readline()
            if not magic:
                raise ReaderError(f"File {str(self.path)!r} seems to be empty.")
            if magic != MAGIC:
                raise ReaderError("File magic is invalid.")
            header = Header.read(bio, RecordType.BAGHEADER)
            index_pos = header.get_uint64("index_pos")
            conn_count = header.get_uint32("conn_count")
            chunk_count = header.get_uint32("chunk_count")
            if "encryptor" in header and header.get_string("encryptor"):
                raise ReaderError("Bag encryption is not supported.")
            if index_pos == 0:
                raise ReaderError("Bag is not indexed, reindex before reading.")
            if chunk_count == 0:
                return
            bio.seek(index_pos)
            try:
                connections = [self.read_connection() for _ in range(conn_count)]
                self.chunk_infos = [self.read_chunk_info() for _ in range(chunk_count)]
            except ReaderError as err:
                raise ReaderError(f"Bag index looks damaged: {err.args}") from None
            counts: Counter[int] = Counter()
            for info in self.chunk_infos:
                counts.update(info.connection_counts)
            self.connections = [c._replace(msgcount=counts[c.id]) for c in connections]
        except BaseException:
            self.close()
            raise

    def messages(
        self,
        connections: Collection[Connection] = (),
        start: int | None = None,
        stop: int | None = None,
    ) -> Generator[tuple[Connection, int, bytes], None, None]:
        """(connection, time ns, raw message) of the wanted connections, one chunk at a time."""
        self._check_open()
        assert self.bio is not None
        wanted = list(connections) or self.connections
        ids = {c.id for c in wanted}
        for info in sorted(self.chunk_infos, key=lambda c: (c.start_time, c.pos)):
            if ids.isdisjoint(info.connection_counts):
                continue
            if stop is not None and info.start_time >= stop:
                return
            self.bio.seek(info.pos)
            chunk = self.read_chunk()  # leaves the file at the chunk's index records
            if chunk.datapos + chunk.datasize > self._size:
                raise ReaderError(f"chunk at byte {info.pos} runs past the end of the file")
            local: defaultdict[int, list[IndexData]] = defaultdict(list)
            for _ in range(len(info.connection_counts)):
                self._index_data(info.pos, local, ids)
            self.chunks = {info.pos: chunk}
            self.indexes = {c.id: sorted(local.get(c.id, ())) for c in self.connections}
            yield from super().messages(wanted, start, stop)

    def _index_data(self, pos: int, local: dict[int, list[IndexData]], ids: set[int]) -> None:
        """One index record: read by rosbags if its connection is wanted, else skipped unread.

        A camera or IMU connection has an index entry per message; parsing those only to throw
        them away would cost as much as rosbags' whole-bag index.
        """
        assert self.bio is not None
        start = self.bio.tell()
        header = Header.read(self.bio, RecordType.IDXDATA)
        size = read_uint32(self.bio)
        if header.get_uint32("conn") in ids:
            self.bio.seek(start)
            self.read_index_data(pos, local)
        else:
            self.bio.seek(size, os.SEEK_CUR)
