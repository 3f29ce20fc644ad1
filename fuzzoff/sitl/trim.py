"""A PX4 ULog cut to the topics fuzzoff reads, so that a run's log stays under 1 MB.

pyulog loads only ``fuzzoff.formats.ulog.reader.LOADED_TOPICS`` and writes them back with
``ULog.write_ulog``: header, info, parameters and logged messages (PX4's own texts, such as
"Disarming denied: not landed") are kept, as ``corpora/real/cut.py`` does for public logs.
``vehicle_local_position``, which the 1.18 builds log at 100 Hz, is thinned to one sample per
``POSITION_MIN_S`` (fuzzoff reads it for the vertical setpoint checks and the plots, at most
10 Hz in a plain lint).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from pyulog import ULog

from fuzzoff.formats.ulog.reader import LOADED_TOPICS

POSITION_MIN_S = 0.02
"""The shortest interval kept between two ``vehicle_local_position`` samples (50 Hz)."""


def trim(source: Path, target: Path) -> Path:
    log = ULog(str(source), message_name_filter_list=list(LOADED_TOPICS))
    for data in log.data_list:
        if data.name == "vehicle_local_position":
            keep = _thinned(data.data["timestamp"], round(POSITION_MIN_S * 1e6))
            data.data = {name: values[keep] for name, values in data.data.items()}
    log.write_ulog(str(target))
    return target


def _thinned(timestamps: np.ndarray, min_us: int) -> np.ndarray:
    """Indices of the samples kept: each at least ``min_us`` after the previous kept one."""
    keep: list[int] = []
    last = None
    for i, ts in enumerate(timestamps.tolist()):
        if last is None or ts - last >= min_us:
            keep.append(i)
            last = ts
    return np.asarray(keep, dtype=np.int64)
