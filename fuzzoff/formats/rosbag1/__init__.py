"""ROS 1 bags of MAVROS topics: reader, index checks, chunkwise and salvage reads, writer."""

from __future__ import annotations

from pathlib import Path

from fuzzoff.formats.format import Format

MAGIC = b"#ROSBAG V2.0"


def _detect(path: Path, head: bytes) -> str | None:
    return "rosbag1" if head.startswith(MAGIC) else None


FORMAT = Format(
    name="rosbag1",
    reader="fuzzoff.formats.rosbag1.reader:Rosbag1Source",
    writer="fuzzoff.formats.rosbag1.writer:write_rosbag1",
    clock="fuzzoff.formats.rosbag1.clock:start_s",
    detect_file=_detect,
    names=("rosbag1",),
    suffixes=(".bag", ".active"),
    written_suffix=".bag",
    transports=("mavros",),
)
"""``.active``: a ROS 1 bag whose recorder was killed (``flight.bag.active``)."""
