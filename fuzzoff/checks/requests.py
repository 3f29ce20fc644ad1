"""OFB201: the recording shows the vehicle rejecting an offboard request.

Acks carry the command's id but not its parameters, so they are paired with the commands of
that id in the order sent (PX4 answers in order): a switch to OFFBOARD followed at once by a
switch to another mode gets the first ack, the other switch the second. The last ack of a
command decides where PX4 sends two (gate.md#acks: 1.16/1.17 answer a mode switch with the
receiver's ACCEPTED and then Commander's verdict a few ms later): an ack within
``DOUBLE_ACK_WINDOW_S`` of an ACCEPTED one replaces it. A first ack that is not ACCEPTED is
never the receiver's, and a ROS 2 command does not pass the MAVLink receiver: then the next
ack belongs to the next command. The finding carries the gate
model's reason for the rejection, or says that the model expected acceptance.

An arm is an offboard request when OFFBOARD is selected, or when a switch to OFFBOARD went
within ``ACK_WAIT_S`` before it and no ack rejected that: a client sends the two at once and
PX4's status shows OFFBOARD only after it answered both (issue 28 miss 2).
"""

from __future__ import annotations

from fuzzoff.checks._keepalive import px4_label
from fuzzoff.checks.base import Check, CheckContext
from fuzzoff.events import (
    Command,
    CommandAck,
    Event,
)
from fuzzoff.findings import Severity
from fuzzoff.gate import GateTransition
from fuzzoff.lean_dataclass import dataclass
from fuzzoff.state import DOUBLE_ACK_WINDOW_S

ACK_WAIT_S = 1.0
"""A command still without an ack this long before a newer ack of its id never got one (a
lost ack); pairing goes on with the commands after it."""


@dataclass(slots=True)
class _Request:
    command: Command
    what: str | None
    """``switch to OFFBOARD`` / ``arm in OFFBOARD``; None for another command of the same id,
    which only takes its place in the order of the acks."""
    verdict: GateTransition | None = None
    ack: CommandAck | None = None


class RequestRejected(Check):
    codes = ("OFB201",)
    wants = (Command, CommandAck, GateTransition)

    def __init__(self, ctx: CheckContext) -> None:
        super().__init__(ctx)
        self.requests: dict[int, list[_Request]] = {}
        """Commands waiting for their ack (or for a second one), oldest first, by command id."""
        self.seen_ack = False
        self.unconfirmed = False
        """A request the model accepts could not be confirmed: there are no acks."""
        self.switch: tuple[Command, bool] | None = None
        """The latest mode switch, and whether it can still be a switch to OFFBOARD (it is one
        and no ack rejected it)."""
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
            what = None
            if event.is_offboard_switch:
                what = "switch to OFFBOARD"
            elif event.is_arm and (self.ctx.offboard_selected() or self._switching(event.t)):
                what = "arm in OFFBOARD"
            if event.is_mode_switch:
                self.switch = (event, event.is_offboard_switch)
            if what is None and not (event.is_mode_switch or event.is_arm or event.is_disarm):
                return
            queue = self.requests.setdefault(event.command, [])
            if not self.ctx.has("command_ack"):
                self._supersede(queue)  # nothing will answer: judge the open one now
            queue.append(_Request(event, what, verdict))
        elif isinstance(event, CommandAck):
            self.seen_ack = True
            self._ack(event)

    def _switching(self, t: float) -> bool:
        """Is a switch to OFFBOARD on its way (sent within ``ACK_WAIT_S``, not rejected)? An arm
        sent right after it is meant for OFFBOARD whatever the recorded status still shows: a
        client sends both at once (px4_ros_com's examples 0.4 ms apart) and PX4's status
        follows some 10 ms later, its answer to the arm before or after it."""
        switch = self.switch
        return switch is not None and switch[1] and t - switch[0].t <= ACK_WAIT_S

    def _ack(self, ack: CommandAck) -> None:
        queue = self.requests.get(ack.command)
        if not queue:
            return
        while queue:
            head = queue[0]
            if head.ack is None:
                if head.command.t < ack.t - ACK_WAIT_S and len(queue) > 1:
                    self._unanswered(queue.pop(0))
                    continue
                head.ack = ack
                return
            if (
                head.ack.accepted
                and ack.t - head.ack.t <= DOUBLE_ACK_WINDOW_S
                and head.command.transport != "ros2"  # the second ack is the MAVLink receiver's
            ):
                head.ack = ack  # PX4 1.16/1.17: Commander's verdict after the receiver's
                return
            self._judge(queue.pop(0))

    def _supersede(self, queue: list[_Request]) -> None:
        """A new command of the same id: the open ones are judged as they stand."""
        while queue:
            request = queue.pop(0)
            if request.ack is not None:
                self._judge(request)
            else:
                self._unanswered(request)

    def _unanswered(self, request: _Request) -> None:
        if request.what is not None:
            self._predict(request)

    def _predict(self, request: _Request) -> None:
        """No ack for this request and none anywhere in the recording: the rule reports the gate
        model's rejection itself (the consequence the docs' rules lead to, rules.md)."""
        if self.ctx.has("command_ack"):
            return
        verdict = request.verdict
        if verdict is not None and verdict.what == "undecided":
            self._undecided(request, verdict)
            return
        if verdict is None or not verdict.what.endswith("rejected"):
            self.unconfirmed = True
            return
        self.ctx.report(
            "OFB201",
            f"{request.what} at {request.command.t:.2f} s: {px4_label(self.ctx)} would reject it "
            f"({verdict.reason or verdict.message}); the recording has no command acks to show "
            "the vehicle's answer",
            request.command.t,
            request.command.where,
            short=f"{request.what}: {px4_label(self.ctx)} would reject it "
            f"({verdict.reason or verdict.message})",
        )

    def _undecided(self, request: _Request, verdict: GateTransition) -> None:
        """The rejection depends on the arming state, which the recording does not show: both
        outcomes, as a warning (PX4 rejects it only in one of them)."""
        self.ctx.report(
            "OFB201",
            f"{request.what} at {request.command.t:.2f} s, {px4_label(self.ctx)}: "
            f"{verdict.reason}; the recording shows neither the arming state nor the vehicle's "
            "answer",
            request.command.t,
            request.command.where,
            severity=Severity.WARNING,
            short=f"{request.what}: {px4_label(self.ctx)} rejects it only if armed (arming not "
            "recorded)",
        )

    def _settle(self, now: float) -> None:
        """Judge the answered commands whose window for a second ack has passed."""
        for queue in self.requests.values():
            while queue and (ack := queue[0].ack) is not None and now - ack.t > DOUBLE_ACK_WINDOW_S:
                self._judge(queue.pop(0))

    def _judge(self, request: _Request) -> None:
        ack = request.ack
        assert ack is not None
        if not ack.accepted and self.switch is not None and self.switch[0] is request.command:
            self.switch = (request.command, False)
        if ack.accepted or request.what is None:
            return
        verdict = request.verdict
        if verdict is not None and verdict.what.endswith("rejected"):
            why = f"gate model: {verdict.reason or verdict.message}"
        elif verdict is not None and verdict.what == "undecided":
            why = (
                f"gate model: {verdict.reason}; the recording did not show the arming state, "
                "this answer does"
            )
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
            short=f"{request.what} at {request.command.t:.2f} s rejected: {ack.result_name}",
        )

    def finish(self, t_end: float) -> None:
        self._settle(float("inf"))
        for queue in self.requests.values():
            self._supersede(queue)
        if self.unconfirmed:
            self.ctx.cannot_check(
                "OFB201",
                "needs the vehicle's command acks (COMMAND_ACK / vehicle_command_ack) to confirm "
                "requests the gate model expects PX4 to accept",
            )
