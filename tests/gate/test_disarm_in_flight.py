"""A disarm request in flight (issue 18; gate spec 13a).

Seen on PX4 1.15.4 and 1.18.0-alpha1 SITL (corpora/gate/px4_*_disarm_refused.ulg): a disarm
that is not forced is refused with ack 1, "Disarming denied: not landed", while the land
detector says airborne; param2 21196 forces it (acked 0 in flight on both, the vehicle falling);
on the ground it is accepted; an arm request while armed is acked ACCEPTED and changes nothing.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from fuzzoff.config import Settings
from fuzzoff.engine import lint_file
from fuzzoff.events import (
    Command,
    CommandAck,
    Event,
    LandDetected,
    SetPositionTargetLocal,
    TrajectorySetpoint,
)
from fuzzoff.formats import open_source
from fuzzoff.formats.tlog.writer import write_tlog
from fuzzoff.formats.ulog.writer import write_ulog
from tests.gate.streams import OFFBOARD, TICK, arm, in_offboard, model, of, run, status, stream

ALL_NEW = ["1.13", *TICK]


def disarm(t: float, forced: bool = False) -> Command:
    return Command(t=t, command=400, params=(0.0, 21196.0 if forced else 0.0, 0, 0, 0, 0, 0))


def _flying(landed: bool | None) -> list[Event]:
    """Armed in OFFBOARD with a stream; the land detector says ``landed`` (None: not
    recorded)."""
    events: list[Event] = [in_offboard(), *stream(0.0, 5.0)]
    if landed is not None:
        events.append(LandDetected(t=0.5, landed=landed))
    return events


@pytest.mark.parametrize("px4", ALL_NEW)
def test_disarm_while_the_land_detector_says_airborne_is_refused(px4: str) -> None:
    gate = model(px4)
    trs = run(px4, [*_flying(False), disarm(3.0)], model=gate)
    (refused,) = of("disarm_rejected", trs)
    assert "Disarming denied: not landed" in (refused.reason or "")
    assert "land detector: not landed since 0.50 s" in (refused.reason or "")
    assert of("disarmed", trs) == [] and gate.armed is True


@pytest.mark.parametrize("px4", ALL_NEW)
def test_disarm_on_the_ground_is_accepted(px4: str) -> None:
    gate = model(px4)
    run(px4, [*_flying(True), disarm(3.0)], model=gate)
    assert gate.armed is False


@pytest.mark.parametrize("px4", ALL_NEW)
def test_forced_disarm_skips_the_land_check(px4: str) -> None:
    gate = model(px4)
    trs = run(px4, [*_flying(False), disarm(3.0, forced=True)], model=gate)
    assert of("disarmed", trs) and gate.armed is False


def test_a_rover_disarms_anywhere() -> None:
    gate = model("1.16", vehicle="rover-differential")
    run("1.16", [*_flying(False), disarm(3.0)], model=gate)
    assert gate.armed is False


def _climb(t0: float, t1: float, z: float) -> list[Event]:
    return [
        TrajectorySetpoint(t=round(t0 + 0.1 * k, 3), position=(0.0, 0.0, z))
        for k in range(round((t1 - t0) / 0.1) + 1)
    ]


@pytest.mark.parametrize("px4", TICK)
def test_without_a_land_detector_a_climb_is_taken_as_a_take_off(px4: str) -> None:
    """No land detector recorded: armed in OFFBOARD with a climb setpoint for 2 s or more is a
    take-off; the reason says it is assumed."""
    events = [status(0.0, OFFBOARD, False, OFFBOARD), *stream(0.0, 8.0), arm(1.0)]
    trs = run(px4, [*events, *_climb(1.0, 8.0, -3.0), disarm(4.0)])
    (refused,) = of("disarm_rejected", trs)
    assert "assumed airborne (armed in OFFBOARD with a climb setpoint since" in refused.message


@pytest.mark.parametrize("px4", TICK)
def test_without_a_land_detector_no_take_off_means_the_ground(px4: str) -> None:
    events = [status(0.0, OFFBOARD, False, OFFBOARD), *stream(0.0, 8.0), arm(1.0)]
    trs = run(px4, [*events, *_climb(1.0, 8.0, 0.0), disarm(4.0)])
    (done,) = of("disarmed", trs)
    assert "assumed on the ground" in done.message


@pytest.mark.parametrize("px4", TICK)
def test_still_armed_past_com_disarm_prflt_has_taken_off(px4: str) -> None:
    """PX4 disarms a vehicle that does not take off within COM_DISARM_PRFLT (10 s): one still
    armed later is in the air."""
    events = [status(0.0, OFFBOARD, False, OFFBOARD), *stream(0.0, 13.0), arm(1.0)]
    trs = run(px4, [*events, disarm(12.0)])
    (refused,) = of("disarm_rejected", trs)
    assert "COM_DISARM_PRFLT" in refused.message


@pytest.mark.parametrize("px4", TICK)
def test_recorded_refusal_agrees_and_is_called_a_disarm(px4: str) -> None:
    """The recorded ack 1 agrees with the model now; before, the model accepted the disarm
    and OFB202 said 'arm acked TEMPORARILY_REJECTED'."""
    trs = run(px4, [*_flying(False), disarm(3.0), CommandAck(t=3.008, command=400, result=1)])
    assert of("disagreement", trs) == []
    accepted = run(px4, [*_flying(False), disarm(3.0), CommandAck(t=3.008, command=400, result=0)])
    (differs,) = of("disagreement", accepted)
    assert differs.message.startswith("recorded: disarm acked ACCEPTED")


@pytest.mark.parametrize("px4", TICK)
def test_arm_while_armed_is_accepted_with_no_change(px4: str) -> None:
    """After the refused disarm: PX4 1.15.4 and 1.18.0-alpha1 ack an arm request 0."""
    events = [*_flying(False), disarm(3.0), arm(4.0), CommandAck(t=4.008, command=400, result=0)]
    trs = run(px4, events)
    assert of("disagreement", trs) == [] and of("arm_rejected", trs) == []
    assert any("already armed" in tr.message for tr in trs)


def _events_of(path: Path) -> list[Event]:
    source = open_source(path)
    source.open()
    try:
        source.probe()
        return list(source.events())
    finally:
        source.close()


def test_tlog_extended_sys_state_is_the_land_detector(tmp_path: Path) -> None:
    """EXTENDED_SYS_STATE.landed_state (written by pymavlink): ON_GROUND landed, IN_AIR not."""
    events: list[Event] = [
        in_offboard(),
        LandDetected(t=0.2, landed=True),
        LandDetected(t=1.0, landed=False),
        *[
            SetPositionTargetLocal(
                t=round(0.1 * k, 3), type_mask=0b110111111000, target_system=1, target_component=1
            )
            for k in range(40)
        ],
        disarm(3.0),
        CommandAck(t=3.01, command=400, result=1),
    ]
    path = write_tlog(tmp_path / "disarm.tlog", sorted(events, key=lambda e: e.t))
    landed = [e.landed for e in _events_of(path) if isinstance(e, LandDetected)]
    assert landed == [True, False]
    report = lint_file(path, Settings(px4="1.15", vehicle="mc"))
    assert not [f for f in report.findings if f.code == "OFB202"]


def test_ulog_vehicle_land_detected(tmp_path: Path) -> None:
    events: list[Event] = [LandDetected(t=0.5, landed=True), LandDetected(t=2.0, landed=False)]
    path = write_ulog(tmp_path / "land.ulg", events, px4_version="1.15.4", vehicle_type="mc")
    assert [e.landed for e in _events_of(path) if isinstance(e, LandDetected)] == [True, False]
