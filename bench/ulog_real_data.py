"""A real-shaped ten-minute PX4 ULog for the benchmark, made from a real SITL flight.

``generate_real(path)`` loads a real SITL ULog of the corpus (``corpora/sitl/``, written by
PX4's own logger) with pyulog, repeats its records end to end until the log spans ``minutes``
(each copy's timestamps moved past the previous copy's last one), and writes the result with
pyulog's own ``ULog.write_ulog``. The topics, their rates, the definition section, the logged
messages and the parameter changes are PX4's; only the length is made. Written at bench time
to ``bench/data/`` (git-ignored), reused while it exists.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
from pyulog import ULog

ROOT = Path(__file__).resolve().parent.parent
SOURCE = ROOT / "corpora" / "sitl" / "hold_with_unknown_sub_mode-1.16.2.ulg"
"""The biggest real SITL ULog of the corpus (PX4 1.16.2, a 26 s offboard flight)."""

GAP_US = 1_000_000
"""Between one copy's last record and the next copy's first."""


def _shifted(ulog: Any, copies: int, step_us: int) -> None:
    """Every record of ``ulog`` repeated ``copies`` times, copy k moved by k * step_us."""
    offsets = np.arange(copies, dtype=np.uint64) * np.uint64(step_us)
    for dataset in ulog.data_list:
        count = len(dataset.data["timestamp"])
        for name, column in list(dataset.data.items()):
            tiled = np.tile(column, copies)
            if name == "timestamp" or name == "timestamp_sample":
                tiled = tiled + np.repeat(offsets, count).astype(column.dtype)
            dataset.data[name] = tiled
    ulog.logged_messages[:] = _repeat_messages(ulog.logged_messages, copies, step_us)
    for tag, messages in ulog.logged_messages_tagged.items():
        ulog.logged_messages_tagged[tag] = _repeat_messages(messages, copies, step_us)
    ulog.changed_parameters[:] = [
        (timestamp + k * step_us, name, value)
        for k in range(copies)
        for timestamp, name, value in ulog.changed_parameters
    ]


def _repeat_messages(messages: list[Any], copies: int, step_us: int) -> list[Any]:
    repeated = []
    for k in range(copies):
        for message in messages:
            copy = object.__new__(type(message))
            for slot in ("log_level", "tag", "timestamp", "message"):
                if hasattr(message, slot):
                    setattr(copy, slot, getattr(message, slot))
            copy.timestamp = message.timestamp + k * step_us
            repeated.append(copy)
    return repeated


def generate_real(path: Path, minutes: float = 10.0, source: Path = SOURCE) -> Path:
    """Write (once) a ULog of about ``minutes`` made of ``source``'s records; returns its path."""
    if path.exists():
        return path
    ulog = ULog(str(source))
    first = min(int(d.data["timestamp"][0]) for d in ulog.data_list if len(d.data["timestamp"]))
    last = max(int(d.data["timestamp"][-1]) for d in ulog.data_list if len(d.data["timestamp"]))
    step_us = last - first + GAP_US
    copies = max(1, math.ceil(minutes * 60e6 / step_us))
    _shifted(ulog, copies, step_us)
    path.parent.mkdir(parents=True, exist_ok=True)
    partial = path.with_suffix(".partial")
    ulog.write_ulog(str(partial))
    partial.rename(path)
    return path
