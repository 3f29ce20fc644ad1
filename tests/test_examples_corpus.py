"""The official client examples, reproduced from their sources against real PX4 (issue 17).

``corpora/examples/`` holds what px4_ros_com, px4-offboard, the PX4 docs' MAVROS ``offb_node``
and px4-ros2-interface-lib send, with PX4 SITL's answers (README.md there says how each was
made). A user runs these examples first, so:

* every clean recording lints with exit 0 at the default fail level (``warning``): no false
  OFB107 on a hold, no OFB203 error on the stream an example must send before its switch, no
  OFB102 on its 10 setpoints at 10 Hz (what the rules said before issue 17's severity
  principle);
* every hazard recording, the same clients with one thing wrong, gives its ``error``, starting
  where the scenario put the fault.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pytest

from tests.helpers import CORPORA, run_cli

EXAMPLES = CORPORA / "examples"


@dataclass(frozen=True)
class Example:
    """A recording, the options a user gives for it (the release: a ROS recording does not
    name it), and for a hazard the error it must give and when the fault began and ended."""

    file: str
    args: tuple[str, ...]
    hazard: str | None = None
    window: tuple[float, float] = (0.0, 0.0)
    """Seconds from the recording's first message within which the error must start."""


CLEAN = [
    Example("px4_ros_com_offboard_control.mcap", ("--px4", "1.16.2")),
    Example("px4_ros_com_offboard_control_py.mcap", ("--px4", "1.15.4")),
    Example("px4_ros_com_ten_minute_hold.mcap", ("--px4", "1.17.0")),
    Example("px4_offboard_circle_after_takeoff.mcap", ("--px4", "1.16.2")),
    Example("mavros_offb_node.bag", ("--px4", "1.14.4")),
    Example("mavros_offb_node_ros2", ("--px4", "1.14.4")),
    Example("interface_lib_goto.mcap", ("--px4", "1.16.2")),
    Example("rover_speed_attitude.mcap", ("--px4", "1.17.0", "--vehicle", "rover-differential")),
]

# windows: the client starts at 1 s; each fault's time is in runs.py's scenario
HAZARDS = [
    # the planner dies 6 s after the velocity phase began at 8 s
    Example("hazard_frozen_velocity.mcap", ("--px4", "1.16.2"), "OFB107", (14.5, 15.5)),
    # the timer stops 15 s after the start; PX4 declares the loss about 1.05 s later
    Example("hazard_stall_mid_air.mcap", ("--px4", "1.16.2"), "OFB103", (16.5, 17.5)),
    # z = +5 from the first setpoint
    Example("hazard_enu_z_from_ground.mcap", ("--px4", "1.16.2"), "OFB404", (0.5, 1.5)),
    # z = +5 from the first setpoint after the pilot's switch, 3 s after the client started
    Example("hazard_enu_z_airborne.mcap", ("--px4", "1.16.2"), "OFB404", (13.5, 15.5)),
    # velocity declared with position 0 from 12 s after the start
    Example(
        "hazard_nan_pattern_velocity_zero_position.mcap",
        ("--px4", "1.16.2"),
        "OFB401",
        (12.5, 13.5),
    ),
    # the switch at the 11th cycle, 1 s after the client started (after a takeoff)
    Example(
        "hazard_switch_without_stream_flying.mcap", ("--px4", "1.16.2"), "OFB201", (11.5, 12.5)
    ),
    # the MAVROS loop stops 25 s after its start, for 1.5 s
    Example("hazard_mavros_stall_mid_air.bag", ("--px4", "1.14.4"), "OFB103", (26.0, 27.0)),
    # the yaw setpoint from the first cycle
    Example(
        "hazard_rover_trajectory_yaw.mcap",
        ("--px4", "1.17.0", "--vehicle", "rover-ackermann"),
        "OFB505",
        (0.5, 1.5),
    ),
]


def lint(example: Example) -> tuple[int, list[dict[str, Any]]]:
    result = run_cli(["lint", str(EXAMPLES / example.file), "--format", "json", *example.args])
    assert result.returncode in (0, 1), result.stderr
    (report,) = json.loads(result.stdout)["files"]
    assert report["complete"], example.file
    return result.returncode, report["findings"]


def loud(findings: list[dict[str, Any]]) -> list[str]:
    """The findings at or above the default fail level, one line each."""
    return [
        f"{f['code']} {f['severity']} at {f['time_s']}: {f['message']}"
        for f in findings
        if f["severity"] in ("error", "warning")
    ]


@pytest.mark.parametrize("example", CLEAN, ids=[e.file for e in CLEAN])
def test_clean_example_lints_clean(example: Example) -> None:
    status, findings = lint(example)
    assert status == 0, "\n".join(loud(findings))


@pytest.mark.parametrize("example", HAZARDS, ids=[e.file for e in HAZARDS])
def test_hazard_gives_its_error(example: Example) -> None:
    status, findings = lint(example)
    errors = [f for f in findings if f["code"] == example.hazard and f["severity"] == "error"]
    assert status == 1
    assert errors, f"no {example.hazard} error:\n" + "\n".join(loud(findings))
    low, high = example.window
    assert any(low <= f["time_s"] <= high for f in errors), [f["time_s"] for f in errors]


def test_every_example_recording_is_listed_and_described() -> None:
    """A recording in corpora/examples is judged here, replayed by test_corpora, and its
    source is named in the README."""
    readme = (EXAMPLES / "README.md").read_text(encoding="utf-8")
    listed = {e.file for e in CLEAN + HAZARDS}
    found = {
        p.name
        for p in EXAMPLES.iterdir()
        if p.suffix in (".mcap", ".bag") or (p.is_dir() and (p / "metadata.yaml").exists())
    }
    assert found == listed
    for name in found:
        stem = Path(name).stem if not (EXAMPLES / name).is_dir() else name
        assert (EXAMPLES / f"{stem}.expected.json").exists(), name
        assert f"`{name}`" in readme, f"{name} is not described in README.md"


def test_rosbag1_writer_keeps_extra_messages_in_time_order(tmp_path: Path) -> None:
    """``write_rosbag1(extra=...)`` (added for the MAVROS example, which publishes
    ``setpoint_position/local``): the extra messages are read back by fuzzoff's MAVROS reader,
    merged in time order with the events."""
    from fuzzoff.events import VehicleStatus
    from fuzzoff.formats import open_source
    from fuzzoff.formats.rosbag1.writer import Ros1Message, mavros_typestore, write_rosbag1

    types = mavros_typestore().types
    header = types["std_msgs/msg/Header"](
        seq=0, stamp=types["builtin_interfaces/msg/Time"](sec=0, nanosec=0), frame_id=""
    )

    def pose(t: float, z: float) -> Ros1Message:
        point = types["geometry_msgs/msg/Point"](x=0.0, y=0.0, z=z)
        q = types["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=0.0, w=1.0)
        message = types["geometry_msgs/msg/PoseStamped"](
            header=header, pose=types["geometry_msgs/msg/Pose"](position=point, orientation=q)
        )
        return Ros1Message(t, "/mavros/setpoint_position/local", message.__msgtype__, message)

    status = VehicleStatus(t=0.5, nav_state=14, mode="OFFBOARD", armed=True)
    path = write_rosbag1(tmp_path / "x.bag", [status], extra=[pose(1.0, 3.0), pose(0.0, 2.0)])
    with open_source(path) as source:
        seen = [(e.kind, round(e.t, 3)) for e in source.events()]
        zs = [e.position[2] for e in source.events() if e.kind == "set_position_target_local_ned"]
    assert seen == [
        ("set_position_target_local_ned", 0.0),
        ("vehicle_status", 0.5),
        ("set_position_target_local_ned", 1.0),
    ]
    assert zs == [-2.0, -3.0]  # ENU up is NED down, as MAVROS sends it
