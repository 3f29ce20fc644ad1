"""Real PX4 over its ROS 2 bridge (``corpora/ros2bridge``): px4_ros_com's offboard_control
flown on PX4 1.16.2 and the 1.18 head through the Micro XRCE-DDS Agent, recorded as
``ros2 bag record`` records (mcap and sqlite3) beside PX4's ULog (issue 28 item 1).

- every *clean* recording lints with exit 0 and nothing at warning or above (where today's
  rules still say more, its expected file lists it under ``known_false``: a strict xfail);
- every *hazard* recording gives one of its error codes (where the recording cannot show it,
  its expected file says why under ``missed``: a strict xfail);
- the two storages of one flight give the same findings, and hold the same records;
- the bags hold what a ROS 2 recorder writes: CDR as received, schemas, the offered QoS.

The findings themselves are pinned by ``tests/test_corpora.py`` (``NAME.expected.json``).
"""

from __future__ import annotations

import functools
import json
from pathlib import Path
from typing import Any

import pytest
from rosbags.interfaces import QosDurability, QosReliability
from rosbags.rosbag2 import Reader

from tests.helpers import CORPORA, run_cli

HERE = CORPORA / "ros2bridge"
RUNS: dict[str, dict[str, Any]] = json.loads((HERE / "runs.json").read_text())
SPECS = sorted(HERE.glob("*.expected.json"))


@functools.cache
def _lint(recording: Path) -> tuple[int, list[dict[str, Any]], dict[str, Any]]:
    out = run_cli(["lint", str(recording), "--format", "json"])
    (report,) = json.loads(out.stdout)["files"]
    return out.returncode, report["findings"], report["profile"]


def _cases(kind: str) -> list[Any]:
    cases = []
    for path in SPECS:
        spec = json.loads(path.read_text())
        if spec["kind"] != kind:
            continue
        marks = []
        why = spec.get("missed") or spec.get("known_false")
        if why:
            marks.append(pytest.mark.xfail(strict=True, reason="; ".join(why)))
        cases.append(pytest.param(spec, id=spec["recording"], marks=marks))
    return cases


@pytest.mark.parametrize("spec", _cases("clean"))
def test_a_clean_bridge_flight_passes_with_nothing_above_info(spec: dict[str, Any]) -> None:
    code, findings, _ = _lint(HERE / spec["recording"])
    loud = [f"{f['code']} {f['message']}" for f in findings if f["severity"] != "info"]
    assert code == 0 and not loud, loud


@pytest.mark.parametrize("spec", _cases("hazard"))
def test_a_hazard_bridge_flight_gives_its_error(spec: dict[str, Any]) -> None:
    _, findings, _ = _lint(HERE / spec["recording"])
    assert any(f["code"] in spec["hazard"] and f["severity"] == "error" for f in findings)


@pytest.mark.parametrize("stem", sorted(RUNS))
def test_both_storages_of_a_flight_hold_the_same_records_and_findings(stem: str) -> None:
    mcap, sqlite = HERE / f"{stem}-mcap", HERE / f"{stem}-sqlite3"
    with Reader(mcap) as a, Reader(sqlite) as b:
        assert [(c.topic, t, bytes(d)) for c, t, d in a.messages()] == [
            (c.topic, t, bytes(d)) for c, t, d in b.messages()
        ]
    strip = [[(f["code"], f["severity"], f["time_s"]) for f in _lint(p)[1]] for p in (mcap, sqlite)]
    assert strip[0] == strip[1]


@pytest.mark.parametrize("stem", sorted(s for s in RUNS if "in_only" not in s))
def test_the_release_of_a_bridge_bag_is_detected_from_its_topics(stem: str) -> None:
    profile = _lint(HERE / f"{stem}-mcap")[2]
    release = RUNS[stem]["release"]
    assert profile["detected"] and profile["vehicle"] == "mc"
    assert profile["px4"] == ("1.16" if release.startswith("1.16") else "main")


@pytest.mark.parametrize("stem", sorted(RUNS))
def test_a_bridge_bag_holds_what_a_ros2_recorder_writes(stem: str) -> None:
    with Reader(HERE / f"{stem}-sqlite3") as reader:
        connections = {c.topic: c for c in reader.connections}
        for topic, count in RUNS[stem]["counts"].items():
            if count:
                assert connections[topic].msgcount == count
        for topic, connection in connections.items():
            assert connection.msgtype.startswith("px4_msgs/msg/")
            assert connection.ext.serialization_format == "cdr"  # type: ignore[union-attr]
            assert "uint64 timestamp" in connection.msgdef.data
            # one profile per writer: the agent restarted mid-flight made PX4's writers again
            offered = connection.ext.offered_qos_profiles  # type: ignore[union-attr]
            assert 1 <= len(offered) <= (2 if "agent_restart" in stem else 1)
            for qos in offered:
                if topic.startswith("/fmu/out/"):  # PX4's bridge writers
                    assert qos.reliability == QosReliability.BEST_EFFORT
                    assert qos.durability == QosDurability.TRANSIENT_LOCAL
                else:  # the node's rclcpp publishers (depth 10)
                    assert qos.reliability == QosReliability.RELIABLE
                    assert qos.durability == QosDurability.VOLATILE
        first = next(iter(reader.messages()))
        assert bytes(first[2])[:4] == b"\x00\x01\x00\x00"  # CDR little endian, as sent


IN_ONLY = HERE / "example_in_only-1.16.2-ros2-mcap"


@pytest.mark.xfail(
    strict=True,
    reason="issue 28 miss 5: a bag of /fmu/in topics only is 'PX4 1.15 assumed' although its"
    " schemas are 1.16's (layouts equal, the definitions' text differs)",
)
def test_a_bag_of_inputs_only_is_dated_from_its_schemas() -> None:
    assert _lint(IN_ONLY)[2]["px4"] == "1.16"


@pytest.mark.xfail(
    strict=True,
    reason="issue 28 miss 5: OFB102 says 'after 0.00 s' when the stream starts at the bag's"
    " first message",
)
def test_a_switch_one_second_into_the_stream_is_not_called_instant() -> None:
    said = [f["summary"] for f in _lint(IN_ONLY)[1] if f["code"] == "OFB102"]
    assert said and not any("after 0.00 s" in m for m in said)
