"""Build the rover rule corpus: ROS 2 offboard control of rovers (OFB501-OFB506, OFB510) as MCAP.

Run ``.venv/bin/python corpora/rules_rover/build.py``; it is deterministic. Every recording is
written through ``fuzzoff.formats.mcap.writer`` with the px4_msgs of PX4 1.17 (1.16 has no
``RoverSpeedSetpoint``) and linted with ``--px4 1.17 --vehicle <rover type>``. Each
``NAME.expected.json`` lists the findings planted here, judged against the rule texts
(rules/OFB5*.toml), and ``clean``: the rules the recording exercises that must stay silent.

Every drive follows one pattern (``Drive``): the companion streams ``OffboardControlMode`` at
10 Hz, the rover sits disarmed in POSCTL, the companion switches to OFFBOARD after 1.5 s of
stream (accepted), arms at 2.0 s and publishes its setpoints at 20 Hz from the switch on. The
mode counts from the accepting ack (1.52 s), so the first ``OffboardControlMode`` judged in
offboard is the one at 1.6 s. A bad case changes one thing of a good one.
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from fuzzoff.catalog import get_rule
from fuzzoff.events import (
    ActuatorMotors,
    ActuatorServos,
    Command,
    CommandAck,
    Event,
    RoverAttitudeSetpoint,
    RoverPositionSetpoint,
    RoverRateSetpoint,
    RoverSpeedSetpoint,
    RoverSteeringSetpoint,
    RoverThrottleSetpoint,
    TrajectorySetpoint,
    VehicleStatus,
    event_from_dict,
)
from fuzzoff.formats.mcap.writer import write_mcap

HERE = Path(__file__).resolve().parent
POSCTL, OFFBOARD = 2, 14
NAN = math.nan
BOOT_US = 120_000_000
SWITCH_T, ARM_T, END_T = 1.5, 2.0, 6.0
OCM_PERIOD, SETPOINT_PERIOD, STATUS_PERIOD = 0.1, 0.05, 0.2
FIRST_SETPOINT = 1.55
"""Setpoints start with the first tick after the accepting ack, as the docs ask."""
FIRST_JUDGED = 1.6
"""The first OffboardControlMode after the accepting ack (the combination rules' time)."""
RELEASE = "1.17"
ROVER_RULES = ["OFB501", "OFB502", "OFB503", "OFB504", "OFB505", "OFB506", "OFB510"]


def ticks(start: float, stop: float, period: float) -> list[float]:
    n = math.ceil((stop - start) / period - 1e-9)
    return [round(start + i * period, 6) for i in range(n)]


def flags_event(t: float, flags: dict[str, bool]) -> Event:
    stamp = BOOT_US + round(t * 1e6)
    return event_from_dict({"kind": "control_mode", "t": t, "sender_time_us": stamp, **flags})


@dataclass
class Drive:
    flags: dict[str, bool]
    setpoint: Callable[[float], list[Event]]
    extra: list[Event] = field(default_factory=list)

    def events(self) -> list[Event]:
        out: list[Event] = [flags_event(t, self.flags) for t in ticks(0.0, END_T, OCM_PERIOD)]
        for t in ticks(0.0, END_T, STATUS_PERIOD):
            nav = OFFBOARD if t >= SWITCH_T + 0.05 else POSCTL
            out.append(VehicleStatus(t=t, nav_state=nav, armed=t >= ARM_T + 0.05))
        out += [
            Command(t=SWITCH_T, command=176, params=(1.0, 6.0, 0, 0, 0, 0, 0), from_external=True),
            CommandAck(t=SWITCH_T + 0.02, command=176, result=0),
            Command(t=ARM_T, command=400, params=(1.0, 0, 0, 0, 0, 0, 0), from_external=True),
            CommandAck(t=ARM_T + 0.02, command=400, result=0),
        ]
        for t in ticks(FIRST_SETPOINT, END_T, SETPOINT_PERIOD):
            out += self.setpoint(t)
        out += self.extra
        return sorted(out, key=lambda e: e.t)


# -- what the companion publishes each tick ------------------------------------------------------


def speed(t: float) -> Event:
    return RoverSpeedSetpoint(t=t, speed_body_x=1.0 + 0.2 * math.sin(t), speed_body_y=NAN)


def heading(t: float, nan: bool = False) -> Event:
    return RoverAttitudeSetpoint(t=t, yaw_setpoint=NAN if nan else 0.3 * math.sin(0.5 * t))


def yaw_rate(t: float, nan: bool = False) -> Event:
    return RoverRateSetpoint(t=t, yaw_rate_setpoint=NAN if nan else 0.2 * math.cos(0.5 * t))


def throttle(t: float) -> Event:
    return RoverThrottleSetpoint(t=t, throttle_body_x=0.3 + 0.05 * math.sin(t), throttle_body_y=NAN)


def steering(t: float) -> Event:
    return RoverSteeringSetpoint(t=t, normalized_steering_angle=0.2 * math.sin(t))


def speed_attitude(t: float) -> list[Event]:
    return [speed(t), heading(t)]


def speed_rate(t: float) -> list[Event]:
    return [speed(t), heading(t, nan=True), yaw_rate(t)]


def speed_rate_no_nan(t: float) -> list[Event]:
    return [speed(t), yaw_rate(t)]


def speed_steering(t: float) -> list[Event]:
    return [speed(t), heading(t, nan=True), yaw_rate(t, nan=True), steering(t)]


def speed_only(t: float) -> list[Event]:
    return [speed(t)]


def throttle_steering(t: float) -> list[Event]:
    return [throttle(t), steering(t)]


def goto(t: float) -> list[Event]:
    """A new waypoint every second."""
    leg = math.floor(t)
    return [
        RoverPositionSetpoint(
            t=t,
            position_ned=(5.0 * leg, 2.0 * (leg % 2)),
            start_ned=(5.0 * (leg - 1), 2.0 * ((leg - 1) % 2)),
            cruising_speed=1.0,
            yaw=NAN,
        )
    ]


def trajectory_velocity(t: float) -> list[Event]:
    return [TrajectorySetpoint(t=t, velocity=(1.0, 0.2 * math.sin(t), NAN))]


def trajectory_yaw(t: float) -> list[Event]:
    return [TrajectorySetpoint(t=t, yaw=0.3 * math.sin(0.5 * t))]


def actuators(t: float) -> list[Event]:
    return [
        ActuatorMotors(t=t, control=(0.3 + 0.05 * math.sin(t), 0.3) + (NAN,) * 10),
        ActuatorServos(t=t, control=(0.1 * math.sin(t),) + (NAN,) * 7),
    ]


# -- cases -----------------------------------------------------------------------------------------


@dataclass
class Case:
    name: str
    vehicle: str
    drive: Drive
    findings: list[tuple[str, str, float]]
    clean: list[str]

    def args(self) -> list[str]:
        return ["--px4", RELEASE, "--vehicle", self.vehicle]


def cases() -> list[Case]:
    velocity = {"velocity": True}
    return [
        Case(
            "good_speed_attitude",
            "rover-differential",
            Drive(velocity, speed_attitude),
            [],
            ROVER_RULES,
        ),
        Case(
            "good_speed_rate",
            "rover-differential",
            Drive(velocity, speed_rate),
            [],
            ROVER_RULES,
        ),
        Case(
            "good_throttle_steering",
            "rover-ackermann",
            Drive({"thrust_and_torque": True}, throttle_steering),
            [],
            ROVER_RULES,
        ),
        Case("good_position", "rover-mecanum", Drive({"position": True}, goto), [], ROVER_RULES),
        Case(
            "good_direct_actuator",
            "rover-differential",
            Drive({"direct_actuator": True}, actuators),
            [],
            ROVER_RULES,
        ),
        # OFB501: the deprecated path, velocity flag + TrajectorySetpoint.velocity.
        Case(
            "ofb501_trajectory_setpoint",
            "rover-differential",
            Drive(velocity, trajectory_velocity),
            [("OFB501", "warning", FIRST_SETPOINT)],
            ["OFB502", "OFB503", "OFB504", "OFB505", "OFB506"],
        ),
        # OFB502: a speed with no heading source (no attitude, rate or steering).
        Case(
            "ofb502_speed_alone",
            "rover-differential",
            Drive(velocity, speed_only),
            [("OFB502", "error", FIRST_JUDGED)],
            ["OFB501", "OFB503", "OFB504", "OFB505", "OFB506"],
        ),
        # OFB503: Throttle + Steering sent with the velocity flag (needs thrust_and_torque).
        Case(
            "ofb503_throttle_steering_velocity_flag",
            "rover-ackermann",
            Drive(velocity, throttle_steering),
            [("OFB503", "error", FIRST_JUDGED)],
            ["OFB501", "OFB502", "OFB504", "OFB505", "OFB506"],
        ),
        # OFB504: Speed + Rate without RoverAttitudeSetpoint published as NaN.
        Case(
            "ofb504_speed_rate_without_nan",
            "rover-differential",
            Drive(velocity, speed_rate_no_nan),
            [("OFB504", "error", FIRST_JUDGED)],
            ["OFB501", "OFB502", "OFB503", "OFB505", "OFB506"],
        ),
        # OFB505: an Ackermann rover steered by yaw on the deprecated path (also OFB501).
        Case(
            "ofb505_ackermann_yaw",
            "rover-ackermann",
            Drive({"attitude": True}, trajectory_yaw),
            [("OFB501", "warning", FIRST_SETPOINT), ("OFB505", "error", FIRST_SETPOINT)],
            ["OFB502", "OFB503", "OFB504", "OFB506"],
        ),
        # OFB506: actuator setpoints with velocity still set before direct_actuator.
        Case(
            "ofb506_actuators_behind_velocity",
            "rover-differential",
            Drive({"velocity": True, "direct_actuator": True}, actuators),
            [("OFB506", "error", FIRST_SETPOINT)],
            ["OFB501", "OFB502", "OFB503", "OFB504", "OFB505"],
        ),
        # OFB510: Speed + Steering to an Ackermann rover in OFFBOARD, as the docs' table says;
        # PX4 1.17+ rewrites the speed and heading from TrajectorySetpoint (seen running).
        Case(
            "ofb510_ackermann_speed_steering",
            "rover-ackermann",
            Drive(velocity, speed_steering),
            [("OFB510", "error", FIRST_JUDGED)],
            ["OFB501", "OFB502", "OFB503", "OFB504", "OFB505", "OFB506"],
        ),
        # The same rover on the deprecated TrajectorySetpoint: PX4's conversion is what drives
        # it (OFB501 only).
        Case(
            "ofb501_ackermann_trajectory",
            "rover-ackermann",
            Drive(velocity, trajectory_velocity),
            [("OFB501", "warning", FIRST_SETPOINT)],
            ["OFB502", "OFB503", "OFB504", "OFB506", "OFB510"],
        ),
        # -- scripts/add_rule.py adds a new rule's cases above this line
    ]


FORCED = {"detected": False, "px4_source": "user", "vehicle_source": "user"}
"""How the report gives a profile set by ``--px4`` and ``--vehicle``."""


def finding(code: str, severity: str, time_s: float | None) -> dict[str, Any]:
    return {"code": code, "severity": severity, "time_s": time_s}


def write(case: Case, other: list[tuple[str, str, float | None]]) -> None:
    path = write_mcap(HERE / f"{case.name}.mcap", case.drive.events(), release=RELEASE)
    planted = [finding(*f) for f in [*case.findings, *other]]
    levels = {f["severity"] for f in planted}
    spec = {
        "recording": path.name,
        "args": case.args(),
        "exit_status": 1 if levels & {"error", "warning"} else 0,
        "complete": True,
        # both set on the command line: a rover type cannot be told from the recording
        "profile": {"px4": RELEASE, "vehicle": case.vehicle, **FORCED},
        "findings": sorted(planted, key=lambda f: (f["time_s"] or -1.0, f["code"])),
        "clean": [c for c in case.clean if get_rule(c).applies_to(RELEASE, case.vehicle)],
    }
    (HERE / f"{case.name}.expected.json").write_text(json.dumps(spec, indent=2) + "\n")


EVERY_DRIVE: list[tuple[str, str, float | None]] = [
    # OFB701: the gate model's summary of the loss action, at the offboard request.
    ("OFB701", "info", SWITCH_T),
    # OFB002: an MCAP has no estimator validity flags, so OFB305 cannot be judged.
    ("OFB002", "info", None),
]
"""Findings of other rules every drive shows, judged correct against their rule texts."""

OTHER_RULES: dict[str, list[tuple[str, str, float | None]]] = {
    # Throttle under the velocity flag is also undeclared (OFB302), and the velocity flag's own
    # setpoint (RoverSpeedSetpoint) never comes (OFB303: its 0.5 s grace runs from the later of
    # the switch and arming, recorded armed at 2.2 s).
    "ofb503_throttle_steering_velocity_flag": [
        ("OFB302", "error", FIRST_SETPOINT),
        ("OFB303", "error", 2.7),
    ],
    # The same for ActuatorMotors and ActuatorServos under the velocity flag.
    "ofb506_actuators_behind_velocity": [
        ("OFB302", "error", FIRST_SETPOINT),
        ("OFB302", "error", FIRST_SETPOINT),
        ("OFB303", "error", 2.7),
    ],
}
"""Findings of other rules a case also shows, each judged by hand against the rule text."""


def main() -> None:
    for case in cases():
        write(case, EVERY_DRIVE + OTHER_RULES.get(case.name, []))


if __name__ == "__main__":
    main()
