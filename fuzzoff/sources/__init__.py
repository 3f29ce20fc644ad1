"""Readers, one per format, behind one ``open_source`` that detects the format from content."""

from __future__ import annotations

import importlib
import re
from pathlib import Path

from fuzzoff.sources.base import RecordingInfo, Source, SourceError, SourceProblem

READERS: dict[str, str] = {
    "tlog": "fuzzoff.sources.tlog:TlogSource",
    "ulog": "fuzzoff.sources.ulog:UlogSource",
    "mcap": "fuzzoff.sources.mcap:McapSource",
    "rosbag2-sqlite3": "fuzzoff.sources.rosbag2:Rosbag2Source",
    "rosbag2-mcap": "fuzzoff.sources.rosbag2:Rosbag2Source",
    "rosbag1": "fuzzoff.sources.rosbag1:Rosbag1Source",
}
"""Format name -> reader class; imported lazily so a run loads only the libraries it needs."""

RECORDING_SUFFIXES = (".tlog", ".ulg", ".mcap", ".bag", ".db3", ".active")
"""``.active``: a ROS 1 bag whose recorder was killed (``flight.bag.active``)."""

_MAGIC: tuple[tuple[bytes, str], ...] = (
    (b"ULog\x01\x12\x35", "ulog"),
    (b"\x89MCAP", "mcap"),
    (b"#ROSBAG V2.0", "rosbag1"),
    (b"SQLite format 3\x00", "rosbag2-sqlite3"),
)


def detect_format(path: Path) -> str:
    """The format of ``path`` from its content (a folder with metadata.yaml is a rosbag2)."""
    if path.is_dir():
        return _detect_bag_folder(path)
    try:
        with path.open("rb") as fh:
            head = fh.read(32)
    except OSError as exc:
        raise SourceError(path, f"cannot open: {exc.strerror or exc}") from None
    if not head:
        raise SourceError(path, "empty file")
    for magic, name in _MAGIC:
        if head.startswith(magic):
            if name == "mcap" and path.parent.joinpath("metadata.yaml").is_file():
                return "rosbag2-mcap"
            return name
    if len(head) >= 9 and head[8] in (0xFD, 0xFE):
        return "tlog"
    raise SourceError(path, "not a recording fuzzoff can read (no tlog, ULog, MCAP, rosbag header)")


def _detect_bag_folder(path: Path) -> str:
    meta = path / "metadata.yaml"
    if meta.is_file():
        text = meta.read_text(errors="replace")
        return "rosbag2-mcap" if "storage_identifier: mcap" in text else "rosbag2-sqlite3"
    files = sorted(p for p in path.iterdir() if p.suffix in (".db3", ".mcap"))
    if files:
        return "rosbag2-mcap" if files[0].suffix == ".mcap" else "rosbag2-sqlite3"
    raise SourceError(path, "a folder without metadata.yaml or .db3/.mcap files is not a ROS 2 bag")


_BAG_PART = re.compile(r"^(?P<stem>.+)_(?P<n>\d+)\.(?:db3|mcap)$")


def _is_bag_without_metadata(path: Path) -> bool:
    """A rosbag2 folder whose metadata.yaml was never written (the recorder crashed): rosbag2
    names its data files ``<folder>_<n>.db3|mcap``. Such a folder is one bag, not one
    recording per file; a folder of independent recordings does not follow that naming."""
    parts = [p for p in path.iterdir() if p.suffix in RECORDING_SUFFIXES]
    if not parts:
        return False
    for part in parts:
        match = _BAG_PART.match(part.name)
        if match is None or match.group("stem") != path.name:
            return False
    return True


def open_source(path: Path, fmt: str | None = None) -> Source:
    """A reader for ``path`` (not yet opened)."""
    fmt = fmt or detect_format(path)
    module_name, _, class_name = READERS[fmt].partition(":")
    try:
        module = importlib.import_module(module_name)
    except ModuleNotFoundError as exc:  # a reader not written yet is a clear error, not a crash
        raise SourceError(
            path, f"format {fmt} is recognised but not supported yet ({exc})"
        ) from None
    cls: type[Source] = getattr(module, class_name)
    source = cls(path)
    source.format = fmt
    return source


def find_recordings(path: Path) -> list[Path]:
    """The recordings in a folder, searched recursively; a ROS 2 bag folder counts as one."""
    if not path.is_dir():
        return [path]
    if (path / "metadata.yaml").is_file() or _is_bag_without_metadata(path):
        return [path]
    found: list[Path] = []
    for child in sorted(path.iterdir()):
        if child.name.startswith("."):
            continue
        if child.is_dir():
            found.extend(find_recordings(child))
        elif child.suffix in RECORDING_SUFFIXES:
            found.append(child)
    return found


__all__ = [
    "READERS",
    "RecordingInfo",
    "Source",
    "SourceError",
    "SourceProblem",
    "detect_format",
    "find_recordings",
    "open_source",
]
