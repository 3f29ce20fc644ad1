"""When a recording started, in UTC, where the recording says (for the fleet table's weeks).

Each format keeps a wall clock somewhere else: a tlog stamps every record with the ground
station's Unix time, MCAP and ROS bags log receive times in Unix nanoseconds, and a ULog's
timestamps count from boot, so its wall clock is the first GPS fix's ``time_utc_usec``. Read
with the formats' own libraries, header or first messages only where they allow it.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

EARLIEST = datetime(2000, 1, 1, tzinfo=UTC)
"""Before this a clock was not set (a companion without NTP stamps 1970 + uptime)."""


def start_time(path: Path, fmt: str) -> datetime | None:
    """The recording's first wall-clock time, or None where it has none (or it cannot be
    read: the lint reports that)."""
    probe = _PROBES.get(fmt)
    if probe is None:
        return None
    try:
        seconds = probe(path)
    except Exception:  # a damaged file: the lint's own reader says what is wrong
        return None
    if seconds is None or not math.isfinite(seconds):
        return None
    try:
        when = datetime.fromtimestamp(seconds, UTC)
    except (OverflowError, OSError, ValueError):
        return None
    return when if when >= EARLIEST else None


def _mcap(path: Path) -> float | None:
    from mcap.reader import make_reader

    with path.open("rb") as fh:
        reader = make_reader(fh)
        summary = reader.get_summary()
        if summary is not None and summary.statistics is not None:
            if summary.statistics.message_count:
                return summary.statistics.message_start_time / 1e9
            return None
        for _schema, _channel, message in reader.iter_messages(log_time_order=False):
            return float(message.log_time) / 1e9
    return None


def _rosbag2(path: Path) -> float | None:
    from rosbags.rosbag2 import Reader

    folder = path if path.is_dir() else path.parent
    if not (folder / "metadata.yaml").is_file():  # a data file given alone
        return _mcap(path) if path.suffix.lower() == ".mcap" else None
    with Reader(folder) as reader:
        return reader.start_time / 1e9 if reader.message_count else None


def _rosbag1(path: Path) -> float | None:
    from rosbags.rosbag1 import Reader

    with Reader(path) as reader:
        return reader.start_time / 1e9 if reader.message_count else None


def _tlog(path: Path) -> float | None:
    from pymavlink import mavutil

    log: Any = mavutil.mavlink_connection(str(path), robust_parsing=True)
    try:
        msg = log.recv_msg()
        return None if msg is None else float(msg._timestamp)
    finally:
        log.close()


ULOG_GPS_TOPICS = ["vehicle_gps_position", "sensor_gps"]


def _ulog(path: Path) -> float | None:
    from pyulog import ULog

    ulog = ULog(str(path), ULOG_GPS_TOPICS, True)
    for data in ulog.data_list:
        times = data.data.get("time_utc_usec")
        if times is None:
            continue
        valid = times[times > 0]
        if len(valid):
            return float(valid[0]) / 1e6
    return None


_PROBES: dict[str, Callable[[Path], float | None]] = {
    "mcap": _mcap,
    "rosbag2-mcap": _rosbag2,
    "rosbag2-sqlite3": _rosbag2,
    "rosbag1": _rosbag1,
    "tlog": _tlog,
    "ulog": _ulog,
}
