"""The land detector from ROS recordings (issue 29 item 7): ROS 2 ``/fmu/out/vehicle_land_detected``
and MAVROS ``extended_state`` (ROS 1 and ROS 2) give the gate model the verdict a ULog or a tlog
gives it, so a disarm request is judged from a bag as PX4 judged it (gate spec 13a), not from
take-off evidence alone."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path
from typing import Any

import pytest
from rosbags.typesys import Stores, get_typestore

from fuzzoff import events as ev
from fuzzoff.formats import open_source
from fuzzoff.formats.mavros.mavros_msgs import mavros_typedefs, msg_text
from fuzzoff.formats.mcap.writer import write_mcap
from fuzzoff.formats.ros2msgs.messages import RawMessage
from fuzzoff.formats.rosbag1.writer import write_rosbag1
from fuzzoff.formats.rosbag2.writer import write_rosbag2
from tests.helpers import run_cli

GATE = Path(__file__).resolve().parents[2] / "corpora" / "gate"
LANDED_DISARM = GATE / "landed_disarm_ros2.mcap"
SITL_ULOGS = sorted(GATE.glob("px4_*_disarm_in_flight.ulg"))
SITL_TLOGS = sorted(GATE.glob("px4_*_disarm_in_flight.onboard.tlog"))

ROS2_SIDE = (
    ev.ControlMode,
    ev.TrajectorySetpoint,
    ev.Command,
    ev.CommandAck,
    ev.VehicleStatus,
    ev.LandDetected,
)
"""What a ROS 2 client of these flights records: its stream and commands, PX4's answers."""


def _disarms(path: Path, *args: str) -> list[dict[str, Any]]:
    result = run_cli(["gate", str(path), "--format", "json", "--no-controllers", *args])
    (vehicle,) = json.loads(result.stdout)["files"][0]["vehicles"]
    return [r for r in vehicle["timeline"] if r["what"] in ("disarmed", "disarm_rejected")]


def _events(path: Path) -> list[ev.Event]:
    with open_source(path) as source:
        return list(source.events())


def _as_ros2(events: list[ev.Event]) -> list[ev.Event]:
    """A ULog's topics as the ROS 2 client's bag holds them (its stream and commands sent)."""
    out: list[ev.Event] = []
    for e in events:
        if isinstance(e, (ev.ControlMode, ev.TrajectorySetpoint, ev.Command)):
            e = dataclasses.replace(e, origin="sent")
        if isinstance(e, ROS2_SIDE):
            out.append(e)
    return out


def test_a_ros2_bag_disarm_is_judged_by_the_land_detector(tmp_path: Path) -> None:
    args = ("--px4", "1.16", "--vehicle", "mc")
    (disarm,) = _disarms(LANDED_DISARM, *args)
    assert disarm["what"] == "disarmed"
    assert "land detector: landed since 14.50 s" in disarm["message"]
    # the same bag without the topic: the vehicle, armed for 13 s, is taken as airborne
    without = [e for e in _events(LANDED_DISARM) if not isinstance(e, ev.LandDetected)]
    bare = write_mcap(tmp_path / "bare.mcap", without, release="1.16")
    (assumed,) = _disarms(bare, *args)
    assert assumed["what"] == "disarm_rejected"
    assert "assumed airborne" in assumed["reason"]


@pytest.mark.parametrize("ulog", SITL_ULOGS, ids=lambda p: p.name)
def test_real_px4_land_detector_through_a_ros2_bag_refuses_both_disarms(
    ulog: Path, tmp_path: Path
) -> None:
    """PX4 SITL's own land detector (1.15.4, 1.18.0-alpha1), carried as the uXRCE-DDS bridge
    publishes it: both disarm requests refused for its verdict, as from the ULog itself."""
    release = "1.15" if "1_15" in ulog.name else "main"
    bag = write_mcap(tmp_path / "flight.mcap", _as_ros2(_events(ulog)), release=release)
    from_bag = _disarms(bag)
    from_ulog = _disarms(ulog)
    assert [r["what"] for r in from_bag] == ["disarm_rejected"] * 2
    assert [r["reason"] for r in from_bag] == [r["reason"] for r in from_ulog]
    assert all("(land detector: not landed since" in r["reason"] for r in from_bag)


def _landed(events: list[ev.Event]) -> list[tuple[float, bool | None]]:
    return [(round(e.t, 6), e.landed) for e in events if isinstance(e, ev.LandDetected)]


@pytest.mark.parametrize("tlog", SITL_TLOGS, ids=lambda p: p.name)
def test_mavros_extended_state_in_a_ros1_bag_gives_the_tlogs_land_detector(
    tlog: Path, tmp_path: Path
) -> None:
    """EXTENDED_SYS_STATE as MAVROS republishes it: the same verdicts at the same times."""
    events = _events(tlog)
    want = _landed(events)
    assert [landed for _, landed in want[:2]] == [True, False]  # on the ground, then flying
    bag = write_rosbag1(tmp_path / "flight.bag", events)
    assert _landed(_events(bag)) == want


def _extended_state(store: Any, landed_state: int) -> bytes:
    types = store.types
    header = types["std_msgs/msg/Header"](
        stamp=types["builtin_interfaces/msg/Time"](sec=0, nanosec=0), frame_id=""
    )
    msg = types["mavros_msgs/msg/ExtendedState"](
        header=header, vtol_state=0, landed_state=landed_state
    )
    data: bytes = store.serialize_cdr(msg, "mavros_msgs/msg/ExtendedState")
    return data


def test_mavros_extended_state_in_a_ros2_bag_without_definitions(tmp_path: Path) -> None:
    """A Humble ``.db3`` bag embeds no definitions: the shipped ExtendedState decodes it. Only
    changes become events; UNDEFINED is unknown, TAKEOFF and LANDING are not landed."""
    store = get_typestore(Stores.ROS2_HUMBLE)
    store.register(mavros_typedefs())
    states = [(0.0, 0), (0.5, 1), (1.0, 1), (1.5, 3), (2.0, 2), (2.5, 4), (3.0, 1)]
    raw = [
        RawMessage(
            t,
            "/uav1/mavros/extended_state",
            "mavros_msgs/msg/ExtendedState",
            msg_text("ExtendedState"),
            _extended_state(store, state),
        )
        for t, state in states
    ]
    bag = write_rosbag2(tmp_path / "bag", [], definitions=False, extra=raw)
    got = [e for e in _events(bag) if isinstance(e, ev.LandDetected)]
    assert [(e.t, e.landed) for e in got] == [
        (0.0, None),
        (0.5, True),
        (1.5, False),
        (3.0, True),
    ]
    assert {e.vehicle for e in got} == {"/uav1"}
    assert got[0].where.topic == "/uav1/mavros/extended_state"
