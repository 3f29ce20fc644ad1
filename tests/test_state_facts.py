"""The per-event facts every check reads: the keep-alive (``VehicleState``), in offboard and
flying (``CheckContext``: the recorded mode, else the gate model's prediction)."""

from __future__ import annotations

from fuzzoff.config import Settings
from fuzzoff.engine import VehicleRun
from fuzzoff.events import (
    ControlMode,
    Dropout,
    LegacyControlMode,
    SetAttitudeTarget,
    SetPositionTargetLocal,
    TrajectorySetpoint,
    VehicleStatus,
)
from fuzzoff.profiles import Profile
from fuzzoff.recording import RecordingInfo
from fuzzoff.state import VehicleState
from tests.gate.streams import arm, stream, switch_offboard


def test_keepalive_is_an_ocm_or_a_mavlink_setpoint_for_this_vehicle() -> None:
    state = VehicleState(own_system=1)
    for event in (
        ControlMode(t=0.0, position=True),
        LegacyControlMode(t=0.0),
        SetPositionTargetLocal(t=0.0, target_system=1),
        SetAttitudeTarget(t=0.0, target_system=0),  # broadcast
    ):
        state.update(event)
        assert state.keepalive is event
    for other in (
        SetPositionTargetLocal(t=0.0, target_system=2),  # another vehicle's
        TrajectorySetpoint(t=0.0),
        VehicleStatus(t=0.0, nav_state=14),
        Dropout(t=0.0),
    ):
        state.update(other)
        assert state.keepalive is None
    ros = VehicleState(own_system=None)  # a ROS namespace: any target counts
    sp = SetPositionTargetLocal(t=0.0, target_system=7)
    ros.update(sp)
    assert ros.keepalive is sp


def _run(*kinds: str) -> VehicleRun:
    info = RecordingInfo(path="flight", format="test", kinds=set(kinds))
    return VehicleRun("1", Profile(px4="1.15"), Settings(), info, None)


def test_flying_follows_the_recorded_mode_and_arming() -> None:
    run = _run("vehicle_status", "offboard_control_mode")
    ctx = run.ctx
    run.feed(VehicleStatus(t=0.0, nav_state=14))
    assert ctx.in_offboard and ctx.flying  # arming unknown: not known to be disarmed
    run.feed(VehicleStatus(t=1.0, armed=False))
    assert ctx.in_offboard and not ctx.flying
    run.feed(VehicleStatus(t=2.0, armed=True))
    assert ctx.flying and ctx.offboard_since == 0.0
    assert ctx.state.mode_source == "recorded"
    run.feed(VehicleStatus(t=3.0, nav_state=2))
    assert not ctx.in_offboard and not ctx.flying and ctx.offboard_since is None


def test_flying_follows_the_gate_where_no_mode_is_recorded() -> None:
    """No recorded mode: the checks read the gate model's prediction itself (the switch and
    the arm accepted, the loss failsafe), not the recording's state."""
    run = _run("offboard_control_mode", "command")
    ctx = run.ctx
    for event in (*stream(0.0, 0.3), switch_offboard(0.31), *stream(0.4, 1.0)):
        run.feed(event)
    assert ctx.in_offboard and ctx.flying and ctx.offboard_since == 0.31
    assert not ctx.state.recorded_offboard and ctx.state.mode_source != "recorded"
    run.feed(arm(1.05))
    assert ctx.flying and ctx.offboard_since == 0.31
    run.feed(Dropout(t=4.0))  # the stream stopped at 1.0 s: lost, then the failsafe
    assert run.gate.nav_state != 14
    assert not ctx.in_offboard and not ctx.flying and ctx.offboard_since is None
