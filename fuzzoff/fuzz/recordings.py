"""Scenarios to recordings through the real writers (``formats/<name>/writer.py``), and back.

``FORMATS_FOR`` lists the formats each transport's stream can be written to: ROS 2 direct ->
MCAP and a rosbag2 (sqlite3) bag; MAVLink -> tlog; MAVROS -> ROS 1 bag. ULog is left out: it is
the vehicle's own log, so its events are the vehicle's copies (``origin="vehicle"``, uORB
names), not the sent stream, by design of the format.
"""

from __future__ import annotations

from pathlib import Path

from fuzzoff.events import Event
from fuzzoff.formats import open_source
from fuzzoff.formats.ros2msgs.px4_msgs import release_for
from fuzzoff.fuzz.scenario import Scenario
from fuzzoff.recording import RecordingInfo, path_text

FORMATS_FOR: dict[str, tuple[str, ...]] = {
    "ros2": ("mcap", "rosbag2"),
    "mavlink": ("tlog",),
    "mavros": ("rosbag1",),
}

SUFFIX = {"mcap": ".mcap", "rosbag2": "", "tlog": ".tlog", "rosbag1": ".bag"}


def release(scenario: Scenario) -> str:
    """The px4_msgs release whose definitions a ROS 2 recording of the scenario embeds."""
    return release_for(scenario.px4) or "main"


def write(scenario: Scenario, path: Path, fmt: str) -> Path:
    """Write the scenario's events as ``fmt`` at ``path`` (a folder for rosbag2)."""
    events = list(scenario.events)
    if fmt == "mcap":
        from fuzzoff.formats.mcap.writer import write_mcap

        return write_mcap(path, events, release=release(scenario))
    if fmt == "rosbag2":
        from fuzzoff.formats.rosbag2.writer import write_rosbag2

        return write_rosbag2(path, events, release=release(scenario))
    if fmt == "tlog":
        from fuzzoff.formats.tlog.writer import write_tlog

        return write_tlog(path, events)
    if fmt == "rosbag1":
        from fuzzoff.formats.rosbag1.writer import write_rosbag1

        return write_rosbag1(path, events)
    raise ValueError(f"no writer for {fmt!r}")


def read(path: Path) -> list[Event]:
    """Every event a reader gives back for ``path`` (raises ``SourceError`` if unreadable)."""
    return read_with_info(path)[0]


def read_with_info(path: Path) -> tuple[list[Event], RecordingInfo, list[str]]:
    """The events, what the reader says about the recording (PX4 version, vehicle type) and
    the parts it could not read, one line each as ``fuzzoff lint`` gives them (the events are
    those before the first such part)."""
    source = open_source(path)
    source.open()
    try:
        info = source.probe()
        events = list(source.events())
    finally:
        source.close()
    return events, info, [problem.line(path_text(path)) for problem in source.problems]
