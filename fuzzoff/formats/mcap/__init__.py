"""ROS 2 MCAP files: reader, damage checks, indexed and streaming paths, time order, writer."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

from fuzzoff.formats.format import Format
from fuzzoff.formats.ros2.storage import MCAP_MAGIC

MAGIC = MCAP_MAGIC


def _detect(path: Path, head: bytes) -> str | None:
    """An MCAP beside a metadata.yaml is a ROS 2 bag's data file: the rosbag2 entry's."""
    if head.startswith(MAGIC) and not path.parent.joinpath("metadata.yaml").is_file():
        return "mcap"
    return None


def release_options(px4: str | None) -> Mapping[str, Any]:
    """The px4_msgs definitions a ROS 2 recording of ``px4`` embeds (``main`` when unknown)."""
    from fuzzoff.formats.px4_msgs import release_for

    return {"release": release_for(px4) or "main"}


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
