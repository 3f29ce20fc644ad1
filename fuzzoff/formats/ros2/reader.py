"""Reading ROS 2 data files through rosbags, with fuzzoff's own decoding (formats.md 4, 5).

Read with ``rosbags.rosbag2.Reader`` (split files, compression, both storages; the storage of a
data file chosen by its content, ``ros2.storage``), but with fuzzoff's own per-connection choice
of definitions (formats.md 3: AnyReader's fallback is all-or-nothing). An MCAP file rosbags
cannot read, or whose summary cannot be trusted (``mcap_check``), goes through fuzzoff's
streaming MCAP reader (``mcap_stream``); a one-file MCAP whose PX4 channels are a small share is
read through its message indexes (``mcap_indexed``). Every salvage is a problem (OFB001).

``Ros2Source`` is the reader both ROS 2 formats share: ``mcap`` (one MCAP file) uses it as it
is; ``rosbag2`` adds a bag folder's metadata.yaml and the salvage of a damaged database.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Iterable, Iterator
from contextlib import suppress
from dataclasses import replace
from pathlib import Path
from typing import Any

from rosbags.interfaces import MessageDefinitionFormat
from rosbags.rosbag2 import Reader

from fuzzoff.events import Event
from fuzzoff.formats.ros2 import mcap_check, mcap_indexed
from fuzzoff.formats.ros2.mcap_stream import McapStream
from fuzzoff.formats.ros2.storage import SUFFIX, Storage, data_files, storage_of
from fuzzoff.formats.ros2msgs.decode import Decoder, Ros2Decoding, TopicDecoder
from fuzzoff.profiles import ROVER_ASSUMED
from fuzzoff.recording import (
    POSITION_PERIOD_S,
    RecordingInfo,
    Source,
    SourceError,
    SourceProblem,
)

STATUS_WINDOW_NS = 10_000_000_000
"""The vehicle type is looked up in the first VehicleStatus of the first 10 s (PX4 sends it
at 1-2 Hz and on every change)."""
_FORMATS = {MessageDefinitionFormat.MSG: "msg", MessageDefinitionFormat.IDL: "idl"}

EventMakers = dict[int, Callable[[bytes | memoryview, float], Event | None]]
"""Connection or channel id -> its decoder's ``event``."""
Messages = Iterable[tuple[int, int, bytes | memoryview]]
"""(connection or channel id, recording time in ns, CDR payload)."""

_SQLITE_TYPES = {str: "text", bytes: "blob", float: "real", type(None): "null"}
"""The SQLite storage class of a value Python's sqlite3 returned."""


def why(exc: BaseException) -> str:
    """Why a library refused a file, in a few words of one line."""
    if isinstance(exc, UnicodeDecodeError):  # see SQLITE_ERRORS
        return "damaged text in its schema"
    if isinstance(exc, MemoryError):
        return "a record claims more bytes than SQLite will read"
    text = str(exc).strip().rstrip(".") or type(exc).__name__
    text = re.sub(r"^Cannot open database .*?: ", "", text)
    return text.replace("\n", " ")


class StorageReader(Reader):
    """rosbags' ``Reader`` with a data file's storage chosen by its content (a bag folder is
    read as rosbags reads it: its metadata.yaml names the storage)."""

    def __init__(self, path: Path, storage: Storage | None = None) -> None:
        if path.is_file():
            storage = storage or storage_of(path)
            if storage is not None:
                plugin = Reader.STORAGE_PLUGINS[SUFFIX[storage]]
                self.STORAGE_PLUGINS = {path.suffix: plugin}
        super().__init__(path)


class Ros2Source(Source):
    """A ROS 2 recording: one data file of either storage, or (``rosbag2``) a bag folder.
    ``px4_hint`` steers bundled definitions (``--px4``). The formats subclass it: ``mcap``
    as it is, ``rosbag2`` with its folder, metadata.yaml and database salvage."""

    format = "mcap"

    def __init__(self, path: Path) -> None:
        super().__init__(path)
        self.decoding = Ros2Decoding()
        self._decoders: dict[tuple[str, str], Decoder | None] = {}
        self._reader: Any = None
        self._files: list[Path] = []
        self._info: RecordingInfo | None = None
        self._t0: int | None = None
        self._messages = 0
        self._done = 0
        self._notes: list[str] = []
        self._vehicle: str | None = None
        self._last_ns = -1
        self._untyped = False
        """A topic without a text name or type was met (said once)."""
        self._untimed_count = 0
        self._untimed_first = ""
        self._untimed_where = ""
        """Messages whose time is not an integer, and the first one's file and value."""
        self._framing: SourceProblem | None = None
        """Damage the summary's index steps around; said if that read loses nothing."""
        self._stream_only: set[Path] = set()
        """MCAP files read front to back whatever rosbags makes of them (summary damaged)."""

    # -- opening -----------------------------------------------------------------------------

    def open(self) -> None:
        self.decoding.release = None if self.px4_hint is None else self.px4_hint.msg_folder
        self.decoding.thin_positions(POSITION_PERIOD_S, self.aside)
        if not self.path.exists():
            raise SourceError(self.path, "no such file or folder")
        if self._summary_damaged():
            return
        self._reader = self._open_whole()

    def _open_whole(self) -> Any:
        """rosbags' reader of the whole recording, open; None when it cannot be read as a
        whole (``_files`` then lists the data files to read one by one)."""
        try:
            reader = StorageReader(self.path)
            reader.open()
        except Exception:
            self._files = [self.path]
            return None
        return reader

    def _summary_damaged(self) -> bool:
        """A one-file MCAP recording whose summary cannot be trusted (``mcap_check``) is read
        front to back, as if it had none: through the summary, rosbags would skip what a
        damaged chunk index leaves out. Damage to the data section's record headers is read
        around through the summary, and said (nothing is lost by either)."""
        mcap_file = self._single_mcap(self.path)
        if mcap_file is None:
            return False
        try:
            damage = mcap_check.summary_damage(mcap_file)
            framing = None if damage is not None else mcap_check.framing_damage(mcap_file)
        except OSError as exc:
            raise SourceError(mcap_file, f"cannot read: {exc.strerror or exc}") from None
        if framing is not None:  # said once that read is done (``_finish``)
            what = f"{framing.what}; its messages were read through the summary's chunk index"
            self._framing = SourceProblem(what, self._at(mcap_file, framing.offset), lost=False)
        if damage is None:
            return False
        what = f"{damage.what}; read front to back without the summary"
        self.problems.append(SourceProblem(what, self._at(mcap_file, damage.offset), lost=False))
        self._files = [mcap_file]
        self._stream_only.add(mcap_file)
        return True

    def _at(self, path: Path, offset: int) -> str:
        """``byte N``, after the data file's name in a bag folder."""
        return f"byte {offset}" if path == self.path else f"{path.name} byte {offset}"

    # -- probe -------------------------------------------------------------------------------

    def probe(self) -> RecordingInfo:
        if self._info is not None:
            return self._info
        info = RecordingInfo(str(self.path), self.format)
        if self._reader is not None:
            reader = self._reader
            info.message_count = reader.message_count
            self._t0 = self._start(reader) if reader.message_count else None
            for conn in reader.connections:
                self._decoder(conn.topic, conn.msgtype, conn.msgdef)
            if reader.ros_distro:
                info.notes.append(f"recorded with ROS 2 {reader.ros_distro}")
            self._presample(reader)
        else:
            self._probe_files()
        info.kinds = self.decoding.kinds()
        info.vehicles = self.decoding.vehicles()
        info.px4_version = self.decoding.detected_release()
        info.px4_candidates = self.decoding.fitting_releases()
        info.px4_msgs_fits = self.decoding.px4_msgs_fits()
        info.px4_msgs_conflicts = self.decoding.px4_msgs_conflicts()
        info.vehicle_type = self._vehicle
        self._rover(info)
        info.notes.extend(self._notes)
        self._info = info
        return info

    def _start(self, reader: Any) -> int:
        """The recording's start, in ns (where the data files and an index disagree, a
        format may say which it believes)."""
        return int(reader.start_time)

    def _rover(self, info: RecordingInfo) -> None:
        """A rover's kind is in no ROS 2 topic: PX4's ``VehicleStatus`` says only "rover"
        (``vehicle_type`` 3), and the rover setpoint topics (``/fmu/in/rover_*``) serve all
        three kinds. Either makes the recording a rover's; the kind is assumed, and said."""
        topics = self.decoding.rover_topics()
        if info.vehicle_type not in (None, ROVER_ASSUMED) or not (
            topics or info.vehicle_type == ROVER_ASSUMED
        ):
            return
        info.vehicle_type = ROVER_ASSUMED
        said = f"its {', '.join(topics)} topics" if topics else "its VehicleStatus"
        info.vehicle_assumed = (
            f"a rover ({said}) but not which kind (assumed {ROVER_ASSUMED}; set --vehicle "
            "rover-ackermann, rover-differential or rover-mecanum)"
        )

    def _presample(self, reader: Any) -> None:
        """Choose bundled definitions now, from each topic's first message, so the release
        they reveal can set the profile (Humble bags embed none). VehicleStatus goes first:
        its layout differs in every release."""
        pending: list[tuple[bool, Any, TopicDecoder]] = []
        for conn in reader.connections:
            decoder = self._decoders.get((conn.topic, conn.msgtype))
            if isinstance(decoder, TopicDecoder) and decoder.definition is None and conn.msgcount:
                pending.append((decoder.message != "VehicleStatus", conn, decoder))
        pending.sort(key=lambda item: (item[0], item[1].id))
        for _, conn, decoder in pending:
            try:
                _, stamp, raw = next(iter(reader.messages(connections=[conn])))
            except Exception:
                continue
            t0 = self._t0 if self._t0 is not None else stamp
            decoder.resolve(raw, (stamp - t0) / 1e9)
        self._vehicle_type(reader)
        chosen = sorted({d.definition.source for _, _, d in pending if d.definition is not None})
        if chosen:
            self._notes.append(
                "no embedded definitions for some topics: decoded with " + ", ".join(chosen)
            )

    def _vehicle_type(self, reader: Any) -> None:
        """The vehicle type from the first ``VehicleStatus`` (a cheap indexed read)."""
        if self._vehicle:
            return
        for conn in reader.connections:
            decoder = self._decoders.get((conn.topic, conn.msgtype))
            if not isinstance(decoder, TopicDecoder) or decoder.message != "VehicleStatus":
                continue
            if not conn.msgcount:
                continue
            # Only the first seconds: a time-bounded query stays cheap on a large sqlite bag.
            window = (self._t0 or reader.start_time) + STATUS_WINDOW_NS
            try:
                _, _, raw = next(iter(reader.messages(connections=[conn], stop=window)))
            except Exception:  # none in the window, or damage the main pass reports
                continue
            self._vehicle = self.decoding.vehicle_from(decoder, raw)
            if self._vehicle:
                return

    def _probe_files(self) -> None:
        starts = []
        for path in self._files:
            try:
                if path in self._stream_only:
                    raise ValueError("read front to back")
                with StorageReader(path) as reader:
                    for conn in reader.connections:
                        self._decoder(conn.topic, conn.msgtype, conn.msgdef)
                    if reader.message_count:
                        starts.append(reader.start_time)
                        # as for a whole bag: definitions, release and vehicle type up front
                        self._presample(reader)
            except Exception:  # salvaged below, and again in the reading pass
                if storage_of(path) != "mcap":
                    start = self._probe_unopened(path)
                else:
                    stream = McapStream(path, self.decoding, None, self._connect)
                    start, vehicle = stream.scan()
                    self._vehicle = self._vehicle or vehicle
                    self._notes.append(f"{path.name}: no usable MCAP summary; scanned for channels")
                if start is not None:
                    starts.append(start)
        self._t0 = min(starts) if starts else None

    def _probe_unopened(self, path: Path) -> int | None:
        """Topics, definitions and start time (ns) of a database rosbags cannot open, where
        the format salvages one (``rosbag2.salvage``); None here."""
        return None

    def _decoder(self, topic: str, msgtype: str, msgdef: Any) -> Decoder | None:
        text = msgdef.data if msgdef is not None and msgdef.format in _FORMATS else None
        fmt = _FORMATS.get(msgdef.format, "msg") if msgdef is not None else "msg"
        return self._connect(topic, msgtype, text, fmt)

    def _connect(self, topic: Any, msgtype: Any, text: str | None, fmt: str) -> Decoder | None:
        """One decoder per (topic, type) across the bag's files and read paths."""
        if not (isinstance(topic, str) and isinstance(msgtype, str)):  # a damaged database
            if not self._untyped:
                self._untyped = True
                what = "a topic's name or type is not text; its messages were skipped"
                self.problems.append(SourceProblem(what))
            return None
        key = (topic, msgtype)
        if key not in self._decoders:
            self._decoders[key] = self.decoding.connection(topic, msgtype, text, fmt)
        return self._decoders[key]

    # -- events ------------------------------------------------------------------------------

    def events(self) -> Iterator[Event]:
        self.probe()
        try:
            if self._reader is not None:
                yield from self._read(self._reader, self.path)
            else:
                for path in self._files:
                    yield from self._read_file(path)
                    self._done += 1
        finally:
            self._finish()

    def _read(self, reader: Any, where: Path) -> Iterator[Event]:
        selected = []
        for conn in reader.connections:
            if self._decoder(conn.topic, conn.msgtype, conn.msgdef) is not None:
                selected.append(conn)
            elif (conn.topic, conn.msgtype) in self.decoding.unknown:
                self.decoding.count_unread(conn.topic, conn.msgtype, conn.msgcount)
        if not selected:  # rosbags reads every message when given no connection
            self._unreachable(reader, where, short=False)
            return
        indexed = self._indexed(where, {(conn.topic, conn.msgtype) for conn in selected})
        if indexed is not None:
            by_id, messages = indexed
        else:
            by_id, messages = self._by_connection(reader, selected)
        t0 = self._t0
        count = 0
        self._last_ns = -1
        try:
            for key, stamp, raw in messages:
                count += 1
                if stamp.__class__ is not int:  # SQLite keeps any type in any column
                    self._untimed(stamp, where)
                    continue
                if t0 is None:
                    t0 = self._t0 = stamp
                self._last_ns = stamp
                event = by_id[key](raw, (stamp - t0) / 1e9)
                if event is not None:
                    yield event
        except Exception as exc:  # rosbags, mcap, sqlite and codec errors mid-read
            mcap_file = self._single_mcap(where)
            if mcap_file is not None:
                # rosbags stops at the first bad chunk; the streaming reader skips it and
                # goes on (only messages after the last one already read are taken).
                yield from self._salvage_mcap(mcap_file, self._last_ns, refused=why(exc))
            else:
                self.problems.append(
                    SourceProblem(
                        f"reading stopped: {why(exc)}", f"{where.name} after {count} messages"
                    )
                )
        else:
            listed = sum(conn.msgcount for conn in selected)
            unreachable = self._unreachable(reader, where, short=count < listed)
            if count < listed and not unreachable:  # e.g. another bag's metadata.yaml
                self._fewer(reader, where, selected, count, listed)
        finally:
            self._messages += count

    def _unreachable(self, reader: Any, where: Path, short: bool) -> bool:
        """Say the messages of ``where`` that no reading by topic reaches (a format whose
        storage can hold such, as a database's rows of no topic, checks for them); True when
        there are any. ``short``: the reading fell short of the topics' counts."""
        return False

    def _fewer(
        self, reader: Any, where: Path, selected: list[Any], count: int, listed: int
    ) -> None:
        """Fewer messages were read than the index lists (an MCAP's statistics, a bag's
        metadata.yaml). Where the data files hold no more than were read (``_held``), either
        the index or the data is damaged: an index that is not the data's own (``_short_of``
        None: another bag's metadata.yaml) is said, nothing lost; one whose start is the
        data's cannot be told from data that lost messages (at the end, where a database's
        ids show no gap), so the rest count as not read. Else the rest were not read."""
        index = "metadata.yaml" if where.is_dir() else where.name
        topics = {(conn.topic, conn.msgtype) for conn in selected}
        held = self._held(where, topics)
        missing = f"{listed - count} of the {listed} messages {index} lists on the PX4 topics"
        if held is not None and held <= count:
            short = self._short_of(reader, where)
            if short is None:
                what = f"{index} lists {listed} messages on the PX4 topics, the data files hold "
                self.problems.append(SourceProblem(f"{what}{held}: every one was read", lost=False))
                return
            ending = f", which end {short / 1e9:.3f} s before the bag's end" if short else ""
            what = (
                f"{missing} are not in the data files{ending} (messages lost, or "
                f"{index}'s counts damaged: which cannot be told)"
            )
            self.problems.append(SourceProblem(what))
            return
        self.problems.append(SourceProblem(f"{missing} are not in the data (the two disagree)"))

    def _held(self, where: Path, topics: set[tuple[str, str]]) -> int | None:
        """How many messages on ``topics`` the data files hold, counted in the data (not an
        index); None where only an index could say."""
        return None

    def _short_of(self, reader: Any, where: Path) -> int | None:
        """How many ns before the index's end the data's last message is (0 or more), where
        the two agree on the start; None where the index is not the data's own (or there is
        no index beside the data)."""
        return None

    def _untimed(self, stamp: Any, where: Path) -> None:
        """A message whose time is not an integer (a damaged database): skipped, counted."""
        if self._untimed_count == 0:
            shown = repr(stamp)
            shown = shown if len(shown) <= 24 else shown[:23] + "…"
            kind = _SQLITE_TYPES.get(type(stamp), type(stamp).__name__)
            self._untimed_first = f"{kind} {shown}"
            self._untimed_where = "messages.timestamp" + (
                "" if where.is_dir() else f" in {where.name}"
            )
        self._untimed_count += 1

    def _by_connection(self, reader: Any, selected: list[Any]) -> tuple[EventMakers, Messages]:
        """rosbags' own reading: (connection id, time, payload) of the selected connections."""
        by_id = self._event_makers((conn.id, (conn.topic, conn.msgtype)) for conn in selected)
        messages = (
            (conn.id, stamp, raw) for conn, stamp, raw in reader.messages(connections=selected)
        )
        return by_id, messages

    def _indexed(
        self, where: Path, selected: set[tuple[str, str]]
    ) -> tuple[EventMakers, Messages] | None:
        """A one-file MCAP bag whose PX4 channels are a small share of its messages is read
        through its message indexes (``mcap_indexed``); None keeps rosbags' own reading."""
        mcap_file = self._single_mcap(where)
        if mcap_file is None:
            return None
        plan = mcap_indexed.plan(mcap_file, lambda topic, msgtype: (topic, msgtype) in selected)
        if plan is None or set(plan.channels.values()) != selected:
            return None  # the two readers must agree on what is read, or rosbags reads it
        return self._event_makers(plan.channels.items()), mcap_indexed.messages(plan)

    def _event_makers(self, keys: Iterable[tuple[int, tuple[str, str]]]) -> EventMakers:
        """Id -> the ``event`` of the decoder of its (topic, type), bound once, not per message."""
        makers: EventMakers = {}
        for ident, key in keys:
            decoder = self._decoders[key]
            assert decoder is not None
            makers[ident] = decoder.event
        return makers

    def _single_mcap(self, where: Path) -> Path | None:
        """The data file of a bag (or a bag file) stored as one MCAP file, else None."""
        files = self._data_files(where)
        return files[0] if len(files) == 1 and storage_of(files[0]) == "mcap" else None

    def _data_files(self, where: Path) -> list[Path]:
        if where.is_file():
            return [where]
        return data_files(where)

    def _read_file(self, path: Path) -> Iterator[Event]:
        if path in self._stream_only:
            yield from self._salvage_mcap(path)
            return
        try:
            reader = StorageReader(path)
            reader.open()
        except Exception as exc:
            if storage_of(path) == "mcap":
                yield from self._salvage_mcap(path, refused=why(exc))
            else:
                yield from self._salvage_database(path, exc)
            return
        try:
            yield from self._read(reader, path)
        finally:
            with suppress(Exception):
                reader.close()

    def _salvage_mcap(
        self, path: Path, after_ns: int = -1, refused: str | None = None
    ) -> Iterator[Event]:
        """fuzzoff's streaming MCAP reader: CRC-checked chunk by chunk, past bad chunks.
        ``refused``: why rosbags could not open the file, said if the stream finds nothing
        wrong (it was read whole, but something in it is malformed)."""
        misplaced = mcap_check.framing_damage(path)
        if misplaced is not None and misplaced.kind == "type":  # read past by the stream
            what = f"{misplaced.what} (a damaged record type): what it held was not read"
            self.problems.append(SourceProblem(what, self._at(path, misplaced.offset)))
        stream = McapStream(path, self.decoding, self._t0, self._connect, after_ns=after_ns)
        stream.summary_said = path in self._stream_only
        if not stream.summary_said:
            stream.use_summary()
        yield from stream.events()
        if self._t0 is None:
            self._t0 = stream.t0_ns
        self._messages += stream.messages
        for problem in stream.problems:
            where = problem.where
            if path != self.path:
                where = f"{path.name} {where}" if where else path.name
            self.problems.append(replace(problem, where=where))
        if refused is not None and not stream.problems:
            what = f"rosbags cannot open it ({refused}); read front to back, every record read"
            self.problems.append(
                SourceProblem(what, None if path == self.path else path.name, lost=False)
            )

    def _salvage_database(self, path: Path, exc: BaseException) -> Iterator[Event]:
        """A database rosbags cannot open, where the format salvages one
        (``rosbag2.salvage``); here it is said, and nothing read."""
        what = f"rosbags cannot open it ({why(exc)}): not read"
        self.problems.append(SourceProblem(what, None if path == self.path else path.name))
        yield from ()

    def _finish(self) -> None:
        if self._t0 is not None:
            self.set_start(self._t0 / 1e9)
        if self._untimed_count:
            n = self._untimed_count
            many = f"{n} messages whose timestamp is not an integer were"
            what = (
                f"{many if n > 1 else '1 message whose timestamp is not an integer was'} not "
                f"read (the first: {self._untimed_first})"
            )
            self.problems.append(SourceProblem(what, self._untimed_where))
        self.problems.extend(self.decoding.problems())
        if self._framing is not None and not any(p.lost for p in self.problems):
            self.problems.append(self._framing)
        self.stats["messages"] = self._messages
        if self._info is not None:
            self._info.notes.extend(self.decoding.notes)
            self._info.kinds |= self.decoding.kinds()
        if self._reader is not None:
            with suppress(Exception):
                self._reader.close()
            self._reader = None

    def close(self) -> None:
        if self._reader is not None:
            with suppress(Exception):
                self._reader.close()
            self._reader = None

    def progress(self) -> float | None:
        if self._files:
            return self._done / len(self._files)
        reader = self._reader
        if reader is None or self._t0 is None or self._last_ns < 0 or not reader.duration:
            return None
        fraction = (self._last_ns - self._t0) / float(reader.duration)
        return min(1.0, max(0.0, fraction))
