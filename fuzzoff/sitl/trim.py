"""A PX4 ULog cut to the topics fuzzoff reads, so that a run's log stays under 1 MB.

pyulog loads only ``fuzzoff.formats.ulog.reader.LOADED_TOPICS`` and writes them back with
``ULog.write_ulog``: header, info, parameters and logged messages (PX4's own texts, such as
"Disarming denied: not landed") are kept, as ``corpora/real/cut.py`` does for public logs.
``vehicle_local_position``, which the 1.18 builds log at 100 Hz, is thinned to one sample per
``POSITION_MIN_S`` (fuzzoff reads it for the vertical setpoint checks and the plots, at most
10 Hz in a plain lint). A long flight (a VTOL's transition and cruise) thins PX4's fastest
estimator and controller topics (``FAST_TOPICS``, 50-250 Hz) to one sample per ``thin_s``
instead; the keep-alive, setpoint, mode and command topics are always kept whole.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from pyulog import ULog

from fuzzoff.formats.ulog.reader import LOADED_TOPICS

FAST_TOPICS = frozenset(
    {
        "vehicle_local_position",
        "vehicle_rates_setpoint",
        "vehicle_thrust_setpoint",
        "vehicle_torque_setpoint",
        "vehicle_attitude_setpoint",
    }
)
ALIGN_TOPICS = ("timesync_status",)
"""Kept beside the topics fuzzoff reads: the bridge's clock offset, 1 Hz, for ``lint --with``
(``fuzzoff.bridge``) where a log holds no time sync line."""
POSITION_MIN_S = 0.02
"""Without ``thin_s``: the slot ``vehicle_local_position`` keeps one sample of (50 Hz)."""


def _thinned(timestamps: np.ndarray, every_us: int) -> np.ndarray:
    """Indices keeping the first sample of each ``every_us`` slot (and the last sample)."""
    slots = timestamps.astype(np.int64) // every_us
    keep = np.flatnonzero(np.diff(slots, prepend=-1) != 0)
    if len(timestamps) and keep[-1] != len(timestamps) - 1:
        keep = np.append(keep, len(timestamps) - 1)
    return keep


def trim(source: Path, target: Path, thin_s: float | None = None) -> Path:
    log = ULog(str(source), message_name_filter_list=[*LOADED_TOPICS, *ALIGN_TOPICS])
    topics = FAST_TOPICS if thin_s is not None else frozenset({"vehicle_local_position"})
    every_us = round((thin_s if thin_s is not None else POSITION_MIN_S) * 1e6)
    for dataset in log.data_list:
        if dataset.name in topics and len(dataset.data["timestamp"]):
            keep = _thinned(dataset.data["timestamp"], every_us)
            dataset.data = {k: v[keep] for k, v in dataset.data.items()}
    log.write_ulog(str(target))
    return target
