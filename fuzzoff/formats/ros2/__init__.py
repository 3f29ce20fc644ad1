"""The ROS 2 reading core the ``mcap`` and ``rosbag2`` formats share (neither imports the other).

A ROS 2 recording is one or more data files of one storage (an MCAP file, a SQLite database).
``storage`` says which storage a file is from its content; ``reader`` reads data files through
rosbags with fuzzoff's own per-connection decoding (``formats/ros2msgs``), and holds the reader
both formats subclass (``Ros2Source``); ``mcap_check``, ``mcap_indexed`` and ``mcap_stream``
check, index and stream an MCAP file where rosbags falls short; ``order`` puts a salvage's
events back in time order; ``clock`` dates an MCAP file.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any


def release_options(px4: str | None) -> Mapping[str, Any]:
    """The px4_msgs definitions a ROS 2 recording of ``px4`` embeds (``main`` when unknown): the
    writer options of both ROS 2 formats."""
    from fuzzoff.formats.px4_msgs import release_for

    return {"release": release_for(px4) or "main"}
