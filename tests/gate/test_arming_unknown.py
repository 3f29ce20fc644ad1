"""Requests whose outcome depends on an arming state the recording does not show (issue 17).

PX4 1.14+ takes a switch to OFFBOARD while disarmed without any stream and rejects it while
armed without one (gate spec 4.1); an arm request is acked ACCEPTED with no change when already
armed (4.2; seen on 1.15.4 and 1.18.0-alpha1 SITL). Where the recording shows neither the
arming state nor PX4's answer, the model gives both outcomes until the recording decides.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from fuzzoff.config import Settings
from fuzzoff.engine import lint_file
from fuzzoff.events import CommandAck, ControlMode, Event, VehicleStatus
from tests.gate.streams import (
    OFFBOARD,
    POSCTL,
    TICK,
    arm,
    model,
    ocm,
    of,
    run,
    status,
    switch_offboard,
)
from tests.helpers import run_cli


def _ack(t: float, command: int, result: int) -> CommandAck:
    return CommandAck(t=t, command=command, result=result)


@pytest.mark.parametrize("px4", TICK)
def test_switch_without_stream_gives_both_outcomes(px4: str) -> None:
    (undecided,) = of("undecided", run(px4, [switch_offboard(1.0)]))
    assert "if disarmed: accepted" in (undecided.reason or "")
    assert "if armed: rejected (no offboard signal)" in (undecided.reason or "")
    assert undecided.message.endswith("; arming not recorded")


@pytest.mark.parametrize("px4", TICK)
def test_no_undecided_where_the_stream_makes_both_accept(px4: str) -> None:
    trs = run(px4, [ocm(0.0), ocm(0.1), switch_offboard(0.15)])
    assert of("undecided", trs) == []
    assert of("request_accepted", trs)


@pytest.mark.parametrize("px4", TICK)
def test_recorded_arming_decides_before_the_request(px4: str) -> None:
    """A recorded status gives the arming state: a single outcome, as before."""
    disarmed = run(px4, [status(0.0, POSCTL, False, POSCTL), switch_offboard(1.0)])
    assert of("undecided", disarmed) == [] and of("request_accepted", disarmed)
    armed = run(px4, [status(0.0, POSCTL, True, POSCTL), switch_offboard(1.0)])
    assert of("undecided", armed) == [] and of("request_rejected", armed)


@pytest.mark.parametrize("px4", TICK)
@pytest.mark.parametrize(("result", "armed", "nav"), [(0, False, OFFBOARD), (1, True, None)])
def test_the_ack_decides_and_is_no_disagreement(
    px4: str, result: int, armed: bool, nav: int | None
) -> None:
    """ACCEPTED: the vehicle was disarmed (OFFBOARD while disarmed); TEMPORARILY_REJECTED: it
    was armed (no mode change). Neither is a disagreement: the recording decided."""
    gate = model(px4)
    trs = run(px4, [switch_offboard(1.0), _ack(1.01, 176, result)], t_end=2.0, model=gate)
    assert of("disagreement", trs) == []
    (decided,) = [tr for tr in of("mode", trs) if "acked" in tr.message]
    assert ("was armed" if armed else "was disarmed") in decided.message
    assert gate.armed is armed
    assert gate.nav_state == nav


@pytest.mark.parametrize("px4", TICK)
def test_a_later_status_decides(px4: str) -> None:
    """The first recorded status shows the vehicle armed in POSCTL: the switch was rejected."""
    gate = model(px4)
    events: list[Event] = [switch_offboard(1.0), status(3.0, POSCTL, True, POSCTL)]
    trs = run(px4, events, t_end=4.0, model=gate)
    assert any("was armed" in tr.message for tr in of("mode", trs))
    assert of("disagreement", trs) == []
    assert gate.armed is True and gate.nav_state == POSCTL


@pytest.mark.parametrize("px4", TICK)
def test_arm_after_an_undecided_switch_without_stream_gives_both(px4: str) -> None:
    """Disarmed, the arm in OFFBOARD is refused (no signal); armed, it changes nothing."""
    trs = run(px4, [switch_offboard(1.0), arm(2.0)], t_end=3.0)
    arms = [tr for tr in of("undecided", trs) if tr.cause is not None and tr.cause.t == 2.0]
    (undecided,) = arms
    assert "if disarmed: rejected (no offboard signal)" in (undecided.reason or "")
    assert "if armed: acked ACCEPTED, no change" in (undecided.reason or "")


@pytest.mark.parametrize("px4", TICK)
def test_a_loss_with_unknown_arming_says_what_each_does(px4: str) -> None:
    """An undecided switch followed by a stream that stops: the failsafe runs only if armed."""
    events: list[Event] = [switch_offboard(0.5), *[ocm(round(1.0 + 0.1 * k, 3)) for k in range(5)]]
    trs = run(px4, events, t_end=4.0)
    (lost,) = of("signal_lost", trs)
    assert "if armed, PX4 runs POSCTL, if disarmed nothing" in lost.message
    assert of("failsafe", trs) == []


def test_lint_reports_both_outcomes(tmp_path: Path) -> None:
    """A companion's MCAP with only what it sent (no vehicle status, no acks): OFB102 and the
    predicted OFB201 name both outcomes; `fuzzoff gate` shows the undecided row."""
    from fuzzoff.formats.mcap.writer import write_mcap
    from tests.gate.streams import Command

    events: list[Event] = [
        Command(t=1.0, command=100001, params=(14.0, 0, 0, 0, 0, 0, 0), origin="sent"),
        *[ControlMode(t=round(2.0 + 0.1 * k, 3), position=True) for k in range(10)],
    ]
    path = write_mcap(tmp_path / "no_status.mcap", events, release="1.15")
    report = lint_file(path, Settings(px4="1.15", vehicle="mc"))
    texts = {f.code: f.message for f in report.findings}
    assert "if disarmed: accepted" in texts["OFB102"] and "if armed: rejected" in texts["OFB102"]
    ofb201 = next(f for f in report.findings if f.code == "OFB201")
    assert ofb201.severity.label == "warning"
    assert "neither the arming state nor the vehicle's answer" in ofb201.message
    result = run_cli(["gate", str(path), "--px4", "1.15", "--vehicle", "mc"])
    assert "undecided" in result.stdout


def test_a_status_without_arming_keeps_it_unknown() -> None:
    """/mavros/state while MAVROS is not connected: no arming state, nothing decided."""
    gate = model("1.15")
    run(
        "1.15", [VehicleStatus(t=0.0, nav_state=None, armed=None), switch_offboard(1.0)], model=gate
    )
    assert gate.armed is None
