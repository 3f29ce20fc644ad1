"""OFB203: PX4 setpoint topics published while the vehicle is not in offboard.

Seed 000 "ROS 2 Offboard Control", warning box: publish PX4 setpoint messages ONLY in
Offboard mode. Only messages on their way to the vehicle count (origin ``sent``): PX4 itself
publishes ``trajectory_setpoint`` and the others in its own modes, and a ULog logs those.

Severity is what the setpoints do (rules.md): they fight PX4's own flight tasks only on an armed
vehicle in another mode. While disarmed nothing flies them, and the stream that runs up to an
offboard request (the switch needs it: px4_ros_com publishes from its first cycle) or that
resumes after a loss until PX4 returns to OFFBOARD by itself lasts only until PX4 switches: both
are ``info``. An armed stretch is judged when its fate is known: a request or the entry into
OFFBOARD while the keep-alive stream that carried it is unbroken makes it a run-up (``info``),
an entry while disarmed does not (PX4 shows OFFBOARD again as it disarms after a landing); a
break of that stream (a keep-alive gap PX4 takes for a loss: the loss timeout or more), a disarm
or the end of the recording before either makes it an ``error`` (a request that finds the stream
already broken is no run-up either). An external mode (nav_state EXTERNAL1-8, a ROS 2 mode of
px4-ros2-interface-lib) is the companion's own: its setpoints are what PX4 flies there.
"""

from __future__ import annotations

from dataclasses import field
from operator import attrgetter

from fuzzoff.checks._external import is_armed
from fuzzoff.checks._keepalive import KEEPALIVE_EVENTS, keepalive_run, loss_timeout, mode_note
from fuzzoff.checks.base import Check, CheckContext, StreamBatch
from fuzzoff.events import PX4_SETPOINTS, Command, Event, VehicleStatus, Where
from fuzzoff.findings import Severity
from fuzzoff.gate import GateTransition
from fuzzoff.lean_dataclass import dataclass
from fuzzoff.modes import nav_state_name
from fuzzoff.tables.control_mode import SETPOINT_KINDS, SETPOINT_NAMES

_KIND = attrgetter("kind")
_ORIGIN = attrgetter("origin")
_SENT = {"sent"}

EXTERNAL_MODES = range(23, 31)
"""nav_state EXTERNAL1-EXTERNAL8: modes a ROS 2 program registers and flies itself."""

assert {cls.kind for cls in PX4_SETPOINTS} <= SETPOINT_KINDS  # on_batch takes every one as named


@dataclass(slots=True)
class _Run:
    """Consecutive setpoints as sent outside offboard, in one arming state."""

    start: float
    last: float
    where: Where
    mode: str
    armed: bool
    count: int = 0
    topics: list[str] = field(default_factory=list)


class SetpointsOutsideOffboard(Check):
    codes = ("OFB203",)
    wants = (*PX4_SETPOINTS, *KEEPALIVE_EVENTS, Command, VehicleStatus, GateTransition)

    def __init__(self, ctx: CheckContext) -> None:
        super().__init__(ctx)
        self.run: _Run | None = None
        self.unasked: _Run | None = None
        """Armed stretches no request followed, merged until one that ran up to a request or
        the vehicle disarmed (a stream that breaks now and then is one finding, not many)."""
        self.logged = False
        self.sent = False
        self.last_keepalive: float | None = None

    def on_event(self, event: Event) -> None:
        state = self.ctx.state
        if event is state.keepalive:
            self._keepalive(event.t)
            if event.kind not in SETPOINT_NAMES:
                return
        if event.kind in SETPOINT_NAMES and event.origin != "sent":
            self.logged = True
            return
        if self._owned():
            if self.run is not None:  # _settle's own test, without the call on every message
                self._settle(entered=self._entered(), t=event.t)
            return
        if isinstance(event, Command):
            request = event.is_offboard_switch or (event.is_arm and self.ctx.offboard_selected())
            if request and self.run is not None and self.run.armed:
                # what ran up to the request is info, if its stream still ran at the request
                last = self.last_keepalive
                fresh = last is not None and event.t - last < loss_timeout(self.ctx)
                self._settle(entered=fresh, t=event.t)
            return
        if event.kind not in SETPOINT_NAMES:
            return
        self._add(event, 1, event)

    def on_batch(self, batch: StreamBatch) -> None:
        """The run's messages all see the same state, and what ``on_event`` does with them
        depends on their order only through a keep-alive gap that breaks the stream: with none
        (from the last keep-alive into the run, and inside it), any logged copy sets
        ``logged``; in offboard (or an external mode) the first one as sent settles the open
        stretch; outside it those as sent extend it (opened by the first), adding their topics
        in order of first appearance. A break replays the run."""
        keepalives = batch.keepalives()
        if keepalives:
            stream = keepalive_run(batch)
            last = self.last_keepalive
            first_gap = 0.0 if last is None else stream.times[0] - last
            limit = loss_timeout(self.ctx)
            if stream.widest >= limit or not 0.0 <= first_gap < limit:
                self.replay(batch)
                return
            self.last_keepalive = stream.times[-1]
        setpoints = batch.of(PX4_SETPOINTS)
        if not setpoints:
            return
        origins = set(map(_ORIGIN, setpoints))
        if origins != _SENT:
            self.logged = True
            if "sent" not in origins:
                return
            setpoints = [e for e in setpoints if e.origin == "sent"]
        if self._owned():
            if self.run is not None:
                self._settle(entered=self._entered(), t=setpoints[0].t)
            return
        self._add(setpoints[0], len(setpoints), setpoints[-1])
        run = self.run
        assert run is not None
        for kind in dict.fromkeys(map(_KIND, setpoints)):
            name = SETPOINT_NAMES[kind]
            if name not in run.topics:
                run.topics.append(name)

    def _owned(self) -> bool:
        """In offboard, or in an external mode: the setpoints are the ones PX4 flies."""
        state = self.ctx.state
        if self.ctx.in_offboard:
            return True
        return state.mode_recorded and state.nav_state in EXTERNAL_MODES

    def _entered(self) -> bool:
        """Does the stretch end by entering OFFBOARD? Only armed: after a disarm (PX4 shows
        OFFBOARD again as it disarms after a landing, its user intention) the armed stretch
        ended with the disarm, not with a run-up."""
        return self.ctx.in_offboard and is_armed(self.ctx)

    def _keepalive(self, t: float) -> None:
        last = self.last_keepalive
        self.last_keepalive = t
        if last is not None and t - last >= loss_timeout(self.ctx) and self.run is not None:
            self._settle(entered=False, t=t)  # the stream broke before any request

    def _add(self, first: Event, count: int, newest: Event) -> None:
        """``count`` setpoints as sent outside offboard, from ``first`` to ``newest``."""
        self.sent = True
        armed = is_armed(self.ctx)
        run = self.run
        if run is not None and run.armed != armed:
            # armed -> disarmed with no request in between: the armed part was not a run-up
            self._settle(entered=False, t=first.t)
            run = None
        if run is None:
            run = self.run = _Run(first.t, first.t, first.where, self._mode(), armed)
        run.last = newest.t
        run.count += count
        if count == 1:
            name = SETPOINT_NAMES[first.kind]
            if name not in run.topics:
                run.topics.append(name)

    def _mode(self) -> str:
        nav = self.ctx.state.nav_state if self.ctx.state.mode_recorded else None
        return "not in offboard" if nav is None else f"in {nav_state_name(nav)}"

    def _settle(self, *, entered: bool, t: float) -> None:
        """Close the open stretch: ``entered`` says an offboard request or the entry into
        OFFBOARD (asked for, or PX4's return after a loss) came at ``t`` while its stream ran."""
        run, self.run = self.run, None
        if run is None:
            return
        if run.armed and not entered:
            held = self.unasked
            if held is None or held.mode != run.mode:
                self._flush()
                self.unasked = run
                return
            held.last, held.count = run.last, held.count + run.count
            held.topics += [name for name in run.topics if name not in held.topics]
            return
        self._flush()
        self._report(run, entered, t)

    def _flush(self) -> None:
        held, self.unasked = self.unasked, None
        if held is not None:
            self._report(held, False, held.last)

    def _report(self, run: _Run, entered: bool, t: float) -> None:
        what = ", ".join(run.topics)
        span = f" ({run.count} messages until {run.last:.3f} s)" if run.count > 1 else ""
        docs = "docs: PX4 setpoint topics only in offboard"
        if not run.armed:
            severity = Severity.INFO
            why = (
                f"{docs}; PX4 flies no setpoint while disarmed, so nothing fights them (the "
                "stream before a switch must run anyway)"
            )
            effect = "nothing flies them (disarmed)"
        elif entered:
            severity = Severity.INFO
            why = (
                f"{docs}; they ran up to the offboard request or PX4's return to OFFBOARD at "
                f"{t:.3f} s, so PX4's own controllers wrote the same topics only until then"
            )
            effect = "the run-up to offboard"
        else:
            severity = Severity.ERROR
            why = (
                f"{docs}; no offboard request followed while they ran, so they collide with "
                "PX4's own controllers, which write the same topics in this mode"
            )
            effect = "they fight PX4's own controllers"
        state = "" if run.armed else ", disarmed"
        self.ctx.report(
            "OFB203",
            f"{what} published while the vehicle is {run.mode}{state}{span}: "
            f"{why}{mode_note(self.ctx)}",
            run.start,
            run.where,
            severity=severity,
            end=run.last if run.last > run.start else None,
            short=f"{what} sent while {run.mode}: {effect}",
        )

    def finish(self, t_end: float) -> None:
        self._settle(entered=False, t=t_end)
        self._flush()
        if self.logged and not self.sent:
            self.ctx.cannot_check(
                "OFB203",
                "needs the setpoints as sent (ROS 2 /fmu/in topics); a ULog also logs the "
                "setpoints PX4 itself publishes in its own modes",
            )
