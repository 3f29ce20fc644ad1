"""PX4's status changes in its ULog, and when the companion received each (``lint --with``).

``vehicle_status`` (mode, arming, failsafe) and ``failsafe_flags`` (the offboard signal lost):
each change in the bag's span, and how long after PX4 published it the companion first received
a sample of the new state from the bag's ``/fmu/out`` topic (before the state changed again, or
within ``GAP_US`` after), or that it never did.
"""

from __future__ import annotations

from typing import Any

from fuzzoff.bridge.bag import Bag
from fuzzoff.bridge.clock import Clock
from fuzzoff.bridge.ulog import Px4Log, ULogTopic
from fuzzoff.lean_dataclass import dataclass
from fuzzoff.modes import nav_state_name

TOLERANCE_US = 30_000
"""Slack between the companion's receipt mapped onto PX4's clock and PX4's publication."""
GAP_US = 1_000_000
"""A new state received this long after the next change still counts (its sample was late)."""
LATE_S = 1.0
"""A status change the companion received this much later than PX4 published it is late."""
STATUS_FIELDS = ("nav_state", "arming_state", "failsafe")


@dataclass(frozen=True, slots=True)
class Change:
    time_s: float
    """When PX4 published it, as seconds from the bag's first message."""
    px4_s: float
    """The same on PX4's clock (the ULog's timestamps)."""
    what: str
    seen_after_s: float | None
    """How long after PX4 published it the companion received it (None: never)."""
    lost_signal: bool = False
    armed: bool = False

    def to_json(self) -> dict[str, Any]:
        return {
            "time_s": round(self.time_s, 3),
            "px4_time_s": round(self.px4_s, 3),
            "state": self.what,
            "seen_after_s": None if self.seen_after_s is None else round(self.seen_after_s, 3),
        }


def _states(topic: ULogTopic, fields: tuple[str, ...]) -> list[tuple[int, tuple[int, ...]]]:
    columns = [topic.data[f].tolist() for f in fields if f in topic.data]
    rows = [tuple(int(c[i]) for c in columns) for i in range(len(topic.timestamps))]
    out: list[tuple[int, tuple[int, ...]]] = []
    for t, row in zip(topic.timestamps.tolist(), rows, strict=True):
        if not out or out[-1][1] != row:
            out.append((int(t), row))
    return out


def _describe(name: str, state: tuple[int, ...]) -> str:
    if name == "failsafe_flags":
        return "offboard signal lost" if state[0] else "offboard signal back"
    nav, arming, *failsafe = state
    text = f"{nav_state_name(nav)}, {'armed' if arming == 2 else 'disarmed'}"
    return text + (", failsafe" if failsafe and failsafe[0] else "")


def changes_of(
    bag: Bag, log: Px4Log, clock: Clock, span: tuple[float, float], seconds: Any
) -> tuple[list[Change], str | None]:
    changes: list[Change] = []
    missing = []
    armed_at: list[tuple[int, bool]] = []
    if "vehicle_status" in log.topics:
        armed_at = [
            (t, s[0] == 2) for t, s in _states(log.topics["vehicle_status"], ("arming_state",))
        ]
    for name, fields in (
        ("vehicle_status", STATUS_FIELDS),
        ("failsafe_flags", ("offboard_control_signal_lost",)),
    ):
        logged, topic = log.topics.get(name), bag.topics.get(name)
        if logged is None:
            continue
        if topic is None or topic.direction != "out":
            missing.append(name)
            continue
        states = _states(logged, fields)
        heard = [
            (clock.px4_us(s.received_us), tuple(int(s.fields.get(f, 0)) for f in fields))
            for s in topic.samples
        ]
        for i, (t, state) in enumerate(states):
            if not span[0] <= t <= span[1] or i == 0:
                continue
            until = states[i + 1][0] if i + 1 < len(states) else span[1]
            seen = next(
                (h for h, got in heard if got == state and t - TOLERANCE_US <= h <= until + GAP_US),
                None,
            )
            armed = (
                any(a for at, a in armed_at if at <= t)
                and ([a for at, a in armed_at if at <= t][-1])
            )
            changes.append(
                Change(
                    seconds(clock.host_us(t)),
                    t / 1e6,
                    _describe(name, state),
                    None if seen is None else max(0.0, (seen - t) / 1e6),
                    lost_signal=name == "failsafe_flags" and bool(state[0]),
                    armed=armed,
                )
            )
    note = None
    if missing:
        note = f"the bag holds no {', '.join('/fmu/out/' + m for m in missing)}: not judged"
    changes.sort(key=lambda c: c.px4_s)
    return changes, note


def signal_lost(changes: list[Change], span_end_s: float) -> list[tuple[float, float]]:
    out = []
    signal = [c for c in changes if c.what.startswith("offboard signal")]
    for i, change in enumerate(signal):
        if change.lost_signal and change.armed:
            end = signal[i + 1].time_s if i + 1 < len(signal) else span_end_s
            out.append((change.time_s, end))
    return out
