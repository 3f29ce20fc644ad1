"""Build the tlog corpus: offboard flights as a MAVLink link would log them (formats.md 7).

Run ``.venv/bin/python corpora/tlog/build.py``; it is deterministic. Every recording is written
through ``fuzzoff.formats.tlog.writer`` (pymavlink packs the packets) and gets
``NAME.expected.json`` with the findings planted here, judged against the rule texts
(rules/OFB*.toml):

* ``good_offboard``: 20 Hz SET_POSITION_TARGET_LOCAL_NED from the companion (1/191) for 2 s
  before an accepted switch, arming in OFFBOARD, flight, AUTO_LAND; no finding but the OFB701
  summary of the loss behaviour (info, in every flight that uses offboard).
* ``keepalive_gap_0_7s``: one 0.7 s gap in offboard: OFB101 as info (the docs' 2 Hz is broken,
  but 0.7 s is under 80 % of COM_OF_LOSS_T = 1.0 s, so PX4 1.15 keeps offboard with margin).
* ``stream_lost_in_offboard``: the stream stops for 3.5 s in offboard: OFB101 error and OFB103
  (loss after COM_OF_LOSS_T, action Position); the HEARTBEAT shows POSCTL, then OFFBOARD again
  when the stream resumes, as PX4 does.
* ``switch_50ms_after_first_setpoint``: MAVSDK style, armed in POSCTL, the switch 50 ms after
  the first setpoint: accepted by PX4 1.15, OFB102 info (the docs' second, enforced nowhere).
* ``switch_rejected``: armed, no stream, switch -> COMMAND_ACK TEMPORARILY_REJECTED: OFB201,
  and OFB102 (a request with no keep-alive at all; an error, as the gate model rejects it).
* ``px4_1_16_double_ack``: the same on PX4 1.16.2, which acks ACCEPTED first and then rejects:
  the last ack decides, OFB201.
* ``mavsdk_stop_to_hold``: PX4 1.16.2; MAVSDK's ``stop()``: the setpoints stop at 10.0 s, then
  DO_SET_MODE to Hold, acked twice (the receiver's ACCEPTED, then Commander's) 20 and 26 ms
  later; the next 1 Hz HEARTBEAT shows Hold at 11.0 s. The offboard window ends at the ack, so
  the second of silence until the HEARTBEAT is no gap in OFFBOARD: no OFB101, no OFB103.
* ``arm_between_acks_1_16_2``: the good flight on PX4 1.16.2, but the client arms 2 ms after
  the receiver's ACCEPTED of its switch to OFFBOARD, 4 ms before Commander's: OFB207 as a
  warning (Commander accepted; the client did not wait to know). ``mavsdk_stop_to_hold`` is the
  good counterpart: every next step comes after the second ack.
* ``mission_on_rejected_switch_1_17_0``: PX4 1.17.0, flying in OFFBOARD; at 10.0 s the client
  switches to AUTO_MISSION (no mission on board: Commander rejects it), stops its setpoints and,
  on the receiver's ACCEPTED, sends MAV_CMD_MISSION_START between the two acks: OFB207 error;
  the vehicle stays in OFFBOARD without a stream and the loss failsafe follows (OFB101, OFB103).
* ``no_autopilot_version``: the good flight without AUTOPILOT_VERSION: OFB003 (version
  assumed; the vehicle type still comes from HEARTBEAT ``type``).
* ``truncated``: the lost-stream flight cut inside a packet: OFB001, exit status 2, and the
  findings of the readable part are kept.
"""

from __future__ import annotations

import json
from collections.abc import Iterable
from pathlib import Path
from typing import Any

from fuzzoff.events import (
    Command,
    CommandAck,
    Event,
    SetPositionTargetLocal,
    VehicleInfo,
    VehicleStatus,
)
from fuzzoff.formats.tlog.writer import write_tlog

HERE = Path(__file__).resolve().parent
POSCTL, OFFBOARD, AUTO_LAND = 2, 14, 18
SENT: dict[str, Any] = {
    "vehicle": "1",
    "source_system": 1,
    "source_component": 191,
    "target_system": 1,
    "target_component": 1,
}
QUADROTOR = 2
SETPOINT_PERIOD = 0.05  # 20 Hz


def identity(version: str | None = "1.15.4") -> list[Event]:
    events: list[Event] = []
    if version is not None:
        events.append(VehicleInfo(t=0.0, vehicle="1", px4_version=version))
    events.append(VehicleInfo(t=0.0, vehicle="1", mav_type=QUADROTOR, vehicle_type="mc"))
    return events


def heartbeats(modes: list[tuple[float, int, bool]], end: float) -> list[Event]:
    """1 Hz HEARTBEAT on whole seconds; ``modes`` = (from time, nav_state, armed)."""
    out: list[Event] = []
    t = 0.0
    while t <= end + 1e-9:
        nav, armed = next((n, a) for since, n, a in reversed(modes) if since <= t + 1e-9)
        out.append(VehicleStatus(t=t, vehicle="1", nav_state=nav, armed=armed))
        t = round(t + 1.0, 6)
    return out


def stream(start: float, stop: float, gaps: Iterable[tuple[float, float]] = ()) -> list[Event]:
    """Setpoints every 50 ms in [start, stop), none inside the (from, to) gaps; moving target."""
    gaps = list(gaps)
    out: list[Event] = []
    k = 0
    while True:
        t = round(start + k * SETPOINT_PERIOD, 6)
        if t >= stop - 1e-9:
            return out
        k += 1
        if any(a < t < b for a, b in gaps):
            continue
        out.append(
            SetPositionTargetLocal(
                t=t,
                sender_time_us=round(t * 1e6) + 5_000_000,
                type_mask=0x09F8,
                coordinate_frame=1,
                position=(round(0.02 * k, 3), 0.0, -2.5),
                yaw=0.0,
                **SENT,
            )
        )


def set_mode(t: float, main: int, sub: int = 0) -> Command:
    return Command(
        t=t,
        command=176,
        params=(1.0, float(main), float(sub), 0.0, 0.0, 0.0, 0.0),
        from_external=True,
        **SENT,
    )


def arm(t: float) -> Command:
    return Command(
        t=t, command=400, params=(1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0), from_external=True, **SENT
    )


def ack(t: float, command: int, result: int = 0) -> CommandAck:
    return CommandAck(
        t=t, vehicle="1", command=command, result=result, target_system=1, target_component=191
    )


def ordered(*groups: list[Event]) -> list[Event]:
    events = [e for group in groups for e in group]
    return sorted(events, key=lambda e: e.t)  # stable: same-time events keep group order


def good_flight(
    version: str | None = "1.15.4", gaps: Iterable[tuple[float, float]] = ()
) -> list[Event]:
    return ordered(
        identity(version),
        heartbeats(
            [
                (0.0, POSCTL, False),
                (4.0, OFFBOARD, False),
                (5.0, OFFBOARD, True),
                (16.0, AUTO_LAND, True),
                (22.0, AUTO_LAND, False),
            ],
            24.0,
        ),
        stream(1.0, 16.0, gaps),
        [set_mode(3.0, 6), ack(3.01, 176), arm(4.5), ack(4.51, 400)],
        [set_mode(15.0, 4, 6), ack(15.01, 176)],
    )


def lost_stream() -> list[Event]:
    return ordered(
        identity(),
        heartbeats(
            [
                (0.0, POSCTL, False),
                (4.0, OFFBOARD, False),
                (5.0, OFFBOARD, True),
                (10.0, POSCTL, True),  # failsafe: COM_OBL_RC_ACT 0 -> Position
                (12.0, OFFBOARD, True),  # back by itself once the stream resumed at 11.5
                (16.0, AUTO_LAND, True),
                (22.0, AUTO_LAND, False),
            ],
            24.0,
        ),
        stream(1.0, 16.0, [(8.0, 11.5)]),
        [set_mode(3.0, 6), ack(3.01, 176), arm(4.5), ack(4.51, 400)],
        [set_mode(15.0, 4, 6), ack(15.01, 176)],
    )


def switch_50ms() -> list[Event]:
    return ordered(
        identity(),
        heartbeats(
            [
                (0.0, POSCTL, True),
                (3.0, OFFBOARD, True),
                (11.0, AUTO_LAND, True),
                (16.0, AUTO_LAND, False),
            ],
            17.0,
        ),
        stream(2.0, 11.0),
        [set_mode(2.05, 6), ack(2.06, 176)],
        [set_mode(10.0, 4, 6), ack(10.01, 176)],
    )


def stop_to_hold() -> list[Event]:
    """MAVSDK ``stop()`` on PX4 1.16.2 (offboard_impl.cpp: stop sending, then Hold)."""
    hold = 4
    return ordered(
        identity("1.16.2"),
        heartbeats(
            [
                (0.0, POSCTL, False),
                (4.0, OFFBOARD, False),
                (5.0, OFFBOARD, True),
                (11.0, hold, True),  # the first HEARTBEAT after the switch away
                (16.0, AUTO_LAND, True),
                (22.0, AUTO_LAND, False),
            ],
            24.0,
        ),
        stream(1.0, 10.01),
        [set_mode(3.0, 6), ack(3.004, 176), ack(3.01, 176), arm(4.5), ack(4.51, 400)],
        [set_mode(10.001, 4, 3), ack(10.02, 176), ack(10.026, 176)],
        [set_mode(15.0, 4, 6), ack(15.004, 176), ack(15.01, 176)],
    )


def arm_between_acks() -> list[Event]:
    """The good flight on 1.16.2, armed between the two acks of the switch (OFB207)."""
    return ordered(
        identity("1.16.2"),
        heartbeats(
            [(0.0, POSCTL, False), (4.0, OFFBOARD, True), (16.0, AUTO_LAND, True)],
            17.0,
        ),
        stream(1.0, 16.0),
        [set_mode(3.0, 6), ack(3.004, 176), arm(3.006), ack(3.01, 176), ack(3.016, 400)],
        [set_mode(15.0, 4, 6), ack(15.004, 176), ack(15.01, 176)],
    )


MISSION_START = 300
AUTO_MAIN, MISSION_SUB = 4, 4


def mission_on_rejected_switch() -> list[Event]:
    """1.17.0: the switch to AUTO_MISSION is rejected by its second ack; the client stopped its
    setpoints and started the mission on the first (OFB207), and PX4 stays in OFFBOARD."""
    mission_start = Command(
        t=10.006,
        command=MISSION_START,
        params=(0.0,) * 7,
        from_external=True,
        **SENT,
    )
    return ordered(
        identity("1.17.0"),
        heartbeats(
            [
                (0.0, POSCTL, False),
                (4.0, OFFBOARD, False),
                (5.0, OFFBOARD, True),
                (11.0, POSCTL, True),  # the loss failsafe: COM_OBL_RC_ACT 0 -> Position
            ],
            13.0,
        ),
        stream(1.0, 10.0),
        [set_mode(3.0, 6), ack(3.004, 176), ack(3.01, 176), arm(4.5), ack(4.51, 400)],
        [set_mode(10.0, AUTO_MAIN, MISSION_SUB), ack(10.004, 176), mission_start],
        [ack(10.009, 176, 1)],
    )


def rejected(version: str, acks: list[tuple[float, int]]) -> list[Event]:
    return ordered(
        identity(version),
        heartbeats([(0.0, POSCTL, True)], 5.0),
        [set_mode(2.0, 6)] + [ack(t, 176, result) for t, result in acks],
    )


def finding(
    code: str, severity: str, time_s: float | None, vehicle: str | None = "1"
) -> dict[str, Any]:
    out: dict[str, Any] = {"code": code, "severity": severity, "time_s": time_s}
    if time_s is not None and vehicle is not None:
        out["vehicle"] = vehicle
    return out


def write(
    name: str,
    events: list[Event],
    findings: list[dict[str, Any]],
    *,
    exit_status: int,
    profile: dict[str, Any],
    complete: bool = True,
    cut: int | None = None,
    clean: list[str] | None = None,
) -> None:
    path = write_tlog(HERE / f"{name}.tlog", events)
    if cut is not None:
        data = path.read_bytes()
        path.write_bytes(data[:cut])
    spec = {
        "recording": path.name,
        "args": [],
        "exit_status": exit_status,
        "complete": complete,
        "profile": profile,
        "findings": findings,
    }
    if clean:
        spec["clean"] = clean
    (HERE / f"{name}.expected.json").write_text(json.dumps(spec, indent=2) + "\n")


def truncation_point(events: list[Event], after_t: float) -> int:
    """A byte offset inside the first packet written after ``after_t`` (mid-packet cut)."""
    probe = HERE / ".probe.tlog"
    head = [e for e in events if e.t <= after_t]
    size = write_tlog(probe, head).stat().st_size
    probe.unlink()
    return size + 8 + 20  # timestamp + part of the next packet's header and payload


def main() -> None:
    p115 = {"px4": "1.15", "vehicle": "mc", "detected": True}
    # OFB701 (info) states the loss behaviour once per vehicle that uses offboard, at its request
    summary = finding("OFB701", "info", 3.0)
    write("good_offboard", good_flight(), [summary], exit_status=0, profile=p115)
    write(
        "keepalive_gap_0_7s",
        good_flight(gaps=[(8.0, 8.7)]),
        [summary, finding("OFB101", "info", 8.0)],
        exit_status=0,
        profile=p115,
    )
    # OFB103 by the end of the loss window (9.0-9.1 s: the 1 Hz HEARTBEAT gives no phase)
    loss_findings = [summary, finding("OFB101", "error", 8.0), finding("OFB103", "error", 9.11)]
    write("stream_lost_in_offboard", lost_stream(), loss_findings, exit_status=1, profile=p115)
    write(
        "switch_50ms_after_first_setpoint",
        switch_50ms(),
        [finding("OFB701", "info", 2.05), finding("OFB102", "info", 2.05)],
        exit_status=0,
        profile=p115,
    )
    write(
        "switch_rejected",
        rejected("1.15.4", [(2.01, 1)]),
        [finding("OFB102", "error", 2.0), finding("OFB201", "error", 2.01)],
        exit_status=1,
        profile=p115,
    )
    write(
        "px4_1_16_double_ack",
        rejected("1.16.2", [(2.004, 0), (2.01, 1)]),
        [finding("OFB102", "error", 2.0), finding("OFB201", "error", 2.01)],
        exit_status=1,
        profile={"px4": "1.16", "vehicle": "mc", "detected": True},
    )
    write(
        "mavsdk_stop_to_hold",
        stop_to_hold(),
        [finding("OFB701", "info", 3.0)],
        exit_status=0,
        profile={"px4": "1.16", "vehicle": "mc", "detected": True},
        clean=["OFB207"],
    )
    write(
        "arm_between_acks_1_16_2",
        arm_between_acks(),
        [finding("OFB701", "info", 3.0), finding("OFB207", "warning", 3.006)],
        exit_status=1,
        profile={"px4": "1.16", "vehicle": "mc", "detected": True},
    )
    write(
        "mission_on_rejected_switch_1_17_0",
        mission_on_rejected_switch(),
        [
            finding("OFB701", "info", 3.0),
            finding("OFB101", "error", 9.95),
            finding("OFB207", "error", 10.006),
            # the gate model cannot know that no mission is on board: it expected the switch
            finding("OFB202", "warning", 10.009),
            finding("OFB103", "error", 11.06),
        ],
        exit_status=1,
        profile={"px4": "1.17", "vehicle": "mc", "detected": True},
    )
    write(
        "no_autopilot_version",
        good_flight(version=None),
        [finding("OFB003", "info", None), summary],
        exit_status=0,
        profile={"px4": "1.15", "vehicle": "mc", "detected": False},
    )
    events = lost_stream()
    write(
        "truncated",
        events,
        [*loss_findings, finding("OFB001", "error", 13.0, vehicle=None)],
        exit_status=2,
        complete=False,
        profile=p115,
        cut=truncation_point(events, 13.0),
    )


if __name__ == "__main__":
    main()
