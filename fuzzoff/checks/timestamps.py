"""OFB106: the ``OffboardControlMode.timestamp`` a ROS 2 sender writes: zero, backwards, lagging.

From 1.14 PX4 judges the keep-alive's age by this field, rewritten on receipt (gate.md#signal):
zero becomes the receive time, anything else ``min(value - time_offset, now)``. So a
clock that lags by more than the loss timeout makes a fresh stream look lost; 1.13 ignores the
field (gate.md#signal). The recording clock is relative, so the lag is measured against the
freshest sender-to-recording offset seen so far.
"""

from __future__ import annotations

from itertools import repeat
from operator import attrgetter, le, sub, truediv

from fuzzoff.checks._keepalive import control_modes, keepalive_run
from fuzzoff.checks.base import Check, CheckContext, StreamBatch
from fuzzoff.events import ControlMode, Event, Where
from fuzzoff.findings import Severity
from fuzzoff.lean_dataclass import dataclass

_STAMP = attrgetter("sender_time_us")
_ORIGIN = attrgetter("origin")
_TIME = attrgetter("t")


@dataclass(slots=True)
class _Seen:
    t: float
    where: Where
    count: int = 1
    worst_lag: float = 0.0
    stale_at: float | None = None
    """The loss timeout a noted message's lag reached first (1.14+), if any did: the
    recording's COM_OF_LOSS_T may arrive, or change, after the first message."""


class KeepaliveTimestamp(Check):
    codes = ("OFB106",)
    wants = (ControlMode,)

    def __init__(self, ctx: CheckContext) -> None:
        super().__init__(ctx)
        self.lag_option = float(ctx.option("OFB106", "lag_s"))
        self.judged_by_timestamp = ctx.profile.release.ros2_timestamp_rewrite
        self.best_offset: float | None = None
        self.previous: int | None = None
        self.seen: dict[str, _Seen] = {}
        self.logged = False
        self.sent = False

    @property
    def timeout(self) -> float:
        """The gate's loss timeout now: the recording's COM_OF_LOSS_T once it has been seen."""
        return float(self.ctx.gate.loss_timeout)

    @property
    def lag_limit(self) -> float:
        return self.lag_option if self.lag_option > 0 else self.timeout

    def on_event(self, event: Event) -> None:
        assert isinstance(event, ControlMode)
        if event.origin != "sent" or event.sender_time_us is None:
            self.logged = self.logged or event.origin == "vehicle"
            return
        self.sent = True
        stamp = event.sender_time_us
        if stamp == 0:
            self._note("zero", event, 0.0)
            return
        lag = self._lag(event.t, stamp)
        if self.previous is not None and stamp < self.previous:
            self._note("backwards", event, lag)
        self.previous = stamp
        if lag > self.lag_limit:
            self._note("lag", event, lag)

    def on_batch(self, batch: StreamBatch) -> None:
        """Fast path: none of the run's OffboardControlMode as sent (only ``logged`` moves);
        or all as sent, with non-zero stamps that never go back and that lag by no more than
        the limit even against the best offset after the run (no greater than any offset a
        message saw, so every lag ``on_event`` works out is at most that): then none is noted
        and only ``best_offset`` and ``previous`` move (to the least offset and last stamp)."""
        ocms = control_modes(batch)
        if not ocms:
            return
        origins = set(map(_ORIGIN, ocms))
        if "sent" not in origins:  # a ULog's copies: nothing but ``logged`` to note
            self.logged = self.logged or "vehicle" in origins
            return
        stamps = list(map(_STAMP, ocms))
        if len(origins) > 1 or None in stamps or 0 in stamps:
            self.replay(batch)
            return
        # the keep-alive times when the OCMs are the run's keep-alives (ROS 2: they are)
        times = keepalive_run(batch).times if ocms is batch.keepalives() else map(_TIME, ocms)
        offsets = list(map(sub, times, map(truediv, stamps, repeat(1e6))))
        if self.previous is not None:
            stamps.insert(0, self.previous)
        best = min(offsets)
        if self.best_offset is not None and self.best_offset <= best:
            best = self.best_offset
        if max(offsets) - best > self.lag_limit or not all(map(le, stamps, stamps[1:])):
            self.replay(batch)
            return
        self.sent = True
        self.best_offset = best
        self.previous = stamps[-1]

    def _lag(self, t: float, stamp_us: int) -> float:
        offset = t - stamp_us / 1e6
        if self.best_offset is None or offset < self.best_offset:
            self.best_offset = offset
        return offset - self.best_offset

    def _note(self, what: str, event: Event, lag: float) -> None:
        seen = self.seen.get(what)
        if seen is None:
            seen = self.seen[what] = _Seen(event.t, event.where, worst_lag=lag)
        else:
            seen.count += 1
            seen.worst_lag = max(seen.worst_lag, lag)
        stale = what != "zero" and self.judged_by_timestamp and lag >= self.timeout
        if stale and seen.stale_at is None:
            seen.stale_at = self.timeout

    def finish(self, t_end: float) -> None:
        for what, seen in sorted(self.seen.items(), key=lambda item: item[1].t):
            self._report(what, seen)
        if self.logged and not self.sent:
            self.ctx.cannot_check(
                "OFB106",
                "needs OffboardControlMode as sent (ROS 2 /fmu/in/offboard_control_mode); "
                "a ULog holds PX4's rewritten timestamp",
            )

    def _report(self, what: str, seen: _Seen) -> None:
        stale = seen.stale_at is not None
        px4 = f"PX4 {self.ctx.profile.px4}"
        if what == "zero":
            text = "OffboardControlMode.timestamp is 0"
            effect = (
                f"{px4} replaces it with the receive time"
                if self.judged_by_timestamp
                else f"{px4} does not use the field"
            )
        else:
            head = (
                "OffboardControlMode.timestamp goes backwards"
                if what == "backwards"
                else "OffboardControlMode.timestamp lags the recording clock"
            )
            text = f"{head} (by up to {seen.worst_lag:.3f} s)"
            if stale:
                effect = (
                    f"{px4} judges the keep-alive's age by this field and takes a stamp older "
                    f"than COM_OF_LOSS_T ({seen.stale_at:.2f} s) for a lost signal"
                )
            elif self.judged_by_timestamp:
                effect = f"{px4} judges the keep-alive's age by it; still within the timeout"
            else:
                effect = f"{px4} does not use the field for the offboard gate"
        count = f" in {seen.count} messages" if seen.count > 1 else ""
        self.ctx.report(
            "OFB106",
            f"{text}{count}: {effect}",
            seen.t,
            seen.where,
            severity=Severity.WARNING if stale else Severity.INFO,
        )
