"""OFB207: the client acted on the first of the two acks PX4 1.16 and 1.17 send for a mode switch.

On the v1.16.x and v1.17.0 tags PX4's MAVLink receiver answers a ``COMMAND_LONG``/``COMMAND_INT``
``DO_SET_MODE`` with its own ACCEPTED and then passes the command on to Commander, whose verdict
follows 4-9 ms later as a second ``COMMAND_ACK`` (gate.md#acks, #drift: PX4 PR #27343 removed the
first one on 1.18 and on the 1.16/1.17 branches after 2026-05-19). ``SET_MODE`` and a ROS 2
``VehicleCommand`` get Commander's ack only. The recording's own acks are the evidence, not the
version string: a switch answered once is never judged.

A client that read the first ack as the answer takes its next step too early: it sends a
command after the first ack and before the second (strictly: a ULog may log both at one time),
or, when the second rejects the switch, goes on (its next command is not another mode switch)
as if the switch had been taken. Commands that only ask for information (``QUERY_COMMANDS``)
are no step.
"""

from __future__ import annotations

from fuzzoff.checks._keepalive import px4_label
from fuzzoff.checks.base import Check, CheckContext
from fuzzoff.events import MAV_CMD_DO_SET_MODE, Command, CommandAck, Event, whole
from fuzzoff.findings import Severity
from fuzzoff.lean_dataclass import dataclass
from fuzzoff.modes import custom_mode_to_nav_state, nav_state_name
from fuzzoff.state import DOUBLE_ACK_WINDOW_S

CODE = "OFB207"

QUERY_COMMANDS = frozenset({410, 511, 512, 519, 520, 521, 522, 525, 527, 528})
"""Commands that ask PX4 for something and change nothing (GET_HOME_POSITION,
SET_MESSAGE_INTERVAL, REQUEST_MESSAGE, REQUEST_PROTOCOL_VERSION, REQUEST_AUTOPILOT_CAPABILITIES,
REQUEST_CAMERA_INFORMATION, REQUEST_CAMERA_SETTINGS, REQUEST_STORAGE_INFORMATION,
REQUEST_CAMERA_CAPTURE_STATUS, REQUEST_FLIGHT_INFORMATION): sending one says nothing about what
the client made of an ack."""

STEP_NAMES = {
    20: "NAV_RETURN_TO_LAUNCH",
    21: "NAV_LAND",
    22: "NAV_TAKEOFF",
    300: "MISSION_START",
    192: "DO_REPOSITION",
    178: "DO_CHANGE_SPEED",
}
"""Names of the commands a client commonly sends next (the rest by number)."""

Client = tuple[int | None, int | None]


def client_of(cmd: Command) -> Client:
    return (cmd.source_system, cmd.source_component)


def answers(ack: CommandAck, client: Client) -> bool:
    """Is ``ack`` addressed to ``client`` (or to anyone: target 0, or a client of unknown id)?"""
    system, component = client
    if system is None or ack.target_system == 0:
        return True
    return ack.target_system == system and ack.target_component in (0, component)


def switch_name(cmd: Command) -> str:
    main, sub = whole(cmd.params[1]), whole(cmd.params[2])
    if main is None or sub is None:
        return "DO_SET_MODE"
    nav = custom_mode_to_nav_state((main & 0xFF) << 16 | (sub & 0xFF) << 24)
    if nav is None:
        return f"DO_SET_MODE (custom main mode {main}, sub mode {sub})"
    return f"DO_SET_MODE to {nav_state_name(nav)}"


def step_name(cmd: Command) -> str:
    if cmd.is_arm:
        return "arm"
    if cmd.is_disarm:
        return "disarm"
    if cmd.command == MAV_CMD_DO_SET_MODE:
        return switch_name(cmd)
    name = STEP_NAMES.get(cmd.command)
    return f"{name} ({cmd.command})" if name else f"command {cmd.command}"


@dataclass(slots=True)
class _Switch:
    cmd: Command
    first: CommandAck | None = None
    step: Command | None = None
    """The client's first command after the first ack, while the second may still come."""
    attempts: int = 1
    """How often the client sent this switch before an answer came (a retry on a lost ack)."""


@dataclass(slots=True)
class _Rejected:
    cmd: Command
    first: CommandAck
    second: CommandAck
    attempts: int = 1


class FirstAckBelieved(Check):
    codes = (CODE,)
    wants = (Command, CommandAck)

    def __init__(self, ctx: CheckContext) -> None:
        super().__init__(ctx)
        self.switches: dict[Client, _Switch] = {}
        """Per client, its last mode switch through PX4's MAVLink receiver not yet judged."""
        self.rejected: dict[Client, _Rejected] = {}
        """Per client, a switch whose second ack rejected it: its next command says what the
        client believed."""
        self.next_step_s = float(ctx.option(CODE, "next_step_s"))
        self.unanswered = False
        """A switch through the MAVLink receiver and no ack in the whole recording."""

    def on_event(self, event: Event) -> None:
        self._expire(event.t)
        if isinstance(event, Command):
            self._command(event)
        elif isinstance(event, CommandAck) and event.command == MAV_CMD_DO_SET_MODE:
            self._ack(event)

    def _command(self, cmd: Command) -> None:
        if cmd.command in QUERY_COMMANDS:
            return
        client = client_of(cmd)
        switch = self.switches.get(client)
        if switch is not None and switch.first is not None and switch.step is None:
            switch.step = cmd
        rejected = self.rejected.pop(client, None)
        if rejected is not None and not cmd.is_mode_switch:
            self._went_on(rejected, cmd)
        if self._through_receiver(cmd) and (switch is None or switch.first is None):
            attempts = 1
            if switch is not None and switch.cmd.params == cmd.params:
                attempts = switch.attempts + 1
            self.switches[client] = _Switch(cmd, attempts=attempts)
            if not self.ctx.has("command_ack"):
                self.unanswered = True

    @staticmethod
    def _through_receiver(cmd: Command) -> bool:
        """A ``DO_SET_MODE`` that PX4's MAVLink receiver acks itself on 1.16/1.17 (a command
        message; not ``SET_MODE``, not a ROS 2 ``VehicleCommand``)."""
        return (
            cmd.command == MAV_CMD_DO_SET_MODE
            and cmd.transport != "ros2"
            and cmd.where.topic != "SET_MODE"
        )

    def _ack(self, ack: CommandAck) -> None:
        for client, switch in self.switches.items():
            if ack.t < switch.cmd.t or not answers(ack, client):
                continue
            if switch.first is None:
                if ack.accepted:
                    switch.first = ack
                else:  # a first answer that rejects is Commander's own: one ack
                    del self.switches[client]
                return
            del self.switches[client]
            self._judge(client, switch, ack)
            return

    def _expire(self, now: float) -> None:
        """A first ack with no second within the window was the only one (a fixed build)."""
        for client in [
            c
            for c, s in self.switches.items()
            if s.first is not None and now - s.first.t > DOUBLE_ACK_WINDOW_S
        ]:
            del self.switches[client]
        for client in [c for c, r in self.rejected.items() if now - r.second.t > self.next_step_s]:
            rejected = self.rejected.pop(client)
            if rejected.attempts > 1:
                self._stopped(rejected)

    def _judge(self, client: Client, switch: _Switch, second: CommandAck) -> None:
        cmd, first, step = switch.cmd, switch.first, switch.step
        assert first is not None
        what = switch_name(cmd)
        acks = (
            f"{what} at {cmd.t:.3f} s was acked twice, as {px4_label(self.ctx)}'s MAVLink "
            f"receiver does on the 1.16/1.17 tags: ACCEPTED at {first.t:.3f} s (the receiver's, "
            f"sent before Commander looked at it), then {second.result_name} at {second.t:.3f} s "
            "(Commander's verdict)"
        )
        if step is not None and step.t >= second.t:
            # at the same time as the second ack (a ULog's samples): no evidence of order
            if second.accepted or step.is_mode_switch:
                return
            self._went_on(_Rejected(cmd, first, second), step)
            return
        if step is not None:
            if second.accepted:
                outcome = (
                    "Commander accepted it this time, so the step went right by luck: on a "
                    "rejection the client would have acted the same"
                )
                severity = Severity.WARNING
            else:
                outcome = (
                    "Commander rejected it, so the vehicle is not in the mode the client acted on"
                )
                severity = Severity.ERROR
            self.ctx.report(
                CODE,
                f"{acks}; the client sent {step_name(step)} at {step.t:.3f} s, between the two: "
                f"it took the receiver's ACCEPTED as the answer; {outcome}. Wait for the last "
                f"ack of the switch (or for the mode in HEARTBEAT) before the next step",
                step.t,
                step.where,
                severity=severity,
                short=f"{step_name(step)} sent between the two acks of {what}"
                + ("" if second.accepted else f" (the second: {second.result_name})"),
            )
            return
        if not second.accepted:
            self.rejected[client] = _Rejected(cmd, first, second, switch.attempts)

    def _went_on(self, rejected: _Rejected, step: Command) -> None:
        what = switch_name(rejected.cmd)
        second = rejected.second
        self.ctx.report(
            CODE,
            f"{what} at {rejected.cmd.t:.3f} s was acked ACCEPTED at {rejected.first.t:.3f} s by "
            f"{px4_label(self.ctx)}'s MAVLink receiver and then {second.result_name} at "
            f"{second.t:.3f} s by Commander; the client's next command, {step_name(step)} at "
            f"{step.t:.3f} s, is no retry and no other mode: it went on as if the switch had "
            "been taken. Read the last ack of the switch (1.16/1.17 tags send two), retry or "
            "stop on a rejection",
            step.t,
            step.where,
            short=f"{step_name(step)} after {what} was rejected by its second ack "
            f"({second.result_name})",
        )

    def _stopped(self, rejected: _Rejected) -> None:
        """A client that retried the switch while no answer came, and stopped once the
        receiver's ACCEPTED came, although Commander's answer rejected it."""
        what = switch_name(rejected.cmd)
        second = rejected.second
        self.ctx.report(
            CODE,
            f"{what} was sent {rejected.attempts} times before an answer came (a client that "
            f"retries until it is accepted); the answer was the MAVLink receiver's ACCEPTED at "
            f"{rejected.first.t:.3f} s, then Commander's {second.result_name} at "
            f"{second.t:.3f} s, and the client retried no more (none within "
            f"{self.next_step_s:g} s): it stopped on the first ack. Read the last ack of the "
            "switch (1.16/1.17 tags send two) before the retry loop ends",
            second.t,
            second.where,
            short=f"stopped retrying {what} on the receiver's ACCEPTED; Commander: "
            f"{second.result_name}",
        )

    def finish(self, t_end: float) -> None:
        self._expire(t_end)
        if self.unanswered:
            self.ctx.cannot_check(
                CODE,
                "needs the vehicle's command acks (COMMAND_ACK / vehicle_command_ack) to see "
                "whether a mode switch was acked once or twice",
            )
