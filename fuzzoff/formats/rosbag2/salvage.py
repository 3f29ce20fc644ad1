"""A ROS 2 database rosbags cannot open, read row by row with Python's ``sqlite3`` (formats.md 5).

The salvage of ``rosbag2``, beside its reader as ``rosbag1/salvage.py`` is beside that one's:
on a header-fixed copy (``sqlite.SalvageCopies``), in row order, until the damage; every row
counted, rows of no topic and of a PX4 topic fuzzoff cannot decode said. Every salvage is a
problem (OFB001).
"""

from __future__ import annotations

import sqlite3
from collections.abc import Iterator
from pathlib import Path
from typing import Any

from fuzzoff.events import Event
from fuzzoff.formats.ros2.order import ChunkOrder
from fuzzoff.formats.ros2.reader import Ros2Source, why
from fuzzoff.formats.ros2msgs.decode import Decoder
from fuzzoff.formats.rosbag2.sqlite import SQLITE_ERRORS, SalvageCopies
from fuzzoff.formats.rosbag2.sqlite import topics as sqlite_topics
from fuzzoff.recording import SourceProblem


def some(names: list[str]) -> str:
    """The first three names, and how many more."""
    more = f" and {len(names) - 3} more" if len(names) > 3 else ""
    return ", ".join(names[:3]) + more


def dangling_rows(lacking: dict[Any, int], where: str) -> SourceProblem:
    """Rows naming topic ids the topics table lacks (id -> rows): no topic says how to read
    them, and rosbags' reading by topic never meets them."""
    n = sum(lacking.values())
    rows = f"{n} message rows name" if n > 1 else "1 message row names"
    ids = some([repr(ident) if isinstance(ident, str) else str(ident) for ident in lacking])
    return SourceProblem(f"{rows} a topic id the topics table lacks ({ids}): not read", where)


class DatabaseSalvage(Ros2Source):
    """``Ros2Source`` that reads a database rosbags cannot open row by row."""

    def __init__(self, path: Path) -> None:
        super().__init__(path)
        self._copies = SalvageCopies()

    def _probe_unopened(self, path: Path) -> int | None:
        """Topics, definitions and start time (ns) of a database rosbags cannot open."""
        try:
            db = self._copies.connect(path)
        except (*SQLITE_ERRORS, OSError):
            return None
        try:
            topics, _ = self._sqlite_topics(db)
            for topic_id, decoder in topics.items():
                if decoder is None:
                    continue
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

    def _salvage_database(self, path: Path, exc: BaseException) -> Iterator[Event]:
        """Row by row with Python's sqlite3, in row order, until the damage (formats.md 5)."""
        try:
            db = self._copies.connect(path)
        except (*SQLITE_ERRORS, OSError) as err:
            what = f"cannot open the database: {why(err)}"
            self.problems.append(SourceProblem(what, path.name))
            return
        yield from self._salvage_rows(db, path, exc)

    def _salvage_rows(
        self, db: sqlite3.Connection, path: Path, exc: BaseException
    ) -> Iterator[Event]:
        count = 0
        lacking: dict[Any, int] = {}
        try:
            topics, unknown = self._sqlite_topics(db)
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
                        if topic_id in unknown:
                            self.decoding.count_unread(*unknown[topic_id], 1)
                        elif topic_id not in topics:
                            lacking[topic_id] = lacking.get(topic_id, 0) + 1
                        continue
                    event = decoder.event(raw, (stamp - t0) / 1e9)
                    if event is not None:
                        yield from order.add(stamp, event)
            finally:
                yield from order.flush()
        except SQLITE_ERRORS as err:
            self.problems.append(
                SourceProblem(
                    f"database damaged ({why(err)}): read row by row up to the damage, "
                    "nothing after it",
                    f"{path.name} after {count} messages",
                )
            )
        else:
            self.problems.append(
                SourceProblem(
                    f"rosbags cannot read this database ({why(exc)}); it was read row by "
                    f"row with sqlite3 ({count} rows)",
                    path.name,
                )
            )
        finally:
            self._messages += count
            db.close()
        if lacking:
            self.problems.append(dangling_rows(lacking, self._column(path, path, "topic_id")))

    def _sqlite_topics(
        self, db: sqlite3.Connection
    ) -> tuple[dict[Any, Decoder | None], dict[Any, tuple[str, str]]]:
        """Topic id -> its decoder (None: a topic fuzzoff does not read), and the PX4 topics
        of a type it cannot decode (whose rows are counted as not read)."""
        out: dict[Any, Decoder | None] = {}
        unknown: dict[Any, tuple[str, str]] = {}
        for topic_id, name, msgtype, text, fmt in sqlite_topics(db):
            out[topic_id] = decoder = self._connect(name, msgtype, text, fmt)
            if decoder is None and (name, msgtype) in self.decoding.unknown:
                unknown[topic_id] = (name, msgtype)
        return out, unknown

    def _column(self, path: Path, where: Path, column: str) -> str:
        """``messages.COLUMN``, in the data file's name when a bag folder is read."""
        return f"messages.{column}" + ("" if path == self.path else f" in {path.name}")

    def close(self) -> None:
        self._copies.close()
        super().close()
