"""The ROS 2 flights: what the node does, how long the flight is recorded, what it should give.

As ``fuzzoff.sitl.scenarios`` for MAVLink: a *clean* program is a correct use of offboard
(fuzzoff should find nothing at warning or above in its recordings), a *hazard* names the error
codes fuzzoff should give. Times count from the node's arm command.
"""

from __future__ import annotations

from typing import Literal

from fuzzoff.lean_dataclass import dataclass
from fuzzoff.sitl.ros2 import rover as r
from fuzzoff.sitl.ros2 import vtol as v
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
    rover: r.RoverPlan | None = None
    """A rover node (``rover.py``) instead of the example's; ``plan`` is then unused."""
    vehicle: str | None = None
    """The SIH airframe it flies (``fuzzoff.sitl.airframes``; None: PX4's default quad)."""
    lint_args: tuple[str, ...] = ()
    """What ``fuzzoff lint`` needs beside the recording (a rover's kind: ``--vehicle``)."""
    mode: ModePlan | None = None
    """The node is an external mode (``external_mode.py``), not the offboard example: it
    registers, answers PX4's arming checks and flies nothing; ``fly_s`` counts from its
    start."""
    vtol: v.VtolPlan | None = None
    """A standard VTOL node (``vtol.py``) instead of the example's; ``plan`` is then unused."""


ROVER = "rover-ackermann"
ROVER_LINT = ("--vehicle", ROVER)
"""Neither the rover topics nor VehicleStatus say which kind of rover (docs/ros2.md)."""


def _rover(
    name: str,
    summary: str,
    plan: r.RoverPlan,
    kind: Literal["clean", "hazard"],
    codes: tuple[str, ...] = (),
    *,
    hazard: str | None = None,
    fly_s: float = 12.0,
    tail_s: float = 0.0,
    notes: str | None = None,
) -> Program:
    return Program(
        name,
        summary,
        Plan(),
        fly_s,
        kind,
        codes,
        tail_s=tail_s,
        hazard=hazard,
        notes=notes,
        rover=plan,
        vehicle=ROVER,
        lint_args=ROVER_LINT,
    )


_STILL = (
    "PX4 overwrote the node's {what} with its own from the (never published)"
    " TrajectorySetpoint from the arm on; the rover stayed within 0.4 m of its start for 12 s,"
    " on 1.17.0 and the 1.18 head (OFB510)"
)

ROVER_PROGRAMS = (
    _rover(
        "rover_position",
        "Ackermann rover: RoverPositionSetpoint 10 m north with the position flag",
        r.RoverPlan(("position",), (("RoverPositionSetpoint", r.POSITION_10M_NORTH),)),
        "hazard",
        ("OFB510",),
        hazard="the docs' Position combination in OFFBOARD, which PX4 rewrites",
        notes=_STILL.format(what="RoverPositionSetpoint (logged as 0, 0)"),
    ),
    _rover(
        "rover_speed_steering",
        "Ackermann rover: Speed + Steering (velocity flag; attitude and rate published as NaN)",
        r.RoverPlan(
            ("velocity",),
            (
                ("RoverSpeedSetpoint", r.SPEED_1),
                ("RoverAttitudeSetpoint", r.ATTITUDE_NAN),
                ("RoverRateSetpoint", r.RATE_NAN),
                ("RoverSteeringSetpoint", r.STEER_RIGHT),
            ),
        ),
        "hazard",
        ("OFB510",),
        hazard="the docs' Speed + Steering combination in OFFBOARD, which PX4 rewrites",
        notes=_STILL.format(what="speed, heading and steering (logged as 0)"),
    ),
    _rover(
        "rover_speed_attitude",
        "Ackermann rover: Speed + Attitude (velocity flag), 1 m/s heading east",
        r.RoverPlan(
            ("velocity",),
            (("RoverSpeedSetpoint", r.SPEED_1), ("RoverAttitudeSetpoint", r.ATTITUDE_EAST)),
        ),
        "hazard",
        ("OFB510",),
        hazard="the docs' Speed + Attitude combination in OFFBOARD, which PX4 rewrites",
        notes=_STILL.format(what="speed and heading (logged as 0)"),
    ),
    _rover(
        "rover_throttle_steering",
        "Ackermann rover: Throttle + Steering (thrust_and_torque flag)",
        r.RoverPlan(
            ("thrust_and_torque",),
            (("RoverThrottleSetpoint", r.THROTTLE_30), ("RoverSteeringSetpoint", r.STEER_RIGHT)),
        ),
        "clean",
        notes="the rover drove a circle (up to 5.1 m from its start, 1.6-2.0 m/s) on 1.17.0 and"
        " the 1.18 head: the throttle level is not rewritten in OFFBOARD",
    ),
    _rover(
        "rover_trajectory",
        "Ackermann rover driven with the deprecated TrajectorySetpoint (position flag, 10 m north)",
        r.RoverPlan(("position",), (("TrajectorySetpoint", r.TRAJECTORY_10M_NORTH),)),
        "hazard",
        ("OFB501",),
        hazard="the deprecated rover TrajectorySetpoint path",
        notes="the rover drove to the 10 m point and stopped on 1.17.0 and the 1.18 head: in"
        " OFFBOARD the deprecated path is what PX4's rover offboard mode converts",
    ),
    _rover(
        "rover_speed_alone",
        "Ackermann rover: RoverSpeedSetpoint alone with the velocity flag (no heading source)",
        r.RoverPlan(("velocity",), (("RoverSpeedSetpoint", r.SPEED_ALONE_2),)),
        "hazard",
        ("OFB502",),
        hazard="an invalid rover setpoint combination",
        notes="the rover stood still (PX4 rewrote the speed to 0 from TrajectorySetpoint), on"
        " 1.17.0 and the 1.18 head",
    ),
    _rover(
        "rover_throttle_velocity_flag",
        "Ackermann rover: Throttle + Steering under the velocity flag (thrust_and_torque needed)",
        r.RoverPlan(
            ("velocity",),
            (("RoverThrottleSetpoint", r.THROTTLE_30), ("RoverSteeringSetpoint", r.STEER_RIGHT)),
        ),
        "hazard",
        ("OFB503",),
        hazard="rover setpoints under the wrong OffboardControlMode flag",
        notes="the rover stood still: the velocity flag ran the speed controller on PX4's own"
        " zero speed, not the throttle sent, on 1.17.0 and the 1.18 head",
    ),
    _rover(
        "rover_stops",
        "Ackermann rover: Throttle + Steering (driving a circle), the node stops 5 s after the arm",
        r.RoverPlan(
            ("thrust_and_torque",),
            (("RoverThrottleSetpoint", r.THROTTLE_30), ("RoverSteeringSetpoint", r.STEER_RIGHT)),
            stop_after_arm_s=5.0,
        ),
        "hazard",
        ("OFB103",),
        fly_s=7.0,
        tail_s=4.0,
        hazard="stream lost in OFFBOARD while driving (PX4's loss failsafe)",
        notes="AUTO_RTL with failsafe 1.09-1.10 s after the last keep-alive PX4 logged, on"
        " 1.17.0 and the 1.18 head; on 1.17.0 the rover drove back, disarmed at home and its"
        " status showed OFFBOARD again (the user intention)",
    ),
)
"""Issue 33 item 1: the rover setpoints of 1.17 and the 1.18 head, each release has all six."""


VTOL = "vtol"

VTOL_PROGRAMS = (
    Program(
        "vtol_transition",
        "standard VTOL: position stream, switch and arm, climb to 20 m in MC, DO_VTOL_TRANSITION"
        " to FW 11 s after the arm while in OFFBOARD, FW position setpoint 400 m ahead",
        Plan(),
        25.0,
        "clean",
        vtol=v.VtolPlan(),
        vehicle=VTOL,
    ),
    Program(
        "vtol_stops",
        "standard VTOL: as vtol_transition, the stream stops 3 s hovering in MC and 3 s cruising"
        " in FW, resuming each time",
        Plan(),
        31.0,
        "hazard",
        ("OFB103",),
        hazard="stream lost in OFFBOARD in each VTOL phase (failsafe, then back to OFFBOARD)",
        vtol=v.VtolPlan(transition_after_arm_s=16.0, stops=((10.0, 3.0), (24.0, 3.0))),
        vehicle=VTOL,
    ),
)
"""Issue 33: the standard VTOL (``sihsim_standard_vtol``, 1.16.2 on) over the bridge."""

FW_PROGRAMS = (
    Program(
        "fw_ground_gate",
        "airplane on the ground (the MAVLink fw_gate): position stream where it stands, switch"
        " and arm, the stream stops for 3 s from 3 s after the arm and resumes, disarm 9 s"
        " after the arm (forced if PX4 still shows it armed)",
        Plan(),
        10.5,
        "hazard",
        ("OFB103",),
        hazard="stream lost in OFFBOARD (failsafe, then back to OFFBOARD)",
        vtol=v.VtolPlan(
            transition_after_arm_s=None,
            mc_point=(0.0, 0.0, 0.0),
            stops=((3.0, 3.0),),
            disarm_after_arm_s=9.0,
        ),
        vehicle="fw",
    ),
)
"""Issue 33: the airplane's gate over the bridge (``sihsim_airplane``, its outputs as SIH reads
them: ``airframes.AIRPLANE_OUTPUTS``, set at boot)."""


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
            " come back with a failsafe status): the bag alone cannot show it, `--with` its ULog"
            " gives OFB108",
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
        *ROVER_PROGRAMS,
        *VTOL_PROGRAMS,
        *FW_PROGRAMS,
    )
}
