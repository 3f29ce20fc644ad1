"""Requests and acks (gate spec 4), the recording as input (12: start mid-flight, estimates,
parameters) and the recorded-vs-model comparison with the evaluation slack (2.1.3)."""

from __future__ import annotations

import pytest

from fuzzoff.events import Command, CommandAck, Parameter, VehicleStatus, Where
from tests.gate.streams import (
    ALL,
    OFFBOARD,
    POSCTL,
    TERMINATION,
    TICK,
    arm,
    flags,
    in_offboard,
    model,
    ocm,
    of,
    run,
    status,
    stream,
    switch_mode,
    switch_offboard,
)


def _set_nav_state(t: float, nav: int) -> Command:
    return Command(t=t, command=100001, params=(float(nav), 0, 0, 0, 0, 0, 0))


@pytest.mark.parametrize(("px4", "handled"), [("1.14", False), *[(p, True) for p in TICK[1:]]])
def test_4_1_set_nav_state_from_115(px4: str, handled: bool) -> None:
    """4.1: ROS 2 VEHICLE_CMD_SET_NAV_STATE (100001) is handled from 1.15, not in 1.14."""
    events = [status(0.0, POSCTL, False, POSCTL), _set_nav_state(1.0, OFFBOARD)]
    trs = run(px4, events)
    assert bool(of("request_accepted", trs)) is handled


@pytest.mark.parametrize(
    ("px4", "rejected"),
    [
        ("1.14", False),
        ("1.15", False),
        ("1.16", False),
        ("1.17", False),
        ("1.18", True),
        ("main", True),
    ],
)
def test_4_1_unsupported_main_mode(px4: str, rejected: bool) -> None:
    """4.1: an unknown custom main mode: 1.18 and main reject it; 1.14-1.17 ack it with no
    change."""
    trs = run(px4, [status(0.0, POSCTL, True, POSCTL), switch_mode(1.0, 42)])
    assert any("no such mode" in (t.message or "") for t in trs)
    assert any("rejected" in t.message for t in trs) is rejected


@pytest.mark.parametrize("px4", ["1.14", "1.16", "1.17", "1.18", "main"])
def test_4_1_auto_with_sub_mode_0_is_mission(px4: str) -> None:
    """4.1 (Commander's AUTO branch; seen on 1.16.2-main SITL): AUTO with sub-mode 0 asks for
    Mission on every release, not for a mode PX4 lacks."""
    trs = run(px4, [status(0.0, POSCTL, True, POSCTL), switch_mode(1.0, 4, 0)])
    (switch,) = [t for t in trs if t.t == 1.0 and t.what == "mode"]
    assert "AUTO_MISSION" in switch.message and switch.nav_state == 3


@pytest.mark.parametrize("px4", ["1.14", "1.16", "1.17", "1.18", "main"])
def test_4_1_an_unknown_auto_sub_mode_is_refused_everywhere(px4: str) -> None:
    """4.1: an AUTO sub-mode Commander does not know is denied on every release (1.16/1.17
    after the receiver's own ACCEPTED), unlike an unknown main mode."""
    trs = run(px4, [status(0.0, POSCTL, True, POSCTL), switch_mode(1.0, 4, 42)])
    (switch,) = [t for t in trs if t.t == 1.0]
    assert "rejected" in switch.message and "AUTO sub-mode 42" in switch.message
    assert switch.nav_state == POSCTL


@pytest.mark.parametrize(("px4", "exists"), [("1.16", False), ("1.17", True), ("main", True)])
def test_4_1_altitude_cruise_exists_from_1_17(px4: str, exists: bool) -> None:
    """4.1: main mode 11 is ALTITUDE_CRUISE (nav_state 8) from 1.17.0 (seen on 1.17.0 SITL);
    before, an unknown main mode (acked, no change)."""
    trs = run(px4, [status(0.0, POSCTL, True, POSCTL), switch_mode(1.0, 11)])
    (switch,) = [t for t in trs if t.t == 1.0]
    assert (switch.nav_state == 8) is exists
    assert ("no such mode" in switch.message) is not exists


@pytest.mark.parametrize("armed", [True, False])
@pytest.mark.parametrize(("px4", "stays"), [("1.14", False), ("1.15", False), ("1.16", True)])
def test_4_1_never_out_of_termination_from_116(px4: str, stays: bool, armed: bool) -> None:
    """4.1: from 1.16 no mode switch leaves TERMINATION, armed or not: the test comes after
    the always-allowed-while-disarmed shortcut in ``UserModeIntention::change``."""
    events = [status(0.0, TERMINATION, armed, TERMINATION), *stream(0.0, 1.0), switch_offboard(0.5)]
    assert bool(of("request_rejected", run(px4, events))) is stays


@pytest.mark.parametrize("px4", TICK)
@pytest.mark.parametrize(("external", "armed"), [(False, True), (True, False)])
def test_4_2_forced_arm_skips_checks_only_from_internal(
    px4: str, external: bool, armed: bool
) -> None:
    """4.2: param2 = 21196 skips the checks only for commands not from external sources."""
    forced = Command(
        t=1.0, command=400, params=(1.0, 21196.0, 0, 0, 0, 0, 0), from_external=external
    )
    trs = run(px4, [status(0.0, OFFBOARD, False, OFFBOARD), forced])
    assert bool(of("arm_accepted", trs)) is armed


@pytest.mark.parametrize("px4", TICK)
def test_4_2_arm_rechecks_at_the_request(px4: str) -> None:
    """4.2: arming re-runs the checks at the request: 1.05 s after the only keep-alive (before
    the next 10 Hz pass would have flagged it) the arm is already rejected."""
    events = [status(0.0, OFFBOARD, False, OFFBOARD), ocm(1.0), arm(2.05)]
    assert of("arm_rejected", run(px4, events))


@pytest.mark.parametrize("px4", ["1.16", "1.17"])
def test_4_3_double_ack_last_one_decides(px4: str) -> None:
    """4.3: 1.16/1.17 ack ACCEPTED first, then Commander's result: the model's rejection agrees
    with the second ack, so no disagreement."""
    events = [
        status(0.0, POSCTL, True, POSCTL),
        switch_offboard(1.0),
        CommandAck(t=1.002, command=176, result=0),
        CommandAck(t=1.008, command=176, result=1),
        status(2.0, POSCTL, True, POSCTL),
    ]
    trs = run(px4, events)
    assert of("request_rejected", trs) and not of("disagreement", trs)


@pytest.mark.parametrize("px4", ALL)
def test_4_3_ack_that_contradicts_the_model_is_a_disagreement(px4: str) -> None:
    """12 / 4.3: the vehicle accepted a switch the model rejects: reported, model follows."""
    events = [
        status(0.0, POSCTL, True, POSCTL),
        switch_offboard(1.0),
        CommandAck(t=1.01, command=176, result=0),
        *stream(1.02, 1.5),
    ]
    gate = model(px4)
    trs = run(px4, events, model=gate)
    (differ,) = of("disagreement", trs)
    assert "acked ACCEPTED" in differ.message and "rejected" in differ.message
    assert gate.user_intention == OFFBOARD


@pytest.mark.parametrize("px4", TICK)
def test_12_recording_that_starts_in_offboard(px4: str) -> None:
    """12: the model starts from the first recorded status; a live stream is assumed there."""
    events = [in_offboard(3.0), *stream(3.02, 5.0)]
    trs = run(px4, events)
    assert of("failsafe", trs) == [] and of("disagreement", trs) == []


@pytest.mark.parametrize("px4", TICK)
def test_12_recorded_failsafe_within_the_window_agrees(px4: str) -> None:
    """2.1.3: PX4's check pass has its own phase: a recorded failsafe anywhere in the loss
    window (1.0 s after the newest keep-alive and up to one check period and one iteration
    later) is agreement, and the model takes its time from the recording."""
    for recorded_at in (2.01, 2.05, 2.11):
        events = [
            in_offboard(),
            *stream(0.0, 1.0),
            VehicleStatus(t=recorded_at, nav_state=POSCTL, armed=True, user_intention=OFFBOARD),
            VehicleStatus(t=3.0, nav_state=POSCTL, armed=True, user_intention=OFFBOARD),
        ]
        trs = run(px4, events)
        assert of("disagreement", trs) == [], recorded_at
        (failsafe,) = of("failsafe", trs)
        assert failsafe.t == pytest.approx(min(recorded_at, 2.11))


@pytest.mark.parametrize("px4", TICK)
def test_12_recorded_failsafe_before_the_window_disagrees(px4: str) -> None:
    """PX4 cannot run the loss failsafe before COM_OF_LOSS_T has passed since the newest
    keep-alive: a recorded one 50 ms before the window is something else (the comparison uses
    the window, one Commander iteration of tolerance)."""
    events = [
        in_offboard(),
        *stream(0.0, 1.0),
        VehicleStatus(t=1.95, nav_state=POSCTL, armed=True, user_intention=OFFBOARD),
        VehicleStatus(t=3.0, nav_state=POSCTL, armed=True, user_intention=OFFBOARD),
    ]
    (differs,) = of("disagreement", run(px4, events))
    assert differs.t == pytest.approx(1.95)


@pytest.mark.parametrize("px4", TICK)
def test_12_recorded_offboard_after_predicted_loss_disagrees(px4: str) -> None:
    """12: the recording stays in OFFBOARD well after the model's failsafe: one disagreement
    naming both sides."""
    events = [in_offboard(), *stream(0.0, 1.0)]
    events += [in_offboard(t) for t in (2.5, 3.0, 3.5)]
    (differ,) = of("disagreement", run(px4, events))
    assert differ.t == pytest.approx(2.5)
    assert "recorded: OFFBOARD" in differ.message and "model: POSCTL" in differ.message


@pytest.mark.parametrize("px4", TICK)
def test_12_pilot_switch_without_command_is_adopted(px4: str) -> None:
    """12: a user-intention change with no command near it (an RC switch) is an input the
    recording shows: adopted, not a disagreement."""
    events = [in_offboard(), *stream(0.0, 5.0), status(3.0, POSCTL, True, POSCTL)]
    gate = model(px4)
    trs = run(px4, events, model=gate)
    assert of("disagreement", trs) == [] and gate.user_intention == POSCTL


def test_13_parameter_precedence() -> None:
    """13: defaults < recorded parameters < user overrides."""
    recorded = [Parameter(t=0.0, name="COM_OF_LOSS_T", value=2.0)]
    assert model("1.15").params["COM_OF_LOSS_T"] == 1.0
    gate = model("1.15")
    run("1.15", recorded, model=gate)
    assert gate.params["COM_OF_LOSS_T"] == 2.0 and gate.loss_timeout == 2.0
    gate = model("1.15", COM_OF_LOSS_T=0.5)
    run("1.15", recorded, model=gate)
    assert gate.params["COM_OF_LOSS_T"] == 0.5


@pytest.mark.parametrize(
    ("px4", "default"),
    [("legacy", 0.0), ("1.11", 0.5), ("1.13", 1.0), *[(p, 1.0) for p in TICK]],
)
def test_13_com_of_loss_t_defaults(px4: str, default: float) -> None:
    """13 / 2.1.2: COM_OF_LOSS_T defaults per profile."""
    assert model(px4).params["COM_OF_LOSS_T"] == default


@pytest.mark.parametrize("px4", ["1.14", "1.15"])
def test_2_1_estimate_loss_drops_the_signal(px4: str) -> None:
    """2.1: estimates come from failsafe_flags: losing local position with a position stream
    makes the signal lost at the next check pass, while the stream goes on: within one check
    period of the change, a window the timeline gives as such."""
    events = [in_offboard(), *stream(0.0, 3.0), flags(1.53, local_position_valid=False)]
    (lost,) = [t for t in of("signal_lost", run(px4, events))]
    assert (lost.t_earliest, lost.t) == (pytest.approx(1.53), pytest.approx(1.63))
    assert "position" in (lost.reason or "")


def test_15_unverified_points_are_marked() -> None:
    """15: behaviour the spec could not confirm is marked unverified."""
    legacy_arm = of(
        "arm_accepted", run("legacy", [status(0.0, OFFBOARD, False, OFFBOARD), arm(1.0)])
    )
    assert legacy_arm and legacy_arm[0].unverified
    vtol = of("controller", run("1.15", [in_offboard(), ocm(0.0)], vehicle="vtol"))
    assert vtol and vtol[-1].unverified
    fw_velocity = of(
        "controller", run("1.15", [in_offboard(), ocm(0.0, velocity=True)], vehicle="fw")
    )
    assert fw_velocity and fw_velocity[-1].unverified


@pytest.mark.parametrize("px4", TICK)
def test_12_heartbeat_may_lag_by_the_link(px4: str) -> None:
    """12: a HEARTBEAT recorded by a ground station shows the old mode for a while after PX4
    switched (1 Hz, link latency): not a disagreement."""
    hb = Where("HEARTBEAT")
    events = [
        VehicleStatus(t=0.0, nav_state=POSCTL, armed=True, where=hb),
        *stream(0.0, 3.0),
        switch_offboard(1.0),
        VehicleStatus(t=1.4, nav_state=POSCTL, armed=True, where=hb),
        VehicleStatus(t=2.4, nav_state=OFFBOARD, armed=True, where=hb),
    ]
    assert of("disagreement", run(px4, events)) == []


@pytest.mark.parametrize(("px4", "fallback"), [("legacy", True), ("1.13", True), ("1.15", False)])
def test_4_1_disarmed_in_offboard_without_signal(px4: str, fallback: bool) -> None:
    """4.1: 1.13 and legacy recompute nav_state to the loss fallback even when disarmed; 1.14+
    evaluate no failsafe while disarmed (nav_state stays OFFBOARD)."""
    gate = model(px4)
    events = [status(0.0, POSCTL, False, POSCTL), *stream(0.0, 1.0), switch_offboard(0.5)]
    trs = run(px4, events, t_end=3.0, model=gate)
    assert bool(of("failsafe", trs)) is fallback
    assert (gate.nav_state != OFFBOARD) is fallback


def test_12_a_recorded_disarm_against_the_models_own_arm_is_a_disagreement() -> None:
    """The model took an ARM that PX4 never got (issue 28 miss 3): no status showed the vehicle
    armed since, and later ones show it disarmed. Not 'no command for it': a disagreement."""
    events = [
        status(0.0, POSCTL, False),
        *stream(0.0, 4.0),
        switch_offboard(1.0),
        arm(1.001),
        CommandAck(t=1.01, command=176, result=0),
        status(1.02, OFFBOARD, False),
        status(3.0, OFFBOARD, False),
    ]
    out = run("1.16", events)
    (differs,) = of("disagreement", out)
    assert differs.t == 3.0 and "never armed since the arm request at 1.00 s" in differs.message
    assert not any("no command for it" in tr.message for tr in out)


def test_12_a_mode_change_after_a_command_the_model_does_not_judge_names_it() -> None:
    events = [
        in_offboard(0.0),
        *stream(0.0, 3.0),
        Command(t=2.0, command=21, params=(0.0,) * 7),
        CommandAck(t=2.01, command=21, result=0),
        status(2.02, 18, True),
    ]
    out = run("1.16", events)
    assert any("after NAV_LAND (21) at 2.00 s" in tr.message for tr in of("mode", out))
    assert not of("disagreement", out)
