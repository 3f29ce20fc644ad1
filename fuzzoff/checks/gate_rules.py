"""Rules read straight off the gate model (gate.md#loss, #history).

* OFB202 gate-model-disagrees: the model's ``disagreement`` transitions (recorded mode or ack vs
  the prediction, judged with the profile's evaluation slack, see ``fuzzoff.gate.compare``); the
  model emits them only for differences that involve OFFBOARD (others are ``mode`` rows);
* OFB701 loss-action-summary: once per vehicle that uses offboard, what the vehicle does on loss;
* OFB702 loss-action-unavailable: the configured loss action cannot run as configured (a mode
  whose estimate is missing, a stick mode without manual control): an ``error`` when a loss
  happened and the fallback ran, else ``info`` (a configuration note: every SITL or autonomous
  setup without RC has it on every flight).
"""

from __future__ import annotations

from fuzzoff.checks.base import Check, CheckContext
from fuzzoff.events import Event, FailsafeFlags, Parameter, VehicleStatus
from fuzzoff.findings import Severity, clip
from fuzzoff.gate import GateTransition
from fuzzoff.gate.failsafe import LossAction
from fuzzoff.gate.params import RC_PRESENT


class GateDisagrees(Check):
    codes = ("OFB202",)
    wants = (GateTransition,)

    def on_event(self, event: Event) -> None:
        if isinstance(event, GateTransition) and event.what == "disagreement":
            profile = self.ctx.profile
            message = (
                f"{event.message} (PX4 {profile.px4} {profile.vehicle}, "
                f"evaluation slack {self.ctx.gate.compare.slack:.2f} s)"
            )
            short = clip(event.message)
            assumed = _assumed(self.ctx)
            if assumed:
                # the model ran on a guess: the guess may be what differs, not PX4
                what = " and ".join(name for name, _ in assumed)
                verb = "is" if len(assumed) == 1 else "are"
                options = " and ".join(option for _, option in assumed)
                message += (
                    f"; the {what} {verb} assumed (the recording does not say, OFB003) and "
                    f"may be the cause: give the vehicle's own with {options}"
                )
                short += f"; {what} assumed"
            self.ctx.report(
                "OFB202",
                message,
                event.t,
                event.cause.where if event.cause is not None else None,
                short=short,
            )

    def finish(self, t_end: float) -> None:
        if not self.ctx.has("vehicle_status", "command_ack"):
            self.ctx.cannot_check(
                "OFB202",
                "needs the vehicle's mode (vehicle_status, HEARTBEAT, /mavros/state) or its "
                "command acks",
            )


def _assumed(ctx: CheckContext) -> list[tuple[str, str]]:
    """What of the profile the model ran on was assumed, neither read from the recording nor
    given: (what, the option that gives it)."""
    profile = ctx.profile
    vehicle_known = profile.vehicle_detected and (
        profile.vehicle_forced or ctx.info.vehicle_assumed is None
    )
    assumed = []
    if not profile.px4_detected:
        assumed.append(("PX4 release", "--px4"))
    if not vehicle_known:
        assumed.append(("vehicle type", "--vehicle"))
    return assumed


def _param_source(ctx: CheckContext, name: str) -> str:
    gate = ctx.gate
    if name in gate.overrides:
        return ctx.settings.param_origin(name)
    if name in gate.recorded_params:
        return "from the recording"
    return "PX4 default"


def _rc_text(ctx: CheckContext) -> str:
    est = ctx.gate.est
    if not ctx.profile.release.consults_manual_control_on_loss:
        return "manual control not consulted (1.14-1.16)"
    if est.rc_recorded:
        return "manual control present" if est.rc_present else "no manual control (recorded)"
    present = bool(ctx.gate.params.get(RC_PRESENT, 1.0))
    return f"manual control assumed {'present' if present else 'absent'} ({RC_PRESENT})"


def loss_summary(ctx: CheckContext) -> str:
    """The OFB701 text: timeout, action parameter, what happens, and the return."""
    gate = ctx.gate
    release = ctx.profile.release
    action = gate.current_loss_action()
    p = gate.params
    loss_t = float(p.get("COM_OF_LOSS_T", 0.0))
    src_t = _param_source(ctx, "COM_OF_LOSS_T")
    act = p.get("COM_OBL_RC_ACT", 0.0)
    src_a = _param_source(ctx, "COM_OBL_RC_ACT")
    if release.fixed_loss_s is not None:
        head = (
            f"offboard loss after {release.fixed_loss_s * 1000:g} ms without a setpoint (fixed), "
            "then after COM_OF_LOSS_T "
            f"{loss_t:g} s ({src_t}) more the loss action"
        )
    elif release.tick_based:
        head = (
            f"offboard loss when the newest keep-alive is COM_OF_LOSS_T {loss_t:g} s ({src_t}) "
            f"old, checked at 10 Hz"
        )
    else:
        head = f"offboard loss after COM_OF_LOSS_T {loss_t:g} s ({src_t}) without a keep-alive"
    head += f"; COM_OBL_RC_ACT {act:g} ({src_a})"
    if "COM_OBL_ACT" in release.param_defaults:
        head += f", COM_OBL_ACT {p.get('COM_OBL_ACT', 0.0):g} ({_param_source(ctx, 'COM_OBL_ACT')})"
    what = _action_text(action)
    back = (
        "it returns to OFFBOARD by itself when the stream resumes"
        if action.nav_state != 13 and not action.disarm
        else "it does not return"
    )
    return f"{head}; {_rc_text(ctx)}: the vehicle will {what}; {back}"


def loss_short(ctx: CheckContext) -> str:
    """OFB701 in a few words: after how long, what the vehicle does, whether it comes back."""
    gate = ctx.gate
    action = gate.current_loss_action()
    loss_t = float(gate.params.get("COM_OF_LOSS_T", 0.0))
    fixed = ctx.profile.release.fixed_loss_s
    after = f"{fixed:g} s + {loss_t:g} s" if fixed is not None else f"{loss_t:g} s"
    if action.disarm:
        what = "disarm"
    elif action.none:
        what = "no failsafe"
    else:
        what = action.action
    back = ", back to OFFBOARD when it resumes" if action.nav_state not in (None, 13) else ""
    return f"on a {after} stream loss: {what}{back}"


def _action_text(action: LossAction) -> str:
    """What the vehicle does, with the parameters that chose it (``note``): a disarm may come
    from COM_OBL_RC_ACT 7 or, on 1.17+ without RC, from NAV_RCL_ACT 6."""
    if action.disarm:
        text = "disarm"
    elif action.none:
        text = "stay in OFFBOARD without a signal, no failsafe"
    else:
        text = f"switch to {action.action}"
    return f"{text} ({action.note})" if action.note else text


class LossActionSummary(Check):
    codes = ("OFB701",)
    wants = (GateTransition, VehicleStatus)

    def __init__(self, ctx: CheckContext) -> None:
        super().__init__(ctx)
        self.done = False

    def on_event(self, event: Event) -> None:
        if self.done:
            return
        if self.ctx.gate.in_offboard or self.ctx.in_offboard:
            self.done = True
            self.ctx.report("OFB701", loss_summary(self.ctx), event.t, short=loss_short(self.ctx))


_Key = tuple[str, str | None, bool, str | None]


class LossActionUnavailable(Check):
    codes = ("OFB702",)
    wants = (GateTransition, VehicleStatus, FailsafeFlags, Parameter)

    def __init__(self, ctx: CheckContext) -> None:
        super().__init__(ctx)
        self.noted: dict[_Key, tuple[float, str, str]] = {}
        """Configuration notes waiting for the end: a loss that runs the fallback later makes
        its error the one finding."""
        self.ran: set[_Key] = set()

    def on_event(self, event: Event) -> None:
        gate = self.ctx.gate
        # a loss on a vehicle the model knows disarmed runs no fallback that flies anything
        loss = (
            isinstance(event, GateTransition)
            and event.what == "failsafe"
            and event.armed is not False
        )
        if not (loss or gate.in_offboard or self.ctx.in_offboard):
            return
        if isinstance(event, GateTransition) and event.what not in (
            "failsafe",
            "request_accepted",
            "offboard_resumed",
            "signal_available",
        ):
            return
        action = gate.current_loss_action()
        if not (action.degraded_from or action.stick_mode_without_rc or action.replaced_from):
            return
        key = (
            action.action,
            action.degraded_from,
            action.stick_mode_without_rc,
            action.replaced_from,
        )
        if key in self.ran:
            return
        if loss:
            self.ran.add(key)
            self.noted.pop(key, None)
            when = f"at {event.t:.2f} s"
            if isinstance(event, GateTransition) and event.t_earliest is not None:
                when = f"between {event.t_earliest:.2f} and {event.t:.2f} s"  # a check window
            message = f"the offboard signal was lost {when} and the fallback ran: "
            self.ctx.report(
                "OFB702",
                message + self._message(action),
                event.t,
                severity=Severity.ERROR,
                short=f"offboard loss: {self._short(action)}",
            )
        elif key not in self.noted:
            self.noted[key] = (event.t, self._message(action), self._short(action))

    def finish(self, t_end: float) -> None:
        for t, message, short in self.noted.values():
            self.ctx.report(
                "OFB702",
                f"configuration note, no offboard loss in this recording: {message}",
                t,
                severity=Severity.INFO,
                short=f"on a loss: {short}",
            )
        self.noted.clear()

    def _rc_source(self) -> str:
        if self.ctx.gate.est.rc_recorded:
            return "the recording's manual_control_signal_lost"
        return f"{RC_PRESENT} = 0"

    def _short(self, action: LossAction) -> str:
        if action.degraded_from:
            return f"{action.degraded_from} cannot run, PX4 falls back to {action.action}"
        if action.replaced_from:
            return f"{action.replaced_from} without manual control, PX4 runs {action.action}"
        return f"{action.action}, a pilot mode, with no manual control"

    def _message(self, action: LossAction) -> str:
        px4 = self.ctx.profile.px4
        if action.degraded_from:
            return (
                f"the configured offboard-loss action {action.degraded_from} cannot run now "
                f"({action.note}); PX4 {px4} would fall back to {action.action} "
                "(mode requirements approximated by fuzzoff)"
            )
        if action.replaced_from:
            return (
                f"the configured offboard-loss action is the stick mode {action.replaced_from} "
                f"but there is no manual control ({self._rc_source()}): PX4 {px4} will "
                f"{_action_text(action)} instead"
            )
        return (
            f"the offboard-loss action is the stick mode {action.action} but there is no manual "
            f"control ({self._rc_source()}): PX4 {px4} switches to it anyway and the vehicle has "
            "no pilot input (on 1.14 it was seen descending slowly until the stream resumed)"
        )
