"""The per-event facts ``VehicleState`` works out once for every check: keep-alive, flying."""

from __future__ import annotations

from fuzzoff.events import (
    ControlMode,
    Dropout,
    LegacyControlMode,
    SetAttitudeTarget,
    SetPositionTargetLocal,
    TrajectorySetpoint,
    VehicleStatus,
)
from fuzzoff.state import VehicleState


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


def test_flying_follows_the_recorded_mode_and_arming() -> None:
    state = VehicleState(mode_recorded=True)
    state.update(VehicleStatus(t=0.0, nav_state=14))
    assert state.in_offboard and state.flying  # arming unknown: not known to be disarmed
    state.update(VehicleStatus(t=1.0, armed=False))
    assert state.in_offboard and not state.flying
    state.update(VehicleStatus(t=2.0, armed=True))
    assert state.flying and state.offboard_since == 0.0
    state.update(VehicleStatus(t=3.0, nav_state=2))
    assert not state.in_offboard and not state.flying and state.offboard_since is None


def test_flying_follows_the_gate_where_no_mode_is_recorded() -> None:
    state = VehicleState(mode_recorded=False)
    state.set_predicted(True, 1.0)
    assert state.in_offboard and state.flying and state.offboard_since == 1.0
    state.update(VehicleStatus(t=2.0, armed=False))
    assert state.in_offboard and not state.flying
    state.set_predicted(False, 3.0)
    assert not state.in_offboard and not state.flying
