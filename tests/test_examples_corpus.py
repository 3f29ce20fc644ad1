"""The official client examples, reproduced from their sources against real PX4 (issue 17).

``corpora/examples/`` holds what px4_ros_com, px4-offboard, the PX4 docs' MAVROS ``offb_node``
and px4-ros2-interface-lib send, with PX4 SITL's answers (README.md there says how each was
made). A user runs these examples first, so:

* every clean recording lints with exit 0 at the default fail level (``warning``);
* every hazard recording, the same clients with one thing wrong, gives its ``error``.

Where today's rules still give a false warning, or miss a hazard, the case is marked
``xfail(strict=True)`` with the rule it waits for: it flips (and fails) when the fix lands, so
the mark is removed then and the recording's ``NAME.expected.json`` updated. Each false finding
also has its own test (``test_no_false_finding``), so that each fix flips its own case.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pytest

from tests.helpers import CORPORA, run_cli

EXAMPLES = CORPORA / "examples"

ISSUE = "issue 17"


@dataclass(frozen=True)
class Example:
    """A recording, the options a user gives for it, and what fuzzoff gets wrong today."""

    file: str
    args: tuple[str, ...]
    false_findings: dict[str, str] = field(default_factory=dict)
    """Rule -> what is wrong: today's findings at warning or above that the rules must drop."""
    hazard: str | None = None
    """The error code the hazard must give (None for a clean recording)."""
    missed: str = ""
    """Why today's rules do not give the hazard's error yet (empty: they do)."""


OFB107_HOLD = "OFB107 warns on a position hold, what a stopped controller should leave"
OFB203_BEFORE = "OFB203 error on the stream the example must send, disarmed, before the switch"
OFB107_ROVER = "OFB107 warns on a rover driving straight at 1 m/s for 9 s (the hazard holds 20 s)"
OFB102_TEN = "OFB102 warns on the example's 10 setpoints at 10 Hz (no release enforces 1 s)"

CLEAN = [
    Example(
        "px4_ros_com_offboard_control.mcap",
        ("--px4", "1.16.2"),
        {"OFB107": OFB107_HOLD, "OFB203": OFB203_BEFORE},
    ),
    Example(
        "px4_ros_com_offboard_control_py.mcap",
        ("--px4", "1.15.4"),
        {"OFB107": OFB107_HOLD, "OFB102": OFB102_TEN},
    ),
    Example(
        "px4_ros_com_ten_minute_hold.mcap",
        ("--px4", "1.17.0"),
        {"OFB107": OFB107_HOLD, "OFB203": OFB203_BEFORE, "OFB102": OFB102_TEN},
    ),
    Example("px4_offboard_circle_after_takeoff.mcap", ("--px4", "1.16.2")),
    Example("mavros_offb_node.bag", ("--px4", "1.14.4"), {"OFB107": OFB107_HOLD}),
    Example("mavros_offb_node_ros2", ("--px4", "1.14.4"), {"OFB107": OFB107_HOLD}),
    Example("interface_lib_goto.mcap", ("--px4", "1.16.2")),
    Example(
        "rover_speed_attitude.mcap",
        ("--px4", "1.17.0", "--vehicle", "rover-differential"),
        {"OFB107": OFB107_ROVER, "OFB203": OFB203_BEFORE, "OFB102": OFB102_TEN},
    ),
]

HAZARDS = [
    Example(
        "hazard_frozen_velocity.mcap",
        ("--px4", "1.16.2"),
        hazard="OFB107",
        missed="OFB107 is a warning; a motion command frozen for 20 s must be an error",
    ),
    Example("hazard_stall_mid_air.mcap", ("--px4", "1.16.2"), hazard="OFB103"),
    Example(
        "hazard_enu_z_from_ground.mcap",
        ("--px4", "1.16.2"),
        hazard="OFB404",
        missed="OFB404 is a warning; a climb written as +z from the ground must be an error",
    ),
    Example(
        "hazard_enu_z_airborne.mcap",
        ("--px4", "1.16.2"),
        hazard="OFB404",
        missed="OFB404 is a warning; a target below the origin while airborne must be an error",
    ),
    Example("hazard_nan_pattern_velocity_zero_position.mcap", ("--px4", "1.16.2"), hazard="OFB401"),
    Example("hazard_switch_without_stream_flying.mcap", ("--px4", "1.16.2"), hazard="OFB201"),
    Example("hazard_mavros_stall_mid_air.bag", ("--px4", "1.14.4"), hazard="OFB103"),
    Example(
        "hazard_rover_trajectory_yaw.mcap",
        ("--px4", "1.17.0", "--vehicle", "rover-ackermann"),
        hazard="OFB505",
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


def marked(example: Example, reason: str) -> Any:
    if not reason:
        return example
    return pytest.param(example, marks=pytest.mark.xfail(strict=True, reason=f"{ISSUE}: {reason}"))


@pytest.mark.parametrize(
    "example",
    [marked(e, "; ".join(e.false_findings.values())) for e in CLEAN],
    ids=[e.file for e in CLEAN],
)
def test_clean_example_lints_clean(example: Example) -> None:
    status, findings = lint(example)
    assert status == 0, "\n".join(loud(findings))


FALSE = [(e, code, why) for e in CLEAN for code, why in e.false_findings.items()]


@pytest.mark.parametrize(
    ("example", "code"),
    [
        pytest.param(e, code, marks=pytest.mark.xfail(strict=True, reason=f"{ISSUE}: {why}"))
        for e, code, why in FALSE
    ],
    ids=[f"{e.file}-{code}" for e, code, _ in FALSE],
)
def test_no_false_finding(example: Example, code: str) -> None:
    _, findings = lint(example)
    wrong = [line for line in loud(findings) if line.startswith(code)]
    assert not wrong, "\n".join(wrong)


@pytest.mark.parametrize(
    "example", [marked(e, e.missed) for e in HAZARDS], ids=[e.file for e in HAZARDS]
)
def test_hazard_gives_its_error(example: Example) -> None:
    status, findings = lint(example)
    errors = [f for f in findings if f["code"] == example.hazard and f["severity"] == "error"]
    assert status == 1
    assert errors, f"no {example.hazard} error:\n" + "\n".join(loud(findings))


@pytest.mark.parametrize(
    "example", [e for e in HAZARDS if e.missed], ids=[e.file for e in HAZARDS if e.missed]
)
def test_missed_hazard_is_still_reported(example: Example) -> None:
    """Until its rule says error, each missed hazard is at least a warning of its own code."""
    _, findings = lint(example)
    assert any(f["code"] == example.hazard for f in findings), "\n".join(loud(findings))


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
    from fuzzoff.sources import open_source
    from fuzzoff.writers.rosbag1 import Ros1Message, mavros_typestore, write_rosbag1

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
