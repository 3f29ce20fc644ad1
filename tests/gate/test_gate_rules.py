"""OFB202, OFB701, OFB702 through the engine (rules.md; gate spec 5 and 12)."""

from __future__ import annotations

from pathlib import Path

import pytest

from fuzzoff.config import Settings
from fuzzoff.engine import run_events
from fuzzoff.events import Command, CommandAck, Event, Parameter
from fuzzoff.findings import Finding, Severity
from fuzzoff.gate import GateModel, GateTransition
from fuzzoff.profiles import Profile
from fuzzoff.recording import RecordingInfo
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
    assert "COM_OF_LOSS_T 0.5 s (set by the user)" in summary.message
    assert "COM_OBL_RC_ACT 3 (from the recording)" in summary.message
    assert "AUTO_RTL" in summary.message


@pytest.mark.parametrize(
    ("px4", "params", "chosen_by"),
    [
        ("1.15", {"COM_OBL_RC_ACT": 7.0}, "COM_OBL_RC_ACT 7"),
        ("1.17", {"NAV_RCL_ACT": 6.0}, "replaced by NAV_RCL_ACT 6 (Disarm)"),
    ],
)
def test_ofb701_a_disarm_names_the_parameter_that_chose_it(
    px4: str, params: dict[str, float], chosen_by: str
) -> None:
    """5.1: COM_OBL_RC_ACT 7 disarms; on 1.17 without RC a stick mode is replaced by the
    NAV_RCL_ACT action, which may be Disarm too (COM_OBL_RC_ACT is then 0, not 7)."""
    events = [flags(0.0, manual_control_signal_lost=True), in_offboard(), *stream(0.0, 1.0)]
    (summary,) = _lint(px4, events, "OFB701", **params)
    assert "will disarm" in summary.message and chosen_by in summary.message


def test_ofb701_once_and_only_for_vehicles_using_offboard() -> None:
    assert _lint("1.15", [status(0.0, POSCTL, True, POSCTL), *stream(0, 1)], "OFB701") == []
    events = [in_offboard(), *stream(0.0, 1.0), *stream(3.0, 4.0)]
    assert len(_lint("1.15", events, "OFB701")) == 1


def test_ofb702_return_without_global_position_degrades() -> None:
    """5.1: Return needs a global position and home: the chain goes on to Land."""
    events = [flags(0.0, global_position_valid=False), in_offboard(), *stream(0.0, 1.0)]
    (finding,) = _lint("1.15", events, "OFB702", COM_OBL_RC_ACT=3.0)
    assert "AUTO_RTL" in finding.message and "AUTO_LAND" in finding.message


@pytest.mark.parametrize(
    ("px4", "shown"),
    [
        ("1.16", "PX4 1.16 switches to it anyway"),
        ("1.17", "PX4 1.17 will switch to AUTO_RTL"),
        ("main", "PX4 main will switch to AUTO_RTL"),
    ],
)
def test_ofb702_stick_mode_without_rc(px4: str, shown: str) -> None:
    """5.1: 1.14-1.16 enter Position without manual control; 1.17 and main replace it by the
    NAV_RCL_ACT action (default 2, Return): either way not what COM_OBL_RC_ACT 0 asked for."""
    events = [flags(0.0, manual_control_signal_lost=True), in_offboard(), *stream(0.0, 1.0)]
    (finding,) = _lint(px4, events, "OFB702")
    assert shown in finding.message and "POSCTL" in finding.message


def test_ofb702_silent_with_manual_control() -> None:
    events = [flags(0.0, manual_control_signal_lost=False), in_offboard(), *stream(0.0, 1.0)]
    assert [px4 for px4 in ("1.16", "1.17", "main") if _lint(px4, events, "OFB702")] == []


def test_ofb702_without_a_loss_is_a_configuration_note() -> None:
    """rules.md: every SITL run and every autonomous setup has no RC; without a loss in the
    recording the fallback never ran: info."""
    events = [flags(0.0, manual_control_signal_lost=True), in_offboard(), *stream(0.0, 30.0)]
    for px4 in ("1.16", "1.17"):
        (finding,) = _lint(px4, events, "OFB702")
        assert finding.severity is Severity.INFO and "configuration note" in finding.message


def test_ofb702_is_an_error_when_a_loss_ran_the_fallback() -> None:
    events = [flags(0.0, manual_control_signal_lost=True), in_offboard()]
    events += [*stream(0.0, 5.0), *stream(8.0, 10.0)]  # 3 s of silence: the loss failsafe
    (finding,) = _lint("1.17", events, "OFB702")
    assert finding.severity is Severity.ERROR
    # dated as the gate dates the failsafe: the 10 Hz check window (its phase not recorded)
    assert "lost between 6.01 and 6.11 s" in finding.message and "fallback ran" in finding.message
    assert 6.0 <= (finding.time_s or 0) <= 6.2


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


# OFB202 only for differences that involve OFFBOARD (rules/OFB202.toml): the model does not model
# other modes' own rules (a NAV_TAKEOFF into AUTO_TAKEOFF, a rejected AUTO_MISSION).

LOITER, TAKEOFF, MISSION, OFFBOARD_NAV = 4, 17, 3, 14


def _gate(px4: str, events: list[Event]) -> list[GateTransition]:
    gate = GateModel(Profile(px4=px4, vehicle="mc"), {}, "")
    out: list[GateTransition] = []
    for event in sorted(events, key=lambda e: e.t):
        out += gate.feed(event)
    return out + gate.finish(events[-1].t + 1.0)


def _auto_takeoff() -> list[Event]:
    """pyulog's sample_px4_events.ulg in short: disarmed in AUTO_LOITER, an arm command, PX4
    runs AUTO_TAKEOFF (a NAV_TAKEOFF the model does not model); no offboard at all."""
    return [
        status(0.0, LOITER, False, LOITER),
        Command(t=14.932, command=400, params=(1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)),
        *(status(round(14.936 + 0.5 * k, 3), TAKEOFF, True, TAKEOFF) for k in range(12)),
        status(21.3, LOITER, True, LOITER),
    ]


def test_ofb202_silent_on_a_flight_that_never_uses_offboard() -> None:
    assert _lint("1.15", _auto_takeoff(), "OFB202") == []
    rows = [tr for tr in _gate("1.15", _auto_takeoff()) if tr.message.startswith("recorded:")]
    assert [tr.what for tr in rows] == ["mode"]
    assert "AUTO_TAKEOFF" in rows[0].message and "no OFFBOARD on either side" in rows[0].message


def test_ofb202_silent_on_a_rejected_switch_between_other_modes() -> None:
    events: list[Event] = [
        status(0.0, POSCTL, True, POSCTL),
        Command(t=1.0, command=176, params=(1.0, 4.0, 4.0, 0.0, 0.0, 0.0, 0.0)),
        CommandAck(t=1.01, command=176, result=2),
        *(status(1.5 + 0.5 * k, POSCTL, True, POSCTL) for k in range(4)),
    ]
    assert _lint("1.15", events, "OFB202") == []


def test_ofb202_still_reports_a_rejected_switch_to_offboard() -> None:
    """Armed with a live stream the model accepts the switch (4.1); the ack says denied."""
    events: list[Event] = [
        status(0.0, POSCTL, True, POSCTL),
        *stream(0.0, 3.0),
        Command(t=2.0, command=176, params=(1.0, 6.0, 0.0, 0.0, 0.0, 0.0, 0.0)),
        CommandAck(t=2.01, command=176, result=2),
        *(status(2.5 + 0.5 * k, POSCTL, True, POSCTL) for k in range(2)),
    ]
    (finding,) = _lint("1.15", events, "OFB202")
    assert "switch to OFFBOARD acked" in finding.message


def test_ofb202_still_reports_a_failsafe_from_offboard_the_vehicle_did_not_take() -> None:
    """The stream stops in OFFBOARD; the model runs the loss failsafe, the recording stays."""
    events: list[Event] = [
        in_offboard(),
        *stream(0.0, 1.0),
        *(status(0.5 * k, OFFBOARD_NAV, True, OFFBOARD_NAV) for k in range(1, 9)),
    ]
    (finding,) = _lint("1.15", events, "OFB202")
    assert "recorded: OFFBOARD" in finding.message and "POSCTL" in finding.message


def test_ofb701_once_per_vehicle_and_recording_for_a_bag_split_in_two_files(
    tmp_path: Path,
) -> None:
    """rules.md: OFB701 is context, once per vehicle and recording, not once per file part of
    a bag that ``ros2 bag record --max-bag-size`` split."""
    import json
    import shutil

    from ruamel.yaml import YAML

    from fuzzoff.formats.rosbag2.writer import write_rosbag2
    from tests.helpers import run_cli

    first = write_rosbag2(tmp_path / "a", [in_offboard(0.0), *stream(0.0, 4.9)])
    second = write_rosbag2(
        tmp_path / "b",
        [in_offboard(0.0), *stream(0.0, 5.0)],
        start_ns=1_700_000_005_000_000_000,
    )
    bag = tmp_path / "bag"
    bag.mkdir()
    shutil.copy(next(first.glob("*.db3")), bag / "bag_0.db3")
    shutil.copy(next(second.glob("*.db3")), bag / "bag_1.db3")
    yaml = YAML()
    meta = yaml.load((first / "metadata.yaml").read_text())
    info = meta["rosbag2_bagfile_information"]
    info["relative_file_paths"] = ["bag_0.db3", "bag_1.db3"]
    info["files"] = []
    with (bag / "metadata.yaml").open("w") as fh:
        yaml.dump(meta, fh)
    result = run_cli(["lint", str(bag), "--format", "json", "--px4", "1.15", "--vehicle", "mc"])
    (report,) = json.loads(result.stdout)["files"]
    summaries = [f for f in report["findings"] if f["code"] == "OFB701"]
    assert [f["severity"] for f in summaries] == ["info"]
