"""The recorded acks against the model's decisions (gate.md#acks): one part of ``GateModel``.

``Acks`` hands each recorded ``COMMAND_ACK`` to the comparison (``compare``), which waits
``ACK_WINDOW`` for a second ack of the same command (PX4 1.16/1.17 ack a mode switch twice) and
judges the last. An ack whose result differs from the model's decision is a ``disagreement``
(or ``mode`` where OFFBOARD is on neither side), and the model follows the ack; an ack of a
request decided while the arming state was unknown says which outcome held.
"""

from __future__ import annotations

from fuzzoff.events import MAV_CMD_COMPONENT_ARM_DISARM, CommandAck
from fuzzoff.gate.commander import Requests, request_name
from fuzzoff.gate.compare import NOT_OFFBOARD, Decided
from fuzzoff.gate.effective import EffectiveMode
from fuzzoff.gate.state import GateState


class Acks:
    def __init__(self, state: GateState, mode: EffectiveMode, requests: Requests) -> None:
        self.s = state
        self.mode = mode
        self.requests = requests

    def ack(self, ack: CommandAck) -> bool:
        self.s.compare.ack(ack)
        return True

    def due(self) -> float:
        """When the ack waiting for a second one is judged (inf if none)."""
        return self.s.compare.ack_due()

    def judge(self, at: float) -> None:
        s = self.s
        judged = s.compare.take_ack()
        if judged is None:
            return
        decided, ack = judged
        if decided.alternative is not None:
            self._decides(decided, ack)
            return
        cmd, target = decided.cmd, decided.target
        what = request_name(cmd, target)
        decision = decided.decision
        model = "accepted" if decision.accepted else f"rejected ({decision.reason})"
        text = f"recorded: {what} acked {ack.result_name} at {ack.t:.2f} s; model: {model}"
        if s.involves_offboard(target, decided.before[0]):
            s.emit(ack.t, "disagreement", text, "4.3", cause=ack)
        else:
            s.emit(ack.t, "mode", f"{text} ({NOT_OFFBOARD})", "4.3", cause=ack)
        self._follow(decided, ack)

    def _follow(self, decided: Decided, ack: CommandAck) -> None:
        """The model takes the ack's outcome."""
        s = self.s
        cmd, target = decided.cmd, decided.target
        if ack.accepted and cmd.command == MAV_CMD_COMPONENT_ARM_DISARM:
            if decided.decision.changes or s.armed is None:
                if cmd.is_arm:
                    s.armed_now(ack.t)
                else:
                    s.disarmed_now()
        elif ack.accepted and target is not None:
            s.user_intention = target
            s.fallback = None
        elif not ack.accepted:
            s.user_intention, s.armed = decided.before
        self.mode.refresh(ack.t, cause=ack)

    def _decides(self, decided: Decided, ack: CommandAck) -> None:
        """An ack of a request decided while the arming state was unknown: its result says
        which it was (never a disagreement while one outcome matches)."""
        alternative = decided.alternative
        assert alternative is not None
        what = request_name(decided.cmd, decided.target)
        said = f"recorded: {what} acked {ack.result_name} at {ack.t:.2f} s"
        if ack.accepted == decided.decision.accepted:
            self.requests.resolve(ack.t, False, said)
        elif ack.accepted == alternative.accepted:
            self.requests.resolve(ack.t, True, said)
