"""The recorded mode history against the prediction (gate.md#history): one part of ``GateModel``.

``RecordedHistory`` starts the model from the recording's first status (a recording may start
mid-flight), adopts what the recording shows with no recorded command for it (an RC switch, an
auto-disarm after landing) and settles the arming state undecided requests depended on. Every
status is compared with the prediction (``compare``): a difference that outlasts the evaluation
slack is reported once (``disagreement``, or ``mode`` where OFFBOARD is on neither side) and
the model re-synchronises to the recording.
"""

from __future__ import annotations

from fuzzoff.events import NAV_STATE_OFFBOARD, VehicleStatus
from fuzzoff.gate.commander import Requests
from fuzzoff.gate.compare import NOT_OFFBOARD
from fuzzoff.gate.effective import TERMINATION, EffectiveMode
from fuzzoff.gate.keepalive import RECORDED_FAILSAFE, KeepAlives
from fuzzoff.gate.signal import INF
from fuzzoff.gate.state import GateState
from fuzzoff.gate.verdict import UnseenStream
from fuzzoff.modes import nav_state_name
from fuzzoff.tables.answered import command_name


class RecordedHistory:
    def __init__(
        self,
        state: GateState,
        mode: EffectiveMode,
        keepalives: KeepAlives,
        requests: Requests,
        unseen: UnseenStream,
    ) -> None:
        self.s = state
        self.mode = mode
        self.keepalives = keepalives
        self.requests = requests
        self.unseen = unseen
        self.started = False

    def status(self, status: VehicleStatus) -> bool:
        s = self.s
        s.landed.mode(status.t, status.nav_state)
        if not self.started:
            self._start(status)
            return True
        s.compare.remember(status)
        self.unseen.lost_in(status)
        if s.unshown_arming is not None and status.armed is s.unshown_arming[1]:
            s.unshown_arming = None
        if status.armed is not None and s.armed is None:
            state = "armed" if status.armed else "disarmed"
            self.requests.resolve(status.t, status.armed, f"recorded: {state} at {status.t:.2f} s")
        if s.signal.held_until != INF and self._shows_failsafe(status):
            self.keepalives.shown(status.t, RECORDED_FAILSAFE)
        if (
            s.failsafe_due != INF
            and status.nav_state is not None
            and status.nav_state != NAV_STATE_OFFBOARD
        ):
            # The recording already shows the vehicle out of OFFBOARD between the check pass
            # that saw the loss and the model's failsafe iteration: PX4's loop phase is not the
            # model's grid (2.1.3), this is the failsafe. Run it now (never back in time).
            s.failsafe_due = INF
            self.mode.refresh(status.t, cause=None)
        armed, intention = self._unseen_inputs(status)
        if armed or intention is not None:
            self._adopt(status.t, status, intention, silent=True)
        self.unseen.back_in(status)
        s.compare.observe(status, s.nav)
        return True

    def _start(self, status: VehicleStatus) -> None:
        """Initialise from the first recorded status (a recording may start mid-flight)."""
        s = self.s
        self.started = True
        t = status.t
        if status.armed is not None:
            state = "armed" if status.armed else "disarmed"
            if self.requests.pending():
                self.requests.resolve(t, status.armed, f"recorded: {state} at {t:.2f} s")
            s.armed = status.armed
            if status.armed:
                s.landed.armed(t)
        intention = status.user_intention
        if intention is None:
            intention = status.nav_state
        s.user_intention = intention
        self.unseen.start(t)
        # Assumption: a recording that starts in OFFBOARD starts with a live stream.
        if (
            not s.follows_flag
            and status.nav_state == NAV_STATE_OFFBOARD
            and not s.signal.available
            and s.signal.keepalive(t, True)
        ):
            s.emit(
                t,
                "signal_available",
                "offboard signal assumed available: the recording starts in OFFBOARD",
                s.signal.spec,
            )
        s.nav = status.nav_state
        s.offboard_since = t if s.nav == NAV_STATE_OFFBOARD else None
        self.mode.refresh(t)
        s.compare.remember(status)

    def _shows_failsafe(self, status: VehicleStatus) -> bool:
        """Does this status, inside the loss window, show PX4 out of OFFBOARD by the loss
        failsafe: no command that explains it, and the intention still OFFBOARD or the mode the
        loss action selects (a recording may carry the mode as the intention)?"""
        s = self.s
        if status.nav_state is None or status.nav_state == NAV_STATE_OFFBOARD:
            return False
        if s.user_intention != NAV_STATE_OFFBOARD or s.compare.recent_command(status.t):
            return False
        if status.user_intention in (None, NAV_STATE_OFFBOARD):
            return True
        return status.nav_state == s.loss_action().nav_state

    def _unseen_inputs(self, status: VehicleStatus) -> tuple[bool, int | None]:
        """Changes the recording shows with no recorded command near them (an RC switch, an
        auto-disarm after landing): adopted silently. (armed changed, intention to adopt)."""
        s = self.s
        if s.compare.recent_command(status.t):
            return False, None
        armed = status.armed is not None and status.armed != s.armed
        intention: int | None = None
        if status.user_intention is not None:
            if status.user_intention != s.user_intention:
                intention = status.user_intention
        elif (
            status.nav_state is not None
            and status.nav_state != s.nav
            and (
                s.user_intention != NAV_STATE_OFFBOARD
                or (
                    s.signal.available
                    and status.failsafe is not True
                    and not self._failsafe_still_shown(status)
                )
            )
        ):
            intention = status.nav_state
        return armed, intention

    def _failsafe_still_shown(self, status: VehicleStatus) -> bool:
        """The loss action's mode, shown within the slack after the model's signal came back:
        PX4 ends the failsafe at its next check pass (gate.md#check-timing), so a status sent
        in between (a tlog's HEARTBEAT, which has no failsafe flag) still shows it. Not a mode
        the pilot chose."""
        s = self.s
        return (
            status.t - s.sig_changed_at <= s.compare.slack
            and status.nav_state == s.loss_action().nav_state
        )

    def _intention_for(self, status: VehicleStatus) -> int | None:
        """The user intention a confirmed difference re-synchronises to."""
        s = self.s
        if status.user_intention is not None:
            return status.user_intention
        if (
            s.user_intention == NAV_STATE_OFFBOARD
            and not s.signal.available
            and status.nav_state != NAV_STATE_OFFBOARD
        ):
            return None  # plausibly the failsafe: keep the intention
        return status.nav_state

    def _adopt(self, t: float, status: VehicleStatus, intention: int | None, silent: bool) -> None:
        """Re-synchronise arming and user intention to the recording."""
        s = self.s
        changed = []
        if status.armed is not None and status.armed != s.armed:
            if status.armed:
                s.armed_now(t)
            else:
                s.disarmed_now()
            changed.append("armed" if status.armed else "disarmed")
        if intention is not None and intention != s.user_intention:
            s.user_intention = intention
            s.terminated = intention == TERMINATION
            s.fallback = None
            changed.append(f"intention {nav_state_name(intention)}")
        unshown = s.unshown_arming
        if silent and unshown is not None and status.armed is not None:
            s.unshown_arming = None
            if changed and changed[0] in ("armed", "disarmed") and status.armed is not unshown[1]:
                self._arming_contradicted(t, status, unshown)
                changed = changed[1:]
        if changed and silent:
            after = s.compare.unjudged_before(t)
            why = (
                "no command for it in the recording"
                if after is None
                else f"after {command_name(after.command)} at {after.t:.2f} s, a command the "
                "model does not judge"
            )
            s.emit(
                t,
                "mode",
                f"from the recording ({why}): " + ", ".join(changed),
                "12",
                cause=status,
            )
        self.mode.refresh(t, cause=status)

    def _arming_contradicted(
        self, t: float, status: VehicleStatus, unshown: tuple[float, bool]
    ) -> None:
        """The recording shows the other arming state than the model took on a command, and
        never showed the model's: PX4 did not do what the model predicted (the command never
        reached it, or it refused it without an ack). A disagreement, not a silent change."""
        at, armed = unshown
        model = "armed" if armed else "disarmed"
        recorded = "disarmed" if armed else "armed"
        self.s.emit(
            t,
            "disagreement",
            f"recorded: {recorded} at {t:.2f} s, never {model} since the "
            f"{'arm' if armed else 'disarm'} request at {at:.2f} s; model: {model}",
            "12",
            cause=status,
            recorded_nav_state=status.nav_state,
        )

    # -- a difference that outlasts the slack

    def due(self) -> float:
        """When a recorded difference is confirmed (inf if none waits)."""
        return self.s.compare.difference_due()

    def confirm(self, at: float) -> None:
        """A recorded difference outlasted the slack: report it once and re-synchronise."""
        s = self.s
        pending = s.compare.take_pending()
        if pending is None:
            return
        status = pending.status
        model = nav_state_name(s.nav)
        if s.fallback is not None:
            model += f" (failsafe {s.fallback.action}{s.fallback_when})"
        text = f"recorded: {nav_state_name(status.nav_state)} at {pending.t:.2f} s; model: {model}"
        if s.involves_offboard(status.nav_state, status.user_intention) or (
            s.involves_offboard(pending.latest.nav_state, pending.latest.user_intention)
        ):
            s.emit(
                pending.t,
                "disagreement",
                text,
                "12",
                cause=status,
                recorded_nav_state=status.nav_state,
            )
        else:
            s.emit(pending.t, "mode", f"{text} ({NOT_OFFBOARD})", "12", cause=status)
        self._adopt(at, pending.latest, self._intention_for(pending.latest), False)
