"""When a ROS 2 bag started on the wall clock: rosbags' start time (Unix nanoseconds)."""

from __future__ import annotations

from pathlib import Path

from fuzzoff.formats.ros2.clock import mcap_start_s
from fuzzoff.formats.ros2.storage import storage_of


def start_s(path: Path) -> float | None:
    from rosbags.rosbag2 import Reader

    folder = path if path.is_dir() else path.parent
    if not (folder / "metadata.yaml").is_file():  # a data file given alone
        return mcap_start_s(path) if storage_of(path) == "mcap" else None
    with Reader(folder) as reader:
        return reader.start_time / 1e9 if reader.message_count else None
