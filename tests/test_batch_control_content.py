"""The control-mode and content checks' ``on_batch`` (OFB301-OFB305, OFB401-OFB408) against one
message at a time, on generated streams built to reach their fast paths and the cases next to
them: every OCM flag set (empty included), NaN patterns per component (a fresh NaN object per
message, as readers make them), logged and sent copies, MAVLink setpoints PX4 takes or drops,
mode, arming, estimate validity and offboard requests between runs. Both the findings and the
checks' own state at the end must be the same."""

from __future__ import annotations

import math
from typing import Any

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from fuzzoff.checks import content, control_mode
from fuzzoff.checks._external import Episodes
from fuzzoff.checks.base import Check
from fuzzoff.config import Settings
from fuzzoff.engine import VehicleRun
from fuzzoff.events import (
    MAV_CMD_DO_SET_MODE,
    ActuatorMotors,
    ActuatorServos,
    AttitudeSetpoint,
    Command,
    CommandAck,
    ControlMode,
    Event,
    FailsafeFlags,
    RatesSetpoint,
    SetAttitudeTarget,
    SetPositionTargetLocal,
    ThrustSetpoint,
    TorqueSetpoint,
    TrajectorySetpoint,
    VehicleStatus,
)
from fuzzoff.profiles import Profile
from fuzzoff.recording import RecordingInfo
from tests.helpers import fresh, in_lint_order

NAN = math.nan
VALUES: list[float] = [0.0, 1.0, -0.5, 2.0, NAN, NAN, math.inf]
FLAGS = ("position", "velocity", "acceleration", "attitude", "body_rate", "thrust_and_torque")
MODULES = (content.__name__, control_mode.__name__)


value = st.sampled_from(VALUES)
vec3 = st.tuples(value, value, value)


@st.composite
def template(draw: st.DrawFn) -> dict[str, Any]:
    """One message's content, as a dict for ``build``."""
    return {
        "cls": draw(
            st.sampled_from(
                [
                    ControlMode,
                    ControlMode,
                    TrajectorySetpoint,
                    TrajectorySetpoint,
                    AttitudeSetpoint,
                    RatesSetpoint,
                    ThrustSetpoint,
                    TorqueSetpoint,
                    ActuatorMotors,
                    ActuatorServos,
                    SetPositionTargetLocal,
                    SetAttitudeTarget,
                ]
            )
        ),
        "origin": draw(st.sampled_from(["sent", "sent", "vehicle"])),
        "flags": draw(st.sets(st.sampled_from(FLAGS), max_size=2)),
        "target": draw(st.sampled_from([(1, 1), (1, 1), (0, 0), (1, 7)])),
        "mask": draw(st.sampled_from([3576, 0b110111000, 0, 4095, 128, 7])),
        "a": draw(vec3),
        "b": draw(vec3),
        "c": draw(vec3),
        "s": draw(value),
        "q": draw(st.sampled_from([None, (1.0, 0.0, 0.0, 0.0), (0.5, 0.5, 0.5, 0.5)])),
    }


def build(tpl: dict[str, Any], t: float) -> Event:
    cls = tpl["cls"]
    common: dict[str, Any] = {"t": t, "vehicle": "1", "origin": tpl["origin"]}
    a, b, c = (tuple(map(fresh, tpl[k])) for k in "abc")
    s = fresh(tpl["s"])
    q = (*b, s) if tpl["q"] is None else tuple(map(fresh, tpl["q"]))
    if cls is ControlMode:
        return ControlMode(**common, **{flag: True for flag in tpl["flags"]})
    if cls is TrajectorySetpoint:
        return cls(**common, position=a, velocity=b, acceleration=c, yaw=s)
    if cls is AttitudeSetpoint:
        return cls(**common, q_d=q, thrust_body=a)
    if cls is RatesSetpoint:
        return cls(**common, roll=s, pitch=fresh(0.1), yaw=fresh(0.2), thrust_body=a)
    if cls in (ThrustSetpoint, TorqueSetpoint):
        return cls(**common, xyz=a)
    if cls in (ActuatorMotors, ActuatorServos):
        return cls(**common, control=(*a, *b))
    mav = {"target_system": tpl["target"][0], "target_component": tpl["target"][1]}
    if cls is SetPositionTargetLocal:
        return cls(**common, **mav, type_mask=tpl["mask"], position=a, velocity=b)
    return SetAttitudeTarget(**common, **mav, type_mask=tpl["mask"], q=q, thrust=s)


def between(kind: str, t: float) -> list[Event]:
    """What may come between two runs of stream messages."""
    if kind == "offboard":
        return [VehicleStatus(t=t, vehicle="1", nav_state=14, armed=True)]
    if kind == "manual":
        return [VehicleStatus(t=t, vehicle="1", nav_state=2, armed=True)]
    if kind == "disarmed":
        return [VehicleStatus(t=t, vehicle="1", nav_state=14, armed=False)]
    if kind in ("valid", "invalid"):
        ok = kind == "valid"
        return [
            FailsafeFlags(
                t=t,
                vehicle="1",
                local_position_valid=ok,
                local_velocity_valid=ok,
                attitude_valid=ok,
                angular_velocity_valid=ok,
            )
        ]
    if kind == "request":
        params = (1.0, 6.0, 0.0, 0.0, 0.0, 0.0, 0.0)
        return [
            Command(t=t, vehicle="1", command=MAV_CMD_DO_SET_MODE, params=params),
            CommandAck(t=round(t + 0.001, 6), vehicle="1", command=MAV_CMD_DO_SET_MODE, result=0),
        ]
    return []


@st.composite
def streams(draw: st.DrawFn) -> list[Event]:
    """Runs of one to three alternating templates at one rate, with mode, arming, estimate or
    request events between some runs."""
    events: list[Event] = []
    t = 0.0
    if draw(st.booleans()):
        events.extend(between("offboard", t))
    for _ in range(draw(st.integers(1, 6))):
        kinds = draw(st.lists(template(), min_size=1, max_size=3))
        count = draw(st.sampled_from([1, 2, 5, 60, 400]))
        dt = draw(st.sampled_from([0.02, 0.02, 0.3]))
        for i in range(count):
            t = round(t + dt, 6)
            events.append(build(kinds[i % len(kinds)], t))
        kind = draw(
            st.sampled_from(
                ["none", "none", "offboard", "manual", "disarmed", "valid", "invalid", "request"]
            )
        )
        t = round(t + 0.01, 6)
        events.extend(between(kind, t))
    return events


def state_of(check: Check) -> dict[str, Any]:
    """The check's own attributes (not its caches), episodes as their open runs."""
    out: dict[str, Any] = {}
    for name, attr in vars(check).items():
        if name == "ctx" or name.startswith("_"):
            continue
        out[name] = dict(attr.open) if isinstance(attr, Episodes) else attr
    return out


def outcome(events: list[Event], profile: Profile, batching: bool) -> tuple[Any, Any]:
    kinds = {e.kind for e in events}
    info = RecordingInfo("stream", "ulog", kinds=kinds | {"vehicle_status", "failsafe_flags"})
    run = VehicleRun("1", profile, Settings(), info, None, batching=batching)
    for event in events:
        run.feed(event)
    mine = [c for c in run.checks if type(c).__module__ in MODULES]
    findings = in_lint_order(run.finish(events[-1].t if events else 0.0))
    states = {type(c).__name__: state_of(c) for c in mine}
    return findings, states


@settings(max_examples=200, deadline=None, suppress_health_check=list(HealthCheck))
@given(
    events=streams(),
    px4=st.sampled_from(["1.14", "1.15", "main"]),
    vehicle=st.sampled_from(["mc", "mc", "fw"]),
)
def test_runs_report_and_leave_what_single_messages_do(
    events: list[Event], px4: str, vehicle: str
) -> None:
    profile = Profile(px4=px4, vehicle=vehicle, px4_detected=True, vehicle_detected=True)
    single = outcome(events, profile, batching=False)
    runs = outcome(events, profile, batching=True)
    assert runs[0] == single[0]
    assert runs[1] == single[1]


def test_the_checks_take_runs() -> None:
    """The comparison above only means something if these checks do take runs."""
    profile = Profile(px4="1.15", vehicle="mc", px4_detected=True, vehicle_detected=True)
    info = RecordingInfo("x", "mcap", kinds={"offboard_control_mode", "trajectory_setpoint"})
    run = VehicleRun("1", profile, Settings(), info, None)
    batched = {type(c).__name__ for c in run.batched}
    expected = {"ControlModeEmpty", "SetpointNotDeclared", "DeclaredSetpointMissing"}
    expected |= {"ControlModeChanged", "RequiredEstimateMissing", "TrajectoryContent"}
    expected |= {"QuaternionNotUnit", "NormalizedOutOfRange", "ActuatorNanDisarms"}
    expected |= {"RatesIncomplete"}
    assert expected <= batched
