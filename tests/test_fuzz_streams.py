"""The generated streams: what the strategies draw is what a recording of it can hold and what
a real PX4 can be sent."""

from __future__ import annotations

import json
import math
from dataclasses import replace
from pathlib import Path

from hypothesis import given, settings
from hypothesis import strategies as st

from fuzzoff.events import (
    Command,
    CommandAck,
    Event,
    MavlinkTarget,
    RoverSteeringSetpoint,
    SetPositionTargetGlobal,
    SetPositionTargetLocal,
)
from fuzzoff.findings import Finding
from fuzzoff.fuzz import strategies as fs
from fuzzoff.fuzz.invariants import invariant_violations
from fuzzoff.fuzz.mutate import outcome
from fuzzoff.fuzz.reproducers import save
from fuzzoff.fuzz.scenario import AUTOPILOT, COMPANION, Scenario, run
from fuzzoff.fuzz.streams import commands, scenarios, settle


@settings(max_examples=30, database=None, deadline=None, derandomize=True)
@given(scenarios(px4="1.17", vehicle="rover-ackermann", transport="ros2"))
def test_a_1_17_rover_stream_sends_only_what_its_messages_carry(scenario: Scenario) -> None:
    """1.17 dropped ``RoverSteeringSetpoint.normalized_speed_diff``: a generated stream that
    set it could not be written (its MCAP read back NaN, and the round trip of seed 3 failed)."""
    for e in scenario.events:
        if isinstance(e, RoverSteeringSetpoint):
            assert math.isnan(e.normalized_speed_diff)


def _as_before(e: Event) -> Event:
    """``e`` as the generator addressed it before: commands and MAVLink setpoints broadcast
    (target 0), the companion sending as system 1, the autopilot's acks back to it. Its
    commands named no MAVLink message: a broadcast COMMAND_LONG as recorded is one PX4 up to 1.17
    does not take (OFB204, tests/test_command_target.py), which the generator never meant."""
    if isinstance(e, Command) and e.origin == "sent":
        e = replace(e, message=None)
    if isinstance(e, Command | MavlinkTarget) and e.origin == "sent":
        e = replace(e, target_system=0, target_component=0)
        if e.source_system == COMPANION[0]:
            e = replace(e, source_system=1, source_component=191)
    elif isinstance(e, CommandAck) and (e.target_system, e.target_component) == COMPANION:
        e = replace(e, target_system=1, target_component=191)
    return e


def _keys(findings: list[Finding]) -> list[tuple[str, str, str, float | None]]:
    return [(f.code, f.severity.label, f.vehicle, f.time_s) for f in findings]


@settings(max_examples=40, database=None, deadline=None, derandomize=True)
@given(st.sampled_from(["mavlink", "ros2"]).flatmap(lambda t: scenarios(transport=t)))
def test_addressing_the_vehicle_changes_nothing_the_properties_see(scenario: Scenario) -> None:
    """The streams now address the vehicle (1/1) from the companion's own system id (245),
    as a real PX4 needs. The gate model and the rules see the same stream either way: the same
    hazards and findings as the broadcast stream sent as system 1, so no finding is hidden."""
    before = replace(scenario, events=tuple(_as_before(e) for e in scenario.events))
    assert before != scenario or not any(isinstance(e, Command) for e in scenario.events)
    assert outcome(before) == outcome(scenario)
    assert _keys(run(before)) == _keys(run(scenario))
    assert invariant_violations(before) == invariant_violations(scenario)


def test_a_mavlink_reproducer_addresses_px4_from_the_companions_own_system(
    tmp_path: Path,
) -> None:
    """What PX4 receives from a reproducer tlog: commands and setpoints to system 1, component
    1, from system 245 (an onboard computer), never broadcast and never as the autopilot."""
    from pymavlink import mavutil

    events: list[Event] = [
        SetPositionTargetLocal(
            t=round(0.1 * i, 4),
            vehicle="1",
            type_mask=3576,
            target_system=AUTOPILOT[0],
            target_component=AUTOPILOT[1],
            source_system=COMPANION[0],
            source_component=COMPANION[1],
            transport="mavlink",
        )
        for i in range(15)
    ]
    plan = fs.CommandPlan(arm=1.2, switch=1.0, leave=None, disarm=None)
    events = settle([*events, *commands(plan, "mavlink")])
    spec = json.loads(
        save(
            "explained", Scenario("1.15", "mc", "mavlink", tuple(events)), [], tmp_path
        ).read_text()
    )
    log = mavutil.mavlink_connection(str(tmp_path / spec["recording"]), notimestamps=False)
    sent = []
    while (msg := log.recv_msg()) is not None:
        if msg.get_type() in ("COMMAND_LONG", "SET_POSITION_TARGET_LOCAL_NED"):
            sent.append(
                (
                    msg.get_srcSystem(),
                    msg.get_srcComponent(),
                    msg.target_system,
                    msg.target_component,
                )
            )
    log.close()
    assert len(sent) == 17 and set(sent) == {(245, 191, 1, 1)}
    assert spec["setup"]["companion"] == {"system": 245, "component": 191}
    assert spec["setup"]["autopilot"] == {"system": 1, "component": 1}


def test_the_generator_holds_a_stream_long_enough_for_what_only_time_shows() -> None:
    """Issue 33 item 5: OFB107 needs 10 s of one moving command; the generator's streams
    lasted at most 6 s (plus stalls) and never reached it."""
    from hypothesis import HealthCheck, Phase, find

    quick = settings(
        max_examples=400,
        database=None,
        deadline=None,
        derandomize=True,
        phases=[Phase.generate],
        suppress_health_check=list(HealthCheck),
    )
    times = find(fs.keepalive_times(1.0), lambda ts: len(ts) > 1 and ts[-1] >= 10.0, settings=quick)
    assert times[-1] >= 10.0
    held = find(
        scenarios(transport="ros2", vehicle="mc"),
        lambda s: any(f.code == "OFB107" for f in run(s)),
        settings=quick,
    )
    assert any(f.code == "OFB107" for f in run(held))


@settings(max_examples=25, database=None, deadline=None, derandomize=True)
@given(st.sampled_from(["fw", "vtol"]).flatmap(lambda v: scenarios(vehicle=v, transport="mavlink")))
def test_a_fixed_wing_stream_sends_the_fixed_wing_setpoint_types(scenario: Scenario) -> None:
    """Issue 33 item 5: per-vehicle setpoints; a fixed-wing program's position targets carry
    the FW types (glide, takeoff, land, loiter) or a NaN altitude, and lint judges them."""
    targets = [
        e
        for e in scenario.events
        if isinstance(e, SetPositionTargetLocal | SetPositionTargetGlobal)
    ]
    assert all(e.type_mask in fs.FW_TYPE_MASKS for e in targets)
    run(scenario)


@settings(max_examples=25, database=None, deadline=None, derandomize=True)
@given(scenarios(vehicle="rover-ackermann", transport="mavlink"))
def test_a_rover_stream_stays_on_the_ground(scenario: Scenario) -> None:
    for e in scenario.events:
        if isinstance(e, SetPositionTargetLocal):
            assert e.position[2] == 0.0 or math.isnan(e.position[2])
            assert e.velocity[2] == 0.0
