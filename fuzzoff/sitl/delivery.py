"""Did a stream reach PX4 as it was meant? Host load against PX4 behaviour.

The client paces each message on PX4's own clock, but a busy host can still send one late: a
1.00 s gap then leaves as 1.03 s, and what PX4 does with it is the host's doing, not PX4's
behaviour for the stream that was meant. The tlog stamps every message with PX4's clock when it
went out; ``check`` compares those gaps with the stream's own.
"""

from __future__ import annotations

from typing import Any

from fuzzoff.lean_dataclass import dataclass

TOLERANCE_S = 0.02
"""A gap may leave this much longer or shorter than meant (the 10 ms Commander loop and the
host's sleep granularity are below it; a loss decision turns on tens of milliseconds)."""


@dataclass(frozen=True, slots=True)
class Delivery:
    worst_s: float
    """The largest difference between a gap as sent and as meant (consecutive messages)."""
    at_s: float
    """Where (the meant time of the message after that gap, from the first message)."""
    drift_s: float
    """The last message's lateness against the first: the stream as a whole took this much
    longer (or shorter, negative) than meant."""

    @property
    def faithful(self) -> bool:
        return self.worst_s <= TOLERANCE_S

    def describe(self) -> str:
        if self.faithful:
            return f"as meant (gaps within {1000 * self.worst_s:.0f} ms)"
        return (
            f"not as meant: a gap left {1000 * self.worst_s:.0f} ms off at {self.at_s:.3f} s"
            f" (tolerance {1000 * TOLERANCE_S:.0f} ms)"
        )

    def to_json(self) -> dict[str, Any]:
        return {
            "faithful": self.faithful,
            "worst_gap_error_s": round(self.worst_s, 4),
            "at_s": round(self.at_s, 4),
            "drift_s": round(self.drift_s, 4),
            "tolerance_s": TOLERANCE_S,
        }


def check(meant: list[float], sent: list[float]) -> Delivery:
    """``meant``: each message's time from the first as the stream says; ``sent``: the PX4
    time it went out. Equal lengths (one per message)."""
    if len(meant) != len(sent):
        raise ValueError(f"{len(meant)} messages meant, {len(sent)} sent")
    worst, at = 0.0, 0.0
    for i in range(1, len(meant)):
        error = abs((sent[i] - sent[i - 1]) - (meant[i] - meant[i - 1]))
        if error > worst:
            worst, at = error, meant[i]
    drift = (sent[-1] - sent[0]) - (meant[-1] - meant[0]) if meant else 0.0
    return Delivery(worst, at, drift)
