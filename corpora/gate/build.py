"""Build the gate corpus: PX4 ULogs (as the vehicle logs them) for the gate-model rules.

Run ``.venv/bin/python corpora/gate/build.py``; deterministic. Every recording is written
through ``fuzzoff.formats.ulog.writer`` (pyulog) and gets ``NAME.expected.json`` with the findings
planted here, judged against the rule texts (rules/OFB202.toml, OFB701.toml, OFB702.toml and the
stream rules the flights also touch):

* ``loss_and_resume_agrees`` (1.15): offboard flight, the stream stops at 5.0 s and resumes at
  8.0 s; the log shows POSCTL with the failsafe flag from 6.1 s and OFFBOARD again at 8.05 s, as
  the gate model predicts (loss due at 6.0 s, seen within one 10 Hz check period: the recorded
  failsafe at 6.1 s dates it; action Position, automatic return). OFB202 must stay clean; OFB701
  states the loss behaviour at the request (1.5 s); OFB103 is the loss (6.1 s) and OFB101 the
  3 s gap.
* ``recorded_stays_offboard`` (1.15): the same stream, but the log stays in OFFBOARD through the
  gap (as if COM_OF_LOSS_T were larger on the vehicle than in the log): OFB202 at the first status
  that contradicts the model (6.5 s).
* ``no_offboard`` (1.15): a POSCTL flight with no offboard use: OFB005 says so; OFB701, OFB702,
  OFB202 clean.
* ``rc_lost_117_return`` (1.17.0): no manual control; on loss 1.17 replaces Position by
  NAV_RCL_ACT (Return): the log shows AUTO_RTL; OFB702 says the configured Position was replaced
  when the loss ran the fallback (an error at the loss, rules.md), OFB202 clean.
* ``no_rc_117_clean`` (1.17.0): the same vehicle without manual control (every SITL run, every
  autonomous setup) flying offboard with no loss: OFB702 is a configuration note (info), exit 0.
* ``signal_flag_agrees`` (1.15): ``loss_and_resume_agrees`` with PX4's own verdict logged at
  10 Hz (``failsafe_flags.offboard_control_signal_lost``): lost from the 6.0 s check pass,
  available again from 8.0 s, as the model says: OFB202 clean.
* ``signal_flag_lost_early`` (1.15): the same, but the flag says lost from 5.6 s, while the
  newest keep-alive (5.0 s) is 0.6 s old and COM_OF_LOSS_T is 1 s (as if the vehicle ran a
  lower timeout that the log does not record; the modes are the same as above): OFB202 at the
  first lost sample (5.605 s), 0.4 s beyond the slack, and once only.
* ``auto_takeoff_no_offboard`` (1.15): as pyulog's ``sample_px4_events.ulg`` (a real auto
  flight, too large for this corpus): disarmed in AUTO_LOITER, an arm command, PX4 runs
  AUTO_TAKEOFF (NAV_TAKEOFF, which the model does not model), then Hold and Return. No offboard
  at all: OFB005, and OFB202 clean (rules/OFB202.toml: only differences that involve OFFBOARD).

And one ROS 2 recording (``fuzzoff.formats.mcap.writer``, px4_msgs 1.16), as a px4_ros_com-style
client records it: its ``/fmu/in`` stream and commands, PX4's ``/fmu/out/vehicle_status`` and
``/fmu/out/vehicle_land_detected``, no acks:

* ``landed_disarm_ros2`` (1.16): take-off to 2.5 m in OFFBOARD, a descent to the ground in
  OFFBOARD, the land detector says landed at 14.5 s, the client disarms at 15.0 s and PX4 does
  (``vehicle_status`` disarmed at 15.05 s). The gate model accepts the disarm for the land
  detector's verdict, as from a ULog or a tlog (``tests/gate/test_landed_from_bags.py``); without
  the topic it would take the vehicle, armed for 13 s, as airborne and refuse it. OFB202 clean,
  and OFB006 (both sides' px4_msgs are 1.16's).
* ``px4_msgs_mismatch_ros2`` (PX4 1.16, OFB006): the same client built against px4_msgs of 1.14
  (its ``/fmu/in`` topics and schemas), PX4 1.16's ``/fmu/out/vehicle_status_v1`` answering:
  PX4 never takes the stream, the switch and the arm; it stays in POSCTL, disarmed. OFB006,
  and OFB202 where the model, which cannot see that, expected the switch.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from fuzzoff.events import (
    Command,
    CommandAck,
    ControlMode,
    Event,
    FailsafeFlags,
    LandDetected,
    TrajectorySetpoint,
    VehicleStatus,
)
from fuzzoff.formats import px4_msgs
from fuzzoff.formats.mcap.writer import write_mcap
from fuzzoff.formats.ros2msgs.messages import RawMessage, encode, to_message
from fuzzoff.formats.ulog.writer import write_ulog

HERE = Path(__file__).resolve().parent
POSCTL, RTL, OFFBOARD = 2, 5, 14
SWITCH_T, ARM_T, STOP_T, RESUME_T, END_T = 1.5, 2.0, 5.0, 8.0, 10.0


def logged(event: Event) -> Event:
    return replace(event, origin="vehicle", sender_time_us=None)


def stream(start: float, stop: float) -> list[Event]:
    """OffboardControlMode and TrajectorySetpoint as PX4 logs them (10 Hz)."""
    out: list[Event] = []
    k = 0
    while True:
        t = round(start + 0.1 * k, 6)
        if t > stop + 1e-9:
            return out
        out.append(logged(ControlMode(t=t, position=True)))
        out.append(logged(TrajectorySetpoint(t=t, position=(0.0, 0.0, -2.0))))
        k += 1


def commands() -> list[Event]:
    return [
        logged(Command(t=SWITCH_T, command=176, params=(1.0, 6.0, 0, 0, 0, 0, 0))),
        CommandAck(t=SWITCH_T + 0.02, command=176, result=0),
        logged(Command(t=ARM_T, command=400, params=(1.0, 0, 0, 0, 0, 0, 0))),
        CommandAck(t=ARM_T + 0.02, command=400, result=0),
    ]


def statuses(during_gap: tuple[int, bool] | None) -> list[Event]:
    """vehicle_status every 0.5 s and at each change; ``during_gap`` = (nav, failsafe) shown
    from 6.1 s until the stream is back (None: no offboard flight at all)."""
    out: list[Event] = []
    times = sorted({round(0.5 * i, 6) for i in range(int(END_T * 2) + 1)} | {1.55, 2.05, 6.1, 8.05})
    for t in times:
        if during_gap is None:
            out.append(VehicleStatus(t=t, nav_state=POSCTL, armed=True, user_intention=POSCTL))
            continue
        armed = t >= ARM_T + 0.05
        if t < SWITCH_T + 0.05:
            nav, intention, failsafe = POSCTL, POSCTL, False
        elif 6.1 <= t < RESUME_T + 0.05:
            nav, failsafe = during_gap
            intention = OFFBOARD
        else:
            nav, intention, failsafe = OFFBOARD, OFFBOARD, False
        out.append(
            VehicleStatus(
                t=t, nav_state=nav, armed=armed, user_intention=intention, failsafe=failsafe
            )
        )
    return out


@dataclass
class Case:
    name: str
    events: list[Event]
    findings: list[tuple[str, str, float | None]]
    clean: list[str]
    px4_version: str = "1.15.4"
    params: dict[str, float] = field(default_factory=dict)


def valid(rc: bool = True) -> FailsafeFlags:
    return FailsafeFlags(
        t=0.0,
        local_position_valid=True,
        local_velocity_valid=True,
        local_altitude_valid=True,
        global_position_valid=True,
        attitude_valid=True,
        angular_velocity_valid=True,
        home_position_valid=True,
        manual_control_signal_lost=not rc,
        offboard_control_signal_lost=False,
    )


def offboard_flight(during_gap: tuple[int, bool], rc: bool = True, gap: bool = True) -> list[Event]:
    """The flight; without ``gap`` the stream never stops (``during_gap`` should then say
    OFFBOARD)."""
    flown = [*stream(0.0, STOP_T), *stream(RESUME_T, END_T)] if gap else stream(0.0, END_T)
    events = [
        valid(rc),
        *flown,
        *commands(),
        *statuses(during_gap),
    ]
    return sorted(events, key=lambda e: e.t)


# Findings every 1.15 ULog flight of this corpus also gets, checked against the rule texts:
# One OFB002 listing OFB104, OFB105 (keep-alive subsampled by the logger), OFB106 (timestamps
# rewritten), OFB203 and OFB302 (only PX4's own copies of the messages): not judged on a ULog.
NOT_CHECKABLE_115 = [("OFB002", "info", None)]
# A flight that never used offboard says so (OFB005), once.
NO_OFFBOARD = [("OFB005", "info", None)]
# The 3 s gap in OFFBOARD: OFB101 (docs: keep-alive gaps under 0.5 s) from the last keep-alive,
# and OFB103 at PX4's failsafe: its loss is due at 6.0 s and seen by a 10 Hz check pass within
# 0.1 s, then one iteration. The recorded failsafe (the status at 6.1 s) dates it; PX4's flag
# (lost from 6.005 s) dates it where logged; with neither, the window's end (6.11 s).
GAP = [("OFB101", "error", STOP_T), ("OFB103", "error", 6.1)]
GAP_FLAG = [("OFB101", "error", STOP_T), ("OFB103", "error", 6.015)]
GAP_UNDATED = [("OFB101", "error", STOP_T), ("OFB103", "error", 6.11)]


def signal_flags(lost: tuple[float, float]) -> list[Event]:
    """``failsafe_flags`` as PX4 publishes them after each 10 Hz check pass (5 ms later), the
    offboard signal lost within ``lost`` = (from, until)."""
    out: list[Event] = []
    for k in range(int(END_T * 10) + 1):
        t = round(0.1 * k + 0.005, 6)
        flag = lost[0] <= t < lost[1]
        out.append(FailsafeFlags(t=t, offboard_control_signal_lost=flag))
    return out


def with_flags(events: list[Event], lost: tuple[float, float]) -> list[Event]:
    return sorted([*events, *signal_flags(lost)], key=lambda e: e.t)


def auto_takeoff() -> list[Event]:
    loiter, takeoff = 4, 17
    events: list[Event] = [
        valid(),
        logged(Command(t=ARM_T, command=400, params=(1.0, 0, 0, 0, 0, 0, 0))),
        CommandAck(t=ARM_T + 0.004, command=400, result=0),
        logged(Command(t=7.0, command=176, params=(1.0, 4.0, 5.0, 0, 0, 0, 0))),
        CommandAck(t=7.004, command=176, result=0),
    ]
    for k in range(int(END_T * 2) + 1):
        t = round(0.5 * k, 6)
        if t < ARM_T:
            nav, armed = loiter, False
        elif t < 6.0:
            nav, armed = takeoff, True
        elif t < 7.0:
            nav, armed = loiter, True
        else:
            nav, armed = RTL, True
        events.append(VehicleStatus(t=t, nav_state=nav, armed=armed, user_intention=nav))
    return sorted(events, key=lambda e: e.t)


def cases() -> list[Case]:
    return [
        Case(
            "loss_and_resume_agrees",
            offboard_flight((POSCTL, True)),
            [*NOT_CHECKABLE_115, ("OFB701", "info", SWITCH_T), *GAP],
            ["OFB005", "OFB202", "OFB702"],
        ),
        Case(
            "recorded_stays_offboard",
            offboard_flight((OFFBOARD, False)),
            [
                *NOT_CHECKABLE_115,
                ("OFB701", "info", SWITCH_T),
                *GAP_UNDATED,
                ("OFB202", "warning", 6.5),
            ],
            ["OFB702"],
        ),
        Case(
            "no_offboard",
            sorted([valid(), *statuses(None)], key=lambda e: e.t),
            NO_OFFBOARD,  # no keep-alive, so no rule is even "not checkable"
            ["OFB202", "OFB701", "OFB702"],
        ),
        Case(
            "rc_lost_117_return",
            offboard_flight((RTL, True), rc=False),
            [
                *NOT_CHECKABLE_115,
                ("OFB701", "info", SWITCH_T),
                *GAP,
                ("OFB702", "error", 6.1),  # the loss ran NAV_RCL_ACT instead of Position
            ],
            ["OFB202"],
            px4_version="1.17.0",
        ),
        Case(
            "no_rc_117_clean",
            offboard_flight((OFFBOARD, False), rc=False, gap=False),
            [
                *NOT_CHECKABLE_115,
                ("OFB701", "info", SWITCH_T),
                ("OFB702", "info", SWITCH_T),  # a configuration note: no loss happened
            ],
            ["OFB101", "OFB103", "OFB202"],
            px4_version="1.17.0",
        ),
        Case(
            "signal_flag_agrees",
            with_flags(offboard_flight((POSCTL, True)), (6.0, RESUME_T)),
            [*NOT_CHECKABLE_115, ("OFB701", "info", SWITCH_T), *GAP_FLAG],
            ["OFB202", "OFB702"],
        ),
        Case(
            "signal_flag_lost_early",
            with_flags(offboard_flight((POSCTL, True)), (5.6, RESUME_T)),
            [
                *NOT_CHECKABLE_115,
                ("OFB701", "info", SWITCH_T),
                *GAP_FLAG,
                ("OFB202", "warning", 5.605),
            ],
            ["OFB702"],
        ),
        Case(
            "auto_takeoff_no_offboard",
            auto_takeoff(),
            NO_OFFBOARD,  # no keep-alive: nothing to judge
            ["OFB202", "OFB701", "OFB702"],
        ),
    ]


def write(case: Case) -> None:
    path = HERE / f"{case.name}.ulg"
    write_ulog(path, case.events, px4_version=case.px4_version, vehicle_type="mc")
    expected: dict[str, Any] = {
        "recording": path.name,
        "args": [],
        "exit_status": 1 if any(sev != "info" for _, sev, _ in case.findings) else 0,
        "complete": True,
        "findings": [
            {"code": code, "severity": sev, "time_s": t} for code, sev, t in case.findings
        ],
        "clean": case.clean,
    }
    (HERE / f"{case.name}.expected.json").write_text(json.dumps(expected, indent=2) + "\n")


LANDED_T, DISARM_T, DESCEND_T = 14.5, 15.0, 9.0
MISMATCH_FINDINGS: list[dict[str, Any]] = [
    {"code": "OFB006", "severity": "error", "time_s": None},
    # the stream before the switch while disarmed, the loss summary at the request
    {"code": "OFB203", "severity": "info", "time_s": 0.0},
    {"code": "OFB701", "severity": "info", "time_s": SWITCH_T},
    # the model takes the switch (1.16 accepts it disarmed); PX4 never got it
    {"code": "OFB202", "severity": "warning", "time_s": 2.0},
    {"code": "OFB002", "severity": "info", "time_s": None},
]
"""``px4_msgs_mismatch_ros2``'s findings, judged by hand against the rule texts."""


def landed_disarm_ros2() -> list[Event]:
    """A px4_ros_com-style flight that lands in OFFBOARD and disarms (gate spec 13a)."""
    events: list[Event] = []
    for k in range(171):  # 10 Hz, 0-17 s
        t = round(0.1 * k, 6)
        us = 5_000_000 + round(t * 1e6)
        z = -2.5 if t < DESCEND_T else 0.0
        events.append(ControlMode(t=t, position=True, sender_time_us=us))
        events.append(TrajectorySetpoint(t=t, position=(0.0, 0.0, z), sender_time_us=us))
    events += [
        Command(t=SWITCH_T, command=176, params=(1.0, 6.0, 0, 0, 0, 0, 0), transport="ros2"),
        Command(t=ARM_T, command=400, params=(1.0, 0, 0, 0, 0, 0, 0), transport="ros2"),
        Command(t=DISARM_T, command=400, params=(0.0, 0, 0, 0, 0, 0, 0), transport="ros2"),
        LandDetected(t=0.0, landed=True),
        LandDetected(t=3.6, landed=False),  # PX4 detects the take-off 1-2 s after the climb
        LandDetected(t=LANDED_T, landed=True),
    ]
    times = sorted({round(0.5 * i, 6) for i in range(35)} | {SWITCH_T + 0.05, ARM_T + 0.05})
    times = sorted({*times, DISARM_T + 0.05})
    for t in times:
        nav = POSCTL if t < SWITCH_T + 0.05 else OFFBOARD
        armed = ARM_T + 0.05 <= t < DISARM_T + 0.05
        events.append(VehicleStatus(t=t, nav_state=nav, armed=armed, user_intention=nav))
    return sorted(events, key=lambda e: e.t)


def built_with(release: str, events: list[Event]) -> list[RawMessage]:
    """The companion's ``/fmu/in`` messages as a program built with ``release``'s px4_msgs
    publishes them: that release's topic names, schemas and layouts."""
    out = []
    for event in events:
        msg = to_message(event, release)
        text = px4_msgs.definition(release, msg.message) or ""
        out.append(RawMessage(event.t, msg.topic, msg.typename, text, encode(msg)))
    return out


def px4_msgs_mismatch_ros2() -> tuple[list[Event], list[RawMessage]]:
    """The client of ``landed_disarm_ros2`` built with 1.14's px4_msgs, PX4 1.16 answering:
    nothing it sends reaches PX4, which stays in POSCTL, disarmed."""
    flight = landed_disarm_ros2()
    sent = [e for e in flight if e.origin == "sent" and e.t < 10.0]
    status = [
        VehicleStatus(t=round(0.5 * i, 6), nav_state=POSCTL, armed=False, user_intention=POSCTL)
        for i in range(21)
    ]
    return status, built_with("1.14", sent)


def write_ros2() -> None:
    mismatch = "px4_msgs_mismatch_ros2"
    status, raw = px4_msgs_mismatch_ros2()
    path = write_mcap(HERE / f"{mismatch}.mcap", status, release="1.16", extra=raw)
    (HERE / f"{mismatch}.expected.json").write_text(
        json.dumps(
            {
                "recording": path.name,
                "args": ["--px4", "1.16", "--vehicle", "mc"],
                "exit_status": 1,
                "complete": True,
                "findings": MISMATCH_FINDINGS,
            },
            indent=2,
        )
        + "\n"
    )
    name = "landed_disarm_ros2"
    path = write_mcap(HERE / f"{name}.mcap", landed_disarm_ros2(), release="1.16")
    expected: dict[str, Any] = {
        "recording": path.name,
        "args": ["--px4", "1.16", "--vehicle", "mc"],
        "exit_status": 0,
        "complete": True,
        "findings": [
            # judged by hand against the rule texts: the setpoints before the switch (info,
            # disarmed), the loss summary at the request, and OFB201 without acks
            {"code": "OFB203", "severity": "info", "time_s": 0.0},
            {"code": "OFB701", "severity": "info", "time_s": SWITCH_T},
            {"code": "OFB002", "severity": "info", "time_s": None},
        ],
        "clean": ["OFB006", "OFB202"],
    }
    (HERE / f"{name}.expected.json").write_text(json.dumps(expected, indent=2) + "\n")


def main() -> None:
    for case in cases():
        write(case)
        print(f"{case.name}.ulg: {(HERE / f'{case.name}.ulg').stat().st_size} bytes")
    write_ros2()


if __name__ == "__main__":
    main()
