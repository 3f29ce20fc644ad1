"""Build the rule corpus: one bad and one good recording per content, control-mode, legacy rule.

Run ``.venv/bin/python corpora/rules/build.py``; it is deterministic. ROS 2 rules are written as
MCAP (``fuzzoff.formats.mcap.writer``, px4_msgs of the case's release), the estimate rule OFB305 and
the legacy rules OFB801-OFB803 as ULog (``fuzzoff.formats.ulog.writer``, the 1.15 and the legacy
layouts), and the MAVLink side of OFB405/OFB406 (``SET_ATTITUDE_TARGET``) as a tlog
(``fuzzoff.formats.tlog.writer``). Each ``NAME.expected.json`` lists the findings planted here,
judged against the rule texts (rules/OFB*.toml), and ``clean``: the rules the recording exercises
that must stay silent.

Every flight is built from one realistic pattern (``Flight``): a companion streams
``OffboardControlMode`` at 10 Hz with a PX4-synced ``timestamp``, the vehicle sits disarmed in
POSCTL, the companion switches to OFFBOARD after 1.5 s of stream (accepted, one ack on 1.15),
arms at 2.0 s, and publishes its setpoints at 20 Hz only from the switch on, a slowly moving
target. A case changes one thing of it. Every planted finding is at the time the rule text
says (the first message of the bad run, or the threshold crossing); the findings every
recording of a format also gets are listed in ``context_findings``.
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from fuzzoff.events import (
    ActuatorMotors,
    ArmingCheckReply,
    ArmingCheckRequest,
    AttitudeSetpoint,
    Command,
    CommandAck,
    ControlMode,
    Event,
    ExtComponentReply,
    ExtComponentRequest,
    FailsafeFlags,
    LegacyControlMode,
    PositionSetpointTriplet,
    RatesSetpoint,
    SetAttitudeTarget,
    ThrustSetpoint,
    TrajectorySetpoint,
    VehicleInfo,
    VehicleStatus,
)
from fuzzoff.formats.mcap.writer import write_mcap
from fuzzoff.formats.tlog.writer import write_tlog
from fuzzoff.formats.ulog.writer import write_ulog

HERE = Path(__file__).resolve().parent
Fields = dict[str, Any]
"""Keyword fields of an event (flags of a control mode, validity of a triplet)."""
ALTCTL, POSCTL, OFFBOARD = 1, 2, 14
NAN = math.nan
BOOT_US = 120_000_000
"""The companion's timestamps are PX4-synced: about two minutes after PX4's boot."""

SWITCH_T, ARM_T, END_T = 1.5, 2.0, 6.0
OCM_PERIOD, SETPOINT_PERIOD, STATUS_PERIOD = 0.1, 0.05, 0.2


def ticks(start: float, stop: float, period: float) -> list[float]:
    """Times in [start, stop) every ``period``, rounded to the microsecond."""
    n = math.ceil((stop - start) / period - 1e-9)
    return [round(start + i * period, 6) for i in range(n)]


def stamp(t: float) -> int:
    return BOOT_US + round(t * 1e6)


@dataclass
class Flight:
    """The realistic pattern; ``setpoint(t)`` gives the companion's setpoints at ``t``."""

    flags: Fields
    setpoint: Callable[[float], list[Event]]
    setpoints_from: float = SWITCH_T + 0.05
    """The companion starts its setpoints once the switch is acked (at 1.52 s)."""
    ocm_stamp: Callable[[float], int] = stamp
    ocm_flags: Callable[[float], Fields] | None = None
    extra: list[Event] = field(default_factory=list)
    end: float = END_T

    def events(self) -> list[Event]:
        out: list[Event] = []
        for t in ticks(0.0, self.end, OCM_PERIOD):
            flags = self.ocm_flags(t) if self.ocm_flags else self.flags
            out.append(ControlMode(t=t, sender_time_us=self.ocm_stamp(t), **flags))
        for t in ticks(0.0, self.end, STATUS_PERIOD):
            nav = OFFBOARD if t >= SWITCH_T + 0.05 else POSCTL
            out.append(VehicleStatus(t=t, nav_state=nav, armed=t >= ARM_T + 0.05))
        out += [
            Command(t=SWITCH_T, command=176, params=(1.0, 6.0, 0, 0, 0, 0, 0), from_external=True),
            CommandAck(t=SWITCH_T + 0.02, command=176, result=0),
            Command(t=ARM_T, command=400, params=(1.0, 0, 0, 0, 0, 0, 0), from_external=True),
            CommandAck(t=ARM_T + 0.02, command=400, result=0),
        ]
        for t in ticks(self.setpoints_from, self.end, SETPOINT_PERIOD):
            out += self.setpoint(t)
        out += self.extra
        return sorted(out, key=lambda e: e.t)


def arm_lost(events: list[Event]) -> list[Event]:
    """The flight whose ARM never reached PX4: no ack for it, the vehicle stays disarmed."""
    out: list[Event] = []
    for event in events:
        if isinstance(event, CommandAck) and event.command == 400:
            continue
        out.append(replace(event, armed=False) if isinstance(event, VehicleStatus) else event)
    return out


def climb(t: float) -> list[Event]:
    """Position control: up to 5 m, then a slow circle (the content changes every message)."""
    z = -min(5.0, max(0.5, 2.0 * (t - SWITCH_T)))
    x, y = math.cos(0.2 * t), math.sin(0.2 * t)
    return [TrajectorySetpoint(t=t, position=(x, y, z), yaw=0.1 * t)]


def quat(yaw: float) -> tuple[float, float, float, float]:
    return (math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2))


def attitude(t: float) -> list[Event]:
    return [AttitudeSetpoint(t=t, q_d=quat(0.1 * t), thrust_body=(0.0, 0.0, -0.6))]


def rates(t: float) -> list[Event]:
    return [RatesSetpoint(t=t, roll=0.0, pitch=0.0, yaw=0.05 * t, thrust_body=(0.0, 0.0, -0.6))]


def motors(t: float) -> list[Event]:
    level = 0.5 + 0.01 * math.sin(t)
    return [ActuatorMotors(t=t, control=(level, level, level, level, NAN, NAN, NAN, NAN))]


POSITION = {"position": True}
MODE_NAME, MODE_ID = "Survey", 23  # the first external mode: nav_state EXTERNAL1


def external_mode_flight(api: int, replies_until: float) -> list[Event]:
    """A px4-ros2-interface-lib mode on PX4 1.18 (API version 2), the vehicle disarmed in
    POSCTL: the node registers its mode and arming check at 0.5 s with API version ``api``,
    PX4 accepts at 0.55 s and asks for arming checks every 300 ms from 0.6 s; the node replies
    within 10 ms while ``t < replies_until`` (never when the library refused PX4's API). PX4
    drops a registration more than 3 requests after its last reply from
    ``valid_registrations_mask``."""
    out: list[Event] = [
        ExtComponentRequest(
            t=0.5,
            sender_time_us=stamp(0.5),
            request_id=4711,
            name=MODE_NAME,
            api_version=api,
            arming_check=True,
            mode=True,
        ),
        ExtComponentReply(
            t=0.55,
            sender_time_us=stamp(0.55),
            request_id=4711,
            name=MODE_NAME,
            api_version=2,
            success=True,
            arming_check_id=0,
            mode_id=MODE_ID,
        ),
    ]
    for t in ticks(0.0, END_T, STATUS_PERIOD):
        out.append(VehicleStatus(t=t, nav_state=POSCTL, armed=False))
    misses, answering = 0, api == 2
    for n, t in enumerate(ticks(0.6, END_T, 0.3)):
        mask = 1 if misses <= 3 else 0
        out.append(
            ArmingCheckRequest(
                t=t, sender_time_us=stamp(t), request_id=n % 256, registrations_mask=mask
            )
        )
        if answering and t < replies_until:
            out.append(
                ArmingCheckReply(
                    t=round(t + 0.01, 6),
                    sender_time_us=stamp(t + 0.01),
                    request_id=n % 256,
                    registration_id=0,
                )
            )
        else:
            misses += 1
    return sorted(out, key=lambda e: e.t)


# ---------------------------------------------------------------------------------------------
# Cases: (name, events, release, expected findings, clean rules, extra CLI args)


@dataclass
class Case:
    name: str
    events: list[Event]
    findings: list[tuple[str, str, float | None]]
    clean: list[str]
    fmt: str = "mcap"
    px4: str = "1.15"
    vehicle: str = "mc"
    release: str = "1.15"
    ulog_version: str | None = "1.15.4"
    ulog_layout: str | None = None
    params: dict[str, float] = field(default_factory=dict)
    request: float | None = None
    """Time of the offboard request (for OFB701), where it is not the flights' 1.5 s."""
    offboard: bool = True
    """The vehicle uses offboard (OFB701 states its loss behaviour)."""
    stream: bool = True
    """The recording holds a setpoint stream (without one, no rule is named not checkable)."""
    note: str = ""

    @property
    def filename(self) -> str:
        return f"{self.name}.{self.fmt}"

    def args(self) -> list[str]:
        if self.fmt == "mcap":
            return ["--px4", self.px4, "--vehicle", self.vehicle]
        return []


def mcap_cases() -> list[Case]:
    cases: list[Case] = []

    good = Flight(POSITION, climb).events()
    cases.append(
        Case(
            "good_position_flight",
            good,
            [],
            [
                *("OFB106", "OFB107", "OFB203", "OFB301", "OFB302", "OFB303", "OFB304"),
                *("OFB401", "OFB402", "OFB403", "OFB404"),
            ],
            note="the realistic pattern with position control",
        )
    )
    cases.append(
        Case(
            "good_attitude_flight",
            Flight({"attitude": True}, attitude).events(),
            [],
            ["OFB302", "OFB303", "OFB404", "OFB405", "OFB406"],
        )
    )
    cases.append(
        Case(
            "good_rates_flight",
            Flight({"body_rate": True}, rates).events(),
            [],
            ["OFB302", "OFB303", "OFB404", "OFB406", "OFB408"],
        )
    )
    cases.append(
        Case(
            "good_direct_actuator",
            Flight({"direct_actuator": True}, motors).events(),
            [],
            ["OFB302", "OFB303", "OFB406", "OFB407"],
        )
    )

    # OFB106: the companion's clock stops at 3.0 s; the first message lagging by more than
    # COM_OF_LOSS_T (1.0 s) is at 4.1 s. PX4 1.15 takes the stream for lost (warning): it judges
    # the keep-alive's age by its rewritten timestamp (gate spec 2.1.1), so at a 10 Hz check
    # within 0.1 s after 4.0 s it fails over to POSCTL, which the recorded status shows from
    # 4.1 s with its failsafe flag (OFB103 at 4.1 s, that status dating it).
    frozen_clock = [
        e
        for e in Flight(POSITION, climb, ocm_stamp=lambda t: stamp(min(t, 3.0))).events()
        if not (isinstance(e, VehicleStatus) and e.t >= 4.1)
    ]
    frozen_clock += [
        VehicleStatus(t=t, nav_state=POSCTL, armed=True, failsafe=True)
        for t in [4.1, *ticks(4.2, END_T, STATUS_PERIOD)]
    ]
    frozen_clock.sort(key=lambda e: e.t)
    cases.append(
        Case(
            "ofb106_clock_stops",
            frozen_clock,
            # ...and the companion keeps publishing TrajectorySetpoint in POSCTL (OFB203).
            [("OFB106", "warning", 4.1), ("OFB103", "error", 4.1), ("OFB203", "error", 4.15)],
            ["OFB202"],
        )
    )

    # OFB107: velocity control; at 2.5 s the planner dies while commanding 2 m/s, and the
    # library re-sends its last setpoint until 14 s: 11.5 s of the same motion (over 10 s).
    def cruise(t: float) -> list[Event]:
        return [TrajectorySetpoint(t=t, velocity=(2.0, 0.2 * math.sin(t), 0.0), yaw=0.0)]

    def dead_planner(t: float) -> list[Event]:
        return [replace(sp, t=t) for sp in cruise(min(t, 2.5))]

    velocity = {"velocity": True}
    cases.append(
        Case(
            "ofb107_planner_dies",
            Flight(velocity, dead_planner, end=14.0).events(),
            [("OFB107", "error", 2.5)],
            [],
        )
    )

    # ...and the same planner stopping with a hold (zero velocity), which is never reported.
    def planner_holds(t: float) -> list[Event]:
        if t < 2.5:
            return cruise(t)
        return [TrajectorySetpoint(t=t, velocity=(0.0, 0.0, 0.0), yaw=0.0)]

    cases.append(
        Case(
            "ofb107_planner_leaves_a_hold",
            Flight(velocity, planner_holds, end=14.0).events(),
            [],
            ["OFB107"],
        )
    )

    # OFB203: the px4_ros_com pattern: setpoints from the first second, before the switch,
    # while disarmed: nothing flies them (info).
    early = Flight(POSITION, climb, setpoints_from=0.0).events()
    cases.append(Case("ofb203_setpoints_before_switch", early, [("OFB203", "info", 0.0)], []))
    # OFB203: a pilot flies in POSCTL while the companion publishes setpoints and never asks
    # for offboard: they fight PX4's own flight task (error).
    fighting: list[Event] = [
        ControlMode(t=t, position=True, sender_time_us=stamp(t))
        for t in ticks(0.0, END_T, OCM_PERIOD)
    ]
    fighting += [
        VehicleStatus(t=t, nav_state=POSCTL, armed=True) for t in ticks(0.0, END_T, STATUS_PERIOD)
    ]
    fighting += [e for t in ticks(1.0, END_T, SETPOINT_PERIOD) for e in climb(t)]
    fighting.sort(key=lambda e: e.t)
    cases.append(
        Case(
            "ofb203_setpoints_in_position_mode",
            fighting,
            [("OFB203", "error", 1.0)],
            [],
            offboard=False,
        )
    )

    # OFB301: the first 0.3 s of OffboardControlMode declare nothing.
    def empty_first(t: float) -> Fields:
        return {} if t < 0.3 else POSITION

    empty = Flight(POSITION, climb, ocm_flags=empty_first).events()
    cases.append(Case("ofb301_empty_control_mode", empty, [("OFB301", "error", 0.0)], []))

    # OFB302: position control, but the companion also writes VehicleAttitudeSetpoint from 3 s.
    def with_attitude(t: float) -> list[Event]:
        return climb(t) + (attitude(t) if t >= 3.0 else [])

    cases.append(
        Case(
            "ofb302_attitude_under_position",
            Flight(POSITION, with_attitude).events(),
            [("OFB302", "error", 3.0)],
            [],
        )
    )

    # OFB303: thrust_and_torque declared, only VehicleThrustSetpoint published.
    def thrust_only(t: float) -> list[Event]:
        return [ThrustSetpoint(t=t, xyz=(0.0, 0.0, -0.6 + 0.01 * math.sin(t)))]

    cases.append(
        Case(
            "ofb303_torque_missing",
            Flight({"thrust_and_torque": True}, thrust_only).events(),
            [("OFB303", "error", 2.2 + 0.5)],
            [],
            note="in offboard from the ack (1.52 s), armed per the status at 2.2 s; + grace 0.5 s",
        )
    )

    # OFB304: position control until 4 s, then velocity control (content follows).
    def to_velocity(t: float) -> list[Event]:
        if t < 4.0:
            return climb(t)
        return [TrajectorySetpoint(t=t, velocity=(1.0, 0.1 * (t - 4.0), 0.0), yaw=0.1 * t)]

    cases.append(
        Case(
            "ofb304_position_then_velocity",
            Flight(
                POSITION,
                to_velocity,
                ocm_flags=lambda t: POSITION if t < 4.0 else {"velocity": True},
            ).events(),
            [("OFB304", "info", 4.0)],
            [],
        )
    )

    # OFB401: velocity declared, the content still carries the position target.
    def velocity_with_position(t: float) -> list[Event]:
        (sp,) = climb(t)
        assert isinstance(sp, TrajectorySetpoint)
        return [TrajectorySetpoint(t=t, position=sp.position, velocity=(0.5, 0.0, 0.0))]

    cases.append(
        Case(
            "ofb401_velocity_declared_position_sent",
            Flight({"velocity": True}, velocity_with_position).events(),
            [("OFB401", "error", SWITCH_T + 0.05)],
            [],
        )
    )

    # OFB402: from 4 s the companion sends yaw-only setpoints.
    def yaw_only(t: float) -> list[Event]:
        return climb(t) if t < 4.0 else [TrajectorySetpoint(t=t, yaw=0.1 * t)]

    cases.append(
        Case(
            "ofb402_yaw_only_setpoints",
            Flight(POSITION, yaw_only).events(),
            [("OFB402", "error", 4.0)],
            [],
        )
    )

    # OFB403: from 4 s y is NaN while x and z are positions.
    def y_missing(t: float) -> list[Event]:
        (sp,) = climb(t)
        assert isinstance(sp, TrajectorySetpoint)
        if t < 4.0:
            return [sp]
        return [TrajectorySetpoint(t=t, position=(sp.position[0], NAN, sp.position[2]))]

    cases.append(
        Case("ofb403_y_nan", Flight(POSITION, y_missing).events(), [("OFB403", "error", 4.0)], [])
    )

    # OFB404: a takeoff to 5 m written in ENU: z = +5 right after arming.
    def enu_takeoff(t: float) -> list[Event]:
        (sp,) = climb(t)
        assert isinstance(sp, TrajectorySetpoint)
        x, y, z = sp.position
        return [TrajectorySetpoint(t=t, position=(x, y, -z), yaw=sp.yaw)]

    cases.append(
        Case(
            "ofb404_enu_takeoff",
            Flight(POSITION, enu_takeoff).events(),
            [("OFB404", "error", 1.8)],
            [],
            note="the first setpoint with |z| over 0.5 m: 2 * (t - 1.5) > 0.5 first at 1.8 s",
        )
    )
    cases += takeoff_cases(enu_takeoff)

    # OFB405: attitude control with a quaternion that is not normalised from 4 s.
    def scaled_quat(t: float) -> list[Event]:
        if t < 4.0:
            return attitude(t)
        w, x, y, z = quat(0.1 * t)
        return [AttitudeSetpoint(t=t, q_d=(2 * w, x, y, 2 * z), thrust_body=(0.0, 0.0, -0.6))]

    cases.append(
        Case(
            "ofb405_quaternion_scaled",
            Flight({"attitude": True}, scaled_quat).events(),
            [("OFB405", "error", 4.0)],
            [],
        )
    )

    # OFB406: thrust in newtons-like units: -1.4 from 4 s.
    def strong(t: float) -> list[Event]:
        thrust = -0.6 if t < 4.0 else -1.4
        return [AttitudeSetpoint(t=t, q_d=quat(0.1 * t), thrust_body=(0.0, 0.0, thrust))]

    cases.append(
        Case(
            "ofb406_thrust_over_one",
            Flight({"attitude": True}, strong).events(),
            [("OFB406", "error", 4.0)],
            [],
        )
    )

    # OFB407: motor 3 turns NaN at 4 s while armed.
    def motor_dies(t: float) -> list[Event]:
        (m,) = motors(t)
        assert isinstance(m, ActuatorMotors)
        if t < 4.0:
            return [m]
        c = list(m.control)
        c[2] = NAN
        return [ActuatorMotors(t=t, control=tuple(c))]

    cases.append(
        Case(
            "ofb407_motor_nan_while_armed",
            Flight({"direct_actuator": True}, motor_dies).events(),
            [("OFB407", "warning", 4.0)],
            [],
        )
    )

    # OFB408: yaw rate NaN from 4 s.
    def yaw_nan(t: float) -> list[Event]:
        if t < 4.0:
            return rates(t)
        return [RatesSetpoint(t=t, roll=0.0, pitch=0.0, yaw=NAN, thrust_body=(0.0, 0.0, -0.6))]

    cases.append(
        Case(
            "ofb408_yaw_rate_nan",
            Flight({"body_rate": True}, yaw_nan).events(),
            [("OFB408", "error", 4.0)],
            [],
        )
    )
    # OFB208 (command-unanswered): the ARM never reaches PX4 (issue 28 miss 3): no ack, the
    # vehicle stays disarmed in OFFBOARD
    cases.append(
        Case(
            "ofb208_command_unanswered",
            arm_lost(Flight(POSITION, climb).events()),
            # and the gate model, which took the arm, disagrees with the disarmed status
            [("OFB208", "error", ARM_T), ("OFB202", "warning", 3.6)],
            [],
        )
    )
    cases.append(
        Case(
            "good_ofb208_command_unanswered",
            Flight(POSITION, climb).events(),
            [],
            ["OFB208"],
        )
    )
    # OFB209 (external-mode-refused): px4-ros2-interface-lib's API 1 against PX4 1.18's API 2
    # (the library gives up, no arming check is answered), and a mode whose node stops
    # answering PX4's arming checks (a watchdog killed it at 3 s)
    cases.append(
        Case(
            "ofb209_external_mode_refused",
            external_mode_flight(api=1, replies_until=0.0),
            [("OFB209", "error", 0.55)],
            [],
            px4="1.18",
            release="main",
            offboard=False,
            stream=False,
        )
    )
    cases.append(
        Case(
            "ofb209_external_mode_dropped",
            external_mode_flight(api=2, replies_until=3.0),
            [("OFB209", "error", 3.9)],
            [],
            px4="1.18",
            release="main",
            offboard=False,
            stream=False,
        )
    )
    cases.append(
        Case(
            "good_ofb209_external_mode",
            external_mode_flight(api=2, replies_until=END_T),
            [],
            ["OFB209"],
            px4="1.18",
            release="main",
            offboard=False,
            stream=False,
        )
    )
    # -- scripts/add_rule.py adds a new rule's cases above this line
    return cases


# MAVLink: OFB405 and OFB406 also judge SET_ATTITUDE_TARGET (a tlog of the companion's link).
MAV: Fields = {"vehicle": "1", "source_system": 1, "source_component": 191}
ATTITUDE_ONLY = 0b111  # body rates ignored: the quaternion and the thrust are used


def attitude_target_flight(target: Callable[[float], tuple[Any, float]]) -> list[Event]:
    """MAVSDK-style attitude control: SET_ATTITUDE_TARGET at 20 Hz from 0 s (the keep-alive),
    the switch at 1.5 s, arming at 2.5 s, 1 Hz HEARTBEAT; ``target(t)`` gives (q, thrust)."""
    out: list[Event] = [
        VehicleInfo(t=0.0, vehicle="1", px4_version="1.15.4"),
        VehicleInfo(t=0.0, vehicle="1", mav_type=2, vehicle_type="mc"),
    ]
    for t in ticks(0.0, 8.0, 1.0):
        nav = OFFBOARD if t >= 2.0 else POSCTL
        out.append(VehicleStatus(t=t, vehicle="1", nav_state=nav, armed=t >= 3.0))
    for t in ticks(0.0, 8.0, SETPOINT_PERIOD):
        q, thrust = target(t)
        out.append(
            SetAttitudeTarget(
                t=t,
                sender_time_us=stamp(t),
                type_mask=ATTITUDE_ONLY,
                target_system=1,
                target_component=1,
                q=q,
                thrust=thrust,
                **MAV,
            )
        )
    link: Fields = {"target_system": 1, "target_component": 1, "from_external": True, **MAV}
    out += [
        Command(t=1.5, command=176, params=(1.0, 6.0, 0, 0, 0, 0, 0), **link),
        CommandAck(t=1.51, vehicle="1", command=176, result=0, target_system=1),
        Command(t=2.5, command=400, params=(1.0, 0, 0, 0, 0, 0, 0), **link),
        CommandAck(t=2.51, vehicle="1", command=400, result=0, target_system=1),
    ]
    return sorted(out, key=lambda e: e.t)


def tlog_cases() -> list[Case]:
    def good(t: float) -> tuple[Any, float]:
        return quat(0.1 * t), 0.6

    def scaled(t: float) -> tuple[Any, float]:
        w, x, y, z = quat(0.1 * t)
        return ((w, x, y, z) if t < 4.0 else (0.5 * w, x, y, 0.5 * z)), 0.6

    def too_strong(t: float) -> tuple[Any, float]:
        return quat(0.1 * t), 0.6 if t < 4.0 else 1.2

    return [
        Case(
            "good_attitude_target",
            attitude_target_flight(good),
            [],
            ["OFB405", "OFB406"],
            fmt="tlog",
            request=1.5,
        ),
        Case(
            "ofb405_attitude_target_half_quaternion",
            attitude_target_flight(scaled),
            [("OFB405", "error", 4.0)],
            [],
            fmt="tlog",
            request=1.5,
        ),
        Case(
            "ofb406_attitude_target_thrust_over_one",
            attitude_target_flight(too_strong),
            [("OFB406", "error", 4.0)],
            [],
            fmt="tlog",
            request=1.5,
        ),
    ]


def ulog_cases() -> list[Case]:
    cases: list[Case] = []
    valid = FailsafeFlags(t=0.0, local_position_valid=True, local_velocity_valid=True)
    lost = FailsafeFlags(t=4.0, local_position_valid=False, local_velocity_valid=True)
    logged = [_as_logged(e) for e in Flight(POSITION, climb).events()]
    cases.append(Case("good_estimates", [*logged, valid], [], ["OFB305"], fmt="ulg"))

    # OFB305: the local position estimate turns invalid at 4.0 s in offboard. PX4 1.15 then
    # takes the offboard signal for lost (gate spec 2.1) and, without a position estimate, falls
    # back to ALTCTL instead of the configured POSCTL (OFB103, OFB702); the logged status
    # shows ALTCTL with the failsafe flag from the next 10 Hz check pass (4.2 s: the status
    # logged every 0.1 s; it dates OFB103, as the log has no failsafe_flags sample of the loss).
    def failsafe(e: Event) -> Event:
        if isinstance(e, VehicleStatus) and e.t >= 4.1:
            return replace(e, nav_state=ALTCTL, failsafe=True, user_intention=OFFBOARD)
        return e

    cases.append(
        Case(
            "ofb305_position_estimate_lost",
            [*(failsafe(e) for e in logged), valid, lost],
            # the loss ran the fallback ALTCTL instead of the configured POSCTL: OFB702 error
            [("OFB305", "error", 4.0), ("OFB103", "error", 4.2), ("OFB702", "error", 4.2)],
            [],
            fmt="ulg",
        )
    )
    cases += legacy_cases()
    return cases


def takeoff_cases(enu_takeoff: Callable[[float], list[Event]]) -> list[Case]:
    """OFB404 after a takeoff in another mode (PX4 AUTO_TAKEOFF from 0.5 s, Hold from 4.0 s,
    then the switch to OFFBOARD at 6.0 s): a first offboard descent is an ordinary command
    there (clean); a height written in ENU flies the vehicle into the ground (error)."""
    takeoff, hold = 17, 4
    switch = 6.0

    def flight(setpoint: Callable[[float], list[Event]]) -> list[Event]:
        out: list[Event] = [
            ControlMode(t=t, position=True, sender_time_us=stamp(t))
            for t in ticks(0.0, 12.0, OCM_PERIOD)
        ]
        for t in ticks(0.0, 12.0, STATUS_PERIOD):
            nav = (
                POSCTL
                if t < 0.5
                else takeoff
                if t < 4.0
                else hold
                if t < switch + 0.05
                else OFFBOARD
            )
            out.append(VehicleStatus(t=t, nav_state=nav, armed=t >= 0.45))
        out += [
            Command(t=0.4, command=400, params=(1.0, 0, 0, 0, 0, 0, 0), from_external=True),
            CommandAck(t=0.42, command=400, result=0),
            Command(t=0.5, command=22, params=(0.0,) * 7, from_external=True),
            CommandAck(t=0.52, command=22, result=0),
            Command(t=switch, command=176, params=(1.0, 6.0, 0, 0, 0, 0, 0), from_external=True),
            CommandAck(t=switch + 0.02, command=176, result=0),
        ]
        for t in ticks(switch + 0.05, 12.0, SETPOINT_PERIOD):
            out += setpoint(t)
        return sorted(out, key=lambda e: e.t)

    def descend(t: float) -> list[Event]:
        # from the 2.5 m takeoff height down to 1 m, then a hold there
        z = min(-1.0, -2.5 + 0.5 * (t - switch))
        return [TrajectorySetpoint(t=t, position=(0.0, 0.0, z), yaw=0.0)]

    def enu_hold(t: float) -> list[Event]:
        return [TrajectorySetpoint(t=t, position=(0.0, 0.0, 2.5), yaw=0.0)]

    return [
        Case(
            "ofb404_descent_after_takeoff",
            flight(descend),
            [],
            ["OFB404"],
            request=switch,
            note="a first offboard command below the takeoff height, in NED",
        ),
        Case(
            "ofb404_enu_height_after_takeoff",
            flight(enu_hold),
            [("OFB404", "error", switch + 0.05)],
            [],
            request=switch,
            note="2.5 m written in ENU (z = +2.5): 2.5 m below the origin",
        ),
    ]


def _as_logged(event: Event) -> Event:
    """The ULog copy of an event: PX4 logged it (origin ``vehicle``)."""
    return replace(event, origin="vehicle", sender_time_us=None)


LEGACY_GOOD = {
    "ignore_thrust": True,
    "ignore_attitude": True,
    "ignore_bodyrate": True,
    "ignore_acceleration_force": True,
}


def legacy_flight(
    mode: Callable[[float], Fields],
    triplet: Callable[[float], Fields],
) -> list[Event]:
    """A uORB-era offboard flight as its ULog shows it (seed 003): the companion publishes
    ``offboard_control_mode`` and ``position_setpoint_triplet`` directly."""
    out: list[Event] = []
    for t in ticks(0.0, END_T, OCM_PERIOD):
        out.append(LegacyControlMode(t=t, origin="vehicle", **mode(t)))
        if t >= SWITCH_T:
            out.append(PositionSetpointTriplet(t=t, origin="vehicle", **triplet(t)))
    for t in ticks(0.0, END_T, STATUS_PERIOD):
        nav = OFFBOARD if t >= SWITCH_T + 0.05 else POSCTL
        out.append(VehicleStatus(t=t, nav_state=nav, armed=t >= ARM_T + 0.05))
    return sorted(out, key=lambda e: e.t)


def legacy_cases() -> list[Case]:
    ok_triplet: Fields = {"current_valid": True, "current_position_valid": True, "current_type": 0}

    def legacy(name: str, events: list[Event], findings: list[Any], clean: list[str]) -> Case:
        return Case(
            name,
            events,
            findings,
            clean,
            fmt="ulg",
            px4="legacy",
            ulog_version="1.7.3",
            ulog_layout="legacy",
        )

    cases = [
        legacy(
            "legacy_good",
            legacy_flight(lambda t: LEGACY_GOOD, lambda t: ok_triplet),
            [],
            ["OFB801", "OFB802", "OFB803"],
        )
    ]
    no_acc_ignore = {**LEGACY_GOOD, "ignore_acceleration_force": False}
    cases.append(
        legacy(
            "ofb801_acceleration_not_ignored",
            legacy_flight(
                lambda t: no_acc_ignore if t >= 3.0 else LEGACY_GOOD, lambda t: ok_triplet
            ),
            [("OFB801", "error", 3.0)],
            [],
        )
    )
    cases.append(
        legacy(
            "ofb802_next_filled",
            legacy_flight(
                lambda t: LEGACY_GOOD,
                lambda t: {**ok_triplet, "next_valid": True} if t >= 3.0 else ok_triplet,
            ),
            [("OFB802", "info", 3.0)],
            [],
        )
    )
    cases.append(
        legacy(
            "ofb803_position_invalid",
            legacy_flight(
                lambda t: LEGACY_GOOD,
                lambda t: {**ok_triplet, "current_position_valid": t < 3.0},
            ),
            [("OFB803", "error", 3.0)],
            [],
        )
    )
    return cases


# ---------------------------------------------------------------------------------------------


def context_findings(case: Case) -> list[tuple[str, str, float | None]]:
    """What every recording of the case's format also gets, checked against the rule texts.

    * OFB701 (info): the loss-action summary at the offboard request (1.5 s; the legacy flights
      have no recorded command, so at the first OFFBOARD status, 1.6 s).
    * OFB002 (info, no time), one line for the rules the format cannot show: in MCAP OFB305 (no
      estimator flags on ROS 2); in a 1.15 ULog OFB104, OFB105 (subsampled keep-alive), OFB106,
      OFB203, OFB302 (only PX4's copies of the messages); in a legacy ULog OFB104, OFB105.
    * OFB005 (info, no time) where the flight never used offboard; no OFB002 where it holds no
      stream at all (the external-mode cases of OFB209).
    """
    not_checkable = (
        [("OFB002", "info", None)] if case.fmt in ("mcap", "ulg") and case.stream else []
    )
    request = (
        case.request if case.request is not None else 1.6 if case.px4 == "legacy" else SWITCH_T
    )
    summary = [("OFB701", "info", request)] if case.offboard else [("OFB005", "info", None)]
    return not_checkable + summary


def write(case: Case) -> None:
    path = HERE / case.filename
    if case.fmt == "mcap":
        write_mcap(path, case.events, release=case.release)
    elif case.fmt == "tlog":
        write_tlog(path, case.events)
    else:
        write_ulog(
            path,
            case.events,
            px4_version=case.ulog_version,
            layout=case.ulog_layout,
            vehicle_type=case.vehicle,
            params=case.params or None,
        )
    expected: dict[str, Any] = {
        "recording": case.filename,
        "args": case.args(),
        "exit_status": 1 if any(sev != "info" for _, sev, _ in case.findings) else 0,
        "complete": True,
        "findings": [
            {"code": code, "severity": sev, "time_s": t}
            for code, sev, t in [*context_findings(case), *case.findings]
        ],
        "clean": case.clean,
    }
    (HERE / f"{case.name}.expected.json").write_text(json.dumps(expected, indent=2) + "\n")


def all_cases() -> Iterable[Case]:
    yield from mcap_cases()
    yield from tlog_cases()
    yield from ulog_cases()


def main() -> None:
    for case in all_cases():
        write(case)
        print(f"{case.filename}: {(HERE / case.filename).stat().st_size} bytes")


if __name__ == "__main__":
    main()
