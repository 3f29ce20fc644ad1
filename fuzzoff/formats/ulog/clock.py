"""When a ULog started on the wall clock: its timestamps count from boot, so the first GPS fix's
``time_utc_usec``."""

from __future__ import annotations

from pathlib import Path

GPS_TOPICS = ["vehicle_gps_position", "sensor_gps"]


def start_s(path: Path) -> float | None:
    from pyulog import ULog

    ulog = ULog(str(path), GPS_TOPICS, True)
    for data in ulog.data_list:
        times = data.data.get("time_utc_usec")
        if times is None:
            continue
        valid = times[times > 0]
        if len(valid):
            return float(valid[0]) / 1e6
    return None
