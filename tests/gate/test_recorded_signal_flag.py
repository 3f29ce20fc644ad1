"""PX4's own verdict on the signal (``failsafe_flags.offboard_control_signal_lost``, gate spec
2.1 and 5.1 "Logs") against the model's, beyond the evaluation slack (2.1.3: >= 110 ms on
1.14+; rules/OFB202.toml). Judged while OFFBOARD is selected."""

from __future__ import annotations

import pytest

from fuzzoff.config import Settings
from fuzzoff.engine import run_events
from fuzzoff.events import Event, FailsafeFlags
from fuzzoff.findings import Finding
from fuzzoff.profiles import Profile
from fuzzoff.recording import RecordingInfo
from tests.gate.streams import POSCTL, TICK, in_offboard, status, stream


def _lint(px4: str, events: list[Event]) -> list[Finding]:
    events = sorted(events, key=lambda e: e.t)
    info = RecordingInfo("test", "ulog", kinds={e.kind for e in events})
    profile = Profile(px4=px4, vehicle="mc", px4_detected=True, vehicle_detected=True)
    findings, _ = run_events(events, info, profile, Settings(select=frozenset({"OFB202"})))
    return [f for f in findings if f.code == "OFB202"]


def _lost(t: float, lost: bool) -> FailsafeFlags:
    return FailsafeFlags(t=t, offboard_control_signal_lost=lost)


def _flags(t0: float, t1: float, lost_from: float | None) -> list[Event]:
    """Flags at 10 Hz, lost from ``lost_from`` on (never if None)."""
    n = round((t1 - t0) / 0.1)
    out: list[Event] = []
    for k in range(n + 1):
        t = round(t0 + 0.1 * k, 3) + 0.005
        out.append(_lost(t, lost_from is not None and t >= lost_from))
    return out


def _flight(lost_from: float | None) -> list[Event]:
    """Armed in OFFBOARD, keep-alive until 1.0 s (the model loses it at the 2.0 s pass); the
    recorded status follows the failsafe, so only the flag can differ."""
    events: list[Event] = [in_offboard(), *stream(0.0, 1.0)]
    events += [status(2.05 + 0.5 * k, POSCTL, True, 14) for k in range(3)]
    return events + _flags(0.0, 3.0, lost_from)


@pytest.mark.parametrize("px4", TICK)
@pytest.mark.parametrize("lost_from", [1.95, 2.0, 2.1])
def test_flag_within_the_slack_agrees(px4: str, lost_from: float) -> None:
    assert _lint(px4, _flight(lost_from)) == []


@pytest.mark.parametrize("px4", TICK)
def test_flag_that_stays_available_is_a_disagreement(px4: str) -> None:
    (finding,) = _lint(px4, _flight(None))
    assert "offboard_control_signal_lost false" in finding.message
    assert "model: offboard signal lost" in finding.message
    assert 2.0 <= finding.time_s <= 2.25


@pytest.mark.parametrize("px4", TICK)
def test_flag_lost_too_early_is_a_disagreement(px4: str) -> None:
    """PX4 says lost at 1.5 s while the newest keep-alive (1.0 s) is 0.5 s old (timeout 1 s)."""
    (finding,) = _lint(px4, _flight(1.5))
    assert "offboard_control_signal_lost true at 1.50 s" in finding.message
    assert "model: offboard signal available" in finding.message


def test_not_judged_outside_offboard() -> None:
    """A POSCTL flight: the flag only matters to a switch request (judged by the acks)."""
    events: list[Event] = [status(0.0, POSCTL, True, POSCTL), *stream(0.0, 1.0)]
    events += _flags(0.0, 3.0, None)
    assert _lint("1.15", events) == []
