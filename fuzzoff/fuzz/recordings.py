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
from fuzzoff.formats.registry import BY_NAME, FORMATS, written_for
from fuzzoff.fuzz.scenario import TRANSPORTS, Scenario
from fuzzoff.recording import RecordingInfo, path_text

FORMATS_FOR: dict[str, tuple[str, ...]] = {
    t: tuple(f.name for f in written_for(t)) for t in TRANSPORTS
}

SUFFIX: dict[str, str] = {f.name: f.written_suffix for f in FORMATS}


def write(scenario: Scenario, path: Path, fmt: str) -> Path:
    """Write the scenario's events as ``fmt`` at ``path`` (a folder for rosbag2)."""
    if fmt not in BY_NAME:
        raise ValueError(f"no writer for {fmt!r}")
    return BY_NAME[fmt].write(path, list(scenario.events), scenario.px4)


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
