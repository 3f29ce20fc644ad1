"""OFB006: a companion built against other px4_msgs than the PX4 it talks to (issue 29 item 1).

The recording's topic names (``_vN``, gate spec §16 S9) and embedded definitions say which
px4_msgs releases each side fits; the rule compares the companion's ``/fmu/in`` topics with
PX4's ``/fmu/out`` topics."""

from __future__ import annotations

import dataclasses
import importlib.util
import sys
from pathlib import Path
from types import ModuleType

from mcap.writer import Writer as McapWriter

from fuzzoff.config import Settings
from fuzzoff.engine import lint_file
from fuzzoff.events import Event, VehicleStatus
from fuzzoff.findings import Finding, Severity
from fuzzoff.formats import px4_msgs
from fuzzoff.formats.mcap.writer import write_mcap
from fuzzoff.formats.ros2msgs.messages import RawMessage, encode, to_message
from tests.helpers import CORPORA


def _gate_corpus() -> ModuleType:
    """corpora/gate/build.py: the flights of the corpus cases and ``built_with``."""
    spec = importlib.util.spec_from_file_location("gate_corpus", CORPORA / "gate" / "build.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # its dataclasses look their module up
    spec.loader.exec_module(module)
    return module


gate_corpus = _gate_corpus()

MISMATCH = CORPORA / "gate" / "px4_msgs_mismatch_ros2.mcap"
MATCHED = CORPORA / "gate" / "landed_disarm_ros2.mcap"


def ofb006(path: Path) -> list[Finding]:
    return [f for f in lint_file(path, Settings()).findings if f.code == "OFB006"]


def test_a_companion_built_with_older_px4_msgs_is_an_error() -> None:
    (finding,) = ofb006(MISMATCH)
    assert finding.severity is Severity.ERROR and finding.time_s is None
    assert "/fmu/in/offboard_control_mode fits px4_msgs 1.13, 1.14" in finding.message
    assert "PX4 expects 1.16, 1.17" in finding.message
    # TrajectorySetpoint has one layout from 1.14 to 1.18: not named
    assert "trajectory_setpoint" not in finding.message


def test_both_sides_built_with_one_release_give_nothing() -> None:
    assert ofb006(MATCHED) == []


def status(t: float, vehicle: str = "") -> VehicleStatus:
    return VehicleStatus(t=t, vehicle=vehicle, nav_state=2, armed=False)


def _status_mcap(path: Path, served_old_name: bool) -> Path:
    """PX4 1.16 publishing ``vehicle_status_v1``, and the old name ``vehicle_status`` of a
    companion with 1.15's px4_msgs: a subscription nobody serves (no message on it), or the
    translation node's output (messages on it). Written with the mcap library itself: its
    writer records a channel that carries no message, as a recorder does for a subscription."""
    new_text = px4_msgs.definition("1.16", "VehicleStatus") or ""
    old_text = px4_msgs.definition("1.15", "VehicleStatus") or ""
    with path.open("wb") as fh:
        writer = McapWriter(fh)
        writer.start(profile="ros2", library="test")
        new = writer.register_schema("px4_msgs/msg/VehicleStatus", "ros2msg", new_text.encode())
        old = writer.register_schema("px4_msgs/msg/VehicleStatus", "ros2msg", old_text.encode())
        px4 = writer.register_channel("/fmu/out/vehicle_status_v1", "cdr", new)
        companion = writer.register_channel("/fmu/out/vehicle_status", "cdr", old)
        for k in range(5):
            t = 1_700_000_000_000_000_000 + k * 500_000_000
            data = encode(to_message(status(0.5 * k), "1.16"))
            writer.add_message(px4, log_time=t, data=data, publish_time=t)
            if served_old_name:
                data = encode(to_message(status(0.5 * k), "1.15"))
                writer.add_message(companion, log_time=t + 1, data=data, publish_time=t + 1)
        writer.finish()
    return path


def test_a_subscription_under_another_releases_name_is_reported(tmp_path: Path) -> None:
    """px4_ros_com #229: a client with 1.15's px4_msgs subscribes to /fmu/out/vehicle_status;
    PX4 1.16 publishes /fmu/out/vehicle_status_v1 only."""
    (finding,) = ofb006(_status_mcap(tmp_path / "sub.mcap", served_old_name=False))
    assert "subscribes to /fmu/out/vehicle_status (px4_msgs " in finding.message
    assert "PX4's (1.16, 1.17)" in finding.message
    assert "never served" in finding.summary


def test_the_translation_node_serving_the_old_name_is_no_finding(tmp_path: Path) -> None:
    assert ofb006(_status_mcap(tmp_path / "served.mcap", served_old_name=True)) == []


def test_a_companion_topic_the_translation_node_republishes_is_no_finding(
    tmp_path: Path,
) -> None:
    """The 1.14 client's /fmu/in topics beside the same messages under PX4 1.16's names."""
    sent = [e for e in gate_corpus.landed_disarm_ros2() if e.origin == "sent" and e.t < 3.0]
    old = gate_corpus.built_with("1.14", sent)
    path = write_mcap(tmp_path / "t.mcap", [status(0.0), *sent], release="1.16", extra=old)
    assert ofb006(path) == []


def test_each_vehicle_is_judged_on_its_own_topics(tmp_path: Path) -> None:
    """Two vehicles: /px4_1's companion matches its PX4, /px4_2's does not."""
    sent = [e for e in gate_corpus.landed_disarm_ros2() if e.origin == "sent" and e.t < 3.0]
    events: list[Event] = [status(0.0, "/px4_1"), status(0.0, "/px4_2")]
    good = [dataclasses.replace(e, vehicle="/px4_1") for e in sent]
    bad = gate_corpus.built_with("1.14", [dataclasses.replace(e, vehicle="/px4_2") for e in sent])
    path = write_mcap(tmp_path / "two.mcap", [*events, *good], release="1.16", extra=bad)
    (finding,) = ofb006(path)
    assert finding.vehicle == "/px4_2"
    assert "/px4_2/fmu/in/offboard_control_mode" in finding.message


def test_a_topic_name_from_other_px4_msgs_than_its_definition(tmp_path: Path) -> None:
    """px4_ros_com #229: an example built with 1.16's px4_msgs keeps the old name
    ``/fmu/out/vehicle_status``; PX4 1.16 publishes ``_v1``. The recording holds the name with
    the 1.16 definition (the subscription's type) beside PX4's own topic."""
    msg = to_message(status(0.2), "1.16")
    text = px4_msgs.definition("1.16", "VehicleStatus") or ""
    old_name = RawMessage(0.2, "/fmu/out/vehicle_status", msg.typename, text, encode(msg))
    path = write_mcap(
        tmp_path / "names.mcap", [status(0.5), status(1.5)], release="1.16", extra=[old_name]
    )
    (finding,) = ofb006(path)
    assert "/fmu/out/vehicle_status: its name fits px4_msgs" in finding.message
    assert "its definition 1.16, 1.17" in finding.message
    assert "topic name and message version disagree" in finding.summary
