"""ROS 2 bags (formats.md 5): a bag folder (metadata.yaml + .db3 / .mcap files) or one data file.

Read through the ROS 2 reading core (``ros2.reader.Ros2Source``, which the ``mcap`` format shares),
with what a bag adds: its metadata.yaml judged against the data files (``metadata``), a database's
tables checked for rows no reading by topic reaches, and what rosbags cannot open salvaged file by
file: a missing or malformed metadata.yaml -> each data file opened on its own; a damaged
database -> ``salvage`` (Python's ``sqlite3`` row by row); a cut MCAP -> the core's streaming
reader. Every salvage is a problem (OFB001).
"""

from __future__ import annotations

import sqlite3
from contextlib import suppress
from pathlib import Path
from typing import Any

from ruamel.yaml import YAML

from fuzzoff.formats.mavros.convert import mavros_topic
from fuzzoff.formats.ros2.reader import StorageReader, why
from fuzzoff.formats.ros2.storage import storage_of
from fuzzoff.formats.ros2msgs.decode import px4_topic
from fuzzoff.formats.rosbag2 import metadata as ros2_metadata
from fuzzoff.formats.rosbag2.salvage import DatabaseSalvage, dangling_rows, some
from fuzzoff.formats.rosbag2.sqlite import dangling as sqlite_dangling
from fuzzoff.formats.rosbag2.sqlite import rows as sqlite_rows
from fuzzoff.formats.rosbag2.sqlite import topics as sqlite_topics
from fuzzoff.recording import SourceError, SourceProblem


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
    if storage_of(path) == "sqlite3":
        db = sqlite3.connect(f"file:{path}?mode=ro", uri=True)
        try:
            return {(name, msgtype) for _, name, msgtype, _, _ in sqlite_topics(db)}
        finally:
            db.close()
    with StorageReader(path) as single:
        return {(conn.topic, conn.msgtype) for conn in single.connections}


def _decoded_topic(topic: Any, msgtype: Any) -> bool:
    """A topic fuzzoff decodes or must say it could not (a PX4 topic, whatever type it is
    recorded as, or a MAVROS one it reads)."""
    if not (isinstance(topic, str) and isinstance(msgtype, str)):  # a damaged database
        return False
    return px4_topic(topic, msgtype) or mavros_topic(topic, msgtype) is not None


class Rosbag2Source(DatabaseSalvage):
    """A ROS 2 bag, either storage, or one of its data files given on its own."""

    format = "rosbag2-sqlite3"

    # -- opening -----------------------------------------------------------------------------

    def _open_whole(self) -> Any:
        """A bag folder whose metadata.yaml or data files are at fault is read file by file
        (``_salvage_plan``): None, with ``_files`` set; else rosbags' reader of it, open."""
        if self.path.is_dir():
            fault = ros2_metadata.fault(self.path, self._data_files(self.path))
            if fault is not None:
                self._salvage_plan(ValueError(fault), fault)
                return None
        try:
            reader = StorageReader(self.path)
            reader.open()
        except Exception as exc:
            self._salvage_plan(exc)
            return None
        if self.path.is_dir() and not all(map(_well_formed, reader.connections)):
            # rosbags takes metadata.yaml's values as they come; the data files name and count
            # their topics themselves.
            with suppress(Exception):
                reader.close()
            fault = "metadata.yaml: a topic's name, type or message count is malformed"
            self._salvage_plan(ValueError(fault), fault)
            return None
        unlisted = self._unlisted_topics(reader) if self.path.is_dir() else []
        if unlisted:
            with suppress(Exception):
                reader.close()
            # One of the two is damaged: a topic renamed in the database reads the same as a
            # metadata.yaml from another bag, so the data files are read but not vouched for.
            fault = (
                f"metadata.yaml does not list {some(unlisted)}, which the data files hold "
                "(one of them is damaged or from another recording)"
            )
            self._salvage_plan(ValueError(fault), fault, lost=True)
            return None
        return reader

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
                raise SourceError(self.path, f"not a readable ROS 2 bag ({fault or why(exc)})")
            fault = fault or f"metadata.yaml cannot be used ({why(exc)})"
        else:
            for path in listed:
                if not path.is_file():
                    what = "data file listed in metadata.yaml is missing"
                    self.problems.append(SourceProblem(what, path.name))
            files = [path for path in listed if path.is_file()]
            if not files:
                raise SourceError(self.path, "none of the bag's data files exist")
        if fault is not None:
            names = some([path.name for path in files])
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

    # -- what the data files say against metadata.yaml ---------------------------------------

    def _start(self, reader: Any) -> int:
        return self._data_time(reader) if self.path.is_dir() else int(reader.start_time)

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

    def _unreachable(self, reader: Any, where: Path, short: bool) -> bool:
        """Message rows of the bag's databases that no reading by topic reaches, each kind
        said in one line (OFB001): rows whose topic id the topics table lacks, and rows
        missing between the first id and the last. True when there are any. The rows' topic
        ids are scanned only where the counts leave room for such rows: the reading fell
        ``short`` of the topics' counts, or the tables hold more rows than the topics count."""
        files = [path for path in self._data_files(where) if storage_of(path) == "sqlite3"]
        counted = {path: sqlite_rows(path) for path in files}
        found = False
        for path, rows in counted.items():
            if rows is not None and rows.missing:
                found = True
                what = (
                    f"{rows.missing} of the {rows.last_id} message rows are missing from the "
                    f"database (ids absent between 1 and {rows.last_id}: deleted or lost)"
                )
                self.problems.append(SourceProblem(what, self._column(path, where, "id")))
        held = sum(rows.held for rows in counted.values() if rows is not None)
        if not files or (not short and held == sum(c.msgcount for c in reader.connections)):
            return found
        for path in files:
            lacking = sqlite_dangling(path)
            if lacking:
                column = self._column(path, where, "topic_id")
                self.problems.append(dangling_rows(lacking, column))
                found = True
        return found

    def _held(self, where: Path, topics: set[tuple[str, str]]) -> int | None:
        return ros2_metadata.held_messages(self._data_files(where), topics)

    def _short_of(self, reader: Any, where: Path) -> int | None:
        """How many ns before metadata.yaml's end the data files' last message is (0 or more),
        where the two agree on the start (not another bag's metadata.yaml); else None."""
        if not where.is_dir():
            return None
        span = ros2_metadata.data_span(self._data_files(where))
        if span is None or span[0] != reader.start_time:
            return None
        return max(0, int(reader.end_time - 1 - span[1]))
