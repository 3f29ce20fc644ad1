"""What a ROS 2 bag's ``metadata.yaml`` gets wrong about its data files (formats.md 5, issue 19).

The data files are the source of truth: each ``.db3`` names its topics and holds its messages
with their times, each ``.mcap`` too. ``metadata.yaml`` is a summary rosbag2 writes when the
recording ends; a crash leaves none, an edit or a copy from another bag leaves a wrong one.
rosbags trusts it (its storage, its compression, its start time), so a metadata.yaml it refuses
used to be read past in silence, and one from another bag shifted every time. Here it is judged
against the data files; the reader then goes by the data files and says which it used.
"""

from __future__ import annotations

import sqlite3
import stat
from pathlib import Path
from typing import Any

from mcap.reader import SeekingReader
from ruamel.yaml import YAML

from fuzzoff.formats.ros2.storage import SUFFIX, storage_of

VERSIONS = range(1, 10)
"""metadata.yaml versions rosbag2 has written (Ardent to Rolling)."""
REQUIRED = (
    "version",
    "storage_identifier",
    "relative_file_paths",
    "duration",
    "starting_time",
    "message_count",
    "topics_with_message_count",
)
ZSTD_MAGIC = b"\x28\xb5\x2f\xfd"


def fault(folder: Path, files: list[Path]) -> str | None:
    """What ``folder/metadata.yaml`` gets wrong about the data ``files``, in a few words, or
    None when it is a readable description of them."""
    meta = folder / "metadata.yaml"
    try:
        mode = meta.stat().st_mode
    except FileNotFoundError:
        return "metadata.yaml is missing"
    except OSError as exc:
        return f"metadata.yaml cannot be read ({exc.strerror or exc})"
    if not stat.S_ISREG(mode):
        kind = "a folder" if stat.S_ISDIR(mode) else "not a regular file"
        return f"metadata.yaml is not a file ({kind})"
    try:
        data = YAML(typ="safe").load(meta.read_text(encoding="utf-8"))
    except Exception as exc:  # ruamel's errors, UnicodeDecodeError, OSError
        return f"metadata.yaml is not readable YAML ({type(exc).__name__}; cut short?)"
    info = data.get("rosbag2_bagfile_information") if isinstance(data, dict) else None
    if not isinstance(info, dict):
        return "metadata.yaml has no rosbag2_bagfile_information"
    missing = [key for key in REQUIRED if key not in info]
    if missing:
        return f"metadata.yaml lacks {', '.join(missing)} (cut short?)"
    version = info["version"]
    if not isinstance(version, int) or isinstance(version, bool) or version not in VERSIONS:
        return f"metadata.yaml says version {_shown(version)}; rosbag2 writes 1 to 9"
    names = info["relative_file_paths"]
    if not isinstance(names, list) or not all(isinstance(name, str) for name in names):
        return "metadata.yaml's relative_file_paths is not a list of file names"
    return _storage_fault(info, files) or _compression_fault(info, files)


def _storage_fault(info: dict[str, Any], files: list[Path]) -> str | None:
    storage = info["storage_identifier"]
    kinds = sorted({SUFFIX[kind] for path in files if (kind := storage_of(path)) is not None})
    if storage not in SUFFIX:
        return f"metadata.yaml names the storage {_shown(storage)}, which rosbag2 does not have"
    if kinds and kinds != [SUFFIX[storage]]:
        held = " and ".join(kinds)
        return f"metadata.yaml names the storage {_shown(storage)}, but the data files are {held}"
    return None


def _compression_fault(info: dict[str, Any], files: list[Path]) -> str | None:
    mode = str(info.get("compression_mode") or "").lower()
    form = info.get("compression_format") or ""
    if mode in ("", "none"):
        return None
    if mode not in ("file", "message"):
        return f"metadata.yaml names the compression mode {_shown(mode)}, which rosbag2 lacks"
    if form != "zstd":
        return f"metadata.yaml names the compression {_shown(form)}; rosbag2 compresses with zstd"
    if mode == "file" and files and not _starts_with(files[0], ZSTD_MAGIC):
        return "metadata.yaml says the data files are zstd-compressed, but they are not"
    return None


def _starts_with(path: Path, magic: bytes) -> bool:
    try:
        with path.open("rb") as fh:
            return fh.read(len(magic)) == magic
    except OSError:
        return False


def _shown(value: Any) -> str:
    text = repr(value)
    return text if len(text) <= 32 else text[:31] + "…"


Span = tuple[int, int]
"""The first and the last message time, in ns."""


def data_span(files: list[Path]) -> Span | None:
    """The first and last message times in the data files, from their own indexes (a
    database's timestamp index, an MCAP's statistics); None where a file cannot say cheaply."""
    spans = []
    for path in files:
        span = _sqlite_span(path) if storage_of(path) == "sqlite3" else _mcap_span(path)
        if span is None:
            return None
        if span[0] <= span[1]:
            spans.append(span)
    if not spans:
        return None
    return min(a for a, _ in spans), max(b for _, b in spans)


_EMPTY: Span = (1, 0)


def _sqlite_span(path: Path) -> Span | None:
    """Each bound alone, as SQLite answers it from the timestamp index without a scan; a
    bound that is not an integer (SQLite sorts text and blobs after numbers) only then
    through the scan that leaves such rows out."""
    try:
        db = sqlite3.connect(f"file:{path}?mode=ro", uri=True)
        try:
            low = db.execute("SELECT MIN(timestamp) FROM messages").fetchone()[0]
            high = db.execute("SELECT MAX(timestamp) FROM messages").fetchone()[0]
            if low is None:
                return _EMPTY
            if type(low) is not int or type(high) is not int:
                low, high = db.execute(
                    "SELECT MIN(timestamp), MAX(timestamp) FROM messages "
                    "WHERE typeof(timestamp) = 'integer'"
                ).fetchone()
        finally:
            db.close()
    except (sqlite3.Error, UnicodeDecodeError, MemoryError):
        return None
    return (int(low), int(high)) if low is not None else _EMPTY


def _mcap_span(path: Path) -> Span | None:
    try:
        with path.open("rb") as fh:
            summary = SeekingReader(fh, record_size_limit=path.stat().st_size).get_summary()
    except Exception:  # no usable summary: the reader finds out what is wrong
        return None
    if summary is None or summary.statistics is None:
        return None
    stats = summary.statistics
    if not stats.message_count:
        return _EMPTY
    return int(stats.message_start_time), int(stats.message_end_time)


def differs(listed_ns: int, start_ns: int) -> str | None:
    """How metadata.yaml's starting time and the data's first message differ, or None. rosbag2
    writes the first message's time there, to the nanosecond."""
    gap = listed_ns - start_ns
    if gap == 0:
        return None
    span = abs(gap)
    if span >= 86_400 * 10**9:
        amount = f"{span / 86_400e9:.1f} days"
    elif span >= 10**6:
        amount = f"{span / 1e9:.3f} s"
    else:
        amount = f"{span} ns"
    way = "after" if gap > 0 else "before"
    return f"metadata.yaml's starting time is {amount} {way} the first message in the data files"


def held_messages(files: list[Path], topics: set[tuple[str, str]]) -> int | None:
    """How many messages on ``topics`` (name, type) the data files hold, counted in the data
    (a database's rows); None where only an index could say (an MCAP's statistics are part
    of the summary that may be what is damaged)."""
    total = 0
    for path in files:
        held = _sqlite_held(path, topics) if storage_of(path) == "sqlite3" else None
        if held is None:
            return None
        total += held
    return total


def _sqlite_held(path: Path, topics: set[tuple[str, str]]) -> int | None:
    try:
        db = sqlite3.connect(f"file:{path}?mode=ro", uri=True)
        try:
            rows = db.execute(
                "SELECT topics.name, topics.type, COUNT(*) FROM messages "
                "JOIN topics ON messages.topic_id = topics.id GROUP BY topics.id"
            ).fetchall()
        finally:
            db.close()
    except (sqlite3.Error, UnicodeDecodeError, MemoryError):
        return None
    return sum(int(count) for name, msgtype, count in rows if (name, msgtype) in topics)
