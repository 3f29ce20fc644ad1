"""Topic names, namespaces, definition choice (--px4, _vN, payload length) and MAVROS in ROS 2."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest
from rosbags.typesys import Stores, get_typestore

from fuzzoff import events as ev
from fuzzoff.formats.mavros.mavros_msgs import mavros_typedefs, msg_text
from fuzzoff.formats.mcap.writer import write_mcap
from fuzzoff.formats.ros2msgs.messages import RawMessage
from fuzzoff.formats.ros2msgs.topics import parse_topic
from fuzzoff.formats.rosbag2.writer import write_rosbag2
from tests.ros2_samples import every_kind, read_all


@pytest.mark.parametrize(
    ("topic", "namespace", "direction", "name", "version"),
    [
        ("/fmu/in/offboard_control_mode", "", "in", "offboard_control_mode", None),
        ("/fmu/out/vehicle_status_v4", "", "out", "vehicle_status", 4),
        (
            "/px4_1/fmu/in/vehicle_attitude_setpoint_v1",
            "/px4_1",
            "in",
            "vehicle_attitude_setpoint",
            1,
        ),
        (
            "/fleet/uav_2/fmu/out/vehicle_command_ack",
            "/fleet/uav_2",
            "out",
            "vehicle_command_ack",
            None,
        ),
        ("fmu/trajectory_setpoint/in", "", "in", "trajectory_setpoint", None),
        ("/fmu/vehicle_status/out", "", "out", "vehicle_status", None),
    ],
)
def test_topic_names(
    topic: str, namespace: str, direction: str, name: str, version: int | None
) -> None:
    ref = parse_topic(topic)
    assert ref is not None
    assert (ref.namespace, ref.direction, ref.name, ref.version) == (
        namespace,
        direction,
        name,
        version,
    )


@pytest.mark.parametrize("topic", ["/camera/image", "/fmu/in", "/mavros/state", "/fmu/in/X"])
def test_other_topics_are_not_px4(topic: str) -> None:
    assert parse_topic(topic) is None


def test_two_vehicles_are_two_streams(tmp_path: Path) -> None:
    events = every_kind("main") + every_kind("main", vehicle="/px4_1")
    source, read = read_all(write_rosbag2(tmp_path / "bag", events))
    assert source.probe().vehicles == ["", "/px4_1"]
    assert {e.vehicle for e in read} == {"", "/px4_1"}
    assert sum(e.vehicle == "/px4_1" for e in read) == len(read) // 2


def test_humble_bag_release_comes_from_the_payloads(tmp_path: Path) -> None:
    bag = write_rosbag2(tmp_path / "bag", every_kind("1.14"), release="1.14", definitions=False)
    source, read = read_all(bag)
    assert source.probe().px4_version == "1.14"
    control = next(e for e in read if isinstance(e, ev.ControlMode))
    assert control.layout == "actuator"
    assert source.problems == []


def test_px4_option_steers_a_bag_without_definitions(tmp_path: Path) -> None:
    bag = write_rosbag2(tmp_path / "bag", every_kind("main"), release="main", definitions=False)
    source, read = read_all(bag, px4="1.13")
    # The 1.13 TrajectorySetpoint is longer than main's: the payload does not fit it.
    assert any("TrajectorySetpoint" in p.what and "--px4 1.13" in p.what for p in source.problems)
    assert not any(isinstance(e, ev.TrajectorySetpoint) for e in read)


def test_px4_option_matching_the_bag_is_used(tmp_path: Path) -> None:
    bag = write_rosbag2(tmp_path / "bag", every_kind("1.15"), release="1.15", definitions=False)
    source, read = read_all(bag, px4="1.15.4")
    assert source.problems == []
    assert len(read) == len(every_kind("1.15"))


def test_an_extra_trailing_field_is_not_decoded_away(tmp_path: Path) -> None:
    # 1.15 OffboardControlMode (7 flags) declared as 1.14 (6 flags) with direct_actuator set:
    # rosbags alone would accept it (3 bytes of slack) and report a wrong flag.
    flight = [ev.ControlMode(t=0.1 * i, position=True, direct_actuator=True) for i in range(5)]
    path = write_mcap(tmp_path / "f.mcap", flight, release="1.14", payload_release="1.15")
    source, read = read_all(path)
    assert read == []
    (problem,) = source.problems
    assert "OffboardControlMode" in problem.what and "embedded definition" in problem.what


def _mavros_raw(t: float, topic: str, name: str, **values: Any) -> RawMessage:
    store = get_typestore(Stores.ROS2_HUMBLE)
    store.register({k: v for k, v in mavros_typedefs().items() if k not in store.fielddefs})
    types = store.types
    header = types["std_msgs/msg/Header"](
        stamp=types["builtin_interfaces/msg/Time"](sec=1, nanosec=0), frame_id=""
    )
    msgtype = f"mavros_msgs/msg/{name}"
    msg = types[msgtype](header=header, **values)
    data = bytes(store.serialize_cdr(msg, msgtype))
    return RawMessage(t, topic, msgtype, msg_text(name), data)


@pytest.mark.parametrize("definitions", [True, False])
def test_mavros_topics_become_what_mavros_sends(tmp_path: Path, definitions: bool) -> None:
    vec = get_typestore(Stores.ROS2_HUMBLE).types
    raw = [
        _mavros_raw(
            0.1 * i,
            "/uav1/mavros/setpoint_raw/local",
            "PositionTarget",
            coordinate_frame=1,
            type_mask=0x0DF8,
            position=vec["geometry_msgs/msg/Point"](x=1.0, y=2.0, z=3.0),
            velocity=vec["geometry_msgs/msg/Vector3"](x=0.0, y=0.0, z=0.0),
            acceleration_or_force=vec["geometry_msgs/msg/Vector3"](x=0.0, y=0.0, z=0.0),
            yaw=0.0,
            yaw_rate=0.0,
        )
        for i in range(5)
    ]
    raw.append(
        _mavros_raw(
            0.45,
            "/uav1/mavros/state",
            "State",
            connected=True,
            armed=True,
            guided=True,
            manual_input=False,
            mode="OFFBOARD",
            system_status=np.uint8(4),
        )
    )
    bag = write_rosbag2(tmp_path / "bag", [], extra=raw, definitions=definitions)
    source, read = read_all(bag)
    assert source.problems == []
    targets = [e for e in read if isinstance(e, ev.SetPositionTargetLocal)]
    assert len(targets) == 5
    assert targets[0].vehicle == "/uav1"
    assert targets[0].position == pytest.approx((2.0, 1.0, -3.0))  # ENU -> NED
    (status,) = [e for e in read if isinstance(e, ev.VehicleStatus)]
    assert status.nav_state == ev.NAV_STATE_OFFBOARD
    assert source.probe().kinds >= {"set_position_target_local_ned", "vehicle_status"}


def test_unparsable_embedded_definition_falls_back_to_bundled(tmp_path: Path) -> None:
    from fuzzoff.formats.ros2msgs.messages import encode, to_message

    raws = [
        RawMessage(
            0.1 * k,
            "/fmu/in/offboard_control_mode",
            "px4_msgs/msg/OffboardControlMode",
            "this is not a message definition ]]]",
            encode(to_message(ev.ControlMode(t=0.1 * k, position=True), "main")),
        )
        for k in range(5)
    ]
    source, read = read_all(write_mcap(tmp_path / "f.mcap", [], extra=raws))
    assert source.problems == []
    assert [e.kind for e in read] == ["control_mode"] * 5
    assert any("embedded definition not usable" in note for note in source.probe().notes)


@pytest.mark.parametrize(
    ("event", "field"),
    [
        (ev.VehicleStatus(t=0.0, nav_state=14, armed=True, vehicle_type=2), "nav_state"),
        (ev.TrajectorySetpoint(t=0.0, position=(1.0, 2.0, -3.0)), "position"),
    ],
)
def test_embedded_definition_without_a_needed_field_falls_back_to_bundled(
    tmp_path: Path, event: ev.Event, field: str
) -> None:
    # A fork's px4_msgs (or a damaged schema) that renamed a field fuzzoff reads: the payload
    # still has the release's layout, so the bundled definition decodes it.
    from fuzzoff.formats import px4_msgs
    from fuzzoff.formats.ros2msgs.messages import encode, to_message

    message = to_message(event, "1.15")
    text = px4_msgs.definition("1.15", message.message)
    assert text is not None and f" {field}\n" in text
    renamed = text.replace(f" {field}\n", f" {field}_renamed\n", 1)
    raw = RawMessage(0.1, message.topic, message.typename, renamed, encode(message, "1.15"))
    source, read = read_all(write_mcap(tmp_path / "f.mcap", [], extra=[raw]))
    _, expected = read_all(write_mcap(tmp_path / "plain.mcap", [event], release="1.15"))
    assert source.problems == []
    assert [(type(e), e.kind) for e in read] == [(type(e), e.kind) for e in expected]
    assert getattr(read[0], field) == getattr(expected[0], field)
    info = source.probe()
    assert any(f"has no field '{field}'; bundled px4_msgs used" in n for n in info.notes)
    if isinstance(event, ev.VehicleStatus):
        assert info.vehicle_type == "fw"  # read from the first status, through the fallback
