"""The real-PX4 link without a running PX4: its clock, its recordings, the replay plan, the
verdicts recorded in corpora/sitl/, and what the user sees when PX4 is not there.

The live runs (a PX4 SITL started by the tests) are in ``test_sitl_live.py``.
"""

from __future__ import annotations

import json
import os
import socket
from pathlib import Path

import pytest

os.environ.setdefault("MAVLINK20", "1")

import itertools

from fuzzoff.sitl import bundle
from fuzzoff.sitl.airframes import DEFAULT, airframe_for
from fuzzoff.sitl.clock import PX4Clock
from fuzzoff.sitl.link import COMPANION_SYSID, open_tlog
from fuzzoff.sitl.replay import plan_from_tlog, readdress
from fuzzoff.sitl.truth import read_truth
from fuzzoff.sitl.verdict import compare
from tests.helpers import CORPORA, run_cli

SITL = CORPORA / "sitl"
RUNS = json.loads((SITL / "runs.json").read_text())
PAIRS = sorted(s for s in RUNS if (SITL / f"{s}.tlog").exists() and (SITL / f"{s}.ulg").exists())


def test_px4_clock_follows_a_simulation_slower_than_real_time() -> None:
    clock = PX4Clock()
    for i in range(31):  # 3 s of TIMESYNC at 10 Hz from a PX4 running at 0.9x
        clock.add(100.0 + i * 0.1, 5.0 + i * 0.09)
    assert clock.rate == pytest.approx(0.9, abs=1e-6)
    assert clock.now(103.0) == pytest.approx(7.7, abs=1e-6)
    # 1.0 s on PX4's clock is 1.11 s on the host's
    assert (8.7 - clock.now(103.0)) / clock.rate == pytest.approx(1.0 / 0.9, abs=1e-6)


def _messages(path: Path) -> list[tuple[float, object]]:
    log = open_tlog(path)
    out = []
    try:
        while (msg := log.recv_msg()) is not None:
            if msg.get_type() != "BAD_DATA":
                out.append((float(msg._timestamp), msg))
    finally:
        log.close()
    return out


def test_a_recorded_tlog_holds_both_directions_addressed_to_the_autopilot() -> None:
    messages = _messages(SITL / "loss_no_manual-1.16.2.tlog")
    senders = {(m.get_srcSystem(), m.get_srcComponent()) for _, m in messages}  # type: ignore[attr-defined]
    assert (1, 1) in senders and (COMPANION_SYSID, 191) in senders
    mine = [m for _, m in messages if m.get_srcSystem() == COMPANION_SYSID]  # type: ignore[attr-defined]
    commands = [m for m in mine if m.get_type() == "COMMAND_LONG"]
    setpoints = [m for m in mine if m.get_type() == "SET_POSITION_TARGET_LOCAL_NED"]
    for msg in [*commands, *setpoints]:
        assert (msg.target_system, msg.target_component) == (1, 1)
    assert commands and setpoints
    stamps = [t for t, _ in messages]
    assert stamps == sorted(stamps)


def test_a_recorded_tlog_is_on_px4s_clock() -> None:
    """The 3 s stall of loss_no_manual: the tlog's gap between setpoints is the gap PX4 logged
    (its receive times in offboard_control_mode), not the host's longer one."""
    stem = "loss_no_manual-1.16.2"
    sent = [
        t
        for t, m in _messages(SITL / f"{stem}.tlog")
        if m.get_type() == "SET_POSITION_TARGET_LOCAL_NED"  # type: ignore[attr-defined]
    ]
    tlog_gap = max(b - a for a, b in itertools.pairwise(sent))
    truth = read_truth(SITL / f"{stem}.ulg")
    ulog_gap = max(b - a for a, b in zip(truth.keepalives, truth.keepalives[1:], strict=False))
    assert tlog_gap == pytest.approx(ulog_gap, abs=0.03)


def test_a_replay_plan_is_the_companions_stream_from_the_recorded_start() -> None:
    plan = plan_from_tlog(CORPORA / "tlog" / "stream_lost_in_offboard.tlog")
    kinds = {m.get_type() for _, m in plan.messages}
    assert kinds == {"SET_POSITION_TARGET_LOCAL_NED", "COMMAND_LONG"}
    assert plan.start_text() == "POSCTL disarmed"
    assert plan.damaged_at is None
    command = next(m for _, m in plan.messages if m.get_type() == "COMMAND_LONG")
    readdress(command, (3, 1))
    assert (command.target_system, command.target_component) == (3, 1)


def test_replay_to_a_damaged_tlog_is_refused_before_anything_is_sent(tmp_path: Path) -> None:
    source = (CORPORA / "tlog" / "stream_lost_in_offboard.tlog").read_bytes()
    damaged = tmp_path / "cut.tlog"
    damaged.write_bytes(source[:4000] + b"\xfd\x09" + source[4100:])
    out = run_cli(["replay", str(damaged), "--to", "udp:127.0.0.1:9"])
    assert out.returncode == 2
    assert "damaged or cut short at byte" in out.stderr
    assert "a replay would not be the recording" in out.stderr


def test_replay_to_a_tlog_cut_short_is_refused(tmp_path: Path) -> None:
    source = (CORPORA / "tlog" / "stream_lost_in_offboard.tlog").read_bytes()
    cut = tmp_path / "cut.tlog"
    cut.write_bytes(source[: len(source) // 2 + 7])
    out = run_cli(["replay", str(cut), "--to", "udp:127.0.0.1:9"])
    assert out.returncode == 2
    assert "cut short at byte" in out.stderr


def test_replay_to_where_no_px4_answers_heartbeats_as_a_companion_and_says_so() -> None:
    from pymavlink.dialects.v20 import development

    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sink:
        sink.bind(("127.0.0.1", 0))
        sink.settimeout(5.0)
        port = sink.getsockname()[1]
        target = f"udp:127.0.0.1:{port}"
        spec = CORPORA / "tlog" / "stream_lost_in_offboard.tlog"
        out = run_cli(["replay", str(spec), "--to", target, "--connect-timeout", "1"])
        data = sink.recv(4096)
    assert out.returncode == 2
    lines = out.stderr.strip().splitlines()
    assert len(lines) == 1 and "no PX4 HEARTBEAT within 1 s" in lines[0]
    assert "14580" in lines[0]
    parser = development.MAVLink(None)
    (msg,) = parser.parse_buffer(data)
    assert msg.get_type() == "HEARTBEAT"
    assert msg.get_srcSystem() == COMPANION_SYSID != 1
    assert msg.type == development.MAV_TYPE_ONBOARD_CONTROLLER


def test_sitl_names_an_unknown_scenario_or_release_in_one_line() -> None:
    out = run_cli(["sitl", "run", "no_such_scenario", "--release", "1.16.2"])
    assert out.returncode == 2 and "no scenario 'no_such_scenario'" in out.stderr
    out = run_cli(["sitl", "run", "clean_offboard", "--px4-build", "/nonexistent"])
    assert out.returncode == 2 and "not a PX4 SITL build folder" in out.stderr


def test_sitl_list_shows_the_scenarios() -> None:
    out = run_cli(["sitl", "list"])
    assert out.returncode == 0
    assert "clean_offboard" in out.stdout and "hazard" in out.stdout


@pytest.mark.parametrize("stem", PAIRS)
def test_the_gate_model_agrees_with_the_recorded_px4_run(stem: str) -> None:
    """Issue 18 item 3 on the recordings: the model run on the client's tlog against PX4's ULog
    (switches and arms, loss time within one check period, failsafe action, return)."""
    run = RUNS[stem]
    release = run["release"].split("-")[0]
    verdict = compare(
        SITL / f"{stem}.tlog",
        release,
        SITL / f"{stem}.ulg",
        run.get("params") or {},
        COMPANION_SYSID,
        airframe_for(run.get("vehicle", DEFAULT)).fuzzoff_vehicle,
    )
    assert verdict.items, "nothing compared"
    differ = [
        f"{i.what} at {i.t:.2f}: PX4 {i.px4}; model {i.model}"
        for i in verdict.items
        if i.agree is False
    ]
    assert not differ, differ


@pytest.mark.parametrize(
    ("stem", "overrides"),
    [
        ("sticks_moved-1.18.0-beta1-head", 1),
        ("sticks_moved-1.17.0", 0),
        ("sticks_moved_override-1.17.0", 1),
    ],
)
def test_the_sticks_end_offboard_on_px4_1_18_and_not_on_1_17_as_the_model_says(
    stem: str, overrides: int
) -> None:
    """Gate spec 16 S1, seen live: a steady ramp of the pitch stick in an OFFBOARD hover; PX4
    1.18 goes to Position (sticks_moving) and stays, 1.17.0 keeps OFFBOARD (COM_RC_OVERRIDE 1)
    and goes to Position with COM_RC_OVERRIDE 3."""
    run = RUNS[stem]
    verdict = compare(
        SITL / f"{stem}.tlog",
        run["release"].split("-")[0],
        SITL / f"{stem}.ulg",
        run.get("params") or {},
        COMPANION_SYSID,
    )
    items = [i for i in verdict.items if i.what == "stick override"]
    assert len(items) == overrides and all(i.agree for i in items)
    assert verdict.agree


def _verdict(stem: str) -> list[tuple[str, str, bool | None]]:
    run = RUNS[stem]
    verdict = compare(
        SITL / f"{stem}.tlog",
        run["release"].split("-")[0],
        SITL / f"{stem}.ulg",
        run.get("params") or {},
        COMPANION_SYSID,
    )
    return [(i.what, i.px4, i.agree) for i in verdict.items]


@pytest.mark.parametrize(
    ("stem", "arm"),
    [
        ("attitude_no_thrust-1.17.0", "accepted"),
        ("attitude_no_thrust-1.18.0-beta1-head", "rejected"),
    ],
)
def test_an_attitude_setpoint_without_thrust_keeps_1_17_alive_and_not_1_18_as_the_model_says(
    stem: str, arm: str
) -> None:
    """Gate spec 16 S3, seen live: SET_ATTITUDE_TARGET with the thrust ignored is a keep-alive
    on 1.17.0 (the arm in OFFBOARD accepted) and dropped on the 1.18 head (refused); the model
    says the same, and lint gives OFB606 on both tlogs. (main's SIH cannot run it: below.)"""
    items = _verdict(stem)
    assert ("arm", arm, True) in [(w, p.split(" ")[0], a) for w, p, a in items], items
    assert all(a is not False for _, _, a in items), items
    out = run_cli(["lint", str(SITL / f"{stem}.tlog"), "--format", "json"])
    assert "OFB606" in {f["code"] for f in json.loads(out.stdout)["files"][0]["findings"]}


@pytest.mark.parametrize(
    "stem",
    ["loss_no_manual-1.17.0", "loss_no_manual-1.18.0-beta1-head", "loss_no_manual-main-2026-08-13"],
)
def test_a_stream_loss_without_rc_is_return_on_1_17_and_later_as_the_model_says(stem: str) -> None:
    """No manual control: NAV_RCL_ACT's Return replaces the loss action's Position from 1.17,
    then OFFBOARD again when the stream resumes (seen on 1.17.0, the 1.18 head and main)."""
    items = _verdict(stem)
    assert ("failsafe action", "AUTO_RTL", True) in items, items
    assert ("automatic return", "back to OFFBOARD", True) in items, items


@pytest.mark.parametrize(
    "stem",
    [
        "clean_offboard-1.18.0-beta1-head",
        "attitude_no_thrust-1.18.0-beta1-head",
        "clean_offboard-main-2026-08-13",
    ],
)
def test_the_unasked_gripper_ack_is_px4s_own_command_and_judges_no_request(stem: str) -> None:
    """The 1.18 head (and main) ack MAV_CMD_DO_GRIPPER (211) about 1 s after boot with no
    client asking: PX4's own command at boot (not from outside), whose ack is addressed to
    system 0, so a MAVLink client receives it. The ULogs kept hold both; the model agrees with
    PX4 on every request there."""
    from pyulog import ULog

    log = ULog(str(SITL / f"{stem}.ulg"), ["vehicle_command", "vehicle_command_ack"])
    commands = log.get_dataset("vehicle_command").data
    own = [i for i, c in enumerate(commands["command"]) if c == 211]
    assert own and not any(commands["from_external"][i] for i in own)
    acks = log.get_dataset("vehicle_command_ack").data
    gripper = [
        (int(t) - log.start_timestamp) / 1e6
        for t, c, r, to in zip(
            acks["timestamp"], acks["command"], acks["result"], acks["target_system"], strict=True
        )
        if c == 211 and r == 0 and to == 0 and int(t) >= log.start_timestamp
    ]
    assert gripper and gripper[0] < 2.0, stem
    items = _verdict(stem)
    assert items and all(a is not False for _, _, a in items), items


def test_main_s_bundle_is_not_asked_to_run_what_stops_its_simulated_clock() -> None:
    """On main-2026-08-13 a quadrotor in OFFBOARD disarmed with no setpoint it takes stops
    SIH's clock (lockstep waiting for actuator outputs): those scenarios are skipped there with
    the reason, and run everywhere else."""
    from fuzzoff.sitl.scenarios import scenarios_for, why_not_run

    stalled = [n for n in scenarios_for("main-2026-08-13") if why_not_run("main-2026-08-13", n)]
    assert stalled == ["disarmed_switch_no_stream", "attitude_no_thrust"]
    assert "actuator_outputs_sim" in (why_not_run("main-2026-08-13", stalled[0]) or "")
    assert not any(why_not_run("1.18.0-beta1-head", n) for n in scenarios_for("1.18.0-beta1-head"))


def test_the_proxy_forwards_both_ways_unchanged_and_records_them(tmp_path: Path) -> None:
    """Between a client and a PX4 (here two sockets speaking pymavlink): every datagram goes
    through as it was sent, and the tlog holds both directions once PX4's clock is known."""
    from pymavlink.dialects.v20 import development

    from fuzzoff.sitl.proxy import RecordingProxy

    px4 = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    px4.bind(("127.0.0.1", 0))
    client = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    client.bind(("127.0.0.1", 0))
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as free:
        free.bind(("127.0.0.1", 0))
        px4_send_port = free.getsockname()[1]  # where PX4 sends: the proxy listens there
    for sock in (px4, client):
        sock.settimeout(5.0)
    autopilot = development.MAVLink(None, srcSystem=1, srcComponent=1)
    companion = development.MAVLink(None, srcSystem=COMPANION_SYSID, srcComponent=191)
    tlog = tmp_path / "proxy.tlog"
    with RecordingProxy(px4.getsockname()[1], px4_send_port, client.getsockname()[1], tlog):
        for i in range(3):
            down = autopilot.timesync_encode(0, int((10.0 + 0.1 * i) * 1e9)).pack(autopilot)
            px4.sendto(down, ("127.0.0.1", px4_send_port))
            got, proxy_addr = client.recvfrom(4096)
            assert got == down
            up = companion.heartbeat_encode(18, 8, 0, 0, 4).pack(companion)
            client.sendto(up, proxy_addr)
            got, from_addr = px4.recvfrom(4096)
            assert got == up
            assert from_addr[1] == px4_send_port  # PX4 sees one peer: the port it sends to
    px4.close()
    client.close()
    kinds = [(m.get_srcSystem(), m.get_type()) for _, m in _messages(tlog)]
    assert (1, "TIMESYNC") in kinds and (COMPANION_SYSID, "HEARTBEAT") in kinds


def test_a_px4_int_parameter_travels_as_its_bytes_in_the_float() -> None:
    from fuzzoff.sitl.link import param_decode, param_encode

    value, param_type = param_encode("NAV_RCL_ACT", 3, 6)
    assert value != 3.0 and param_decode(value, param_type) == 3.0
    value, param_type = param_encode("COM_OF_LOSS_T", 1.5, 9)
    assert (value, param_type) == (1.5, 9)


def _fake_bundles(root: Path, names: list[str]) -> Path:
    for name in names:
        (root / name / "bin").mkdir(parents=True)
        (root / name / "bin" / "px4").write_bytes(b"")
    return root


def test_a_release_named_exactly_starts_that_bundle_not_its_ros2_sibling(tmp_path: Path) -> None:
    root = _fake_bundles(tmp_path, ["1.16.2-ros2", "1.16.2", "1.17.0", "1.18.0-beta1-head"])
    assert bundle.find_build("1.16.2", None, root).folder == root / "1.16.2"
    assert bundle.find_build("1.16.2-ros2", None, root).release == "1.16.2-ros2"
    assert bundle.find_build("1.18.0", None, root).release == "1.18.0-beta1-head"
    assert bundle.releases(root) == ["1.16.2", "1.16.2-ros2", "1.17.0", "1.18.0-beta1-head"]
    with pytest.raises(bundle.BundleError, match="no such bundle"):
        bundle.find_build("1.15.4", None, root)


def test_a_ros2_flight_takes_the_releases_bundle_with_the_bridge(tmp_path: Path) -> None:
    root = _fake_bundles(tmp_path, ["1.16.2", "1.16.2-ros2", "1.17.0", "1.18.0-beta1-head"])
    for name in ("1.16.2-ros2", "1.18.0-beta1-head"):
        (root / name / "bin" / "commands.txt").write_text("commander\nuxrce_dds_client\n")
    assert bundle.find_bridge_build("1.16.2", None, root).release == "1.16.2-ros2"
    assert bundle.find_bridge_build("1.18.0", None, root).release == "1.18.0-beta1-head"
    with pytest.raises(bundle.BundleError, match="no bundle with the ROS 2 bridge"):
        bundle.find_bridge_build("1.17.0", None, root)


def test_sitl_run_over_ros2_names_an_unknown_program_or_a_mavlink_only_option() -> None:
    out = run_cli(["sitl", "run", "clean_offboard", "--transport", "ros2", "--release", "1.16.2"])
    assert out.returncode == 2 and "no ROS 2 program 'clean_offboard'" in out.stderr
    out = run_cli(
        ["sitl", "run", "example", "--transport", "ros2", "--release", "1.16.2", "--instance", "3"]
    )
    assert out.returncode == 2 and "MAVLink-only" in out.stderr
    out = run_cli(
        ["sitl", "run", "example", "--transport", "ros2", "--release", "1.16.2", "--param", "A=1"]
    )
    assert out.returncode == 2 and "--param goes with a ROS 2 replay" in out.stderr
    listed = run_cli(["sitl", "list"]).stdout
    assert "ROS 2 programs (--transport ros2):" in listed and "example_stops" in listed


def test_an_answer_that_comes_while_its_command_is_being_sent_is_recorded_after_it(
    tmp_path: Path,
) -> None:
    """pymavlink records a sent message only after writing it to the socket; on a busy host
    PX4's answer came in between and the tlog held the COMMAND_ACK before its COMMAND_LONG
    (OFB208 then saw a command without an answer). Here a stand-in for PX4 answers at once
    and the send is held up after the write: the command is still recorded first."""
    import threading
    import time

    from pymavlink.dialects.v20 import development as mavlink

    from fuzzoff.sitl.link import Link
    from fuzzoff.sitl.recorder import TlogRecorder

    px4_sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    px4_sock.bind(("127.0.0.1", 0))
    px4_sock.settimeout(5.0)
    probe = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    probe.bind(("127.0.0.1", 0))
    client_port = probe.getsockname()[1]
    probe.close()
    link = Link(f"udpin:127.0.0.1:{client_port}")
    px4 = mavlink.MAVLink(None, srcSystem=1, srcComponent=1)
    client = ("127.0.0.1", client_port)
    try:
        for ms in (1000, 1100, 1200):  # PX4's clock, so that records are written
            px4_sock.sendto(px4.system_time_encode(0, ms).pack(px4), client)
        deadline = time.monotonic() + 5.0
        while not link.clock.synced and time.monotonic() < deadline:
            time.sleep(0.01)
        link.recorder = TlogRecorder(tmp_path / "x.tlog", clock=link.clock.now)

        def answer() -> None:
            while True:  # the client's heartbeats, then the command
                data, where = px4_sock.recvfrom(2048)
                msgs = mavlink.MAVLink(None).parse_buffer(data) or []
                if any(m.get_type() == "COMMAND_LONG" for m in msgs):
                    break
            px4_sock.sendto(px4.command_ack_encode(176, 0, 0, 0, 245, 191).pack(px4), where)

        responder = threading.Thread(target=answer, daemon=True)
        responder.start()
        write = link.conn.write

        def slow_write(buf: bytes) -> None:
            write(buf)
            msgs = mavlink.MAVLink(None).parse_buffer(buf) or []
            if any(m.get_type() == "COMMAND_LONG" for m in msgs):
                time.sleep(0.3)  # the answer arrives before pymavlink's send callback runs

        link.conn.write = slow_write
        link.send(link.mav.command_long_encode(1, 1, 176, 0, 1, 6, 0, 0, 0, 0, 0))
        responder.join(5.0)
        time.sleep(0.3)
    finally:
        link.close()
        px4_sock.close()
        if link.recorder is not None:
            link.recorder.close()
    kinds = [m.get_type() for _, m in _messages(tmp_path / "x.tlog")]
    commands = [k for k in kinds if k in ("COMMAND_LONG", "COMMAND_ACK")]
    assert commands == ["COMMAND_LONG", "COMMAND_ACK"], kinds
