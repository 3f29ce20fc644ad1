"""OFB208: a command PX4 always answers, left without any answer in a recording that holds
PX4's answers.

Commander answers every DO_SET_MODE, COMPONENT_ARM_DISARM, NAV_LAND, NAV_TAKEOFF and
NAV_RETURN_TO_LAUNCH it handles (``fuzzoff/tables/answered.py``). A recording of the client's
side that shows PX4's answers to other commands and none to this one shows a command that
never reached PX4 (over ROS 2 PX4's inputs are best-effort readers that match a new writer some
100 ms late; over MAVLink a message is lost on the link) or whose answer was lost, with a
client that did not notice: it never sent it again. Issue 28 miss 3: the ARM of px4_ros_com's
example, sent 0.6 ms after DO_SET_MODE, never reached PX4, which stayed disarmed in OFFBOARD.

Judged are the commands as sent (ROS 2 ``/fmu/in/vehicle_command``, a MAVLink message from the
client) that the vehicle takes by their address (one PX4 drops by address is OFB204's case). A
copy of the command sent again within ``answer_s`` of the last is a retry: an answer to it
answers all. A recording that holds no answer at all (no ack topic, or none recorded) is not
judged; nor a command sent less than ``answer_s`` before the recording ends.
"""

from __future__ import annotations

from fuzzoff.checks.base import Check, CheckContext
from fuzzoff.checks.first_ack import step_name
from fuzzoff.events import Command, CommandAck, Event
from fuzzoff.gate.addressing import command_addressing
from fuzzoff.lean_dataclass import dataclass
from fuzzoff.mavlink_ids import MAV_COMP_ID_AUTOPILOT1
from fuzzoff.tables.answered import always_answered

CODE = "OFB208"


@dataclass(slots=True)
class _Pending:
    first: Command
    last_t: float
    sent: int = 1


class CommandUnanswered(Check):
    """OFB208: one finding per command (with its retries) that got no answer."""

    codes = (CODE,)
    wants = (Command, CommandAck)

    def __init__(self, ctx: CheckContext) -> None:
        super().__init__(ctx)
        self.answer_s = float(ctx.option(CODE, "answer_s"))
        self.table = always_answered(ctx.profile.release)
        self.pending: dict[int, _Pending] = {}
        self.unanswered: list[_Pending] = []
        self.acks = 0

    def on_event(self, event: Event) -> None:
        if isinstance(event, CommandAck):
            self.acks += 1
            self.pending.pop(event.command, None)
            return
        if not isinstance(event, Command) or not self._judged(event):
            return
        held = self.pending.get(event.command)
        if held is not None and event.t - held.last_t <= self.answer_s:
            held.last_t, held.sent = event.t, held.sent + 1  # a retry
            return
        if held is not None:
            self.unanswered.append(held)
        self.pending[event.command] = _Pending(event, event.t)

    def _judged(self, cmd: Command) -> bool:
        if cmd.origin != "sent" or cmd.command not in self.table:
            return False
        own = int(self.ctx.vehicle) if self.ctx.vehicle.isdigit() else None
        component = int(self.ctx.state.params.get("MAV_COMP_ID", MAV_COMP_ID_AUTOPILOT1))
        answer = command_addressing(self.ctx.profile.release, cmd, own, component)
        return answer.answer != "ignored"

    def finish(self, t_end: float) -> None:
        if "command_ack" not in self.ctx.info.kinds or not self.acks:
            if self.unanswered or self.pending:
                self.ctx.cannot_check(
                    CODE, "needs PX4's command acks (/fmu/out/vehicle_command_ack, COMMAND_ACK)"
                )
            return
        late = [p for p in self.pending.values() if t_end - p.last_t >= self.answer_s]
        for held in sorted([*self.unanswered, *late], key=lambda p: p.first.t):
            self._report(held, t_end)

    def _report(self, held: _Pending, t_end: float) -> None:
        cmd = held.first
        what = step_name(cmd)
        name = self.table[cmd.command]
        times = f"sent {held.sent} times, " if held.sent > 1 else ""
        self.ctx.report(
            CODE,
            f"{what} ({name}) got no answer ({times}{t_end - held.last_t:.2f} s to the end of the "
            f"recording or the next try) although PX4 answers every {name} it receives and the "
            f"recording holds its answers to other commands ({self.acks} acks): it did not reach "
            "PX4, or its answer was lost, and the client did not send it again",
            cmd.t,
            cmd.where,
            short=f"{what}: no answer from PX4 (it answers every {name}); not sent again",
        )
