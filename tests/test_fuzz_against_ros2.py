"""``fuzzoff fuzz --against sitl:RELEASE --transport ros2``: the live campaign over PX4's ROS 2
bridge. Without PX4: the options it refuses, the stream it sends (the scenario's ``/fmu/in``
messages, on the bridge's topics, restamped and readdressed as sent), its report and its
reproducer. One short live campaign on the 1.18 head when a bundle with the bridge, cyclonedds
and a private network namespace (root, ``unshare``) are all here; skipped, saying which is
missing, otherwise."""

from __future__ import annotations

import contextlib
import json
import os
import time
import types
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from fuzzoff import events as ev
from fuzzoff.bridge.clock import Clock
from fuzzoff.fuzz import recordings
from fuzzoff.fuzz.scenario import Scenario
from fuzzoff.fuzz.strategies import CommandPlan
from fuzzoff.fuzz.streams import commands, echo, scenarios, settle
from fuzzoff.profiles import px4_profile_for
from fuzzoff.sitl import bundle
from fuzzoff.sitl.against import (
    AgainstConfig,
    AgainstResult,
    Campaign,
    Disagreement,
    Example,
    with_start,
)
from fuzzoff.sitl.against_report import to_json, to_terminal
from fuzzoff.sitl.verdict import Item, Verdict
from tests.helpers import run_cli, run_cli_process

LIVE_RELEASE = "1.18.0-beta1-head"
NO_BRIDGE = ("1.14.4", "1.15.4", "1.16.2", "1.17.0", "1.18.0-alpha1")
"""The bundles built without ``uxrce_dds_client``."""


# ------------------------------------------------------------------------- the command line


def _fake_bundle(root: Path, name: str, bridge: bool) -> None:
    """A folder ``find_build`` takes for a bundle (PX4 is never started here)."""
    (root / name / "bin").mkdir(parents=True)
    (root / name / "etc").mkdir()
    (root / name / "bin" / "px4").write_text("")
    modules = ["commander", "logger", *(["uxrce_dds_client"] if bridge else [])]
    (root / name / "bin" / "commands.txt").write_text("\n".join(f"px4-{m}" for m in modules))


def test_a_release_without_the_bridge_is_refused_in_one_line_naming_those_with_it(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    root = tmp_path / "bundles"
    _fake_bundle(root, "1.16.2", bridge=False)
    _fake_bundle(root, "1.16.2-ros2", bridge=True)
    monkeypatch.setenv("FUZZOFF_PX4_SITL", str(root))
    out = run_cli(
        ["fuzz", "--against", "sitl:1.16.2", "--transport", "ros2", "--budget", "60"],
        cwd=tmp_path,
    )
    assert out.returncode == 2
    lines = out.stderr.strip().splitlines()
    assert lines == [
        "error: --against sitl:1.16.2 --transport ros2: PX4 1.16.2 is built without the ROS 2"
        " bridge (uxrce_dds_client); bundles with it: 1.16.2-ros2"
    ], out.stderr
    assert not (tmp_path / ".fuzzoff").exists()


@pytest.mark.parametrize("release", NO_BRIDGE)
def test_each_bundle_without_the_bridge_is_refused_before_anything_starts(
    release: str, tmp_path: Path
) -> None:
    if release not in bundle.releases():
        pytest.skip(f"no bundle {release} in {bundle.default_root()}")
    out = run_cli(
        ["fuzz", "--against", f"sitl:{release}", "--transport", "ros2", "--budget", "60"],
        cwd=tmp_path,
    )
    assert out.returncode == 2
    (line,) = out.stderr.strip().splitlines()
    assert f"PX4 {release} is built without the ROS 2 bridge (uxrce_dds_client)" in line
    assert "bundles with it: 1.16.2-ros2" in line
    assert not out.stdout


def test_mavros_is_not_a_transport_a_live_campaign_sends(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    monkeypatch.setenv("FUZZOFF_PX4_SITL", str(tmp_path))
    out = run_cli(["fuzz", "--against", "sitl:1.18", "--transport", "mavros"], cwd=tmp_path)
    assert out.returncode == 2
    assert out.stderr.strip() == (
        "error: --transport mavros: --against sends MAVLink, or ROS 2 over PX4's bridge"
    )


# ------------------------------------------------------------------------- the stream sent


@pytest.mark.parametrize("release", ["1.16.2", "1.18.0"])
@settings(max_examples=15, deadline=None, suppress_health_check=list(HealthCheck))
@given(data=st.data())
def test_every_generated_stream_goes_out_on_the_bridges_own_topics(
    release: str, data: st.DataObject, tmp_path_factory: pytest.TempPathFactory
) -> None:
    """The campaign writes the stream with the rosbag2 writer and sends its /fmu/in messages
    (``plan_from_bag``): each one on a topic the release's bridge carries, one per message
    the companion sent, the starting status (PX4's side) left out."""
    from fuzzoff.sitl.ros2.bench import STREAMED
    from fuzzoff.sitl.ros2.names import NamesError, bridge_topic
    from fuzzoff.sitl.ros2.replay import ReplayError, plan_from_bag

    bridged = set()
    for message in STREAMED:
        with contextlib.suppress(NamesError):  # not in this release (rover setpoints)
            bridged.add(bridge_topic(release, message).ros_topic)
    profile = px4_profile_for(release.split("-")[0])
    scenario = data.draw(scenarios(profile, "mc", "ros2"))
    live = with_start(scenario)
    assert live.events[0].t >= 0.0  # a bag cannot hold a message before its start
    assert isinstance(live.events[0], ev.VehicleStatus) and not live.events[0].armed
    folder = tmp_path_factory.mktemp("stream") / "s"
    recordings.write(live, folder, "rosbag2")
    sent = [e for e in scenario.events if e.origin == "sent"]
    try:
        plan = plan_from_bag(folder, release)
    except ReplayError:
        assert not sent
        return
    assert {m.topic for m in plan.messages} <= bridged
    assert len(plan.messages) == len(sent)
    assert plan.messages[0].offset_s == 0.0
    assert plan.messages[-1].offset_s == pytest.approx(sent[-1].t - sent[0].t, abs=2e-6)


def test_stamps_keep_their_distances_per_topic_and_commands_go_to_the_px4_sent_to() -> None:
    """A keep-alive whose clock runs 1.96 s ahead and then stops (as fuzzoff's streams draw
    it) still stops once sent, its first stamp the sending time; commands stamped with the
    sending time keep it (not moved by the keep-alive's clock); 0 (PX4 stamps it on receipt)
    stays 0; a command to system 1 goes to PX4 instance 4 (system 5), a broadcast (0) stays."""
    from fuzzoff.sitl.ros2.flight import readdressed, stamp_shifts

    def sample(timestamp: int, target: int | None = None) -> types.SimpleNamespace:
        fields = {"timestamp": timestamp, "timestamp_sample": timestamp}
        addressed = {} if target is None else {"target_system": target}
        return types.SimpleNamespace(**fields, **addressed)

    ocm, command, setpoint = "/fmu/in/offboard_control_mode", "/fmu/in/vehicle_command", "sp"
    samples = [
        (setpoint, 0.0, sample(0)),
        (ocm, 0.0001, sample(1_958_093)),
        (command, 0.0003, sample(300, 1)),
        (ocm, 0.5001, sample(1_958_093)),
        (command, 16.6251, sample(16_625_100, 1)),
    ]
    start = 5_000_000_000
    shifts = stamp_shifts(samples, start)
    out = [readdressed(s, shifts.get(topic, 0), 5) for topic, _, s in samples]
    assert out[0].timestamp == 0 and out[0].timestamp_sample == 0
    assert out[1].timestamp == start + 100  # the keep-alive's first: its sending time
    assert out[3].timestamp == start + 100  # stopped, as sent: PX4 ages it
    assert out[2].timestamp == start + 300 and out[2].target_system == 5
    assert out[4].timestamp == start + 16_625_100  # the sending time, 16.6 s on
    assert readdressed(sample(7, 0), 0, 5).target_system == 0
    assert stamp_shifts([(ocm, 0.0, sample(0))], start) == {}


# ------------------------------------------------------------------------- report, reproducer


def _ros2_stream() -> Scenario:
    """A ROS 2 companion as the campaign draws them: 10 Hz keep-alive and setpoints for 2 s,
    arm and switch, the model's acks."""
    times = [round(0.1 * i, 4) for i in range(20)]
    flags = {"position": True, "layout": "thrust_and_torque"}
    sent: list[ev.Event] = []
    for t in times:
        sent.append(ev.ControlMode(t=t, sender_time_us=round(t * 1e6), **flags))  # type: ignore[arg-type]
        t1 = round(t + 0.001, 4)
        sent.append(
            ev.TrajectorySetpoint(t=t1, sender_time_us=round(t1 * 1e6), position=(0.0, 0.0, -2.0))
        )
    sent = settle(
        [*sent, *commands(CommandPlan(arm=0.5, switch=1.0, leave=None, disarm=None), "ros2")]
    )
    params = {"COM_OF_LOSS_T": 0.5}
    profile = px4_profile_for("1.18.0")
    answers = echo(sent, profile, "mc", params, acks=True, status=False, transport="ros2")
    return Scenario(profile, "mc", "ros2", tuple(settle([*sent, *answers])), params)


def _config(tmp_path: Path) -> AgainstConfig:
    return AgainstConfig(
        build=bundle.Build(tmp_path, LIVE_RELEASE),
        instance=4,
        save_dir=tmp_path / "out",
        transport="ros2",
    )


def _case(tmp_path: Path) -> Disagreement:
    exchange = tmp_path / "run.px4-mcap"
    exchange.mkdir()
    (exchange / "metadata.yaml").write_text("rosbag2_bagfile_information: {}\n")
    item = Item("arm", 12.5, "rejected (1)", "accepted: armed", False)
    verdict = Verdict("1.18.0", "ulog", [item])
    found = Example(2, _ros2_stream(), "differ", verdict=verdict, tlog=exchange)
    return Disagreement(found, True, found)


def test_the_report_says_the_transport_and_how_to_send_a_disagreement_over_dds(
    tmp_path: Path,
) -> None:
    result = AgainstResult(_config(tmp_path))
    case = _case(tmp_path)
    case.reproducer = tmp_path / "out" / "px4-x.expected.json"
    result.examples.append(case.found)
    result.disagreements.append(case)
    text = to_terminal(result)
    assert text.startswith(
        f"fuzzoff fuzz --against sitl:{LIVE_RELEASE} --vehicle quad --transport ros2, seed 0\n"
    )
    path = tmp_path / "out" / "px4-x.expected.json"
    assert (
        f"    again:     fuzzoff sitl replay {path} --transport ros2 --release {LIVE_RELEASE}\n"
        in text
    )
    data = json.loads(to_json(result))
    assert data["campaign"]["transport"] == "ros2"
    assert data["campaign"]["against"] == f"sitl:{LIVE_RELEASE}"
    assert data["verdicts"]["differ"] == 1


def test_a_disagreement_over_dds_is_saved_with_its_bag_and_replay_says_how_to_send_it(
    tmp_path: Path,
) -> None:
    pytest.importorskip("cyclonedds")
    case = _case(tmp_path)
    campaign = Campaign(_config(tmp_path), log=lambda line: None)
    campaign._save(case)
    assert case.reproducer is not None
    name = case.reproducer.name.removesuffix(".expected.json")
    assert name.startswith("px4-1.18-mc-ros2-")
    spec = json.loads(case.reproducer.read_text())
    assert spec["recording"] == f"{name}.mcap"
    assert spec["setup"]["params"] == {"COM_OF_LOSS_T": 0.5}
    against = spec["against"]
    assert against["transport"] == "ros2"
    assert against["exchange_bag"] == f"{name}.px4-mcap"
    assert "exchange_tlog" not in against
    assert (tmp_path / "out" / f"{name}.px4-mcap" / "metadata.yaml").exists()
    assert against["replay"] == (
        f"fuzzoff sitl replay NAME.expected.json --transport ros2 --release {LIVE_RELEASE}"
    )
    out = run_cli(["replay", str(case.reproducer)])
    assert out.returncode == 0, out.stdout + out.stderr
    assert f"against PX4 {LIVE_RELEASE} (confirmed): it and the model differed" in out.stdout
    assert (
        f"send it to PX4 over DDS again: fuzzoff sitl replay {case.reproducer} --transport ros2"
        f" --release {LIVE_RELEASE}"
    ) in out.stdout


def test_sitl_replay_over_dds_sends_a_ros2_reproducers_stream_with_its_parameters(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """``fuzzoff sitl replay NAME.expected.json --transport ros2``: the reproducer's MCAP, its
    setup's parameters (set at PX4's boot), and a line saying no manual control is sent."""
    from fuzzoff.fuzz.reproducers import save

    stream = _ros2_stream()
    stream = Scenario(
        stream.px4, "mc", "ros2", stream.events, {**stream.params, "FUZZOFF_RC_PRESENT": 1.0}
    )
    path = save("explained", with_start(stream), [], tmp_path / "out")
    _fake_bundle(tmp_path, "build", bridge=True)
    seen: dict[str, object] = {}

    def fake(recording: Path, build: object, save_dir: Path, log: object, params: object) -> object:
        seen.update(recording=recording, params=params)
        raise __import__("fuzzoff.sitl.ros2.run", fromlist=["x"]).FlightError("stop here")

    monkeypatch.setattr("fuzzoff.sitl.ros2.run.replay_bag", fake)
    args = [
        "sitl",
        "replay",
        str(path),
        "--transport",
        "ros2",
        "--px4-build",
        str(tmp_path / "build"),
    ]
    out = run_cli(args)
    assert out.returncode == 2 and "error: stop here" in out.stderr
    assert seen["recording"] == path.with_name(path.name.replace(".expected.json", ".mcap"))
    assert seen["params"] == {"COM_OF_LOSS_T": 0.5}
    assert "a ROS 2 replay sends none" in out.stderr


@pytest.mark.parametrize(
    ("name", "says"),
    [
        ("stream.tlog", "a ROS 2 replay takes a bag folder (metadata.yaml), an .mcap file or"),
        ("mav.expected.json", "a mavlink reproducer: replay it without --transport ros2"),
    ],
)
def test_sitl_replay_over_dds_refuses_what_it_cannot_send(
    name: str, says: str, tmp_path: Path
) -> None:
    from fuzzoff.fuzz.reproducers import save

    if name.endswith(".json"):
        from tests.test_fuzz_against import PLAN, TEN_HZ, _stream

        path = save("explained", _stream(TEN_HZ, PLAN), [], tmp_path)
    else:
        path = tmp_path / name
        path.write_bytes(b"")
    out = run_cli(["sitl", "replay", str(path), "--transport", "ros2", "--release", "1.18"])
    assert out.returncode == 2
    (line,) = out.stderr.strip().splitlines()
    assert says in line


# ------------------------------------------------------------------------- live


def _why_not() -> str | None:
    from fuzzoff.sitl.ros2.run import missing

    if LIVE_RELEASE not in bundle.releases():
        return f"no bundle {LIVE_RELEASE} in {bundle.default_root()} (set FUZZOFF_PX4_SITL)"
    return missing()


WHY_NOT = _why_not()


def _instance() -> int:
    """Not the MAVLink live tests' 2 and 3: PX4's lock file stays in the machine's /tmp."""
    return 5 if os.environ.get("PYTEST_XDIST_WORKER", "gw0") == "gw1" else 4


@pytest.mark.skipif(WHY_NOT is not None, reason=f"live ROS 2 campaign: {WHY_NOT}")
def test_a_live_campaign_over_the_bridge_sends_a_stream_over_dds_and_judges_it(
    tmp_path: Path,
) -> None:
    """One stream drawn, sent over DDS to the 1.18 head the campaign starts with its agent in a
    private network namespace, judged against PX4's ULog (about 40 s)."""
    saved = tmp_path / "reproducers"
    out = run_cli_process(
        [
            "fuzz",
            "--against",
            f"sitl:{LIVE_RELEASE}",
            "--transport",
            "ros2",
            "--examples",
            "1",
            "--shrink-runs",
            "0",
            "--seed",
            "0",
            "--instance",
            str(_instance()),
            "--save-dir",
            str(saved),
            "--format",
            "json",
        ],
        timeout=240,
    )
    assert out.returncode in (0, 1), out.stdout + out.stderr
    data = json.loads(out.stdout)
    assert data["campaign"]["transport"] == "ros2"
    assert data["streams_sent"] == 1
    (run, *_) = data["runs"]
    assert run["verdict"] is not None, run["reason"]
    assert run["delivery"] is not None
    # seed 0's first stream arms and switches: PX4 answered both over the bridge
    assert data["px4_outcomes"]["switch to OFFBOARD: accepted"] == 1
    assert data["px4_outcomes"]["arm: accepted"] == 1
    assert "fuzzoff: search 1:" in out.stderr
    if out.returncode == 1:
        assert list(saved.glob("px4-*-ros2-*.px4-mcap")), out.stderr
    else:
        assert not saved.exists()


def test_a_time_sync_jump_mid_stream_does_not_move_the_models_times() -> None:
    """A real exchange (the 1.18 head, COM_OF_LOSS_T 0.2, seed 0's campaign): PX4's bridge kept
    one time sync offset, then jumped to one 212 ms away (a simulated PX4 off the host's pace)
    after the stream. Each of PX4's outputs the bag holds is read with the offset in effect
    when PX4 published it; reading some with the later one paired them with the wrong samples
    and moved every model time 216 ms early (three loss times 'differed')."""
    from fuzzoff.sitl.ros2 import verdict as ros2_verdict

    bag, ulog, clock = _exchange_with_a_sync_jump("timesync_jump_mid_stream-1.18.0-beta1-head")
    assert clock.pairs >= 20 and clock.residual_us < 20_000
    verdict = ros2_verdict.compare(bag, "1.18.0", ulog, {"COM_OF_LOSS_T": 0.2})
    losses = [i for i in verdict.items if i.what == "loss time"]
    assert len(losses) >= 3
    assert all(i.agree for i in losses), [i.note for i in losses]
    assert not [i for i in verdict.items if i.agree is False]


def test_an_output_near_a_time_sync_jump_is_paired_by_its_own_offsets_distance() -> None:
    """A real exchange of the main-2026-08-13 campaign (COM_OF_LOSS_T 0.2, four losses):
    PX4's bridge jumped to a time sync offset 213 ms away near the stream's end, and an output
    published just before it could be read with either offset. The pairing compared the
    first offset's exact match (0 ms) with the second's time, 213 ms away, so the second's
    3 ms match won: the clock's residual rose to 12 ms and the last loss time 'differed' (the
    model 24 ms after PX4's newest keep-alive, PX4 240 ms). Each candidate is now judged by
    its distance from the time its own offset gives."""
    from fuzzoff.sitl.ros2 import verdict as ros2_verdict

    bag, ulog, clock = _exchange_with_a_sync_jump("timesync_jump_pairing-main-2026-08-13")
    assert clock.pairs >= 30 and clock.residual_us < 5_000
    verdict = ros2_verdict.compare(bag, "main", ulog, {"COM_OF_LOSS_T": 0.2})
    losses = [i for i in verdict.items if i.what == "loss time"]
    assert len(losses) == 4 and all(i.agree for i in losses), [i.model for i in losses]
    assert not [i for i in verdict.items if i.agree is False]


STALL = "sim_stall_offboard_disarmed-main-2026-08-13"
"""A stream of main-2026-08-13's ROS 2 campaign (seed 0): 20 s of keep-alives with no flag
set, DO_SET_MODE OFFBOARD disarmed. PX4 took the switch, and its SIH stopped the clock ("SIH
lockstep: timed out waiting for actuator_outputs_sim"): its log spans 0.6 s."""


def test_a_stream_on_which_mains_sih_stopped_px4s_clock_is_not_run_saying_why(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The campaign judged it and met an IndexError (no time sync and no pair in a log of
    0.6 s), which Hypothesis then hid as "Unreliable assumption". The stream is now not run,
    with the reason: PX4 ran nothing after its clock stopped."""
    pytest.importorskip("cyclonedds")
    from fuzzoff.sitl.bench import LiveRun

    exchanges = Path(__file__).resolve().parent.parent / "corpora" / "against" / "exchanges"
    bag, ulog = exchanges / f"{STALL}-mcap", exchanges / f"{STALL}.ulg"
    meant = [0.1 * i for i in range(201)]
    run = LiveRun(bag, ulog, meant, meant, {}, False, 0.0, [])
    campaign = Campaign(_config(tmp_path), log=lambda line: None)
    monkeypatch.setattr(campaign, "_exchange", lambda example, stem: run)
    example = Example(3, _ros2_stream(), "failed")
    campaign._send(example, tmp_path / "0003")
    assert example.status == "failed" and example.verdict is None
    assert example.reason is not None
    assert "PX4's simulated clock stopped" in example.reason
    assert "SIH lockstep: timed out" in example.reason
    assert "0.6 s of the 20.0 s sent" in example.reason


def test_a_bag_and_a_log_with_nothing_to_align_by_are_refused_in_one_line() -> None:
    """The stalled stream's log holds no time sync and none of PX4's outputs in the bag: the
    ROS 2 verdict says it cannot put the bag on PX4's clock (it raised an IndexError)."""
    from fuzzoff.bridge import BridgeError
    from fuzzoff.sitl.ros2 import verdict as ros2_verdict

    exchanges = Path(__file__).resolve().parent.parent / "corpora" / "against" / "exchanges"
    with pytest.raises(BridgeError, match="cannot be put on PX4's clock"):
        ros2_verdict.compare(exchanges / f"{STALL}-mcap", "main", exchanges / f"{STALL}.ulg")


def test_an_error_of_fuzzoffs_own_in_a_campaign_is_raised_as_it_is(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Hypothesis runs a failing example again to confirm it; the campaign then rejects it as a
    shape already sent and Hypothesis reported only "Unreliable assumption" (FlakyFailure),
    hiding the error. The error now ends the search and is raised itself."""
    pytest.importorskip("cyclonedds")
    campaign = Campaign(_config(tmp_path), log=lambda line: None)

    def send(scenario: Scenario, purpose: str) -> Example:
        raise IndexError("the error itself")

    monkeypatch.setattr(campaign, "send", send)
    campaign.started = time.monotonic()
    with pytest.raises(IndexError, match="the error itself"):
        campaign._search()


MATRIX = os.environ.get("FUZZOFF_SITL_MATRIX") == "1"
CAMPAIGN_RELEASES = ("1.16.2-ros2", "1.18.0-beta1-head")


@pytest.mark.skipif(WHY_NOT is not None, reason=f"live ROS 2 campaign: {WHY_NOT}")
@pytest.mark.skipif(not MATRIX, reason="the long campaigns run with make test-sitl")
@pytest.mark.parametrize("release", CAMPAIGN_RELEASES)
def test_a_campaign_over_the_bridge_judges_every_stream_it_sends(
    release: str, tmp_path: Path
) -> None:
    """Two minutes of streams over DDS on each bridge bundle: every stream sent is judged
    (none 'not run'), PX4 answered switches over the bridge, the campaign ran its course."""
    if release not in bundle.releases():
        pytest.skip(f"no bundle {release}")
    out = run_cli_process(
        [
            "fuzz",
            "--against",
            f"sitl:{release}",
            "--transport",
            "ros2",
            "--budget",
            "120",
            "--instance",
            str(_instance()),
            "--save-dir",
            str(tmp_path / "reproducers"),
            "--format",
            "json",
        ],
        timeout=600,
    )
    assert out.returncode in (0, 1), out.stdout + out.stderr
    data = json.loads(out.stdout)
    assert data["stopped"] is None
    assert data["streams_sent"] >= 3
    assert data["verdicts"]["failed"] == 0
    assert any(k.startswith("switch to OFFBOARD: ") for k in data["px4_outcomes"])


def test_the_bridges_namespace_is_the_one_each_release_gives_an_instance(tmp_path: Path) -> None:
    """1.18's rcS clears the namespace for PX4_UXRCE_DDS_NS=""; 1.16's and 1.17's take only a
    namespace that is not empty, so instance 4 publishes under /px4_4 there."""
    from fuzzoff.sitl.ros2.bench import bridge_namespace

    def build(name: str, rcs: str) -> bundle.Build:
        folder = tmp_path / name / "etc" / "init.d-posix"
        folder.mkdir(parents=True)
        (folder / "rcS").write_text(rcs)
        return bundle.Build(tmp_path / name, name)

    newer = build("1.18.0-beta1-head", 'if [ "${PX4_UXRCE_DDS_NS+x}" ]; then\n')
    older = build("1.16.2-ros2", 'if [ -n "$PX4_UXRCE_DDS_NS" ]\n')
    assert bridge_namespace(newer, 4) == ""
    assert bridge_namespace(older, 4) == "/px4_4"
    assert bridge_namespace(older, 0) == ""


def _exchange_with_a_sync_jump(stem: str) -> tuple[Path, Path, Clock]:
    """A kept exchange's bag and ULog, checked to hold a time sync jump of over 200 ms, and the
    clock measured between them."""
    from fuzzoff.bridge.bag import read_bag
    from fuzzoff.bridge.clock import measure
    from fuzzoff.bridge.ulog import read_ulog
    from fuzzoff.sitl.ros2 import verdict as ros2_verdict

    exchanges = Path(__file__).resolve().parent.parent / "corpora" / "against" / "exchanges"
    bag, ulog = exchanges / f"{stem}-mcap", exchanges / f"{stem}.ulg"
    log = read_ulog(ulog, ros2_verdict.STATUS)
    (_, first), (_, second) = log.syncs
    assert abs(second - first) > 200_000
    return bag, ulog, measure(read_bag(bag), log)
