"""The host's clock on PX4's: where a message the bag holds falls in PX4's ULog.

The bridge's time sync offset alone does not do it: PX4's client keeps the offset it measured
when it connected, and a simulated (or loaded) PX4 does not keep the host's pace (PX4's SITL
bundles run at 0.83-0.99 of real time here: 90 ms apart after 5 s). So the mapping is measured:
each of PX4's status outputs the bag received (``PAIR_TOPICS``) is found in the ULog by its
``timestamp`` less the offset (within ``PAIR_TOLERANCE_US``: the offset creeps by a few ms),
which pairs the host's receive time with PX4's publish time; a line through those pairs is the
clock (PX4 time = a + b x host time). PX4's outputs reach the bag within milliseconds over
loopback, which the line absorbs: times mapped are when PX4 published what the bag then held.
Without such outputs (a bag of ``/fmu/in`` topics only) the offset alone maps, at rate 1.
"""

from __future__ import annotations

import numpy as np

from fuzzoff.bridge import BridgeError
from fuzzoff.bridge.bag import Bag
from fuzzoff.bridge.ulog import Px4Log
from fuzzoff.lean_dataclass import dataclass

PAIR_TOPICS = ("vehicle_status", "failsafe_flags", "vehicle_control_mode", "vehicle_command_ack")
"""PX4 outputs logged whole and published at most a few times a second: one ULog sample near
each received one."""
PAIR_TOLERANCE_US = 20_000
OUTLIER_US = 10_000
"""A pair further than this from its neighbours' running median is left out (a late receipt)."""
SMOOTH = 5
IN_EFFECT_SLACK_US = 1_100_000
"""PX4 logs ``timesync_status`` at 1 Hz: a new offset shows up to this late."""


@dataclass(frozen=True, slots=True)
class Clock:
    origin_us: int
    """A host time (the bag's first message), x = 0."""
    a_us: float
    rate: float
    """The line through the pairs: PX4 time = a + rate x (host time - origin)."""
    pairs: int
    """How many of PX4's outputs measured it (0: the offset alone)."""
    residual_us: float
    """The pairs' largest distance from the clock (after outliers)."""
    knots_x: tuple[float, ...] = ()
    knots_y: tuple[float, ...] = ()
    """Between the first and the last pair the clock follows the pairs (their running median
    about the line, ``SMOOTH`` of them): a simulated PX4's pace changes with the host's load."""

    def px4_us(self, host_us: float) -> float:
        x = host_us - self.origin_us
        if self.knots_x and self.knots_x[0] <= x <= self.knots_x[-1]:
            return float(np.interp(x, self.knots_x, self.knots_y))
        return self.a_us + self.rate * x

    def host_us(self, px4_us: float) -> float:
        if self.knots_y and self.knots_y[0] <= px4_us <= self.knots_y[-1]:
            return self.origin_us + float(np.interp(px4_us, self.knots_y, self.knots_x))
        return self.origin_us + (px4_us - self.a_us) / self.rate

    def to_json(self) -> dict[str, float | int | str]:
        return {
            "source": "px4_outputs" if self.pairs else "time_sync_offset",
            "rate": round(self.rate, 6),
            "pairs": self.pairs,
            "residual_ms": round(self.residual_us / 1000, 3),
        }


def _in_effect(syncs: list[tuple[int, int]], index: int, px4_us: int) -> bool:
    """Whether the ``index``-th time sync's offset was PX4's at ``px4_us``: from its own time
    (less ``IN_EFFECT_SLACK_US``: a ``timesync_status`` sample shows a new offset up to a
    second late) until the next sync's. The first one also covers the time before it."""
    start = syncs[index][0] - IN_EFFECT_SLACK_US if index else -(2**62)
    end = syncs[index + 1][0] if index + 1 < len(syncs) else 2**62
    return start <= px4_us < end


def pairs(bag: Bag, log: Px4Log) -> tuple[np.ndarray, np.ndarray]:
    """(host receive times, PX4 publish times) of the bag's PX4 outputs found in the ULog.
    Each output is read with the offset PX4 stamped it with: the time sync in effect when it
    was published (PX4's client keeps one offset and jumps to a new one at a new sync, 0.2 s
    at once on a simulated PX4 off the host's pace; another sync's offset would pair an output
    with a sample it is not)."""
    hosts: list[int] = []
    px4: list[int] = []
    offsets = [offset for _, offset in log.syncs]
    for name in PAIR_TOPICS:
        topic, logged = bag.topics.get(name), log.topics.get(name)
        if topic is None or logged is None or topic.direction != "out" or not offsets:
            continue
        times = logged.timestamps
        for sample in topic.samples:
            best: int | None = None
            best_distance = PAIR_TOLERANCE_US + 1
            for index, offset in enumerate(offsets):
                meant = sample.stamp_us - offset
                if not _in_effect(log.syncs, index, meant):
                    continue
                i = int(np.searchsorted(times, meant))
                for j in (i - 1, i):
                    if not 0 <= j < len(times):
                        continue
                    # each candidate's distance from the time its own offset gives (against
                    # another offset's, a match 0.2 s away beat an exact one)
                    distance = abs(int(times[j]) - meant)
                    if distance < best_distance:
                        best, best_distance = int(times[j]), distance
            if best is not None:
                hosts.append(sample.received_us)
                px4.append(best)
    return np.array(hosts, dtype=np.int64), np.array(px4, dtype=np.int64)


def measure(bag: Bag, log: Px4Log) -> Clock:
    """The clock from the pairs, or the first time sync's offset where there are fewer than 2."""
    hosts, px4 = pairs(bag, log)
    origin = bag.first_us
    if len(hosts) < 2:
        if not log.syncs:
            raise BridgeError(
                f"{log.path}: PX4 logged no time sync with a Micro XRCE-DDS agent and none of"
                " its outputs in the bag pair with its log: the bag's times cannot be put on"
                " PX4's clock"
            )
        offset = log.syncs[0][1]
        return Clock(origin, float(origin - offset), 1.0, 0, 0.0)
    order = np.argsort(hosts, kind="stable")
    x = (hosts[order] - origin).astype(np.float64)
    y = px4[order].astype(np.float64)
    rate, a = np.polyfit(x, y, 1)
    residual = y - (a + rate * x)
    half = SMOOTH // 2
    local = np.array(
        [np.median(residual[max(0, i - half) : i + half + 1]) for i in range(len(residual))]
    )
    keep = np.abs(residual - local) <= OUTLIER_US
    x, y, local = x[keep], y[keep], local[keep]
    knots = np.maximum.accumulate(a + rate * x + local)
    worst = float(np.abs(y - knots).max()) if len(y) else 0.0
    return Clock(
        origin, float(a), float(rate), int(keep.sum()), worst, tuple(x.tolist()), tuple(knots)
    )
