"""OFB201: the recording shows the vehicle rejecting an offboard request.

The last ack of a command decides (gate spec 4.3: PX4 1.16/1.17 answer a mode switch with the
receiver's ACCEPTED and then Commander's verdict a few ms later). The finding carries the gate
model's reason for the rejection, or says that the model expected acceptance.
"""

from __future__ import annotations

from dataclasses import dataclass

from fuzzoff.checks._keepalive import px4_label
from fuzzoff.checks.base import Check, CheckContext
from fuzzoff.events import (
    NAV_STATE_OFFBOARD,
    Command,
    CommandAck,
    Event,
)
from fuzzoff.gate import GateTransition
from fuzzoff.state import DOUBLE_ACK_WINDOW_S


@dataclass(slots=True)
class _Request:
    command: Command
    what: str
    verdict: GateTransition | None = None
    ack: CommandAck | None = None


class RequestRejected(Check):
    codes = ("OFB201",)
    wants = (Command, CommandAck, GateTransition)

    def __init__(self, ctx: CheckContext) -> None:
        super().__init__(ctx)
        self.requests: dict[int, _Request] = {}
        """Open offboard requests by MAVLink command id (one outstanding per command)."""
        self.seen_ack = False
        self.unconfirmed = False
        """A request the model accepts could not be confirmed: there are no acks."""
        self.verdicts: dict[int, GateTransition] = {}
        """The gate's answer to a command, keyed by the command's id: the engine dispatches the
        gate's transitions before the event that caused them."""

    def on_event(self, event: Event) -> None:
        self._settle(event.t)
        if isinstance(event, GateTransition):
            if event.cause is not None:
                self.verdicts[id(event.cause)] = event
        elif isinstance(event, Command):
            verdict = self.verdicts.pop(id(event), None)
            self.verdicts.clear()
            request = None
            if event.is_offboard_switch:
                request = _Request(event, "switch to OFFBOARD", verdict)
            elif event.is_arm and self._offboard_selected():
                request = _Request(event, "arm in OFFBOARD", verdict)
            if request is not None or event.is_mode_switch or event.is_arm or event.is_disarm:
                self._supersede(event.command)
            if request is not None:
                self.requests[event.command] = request
        elif isinstance(event, CommandAck):
            self.seen_ack = True
            request = self.requests.get(event.command)
            if request is not None:
                request.ack = event  # a later ack within the window replaces an earlier one

    def _offboard_selected(self) -> bool:
        """OFFBOARD is the selected mode: as recorded, else as the gate model has it."""
        state = self.ctx.state
        if state.mode_recorded:
            return state.nav_state == NAV_STATE_OFFBOARD
        return self.ctx.gate.user_intention == NAV_STATE_OFFBOARD

    def _supersede(self, command: int) -> None:
        """A new request of the same command: the open one is judged as it stands."""
        request = self.requests.pop(command, None)
        if request is None:
            return
        if request.ack is not None:
            self._judge(request)
        else:
            self._predict(request)

    def _predict(self, request: _Request) -> None:
        """No ack for this request and none anywhere in the recording: the rule reports the gate
        model's rejection itself (the consequence the docs' rules lead to, rules.md)."""
        if self.ctx.has("command_ack"):
            return
        verdict = request.verdict
        if verdict is None or not verdict.what.endswith("rejected"):
            self.unconfirmed = True
            return
        self.ctx.report(
            "OFB201",
            f"{request.what} at {request.command.t:.2f} s: {px4_label(self.ctx)} would reject it "
            f"({verdict.reason or verdict.message}, gate spec {verdict.spec}); the recording "
            "has no command acks to show the vehicle's answer",
            request.command.t,
            request.command.where,
        )

    def _settle(self, now: float) -> None:
        if not self.requests:
            return
        for key, request in list(self.requests.items()):
            if request.ack is not None and now - request.ack.t > DOUBLE_ACK_WINDOW_S:
                del self.requests[key]
                self._judge(request)

    def _judge(self, request: _Request) -> None:
        ack = request.ack
        assert ack is not None
        if ack.accepted:
            return
        verdict = request.verdict
        if verdict is not None and verdict.what.endswith("rejected"):
            why = f"gate model: {verdict.reason or verdict.message} (gate spec {verdict.spec})"
        elif verdict is not None:
            why = (
                f"the gate model expected {px4_label(self.ctx)} to accept it, so the cause is "
                "outside the offboard gate (arming checks, estimates) or the profile is wrong"
            )
        else:
            why = "the gate model has no verdict for this request"
        self.ctx.report(
            "OFB201",
            f"{request.what} at {request.command.t:.2f} s rejected by the vehicle with "
            f"{ack.result_name}; {why}",
            ack.t,
            ack.where,
        )

    def finish(self, t_end: float) -> None:
        self._settle(float("inf"))
        for command in list(self.requests):
            self._supersede(command)
        if self.unconfirmed:
            self.ctx.cannot_check(
                "OFB201",
                "needs the vehicle's command acks (COMMAND_ACK / vehicle_command_ack) to confirm "
                "requests the gate model expects PX4 to accept",
            )
