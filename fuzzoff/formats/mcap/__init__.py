"""ROS 2 MCAP files: detection, reader and writer (the reading core, shared with ``rosbag2``, is
``formats/ros2``: damage checks, indexed and streaming paths, time order)."""

from __future__ import annotations

from pathlib import Path

from fuzzoff.formats.format import Format
from fuzzoff.formats.ros2 import release_options
from fuzzoff.formats.ros2.storage import storage_from_head


def _detect(path: Path, head: bytes) -> str | None:
    """An MCAP, whatever its name; one beside a metadata.yaml is a ROS 2 bag's data file: the
    rosbag2 entry's."""
    if storage_from_head(head) == "mcap" and not path.parent.joinpath("metadata.yaml").is_file():
        return "mcap"
    return None


FORMAT = Format(
    name="mcap",
    reader="fuzzoff.formats.mcap.reader:McapSource",
    writer="fuzzoff.formats.mcap.writer:write_mcap",
    clock="fuzzoff.formats.mcap.clock:start_s",
    detect_file=_detect,
    names=("mcap",),
    suffixes=(".mcap",),
    written_suffix=".mcap",
    transports=("ros2",),
    writer_options=release_options,
)
