"""OFB104: the keep-alive continues while the declared setpoint topic has gone quiet (ROS 2).

Seed 000, ROS 2 warning item 4: PX4 does not failsafe when setpoints stop, only when the
``OffboardControlMode`` keep-alive stops, so a dead planner behind a live heartbeat goes unnoticed.
"""

from __future__ import annotations

import math
from operator import attrgetter, le, sub

from fuzzoff.checks._keepalive import control_modes, keepalive_run, mode_note
from fuzzoff.checks.base import Check, CheckContext, StreamBatch
from fuzzoff.events import PX4_SETPOINTS, ControlMode, Event, Where
from fuzzoff.formats.registry import reported_names
from fuzzoff.tables.control_mode import SETPOINT_NAMES

ROS2_FORMATS = reported_names("ros2")
"""The formats that hold the ROS 2 topics as sent (MCAP, ROS 2 bags)."""

_SETPOINTS: frozenset[type[Event]] = frozenset(PX4_SETPOINTS)
_TIME = attrgetter("t")
_ORIGIN = attrgetter("origin")
_SENT = {"sent"}


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
        if not self.ctx.flying:
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
                    # one alternative is served again: the stretch ended when its last kind
                    # came back (``oldest``), not at this keep-alive
                    self._close(oldest)
                    return
                stale.append((oldest, SETPOINT_NAMES.get(kind, kind)))
        if stale and self.episode is None:
            since, what = max(stale)
            self.episode = (what, since, event.where)

    def on_batch(self, batch: StreamBatch) -> None:
        """Fast path: the run's messages in time order, the keep-alive never pausing for more
        than ``stale_s``, and (in offboard, with a row and no stale stretch open) one
        alternative whose every kind was published, before and throughout the run, at most
        ``stale_s`` before each OffboardControlMode: then each of them finds a served
        alternative (``event.t - oldest`` can only be smaller) and nothing is reported.
        Only the last times move."""
        ocms = control_modes(batch)
        setpoints = batch.of(PX4_SETPOINTS)
        kinds = {cls.kind for cls in batch.classes() & _SETPOINTS}
        all_sent = not setpoints or set(map(_ORIGIN, setpoints)) == _SENT
        if not ocms:
            self._note_sent(setpoints, kinds)
            return
        ocm_times, widest = self._times(batch, ocms)
        last_ocm = self.last_ocm
        if widest > self.stale or (last_ocm is not None and ocm_times[0] - last_ocm > self.stale):
            self.replay(batch)  # the keep-alive paused: ocm_since moves
            return
        if self.ctx.flying:
            alternatives = self._alternatives(batch.state.declared_flag)
            if alternatives is not None and (
                self.episode is not None
                or not self._served(batch, alternatives, setpoints, kinds, all_sent, ocm_times[-1])
            ):
                self.replay(batch)
                return
        elif self.episode is not None:
            self._close(ocm_times[0])
        if last_ocm is None:
            self.ocm_since = ocm_times[0]
        self.last_ocm = ocm_times[-1]
        self._note_sent(setpoints, kinds)

    @staticmethod
    def _times(batch: StreamBatch, ocms: list[Event]) -> tuple[list[float], float]:
        """The OCMs' times and the widest gap between them (-inf for one): the keep-alive
        figures when the OCMs are the run's keep-alives (ROS 2: they are, and several stream
        rules share those)."""
        if ocms is batch.keepalives():
            run = keepalive_run(batch)
            return run.times, run.widest
        times = list(map(_TIME, ocms))
        return times, max(map(sub, times[1:], times), default=-math.inf)

    def _served(
        self,
        batch: StreamBatch,
        alternatives: tuple[tuple[str, ...], ...],
        setpoints: list[Event],
        kinds: set[str],
        all_sent: bool,
        newest_ocm: float,
    ) -> bool:
        """Does one alternative provably serve every OffboardControlMode of the run? With
        the run in time order, the latest ``kind`` before an OCM is at most a gap between
        consecutive ``kind`` times (or the gap from the last one to the newest OCM) old."""
        times = list(map(_TIME, batch.events))
        if not all(map(le, times, times[1:])):
            return False
        for alternative in alternatives:
            for kind in alternative:
                before = self.last_sent.get(kind)
                if before is None:
                    break
                if all_sent and kinds == {kind}:
                    sent = list(map(_TIME, setpoints))
                else:
                    sent = [e.t for e in setpoints if e.kind == kind and e.origin == "sent"]
                sent.insert(0, before)
                oldest = max(map(sub, sent[1:], sent), default=0.0)
                if newest_ocm - sent[-1] > oldest:
                    oldest = newest_ocm - sent[-1]
                if oldest > self.stale:
                    break
            else:
                return True
        return False

    def _note_sent(self, setpoints: list[Event], kinds: set[str]) -> None:
        """``last_sent`` as ``on_event`` leaves it: each kind's newest message as sent."""
        missing = set(kinds)
        for event in reversed(setpoints):  # usually a step or two per kind
            if event.kind in missing and event.origin == "sent":
                self.last_sent[event.kind] = event.t
                missing.discard(event.kind)
                if not missing:
                    return

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
            short=f"{what} not sent for {t - since:.2f} s while the keep-alive goes on",
        )

    def finish(self, t_end: float) -> None:
        self._close(t_end)
