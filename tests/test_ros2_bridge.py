"""PX4's ROS 2 bridge without DDS: the names of a release's topics, the example's behaviour,
and the bags the recorder writes (``fuzzoff/sitl/ros2``). The live flight, which needs the
bundles and cyclonedds, is in ``test_ros2_live.py``."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from rosbags.interfaces import (
    Nodetype,
    Qos,
    QosDurability,
    QosHistory,
    QosLiveliness,
    QosReliability,
    QosTime,
)
from rosbags.rosbag2 import Reader

from fuzzoff.formats import px4_msgs
from fuzzoff.sitl.ros2.bag import Record, write_bag
from fuzzoff.sitl.ros2.example import (
    VEHICLE_CMD_COMPONENT_ARM_DISARM,
    VEHICLE_CMD_DO_SET_MODE,
    OffboardControl,
    Plan,
)
from fuzzoff.sitl.ros2.names import BridgeTopic, NamesError, bridge_topic
from tests.helpers import run_cli


def test_a_release_names_its_versioned_topics_as_its_bridge_does() -> None:
    assert bridge_topic("1.16.2", "VehicleStatus").dds_topic == "rt/fmu/out/vehicle_status_v1"
    assert bridge_topic("1.16.2", "VehicleCommandAck").ros_topic == "/fmu/out/vehicle_command_ack"
    head = bridge_topic("1.18.0", "VehicleCommandAck")
    assert head.ros_topic == "/fmu/out/vehicle_command_ack_v1"
    assert bridge_topic("1.18.0", "VehicleStatus").ros_topic == "/fmu/out/vehicle_status_v4"
    setpoint = bridge_topic("1.16.2", "TrajectorySetpoint")
    assert setpoint.dds_topic == "rt/fmu/in/trajectory_setpoint"
    assert setpoint.dds_type == "px4_msgs::msg::dds_::TrajectorySetpoint_"
    assert setpoint.ros_type == "px4_msgs/msg/TrajectorySetpoint"
    with pytest.raises(NamesError):
        bridge_topic("1.16.2", "NoSuchMessage")


class _Sink:
    def __init__(self, name: str, sent: list[tuple[str, dict[str, Any]]]) -> None:
        self.name = name
        self.sent = sent

    def publish(self, **values: Any) -> None:
        self.sent.append((self.name, values))


def _node(plan: Plan | None = None) -> tuple[OffboardControl, list[tuple[str, dict[str, Any]]]]:
    sent: list[tuple[str, dict[str, Any]]] = []
    names = ("OffboardControlMode", "TrajectorySetpoint", "VehicleCommand")
    return OffboardControl({n: _Sink(n, sent) for n in names}, plan or Plan()), sent


def test_the_example_switches_and_arms_on_its_eleventh_tick_and_keeps_streaming() -> None:
    node, sent = _node()
    for i in range(30):
        node.tick(i * 0.1)
    commands = [v for name, v in sent if name == "VehicleCommand"]
    assert [c["command"] for c in commands] == [
        VEHICLE_CMD_DO_SET_MODE,
        VEHICLE_CMD_COMPONENT_ARM_DISARM,
    ]
    assert (commands[0]["param1"], commands[0]["param2"]) == (1.0, 6.0)
    assert all(c["target_system"] == 1 and c["from_external"] for c in commands)
    order = [name for name, _ in sent]
    # ten mode + setpoint pairs, then the two commands before the eleventh pair
    assert order[20:24] == [
        "VehicleCommand",
        "VehicleCommand",
        "OffboardControlMode",
        "TrajectorySetpoint",
    ]
    setpoints = [v for name, v in sent if name == "TrajectorySetpoint"]
    assert len(setpoints) == 30 and setpoints[-1]["position"] == [0.0, 0.0, -5.0]
    assert all(v["position"] for name, v in sent if name == "OffboardControlMode")


def test_the_hazard_plan_stops_the_stream_after_the_arm() -> None:
    node, sent = _node(Plan(stop_after_arm_s=2.0))
    for i in range(60):
        node.tick(i * 0.1)
    setpoints = [v for name, v in sent if name == "TrajectorySetpoint"]
    assert len(setpoints) == 10 + 20
    assert node.stopped and node.notes[-1][1] == "the node stops publishing"


QOS = Qos(
    QosHistory.UNKNOWN,
    0,
    QosReliability.BEST_EFFORT,
    QosDurability.TRANSIENT_LOCAL,
    QosTime(2147483647, 4294967295),
    QosTime(2147483647, 4294967295),
    QosLiveliness.AUTOMATIC,
    QosTime(2147483647, 4294967295),
    False,
)


def _cdr(topic: BridgeTopic, **values: Any) -> bytes:
    store = px4_msgs.typestore_for(topic.ros_type, topic.msgdef)
    cls = store.types[topic.ros_type]
    fields: list[tuple[str, Any]] = store.fielddefs[topic.ros_type][1]
    init: dict[str, Any] = {}
    for name, (nodetype, details) in fields:
        if name in values:
            init[name] = values[name]
        elif nodetype == Nodetype.ARRAY:
            init[name] = np.zeros(details[1], dtype=np.float32)
        else:
            init[name] = False if details[0] == "bool" else 0
    return bytes(store.serialize_cdr(cls(**init), topic.ros_type))


def _records() -> list[Record]:
    mode = bridge_topic("1.16.2", "OffboardControlMode")
    status = bridge_topic("1.16.2", "VehicleStatus")
    t0 = 1_790_000_000_000_000_000
    out = [Record(status, _cdr(status, nav_state=4, arming_state=1), t0)]
    out += [
        Record(mode, _cdr(mode, position=True, timestamp=1), t0 + i * 100_000_000)
        for i in range(1, 30)
    ]
    return out


@pytest.mark.parametrize("storage", ["mcap", "sqlite3"])
def test_a_recorded_bag_holds_the_bytes_times_schemas_and_offered_qos(
    storage: str, tmp_path: Path
) -> None:
    records = _records()
    bag = write_bag(tmp_path / "flight", records, {"/fmu/out/vehicle_status_v1": [QOS]}, storage)  # type: ignore[arg-type]
    with Reader(bag) as reader:
        by_topic = {c.topic: c for c in reader.connections}
        assert set(by_topic) == {"/fmu/in/offboard_control_mode", "/fmu/out/vehicle_status_v1"}
        status = by_topic["/fmu/out/vehicle_status_v1"]
        assert status.msgtype == "px4_msgs/msg/VehicleStatus"
        assert "MESSAGE_VERSION = 1" in status.msgdef.data
        assert status.ext.offered_qos_profiles == [QOS]  # type: ignore[union-attr]
        got = [(c.topic, t, bytes(d)) for c, t, d in reader.messages()]
    assert got == [(r.topic.ros_topic, r.received_ns, r.data) for r in records]


def test_both_storages_of_one_flight_lint_alike(tmp_path: Path) -> None:
    reports = []
    for storage in ("mcap", "sqlite3"):
        bag = write_bag(tmp_path / storage, _records(), {}, storage)  # type: ignore[arg-type]
        out = run_cli(["lint", str(bag), "--format", "json"])
        (report,) = json.loads(out.stdout)["files"]
        reports.append([(f["code"], f["time_s"]) for f in report["findings"]])
    assert reports[0] == reports[1]


def test_the_landing_plan_sends_nav_land_once_and_streams_on() -> None:
    node, sent = _node(Plan(land_after_arm_s=1.0))
    for i in range(40):
        node.tick(i * 0.1)
    commands = [v["command"] for name, v in sent if name == "VehicleCommand"]
    assert commands == [176, 400, 21]
    assert len([v for name, v in sent if name == "TrajectorySetpoint"]) == 40


def test_an_arm_from_a_new_publisher_leaves_the_streaming_ones_alone() -> None:
    made: list[tuple[str, dict[str, Any]]] = []
    node, sent = _node(Plan(arm_from_new_publisher=True, setpoints_before_switch=0))
    node.new_sink = lambda message: _Sink(message, made)
    node.tick(0.0)
    assert [v["command"] for _, v in sent if "command" in v] == [VEHICLE_CMD_DO_SET_MODE]
    assert [v["command"] for _, v in made] == [VEHICLE_CMD_COMPONENT_ARM_DISARM]
    # the switch and the arm come before the first setpoint of the tick
    assert [name for name, _ in sent] == [
        "VehicleCommand",
        "OffboardControlMode",
        "TrajectorySetpoint",
    ]


def test_the_agent_pid_is_read_from_what_run_px4_says(tmp_path: Path) -> None:
    from fuzzoff.sitl.ros2 import agent

    console = tmp_path / "console.log"
    console.write_text("INFO boot\nrun-px4.sh: agent PID 4242 (udp4 port 8888), log x\n")
    assert agent.started_pid(console) == 4242
    console.write_text("INFO boot\n")
    with pytest.raises(agent.AgentError):
        agent.started_pid(console)


def test_a_replay_plan_is_the_bags_inputs_to_px4_from_their_first_message(
    tmp_path: Path,
) -> None:
    from fuzzoff.sitl.ros2.replay import load_plan, plan_from_bag, save_plan

    bag = Path(__file__).parent.parent / "corpora" / "ros2bridge" / "example-1.16.2-ros2-sqlite3"
    plan = plan_from_bag(bag, "1.16.2")
    assert {m.topic for m in plan.messages} == {
        "/fmu/in/offboard_control_mode",
        "/fmu/in/trajectory_setpoint",
        "/fmu/in/vehicle_command",
    }
    assert plan.messages[0].offset_s == 0.0
    offsets = [m.offset_s for m in plan.messages]
    assert offsets == sorted(offsets) and 12.0 < offsets[-1] < 15.0
    with Reader(bag) as reader:
        sent = [bytes(d) for c, _, d in reader.messages() if c.topic.startswith("/fmu/in/")]
    assert [m.data for m in plan.messages] == sent
    assert load_plan(save_plan(plan, tmp_path / "plan.json")) == plan


def test_a_ros2_replay_takes_a_bag_folder() -> None:
    out = run_cli(["sitl", "replay", "flight.tlog", "--transport", "ros2", "--release", "1.16.2"])
    assert out.returncode == 2 and "a ROS 2 replay takes a bag folder" in out.stderr


def test_a_rover_program_publishes_its_flag_and_rover_setpoints_then_switches_and_arms() -> None:
    """Issue 33: the rover node of the ``rover_*`` programs, as the example but for a rover."""
    from fuzzoff.sitl.ros2.programs import PROGRAMS
    from fuzzoff.sitl.ros2.rover import ROVER_MESSAGES, RoverNode

    program = PROGRAMS["rover_stops"]
    assert program.rover is not None and program.vehicle == "rover-ackermann"
    assert program.lint_args == ("--vehicle", "rover-ackermann")
    sent: list[tuple[str, dict[str, Any]]] = []
    names = ("OffboardControlMode", "VehicleCommand", *program.rover.messages)
    node = RoverNode({n: _Sink(n, sent) for n in names}, program.rover)
    for i in range(12):
        node.tick(float(i) * 0.1)
    modes = [v for n, v in sent if n == "OffboardControlMode"]
    assert len(modes) == 12 and all(m["thrust_and_torque"] and not m["velocity"] for m in modes)
    commands = [(v["command"], v["param1"], v["param2"]) for n, v in sent if n == "VehicleCommand"]
    assert commands == [(176, 1.0, 6.0), (400, 1.0, 0.0)]
    first_command = next(i for i, (n, _) in enumerate(sent) if n == "VehicleCommand")
    assert [n for n, _ in sent[:3]] == ["OffboardControlMode", *program.rover.messages]
    assert first_command == 10 * 3  # after ten ticks of the mode and its two setpoints
    node.tick(1.0 + 5.0)  # 5 s after the arm: the node stops
    node.tick(6.1)
    assert node.stopped and len([n for n, _ in sent if n == "OffboardControlMode"]) == 12
    # every rover program's messages exist in both releases it flies on
    for rover in (p.rover for p in PROGRAMS.values() if p.rover is not None):
        for message in rover.messages:
            assert message in (*ROVER_MESSAGES, "TrajectorySetpoint")
            for release in ("1.17.0", "1.18.0"):
                assert bridge_topic(release, message).ros_topic.startswith("/fmu/in/")


def test_a_ros2_flight_refuses_a_vehicle_the_build_cannot_fly() -> None:
    out = run_cli(["sitl", "run", "rover_position", "--transport", "ros2", "--vehicle", "boat"])
    assert out.returncode == 2 and "boat" in out.stderr and "Traceback" not in out.stderr


def test_the_rover_on_main_is_refused_saying_why() -> None:
    """Issue 33: main's SIH stalls with the rover; its ROS 2 rover flights say so, not hang."""
    from fuzzoff.sitl.bundle import default_root

    if not (default_root() / "main-2026-08-13").is_dir():
        pytest.skip(f"no main-2026-08-13 bundle in {default_root()}")
    args = ["sitl", "run", "rover_position", "--transport", "ros2"]
    out = run_cli([*args, "--release", "main-2026-08-13"])
    assert out.returncode == 2 and "stalls PX4's simulated clock" in out.stderr


def test_a_vtol_program_climbs_then_asks_the_fw_transition_in_offboard_and_stops_where_told() -> (
    None
):
    """Issue 33: the standard VTOL over the bridge (``vtol.py``): the example's switch and arm,
    the MC point, DO_VTOL_TRANSITION to FW (param1 4) at its time, the FW point after; the loss
    program publishes nothing in each stop window and resumes after it."""
    from fuzzoff.sitl.ros2.programs import PROGRAMS
    from fuzzoff.sitl.ros2.vtol import VtolNode

    program = PROGRAMS["vtol_stops"]
    assert program.vtol is not None and program.vehicle == "vtol" and program.codes == ("OFB103",)
    sent: list[tuple[str, dict[str, Any]]] = []
    names = ("OffboardControlMode", "TrajectorySetpoint", "VehicleCommand")
    node = VtolNode({n: _Sink(n, sent) for n in names}, program.vtol)
    ticks = [round(i * 0.1, 1) for i in range(int((1.0 + program.fly_s) / 0.1))]
    published: dict[float, list[tuple[str, dict[str, Any]]]] = {}
    for t in ticks:
        before = len(sent)
        node.tick(t)
        published[t] = sent[before:]
    commands = [(v["command"], v["param1"], v["param2"]) for n, v in sent if n == "VehicleCommand"]
    assert commands == [(176, 1.0, 6.0), (400, 1.0, 0.0), (3000, 4.0, 0.0)]
    assert node.armed_at == 1.0
    # silent 3 s in MC (10-13 s after the arm) and in FW (24-27 s), streaming on either side
    assert not published[11.0] and not published[13.9]
    assert not published[25.0] and not published[27.9]
    assert published[10.9] and published[14.0] and published[24.9] and published[28.0]
    position = {t: v["position"] for t, out in published.items() for n, v in out if "position" in v}
    assert position[5.0] == [0.0, 0.0, -20.0] and position[20.0] == [400.0, 0.0, -30.0]
    transition = next(
        t for t, out in published.items() if any(v.get("command") == 3000 for _, v in out)
    )
    assert transition == 17.0 and position[16.9] == [0.0, 0.0, -20.0]
    assert [n for _, n in node.notes] == [
        "DO_SET_MODE offboard and ARM sent",
        "stream stops (MC)",
        "stream resumes (MC)",
        "DO_VTOL_TRANSITION to FW sent",
        "stream stops (FW)",
        "stream resumes (FW)",
    ]
    modes = [v for n, v in sent if n == "OffboardControlMode"]
    assert all(m["position"] and not m["velocity"] for m in modes)
    for release in ("1.16.2", "1.17.0", "1.18.0"):  # the releases it flies on have its topics
        for message in names:
            assert bridge_topic(release, message).ros_topic.startswith("/fmu/in/")


@pytest.mark.parametrize("still_armed", [True, False])
def test_the_airplane_ground_gate_disarms_and_forces_it_only_while_px4_shows_armed(
    still_armed: bool,
) -> None:
    """Issue 33: ``fw_ground_gate`` (the MAVLink ``fw_gate`` over the bridge): no transition,
    the point where it stands, a 3 s stop, a DISARM 9 s after the arm and, half a second later,
    a forced one (param2 21196) only if PX4's status still says armed."""
    from fuzzoff.sitl.ros2.programs import PROGRAMS
    from fuzzoff.sitl.ros2.vtol import VtolNode

    program = PROGRAMS["fw_ground_gate"]
    assert program.vtol is not None and program.vehicle == "fw"
    sent: list[tuple[str, dict[str, Any]]] = []
    names = ("OffboardControlMode", "TrajectorySetpoint", "VehicleCommand")
    node = VtolNode({n: _Sink(n, sent) for n in names}, program.vtol, armed=lambda: still_armed)
    for i in range(int((1.0 + program.fly_s) / 0.1)):
        node.tick(round(i * 0.1, 1))
    commands = [(v["command"], v["param1"], v["param2"]) for n, v in sent if n == "VehicleCommand"]
    forced = [(400, 0.0, 21196.0)] if still_armed else []
    assert commands == [(176, 1.0, 6.0), (400, 1.0, 0.0), (400, 0.0, 0.0), *forced]
    assert {tuple(v["position"]) for n, v in sent if n == "TrajectorySetpoint"} == {(0.0, 0.0, 0.0)}
    assert [n for _, n in node.notes][:3] == [
        "DO_SET_MODE offboard and ARM sent",
        "stream stops",
        "stream resumes",
    ]
