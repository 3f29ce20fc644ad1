"""Both directions of a MAVLink exchange written as one .tlog.

Every record is what pymavlink's own logger writes for a message it parsed
(``mavfile.setup_logfile``: the 8-byte big-endian microsecond time, then the packet exactly as
pymavlink framed it, ``msg.get_msgbuf()``); the messages going out are the ones pymavlink packed
for sending, caught with its send callback. Messages of a dialect pymavlink does not know keep
their bytes too (pymavlink parses them as ``UNKNOWN_<id>`` with their whole packet).

The time of a record is the autopilot's clock where it is known (``PX4Clock``), anchored at the
wall-clock time of the first record: the simulation runs slower than real time, and a recording
whose gaps are the host's would show gaps PX4 never saw. ``clock=None`` writes the host's clock.
"""

from __future__ import annotations

import struct
import threading
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any, BinaryIO

TimeSource = Callable[[], float]
"""Seconds on the clock the records are stamped with (monotonic within a recording)."""


class TlogRecorder:
    """A .tlog being written; thread-safe (the link's receiver and sender both write)."""

    def __init__(self, path: Path, clock: TimeSource | None = None) -> None:
        self.path = path
        self._file: BinaryIO = path.open("wb")
        self._lock = threading.Lock()
        self._clock = clock or time.monotonic
        self._anchor_wall = time.time()
        self._anchor: float | None = None
        self._last_us = 0
        self.count = 0

    def _usec(self) -> int:
        now = self._clock()
        if self._anchor is None:
            self._anchor = now
        usec = int((self._anchor_wall + (now - self._anchor)) * 1e6)
        # Records stay in order even if the clock estimate steps back by a little.
        usec = max(usec, self._last_us)
        self._last_us = usec
        return usec

    def write(self, msg: Any) -> None:
        """Record one pymavlink message (received or sent)."""
        if msg.get_type() == "BAD_DATA":
            return
        data = bytes(msg.get_msgbuf())
        with self._lock:
            if self._file.closed:
                return
            self._file.write(struct.pack(">Q", self._usec()) + data)
            self.count += 1

    def close(self) -> None:
        with self._lock:
            if not self._file.closed:
                self._file.close()
