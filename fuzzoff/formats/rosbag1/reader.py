"""ROS 1 bags (``#ROSBAG V2.0``) with MAVROS topics, read by ``rosbags.rosbag1`` (formats.md 6).

Only the connections that matter are decoded: the MAVROS topics ``fuzzoff.formats.mavros.convert``
converts (setpoints and ``state``). Every other connection (images, IMU, ...) is filtered out
before its messages are read, using the bag's index, one chunk at a time
(``rosbag1_chunkwise``: memory does not grow with the bag). Message definitions come from the bag
itself (every ROS 1 connection record embeds them, formats.md section 3); the shipped
mavros_msgs definitions are the fallback for a connection whose embedded text does not parse.

Damaged bags: rosbags needs the index at the end of the file and has no reindex mode (formats.md
section 9 item 2), so an unindexed bag (``.bag.active`` from a killed ``rosbag record``) or a
truncated one yields nothing through it. ``rosbag1_salvage`` then reads the chunks in file
order with the library's own record primitives, the way ``rosbag reindex`` would; the events
read are kept and the file is reported incomplete, with one line saying why.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from functools import partial
from pathlib import Path
from typing import Any

from rosbags.interfaces import Connection
from rosbags.rosbag1 import ReaderError
from rosbags.typesys import Stores, get_types_from_msg, get_typestore

from fuzzoff.events import Event
from fuzzoff.formats.mavros.convert import TOPIC_KINDS, Handler, MavrosConverter, mavros_topic
from fuzzoff.formats.mavros.mavros_msgs import mavros_typedefs
from fuzzoff.formats.rosbag1.check import chunk_infos_disagree, walk
from fuzzoff.formats.rosbag1.chunkwise import ChunkwiseReader
from fuzzoff.formats.rosbag1.salvage import SalvageReader, bag_header_index_pos
from fuzzoff.formats.typedefs import bounded
from fuzzoff.recording import (
    POSITION_PERIOD_S,
    RecordingInfo,
    Source,
    SourceError,
    SourceProblem,
)

REINDEX_HINT = "run `rosbag reindex` on it for a complete read"


class Rosbag1Source(Source):
    """A ROS 1 bag; MAVROS topics become MAVLink setpoint and vehicle-status events."""

    format = "rosbag1"

    def __init__(self, path: Path) -> None:
        super().__init__(path)
        self._reader: ChunkwiseReader | None = None
        self._salvage: SalvageReader | None = None
        self._salvage_reason = ""
        self._typestore: Any = None
        self._wanted: list[Connection] = []
        self._done = 0
        self._total = 0
        self._framing: SourceProblem | None = None
        """Damage the index read steps around; said if that read loses nothing."""

    # -- opening -------------------------------------------------------------------------------

    def open(self) -> None:
        reader = ChunkwiseReader(self.path)
        try:
            reader.open()
        except ReaderError as exc:
            self._open_damaged(str(exc))
            return
        except PermissionError as exc:
            raise SourceError(self.path, f"cannot open: {exc.strerror or exc}") from None
        except Exception as exc:  # rosbags asserts and struct errors on corrupt index records
            self._open_damaged(f"{type(exc).__name__}: {exc}")
            return
        found = walk(self.path)
        wrong = chunk_infos_disagree(found, reader.chunk_infos)
        if found.in_index or wrong is not None:  # the index cannot say where messages are
            reader.close()
            self._open_damaged(f"index damaged ({wrong or 'a record does not read'})")
            return
        self._reader = reader
        if found.damage is not None:  # read around through the index: said once that is done
            what = f"{found.damage[0]}; the messages were read through the bag's index"
            self._framing = SourceProblem(what, f"byte {found.damage[1]}", lost=False)
        self._wanted = [c for c in reader.connections if mavros_topic(c.topic, c.msgtype)]
        self._total = sum(c.msgcount for c in self._wanted)
        self._typestore = self._build_typestore(self._wanted)

    def _open_damaged(self, why: str) -> None:
        """The index could not be read: say why in one line, then fall back to the salvage."""
        size = self.path.stat().st_size
        if why.startswith("File magic is invalid") or "seems to be empty" in why:
            raise SourceError(self.path, "not a ROS 1 bag (no `#ROSBAG V2.0` header)")
        if why.startswith(("Bag version", "Bag encryption")):  # the bag's own format
            raise SourceError(self.path, why.rstrip("."))
        index_pos = bag_header_index_pos(self.path)
        if index_pos is None:
            raise SourceError(self.path, "bag header unreadable", "byte 13")
        if index_pos == 0:
            self._salvage_reason = f"bag is not indexed ({REINDEX_HINT})"
        elif index_pos >= size:
            self._salvage_reason = (
                f"truncated at byte {size} (the index was due at byte {index_pos}); "
                "the events before the cut were read"
            )
        else:
            self._salvage_reason = f"index damaged at byte {index_pos} ({REINDEX_HINT})"
        self._salvage = SalvageReader(self.path)
        try:
            self._salvage.open()
        except ReaderError as exc:
            raise SourceError(self.path, f"unreadable bag: {exc}") from None

    def _build_typestore(self, connections: list[Connection]) -> Any:
        """Embedded definitions first, per connection; the shipped mavros_msgs as fallback."""
        store = get_typestore(Stores.ROS1_NOETIC)
        store.register(mavros_typedefs())
        for conn in connections:
            try:
                typedefs = bounded(get_types_from_msg(conn.msgdef.data, conn.msgtype))
                fresh = {k: v for k, v in typedefs.items() if k not in store.fielddefs}
                store.register(fresh)
            except Exception:
                continue
        return store

    def close(self) -> None:
        if self._reader is not None:
            self._reader.close()
            self._reader = None
        if self._salvage is not None:
            self._salvage.close()
            self._salvage = None

    # -- probing -------------------------------------------------------------------------------

    def probe(self) -> RecordingInfo:
        info = RecordingInfo(str(self.path), self.format)
        if self._salvage is not None:
            info.notes.append(self._salvage_reason)
            conns = [c for c in self._salvage.connections if mavros_topic(c.topic, c.msgtype)]
        else:
            conns = self._wanted
            info.message_count = self._total
        for conn in conns:
            split = mavros_topic(conn.topic, conn.msgtype)
            assert split is not None
            info.kinds.add(TOPIC_KINDS[split.name])
            if split.namespace not in info.vehicles:
                info.vehicles.append(split.namespace)
        if self._salvage is None and self._reader is not None:
            px4 = sorted({c.topic for c in self._reader.connections if "px4_msgs" in c.msgtype})
            if px4:
                info.notes.append(f"px4_msgs topics are not read from ROS 1 bags: {px4[0]} ...")
        return info

    def progress(self) -> float | None:
        if self._salvage is not None:
            return self._salvage.progress()
        return self._done / self._total if self._total else None

    # -- events --------------------------------------------------------------------------------

    def events(self) -> Iterator[Event]:
        if self._salvage is not None:
            yield from self._salvaged_events()
            return
        reader = self._reader
        if reader is None or not self._wanted:
            self._said_framing()
            return
        self.set_start(reader.start_time / 1e9 if reader.message_count else None)
        yield from self._convert(self._indexed_then_in_file_order(reader), [reader.start_time])
        self._said_framing()

    def _said_framing(self) -> None:
        """The framing damage the index read stepped around, unless something was lost after
        all (then that line says what; this one would say the opposite)."""
        if self._framing is not None and not any(p.lost for p in self.problems):
            self.problems.append(self._framing)

    def _indexed_then_in_file_order(
        self, reader: ChunkwiseReader
    ) -> Iterator[tuple[Connection, int, bytes]]:
        """The messages through the index; where a damaged index entry or chunk stops that
        read, the rest in file order (the salvage reader), from after the last message read.
        The data of a bag is usually intact where one offset in its index is not."""
        last_ns = -1
        try:
            for conn, timestamp, raw in reader.messages(connections=self._wanted):
                last_ns = timestamp
                yield conn, timestamp, raw
            return
        except Exception as exc:  # rosbags ReaderError, asserts, codec errors
            detail = _failure(exc)
        salvage = SalvageReader(self.path)
        same = {(c.topic, c.msgtype): c for c in self._wanted}
        resumed = 0
        try:
            salvage.open()
            for conn, timestamp, raw in salvage.messages():
                wanted = same.get((conn.topic, conn.msgtype))
                if wanted is not None and timestamp > last_ns:
                    resumed += 1
                    yield wanted, timestamp, raw
        except ReaderError as exc:
            salvage.stopped = salvage.stopped or (str(exc), 0)
        finally:
            salvage.close()
        t = (last_ns - reader.start_time) / 1e9 if last_ns >= 0 else None
        what = f"the indexed read stopped ({detail}); {resumed} later messages read in file order"
        at = None
        if salvage.stopped is not None:
            what += f", until: {salvage.stopped[0]}"
            at = f"byte {salvage.stopped[1]}"
        self.problems.append(SourceProblem(f"{what} ({REINDEX_HINT})", at, t))

    def _salvaged_events(self) -> Iterator[Event]:
        """File order, as recorded; the first message of any topic is time zero."""
        salvage = self._salvage
        assert salvage is not None
        first = [-1]

        def wanted() -> Iterator[tuple[Connection, int, bytes]]:
            for conn, timestamp, raw in salvage.messages():
                if first[0] < 0:
                    first[0] = timestamp
                if mavros_topic(conn.topic, conn.msgtype):
                    if conn.msgtype not in self._typestore.fielddefs:
                        self._typestore = self._build_typestore(salvage.connections)
                    yield conn, timestamp, raw

        self._typestore = self._build_typestore(salvage.connections)
        yield from self._convert(wanted(), first)
        what, at = self._salvage_reason, None
        if salvage.stopped is not None and "truncated" not in what:
            what = f"{what}; reading stopped: {salvage.stopped[0]}"
            at = f"byte {salvage.stopped[1]}"
        self.problems.append(SourceProblem(what, at))

    def _handler(
        self, converter: MavrosConverter, conn: Connection
    ) -> tuple[Handler | None, Callable[[bytes], Any]]:
        """The conversion and the decoder for one connection (looked up once, not per message)."""
        return converter.handler(conn.topic), _decoder(self._typestore, conn.msgtype)

    def _convert(
        self, messages: Iterator[tuple[Connection, int, bytes]], start_ns: list[int]
    ) -> Iterator[Event]:
        """Decode, convert and yield; corrupt messages are skipped and reported once.

        ``start_ns[0]`` is the recording's first time (set by the salvage once it has read it).
        """
        converter = MavrosConverter(position_period_s=POSITION_PERIOD_S, aside=self.aside)
        handlers: dict[int, tuple[Handler | None, Callable[[bytes], Any]]] = {}
        counts: dict[int, int] = {}
        first_bad: SourceProblem | None = None
        bad = 0
        last: tuple[Connection, int, float] | None = None
        """(connection, index, t) of the last message decoded; named only if reading stops."""
        try:
            for conn, timestamp, raw in messages:
                self._done += 1
                cid = conn.id
                index = counts.get(cid, 0)
                counts[cid] = index + 1
                t = (timestamp - start_ns[0]) / 1e9
                entry = handlers.get(cid)
                if entry is None:
                    entry = handlers[cid] = self._handler(converter, conn)
                handler, decode = entry
                if handler is None:
                    continue
                try:
                    msg = decode(raw)
                except Exception as exc:  # corrupt message bytes: skip it, say so once
                    what = f"message does not decode as {conn.msgtype} ({type(exc).__name__})"
                    bad += 1
                    first_bad = first_bad or SourceProblem(what, f"{conn.topic} #{index}", t)
                    continue
                last = (conn, index, t)  # formatted only on failure: once per message
                event = handler(msg, t, index)
                if event is not None:
                    yield event
        except Exception as exc:  # rosbags ReaderError, asserts, codec errors on corrupt chunks
            detail = _failure(exc)
            where = f"{last[0].topic} #{last[1]}" if last is not None else None
            t_last = last[2] if last is not None else None
            after = "after the message" if last is not None else "before the first message"
            what = f"bag data corrupt ({detail}); reading stopped {after}"
            self.problems.append(SourceProblem(what, where, t_last))
        if first_bad is not None:
            more = f" (and {bad - 1} more)" if bad > 1 else ""
            self.problems.append(
                SourceProblem(first_bad.what + more, first_bad.where, first_bad.time_s)
            )
        self.stats["messages_decoded"] = self._done


def _failure(exc: Exception) -> str:
    """What stopped a read, in a few words: rosbags' own message, else the exception's type
    (an assert or a codec error says nothing a user can act on)."""
    return str(exc).rstrip(".") if isinstance(exc, ReaderError) else type(exc).__name__


def _decoder(store: Any, msgtype: str) -> Callable[[bytes], Any]:
    """``store.deserialize_ros1(raw, msgtype)`` with the type's deserialiser looked up once.

    A message that does not decode to exactly its length goes through
    ``store.deserialize_ros1`` itself, which raises the library's own error for it.
    """
    try:
        msgdef = store.get_msgdef(msgtype)
    except Exception:  # an unknown type: the library's call fails per message, as it would
        return partial(store.deserialize_ros1, typename=msgtype)
    func, cls = msgdef.deserialize_ros1, msgdef.cls

    def decode(raw: bytes) -> Any:
        try:
            message, pos = func(raw, 0, cls, store)
        except Exception:
            return store.deserialize_ros1(raw, msgtype)
        if pos != len(raw):
            return store.deserialize_ros1(raw, msgtype)
        return message

    return decode
