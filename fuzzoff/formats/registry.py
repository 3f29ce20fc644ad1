"""The formats fuzzoff reads and writes, each registered once (add a format here).

In the order the folder search lists their file names. Detection asks every format but the
fallback ones (a tlog, which has no header) first; no two of the others claim the same file.
"""

from __future__ import annotations

from fuzzoff.formats import mcap, rosbag1, rosbag2, tlog, ulog
from fuzzoff.formats.format import Format, Transport

FORMATS: tuple[Format, ...] = (
    tlog.FORMAT,
    ulog.FORMAT,
    mcap.FORMAT,
    rosbag1.FORMAT,
    rosbag2.FORMAT,
)

DETECTION_ORDER: tuple[Format, ...] = tuple(
    sorted(FORMATS, key=lambda f: f.fallback)  # stable: the fallback ones last
)

FOLDER_FORMATS: tuple[Format, ...] = tuple(f for f in FORMATS if f.is_folder is not None)
"""The formats a folder can be one recording of (a ROS 2 bag)."""

BY_NAME: dict[str, Format] = {f.name: f for f in FORMATS}
"""Package name -> format (``rosbag2``)."""

BY_REPORTED_NAME: dict[str, Format] = {name: f for f in FORMATS for name in f.names}
"""Every name a recording is reported under (``rosbag2-sqlite3``) -> its format."""

RECORDING_SUFFIXES: tuple[str, ...] = tuple(f.suffixes[0] for f in FORMATS) + tuple(
    s for f in FORMATS for s in f.suffixes[1:]
)
"""The file names a folder search takes, the usual one of each format first."""


def written_for(transport: Transport) -> tuple[Format, ...]:
    """The formats a stream of ``transport`` is written to, the one a reproducer keeps first."""
    return tuple(f for f in FORMATS if transport in f.transports)


def reported_names(transport: Transport) -> frozenset[str]:
    """The names recordings holding a ``transport`` stream are reported under."""
    return frozenset(name for f in written_for(transport) for name in f.names)
