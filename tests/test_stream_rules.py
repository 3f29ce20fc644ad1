"""OFB101-OFB105 and OFB201 on minimal streams: edges of their thresholds, per profile."""

from __future__ import annotations

from dataclasses import replace

import pytest

from fuzzoff.config import Settings
from fuzzoff.engine import lint_file, run_events
from fuzzoff.events import (
    Command,
    ControlMode,
    Dropout,
    Event,
    FailsafeFlags,
    SetPositionTargetLocal,
    TrajectorySetpoint,
    VehicleStatus,
)
from fuzzoff.findings import Severity
from fuzzoff.profiles import Profile
from fuzzoff.recording import RecordingInfo
from tests.helpers import CORPORA
from tests.streams import OFFBOARD, POSCTL, ack, codes, every, lint_events, ocm, status, switch


def flying(*gaps_at: tuple[float, float]) -> list:
    """Armed in OFFBOARD from t=0, a 10 Hz keep-alive to t=10 with the given (start, end) holes."""
    times = [t for t in every(0.0, 10.0, 0.1) if not any(a < t < b for a, b in gaps_at)]
    return [status(0.0, OFFBOARD), *ocm(times)]


@pytest.mark.parametrize(
    ("gap", "expected"),
    [
        (0.49, None),
        (0.5, Severity.INFO),  # the docs' 2 Hz only: no release with a 1 s timeout acts on it
        (0.79, Severity.INFO),
        (0.8, Severity.WARNING),  # 80 % of COM_OF_LOSS_T: kept, but only just
        (0.95, Severity.WARNING),
        (1.0, Severity.ERROR),  # PX4 takes the signal for lost
        (1.2, Severity.ERROR),
    ],
)
def test_ofb101_gap_edges_on_1_15(gap: float, expected: Severity | None) -> None:
    events = [status(0.0, OFFBOARD), *ocm([0.0, 0.1, 0.2, 0.2 + gap, 0.3 + gap])]
    found = codes(lint_events(events), "OFB101")
    if expected is None:
        assert found == []
    else:
        assert [f.severity for f in found] == [expected]
        assert found[0].time_s == pytest.approx(0.2)
        assert "docs:" in found[0].message


def test_ofb101_is_an_error_on_legacy_where_500ms_is_the_timeout() -> None:
    events = [status(0.0, OFFBOARD), *ocm([0.0, 0.1, 0.7, 0.8])]
    (found,) = codes(lint_events(events, px4="legacy"), "OFB101")
    assert found.severity is Severity.ERROR


def test_ofb101_ignores_gaps_outside_offboard() -> None:
    events = [status(0.0, POSCTL), *ocm([0.0, 0.1, 2.0, 2.1])]
    assert codes(lint_events(events), "OFB101") == []


def test_ofb101_counts_a_gap_in_the_second_before_a_request() -> None:
    events = [status(0.0, POSCTL), *ocm([0.0, 0.1, 0.8, 0.9, 1.0]), switch(1.05)]
    (found,) = codes(lint_events(events), "OFB101")
    assert "before an offboard request" in found.message
    # PX4 judges only the newest keep-alive at the request: the docs' rule alone
    assert found.severity is Severity.INFO
    assert "OFB102" in found.message


def test_ofb101_near_loss_tier_follows_a_lowered_loss_timeout() -> None:
    from fuzzoff.events import Parameter

    # COM_OF_LOSS_T 0.6 s: a 0.5 s gap is 83 % of it (warning), 0.6 s is a loss (error)
    for gap, expected in ((0.5, Severity.WARNING), (0.6, Severity.ERROR)):
        events = [Parameter(t=0.0, name="COM_OF_LOSS_T", value=0.6), status(0.0, OFFBOARD)]
        events += ocm([0.0, 0.1, 0.1 + gap, 0.2 + gap])
        (found,) = codes(lint_events(events), "OFB101")
        assert found.severity is expected, gap


def test_ofb101_judges_ulog_gaps_against_the_logging_interval() -> None:
    sampled = {"control_mode": 0.1}
    near_miss = [status(0.0, OFFBOARD), *ocm([0.0, 0.1, 0.65, 0.75])]  # proves only 0.45 s
    assert codes(lint_events(near_miss, fmt="ulog", sampled=sampled), "OFB101") == []
    real = [status(0.0, OFFBOARD), *ocm([0.0, 0.1, 0.75, 0.85])]  # proves 0.55 s
    assert len(codes(lint_events(real, fmt="ulog", sampled=sampled), "OFB101")) == 1


def test_ofb101_does_not_count_a_gap_across_a_logger_dropout() -> None:
    events = [status(0.0, OFFBOARD), *ocm([0.0, 0.1, 0.9]), Dropout(t=0.3, duration_s=0.5)]
    assert codes(lint_events(events, fmt="ulog", sampled={"control_mode": 0.1}), "OFB101") == []


def test_ofb101_mavlink_setpoints_for_another_system_are_not_keepalive() -> None:
    own = [SetPositionTargetLocal(t=t, vehicle="1", target_system=1) for t in every(0, 2, 0.1)]
    other = [SetPositionTargetLocal(t=t, vehicle="1", target_system=7) for t in every(0.05, 2, 0.1)]
    base = [VehicleStatus(t=0.0, vehicle="1", nav_state=OFFBOARD, armed=True)]
    assert codes(lint_events(base + own + other, fmt="tlog"), "OFB101") == []
    only_other = base + other + [own[0], own[-1]]
    assert len(codes(lint_events(only_other, fmt="tlog"), "OFB101")) == 1


def test_ofb102_switch_on_first_setpoint_is_info_with_what_px4_does() -> None:
    events = [status(0.0, POSCTL), *ocm([1.0, 1.02, 1.04]), switch(1.048)]
    (found,) = codes(lint_events(events), "OFB102")
    assert found.severity is Severity.INFO  # no release enforces the one second (D1)
    assert "0.05 s of unbroken keep-alive" in found.message
    assert "PX4 1.15 would: accept it" in found.message


def test_ofb102_no_stream_at_all_and_disarmed_on_1_14_is_accepted_by_px4() -> None:
    events = [status(0.0, POSCTL, armed=False), switch(1.0)]
    (found,) = codes(lint_events(events, px4="1.14"), "OFB102")
    assert "no keep-alive at all" in found.message
    assert "accept it" in found.message and "checked at arming" in found.message
    assert found.severity is Severity.INFO


def test_ofb102_is_an_error_where_the_gate_model_rejects_the_request() -> None:
    # armed, the last keep-alive 1.5 s old: PX4 1.15 rejects the switch
    events = [status(0.0, POSCTL), *ocm(every(0.0, 1.0, 0.1)), switch(2.5)]
    (found,) = codes(lint_events(events), "OFB102")
    assert found.severity is Severity.ERROR and "reject it" in found.message


def test_ofb102_ten_setpoints_at_10hz_with_a_millisecond_of_jitter() -> None:
    """px4_ros_com: 10 setpoints at 10 Hz, then the switch and the arm in the 11th cycle; the
    timer fires a millisecond early (rules.md: info at most, the switch is accepted)."""
    times = [round(0.1 * k + (0.001 if k == 0 else 0.0), 6) for k in range(20)]
    # the commands go out in the 11th cycle before its keep-alive, as in the source
    events = [status(0.0, POSCTL, armed=False), *ocm(times), switch(0.9995)]
    found = codes(lint_events(events), "OFB102")
    assert [f.severity for f in found] == [Severity.INFO]
    assert "only 1.00 s" in found[0].message and "accept it" in found[0].message


def test_ofb102_clean_after_one_second_of_stream() -> None:
    events = [status(0.0, POSCTL), *ocm(every(0.0, 1.2, 0.1)), switch(1.21)]
    assert codes(lint_events(events), "OFB102") == []


def test_ofb102_recorded_switch_counts_when_no_commands_are_recorded() -> None:
    events = [status(0.0, POSCTL), *ocm(every(0.5, 1.0, 0.05)), status(1.0, OFFBOARD)]
    (found,) = codes(lint_events(events), "OFB102")
    assert "recorded mode" in found.message
    started_in_offboard = [status(0.0, OFFBOARD), *ocm(every(0.0, 1.0, 0.1))]
    assert codes(lint_events(started_in_offboard), "OFB102") == []


def test_ofb103_failsafe_with_action_and_recorded_answer() -> None:
    events = [*flying((2.0, 9.0)), status(3.2, POSCTL)]
    (found,) = codes(lint_events(events), "OFB103")
    assert found.severity is Severity.ERROR
    assert 2.9 <= (found.time_s or 0) <= 3.15
    assert "POSCTL" in found.message and "recorded: POSCTL" in found.message


def test_ofb103_not_for_a_gap_under_the_timeout() -> None:
    assert codes(lint_events(flying((2.0, 2.8))), "OFB103") == []


def test_ofb103_respects_a_recorded_loss_timeout_parameter() -> None:
    from fuzzoff.events import Parameter

    events = [Parameter(t=0.0, name="COM_OF_LOSS_T", value=0.5), *flying((2.0, 2.8))]
    assert len(codes(lint_events(events), "OFB103")) == 1


def test_ofb104_stale_trajectory_under_live_keepalive_ros2_only() -> None:
    sp = [TrajectorySetpoint(t=t, position=(0.0, 0.0, -2.0)) for t in every(0.0, 1.0, 0.1)]
    events = [*flying(), *sp]
    (found,) = codes(lint_events(events, fmt="mcap"), "OFB104")
    assert "TrajectorySetpoint" in found.message
    assert found.time_s == pytest.approx(1.5)
    assert codes(lint_events(events, fmt="tlog"), "OFB104") == []


def test_ofb104_a_stretch_ends_when_the_setpoint_comes_back() -> None:
    """TrajectorySetpoint silent from 2.00 to 2.60 s under a 20 Hz keep-alive: 0.60 s, not
    the time to the next keep-alive after it came back."""
    times = [t for t in every(0.0, 5.0, 0.05) if not 2.0 < t < 2.6]
    sp = [TrajectorySetpoint(t=t + 0.01, position=(0.0, 0.0, -2.0)) for t in times]
    events = [status(0.0, OFFBOARD), *ocm(every(0.0, 5.0, 0.05)), *sp]
    (found,) = codes(lint_events(events, fmt="mcap"), "OFB104")
    assert "not published for 0.60 s" in found.message
    assert found.end_s == pytest.approx(2.61)


def test_ofb105_marginal_rate_and_p99() -> None:
    times = every(0.0, 20.0, 0.2)
    shifted = [t + (0.25 if i % 10 == 5 else 0) for i, t in enumerate(times)]  # one 450 ms gap
    marginal = [status(0.0, OFFBOARD), *ocm(shifted)]
    (found,) = codes(lint_events(marginal), "OFB105")
    assert "worst gap" in found.message
    healthy = [status(0.0, OFFBOARD), *ocm(every(0.0, 20.0, 0.05))]
    assert codes(lint_events(healthy), "OFB105") == []
    # 2.5 Hz: every gap 400 ms, so p99 and worst are both over their limits
    slow = [status(0.0, OFFBOARD), *ocm(every(0.0, 30.0, 0.4))]
    (found,) = codes(lint_events(slow), "OFB105")
    assert "99th-percentile" in found.message


def test_ofb201_double_ack_last_one_decides() -> None:
    base = [status(0.0, POSCTL), switch(1.0)]
    rejected = lint_events([*base, ack(1.004, 0), ack(1.010, 1), status(2.0, POSCTL)], px4="1.16")
    (found,) = codes(rejected, "OFB201")
    assert "TEMPORARILY_REJECTED" in found.message
    assert "no offboard signal" in found.message
    accepted = lint_events([*base, *ocm(every(0.0, 1.0, 0.1)), ack(1.004, 0), ack(1.01, 0)])
    assert codes(accepted, "OFB201") == []


def test_ofb201_a_late_second_ack_is_a_new_answer_not_a_double_ack() -> None:
    events = [
        status(0.0, POSCTL),
        *ocm(every(0.0, 1.0, 0.1)),
        switch(1.0),
        ack(1.01, 0),
        ack(1.5, 1),
    ]
    assert codes(lint_events(events), "OFB201") == []


def test_ofb201_acks_answer_back_to_back_switches_in_order() -> None:
    # found by fuzzing (ROS 2): OFFBOARD then POSCTL requested 0.1 ms apart, before either
    # ack; PX4 answers in order, so the rejection belongs to the OFFBOARD switch
    offboard = replace(switch(1.0001), transport="ros2")
    posctl = Command(
        t=1.0002, command=176, params=(1.0, 3.0, 0.0, 0.0, 0.0, 0.0, 0.0), transport="ros2"
    )
    events = [status(0.0, POSCTL), offboard, posctl, ack(1.008, 1), ack(1.0082, 0)]
    (found,) = codes(lint_events(events, px4="1.16"), "OFB201")
    assert found.time_s == pytest.approx(1.008)
    assert "switch to OFFBOARD at 1.00 s" in found.message
    swapped = [status(0.0, POSCTL), offboard, posctl, ack(1.008, 0), ack(1.0082, 1)]
    assert codes(lint_events(swapped, px4="1.16"), "OFB201") == []


def test_ofb201_a_rejection_first_is_never_the_receivers_ack() -> None:
    # 1.16's receiver acks ACCEPTED first: a first ack that rejects is Commander's verdict
    events = [status(0.0, POSCTL), switch(1.0), ack(1.004, 2), ack(1.010, 0)]
    (found,) = codes(lint_events(events, px4="1.16"), "OFB201")
    assert "DENIED" in found.message


def test_ofb101_silence_after_leaving_offboard_does_not_count() -> None:
    # the stream stops 50 ms before the recorded mode leaves OFFBOARD, then the recording goes on
    events = [status(0.0, OFFBOARD), *ocm(every(0.0, 5.0, 0.1)), status(5.05, POSCTL)]
    events.append(status(8.0, POSCTL))
    found = lint_events(events)
    assert codes(found, "OFB101") == [] and codes(found, "OFB103") == []


def test_ofb101_silence_in_offboard_until_the_vehicle_leaves_counts_up_to_the_switch() -> None:
    events = [status(0.0, OFFBOARD), *ocm(every(0.0, 5.0, 0.1)), status(5.7, POSCTL)]
    (found,) = codes(lint_events(events), "OFB101")
    assert found.end_s == pytest.approx(5.7)
    assert "0.70 s" in found.message


HOLD_MODE = (1.0, 4.0, 3.0, 0.0, 0.0, 0.0, 0.0)
"""DO_SET_MODE to Hold (custom main mode AUTO, sub mode LOITER), as MAVSDK's stop() sends it."""
LOITER = 4


def _mavsdk_stop(acks: list[tuple[float, int]]) -> list:
    """MAVSDK offboard stop(): the setpoints stop, then DO_SET_MODE to Hold; PX4 acks it 20 ms
    after the last setpoint and the next 1 Hz HEARTBEAT shows Hold a second later."""
    setpoints = [SetPositionTargetLocal(t=t, type_mask=0b110111000111) for t in every(0, 10, 0.05)]
    heartbeats = [status(float(k), OFFBOARD) for k in range(11)]
    stop = Command(t=10.001, command=176, params=HOLD_MODE)
    answer = [ack(t, result) for t, result in acks]
    later = [status(float(k), LOITER) for k in range(11, 16)]
    return [*heartbeats, *setpoints, stop, *answer, *later]


@pytest.mark.parametrize(
    ("px4", "acks"),
    [("1.15", [(10.02, 0)]), ("1.16", [(10.02, 0), (10.026, 0)])],
)
def test_ofb101_the_window_ends_at_the_accepted_ack_of_a_switch_away(
    px4: str, acks: list[tuple[float, int]]
) -> None:
    found = lint_events(_mavsdk_stop(acks), px4=px4, fmt="tlog")
    assert codes(found, "OFB101") == [] and codes(found, "OFB103") == []


def test_ofb101_commanders_rejection_after_the_receivers_ack_keeps_the_window_open() -> None:
    # 1.16: the receiver acks ACCEPTED, Commander rejects: the vehicle stays in OFFBOARD with no
    # keep-alive, so the silence is a loss
    events = [e for e in _mavsdk_stop([(10.02, 0), (10.026, 1)]) if e.t < 11.0]
    events += [status(float(k), OFFBOARD) for k in range(11, 16)]
    found = codes(lint_events(events, px4="1.16", fmt="tlog"), "OFB101")
    assert [f.severity for f in found] == [Severity.ERROR]


def test_pxs_automatic_return_after_a_loss_is_not_a_request() -> None:
    # MAVROS-like: no commands recorded; stream stops 6.0-8.0 s, PX4 fails over to POSCTL at
    # 7.0 s and returns to OFFBOARD by itself when the stream resumes (gate spec D9)
    times = [t for t in every(0.0, 12.0, 0.05) if not 6.0 < t < 8.0]
    events = [status(0.0, POSCTL), *ocm(times), status(3.0, OFFBOARD)]
    events += [status(7.0, POSCTL), status(8.2, OFFBOARD)]
    found = lint_events(events)
    assert codes(found, "OFB102") == []
    assert [f.time_s for f in codes(found, "OFB101")] == [pytest.approx(6.0)]


def test_pxs_return_to_offboard_as_it_disarms_after_a_landing_is_not_a_request() -> None:
    # MAVROS-like: the stream stops as the vehicle lands in AUTO_LAND; after "Disarmed by
    # landing" PX4 shows OFFBOARD again, disarmed (its user intention from before the landing,
    # as 1.16.2 and 1.17.0 SITL did), with no stream running: nobody asked for it
    land = 18
    events = [status(0.0, POSCTL, armed=False), *ocm(every(0.0, 20.0, 0.05))]
    events += [status(5.0, OFFBOARD, armed=False), status(10.0, OFFBOARD, armed=True)]
    events += [status(20.01, land, armed=True), status(25.0, land, armed=True)]
    events += [status(30.0, OFFBOARD, armed=False), status(31.0, OFFBOARD, armed=False)]
    assert codes(lint_events(events, px4="1.16"), "OFB102") == []
    # a user's switch while disarmed on the ground is still one
    user = [status(0.0, POSCTL, armed=False), status(1.0, POSCTL, armed=False)]
    user += [*ocm(every(1.5, 2.0, 0.05)), status(2.0, OFFBOARD, armed=False)]
    (found,) = codes(lint_events(user, px4="1.16"), "OFB102")
    assert found.time_s == 2.0 and "recorded mode" in found.message


def test_a_heartbeat_sent_between_the_ack_and_the_switch_is_not_a_switch_back() -> None:
    # PX4 1.16.2 SITL: the client sends its last setpoint, asks for AUTO_LAND, PX4 acks twice,
    # and a HEARTBEAT 7 ms later still shows OFFBOARD (sent before Commander's new status);
    # the next one, a second later, shows AUTO_LAND. The vehicle did not go back to OFFBOARD
    land = 18
    events: list[Event] = [status(0.0, OFFBOARD)]
    events += [
        SetPositionTargetLocal(t=t, target_system=1, type_mask=0x9F8, position=(0, 0, -2.5))
        for t in every(0.0, 4.95, 0.1)
    ]
    to_land = Command(t=5.0, command=176, params=(1.0, 4.0, 6.0, 0.0, 0.0, 0.0, 0.0))
    events += [to_land, ack(5.007, 0), ack(5.007, 0), status(5.014, OFFBOARD)]
    events += [status(6.0, land), status(7.0, land)]
    found = lint_events(events, px4="1.16", fmt="tlog")
    assert codes(found, "OFB303") == [] and codes(found, "OFB101") == []


def test_ofb102_follows_the_models_second_look_at_a_switch_the_logger_hid() -> None:
    # MAVSDK's set-then-start on PX4 1.16.2 SITL, as its ULog holds it: the switch is logged
    # 4 ms before PX4's flag turns available, and the logger missed the keep-alive PX4 had
    lost = [FailsafeFlags(t=0.5, offboard_control_signal_lost=True)]
    events: list[Event] = [status(0.0, 17, armed=True), *lost]
    events += [switch(2.0), FailsafeFlags(t=2.004, offboard_control_signal_lost=False)]
    events += [ack(2.004, 0), ack(2.008, 0), status(2.016, OFFBOARD)]
    events += [ControlMode(t=2.1 + 0.1 * k, attitude=True, origin="vehicle") for k in range(20)]
    found = lint_events(events, px4="1.16", fmt="ulog", sampled={"control_mode": 0.1})
    (request,) = codes(found, "OFB102")
    assert request.severity is Severity.INFO and "would: accept it" in request.message
    assert codes(found, "OFB202") == [] and codes(found, "OFB103") == []


def test_ofb104_not_when_the_keepalive_stopped_with_the_setpoints() -> None:
    times = [t for t in every(0.0, 10.0, 0.1) if not 4.0 < t < 6.0]
    sp = [TrajectorySetpoint(t=t + 0.01, position=(0.0, 0.0, -2.0)) for t in times]
    events = [status(0.0, OFFBOARD), *ocm(times), *sp]
    assert codes(lint_events(events, fmt="mcap"), "OFB104") == []


def test_ofb201_reports_the_models_rejection_when_the_recording_has_no_acks() -> None:
    # no keep-alive at all, armed: PX4 1.15 rejects the switch; no ack recorded
    found = lint_events([status(0.0, POSCTL), switch(1.0)])
    (rejected,) = codes(found, "OFB201")
    assert "would reject it" in rejected.message and "no offboard signal" in rejected.message
    assert not [f for f in codes(found, "OFB002") if "OFB201" in f.message]


def test_ofb201_no_acks_and_an_accepted_switch_is_not_checkable() -> None:
    found = lint_events([status(0.0, POSCTL), *ocm(every(0.0, 1.5, 0.1)), switch(1.5)])
    assert codes(found, "OFB201") == []
    assert [f for f in codes(found, "OFB002") if "OFB201" in f.message]


def test_ofb201_arm_in_predicted_offboard_without_a_recorded_mode() -> None:
    from fuzzoff.events import Command

    arm = Command(t=2.0, command=400, params=(1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0))
    # disarmed switch without a stream is accepted on 1.15; the arm is rejected (gate spec 4.2)
    events = [switch(1.0), ack(1.01, 0), arm, ack(2.01, 1, command=400)]
    (found,) = codes(lint_events(events), "OFB201")
    assert "arm in OFFBOARD" in found.message


@pytest.mark.parametrize("mode_recorded", [True, False])
def test_ofb102_arm_in_offboard_with_or_without_a_recorded_mode(mode_recorded: bool) -> None:
    """Disarmed, switched to OFFBOARD, then armed after 0.2 s of stream: an offboard request
    with too little stream, whether OFFBOARD shows in a recorded status or only in the gate
    model's prediction from the acked switch."""
    arm = Command(t=3.0, command=400, params=(1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0))
    events = [switch(1.0), ack(1.005, 0), *ocm(every(2.8, 6.0, 0.1)), arm]
    events.append(ack(3.005, 0, command=400))
    if mode_recorded:
        events += [status(0.0, POSCTL, False), status(1.5, OFFBOARD, False), status(3.5, OFFBOARD)]
    found = [f for f in codes(lint_events(events), "OFB102") if "arm in OFFBOARD" in f.message]
    assert [f.time_s for f in found] == [3.0]
    assert "0.20 s" in found[0].message


def test_ofb101_a_gap_that_spans_the_switch_counts() -> None:
    # keep-alive stops at 1.0 s in POSCTL; the switch comes at 1.3 s; the stream resumes at 1.8 s
    events = [status(0.0, POSCTL), *ocm(every(0.0, 1.0, 0.1)), switch(1.3), ack(1.31, 0)]
    events += [status(1.32, OFFBOARD), *ocm(every(1.8, 3.0, 0.1))]
    (found,) = codes(lint_events(events), "OFB101")
    assert "across the switch" in found.message
    assert found.time_s == pytest.approx(1.0) and found.end_s == pytest.approx(1.8)


def test_ofb105_keepalives_out_of_time_order_do_not_break_the_check() -> None:
    # a recording not in time order (e.g. an MCAP read in file order) can step back in time
    times = every(0.0, 5.0, 0.1)
    events = [status(0.0, OFFBOARD), *ocm(times), *ocm([4.2])]
    info = RecordingInfo("stream", "mcap", kinds={e.kind for e in events})
    profile = Profile(px4="1.15", vehicle="mc", px4_detected=True, vehicle_detected=True)
    for batching in (True, False):
        found, _ = run_events(events, info, profile, Settings(), batching=batching)
        assert codes(found, "OFB105") == []


def test_ofb103_reports_each_loss_when_the_next_comes_before_the_recorded_answer() -> None:
    """Two losses 1.4 s apart, the recorded mode still OFFBOARD: the first waits up to 2.5 s
    for the recording's answer, and must not be dropped when the second one comes."""
    times = [*every(0.0, 1.0, 0.1), *every(2.2, 2.4, 0.1)]
    events = [status(0.0, OFFBOARD), *ocm(times), status(4.0, OFFBOARD)]
    found = codes(lint_events(events), "OFB103")
    # each at its failsafe: one iteration after the end of the loss window (2.0-2.1, 3.4-3.5 s)
    assert [round(f.time_s or 0.0, 1) for f in found] == [2.1, 3.5]
    assert all("recorded: still OFFBOARD" in f.message for f in found)


def test_ofb103_says_the_recording_has_no_mode_yet_rather_than_still_unknown() -> None:
    """A switch and an arm without acks, the stream lost, and the first status only after the
    loss's recorded-answer window: there is no recorded mode yet to compare, not an 'unknown'
    mode the vehicle stayed in."""
    arm = Command(t=0.6, command=400, params=(1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0))
    events = [*ocm(every(0.0, 2.0, 0.1)), switch(0.5), arm, *ocm(every(7.0, 8.0, 0.1))]
    (found,) = codes(lint_events([*events, status(9.0, POSCTL)]), "OFB103")
    assert "still unknown" not in found.message and "unknown" not in found.short
    assert found.message.endswith("recorded: no mode yet (no status names one before it)")
    assert "recorded: no mode yet" in found.short


@pytest.mark.parametrize("detected", [True, False])
def test_ofb202_says_an_assumed_release_may_be_the_cause(detected: bool) -> None:
    """A disarmed switch without a stream, refused: PX4 1.13 does that, the 1.15 the
    recording's missing version made fuzzoff assume accepts it. The disagreement says that
    the assumption may be why, and how to give the release; with a known release it does not."""
    events = [status(0.0, POSCTL, armed=False), switch(1.0), ack(1.01, 1)]
    events.append(status(2.0, POSCTL, armed=False))
    info = RecordingInfo("stream", "tlog", kinds={e.kind for e in events})
    profile = Profile(px4="1.15", vehicle="mc", px4_detected=detected, vehicle_detected=True)
    found, _ = run_events(events, info, profile, Settings())
    (disagrees,) = codes(found, "OFB202")
    assert ("assumed" in disagrees.message) is not detected
    assert ("may be the cause" in disagrees.message) is not detected
    if not detected:
        assert "--px4" in disagrees.message and "--vehicle" not in disagrees.message
        assert disagrees.short.endswith("; PX4 release assumed")


def test_ofb102_on_a_ulog_says_dropped_setpoints_are_no_keepalive_and_where_to_look() -> None:
    """A real PX4 1.16.2 ULog of a client streaming LOCAL_ENU setpoints, which PX4 drops: the
    log shows no keep-alive, which is what PX4 accepted, not what was sent."""
    found = lint_file(CORPORA / "sitl" / "enu_frame-1.16.2.ulg").findings
    (request,) = codes(found, "OFB102")
    assert request.short.startswith("switch to OFFBOARD with no keep-alive PX4 accepted")
    assert "coordinate_frame, type_mask or target" in request.message
    assert "the companion's side of the link" in request.message
    # where the stream as sent is recorded, the keep-alive is what was sent: no such note
    sent = [status(0.0, POSCTL), switch(1.0)]
    (plain,) = codes(lint_events(sent), "OFB102")
    assert "PX4 accepted" not in plain.short and "companion's side" not in plain.message
    (logged,) = codes(lint_events(sent, fmt="ulog"), "OFB102")
    assert "no keep-alive PX4 accepted" in logged.short


def test_ofb101_on_a_ulog_gap_px4_acts_on_says_the_log_holds_what_px4_accepted() -> None:
    sampled = {"control_mode": 0.1}
    lost = codes(lint_events(flying((2.0, 4.0)), fmt="ulog", sampled=sampled), "OFB101")
    assert lost and all("the companion's side of the link" in f.message for f in lost)
    short_gap = codes(lint_events(flying((2.0, 2.75)), fmt="ulog", sampled=sampled), "OFB101")
    assert short_gap and not any("companion's side" in f.message for f in short_gap)
    sent = codes(lint_events(flying((2.0, 4.0))), "OFB101")
    assert sent and not any("companion's side" in f.message for f in sent)
