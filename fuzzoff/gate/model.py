"""The gate model: proof of life, requests, loss failsafe and controllers, per profile.

Interface (stable for the engine and the checks):

* ``GateModel(profile, params=None, vehicle="")``: ``params`` are the user's overrides (they win
  over the recording's ``Parameter`` events, which win over PX4's defaults); ``vehicle`` is the
  vehicle id the events carry (the vehicle *type* comes from ``profile.vehicle``);
* ``feed(event) -> list[GateTransition]``: advance the clock to ``event.t`` (timeouts are computed
  arithmetically, see ``signal``), then apply the event. The returned list must not be mutated.
  No transition is earlier than one returned before, with one exception: a ``disagreement``
  (and its ``mode`` twin for differences without OFFBOARD) is confirmed one evaluation slack
  after the recorded difference began and carries that beginning as its time;
* ``finish(t_end) -> list[GateTransition]``;
* ``signal_ok``, ``armed``, ``user_intention``, ``nav_state`` (effective), ``in_offboard``,
  ``params``.

The recording's own mode history is compared with the prediction as it goes (``compare``): a
difference that outlasts the evaluation slack becomes a ``disagreement`` transition and the model
re-synchronises (arming, user intention) so one difference is reported once.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

from fuzzoff.events import (
    MAV_CMD_COMPONENT_ARM_DISARM,
    NAV_STATE_OFFBOARD,
    Command,
    CommandAck,
    ControlMode,
    Event,
    FailsafeFlags,
    LandDetected,
    LegacyControlMode,
    Parameter,
    PositionSetpointTriplet,
    SetAttitudeTarget,
    SetPositionTargetGlobal,
    SetPositionTargetLocal,
    StatusText,
    TrajectorySetpoint,
    VehicleStatus,
)
from fuzzoff.gate import controllers, ocm
from fuzzoff.gate.compare import SAMPLED_SLACK, Comparator, Decided
from fuzzoff.gate.estimates import Estimates
from fuzzoff.gate.failsafe import LossAction, loss_action, rc_present
from fuzzoff.gate.landed import LandedState, climbs
from fuzzoff.gate.params import default_params
from fuzzoff.gate.receiver import DROPPED, SHAPES, ReceiverContext, Result, Shape, receive
from fuzzoff.gate.requests import (
    Decision,
    arm_decision,
    decode_mode,
    disarm_decision,
    switch_decision,
)
from fuzzoff.gate.signal import (
    CHECK_PERIOD,
    INF,
    LOOP_PERIOD,
    UnseenSignal,
    estimate_failure,
    make_signal,
    px4_stamp,
    slack,
)
from fuzzoff.gate.tracker import ControllerTracker
from fuzzoff.gate.transitions import GateTransition, TransitionKind
from fuzzoff.modes import nav_state_name
from fuzzoff.profiles import Profile
from fuzzoff.releases import LossFailsafe

EMPTY: list[GateTransition] = []
"""Returned when an event changes nothing (shared: never mutate a returned list)."""

TERMINATION = 13
NOT_OFFBOARD = "no OFFBOARD on either side: other modes' own rules are not modelled; followed"
FAILSAFE_TEXT_WINDOW_S = 3.0
"""A failsafe STATUSTEXT this long before a recorded change out of OFFBOARD explains it (PX4
sends the text at once; the 1 Hz HEARTBEAT shows the new mode up to a second later)."""
_RESUME_SPEC: dict[LossFailsafe, str] = {
    "framework": "5.1",
    "state_machine": "5.2",
    "state_machine_legacy": "5.3",
}
"""The spec section of the return to OFFBOARD when the signal comes back, by loss failsafe."""
NO_STREAM_SWITCH = "1.14+: no stream needed while disarmed, checked at arming"
RECORDED_FAILSAFE = "PX4's failsafe recorded then"
NOT_FLAGGED = "the model's alone: PX4's failsafe_flags shows no loss"
"""``seen_in`` of a loss the recording's flag of PX4 contradicts (a disagreement follows)."""
SAME_ITERATION_S = 0.012
"""A request and a flag logged this close were handled in one Commander iteration (10 ms)."""
FLAG_FRESH_S = 1.0
"""PX4 publishes ``failsafe_flags`` at each change and about every 0.5 s: a recording whose
newest sample is older than this does not show PX4's verdict any more."""


@dataclass(slots=True)
class Undecided:
    """A request decided while the recording did not show the arming state, whose outcome
    depends on it: the model follows ``if_disarmed`` until the recording decides."""

    cmd: Command
    target: int | None
    if_disarmed: Decision
    if_armed: Decision
    before: tuple[int | None, bool | None]
    """(user intention, armed) before the request."""
    nav_before: int | None


class GateModel:
    def __init__(
        self,
        profile: Profile,
        params: Mapping[str, float] | None = None,
        vehicle: str = "",
        *,
        stream_recorded: bool = True,
        armed: bool | None = None,
    ) -> None:
        self.profile = profile
        self.px4 = profile.px4
        self.release = profile.release
        self.vehicle_type = profile.vehicle
        self.vehicle = vehicle
        self.overrides = dict(params or {})
        self.recorded_params: dict[str, float] = {}
        self.params = default_params(self.px4) | self.overrides
        self.est = Estimates()
        self.stream_recorded = stream_recorded
        """False: the recording cannot show the keep-alive (a ground station's tlog, a ULog
        without ``offboard_control_mode``). The signal is then PX4's own recorded verdict
        (``failsafe_flags.offboard_control_signal_lost``) where the recording has it; else it
        is taken as present, and lost only where PX4's own failsafe is recorded."""
        self.follows_flag = False
        """Without the stream: PX4's ``offboard_control_signal_lost`` has been seen, and the
        signal follows it from then on (the mode history no longer decides it)."""
        self.signal = make_signal(self.release, self.params)
        if not stream_recorded:
            self.signal = UnseenSignal(self.signal.timeout)
        self._failsafe_text_at = -INF
        """When PX4 last said a failsafe began (STATUSTEXT), for a recording without stream."""
        self.tick_based = self.release.tick_based
        self._flags_ignored = not self.release.control_mode_flags
        """Before 1.13 any keep-alive counts, whatever its flags (2.2)."""
        self.armed: bool | None = armed
        """None until the recording shows the arming state (or a request settles it):
        decisions that depend on it give both outcomes (``undecided``). A generator that
        simulates a vehicle from boot passes False."""
        self._undecided: list[Undecided] = []
        self.landed = LandedState(float(self.params.get("COM_DISARM_PRFLT", 0.0)))
        self.user_intention: int | None = None
        self._nav: int | None = None
        self._fallback: LossAction | None = None
        self._fallback_when = ""
        """When the model ran the current failsafe (a window where the recording does not
        date it), for disagreement texts."""
        self._fallback_stage = 0
        self._terminated = False
        self.ocm_mask = 0
        self._started = False
        self._out: list[GateTransition] | None = None
        self._cause: Event | None = None
        # controllers (sections 7-10)
        self._drop_reason: str | None = None
        self._good = False
        self._sampled = False
        self.ctl = ControllerTracker(self.release, self.vehicle_type, self.est)
        self._deadline = INF
        self._clock = -INF
        """The newest event time fed: nothing is emitted earlier (the timeline never goes back)."""
        self._sig_changed_at = -INF
        """When the model's signal state (available / lost) last changed."""
        self._flag: tuple[float, bool, FailsafeFlags] | None = None
        """A recorded ``offboard_control_signal_lost`` that differs from the model, waiting for
        the slack (time, recorded value, event)."""
        self._flag_episode = False
        """A flag difference was reported and the two have not agreed since."""
        self._failsafe_due = INF
        """1.14+: the Commander iteration that will run the loss failsafe (2.1.3), inf if none."""
        self._window: tuple[float, float] | None = None
        """1.14+: the current loss window (its start, the latest check pass), while held."""
        self._timing: tuple[float | None, str | None] = (None, None)
        """(earliest time, where the recording shows it) for the next failsafe transition."""
        self._verdict_recorded = False
        """The recording holds PX4's ``offboard_control_signal_lost`` (1.14+)."""
        self._flag_at = -INF
        """When that flag was last recorded."""
        self._flag_was: bool | None = None
        """That flag's previous recorded value."""
        self._flag_shows = False
        """The current loss window is one PX4's recorded flag will date."""
        self._rejected_unseen: tuple[Command, int | None, tuple[int | None, bool | None]] | None
        self._rejected_unseen = None
        """The newest request the model rejected for want of a signal (PX4's flag turning
        available in the same Commander iteration shows PX4 had one)."""
        self._flags_unlogged = False
        """PX4's flag made the signal available before any logged keep-alive: its flags are
        not known yet, and PX4's flag stands for them."""
        self._dirty = False
        self._stamp_offset: float | None = None
        self.compare = Comparator(slack(self.release) + LOOP_PERIOD)
        try:
            own: int | None = int(vehicle)
        except ValueError:
            own = None
        self._rx = ReceiverContext(
            release=self.release,
            own_system=own,
            own_component=int(self.params.get("MAV_COMP_ID", 1.0)),
            fwdextsp=bool(self.params.get("MAV_FWDEXTSP", 1.0)),
            est=self.est,
        )
        self._verdicts: dict[Shape, Result] = {}
        """``receive``'s accepted verdicts by message shape (``receiver.shape``) under the current
        receiver context: cleared when a parameter or an estimate changes."""
        self._handlers: dict[type, Callable[[Any], None]] = {
            ControlMode: self._on_control_mode,
            LegacyControlMode: self._on_legacy_control_mode,
            SetPositionTargetLocal: self._on_mavlink,
            SetPositionTargetGlobal: self._on_mavlink,
            SetAttitudeTarget: self._on_mavlink,
            TrajectorySetpoint: self._on_trajectory,
            PositionSetpointTriplet: self._on_triplet,
            VehicleStatus: self._on_status,
            FailsafeFlags: self._on_failsafe_flags,
            Command: self._on_command,
            CommandAck: self._on_ack,
            Parameter: self._on_parameter,
            StatusText: self._on_status_text,
            LandDetected: self._on_land,
        }

    # ------------------------------------------------------------------ public state

    @property
    def signal_ok(self) -> bool:
        return self.signal.available

    @property
    def nav_state(self) -> int | None:
        return self._nav

    @property
    def in_offboard(self) -> bool:
        return self._nav == NAV_STATE_OFFBOARD

    @property
    def receiver(self) -> ReceiverContext:
        """What PX4's MAVLink receiver reads besides the message (parameters, estimates),
        kept up to date as parameters arrive."""
        return self._rx

    @property
    def loss_timeout(self) -> float:
        return self.signal.timeout

    def current_loss_action(self) -> LossAction:
        """What the vehicle would do if the signal were lost now (OFB701/OFB702)."""
        return loss_action(self.release, self.vehicle_type, self.params, self.est)

    # ------------------------------------------------------------------ driving

    def feed(self, event: Event) -> list[GateTransition]:
        t = event.t
        if t >= self._deadline:
            self._advance(t)
            self._deadline = self._now_deadline
        if t > self._clock:
            self._clock = t
        handler = self._handlers.get(type(event))
        if handler is not None:
            self._cause = event
            self._dirty = True
            handler(event)
            self._cause = None
            if self._dirty:
                self._deadline = self._now_deadline
        out = self._out
        if out is None:
            return EMPTY
        self._out = None
        return out

    def finish(self, t_end: float) -> list[GateTransition]:
        self._advance(t_end)
        self.compare.drop_pending()
        return self._flush()

    def _flush(self) -> list[GateTransition]:
        out = self._out
        if out is None:
            return EMPTY
        self._out = None
        return out

    def _emit(
        self,
        t: float,
        what: TransitionKind,
        message: str,
        spec: str,
        **fields: Any,
    ) -> None:
        tr = GateTransition(
            t=t,
            vehicle=self.vehicle,
            what=what,
            message=message,
            spec=spec,
            cause=fields.pop("cause", self._cause),
            nav_state=fields.pop("nav_state", self._nav),
            armed=self.armed,
            **fields,
        )
        if self._out is None:
            self._out = [tr]
        else:
            self._out.append(tr)

    @property
    def _now_deadline(self) -> float:
        """The earliest time at which something happens without a new event."""
        return min(
            self.signal.lost_at(),
            self.signal.timeout_at(),
            self.ctl.reuse_due,
            self.compare.due(),
            self._failsafe_due,
            self._flag_due,
            self.signal.held_until,
        )

    @property
    def _flag_due(self) -> float:
        return INF if self._flag is None else self._flag[0] + self.compare.slack

    def _advance(self, t: float) -> None:
        while True:
            lost = self.signal.lost_at()
            timeout = self.signal.timeout_at()
            failsafe = self._failsafe_due
            flag = self._flag_due
            held = self.signal.held_until
            due = min(lost, timeout, self.ctl.reuse_due, self.compare.due(), failsafe, flag, held)
            if due > t:
                return
            # Due before an event already applied (a deadline that moved earlier): PX4 acts at
            # the next pass it runs, never in the past.
            at = max(due, self._clock)
            if flag == due:
                self._flag_differs()
            elif held == due:
                self._not_shown(at)
            elif failsafe == due:
                self._failsafe_due = INF
                self._refresh(at, cause=None)
                self._timing = (None, None)  # no failsafe ran (disarmed): nothing to date
            elif lost == due:
                self._signal_lost(at)
            elif timeout == due:
                self.signal.timed_out = True  # type: ignore[attr-defined]
                self._refresh(at)
            elif self.ctl.reuse_due == due:
                self.ctl.reuse_due = INF
                self._update_controller(at)
            else:
                self._confirm(at)

    # ------------------------------------------------------------------ proof of life

    def _signal_lost(self, t: float) -> None:
        """The loss is due at ``t``. On 1.14+ PX4's 10 Hz check pass sees it within one check
        period (2.1.3), at a phase only the recording can show: the model waits to the end of
        that window (``hold``). PX4's flag or its failsafe recorded meanwhile dates the loss;
        a good keep-alive meanwhile ends it with no loss (PX4 flags one only if its pass fell
        before it); otherwise the loss is the window, dated at its end."""
        if not self.tick_based:
            self._lose(t)
            return
        self._window = (t, t + CHECK_PERIOD)
        wait = CHECK_PERIOD
        self._flag_shows = self._verdict_recorded and t - self._flag_at <= FLAG_FRESH_S
        if self._flag_shows:
            # PX4's flag will say: allow one iteration, and one logging interval where the
            # keep-alive is a logged subsample that may hide the stream's last messages.
            wait += LOOP_PERIOD + (SAMPLED_SLACK if self._sampled else 0.0)
        self.signal.hold(t + wait)

    def _not_shown(self, t: float) -> None:
        """The window passed with no keep-alive: the loss is the window, or, where the
        recording holds PX4's flag and it has not flipped, the model's own verdict (a flag
        that still says available becomes a disagreement)."""
        window = self._window or (t, t)
        self._lose(t, window, NOT_FLAGGED if self._flag_shows else None)

    def _lose(
        self,
        t: float,
        window: tuple[float, float] | None = None,
        seen_in: str | None = None,
    ) -> None:
        """The signal is lost at ``t``: ``window`` is PX4's check-pass window (1.14+),
        ``seen_in`` where the recording shows PX4's verdict when ``t`` comes from there."""
        self._window = None
        self.signal.mark_lost()
        self._signal_changed(t)
        last = self.signal.last
        why = estimate_failure(self.release, self.ocm_mask, self.est) if self.tick_based else None
        if why is None and self.ocm_mask == 0 and last is not None and not self._flags_ignored:
            why = "no flag set in the newest keep-alive"
        if why is None and self.tick_based and self.signal.stamps_lag:
            why = "the newest keep-alive's timestamp is older than COM_OF_LOSS_T (2.1.1)"
        reason = why or "keep-alive timeout"
        when, earliest = self._loss_when(t, window, seen_in)
        age = ""
        if why is None and last is not None:
            start = t if earliest is None else earliest
            span = f"{t - last:.2f}" if start == t else f"{start - last:.2f}-{t - last:.2f}"
            age = f", {span} s after the newest keep-alive"
        note = self._unknown_arming_note()
        self._emit(
            t,
            "signal_lost",
            f"offboard signal lost ({reason}){when}{age}{note}",
            self.signal.spec,
            cause=None,
            reason=reason,
            t_earliest=earliest,
            seen_in=seen_in,
        )
        if self.signal.timeout_at() <= t:  # legacy: COM_OF_LOSS_T 0 = both stages at once
            self.signal.timed_out = True  # type: ignore[attr-defined]
        if self.tick_based:
            # 1.14+ (2.1.3): Commander's iteration runs handleModeIntentionAndFailsafe() before
            # the check block, so the failsafe reacts one iteration (10 ms) after the check pass
            # that saw the loss. Until then nothing changes the mode, and a keep-alive that
            # arrives in between cancels it (the forced check pass clears the flag). Emitting
            # it only when that iteration is reached keeps the timeline in time order.
            self._failsafe_due = t + LOOP_PERIOD
            self._timing = (None if earliest is None else earliest + LOOP_PERIOD, seen_in)
        else:
            self._refresh(t, cause=None)

    @staticmethod
    def _loss_when(
        t: float, window: tuple[float, float] | None, seen_in: str | None
    ) -> tuple[str, float | None]:
        """The time words of a loss and the window's start (None: ``t`` is the time)."""
        if window is None:
            return "", None
        start, end = window
        if seen_in == NOT_FLAGGED:
            return (
                f" by {end:.3f} s (the model's window {start:.3f}-{end:.3f} s; PX4's "
                f"failsafe_flags shows no loss by {t:.3f} s)",
                None,
            )
        if seen_in is not None:
            at = "by" if seen_in == RECORDED_FAILSAFE else "at"
            return f" {at} {t:.3f} s ({seen_in}; the model's window {start:.3f}-{end:.3f} s)", None
        return (
            f" between {start:.3f} and {end:.3f} s (PX4 checks at 10 Hz; the check's phase is "
            "not in the recording)",
            start,
        )

    def _unknown_arming_note(self) -> str:
        """A loss in OFFBOARD while the arming state is unknown: the failsafe runs only if
        armed (1.14+: none while disarmed, 4.1)."""
        if not (self.tick_based and self.armed is None):
            return ""
        if self.user_intention != NAV_STATE_OFFBOARD:
            return ""
        action = self.current_loss_action()
        return f"; arming not recorded: if armed, PX4 runs {action.action}, if disarmed nothing"

    def _keepalive(self, t: float, mask: int, event: Event, stamp: float | None = None) -> None:
        if mask == self.ocm_mask and self._good and (self._sampled or event.origin != "vehicle"):
            # The steady stream: same flags, good, sampling settled: only the signal moves. A
            # good keep-alive received now while available only moves the loss later: the
            # cached deadline stays a valid lower bound (feed() recomputes it when it is
            # reached). One with its own timestamp (2.1.1) may lag and move the loss earlier
            # (the signal says).
            if self.signal.keepalive(t, True, stamp):
                self._dirty = True
                self._signal_available(t, mask)
            else:
                self._dirty = stamp is not None and not self.signal.moved_later
            return
        self._flags_unlogged = False
        changed = mask != self.ocm_mask
        if changed:
            self.ocm_mask = mask
            self._mask_changed()
        if event.origin == "vehicle" and not self._sampled:
            self._sampled = True
            self.compare.sampled_keepalive()
        became = self.signal.keepalive(t, self._good, stamp)
        self._dirty = True  # a new mask, a bad keep-alive or a newly available signal
        if became:
            self._signal_available(t, mask)
        if changed:
            self._update_controller(t)

    def _signal_available(self, t: float, mask: int | None, seen_in: str | None = None) -> None:
        """``mask`` None: the keep-alive's flags are not in the recording yet."""
        self._failsafe_due = INF
        self._window = None
        self._timing = (None, None)
        self._signal_changed(t)
        what = [] if mask is None else [ocm.names(mask)]
        what += [seen_in] if seen_in else []
        self._emit(
            t,
            "signal_available",
            f"offboard signal available ({'; '.join(what)})",
            self.signal.spec,
            seen_in=seen_in,
        )
        self._refresh(t)

    def _mask_changed(self) -> None:
        """Recompute what depends only on the OCM flags and the estimates (cached: the hot path
        is one keep-alive per message)."""
        mask = self.ocm_mask
        if self._flags_ignored:
            self._good = True
        else:
            self._good = mask != 0 and estimate_failure(self.release, mask, self.est) is None
        self.ctl.set_mask(mask)

    def _on_control_mode(self, event: ControlMode) -> None:
        stamp = None
        if self.tick_based and event.origin == "sent" and event.sender_time_us is not None:
            stamp = self._px4_stamp(event.t, event.sender_time_us)
        self._keepalive(event.t, ocm.mask_of(event), event, stamp)

    def _px4_stamp(self, t: float, sender_us: int) -> float:
        """The OCM ``timestamp`` after PX4's uXRCE-DDS rewrite (2.1.1): 0 becomes the receive
        time, any other value ``min(value - offset, now)``. The agent-PX4 offset is unknown;
        fuzzoff takes the first stamped keep-alive as fresh (a sender clock that runs with the
        recording's is always fresh; one that stops or lags ages)."""
        if sender_us == 0:
            return t
        if self._stamp_offset is None:
            self._stamp_offset = sender_us * 1e-6 - t
        return px4_stamp(t, sender_us, self._stamp_offset)

    def _on_legacy_control_mode(self, event: LegacyControlMode) -> None:
        self._keepalive(event.t, ocm.legacy_mask(event), event)

    def _receive(self, event: SetPositionTargetLocal, key: Shape | None) -> Result:
        """``receive(event, self._rx)``, remembered under ``key`` (its shape). Only verdicts
        without a reason are kept: a reason's text shows field values, whose repr the shape
        does not fix (``1`` and ``True`` are the same key)."""
        verdict = receive(event, self._rx)
        if key is not None and verdict[2] is None:
            self._verdicts[key] = verdict
        return verdict

    def _on_mavlink(self, event: SetPositionTargetLocal) -> None:
        key = SHAPES[type(event)](event)
        verdict = self._verdicts.get(key) if key is not None else None
        if verdict is None:
            verdict = self._receive(event, key)
        mask, axes, reason, spec = verdict
        if mask == DROPPED:
            if reason != self._drop_reason:
                self._drop_reason = reason
                self._emit(
                    event.t,
                    "setpoint_dropped",
                    f"{event.kind.upper()} dropped, no keep-alive: {reason}",
                    spec,
                    reason=reason,
                )
            return
        if reason is not None and reason != self._drop_reason:
            self._drop_reason = reason
            self._emit(
                event.t,
                "setpoint_dropped",
                f"{event.kind.upper()}: {reason}",
                spec,
                reason=reason,
                unverified="unverified" in reason,
            )
        elif reason is None:
            self._drop_reason = None
        t = event.t
        self._keepalive(t, mask, event)
        if self.landed.watching and self._nav == NAV_STATE_OFFBOARD:
            self.landed.setpoint(t, isinstance(event, SetPositionTargetLocal) and climbs(event))
        if not axes:
            return
        if self._nav == NAV_STATE_OFFBOARD:
            if self.ctl.trajectory(t, axes, True):
                self._dirty = True
                self._update_controller(t)
        elif self.ctl.legacy:
            self.ctl.setpoint(t)  # legacy: counted once offboard runs (section 8)

    def _on_trajectory(self, event: TrajectorySetpoint) -> None:
        t = event.t
        if self.landed.watching and self._nav == NAV_STATE_OFFBOARD:
            self.landed.setpoint(t, climbs(event))
        self._dirty = self.ctl.trajectory(
            t, controllers.axes_of(event), self._nav == NAV_STATE_OFFBOARD
        )
        if self._dirty:
            self._update_controller(t)

    def _on_triplet(self, event: PositionSetpointTriplet) -> None:
        """legacy/1.11: the offboard setpoint as mc_pos_control sees it (section 8)."""
        self._dirty = False
        if self.ctl.legacy and event.current_valid and self.ctl.setpoint(event.t):
            self._update_controller(event.t)

    # ------------------------------------------------------------------ PX4's own verdict

    def _signal_changed(self, t: float) -> None:
        self._sig_changed_at = t
        if self._flag is not None and self._flag[1] == (not self.signal.available):
            self._flag = None  # the model reached the recorded value within the slack

    def _recorded_flag(self, event: FailsafeFlags) -> None:
        """``failsafe_flags.offboard_control_signal_lost`` is PX4's verdict on the signal: a
        value the model does not reach within the evaluation slack is a disagreement (2.1).
        Judged while OFFBOARD is selected (recorded or predicted), where the verdict decides
        the mode; elsewhere it only matters to a switch request, which the acks judge."""
        recorded = event.offboard_control_signal_lost
        if recorded is None:
            return
        flipped = self._flag_was is True and not recorded
        self._flag_was = recorded
        self._flag_at = event.t
        if self.tick_based:
            self._verdict_recorded = True
            if recorded and self.signal.held_until != INF:
                self._lose(event.t, self._window, "PX4's failsafe_flags")
            elif flipped and self._flag_back(event.t):
                return
        if recorded == (not self.signal.available):
            self._flag = None
            self._flag_episode = False
            return
        if self._flag_episode or self._flag is not None:
            return
        status = self.compare.last_status
        seen = (status.nav_state, status.user_intention) if status is not None else ()
        if not self._involves_offboard(*seen):
            return
        if event.t - self._sig_changed_at <= self.compare.slack:
            return  # the log lags the model's own change
        self._flag = (event.t, recorded, event)

    def _flag_back(self, t: float) -> bool:
        """PX4's flag has just turned to available before the logger's subsampled copy of the
        keep-alive arrives (13a: its first samples can be missing): the signal is available at
        the flag's time. Not where the model lost it because the keep-alive stopped counting."""
        if self.signal.available or (self.signal.last is not None and not self._good):
            return False  # a keep-alive that stopped counting (flags, estimates) is not lag
        first = self.signal.last is None
        if not self.signal.keepalive(t, True):
            return False
        mask = None if first else self.ocm_mask
        self._flags_unlogged = first
        self._signal_available(t, mask, "PX4's failsafe_flags; the logged keep-alive follows")
        self._rejudge(t)
        return True

    def _rejudge(self, t: float) -> None:
        """A switch or arm the model rejected for want of a signal, logged in the same
        Commander iteration as PX4's flag turning available: Commander had the keep-alive the
        logger missed (its forced check pass runs before it handles the command, 2.1.3; the
        ULog dates the command on receipt and the flag on publication). Judged again."""
        rejected, self._rejected_unseen = self._rejected_unseen, None
        if rejected is None:
            return
        cmd, target, before = rejected
        if t - cmd.t > SAME_ITERATION_S or self.armed is None:
            return
        decision = self._decide(cmd, target, self.armed)
        if not decision.accepted:
            return
        self._emit(
            t,
            "mode",
            f"{self._request_name(cmd, target)} at {cmd.t:.3f} s judged again: PX4's flag shows "
            "the signal it had (the logger missed that keep-alive)",
            "2.1.3",
            cause=None,
        )
        self._cause = cmd  # the new verdict answers the command (OFB102 pairs them)
        if cmd.is_mode_switch:
            self._apply_switch(t, target, decision)
        else:
            self._apply_arm(t, decision)
        self.compare.decided(cmd, decision, before, target)

    def _flag_differs(self) -> None:
        pending, self._flag = self._flag, None
        if pending is None:
            return
        t, recorded, event = pending
        self._flag_episode = True
        model = "available" if self.signal.available else "lost"
        last = self.signal.last
        age = f", newest keep-alive at {last:.2f} s" if last is not None else ", no keep-alive"
        self._emit(
            t,
            "disagreement",
            f"recorded: offboard_control_signal_lost {str(recorded).lower()} at {t:.2f} s "
            f"(PX4's own verdict); model: offboard signal {model}{age}",
            self.signal.spec,
            cause=event,
        )

    def _on_land(self, event: LandDetected) -> None:
        self._dirty = False
        self.landed.land_detected(event)

    def _follow_flag(self, event: FailsafeFlags) -> None:
        """Without the stream, PX4's own verdict is the signal: the flag is what Commander's
        check pass decided, and the failsafe follows it in the same iteration."""
        lost = event.offboard_control_signal_lost
        if lost is None:
            return
        self.follows_flag = True
        t = event.t
        if lost and self.signal.available:
            self.signal.mark_lost()
            self._signal_changed(t)
            reason = "PX4's recorded offboard_control_signal_lost (the stream is not recorded)"
            self._emit(t, "signal_lost", f"offboard signal lost: {reason}", "2", reason=reason)
            self._refresh(t)
        elif not lost and self.signal.keepalive(t, True):
            self._signal_changed(t)
            self._emit(
                t,
                "signal_available",
                "offboard signal available: PX4's recorded offboard_control_signal_lost "
                "(the stream is not recorded)",
                "2",
            )
            self._refresh(t)

    def _on_failsafe_flags(self, event: FailsafeFlags) -> None:
        if self.stream_recorded:
            self._recorded_flag(event)
        else:
            self._follow_flag(event)
        if self.est.update(event):
            self._verdicts.clear()
            self._mask_changed()
            if self.tick_based and estimate_failure(self.release, self.ocm_mask, self.est):
                self.signal.turned_bad(event.t)
            self._update_controller(event.t)

    def _on_parameter(self, event: Parameter) -> None:
        name = event.name.upper()
        self.recorded_params[name] = event.value
        if name in self.overrides or not math.isfinite(event.value):
            # A NaN or infinite value (a damaged record) is shown as recorded but not applied:
            # PX4 would cast it to a whole number, which C leaves undefined.
            return
        self.params[name] = event.value
        self._verdicts.clear()
        if name == "COM_OF_LOSS_T" and self.stream_recorded:
            if self.release.fixed_loss_s is not None:
                self.signal.loss_extra = max(0.0, event.value)  # type: ignore[attr-defined]
            else:
                self.signal.timeout = max(0.0, event.value)
        elif name == "MAV_FWDEXTSP":
            self._rx.fwdextsp = bool(event.value)
        elif name == "COM_DISARM_PRFLT":
            self.landed.preflight_disarm_s = event.value
        elif name == "MAV_COMP_ID":
            self._rx.own_component = int(event.value)

    # ------------------------------------------------------------------ effective mode

    def _needs_failsafe(self) -> bool:
        if self.user_intention != NAV_STATE_OFFBOARD or self.signal.available:
            return False
        if self._failsafe_due != INF:
            return False  # lost at the last check pass; the failsafe iteration is still ahead
        if self.tick_based:
            return self.armed is True  # unknown: the signal_lost row says both
        return True  # 1.13 and older: recomputed even when disarmed (4.1)

    def _refresh(self, t: float, cause: Event | bool | None = True) -> None:
        """Recompute the effective nav_state after anything that can change it."""
        kwargs: dict[str, Any] = {} if cause is True else {"cause": cause}
        if self._terminated:
            new: int | None = TERMINATION
        elif self._needs_failsafe():
            stage = 2 if getattr(self.signal, "timed_out", True) else 1
            if self._fallback is None or self._fallback_stage != stage:
                action = loss_action(self.release, self.vehicle_type, self.params, self.est, stage)
                self._fallback = action
                self._fallback_stage = stage
                self._failsafe(t, action, kwargs)
            action = self._fallback
            new = action.nav_state if action.nav_state is not None else NAV_STATE_OFFBOARD
            if action.nav_state == TERMINATION:
                self._terminated = True
        else:
            if self._fallback is not None:
                self._fallback = None
                self._fallback_stage = 0
                if self.user_intention == NAV_STATE_OFFBOARD and (
                    self.armed is True or not self.tick_based
                ):
                    self._emit(
                        t,
                        "offboard_resumed",
                        "offboard signal back: OFFBOARD again (the user intention never changed)",
                        _RESUME_SPEC[self.release.loss_failsafe],
                        nav_state=NAV_STATE_OFFBOARD,
                        **kwargs,
                    )
            new = self.user_intention if self.user_intention is not None else self._nav
        self._set_nav(t, new)

    def _failsafe(self, t: float, action: LossAction, kwargs: dict[str, Any]) -> None:
        note = f" ({action.note})" if action.note else ""
        disarmed = " while disarmed" if self.armed is False else ""
        earliest, seen_in = self._timing
        self._timing = (None, None)
        when = ""
        if earliest is not None:
            when = f" between {earliest:.3f} and {t:.3f} s"
        elif seen_in is not None:
            when = f" at {t:.3f} s ({seen_in})"
        self._fallback_when = when or f" at {t:.3f} s"
        self._emit(
            t,
            "failsafe",
            f"offboard loss{disarmed}{when}: {action.action}{note}",
            action.spec,
            action=action.action,
            nav_state=action.nav_state if action.nav_state is not None else self._nav,
            unverified=action.unverified,
            t_earliest=earliest,
            seen_in=seen_in,
            **kwargs,
        )
        if action.disarm and self.armed is not False:
            self.armed = False
            self.landed.disarmed()
            self._emit(t, "disarmed", "disarmed by the offboard-loss action", action.spec, **kwargs)

    def _set_nav(self, t: float, new: int | None) -> None:
        if new == self._nav:
            return
        self.compare.nav_changed(t, self._nav, new)
        self._nav = new
        if new == NAV_STATE_OFFBOARD:
            self.ctl.entered_offboard(t)
        self._update_controller(t)

    # ------------------------------------------------------------------ controllers

    def _update_controller(self, t: float) -> None:
        self.ctl.land_speed = float(self.params.get("MPC_LAND_SPEED", 0.7))
        change = self.ctl.update(t, self._nav)
        if change is not None:
            self._emit(
                t,
                "controller",
                change.text,
                change.spec,
                reason=change.reason,
                unverified=change.unverified,
                cause=None,
            )

    # ------------------------------------------------------------------ commands

    def _on_command(self, cmd: Command) -> None:
        t = cmd.t
        if cmd.is_mode_switch:
            target = decode_mode(cmd)
        elif cmd.command == MAV_CMD_COMPONENT_ARM_DISARM:
            target = None
        else:
            return
        before = (self.user_intention, self.armed)
        if self.armed is None:
            if_disarmed, if_armed = (
                self._decide(cmd, target, False),
                self._decide(cmd, target, True),
            )
            if if_disarmed.accepted != if_armed.accepted:
                self._undecided_request(cmd, target, if_disarmed, if_armed, before)
                return
            decision = if_disarmed
        else:
            decision = self._decide(cmd, target, self.armed)
        if cmd.is_mode_switch:
            self._apply_switch(t, target, decision)
        elif cmd.is_arm:
            self._apply_arm(t, decision)
        else:
            self._apply_disarm(t, decision)
        self.compare.decided(cmd, decision, before, target)
        unseen = not decision.accepted and decision.reason == "no offboard signal"
        self._rejected_unseen = (cmd, target, before) if unseen and not cmd.is_disarm else None

    def _decide(self, cmd: Command, target: int | None, armed: bool) -> Decision:
        """PX4's answer to ``cmd`` were the vehicle ``armed`` (4.1, 4.2, 13a)."""
        attitude_ok = self.est.attitude and self.est.angular_velocity
        if cmd.is_mode_switch:
            return switch_decision(
                self.release, cmd, target, armed, self.signal.available, self._nav, attitude_ok
            )
        if cmd.is_arm:
            why = estimate_failure(self.release, self.ocm_mask, self.est) or "no offboard signal"
            flags_known = self.ocm_mask != 0 or self._flags_unlogged
            now_ok = self.signal.ok_now(cmd.t, flags_known and why == "no offboard signal")
            manual = rc_present(self.params, self.est)
            return arm_decision(
                self.release, cmd, self.user_intention, now_ok, why, attitude_ok, armed, manual
            )
        landed, why = self.landed.landed(cmd.t)
        ground = self.vehicle_type.startswith("rover")
        return disarm_decision(self.release, cmd, armed, landed, why, ground)

    # -- requests while the arming state is unknown

    @staticmethod
    def _outcome(decision: Decision, switch: bool) -> str:
        if not decision.accepted:
            return f"rejected ({decision.reason or 'no reason modelled'})"
        if not decision.changes:
            return f"acked ACCEPTED, no change ({decision.reason})"
        if switch and decision.reason is None:
            return f"accepted ({NO_STREAM_SWITCH})"
        return "accepted" + (f" ({decision.reason})" if decision.reason else "")

    @staticmethod
    def _request_name(cmd: Command, target: int | None) -> str:
        if cmd.is_mode_switch:
            return f"switch to {nav_state_name(target) if target is not None else 'a mode'}"
        return "arm" if cmd.is_arm else "disarm"

    def _undecided_request(
        self,
        cmd: Command,
        target: int | None,
        if_disarmed: Decision,
        if_armed: Decision,
        before: tuple[int | None, bool | None],
    ) -> None:
        """Both outcomes on the timeline; the model goes on with the disarmed one, arming still
        unknown, until the recording decides (an ack of this request, a recorded arming)."""
        switch = cmd.is_mode_switch
        reason = (
            f"if disarmed: {self._outcome(if_disarmed, switch)}; "
            f"if armed: {self._outcome(if_armed, switch)}"
        )
        self._emit(
            cmd.t,
            "undecided",
            f"{self._request_name(cmd, target)}: {reason}; arming not recorded",
            if_armed.spec if not if_armed.accepted else if_disarmed.spec,
            reason=reason,
            unverified=if_disarmed.unverified or if_armed.unverified,
        )
        self._undecided.append(Undecided(cmd, target, if_disarmed, if_armed, before, self._nav))
        self.compare.decided(cmd, if_disarmed, before, target, alternative=if_armed)
        if switch and if_disarmed.accepted and if_disarmed.changes and target is not None:
            self._take_intention(cmd.t, target)

    def _resolve(self, t: float, was_armed: bool, because: str) -> None:
        """The recording shows the arming state the undecided requests depended on."""
        undecided, self._undecided = self._undecided, []
        if not undecided:
            if self.armed is None:
                self.armed = was_armed
            return
        names = ", ".join(
            f"{self._request_name(u.cmd, u.target)} at {u.cmd.t:.2f} s" for u in undecided
        )
        if not was_armed:
            if self.armed is None:
                self.armed = False
            self._emit(
                t,
                "mode",
                f"{because}: the vehicle was disarmed, so the outcomes if disarmed stand ({names})",
                "12",
            )
            return
        intention = undecided[0].before[0]
        for u in undecided:
            if u.cmd.is_mode_switch and u.if_armed.accepted and u.if_armed.changes:
                intention = u.target
        self.armed = True
        self.landed.armed(undecided[0].cmd.t)
        self.user_intention = intention
        self._fallback = None
        if intention is None:
            self._set_nav(t, undecided[0].nav_before)
        self._emit(
            t,
            "mode",
            f"{because}: the vehicle was armed, so the outcomes if armed hold ({names}); the "
            "model follows them",
            "12",
        )
        self._refresh(t)

    # -- applying a decision

    def _take_intention(self, t: float, target: int) -> None:
        self.user_intention = target
        self._terminated = self._terminated and target == TERMINATION
        self._fallback = None
        self._fallback_stage = 0
        self._refresh(t, cause=None)

    def _apply_switch(self, t: float, target: int | None, decision: Decision) -> None:
        offboard = target == NAV_STATE_OFFBOARD
        name = nav_state_name(target) if target is not None else "an unknown mode"
        if not decision.accepted:
            self._emit(
                t,
                "request_rejected" if offboard else "mode",
                f"switch to {name} rejected: {decision.reason}",
                decision.spec,
                reason=decision.reason,
                unverified=decision.unverified,
            )
            return
        if not decision.changes or target is None:
            self._emit(t, "mode", f"mode request acked, no change ({decision.reason})", "4.1")
            return
        if offboard:
            note = ""
            if self.armed is False and self.tick_based:
                note = " (disarmed: accepted without a stream, checked at arming)"
            self._emit(
                t,
                "request_accepted",
                f"switch to OFFBOARD accepted{note}",
                decision.spec,
                nav_state=target,
                unverified=decision.unverified,
            )
        else:
            self._emit(
                t, "mode", f"switch to {name} (assumed accepted)", decision.spec, nav_state=target
            )
        self._take_intention(t, target)

    def _apply_arm(self, t: float, decision: Decision) -> None:
        if not decision.accepted:
            self._emit(
                t,
                "arm_rejected",
                f"arming rejected: {decision.reason}",
                decision.spec,
                reason=decision.reason,
            )
            return
        if self.armed is not True:
            self.armed = True
            self.landed.armed(t)
            note = f" ({decision.reason})" if decision.reason else ""
            self._emit(
                t, "arm_accepted", f"armed{note}", decision.spec, unverified=decision.unverified
            )
            self._refresh(t, cause=None)
        elif not decision.changes:
            self._emit(t, "mode", f"arm request: {decision.reason}", decision.spec)

    def _apply_disarm(self, t: float, decision: Decision) -> None:
        if not decision.accepted:
            self._emit(
                t,
                "disarm_rejected",
                f"disarm rejected: {decision.reason}",
                decision.spec,
                reason=decision.reason,
                unverified=decision.unverified,
            )
            return
        if self.armed is not False:
            self.armed = False
            self.landed.disarmed()
            note = f" ({decision.reason})" if decision.reason else ""
            self._emit(t, "disarmed", f"disarm requested{note}", decision.spec)
            self._refresh(t)

    # ------------------------------------------------------------------ the recording

    def _on_status_text(self, text: StatusText) -> None:
        self._dirty = False
        if not self.stream_recorded and "failsafe" in text.text.lower():
            self._failsafe_text_at = text.t

    def _recorded_loss(self, status: VehicleStatus) -> None:
        """Without the stream, PX4's own failsafe is the loss: OFFBOARD left with no command
        for it, while PX4 says a failsafe is active (``failsafe`` in the status, or a
        STATUSTEXT just before)."""
        t = status.t
        if (
            status.nav_state is None
            or status.nav_state == NAV_STATE_OFFBOARD
            or not self.signal.available
            or self.user_intention != NAV_STATE_OFFBOARD
            or self.compare.recent_command(t)
        ):
            return
        text_before = 0.0 <= t - self._failsafe_text_at <= FAILSAFE_TEXT_WINDOW_S
        if not (status.failsafe is True or text_before):
            return
        said = f"STATUSTEXT at {self._failsafe_text_at:.2f} s" if text_before else "its status"
        self.signal.mark_lost()
        self._signal_changed(t)
        reason = f"PX4's recorded failsafe ({said}; the stream is not in the recording)"
        self._emit(
            t,
            "signal_lost",
            f"offboard signal lost: {reason}",
            self.signal.spec,
            cause=status,
            reason=reason,
        )
        self._refresh(t, cause=status)

    def _recorded_back(self, status: VehicleStatus) -> None:
        """Without the stream: the vehicle shown in OFFBOARD again is the signal back."""
        t = status.t
        if status.nav_state == NAV_STATE_OFFBOARD and self.signal.keepalive(t, True):
            self._signal_changed(t)
            self._emit(
                t,
                "signal_available",
                "recorded: OFFBOARD again (the stream is not in the recording)",
                self.signal.spec,
            )
            self._refresh(t)

    def _on_status(self, status: VehicleStatus) -> None:
        self.landed.mode(status.t, status.nav_state)
        if not self._started:
            self._start(status)
            return
        self.compare.remember(status)
        if not self.stream_recorded and not self.follows_flag:
            self._recorded_loss(status)
        if status.armed is not None and self.armed is None:
            state = "armed" if status.armed else "disarmed"
            self._resolve(status.t, status.armed, f"recorded: {state} at {status.t:.2f} s")
        if self.signal.held_until != INF and self._shows_failsafe(status):
            self._lose(status.t, self._window, RECORDED_FAILSAFE)
        if (
            self._failsafe_due != INF
            and status.nav_state is not None
            and status.nav_state != NAV_STATE_OFFBOARD
        ):
            # The recording already shows the vehicle out of OFFBOARD between the check pass
            # that saw the loss and the model's failsafe iteration: PX4's loop phase is not the
            # model's grid (2.1.3), this is the failsafe. Run it now (never back in time).
            self._failsafe_due = INF
            self._refresh(status.t, cause=None)
        armed, intention = self._unseen_inputs(status)
        if armed or intention is not None:
            self._adopt(status.t, status, intention, silent=True)
        if not self.stream_recorded and not self.follows_flag:
            self._recorded_back(status)
        self.compare.observe(status, self._nav)

    def _shows_failsafe(self, status: VehicleStatus) -> bool:
        """Does this status, inside the loss window, show PX4 out of OFFBOARD by the loss
        failsafe: no command that explains it, and the intention still OFFBOARD or the mode the
        loss action selects (a recording may carry the mode as the intention)?"""
        if status.nav_state is None or status.nav_state == NAV_STATE_OFFBOARD:
            return False
        if self.user_intention != NAV_STATE_OFFBOARD or self.compare.recent_command(status.t):
            return False
        if status.user_intention in (None, NAV_STATE_OFFBOARD):
            return True
        return status.nav_state == self.current_loss_action().nav_state

    def _unseen_inputs(self, status: VehicleStatus) -> tuple[bool, int | None]:
        """Changes the recording shows with no recorded command near them (an RC switch, an
        auto-disarm after landing): adopted silently. (armed changed, intention to adopt)."""
        if self.compare.recent_command(status.t):
            return False, None
        armed = status.armed is not None and status.armed != self.armed
        intention: int | None = None
        if status.user_intention is not None:
            if status.user_intention != self.user_intention:
                intention = status.user_intention
        elif (
            status.nav_state is not None
            and status.nav_state != self._nav
            and (
                self.user_intention != NAV_STATE_OFFBOARD
                or (self.signal.available and status.failsafe is not True)
            )
        ):
            intention = status.nav_state
        return armed, intention

    def _intention_for(self, status: VehicleStatus) -> int | None:
        """The user intention a confirmed difference re-synchronises to."""
        if status.user_intention is not None:
            return status.user_intention
        if (
            self.user_intention == NAV_STATE_OFFBOARD
            and not self.signal.available
            and status.nav_state != NAV_STATE_OFFBOARD
        ):
            return None  # plausibly the failsafe: keep the intention
        return status.nav_state

    def _start(self, status: VehicleStatus) -> None:
        """Initialise from the first recorded status (a recording may start mid-flight)."""
        self._started = True
        t = status.t
        if status.armed is not None:
            state = "armed" if status.armed else "disarmed"
            if self._undecided:
                self._resolve(t, status.armed, f"recorded: {state} at {t:.2f} s")
            self.armed = status.armed
            if status.armed:
                self.landed.armed(t)
        intention = status.user_intention
        if intention is None:
            intention = status.nav_state
        self.user_intention = intention
        if not self.stream_recorded and not self.follows_flag:
            self._emit(
                t,
                "signal_available",
                "offboard signal taken as present: the recording holds no keep-alive sent to "
                "the vehicle; PX4's recorded offboard_control_signal_lost decides it where "
                "the recording has it, else only a failsafe PX4 recorded counts as its loss",
                self.signal.spec,
            )
        # Assumption: a recording that starts in OFFBOARD starts with a live stream.
        if (
            not self.follows_flag
            and status.nav_state == NAV_STATE_OFFBOARD
            and not self.signal.available
            and self.signal.keepalive(t, True)
        ):
            self._emit(
                t,
                "signal_available",
                "offboard signal assumed available: the recording starts in OFFBOARD",
                self.signal.spec,
            )
        self._nav = status.nav_state
        self._refresh(t)
        self.compare.remember(status)

    def _adopt(self, t: float, status: VehicleStatus, intention: int | None, silent: bool) -> None:
        """Re-synchronise arming and user intention to the recording."""
        changed = []
        if status.armed is not None and status.armed != self.armed:
            self.armed = status.armed
            if status.armed:
                self.landed.armed(t)
            else:
                self.landed.disarmed()
            changed.append("armed" if status.armed else "disarmed")
        if intention is not None and intention != self.user_intention:
            self.user_intention = intention
            self._terminated = intention == TERMINATION
            self._fallback = None
            changed.append(f"intention {nav_state_name(intention)}")
        if changed and silent:
            self._emit(
                t,
                "mode",
                "from the recording (no command for it in the recording): " + ", ".join(changed),
                "12",
                cause=status,
            )
        self._refresh(t, cause=status)

    def _confirm(self, due: float) -> None:
        """A recorded difference outlasted the slack (or an ack was judged): report it once
        and re-synchronise."""
        if self.compare.ack_due_first():
            self._judge_ack()
            return
        pending = self.compare.take_pending()
        if pending is None:
            return
        status = pending.status
        model = nav_state_name(self._nav)
        if self._fallback is not None:
            model += f" (failsafe {self._fallback.action}{self._fallback_when})"
        text = f"recorded: {nav_state_name(status.nav_state)} at {pending.t:.2f} s; model: {model}"
        if self._involves_offboard(status.nav_state, status.user_intention) or (
            self._involves_offboard(pending.latest.nav_state, pending.latest.user_intention)
        ):
            self._emit(
                pending.t,
                "disagreement",
                text,
                "12",
                cause=status,
                recorded_nav_state=status.nav_state,
            )
        else:
            self._emit(pending.t, "mode", f"{text} ({NOT_OFFBOARD})", "12", cause=status)
        self._adopt(due, pending.latest, self._intention_for(pending.latest), False)

    def _involves_offboard(self, *recorded: int | None) -> bool:
        """Does a difference concern the offboard gate (OFB202)? OFFBOARD on either side (the
        recorded mode or intention, the model's mode or intention), or a failsafe from it."""
        return (
            NAV_STATE_OFFBOARD in recorded
            or self._nav == NAV_STATE_OFFBOARD
            or self.user_intention == NAV_STATE_OFFBOARD
            or self._fallback is not None
        )

    def _on_ack(self, ack: CommandAck) -> None:
        self.compare.ack(ack)

    def _judge_ack(self) -> None:
        judged = self.compare.take_ack()
        if judged is None:
            return
        decided, ack = judged
        if decided.alternative is not None:
            self._ack_decides(decided, ack)
            return
        cmd, target = decided.cmd, decided.target
        what = self._request_name(cmd, target)
        decision = decided.decision
        model = "accepted" if decision.accepted else f"rejected ({decision.reason})"
        text = f"recorded: {what} acked {ack.result_name} at {ack.t:.2f} s; model: {model}"
        if self._involves_offboard(target, decided.before[0]):
            self._emit(ack.t, "disagreement", text, "4.3", cause=ack)
        else:
            self._emit(ack.t, "mode", f"{text} ({NOT_OFFBOARD})", "4.3", cause=ack)
        self._follow_ack(decided, ack)

    def _follow_ack(self, decided: Decided, ack: CommandAck) -> None:
        cmd, target = decided.cmd, decided.target
        if ack.accepted and cmd.command == MAV_CMD_COMPONENT_ARM_DISARM:
            if decided.decision.changes or self.armed is None:
                self.armed = cmd.is_arm
                if cmd.is_arm:
                    self.landed.armed(ack.t)
                else:
                    self.landed.disarmed()
        elif ack.accepted and target is not None:
            self.user_intention = target
            self._fallback = None
        elif not ack.accepted:
            self.user_intention, self.armed = decided.before
        self._refresh(ack.t, cause=ack)

    def _ack_decides(self, decided: Decided, ack: CommandAck) -> None:
        """An ack of a request decided while the arming state was unknown: its result says
        which it was (never a disagreement while one outcome matches)."""
        alternative = decided.alternative
        assert alternative is not None
        what = self._request_name(decided.cmd, decided.target)
        said = f"recorded: {what} acked {ack.result_name} at {ack.t:.2f} s"
        if ack.accepted == decided.decision.accepted:
            self._resolve(ack.t, False, said)
        elif ack.accepted == alternative.accepted:
            self._resolve(ack.t, True, said)
