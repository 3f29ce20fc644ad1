"""The loss failsafe's place in time on 1.14+ (gate spec 2.1.3) and the timeline's order.

Facts used (spec 2.1.3, Commander::run): the loss is detected at a ~10 Hz check pass, so within
one check period after the newest keep-alive is COM_OF_LOSS_T old; the failsafe reacts one
Commander iteration (10 ms) later, because handleModeIntentionAndFailsafe() runs before the
check block. A keep-alive that arrives after the check pass but before that iteration clears
the flag first (offboardControlCheck forces a check pass), so no failsafe is run. Where the
recording does not show PX4's pass, the loss is the window [timeout, timeout + 0.1 s], dated at
its end, and a keep-alive inside the window ends it with no loss. Whatever the events, ``feed``
never returns a transition earlier than one it returned before.
"""

from __future__ import annotations

import json
import random
from pathlib import Path

import pytest

from fuzzoff.events import ControlMode, Event, TrajectorySetpoint, VehicleStatus
from fuzzoff.formats.mcap.writer import write_mcap
from fuzzoff.gate import GateModel, GateTransition
from fuzzoff.profiles import Profile
from tests.gate.streams import (
    ALL,
    OFFBOARD,
    POSCTL,
    TICK,
    arm,
    in_offboard,
    ocm,
    of,
    status,
    stream,
    switch_offboard,
)
from tests.helpers import run_cli

ITERATION = 0.01


def _feed(px4: str, events: list[Event], t_end: float, **params: float) -> list[GateTransition]:
    """Feed in time order and check, call by call, that the timeline never goes back."""
    gate = GateModel(Profile(px4=px4, vehicle="mc"), params, "1")
    out: list[GateTransition] = []
    for event in sorted(events, key=lambda e: e.t):
        for tr in gate.feed(event):
            assert not out or tr.t >= out[-1].t - 1e-12, (out[-1], tr)
            out.append(tr)
    for tr in gate.finish(t_end):
        assert not out or tr.t >= out[-1].t - 1e-12, (out[-1], tr)
        out.append(tr)
    return out


WINDOW_END = 2.1
"""Newest keep-alive 1.0 s, COM_OF_LOSS_T 1 s: the loss window is 2.0-2.1 s."""


@pytest.mark.parametrize("px4", TICK)
def test_keepalives_exactly_the_timeout_apart_take_no_loss(px4: str) -> None:
    """Keep-alives exactly COM_OF_LOSS_T apart (the fuzz reproducer: 0.2 s): each arrives at
    the start of its loss window, before any check pass can see it: no loss, no failsafe, the
    vehicle stays in OFFBOARD."""
    events: list[Event] = [in_offboard(), *stream(0.0, 1.0, period=0.2)]
    trs = _feed(px4, events, 1.05, COM_OF_LOSS_T=0.2)
    assert of("signal_lost", trs) == []
    assert of("failsafe", trs) == []
    assert {tr.nav_state for tr in trs} <= {OFFBOARD, None}


@pytest.mark.parametrize("px4", TICK)
@pytest.mark.parametrize("inside", [0.0, 0.05, 0.099])
def test_keepalive_inside_the_window_takes_no_loss(px4: str, inside: float) -> None:
    """A keep-alive 0-99 ms into the window: PX4 flags a loss only if its pass fell before it
    (a phase the recording does not show); the model takes none."""
    events: list[Event] = [in_offboard(), *stream(0.0, 1.0), ocm(round(2.0 + inside, 6))]
    trs = _feed(px4, events, 2.5)
    assert of("signal_lost", trs) == []
    assert of("failsafe", trs) == []


@pytest.mark.parametrize("px4", TICK)
@pytest.mark.parametrize("late", [0.0, 0.004, 0.0099])
def test_keepalive_before_the_failsafe_iteration_prevents_it(px4: str, late: float) -> None:
    """Lost by the end of the window (2.1 s); a keep-alive at 2.1 s + ``late`` (< 10 ms)
    arrives before the failsafe iteration."""
    events: list[Event] = [in_offboard(), *stream(0.0, 1.0), ocm(round(WINDOW_END + late, 6))]
    trs = _feed(px4, events, 2.5)
    (lost,) = of("signal_lost", trs)
    assert (lost.t_earliest, lost.t) == (pytest.approx(2.0), pytest.approx(WINDOW_END))
    assert [tr.t for tr in of("signal_available", trs)][-1] == pytest.approx(WINDOW_END + late)
    assert of("failsafe", trs) == []
    assert of("offboard_resumed", trs) == []


@pytest.mark.parametrize("px4", TICK)
@pytest.mark.parametrize("late", [ITERATION, 0.05])
def test_keepalive_after_the_failsafe_iteration_comes_too_late(px4: str, late: float) -> None:
    """A keep-alive at or after the failsafe iteration (window end + 10 ms): the failsafe ran
    (5.1: POSCTL by default), dated by its own window, and the vehicle returns to OFFBOARD at
    the keep-alive."""
    events: list[Event] = [in_offboard(), *stream(0.0, 1.0), ocm(round(WINDOW_END + late, 6))]
    trs = _feed(px4, events, 2.5)
    (failsafe,) = of("failsafe", trs)
    assert failsafe.t == pytest.approx(WINDOW_END + ITERATION)
    assert failsafe.t_earliest == pytest.approx(2.0 + ITERATION)
    assert failsafe.nav_state == POSCTL
    assert "between 2.010 and 2.110 s" in failsafe.message
    (resumed,) = of("offboard_resumed", trs)
    assert resumed.t == pytest.approx(WINDOW_END + late)
    assert resumed.t >= failsafe.t


@pytest.mark.parametrize("px4", TICK)
def test_other_events_in_the_window_do_not_run_the_failsafe_early(px4: str) -> None:
    """A setpoint and a recorded status still in OFFBOARD between the window's end and the
    failsafe iteration change nothing: the failsafe still comes at the iteration."""
    events: list[Event] = [
        in_offboard(),
        *stream(0.0, 1.0),
        TrajectorySetpoint(t=2.103, position=(0.0, 0.0, -2.0)),
        status(2.105, OFFBOARD, True, OFFBOARD),
    ]
    trs = _feed(px4, events, 3.0)
    (failsafe,) = of("failsafe", trs)
    assert failsafe.t == pytest.approx(WINDOW_END + ITERATION)


@pytest.mark.parametrize("px4", TICK)
@pytest.mark.parametrize(("end", "losses"), [(2.05, 0), (2.105, 1)])
def test_recording_ending_inside_the_window_runs_no_failsafe(
    px4: str, end: float, losses: int
) -> None:
    """Nothing after the recording's end: inside the loss window nothing is decided yet; after
    it, the loss but no failsafe yet."""
    trs = _feed(px4, [in_offboard(), *stream(0.0, 1.0)], end)
    assert len(of("signal_lost", trs)) == losses
    assert of("failsafe", trs) == []


def _random_session(rng: random.Random) -> list[Event]:
    events: list[Event] = [status(0.0, POSCTL, False, POSCTL)]
    t = 0.0
    while t < 6.0:
        t = round(t + rng.choice([0.05, 0.1, 0.2, 0.3, 0.5, 0.9, 1.0, 1.1, 1.3]), 3)
        events.append(ocm(t))
        if rng.random() < 0.05:
            events.append(switch_offboard(round(t + rng.choice([0.0, 0.005, 0.01]), 3)))
        if rng.random() < 0.05:
            events.append(arm(round(t + rng.choice([0.0, 0.005, 0.01]), 3)))
        if rng.random() < 0.1:
            nav = rng.choice([OFFBOARD, POSCTL])
            events.append(status(round(t + 0.007, 3), nav, True, None))
    return events


@pytest.mark.parametrize("px4", ALL)
@pytest.mark.parametrize("seed", range(12))
@pytest.mark.parametrize("timeout", [0.2, 0.5, 1.0])
def test_feed_never_goes_back_in_time(px4: str, seed: int, timeout: float) -> None:
    """Keep-alive gaps around COM_OF_LOSS_T, switches, arms and recorded statuses at and just
    after check passes: every profile's timeline stays in time order."""
    events = _random_session(random.Random(seed))
    _feed(px4, events, 7.0, COM_OF_LOSS_T=timeout)


def test_gate_command_output_is_in_time_order(tmp_path: Path) -> None:
    """``fuzzoff gate`` on a ROS 2 recording with keep-alives exactly COM_OF_LOSS_T apart:
    rows in time order and no failsafe PX4 would not run."""
    events: list[Event] = [
        VehicleStatus(t=0.0, vehicle="1", nav_state=OFFBOARD, armed=True, user_intention=14),
    ]
    events += [
        ControlMode(t=round(0.2 * k, 3), vehicle="1", position=True, origin="sent")
        for k in range(11)
    ]
    path = write_mcap(tmp_path / "exact.mcap", events, release="1.16")
    args = ["gate", str(path), "--px4", "1.16", "--vehicle", "mc", "--param", "COM_OF_LOSS_T=0.2"]
    result = run_cli([*args, "--format", "json"])
    assert result.returncode == 0, result.stdout + result.stderr
    rows = json.loads(result.stdout)["files"][0]["vehicles"][0]["timeline"]
    times = [r["time_s"] for r in rows]
    assert times == sorted(times)
    assert not [r for r in rows if r["what"] == "failsafe"]


@pytest.mark.parametrize("px4", TICK)
def test_lagging_timestamp_brings_the_loss_forward(px4: str) -> None:
    """2.1.1: a ROS 2 keep-alive whose own timestamp lags makes PX4 see an older sample. The
    first stamped keep-alive (1.0 s) sets the clock offset; one received at 1.95 s stamped
    1.55 s expires at 2.05 s, seen within the next check period, even though an earlier
    unstamped keep-alive (1.9 s) would have lasted until 2.4 s. The next keep-alive (2.2 s)
    ends it."""

    def sent(t: float, stamp_s: float) -> ControlMode:
        return ControlMode(t=t, position=True, origin="sent", sender_time_us=round(stamp_s * 1e6))

    events: list[Event] = [in_offboard(), *stream(0.0, 0.9)]
    events += [sent(1.0, 1.0), ocm(1.3), ocm(1.6), ocm(1.9), sent(1.95, 1.55), sent(2.2, 0.0)]
    trs = _feed(px4, events, 2.5, COM_OF_LOSS_T=0.5)
    (lost,) = of("signal_lost", trs)
    assert (lost.t_earliest, lost.t) == (pytest.approx(2.05), pytest.approx(2.15))
    (failsafe,) = of("failsafe", trs)
    assert failsafe.t == pytest.approx(2.15 + ITERATION)
    assert [tr.t for tr in of("signal_available", trs)][-1] == pytest.approx(2.2)
