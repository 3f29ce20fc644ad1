"""Streaming MCAP reading for damaged files (formats.md 4.2, 4.4): front to back, CRC-checked.

``mcap``'s ``StreamReader`` reads the records in file order, with no time-order buffering of the
whole file; chunks are broken up one at a time, each chunk's CRC checked. Only the channels of
topics fuzzoff decodes are decoded (rosbags' CDR deserialiser, the faster of the two, 4.5). A bad
chunk is skipped and reported; a cut file keeps everything before the cut. ``ChunkOrder`` puts
the events in time order within a bounded window.
"""

from __future__ import annotations

import io
from collections.abc import Callable, Iterator
from dataclasses import replace
from pathlib import Path
from typing import Any

from mcap.exceptions import McapError
from mcap.reader import SeekingReader
from mcap.records import Channel, Chunk, DataEnd, Footer, Message, Schema
from mcap.stream_reader import (
    CRCValidationError,
    StreamReader,
    breakup_chunk,
    get_chunk_data_stream,
)

from fuzzoff.events import Event
from fuzzoff.formats.ros2.order import ChunkOrder
from fuzzoff.formats.ros2msgs.decode import Decoder, Ros2Decoding
from fuzzoff.recording import SourceProblem

Connect = Callable[[str, str, str | None, str], Decoder | None]
"""(topic, message type, embedded definition, its format) -> decoder or None."""

MAGIC = b"\x89MCAP0\r\n"
CHUNK_FIELDS = 8 + 8 + 8 + 4 + 4 + 8
"""A chunk record's fixed fields: times, size, CRC, the compression's and the data's lengths."""
MAX_CHUNK_INFLATION = 1 << 30
"""A chunk claiming to inflate to more than this is treated as corrupt (bounded memory)."""

SCHEMA_FORMATS = {"ros2msg": "msg", "ros2idl": "idl"}


class McapStream:
    """One pass over an MCAP file's records, decoding the PX4 channels into time-ordered events.

    Shared by ``McapSource`` and the rosbag2 reader's salvage path. ``decoding`` holds the
    per-connection definitions; ``problems`` collects what could not be read.
    """

    def __init__(
        self,
        path: Path,
        decoding: Ros2Decoding,
        t0_ns: int | None,
        connect: Connect | None = None,
        after_ns: int = -1,
    ) -> None:
        self.path = path
        self.after_ns = after_ns
        self.decoding = decoding
        self.connect: Connect = connect or decoding.connection
        self.t0_ns = t0_ns
        self.problems: list[SourceProblem] = []
        self.schemas: dict[int, Schema] = {}
        self.decoders: dict[int, Decoder | None] = {}
        self.messages = 0
        self.late = 0
        self.fh: io.BufferedReader | None = None
        self.size = 0
        self.footer = False
        self.data_end = False
        """The DataEnd record was read: every chunk came before it (damage after it costs no
        message)."""
        self.summary_said = False
        """The caller already said what is wrong with the summary section."""
        self.orphans = 0
        """Messages on a channel no Channel record defined (it sat in a skipped chunk)."""
        self._orphan_at: str | None = None

    def channel(self, record: Channel) -> None:
        if record.id in self.decoders:
            return
        schema = self.schemas.get(record.schema_id)
        text, fmt = None, "msg"
        if schema is not None and schema.encoding in SCHEMA_FORMATS:
            text = schema.data.decode("utf-8", errors="replace")
            fmt = SCHEMA_FORMATS[schema.encoding]
        msgtype = schema.name if schema is not None else ""
        self.decoders[record.id] = self.connect(record.topic, msgtype, text, fmt)

    def use_summary(self) -> None:
        """Schemas and channels from the summary section (where it can be read): a channel
        whose only Channel record sits in a chunk that proves damaged still decodes in the
        chunks after it."""
        try:
            with self.path.open("rb") as fh:
                size = self.path.stat().st_size
                summary = SeekingReader(fh, record_size_limit=max(size, 1)).get_summary()
        except Exception:  # no usable summary: channels come from the chunks
            return
        if summary is None:
            return
        self.schemas.update(summary.schemas)
        for record in summary.channels.values():
            self.channel(record)

    def records(self) -> Iterator[Any]:
        """Top-level records, chunks broken up (CRC checked); problems recorded, never raised."""
        self.size = self.path.stat().st_size
        if not self.size:
            self.problems.append(SourceProblem("empty file (0 bytes)"))
            return
        with self.path.open("rb") as fh:
            self.fh = fh
            reader = StreamReader(
                fh, emit_chunks=True, validate_crcs=True, record_size_limit=max(self.size, 1)
            )
            good = 0
            try:
                for record in reader.records:
                    if type(record) is Chunk:
                        yield from self._chunk(record, good, fh.tell())
                    else:
                        if type(record) is Footer:
                            self.footer = True
                        elif type(record) is DataEnd:
                            self.data_end = True
                        yield record
                    good = fh.tell()
            except CRCValidationError as exc:
                if isinstance(exc.record, DataEnd):
                    self.problems.append(
                        SourceProblem(
                            "data section CRC mismatch (file altered)", f"byte {fh.tell()}"
                        )
                    )
                else:
                    self._cut(good, "corrupt record")
            except Exception as exc:
                self._cut(good, _reason(exc))
            else:
                end = fh.tell()  # after the closing magic bytes
                if end < self.size:
                    what = (
                        f"{self.size - end} bytes after the end of the MCAP file, not read "
                        "(every record before them was)"
                    )
                    self.problems.append(SourceProblem(what, f"byte {end}", lost=False))
            finally:
                self.fh = None

    def _cut(self, offset: int, why: str) -> None:
        if self.data_end:  # every chunk was read: the summary after them cannot be
            if not self.summary_said:
                what = f"summary section unreadable ({why}); every chunk before it was read"
                self.problems.append(SourceProblem(what, f"byte {offset}", lost=False))
            return
        self.problems.append(
            SourceProblem(
                f"{why}: nothing after the last whole record could be read (truncated or "
                "corrupt; no valid footer)",
                f"byte {offset} of {self.size}",
            )
        )

    def _chunk(self, chunk: Chunk, start: int, end: int) -> Iterator[Any]:
        """The records of the chunk record at [start, end), or none and a problem."""
        fields = CHUNK_FIELDS + len(chunk.compression.encode()) + len(chunk.data)
        if end - start - 9 != fields:
            # A header damaged where no CRC covers it: its data length and sizes read short
            # (zeroed), the record's own length stepped over the rest, and the chunk would
            # give no message and no error.
            what = f"chunk header damaged (its fields fill {fields} of its {end - start - 9} bytes)"
            self.problems.append(
                SourceProblem(f"{what}; its messages were skipped", f"byte {start}")
            )
            return
        if chunk.uncompressed_size > MAX_CHUNK_INFLATION:
            self.problems.append(
                SourceProblem(
                    "chunk header claims an impossible size; chunk skipped", f"byte {end}"
                )
            )
            return
        try:
            data, length = get_chunk_data_stream(chunk, validate_crc=True)
            if length != chunk.uncompressed_size:
                # Its header was damaged where no CRC covers it (or the CRC itself): parsed,
                # the bytes would give no message and no error.
                what = (
                    f"chunk header damaged (it says {chunk.uncompressed_size} bytes of "
                    f"records, its data holds {length}); its messages were skipped"
                )
                self.problems.append(SourceProblem(what, f"chunk ending at byte {end}"))
                return
            whole = replace(chunk, compression="", data=data.read(length), uncompressed_crc=0)
            records = breakup_chunk(whole)
        except CRCValidationError:
            self.problems.append(
                SourceProblem(
                    "chunk CRC mismatch (corrupt bytes); its messages were skipped",
                    f"chunk ending at byte {end}",
                )
            )
            return
        except (McapError, ValueError, EOFError, Exception) as exc:
            self.problems.append(
                SourceProblem(f"chunk cannot be read ({_reason(exc)}); skipped", f"byte {end}")
            )
            return
        yield ChunkOrder.Boundary(chunk.message_start_time)
        yield from records

    def events(self) -> Iterator[Event]:
        """Decoded PX4 events in recording-time order (per chunk; see ``ChunkOrder``)."""
        order = ChunkOrder()
        decoders = self.decoders
        t0 = self.t0_ns
        after = self.after_ns
        messages = 0
        for record in self.records():
            if type(record) is Message:
                messages += 1
                if t0 is None:
                    t0 = self.t0_ns = record.log_time
                decoder = decoders.get(record.channel_id)
                if decoder is None or record.log_time <= after:
                    if record.channel_id not in decoders:
                        self._orphan(record)
                    continue
                event = decoder.event(record.data, (record.log_time - t0) / 1e9)
                if event is not None:
                    yield from order.add(record.log_time, event)
            elif type(record) is ChunkOrder.Boundary:
                yield from order.boundary(record.start_ns)
            elif type(record) is Schema:
                self.schemas[record.id] = record
            elif type(record) is Channel:
                self.channel(record)
        yield from order.flush()
        self.messages = messages
        self.late = order.late
        if self.orphans:
            what = (
                f"{self.orphans} messages on channels that no readable record defines (their "
                "Channel record was in a skipped chunk, or is missing) were not read"
            )
            self.problems.append(SourceProblem(what, self._orphan_at))

    def _orphan(self, record: Message) -> None:
        if not self.orphans and self.fh is not None:
            self._orphan_at = f"in the chunk ending at byte {self.fh.tell()}"
        self.orphans += 1

    def scan(self) -> tuple[int | None, str | None]:
        """Channels, the earliest log time and the vehicle type, for a file without a usable
        summary (a full pass; only on the salvage path). Problems are left to ``events``."""
        start: int | None = None
        vehicle: str | None = None
        for record in self.records():
            if type(record) is Message:
                start = record.log_time if start is None else min(start, record.log_time)
                if vehicle is None:
                    decoder = self.decoders.get(record.channel_id)
                    vehicle = self.decoding.vehicle_from(decoder, record.data)
            elif type(record) is Schema:
                self.schemas[record.id] = record
            elif type(record) is Channel:
                self.channel(record)
        self.problems.clear()
        self.t0_ns = start
        return start, vehicle

    def progress(self) -> float | None:
        fh = self.fh
        if fh is None or not self.size:
            return None
        try:
            return min(1.0, fh.tell() / self.size)
        except (OSError, ValueError):
            return None


def _reason(exc: BaseException) -> str:
    name = type(exc).__name__
    if name in ("EndOfFile", "error"):
        return "file ends inside a record"
    if name == "InvalidMagic":
        return "bad magic bytes"
    if name == "RecordLengthLimitExceeded":
        return "record length larger than the file"
    return f"{name}: {exc}" if str(exc) else name
