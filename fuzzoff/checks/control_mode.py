"""OFB301-OFB305: what ``OffboardControlMode`` declares, against what is published and valid.

Seed 000 "The OffboardControlMode PX4 message" (1.15+; rover table in "Ровер"), seed 002
"ROS 2 消息" (1.13-1.14). The table lives in fuzzoff/tables/control_mode.py.
"""

from __future__ import annotations

from itertools import chain
from operator import attrgetter

from fuzzoff.checks._external import Episodes, declared_flag
from fuzzoff.checks._keepalive import mode_note
from fuzzoff.checks.base import Check, CheckContext, StreamBatch
from fuzzoff.events import (
    MAVLINK_SETPOINTS,
    PX4_SETPOINTS,
    Command,
    CommandAck,
    ControlMode,
    Event,
    FailsafeFlags,
    MavlinkTarget,
    Parameter,
    SetAttitudeTarget,
    VehicleStatus,
    Where,
)
from fuzzoff.gate import GateTransition, ocm
from fuzzoff.gate.receiver import DROPPED, SHAPES, ReceiverContext, Shape, receive
from fuzzoff.lean_dataclass import dataclass
from fuzzoff.state import VehicleState
from fuzzoff.tables.control_mode import (
    SETPOINT_NAMES,
    FlagRow,
    describe_required,
    estimate_valid,
    row_for,
)

_ORIGIN = attrgetter("origin")


class ControlModeEmpty(Check):
    """OFB301: an ``OffboardControlMode`` with every field false declares nothing."""

    codes = ("OFB301",)
    wants = (ControlMode,)

    def __init__(self, ctx: CheckContext) -> None:
        super().__init__(ctx)
        self.episodes = Episodes(ctx, "OFB301")

    def on_event(self, event: Event) -> None:
        assert isinstance(event, ControlMode)
        if event.flags():
            self.episodes.good("empty")
            return
        self.episodes.bad(
            "empty",
            event.t,
            event.where,
            "OffboardControlMode with no field true: it declares no setpoint, and PX4 takes "
            "it for no offboard signal at all",
        )

    def on_batch(self, batch: StreamBatch) -> None:
        """A run never spans a change of the declared first flag, so its OCMs are all empty
        (``declared_flag`` None: judged one by one) or all declare something: then the first
        one closes an open episode and the rest change nothing."""
        if ControlMode not in batch.classes():
            return
        if batch.state.declared_flag is None:
            self.replay(batch)
        elif self.episodes.open:
            self.episodes.good("empty")

    def finish(self, t_end: float) -> None:
        self.episodes.close_all()


class SetpointNotDeclared(Check):
    """OFB302: in offboard, a setpoint topic the first true field does not select."""

    codes = ("OFB302",)
    wants = PX4_SETPOINTS

    def __init__(self, ctx: CheckContext) -> None:
        super().__init__(ctx)
        self.episodes = Episodes(ctx, "OFB302")
        self.logged = False
        self.sent = False

    def on_event(self, event: Event) -> None:
        if event.origin != "sent":
            # A ULog copy cannot tell the external writer from PX4's own controllers.
            self.logged = True
            return
        self.sent = True
        flag = declared_flag(self.ctx)
        row = row_for(self.ctx.profile, flag)
        if not self.ctx.in_offboard or row is None:
            self.episodes.close_all()
            return
        key = f"{event.kind}/{flag}"
        if event.kind in row.allowed:
            self.episodes.good(key)
            return
        self.episodes.bad(
            key,
            event.t,
            event.where,
            f"{SETPOINT_NAMES[event.kind]} published in offboard while OffboardControlMode's "
            f"first true field is '{flag}', which does not select it: PX4's own controller "
            f"still writes this topic{mode_note(self.ctx)}",
            short=f"{SETPOINT_NAMES[event.kind]} sent under '{flag}', which does not select it",
        )

    def on_batch(self, batch: StreamBatch) -> None:
        """Within a run the mode and the declared flag are fixed, so the verdict depends only
        on each setpoint's origin and kind: logged copies only set ``logged``; sent setpoints of
        kinds the declaration selects, with nothing open, change nothing but ``sent``."""
        events = batch.of(PX4_SETPOINTS)
        if not events:
            return
        origins = set(map(_ORIGIN, events))
        if "sent" not in origins:
            self.logged = True
            return
        if len(origins) > 1 or self.episodes.open:
            self.replay(batch)
            return
        self.sent = True
        row = self.ctx.row_for(batch.state.declared_flag)
        if not self.ctx.in_offboard or row is None:
            return  # close_all with nothing open
        kinds = {cls.kind for cls in batch.classes() if cls in PX4_SETPOINTS}
        if not row.allowed.issuperset(kinds):
            self.replay(batch)

    def finish(self, t_end: float) -> None:
        self.episodes.close_all()
        if self.logged and not self.sent:
            self.ctx.cannot_check(
                "OFB302",
                "needs the setpoints as sent (ROS 2 /fmu/in topics); a ULog logs PX4's own "
                "setpoints on the same topics",
            )


ULOG_NEW_TOPIC_S = 1.0
"""How late PX4's logger may log the first sample of a topic first advertised in flight: the
1.17.0 airplane's ``trajectory_setpoint`` (advertised by the MAVLink receiver at the switch to
OFFBOARD, published every 0.1 s from then) was first logged 0.75 s after the switch
(``corpora/sitl/fw_loss-1.17.0.ulg``)."""


class DeclaredSetpointMissing(Check):
    """OFB303: in offboard, the declared setpoint message has not been published.

    ROS 2: per the first true field of ``OffboardControlMode``; a setpoint published once before
    counts (it stays on the topic). MAVLink (no ``OffboardControlMode`` in the recording): PX4's
    receiver forwards a setpoint only while the vehicle is in OFFBOARD (gate.md#receiver), so only a
    setpoint it takes at or after the switch counts."""

    codes = ("OFB303",)
    wants = (
        *PX4_SETPOINTS,
        *MAVLINK_SETPOINTS,
        ControlMode,
        VehicleStatus,
        GateTransition,
        Command,
        CommandAck,
    )

    def __init__(self, ctx: CheckContext) -> None:
        super().__init__(ctx)
        self.grace = float(ctx.option("OFB303", "grace_s"))
        self.first_seen: dict[str, float] = {}
        self.since: float | None = None
        """When the current (offboard, first flag) period began."""
        self.flag: str | None = None
        self.checked = False
        self.armed: bool | None = None
        self.armed_at = 0.0
        self.mav_sent: MavlinkTarget | None = None
        """The newest MAVLink setpoint sent (None: not a MAVLink stream, so far)."""
        self.mav_taken: float | None = None
        """When PX4's receiver last took one (published a setpoint in OFFBOARD)."""
        self.mav_since: float | None = None
        self.mav_checked = False

    def on_event(self, event: Event) -> None:
        self._due(event.t)
        self._mav_due(event.t)
        if event.kind in SETPOINT_NAMES and event.origin != "model":
            self.first_seen.setdefault(event.kind, event.t)
        state = self.ctx.state
        if isinstance(event, MavlinkTarget) and event.origin == "sent":
            self.mav_sent = event
            if self.ctx.in_offboard and self._taken(event, self.ctx.gate.receiver):
                self.mav_taken = event.t
        if state.armed is not self.armed:
            self.armed = state.armed
            self.armed_at = event.t
        # A vehicle parked disarmed in OFFBOARD (accepted from 1.14) needs no setpoint yet.
        active = self.ctx.flying
        if not active:
            self.mav_since = None
        elif self.mav_since is None:
            self.mav_since = max(self.ctx.offboard_since or event.t, self.armed_at)
            self.mav_checked = False
        flag = declared_flag(self.ctx) if active else None
        if flag != self.flag:
            since = self.ctx.offboard_since
            if self.flag is None and since is not None:
                # Counted from the switch itself (an accepted ack) or the arming, if later.
                self.since = max(since, self.armed_at)
            else:
                self.since = None if flag is None else event.t
            self.flag = flag
            self.checked = False

    def on_batch(self, batch: StreamBatch) -> None:
        """Fast path once a period is settled (both deadlines judged, and the run's first
        message would not start a new period): then ``on_event`` only records the first time
        of each setpoint kind and the newest MAVLink setpoint sent and taken, which are
        worked out from the end of the run. Otherwise the run is replayed."""
        if not self._settled(batch.state):
            self.replay(batch)
            return
        present = batch.classes()
        new = {cls.kind for cls in present if cls.kind not in self.first_seen}
        if not new.isdisjoint(SETPOINT_NAMES):
            self._note_first_seen(batch.of(PX4_SETPOINTS), new)
        if not present.isdisjoint(MAVLINK_SETPOINTS):
            self._note_mavlink(batch.events, self.ctx.in_offboard)

    def _settled(self, state: VehicleState) -> bool:
        """Nothing due can be reported and a message of this state moves no period on."""
        if self.since is not None and not self.checked and self.flag is not None:
            return False
        if self.mav_since is not None and not self.mav_checked:
            return False
        active = self.ctx.flying
        return (
            state.armed is self.armed
            and active is (self.mav_since is not None)
            and (state.declared_flag if active else None) == self.flag
        )

    def _note_first_seen(self, setpoints: list[Event], new: set[str]) -> None:
        """``first_seen.setdefault`` for each setpoint of a kind not seen yet (``new``)."""
        first_seen = self.first_seen
        for event in setpoints:
            if event.kind in new and event.kind in SETPOINT_NAMES and event.origin != "model":
                first_seen.setdefault(event.kind, event.t)

    def _note_mavlink(self, events: list[Event], in_offboard: bool) -> None:
        """The newest MAVLink setpoint sent, and the newest one PX4's receiver takes (in
        offboard): the last assignment of each in ``on_event``, found from the end (on a
        MAVLink stream usually the run's last message)."""
        sent = (e for e in reversed(events) if isinstance(e, MavlinkTarget) and e.origin == "sent")
        newest = next(sent, None)
        if newest is None:
            return
        assert isinstance(newest, MavlinkTarget)
        self.mav_sent = newest
        if not in_offboard:
            return
        rx = self.ctx.gate.receiver
        for event in chain((newest,), sent):
            assert isinstance(event, MavlinkTarget)
            if self._taken(event, rx):
                self.mav_taken = event.t
                return

    def _due(self, t: float) -> None:
        if self.since is None or self.checked or self.flag is None:
            return
        row = row_for(self.ctx.profile, self.flag)
        deadline = self.since + self.grace
        if row is not None and self._first_logged_late(row):
            deadline = self.since + max(self.grace, ULOG_NEW_TOPIC_S)
        if t < deadline:
            return
        self.checked = True
        if row is None or self._served(row, deadline):
            return
        self.ctx.report(
            "OFB303",
            f"in offboard with first true field '{self.flag}' since {self.since:.3f} s, but no "
            f"{describe_required(row)} has been published by {deadline:.3f} s: PX4 has no "
            f"setpoint for the controllers it enabled{mode_note(self.ctx)}",
            deadline,
            self.ctx.state.control_mode.where if self.ctx.state.control_mode else None,
            short=f"'{self.flag}' declared since {self.since:.3f} s, but no "
            f"{describe_required(row)} published",
        )

    def _first_logged_late(self, row: FlagRow) -> bool:
        """A ULog in which no setpoint the flag needs was logged before the period: PX4's logger
        may log a topic first advertised now (a fixed-wing's ``trajectory_setpoint``, which its
        MAVLink receiver advertises at the switch) up to ``ULOG_NEW_TOPIC_S`` late."""
        if self.ctx.info.format != "ulog" or self.since is None:
            return False
        seen = self.first_seen
        return not any(
            seen.get(kind, self.since) < self.since for alt in row.required for kind in alt
        )

    def _served(self, row: FlagRow, by: float) -> bool:
        return any(
            all(kind in self.first_seen and self.first_seen[kind] <= by for kind in alt)
            for alt in row.required
        )

    # -- MAVLink ------------------------------------------------------------------------

    @staticmethod
    def _taken(event: MavlinkTarget, rx: ReceiverContext) -> bool:
        """Does PX4's receiver publish a setpoint for it (gate.md#receiver)?"""
        mask, axes, _, _ = receive(event, rx)
        return mask != DROPPED and (axes != 0 or isinstance(event, SetAttitudeTarget))

    def _mav_due(self, t: float) -> None:
        since = self.mav_since
        if since is None or self.mav_checked or t <= since + self.grace:
            return  # a setpoint at the deadline itself is in time
        self.mav_checked = True
        sent = self.mav_sent
        if sent is None or self.ctx.state.control_mode is not None:
            return  # not a MAVLink stream (so far), or ROS 2's declaration decides
        deadline = since + self.grace
        if self.mav_taken is not None and self.mav_taken >= since:
            return
        if sent.t >= since:
            what = (
                f"the MAVLink setpoints sent since (the newest {sent.kind.upper()} at "
                f"{sent.t:.3f} s) are all dropped by PX4's receiver (see OFB6xx)"
            )
        else:
            what = f"the newest MAVLink setpoint was sent at {sent.t:.3f} s, before the switch"
        self.ctx.report(
            "OFB303",
            f"in OFFBOARD since {since:.3f} s, but no MAVLink setpoint PX4 takes has arrived "
            f"by {deadline:.3f} s ({what}): PX4 forwards MAVLink setpoints only in OFFBOARD, "
            "so the vehicle holds (a multicopter flies a failsafe hold setpoint) until the "
            f"next one arrives{mode_note(self.ctx)}",
            deadline,
            sent.where,
            short=f"in OFFBOARD since {since:.3f} s without a MAVLink setpoint: the vehicle holds",
        )

    def finish(self, t_end: float) -> None:
        self._due(t_end)
        self._mav_due(t_end + 1e-9)


@dataclass(slots=True)
class _Stretch:
    """Changes of the first true field close together: one finding."""

    start: float
    where: Where
    first: str
    flags: list[str]
    last: float
    changes: int = 1


class ControlModeChanged(Check):
    """OFB304: the first true field PX4 receives changes while in offboard (info).

    On ROS 2 (and in a ULog) that is ``OffboardControlMode`` as recorded; over MAVLink there is
    none, and PX4's receiver sets the flags from each setpoint's type mask (gate.md#receiver), so
    the same flight judged from its tlog and from its ULog (which logs the receiver's
    ``offboard_control_mode``) tells the same changes. Changes less than ``stretch_s`` apart are
    one finding: a stream that interleaves setpoint types switches the flags with every
    message, which the logger's 10 Hz samples of it show as an irregular alternation."""

    codes = ("OFB304",)
    wants = (
        ControlMode,
        *MAVLINK_SETPOINTS,
        VehicleStatus,
        GateTransition,
        FailsafeFlags,
        Parameter,
    )

    def __init__(self, ctx: CheckContext) -> None:
        super().__init__(ctx)
        self.flag: str | None = None
        self.stretch_s = float(ctx.option("OFB304", "stretch_s"))
        self.open: _Stretch | None = None
        self.memo: dict[Shape, str | None] = {}
        """The first flag PX4's receiver sets for a MAVLink setpoint, by the message's shape
        (``receiver.shape``): emptied when a parameter or an estimate may change the answer."""

    def on_event(self, event: Event) -> None:
        if isinstance(event, FailsafeFlags | Parameter):
            self.memo.clear()
            return
        if not self.ctx.in_offboard:
            self.flag = None
            self._close()
            return
        if isinstance(event, ControlMode):
            flag = event.first_flag()
        elif isinstance(event, MavlinkTarget):
            flag = self._mavlink_flag(event)
        else:
            return
        if flag is None:
            return  # OFB301's case, or a setpoint PX4 drops (OFB6xx)
        if self.flag is not None and flag != self.flag:
            self._changed(event, flag)
        self.flag = flag

    def on_batch(self, batch: StreamBatch) -> None:
        """An OCM run carries the run's declared first flag (a change of it ends a run), so
        only its first message can change it; a MAVLink run is judged by the flag each message
        implies, replayed only where one differs."""
        classes = batch.classes()
        mavlink = batch.of(MAVLINK_SETPOINTS) if classes & _MAVLINK else []
        if ControlMode not in classes and not mavlink:
            return
        if not self.ctx.in_offboard:
            self.flag = None
            self._close()
            return
        if ControlMode in classes:
            if mavlink:
                self.replay(batch)
                return
            flag = batch.state.declared_flag
            if flag is None:
                return
            if self.flag is not None and flag != self.flag:
                self.replay(batch)
                return
            self.flag = flag
            return
        flags = self._run_flags(mavlink, classes)
        flags.discard(None)
        if not flags:
            return
        if len(flags) > 1 or (self.flag is not None and self.flag not in flags):
            self.replay(batch)
            return
        (self.flag,) = flags

    def _run_flags(self, mavlink: list[Event], classes: frozenset[type[Event]]) -> set[str | None]:
        """The first flags a run's MAVLink setpoints imply: by their distinct shapes where the
        run has one setpoint class (a MAVLink stream: one shape, one lookup), else one by one."""
        if len(classes) == 1:
            (cls,) = classes
            shapes = set(map(SHAPES[cls], mavlink))
            if None not in shapes and all(key in self.memo for key in shapes):
                return {self.memo[key] for key in shapes}  # type: ignore[index]
        return set(map(self._mavlink_flag, mavlink))

    def _mavlink_flag(self, event: Event) -> str | None:
        assert isinstance(event, MavlinkTarget)
        key = SHAPES[type(event)](event)
        if key is not None:
            try:
                return self.memo[key]
            except KeyError:
                pass
        mask, _, _, _ = receive(event, self.ctx.gate.receiver)
        flag = None if mask == DROPPED else ocm.FLAG_NAMES.get(ocm.first_flag(mask))
        if key is not None:
            self.memo[key] = flag
        return flag

    def _changed(self, event: Event, flag: str) -> None:
        assert self.flag is not None
        stretch = self.open
        if stretch is not None and event.t - stretch.last <= self.stretch_s:
            stretch.last = event.t
            stretch.changes += 1
            if flag not in stretch.flags:
                stretch.flags.append(flag)
            return
        self._close()
        self.open = _Stretch(event.t, event.where, self.flag, [self.flag, flag], event.t)

    def _close(self) -> None:
        stretch, self.open = self.open, None
        if stretch is None:
            return
        mavlink = self.ctx.has(*_MAVLINK_KINDS) and not self.ctx.has(ControlMode.kind)
        field = (
            "the first true field PX4's receiver sets from the setpoints' type masks"
            if mavlink
            else "OffboardControlMode's first true field"
        )
        what = "implied flags" if mavlink else "declaration"
        if stretch.changes == 1:
            first, then = stretch.flags
            message = (
                f"{field} changed from '{first}' to '{then}' in offboard: PX4 switches its "
                "controller chain mid-flight"
            )
            end = None
        else:
            among = ", ".join(f"'{f}'" for f in stretch.flags)
            message = (
                f"{field} changed {stretch.changes} times in offboard, between {among}, until "
                f"{stretch.last:.3f} s (each change less than {self.stretch_s:g} s after the "
                "one before: setpoint types interleaved): PX4 switches its controller chain "
                "at every change"
            )
            end = stretch.last
        if stretch.changes == 1:
            short = f"{what} changed from '{stretch.flags[0]}' to '{stretch.flags[1]}' in offboard"
        else:
            short = f"{what} changed {stretch.changes} times in offboard (interleaved types)"
        self.ctx.report(
            "OFB304",
            message + mode_note(self.ctx),
            stretch.start,
            stretch.where,
            end=end,
            short=short,
        )

    def finish(self, t_end: float) -> None:
        self._close()


_MAVLINK = frozenset(MAVLINK_SETPOINTS)
_MAVLINK_KINDS = tuple(cls.kind for cls in MAVLINK_SETPOINTS)


class RequiredEstimateMissing(Check):
    """OFB305: the estimate the first true field requires is invalid at the request or in
    offboard (needs the estimator validity the recording rarely has outside a ULog)."""

    codes = ("OFB305",)
    wants = (ControlMode, FailsafeFlags, VehicleStatus, GateTransition, Command)

    def __init__(self, ctx: CheckContext) -> None:
        super().__init__(ctx)
        self.bad_key: str | None = None
        self.saw_mode = False

    def on_event(self, event: Event) -> None:
        if isinstance(event, ControlMode):
            self.saw_mode = True
        request = isinstance(event, Command) and event.is_offboard_switch
        if not (self.ctx.in_offboard or request):
            self.bad_key = None
            return
        missing = self._missing()
        if missing is None:
            self.bad_key = None
            return
        flag, estimate = missing
        key = f"{flag}/{estimate}"
        if key == self.bad_key and not request:
            return
        self.bad_key = key
        at = "at the offboard request" if request else f"in offboard{mode_note(self.ctx)}"
        self.ctx.report(
            "OFB305",
            f"first true field '{flag}' requires a valid {estimate} estimate, but the "
            f"recording shows it invalid {at}",
            event.t,
            _where(event),
            short=f"'{flag}' declared without a valid {estimate} estimate",
        )

    def _missing(self) -> tuple[str | None, str] | None:
        """(declared flag, its estimate) when the recording shows that estimate invalid."""
        flags = self.ctx.state.failsafe_flags
        flag = declared_flag(self.ctx)
        row = self.ctx.row_for(flag)
        if flags is None or row is None or row.estimate is None:
            return None
        if estimate_valid(flags, row.estimate) is not False:
            return None
        return flag, row.estimate

    def on_batch(self, batch: StreamBatch) -> None:
        """The state an OCM is judged on is fixed within a run, so every OCM of it gives the
        same key: only the first can report (then replayed), the rest keep ``bad_key``."""
        if ControlMode not in batch.classes():
            return
        self.saw_mode = True
        key = None
        if self.ctx.in_offboard:
            missing = self._missing()
            if missing is not None:
                key = f"{missing[0]}/{missing[1]}"
        if key is not None and key != self.bad_key:
            self.replay(batch)
            return
        self.bad_key = key

    def finish(self, t_end: float) -> None:
        if self.saw_mode and not self.ctx.has("failsafe_flags"):
            self.ctx.cannot_check(
                "OFB305",
                "needs the estimator validity flags (failsafe_flags in a ULog or on /fmu/out, "
                "vehicle_status_flags before 1.14)",
            )


def _where(event: Event) -> Where | None:
    return None if isinstance(event, GateTransition) else event.where
