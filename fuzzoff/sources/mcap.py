"""MCAP recordings of PX4 ROS 2 topics (formats.md 4): streamed, CRC-checked, PX4 topics only.

The summary (when the footer is intact) gives channels, schemas and the start time cheaply; the
messages are then streamed front to back with ``mcap``'s ``StreamReader`` (no time-order buffering
of the whole file, formats.md 4.2), one chunk at a time, every chunk's CRC checked. Only the
channels of PX4 topics are decoded (rosbags' CDR deserialiser, the faster of the two, 4.5). A bad
chunk is skipped and reported; a cut file keeps everything before the cut.
"""

from __future__ import annotations

import io
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

from mcap.exceptions import McapError
from mcap.reader import SeekingReader
from mcap.records import Channel, Chunk, DataEnd, Footer, Message, Schema
from mcap.stream_reader import CRCValidationError, StreamReader, breakup_chunk

from fuzzoff.events import Event
from fuzzoff.sources import px4_msgs
from fuzzoff.sources.base import RecordingInfo, Source, SourceError, SourceProblem
from fuzzoff.sources.ros2_decode import Decoder, Ros2Decoding, TopicDecoder
from fuzzoff.sources.ros2_order import ChunkOrder

Connect = Callable[[str, str, str | None, str], Decoder | None]
"""(topic, message type, embedded definition, its format) -> decoder or None."""

MAGIC = b"\x89MCAP0\r\n"
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
    ) -> None:
        self.path = path
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

    def records(self) -> Iterator[Any]:
        """Top-level records, chunks broken up (CRC checked); problems recorded, never raised."""
        self.size = self.path.stat().st_size
        with self.path.open("rb") as fh:
            self.fh = fh
            reader = StreamReader(
                fh, emit_chunks=True, validate_crcs=True, record_size_limit=max(self.size, 1)
            )
            good = 0
            try:
                for record in reader.records:
                    if type(record) is Chunk:
                        yield from self._chunk(record, fh.tell())
                    else:
                        if type(record) is Footer:
                            self.footer = True
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
            finally:
                self.fh = None

    def _cut(self, offset: int, why: str) -> None:
        self.problems.append(
            SourceProblem(
                f"{why}: nothing after the last whole record could be read (truncated or "
                "corrupt; no valid footer)",
                f"byte {offset} of {self.size}",
            )
        )

    def _chunk(self, chunk: Chunk, end: int) -> Iterator[Any]:
        if chunk.uncompressed_size > MAX_CHUNK_INFLATION:
            self.problems.append(
                SourceProblem(
                    "chunk header claims an impossible size; chunk skipped", f"byte {end}"
                )
            )
            return
        try:
            records = breakup_chunk(chunk, validate_crc=True)
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
        messages = 0
        for record in self.records():
            if type(record) is Message:
                messages += 1
                if t0 is None:
                    t0 = self.t0_ns = record.log_time
                decoder = decoders.get(record.channel_id)
                if decoder is None:
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


class McapSource(Source):
    """A ``.mcap`` file (ROS 2, CDR). ``px4_hint`` steers bundled definitions (``--px4``)."""

    format = "mcap"

    def __init__(self, path: Path) -> None:
        super().__init__(path)
        self.px4_hint: str | None = None
        self.decoding = Ros2Decoding()
        self._stream: McapStream | None = None
        self._info: RecordingInfo | None = None
        self._t0: int | None = None

    def open(self) -> None:
        try:
            with self.path.open("rb") as fh:
                head = fh.read(len(MAGIC))
        except OSError as exc:
            raise SourceError(self.path, f"cannot open: {exc.strerror or exc}") from None
        if head != MAGIC:
            raise SourceError(self.path, "not an MCAP file (bad magic bytes)", "byte 0")
        self.decoding.release = px4_msgs.release_for(self.px4_hint)

    def probe(self) -> RecordingInfo:
        if self._info is not None:
            return self._info
        info = RecordingInfo(str(self.path), self.format)
        stream = self._stream = McapStream(self.path, self.decoding, None)
        summary = self._summary()
        if summary is not None:
            stream.schemas.update(summary.schemas)
            for channel in summary.channels.values():
                stream.channel(channel)
            if summary.statistics is not None:
                info.message_count = summary.statistics.message_count
                if summary.statistics.message_count:
                    stream.t0_ns = summary.statistics.message_start_time
            info.vehicle_type = self._vehicle_type(stream)
        else:
            info.notes.append("no MCAP summary (footer missing or damaged): scanned for channels")
            info.vehicle_type = self._scan(stream)
        self._fill(info)
        self._info = info
        return info

    def _summary(self) -> Any:
        try:
            with self.path.open("rb") as fh:
                return SeekingReader(fh, validate_crcs=True).get_summary()
        except Exception:
            return None

    def _vehicle_type(self, stream: McapStream) -> str | None:
        """The vehicle type from the first ``VehicleStatus`` (read through the chunk index)."""
        topics = {
            d.topic: d
            for d in stream.decoders.values()
            if isinstance(d, TopicDecoder) and d.message == "VehicleStatus" and d.builder
        }
        if not topics:
            return None
        try:
            with self.path.open("rb") as fh:
                reader = SeekingReader(fh, validate_crcs=True)
                for _, channel, message in reader.iter_messages(
                    topics=sorted(topics), log_time_order=False
                ):
                    return self.decoding.vehicle_from(topics[channel.topic], message.data)
        except Exception:
            return None
        return None

    def _scan(self, stream: McapStream) -> str | None:
        """Channels, the earliest log time and the vehicle type without a summary (a full
        pass; only for files whose footer is gone)."""
        scan = McapStream(self.path, Ros2Decoding(), None)
        start: int | None = None
        vehicle: str | None = None
        for record in scan.records():
            if type(record) is Message:
                start = record.log_time if start is None else min(start, record.log_time)
                if vehicle is None:
                    vehicle = self._status_vehicle(stream.decoders.get(record.channel_id), record)
            elif type(record) is Schema:
                stream.schemas[record.id] = record
            elif type(record) is Channel:
                stream.channel(record)
        stream.t0_ns = start
        return vehicle

    def _status_vehicle(self, decoder: Decoder | None, record: Message) -> str | None:
        return self.decoding.vehicle_from(decoder, record.data)

    def _fill(self, info: RecordingInfo) -> None:
        info.kinds = self.decoding.kinds()
        info.vehicles = self.decoding.vehicles()
        info.px4_version = self.decoding.detected_release()

    def events(self) -> Iterator[Event]:
        self.probe()
        stream = self._stream
        assert stream is not None
        yield from stream.events()
        self._finish(stream)

    def _finish(self, stream: McapStream) -> None:
        self.problems.extend(stream.problems)
        self.problems.extend(self.decoding.problems())
        self.stats["messages"] = stream.messages
        if stream.late:
            self.stats["late_messages"] = stream.late
        if self._info is not None:
            self._info.notes.extend(self.decoding.notes)
            self._info.kinds |= self.decoding.kinds()
            if not self._info.px4_version:
                self._info.px4_version = self.decoding.detected_release()

    def progress(self) -> float | None:
        return self._stream.progress() if self._stream is not None else None
