"""ROS 2 bag folders (sqlite3 or MCAP storage): reader, metadata.yaml checks, salvage, writer."""

from __future__ import annotations

import os
import re
from pathlib import Path

from fuzzoff.formats.format import Format
from fuzzoff.formats.ros2 import release_options
from fuzzoff.formats.ros2.storage import data_files, storage_from_head, storage_of
from fuzzoff.recording import SourceError


def _detect(path: Path, head: bytes) -> str | None:
    """A SQLite database given on its own, or an MCAP beside a metadata.yaml (a bag's data
    file), whatever their names."""
    storage = storage_from_head(head)
    if storage == "sqlite3":
        return "rosbag2-sqlite3"
    if storage == "mcap" and path.parent.joinpath("metadata.yaml").is_file():
        return "rosbag2-mcap"
    return None


def detect_folder(path: Path) -> str:
    """The storage of a bag folder: its data files say it (metadata.yaml may be missing, cut
    short or another bag's); metadata.yaml only where they do not (file-compressed data)."""
    storages = {storage_of(p) for p in data_files(path)}
    if storages == {"mcap"}:
        return "rosbag2-mcap"
    if storages == {"sqlite3"}:
        return "rosbag2-sqlite3"
    meta = path / "metadata.yaml"
    if meta.is_file():
        text = meta.read_text(errors="replace")
        return "rosbag2-mcap" if "storage_identifier: mcap" in text else "rosbag2-sqlite3"
    if storages:
        return "rosbag2-sqlite3"
    raise SourceError(path, "a folder without metadata.yaml or .db3/.mcap files is not a ROS 2 bag")


_BAG_PART = re.compile(r"^(?P<stem>.+)_(?P<n>\d+)\.(?:db3|mcap)(?:\.active)?$", re.IGNORECASE)


def is_bag_folder(path: Path, suffixes: tuple[str, ...]) -> bool:
    """A folder that is one ROS 2 bag (with its metadata.yaml, whatever state that is in, or a
    bag whose recorder crashed before writing it), not a folder of recordings to search;
    ``suffixes``: the names of recordings a search takes."""
    return os.path.lexists(path / "metadata.yaml") or _is_bag_without_metadata(path, suffixes)


def _is_bag_without_metadata(path: Path, suffixes: tuple[str, ...]) -> bool:
    """A rosbag2 folder whose metadata.yaml was never written (the recorder crashed): rosbag2
    names its data files ``<folder>_<n>.db3|mcap``. Such a folder is one bag, not one
    recording per file; a folder of independent recordings does not follow that naming."""
    parts = [p for p in path.iterdir() if p.suffix.lower() in suffixes]
    if not parts:
        return False
    for part in parts:
        match = _BAG_PART.match(part.name)
        if match is None or match.group("stem") != path.name:
            return False
    return True


FORMAT = Format(
    name="rosbag2",
    reader="fuzzoff.formats.rosbag2.reader:Rosbag2Source",
    writer="fuzzoff.formats.rosbag2.writer:write_rosbag2",
    clock="fuzzoff.formats.rosbag2.clock:start_s",
    detect_file=_detect,
    names=("rosbag2-sqlite3", "rosbag2-mcap"),
    suffixes=(".db3",),
    written_suffix="",
    transports=("ros2",),
    is_folder=is_bag_folder,
    detect_folder=detect_folder,
    writer_options=release_options,
)
