"""The stream checks' ``on_batch`` (OFB101-OFB106, OFB203) against one message at a time, on
generated streams built to reach their fast paths and the cases next to them: gaps around the
budget, the stale threshold and the loss timeout, times that step back, keep-alives as sent and
as logged, MAVLink setpoints for this vehicle, for all and for another, sender stamps that are
zero, go back or lag, setpoints of several kinds, and mode, arming, dropouts and offboard
requests between runs. Both the findings and the checks' own state at the end must be the same.
"""

from __future__ import annotations

from typing import Any

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from fuzzoff.checks import loss, outside_offboard, stale, stream, timestamps
from fuzzoff.checks.base import Check
from fuzzoff.config import Settings
from fuzzoff.engine import VehicleRun
from fuzzoff.events import (
    MAV_CMD_DO_SET_MODE,
    AttitudeSetpoint,
    Command,
    ControlMode,
    Dropout,
    Event,
    SetPositionTargetLocal,
    ThrustSetpoint,
    TrajectorySetpoint,
    VehicleStatus,
)
from fuzzoff.profiles import Profile
from fuzzoff.recording import RecordingInfo
from tests.helpers import in_lint_order

MODULES = tuple(m.__name__ for m in (loss, outside_offboard, stale, stream, timestamps))
STAMPS = ("good", "good", "good", "zero", "lag", "back", "none")


@st.composite
def template(draw: st.DrawFn) -> dict[str, Any]:
    """One message's kind and header, as a dict for ``build``."""
    return {
        "cls": draw(
            st.sampled_from(
                [
                    ControlMode,
                    ControlMode,
                    ControlMode,
                    TrajectorySetpoint,
                    TrajectorySetpoint,
                    AttitudeSetpoint,
                    ThrustSetpoint,
                    SetPositionTargetLocal,
                ]
            )
        ),
        "origin": draw(st.sampled_from(["sent", "sent", "sent", "vehicle"])),
        "flag": draw(st.sampled_from(["position", "position", "attitude", None])),
        "target": draw(st.sampled_from([1, 1, 0, 7])),
        "stamp": draw(st.sampled_from(STAMPS)),
    }


def build(tpl: dict[str, Any], t: float, i: int) -> Event:
    stamp = {
        "good": round(t * 1e6) + 5000,
        "zero": 0,
        "lag": max(1, round(t * 1e6) - 1_500_000 * (i % 2)),
        "back": max(1, round(t * 1e6) - 30_000 * i),
        "none": None,
    }[tpl["stamp"]]
    common: dict[str, Any] = {
        "t": t,
        "vehicle": "1",
        "origin": tpl["origin"],
        "sender_time_us": stamp,
    }
    cls = tpl["cls"]
    if cls is ControlMode:
        flag = tpl["flag"]
        return ControlMode(**common, **({flag: True} if flag else {}))
    if cls is SetPositionTargetLocal:
        return cls(**common, target_system=tpl["target"], target_component=1)
    return cls(**common)  # type: ignore[no-any-return]


def between(kind: str, t: float) -> list[Event]:
    """What may come between two runs of stream messages."""
    if kind == "offboard":
        return [VehicleStatus(t=t, vehicle="1", nav_state=14, armed=True)]
    if kind == "manual":
        return [VehicleStatus(t=t, vehicle="1", nav_state=2, armed=True)]
    if kind == "offboard-arming-unknown":  # the gate model does not take it as armed
        return [VehicleStatus(t=t, vehicle="1", nav_state=14)]
    if kind == "disarmed":
        return [VehicleStatus(t=t, vehicle="1", nav_state=14, armed=False)]
    if kind == "dropout":
        return [Dropout(t=t, vehicle="1", duration_s=0.2)]
    if kind == "request":
        params = (1.0, 6.0, 0.0, 0.0, 0.0, 0.0, 0.0)
        return [Command(t=t, vehicle="1", command=MAV_CMD_DO_SET_MODE, params=params)]
    return []


@st.composite
def streams(draw: st.DrawFn) -> list[Event]:
    """Runs of one to three alternating templates at one rate (now and then a longer gap, a
    step back in time or one message out of order), with mode, arming, dropouts, requests or
    a pause between some runs."""
    events: list[Event] = []
    t = 0.0
    events.extend(
        between(draw(st.sampled_from(["none", "offboard", "offboard-arming-unknown"])), t)
    )
    for _ in range(draw(st.integers(1, 8))):
        kinds = draw(st.lists(template(), min_size=1, max_size=3))
        count = draw(st.sampled_from([1, 2, 5, 60, 300]))
        dt = draw(st.sampled_from([0.02, 0.02, 0.02, 0.0195, 0.1, 0.45]))
        odd = draw(st.sampled_from([None, None, 0.3, 0.55, 1.2, -0.05, -0.6]))
        odd_at = draw(st.integers(0, max(0, count - 1)))
        blip = draw(st.booleans())  # the odd step moves that message alone, or all after it
        for i in range(count):
            if odd is not None and i == odd_at:
                at = round(max(0.0, t + odd), 6)
                events.append(build(kinds[i % len(kinds)], at, i))
                t = t if blip else at
                continue
            t = round(t + dt, 6)
            events.append(build(kinds[i % len(kinds)], t, i))
        kind = draw(
            st.sampled_from(
                [
                    "none",
                    "none",
                    "offboard",
                    "offboard-arming-unknown",
                    "manual",
                    "disarmed",
                    "dropout",
                    "request",
                    "pause",
                ]
            )
        )
        t = round(t + (1.5 if kind == "pause" else 0.01), 6)
        events.extend(between(kind, t))
    return events


def state_of(check: Check) -> dict[str, Any]:
    """The check's own attributes; helper objects as their attributes, and the gate verdicts
    (keyed by the identity of their command) as a list."""
    out: dict[str, Any] = {}
    for name, attr in vars(check).items():
        if name == "ctx":
            continue
        if name == "gate_verdict":
            attr = list(attr.values())
        elif isinstance(attr, stream._Histogram):
            attr = (attr.bins, attr.count, attr.worst)
        elif hasattr(attr, "__dict__") and not hasattr(attr, "__dataclass_fields__"):
            attr = {k: v for k, v in vars(attr).items() if k != "ctx"}
        out[name] = attr
    return out


def outcome(
    events: list[Event], profile: Profile, fmt: str, lint: Settings, batching: bool
) -> tuple[Any, Any]:
    kinds = {e.kind for e in events} | {"vehicle_status"}
    sampled = {"control_mode": 0.1} if fmt == "ulog" else {}
    info = RecordingInfo("stream", fmt, kinds=kinds, sampled_intervals=sampled)
    run = VehicleRun("1", profile, lint, info, None, batching=batching)
    for event in events:
        run.feed(event)
    mine = [c for c in run.checks if type(c).__module__ in MODULES]
    run._flush()  # the last run, to compare the states before ``finish`` closes stretches
    before = {type(c).__name__: state_of(c) for c in mine}
    findings = in_lint_order(run.finish(max((e.t for e in events), default=0.0)))
    findings = [f for f in findings if f.code.startswith(("OFB10", "OFB203"))]
    return findings, (before, {type(c).__name__: state_of(c) for c in mine})


@settings(max_examples=300, deadline=None, suppress_health_check=list(HealthCheck))
@given(
    events=streams(),
    px4=st.sampled_from(["1.13", "1.14", "1.15", "main", "legacy"]),
    fmt=st.sampled_from(["mcap", "mcap", "tlog", "ulog"]),
    budget=st.sampled_from([0.5, 0.5, 2.0]),
)
def test_runs_report_and_leave_what_single_messages_do(
    events: list[Event], px4: str, fmt: str, budget: float
) -> None:
    profile = Profile(px4=px4, vehicle="mc", px4_detected=True, vehicle_detected=True)
    lint = Settings(options={"OFB105": {"budget_s": budget}})
    single = outcome(events, profile, fmt, lint, batching=False)
    runs = outcome(events, profile, fmt, lint, batching=True)
    assert runs[0] == single[0]
    for phase, (as_runs, alone) in enumerate(zip(runs[1], single[1], strict=True)):
        for name, attrs in alone.items():
            for attr, value in attrs.items():
                assert as_runs[name][attr] == value, (phase, name, attr)


@st.composite
def served_streams(draw: st.DrawFn) -> list[Event]:
    """OFB104's cases in offboard: OffboardControlMode (position) and TrajectorySetpoint as
    sent, in segments where both come, only one of them comes, or one setpoint comes out of
    time order; now and then the mode changes between segments."""
    events: list[Event] = [VehicleStatus(t=0.0, vehicle="1", nav_state=14, armed=True)]
    t = 0.0
    for _ in range(draw(st.integers(1, 6))):
        pattern = draw(
            st.sampled_from(["both", "both", "ocm", "setpoint", "late", "early", "sparse"])
        )
        dt = 0.12 if pattern == "sparse" else draw(st.sampled_from([0.02, 0.1, 0.3]))
        for i in range(draw(st.sampled_from([3, 20, 60]))):
            t = round(t + dt, 6)
            setpoint_t = t
            if pattern in ("late", "early") and i == 2:
                setpoint_t = round(max(0.0, t + (0.6 if pattern == "late" else -0.6)), 6)
            if pattern == "sparse":  # every 0.48 s, stamped a little before the OCM ahead of it
                setpoint_t = round(t - 0.05, 6) if i % 4 == 0 else -1.0
            if pattern != "setpoint":
                events.append(ControlMode(t=t, vehicle="1", position=True, sender_time_us=1))
            if pattern != "ocm" and setpoint_t >= 0.0:
                events.append(TrajectorySetpoint(t=setpoint_t, vehicle="1"))
        kind = draw(st.sampled_from(["none", "none", "offboard", "manual", "pause"]))
        t = round(t + (0.7 if kind == "pause" else 0.01), 6)
        events.extend(between(kind, t))
    return events


@settings(max_examples=200, deadline=None, suppress_health_check=list(HealthCheck))
@given(events=served_streams())
def test_runs_judge_stale_setpoints_as_single_messages_do(events: list[Event]) -> None:
    profile = Profile(px4="1.15", vehicle="mc", px4_detected=True, vehicle_detected=True)
    lint = Settings(options={"OFB105": {"budget_s": 2.0}})
    single = outcome(events, profile, "mcap", lint, batching=False)
    runs = outcome(events, profile, "mcap", lint, batching=True)
    assert runs == single
