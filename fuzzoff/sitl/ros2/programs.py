"""The ROS 2 flights: what the node does, how long the flight is recorded, what it should give.

As ``fuzzoff.sitl.scenarios`` for MAVLink: a *clean* program is a correct use of offboard
(fuzzoff should find nothing at warning or above in its recordings), a *hazard* names the error
codes fuzzoff should give. Times count from the node's arm command.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal

from fuzzoff.sitl.ros2.example import Plan


@dataclass(frozen=True, slots=True)
class Program:
    name: str
    summary: str
    plan: Plan
    fly_s: float
    """How long after the arm the node's loop runs."""
    kind: Literal["clean", "hazard"]
    codes: tuple[str, ...] = ()
    tail_s: float = 0.0
    """How long the recording goes on after the loop."""
    hazard: str | None = None
    notes: tuple[str, ...] = field(default=())


PROGRAMS: dict[str, Program] = {
    p.name: p
    for p in (
        Program(
            "example",
            "px4_ros_com offboard_control: 10 setpoints, switch and arm, hover at 5 m, streaming",
            Plan(),
            12.0,
            "clean",
        ),
        Program(
            "example_stops",
            "offboard_control whose node stops publishing 6 s after the arm, in the air",
            Plan(stop_after_arm_s=6.0),
            8.0,
            "hazard",
            ("OFB103",),
            tail_s=4.0,
            hazard="stream lost in OFFBOARD mid-flight (PX4's loss failsafe)",
        ),
        Program(
            "example_lands",
            "offboard_control that sends NAV_LAND 8 s after the arm and keeps streaming (issue 28"
            " miss 1: setpoints fighting PX4's landing)",
            Plan(land_after_arm_s=8.0),
            24.0,
            "hazard",
            ("OFB203",),
            hazard="setpoints streamed into PX4's own landing while armed",
        ),
    )
}
