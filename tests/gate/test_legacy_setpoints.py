"""legacy (v1.5 - v1.10) and 1.11: what the multicopter controller flies in offboard.

Facts used (gate spec section 8, legacy note): legacy ``mc_pos_control`` consumed
``position_setpoint_triplet`` (fed by the legacy MAVLink receiver) with ``*_valid`` flags, not
``trajectory_setpoint``; its details are not modelled, so the model marks what runs as
unverified and never claims the hold that 1.13+ flies without a TrajectorySetpoint.
"""

from __future__ import annotations

import json

import pytest

from fuzzoff.events import Event, PositionSetpointTriplet
from fuzzoff.gate import GateTransition
from tests.gate.streams import (
    POSCTL,
    in_offboard,
    local_ned,
    of,
    run,
    status,
    stream,
    switch_offboard,
)
from tests.helpers import CORPORA, run_cli


def _triplet(t: float) -> PositionSetpointTriplet:
    return PositionSetpointTriplet(
        t=t, current_valid=True, current_position_valid=True, current_type=0
    )


def _controllers(px4: str, events: list[Event]) -> list[GateTransition]:
    return [
        tr for tr in of("controller", run(px4, events, t_end=2.0)) if "multicopter" in tr.message
    ]


@pytest.mark.parametrize("px4", ["legacy", "1.11"])
def test_triplet_is_the_setpoint(px4: str) -> None:
    events: list[Event] = [
        in_offboard(),
        *stream(0.0, 2.0),
        *(_triplet(k * 0.1) for k in range(20)),
    ]
    trs = _controllers(px4, events)
    assert trs, "a controller row in OFFBOARD"
    assert all("hold" not in tr.message and "no TrajectorySetpoint" not in tr.message for tr in trs)
    assert all(tr.unverified for tr in trs)
    assert "position_setpoint_triplet" in trs[-1].message


@pytest.mark.parametrize("px4", ["legacy", "1.11"])
def test_legacy_mavlink_setpoint_is_the_setpoint(px4: str) -> None:
    events: list[Event] = [
        in_offboard(),
        *(local_ned(round(k * 0.1, 3), position=(0.0, 0.0, -2.0)) for k in range(20)),
    ]
    trs = _controllers(px4, events)
    assert trs and all("hold" not in tr.message for tr in trs)
    assert "position_setpoint_triplet" in trs[-1].message and trs[-1].unverified


def test_no_setpoint_yet_is_unverified_not_a_hold() -> None:
    (tr,) = _controllers("legacy", [in_offboard(), *stream(0.0, 2.0)])
    assert tr.unverified
    assert "no offboard setpoint recorded yet" in tr.message
    assert "hold" not in tr.message


def test_an_invalid_triplet_is_not_a_setpoint() -> None:
    invalid = PositionSetpointTriplet(t=0.5, current_valid=False)
    (tr,) = _controllers("legacy", [in_offboard(), *stream(0.0, 2.0), invalid])
    assert "no offboard setpoint recorded yet" in tr.message


def test_1_13_still_holds_without_a_trajectory_setpoint() -> None:
    """Section 8 (v1.13+): no trajectory_setpoint since position control -> failsafe hold;
    a triplet does not count there."""
    events: list[Event] = [
        status(0.0, POSCTL, True, POSCTL),
        *stream(0.0, 2.0),
        switch_offboard(1.0),
        _triplet(1.5),
    ]
    (tr,) = _controllers("1.13", events)
    assert "hold" in tr.message and "no TrajectorySetpoint" in tr.message


def test_gate_command_on_the_legacy_ulog_claims_no_hold() -> None:
    """The v1.7.3 ULog (setpoint in position_setpoint_triplet): no failsafe-hold row."""
    path = CORPORA / "ulog" / "legacy_ignore_flags.ulg"
    result = run_cli(["gate", str(path), "--format", "json"])
    assert result.returncode == 0, result.stdout + result.stderr
    rows = json.loads(result.stdout)["files"][0]["vehicles"][0]["timeline"]
    ctl = [r for r in rows if r["what"] == "controller" and "multicopter" in r["message"]]
    assert ctl and not [r for r in ctl if "hold" in r["message"]]
    assert "position_setpoint_triplet" in ctl[-1]["message"]
