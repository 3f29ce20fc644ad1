"""What the companion sent that PX4 never received, and what PX4 did that the companion never saw.

For each ``/fmu/in`` topic of the bag, PX4's ULog holds what PX4 received, with the fields as
sent: a ULog sample is the companion's when its fields other than the timestamps equal a sent
one's (PX4's own flight tasks publish ``trajectory_setpoint`` and ``vehicle_command`` too, with
other content). PX4's logger keeps at most one sample per its interval, so delivery is judged
per stretch, not per message: a sent message counts as received when PX4 logged one of the
companion's samples of that topic within ``window`` after it (3 logging intervals, 0.3-2 s).
Runs of sent messages not received are the undelivered windows; a run before PX4's first receipt
is the bridge's discovery (PX4's agent matches a new writer 100-400 ms after a reader on the
companion's host does), said apart. A received sample stamped in PX4's future was taken at its
receive time (``ulog`` module): those give the delivery latency, PX4's receive time less the
send time mapped onto PX4's clock (``clock``).

For each ``/fmu/out`` topic: the stretches in which PX4 published (its ULog) and the companion
received nothing; PX4's status changes and their receipt come from ``changes``.
"""

from __future__ import annotations

import itertools
import math
from typing import Any

import numpy as np

from fuzzoff.bridge import BridgeError
from fuzzoff.bridge.bag import Bag, BagTopic
from fuzzoff.bridge.changes import Change, changes_of, signal_lost
from fuzzoff.bridge.clock import Clock, measure, pairs
from fuzzoff.bridge.ulog import Px4Log, ULogTopic
from fuzzoff.lean_dataclass import dataclass

TOLERANCE_US = 30_000
"""Slack between a send time mapped onto PX4's clock and PX4's record of it."""
WINDOW_MIN_US, WINDOW_MAX_US = 300_000, 2_000_000
COMMAND_WINDOW_US = 1_000_000
GAP_US = 1_000_000
"""A silence of PX4's outputs this long (or 3 of their intervals) is reported."""
STAMPS = frozenset({"timestamp", "timestamp_sample"})


@dataclass(frozen=True, slots=True)
class Window:
    start_s: float
    end_s: float
    """Seconds from the bag's first message."""
    count: int
    """Messages sent (``in``) or published by PX4 (``out``) in it."""
    discovery: bool = False
    """Before PX4's first receipt of the topic (``in``)."""

    def to_json(self) -> dict[str, Any]:
        return {
            "start_s": round(self.start_s, 3),
            "end_s": round(self.end_s, 3),
            "count": self.count,
            **({"discovery": True} if self.discovery else {}),
        }


@dataclass(frozen=True, slots=True)
class TopicResult:
    topic: str
    name: str
    direction: str
    recorded: int
    """Messages of the topic in the bag."""
    logged: int
    """The companion's samples PX4's ULog holds (``in``), PX4's samples in the bag's span
    (``out``)."""
    windows: tuple[Window, ...] = ()
    latency_ms: tuple[float, float, int] | None = None
    """Median, largest, how many measured."""
    note: str | None = None

    @property
    def undelivered(self) -> int:
        return sum(w.count for w in self.windows if not w.discovery)

    def to_json(self) -> dict[str, Any]:
        out: dict[str, Any] = {
            "topic": self.topic,
            "direction": "to_px4" if self.direction == "in" else "from_px4",
            "recorded": self.recorded,
            "logged_by_px4": self.logged,
            "undelivered": self.undelivered,
            "windows": [w.to_json() for w in self.windows],
        }
        if self.latency_ms is not None:
            median, worst, count = self.latency_ms
            out["latency_ms"] = {"median": median, "max": worst, "measured": count}
        if self.note:
            out["note"] = self.note
        return out


@dataclass(frozen=True, slots=True)
class Delivery:
    ulog: str
    clock: Clock
    syncs: list[tuple[int, int]]
    topics: list[TopicResult]
    changes: list[Change]
    lost: list[tuple[float, float]]
    """Where PX4 flagged the offboard signal lost (bag seconds), while armed."""
    changes_note: str | None = None

    def to_json(self) -> dict[str, Any]:
        return {
            "ulog": self.ulog,
            "clock": {
                **self.clock.to_json(),
                "time_syncs": [
                    {"px4_time_s": round(t / 1e6, 3), "offset_us": o} for t, o in self.syncs
                ],
            },
            "topics": [t.to_json() for t in self.topics],
            "px4_changes": [c.to_json() for c in self.changes],
            "px4_signal_lost": [
                {"start_s": round(a, 3), "end_s": round(b, 3)} for a, b in self.lost
            ],
            **({"px4_changes_note": self.changes_note} if self.changes_note else {}),
        }


def _key(value: Any) -> Any:
    if isinstance(value, (float, np.floating)):
        number = float(np.float32(value))
        return "nan" if math.isnan(number) else number
    return int(value)


def _companions(
    topic: BagTopic, logged: ULogTopic
) -> tuple[np.ndarray, list[Any], list[Any], np.ndarray]:
    """The ULog's samples whose fields equal a sent one's: their times; each sent sample's key
    and each such logged sample's key (same fields); the times of PX4's other samples."""
    names = sorted(
        (set(topic.samples[0].fields) & set(logged.data)) - STAMPS if topic.samples else set()
    )
    sent_keys = [tuple(_key(s.fields[n]) for n in names) for s in topic.samples]
    columns = [logged.data[n].tolist() for n in names]
    logged_keys = [tuple(_key(c[i]) for c in columns) for i in range(len(logged.timestamps))]
    wanted = set(sent_keys)
    mask = np.array([k in wanted for k in logged_keys], dtype=bool)
    return (
        logged.timestamps[mask] if len(mask) else logged.timestamps[:0],
        sent_keys,
        [k for k, m in zip(logged_keys, mask, strict=True) if m],
        logged.timestamps[~mask] if len(mask) else logged.timestamps[:0],
    )


def _window_us(received: np.ndarray, command: bool) -> int:
    if command:
        return COMMAND_WINDOW_US
    if len(received) < 2:
        return WINDOW_MAX_US
    step = float(np.median(np.diff(received)))
    return int(min(max(3 * step, WINDOW_MIN_US), WINDOW_MAX_US))


def _sent_topic(
    topic: BagTopic, logged: ULogTopic | None, log: Px4Log, clock: Clock, seconds: Any
) -> TopicResult:
    if logged is None:
        return TopicResult(
            topic.topic,
            topic.name,
            "in",
            len(topic.samples),
            0,
            note="not in PX4's log: not judged",
        )
    received, sent_keys, received_keys, foreign = _companions(topic, logged)
    window = _window_us(received, topic.name == "vehicle_command")
    mapped = np.array([clock.px4_us(s.received_us) for s in topic.samples])
    first_received = received[0] if len(received) else None
    delivered = []
    judged = []
    mixed_out = 0
    per_message = topic.name == "vehicle_command"  # logged whole: each command by its fields
    times_of: dict[Any, np.ndarray] = {}
    for key in set(received_keys) if per_message else ():
        times_of[key] = received[[k == key for k in received_keys]]
    for x, key in zip(mapped, sent_keys, strict=True):
        times = times_of.get(key, received[:0]) if per_message else received
        lo = int(np.searchsorted(times, x - TOLERANCE_US))
        ok = lo < len(times) and times[lo] <= x + window
        delivered.append(ok)
        near = int(np.searchsorted(foreign, x - window))
        mixed = not per_message and near < len(foreign) and foreign[near] <= x + window
        judged.append(log.start_us + window <= x <= log.last_us - window and not mixed)
        mixed_out += int(mixed and not ok)
    windows: list[Window] = []
    run: list[int] = []
    for i, (ok, judge) in enumerate([*zip(delivered, judged, strict=True), (True, True)]):
        if i < len(delivered) and not ok and judge:
            run.append(i)
            continue
        if run:
            discovery = not per_message and (
                first_received is None or mapped[run[-1]] < first_received
            )
            windows.append(
                Window(
                    seconds(topic.samples[run[0]].received_us),
                    seconds(topic.samples[run[-1]].received_us),
                    len(run),
                    discovery and first_received is not None,
                )
            )
            run = []
    return TopicResult(
        topic.topic,
        topic.name,
        "in",
        len(topic.samples),
        len(received),
        tuple(windows),
        _latency(received, received_keys, mapped, sent_keys),
        note=(
            f"{mixed_out} sent while PX4 logged its own samples of the topic (its logger keeps"
            " one per interval, from any publisher): not judged"
            if mixed_out
            else None
        ),
    )


def _latency(
    received: np.ndarray, received_keys: list[Any], mapped: np.ndarray, sent_keys: list[Any]
) -> tuple[float, float, int] | None:
    """PX4's receive time less the send time, for the samples PX4 stamped at receipt (a 4 ms
    grid in SITL shows them; a stamp not in PX4's future was kept and says nothing of it)."""
    by_key: dict[Any, list[float]] = {}
    for x, key in zip(mapped, sent_keys, strict=True):
        by_key.setdefault(key, []).append(float(x))
    delays = []
    for u, key in zip(received.tolist(), received_keys, strict=True):
        times = by_key.get(key, [])
        i = int(np.searchsorted(times, u + TOLERANCE_US)) - 1
        if i >= 0 and u - times[i] >= 0 and u - times[i] <= TOLERANCE_US * 4:
            delays.append(u - times[i])
    if not delays:
        return None
    return round(float(np.median(delays)) / 1000, 1), round(max(delays) / 1000, 1), len(delays)


def _heard_topic(
    topic: BagTopic, logged: ULogTopic | None, clock: Clock, span: tuple[float, float], seconds: Any
) -> TopicResult:
    if logged is None:
        return TopicResult(
            topic.topic,
            topic.name,
            "out",
            len(topic.samples),
            0,
            note="not in PX4's log: not judged",
        )
    published = logged.timestamps[(logged.timestamps >= span[0]) & (logged.timestamps <= span[1])]
    heard = np.array([clock.px4_us(s.received_us) for s in topic.samples])
    gap = GAP_US if len(heard) < 2 else max(GAP_US, int(3 * np.median(np.diff(heard))))
    bounds = [span[0], *heard.tolist(), span[1]]
    windows = []
    for a, b in itertools.pairwise(bounds):
        inside = published[(published > a + TOLERANCE_US) & (published < b - TOLERANCE_US)]
        if b - a >= gap and len(inside):
            windows.append(
                Window(seconds(clock.host_us(a)), seconds(clock.host_us(b)), len(inside))
            )
    return TopicResult(
        topic.topic, topic.name, "out", len(topic.samples), len(published), tuple(windows)
    )


def compare(bag: Bag, log: Px4Log) -> Delivery:
    """BridgeError when the two are not one flight."""
    if not log.syncs and log.synct == 0:
        raise BridgeError(
            f"{log.path}: PX4 ran its ROS 2 bridge without time sync (UXRCE_DDS_SYNCT 0): the"
            " bag's times, on the host's clock, cannot be put on PX4's; nothing compared (set"
            " UXRCE_DDS_SYNCT 1 to compare a flight)"
        )
    if not log.syncs:
        raise BridgeError(
            f"{log.path}: PX4 logged no time sync with a Micro XRCE-DDS agent: it was not on the"
            " ROS 2 bridge in this log"
        )
    on_px4 = [(bag.first_us - o, bag.last_us - o) for _, o in log.syncs]
    if not any(a <= log.last_us and b >= log.start_us for a, b in on_px4):
        a, b = on_px4[0]
        raise BridgeError(
            f"{bag.path} and {log.path} are not the same flight: by the ULog's time sync the"
            f" bag's messages fall at {a / 1e6:.1f} to {b / 1e6:.1f} s of PX4's clock, the log"
            f" covers {log.start_us / 1e6:.1f} to {log.last_us / 1e6:.1f} s"
        )
    hosts, _ = pairs(bag, log)
    outputs = sum(
        len(bag.topics[n].samples)
        for n in bag.topics
        if bag.topics[n].direction == "out" and n in log.topics
    )
    if outputs and len(hosts) == 0:
        raise BridgeError(
            f"{bag.path} and {log.path} are not the same flight: none of the bag's {outputs}"
            " messages from PX4 is in the ULog"
        )
    clock = measure(bag, log)

    def seconds(host_us: float) -> float:
        return (host_us - bag.first_us) / 1e6

    span = (
        max(float(log.start_us), clock.px4_us(bag.first_us)),
        min(float(log.last_us), clock.px4_us(bag.last_us)),
    )
    results = []
    for name in sorted(bag.topics, key=lambda n: (bag.topics[n].direction, n)):
        topic = bag.topics[name]
        if topic.direction == "in":
            results.append(_sent_topic(topic, log.topics.get(name), log, clock, seconds))
        else:
            results.append(_heard_topic(topic, log.topics.get(name), clock, span, seconds))
    sent = [r for r in results if r.direction == "in"]
    if sent and not outputs and not any(r.logged for r in sent):
        raise BridgeError(
            f"{bag.path} and {log.path} are not the same flight: none of the messages the bag"
            " sent is in the ULog"
        )
    changes, note = changes_of(bag, log, clock, span, seconds)
    return Delivery(
        log.path,
        clock,
        log.syncs,
        results,
        changes,
        signal_lost(changes, seconds(bag.last_us)),
        note,
    )
