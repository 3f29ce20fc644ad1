"""OFB106, OFB107, OFB203, OFB3xx, OFB4xx, OFB8xx on minimal streams: edges and near misses."""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fuzzoff.config import Settings
from fuzzoff.events import (
    ActuatorMotors,
    AttitudeSetpoint,
    Command,
    ControlMode,
    Event,
    FailsafeFlags,
    LegacyControlMode,
    Origin,
    Parameter,
    PositionSetpointTriplet,
    RatesSetpoint,
    RoverAttitudeSetpoint,
    RoverRateSetpoint,
    RoverSpeedSetpoint,
    SetAttitudeTarget,
    SetPositionTargetLocal,
    TrajectorySetpoint,
    VehiclePosition,
)
from fuzzoff.findings import Finding, Severity
from tests.streams import OFFBOARD, POSCTL, ack, codes, every, ocm, status, switch
from tests.streams import lint_events as _lint_events

NAN = math.nan
MINE = frozenset(
    {"OFB002", "OFB106", "OFB107", "OFB203", "OFB404", "OFB405", "OFB406", "OFB407", "OFB408"}
    | {"OFB301", "OFB302", "OFB303", "OFB304", "OFB305", "OFB401", "OFB402", "OFB403"}
    | {"OFB801", "OFB802", "OFB803"}
)


def lint_events(
    events: Sequence[Event], settings: Settings | None = None, **kw: Any
) -> list[Finding]:
    """These rules alone (plus OFB002), so that a test shows only what they do."""
    chosen = settings or Settings()
    chosen = Settings(select=MINE - chosen.ignore)
    return _lint_events(events, settings=chosen, **kw)


def ocm_stamped(times: list[float], stamps_us: list[int], origin: Origin = "sent") -> list[Event]:
    return [
        ControlMode(t=t, position=True, sender_time_us=s, origin=origin)
        for t, s in zip(times, stamps_us, strict=True)
    ]


# --- OFB106 -------------------------------------------------------------------------------


@pytest.mark.parametrize(("lag", "flagged"), [(1.0, False), (1.1, True)])
def test_ofb106_lag_edge_is_the_loss_timeout(lag: float, flagged: bool) -> None:
    # The sender clock stops at t=0.5; by t=0.5+lag its stamp lags by ``lag``.
    times = [0.0, 0.5, 0.5 + lag]
    events = ocm_stamped(times, [10_000_000, 10_500_000, 10_500_000])
    found = codes(lint_events(events), "OFB106")
    assert bool(found) is flagged
    if flagged:
        assert found[0].severity is Severity.WARNING
        assert found[0].time_s == pytest.approx(0.5 + lag)


@pytest.mark.parametrize(("loss_t_at", "severity"), [(0.0, Severity.INFO), (2.0, Severity.WARNING)])
def test_ofb106_judges_by_the_recordings_com_of_loss_t(
    loss_t_at: float, severity: Severity
) -> None:
    """The recording's COM_OF_LOSS_T (3 s) sets the line from when it is seen: a 1.5 s lag
    after it is within the timeout; one before it was judged by the default (1 s)."""
    times = [0.0, 0.5, 1.0, 1.5, 2.0]
    stamps = [10_000_000, 10_000_000, 10_000_000, 10_000_000, 10_500_000]
    events: list[Event] = [
        *ocm_stamped(times, stamps),
        Parameter(t=loss_t_at, name="COM_OF_LOSS_T", value=3.0),
    ]
    events.sort(key=lambda e: (e.t, not isinstance(e, Parameter)))
    # lag_s 0.4: every lagging message is noted, the severity then says how PX4 takes it
    chosen = Settings(select=MINE, options={"OFB106": {"lag_s": 0.4}})
    (found,) = codes(_lint_events(events, settings=chosen), "OFB106")
    assert found.severity is severity
    if severity is Severity.WARNING:
        assert "COM_OF_LOSS_T (1.00 s)" in found.message


def test_ofb106_lag_is_info_on_1_13_which_ignores_the_field() -> None:
    events = ocm_stamped([0.0, 1.0, 2.0], [10_000_000] * 3)
    (found,) = codes(lint_events(events, px4="1.13"), "OFB106")
    assert found.severity is Severity.INFO
    assert "does not use" in found.message


def test_ofb106_zero_is_info_because_px4_uses_the_receive_time() -> None:
    events = ocm_stamped([0.0, 0.1, 0.2], [0, 0, 0])
    (found,) = codes(lint_events(events), "OFB106")
    assert found.severity is Severity.INFO
    assert "receive time" in found.message and "3 messages" in found.message


def test_ofb106_small_backwards_step_is_info() -> None:
    events = ocm_stamped([0.0, 0.1, 0.2], [10_000_000, 10_100_000, 10_050_000])
    (found,) = codes(lint_events(events), "OFB106")
    assert found.severity is Severity.INFO and "backwards" in found.message


def test_ofb106_ulog_copies_are_not_checkable() -> None:
    events = ocm_stamped([0.0, 1.0, 2.0], [0, 0, 0], origin="vehicle")
    findings = lint_events(events, fmt="ulog")
    assert codes(findings, "OFB106") == []
    assert any("OFB106" in f.message for f in codes(findings, "OFB002"))


# --- OFB107 -------------------------------------------------------------------------------


def _repeat(t0: float, t1: float, hz: float, **fields: Any) -> list[Event]:
    return [TrajectorySetpoint(t=round(t, 6), **fields) for t in every(t0, t1, 1 / hz)]


@pytest.mark.parametrize(("duration", "flagged"), [(10.0, False), (10.05, True)])
def test_ofb107_freeze_edge(duration: float, flagged: bool) -> None:
    events = [
        status(0.0, OFFBOARD),
        *ocm(every(0.0, 11.0, 0.05), velocity=True),
        *_repeat(0.0, duration, 20.0, velocity=(1.0, 0.0, 0.0)),
        TrajectorySetpoint(t=duration + 0.05, velocity=(0.5, 0.0, 0.0)),
    ]
    found = codes(lint_events(events), "OFB107")
    assert bool(found) is flagged
    if flagged:
        assert found[0].time_s == pytest.approx(0.0)
        assert found[0].end_s == pytest.approx(duration)
        assert found[0].severity is Severity.ERROR
        assert "velocity 1.00 m/s" in found[0].message


def test_ofb107_a_velocity_of_2mps_frozen_for_20s_is_an_error() -> None:
    events = [
        status(0.0, OFFBOARD),
        *ocm(every(0.0, 20.0, 0.05), velocity=True),
        *_repeat(0.0, 20.0, 20.0, velocity=(2.0, 0.0, NAN)),
    ]
    (found,) = codes(lint_events(events), "OFB107")
    assert found.severity is Severity.ERROR
    assert "velocity 2.00 m/s" in found.message and "20.00 s" in found.message


@pytest.mark.parametrize(
    "fields",
    [
        {"position": (20.0, 0.0, -5.0)},  # a held position (px4_ros_com, MAVROS offb_node)
        {"position": (20.0, 0.0, -5.0), "velocity": (1.0, 0.0, 0.0)},  # position wins per axis
        {"velocity": (0.0, 0.0, 0.0)},  # a zero velocity (MAVSDK's "stay")
        {"velocity": (0.0, 0.0, 0.0), "yaw": 1.5},
        {"acceleration": (0.0, 0.0, 0.0)},
    ],
)
def test_ofb107_a_hold_is_never_flagged(fields: dict[str, Any]) -> None:
    """A ten-minute hold at 10 Hz: what a stopped controller should leave behind."""
    events = [status(0.0, OFFBOARD), *ocm(every(0.0, 600.0, 0.1))]
    events += _repeat(0.0, 600.0, 10.0, **fields)
    assert codes(lint_events(events), "OFB107") == []


def test_ofb107_a_turn_on_the_spot_is_bounded_and_judged_after_turning_s() -> None:
    def spin(seconds: float, **fields: Any) -> list[Event]:
        events = [status(0.0, OFFBOARD), *ocm(every(0.0, seconds, 0.1))]
        return events + _repeat(0.0, seconds, 10.0, yawspeed=0.5, **fields)

    assert codes(lint_events(spin(20.0, position=(0, 0, -5.0))), "OFB107") == []
    (found,) = codes(lint_events(spin(61.0, velocity=(0.0, 0.0, 0.0))), "OFB107")
    assert "yaw rate" in found.message and "bounded" in found.message
    # a yaw angle given with the rate: PX4 turns to it and stops
    assert codes(lint_events(spin(61.0, position=(0, 0, -5.0), yaw=1.0)), "OFB107") == []


def _mavsdk_body(seconds: float, forward: float, yaw_rate: float) -> list[Event]:
    """MAVSDK's set_velocity_body re-sent at 20 Hz: BODY_NED, position and acceleration and
    yaw ignored (offboard_impl.cpp send_velocity_body)."""
    mask = 1 | 2 | 4 | 64 | 128 | 256 | 1024
    events: list[Event] = [status(0.0, OFFBOARD)]
    events += [
        SetPositionTargetLocal(
            t=round(t, 6),
            coordinate_frame=8,
            type_mask=mask,
            velocity=(forward, 0.0, 0.0),
            yaw_rate=yaw_rate,
        )
        for t in every(0.0, seconds, 0.05)
    ]
    return events


def test_ofb107_mavsdk_example_circle_is_bounded_and_stays_clean() -> None:
    # "Fly a circle": 5 m/s forward with 30 deg/s of yaw for 15 s, identical at 20 Hz
    assert codes(lint_events(_mavsdk_body(15.0, 5.0, math.radians(30)), fmt="tlog"), "OFB107") == []
    (found,) = codes(lint_events(_mavsdk_body(61.0, 5.0, math.radians(30)), fmt="tlog"), "OFB107")
    assert "bounded" in found.message
    # the same forward velocity without the yaw rate is a straight line
    (straight,) = codes(lint_events(_mavsdk_body(10.5, 5.0, 0.0), fmt="tlog"), "OFB107")
    assert "body velocity 5.00 m/s" in straight.message


def test_ofb107_judges_mavlink_setpoints_too() -> None:
    position = [status(0.0, OFFBOARD)]
    position += [
        SetPositionTargetLocal(t=round(t, 6), type_mask=0b110111111000, position=(0, 0, -3))
        for t in every(0.0, 12.0, 0.05)
    ]
    assert codes(lint_events(position, fmt="tlog"), "OFB107") == []  # a held position
    velocity = [status(0.0, OFFBOARD)]
    velocity += [
        SetPositionTargetLocal(t=round(t, 6), type_mask=0b110111000111, velocity=(0, 0, -2.0))
        for t in every(0.0, 12.0, 0.05)
    ]
    (found,) = codes(lint_events(velocity, fmt="tlog"), "OFB107")
    assert "velocity 2.00 m/s" in found.message


@pytest.mark.parametrize(
    ("q", "thrust", "flagged"),
    [
        ((1.0, 0.0, 0.0, 0.0), 0.6, False),  # level at a hover thrust
        ((1.0, 0.0, 0.0, 0.0), 0.9, True),  # level, climbing
        ((0.966, 0.259, 0.0, 0.0), 0.6, True),  # 30 degrees of roll (MAVSDK's example, 2 s)
    ],
)
def test_ofb107_attitude_tilt_and_thrust(
    q: tuple[float, float, float, float], thrust: float, flagged: bool
) -> None:
    events: list[Event] = [status(0.0, OFFBOARD)]
    events += [
        SetAttitudeTarget(t=round(t, 6), type_mask=7, q=q, thrust=thrust)
        for t in every(0.0, 12.0, 0.05)
    ]
    assert bool(codes(lint_events(events, fmt="tlog"), "OFB107")) is flagged


def test_ofb107_rover_speed_is_a_motion_and_a_placeholder_is_not() -> None:
    events: list[Event] = [status(0.0, OFFBOARD), *ocm(every(0.0, 12.0, 0.1), velocity=True)]
    events += [RoverSpeedSetpoint(t=round(t, 6), speed_body_x=1.5) for t in every(0, 12, 0.1)]
    events += [RoverAttitudeSetpoint(t=round(t, 6), yaw_setpoint=0.3) for t in every(0, 12, 0.1)]
    found = codes(lint_events(events, px4="1.16", vehicle="rover-differential"), "OFB107")
    assert [f.where.topic if f.where else "" for f in found] == ["rover_speed"] or len(found) == 1
    assert "rover speed 1.50 m/s" in found[0].message


def test_ofb107_realistic_near_miss_with_estimator_noise_stays_clean() -> None:
    # A live velocity controller: its output jitters by micrometres per second at 20 Hz.
    events: list[Event] = [status(0.0, OFFBOARD), *ocm(every(0.0, 30.0, 0.1), velocity=True)]
    for i, t in enumerate(every(0.0, 30.0, 0.05)):
        jitter = 1e-6 * ((i * 7919) % 13 - 6)
        events.append(TrajectorySetpoint(t=round(t, 6), velocity=(1.0 + jitter, 2.0, 0.0)))
    assert codes(lint_events(events), "OFB107") == []


def test_ofb107_gap_restarts_and_outside_offboard_does_not_count() -> None:
    gap = [
        status(0.0, OFFBOARD),
        *_repeat(0.0, 8.0, 20.0, velocity=(1.0, 0.0, 0.0)),
        *_repeat(9.5, 17.5, 20.0, velocity=(1.0, 0.0, 0.0)),
    ]
    assert codes(lint_events(gap), "OFB107") == []
    outside = [status(0.0, POSCTL), *_repeat(0.0, 15.0, 20.0, velocity=(1.0, 0.0, 0.0))]
    assert codes(lint_events(outside), "OFB107") == []


# --- OFB203 -------------------------------------------------------------------------------


def test_ofb203_one_finding_per_stretch_with_count() -> None:
    events = [
        status(0.0, POSCTL),
        *_repeat(0.0, 0.9, 10.0, position=(0.0, 0.0, -2.0)),
        status(1.0, OFFBOARD),
        *_repeat(1.0, 2.0, 10.0, position=(0.0, 0.0, -2.0)),
    ]
    (found,) = codes(lint_events(events), "OFB203")
    assert found.time_s == 0.0 and "10 messages" in found.message
    assert "POSCTL" in found.message or "Position" in found.message


def test_ofb203_armed_in_another_mode_with_no_request_is_an_error() -> None:
    events = [status(0.0, POSCTL), *ocm(every(0.0, 5.0, 0.1))]
    events += _repeat(0.0, 5.0, 10.0, position=(0.0, 0.0, -2.0))
    (found,) = codes(lint_events(events), "OFB203")
    assert found.severity is Severity.ERROR and "no offboard request followed" in found.message


def test_ofb203_px4_ros_com_publishes_from_its_first_cycle_while_disarmed() -> None:
    """px4_ros_com offboard_control: OffboardControlMode and TrajectorySetpoint every 100 ms
    from the first cycle, the switch and the arm at the 11th (rules.md: info)."""
    events = [status(0.0, POSCTL, armed=False), *ocm(every(0.0, 3.0, 0.1))]
    events += _repeat(0.0, 3.0, 10.0, position=(0.0, 0.0, -5.0))
    events += [switch(1.0), ack(1.005, 0), status(1.02, OFFBOARD, armed=True)]
    (found,) = codes(lint_events(events), "OFB203")
    assert found.severity is Severity.INFO and "disarmed" in found.message
    assert found.time_s == 0.0 and found.end_s == pytest.approx(1.0)


def test_ofb203_the_run_up_of_a_request_while_armed_is_info_and_a_broken_one_an_error() -> None:
    run_up = [status(0.0, POSCTL), *ocm(every(0.0, 4.0, 0.1))]
    run_up += _repeat(0.0, 4.0, 10.0, position=(0.0, 0.0, -5.0))
    run_up += [switch(2.0), ack(2.005, 0), status(2.01, OFFBOARD)]
    (found,) = codes(lint_events(run_up), "OFB203")
    assert found.severity is Severity.INFO and "ran up to the offboard request" in found.message
    # the keep-alive stops for 2 s after the setpoints: the request that follows is not theirs
    broken = [status(0.0, POSCTL), *ocm(every(0.0, 1.0, 0.1)), *ocm(every(3.0, 4.0, 0.1))]
    broken += _repeat(0.0, 1.0, 10.0, position=(0.0, 0.0, -5.0))
    broken += [switch(3.5), ack(3.505, 0), status(3.51, OFFBOARD)]
    (found,) = codes(lint_events(broken), "OFB203")
    assert found.severity is Severity.ERROR and found.end_s == pytest.approx(1.0)


def test_ofb203_the_stream_resuming_after_a_loss_until_px4_returns_is_info() -> None:
    times = [t for t in every(0.0, 8.0, 0.05) if not 3.0 < t < 5.0]
    events = [status(0.0, OFFBOARD), *ocm(times)]
    events += [TrajectorySetpoint(t=t + 0.001, position=(0.0, 0.0, -5.0)) for t in times]
    events += [status(4.05, POSCTL), status(5.02, OFFBOARD)]  # PX4's fallback, then its return
    (found,) = codes(lint_events(events), "OFB203")
    assert found.severity is Severity.INFO and found.time_s == pytest.approx(5.001)


def test_ofb203_px4s_offboard_again_after_a_landing_disarm_is_no_run_up() -> None:
    """Issue 28 miss 1: a stream through AUTO_LAND; PX4 disarms after the landing and its
    status shows OFFBOARD again (the user intention, disarmed): the armed stretch fought the
    land task, whatever status follows the disarm."""
    events = [status(0.0, OFFBOARD), *ocm(every(0.0, 9.0, 0.1))]
    events += _repeat(0.0, 9.0, 10.0, position=(0.0, 0.0, -5.0))
    events += [status(2.02, 18), status(8.05, OFFBOARD, armed=False)]
    (found,) = codes(lint_events(events), "OFB203")
    assert found.severity is Severity.ERROR and "AUTO_LAND" in found.summary
    assert found.time_s == pytest.approx(2.1) and found.end_s == pytest.approx(8.0)


def test_ofb203_an_external_mode_is_the_companions_own() -> None:
    """px4-ros2-interface-lib modes publish their setpoints while PX4 runs them (EXTERNAL1)."""
    events = [status(0.0, 23), *_repeat(0.0, 5.0, 20.0, velocity=(1.0, 0.0, 0.0))]
    assert codes(lint_events(events), "OFB203") == []


def test_ofb203_uses_the_gate_prediction_without_a_recorded_mode() -> None:
    events = [
        *ocm(every(0.0, 2.0, 0.1)),
        *_repeat(0.0, 0.5, 10.0, position=(0.0, 0.0, -2.0)),
        switch(1.0),
        *_repeat(1.1, 2.0, 10.0, position=(0.0, 0.0, -2.0)),
    ]
    (found,) = codes(lint_events(events), "OFB203")
    assert "predicted by the gate model" in found.message
    assert found.end_s == pytest.approx(0.5)


def test_ofb203_ulog_copies_are_not_checkable() -> None:
    events = [status(0.0, POSCTL), TrajectorySetpoint(t=0.1, origin="vehicle", position=(0, 0, -1))]
    findings = lint_events(events, fmt="ulog")
    assert codes(findings, "OFB203") == []
    assert any("OFB203" in f.message for f in codes(findings, "OFB002"))


# --- OFB3xx -------------------------------------------------------------------------------


def test_ofb302_rover_speed_rate_with_nan_attitude_is_declared() -> None:
    events = [
        status(0.0, OFFBOARD),
        ControlMode(t=0.0, velocity=True),
        RoverSpeedSetpoint(t=0.1, speed_body_x=1.0),
        RoverAttitudeSetpoint(t=0.1),
        RoverRateSetpoint(t=0.1, yaw_rate_setpoint=0.2),
    ]
    findings = lint_events(events, px4="1.16", vehicle="rover-differential")
    assert codes(findings, "OFB302") == []
    assert codes(findings, "OFB303") == []


def test_ofb302_actuator_flag_of_1_14_selects_thrust_and_torque() -> None:
    events = [
        status(0.0, OFFBOARD),
        ControlMode(t=0.0, actuator=True, layout="actuator"),
        AttitudeSetpoint(t=0.1, q_d=(1, 0, 0, 0), thrust_body=(0, 0, -0.5)),
    ]
    (found,) = codes(lint_events(events, px4="1.14"), "OFB302")
    assert "'actuator'" in found.message


@pytest.mark.parametrize(("first_at", "flagged"), [(0.49, False), (None, True)])
def test_ofb303_grace_edge(first_at: float | None, flagged: bool) -> None:
    events: list[Event] = [status(0.0, OFFBOARD), *ocm(every(0.0, 1.0, 0.1), attitude=True)]
    if first_at is not None:
        events.append(AttitudeSetpoint(t=first_at, q_d=(1, 0, 0, 0), thrust_body=(0, 0, -0.5)))
    found = codes(lint_events(events), "OFB303")
    assert bool(found) is flagged
    if flagged:
        assert found[0].time_s == pytest.approx(0.5)
        assert "VehicleAttitudeSetpoint" in found[0].message


@pytest.mark.parametrize(
    ("fmt", "first_at", "flagged"),
    [("ulog", 0.75, False), ("ulog", 1.2, True), ("mcap", 0.75, True)],
)
def test_ofb303_a_ulogs_setpoint_topic_first_logged_late_is_not_missing(
    fmt: str, first_at: float, flagged: bool
) -> None:
    """The 1.17.0 airplane's ULog (corpora/sitl/fw_loss-1.17.0.ulg): its MAVLink receiver
    advertises trajectory_setpoint at the switch, and PX4's logger logged the first one 0.75 s
    later. Up to 1 s is the logger; later, or in a stream as sent, the setpoint is missing."""
    events: list[Event] = [status(0.0, OFFBOARD), *ocm(every(0.0, 3.0, 0.1), position=True)]
    events += [
        TrajectorySetpoint(t=first_at + 0.1 * k, position=(0.0, 0.0, -5.0)) for k in range(10)
    ]
    found = codes(lint_events(events, fmt=fmt, vehicle="fw", px4="1.17"), "OFB303")
    assert bool(found) is flagged


def test_ofb304_changes_outside_offboard_are_not_reported() -> None:
    events = [
        status(0.0, POSCTL),
        ControlMode(t=0.0, position=True),
        ControlMode(t=0.1, attitude=True),
        status(0.2, OFFBOARD),
        ControlMode(t=0.3, attitude=True),
    ]
    assert codes(lint_events(events), "OFB304") == []


POSITION_MASK, BODY_VELOCITY_MASK = 0x9F8, 0xDC7


def _mavlink(t: float, mask: int, frame: int = 1) -> SetPositionTargetLocal:
    return SetPositionTargetLocal(
        t=t, target_system=1, type_mask=mask, coordinate_frame=frame, velocity=(0.5, 0.0, 0.0)
    )


def test_ofb304_judges_the_flags_pxs_receiver_sets_from_mavlink_type_masks() -> None:
    # no OffboardControlMode over MAVLink: a position segment, then a velocity segment
    events: list[Event] = [status(0.0, OFFBOARD)]
    events += [_mavlink(0.05 * k, POSITION_MASK) for k in range(40)]
    events += [_mavlink(2.0 + 0.05 * k, BODY_VELOCITY_MASK, 8) for k in range(40)]
    (found,) = codes(lint_events(events, fmt="tlog"), "OFB304")
    assert found.time_s == pytest.approx(2.0)
    assert "from 'position' to 'velocity'" in found.message and "type masks" in found.message


def test_ofb304_interleaved_setpoint_types_are_one_stretch() -> None:
    # a position setpoint at 10 Hz with a body-velocity nudge between them for 1 s, twice
    events: list[Event] = [status(0.0, OFFBOARD)]
    events += [_mavlink(0.1 * k, POSITION_MASK) for k in range(80)]
    for start in (2.0, 5.0):
        events += [_mavlink(start + 0.05 + 0.1 * k, BODY_VELOCITY_MASK, 8) for k in range(10)]
    found = codes(lint_events(events, fmt="tlog"), "OFB304")
    assert [(f.time_s, f.end_s) for f in found] == [
        (pytest.approx(2.05), pytest.approx(3.0)),
        (pytest.approx(5.05), pytest.approx(6.0)),
    ]
    assert all("changed 20 times" in f.message for f in found)
    # the same alternation as a ULog's 10 Hz samples of the receiver's offboard_control_mode
    sampled: list[Event] = [status(0.0, OFFBOARD)]
    sampled += [
        ControlMode(t=0.1 * k, position=not 20 < k < 30 or k % 3 != 0, velocity=True)
        for k in range(80)
    ]
    (one,) = codes(lint_events(sampled, fmt="ulog"), "OFB304")
    assert one.time_s == pytest.approx(2.1) and "times" in one.message


def test_ofb305_at_the_request_and_not_checkable_without_flags() -> None:
    events = [
        status(0.0, POSCTL),
        ControlMode(t=0.0, velocity=True),
        FailsafeFlags(t=0.0, local_velocity_valid=False),
        switch(0.5),
    ]
    (found,) = codes(lint_events(events, fmt="ulog"), "OFB305")
    assert "at the offboard request" in found.message and found.time_s == 0.5
    bare = lint_events([status(0.0, OFFBOARD), ControlMode(t=0.0, velocity=True)])
    assert any("OFB305" in f.message for f in codes(bare, "OFB002"))


def test_ofb305_follows_the_profile_table() -> None:
    # acceleration needs a velocity estimate on 1.14 (seed 002) but an attitude on 1.16 (000).
    events = [
        status(0.0, OFFBOARD),
        ControlMode(t=0.0, acceleration=True),
        FailsafeFlags(t=0.1, local_velocity_valid=False, attitude_valid=True),
    ]
    assert len(codes(lint_events(events, px4="1.14"), "OFB305")) == 1
    assert codes(lint_events(events, px4="1.16"), "OFB305") == []


# --- OFB4xx -------------------------------------------------------------------------------


def _traj(**fields: Any) -> list[Event]:
    return [
        status(0.0, OFFBOARD),
        ControlMode(t=0.0, position=True),
        TrajectorySetpoint(t=0.1, **fields),
    ]


def test_ofb401_acceleration_only_under_acceleration_is_clean() -> None:
    events = [
        status(0.0, OFFBOARD),
        ControlMode(t=0.0, acceleration=True),
        TrajectorySetpoint(t=0.1, acceleration=(0.0, 0.0, -1.0)),
    ]
    findings = lint_events(events)
    assert codes(findings, "OFB401") == [] and codes(findings, "OFB403") == []


def test_ofb401_mixed_axes_follow_the_docs_per_message_reading() -> None:
    events = [
        status(0.0, OFFBOARD),
        ControlMode(t=0.0, velocity=True),
        TrajectorySetpoint(t=0.1, position=(NAN, NAN, -2.0), velocity=(1.0, 0.0, NAN)),
    ]
    findings = lint_events(events)
    (found,) = codes(findings, "OFB401")
    assert "position controller" in found.message
    assert codes(findings, "OFB403") == []  # valid per axis for the code


def test_ofb403_says_what_each_profile_does() -> None:
    events = _traj(position=(1.0, 2.0, NAN))
    (old,) = codes(lint_events(events, px4="1.15"), "OFB403")
    (new,) = codes(lint_events(events, px4="1.16"), "OFB403")
    assert "axis z" in old.message and "at once" in old.message
    assert "200 ms" in new.message
    assert codes(lint_events(events, vehicle="fw"), "OFB403") == []


def test_ofb402_is_reported_instead_of_ofb403() -> None:
    findings = lint_events(_traj(yaw=0.5))
    assert len(codes(findings, "OFB402")) == 1 and codes(findings, "OFB403") == []


def _on_ground_then(*events: Event, armed_at_start: bool = False) -> list[Event]:
    head = [status(0.0, OFFBOARD, armed=armed_at_start), status(0.1, OFFBOARD, armed=True)]
    return [*head, *events]


def test_ofb404_small_first_commands_decide_nothing() -> None:
    events = _on_ground_then(
        TrajectorySetpoint(t=0.2, position=(0.0, 0.0, 0.3)),  # zero-ish setpoint before takeoff
        TrajectorySetpoint(t=0.3, position=(0.0, 0.0, -5.0)),
        TrajectorySetpoint(t=5.0, velocity=(0.0, 0.0, 1.0)),  # a later descent is fine
    )
    assert codes(lint_events(events), "OFB404") == []


@pytest.mark.parametrize(("vz", "flagged"), [(0.3, False), (0.31, True)])
def test_ofb404_vertical_velocity_edge(vz: float, flagged: bool) -> None:
    events = _on_ground_then(TrajectorySetpoint(t=0.2, velocity=(0.0, 0.0, vz)))
    assert bool(codes(lint_events(events), "OFB404")) is flagged


def test_ofb404_recording_that_starts_in_flight_is_not_a_takeoff() -> None:
    events = [
        status(0.0, OFFBOARD, armed=True),
        TrajectorySetpoint(t=0.2, velocity=(0.0, 0.0, 1.0)),
    ]
    assert codes(lint_events(events), "OFB404") == []


def test_ofb404_a_climb_in_enu_from_the_ground_is_an_error() -> None:
    events = _on_ground_then(TrajectorySetpoint(t=0.2, position=(0.0, 0.0, 5.0)))
    (found,) = codes(lint_events(events), "OFB404")
    assert found.severity is Severity.ERROR and "on the ground" in found.message


TAKEOFF, LOITER = 17, 4


@pytest.mark.parametrize(
    "takeoff",
    [
        [status(1.0, TAKEOFF), status(6.0, LOITER)],  # MAVSDK action.takeoff(): AUTO_TAKEOFF
        [status(1.0, POSCTL)],  # a pilot's takeoff in Position mode
        [Command(t=1.0, command=22)],  # MAV_CMD_NAV_TAKEOFF, no status recorded for it
    ],
)
def test_ofb404_a_first_offboard_descent_after_a_takeoff_is_not_enu(takeoff: list[Event]) -> None:
    events = [status(0.0, LOITER, armed=False), status(0.5, LOITER, armed=True), *takeoff]
    events += [status(8.0, OFFBOARD), ControlMode(t=8.0, velocity=True)]
    events += [TrajectorySetpoint(t=8.1 + 0.05 * k, velocity=(0.0, 0.0, 0.5)) for k in range(40)]
    assert codes(lint_events(events), "OFB404") == []


def test_ofb404_enu_height_when_the_recording_starts_in_the_air() -> None:
    """The missed case: ENU z up (z = +10 for 10 m) while airborne: PX4 descends to 10 m
    below the origin, into the ground."""
    events: list[Event] = [status(0.0, OFFBOARD, armed=True), ControlMode(t=0.0, position=True)]
    events += [TrajectorySetpoint(t=0.1 * k, position=(0.0, 0.0, 10.0)) for k in range(1, 30)]
    (found,) = codes(lint_events(events), "OFB404")
    assert found.severity is Severity.ERROR
    assert "below the local origin" in found.message and "29 messages" in found.message
    # NED heights while airborne are fine, and so is a landing at the origin
    ned = [status(0.0, OFFBOARD, armed=True), ControlMode(t=0.0, position=True)]
    ned += [TrajectorySetpoint(t=0.1 * k, position=(0.0, 0.0, -10.0 + k)) for k in range(1, 11)]
    assert codes(lint_events(ned), "OFB404") == []


def test_ofb404_enu_height_after_an_auto_takeoff_is_an_error() -> None:
    events = [status(0.0, LOITER, armed=False), status(0.5, TAKEOFF), status(5.0, LOITER)]
    events += [status(8.0, OFFBOARD), ControlMode(t=8.0, position=True)]
    events += [TrajectorySetpoint(t=8.1 + 0.05 * k, position=(0.0, 0.0, 2.5)) for k in range(9)]
    (found,) = codes(lint_events(events), "OFB404")
    assert found.time_s == pytest.approx(8.1) and found.severity is Severity.ERROR


def test_ofb404_pxs_own_setpoints_in_a_ulog_are_not_judged() -> None:
    """A clean SITL flight's ULog: PX4's flight task writes trajectory_setpoint in AUTO_LOITER
    on the ground (a push down). On 1.16 the receiver acks the switch ACCEPTED 6 ms before
    Commander's verdict, and vehicle_status says OFFBOARD only later: none of that is the
    companion's."""
    events: list[Event] = [status(0.0, LOITER, armed=False), ControlMode(t=0.0, origin="vehicle")]
    events += [ControlMode(t=0.1 * k, position=True, origin="vehicle") for k in range(1, 40)]
    own = [
        TrajectorySetpoint(t=0.02 + 0.05 * k, velocity=(0.0, 0.0, 0.7), origin="vehicle")
        for k in range(32)  # until 1.57 s: after the acks, before the status says OFFBOARD
    ]
    events += own
    events += [switch(1.5), ack(1.502, 0), ack(1.508, 0), status(1.6, OFFBOARD, armed=False)]
    events += [status(2.0, OFFBOARD, armed=True)]
    events += [
        TrajectorySetpoint(t=2.02 + 0.1 * k, position=(0.0, 0.0, -3.0), origin="vehicle")
        for k in range(20)
    ]
    assert codes(lint_events(events, px4="1.16", fmt="ulog"), "OFB404") == []


def _drifted_ground(*events: Event) -> list[Event]:
    """PX4 1.15 SIH on the ground: the estimator's local z has drifted to +1.78 m."""
    head: list[Event] = [status(0.0, LOITER, armed=False), ControlMode(t=0.0, position=True)]
    head += [VehiclePosition(t=0.5 * k, x=0.0, y=0.0, z=1.78) for k in range(6)]
    return [*head, *events]


def test_ofb404_a_client_sending_its_current_position_from_the_ground_is_not_enu() -> None:
    # px4_ros_com's Python example on 1.15: the current position until its first setpoint
    held = [TrajectorySetpoint(t=2.6 + 0.1 * k, position=(0.0, 0.0, 1.78)) for k in range(10)]
    climb = [TrajectorySetpoint(t=3.6 + 0.1 * k, position=(0.0, 0.0, -5.0)) for k in range(10)]
    events = _drifted_ground(*held, status(3.5, OFFBOARD, armed=True), *climb)
    assert codes(lint_events(events), "OFB404") == []
    # without the vehicle's position the origin stands for the ground: 1.78 m below it
    blind = [e for e in events if not isinstance(e, VehiclePosition)]
    (found,) = codes(lint_events(blind), "OFB404")
    assert "no vehicle position" in found.message


def test_ofb404_a_climb_in_enu_is_judged_against_the_vehicles_height() -> None:
    events = _drifted_ground(TrajectorySetpoint(t=2.6, position=(0.0, 0.0, 5.0)))
    (found,) = codes(lint_events(events), "OFB404")
    assert found.severity is Severity.ERROR
    assert "3.22 m below the vehicle (its local z = 1.78 m)" in found.message


def test_ofb404_one_climb_in_enu_on_the_ground_is_one_finding() -> None:
    # real PX4 SITL: the first setpoint comes before the first HEARTBEAT (disarmed), and PX4
    # disarms the vehicle itself 10 s after it armed pushing into the ground, the stream going on
    events: list[Event] = [
        TrajectorySetpoint(t=0.1 * k, position=(0.0, 0.0, 2.5)) for k in range(200)
    ]
    events += [status(0.35, LOITER, armed=False), status(2.0, OFFBOARD, armed=True)]
    events += [status(12.0, OFFBOARD, armed=False)]
    (found,) = codes(lint_events(events), "OFB404")
    assert found.time_s == 0.0
    # a flight that lands is a new stretch on the ground: its next climb is judged again
    flew = [status(0.0, LOITER, armed=False), status(1.0, TAKEOFF, armed=True)]
    flew += [status(6.0, LOITER, armed=False)]
    flew += [TrajectorySetpoint(t=7.0 + 0.1 * k, position=(0.0, 0.0, 2.5)) for k in range(5)]
    assert [f.time_s for f in codes(lint_events(flew), "OFB404")] == [7.0]


def test_ofb404_a_setpoint_at_the_origin_is_not_enu_when_the_estimate_drifted_up() -> None:
    """PX4 1.14.4 SITL, the airplane at rest: its estimate read 0.56 m up. A ground setpoint at
    the origin (z = 0) is 0.56 m below that estimate but not below the origin: no finding, on
    the ground or after a takeoff; a height in ENU is still one."""
    head: list[Event] = [status(0.0, LOITER, armed=False), ControlMode(t=0.0, position=True)]
    head += [VehiclePosition(t=0.5 * k, x=0.0, y=0.0, z=-0.56) for k in range(6)]
    at_origin = [TrajectorySetpoint(t=2.6 + 0.1 * k, position=(0.0, 0.0, 0.0)) for k in range(10)]
    assert codes(lint_events([*head, *at_origin]), "OFB404") == []
    flown = [*head, status(3.0, TAKEOFF, armed=True), status(8.0, OFFBOARD), *at_origin[:1]]
    flown[-1] = TrajectorySetpoint(t=8.1, position=(0.0, 0.0, 0.0))
    assert codes(lint_events(flown), "OFB404") == []
    (found,) = codes(
        lint_events([*head, TrajectorySetpoint(t=2.6, position=(0, 0, 1.0))]), "OFB404"
    )
    assert "1.56 m below the vehicle (its local z = -0.56 m)" in found.message


def test_ofb404_in_the_air_a_target_is_judged_against_the_ground_it_took_off_from() -> None:
    events = _drifted_ground(
        status(3.0, TAKEOFF, armed=True),
        *[VehiclePosition(t=3.5 + 0.5 * k, x=0.0, y=0.0, z=1.78 - k) for k in range(8)],
        status(8.0, OFFBOARD),
        TrajectorySetpoint(t=8.1, position=(0.0, 0.0, 2.0)),  # a landing 0.22 m below: fine
    )
    assert codes(lint_events(events), "OFB404") == []
    events.append(TrajectorySetpoint(t=8.2, position=(0.0, 0.0, 5.0)))
    (found,) = codes(lint_events(events), "OFB404")
    assert "3.22 m below the ground the vehicle took off from (z = 1.78 m)" in found.message


def test_a_ulogs_setpoint_between_the_receivers_ack_and_the_switch_is_pxs_own() -> None:
    """PX4 1.17 SITL, acceleration-only MAVLink setpoints: the receiver acks the switch 24 ms
    before Commander makes it, and PX4's AUTO_LOITER flight task writes trajectory_setpoint
    (a position hold) in between: not the client's, no OFB401. Once the status says OFFBOARD,
    a logged setpoint is the client's again."""
    events: list[Event] = [status(0.0, LOITER, armed=False)]
    events += [ControlMode(t=0.1 * k, acceleration=True, origin="vehicle") for k in range(1, 40)]
    events += [switch(1.992), ack(1.992, 0), ack(2.004, 0), status(2.016, OFFBOARD, armed=False)]
    own = TrajectorySetpoint(
        t=2.0, position=(0.08, -0.03, 0.54), acceleration=(0.0, -0.06, -0.06), origin="vehicle"
    )
    events.append(own)
    found = lint_events(events, px4="1.17", fmt="ulog")
    assert codes(found, "OFB401") == []
    late = TrajectorySetpoint(t=2.5, position=(0.0, 0.0, -2.0), origin="vehicle")
    (mismatch,) = codes(lint_events([*events, late], px4="1.17", fmt="ulog"), "OFB401")
    assert mismatch.time_s == 2.5


def test_ofb404_thrust_pointing_down_on_a_multicopter() -> None:
    events = [
        status(0.0, OFFBOARD),
        ControlMode(t=0.0, body_rate=True),
        RatesSetpoint(t=0.1, roll=0, pitch=0, yaw=0, thrust_body=(0.0, 0.0, 0.6)),
    ]
    (found,) = codes(lint_events(events), "OFB404")
    assert "FLU" in found.message
    assert codes(lint_events(events, vehicle="fw"), "OFB404") == []


@pytest.mark.parametrize(("w", "flagged"), [(1.0009, False), (1.0011, True), (NAN, True)])
def test_ofb405_norm_edge(w: float, flagged: bool) -> None:
    events = [AttitudeSetpoint(t=0.0, q_d=(w, 0.0, 0.0, 0.0), thrust_body=(0, 0, -0.5))]
    assert bool(codes(lint_events(events), "OFB405")) is flagged


def test_ofb405_ignores_the_quaternion_of_a_body_rate_attitude_target() -> None:
    rates = SetAttitudeTarget(t=0.0, type_mask=128, q=(0.0, 0.0, 0.0, 0.0), thrust=0.5)
    attitude = SetAttitudeTarget(t=0.1, type_mask=7, q=(0.0, 0.0, 0.0, 0.0), thrust=0.5)
    (found,) = codes(lint_events([rates, attitude], fmt="tlog"), "OFB405")
    assert found.time_s == 0.1 and "SET_ATTITUDE_TARGET.q" in found.message


@pytest.mark.parametrize(("value", "flagged"), [(1.0, False), (-1.0, False), (-1.0001, True)])
def test_ofb406_range_edge(value: float, flagged: bool) -> None:
    events = [ActuatorMotors(t=0.0, control=(0.5, value))]
    assert bool(codes(lint_events(events), "OFB406")) is flagged


def test_ofb406_mavlink_thrust_range_depends_on_the_vehicle() -> None:
    reverse = [SetAttitudeTarget(t=0.0, type_mask=7, thrust=-0.2)]
    assert len(codes(lint_events(reverse, fmt="tlog"), "OFB406")) == 1
    assert codes(lint_events(reverse, fmt="tlog", vehicle="fw"), "OFB406") == []
    ignored = [SetAttitudeTarget(t=0.0, type_mask=7 | 64, thrust=7.0)]
    assert codes(lint_events(ignored, fmt="tlog"), "OFB406") == []


def test_ofb407_trailing_nans_are_unused_outputs_unless_they_ran() -> None:
    unused = [status(0.0, OFFBOARD), ActuatorMotors(t=0.1, control=(0.5, 0.5, NAN, NAN))]
    assert codes(lint_events(unused), "OFB407") == []
    stopped = [
        status(0.0, OFFBOARD),
        ActuatorMotors(t=0.1, control=(0.5, 0.5, 0.5, 0.5)),
        ActuatorMotors(t=0.2, control=(0.5, 0.5, 0.5, NAN)),
    ]
    (found,) = codes(lint_events(stopped), "OFB407")
    assert found.time_s == 0.2 and "[3]" in found.message


def test_ofb407_not_while_disarmed() -> None:
    events = [
        status(0.0, OFFBOARD, armed=False),
        ActuatorMotors(t=0.1, control=(NAN, 0.5)),
    ]
    assert codes(lint_events(events), "OFB407") == []


def test_ofb408_names_the_missing_component() -> None:
    events = [RatesSetpoint(t=0.0, roll=0, pitch=0, yaw=0, thrust_body=(NAN, 0.0, -0.5))]
    (found,) = codes(lint_events(events), "OFB408")
    assert "thrust_body[0]" in found.message


# --- OFB8xx -------------------------------------------------------------------------------


def test_ofb801_acceleration_alone_is_deliberate() -> None:
    events = [
        LegacyControlMode(
            t=0.0, ignore_position=True, ignore_velocity=True, ignore_acceleration_force=False
        )
    ]
    assert codes(lint_events(events, px4="legacy", fmt="ulog"), "OFB801") == []


def test_ofb802_only_in_offboard() -> None:
    triplet = PositionSetpointTriplet(t=0.1, current_valid=True, previous_valid=True)
    assert codes(lint_events([status(0.0, POSCTL), triplet], px4="legacy"), "OFB802") == []
    assert len(codes(lint_events([status(0.0, OFFBOARD), triplet], px4="legacy"), "OFB802")) == 1


def test_ofb803_current_invalid_and_velocity_validity() -> None:
    invalid = [status(0.0, OFFBOARD), PositionSetpointTriplet(t=0.1, current_valid=False)]
    (found,) = codes(lint_events(invalid, px4="legacy"), "OFB803")
    assert "current.valid false" in found.message
    velocity = [
        status(0.0, OFFBOARD),
        LegacyControlMode(t=0.0, ignore_position=True, ignore_acceleration_force=True),
        PositionSetpointTriplet(t=0.1, current_valid=True, current_position_valid=True),
    ]
    (found,) = codes(lint_events(velocity, px4="legacy"), "OFB803")
    assert "velocity_valid" in found.message


def test_content_rules_can_be_ignored() -> None:
    events = [AttitudeSetpoint(t=0.0, q_d=(2.0, 0, 0, 0), thrust_body=(0, 0, 3.0))]
    settings = Settings(ignore=frozenset({"OFB405", "OFB406"}))
    found = lint_events(events, settings=settings)
    assert codes(found, "OFB405") == [] and codes(found, "OFB406") == []


def test_ofb801_from_a_legacy_mavlink_type_mask() -> None:
    use_all = SetPositionTargetLocal(t=0.0, type_mask=0, position=(0.0, 0.0, -2.0))
    (found,) = codes(lint_events([use_all], px4="legacy", fmt="tlog"), "OFB801")
    assert "type_mask 0" in found.message
    position_only = SetPositionTargetLocal(t=0.0, type_mask=0b110111111000)
    assert codes(lint_events([position_only], px4="legacy", fmt="tlog"), "OFB801") == []
    # One acceleration bit set is enough for the legacy receiver to ignore acceleration.
    one_bit = SetPositionTargetLocal(t=0.0, type_mask=0b000001000000)
    assert codes(lint_events([one_bit], px4="legacy", fmt="tlog"), "OFB801") == []


def test_ofb303_counts_from_arming_when_parked_disarmed_in_offboard() -> None:
    events: list[Event] = [
        status(0.0, OFFBOARD, armed=False),
        *ocm(every(0.0, 3.0, 0.1), attitude=True),
        status(2.0, OFFBOARD, armed=True),
    ]
    (found,) = codes(lint_events(events), "OFB303")
    assert found.time_s == pytest.approx(2.5)
    parked = [status(0.0, OFFBOARD, armed=False), *ocm(every(0.0, 3.0, 0.1), attitude=True)]
    assert codes(lint_events(parked), "OFB303") == []


def test_ofb107_not_while_disarmed() -> None:
    events = [
        status(0.0, OFFBOARD, armed=False),
        *_repeat(0.0, 5.0, 20.0, position=(0.0, 0.0, -2.0)),
    ]
    assert codes(lint_events(events), "OFB107") == []


def test_ofb107_an_all_nan_rover_setpoint_published_on_purpose_is_not_frozen() -> None:
    """Seed 000: Speed + Rate needs RoverAttitudeSetpoint published as NaN, unchanging."""
    from fuzzoff.events import ControlMode, RoverAttitudeSetpoint, VehicleStatus
    from tests.streams import codes, every, lint_events

    events = [VehicleStatus(t=0.0, nav_state=14, armed=True)]
    events += [ControlMode(t=t, velocity=True) for t in every(0.0, 8.0, 0.1)]
    events += [RoverAttitudeSetpoint(t=t + 0.01) for t in every(0.0, 8.0, 0.05)]
    assert codes(lint_events(events, px4="1.17", vehicle="rover-differential"), "OFB107") == []


@settings(max_examples=60, deadline=None)
@given(
    st.lists(st.tuples(st.integers(1, 3), st.integers(1, 300)), min_size=1, max_size=8),
    st.sampled_from([0.02, 0.05]),
)
def test_ofb107_sampled_comparison_finds_the_same_runs_as_comparing_every_message(
    segments: list[tuple[int, int]], period: float
) -> None:
    """OFB107 compares content at 10 Hz; its runs must still start and end on the exact
    messages a message-by-message comparison gives."""
    values: list[int] = [v for v, n in segments for _ in range(n)]
    times = [round(i * period, 6) for i in range(len(values))]
    events: list[Event] = [status(0.0, OFFBOARD), *ocm(every(0.0, times[-1] + 0.1, 0.1))]
    events += [
        TrajectorySetpoint(t=t, velocity=(float(v), 0.0, 0.0))
        for t, v in zip(times, values, strict=True)
    ]
    expected = []
    start = 0
    for i in range(1, len(values) + 1):
        if i == len(values) or values[i] != values[start]:
            if times[i - 1] - times[start] > 10.0:
                expected.append((times[start], times[i - 1]))
            start = i
    found = [(f.time_s, f.end_s) for f in codes(lint_events(events), "OFB107")]
    assert found == [(pytest.approx(a), pytest.approx(b)) for a, b in expected]


# -- OFB303 on a MAVLink stream: PX4 forwards MAVLink setpoints only in OFFBOARD -------------

POSITION_MASK = 0b110111111000  # position only, no yaw (3576)


def mavlink_stream(times: Sequence[float], frame: int = 1) -> list[Event]:
    return [
        SetPositionTargetLocal(
            t=round(t, 6), type_mask=POSITION_MASK, coordinate_frame=frame, position=(0, 0, -2)
        )
        for t in times
    ]


def test_ofb303_mavlink_setpoints_only_before_the_switch_hold_the_vehicle() -> None:
    events: list[Event] = [
        status(0.0, POSCTL),
        *mavlink_stream(every(0.0, 1.0, 0.1)),
        status(1.05, OFFBOARD),
        *mavlink_stream(every(2.0, 3.0, 0.1)),
    ]
    (found,) = codes(lint_events(events, fmt="tlog"), "OFB303")
    assert found.severity is Severity.ERROR
    assert found.time_s == pytest.approx(1.55)
    assert "no MAVLink setpoint PX4 takes has arrived by 1.550 s" in found.message
    assert "sent at 1.000 s, before the switch" in found.message
    assert "PX4 forwards MAVLink setpoints only in OFFBOARD" in found.message


@pytest.mark.parametrize(("first_after", "flagged"), [(1.5, False), (1.6, True)])
def test_ofb303_mavlink_grace_edge(first_after: float, flagged: bool) -> None:
    events: list[Event] = [
        status(0.0, POSCTL),
        *mavlink_stream(every(0.0, 1.0, 0.1)),
        status(1.0, OFFBOARD),
        *mavlink_stream(every(first_after, 3.0, 0.1)),
    ]
    assert bool(codes(lint_events(events, fmt="tlog"), "OFB303")) is flagged


def test_ofb303_mavlink_steady_stream_through_the_switch_is_clean() -> None:
    events: list[Event] = [
        status(0.0, POSCTL),
        *mavlink_stream(every(0.0, 3.0, 0.1)),
        status(1.02, OFFBOARD),
    ]
    assert codes(lint_events(events, fmt="tlog"), "OFB303") == []


def test_ofb303_mavlink_setpoints_the_receiver_drops_do_not_count() -> None:
    events: list[Event] = [
        status(0.0, OFFBOARD),
        *mavlink_stream(every(0.0, 2.0, 0.1), frame=9),  # BODY_OFFSET_NED: dropped (6.2)
    ]
    (found,) = codes(lint_events(events, px4="1.16", fmt="tlog"), "OFB303")
    assert "are all dropped by PX4's receiver" in found.message


def test_ofb303_mavlink_parked_disarmed_then_armed() -> None:
    parked: list[Event] = [
        status(0.0, OFFBOARD, armed=False),
        *mavlink_stream(every(0.0, 1.0, 0.1)),
    ]
    assert codes(lint_events(parked, fmt="tlog"), "OFB303") == []
    armed = [*parked, status(1.5, OFFBOARD, armed=True), status(3.0, OFFBOARD, armed=True)]
    (found,) = codes(lint_events(armed, fmt="tlog"), "OFB303")
    assert found.time_s == pytest.approx(2.0)


def test_ofb303_mavlink_attitude_target_counts() -> None:
    events: list[Event] = [
        status(0.0, POSCTL),
        status(0.5, OFFBOARD),
        *[SetAttitudeTarget(t=round(t, 6), type_mask=7, thrust=0.5) for t in every(0, 2, 0.1)],
    ]
    assert codes(lint_events(events, fmt="tlog"), "OFB303") == []


def test_ofb107_a_rover_throttle_held_under_a_held_steering_drives_a_circle() -> None:
    """Issue 33: PX4 1.17.0 and 1.18 drove the Ackermann rover on 0.3 throttle and 0.3
    steering in a 5 m circle (corpora/ros2bridge rover_throttle_steering): a bounded motion,
    reported after turning_s (60 s), not freeze_s; straight ahead (no steering) it is not."""
    from fuzzoff.events import RoverSteeringSetpoint, RoverThrottleSetpoint

    def drive(seconds: float, steering: float) -> list[Event]:
        events: list[Event] = [status(0.0, OFFBOARD)]
        events += ocm(every(0.0, seconds, 0.1), thrust_and_torque=True)
        events += [
            RoverThrottleSetpoint(t=round(t + 0.001, 6), throttle_body_x=0.3, throttle_body_y=0.0)
            for t in every(0.0, seconds, 0.1)
        ]
        events += [
            RoverSteeringSetpoint(t=round(t + 0.002, 6), normalized_steering_angle=steering)
            for t in every(0.0, seconds, 0.1)
        ]
        return events

    def frozen(events: list[Event]) -> list[Finding]:
        return codes(lint_events(events, px4="1.17", vehicle="rover-ackermann"), "OFB107")

    assert frozen(drive(20.0, 0.3)) == []
    (circle,) = frozen(drive(65.0, 0.3))
    assert "rover throttle 0.30 under a held turn (a bounded motion)" in circle.message
    (straight,) = frozen(drive(20.0, 0.0))
    assert "rover throttle 0.30 for" in straight.message
