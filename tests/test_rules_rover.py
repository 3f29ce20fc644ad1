"""Rover rules (OFB501-OFB509): the docs' rover tables, edge by edge, per profile."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import replace
from typing import Any

import pytest

from fuzzoff.config import Settings
from fuzzoff.events import (
    ActuatorMotors,
    ActuatorServos,
    ControlMode,
    Event,
    Parameter,
    RoverAttitudeSetpoint,
    RoverPositionSetpoint,
    RoverRateSetpoint,
    RoverSpeedSetpoint,
    RoverSteeringSetpoint,
    RoverThrottleSetpoint,
    SetAttitudeTarget,
    SetPositionTargetGlobal,
    SetPositionTargetLocal,
    TrajectorySetpoint,
    VehicleStatus,
    event_from_dict,
)
from fuzzoff.findings import Finding, Severity
from fuzzoff.tables import rover as tr
from tests.streams import codes, lint_events

NAN = math.nan
ROVERS = ("rover-ackermann", "rover-differential", "rover-mecanum")
VELOCITY_ONLY = 3527
"""type_mask: vx, vy, vz used; position, acceleration, yaw and yaw rate ignored."""


def mode(t: float, flags: dict[str, bool]) -> Event:
    return event_from_dict({"kind": ControlMode.kind, "t": t, **flags})


def value(kind: str, t: float, nan: bool = False) -> Event:
    x = NAN if nan else 0.5
    builders: dict[str, Event] = {
        tr.POSITION: RoverPositionSetpoint(t=t, position_ned=(x, x)),
        tr.SPEED: RoverSpeedSetpoint(t=t, speed_body_x=x),
        tr.ATTITUDE: RoverAttitudeSetpoint(t=t, yaw_setpoint=x),
        tr.RATE: RoverRateSetpoint(t=t, yaw_rate_setpoint=x),
        tr.THROTTLE: RoverThrottleSetpoint(t=t, throttle_body_x=x),
        tr.STEERING: RoverSteeringSetpoint(t=t, normalized_steering_angle=x),
    }
    return builders[kind]


def drive(
    publish: set[str] | frozenset[str],
    nan: set[str] | frozenset[str] = frozenset(),
    *,
    flags: dict[str, bool],
    seconds: float = 1.0,
    offboard: bool = True,
) -> list[Event]:
    """A 10 Hz rover loop: OffboardControlMode, then the setpoints, every tick."""
    events: list[Event] = [VehicleStatus(t=0.0, nav_state=14 if offboard else 2, armed=True)]
    for i in range(round(seconds * 10)):
        t = round(i * 0.1, 3)
        events.append(mode(t, flags))
        events += [value(k, t + 0.001) for k in sorted(publish)]
        events += [value(k, t + 0.001, nan=True) for k in sorted(nan)]
    return events


def lint(
    events: Sequence[Event], px4: str = "1.16", vehicle: str = "rover-differential", **kw: Any
) -> list[Finding]:
    return lint_events(events, px4=px4, vehicle=vehicle, fmt="mcap", **kw)


COMBOS = tr.COMBINATIONS_000


@pytest.mark.parametrize("vehicle", ROVERS)
@pytest.mark.parametrize("row", COMBOS, ids=[r.name for r in COMBOS])
def test_every_documented_combination_is_clean(row: tr.RoverCombination, vehicle: str) -> None:
    found = lint(drive(row.publish, row.nan, flags={row.flag: True}), vehicle=vehicle)
    assert not [f for f in found if f.code in ("OFB502", "OFB503", "OFB504", "OFB501")]


@pytest.mark.parametrize("row", COMBOS, ids=[r.name for r in COMBOS])
def test_wrong_control_flag(row: tr.RoverCombination) -> None:
    wrong = "position" if row.flag != "position" else "velocity"
    (finding,) = codes(lint(drive(row.publish, row.nan, flags={wrong: True})), "OFB503")
    assert row.name in finding.message and row.flag in finding.message
    assert finding.time_s == pytest.approx(0.1)  # the first tick sees last tick's setpoints
    assert finding.end_s == pytest.approx(0.9)


@pytest.mark.parametrize("row", COMBOS, ids=[r.name for r in COMBOS])
def test_rover_setpoints_under_direct_actuator_are_a_mismatch(row: tr.RoverCombination) -> None:
    """direct_actuator runs no rover controller: the published combination is ignored."""
    found = lint(drive(row.publish, row.nan, flags={"direct_actuator": True}))
    (finding,) = codes(found, "OFB503")
    assert row.name in finding.message and "direct_actuator" in finding.message


def test_extra_control_flag_is_a_mismatch() -> None:
    flags = {"velocity": True, "attitude": True}
    found = lint(drive({tr.SPEED, tr.ATTITUDE}, flags=flags))
    (finding,) = codes(found, "OFB503")
    assert "velocity, attitude" in finding.message


@pytest.mark.parametrize(
    "publish",
    [
        {tr.SPEED},
        {tr.THROTTLE},
        {tr.ATTITUDE},
        {tr.SPEED, tr.THROTTLE, tr.ATTITUDE},
        {tr.POSITION, tr.SPEED, tr.ATTITUDE},
        {tr.THROTTLE, tr.ATTITUDE, tr.RATE},  # Throttle + Rate has no NaN row to explain it
    ],
)
def test_invalid_combination(publish: set[str]) -> None:
    found = lint(drive(publish, flags={"velocity": True}))
    (finding,) = codes(found, "OFB502")
    assert finding.severity is Severity.ERROR
    assert tr.names(frozenset(publish)) in finding.message
    assert not codes(found, "OFB503") and not codes(found, "OFB504")


@pytest.mark.parametrize("row", [r for r in COMBOS if r.nan], ids=lambda r: r.name)
def test_required_nan_not_published(row: tr.RoverCombination) -> None:
    found = lint(drive(row.publish, flags={row.flag: True}))
    (finding,) = codes(found, "OFB504")
    assert "is not published" in finding.message
    assert not codes(found, "OFB502")


@pytest.mark.parametrize("row", [r for r in COMBOS if r.nan], ids=lambda r: r.name)
def test_required_nan_carries_a_value(row: tr.RoverCombination) -> None:
    found = lint(drive(row.publish | row.nan, flags={row.flag: True}))
    (finding,) = codes(found, "OFB504")
    assert "carries a value" in finding.message
    assert not codes(found, "OFB502") and not codes(found, "OFB503")


def test_stale_nan_setpoint_counts_as_missing() -> None:
    events = drive({tr.SPEED, tr.RATE}, flags={"velocity": True}, seconds=2.0)
    events.append(RoverAttitudeSetpoint(t=0.0, yaw_setpoint=NAN))  # once, then never again
    (finding,) = codes(lint(events), "OFB504")
    assert finding.time_s == pytest.approx(0.6)  # first tick more than 0.5 s after it


def test_window_option_widens_what_counts_as_published() -> None:
    events = drive({tr.SPEED, tr.RATE}, flags={"velocity": True}, seconds=2.0)
    events.append(RoverAttitudeSetpoint(t=0.0, yaw_setpoint=NAN))
    settings = Settings(options={"OFB504": {"window_s": 5.0}})
    assert not codes(lint(events, settings=settings), "OFB504")


def test_combination_rules_need_offboard() -> None:
    found = lint(drive({tr.SPEED}, flags={"attitude": True}, offboard=False))
    assert not [f for f in found if f.code in ("OFB502", "OFB503", "OFB504")]


def test_combination_rules_need_rover_setpoints_on_116() -> None:
    events = drive({tr.SPEED}, flags={"velocity": True})
    assert not codes(lint(events, px4="1.15"), "OFB502")
    assert not codes(lint(events, vehicle="mc"), "OFB502")


def test_trajectory_setpoint_is_deprecated_from_116() -> None:
    events: list[Event] = [ControlMode(t=0.0, velocity=True)]
    events += [TrajectorySetpoint(t=0.1 * i, velocity=(1.0, 0.0, NAN)) for i in range(1, 6)]
    (finding,) = codes(lint(events), "OFB501")
    assert finding.severity is Severity.WARNING
    assert finding.time_s == pytest.approx(0.1) and finding.end_s == pytest.approx(0.5)
    assert not codes(lint(events, px4="1.15"), "OFB501")
    logged = [TrajectorySetpoint(t=0.1, origin="vehicle", velocity=(1.0, 0.0, NAN))]
    assert not codes(lint(logged), "OFB501")


@pytest.mark.parametrize(
    ("vehicle", "flags", "flagged"),
    [
        ("rover-ackermann", {"attitude": True}, True),
        ("rover-ackermann", {"velocity": True}, False),
        ("rover-ackermann", {"velocity": True, "attitude": True}, False),
        ("rover-differential", {"attitude": True}, False),
        ("rover-mecanum", {"attitude": True}, False),
    ],
)
def test_ackermann_yaw(vehicle: str, flags: dict[str, bool], flagged: bool) -> None:
    events: list[Event] = [mode(0.0, flags), TrajectorySetpoint(t=0.05, yaw=1.0)]
    assert bool(codes(lint(events, vehicle=vehicle), "OFB505")) is flagged


@pytest.mark.parametrize(
    ("flags", "flagged"),
    [
        ({"direct_actuator": True}, False),
        ({"velocity": True, "direct_actuator": True}, True),
        ({"thrust_and_torque": True}, True),
    ],
)
def test_direct_actuator_must_be_alone(flags: dict[str, bool], flagged: bool) -> None:
    events: list[Event] = [
        VehicleStatus(t=0.0, nav_state=14, armed=True),
        mode(0.0, flags),
        ActuatorMotors(t=0.05, control=(0.2, 0.2)),
        ActuatorServos(t=0.05, control=(0.1,)),
    ]
    found = codes(lint(events), "OFB506")
    assert len(found) == (1 if flagged else 0)


def test_direct_actuator_outside_offboard_is_not_judged() -> None:
    events: list[Event] = [
        VehicleStatus(t=0.0, nav_state=2, armed=True),
        ControlMode(t=0.0, velocity=True),
        ActuatorMotors(t=0.05, control=(0.2, 0.2)),
    ]
    assert not codes(lint(events), "OFB506")


# -- MAVLink to rovers ------------------------------------------------------------------------


def attitude_target(t: float, mask: int, q: tuple[float, float, float, float]) -> Event:
    return SetAttitudeTarget(t=t, type_mask=mask, q=q, thrust=0.4)


def yaw_quat(yaw: float) -> tuple[float, float, float, float]:
    return (math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2))


def tilted_quat(roll: float) -> tuple[float, float, float, float]:
    return (math.cos(roll / 2), math.sin(roll / 2), 0.0, 0.0)


@pytest.mark.parametrize(
    ("px4", "mask", "q", "severity"),
    [
        ("1.16", 7, yaw_quat(1.0), Severity.ERROR),
        ("1.15", 7, yaw_quat(1.0), Severity.ERROR),
        ("main", 128, yaw_quat(0.0), Severity.ERROR),
        ("1.14", 7, yaw_quat(1.0), Severity.WARNING),  # only this release takes it
        ("1.13", 7, tilted_quat(0.1), Severity.WARNING),
        ("1.14", 128, yaw_quat(0.0), Severity.ERROR),
    ],
)
def test_attitude_target_to_a_rover(
    px4: str, mask: int, q: tuple[float, float, float, float], severity: Severity | None
) -> None:
    found = codes(lint([attitude_target(0.0, mask, q)], px4=px4), "OFB507")
    assert [f.severity for f in found] == ([] if severity is None else [severity])


def local(mask: int, **kw: Any) -> Event:
    return SetPositionTargetLocal(t=0.0, type_mask=mask, coordinate_frame=1, **kw)


@pytest.mark.parametrize(
    ("vehicle", "event", "keys"),
    [
        ("rover-differential", local(VELOCITY_ONLY, velocity=(1.0, 0.0, 0.0)), []),
        ("rover-differential", local(VELOCITY_ONLY & ~1024, velocity=(1, 0, 0)), ["yaw"]),
        ("rover-ackermann", local(VELOCITY_ONLY & ~2048, velocity=(1, 0, 0)), ["yaw_rate"]),
        ("rover-mecanum", local(VELOCITY_ONLY & ~3072, velocity=(1, 0, 0)), []),
        ("rover-mecanum", local(VELOCITY_ONLY, velocity=(1.0, 0.0, 0.5)), ["vz"]),
        ("rover-mecanum", local(0x0DF8, position=(5.0, 0.0, -2.0)), ["z"]),
        ("rover-mecanum", local(0x0DF8, position=(5.0, 0.0, 0.0)), []),
        ("rover-mecanum", local(0x0C00, acceleration=(0.5, 0.0, 0.0)), ["afx"]),
        (
            "rover-mecanum",
            SetPositionTargetGlobal(t=0.0, type_mask=0x0C07, velocity=(1, 0, 0.3)),
            ["vz"],
        ),
    ],
)
def test_rover_fields_ignored(vehicle: str, event: Event, keys: list[str]) -> None:
    found = codes(lint([event], vehicle=vehicle), "OFB508")
    assert len(found) == len(keys)
    for key, finding in zip(keys, found, strict=True):
        assert key in finding.message
        assert finding.severity is Severity.WARNING


def test_rover_fields_rule_follows_the_current_page_only() -> None:
    event = local(VELOCITY_ONLY & ~1024, velocity=(1, 0, 0))
    assert not codes(lint([event], px4="1.14"), "OFB508")


def velocity_stream(start: float, count: int) -> list[Event]:
    return [
        SetPositionTargetLocal(
            t=round(start + 0.1 * i, 3),
            type_mask=VELOCITY_ONLY,
            coordinate_frame=1,
            velocity=(1.0, 0.0, 0.0),
        )
        for i in range(count)
    ]


def fwdextsp(t: float, value: float) -> Parameter:
    return Parameter(t=t, name="MAV_FWDEXTSP", value=value)


def test_setpoints_while_not_forwarded() -> None:
    events = [fwdextsp(0.0, 0.0), *velocity_stream(0.1, 10)]
    (finding,) = codes(lint(events), "OFB509")
    assert finding.time_s == pytest.approx(0.1) and finding.end_s == pytest.approx(1.0)
    assert not codes(lint([fwdextsp(0.0, 1.0), *velocity_stream(0.1, 10)]), "OFB509")


def test_setpoints_before_the_parameter_are_judged_by_it() -> None:
    events = [*velocity_stream(0.0, 5), fwdextsp(0.45, 0.0), *velocity_stream(0.5, 5)]
    (finding,) = codes(lint(events), "OFB509")
    assert finding.time_s == pytest.approx(0.0) and finding.end_s == pytest.approx(0.9)


def test_forwarding_unknown_is_not_checkable() -> None:
    found = lint(velocity_stream(0.0, 5))
    assert not codes(found, "OFB509")
    (note,) = [f for f in codes(found, "OFB002") if "OFB509" in f.message]
    assert "MAV_FWDEXTSP" in note.message


def test_forwarding_given_by_the_user() -> None:
    settings = Settings(params={"MAV_FWDEXTSP": 0.0})
    assert codes(lint(velocity_stream(0.0, 5), settings=settings), "OFB509")


def test_a_ulog_cannot_show_what_the_companion_published() -> None:
    events = drive({tr.SPEED}, flags={"velocity": True})
    logged = [replace(e, origin="vehicle") if e.kind == tr.SPEED else e for e in events]
    found = lint_events(logged, px4="1.16", vehicle="rover-differential", fmt="ulog")
    assert not codes(found, "OFB502")
    notes = [f.message for f in codes(found, "OFB002")]
    assert any("OFB502" in n and "ULog" in n for n in notes)
