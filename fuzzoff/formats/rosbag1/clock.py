"""When a ROS 1 bag started on the wall clock: rosbags' start time (Unix nanoseconds)."""

from __future__ import annotations

from pathlib import Path


def start_s(path: Path) -> float | None:
    from rosbags.rosbag1 import Reader

    with Reader(path) as reader:
        return reader.start_time / 1e9 if reader.message_count else None
