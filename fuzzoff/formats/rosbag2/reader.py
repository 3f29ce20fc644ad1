"""ROS 2 bags (formats.md 5): a bag folder (metadata.yaml + .db3 / .mcap files) or one data file.

Read with ``rosbags.rosbag2.Reader`` (split files, compression, both storages), but with
fuzzoff's own per-connection choice of definitions (formats.md 3: AnyReader's fallback is
all-or-nothing). What rosbags cannot open is salvaged file by file: a missing or malformed
metadata.yaml -> each data file opened on its own; a damaged ``.db3`` -> Python's ``sqlite3`` row
by row; a cut ``.mcap`` -> fuzzoff's streaming MCAP reader. Every salvage is a problem (OFB001).
"""

from __future__ import annotations

import re
import sqlite3
from collections.abc import Callable, Iterable, Iterator
from contextlib import suppress
from dataclasses import replace
from pathlib import Path
from typing import Any

from rosbags.interfaces import MessageDefinitionFormat
from rosbags.rosbag2 import Reader
from ruamel.yaml import YAML

from fuzzoff.events import Event
from fuzzoff.formats import px4_msgs
from fuzzoff.formats.mavros.convert import mavros_topic
from fuzzoff.formats.mcap import check as mcap_check
from fuzzoff.formats.mcap import indexed as mcap_indexed
from fuzzoff.formats.mcap.order import ChunkOrder
from fuzzoff.formats.mcap.stream import McapStream
from fuzzoff.formats.ros2msgs.decode import Decoder, Ros2Decoding, TopicDecoder, message_of
from fuzzoff.formats.rosbag2 import metadata as ros2_metadata
from fuzzoff.formats.rosbag2.sqlite import SQLITE_ERRORS, SalvageCopies
from fuzzoff.formats.rosbag2.sqlite import topics as sqlite_topics
from fuzzoff.profiles import ROVER_ASSUMED
from fuzzoff.recording import (
    POSITION_PERIOD_S,
    RecordingInfo,
    Source,
    SourceError,
    SourceProblem,
)

DATA_SUFFIXES = (".db3", ".mcap")
STATUS_WINDOW_NS = 10_000_000_000
"""The vehicle type is looked up in the first VehicleStatus of the first 10 s (PX4 sends it
at 1-2 Hz and on every change)."""
_FORMATS = {MessageDefinitionFormat.MSG: "msg", MessageDefinitionFormat.IDL: "idl"}

EventMakers = dict[int, Callable[[bytes | memoryview, float], Event | None]]
"""Connection or channel id -> its decoder's ``event``."""
Messages = Iterable[tuple[int, int, bytes | memoryview]]
"""(connection or channel id, recording time in ns, CDR payload)."""


def _well_formed(conn: Any) -> bool:
    """A connection as metadata.yaml must describe it: text name and type, a count."""
    count = conn.msgcount
    return (
        isinstance(conn.topic, str)
        and isinstance(conn.msgtype, str)
        and isinstance(count, int)
        and not isinstance(count, bool)
        and count >= 0
    )


def _topics_held(path: Path) -> set[tuple[Any, Any]]:
    """(topic, type) of every topic a data file names: a database's topics table (rosbags'
    own opening of one would also count its messages, 0.5 s on a million), an MCAP's
    channels through rosbags."""
    if path.suffix == ".db3":
        db = sqlite3.connect(f"file:{path}?mode=ro", uri=True)
        try:
            return {(name, msgtype) for _, name, msgtype, _, _ in sqlite_topics(db)}
        finally:
            db.close()
    with Reader(path) as single:
        return {(conn.topic, conn.msgtype) for conn in single.connections}


def _decoded_topic(topic: Any, msgtype: Any) -> bool:
    """A topic fuzzoff decodes (a PX4 topic, or a MAVROS one it reads)."""
    if not (isinstance(topic, str) and isinstance(msgtype, str)):  # a damaged database
        return False
    return message_of(topic, msgtype)[0] is not None or mavros_topic(topic, msgtype) is not None


_SQLITE_TYPES = {str: "text", bytes: "blob", float: "real", type(None): "null"}
"""The SQLite storage class of a value Python's sqlite3 returned."""


def _some(names: list[str]) -> str:
    """The first three names, and how many more."""
    more = f" and {len(names) - 3} more" if len(names) > 3 else ""
    return ", ".join(names[:3]) + more


def _why(exc: BaseException) -> str:
    if isinstance(exc, UnicodeDecodeError):  # see SQLITE_ERRORS
        return "damaged text in its schema"
    if isinstance(exc, MemoryError):
        return "a record claims more bytes than SQLite will read"
    text = str(exc).strip().rstrip(".") or type(exc).__name__
    text = re.sub(r"^Cannot open database .*?: ", "", text)
    return text.replace("\n", " ")


class Rosbag2Source(Source):
    """A ROS 2 bag, either storage. ``px4_hint`` steers bundled definitions (``--px4``)."""

    format = "rosbag2-sqlite3"

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
        self._copies = SalvageCopies()
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
        self.decoding.release = px4_msgs.release_for(self.px4_hint)
        self.decoding.thin_positions(0.0 if self.plot_data else POSITION_PERIOD_S)
        if not self.path.exists():
            raise SourceError(self.path, "no such file or folder")
        if self._summary_damaged():
            return
        if self.path.is_dir():
            fault = ros2_metadata.fault(self.path, self._data_files(self.path))
            if fault is not None:
                self._salvage_plan(ValueError(fault), fault)
                return
        try:
            reader = Reader(self.path)
            reader.open()
        except Exception as exc:
            self._salvage_plan(exc)
            return
        if self.path.is_dir() and not all(map(_well_formed, reader.connections)):
            # rosbags takes metadata.yaml's values as they come; the data files name and count
            # their topics themselves.
            with suppress(Exception):
                reader.close()
            fault = "metadata.yaml: a topic's name, type or message count is malformed"
            self._salvage_plan(ValueError(fault), fault)
            return
        unlisted = self._unlisted_topics(reader) if self.path.is_dir() else []
        if unlisted:
            with suppress(Exception):
                reader.close()
            # One of the two is damaged: a topic renamed in the database reads the same as a
            # metadata.yaml from another bag, so the data files are read but not vouched for.
            fault = (
                f"metadata.yaml does not list {_some(unlisted)}, which the data files hold "
                "(one of them is damaged or from another recording)"
            )
            self._salvage_plan(ValueError(fault), fault, lost=True)
            return
        self._reader = reader

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

    def _unlisted_topics(self, reader: Any) -> list[str]:
        """PX4 or MAVROS topics a data file names that metadata.yaml leaves out (an edited or
        half-written file): reading through it would drop their messages without a word, and
        the stream rules would see a keep-alive missing that was recorded."""
        listed = {(conn.topic, conn.msgtype) for conn in reader.connections}
        unlisted: set[str] = set()
        for path in self._data_files(self.path):
            try:
                held = _topics_held(path)
            except Exception:  # a damaged file: the reading says what is wrong with it
                continue
            unlisted.update(t for t, m in held - listed if _decoded_topic(t, m))
        return sorted(unlisted)

    def _salvage_plan(
        self, exc: BaseException, fault: str | None = None, lost: bool = False
    ) -> None:
        """rosbags could not open the bag as a whole, or ``fault`` is what its metadata.yaml
        gets wrong (``ros2_metadata``): the data files, to read one by one. A metadata.yaml at
        fault is said, and the folder's own data files are read: nothing is lost by it, unless
        the two disagree on what the data holds (``lost``: which is damaged cannot be told)."""
        if self.path.is_file():
            self._files = [self.path]
            return
        listed = (
            None if fault is not None else self._files_from_metadata(self.path / "metadata.yaml")
        )
        if listed is None:
            files = self._data_files(self.path)
            if not files:
                raise SourceError(self.path, f"not a readable ROS 2 bag ({fault or _why(exc)})")
            fault = fault or f"metadata.yaml cannot be used ({_why(exc)})"
        else:
            for path in listed:
                if not path.is_file():
                    what = "data file listed in metadata.yaml is missing"
                    self.problems.append(SourceProblem(what, path.name))
            files = [path for path in listed if path.is_file()]
            if not files:
                raise SourceError(self.path, "none of the bag's data files exist")
        if fault is not None:
            names = _some([path.name for path in files])
            what = f"{fault}; the data files were read instead: {names}"
            self.problems.append(SourceProblem(what, lost=lost))
        self._files = files

    def _files_from_metadata(self, meta: Path) -> list[Path] | None:
        try:
            data = YAML(typ="safe").load(meta.read_text(encoding="utf-8"))
            names = data["rosbag2_bagfile_information"]["relative_file_paths"]
            if not all(isinstance(n, str) for n in names):
                return None  # the folder's own files are read instead
            return [self.path / Path(n).name for n in names]
        except Exception:
            return None

    # -- probe -------------------------------------------------------------------------------

    def probe(self) -> RecordingInfo:
        if self._info is not None:
            return self._info
        info = RecordingInfo(str(self.path), self.format)
        if self._reader is not None:
            reader = self._reader
            info.message_count = reader.message_count
            self._t0 = reader.start_time if reader.message_count else None
            if self._t0 is not None and self.path.is_dir():
                self._t0 = self._data_time(reader)
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

    def _data_time(self, reader: Any) -> int:
        """The bag's start. metadata.yaml states it, with the bag's duration; the data files
        hold the messages' own times. Where the two disagree, the one whose span matches the
        data's is believed: metadata.yaml from another recording (every time shifted by the
        difference) gives way to the data; a database whose earliest time alone disagrees
        (a damaged timestamp: its last agrees with metadata.yaml) keeps metadata.yaml's."""
        listed, listed_end = reader.start_time, reader.end_time - 1
        span = ros2_metadata.data_span(self._data_files(self.path))
        if span is None or span[0] == listed:
            return int(listed)
        start, end = span
        if end == listed_end:
            way = "before" if start < listed else "after"
            what = (
                f"the first message is {abs(listed - start) / 1e9:.3f} s {way} the bag's start, "
                "as metadata.yaml and the last message agree on it (a damaged timestamp?); "
                "metadata.yaml's start was used"
            )
            self.problems.append(SourceProblem(what, "messages.timestamp"))
            return int(listed)
        differs = ros2_metadata.differs(listed, start)
        what = f"{differs}; the data files' times were used"
        self.problems.append(SourceProblem(what, lost=False))
        return start

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
                with Reader(path) as reader:
                    for conn in reader.connections:
                        self._decoder(conn.topic, conn.msgtype, conn.msgdef)
                    if reader.message_count:
                        starts.append(reader.start_time)
                        # as for a whole bag: definitions, release and vehicle type up front
                        self._presample(reader)
            except Exception:  # salvaged below, and again in the reading pass
                if path.suffix == ".db3":
                    start = self._probe_salvage(path)
                else:
                    stream = McapStream(path, self.decoding, None, self._connect)
                    start, vehicle = stream.scan()
                    self._vehicle = self._vehicle or vehicle
                    self._notes.append(f"{path.name}: no usable MCAP summary; scanned for channels")
                if start is not None:
                    starts.append(start)
        self._t0 = min(starts) if starts else None

    def _probe_salvage(self, path: Path) -> int | None:
        """Topics, definitions and start time of a database rosbags cannot open."""
        try:
            db = self._copies.connect(path)
        except (*SQLITE_ERRORS, OSError):
            return None
        try:
            topics = self._sqlite_topics(db)
            for topic_id, decoder in topics.items():
                first = db.execute(
                    "SELECT data FROM messages WHERE topic_id = ? ORDER BY id LIMIT 1", (topic_id,)
                ).fetchone()
                if first is not None and self._vehicle is None:
                    self._vehicle = self.decoding.vehicle_from(decoder, first[0])
            row = db.execute(
                "SELECT MIN(timestamp) FROM messages WHERE typeof(timestamp) = 'integer'"
            ).fetchone()
            return int(row[0]) if row and row[0] is not None else None
        except SQLITE_ERRORS:
            return None
        finally:
            db.close()

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
        if not selected:  # rosbags reads every message when given no connection
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
                yield from self._salvage_mcap(mcap_file, self._last_ns, refused=_why(exc))
            else:
                self.problems.append(
                    SourceProblem(
                        f"reading stopped: {_why(exc)}", f"{where.name} after {count} messages"
                    )
                )
        else:
            listed = sum(conn.msgcount for conn in selected)
            if count < listed:  # e.g. a metadata.yaml whose topics the database does not have
                self._fewer(where, selected, count, listed)
        finally:
            self._messages += count

    def _fewer(self, where: Path, selected: list[Any], count: int, listed: int) -> None:
        """Fewer messages were read than the index lists. If the data files hold no more than
        were read, the index is what is wrong (metadata.yaml from another recording, a
        damaged count): said, nothing lost; else the rest were not read."""
        index = "metadata.yaml" if where.is_dir() else where.name
        topics = {(conn.topic, conn.msgtype) for conn in selected}
        held = ros2_metadata.held_messages(self._data_files(where), topics)
        if held is not None and held <= count:
            what = (
                f"{index} lists {listed} messages on the PX4 topics, the data files hold "
                f"{held}: every one was read"
            )
            self.problems.append(SourceProblem(what, lost=False))
            return
        what = (
            f"{listed - count} of the {listed} messages {index} lists on the PX4 topics "
            "are not in the data (the two disagree)"
        )
        self.problems.append(SourceProblem(what))

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
        return files[0] if len(files) == 1 and files[0].suffix == ".mcap" else None

    def _data_files(self, where: Path) -> list[Path]:
        if where.is_file():
            return [where]
        return sorted(p for p in where.iterdir() if p.suffix in DATA_SUFFIXES)

    def _read_file(self, path: Path) -> Iterator[Event]:
        if path in self._stream_only:
            yield from self._salvage_mcap(path)
            return
        try:
            reader = Reader(path)
            reader.open()
        except Exception as exc:
            if path.suffix == ".mcap":
                yield from self._salvage_mcap(path, refused=_why(exc))
            else:
                yield from self._salvage_sqlite(path, exc)
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

    def _salvage_sqlite(self, path: Path, exc: BaseException) -> Iterator[Event]:
        """Row by row with Python's sqlite3, in row order, until the damage (formats.md 5)."""
        try:
            db = self._copies.connect(path)
        except (*SQLITE_ERRORS, OSError) as err:
            what = f"cannot open the database: {_why(err)}"
            self.problems.append(SourceProblem(what, path.name))
            return
        yield from self._salvage_rows(db, path, exc)

    def _salvage_rows(
        self, db: sqlite3.Connection, path: Path, exc: BaseException
    ) -> Iterator[Event]:
        count = 0
        try:
            topics = self._sqlite_topics(db)
            order = ChunkOrder()
            t0 = self._t0
            rows = db.execute("SELECT topic_id, timestamp, data FROM messages ORDER BY id")
            try:
                for topic_id, stamp, raw in rows:
                    count += 1
                    if stamp.__class__ is not int:
                        self._untimed(stamp, path)
                        continue
                    if t0 is None:
                        t0 = self._t0 = stamp
                    decoder = topics.get(topic_id)
                    if decoder is None:
                        continue
                    event = decoder.event(raw, (stamp - t0) / 1e9)
                    if event is not None:
                        yield from order.add(stamp, event)
            finally:
                yield from order.flush()
        except SQLITE_ERRORS as err:
            self.problems.append(
                SourceProblem(
                    f"database damaged ({_why(err)}): read row by row up to the damage, "
                    "nothing after it",
                    f"{path.name} after {count} messages",
                )
            )
        else:
            self.problems.append(
                SourceProblem(
                    f"rosbags cannot read this database ({_why(exc)}); it was read row by "
                    f"row with sqlite3 ({count} rows)",
                    path.name,
                )
            )
        finally:
            self._messages += count
            db.close()

    def _sqlite_topics(self, db: sqlite3.Connection) -> dict[int, Decoder]:
        out: dict[int, Decoder] = {}
        for topic_id, name, msgtype, text, fmt in sqlite_topics(db):
            decoder = self._connect(name, msgtype, text, fmt)
            if decoder is not None:
                out[topic_id] = decoder
        return out

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
        self._copies.close()
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
