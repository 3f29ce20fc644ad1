"""Gate spec section 14 ("Docs vs code"), rows D1-D23: the code-side behaviour on a minimal
event stream, for every profile the row concerns."""

from __future__ import annotations

import math
from dataclasses import replace

import pytest

from fuzzoff.events import (
    Command,
    SetAttitudeTarget,
    SetPositionTargetGlobal,
    SetPositionTargetLocal,
    TrajectorySetpoint,
)
from tests.gate.streams import (
    ALL,
    LOITER,
    OFFBOARD,
    OLD,
    POSCTL,
    RECEIVER_NEW,
    TICK,
    arm,
    flags,
    in_offboard,
    local_ned,
    loss_times,
    ocm,
    of,
    run,
    status,
    stream,
    switch_offboard,
)

NAN = math.nan
POS_ONLY = 0b110111111000
VEL_ONLY = 0b110111000111
ACC_ONLY = 0b110000111111


def _keepalive_count(px4: str, msgs: list, vehicle: str = "mc", **params: float) -> int:  # type: ignore[type-arg]
    """How many of ``msgs`` gave a keep-alive: feed them to a model armed in POSCTL and count
    how long the signal stayed available (one message each 0.3 s, timeout 0.2 s)."""
    events = [status(0.0, POSCTL, True, POSCTL)]
    events += [replace(m, t=1.0 + 0.3 * i) for i, m in enumerate(msgs)]
    params = {"COM_OF_LOSS_T": 0.2, **params}
    trs = run(px4, events, params=params, vehicle=vehicle, t_end=1.0 + 0.3 * len(msgs))
    return len(of("signal_available", trs))


def _accepted(px4: str, msg: object, vehicle: str = "mc", **params: float) -> bool:
    return _keepalive_count(px4, [msg], vehicle, **params) == 1


# D1 -------------------------------------------------------------------------------------------


@pytest.mark.parametrize("px4", ALL)
def test_d1_switch_50ms_after_one_setpoint_accepted_armed(px4: str) -> None:
    """D1 / 3: no one-second warm-up: armed, one keep-alive, switch 50 ms later: accepted."""
    events = [status(0.0, POSCTL, True, POSCTL), ocm(1.0), switch_offboard(1.05)]
    trs = run(px4, events)
    assert of("request_accepted", trs) and not of("request_rejected", trs)


@pytest.mark.parametrize("px4", TICK)
def test_d1_arm_48ms_after_one_setpoint_accepted(px4: str) -> None:
    """D1 / 13a: one setpoint, 48 ms later an arm request in OFFBOARD: armed."""
    events = [status(0.0, OFFBOARD, False, OFFBOARD), ocm(5.0), arm(5.048)]
    assert of("arm_accepted", run(px4, events))


# D2, D7 ----------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("px4", "lost"),
    [("legacy", True), ("1.11", True), ("1.13", False), *[(p, False) for p in TICK]],
)
def test_d2_gap_of_073s(px4: str, lost: bool) -> None:
    """D2 / 13a: a 0.73 s gap: only the 500 ms profiles (legacy, 1.11 default 0.5 s) lose it."""
    events = [in_offboard(), *stream(0.0, 1.0), ocm(1.73), ocm(1.8)]
    assert bool(loss_times(run(px4, events, t_end=1.8))) is lost


@pytest.mark.parametrize("px4", ["1.13", *TICK])
def test_d7_stream_below_2hz_kept_with_default_timeout(px4: str) -> None:
    """D7: 1.2 Hz (0.83 s gaps) stays alive with COM_OF_LOSS_T 1.0 s."""
    events = [in_offboard(), *[ocm(round(i / 1.2, 4)) for i in range(10)]]
    assert loss_times(run(px4, events, t_end=9 / 1.2)) == []


# D3 --------------------------------------------------------------------------------------------


def test_d3_legacy_timeout_after_500ms_detection() -> None:
    """D3 / 2.3: legacy: 500 ms detection, then COM_OF_LOSS_T extra before the action."""
    events = [in_offboard(), *stream(0.0, 1.0)]
    trs = run("legacy", events, params={"COM_OF_LOSS_T": 2.0, "COM_OBL_RC_ACT": 3.0}, t_end=5.0)
    assert [(round(t.t, 2), t.action) for t in of("failsafe", trs)] == [
        (1.5, "POSCTL"),
        (3.5, "AUTO_RTL"),
    ]


@pytest.mark.parametrize("px4", TICK)
def test_d3_com_of_loss_t_is_the_loss_timeout(px4: str) -> None:
    """D3: 1.14+: COM_OF_LOSS_T itself is the timeout (no 2 Hz detector before it)."""
    events = [in_offboard(), *stream(0.0, 1.0)]
    trs = run(px4, events, params={"COM_OF_LOSS_T": 2.0}, t_end=5.0)
    (lost,) = loss_times(trs)
    assert 3.0 <= lost <= 3.1 + 1e-9


# D4, D5, D6 ----------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("px4", "action"),
    [
        ("1.13", "AUTO_LAND"),
        ("1.14", "POSCTL"),
        ("1.15", "POSCTL"),
        ("1.16", "POSCTL"),
        ("1.17", "AUTO_RTL"),
        ("main", "AUTO_RTL"),
    ],
)
def test_d4_rc_availability(px4: str, action: str) -> None:
    """D4 / 5: no RC: 1.13 uses COM_OBL_ACT (Land), 1.14-1.16 ignore RC (Position), 1.17+
    replace the stick action by NAV_RCL_ACT (Return)."""
    events = [flags(0.0, manual_control_signal_lost=True), in_offboard(), *stream(0.0, 1.0)]
    trs = run(px4, events, t_end=3.0)
    assert [t.action for t in of("failsafe", trs)] == [action]


@pytest.mark.parametrize(
    ("px4", "action"),
    [("legacy", "MANUAL"), ("1.13", "MANUAL"), *[(p, "STAB") for p in TICK]],
)
def test_d5_value_2(px4: str, action: str) -> None:
    """D5: COM_OBL_RC_ACT 2 is MANUAL up to 1.13 and Stabilized from 1.14."""
    events = [in_offboard(), *stream(0.0, 1.0)]
    trs = run(px4, events, params={"COM_OBL_RC_ACT": 2.0}, t_end=3.0)
    assert of("failsafe", trs)[-1].action == action


@pytest.mark.parametrize("px4", ALL)
def test_d6_fallback_is_not_the_previous_mode(px4: str) -> None:
    """D6: after Hold -> OFFBOARD, the loss action is the configured one (Position), not Hold."""
    events = [status(0.0, LOITER, True, LOITER), *stream(0.5, 1.0), switch_offboard(0.6)]
    trs = run(px4, events, t_end=3.0)
    assert of("failsafe", trs)[-1].nav_state == POSCTL


# D8 --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("px4", TICK)
def test_d8_disarmed_switch_without_stream_accepted_then_arm_rejected(px4: str) -> None:
    """D8 / 4.1 / 4.2: disarmed, no stream: switch accepted (nav OFFBOARD); arming rejected."""
    events = [status(0.0, POSCTL, False, POSCTL), switch_offboard(1.0), arm(2.0)]
    trs = run(px4, events)
    assert of("request_accepted", trs)[0].nav_state == OFFBOARD
    (rejected,) = of("arm_rejected", trs)
    assert "offboard signal" in (rejected.reason or "")


@pytest.mark.parametrize("px4", OLD)
def test_d8_old_profiles_reject_disarmed_switch_without_stream(px4: str) -> None:
    """D8 / 4.1: legacy and 1.13 reject the switch without a stream even when disarmed."""
    events = [status(0.0, POSCTL, False, POSCTL), switch_offboard(1.0)]
    assert of("request_rejected", run(px4, events))


@pytest.mark.parametrize("px4", ["1.11", "1.13"])
def test_d8_arming_not_offboard_gated_before_114(px4: str) -> None:
    """D8 / 4.2: 1.13: arming has no offboard condition: it arms into the loss fallback."""
    events = [
        status(0.0, POSCTL, False, POSCTL),
        *stream(0.0, 1.0),
        switch_offboard(0.5),
        arm(3.0),
    ]
    trs = run(px4, events, t_end=3.5)
    assert of("arm_accepted", trs) and not of("arm_rejected", trs)


# D9 --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("px4", ALL)
def test_d9_automatic_return_to_offboard(px4: str) -> None:
    """D9 / 5: the user intention stays OFFBOARD; the vehicle returns when the stream resumes."""
    events = [in_offboard(), *stream(0.0, 1.0), *stream(4.0, 4.5)]
    trs = run(px4, events, t_end=4.5)
    (back,) = of("offboard_resumed", trs)
    assert back.t == pytest.approx(4.0) and back.nav_state == OFFBOARD


# D10, D11 --------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("px4", "available"),
    [("1.14", False), ("1.15", False), ("1.16", True), ("1.17", True), ("main", True)],
)
def test_d10_acceleration_needs_velocity_until_115(px4: str, available: bool) -> None:
    """D10 / 2.1: acceleration needs local velocity on 1.14/1.15, attitude from 1.16."""
    events = [flags(0.0, local_velocity_valid=False), ocm(1.0, acceleration=True)]
    assert bool(of("signal_available", run(px4, events))) is available


@pytest.mark.parametrize(
    ("px4", "available"),
    [("1.14", True), ("1.15", True), ("1.16", True), ("1.17", True), ("main", False)],
)
def test_d10_attitude_flag_needs_attitude_only_on_main(px4: str, available: bool) -> None:
    """D10 / 2.1: the attitude flag needs an attitude estimate only on main."""
    events = [flags(0.0, attitude_valid=False), ocm(1.0, attitude=True)]
    assert bool(of("signal_available", run(px4, events))) is available


@pytest.mark.parametrize("px4", ["1.13", *TICK])
def test_d10_every_set_flag_is_checked(px4: str) -> None:
    """D10: position + velocity with only the velocity estimate missing: not available."""
    events = [flags(0.0, local_velocity_valid=False), ocm(1.0, position=True, velocity=True)]
    assert of("signal_available", run(px4, events)) == []


@pytest.mark.parametrize("px4", TICK)
def test_d11_body_rate_needs_no_angular_velocity_in_offboard_checks(px4: str) -> None:
    """D11: OffboardChecks has no angular-velocity condition for body_rate."""
    events = [flags(0.0, angular_velocity_valid=False), ocm(1.0, body_rate=True)]
    assert of("signal_available", run(px4, events))


@pytest.mark.parametrize("px4", TICK)
def test_d11_offboard_mode_needs_angular_velocity_whatever_the_flags(px4: str) -> None:
    """D11 / 4.1: the OFFBOARD mode requirement asks for attitude and angular velocity even for
    a direct_actuator stream: the armed switch is rejected without them."""
    events = [
        status(0.0, POSCTL, True, POSCTL),
        flags(0.0, angular_velocity_valid=False),
        ocm(1.0, direct_actuator=True),
        switch_offboard(1.05),
    ]
    assert of("request_rejected", run(px4, events))


# D12 -------------------------------------------------------------------------------------------


def _controller_text(px4: str, vehicle: str = "mc", **ocm_flags: bool) -> str:
    layout = "actuator" if "actuator" in ocm_flags else "thrust_and_torque"
    events = [in_offboard(), ocm(0.0, layout=layout, **ocm_flags)]
    controllers = of("controller", run(px4, events, vehicle=vehicle, t_end=0.5))
    return controllers[-1].message


@pytest.mark.parametrize("px4", ["1.13", "1.14"])
def test_d12_actuator_flag_enables_no_controller(px4: str) -> None:
    """D12 / 7: 1.13/1.14 have one actuator flag, which enables no controller."""
    assert "no controller" in _controller_text(px4, actuator=True)


@pytest.mark.parametrize("px4", ["1.15", "1.16", "1.17", "main"])
def test_d12_thrust_and_torque_enables_allocation_only(px4: str) -> None:
    """D12 / 7: thrust_and_torque (1.15+) enables the allocation only; direct_actuator nothing."""
    assert _controller_text(px4, thrust_and_torque=True).endswith(": allocation")
    assert "no controller" in _controller_text(px4, direct_actuator=True)


# D13, D22 --------------------------------------------------------------------------------------


def _traj(t: float, pos: tuple = (NAN,) * 3, vel: tuple = (NAN,) * 3) -> TrajectorySetpoint:  # type: ignore[type-arg]
    return TrajectorySetpoint(t=t, position=pos, velocity=vel)


@pytest.mark.parametrize("px4", ["1.13", *TICK])
def test_d13_per_axis_mixed_setpoint_is_valid(px4: str) -> None:
    """D13 / 8: z position with x/y velocity is legal: decided per axis."""
    events = [in_offboard(), ocm(0.0), _traj(0.01, pos=(NAN, NAN, -2.0), vel=(1.0, 0.0, NAN))]
    text = of("controller", run(px4, events))[-1].message
    assert "x,y velocity" in text and "z position" in text


@pytest.mark.parametrize(
    ("px4", "reuse"),
    [
        ("1.13", False),
        ("1.14", False),
        ("1.15", False),
        ("1.16", True),
        ("1.17", True),
        ("main", True),
    ],
)
def test_d13_invalid_setpoint_fallback(px4: str, reuse: bool) -> None:
    """D13 / 8: x finite but y NaN is invalid: 1.16+ reuse the last valid setpoint for 200 ms,
    then the failsafe setpoint; 1.13-1.15 the failsafe setpoint at once."""
    good = _traj(0.01, pos=(0.0, 0.0, -2.0))
    bad = _traj(0.1, pos=(1.0, NAN, -2.0))
    events = [in_offboard(), *stream(0.0, 0.5), good, bad]
    texts = [(round(t.t, 3), t.message) for t in of("controller", run(px4, events, t_end=0.5))]
    failsafe = [t for t, m in texts if "failsafe setpoint" in m]
    if reuse:
        assert any("last valid" in m for _, m in texts)
        assert failsafe and failsafe[-1] == pytest.approx(0.21)
    else:
        assert failsafe and failsafe[-1] == pytest.approx(0.1)


@pytest.mark.parametrize("px4", ["1.13", *TICK])
def test_d22_no_trajectory_since_position_control_enabled_holds(px4: str) -> None:
    """D22 / 8: position control enabled, no TrajectorySetpoint since: failsafe hold."""
    events = [status(0.0, POSCTL, True, POSCTL), *stream(0.0, 1.0), switch_offboard(0.5)]
    texts = [t.message for t in of("controller", run(px4, events))]
    assert any("no TrajectorySetpoint since" in m for m in texts)


# D14 -------------------------------------------------------------------------------------------


@pytest.mark.parametrize("px4", RECEIVER_NEW)
@pytest.mark.parametrize("mask", [4096, 8192, 12288, 16384, 292])
def test_d14_fixed_wing_type_bits_not_interpreted(px4: str, mask: int) -> None:
    """D14 / 6.1: bits 12-14 and '292' are not read from v1.12: only the ignore bits count."""
    msg = local_ned(0.0, mask=mask, position=(0.0, 0.0, -10.0), velocity=(15.0, 0.0, 0.0))
    assert _accepted(px4, msg, vehicle="fw")


@pytest.mark.parametrize("mask", [4096, 8192])
def test_d14_legacy_takeoff_and_land_classified_as_loiter(mask: int) -> None:
    """D14 / 6.5: legacy tests 0x3000 first: takeoff and land become LOITER."""
    msg = local_ned(1.0, mask=mask | POS_ONLY & 0x1FF)
    trs = run("legacy", [status(0.0, POSCTL, True, POSCTL), msg], vehicle="fw")
    assert any("LOITER" in (t.reason or "") for t in of("setpoint_dropped", trs))
    assert of("signal_available", trs)  # still a keep-alive


# D15, D18 --------------------------------------------------------------------------------------


def _global(frame: int, mask: int = POS_ONLY, **kw: object) -> SetPositionTargetGlobal:
    return SetPositionTargetGlobal(
        t=0.0,
        coordinate_frame=frame,
        type_mask=mask,
        target_system=1,
        target_component=1,
        lat_int=473977420,
        lon_int=85455940,
        alt=10.0,
        **kw,  # type: ignore[arg-type]
    )


@pytest.mark.parametrize("px4", RECEIVER_NEW)
@pytest.mark.parametrize(
    ("frame", "accepted"), [(0, False), (3, False), (5, True), (6, True), (11, True)]
)
def test_d15_global_int_frames(px4: str, frame: int, accepted: bool) -> None:
    """D15 / 6.3: MAV_FRAME_GLOBAL (0) and 3 are rejected; only 5, 6, 11 are accepted."""
    assert _accepted(px4, _global(frame), vehicle="rover-differential") is accepted


@pytest.mark.parametrize("px4", RECEIVER_NEW)
def test_d18_global_int_acceleration_is_acceleration(px4: str) -> None:
    """D18 / 6.3: afx/afy/afz pass through as acceleration (OCM acceleration), no thrust."""
    events = [
        status(0.0, POSCTL, True, POSCTL),
        _global(5, mask=ACC_ONLY, acceleration=(1.0, 0.0, 0.0)),
    ]
    events[1] = replace(events[1], t=1.0)
    (available,) = of("signal_available", run(px4, events))
    assert "acceleration" in available.message


# D16 -------------------------------------------------------------------------------------------


@pytest.mark.parametrize("px4", RECEIVER_NEW)
@pytest.mark.parametrize("vehicle", ["mc", "fw", "rover-ackermann"])
def test_d16_mav_fwdextsp_gates_the_keepalive_for_every_vehicle(px4: str, vehicle: str) -> None:
    """D16 / 6.1: MAV_FWDEXTSP = 0 drops every setpoint message, keep-alive included."""
    assert not _accepted(px4, local_ned(0.0, position=(0.0, 0.0, -1.0)), vehicle, MAV_FWDEXTSP=0.0)


@pytest.mark.parametrize("px4", ["legacy", "1.11"])
def test_d16_legacy_keepalive_not_gated(px4: str) -> None:
    """D16 / 6.5: in legacy MAV_FWDEXTSP gates forwarding only, not the keep-alive."""
    assert _accepted(px4, local_ned(0.0, position=(0.0, 0.0, -1.0)), MAV_FWDEXTSP=0.0)


# D17 -------------------------------------------------------------------------------------------


@pytest.mark.parametrize("px4", RECEIVER_NEW)
def test_d17_body_ned_position_only_is_dropped(px4: str) -> None:
    """D17 / 6.2: BODY_NED position is always ignored: a position-only message is 'invalid'."""
    msg = local_ned(0.0, frame=8, position=(1.0, 0.0, 0.0))
    assert not _accepted(px4, msg)


@pytest.mark.parametrize("px4", RECEIVER_NEW)
@pytest.mark.parametrize("frame", [7, 9, 20, 21])
def test_d17_unsupported_frames_give_no_keepalive(px4: str, frame: int) -> None:
    """D17 / 6.2: frames other than LOCAL_NED and BODY_NED are dropped, no keep-alive."""
    assert not _accepted(px4, local_ned(0.0, frame=frame, position=(1.0, 0.0, -1.0)))


@pytest.mark.parametrize("px4", RECEIVER_NEW)
def test_d17_body_ned_velocity_with_one_ignore_bit_drops_the_vector(px4: str) -> None:
    """D17 / 6.2: BODY_NED: any VX/VY/VZ ignore bit drops the whole velocity."""
    msg = local_ned(0.0, frame=8, mask=0b110111100111, velocity=(1.0, 0.0, 0.0))
    assert not _accepted(px4, msg)
    assert _accepted(px4, local_ned(0.0, frame=8, mask=VEL_ONLY, velocity=(1.0, 0.0, 0.0)))


@pytest.mark.parametrize("px4", RECEIVER_NEW)
def test_d17_any_component_mix_passes_the_receiver(px4: str) -> None:
    """D17 / 6.2: any per-component mix is passed through (restrictions come from 8)."""
    mask = 0b110111011110  # x position and y velocity only
    assert _accepted(px4, local_ned(0.0, mask=mask, position=(1.0, 0.0, 0.0)))


# D19, D20 --------------------------------------------------------------------------------------


def _att(mask: int) -> SetAttitudeTarget:
    return SetAttitudeTarget(t=0.0, type_mask=mask, target_system=1, target_component=1)


@pytest.mark.parametrize(
    ("px4", "accepted"),
    [
        ("1.13", True),
        ("1.14", True),
        ("1.15", True),
        ("1.16", True),
        ("1.17", True),
        ("main", False),
    ],
)
def test_d19_attitude_without_thrust(px4: str, accepted: bool) -> None:
    """D19 / 6.4: attitude with the throttle ignored (bit 64, no 32): accepted up to 1.17,
    ignored entirely on main (thrust required)."""
    assert _accepted(px4, _att(64 | 7)) is accepted


@pytest.mark.parametrize("px4", RECEIVER_NEW)
@pytest.mark.parametrize("vehicle", ["rover-ackermann", "rover-differential", "rover-mecanum"])
def test_d20_rover_attitude_target_is_a_keepalive(px4: str, vehicle: str) -> None:
    """D20 / 6.4: the receiver handles SET_ATTITUDE_TARGET for rovers like any vehicle."""
    assert _accepted(px4, _att(7), vehicle)


# D21 -------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("vehicle", "flag", "expected"),
    [
        ("rover-ackermann", "attitude", "nothing"),
        ("rover-ackermann", "body_rate", "nothing"),
        ("rover-differential", "body_rate", "RoverRateSetpoint"),
        ("rover-differential", "attitude", "RoverAttitudeSetpoint"),
        ("rover-mecanum", "attitude", "RoverAttitudeSetpoint"),
        ("rover-mecanum", "position", "+ yaw/yawspeed"),
    ],
)
def test_d21_rover_per_flag_on_main(vehicle: str, flag: str, expected: str) -> None:
    """D21 / 10: Ackermann ignores attitude/body_rate; Differential maps body_rate to
    yawspeed; Mecanum applies attitude in addition to position/velocity."""
    assert expected in _controller_text("main", vehicle, **{flag: True})


@pytest.mark.parametrize("px4", ["1.13", "1.14", "1.15", "1.16", "1.17"])
def test_d21_rover_before_main_is_unverified(px4: str) -> None:
    """15: rover per-flag behaviour before main is not tabulated: marked unverified."""
    events = [in_offboard(), ocm(0.0)]
    controllers = of("controller", run(px4, events, vehicle="rover-differential"))
    assert controllers and controllers[-1].unverified


# D23 -------------------------------------------------------------------------------------------


@pytest.mark.parametrize("px4", RECEIVER_NEW)
def test_d23_force_bit_with_acceleration_is_dropped(px4: str) -> None:
    """D23 / 6.2: acceleration with FORCE_SET (512) is rejected: no keep-alive."""
    msg = local_ned(0.0, mask=ACC_ONLY | 512, acceleration=(1.0, 0.0, 0.0))
    assert not _accepted(px4, msg)


@pytest.mark.parametrize("px4", ALL)
def test_d23_wrong_target_is_not_a_keepalive(px4: str) -> None:
    """D23 / 6.1: a message for another system is dropped: the armed switch is rejected."""
    msg = SetPositionTargetLocal(
        t=1.0, type_mask=POS_ONLY, target_system=7, target_component=1, position=(0.0, 0.0, -1.0)
    )
    events = [status(0.0, POSCTL, True, POSCTL), msg, switch_offboard(1.05)]
    assert of("request_rejected", run(px4, events))


@pytest.mark.parametrize("px4", RECEIVER_NEW)
def test_d23_yaw_only_is_dropped(px4: str) -> None:
    """D23 / 6.2: no position, velocity or acceleration (yaw only): dropped, no keep-alive."""
    assert not _accepted(px4, local_ned(0.0, mask=0b100111111111, yaw=1.0))


@pytest.mark.parametrize("px4", ["legacy", "1.11"])
def test_d23_legacy_non_finite_ignored_field_drops_the_message(px4: str) -> None:
    """D23 / 6.5: legacy drops a message with any non-finite field, even an ignored one."""
    msg = local_ned(0.0, mask=POS_ONLY, position=(0.0, 0.0, -1.0), velocity=(NAN, 0.0, 0.0))
    assert not _accepted(px4, msg)
    assert _accepted(px4, local_ned(0.0, mask=POS_ONLY, position=(0.0, 0.0, -1.0)))


@pytest.mark.parametrize("px4", RECEIVER_NEW)
def test_d23_non_finite_ignored_field_is_fine_from_v112(px4: str) -> None:
    """6.2: from v1.12 an ignored field is NaN anyway: its content does not matter."""
    msg = local_ned(0.0, mask=POS_ONLY, position=(0.0, 0.0, -1.0), velocity=(NAN, 0.0, 0.0))
    assert _accepted(px4, msg)


def test_mavlink_command_type_is_the_one_from_events() -> None:
    """Sanity: the streams use the real Command event (DO_SET_MODE main mode 6)."""
    assert Command(t=0.0, command=176, params=(1.0, 6.0, 0, 0, 0, 0, 0)).is_offboard_switch


@pytest.mark.parametrize("px4", RECEIVER_NEW)
def test_d19_quaternion_and_thrust_not_validated(px4: str) -> None:
    """D19 / 6.4: the receiver neither normalises the quaternion nor checks the thrust."""
    msg = SetAttitudeTarget(
        t=0.0, type_mask=7, q=(2.0, 0.0, 0.0, 0.0), thrust=3.0, target_system=1, target_component=1
    )
    assert _accepted(px4, msg)
