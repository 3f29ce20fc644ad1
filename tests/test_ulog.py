"""PX4 ULog: the writer and reader round-trip every kind; damage is one line, never a traceback."""

from __future__ import annotations

import json
import math
import struct
from pathlib import Path
from typing import Any

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from fuzzoff.events import (
    ActuatorMotors,
    ActuatorServos,
    AttitudeSetpoint,
    Command,
    CommandAck,
    ControlMode,
    Dropout,
    Event,
    FailsafeFlags,
    LandDetected,
    LegacyControlMode,
    ManualControl,
    Parameter,
    PositionSetpointTriplet,
    RatesSetpoint,
    RoverAttitudeSetpoint,
    RoverPositionSetpoint,
    RoverRateSetpoint,
    RoverSpeedSetpoint,
    RoverSteeringSetpoint,
    RoverThrottleSetpoint,
    StatusText,
    ThrustSetpoint,
    TorqueSetpoint,
    TrajectorySetpoint,
    VehicleControlModeStatus,
    VehicleInfo,
    VehiclePosition,
    VehicleStatus,
    event_to_dict,
)
from fuzzoff.formats import open_source
from fuzzoff.formats.ulog.reader import UlogSource, decode_release
from fuzzoff.formats.ulog.writer import DEFAULT_START_US, ver_sw_release, write_ulog
from tests.helpers import run_cli, run_cli_process

NAN = math.nan
VERSIONS = {
    "legacy": "1.7.3",
    "1.13": "1.13.3",
    "1.14": "1.14.4",
    "1.15": "1.15.4",
    "1.17": "1.17.0",
}


def _flags(valid: bool) -> dict[str, Any]:
    names = ("local_position", "local_velocity", "local_altitude", "global_position")
    names += ("attitude", "angular_velocity", "home_position")
    return {f"{name}_valid": valid for name in names}


def flight(era: str) -> list[Event]:
    """One of every kind the ULog reader emits for ``era`` (values exact in float32)."""
    legacy, modern = era == "legacy", era not in ("legacy", "1.13")
    params = {"COM_OBL_RC_ACT": 0.0, "COM_OF_LOSS_T": 0.0 if legacy else 1.0, "MAV_TYPE": 2.0}
    if modern:
        params["CA_AIRFRAME"] = 0.0
    out: list[Event] = [
        VehicleInfo(t=0.0, px4_version=VERSIONS[era], vehicle_type="mc", mav_type=2),
        *(Parameter(t=0.0, name=n, value=v) for n, v in params.items()),
        VehicleStatus(
            t=0.5,
            nav_state=2,
            mode="POSCTL",
            armed=True,
            user_intention=2,
            failsafe=False,
            vehicle_type=1,
            is_vtol=False,
        ),
        FailsafeFlags(
            t=0.5,
            offboard_control_signal_lost=True,
            manual_control_signal_lost=False,
            **_flags(True),
        ),
        VehicleControlModeStatus(
            t=0.6, offboard_enabled=True, enabled=frozenset({"offboard", "position", "velocity"})
        ),
        VehiclePosition(t=0.7, x=1.5, y=-2.0, z=0.25),
        VehiclePosition(t=1.75, x=NAN, y=NAN, z=-1.5),  # xy_valid false: x and y mean nothing
    ]
    if modern:
        out.append(
            ManualControl(
                t=0.8,
                roll=0.25,
                pitch=-0.5,
                yaw=0.125,
                throttle=0.0,
                sticks_moving=True,
                origin="vehicle",
            )
        )
    layout = "thrust_and_torque" if era in ("1.15", "1.17") else "actuator"
    if legacy:
        out.append(LegacyControlMode(t=1.0, ignore_thrust=True, ignore_acceleration_force=True))
    else:
        out.append(
            ControlMode(
                t=1.0,
                position=True,
                thrust_and_torque=layout == "thrust_and_torque",
                actuator=layout == "actuator",
                layout=layout,  # type: ignore[arg-type]
            )
        )
    motors = 8 if era in ("legacy", "1.13") else 12
    out += [
        TrajectorySetpoint(
            t=1.0,
            position=(1.5, -2.0, -3.25),
            velocity=(NAN, NAN, NAN) if legacy else (0.5, 0.0, -0.25),
            acceleration=(NAN, NAN, NAN),
            jerk=(0.0, 0.0, 0.0),
            yaw=1.5,
            yawspeed=NAN,
        ),
        AttitudeSetpoint(
            t=1.1, q_d=(1.0, 0.0, 0.0, 0.0), thrust_body=(0.0, 0.0, -0.5), yaw_sp_move_rate=0.0
        ),
        RatesSetpoint(t=1.2, roll=0.25, pitch=-0.25, yaw=0.5, thrust_body=(0.0, 0.0, -0.75)),
        ThrustSetpoint(t=1.3, xyz=(0.0, 0.0, -0.5)),
        TorqueSetpoint(t=1.3, xyz=(0.125, -0.125, 0.0)),
        ActuatorMotors(t=1.4, control=(0.5,) * 4 + (NAN,) * (motors - 4), reversible_flags=3),
        ActuatorServos(t=1.4, control=(0.25,) * 8),
        PositionSetpointTriplet(
            t=1.5,
            previous_valid=True,
            current_valid=True,
            current_type=6,
            current_position_valid=True,
            current_yaw_valid=True,
        ),
        RoverPositionSetpoint(
            t=1.6,
            position_ned=(10.0, 20.0),
            start_ned=(0.0, 0.0) if era == "1.17" else (NAN, NAN),
            cruising_speed=2.0,
            arrival_speed=0.5 if era == "1.17" else NAN,
            yaw=NAN,
        ),
        LandDetected(t=1.6, landed=False),
        RoverAttitudeSetpoint(t=1.6, yaw_setpoint=0.5),
        RoverRateSetpoint(t=1.6, yaw_rate_setpoint=0.25),
        RoverThrottleSetpoint(t=1.6, throttle_body_x=0.5, throttle_body_y=0.0),
        RoverSpeedSetpoint(t=1.6, speed_body_x=1.5, speed_body_y=0.0),
        RoverSteeringSetpoint(
            t=1.6,
            normalized_steering_angle=0.25,
            normalized_speed_diff=NAN if era == "1.17" else 0.5,
        ),
        Command(
            t=2.0,
            command=176,
            params=(1.0, 6.0, 0.0, 0.0, 0.0, 0.0, 0.0),
            target_system=1,
            target_component=1,
            source_system=255,
            source_component=190,
            from_external=True,
            transport="uorb",
        ),
        CommandAck(t=2.0, command=176, result=0, target_system=255, target_component=190),
        VehicleStatus(
            t=2.0,
            nav_state=14,
            mode="OFFBOARD",
            armed=True,
            user_intention=14,
            failsafe=False,
            vehicle_type=1,
            is_vtol=False,
        ),
        StatusText(t=2.5, severity=4, text="Offboard control lost"),
        # A parameter change and a dropout are dated at the data message before them.
        LegacyControlMode(t=3.0) if legacy else ControlMode(t=3.0, velocity=True, layout=layout),  # type: ignore[arg-type]
        Parameter(t=3.0, name="COM_OBL_RC_ACT", value=3.0),
        Dropout(t=3.0, duration_s=0.25),
    ]
    return out


def _comparable(event: Event) -> tuple[Any, ...]:
    data = event_to_dict(event)
    data.pop("where")
    data.pop("sender_time_us")
    data.pop("origin")  # a ULog is the vehicle's copy: always "vehicle" (asserted apart)
    text = json.dumps(data, sort_keys=True, default=str).replace("NaN", '"nan"')
    return (round(event.t, 6), event.kind, text)


def read(path: Path) -> list[Event]:
    with open_source(path) as source:
        events = list(source.events())
        assert source.problems == []
    return events


@pytest.mark.parametrize("era", sorted(VERSIONS))
def test_every_kind_round_trips_through_a_ulog(era: str, tmp_path: Path) -> None:
    events = flight(era)
    path = write_ulog(tmp_path / "flight.ulg", events, px4_version=VERSIONS[era])
    back = read(path)
    assert sorted(map(_comparable, back)) == sorted(map(_comparable, events))
    for event in back:
        assert event.origin == "vehicle"
        if event.where.topic not in ("info", "parameters"):
            assert event.sender_time_us == DEFAULT_START_US + round(event.t * 1e6)


def test_round_trip_covers_every_kind_the_reader_emits() -> None:
    from fuzzoff.formats.ulog.topics import TOPICS

    kinds = {e.kind for era in VERSIONS for e in flight(era)}
    assert {spec.kind for spec in TOPICS.values()} | {"legacy_control_mode"} <= kinds


def test_events_come_out_in_time_order_with_their_place_in_the_topic(tmp_path: Path) -> None:
    events = [ControlMode(t=0.1 * k, position=True) for k in range(1, 30)]
    events += [TrajectorySetpoint(t=0.05 + 0.2 * k, position=(0.0, 0.0, -1.0)) for k in range(15)]
    back = read(write_ulog(tmp_path / "a.ulg", events))
    times = [e.t for e in back]
    assert times == sorted(times)
    ocm = [e for e in back if isinstance(e, ControlMode)]
    assert [e.where.index for e in ocm] == list(range(29))
    assert {e.where.topic for e in ocm} == {"offboard_control_mode"}


def test_probe_reports_version_vehicle_kinds_and_logging_intervals(tmp_path: Path) -> None:
    events: list[Event] = [VehicleStatus(t=0.1, nav_state=14, armed=True, vehicle_type=1)]
    events += [ControlMode(t=0.5 + 0.1 * k, position=True) for k in range(50)]
    events += [TrajectorySetpoint(t=0.5 + 0.2 * k, position=(0.0, 0.0, -2.0)) for k in range(25)]
    path = write_ulog(tmp_path / "a.ulg", events, px4_version="1.16.1")
    with open_source(path) as source:
        info = source.probe()
    assert info.format == "ulog"
    assert info.px4_version == "1.16.1"
    assert info.vehicle_type == "mc"
    assert {"control_mode", "trajectory", "vehicle_status", "parameter"} <= info.kinds
    assert info.sampled_intervals == {"control_mode": 0.1, "trajectory": 0.2}


def test_a_stream_slower_than_the_logger_is_not_taken_for_its_interval(tmp_path: Path) -> None:
    events = [ControlMode(t=0.5 * k, position=True) for k in range(1, 20)]
    with open_source(write_ulog(tmp_path / "a.ulg", events)) as source:
        assert source.probe().sampled_intervals == {"control_mode": 0.1}


@pytest.mark.parametrize(
    ("word", "text"),
    [
        (0x010F04FF, "1.15.4"),
        (0x011100C0, "1.17.0-rc"),
        (0x010E0080, "1.14.0-beta"),
        (0x010D0300, "1.13.3-dev"),
        (0, None),
    ],
)
def test_ver_sw_release_is_decoded(word: int, text: str | None) -> None:
    assert decode_release(word) == text
    if text is not None:
        assert ver_sw_release(text) == word


@pytest.mark.parametrize(
    ("params", "status", "vehicle"),
    [
        ({"CA_AIRFRAME": 5}, 3, "rover-ackermann"),
        ({"CA_AIRFRAME": 13}, 3, "rover-mecanum"),
        ({"RD_WHEEL_TRACK": 0.3, "MAV_TYPE": 10}, 3, "rover-differential"),
        ({"RA_WHEEL_BASE": 0.3, "MAV_TYPE": 10}, 3, "rover-ackermann"),
        ({"MAV_TYPE": 10}, 3, "rover-differential"),
        ({"CA_AIRFRAME": 2}, 1, "vtol"),
        ({"MAV_TYPE": 1}, 2, "fw"),
    ],
)
def test_vehicle_type_comes_from_status_and_parameters(
    params: dict[str, float], status: int, vehicle: str, tmp_path: Path
) -> None:
    is_vtol = vehicle == "vtol"
    events = [VehicleStatus(t=0.1, nav_state=2, vehicle_type=status, is_vtol=is_vtol)]
    path = write_ulog(tmp_path / "a.ulg", events, layout="1.13", params=params)
    with open_source(path) as source:
        assert source.probe().vehicle_type == vehicle


def test_legacy_arming_numbering_counts_armed_error_as_armed(tmp_path: Path) -> None:
    path = write_ulog(tmp_path / "a.ulg", [VehicleStatus(t=0.1, armed=True)], px4_version="1.7.3")
    with open_source(path) as source:
        (status,) = [e for e in source.events() if isinstance(e, VehicleStatus)]
    assert status.armed is True


# -- bad input -------------------------------------------------------------------------------


def offboard_with_rejection() -> list[Event]:
    """A rejected switch early (OFB201 at 1.0 s), then a long clean offboard flight."""
    events: list[Event] = [
        VehicleStatus(t=0.05, nav_state=2, armed=True, user_intention=2, vehicle_type=1),
        Command(t=1.0, command=176, params=(1.0, 6.0, 0, 0, 0, 0, 0), target_system=1),
        CommandAck(t=1.01, command=176, result=1),
    ]
    for k in range(300):
        t = 2.0 + 0.1 * k
        events.append(ControlMode(t=t, position=True))
        events.append(TrajectorySetpoint(t=t, position=(0.0, 0.0, -5.0)))
    return events


@pytest.fixture(scope="module")
def good_log(tmp_path_factory: pytest.TempPathFactory) -> bytes:
    path = tmp_path_factory.mktemp("ulog") / "good.ulg"
    return write_ulog(path, offboard_with_rejection()).read_bytes()


def _damaged(data: bytes, how: str) -> bytes:
    middle = len(data) // 2
    if how == "empty":
        return b""
    if how == "foreign":
        return b"%PDF-1.4 not a flight log at all\n" * 4
    if how == "header":
        return data[:10]
    if how == "definitions":
        return data[:400]
    if how == "definitions-header":
        return data[:18]  # inside the first record's 3-byte header
    if how.startswith("cut"):
        return data[: int(len(data) * float(how[3:]))]
    if how == "flipped":
        return (
            data[:middle]
            + bytes(b ^ 0xA5 for b in data[middle : middle + 64])
            + data[middle + 64 :]
        )
    if how == "no-format":
        at = data.index(b"trajectory_setpoint:")
        return data[:at] + b"trajectory_setpoinX:" + data[at + 20 :]
    if how == "garbage-definitions":
        # Among the definitions, a record header of no known type that claims one byte more
        # than the rest of the file (over pyulog's 10000-byte limit, so taken for damage):
        # pyulog 1.3 alone seeks back onto that same header, forever.
        at = data.index(b"trajectory_setpoint:") - 3  # a format record's header
        rest = data[at : at + 10000]
        return data[:at] + struct.pack("<HB", len(rest) + 1, ord("[")) + rest
    raise AssertionError(how)


BAD = {
    "empty": "empty file",
    "foreign": "not a recording",
    "header": "shorter than the 16-byte ULog header",
    "definitions": "truncated in the definition section",
    "definitions-header": "truncated in the definition section",
    "cut0.6": "truncated in the middle of a message",
    "cut0.93": "truncated in the middle of a message",
    "flipped": "corrupt",
    "no-format": "no message format for topic trajectory_setpoint",
    "garbage-definitions": "broken definition section",
}


@pytest.mark.parametrize("how", sorted(BAD))
def test_damaged_ulog_is_one_line_exit_2_and_json_stays_clean(
    how: str, good_log: bytes, tmp_path: Path
) -> None:
    path = tmp_path / "flight.ulg"
    path.write_bytes(_damaged(good_log, how))
    result = run_cli_process(["lint", str(path), "--format", "json"], timeout=60)
    assert result.returncode == 2
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1, result.stderr
    assert str(path) in lines[0] and BAD[how] in lines[0]
    assert "Traceback" not in result.stderr
    (report,) = json.loads(result.stdout)["files"]  # nothing else on stdout
    assert report["complete"] is False
    codes = [f["code"] for f in report["findings"]]
    assert codes.count("OFB001") == 1
    if how == "garbage-definitions":
        at = good_log.index(b"trajectory_setpoint:") - 3
        assert f" at byte {at}" in lines[0]  # where the damaged record starts
    if how.startswith("cut") or how in ("flipped", "no-format"):
        assert " at byte " in lines[0]
        assert "OFB201" in codes  # found in the readable part, kept


def test_a_parameter_of_a_damaged_type_is_reported_and_the_rest_kept(tmp_path: Path) -> None:
    params = {"COM_OF_LOSS_T": 2.0, "MPC_XY_VEL_MAX": 5.0}
    data = write_ulog(tmp_path / "p.ulg", offboard_with_rejection(), params=params).read_bytes()
    assert data.count(b"float MPC_XY_VEL_MAX") == 1
    path = tmp_path / "damaged.ulg"
    path.write_bytes(data.replace(b"float MPC_XY_VEL_MAX", b"floaz MPC_XY_VEL_MAX"))
    result = run_cli(["lint", str(path), "--format", "json"])
    assert result.returncode == 2
    (line,) = result.stderr.strip().splitlines()
    assert "damaged parameter records" in line and "MPC_XY_VEL_MAX" in line
    (report,) = json.loads(result.stdout)["files"]
    assert "OFB201" in [f["code"] for f in report["findings"]]  # the flight is still linted
    with open_source(path) as source:
        read = {e.name: e.value for e in source.events() if isinstance(e, Parameter)}
    assert read["COM_OF_LOSS_T"] == 2.0 and "MPC_XY_VEL_MAX" not in read


def test_a_topic_name_from_the_file_cannot_break_or_colour_the_error_line(
    good_log: bytes, tmp_path: Path
) -> None:
    # The subscription record (after the format record) names a topic with no format: a line
    # break and an ANSI colour in that name reach the message, shown escaped on one line.
    name = b"trajectory_setpoint"
    at = good_log.index(name, good_log.index(name + b":") + 1)
    odd = b"traj\n\x1b[31mpoint_xyz"
    assert len(odd) == len(name)
    path = tmp_path / "odd.ulg"
    path.write_bytes(good_log[:at] + odd + good_log[at + len(name) :])
    result = run_cli(["lint", str(path), "--format", "json"])
    assert result.returncode == 2
    (line,) = result.stderr.splitlines()
    assert "no message format for topic traj\\x0a\\x1b[31mpoint_xyz" in line


def test_truncation_says_when_the_last_complete_message_was(
    good_log: bytes, tmp_path: Path
) -> None:
    path = tmp_path / "cut.ulg"
    path.write_bytes(good_log[: len(good_log) // 2 + 5])
    with open_source(path) as source:
        events = list(source.events())
        (problem,) = source.problems
    assert problem.time_s == pytest.approx(events[-1].t)
    assert f"{problem.time_s:.3f} s" in (problem.where or "")


def test_pyulog_output_never_reaches_stdout(good_log: bytes, tmp_path: Path) -> None:
    path = tmp_path / "flipped.ulg"
    path.write_bytes(_damaged(good_log, "flipped"))
    result = run_cli_process(["lint", str(path), "--format", "json"])
    assert result.returncode == 2
    assert result.stdout.lstrip().startswith("{")
    json.loads(result.stdout)
    assert "corruption detected" not in result.stdout + result.stderr


def test_reader_is_registered_for_ulog_content(tmp_path: Path) -> None:
    path = write_ulog(tmp_path / "renamed.bin", [ControlMode(t=0.1, position=True)])
    assert isinstance(open_source(path), UlogSource)


# -- sampling: PX4's own setpoints are not an offboard stream -----------------------------------


def auto_mission() -> list[Event]:
    """Takeoff, mission and landing: PX4 logs trajectory_setpoint itself, no offboard at all."""
    events: list[Event] = [VehicleStatus(t=0.1, nav_state=4, armed=False, vehicle_type=1)]
    events.append(VehicleStatus(t=1.0, nav_state=17, armed=True, user_intention=17, vehicle_type=1))
    events.append(VehicleStatus(t=5.0, nav_state=3, armed=True, user_intention=3, vehicle_type=1))
    events.append(
        VehicleStatus(t=40.0, nav_state=18, armed=True, user_intention=18, vehicle_type=1)
    )
    for k in range(1, 250):  # 5 Hz, with the logger's occasional 0.6 s hole
        if k % 50 == 0:
            continue
        events.append(TrajectorySetpoint(t=0.2 * k, position=(float(k), 0.0, -10.0)))
        events.append(AttitudeSetpoint(t=0.2 * k + 0.01, q_d=(1.0, 0.0, 0.0, 0.0)))
    return events


def test_auto_mission_log_gives_no_stream_findings(tmp_path: Path) -> None:
    path = write_ulog(tmp_path / "mission.ulg", auto_mission())
    result = run_cli(["lint", str(path), "--format", "json"])
    (report,) = json.loads(result.stdout)["files"]
    assert report["complete"] is True
    assert not [f for f in report["findings"] if f["code"].startswith("OFB1")]
    with open_source(path) as source:
        info = source.probe()
    assert "control_mode" not in info.kinds  # no offboard source: PX4 never published it
    assert info.sampled_intervals["trajectory"] == 0.2


def _switch_without_stream() -> list[Event]:
    """Armed in Position, a switch to OFFBOARD that PX4 rejects, no offboard_control_mode."""
    return [
        VehicleStatus(t=0.0, nav_state=2, armed=True, user_intention=2),
        Command(t=2.0, command=176, params=(1.0, 6.0, 0.0, 0.0, 0.0, 0.0, 0.0)),
        CommandAck(t=2.01, command=176, result=1),
        VehicleStatus(t=4.0, nav_state=2, armed=True, user_intention=2),
    ]


def test_a_logger_subscribed_to_the_stream_shows_that_none_was_sent(tmp_path: Path) -> None:
    # PX4's logger writes offboard_control_mode's format from the start: no data = no stream
    path = write_ulog(tmp_path / "sent_nothing.ulg", _switch_without_stream())
    result = run_cli(["lint", str(path), "--format", "json"])
    codes = [f["code"] for f in json.loads(result.stdout)["files"][0]["findings"]]
    assert "OFB102" in codes and "OFB201" in codes and "OFB002" not in codes


def test_a_logger_not_logging_the_stream_cannot_judge_it(tmp_path: Path) -> None:
    # a logger_topics.txt without offboard_control_mode: the stream rules are not checkable
    path = write_ulog(tmp_path / "not_logged.ulg", _switch_without_stream(), subscribed=())
    result = run_cli(["lint", str(path), "--format", "json"])
    findings = json.loads(result.stdout)["files"][0]["findings"]
    codes = [f["code"] for f in findings]
    assert "OFB102" not in codes and "OFB201" in codes
    (note,) = [f for f in findings if f["code"] == "OFB002"]
    assert "did not log offboard_control_mode" in note["message"]


def test_a_damaged_record_is_skipped_and_reported_with_the_last_good_time(tmp_path: Path) -> None:
    events = offboard_with_rejection()
    whole = write_ulog(tmp_path / "whole.ulg", events).read_bytes()
    head = write_ulog(tmp_path / "head.ulg", [e for e in events if e.t <= 10.0]).read_bytes()
    assert whole.startswith(head)  # the head ends on a record boundary of the whole log
    bogus = b"\x03\x00D\xff\xff\x00"  # a data record for a topic that was never subscribed
    path = tmp_path / "damaged.ulg"
    path.write_bytes(head + bogus + whole[len(head) :])
    result = run_cli(["lint", str(path), "--format", "json"])
    assert result.returncode == 2
    (line,) = result.stderr.strip().splitlines()
    at = len(head) + len(bogus)
    assert (
        f"corrupt data: damaged records were skipped and reading resumed after them at byte {at}"
        in line
    )
    assert "after the last good message at 10.000 s" in line
    assert json.loads(result.stdout)["files"][0]["complete"] is False
    with open_source(path) as source:
        times = [e.t for e in source.events() if isinstance(e, ControlMode)]
    assert times[-1] == pytest.approx(31.9)  # read on after the damage


def _chunk(columns: dict[str, list[Any]]) -> Any:
    import numpy as np

    from fuzzoff.formats.ulog.topics import Chunk

    cols = {name: np.asarray(values) for name, values in columns.items()}
    return Chunk(cols, slice(None), "vehicle_status", 0)


def test_older_layouts_the_writer_does_not_produce_are_read() -> None:
    """The seed's single ``ignore_bodyrate`` and the link-loss flags of a legacy status."""
    from fuzzoff.formats.ulog.topics import Context, control_mode, failsafe_flags

    ocm = _chunk(
        {
            "timestamp": [1_000_000],
            "ignore_thrust": [1],
            "ignore_bodyrate": [0],
            "ignore_alt_hold": [1],
        }
    )
    (legacy,) = control_mode(ocm, Context())
    assert isinstance(legacy, LegacyControlMode)
    assert (legacy.ignore_thrust, legacy.ignore_bodyrate, legacy.ignore_alt_hold) == (
        True,
        False,
        True,
    )
    status = _chunk(
        {"timestamp": [2_000_000], "offboard_control_signal_lost": [1], "rc_signal_lost": [0]}
    )
    (flags,) = failsafe_flags(status, Context())
    assert isinstance(flags, FailsafeFlags)
    assert flags.offboard_control_signal_lost is True
    assert flags.manual_control_signal_lost is False
    assert flags.local_position_valid is None  # not in that layout: unknown, not invalid
    assert flags.t == 2.0


# -- round trip as a property ------------------------------------------------------------------


_F32 = st.floats(width=32, allow_nan=True, allow_infinity=False)
_VEC3 = st.tuples(_F32, _F32, _F32)
_TIME = st.integers(min_value=0, max_value=600_000_000).map(lambda us: us / 1e6)


@st.composite
def _setpoint(draw: st.DrawFn) -> Event:
    t = draw(_TIME)
    if draw(st.booleans()):
        flags = draw(st.lists(st.booleans(), min_size=7, max_size=7))
        names = ("position", "velocity", "acceleration", "attitude", "body_rate")
        names += ("thrust_and_torque", "direct_actuator")
        return ControlMode(t=t, **dict(zip(names, flags, strict=True)))
    return TrajectorySetpoint(
        t=t,
        position=draw(_VEC3),
        velocity=draw(_VEC3),
        acceleration=draw(_VEC3),
        jerk=draw(_VEC3),
        yaw=draw(_F32),
        yawspeed=draw(_F32),
    )


@settings(
    max_examples=25, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(events=st.lists(_setpoint(), min_size=1, max_size=30))
def test_any_setpoint_stream_round_trips(events: list[Event], tmp_path: Path) -> None:
    path = write_ulog(tmp_path / "p.ulg", events, params={})
    back = [e for e in read(path) if e.kind in ("control_mode", "trajectory")]
    assert sorted(map(_comparable, back)) == sorted(map(_comparable, events))
