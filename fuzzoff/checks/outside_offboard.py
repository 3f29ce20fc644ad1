"""OFB203: PX4 setpoint topics published while the vehicle is not in offboard.

Seed 000 "ROS 2 Offboard Control", warning box: publish PX4 setpoint messages ONLY in
Offboard mode. Only messages on their way to the vehicle count (origin ``sent``): PX4 itself
publishes ``trajectory_setpoint`` and the others in its own modes, and a ULog logs those.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from operator import attrgetter

from fuzzoff.checks._keepalive import mode_note
from fuzzoff.checks.base import Check, CheckContext, StreamBatch
from fuzzoff.events import PX4_SETPOINTS, Event, VehicleStatus, Where
from fuzzoff.gate import GateTransition
from fuzzoff.modes import nav_state_name
from fuzzoff.tables.control_mode import SETPOINT_KINDS, SETPOINT_NAMES

_KIND = attrgetter("kind")
_ORIGIN = attrgetter("origin")
_SENT = {"sent"}

assert {cls.kind for cls in PX4_SETPOINTS} <= SETPOINT_KINDS  # on_batch takes every one as named


@dataclass(slots=True)
class _Run:
    start: float
    last: float
    where: Where
    mode: str
    count: int = 1
    topics: list[str] = field(default_factory=list)


class SetpointsOutsideOffboard(Check):
    codes = ("OFB203",)
    wants = (*PX4_SETPOINTS, VehicleStatus, GateTransition)

    def __init__(self, ctx: CheckContext) -> None:
        super().__init__(ctx)
        self.run: _Run | None = None
        self.logged = False
        self.sent = False

    def on_event(self, event: Event) -> None:
        if event.kind in SETPOINT_NAMES and event.origin != "sent":
            self.logged = True
            return
        if self.ctx.state.in_offboard:
            if self.run is not None:  # _close's own test, without the call on every message
                self._close()
            return
        if event.kind not in SETPOINT_NAMES:
            return
        self.sent = True
        name = SETPOINT_NAMES[event.kind]
        if self.run is None:
            self.run = _Run(event.t, event.t, event.where, self._mode(), count=0)
        self.run.last = event.t
        self.run.count += 1
        if name not in self.run.topics:
            self.run.topics.append(name)

    def on_batch(self, batch: StreamBatch) -> None:
        """The run's setpoints all see the same ``in_offboard``, and what ``on_event`` does
        with them does not depend on their order (every setpoint kind has a name): any
        logged copy sets ``logged``; in offboard the first one as sent closes the open run;
        outside it those as sent extend the run (opened by the first), adding their topics
        in order of first appearance."""
        setpoints = batch.of(PX4_SETPOINTS)
        if not setpoints:
            return
        origins = set(map(_ORIGIN, setpoints))
        if origins != _SENT:
            self.logged = True
            if "sent" not in origins:
                return
            setpoints = [e for e in setpoints if e.origin == "sent"]
        if batch.state.in_offboard:
            if self.run is not None:
                self._close()
            return
        self.sent = True
        first = setpoints[0]
        if self.run is None:
            self.run = _Run(first.t, first.t, first.where, self._mode(), count=0)
        run = self.run
        run.last = setpoints[-1].t
        run.count += len(setpoints)
        for kind in dict.fromkeys(map(_KIND, setpoints)):
            name = SETPOINT_NAMES[kind]
            if name not in run.topics:
                run.topics.append(name)

    def _mode(self) -> str:
        nav = self.ctx.state.nav_state if self.ctx.state.mode_recorded else None
        return "not in offboard" if nav is None else f"in {nav_state_name(nav)}"

    def _close(self) -> None:
        run, self.run = self.run, None
        if run is None:
            return
        what = ", ".join(run.topics)
        span = f" ({run.count} messages until {run.last:.3f} s)" if run.count > 1 else ""
        self.ctx.report(
            "OFB203",
            f"{what} published while the vehicle is {run.mode}{span}: PX4 setpoint topics "
            f"must be written only in offboard, else they collide with PX4's own "
            f"controllers{mode_note(self.ctx)}",
            run.start,
            run.where,
            end=run.last if run.last > run.start else None,
        )

    def finish(self, t_end: float) -> None:
        self._close()
        if self.logged and not self.sent:
            self.ctx.cannot_check(
                "OFB203",
                "needs the setpoints as sent (ROS 2 /fmu/in topics); a ULog also logs the "
                "setpoints PX4 itself publishes in its own modes",
            )
