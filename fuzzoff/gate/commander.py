"""Commander's requests: mode switches, arming and disarming (gate.md#requests, #seen-on-px4):
one part of ``GateModel``.

``Requests`` judges each recorded command the way Commander would (``requests`` holds the
decisions per release) and applies the outcome: the user intention and the arming state change,
and the effective mode follows (``effective.EffectiveMode``). Where the outcome depends on an
arming state the recording does not show, both outcomes go on the timeline (``undecided``)
until the recording settles it (``resolve``).
"""

from __future__ import annotations

from fuzzoff.events import MAV_CMD_COMPONENT_ARM_DISARM, NAV_STATE_OFFBOARD, Command
from fuzzoff.gate.addressing import Addressing, command_addressing
from fuzzoff.gate.effective import TERMINATION, EffectiveMode
from fuzzoff.gate.failsafe import rc_present
from fuzzoff.gate.requests import (
    ACCEPTED,
    FAILED,
    Decision,
    arm_decision,
    decode_mode,
    disarm_decision,
    switch_decision,
)
from fuzzoff.gate.signal import estimate_failure
from fuzzoff.gate.state import GateState
from fuzzoff.lean_dataclass import dataclass
from fuzzoff.modes import nav_state_name

NO_STREAM_SWITCH = "1.14+: no stream needed while disarmed, checked at arming"
SAME_ITERATION_S = 0.012
"""A request and a flag logged this close were handled in one Commander iteration (10 ms)."""
UNANSWERED_S = 0.1
"""A request not answered yet when the flag turns available, this close to it, is handled by
Commander after that check pass: its ack dates the handling (the ULog dates the command on
receipt; PX4 1.16.2 handled an arm sent 0.4 ms before the first keep-alive 17 ms later, with
the signal, in corpora/ros2bridge/example_no_setpoint)."""

Before = tuple[int | None, bool | None]
"""(user intention, armed) before a request."""


@dataclass(slots=True)
class Undecided:
    """A request decided while the recording did not show the arming state, whose outcome
    depends on it: the model follows ``if_disarmed`` until the recording decides."""

    cmd: Command
    target: int | None
    if_disarmed: Decision
    if_armed: Decision
    before: Before
    nav_before: int | None


def request_name(cmd: Command, target: int | None) -> str:
    if cmd.is_mode_switch:
        return f"switch to {nav_state_name(target) if target is not None else 'a mode'}"
    return "arm" if cmd.is_arm else "disarm"


def _outcome(decision: Decision, switch: bool) -> str:
    if not decision.accepted:
        return f"rejected ({decision.reason or 'no reason modelled'})"
    if not decision.changes:
        return f"acked ACCEPTED, no change ({decision.reason})"
    if switch and decision.reason is None:
        return f"accepted ({NO_STREAM_SWITCH})"
    return "accepted" + (f" ({decision.reason})" if decision.reason else "")


class Requests:
    def __init__(self, state: GateState, mode: EffectiveMode) -> None:
        self.s = state
        self.mode = mode
        self.undecided: list[Undecided] = []
        self.rejected_unseen: tuple[Command, int | None, Before] | None = None
        """The newest request the model rejected for want of a signal (PX4's flag turning
        available in the same Commander iteration shows PX4 had one)."""

    def command(self, cmd: Command) -> bool:
        s = self.s
        t = cmd.t
        if cmd.is_mode_switch:
            target = decode_mode(cmd, s.release)
        elif cmd.command == MAV_CMD_COMPONENT_ARM_DISARM:
            target = None
        else:
            s.compare.unjudged = cmd
            return True
        before = (s.user_intention, s.armed)
        address = command_addressing(s.release, cmd, s.rx.own_system, s.rx.own_component)
        if not address.handled:
            self._not_addressed(cmd, target, address, before)
            return True
        if s.armed is None:
            if_disarmed, if_armed = (
                self._decide(cmd, target, False),
                self._decide(cmd, target, True),
            )
            if if_disarmed.accepted != if_armed.accepted:
                self._undecided_request(cmd, target, if_disarmed, if_armed, before)
                return True
            decision = if_disarmed
        else:
            decision = self._decide(cmd, target, s.armed)
        self._apply(t, cmd, target, decision)
        s.compare.decided(cmd, decision, before, target)
        unseen = not decision.accepted and decision.reason == "no offboard signal"
        self.rejected_unseen = (cmd, target, before) if unseen and not cmd.is_disarm else None
        return True

    def _not_addressed(
        self, cmd: Command, target: int | None, address: Addressing, before: Before
    ) -> None:
        """A request PX4's receiver does not pass to Commander: nothing changes; up to 1.15 it
        answers FAILED (the recorded ack is compared), later releases answer nothing."""
        s = self.s
        reason = f"addressed to {address.wrong}: {address.effect(s.release)}"
        failed = address.answer == "ack_failed"
        decision = Decision(
            False,
            "13a",
            reason,
            result=FAILED if failed else ACCEPTED,
            changes=False,
            unverified=s.release.old_code_unverified,
        )
        self._apply(cmd.t, cmd, target, decision)
        if failed:
            s.compare.decided(cmd, decision, before, target)

    def _decide(self, cmd: Command, target: int | None, armed: bool) -> Decision:
        """PX4's answer to ``cmd`` were the vehicle ``armed`` (4.1, 4.2, 13a)."""
        s = self.s
        attitude_ok = s.est.attitude and s.est.angular_velocity
        if cmd.is_mode_switch:
            return switch_decision(
                s.release, cmd, target, armed, s.signal.available, s.nav, attitude_ok
            )
        if cmd.is_arm:
            why = estimate_failure(s.release, s.ocm_mask, s.est) or "no offboard signal"
            flags_known = s.ocm_mask != 0 or s.flags_unlogged
            now_ok = s.signal.ok_now(cmd.t, flags_known and why == "no offboard signal")
            manual = rc_present(s.params, s.est)
            return arm_decision(
                s.release, cmd, s.user_intention, now_ok, why, attitude_ok, armed, manual
            )
        landed, why = s.landed.landed(cmd.t)
        ground = s.vehicle_type.startswith("rover")
        return disarm_decision(s.release, cmd, armed, landed, why, ground)

    def _apply(self, t: float, cmd: Command, target: int | None, decision: Decision) -> None:
        if cmd.is_mode_switch:
            self._apply_switch(t, target, decision)
        elif cmd.is_arm:
            self._apply_arm(t, decision)
        else:
            self._apply_disarm(t, decision)

    def rejudge(self, t: float) -> None:
        """A switch or arm the model rejected for want of a signal, logged in the same
        Commander iteration as PX4's flag turning available, or not answered yet when it turns:
        Commander had the keep-alive the logger missed (its forced check pass runs before it
        handles the command, 2.1.3; the ULog dates the command on receipt and the flag on
        publication). Judged again."""
        s = self.s
        rejected, self.rejected_unseen = self.rejected_unseen, None
        if rejected is None:
            return
        cmd, target, before = rejected
        late = t - cmd.t
        if s.armed is None or late > UNANSWERED_S:
            return
        if late > SAME_ITERATION_S and s.compare.answered_between(cmd.command, cmd.t, t):
            return  # answered before the flag turned: Commander judged it without the signal
        decision = self._decide(cmd, target, s.armed)
        if not decision.accepted:
            return
        s.emit(
            t,
            "mode",
            f"{request_name(cmd, target)} at {cmd.t:.3f} s judged again: PX4's flag shows "
            "the signal it had (the logger missed that keep-alive)",
            "2.1.3",
            cause=None,
        )
        s.cause = cmd  # the new verdict answers the command (OFB102 pairs them)
        if cmd.is_mode_switch:
            self._apply_switch(t, target, decision)
        else:
            self._apply_arm(t, decision)
        s.compare.decided(cmd, decision, before, target)

    # -- requests while the arming state is unknown

    def _undecided_request(
        self,
        cmd: Command,
        target: int | None,
        if_disarmed: Decision,
        if_armed: Decision,
        before: Before,
    ) -> None:
        """Both outcomes on the timeline; the model goes on with the disarmed one, arming still
        unknown, until the recording decides (an ack of this request, a recorded arming)."""
        s = self.s
        switch = cmd.is_mode_switch
        reason = (
            f"if disarmed: {_outcome(if_disarmed, switch)}; if armed: {_outcome(if_armed, switch)}"
        )
        s.emit(
            cmd.t,
            "undecided",
            f"{request_name(cmd, target)}: {reason}; arming not recorded",
            if_armed.spec if not if_armed.accepted else if_disarmed.spec,
            reason=reason,
            unverified=if_disarmed.unverified or if_armed.unverified,
        )
        self.undecided.append(Undecided(cmd, target, if_disarmed, if_armed, before, s.nav))
        s.compare.decided(cmd, if_disarmed, before, target, alternative=if_armed)
        if switch and if_disarmed.accepted and if_disarmed.changes and target is not None:
            self._take_intention(cmd.t, target)

    def resolve(self, t: float, was_armed: bool, because: str) -> None:
        """The recording shows the arming state the undecided requests depended on."""
        s = self.s
        undecided, self.undecided = self.undecided, []
        if not undecided:
            if s.armed is None:
                s.armed = was_armed
            return
        names = ", ".join(f"{request_name(u.cmd, u.target)} at {u.cmd.t:.2f} s" for u in undecided)
        if not was_armed:
            if s.armed is None:
                s.armed = False
            s.emit(
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
        s.armed_now(undecided[0].cmd.t)
        s.user_intention = intention
        s.fallback = None
        if intention is None:
            self.mode.set_nav(t, undecided[0].nav_before)
        s.emit(
            t,
            "mode",
            f"{because}: the vehicle was armed, so the outcomes if armed hold ({names}); the "
            "model follows them",
            "12",
        )
        self.mode.refresh(t)

    def pending(self) -> bool:
        """Are requests waiting for the recording to show the arming state?"""
        return bool(self.undecided)

    # -- applying a decision

    def _take_intention(self, t: float, target: int) -> None:
        s = self.s
        s.user_intention = target
        s.terminated = s.terminated and target == TERMINATION
        s.fallback = None
        s.fallback_stage = 0
        self.mode.refresh(t, cause=None)

    def _apply_switch(self, t: float, target: int | None, decision: Decision) -> None:
        s = self.s
        offboard = target == NAV_STATE_OFFBOARD
        name = nav_state_name(target) if target is not None else "an unknown mode"
        if not decision.accepted:
            s.emit(
                t,
                "request_rejected" if offboard else "mode",
                f"switch to {name} rejected: {decision.reason}",
                decision.spec,
                reason=decision.reason,
                unverified=decision.unverified,
            )
            return
        if not decision.changes or target is None:
            s.emit(t, "mode", f"mode request acked, no change ({decision.reason})", "4.1")
            return
        if offboard:
            note = ""
            if s.armed is False and s.tick_based:
                note = " (disarmed: accepted without a stream, checked at arming)"
            s.emit(
                t,
                "request_accepted",
                f"switch to OFFBOARD accepted{note}",
                decision.spec,
                nav_state=target,
                unverified=decision.unverified,
            )
        else:
            s.emit(
                t, "mode", f"switch to {name} (assumed accepted)", decision.spec, nav_state=target
            )
        self._take_intention(t, target)

    def _apply_arm(self, t: float, decision: Decision) -> None:
        s = self.s
        if not decision.accepted:
            s.emit(
                t,
                "arm_rejected",
                f"arming rejected: {decision.reason}",
                decision.spec,
                reason=decision.reason,
            )
            return
        if s.armed is not True:
            s.armed_now(t)
            s.unshown_arming = (t, True)
            note = f" ({decision.reason})" if decision.reason else ""
            s.emit(t, "arm_accepted", f"armed{note}", decision.spec, unverified=decision.unverified)
            self.mode.refresh(t, cause=None)
        elif not decision.changes:
            s.emit(t, "mode", f"arm request: {decision.reason}", decision.spec)

    def _apply_disarm(self, t: float, decision: Decision) -> None:
        s = self.s
        if not decision.accepted:
            s.emit(
                t,
                "disarm_rejected",
                f"disarm rejected: {decision.reason}",
                decision.spec,
                reason=decision.reason,
                unverified=decision.unverified,
            )
            return
        if s.armed is not False:
            s.disarmed_now()
            s.unshown_arming = (t, False)
            note = f" ({decision.reason})" if decision.reason else ""
            s.emit(t, "disarmed", f"disarm requested{note}", decision.spec)
            self.mode.refresh(t)
