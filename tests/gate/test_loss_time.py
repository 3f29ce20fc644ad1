"""When PX4 declares the loss, and which times the findings quote (issue 18; gate spec 2.1.3).

PX4 checks the keep-alive at 10 Hz, so it flags the loss between COM_OF_LOSS_T and one check
period later (1.000-1.077 s after the last keep-alive on 1.15.4 and 1.18.0-alpha1 SITL). The
phase of that check comes from the recording where PX4's flag or a status on change shows it;
otherwise the loss is that window. Findings quote the recorded change where the recording shows
it (the first sample with the new mode), "between A and B" where the mode is sampled at 1 Hz.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import pytest

from fuzzoff.config import Settings
from fuzzoff.engine import lint_file, run_events
from fuzzoff.events import CommandAck, ControlMode, Event, FailsafeFlags, SetPositionTargetLocal
from fuzzoff.findings import Finding
from fuzzoff.formats.tlog.writer import write_tlog
from fuzzoff.profiles import Profile
from fuzzoff.recording import RecordingInfo
from tests.gate.streams import (
    OFFBOARD,
    POSCTL,
    TICK,
    arm,
    in_offboard,
    of,
    run,
    status,
    stream,
    switch_offboard,
)


def _flag(t: float, lost: bool) -> FailsafeFlags:
    return FailsafeFlags(t=t, offboard_control_signal_lost=lost)


def _logged(events: list[ControlMode]) -> list[Event]:
    """As a ULog holds them: PX4's own copies."""
    return [replace(e, origin="vehicle") for e in events]


@pytest.mark.parametrize("px4", TICK)
@pytest.mark.parametrize("flip", [2.0, 2.046, 2.099])
def test_pxs_flag_dates_the_loss(px4: str, flip: float) -> None:
    """The flag flips at PX4's check pass: the loss is then, the failsafe one iteration after."""
    events = [in_offboard(), *stream(0.0, 1.0), _flag(0.5, False), _flag(flip, True)]
    trs = run(px4, events, t_end=3.0)
    (lost,) = of("signal_lost", trs)
    assert lost.t == pytest.approx(flip) and lost.t_earliest is None
    assert lost.seen_in == "PX4's failsafe_flags"
    assert "the model's window 2.000-2.100 s" in lost.message
    (failsafe,) = of("failsafe", trs)
    assert failsafe.t == pytest.approx(flip + 0.01)


@pytest.mark.parametrize("px4", TICK)
def test_a_logged_keepalive_lets_the_flag_come_one_logging_interval_later(px4: str) -> None:
    """A ULog logs offboard_control_mode at 10 Hz: the stream may have gone on up to 0.1 s past
    the last logged sample, so PX4's flag may flip after the model's window."""
    flags = [_flag(0.5 * k, False) for k in range(1, 4)]  # PX4 publishes it every ~0.5 s
    events = [in_offboard(), *_logged(stream(0.0, 1.0)), *flags, _flag(2.17, True)]
    (lost,) = of("signal_lost", run(px4, events, t_end=3.0))
    assert lost.t == pytest.approx(2.17) and lost.seen_in == "PX4's failsafe_flags"


@pytest.mark.parametrize("px4", TICK)
def test_without_the_flag_the_loss_is_the_window(px4: str) -> None:
    events = [in_offboard(), *stream(0.0, 1.0)]
    (lost,) = of("signal_lost", run(px4, events, t_end=3.0))
    assert (lost.t_earliest, lost.t) == (pytest.approx(2.0), pytest.approx(2.1))
    assert "the check's phase is not in the recording" in lost.message


@pytest.mark.parametrize("px4", TICK)
def test_a_status_on_change_dates_the_loss(px4: str) -> None:
    """The failsafe in a status published on change (ULog/ROS 2 vehicle_status) inside the
    window: the loss is no later than that."""
    events = [in_offboard(), *stream(0.0, 1.0), status(2.04, POSCTL, True, OFFBOARD)]
    trs = run(px4, events, t_end=3.0)
    (lost,) = of("signal_lost", trs)
    assert lost.t == pytest.approx(2.04) and lost.seen_in is not None
    (failsafe,) = of("failsafe", trs)
    assert failsafe.t == pytest.approx(2.04)


@pytest.mark.parametrize("px4", TICK)
def test_pxs_flag_says_available_before_the_first_logged_keepalive(px4: str) -> None:
    """The logger misses the first samples of offboard_control_mode (up to 104 ms on SITL): the
    signal is available when PX4's flag says so, not at the first logged sample."""
    events = [
        status(0.0, POSCTL, False, POSCTL),
        _flag(0.5, True),
        _flag(1.0, False),
        *_logged(stream(1.1, 2.0)),
    ]
    (available,) = of("signal_available", run(px4, events, t_end=2.0))
    assert available.t == pytest.approx(1.0)
    assert "PX4's failsafe_flags" in available.message


def _lint(px4: str, events: list[Event]) -> list[Finding]:
    events = sorted(events, key=lambda e: e.t)
    info = RecordingInfo("test", "ulog", kinds={e.kind for e in events})
    profile = Profile(px4=px4, vehicle="mc", px4_detected=True, vehicle_detected=True)
    findings, _ = run_events(events, info, profile, Settings(select=frozenset({"OFB103"})))
    return findings


@pytest.mark.parametrize("px4", TICK)
def test_ofb103_quotes_the_first_status_showing_the_change(px4: str) -> None:
    """Statuses every 0.5 s and on each change: PX4 changed mode at 6.06 s, inside the window
    of a stream that stopped at 5.05 s. OFB103 quoted the first status after its own predicted
    failsafe (6.50 s); it quotes 6.06 s."""
    events: list[Event] = [in_offboard(), *stream(0.0, 5.05, period=0.05)]
    events += [status(round(0.5 * k, 3), OFFBOARD, True, OFFBOARD) for k in range(1, 13)]
    events = [e for e in events if not (e.kind == "vehicle_status" and 6.0 < e.t < 8.0)]
    events += [status(6.06, POSCTL, True, OFFBOARD), status(6.5, POSCTL, True, OFFBOARD)]
    events += [status(7.0, POSCTL, True, OFFBOARD)]
    (finding,) = _lint(px4, events)
    assert "recorded: POSCTL at 6.06 s" in finding.message
    assert "lost by 6.06 s" not in finding.message  # the loss is quoted as PX4's record
    assert "at 6.06 s (PX4's failsafe recorded then)" in finding.message


@pytest.mark.parametrize("px4", TICK)
def test_ofb103_gives_the_window_where_the_recording_has_no_phase(px4: str) -> None:
    events: list[Event] = [in_offboard(), *stream(0.0, 5.0), status(7.0, POSCTL, True, OFFBOARD)]
    (finding,) = _lint(px4, events)
    assert "lost between 6.00 and 6.10 s (its 10 Hz check pass" in finding.message


def test_ofb103_says_between_for_a_heartbeat(tmp_path: Path) -> None:
    """A tlog's 1 Hz HEARTBEAT: the recorded change lies between the last one in OFFBOARD and
    the first one out of it."""
    events: list[Event] = [status(round(1.0 * k, 3), OFFBOARD, True, None) for k in range(7)]
    events += [status(7.0, POSCTL, True, None), status(8.0, POSCTL, True, None)]
    events += [
        SetPositionTargetLocal(
            t=round(0.05 * k, 3), type_mask=0b110111111000, target_system=1, target_component=1
        )
        for k in range(101)
    ]
    path = write_tlog(tmp_path / "loss.tlog", sorted(events, key=lambda e: e.t))
    report = lint_file(path, Settings(px4="1.15", vehicle="mc"))
    (finding,) = [f for f in report.findings if f.code == "OFB103"]
    assert "recorded: POSCTL between 6.00 and 7.00 s (mode sampled at 1 Hz)" in finding.message


@pytest.mark.parametrize("px4", TICK)
def test_a_loss_pxs_flag_does_not_show_is_the_models_alone(px4: str) -> None:
    """PX4's flag, published every 0.5 s, still says available past the window: the model's
    loss says so, and the flag's next sample is a disagreement."""
    flags = [_flag(round(0.5 * k, 3), False) for k in range(1, 7)]
    trs = run(px4, [in_offboard(), *stream(0.0, 1.0), *flags], t_end=3.0)
    (lost,) = of("signal_lost", trs)
    assert lost.seen_in is not None and "failsafe_flags shows no loss" in lost.seen_in
    assert of("disagreement", trs)


@pytest.mark.parametrize("px4", TICK)
def test_a_switch_logged_just_before_pxs_flag_is_judged_with_it(px4: str) -> None:
    """MAVSDK's set-then-start on SITL: the ULog has the switch at 6.552 s, PX4's flag turning
    available at 6.556 s and the ack ACCEPTED, but not the keep-alive (the logger missed it).
    Commander's forced check pass ran before it handled the command: the switch had a signal."""
    events: list[Event] = [
        status(0.0, POSCTL, True, POSCTL),
        _flag(0.5, True),
        switch_offboard(1.000),
        _flag(1.004, False),
        CommandAck(t=1.004, command=176, result=0),
        *_logged(stream(1.1, 2.0)),
    ]
    trs = run(px4, events, t_end=2.0)
    assert of("disagreement", trs) == []
    (accepted,) = of("request_accepted", trs)
    assert accepted.t == pytest.approx(1.004)


@pytest.mark.parametrize("px4", TICK)
def test_an_arm_while_only_pxs_flag_shows_the_signal_is_accepted(px4: str) -> None:
    """One setpoint, the switch, the arm (SITL, 1.17.0 and 1.18.0-alpha1): PX4's flag says
    available from 4.39 s while the first logged offboard_control_mode comes at 4.99 s; PX4
    armed at 4.64 s. The flag stands for the keep-alive's flags the log does not hold yet."""
    events: list[Event] = [
        status(0.0, POSCTL, False, POSCTL),
        _flag(0.5, True),
        _flag(4.392, False),
        switch_offboard(4.484),
        arm(4.636),
        CommandAck(t=4.644, command=400, result=0),
        *_logged(stream(4.992, 6.0)),
    ]
    trs = run(px4, events, t_end=6.0)
    assert of("arm_accepted", trs) and of("disagreement", trs) == []
