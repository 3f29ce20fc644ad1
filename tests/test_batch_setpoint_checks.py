"""The setpoint checks' ``on_batch`` (OFB107, OFB404, OFB601-607, OFB609) against one message at a
time, on generated streams built to reach their fast paths and the cases next to them: frozen and
moving content, NaN (a fresh object per message, as readers make them), signed zeros, ints
where floats are usual, gaps, several kinds and senders, wrong targets, mode changes."""

from __future__ import annotations

import math
from typing import Any

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from fuzzoff import releases
from fuzzoff.config import Settings
from fuzzoff.engine import run_events
from fuzzoff.events import (
    AttitudeSetpoint,
    ControlMode,
    Event,
    Parameter,
    RatesSetpoint,
    SetAttitudeTarget,
    SetPositionTargetGlobal,
    SetPositionTargetLocal,
    ThrustSetpoint,
    TrajectorySetpoint,
    VehicleStatus,
)
from fuzzoff.profiles import Profile
from fuzzoff.recording import RecordingInfo
from tests.helpers import fresh

CODES = ("OFB107", "OFB404", "OFB601", "OFB602", "OFB603", "OFB604", "OFB605", "OFB606")
CODES += ("OFB607", "OFB609")

NAN = math.nan
VALUES: list[Any] = [0.0, -0.0, 1.0, -3.0, 7.5, NAN, math.inf, 0, 2]
"""Values a field takes: equal-but-not-alike pairs (0.0/-0.0/0, 2/2.0...) and NaN included."""


def vec(values: tuple[Any, ...], step: int, new: bool) -> tuple[Any, ...]:
    return tuple(v + step if step and isinstance(v, float) else fresh(v, new) for v in values)


value = st.sampled_from(VALUES)
vec3 = st.tuples(value, value, value)


@st.composite
def template(draw: st.DrawFn) -> dict[str, Any]:
    """One message's content (all kinds the checks read), as a dict for ``build``."""
    return {
        "cls": draw(
            st.sampled_from(
                [
                    SetPositionTargetLocal,
                    SetPositionTargetLocal,
                    SetPositionTargetGlobal,
                    SetAttitudeTarget,
                    TrajectorySetpoint,
                    TrajectorySetpoint,
                    AttitudeSetpoint,
                    RatesSetpoint,
                    ThrustSetpoint,
                    ControlMode,
                ]
            )
        ),
        "origin": draw(st.sampled_from(["sent", "sent", "vehicle"])),
        "transport": draw(st.sampled_from(["mavlink", "mavlink", "mavros"])),
        "target": draw(st.sampled_from([(1, 1), (1, 1), (0, 0), (2, 1), (1, 7)])),
        "mask": draw(st.sampled_from([2552, 3576, 0b110111000, 0b111000111, 0, 4095, 1024 | 448])),
        "frame": draw(st.sampled_from([1, 1, 8, 5, 7])),
        "a": draw(vec3),
        "b": draw(vec3),
        "c": draw(vec3),
        "s": draw(value),
        "new": draw(st.booleans()),
    }


def build(tpl: dict[str, Any], t: float, step: int, vehicle: str) -> Event:
    cls = tpl["cls"]
    common: dict[str, Any] = {"t": t, "vehicle": vehicle, "origin": tpl["origin"]}
    new = tpl["new"]
    a, b, c = vec(tpl["a"], step, new), vec(tpl["b"], 0, new), vec(tpl["c"], 0, new)
    s = fresh(tpl["s"], new)
    mav = {
        "target_system": tpl["target"][0],
        "target_component": tpl["target"][1],
        "type_mask": tpl["mask"],
        "transport": tpl["transport"],
    }
    if cls is SetPositionTargetLocal:
        return cls(**common, **mav, coordinate_frame=tpl["frame"], position=a, velocity=b,
                   acceleration=c, yaw=s)  # fmt: skip
    if cls is SetPositionTargetGlobal:
        return cls(**common, **mav, coordinate_frame=tpl["frame"], lat_int=step, velocity=b,
                   acceleration=c, alt=s)  # fmt: skip
    if cls is SetAttitudeTarget:
        return cls(**common, **mav, q=(*a, s), thrust=s, thrust_body=c)
    if cls is TrajectorySetpoint:
        return cls(**common, position=a, velocity=b, acceleration=c, yaw=s)
    if cls is AttitudeSetpoint:
        return cls(**common, q_d=(*b, s), thrust_body=a)
    if cls is RatesSetpoint:
        return cls(**common, roll=s, thrust_body=a)
    if cls is ThrustSetpoint:
        return cls(**common, xyz=a)
    return ControlMode(**common, position=True)


@st.composite
def streams(draw: st.DrawFn) -> list[Event]:
    """Segments of one or two alternating templates, frozen or moving, at one rate, with
    status/parameter events between some segments."""
    events: list[Event] = []
    t = 0.0
    vehicle = draw(st.sampled_from(["1", "1", ""]))
    if draw(st.booleans()):  # else the vehicle is first heard of later (or never)
        events.append(VehicleStatus(t=t, vehicle=vehicle, nav_state=14, armed=True))
    for _ in range(draw(st.integers(1, 6))):
        kinds = [draw(template())]
        second = draw(st.sampled_from(["none", "other", "values"]))
        if second == "other":
            kinds.append(draw(template()))
        elif second == "values":  # same type, mask, frame and targets: other values only
            kinds.append({**kinds[0], "a": draw(vec3), "c": draw(vec3), "s": draw(value)})
        count = draw(st.sampled_from([1, 2, 3, 40, 300]))
        dt = draw(st.sampled_from([0.02, 0.02, 0.3, 1.5]))
        moving = draw(st.booleans())
        for i in range(count):
            t = round(t + dt, 6)
            tpl = kinds[i % len(kinds)]
            events.append(build(tpl, t, i if moving else 0, vehicle))
        between = draw(st.sampled_from(["none", "none", "status", "param", "other"]))
        t = round(t + 0.01, 6)
        if between == "status":
            nav = draw(st.sampled_from([14, 2]))
            armed = draw(st.booleans())
            events.append(VehicleStatus(t=t, vehicle=vehicle, nav_state=nav, armed=armed))
        elif between == "param":
            events.append(Parameter(t=t, vehicle=vehicle, name="MAV_SYS_ID", value=1.0))
        elif between == "other":
            events.append(VehicleStatus(t=t, vehicle="2", nav_state=14, armed=True))
    return events


def findings_by_code(
    events: list[Event], options: dict[str, Any], profile: Profile, batching: bool
) -> list[Any]:
    kinds = {e.kind for e in events}
    info = RecordingInfo("stream", "tlog", kinds=kinds, vehicles=["1", "2"])
    lint = Settings(options=options)
    findings, _ = run_events(events, info, profile, lint, batching=batching)
    return [[f for f in findings if f.code == code] for code in CODES]


@settings(max_examples=300, deadline=None, suppress_health_check=list(HealthCheck))
@given(
    events=streams(),
    freeze=st.sampled_from([0.0, 0.1, 0.5, 3.0]),
    max_gap=st.sampled_from([0.3, 1.0]),
    px4=st.sampled_from(releases.names()),
    vehicle=st.sampled_from(["mc", "mc", "fw", "rover-ackermann"]),
)
def test_runs_report_what_single_messages_report(
    events: list[Event], freeze: float, max_gap: float, px4: str, vehicle: str
) -> None:
    options = {"OFB107": {"freeze_s": freeze, "max_gap_s": max_gap}}
    profile = Profile(px4=px4, vehicle=vehicle, px4_detected=True, vehicle_detected=True)
    single = findings_by_code(events, options, profile, batching=False)
    runs = findings_by_code(events, options, profile, batching=True)
    assert runs == single


def test_the_vehicle_first_heard_of_inside_a_run() -> None:
    """OFB607 holds setpoints until the vehicle's id is known; its first own message can be a
    stream message (a logged OffboardControlMode) in the middle of a run."""
    wrong = {**TEMPLATE, "target": (2, 1)}
    events = [build(wrong, round(0.02 * i, 6), 0, "1") for i in range(1, 6)]
    events.append(build({**TEMPLATE, "cls": ControlMode, "origin": "vehicle"}, 0.11, 0, "1"))
    events += [build(wrong, round(0.02 * i, 6), 0, "1") for i in range(6, 60)]
    profile = Profile(px4="1.15", vehicle="mc", px4_detected=True, vehicle_detected=True)
    single = findings_by_code(events, {}, profile, batching=False)
    runs = findings_by_code(events, {}, profile, batching=True)
    assert runs == single
    assert single[CODES.index("OFB607")]


TEMPLATE: dict[str, Any] = {
    "cls": SetPositionTargetLocal,
    "origin": "sent",
    "transport": "mavlink",
    "target": (1, 1),
    "mask": 2552,
    "frame": 1,
    "a": (1.0, 2.0, -3.0),
    "b": (0.0, 0.0, 0.0),
    "c": (0.0, 0.0, 0.0),
    "s": 0.0,
    "new": True,
}
