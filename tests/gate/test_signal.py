"""Proof of life (gate spec section 2): thresholds around COM_OF_LOSS_T per profile.

Timing facts used (from the spec, not the model): 1.14+ evaluates the loss at ~10 Hz check
passes, so a gap of at least COM_OF_LOSS_T is seen at most 0.1 s late (2.1.3); recovery is
immediate. 1.13 counts COM_OF_LOSS_T from the first 10 ms Commander iteration without a message
(2.2). 1.11 compares the keep-alive's age with COM_OF_LOSS_T (default 0.5 s). legacy has a fixed
500 ms (2.3).
"""

from __future__ import annotations

import pytest

from fuzzoff.events import ControlMode
from tests.gate.streams import (
    TICK,
    in_offboard,
    loss_times,
    ocm,
    of,
    run,
    stream,
)

CHECK_SLACK = 0.1
"""2.1.3: the available -> lost transition can lag by up to one 10 Hz check pass."""


def _gap(px4: str, last: float, gap: float, **params: float) -> list[float]:
    events = [in_offboard(0.0), *stream(0.0, 1.0), ocm(last), ocm(round(last + gap, 6))]
    return loss_times(run(px4, events, params=params, t_end=last + gap))


@pytest.mark.parametrize("px4", TICK)
@pytest.mark.parametrize("timeout", [1.0, 0.5, 2.0])
def test_2_1_gap_just_under_timeout_never_loses(px4: str, timeout: float) -> None:
    """2.1: available iff now < newest + COM_OF_LOSS_T: a gap just under never loses."""
    assert _gap(px4, 1.0, timeout - 0.01, COM_OF_LOSS_T=timeout) == []


@pytest.mark.parametrize("px4", TICK)
@pytest.mark.parametrize("timeout", [1.0, 0.5, 2.0])
def test_2_1_silence_of_the_timeout_loses_within_one_check_period(px4: str, timeout: float) -> None:
    """2.1: lost when now - newest >= COM_OF_LOSS_T, seen at the next 10 Hz check pass, whose
    phase the recording does not show: the loss is the window from the timeout to one check
    period later, dated at its end."""
    events = [in_offboard(0.0), *stream(0.0, 1.0)]
    (lost,) = of("signal_lost", run(px4, events, params={"COM_OF_LOSS_T": timeout}, t_end=5.0))
    assert lost.t_earliest == pytest.approx(1.0 + timeout)
    assert lost.t == pytest.approx(1.0 + timeout + CHECK_SLACK)
    assert f"between {1.0 + timeout:.3f} and {1.1 + timeout:.3f} s" in lost.message


@pytest.mark.parametrize("px4", TICK)
def test_2_1_3_gap_just_over_between_check_passes_can_go_unseen(px4: str) -> None:
    """2.1.3: the loss waits for the next 10 Hz pass; a gap 0.01 s over the timeout is seen
    only if that pass falls in those 10 ms: the model takes no loss where the next keep-alive
    arrives inside the window (a tenth of the cases, within the evaluation slack)."""
    assert _gap(px4, 1.03, 1.01) == []


@pytest.mark.parametrize("px4", TICK)
@pytest.mark.parametrize("last", [1.0, 1.03, 1.07])
def test_2_1_3_gap_over_timeout_plus_slack_always_loses(px4: str, last: float) -> None:
    """2.1.3: a gap >= COM_OF_LOSS_T + one check period is always seen, at most 0.1 s late."""
    (lost,) = _gap(px4, last, 1.0 + CHECK_SLACK + 0.01)
    assert last + 1.0 <= lost <= last + 1.0 + CHECK_SLACK + 1e-9


@pytest.mark.parametrize("px4", TICK)
def test_2_1_3_recovery_is_immediate(px4: str) -> None:
    """2.1.3: the first good keep-alive after a loss clears the flag in the same iteration."""
    trs = run(px4, [in_offboard(), ocm(0.0), ocm(3.37)], t_end=3.5)
    back = of("signal_available", trs)[-1]
    assert back.t == pytest.approx(3.37)


@pytest.mark.parametrize("px4", TICK)
def test_2_1_zero_timeout_never_available(px4: str) -> None:
    """2.1: COM_OF_LOSS_T = 0 makes 'recent' always false: offboard can never be entered."""
    trs = run(px4, [ocm(0.0), ocm(0.05)], params={"COM_OF_LOSS_T": 0.0}, t_end=0.2)
    assert of("signal_available", trs) == []


@pytest.mark.parametrize("px4", TICK)
def test_2_1_newest_sample_without_flags_is_lost(px4: str) -> None:
    """2.1: only the newest sample counts: a fresh OCM with every flag false means lost."""
    events = [in_offboard(), ocm(0.0), ocm(0.1), ocm(0.2, position=False)]
    (lost,) = loss_times(run(px4, events, t_end=0.5))
    assert 0.2 <= lost <= 0.2 + CHECK_SLACK + 1e-9


@pytest.mark.parametrize(
    ("gap", "lost"), [(0.99, False), (1.0, False), (1.01, False), (1.03, True)]
)
def test_2_2_v113_hysteresis_counts_from_first_iteration_without_message(
    gap: float, lost: bool
) -> None:
    """2.2 (1.13): lost when no new OCM was seen for COM_OF_LOSS_T counted from the first 10 ms
    iteration without one: a gap must exceed the timeout by about one iteration."""
    assert bool(_gap("1.13", 1.0, gap)) is lost


def test_2_2_v113_zero_timeout_flickers_below_commander_rate() -> None:
    """2.2: with COM_OF_LOSS_T = 0 the signal drops on every iteration without a new message."""
    events = [in_offboard(), *[ocm(round(i * 0.05, 3)) for i in range(6)]]
    trs = run("1.13", events, params={"COM_OF_LOSS_T": 0.0}, t_end=0.3)
    assert len(loss_times(trs)) >= 4


def test_2_2_v113_flags_needed() -> None:
    """2.2: a new OCM counts only with at least one true flag."""
    events = [in_offboard(), ocm(0.0), *[ocm(0.1 * i, position=False) for i in range(1, 20)]]
    assert len(loss_times(run("1.13", events, t_end=2.0))) == 1


@pytest.mark.parametrize("px4", ["1.13", *TICK])
def test_2_1_a_fresh_keepalive_with_no_flag_is_lost_for_that_reason(px4: str) -> None:
    """2.1/2.2: an all-false OCM is a lost signal however fresh; the transition says so, not
    "keep-alive timeout" (the keep-alive kept arriving)."""
    events = [in_offboard(), ocm(0.0), *[ocm(0.1 * i, position=False) for i in range(1, 20)]]
    (lost,) = of("signal_lost", run(px4, events, t_end=2.0))
    assert "no flag set" in lost.message and "timeout" not in lost.message


@pytest.mark.parametrize(("gap", "lost"), [(0.49, False), (0.5, True), (0.51, True)])
def test_2_2_v111_age_against_default_half_second(gap: float, lost: bool) -> None:
    """2.2 (1.11): lost when the keep-alive's age >= COM_OF_LOSS_T (default 0.5 s)."""
    assert bool(_gap("1.11", 1.0, gap)) is lost


def test_2_2_v111_no_flag_condition() -> None:
    """2.2 (1.11): no flag or estimate conditions: an all-false OCM still keeps alive."""
    events = [in_offboard(), *[ocm(0.1 * i, position=False) for i in range(20)]]
    assert loss_times(run("1.11", events, t_end=1.9)) == []


@pytest.mark.parametrize(("gap", "lost"), [(0.49, False), (0.5, True), (0.51, True)])
@pytest.mark.parametrize("loss_t", [0.0, 2.0])
def test_2_3_legacy_fixed_500ms_whatever_com_of_loss_t(
    gap: float, lost: bool, loss_t: float
) -> None:
    """2.3: legacy's loss is a hard-coded 500 ms; COM_OF_LOSS_T does not move it."""
    assert bool(_gap("legacy", 1.0, gap, COM_OF_LOSS_T=loss_t)) is lost


def _stamped(t: float, sender_s: float) -> ControlMode:
    return ControlMode(t=t, position=True, sender_time_us=round(sender_s * 1e6))


@pytest.mark.parametrize("px4", TICK)
def test_2_1_1_frozen_sender_clock_loses_the_signal(px4: str) -> None:
    """2.1.1: PX4 judges the ROS 2 keep-alive by its own timestamp field: a sender clock that
    stops at 3.0 s makes every later OCM old once COM_OF_LOSS_T has passed."""
    events = [in_offboard(), *[_stamped(0.1 * i, min(0.1 * i, 3.0) + 1000.0) for i in range(60)]]
    (lost,) = of("signal_lost", run(px4, events, t_end=5.9))
    assert 4.0 <= lost.t <= 4.1 + 1e-9
    assert "timestamp" in (lost.reason or "")


@pytest.mark.parametrize("px4", TICK)
@pytest.mark.parametrize("offset", [0.0, 1000.0, -0.5])
def test_2_1_1_sender_clock_with_constant_offset_is_fresh(px4: str, offset: float) -> None:
    """2.1.1: stamps rewritten by the agent-PX4 offset (or clamped to now): a sender clock that
    runs with the recording's is fresh whatever its origin."""
    events = [in_offboard(), *[_stamped(0.1 * i, 0.1 * i + 5.0 + offset) for i in range(60)]]
    assert loss_times(run(px4, events, t_end=5.9)) == []


@pytest.mark.parametrize("px4", TICK)
def test_2_1_1_zero_timestamp_is_the_receive_time(px4: str) -> None:
    """2.1.1: a zero timestamp is replaced by the receive time: fresh."""
    events = [in_offboard(), *[_stamped(0.1 * i, 0.0) for i in range(60)]]
    assert loss_times(run(px4, events, t_end=5.9)) == []


def test_2_2_v113_ignores_the_timestamp() -> None:
    """2.2: v1.13's gate counts new messages; the timestamp field is not used."""
    events = [in_offboard(), *[_stamped(0.1 * i, 1000.0) for i in range(60)]]
    assert loss_times(run("1.13", events, t_end=5.9)) == []
