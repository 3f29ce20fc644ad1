"""The ROS 2 flights: what the node does, how long the flight is recorded, what it should give.

As ``fuzzoff.sitl.scenarios`` for MAVLink: a *clean* program is a correct use of offboard
(fuzzoff should find nothing at warning or above in its recordings), a *hazard* names the error
codes fuzzoff should give. Times count from the node's arm command.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

from fuzzoff.sitl.ros2.example import Plan
from fuzzoff.sitl.ros2.external_mode import ModePlan


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
    record_from_s: float | None = None
    """The recording starts this long after the node (None: ``flight.LEAD_S`` before it)."""
    topics: Literal["all", "in"] = "all"
    """What the recording subscribes to: the node's inputs to PX4 and PX4's outputs, or only
    the ``/fmu/in`` topics (a companion that records what it sends)."""
    missed: str | None = None
    """The issue 28 miss this program reproduces (a finding fuzzoff does not give yet)."""
    notes: str | None = None
    """What the recorded flight showed that its summary does not say."""
    agent_stop_after_arm_s: float | None = None
    """The agent is stopped this long after the arm (PX4 loses the bridge) ..."""
    agent_down_s: float = 2.0
    """... and a new one started this much later (PX4 #26022: does PX4 come back?)."""
    mode: ModePlan | None = None
    """The node is an external mode (``external_mode.py``), not the offboard example: it
    registers, answers PX4's arming checks and flies nothing; ``fly_s`` counts from its
    start."""


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
        Program(
            "example_lands_through",
            "as example_lands, hovering 2 s, recorded through touchdown and the disarm (issue 28"
            " miss 1: after 'Disarmed by landing' the status shows OFFBOARD again)",
            Plan(land_after_arm_s=6.0),
            40.0,
            "hazard",
            ("OFB203",),
            hazard="setpoints streamed into PX4's own landing while armed, through touchdown",
            missed="issue 28 miss 1",
        ),
        Program(
            "example_agent_restart",
            "offboard_control in the air while the Micro XRCE-DDS Agent is stopped 5 s after the"
            " arm and started again 2 s later; the node keeps publishing (issue 28 item 3, PX4"
            " #26022)",
            Plan(),
            16.0,
            "hazard",
            ("OFB103",),
            hazard="the bridge lost mid-flight: PX4's offboard loss while the node streams on",
            agent_stop_after_arm_s=5.0,
            missed="issue 28 item 3 (the bag's stream never stops; PX4's outputs fall silent and"
            " come back with a failsafe status)",
        ),
        Program(
            "example_no_setpoint",
            "offboard_control switching and arming in the tick before its first setpoint (issue"
            " 28 miss 2's sequence, DO_SET_MODE and ARM 0.4 ms apart, with no stream before)",
            Plan(setpoints_before_switch=0),
            6.0,
            "clean",
            notes="PX4 1.16.2 accepted both here (the ARM denial of issue 28 miss 2 did not"
            " happen)",
        ),
        Program(
            "example_arm_lost",
            "offboard_control whose ARM goes through a publisher made for it: the bag has the ARM,"
            " PX4 never gets it and stays disarmed in OFFBOARD (issue 28 miss 3)",
            Plan(arm_from_new_publisher=True),
            6.0,
            "hazard",
            ("OFB208",),
            hazard="an ARM PX4 never answered: the vehicle stays disarmed",
        ),
        Program(
            "example_late_bag",
            "the clean example with the recording started 0.16 s before the first command (issue"
            " 28 miss 4's setting)",
            Plan(),
            10.0,
            "clean",
            record_from_s=0.94,
            notes="no false OFB202 here (issue 28 miss 4 did not happen)",
        ),
        Program(
            "ext_mode",
            "an external mode as px4-ros2-interface-lib registers it, with the release's API"
            " version: it answers every arming-check request and unregisters 6 s later",
            Plan(),
            8.0,
            "clean",
            mode=ModePlan(unregister_after_s=6.0),
        ),
        Program(
            "ext_mode_old_api",
            "an external mode built for the API version before the release's (the library's"
            " 2.1.1 on PX4 1.18): PX4 registers it, the library gives up at the reply and"
            " answers no arming check, PX4 drops the mode",
            Plan(),
            8.0,
            "hazard",
            ("OFB209",),
            hazard="an external mode that never works: API version mismatch",
            mode=ModePlan(api_offset=-1),
        ),
        Program(
            "ext_mode_dies",
            "an external mode whose node dies 3 s after it registered, without unregistering"
            " (px4-ros2-interface-lib #195: its watchdog's exception ends the node): PX4's arming"
            " checks go unanswered and PX4 drops the mode",
            Plan(),
            8.0,
            "hazard",
            ("OFB209",),
            hazard="an external mode PX4 drops: arming checks unanswered",
            mode=ModePlan(stops_after_s=3.0),
        ),
        Program(
            "example_in_only",
            "the clean example recorded on its /fmu/in topics only (issue 28 miss 5: the release"
            " assumed, not read from the schemas)",
            Plan(),
            10.0,
            "clean",
            topics="in",
        ),
    )
}
