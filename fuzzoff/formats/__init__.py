"""Recording formats, one package each (``fuzzoff/formats/<name>/``: reader, writer, damage
checks, detection), registered in ``registry``; ``open_source`` detects a file's format from
its content and the search finds the recordings under a folder."""

from __future__ import annotations

import stat
from collections.abc import Iterable, Iterator
from pathlib import Path

from fuzzoff.formats.format import Format
from fuzzoff.formats.registry import (
    BY_REPORTED_NAME,
    DETECTION_ORDER,
    FOLDER_FORMATS,
    RECORDING_SUFFIXES,
)
from fuzzoff.recording import RecordingInfo, Source, SourceError, SourceProblem


def detect_format(path: Path) -> str:
    """The format of ``path`` from its content (a folder: the format whose recording it is)."""
    try:
        mode = path.stat().st_mode
        if stat.S_ISDIR(mode):
            return _folder_format(path)
        if not stat.S_ISREG(mode):
            raise SourceError(path, f"{_special(mode)}, not a file: {_NEEDS_A_FILE}")
        with path.open("rb") as fh:
            head = fh.read(32)
    except OSError as exc:
        raise SourceError(path, f"cannot open: {exc.strerror or exc}") from None
    if not head:
        raise SourceError(path, "empty file")
    for fmt in DETECTION_ORDER:
        name = fmt.detect_file(path, head)
        if name is not None:
            return name
    raise SourceError(path, "not a recording fuzzoff can read (no tlog, ULog, MCAP, rosbag header)")


_NEEDS_A_FILE = "fuzzoff reads recordings from files (save a stream to one first)"


def _special(mode: int) -> str:
    if stat.S_ISFIFO(mode):
        return "a pipe"
    if stat.S_ISSOCK(mode):
        return "a socket"
    return "a device"


def is_bag_folder(path: Path) -> bool:
    """A folder that is one recording (a ROS 2 bag), not a folder of recordings to search."""
    return _claimed_by(path) is not None


def _claimed_by(folder: Path) -> Format | None:
    """The format whose recording ``folder`` is (``Format.is_folder``), or None."""
    for fmt in FOLDER_FORMATS:
        assert fmt.is_folder is not None
        if fmt.is_folder(folder, RECORDING_SUFFIXES):
            return fmt
    return None


def _folder_format(folder: Path) -> str:
    """The reported format of a folder given as one recording (``Format.detect_folder``): the
    format that claims it, else the first folder format that can read it (a bag folder whose
    metadata.yaml is gone and whose data file is not named as rosbag2 names it, given by
    itself rather than found by the search)."""
    claimed = _claimed_by(folder)
    refusal: SourceError | None = None
    for fmt in (claimed,) if claimed is not None else FOLDER_FORMATS:
        assert fmt.detect_folder is not None
        try:
            return fmt.detect_folder(folder)
        except SourceError as exc:
            refusal = refusal or exc
    raise refusal or SourceError(folder, "a folder that is no recording fuzzoff reads")


def open_source(path: Path, fmt: str | None = None) -> Source:
    """A reader for ``path`` (not yet opened)."""
    fmt = fmt or detect_format(path)
    try:
        return BY_REPORTED_NAME[fmt].open(path, fmt)
    except ModuleNotFoundError as exc:  # a reader not written yet is a clear error, not a crash
        raise SourceError(
            path, f"format {fmt} is recognised but not supported yet ({exc})"
        ) from None


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
    "RECORDING_SUFFIXES",
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
