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
* what ``view.GateView`` lists (``nav_state``, ``in_offboard``, ``offboard_since``, ``armed``,
  ``user_intention``, ``signal_ok``, ``params``...), read by the checks, and ``snapshot()``.

``GateModel`` is a façade: it hands each event to the part whose job it is, and runs each part's
deadline when it comes. The parts share one ``state.GateState``:

* ``keepalive.KeepAlives``: the keep-alives, when the signal is available, the loss window;
* ``verdict.RecordedFlag`` / ``verdict.UnseenStream``: PX4's own verdict on the signal as the
  recording shows it (with the stream recorded / without it);
* ``mavlink.MavlinkSetpoints`` and ``setpoints.Controllers``: PX4's MAVLink receiver, and which
  controller runs on the setpoints;
* ``effective.EffectiveMode``: the effective mode, and the loss action while the signal is lost;
* ``commander.Requests``: Commander's answer to switch, arm and disarm requests;
* ``sticks.StickOverride``: the pilot's sticks taking over OFFBOARD (1.14+ by parameter, 1.18+
  by default);
* ``history.RecordedHistory`` and ``acks.Acks``: the recorded mode history and acks against
  the prediction (``compare``): a difference that outlasts the evaluation slack becomes a
  ``disagreement`` and the model re-synchronises, so one difference is reported once.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any

from fuzzoff.events import (
    NAV_STATE_OFFBOARD,
    Command,
    CommandAck,
    ControlMode,
    Event,
    FailsafeFlags,
    LandDetected,
    LegacyControlMode,
    ManualControl,
    Parameter,
    PositionSetpointTriplet,
    SetAttitudeTarget,
    SetPositionTargetGlobal,
    SetPositionTargetLocal,
    StatusText,
    TrajectorySetpoint,
    VehicleStatus,
)
from fuzzoff.gate.acks import Acks
from fuzzoff.gate.commander import Requests
from fuzzoff.gate.compare import Comparator
from fuzzoff.gate.effective import EffectiveMode
from fuzzoff.gate.estimates import Estimates
from fuzzoff.gate.failsafe import LossAction
from fuzzoff.gate.history import RecordedHistory
from fuzzoff.gate.keepalive import KeepAlives
from fuzzoff.gate.mavlink import MavlinkSetpoints
from fuzzoff.gate.receiver import ReceiverContext
from fuzzoff.gate.setpoints import Controllers
from fuzzoff.gate.signal import INF
from fuzzoff.gate.state import GateState
from fuzzoff.gate.sticks import StickOverride
from fuzzoff.gate.transitions import GateTransition
from fuzzoff.gate.verdict import RecordedFlag, UnseenStream
from fuzzoff.gate.view import GateSnapshot
from fuzzoff.profiles import Profile

EMPTY: list[GateTransition] = []
"""Returned when an event changes nothing (shared: never mutate a returned list)."""

Handler = Callable[[Any], bool]
"""A part's handler of one event type: True when the model's deadlines may have moved earlier
(``feed`` then works them out again)."""


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
        """``armed``: the arming state at the start, where known (a generator that simulates a
        vehicle from boot passes False); None until the recording shows it."""
        self.profile = profile
        self.state = s = GateState.for_profile(
            profile, params or {}, vehicle, stream_recorded, armed
        )
        self.controllers = Controllers(s)
        self.mode = EffectiveMode(s, self.controllers)
        self.keepalives = KeepAlives(s, self.mode, self.controllers)
        self.mavlink = MavlinkSetpoints(s, self.keepalives, self.controllers)
        self.requests = Requests(s, self.mode)
        self.flag = RecordedFlag(s, self.keepalives, self.requests)
        self.unseen = UnseenStream(s, self.mode)
        self.history = RecordedHistory(s, self.mode, self.keepalives, self.requests, self.unseen)
        self.acks = Acks(s, self.mode, self.requests)
        self.sticks = StickOverride(s, self.mode)
        self._handlers: dict[type, Handler] = {
            ControlMode: self.keepalives.control_mode,
            LegacyControlMode: self.keepalives.legacy_control_mode,
            SetPositionTargetLocal: self.mavlink.setpoint,
            SetPositionTargetGlobal: self.mavlink.setpoint,
            SetAttitudeTarget: self.mavlink.setpoint,
            TrajectorySetpoint: self.controllers.trajectory,
            PositionSetpointTriplet: self.controllers.triplet,
            VehicleStatus: self.history.status,
            FailsafeFlags: self._on_failsafe_flags,
            Command: self.requests.command,
            CommandAck: self.acks.ack,
            Parameter: self._on_parameter,
            StatusText: self.unseen.status_text,
            LandDetected: self._on_land,
            ManualControl: self.sticks.manual_control,
        }
        sig = s.signal
        self._timers: tuple[tuple[Callable[[], float], Callable[[float], None]], ...] = (
            (self.flag.due, self.flag.differs),
            (self.keepalives.held_until, self.keepalives.not_shown),
            (self.mode.failsafe_due, self.mode.failsafe_iteration),
            (sig.lost_at, self.keepalives.lost),
            (sig.timeout_at, self.mode.timed_out),
            (self.controllers.reuse_due, self.controllers.reuse_expired),
            (self.acks.due, self.acks.judge),
            (self.history.due, self.history.confirm),
        )
        """Each part's deadline and what runs when it comes, in the order ties are run."""
        self._deadline = INF
        """No deadline comes before this (a lower bound: ``feed`` checks when it is reached)."""

    # ------------------------------------------------------------------ what checks read

    @property
    def nav_state(self) -> int | None:
        return self.state.nav

    @property
    def in_offboard(self) -> bool:
        return self.state.nav == NAV_STATE_OFFBOARD

    @property
    def offboard_since(self) -> float | None:
        return self.state.offboard_since

    @property
    def armed(self) -> bool | None:
        return self.state.armed

    @property
    def user_intention(self) -> int | None:
        return self.state.user_intention

    @property
    def signal_ok(self) -> bool:
        return self.state.signal.available

    @property
    def loss_timeout(self) -> float:
        return self.state.signal.timeout

    @property
    def follows_flag(self) -> bool:
        return self.state.follows_flag

    @property
    def params(self) -> dict[str, float]:
        return self.state.params

    @property
    def overrides(self) -> dict[str, float]:
        return self.state.overrides

    @property
    def recorded_params(self) -> dict[str, float]:
        return self.state.recorded_params

    @property
    def est(self) -> Estimates:
        return self.state.est

    @property
    def receiver(self) -> ReceiverContext:
        """What PX4's MAVLink receiver reads besides the message (parameters, estimates),
        kept up to date as parameters arrive."""
        return self.state.rx

    @property
    def compare(self) -> Comparator:
        return self.state.compare

    def current_loss_action(self) -> LossAction:
        """What the vehicle would do if the signal were lost now (OFB701/OFB702)."""
        return self.state.loss_action()

    def snapshot(self) -> GateSnapshot:
        """The prediction as it is now (the runs of stream messages the checks judge at once)."""
        return GateSnapshot(self.state)

    # ------------------------------------------------------------------ driving

    def feed(self, event: Event) -> list[GateTransition]:
        t = event.t
        if t >= self._deadline:
            self._advance(t)
            self._deadline = self._next_deadline()
        s = self.state
        if t > s.clock:
            s.clock = t
        handler = self._handlers.get(type(event))
        if handler is not None:
            s.cause = event
            moved = handler(event)
            s.cause = None
            if moved:
                self._deadline = self._next_deadline()
        out = s.out
        if out is None:
            return EMPTY
        s.out = None
        return out

    def finish(self, t_end: float) -> list[GateTransition]:
        self._advance(t_end)
        self.state.compare.drop_pending()
        out = self.state.take_output()
        return EMPTY if out is None else out

    def _next_deadline(self) -> float:
        """The earliest time at which something happens without a new event."""
        return min([due() for due, _ in self._timers])

    def _advance(self, t: float) -> None:
        """Run every deadline up to ``t``, earliest first."""
        timers = self._timers
        while True:
            dues = [due() for due, _ in timers]
            due = min(dues)
            if due > t:
                return
            # Due before an event already applied (a deadline that moved earlier): PX4 acts at
            # the next pass it runs, never in the past.
            timers[dues.index(due)][1](max(due, self.state.clock))

    # ------------------------------------------------------------------ events no part owns

    def _on_failsafe_flags(self, event: FailsafeFlags) -> bool:
        """PX4's verdict on the signal (``verdict``) and the estimates every part reads."""
        s = self.state
        if s.stream_recorded:
            self.flag.flags(event)
        else:
            self.unseen.flags(event)
        if s.est.update(event):
            self.mavlink.forget()
            self.keepalives.estimates_changed(event.t)
            self.controllers.update(event.t)
        return True

    def _on_parameter(self, event: Parameter) -> bool:
        if self.state.apply_parameter(event):
            self.mavlink.forget()  # the receiver reads MAV_FWDEXTSP, MAV_COMP_ID
        return True

    def _on_land(self, event: LandDetected) -> bool:
        self.state.landed.land_detected(event)
        return False
