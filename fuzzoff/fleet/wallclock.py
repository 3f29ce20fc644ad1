"""When a recording started, in UTC, where the recording says (for the fleet table's weeks).

Each format keeps a wall clock somewhere else: a tlog stamps every record with the ground
station's Unix time, MCAP and ROS bags log receive times in Unix nanoseconds, and a ULog's
timestamps count from boot, so its wall clock is the first GPS fix's ``time_utc_usec``. Each
format's ``clock`` module reads it with the format's own library, header or first messages only
where they allow it.
"""

from __future__ import annotations

import math
from datetime import UTC, datetime
from pathlib import Path

from fuzzoff.formats.registry import BY_REPORTED_NAME

EARLIEST = datetime(2000, 1, 1, tzinfo=UTC)
"""Before this a clock was not set (a companion without NTP stamps 1970 + uptime)."""


def start_time(path: Path, fmt: str) -> datetime | None:
    """The recording's first wall-clock time, or None where it has none (or it cannot be
    read: the lint reports that)."""
    entry = BY_REPORTED_NAME.get(fmt)
    if entry is None:
        return None
    try:
        seconds = entry.start_s(path)
    except Exception:  # a damaged file: the lint's own reader says what is wrong
        return None
    if seconds is None or not math.isfinite(seconds):
        return None
    try:
        when = datetime.fromtimestamp(seconds, UTC)
    except (OverflowError, OSError, ValueError):
        return None
    return when if when >= EARLIEST else None
