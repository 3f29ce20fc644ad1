"""Real PX4 over its ROS 2 bridge (``corpora/ros2bridge``): px4_ros_com's offboard_control
flown on PX4 1.16.2 and the 1.18 head through the Micro XRCE-DDS Agent (and an Ackermann
rover on its rover setpoints, 1.17.0 and the 1.18 head, and the standard VTOL through its
transition to FW, 1.16.2, 1.17.0 and the 1.18 head, issue 33), recorded as
``ros2 bag record`` records (mcap and sqlite3) beside PX4's ULog (issue 28 item 1).

- every *clean* recording lints with exit 0 and nothing at warning or above (where today's
  rules still say more, its expected file lists it under ``known_false``: a strict xfail);
- every *hazard* recording gives one of its error codes (where the recording cannot show it,
  its expected file says why under ``missed``: a strict xfail);
- the two storages of one flight give the same findings, and hold the same records;
- the bags hold what a ROS 2 recorder writes: CDR as received, schemas, the offered QoS.

The findings themselves are pinned by ``tests/test_corpora.py`` (``NAME.expected.json``).
"""

from __future__ import annotations

import functools
import json
from dataclasses import replace
from pathlib import Path
from typing import Any

import pytest
from rosbags.interfaces import QosDurability, QosReliability
from rosbags.rosbag2 import Reader

from fuzzoff.catalog import get_rule
from fuzzoff.config import Settings
from fuzzoff.engine import resolve_profile, run_events
from fuzzoff.events import (
    Command,
    CommandAck,
    Event,
    FailsafeFlags,
    TrajectorySetpoint,
    VehicleStatus,
)
from fuzzoff.findings import Severity
from fuzzoff.formats import open_source
from fuzzoff.profiles import Profile
from fuzzoff.recording import RecordingInfo
from tests.helpers import CORPORA, run_cli

HERE = CORPORA / "ros2bridge"
RUNS: dict[str, dict[str, Any]] = json.loads((HERE / "runs.json").read_text())
SPECS = sorted(
    p for p in HERE.glob("*.expected.json") if not p.name.endswith(".with.expected.json")
)
"""Each recording linted alone (``BAG.with.expected.json``: with its ULog, tests/test_bridge_with.py
and tests/test_corpora.py)."""


@functools.cache
def _lint(
    recording: Path, args: tuple[str, ...] = ()
) -> tuple[int, list[dict[str, Any]], dict[str, Any]]:
    out = run_cli(["lint", str(recording), *args, "--format", "json"])
    (report,) = json.loads(out.stdout)["files"]
    return out.returncode, report["findings"], report["profile"]


def _cases(kind: str) -> list[Any]:
    cases = []
    for path in SPECS:
        spec = json.loads(path.read_text())
        if spec["kind"] != kind:
            continue
        marks = []
        why = spec.get("missed") or spec.get("known_false")
        if why:
            marks.append(pytest.mark.xfail(strict=True, reason="; ".join(why)))
        cases.append(pytest.param(spec, id=spec["recording"], marks=marks))
    return cases


@pytest.mark.parametrize("spec", _cases("clean"))
def test_a_clean_bridge_flight_passes_with_nothing_above_info(spec: dict[str, Any]) -> None:
    code, findings, _ = _lint(HERE / spec["recording"], tuple(spec["args"]))
    loud = [f"{f['code']} {f['message']}" for f in findings if f["severity"] != "info"]
    assert code == 0 and not loud, loud


@pytest.mark.parametrize("spec", _cases("hazard"))
def test_a_hazard_bridge_flight_gives_its_error(spec: dict[str, Any]) -> None:
    """Its error, or its warning for a rule that warns (OFB501: the deprecated path)."""
    _, findings, _ = _lint(HERE / spec["recording"], tuple(spec["args"]))
    assert any(
        f["code"] in spec["hazard"] and f["severity"] == get_rule(f["code"]).severity.label
        for f in findings
    )


@pytest.mark.parametrize("stem", sorted(RUNS))
def test_both_storages_of_a_flight_hold_the_same_records_and_findings(stem: str) -> None:
    mcap, sqlite = HERE / f"{stem}-mcap", HERE / f"{stem}-sqlite3"
    with Reader(mcap) as a, Reader(sqlite) as b:
        assert [(c.topic, t, bytes(d)) for c, t, d in a.messages()] == [
            (c.topic, t, bytes(d)) for c, t, d in b.messages()
        ]
    strip = [[(f["code"], f["severity"], f["time_s"]) for f in _lint(p)[1]] for p in (mcap, sqlite)]
    assert strip[0] == strip[1]


@pytest.mark.parametrize("stem", sorted(s for s in RUNS if "in_only" not in s))
def test_the_release_of_a_bridge_bag_is_detected_from_its_topics(stem: str) -> None:
    profile = _lint(HERE / f"{stem}-mcap")[2]
    release = RUNS[stem]["release"]
    # a rover's status says rover, not which kind: differential is assumed (docs/ros2.md); a
    # standard VTOL's says VTOL (is_vtol) from the first status on, whatever it flies as, and
    # the airplane's fixed-wing
    kinds = {"rover": "rover-differential", "vtol": "vtol", "fw": "fw"}
    vehicle = kinds.get(stem.split("_")[0], "mc")
    assert profile["detected"] and profile["vehicle"] == vehicle
    # the 1.18 head's bags are 1.18, as its ULog says; main's too (its messages are 1.18's and
    # its builds report 1.18: docs/ros2.md); 1.17.0's are 1.17 (its ArmingCheckRequest has the
    # mask, its registration topics no _v2)
    expected = "1.18" if release.startswith("main-") else ".".join(release.split(".")[:2])
    assert profile["px4"] == expected


@pytest.mark.parametrize("stem", sorted(RUNS))
def test_a_bridge_bag_holds_what_a_ros2_recorder_writes(stem: str) -> None:
    with Reader(HERE / f"{stem}-sqlite3") as reader:
        connections = {c.topic: c for c in reader.connections}
        for topic, count in RUNS[stem]["counts"].items():
            if count:
                assert connections[topic].msgcount == count
        for topic, connection in connections.items():
            assert connection.msgtype.startswith("px4_msgs/msg/")
            assert connection.ext.serialization_format == "cdr"  # type: ignore[union-attr]
            assert "uint64 timestamp" in connection.msgdef.data
            # one profile per writer: the agent restarted mid-flight made PX4's writers again
            offered = connection.ext.offered_qos_profiles  # type: ignore[union-attr]
            assert 1 <= len(offered) <= (2 if "agent_restart" in stem else 1)
            for qos in offered:
                if topic.startswith("/fmu/out/"):  # PX4's bridge writers
                    assert qos.reliability == QosReliability.BEST_EFFORT
                    assert qos.durability == QosDurability.TRANSIENT_LOCAL
                else:  # the node's rclcpp publishers (depth 10)
                    assert qos.reliability == QosReliability.RELIABLE
                    assert qos.durability == QosDurability.VOLATILE
        first = next(iter(reader.messages()))
        assert bytes(first[2])[:4] == b"\x00\x01\x00\x00"  # CDR little endian, as sent


IN_ONLY = HERE / "example_in_only-1.16.2-ros2-mcap"


def test_a_bag_of_inputs_only_is_dated_from_its_schemas() -> None:
    """Issue 28 miss 5: its three /fmu/in messages are laid out alike from 1.15 on, but their
    definitions carry the MESSAGE_VERSION constant 1.16 added: 1.16 or later, never 1.15
    (nothing in the bag tells 1.16 from 1.17 or 1.18: OFB003 names them)."""
    _, findings, profile = _lint(IN_ONLY)
    assert not profile["detected"] and profile["px4"] in ("1.16", "1.17", "1.18")
    (assumed,) = [f["message"] for f in findings if f["code"] == "OFB003"]
    assert "fit 1.16 or 1.17 or 1.18" in assumed


def test_a_switch_one_second_into_the_stream_is_not_called_instant() -> None:
    """Issue 28 miss 5: the stream starts at the bag's first message (time 0.0)."""
    said = [f["summary"] for f in _lint(IN_ONLY)[1] if f["code"] == "OFB102"]
    assert said and not any("after 0.00 s" in m for m in said)


def _bag_events(recording: Path) -> tuple[list[Event], RecordingInfo, Profile]:
    """The events fuzzoff reads from a bridge recording, its info and detected profile, to
    lint a variant of the real flight (what PX4 did differently) with ``run_events``."""
    with open_source(recording) as source:
        info = source.probe()
        events = list(source.events())
    return events, info, resolve_profile(info, Settings())


def test_a_stream_through_a_landing_is_an_error_whatever_status_follows_the_disarm() -> None:
    """Issue 28 miss 1 on the real NAV_LAND flight: PX4 disarms after the landing and shows
    OFFBOARD again (its user intention), disarmed, while the stream goes on. The setpoints
    streamed into AUTO_LAND are no run-up to offboard."""
    events, info, profile = _bag_events(HERE / "example_lands-1.16.2-ros2-mcap")
    end = events[-1].t
    sent = [e for e in events if isinstance(e, TrajectorySetpoint)][-1]
    events += [
        VehicleStatus(t=end + 0.01, nav_state=14, armed=False),
        replace(sent, t=end + 0.1),
    ]
    findings, _ = run_events(events, info, profile, Settings())
    (land,) = [f for f in findings if f.code == "OFB203" and "AUTO_LAND" in f.summary]
    assert land.severity is Severity.ERROR and "fight" in land.summary


def _denied_arm(events: list[Event]) -> list[Event]:
    """The flight as PX4 answers the ARM with result 1 (issue 28 miss 2: 'Arming denied'):
    the ack says so and the vehicle stays disarmed; the rest as recorded."""
    out: list[Event] = []
    for event in events:
        if isinstance(event, CommandAck) and event.command == 400:
            event = replace(event, result=1)
        elif isinstance(event, VehicleStatus):
            event = replace(event, armed=False)
        out.append(event)
    return out


def test_an_arm_denied_right_after_the_switch_is_reported_before_offboard_shows() -> None:
    """Issue 28 miss 2 on the real example flight: DO_SET_MODE and ARM 0.4 ms apart, PX4's
    status shows OFFBOARD some 15 ms later; the arm's ack says denied."""
    events, info, profile = _bag_events(HERE / "example-1.16.2-ros2-mcap")
    arm = next(e for e in events if isinstance(e, Command) and e.is_arm)
    shown = next(e for e in events if isinstance(e, VehicleStatus) and e.nav_state == 14)
    assert arm.t < shown.t  # the arm goes before the status shows OFFBOARD
    findings, _ = run_events(_denied_arm(events), info, profile, Settings())
    (denied,) = [f for f in findings if f.code == "OFB201"]
    assert denied.severity is Severity.ERROR and "arm in OFFBOARD" in denied.summary


def test_the_gate_names_the_land_command_that_the_recorded_auto_land_follows() -> None:
    """Issue 28 miss 5: NAV_LAND and its ack are in the bag; the gate said 'no command for it'."""
    out = run_cli(["gate", str(HERE / "example_lands-1.16.2-ros2-mcap")])
    assert "no command for it" not in out.stdout
    assert "after NAV_LAND (21) at 9.59 s" in out.stdout


def test_the_gate_does_not_follow_a_disarmed_status_after_an_arm_that_never_arrived() -> None:
    """Issue 28 miss 3: the model took the ARM; PX4 never got it and the status stays disarmed.
    `fuzzoff gate` said the mode history agrees (the disarm adopted as 'no command for it')."""
    out = run_cli(["gate", str(HERE / "example_arm_lost-1.16.2-ros2-mcap")])
    assert out.returncode == 1 and "agrees" not in out.stdout
    assert "never armed since the arm request at 1.61 s" in out.stdout


def test_an_unanswered_command_is_not_judged_without_acks_in_the_recording() -> None:
    """A bag of /fmu/in topics only holds no answer at all: OFB208 says nothing there, and
    neither does it on the ULog, whose vehicle_command holds only what PX4 received."""
    for name in ("example_in_only-1.16.2-ros2-mcap", "example_arm_lost-1.16.2-ros2.ulg"):
        assert not [f for f in _lint(HERE / name)[1] if f["code"] == "OFB208"]


def test_a_bag_started_just_before_the_first_command_gives_no_false_disagreement() -> None:
    """Issue 28 miss 4's setting on the real late-started bag (0.16 s before DO_SET_MODE and
    ARM), with PX4's first failsafe_flags saying the signal is lost and AUTO_LOITER disarmed
    before them, as when PX4's agent had not matched the node's writers yet: PX4 accepted both
    (their acks): the model takes the recording's keep-alive and PX4's flag, no OFB202."""
    events, info, profile = _bag_events(HERE / "example_late_bag-1.16.2-ros2-mcap")
    events += [
        FailsafeFlags(t=0.10, offboard_control_signal_lost=True),
        VehicleStatus(t=0.10, nav_state=4, armed=False),
    ]
    findings, _ = run_events(sorted(events, key=lambda e: e.t), info, profile, Settings())
    assert not [f for f in findings if f.severity is not Severity.INFO]


@pytest.mark.parametrize("stem", sorted(s for s in RUNS if s.startswith("vtol_stops-")))
def test_the_gate_model_agrees_with_px4_on_each_vtol_loss_over_the_bridge(stem: str) -> None:
    """Issue 33: the standard VTOL's stream stops 3 s hovering in MC and 3 s in FW (in MC again
    on 1.16.2, whose transition quad-chutes back): the model, run on the bag, gives PX4's loss
    time, its failsafe action (Position on 1.16.2, Return on 1.17.0 and later: no manual
    control) and the return to OFFBOARD on resume, each time."""
    from fuzzoff.sitl.ros2.verdict import compare

    release = RUNS[stem]["release"].split("-")[0]
    verdict = compare(HERE / f"{stem}-mcap", release, HERE / f"{stem}.ulg", vehicle="vtol")
    assert not verdict.problems
    assert [(i.what, i.agree) for i in verdict.items] == [
        ("switch to OFFBOARD", True),
        ("arm", True),
        *[("loss time", True), ("failsafe action", True), ("automatic return", True)] * 2,
    ]
    action = "POSCTL" if release == "1.16.2" else "AUTO_RTL"
    assert [i.px4 for i in verdict.items if i.what == "failsafe action"] == [action, action]


def test_a_time_sync_jump_within_the_bridges_session_keeps_the_clock_on_px4s() -> None:
    """vtol_stops on main-2026-08-13: 23 s after its one logged time sync ("synchronized with
    time offset"), PX4's bridge client reset its time sync to an offset 232 ms away (SIH 0.8 %
    slower than the host, the client's estimate frozen on the old offset), logging no line:
    only its ``timesync_status`` shows it. PX4's outputs from then on carry the new offset.
    Read with the old one they paired with none of PX4's samples, the clock ran on past its
    last pair and was 0.1 s off PX4's by the FW stop, and that loss time "differed" (the model
    1.209 s after PX4's newest keep-alive, PX4 1.056 s). The jump is now a sync of its own."""
    from fuzzoff.bridge.bag import read_bag
    from fuzzoff.bridge.clock import pairs
    from fuzzoff.bridge.ulog import read_ulog
    from fuzzoff.sitl.ros2.verdict import STATUS, compare

    stem = "vtol_stops-main-2026-08-13"
    log = read_ulog(HERE / f"{stem}.ulg", STATUS)
    (logged_at, logged), (jump_at, jumped) = log.syncs
    assert jump_at - logged_at > 20e6 and abs(jumped - logged) > 200_000
    _, px4 = pairs(read_bag(HERE / f"{stem}-mcap"), log)
    assert (px4 > jump_at).sum() >= 10  # PX4's outputs after the jump are on the clock
    verdict = compare(HERE / f"{stem}-mcap", "main", HERE / f"{stem}.ulg", vehicle="vtol")
    losses = [i for i in verdict.items if i.what == "loss time"]
    assert len(losses) == 2 and all(i.agree for i in losses), [i.model for i in losses]
    assert losses[1].t > jump_at / 1e6


@pytest.mark.parametrize("stem", sorted(s for s in RUNS if s.startswith("fw_ground_gate-")))
def test_the_gate_model_judges_the_airplanes_disarm_by_the_land_detector_the_bag_holds(
    stem: str,
) -> None:
    """Issue 33: the airplane's gate on the ground over the bridge. PX4 refuses the plain
    disarm while it counts the rolling airplane as flying; the bag holds PX4's
    ``VehicleLandDetected`` (as a tlog holds EXTENDED_SYS_STATE), so the model refuses it too,
    then takes the forced one; where PX4's land detector had counted the rolling airplane
    landed again (main-2026-08-13), PX4 took the plain disarm, the model with it, and the node
    sent no forced one. The loss, its action and the return agree as well."""
    from fuzzoff.sitl.ros2.verdict import compare

    with Reader(HERE / f"{stem}-mcap") as reader:
        assert "/fmu/out/vehicle_land_detected" in {c.topic for c in reader.connections}
    release = RUNS[stem]["release"].split("-")[0]
    verdict = compare(HERE / f"{stem}-mcap", release, HERE / f"{stem}.ulg", vehicle="fw")
    forced_sent = any("forced DISARM" in note for _, note in RUNS[stem]["notes"])
    assert [(i.what, i.agree) for i in verdict.items] == [
        ("switch to OFFBOARD", True),
        ("arm", True),
        ("loss time", True),
        ("failsafe action", True),
        ("automatic return", True),
        *[("disarm", True)] * (2 if forced_sent else 1),
    ]
    plain, *forced = (i for i in verdict.items if i.what == "disarm")
    if forced_sent:
        assert plain.px4 == "rejected (1)" and "not landed" in plain.model
        assert forced[0].px4 == "accepted" and "forced" in forced[0].model
    else:
        assert plain.px4 == "accepted" and "landed since" in plain.model
