"""OFB204 and the gate model's refusal: mode and arming commands PX4's MAVLink receiver does not
pass on, per release, as seen on running PX4 SITL (rules/OFB204.toml). Each case is a tlog
written with pymavlink and read back, so the reader's routing by target_system is part of it."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from fuzzoff.events import Command, CommandMessage, Event, VehicleInfo, VehicleStatus
from fuzzoff.formats.tlog.writer import write_tlog
from tests.helpers import run_cli

POSCTL, OFFBOARD = 2, 14
SWITCH = (1.0, 6.0, 0.0, 0.0, 0.0, 0.0, 0.0)
"""DO_SET_MODE to OFFBOARD (custom main mode 6)."""


def _tlog(
    tmp_path: Path, system: int, component: int, message: CommandMessage, version: str
) -> Path:
    events: list[Event] = [VehicleInfo(t=0.0, vehicle="1", px4_version=version)]
    events += [VehicleStatus(t=t / 2, vehicle="1", nav_state=POSCTL, armed=False) for t in range(6)]
    events.append(
        Command(
            t=1.2,
            vehicle="1",
            command=176,
            params=SWITCH,
            target_system=system,
            target_component=component,
            source_system=1,
            source_component=191,
            message=message,
        )
    )
    return write_tlog(
        tmp_path / f"cmd-{system}-{component}-{message}.tlog", sorted(events, key=lambda e: e.t)
    )


def _lint(path: Path) -> tuple[int, list[dict[str, object]], list[dict[str, object]]]:
    result = run_cli(["lint", str(path), "--format", "json", "--select", "OFB204"])
    report = json.loads(result.stdout)
    findings = [f for f in report["files"][0]["findings"] if f["code"] == "OFB204"]
    gate = run_cli(["gate", str(path), "--format", "json"])
    transitions = json.loads(gate.stdout)["files"][0]["vehicles"][0]["timeline"]
    return result.returncode, findings, transitions


@pytest.mark.parametrize(
    ("version", "severity", "effect"),
    [
        ("1.14.4", "error", "answers it with FAILED"),
        ("1.15.4", "error", "answers it with FAILED"),
        ("1.16.2", "error", "drops it without an answer"),
        ("1.17.0", "error", "drops it without an answer"),
        ("1.18.0", "warning", "1.18 handles it"),
    ],
)
def test_broadcast_switch_per_release(
    tmp_path: Path, version: str, severity: str, effect: str
) -> None:
    code, findings, transitions = _lint(_tlog(tmp_path, 0, 0, "COMMAND_LONG", version))
    (finding,) = findings
    assert finding["severity"] == severity and effect in finding["message"]
    assert "target_system 0" in finding["message"]
    assert code == 1
    verdicts = [t for t in transitions if t["time_s"] == pytest.approx(finding["time_s"])]
    accepted = any(t["what"] == "request_accepted" for t in verdicts)
    assert accepted is (severity == "warning"), verdicts


@pytest.mark.parametrize("message", ["COMMAND_LONG", "COMMAND_INT"])
def test_another_component_is_refused_on_every_release(tmp_path: Path, message: str) -> None:
    for version in ("1.14.4", "1.16.2", "1.18.0"):
        _, findings, transitions = _lint(_tlog(tmp_path, 1, 5, message, version))
        (finding,) = findings
        assert finding["severity"] == "error"
        assert "target_component 5" in finding["message"]
        assert not any(t["what"] == "request_accepted" for t in transitions)


@pytest.mark.parametrize(("system", "component"), [(1, 1), (1, 0)])
def test_the_vehicle_or_component_0_is_taken(tmp_path: Path, system: int, component: int) -> None:
    for version in ("1.14.4", "1.17.0", "1.18.0"):
        code, findings, transitions = _lint(
            _tlog(tmp_path, system, component, "COMMAND_LONG", version)
        )
        assert not findings and code == 0
        assert any(t["what"] == "request_accepted" for t in transitions)


def test_set_mode_to_system_0_is_taken_everywhere(tmp_path: Path) -> None:
    for version in ("1.14.4", "1.16.2", "1.18.0"):
        code, findings, _ = _lint(_tlog(tmp_path, 0, 0, "SET_MODE", version))
        assert not findings and code == 0


def test_a_command_for_a_system_not_in_the_recording(tmp_path: Path) -> None:
    code, findings, _ = _lint(_tlog(tmp_path, 9, 1, "SET_MODE", "1.16.2"))
    (finding,) = findings
    assert finding["vehicle"] == "9" and "no vehicle with that id" in finding["message"]
    assert finding["severity"] == "error" and code == 1
