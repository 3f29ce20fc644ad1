"""Build the MAVLink setpoint-field corpus (OFB601-OFB609, OFB507-OFB509): tlogs and MAVROS bags.

Run ``.venv/bin/python corpora/rules_mavlink/build.py``; it is deterministic. Each case is
written as a tlog (``fuzzoff.formats.tlog.writer``: the MAVLink the companion sent, with the
autopilot's HEARTBEAT, COMMAND_ACK, PARAM_VALUE and AUTOPILOT_VERSION) and, where a MAVROS bag
can show the rule, as a ROS 1 bag of MAVROS ``setpoint_raw`` topics and ``state``
(``fuzzoff.formats.rosbag1.writer``). A bag cannot show OFB204, OFB205 (it records no
command), OFB607 (MAVROS fills the target ids from its own parameters), OFB509 (no parameters
in a bag) or OFB608 (MAVROS's ``actuator_control`` topic is not read). Each
``NAME.expected.json`` lists the findings planted here, judged against the rule texts
(rules/OFB5*.toml, rules/OFB6*.toml), and ``clean``: the rules the recording exercises that
must stay silent.

Every flight follows one pattern (``flight``): PX4 1.16.2 (AUTOPILOT_VERSION in the tlog), the
companion (1/191) streams its setpoint at 20 Hz from 1.0 s, switches to OFFBOARD at 3.0 s
(accepted), arms at 4.5 s, switches to AUTO_LOITER at 9.5 s and stops streaming at 10.5 s,
after the HEARTBEAT (1 Hz) showed the new mode at 10.0 s (a MAVROS bag sees the switch only
there). A bad
case changes the stream, or adds a second one from 5.0 s to 6.0 s at 10 Hz beside the good
stream, so the keep-alive and the gate stay as in the good flight. The OFB609 cases fly the same
pattern on PX4 1.8.2 (``legacy``), tlog only.
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
    Command,
    CommandAck,
    Event,
    Parameter,
    SetActuatorControlTarget,
    SetAttitudeTarget,
    SetPositionTargetGlobal,
    SetPositionTargetLocal,
    VehicleInfo,
    VehicleStatus,
)
from fuzzoff.formats.rosbag1.writer import write_rosbag1
from fuzzoff.formats.tlog.writer import write_tlog

HERE = Path(__file__).resolve().parent
POSCTL, OFFBOARD, AUTO_LOITER = 2, 14, 4
TEMPORARILY_REJECTED = 1
VERSION, PX4 = "1.16.2", "1.16"
MAV_TYPES = {"mc": 2, "fw": 1, "rover-differential": 10}
PERIOD, EXTRA_PERIOD = 0.05, 0.1
START, SWITCH, ARM, LOITER, STOP, END = 1.0, 3.0, 4.5, 9.5, 10.5, 11.0
EXTRA_FROM, EXTRA_TO = 5.0, 6.0
SENT: dict[str, Any] = {
    "vehicle": "1",
    "source_system": 1,
    "source_component": 191,
    "target_system": 1,
    "target_component": 1,
}
ORIGIN = (473977420, 85455940)
"""lat_int, lon_int of the take-off point (1e-7 degrees)."""

POSITION_YAW = 0x09F8
"""x, y, z and yaw (MAVROS setpoint_position/local)."""
POSITION_ONLY = 0x0DF8
VELOCITY_ONLY = 0x0DC7
VELOCITY_YAW = 0x09C7
LOITER_TYPE = 0x3000
GLOBAL_LATLON_YAW = 0x09FC
"""lat, lon and yaw; alt, velocity and acceleration ignored."""


def ticks(start: float, stop: float, period: float) -> list[float]:
    n = math.ceil((stop - start) / period - 1e-9)
    return [round(start + i * period, 6) for i in range(n)]


Maker = Callable[[float], Event]


def local(t: float, mask: int = POSITION_YAW, frame: int = 1, **kw: Any) -> Event:
    x = round(0.5 * math.sin(0.3 * t), 4)
    fields: dict[str, Any] = {**SENT, "position": (x, 0.0, -2.5), "yaw": 0.0, **kw}
    return SetPositionTargetLocal(
        t=t,
        sender_time_us=round(t * 1e6) + 5_000_000,
        type_mask=mask,
        coordinate_frame=frame,
        **fields,
    )


def global_int(t: float, mask: int = POSITION_ONLY, frame: int = 6, **kw: Any) -> Event:
    lat = ORIGIN[0] + round(50 * math.sin(0.3 * t))
    return SetPositionTargetGlobal(
        t=t,
        sender_time_us=round(t * 1e6) + 5_000_000,
        type_mask=mask,
        coordinate_frame=frame,
        lat_int=lat,
        lon_int=ORIGIN[1],
        alt=10.0,
        **{**SENT, **kw},
    )


def attitude(t: float, mask: int = 7, **kw: Any) -> Event:
    yaw = 0.1 * math.sin(0.3 * t)
    fields: dict[str, Any] = {
        **SENT,
        "q": (math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2)),
        "thrust": 0.6,
        **kw,
    }
    return SetAttitudeTarget(
        t=t, sender_time_us=round(t * 1e6) + 5_000_000, type_mask=mask, **fields
    )


def rover_velocity(t: float, mask: int = VELOCITY_ONLY) -> Event:
    v = (1.0 + 0.2 * math.sin(0.3 * t), 0.1, 0.0)
    return local(t, mask, velocity=v, position=(0.0, 0.0, 0.0))


def fw_loiter(t: float, mask: int = POSITION_ONLY | LOITER_TYPE, **kw: Any) -> Event:
    x = round(200.0 + 5.0 * math.sin(0.3 * t), 3)
    return local(t, mask, position=(x, 0.0, -50.0), **kw)


def flight(
    vehicle: str,
    main: Maker,
    extra: Maker | None = None,
    params: dict[str, float] | None = None,
    arm_result: int = 0,
    version: str = VERSION,
) -> list[Event]:
    events: list[Event] = [
        VehicleInfo(t=0.0, vehicle="1", px4_version=version),
        VehicleInfo(t=0.0, vehicle="1", mav_type=MAV_TYPES[vehicle], vehicle_type=vehicle),
    ]
    events += [
        Parameter(t=0.5, vehicle="1", name=name, value=value)
        for name, value in (params or {}).items()
    ]
    armed_ok = arm_result == 0
    for t in ticks(0.0, END + 0.5, 1.0):
        if t < SWITCH + 1.0:
            nav, armed = POSCTL, False
        elif t < LOITER:
            nav, armed = OFFBOARD, armed_ok and t >= ARM + 0.5
        else:
            nav, armed = AUTO_LOITER, armed_ok
        events.append(VehicleStatus(t=t, vehicle="1", nav_state=nav, armed=armed))
    events += [main(t) for t in ticks(START, STOP, PERIOD)]
    if extra is not None:
        events += [extra(t) for t in ticks(EXTRA_FROM, EXTRA_TO, EXTRA_PERIOD)]
    events += [
        command(SWITCH, 176, (1.0, 6.0, 0.0)),
        ack(SWITCH + 0.01, 176),
        command(ARM, 400, (1.0, 0.0, 0.0)),
        ack(ARM + 0.01, 400, arm_result),
        command(LOITER, 176, (1.0, 4.0, 3.0)),
        ack(LOITER + 0.01, 176),
    ]
    return sorted(events, key=lambda e: e.t)


def command(t: float, number: int, params: tuple[float, float, float]) -> Command:
    return Command(
        t=t, command=number, params=(*params, 0.0, 0.0, 0.0, 0.0), from_external=True, **SENT
    )


def ack(t: float, number: int, result: int = 0) -> CommandAck:
    return CommandAck(
        t=t, vehicle="1", command=number, result=result, target_system=1, target_component=191
    )


# -- cases -----------------------------------------------------------------------------------------

Planted = tuple[str, str, float | None] | tuple[str, str, float | None, str]


@dataclass
class Case:
    name: str
    vehicle: str
    events: list[Event]
    findings: list[Planted]
    clean: list[str]
    bag: bool = True
    """Also written as a MAVROS bag (the rule can be seen there)."""
    bag_findings: list[Planted] | None = None
    """What the bag shows where it differs from the tlog (None: the same)."""
    notes: list[str] = field(default_factory=list)
    px4: str = PX4
    """The profile the recording's AUTOPILOT_VERSION names."""


MC_RULES = ["OFB204", "OFB205", "OFB601", "OFB602", "OFB605", "OFB606", "OFB607", "OFB608"]
LEGACY_RULES = ["OFB607", "OFB609", "OFB801"]
LEGACY_VERSION = "1.8.2"
FW_RULES = ["OFB601", "OFB602", "OFB603", "OFB604", "OFB606", "OFB607"]
ROVER_RULES = ["OFB507", "OFB508", "OFB509", "OFB601", "OFB602", "OFB607"]


def cases() -> list[Case]:
    def nudge_body(t: float) -> Event:
        return local(t, VELOCITY_ONLY, 8, velocity=(0.5, 0.0, 0.0))

    def nudge_body_offset(t: float) -> Event:
        return local(t, VELOCITY_ONLY, 9, velocity=(0.5, 0.0, 0.0))

    def yaw_only(t: float) -> Event:
        return local(t, 0x0DFF & ~0x400, yaw=0.5)

    def wrong_target(t: float) -> Event:
        return SetPositionTargetLocal(
            t=t,
            vehicle="2",
            source_system=1,
            source_component=191,
            target_system=2,
            target_component=1,
            type_mask=POSITION_YAW,
            coordinate_frame=1,
            position=(0.0, 0.0, -2.5),
        )

    def broadcast(t: float) -> Event:
        return local(t, POSITION_YAW, target_system=0, target_component=0)

    def body_position(t: float) -> Event:
        return local(t, POSITION_ONLY, 8)

    def nan_unused(t: float) -> Event:
        # NaN in the unused fields: fine from v1.12, dropped by the legacy receiver (6.5).
        nan = math.nan
        return local(t, POSITION_YAW, velocity=(nan, nan, nan), acceleration=(nan, nan, nan))

    def legacy_flight(extra: Maker | None = None) -> list[Event]:
        return flight("mc", local, extra, version=LEGACY_VERSION)

    def gripper(t: float) -> Event:
        # a payload servo on actuator control group 1 beside the position stream (MAVSDK's
        # set_actuator_control, MAVROS actuator_control): PX4 1.14+ ignores the message
        controls = (0.0, 0.0, 0.0, 0.0, 0.0, 1.0 if t >= 5.5 else -1.0, 0.0, 0.0)
        return SetActuatorControlTarget(
            t=t, sender_time_us=round(t * 1e6) + 5_000_000, group_mlx=1, controls=controls, **SENT
        )

    def to_latlon_keep_altitude(t: float) -> Event:
        # "fly there at the altitude you have": alt ignored, so PX4 ignores lat and lon too,
        # and with nothing else used drops the message (gate spec 6.3)
        return global_int(t, GLOBAL_LATLON_YAW, 6, yaw=0.5)

    def heading_hold(t: float) -> Event:
        return attitude(t, 7, q=(math.cos(0.25), 0.0, 0.0, math.sin(0.25)), thrust=0.3)

    return [
        Case("good_copter_position", "mc", flight("mc", local), [], MC_RULES),
        Case("good_copter_body_velocity", "mc", flight("mc", local, nudge_body), [], MC_RULES),
        Case(
            "ofb601_body_offset_frame",
            "mc",
            flight("mc", local, nudge_body_offset),
            [("OFB601", "error", EXTRA_FROM)],
            ["OFB602", "OFB605", "OFB606", "OFB607"],
        ),
        Case(
            "ofb602_yaw_only",
            "mc",
            flight("mc", local, yaw_only),
            [("OFB602", "error", EXTRA_FROM)],
            ["OFB601", "OFB605", "OFB606", "OFB607"],
        ),
        Case(
            "ofb602_body_ned_position",
            "mc",
            flight("mc", local, body_position),
            [("OFB602", "error", EXTRA_FROM)],
            ["OFB601", "OFB605", "OFB606", "OFB607"],
            notes=["the docs list BODY_NED for position setpoints; the receiver drops them"],
        ),
        Case(
            "good_copter_global_position",
            "mc",
            flight("mc", global_int),
            [],
            MC_RULES,
        ),
        Case(
            "ofb605_global_mask_zero",
            "mc",
            flight("mc", lambda t: global_int(t, 0x0800)),
            [("OFB602", "info", START), ("OFB605", "warning", START)],
            ["OFB601", "OFB606", "OFB607"],
            notes=[
                "mask 0x0800 uses every field: P+V+A (OFB602: the docs' list only, PX4's "
                "position controller flies it per axis: info) and afx/afy/afz (OFB605)"
            ],
        ),
        Case(
            "ofb602_global_altitude_ignored",
            "mc",
            flight("mc", local, to_latlon_keep_altitude),
            [("OFB602", "error", EXTRA_FROM)],
            ["OFB601", "OFB605", "OFB606", "OFB607"],
            notes=["GLOBAL_INT takes lat, lon and alt only together: this one is dropped"],
        ),
        Case("good_copter_attitude", "mc", flight("mc", attitude), [], MC_RULES),
        Case(
            "ofb606_attitude_without_thrust",
            "mc",
            flight("mc", lambda t: attitude(t, 7 | 64)),
            [("OFB606", "error", START)],
            ["OFB601", "OFB602", "OFB605", "OFB607"],
        ),
        Case(
            "good_copter_broadcast_target",
            "mc",
            flight("mc", local, broadcast),
            [],
            MC_RULES,
            bag=False,
        ),
        Case(
            "ofb608_actuator_control_beside_position",
            "mc",
            flight("mc", local, gripper),
            [("OFB608", "error", EXTRA_FROM)],
            ["OFB601", "OFB602", "OFB605", "OFB606", "OFB607"],
            bag=False,
            notes=["the position stream keeps OFFBOARD; the actuator messages do nothing"],
        ),
        Case(
            "ofb607_second_vehicle_target",
            "mc",
            flight("mc", local, wrong_target),
            [("OFB607", "error", EXTRA_FROM, "2")],
            ["OFB601", "OFB602", "OFB605", "OFB606"],
            bag=False,
        ),
        Case("good_fixedwing_loiter", "fw", flight("fw", fw_loiter), [], FW_RULES),
        Case(
            "ofb603_fixedwing_no_type",
            "fw",
            flight("fw", lambda t: fw_loiter(t, POSITION_ONLY)),
            # v1.12+ do not read the setpoint-type bits (D14): the docs' rule only, info
            [("OFB603", "info", START)],
            ["OFB601", "OFB602", "OFB604", "OFB606", "OFB607"],
        ),
        Case(
            "ofb604_fixedwing_velocity",
            "fw",
            flight("fw", lambda t: fw_loiter(t, LOITER_TYPE, velocity=(15.0, 0.0, 0.0))),
            [("OFB604", "warning", START)],
            ["OFB601", "OFB602", "OFB603", "OFB606", "OFB607"],
        ),
        Case(
            "good_rover_velocity",
            "rover-differential",
            flight("rover-differential", rover_velocity, params={"MAV_FWDEXTSP": 1.0}),
            [],
            ROVER_RULES,
        ),
        Case(
            "ofb507_rover_heading_by_attitude",
            "rover-differential",
            flight(
                "rover-differential",
                rover_velocity,
                heading_hold,
                params={"MAV_FWDEXTSP": 1.0},
            ),
            [("OFB507", "error", EXTRA_FROM)],
            ["OFB508", "OFB509", "OFB601", "OFB602", "OFB607"],
        ),
        Case(
            "ofb508_rover_yaw",
            "rover-differential",
            flight(
                "rover-differential",
                lambda t: rover_velocity(t, VELOCITY_YAW),
                params={"MAV_FWDEXTSP": 1.0},
            ),
            [("OFB508", "warning", START)],
            ["OFB507", "OFB509", "OFB601", "OFB602", "OFB607"],
        ),
        Case(
            "ofb509_rover_not_forwarded",
            "rover-differential",
            flight(
                "rover-differential",
                rover_velocity,
                params={"MAV_FWDEXTSP": 0.0},
                arm_result=TEMPORARILY_REJECTED,
            ),
            [("OFB509", "error", START)],
            ["OFB507", "OFB508", "OFB601", "OFB602", "OFB607"],
            bag=False,
            notes=[
                "PX4 1.16 accepts the switch while disarmed (no stream needed), then refuses "
                "to arm: with MAV_FWDEXTSP = 0 the stream is no keep-alive (OFB201 below)"
            ],
        ),
        Case(
            "good_legacy_copter_position",
            "mc",
            legacy_flight(),
            [],
            LEGACY_RULES,
            bag=False,
            px4="legacy",
        ),
        Case(
            "ofb609_legacy_nan_unused_fields",
            "mc",
            legacy_flight(nan_unused),
            [("OFB609", "error", EXTRA_FROM)],
            ["OFB607", "OFB801"],
            bag=False,
            px4="legacy",
        ),
        # -- scripts/add_rule.py adds a new rule's cases above this line
    ]


def finding(planted: Planted, with_vehicle: bool) -> dict[str, Any]:
    code, severity, time_s = planted[0], planted[1], planted[2]
    out: dict[str, Any] = {"code": code, "severity": severity, "time_s": time_s}
    if with_vehicle and time_s is not None:
        out["vehicle"] = planted[3] if len(planted) == 4 else "1"
    return out


def _sources(args: list[str]) -> dict[str, Any]:
    """How the report gives the profile: detected from a tlog; set by the user for a bag,
    which names neither the release nor the vehicle."""
    if "--px4" in args:
        return {"detected": False, "px4_source": "user", "vehicle_source": "user"}
    return {"detected": True}


def write_spec(
    name: str, recording: str, case: Case, planted: list[Planted], args: list[str], tlog: bool
) -> None:
    found = [finding(p, tlog) for p in planted]
    levels = {f["severity"] for f in found}
    applies = [c for c in case.clean if get_rule(c).applies_to(case.px4, case.vehicle)]
    if not tlog:  # a bag cannot show these (see the module docstring)
        applies = [c for c in applies if c not in ("OFB204", "OFB205", "OFB607", "OFB509")]
    spec = {
        "recording": recording,
        "args": args,
        "exit_status": 1 if levels & {"error", "warning"} else 0,
        "complete": True,
        "profile": {"px4": case.px4, "vehicle": case.vehicle, **_sources(args)},
        "findings": sorted(found, key=lambda f: (f["time_s"] or -1.0, f["code"])),
        "clean": applies,
    }
    (HERE / f"{name}.expected.json").write_text(json.dumps(spec, indent=2) + "\n")


def main() -> None:
    for case in cases():
        tlog = write_tlog(HERE / f"{case.name}.tlog", case.events)
        other: list[Planted] = [("OFB701", "info", SWITCH), *OTHER_RULES.get(case.name, [])]
        if case.vehicle.startswith("rover"):
            other.append(("OFB003", "info", None))  # HEARTBEAT type 10: the rover's kind unsaid
        write_spec(case.name, tlog.name, case, case.findings + other, [], True)
        if case.bag:
            bag = write_rosbag1(HERE / f"{case.name}.bag", case.events)
            planted = case.bag_findings if case.bag_findings is not None else case.findings
            extra: list[Planted] = [("OFB701", "info", SWITCH_SEEN_IN_BAG)]
            extra += BAG_OTHER_RULES.get(case.name, [])
            if case.vehicle.startswith("rover"):
                extra.append(("OFB002", "info", None))  # OFB509: no parameters in a bag
            args = ["--px4", case.px4, "--vehicle", case.vehicle]
            write_spec(f"{case.name}.mavros", bag.name, case, planted + extra, args, False)


SWITCH_SEEN_IN_BAG = 4.0
"""A MAVROS bag records no commands: the request shows as the ``state`` change at 4.0 s."""

INTERLEAVED: list[Planted] = [("OFB304", "info", EXTRA_FROM)]
"""A second setpoint type between the main ones: PX4's receiver sets offboard_control_mode from
each message's type mask, so the first true field alternates; one OFB304 for the stretch."""

OTHER_RULES: dict[str, list[Planted]] = {
    # The arm request in OFFBOARD is refused, and the gate model gives the reason: with
    # MAV_FWDEXTSP = 0 the setpoints are no keep-alive (gate spec 4.2, 6.1).
    "ofb509_rover_not_forwarded": [("OFB201", "error", ARM + 0.01)],
    "good_copter_body_velocity": INTERLEAVED,
    "ofb507_rover_heading_by_attitude": INTERLEAVED,
}
"""Findings of other rules a tlog case also shows, each judged by hand against the rule text.
Every flight also gets OFB701 at the request (the gate model's loss-action summary, info)."""

BAG_OTHER_RULES: dict[str, list[Planted]] = {
    "good_copter_body_velocity": INTERLEAVED,
    "ofb507_rover_heading_by_attitude": INTERLEAVED,
}
"""The same for the MAVROS bags."""


if __name__ == "__main__":
    main()
