"""Build the stream-rule corpus: OFB104 (stale setpoints) and OFB105 (marginal rate), bad and good.

Run ``.venv/bin/python corpora/stream/build.py``; it is deterministic. OFB104 is a ROS 2 rule, so
its cases are MCAP (``fuzzoff.formats.mcap.writer``, PX4 1.15 definitions); OFB105 judges the
keep-alive as sent, so its cases are tlogs (``fuzzoff.formats.tlog.writer``: MAVLink setpoints are
the keep-alive).

* ``ofb104_planner_stops``: OffboardControlMode at 10 Hz for the whole flight, TrajectorySetpoint
  at 20 Hz until 5.0 s, then nothing while the vehicle stays in OFFBOARD until 9.0 s: OFB104 from
  5.5 s (0.5 s threshold) to the end of offboard.
* ``ofb104_good``: the same flight with the setpoints going on: clean.
* ``ofb105_2hz_stream``: MAVLink setpoints every 450 ms in OFFBOARD: above 2 Hz but marginal:
  OFB105 (info: no PX4 release acts on the 2 Hz margin) over the offboard stretch.
* ``ofb105_good``: 20 Hz setpoints with a little jitter: clean.

Every flight switches to OFFBOARD after 2 s of stream (accepted) and is a multicopter whose PX4
version the recording names. The context findings every recording of its format gets (from
other rules: OFB701's loss-action summary at the request; OFB002 for OFB305 on MCAP, which has
no estimator flags) are listed too, checked against those rules' pages.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from fuzzoff.events import (
    Command,
    CommandAck,
    ControlMode,
    Event,
    SetPositionTargetLocal,
    TrajectorySetpoint,
    VehicleInfo,
    VehicleStatus,
)
from fuzzoff.formats.mcap.writer import write_mcap
from fuzzoff.formats.tlog.writer import write_tlog

HERE = Path(__file__).resolve().parent
POSCTL, OFFBOARD = 2, 14
SWITCH_T, END_T = 2.0, 9.0
BOOT_US = 60_000_000


def _switch(vehicle: str, transport: str) -> list[Event]:
    return [
        Command(
            t=SWITCH_T,
            vehicle=vehicle,
            command=176,
            params=(1.0, 6.0, 0.0, 0.0, 0.0, 0.0, 0.0),
            target_system=1,
            target_component=1,
            transport=transport,  # type: ignore[arg-type]
        ),
        CommandAck(t=SWITCH_T + 0.01, vehicle=vehicle, command=176, result=0),
    ]


def _status(vehicle: str, step: float) -> list[Event]:
    out: list[Event] = []
    t = 0.0
    while t < END_T:
        nav = OFFBOARD if t >= SWITCH_T + 0.02 else POSCTL
        out.append(
            VehicleStatus(t=round(t, 6), vehicle=vehicle, nav_state=nav, armed=True, vehicle_type=1)
        )
        t += step
    out.append(
        VehicleStatus(
            t=SWITCH_T + 0.02, vehicle=vehicle, nav_state=OFFBOARD, armed=True, vehicle_type=1
        )
    )
    return out


def ros2_flight(setpoints_until: float) -> list[Event]:
    events: list[Event] = []
    for k in range(int(END_T / 0.1)):
        t = round(k * 0.1, 6)
        events.append(ControlMode(t=t, sender_time_us=BOOT_US + round(t * 1e6), position=True))
    for k in range(int(END_T / 0.05)):
        t = round(k * 0.05 + 0.003, 6)
        if SWITCH_T + 0.02 <= t < setpoints_until:
            events.append(
                TrajectorySetpoint(
                    t=t, sender_time_us=BOOT_US + round(t * 1e6), position=(0.0, 0.01 * k, -2.0)
                )
            )
    events += _switch("", "ros2") + _status("", 0.5)
    return sorted(events, key=lambda e: e.t)


def mavlink_flight(period: float, jitter: float) -> list[Event]:
    events: list[Event] = [VehicleInfo(t=0.0, vehicle="1", px4_version="1.15.4", mav_type=2)]
    k = 0
    while (t := round(k * period + (jitter if k % 3 == 1 else 0.0), 6)) < END_T:
        events.append(
            SetPositionTargetLocal(
                t=t,
                vehicle="1",
                sender_time_us=round(t * 1e6),
                target_system=1,
                target_component=1,
                type_mask=0x09F8,
                coordinate_frame=1,
                position=(0.0, 0.01 * k, -2.0),
            )
        )
        k += 1
    events += _switch("1", "mavlink") + _status("1", 1.0)
    return sorted(events, key=lambda e: e.t)


def expected(recording: str, findings: list[dict[str, Any]], clean: list[str]) -> dict[str, Any]:
    return {
        "recording": recording,
        "exit_status": 1 if any(f["severity"] != "info" for f in findings) else 0,
        "complete": True,
        "profile": {"px4": "1.15", "vehicle": "mc", "detected": True},
        "findings": findings,
        "clean": clean,
    }


def main() -> None:
    context_mcap = [
        {"code": "OFB002", "severity": "info", "time_s": None},
        {"code": "OFB701", "severity": "info", "time_s": SWITCH_T},
    ]
    context_tlog = [{"code": "OFB701", "severity": "info", "time_s": SWITCH_T, "vehicle": "1"}]
    cases: dict[str, tuple[list[Event], list[dict[str, Any]], list[str]]] = {
        "ofb104_planner_stops.mcap": (
            ros2_flight(setpoints_until=5.0),
            [{"code": "OFB104", "severity": "warning", "time_s": 5.453}, *context_mcap],
            ["OFB101", "OFB102", "OFB103", "OFB105", "OFB201"],
        ),
        "ofb104_good.mcap": (
            ros2_flight(setpoints_until=END_T),
            context_mcap,
            ["OFB101", "OFB102", "OFB103", "OFB104", "OFB105", "OFB201"],
        ),
        "ofb105_2hz_stream.tlog": (
            mavlink_flight(period=0.45, jitter=0.0),
            [
                # info: no release acts on the 2 Hz margin (0.45 s gaps, 45 % of COM_OF_LOSS_T)
                {"code": "OFB105", "severity": "info", "time_s": 2.25, "vehicle": "1"},
                *context_tlog,
            ],
            ["OFB101", "OFB102", "OFB103", "OFB201"],
        ),
        "ofb105_good.tlog": (
            mavlink_flight(period=0.05, jitter=0.012),
            context_tlog,
            ["OFB101", "OFB102", "OFB103", "OFB105", "OFB201", "OFB001", "OFB002", "OFB003"],
        ),
    }
    for name, (events, findings, clean) in cases.items():
        path = HERE / name
        if name.endswith(".mcap"):
            write_mcap(path, events, release="1.15")
        else:
            write_tlog(path, events)
        spec = expected(name, findings, clean)
        stem = name.rsplit(".", 1)[0]
        (HERE / f"{stem}.expected.json").write_text(json.dumps(spec, indent=2) + "\n")


if __name__ == "__main__":
    main()
