"""Build the ULog corpus: offboard flights as PX4's logger records them (formats.md 8).

Run ``.venv/bin/python corpora/ulog/build.py``; it is deterministic. Every recording is written
through ``fuzzoff.formats.ulog.writer`` (pyulog's ``write_ulog``) the way PX4 logs a flight: topics
subsampled by the default logger profile (``offboard_control_mode`` every 100 ms,
``trajectory_setpoint`` every 200 ms), ``vehicle_status`` on change and every second, PX4's own
verdict in ``failsafe_flags``. Each gets ``NAME.expected.json`` with the findings planted here,
judged against the rule texts (rules/OFB*.toml). Every offboard flight also gets the info
notes a ULog always gets: one OFB002 for the rules that need the stream as sent (a ULog holds
PX4's subsampled copies) and OFB701, the loss-action summary, at the first offboard request; a
flight without offboard gets OFB005 instead of OFB701 (and lists it as clean where it flew
offboard).

* ``good_offboard``: PX4 1.15.4, 2 s of keep-alive before an accepted switch, arming in
  OFFBOARD, a moving position setpoint, AUTO_LAND; no finding (profile detected).
* ``keepalive_gap_0_8s``: the good flight with no ``offboard_control_mode`` sample logged
  between 8.0 and 8.8 s: OFB101 as info (0.7 s proven, the logged gap minus the logger's 0.1 s:
  the docs' 2 Hz is broken, but PX4 1.15 keeps offboard, under 80 % of COM_OF_LOSS_T 1.0 s).
* ``logger_dropout``: the same hole in every topic, explained by a 750 ms logger dropout
  record: the log proves nothing about the stream there, no finding.
* ``stream_lost_in_offboard``: the keep-alive stops for 3.5 s in offboard (last logged sample
  at 8.0 s): OFB101 error (3.4 s proven: the logged gap minus the logger's 0.1 s) and OFB103
  (loss after COM_OF_LOSS_T 1.0 s, action Position). The log shows PX4's own failsafe at 9.08 s
  (``failsafe_flags.offboard_control_signal_lost``, ``vehicle_status`` POSCTL with ``failsafe``
  and the user intention still OFFBOARD) and the return to OFFBOARD when the stream resumes.
* ``switch_rejected``: armed in POSCTL, no offboard source, a switch to OFFBOARD acked
  TEMPORARILY_REJECTED: OFB201, and OFB102 (a request with no keep-alive at all: an error, as
  PX4 rejects it).
* ``legacy_ignore_flags``: PX4 1.7.3 with the ``ignore_*`` ``offboard_control_mode``, the
  setpoint in ``position_setpoint_triplet`` (only ``current`` filled) and the v1.7 user
  intention in ``commander_state``; a clean flight on the legacy profile.
* ``no_ver_sw_release``: the good flight without ``ver_sw_release`` in the info section: OFB003
  (PX4 version assumed; the vehicle type still comes from ``vehicle_status``).
* ``auto_mission``: takeoff, mission, landing; PX4 logs its own ``trajectory_setpoint`` and
  attitude setpoints, there is no ``offboard_control_mode``: no stream finding (docs/ulog.md),
  and OFB005: no offboard in this recording.
* ``truncated``: the lost-stream flight cut inside the first message after 13.0 s: OFB001 at
  13.0 s (the last complete message), exit status 2; the findings before the cut stay.
"""

from __future__ import annotations

import json
from collections.abc import Iterable
from pathlib import Path
from typing import Any

from fuzzoff.events import (
    ESTIMATES,
    AttitudeSetpoint,
    Command,
    CommandAck,
    ControlMode,
    Dropout,
    Event,
    FailsafeFlags,
    LegacyControlMode,
    PositionSetpointTriplet,
    StatusText,
    TrajectorySetpoint,
    VehicleControlModeStatus,
    VehicleStatus,
)
from fuzzoff.formats.ulog.writer import write_ulog

HERE = Path(__file__).resolve().parent
POSCTL, AUTO_MISSION, AUTO_TAKEOFF, OFFBOARD, AUTO_LAND, AUTO_LOITER = 2, 3, 17, 14, 18, 4
OCM_INTERVAL, TRAJECTORY_INTERVAL = 0.1, 0.2  # PX4's default logger profile
GCS = {"target_system": 1, "target_component": 1, "source_system": 255, "source_component": 190}
ESTIMATES_OK = {
    f"{name}_valid": True
    for name in ESTIMATES
}

Mode = tuple[float, int, bool, int, bool]
"""(from time, nav_state, armed, user intention, failsafe)."""


def statuses(modes: list[Mode], end: float) -> list[Event]:
    """``vehicle_status`` on every change and every second in between (as commander does)."""
    out: list[Event] = []
    times = sorted({round(t, 6) for t, *_ in modes} | {float(s) for s in range(int(end) + 1)})
    for t in times:
        _, nav, armed, intention, failsafe = next(m for m in reversed(modes) if m[0] <= t + 1e-9)
        out.append(
            VehicleStatus(
                t=t,
                nav_state=nav,
                armed=armed,
                user_intention=intention,
                failsafe=failsafe,
                vehicle_type=1,
                is_vtol=False,
            )
        )
    return out


def flags(changes: list[tuple[float, bool]]) -> list[Event]:
    """``failsafe_flags`` whenever PX4's offboard-lost verdict changes; estimates all valid."""
    return [
        FailsafeFlags(
            t=t,
            offboard_control_signal_lost=lost,
            manual_control_signal_lost=False,
            **ESTIMATES_OK,
        )
        for t, lost in changes
    ]


def control_modes(changes: list[tuple[float, bool]]) -> list[Event]:
    """``vehicle_control_mode`` on change: offboard on or off (position control either way)."""
    return [
        VehicleControlModeStatus(
            t=t,
            offboard_enabled=on,
            enabled=frozenset({"offboard" if on else "manual", "position", "velocity", "altitude"}),
        )
        for t, on in changes
    ]


def _ticks(
    start: float, stop: float, period: float, gaps: Iterable[tuple[float, float]]
) -> list[float]:
    gaps = list(gaps)
    out, k = [], 0
    while (t := round(start + k * period, 6)) < stop - 1e-9:
        k += 1
        if not any(a < t < b for a, b in gaps):
            out.append(t)
    return out


def offboard_stream(
    start: float, stop: float, gaps: Iterable[tuple[float, float]] = ()
) -> list[Event]:
    """The logged copies: OCM (position) at 10 Hz, a slowly moving position setpoint at 5 Hz."""
    gaps = list(gaps)
    out: list[Event] = [
        ControlMode(t=t, position=True) for t in _ticks(start, stop, OCM_INTERVAL, gaps)
    ]
    for t in _ticks(start, stop, TRAJECTORY_INTERVAL, gaps):
        x = round(0.1 * (t - start), 3)
        out.append(TrajectorySetpoint(t=t, position=(x, 0.0, -2.5), yaw=0.0))
    return out


def set_mode(t: float, main: int, sub: int = 0) -> Command:
    params = (1.0, float(main), float(sub), 0.0, 0.0, 0.0, 0.0)
    return Command(t=t, command=176, params=params, from_external=True, transport="uorb", **GCS)


def arm(t: float) -> Command:
    params = (1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    return Command(t=t, command=400, params=params, from_external=True, transport="uorb", **GCS)


def ack(t: float, command: int, result: int = 0) -> CommandAck:
    return CommandAck(t=t, command=command, result=result, target_system=255, target_component=190)


def ordered(*groups: list[Event]) -> list[Event]:
    return sorted((e for group in groups for e in group), key=lambda e: e.t)


def good_flight() -> list[Event]:
    return ordered(
        statuses(
            [
                (0.0, POSCTL, False, POSCTL, False),
                (3.01, OFFBOARD, False, OFFBOARD, False),
                (4.51, OFFBOARD, True, OFFBOARD, False),
                (15.01, AUTO_LAND, True, AUTO_LAND, False),
                (22.0, AUTO_LAND, False, AUTO_LAND, False),
            ],
            24.0,
        ),
        flags([(0.0, True), (1.0, False), (16.1, True)]),
        control_modes([(0.0, False), (3.02, True), (15.02, False)]),
        offboard_stream(1.0, 16.0),
        [set_mode(3.0, 6), ack(3.01, 176), arm(4.5), ack(4.51, 400)],
        [set_mode(15.0, 4, 6), ack(15.01, 176)],
        [StatusText(t=4.52, severity=6, text="Armed by external command")],
    )


def with_gap(dropout: bool) -> list[Event]:
    """The good flight with 0.8 s of missing keep-alive samples in offboard (8.0-8.8 s): a
    logger dropout (everything missing, a dropout record) or a stream gap (only the OCM)."""
    if not dropout:
        return [e for e in good_flight() if not (isinstance(e, ControlMode) and 8.0 < e.t < 8.8)]
    kept = [e for e in good_flight() if not 8.0 < e.t < 8.8]
    return ordered(kept, [Dropout(t=8.0, duration_s=0.75)])


def lost_stream() -> list[Event]:
    return ordered(
        statuses(
            [
                (0.0, POSCTL, False, POSCTL, False),
                (3.01, OFFBOARD, False, OFFBOARD, False),
                (4.51, OFFBOARD, True, OFFBOARD, False),
                (9.08, POSCTL, True, OFFBOARD, True),  # failsafe: COM_OBL_RC_ACT 0 -> Position
                (11.52, OFFBOARD, True, OFFBOARD, False),  # back by itself once it resumed
                (15.01, AUTO_LAND, True, AUTO_LAND, False),
                (22.0, AUTO_LAND, False, AUTO_LAND, False),
            ],
            24.0,
        ),
        flags([(0.0, True), (1.0, False), (9.08, True), (11.51, False), (16.1, True)]),
        control_modes([(0.0, False), (3.02, True), (9.09, False), (11.53, True), (15.02, False)]),
        offboard_stream(1.0, 16.0, [(8.0, 11.5)]),
        [set_mode(3.0, 6), ack(3.01, 176), arm(4.5), ack(4.51, 400)],
        [StatusText(t=9.08, severity=4, text="Failsafe activated: No offboard signal")],
        [set_mode(15.0, 4, 6), ack(15.01, 176)],
    )


def rejected() -> list[Event]:
    return ordered(
        statuses([(0.0, POSCTL, True, POSCTL, False)], 5.0),
        flags([(0.0, True)]),
        [set_mode(2.0, 6), ack(2.01, 176, 1)],
        [StatusText(t=2.01, severity=4, text="Switching to Offboard is currently not available")],
    )


def legacy_flight() -> list[Event]:
    """PX4 1.7: ignore_* flags (position only), setpoint in the triplet's ``current``."""
    keepalive = _ticks(1.0, 16.0, OCM_INTERVAL, ())
    ocm = [
        LegacyControlMode(
            t=t,
            ignore_thrust=True,
            ignore_attitude=True,
            ignore_bodyrate=True,
            ignore_velocity=True,
            ignore_acceleration_force=True,
        )
        for t in keepalive
    ]
    triplets = [
        PositionSetpointTriplet(
            t=t,
            current_valid=True,
            current_type=0,
            current_position_valid=True,
            current_yaw_valid=True,
        )
        for t in _ticks(1.0, 16.0, TRAJECTORY_INTERVAL, ())
    ]
    return ordered(
        statuses(
            [
                (0.0, POSCTL, True, POSCTL, False),
                (3.01, OFFBOARD, True, OFFBOARD, False),
                (15.01, AUTO_LAND, True, AUTO_LAND, False),
                (20.0, AUTO_LAND, False, AUTO_LAND, False),
            ],
            22.0,
        ),
        flags([(0.0, True), (1.0, False), (16.1, True)]),
        ocm,
        triplets,
        [set_mode(3.0, 6), ack(3.01, 176), set_mode(15.0, 4, 6), ack(15.01, 176)],
    )


def auto_mission() -> list[Event]:
    """Takeoff, a mission and a landing: PX4's own setpoints only, no offboard source."""
    setpoints: list[Event] = []
    for t in _ticks(1.0, 40.0, TRAJECTORY_INTERVAL, ()):
        x = round(0.5 * max(0.0, t - 5.0), 3)
        setpoints.append(TrajectorySetpoint(t=t, position=(x, 0.0, -10.0), yaw=0.0))
    for t in _ticks(1.05, 40.0, 0.1, ()):
        setpoints.append(
            AttitudeSetpoint(t=t, q_d=(1.0, 0.0, 0.0, 0.0), thrust_body=(0.0, 0.0, -0.5))
        )
    return ordered(
        statuses(
            [
                (0.0, AUTO_LOITER, False, AUTO_LOITER, False),
                (1.0, AUTO_TAKEOFF, True, AUTO_TAKEOFF, False),
                (5.0, AUTO_MISSION, True, AUTO_MISSION, False),
                (35.0, AUTO_LAND, True, AUTO_LAND, False),
                (40.0, AUTO_LAND, False, AUTO_LAND, False),
            ],
            41.0,
        ),
        flags([(0.0, True)]),
        setpoints,
        [
            Command(t=0.9, command=22, params=(0.0,) * 7, transport="uorb", **GCS),
            ack(0.91, 22),
            Command(t=4.9, command=300, params=(0.0,) * 7, transport="uorb", **GCS),
            ack(4.91, 300),
        ],
    )


def finding(code: str, severity: str, time_s: float | None) -> dict[str, Any]:
    out: dict[str, Any] = {"code": code, "severity": severity, "time_s": time_s}
    if time_s is not None:
        out["vehicle"] = ""
    return out


NOT_CHECKABLE_ON_ULOG = ("OFB104", "OFB105", "OFB106", "OFB203", "OFB302")
"""Rules that need the stream as sent (rules/OFB104-106, 203, 302): OFB002 on every 1.14+ ULog
of an offboard flight (OFB106, 203 and 302 do not apply to the legacy profile; OFB104, 106 need
a keep-alive to be judged at all)."""


def not_checkable(*codes: str) -> list[dict[str, Any]]:
    """The one OFB002 line that lists ``codes`` (none when there are none)."""
    return [finding("OFB002", "info", None)] if codes else []


def offboard_context(*codes: str) -> list[dict[str, Any]]:
    """What every offboard ULog gets: the not-checkable notes and the loss-action summary
    (OFB701, once per vehicle that uses offboard, at its first offboard request)."""
    return [*not_checkable(*codes), finding("OFB701", "info", 3.0)]


def write(
    name: str,
    events: list[Event],
    findings: list[dict[str, Any]],
    *,
    exit_status: int,
    profile: dict[str, Any],
    complete: bool = True,
    px4_version: str | None = "1.15.4",
    cut_after: float | None = None,
    clean: list[str] | None = None,
) -> None:
    path = write_ulog(HERE / f"{name}.ulg", events, px4_version=px4_version)
    if cut_after is not None:
        probe = HERE / ".probe.ulg"
        head = write_ulog(probe, [e for e in events if e.t <= cut_after], px4_version=px4_version)
        prefix = head.read_bytes()
        probe.unlink()
        data = path.read_bytes()
        assert data.startswith(prefix), "the head must be a prefix of the whole log"
        path.write_bytes(data[: len(prefix) + 12])  # inside the next message
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


def main() -> None:
    p115 = {"px4": "1.15", "vehicle": "mc", "detected": True}
    context = offboard_context(*NOT_CHECKABLE_ON_ULOG)
    write("good_offboard", good_flight(), context, exit_status=0, profile=p115, clean=["OFB005"])
    write(
        "keepalive_gap_0_8s",
        with_gap(dropout=False),
        [*context, finding("OFB101", "info", 8.0)],
        exit_status=0,
        profile=p115,
    )
    write("logger_dropout", with_gap(dropout=True), context, exit_status=0, profile=p115)
    loss = [finding("OFB101", "error", 8.0), finding("OFB103", "error", 9.08)]  # PX4's own time
    write("stream_lost_in_offboard", lost_stream(), [*context, *loss], exit_status=1, profile=p115)
    write(
        "switch_rejected",
        rejected(),
        [finding("OFB102", "error", 2.0), finding("OFB201", "error", 2.01)],
        exit_status=1,
        profile=p115,
    )
    write(
        "legacy_ignore_flags",
        legacy_flight(),
        offboard_context("OFB104", "OFB105"),
        exit_status=0,
        profile={"px4": "legacy", "vehicle": "mc", "detected": True},
        px4_version="1.7.3",
    )
    write(
        "no_ver_sw_release",
        good_flight(),
        [*context, finding("OFB003", "info", None)],
        exit_status=0,
        profile={"px4": "1.15", "vehicle": "mc", "detected": False},
        px4_version=None,
    )
    write(
        "auto_mission",
        auto_mission(),
        # no keep-alive: nothing else to say but that offboard was never used
        [*not_checkable("OFB105", "OFB203", "OFB302"), finding("OFB005", "info", None)],
        exit_status=0,
        profile=p115,
    )
    write(
        "truncated",
        lost_stream(),
        [*context, *loss, finding("OFB001", "error", 13.0)],
        exit_status=2,
        complete=False,
        profile=p115,
        cut_after=13.0,
    )


if __name__ == "__main__":
    main()
