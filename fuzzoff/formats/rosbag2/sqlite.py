"""Reading a ``.db3`` that rosbags cannot open, with Python's ``sqlite3`` (formats.md 5).

The salvage works on a copy in a temporary folder (the user's file is never written): a
byte-truncated database has a header that still claims the missing pages, and SQLite refuses
every query on it, so the copy's header is corrected first. Rows are then read in row order
until the damage.
"""

from __future__ import annotations

import shutil
import sqlite3
import struct
import tempfile
from contextlib import closing, suppress
from pathlib import Path
from typing import Any

from fuzzoff.lean_dataclass import dataclass

ENCODINGS = {"ros2msg": "msg", "ros2idl": "idl"}


class SalvageCopies:
    """Header-fixed read-only copies of damaged databases, one per file, removed on close."""

    def __init__(self) -> None:
        self._tmp: tempfile.TemporaryDirectory[str] | None = None

    def connect(self, path: Path) -> sqlite3.Connection:
        if self._tmp is None:
            self._tmp = tempfile.TemporaryDirectory(prefix="fuzzoff-")
        copy = Path(self._tmp.name) / path.name
        if not copy.exists():
            readable_copy(path, Path(self._tmp.name))
        db = sqlite3.connect(f"file:{copy}?mode=ro", uri=True)
        db.text_factory = _lenient_text
        return db

    def close(self) -> None:
        if self._tmp is not None:
            self._tmp.cleanup()
            self._tmp = None


SQLITE_ERRORS = (sqlite3.Error, UnicodeDecodeError, MemoryError)
"""What reading a damaged database raises. Besides sqlite3's own errors: UnicodeDecodeError when
SQLite's error message quotes damaged schema bytes (Python's sqlite3 cannot decode it), and
MemoryError when a damaged record claims more bytes than SQLite will allocate (it refuses before
allocating: peak memory stays where it was)."""


def _lenient_text(raw: bytes) -> str:
    """TEXT as Python's sqlite3 reads it, but damaged UTF-8 shows U+FFFD instead of raising."""
    return raw.decode("utf-8", "replace")


def topics(db: sqlite3.Connection) -> list[tuple[int, Any, Any, str | None, str]]:
    """(topic id, name, type, embedded definition or None, its format) of every topic.

    SQLite keeps any type in any column: in a damaged database a name or type may not be text.
    """
    definitions: dict[str, tuple[str, str]] = {}
    with suppress(*SQLITE_ERRORS):  # schema 3 and older have no message_definitions
        for name, encoding, text in db.execute(
            "SELECT topic_type, encoding, encoded_message_definition FROM message_definitions"
        ):
            if encoding in ENCODINGS and text and isinstance(text, str):
                definitions[name] = (text, ENCODINGS[encoding])
    out = []
    for topic_id, name, msgtype in db.execute("SELECT id, name, type FROM topics"):
        text, fmt = definitions.get(msgtype, (None, "msg"))
        out.append((topic_id, name, msgtype, text, fmt))
    return out


@dataclass(frozen=True, slots=True)
class Rows:
    """How one database numbers its message rows."""

    held: int
    """Message rows in the table."""
    missing: int
    """Rows absent between the first id and the last: rosbag2 numbers its rows 1, 2, 3...
    and never deletes one, so a gap is rows deleted or lost."""
    last_id: int


def rows(path: Path) -> Rows | None:
    """The message table's row count and id bounds, from its b-trees (no scan of the rows);
    None where the database cannot say (it will not open: the reading says why)."""
    try:
        with closing(sqlite3.connect(f"file:{path}?mode=ro", uri=True)) as db:
            first, last, held = db.execute(
                "SELECT MIN(id), MAX(id), COUNT(*) FROM messages"
            ).fetchone()
    except SQLITE_ERRORS:
        return None
    if not (isinstance(first, int) and isinstance(last, int) and first >= 1):
        return Rows(held, 0, 0)
    return Rows(held, max(0, last - held), last)


def dangling(path: Path) -> dict[Any, int]:
    """Topic id the topics table lacks -> how many message rows name it (a scan of the rows:
    asked only when the counts say some rows belong to no topic)."""
    try:
        with closing(sqlite3.connect(f"file:{path}?mode=ro", uri=True)) as db:
            found = db.execute(
                "SELECT topic_id, COUNT(*) FROM messages WHERE topic_id NOT IN "
                "(SELECT id FROM topics) GROUP BY topic_id ORDER BY topic_id"
            ).fetchall()
    except SQLITE_ERRORS:
        return {}
    return {topic_id: int(count) for topic_id, count in found}


def readable_copy(path: Path, folder: Path) -> Path:
    """A copy of a cut database whose header no longer claims the missing pages.

    SQLite trusts the page count in the header of a cleanly closed file, so a byte-truncated
    database fails on its first query, even for pages that are all there. The copy's header
    states the pages the file really has (and rollback-journal mode, so no -wal is needed).
    """
    copy = folder / path.name
    shutil.copyfile(path, copy)
    with copy.open("r+b") as fh:
        header = fh.read(100)
        if len(header) < 100 or not header.startswith(b"SQLite format 3\x00"):
            return copy
        page_size = struct.unpack(">H", header[16:18])[0]
        page_size = 65536 if page_size == 1 else page_size
        pages = copy.stat().st_size // max(page_size, 512)
        if struct.unpack(">I", header[28:32])[0] > pages:
            fh.seek(28)
            fh.write(struct.pack(">I", pages))
        fh.seek(18)
        fh.write(b"\x01\x01")
    return copy
