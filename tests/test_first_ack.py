"""OFB207: a client that acted on the first of the two acks PX4 1.16/1.17 send for a mode switch."""

from __future__ import annotations

import pytest

from fuzzoff.events import Command, CommandAck, Event, Where
from fuzzoff.findings import Finding, Severity
from tests.streams import ack, codes, lint_events, switch

ACCEPTED, TEMPORARILY_REJECTED = 0, 1


def arm(t: float) -> Command:
    return Command(t=t, command=400, params=(1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0))


def request_message(t: float) -> Command:
    return Command(t=t, command=512, params=(148.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0))


def ofb207(events: list[Event], px4: str = "1.16", fmt: str = "tlog") -> list[Finding]:
    return codes(lint_events(events, px4=px4, fmt=fmt), "OFB207")


def two_acks(second: int, step: Event | None) -> list[Event]:
    events: list[Event] = [switch(1.0), ack(1.003, ACCEPTED), ack(1.009, second)]
    return events if step is None else [*events, step]


@pytest.mark.parametrize("px4", ["1.16", "1.17"])
def test_a_step_between_the_acks_is_an_error_when_the_second_rejects(px4: str) -> None:
    (finding,) = ofb207(two_acks(TEMPORARILY_REJECTED, arm(1.005)), px4)
    assert finding.severity is Severity.ERROR
    assert finding.time_s == pytest.approx(1.005)
    assert "arm" in finding.message and "TEMPORARILY_REJECTED" in finding.message


def test_a_step_between_the_acks_is_a_warning_when_the_second_accepts() -> None:
    (finding,) = ofb207(two_acks(ACCEPTED, arm(1.005)))
    assert finding.severity is Severity.WARNING
    assert "by luck" in finding.message


def test_going_on_after_a_rejecting_second_ack_is_an_error() -> None:
    (finding,) = ofb207(two_acks(TEMPORARILY_REJECTED, arm(1.3)))
    assert finding.severity is Severity.ERROR
    assert finding.time_s == pytest.approx(1.3)
    assert "no retry" in finding.message


@pytest.mark.parametrize(
    "step",
    [switch(1.3), arm(3.5), request_message(1.005), None],
    ids=["retry", "much-later", "a-mere-request", "nothing"],
)
def test_no_finding_for_a_client_that_read_the_last_ack(step: Event | None) -> None:
    assert ofb207(two_acks(TEMPORARILY_REJECTED, step)) == []


def test_a_step_after_an_accepting_second_ack_is_right() -> None:
    assert ofb207(two_acks(ACCEPTED, arm(1.02))) == []


def test_one_ack_is_a_fixed_build_and_never_judged() -> None:
    """A 1.16/1.17 branch built after 2026-05-19 acks once: the recording's count decides."""
    events = [switch(1.0), ack(1.008, TEMPORARILY_REJECTED), arm(1.3)]
    assert ofb207(events) == []
    events = [switch(1.0), ack(1.008, ACCEPTED), arm(1.009), ack(1.5, ACCEPTED, 400)]
    assert ofb207(events) == []


@pytest.mark.parametrize("px4", ["1.15", "1.18", "main"])
def test_profiles_with_one_ack_do_not_run_the_rule(px4: str) -> None:
    assert ofb207(two_acks(TEMPORARILY_REJECTED, arm(1.005)), px4) == []


def test_set_mode_and_ros2_commands_get_commanders_ack_only() -> None:
    set_mode = Command(
        t=1.0, command=176, params=(1.0, 6.0, 0.0, 0.0, 0.0, 0.0, 0.0), where=Where("SET_MODE")
    )
    events: list[Event] = [set_mode, ack(1.003, ACCEPTED), arm(1.005), ack(1.009, ACCEPTED)]
    assert ofb207(events) == []
    ros2 = Command(t=1.0, command=176, params=switch(1.0).params, transport="ros2")
    events = [ros2, ack(1.003, ACCEPTED), arm(1.005), ack(1.009, ACCEPTED)]
    assert ofb207(events, fmt="mcap") == []


def test_a_step_logged_at_the_second_acks_time_is_not_between() -> None:
    """A ULog may log the step and Commander's ack at one time: no evidence of order."""
    events = [
        switch(1.0),
        ack(1.004, ACCEPTED),
        Command(t=1.008, command=21, params=(0.0,) * 7),
        ack(1.008, ACCEPTED),
    ]
    assert ofb207(events, fmt="ulog") == []


def test_the_acks_of_another_client_are_not_this_clients() -> None:
    mine = Command(
        t=1.0, command=176, params=switch(1.0).params, source_system=245, source_component=191
    )
    theirs = CommandAck(t=1.003, command=176, result=ACCEPTED, target_system=255)
    mine_ack = CommandAck(t=1.006, command=176, result=ACCEPTED, target_system=245)
    step = Command(
        t=1.004, command=400, params=arm(0).params, source_system=245, source_component=191
    )
    assert ofb207([mine, theirs, step, mine_ack]) == []


def test_without_acks_the_rule_says_it_cannot_judge() -> None:
    findings = lint_events([switch(1.0), arm(1.005)], px4="1.16", fmt="tlog")
    assert codes(findings, "OFB207") == []
    (not_checkable,) = codes(findings, "OFB002")
    assert "OFB207" in not_checkable.message


def test_a_retry_loop_that_stops_on_the_receivers_accepted_is_an_error() -> None:
    """The switch sent again while no answer came (a lost ack), then acked ACCEPTED by the
    receiver and rejected by Commander: no retry follows."""
    events = [switch(1.0), switch(1.5), ack(1.503, ACCEPTED), ack(1.509, TEMPORARILY_REJECTED)]
    (finding,) = ofb207([*events, Command(t=5.0, command=511, params=(0.0,) * 7)])
    assert ofb207(events) == []  # the recording ends before next_step_s has passed
    assert finding.severity is Severity.ERROR
    assert finding.time_s == pytest.approx(1.509)
    assert "sent 2 times" in finding.message and "stopped on the first ack" in finding.message


def test_a_retry_loop_that_goes_on_retrying_is_right() -> None:
    events = [switch(1.0), switch(1.5), ack(1.503, ACCEPTED), ack(1.509, TEMPORARILY_REJECTED)]
    assert ofb207([*events, switch(2.0), Command(t=5.0, command=511, params=(0.0,) * 7)]) == []
