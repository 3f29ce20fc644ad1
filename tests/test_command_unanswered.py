"""OFB208 on minimal streams: what counts as unanswered, and where it is not judged."""

from __future__ import annotations

from fuzzoff.events import Command, CommandAck, Event, VehicleStatus
from fuzzoff.findings import Severity
from tests.streams import codes, lint_events

Params = tuple[float, float, float, float, float, float, float]
ARM: Params = (1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
OFFBOARD: Params = (1.0, 6.0, 0.0, 0.0, 0.0, 0.0, 0.0)


def _cmd(t: float, command: int, params: Params) -> Command:
    return Command(t=t, command=command, params=params, origin="sent")


def _flight(*extra: Event, end: float = 4.0) -> list[Event]:
    return [
        _cmd(1.0, 176, OFFBOARD),
        CommandAck(t=1.01, command=176, result=0),
        VehicleStatus(t=1.02, nav_state=14, armed=False),
        VehicleStatus(t=end, nav_state=14, armed=False),
        *extra,
    ]


def test_an_arm_with_no_ack_among_answered_commands_is_an_error() -> None:
    (found,) = codes(lint_events(_flight(_cmd(1.001, 400, ARM)), px4="1.16"), "OFB208")
    assert found.severity is Severity.ERROR and found.time_s == 1.001
    assert "COMPONENT_ARM_DISARM" in found.summary


def test_a_retry_that_is_answered_answers_the_first_copy() -> None:
    events = _flight(
        _cmd(1.001, 400, ARM), _cmd(1.6, 400, ARM), CommandAck(t=1.61, command=400, result=1)
    )
    assert codes(lint_events(events, px4="1.16"), "OFB208") == []


def test_a_rejection_is_an_answer() -> None:
    events = _flight(_cmd(1.001, 400, ARM), CommandAck(t=1.02, command=400, result=1))
    assert codes(lint_events(events, px4="1.16"), "OFB208") == []


def test_not_judged_without_any_ack_nor_at_the_end_of_the_recording() -> None:
    no_acks = [e for e in _flight(_cmd(1.001, 400, ARM)) if not isinstance(e, CommandAck)]
    assert codes(lint_events(no_acks, px4="1.16"), "OFB208") == []
    late = _flight(_cmd(3.5, 400, ARM), end=4.0)
    assert codes(lint_events(late, px4="1.16"), "OFB208") == []


def test_a_command_px4_does_not_always_answer_is_not_judged() -> None:
    other = _cmd(1.5, 183, (1.0, 1500.0, 0.0, 0.0, 0.0, 0.0, 0.0))  # DO_SET_SERVO
    assert codes(lint_events(_flight(other), px4="1.16"), "OFB208") == []
