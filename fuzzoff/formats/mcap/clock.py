"""When an MCAP started on the wall clock (for the fleet table): the ROS 2 core's reading of its
statistics, else of its first message's log time."""

from __future__ import annotations

from pathlib import Path

from fuzzoff.formats.ros2.clock import mcap_start_s


def start_s(path: Path) -> float | None:
    return mcap_start_s(path)
