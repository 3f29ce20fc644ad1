"""OFB104: the keep-alive continues while the declared setpoint topic has gone quiet (ROS 2).

Seed 000, ROS 2 warning item 4: PX4 does not failsafe when setpoints stop, only when the
``OffboardControlMode`` keep-alive stops, so a dead planner behind a live heartbeat goes unnoticed.
"""

from __future__ import annotations

from fuzzoff.checks._keepalive import mode_note, offboard_and_flying
from fuzzoff.checks.base import Check, CheckContext
from fuzzoff.events import ControlMode, Event, Where
from fuzzoff.tables.declared import MESSAGE_NAMES, declared_setpoints

ROS2_FORMATS = ("mcap", "rosbag2-sqlite3", "rosbag2-mcap")


class StaleSetpoints(Check):
    codes = ("OFB104",)
    wants = (Event,)

    def __init__(self, ctx: CheckContext) -> None:
        super().__init__(ctx)
        self.stale = float(ctx.option("OFB104", "stale_s"))
        self.active = ctx.info.format in ROS2_FORMATS
        if not self.active and ctx.has("control_mode", "legacy_control_mode"):
            ctx.cannot_check(
                "OFB104",
                "needs the ROS 2 setpoint topics as sent (/fmu/in/...); a ULog holds PX4's "
                "subsampled copies",
            )
        self.last_sent: dict[str, float] = {}
        self.episode: tuple[str, float, Where] | None = None
        """(what went stale, since when, where) while a stale stretch is open."""

    def on_event(self, event: Event) -> None:
        if not self.active:
            return
        if event.origin == "sent" and not isinstance(event, ControlMode):
            self.last_sent[event.kind] = event.t
            return
        if not isinstance(event, ControlMode):
            return
        flying = offboard_and_flying(self.ctx)
        if not flying:
            self._close(event.t)
            return
        flag = event.first_flag()
        if flag is None:
            return
        stale_what = None
        since = 0.0
        for group in declared_setpoints(flag, self.ctx.profile):
            times = [self.last_sent[k] for k in group if k in self.last_sent]
            if not times:
                continue  # never published: OFB303's finding, not a stale one
            newest = max(times)
            if event.t - newest > self.stale:
                stale_what = " or ".join(MESSAGE_NAMES.get(k, k) for k in group)
                since = newest
                break
        if stale_what is None:
            self._close(event.t)
        elif self.episode is None:
            self.episode = (stale_what, since, event.where)

    def _close(self, t: float) -> None:
        if self.episode is None:
            return
        what, since, where = self.episode
        self.episode = None
        self.ctx.report(
            "OFB104",
            f"OffboardControlMode kept coming but {what} was not published for "
            f"{t - since:.2f} s in OFFBOARD{mode_note(self.ctx)}: PX4 keeps flying the last "
            f"setpoint and does not failsafe (threshold {self.stale:.2f} s)",
            since + self.stale,
            where,
            end=t,
        )

    def finish(self, t_end: float) -> None:
        self._close(t_end)
