"""What was seen on a running PX4 (gate spec 13a: v1.16.2, v1.17.0 and v1.14.4 SITL driven over
MAVLink): the model must reproduce each observation within the profile's evaluation slack."""

from __future__ import annotations

import pytest

from fuzzoff.events import CommandAck, SetPositionTargetLocal
from tests.gate.streams import (
    OFFBOARD,
    POSCTL,
    arm,
    flags,
    model,
    of,
    run,
    status,
    switch_offboard,
)

SLACK = 0.12
POS = 0b110111111000
ACC = 0b110000111111


def setpoints(
    t0: float, t1: float, mask: int = POS, frame: int = 1
) -> list[SetPositionTargetLocal]:
    out = []
    k = 0
    while t0 + 0.05 * k <= t1 + 1e-9:
        out.append(
            SetPositionTargetLocal(
                t=round(t0 + 0.05 * k, 6),
                type_mask=mask,
                coordinate_frame=frame,
                target_system=1,
                target_component=1,
                position=(0.0, 0.0, -2.0),
                acceleration=(0.5, 0.0, 0.0),
            )
        )
        k += 1
    return out


def _flight(px4: str, *extra: object) -> list:  # type: ignore[type-arg]
    """Armed in POSCTL, stream from 1 s, switch at 2 s, stream stops at 5 s."""
    return [
        status(0.0, POSCTL, True, POSCTL),
        *setpoints(1.0, 5.0),
        switch_offboard(2.0),
        *extra,
    ]


@pytest.mark.parametrize("observed", [1.08, 1.09])
def test_v116_loss_seen_about_1_08_s_after_the_last_setpoint(observed: float) -> None:
    (lost,) = of("signal_lost", run("1.16", _flight("1.16"), t_end=7.0))
    assert abs((lost.t - 5.0) - observed) <= SLACK


def test_v116_arm_48ms_after_one_setpoint_but_not_after_1_2s_silence() -> None:
    one = setpoints(3.0, 3.0)
    events = [status(0.0, OFFBOARD, False, OFFBOARD), *one, arm(3.048)]
    assert of("arm_accepted", run("1.16", events))
    events = [status(0.0, OFFBOARD, False, OFFBOARD), *one, arm(4.2)]
    assert of("arm_rejected", run("1.16", events))


def test_v116_local_enu_frame_dropped_and_switch_rejected() -> None:
    events = [
        status(0.0, POSCTL, True, POSCTL),
        *setpoints(1.0, 3.0, frame=4),
        switch_offboard(2.0),
    ]
    trs = run("1.16", events)
    assert any("coordinate frame 4 unsupported" in (t.reason or "") for t in trs)
    assert of("request_rejected", trs)


def test_v116_loss_action_position_keeps_the_intention() -> None:
    gate = model("1.16")
    trs = run("1.16", _flight("1.16"), t_end=7.0, model=gate)
    assert [t.action for t in of("failsafe", trs)] == ["POSCTL"]
    assert gate.user_intention == OFFBOARD


@pytest.mark.parametrize(("rc", "action"), [(False, "AUTO_RTL"), (True, "POSCTL")])
def test_v117_loss_without_manual_control_returns_and_comes_back(rc: bool, action: str) -> None:
    events = _flight("1.17", flags(0.0, manual_control_signal_lost=not rc), *setpoints(8.0, 9.0))
    trs = run("1.17", events, t_end=9.0)
    (failsafe,) = of("failsafe", trs)
    assert failsafe.action == action and abs((failsafe.t - 5.0) - 1.07) <= SLACK
    (back,) = of("offboard_resumed", trs)
    assert 0.0 <= back.t - 8.0 <= 0.02  # 16-20 ms after the first resumed setpoint


def test_v117_two_acks_first_accepted() -> None:
    events = [
        status(0.0, POSCTL, True, POSCTL),
        switch_offboard(1.0),
        CommandAck(t=1.001, command=176, result=0),
        CommandAck(t=1.007, command=176, result=1),
    ]
    trs = run("1.17", events, t_end=2.0)
    assert of("request_rejected", trs) and not of("disagreement", trs)


@pytest.mark.parametrize("rc", [False, True])
def test_v114_loss_is_position_with_or_without_joystick(rc: bool) -> None:
    events = _flight("1.14", flags(0.0, manual_control_signal_lost=not rc))
    assert [t.action for t in of("failsafe", run("1.14", events, t_end=7.0))] == ["POSCTL"]


@pytest.mark.parametrize(
    ("px4", "controllers"),
    [
        ("1.14", "acceleration, attitude, rates"),
        ("1.17", "acceleration, attitude, rates, allocation"),
    ],
)
def test_acceleration_only_stream_accepted(px4: str, controllers: str) -> None:
    events = [
        status(0.0, POSCTL, True, POSCTL),
        *setpoints(1.0, 3.0, mask=ACC),
        switch_offboard(2.0),
    ]
    trs = run(px4, events)
    assert of("request_accepted", trs)
    assert any(f"({controllers})" in t.message for t in of("controller", trs))
