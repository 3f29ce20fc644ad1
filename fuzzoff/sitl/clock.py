"""PX4's own clock, as seen from the host (SYSTEM_TIME and TIMESYNC).

PX4 SITL with SIH runs on a simulated clock that goes at 0.83-0.99 of real time on a loaded
machine, and its offboard gate times a loss on that clock (the keep-alive's receive time against
``COM_OF_LOSS_T``). A gap of 1.0 s has to be 1.0 s there, so a replay waits on an estimate of
PX4's time rather than on the host's.

PX4 stamps the TIMESYNC requests it sends about ten times a second with its boot time in
nanoseconds (``tc1`` 0, ``ts1`` its time) and SYSTEM_TIME once a second with ``time_boot_ms``.
Each gives one (host time, PX4 time) pair; a least-squares line over the last few seconds of
pairs gives PX4's time now and how fast its clock runs.
"""

from __future__ import annotations

import threading
import time
from collections import deque
from typing import Any

WINDOW_S = 3.0
"""Seconds of samples the line is fitted to: long enough to average the host's scheduling
jitter, short enough to follow a simulation whose speed changes with the machine's load."""
MIN_SPAN_S = 0.5
"""Below this spread of samples the rate is taken as 1."""


class ClockNotSynced(RuntimeError):
    """PX4's time was asked for before PX4 sent a stamped message."""


class PX4Clock:
    """PX4's boot time in seconds, estimated from stamped messages; thread-safe."""

    def __init__(self) -> None:
        self._samples: deque[tuple[float, float]] = deque()
        self._lock = threading.Lock()
        self._fit: tuple[float, float, float] | None = None
        """(host time of the fit's origin, PX4 time there, rate)."""
        self._last = 0.0

    def observe(self, msg: Any, host: float | None = None) -> None:
        """Take PX4's time from a TIMESYNC request or a SYSTEM_TIME it sent."""
        kind = msg.get_type()
        if kind == "TIMESYNC" and msg.tc1 == 0 and msg.ts1 > 0:
            px4 = msg.ts1 / 1e9
        elif kind == "SYSTEM_TIME" and msg.time_boot_ms > 0:
            px4 = msg.time_boot_ms / 1e3
        else:
            return
        self.add(time.monotonic() if host is None else host, px4)

    def add(self, host: float, px4: float) -> None:
        with self._lock:
            if self._samples and px4 < self._samples[-1][1] - 1.0:
                self._samples.clear()  # PX4 restarted
            self._samples.append((host, px4))
            while self._samples and self._samples[0][0] < host - WINDOW_S:
                self._samples.popleft()
            self._fit = _fit(list(self._samples))

    @property
    def synced(self) -> bool:
        return self._fit is not None

    @property
    def rate(self) -> float:
        """PX4 seconds per host second (1.0 before a fit)."""
        return self._fit[2] if self._fit else 1.0

    def now(self, host: float | None = None) -> float:
        """PX4's time at host time ``host`` (now), never going backwards."""
        with self._lock:
            if self._fit is None:
                raise ClockNotSynced("PX4 has sent no TIMESYNC or SYSTEM_TIME yet")
            h0, p0, rate = self._fit
            value = p0 + ((time.monotonic() if host is None else host) - h0) * rate
            self._last = max(self._last, value)
            return self._last

    def host_delay(self, px4_time: float) -> float:
        """Host seconds until PX4's clock reads ``px4_time`` (0 if it already has)."""
        return max(0.0, (px4_time - self.now()) / self.rate)


def _fit(samples: list[tuple[float, float]]) -> tuple[float, float, float]:
    host0, px40 = samples[-1]
    if len(samples) < 3 or samples[-1][0] - samples[0][0] < MIN_SPAN_S:
        return host0, px40, 1.0
    n = len(samples)
    mh = sum(h for h, _ in samples) / n
    mp = sum(p for _, p in samples) / n
    var = sum((h - mh) ** 2 for h, _ in samples)
    cov = sum((h - mh) * (p - mp) for h, p in samples)
    rate = cov / var if var > 0 else 1.0
    if not 0.05 < rate < 20.0:  # a restart or a stall: trust the newest sample
        return host0, px40, 1.0
    # Anchor at the newest sample's host time, on the fitted line.
    return host0, mp + (host0 - mh) * rate, rate
