"""Whether a MAVLink command reaches Commander: PX4's receiver checks its address first.

Seen on running PX4 SITL (1.14.4, 1.15.4, 1.16.2, 1.17.0, the 1.18 beta head and main, 2026-12;
gate.md#seen-on-px4): a COMMAND_LONG or COMMAND_INT for another system or another component is never
handled; up to 1.15 the receiver answers it with FAILED, from 1.16 it drops it without an ack.
One with ``target_system`` 0 is treated the same way up to 1.17 and handled from 1.18. SET_MODE
has no component: for system 0 or the vehicle's it is handled on every release, for another
system dropped without an ack. A command in a ROS 2 recording or a ULog is past the receiver;
only a MAVLink message as recorded (``Command.message``, a tlog) is judged.
"""

from __future__ import annotations

from typing import Literal

from fuzzoff.events import Command
from fuzzoff.lean_dataclass import dataclass
from fuzzoff.releases import Release

Answer = Literal["handled", "ack_failed", "ignored"]


@dataclass(frozen=True, slots=True)
class Addressing:
    answer: Answer
    wrong: str = ""
    """What in the address PX4 does not take ("target_system 0 (broadcast)", ...)."""

    @property
    def handled(self) -> bool:
        return self.answer == "handled"

    def effect(self, release: Release) -> str:
        """What PX4 of ``release`` does with the command, in a user's words."""
        if self.answer == "ack_failed":
            return f"PX4 {release.name} answers it with FAILED and does nothing"
        if self.answer == "ignored":
            return f"PX4 {release.name} drops it without an answer"
        return f"PX4 {release.name} handles it"


HANDLED = Addressing("handled")


def wrong_address(
    cmd: Command, own_system: int | None, own_component: int, broadcast_ok: bool
) -> str:
    """What in ``cmd``'s address the receiver refuses ('' if nothing)."""
    wrong = []
    system = cmd.target_system
    if system == 0:
        if not broadcast_ok and cmd.message != "SET_MODE":
            wrong.append("target_system 0 (broadcast)")
    elif own_system is not None and system != own_system:
        wrong.append(f"target_system {system} (the vehicle is system {own_system})")
    component = cmd.target_component
    if cmd.message != "SET_MODE" and component not in (0, own_component):
        wrong.append(f"target_component {component} (the autopilot is component {own_component})")
    return " and ".join(wrong)


def command_addressing(
    release: Release, cmd: Command, own_system: int | None, own_component: int
) -> Addressing:
    """What PX4 of ``release`` does with ``cmd`` on receipt, by its address."""
    if cmd.message is None or cmd.transport != "mavlink" or cmd.origin != "sent":
        return HANDLED  # not a MAVLink message as recorded: its address is not known
    wrong = wrong_address(cmd, own_system, own_component, release.handles_broadcast_command)
    if not wrong:
        return HANDLED
    if cmd.message == "SET_MODE":
        return Addressing("ignored", wrong)
    return Addressing(release.alien_command_answer, wrong)
