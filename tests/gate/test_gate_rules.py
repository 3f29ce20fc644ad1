"""OFB202, OFB701, OFB702 through the engine (rules.md; gate spec 5 and 12)."""

from __future__ import annotations

from fuzzoff.config import Settings
from fuzzoff.engine import run_events
from fuzzoff.events import Event, Parameter
from fuzzoff.findings import Finding
from fuzzoff.profiles import Profile
from fuzzoff.sources.base import RecordingInfo
from tests.gate.streams import flags, in_offboard, status, stream

POSCTL = 2


def _lint(px4: str, events: list[Event], code: str, **params: float) -> list[Finding]:
    events = sorted(events, key=lambda e: e.t)
    info = RecordingInfo("test", "mcap", kinds={e.kind for e in events})
    profile = Profile(px4=px4, vehicle="mc", px4_detected=True, vehicle_detected=True)
    settings = Settings(select=frozenset({code}), params=params)
    findings, _ = run_events(events, info, profile, settings)
    return [f for f in findings if f.code == code]


def test_ofb701_legacy_names_the_fixed_500ms() -> None:
    (summary,) = _lint("legacy", [in_offboard(), *stream(0.0, 1.0)], "OFB701")
    assert "500 ms" in summary.message and "POSCTL" in summary.message


def test_ofb701_names_where_each_value_comes_from() -> None:
    events = [Parameter(t=0.0, name="COM_OBL_RC_ACT", value=3.0), in_offboard(), *stream(0, 1)]
    (summary,) = _lint("1.15", events, "OFB701", COM_OF_LOSS_T=0.5)
    assert "COM_OF_LOSS_T 0.5 s (set on the command line)" in summary.message
    assert "COM_OBL_RC_ACT 3 (from the recording)" in summary.message
    assert "AUTO_RTL" in summary.message


def test_ofb701_once_and_only_for_vehicles_using_offboard() -> None:
    assert _lint("1.15", [status(0.0, POSCTL, True, POSCTL), *stream(0, 1)], "OFB701") == []
    events = [in_offboard(), *stream(0.0, 1.0), *stream(3.0, 4.0)]
    assert len(_lint("1.15", events, "OFB701")) == 1


def test_ofb702_return_without_global_position_degrades() -> None:
    """5.1: Return needs a global position and home: the chain goes on to Land."""
    events = [flags(0.0, global_position_valid=False), in_offboard(), *stream(0.0, 1.0)]
    (finding,) = _lint("1.15", events, "OFB702", COM_OBL_RC_ACT=3.0)
    assert "AUTO_RTL" in finding.message and "AUTO_LAND" in finding.message


def test_ofb702_stick_mode_without_rc_only_before_117() -> None:
    """5.1: 1.14-1.16 enter Position without manual control; 1.17 replaces it (no finding)."""
    events = [flags(0.0, manual_control_signal_lost=True), in_offboard(), *stream(0.0, 1.0)]
    assert _lint("1.16", events, "OFB702")
    assert _lint("1.17", events, "OFB702") == []


def test_ofb202_reports_once_per_episode() -> None:
    events = [in_offboard(), *stream(0.0, 1.0), *[in_offboard(2.5 + 0.5 * i) for i in range(6)]]
    (finding,) = _lint("1.15", events, "OFB202")
    assert "recorded: OFFBOARD" in finding.message and "PX4 1.15" in finding.message


def test_ofb202_not_checkable_without_recorded_mode() -> None:
    events = [*stream(0.0, 1.0)]
    info = RecordingInfo("test", "mcap", kinds={"control_mode"})
    profile = Profile(px4="1.15", vehicle="mc", px4_detected=True, vehicle_detected=True)
    findings, _ = run_events(
        events, info, profile, Settings(select=frozenset({"OFB202", "OFB002"}))
    )
    assert any(f.code == "OFB002" and "OFB202" in f.message for f in findings)
