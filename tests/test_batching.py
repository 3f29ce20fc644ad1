"""Checks that take the stream as runs (``on_batch``) must report what they report when given
one message at a time: compared on every corpus recording and on generated streams."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from fuzzoff import engine, releases
from fuzzoff.checks.base import STREAM_TYPES
from fuzzoff.cli import build_parser
from fuzzoff.commands._common import settings_from_args
from fuzzoff.engine import VehicleRun, lint_file
from fuzzoff.events import Event
from fuzzoff.fuzz.properties import FuzzContext, runs_match_single_messages
from fuzzoff.fuzz.scenario import Scenario
from fuzzoff.fuzz.streams import scenarios

CORPORA = Path(__file__).resolve().parent.parent / "corpora"
EXPECTED = sorted(CORPORA.rglob("*.expected.json"))


@pytest.mark.parametrize("short_runs", ["every run as a run", "short runs one at a time"])
@pytest.mark.parametrize(
    "expected_file", EXPECTED, ids=[str(p.relative_to(CORPORA)) for p in EXPECTED]
)
def test_corpus_findings_are_the_same_as_runs_and_one_at_a_time(
    expected_file: Path, short_runs: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Batching gives what one message at a time gives: with every run handed over as a run,
    and as a lint runs (short runs one message at a time, ``engine.SHORT_RUNS``)."""
    if short_runs == "every run as a run":
        monkeypatch.setattr(engine, "SHORT_RUNS", 0.0)
    spec = json.loads(expected_file.read_text())
    recording = expected_file.parent / spec["recording"]
    args = build_parser("lint").parse_args(["lint", str(recording), *spec.get("args", [])])
    lint_settings = settings_from_args(args)
    single = lint_file(recording, lint_settings, batching=False)
    runs = lint_file(recording, lint_settings, batching=True)
    assert runs.findings == single.findings


def _runs_handed_over(recording: Path, monkeypatch: pytest.MonkeyPatch) -> tuple[int, int]:
    """(runs handed to the checks as runs, stream messages) in a lint of ``recording``."""
    counted = [0, 0]
    flush, feed = VehicleRun._flush, VehicleRun.feed

    def counting_flush(run: VehicleRun) -> None:
        counted[0] += run._batch is not None
        flush(run)

    def counting_feed(run: VehicleRun, event: Event) -> None:
        counted[1] += type(event) in STREAM_TYPES
        feed(run, event)

    monkeypatch.setattr(VehicleRun, "_flush", counting_flush)
    monkeypatch.setattr(VehicleRun, "feed", counting_feed)
    lint_file(recording)
    return counted[0], counted[1]


def test_a_stream_between_status_messages_goes_one_message_at_a_time(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """PX4's ULog logs its status, flags and positions between every one or two setpoints: a
    run there would cost more than it saves. A companion's own stream (ROS 2 bag) runs long,
    and goes as runs."""
    ulog = CORPORA / "sitl" / "hold_with_unknown_sub_mode-1.16.2.ulg"
    runs, messages = _runs_handed_over(ulog, monkeypatch)
    assert messages > 100
    assert runs < messages / 20
    bag = next(p for p in sorted((CORPORA / "examples").rglob("*.mcap")))
    runs, messages = _runs_handed_over(bag, monkeypatch)
    assert messages > 100
    assert 0 < runs < messages / 8


def test_runs_are_used_on_the_hot_path() -> None:
    """The equivalence above only means something if checks do take runs."""
    from fuzzoff.config import Settings
    from fuzzoff.profiles import Profile
    from fuzzoff.recording import RecordingInfo

    for kinds in ({"offboard_control_mode", "trajectory_setpoint"}, {"set_position_target_local"}):
        info = RecordingInfo("x", "mcap", kinds=set(kinds))
        profile = Profile(px4="1.15", vehicle="mc", px4_detected=True, vehicle_detected=True)
        run = VehicleRun("1", profile, Settings(), info, None)
        assert run.batched, kinds


@pytest.mark.parametrize(("px4", "vehicle"), [("1.17", "rover-differential"), ("legacy", "mc")])
def test_every_check_that_wants_stream_messages_takes_them_as_runs(px4: str, vehicle: str) -> None:
    """One way for keep-alives and setpoints to reach a check: the checks without a fast pass of
    their own (the rover and legacy rules) get the runs replayed through ``on_event``."""
    from fuzzoff.checks.base import STREAM_TYPES, Check
    from fuzzoff.config import Settings
    from fuzzoff.profiles import Profile
    from fuzzoff.recording import RecordingInfo

    info = RecordingInfo("x", "mcap", kinds={"offboard_control_mode", "trajectory_setpoint"})
    profile = Profile(px4=px4, vehicle=vehicle, px4_detected=True, vehicle_detected=True)
    run = VehicleRun("1", profile, Settings(), info, None)
    wanting = [c for c in run.checks if any(issubclass(t, c.subscriptions) for t in STREAM_TYPES)]
    assert run.batched == wanting
    replaying = {type(c).__name__ for c in wanting if type(c).on_batch is Check.on_batch}
    expected = {"RoverCombination", "RoverTrajectory"} if vehicle != "mc" else set()
    assert expected <= replaying
    if px4 == "legacy":
        assert "LegacyAccelerationNotIgnored" in replaying


@pytest.mark.parametrize("px4", releases.names())
@settings(max_examples=40, deadline=None, suppress_health_check=list(HealthCheck), derandomize=True)
@given(data=st.data())
def test_generated_streams_give_the_same_findings_as_runs(px4: str, data: st.DataObject) -> None:
    scenario: Scenario = data.draw(scenarios(px4, None, None))
    problems = runs_match_single_messages(scenario, FuzzContext())
    assert not problems, problems
