"""Readers, one per format, behind one ``open_source`` that detects the format from content."""

from __future__ import annotations

import importlib
import os
import re
import stat
from collections.abc import Iterable, Iterator
from pathlib import Path

from fuzzoff.recording import RecordingInfo, Source, SourceError, SourceProblem

READERS: dict[str, str] = {
    "tlog": "fuzzoff.formats.tlog.reader:TlogSource",
    "ulog": "fuzzoff.formats.ulog.reader:UlogSource",
    "mcap": "fuzzoff.formats.mcap.reader:McapSource",
    "rosbag2-sqlite3": "fuzzoff.formats.rosbag2.reader:Rosbag2Source",
    "rosbag2-mcap": "fuzzoff.formats.rosbag2.reader:Rosbag2Source",
    "rosbag1": "fuzzoff.formats.rosbag1.reader:Rosbag1Source",
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
    try:
        mode = path.stat().st_mode
        if stat.S_ISDIR(mode):
            return _detect_bag_folder(path)
        if not stat.S_ISREG(mode):
            raise SourceError(path, f"{_special(mode)}, not a file: {_NEEDS_A_FILE}")
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


_NEEDS_A_FILE = "fuzzoff reads recordings from files (save a stream to one first)"


def _special(mode: int) -> str:
    if stat.S_ISFIFO(mode):
        return "a pipe"
    if stat.S_ISSOCK(mode):
        return "a socket"
    return "a device"


def _detect_bag_folder(path: Path) -> str:
    """The storage of a bag folder: its data files say it (metadata.yaml may be missing, cut
    short or another bag's); metadata.yaml only where they do not (file-compressed data)."""
    suffixes = {p.suffix for p in path.iterdir() if p.suffix in (".db3", ".mcap")}
    if suffixes == {".mcap"}:
        return "rosbag2-mcap"
    if suffixes == {".db3"}:
        return "rosbag2-sqlite3"
    meta = path / "metadata.yaml"
    if meta.is_file():
        text = meta.read_text(errors="replace")
        return "rosbag2-mcap" if "storage_identifier: mcap" in text else "rosbag2-sqlite3"
    if suffixes:
        return "rosbag2-sqlite3"
    raise SourceError(path, "a folder without metadata.yaml or .db3/.mcap files is not a ROS 2 bag")


_BAG_PART = re.compile(r"^(?P<stem>.+)_(?P<n>\d+)\.(?:db3|mcap)$")


def is_bag_folder(path: Path) -> bool:
    """A folder that is one ROS 2 bag (with its metadata.yaml, whatever state that is in, or a
    bag whose recorder crashed before writing it), not a folder of recordings to search."""
    return os.path.lexists(path / "metadata.yaml") or _is_bag_without_metadata(path)


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
    """The recordings at ``path`` (see ``recordings_in``)."""
    return recordings_in([path])


def recordings_in(paths: Iterable[Path | str]) -> list[Path]:
    """The recordings the paths name, in order: a file as given; a ROS 2 bag folder as one
    recording; any other folder searched recursively for files with a recording's suffix.

    Links are followed, but each real folder is searched once and each real file listed once:
    a link back up the tree, a second name for a folder or a path given twice cannot list a
    recording twice (nor forever). The search takes regular files only: opening a named pipe
    waits for a writer, which would hang the lint. A folder that cannot be listed is listed
    itself, so that linting it says why."""
    seen: set[object] = set()
    found: list[Path] = []
    for raw in paths:
        path = Path(raw)
        if path.is_dir():
            _search(path, seen, found)
        elif _first_time(path, seen):
            found.append(path)
    return found


def _first_time(path: Path, seen: set[object]) -> bool:
    """Is this the first time the search meets ``path``'s file or folder? Known by device and
    inode, as ``find`` does: one ``stat`` however deep the path (``resolve`` walks it)."""
    try:
        info = path.stat()
        key: object = (info.st_dev, info.st_ino)
    except OSError:  # a dangling link, a link loop: not seen through any other name
        key = str(path.absolute())
    if key in seen:
        return False
    seen.add(key)
    return True


def _search(top: Path, seen: set[object], found: list[Path]) -> None:
    """Depth first in name order, with a stack of each open folder's remaining children
    (not recursion: a folder tree deeper than Python's recursion limit is still searched)."""
    stack: list[Iterator[Path]] = []
    folder: Path | None = top
    while True:
        if folder is not None and _first_time(folder, seen):
            children = _children_to_search(folder, found)
            if children is not None:
                stack.append(iter(children))
        folder = None
        if not stack:
            return
        child = next(stack[-1], None)
        if child is None:
            stack.pop()
        elif child.is_dir():
            folder = child
        elif _has_recording_suffix(child) and child.is_file() and _first_time(child, seen):
            found.append(child)


def _has_recording_suffix(path: Path) -> bool:
    """``FLIGHT.TLOG`` too: logs copied from FAT-formatted SD cards and Windows ground stations
    often carry upper-case names."""
    return path.suffix.lower() in RECORDING_SUFFIXES


def _children_to_search(folder: Path, found: list[Path]) -> list[Path] | None:
    """The folder's children in name order, or None when the folder is a recording itself (a
    bag folder) or cannot be listed: then it goes to ``found``, and linting it says why."""
    try:
        if is_bag_folder(folder):
            found.append(folder)
            return None
        return sorted(c for c in folder.iterdir() if not c.name.startswith("."))
    except OSError:
        found.append(folder)
        return None


__all__ = [
    "READERS",
    "RecordingInfo",
    "Source",
    "SourceError",
    "SourceProblem",
    "detect_format",
    "find_recordings",
    "is_bag_folder",
    "open_source",
    "recordings_in",
]
