"""OFB104: the keep-alive continues while the declared setpoint topic has gone quiet (ROS 2).

Seed 000, ROS 2 warning item 4: PX4 does not failsafe when setpoints stop, only when the
``OffboardControlMode`` keep-alive stops, so a dead planner behind a live heartbeat goes unnoticed.
"""

from __future__ import annotations

from fuzzoff.checks._keepalive import mode_note
from fuzzoff.checks.base import Check, CheckContext
from fuzzoff.events import PX4_SETPOINTS, ControlMode, Event, Where
from fuzzoff.tables.control_mode import SETPOINT_NAMES

ROS2_FORMATS = ("mcap", "rosbag2-sqlite3", "rosbag2-mcap")


class StaleSetpoints(Check):
    codes = ("OFB104",)
    wants = (*PX4_SETPOINTS, ControlMode)

    def __init__(self, ctx: CheckContext) -> None:
        super().__init__(ctx)
        self.stale = float(ctx.option("OFB104", "stale_s"))
        self.active = ctx.info.format in ROS2_FORMATS
        if not self.active:
            self.subscriptions = ()
        if not self.active and ctx.has("control_mode", "legacy_control_mode"):
            ctx.cannot_check(
                "OFB104",
                "needs the ROS 2 setpoint topics as sent (/fmu/in/...); a ULog holds PX4's "
                "subsampled copies",
            )
        self.last_sent: dict[str, float] = {}
        self.last_ocm: float | None = None
        self.ocm_since = 0.0
        """Start of the keep-alive's current unbroken run."""
        self.episode: tuple[str, float, Where] | None = None
        """(what went stale, since when, where) while a stale stretch is open."""
        self.required: dict[str | None, tuple[tuple[str, ...], ...] | None] = {}
        """First flag -> its row's alternatives (``_alternatives``)."""

    def on_event(self, event: Event) -> None:
        if event.origin == "sent" and not isinstance(event, ControlMode):
            self.last_sent[event.kind] = event.t
            return
        if not isinstance(event, ControlMode):
            return
        if self.last_ocm is None or event.t - self.last_ocm > self.stale:
            self.ocm_since = event.t  # the keep-alive itself paused: not "kept coming"
        self.last_ocm = event.t
        if not self.ctx.state.flying:
            self._close(event.t)
            return
        alternatives = self._alternatives(self.ctx.state.declared_flag)  # this OCM's first flag
        if alternatives is None:
            return
        stale: list[tuple[float, str]] = []
        for alternative in alternatives:
            published = []
            for kind in alternative:
                t = self.last_sent.get(kind)
                if t is None:
                    break  # never published in full: OFB303's finding, not a stale one
                published.append((t, kind))
            else:
                oldest, kind = min(published)
                oldest = max(oldest, self.ocm_since)  # quiet only counts under a live keep-alive
                if event.t - oldest <= self.stale:
                    self._close(event.t)  # one alternative is being served
                    return
                stale.append((oldest, SETPOINT_NAMES.get(kind, kind)))
        if stale and self.episode is None:
            since, what = max(stale)
            self.episode = (what, since, event.where)

    def _alternatives(self, flag: str | None) -> tuple[tuple[str, ...], ...] | None:
        """The row's required alternatives as sorted kinds (None: no row), once per flag."""
        try:
            return self.required[flag]
        except KeyError:
            row = self.ctx.row_for(flag)
            found = None if row is None else tuple(tuple(sorted(a)) for a in row.required)
            self.required[flag] = found
            return found

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
