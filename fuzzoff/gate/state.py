"""What the parts of the gate model share: one vehicle's ``GateState``.

Each part of ``GateModel`` (the keep-alives, PX4's recorded verdict, the setpoints and
controllers, the effective mode, Commander's requests, the recorded history and the acks) keeps
its own bookkeeping and reads and writes the facts here, the ones more than one part needs: the
vehicle's arming, user intention and effective mode, the newest keep-alive's flags, the loss
under way and the failsafe that answers it, the parameters and estimates, and the transitions the
event being fed has caused so far (``emit``).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import field
from typing import Any

from fuzzoff.events import NAV_STATE_OFFBOARD, Event, FailsafeFlags, Parameter
from fuzzoff.gate.compare import Comparator
from fuzzoff.gate.estimates import Estimates
from fuzzoff.gate.failsafe import LossAction, loss_action
from fuzzoff.gate.landed import LandedState
from fuzzoff.gate.params import default_params
from fuzzoff.gate.receiver import ReceiverContext
from fuzzoff.gate.signal import INF, LOOP_PERIOD, Signal, UnseenSignal, make_signal, slack
from fuzzoff.gate.tracker import ControllerTracker
from fuzzoff.gate.transitions import GateTransition, TransitionKind
from fuzzoff.lean_dataclass import dataclass
from fuzzoff.profiles import Profile
from fuzzoff.releases import Release


@dataclass(slots=True, eq=False)
class GateState:
    """One vehicle's gate, as every part of the model sees it (built by ``for_profile``)."""

    release: Release
    vehicle_type: str
    """``mc``, ``fw``, ``vtol``, ``rover-...`` (the profile's)."""
    vehicle: str
    """The vehicle id the events carry; every transition carries it too."""
    params: dict[str, float]
    """Effective parameters: PX4's defaults < the recording's ``Parameter`` events < overrides."""
    overrides: dict[str, float]
    """The user's parameters (they win over the recording's)."""
    est: Estimates
    signal: Signal
    """Proof of life: the newest keep-alive and when the signal is lost (``signal``)."""
    rx: ReceiverContext
    """What PX4's MAVLink receiver reads besides the message."""
    compare: Comparator
    """The recorded mode history and acks against the prediction."""
    ctl: ControllerTracker
    """Which controller runs in offboard."""
    landed: LandedState
    """On the ground or not, as a disarm request is judged."""
    stream_recorded: bool
    """False: the recording cannot show the keep-alive (a ground station's tlog, a ULog
    without ``offboard_control_mode``). The signal is then PX4's own recorded verdict
    (``failsafe_flags.offboard_control_signal_lost``) where the recording has it; else it is
    taken as present, and lost only where PX4's own failsafe is recorded."""
    tick_based: bool
    """1.14+: OffboardChecks at 10 Hz (gate.md#signal)."""
    recorded_params: dict[str, float] = field(default_factory=dict)
    """The recording's ``Parameter`` events, as recorded (also those not applied)."""

    # -- the vehicle
    armed: bool | None = None
    """None until the recording shows the arming state (or a request settles it): decisions
    that depend on it give both outcomes (``undecided``)."""
    user_intention: int | None = None
    nav: int | None = None
    """The effective nav_state the model predicts."""
    offboard_since: float | None = None
    """When ``nav`` last became OFFBOARD (None while it is not OFFBOARD)."""
    terminated: bool = False
    """Flight termination ran: never left (the effective mode stays TERMINATION)."""

    # -- the newest keep-alive
    ocm_mask: int = 0
    """Its control-mode flags (``ocm``)."""
    good: bool = False
    """Its flags pass (set, and their estimates valid; any flags before 1.13)."""
    flags_unlogged: bool = False
    """PX4's flag made the signal available before any logged keep-alive: its flags are not
    known yet, and PX4's flag stands for them."""
    sig_changed_at: float = -INF
    """When the model's signal (available / lost) last changed."""

    # -- PX4's recorded verdict (failsafe_flags.offboard_control_signal_lost)
    flag_recorded: bool = False
    """The recording holds PX4's verdict (1.14+)."""
    flag_at: float = -INF
    """When PX4's verdict was last recorded."""
    flag_pending: tuple[float, bool, FailsafeFlags] | None = None
    """A recorded verdict that differs from the model, waiting for the slack (time, recorded
    value, event)."""
    unshown_arming: tuple[float, bool] | None = None
    """The model's own arming change on a recorded command (time, armed) that no recorded
    status has shown yet: a recording that then shows the other state contradicts it."""
    follows_flag: bool = False
    """Without the stream: PX4's verdict has been seen, and the signal follows it from then
    on (the mode history no longer decides it)."""

    # -- the loss and its failsafe
    failsafe_due: float = INF
    """1.14+: the Commander iteration that will run the loss failsafe (2.1.3), inf if none."""
    timing: tuple[float | None, str | None] = (None, None)
    """(earliest time, where the recording shows it) for the next failsafe transition."""
    fallback: LossAction | None = None
    """The loss action running (the effective mode is its mode), None if none."""
    fallback_stage: int = 0
    """legacy: the stage ``fallback`` was chosen for (1 lost, 2 loss timeout)."""
    fallback_when: str = ""
    """When the model ran ``fallback`` (a window where the recording does not date it), for
    disagreement texts."""

    # -- the output of the event being fed
    clock: float = -INF
    """The newest event time fed: nothing is emitted earlier (the timeline never goes back)."""
    cause: Event | None = None
    """The event being fed (the default cause of what it emits)."""
    out: list[GateTransition] | None = None
    """What the event has emitted so far (None: nothing)."""

    @classmethod
    def for_profile(
        cls,
        profile: Profile,
        overrides: Mapping[str, float],
        vehicle: str,
        stream_recorded: bool,
        armed: bool | None,
    ) -> GateState:
        release = profile.release
        own = dict(overrides)
        params = default_params(profile.px4) | own
        est = Estimates()
        signal = make_signal(release, params)
        if not stream_recorded:
            signal = UnseenSignal(signal.timeout)
        try:
            own_system: int | None = int(vehicle)
        except ValueError:
            own_system = None
        return cls(
            release=release,
            vehicle_type=profile.vehicle,
            vehicle=vehicle,
            params=params,
            overrides=own,
            est=est,
            signal=signal,
            rx=ReceiverContext(
                release=release,
                own_system=own_system,
                own_component=int(params.get("MAV_COMP_ID", 1.0)),
                fwdextsp=bool(params.get("MAV_FWDEXTSP", 1.0)),
                est=est,
            ),
            compare=Comparator(slack(release) + LOOP_PERIOD),
            ctl=ControllerTracker(release, profile.vehicle, est),
            landed=LandedState(float(params.get("COM_DISARM_PRFLT", 0.0))),
            stream_recorded=stream_recorded,
            tick_based=release.tick_based,
            armed=armed,
        )

    def emit(self, t: float, what: TransitionKind, message: str, spec: str, **fields: Any) -> None:
        """Add a transition at ``t`` to the event's output (caused by the event being fed and
        leaving the effective mode, unless ``cause`` or ``nav_state`` say otherwise)."""
        tr = GateTransition(
            t=t,
            vehicle=self.vehicle,
            what=what,
            message=message,
            spec=spec,
            cause=fields.pop("cause", self.cause),
            nav_state=fields.pop("nav_state", self.nav),
            armed=self.armed,
            **fields,
        )
        if self.out is None:
            self.out = [tr]
        else:
            self.out.append(tr)

    def apply_parameter(self, event: Parameter) -> bool:
        """A recorded parameter; True when applied (the user's overrides win, and a value that
        is not a finite number is shown as recorded but not applied)."""
        name = event.name.upper()
        self.recorded_params[name] = event.value
        if name in self.overrides or not math.isfinite(event.value):
            # PX4 would cast a NaN or infinite value (a damaged record) to a whole number,
            # which C leaves undefined.
            return False
        self.params[name] = event.value
        if name == "COM_OF_LOSS_T" and self.stream_recorded:
            if self.release.fixed_loss_s is not None:
                self.signal.loss_extra = max(0.0, event.value)  # type: ignore[attr-defined]
            else:
                self.signal.timeout = max(0.0, event.value)
        elif name == "MAV_FWDEXTSP":
            self.rx.fwdextsp = bool(event.value)
        elif name == "COM_DISARM_PRFLT":
            self.landed.preflight_disarm_s = event.value
        elif name == "MAV_COMP_ID":
            self.rx.own_component = int(event.value)
        return True

    def take_output(self) -> list[GateTransition] | None:
        out = self.out
        self.out = None
        return out

    def signal_changed(self, t: float) -> None:
        """The model's signal turned available or lost at ``t``: a recorded verdict waiting for
        the slack that the model now matches is no difference."""
        self.sig_changed_at = t
        pending = self.flag_pending
        if pending is not None and pending[1] == (not self.signal.available):
            self.flag_pending = None

    def involves_offboard(self, *recorded: int | None) -> bool:
        """Does a difference concern the offboard gate (OFB202)? OFFBOARD on either side (the
        recorded mode or intention, the model's mode or intention), or a failsafe from it."""
        return (
            NAV_STATE_OFFBOARD in recorded
            or self.nav == NAV_STATE_OFFBOARD
            or self.user_intention == NAV_STATE_OFFBOARD
            or self.fallback is not None
        )

    def loss_action(self, stage: int = 2) -> LossAction:
        """What the vehicle would do if the signal were lost now (legacy: at ``stage``)."""
        return loss_action(self.release, self.vehicle_type, self.params, self.est, stage)

    def armed_now(self, t: float) -> None:
        """The vehicle is armed from ``t`` (the land detector's view follows)."""
        self.armed = True
        self.landed.armed(t)

    def disarmed_now(self) -> None:
        self.armed = False
        self.landed.disarmed()
