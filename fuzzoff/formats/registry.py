"""The formats fuzzoff reads and writes, each registered once (add a format here).

The order is detection's: a file goes to the first format whose ``detect_file`` names it, so
a ROS 2 bag's MCAP data file is claimed by ``rosbag2`` before ``mcap``, and a tlog (which has
no header, only a likely first packet) comes last.
"""

from __future__ import annotations

from fuzzoff.formats import mcap, rosbag1, rosbag2, tlog, ulog
from fuzzoff.formats.format import Format, Transport

FORMATS: tuple[Format, ...] = (
    ulog.FORMAT,
    rosbag2.FORMAT,
    mcap.FORMAT,
    rosbag1.FORMAT,
    tlog.FORMAT,
)

BY_NAME: dict[str, Format] = {f.name: f for f in FORMATS}
"""Package name -> format (``rosbag2``)."""

BY_REPORTED_NAME: dict[str, Format] = {name: f for f in FORMATS for name in f.names}
"""Every name a recording is reported under (``rosbag2-sqlite3``) -> its format."""

_SEARCH_ORDER = (tlog.FORMAT, ulog.FORMAT, mcap.FORMAT, rosbag1.FORMAT, rosbag2.FORMAT)

RECORDING_SUFFIXES: tuple[str, ...] = tuple(f.suffixes[0] for f in _SEARCH_ORDER) + tuple(
    s for f in _SEARCH_ORDER for s in f.suffixes[1:]
)
"""The file names a folder search takes, the usual one of each format first."""


def written_for(transport: Transport) -> tuple[Format, ...]:
    """The formats a stream of ``transport`` is written to, the one a reproducer keeps first."""
    return tuple(f for f in _SEARCH_ORDER if transport in f.transports)


def reported_names(transport: Transport) -> frozenset[str]:
    """The names recordings holding a ``transport`` stream are reported under."""
    return frozenset(name for f in written_for(transport) for name in f.names)
